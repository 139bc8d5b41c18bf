"""Error types the CLI turns into one line on stderr and an exit status (no traceback)."""

from __future__ import annotations


class FivebarError(Exception):
    """A failure the user should see as one clear line; `exit_status` is what the CLI returns."""

    exit_status = 1


class InputError(FivebarError, ValueError):
    """Bad input (a file, a field, an option): `source: field: message`, exit status 2."""

    exit_status = 2

    def __init__(self, source: str, field: str, message: str):
        self.source, self.field, self.message = source, field, message
        where = f"{source}: {field}" if field else source
        super().__init__(f"{where}: {message}")


class OutputError(FivebarError, OSError):
    """An output could not be written, exit status 1."""


class Interrupted(FivebarError):
    """Ctrl-C or SIGTERM, raised by the CLI's signal handlers (cli/main.py) so that click does not turn
    it into its own Abort, and so that the atomic writer removes its temporary file on the way out.
    Code that wraps errors lets it through unchanged."""
