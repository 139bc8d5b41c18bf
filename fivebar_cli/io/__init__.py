"""Files: strict YAML reading and field checks, the `.qt` format, atomic writes and CSV, the
output folder layout. Nothing here knows a mechanism."""
