"""Files in and out: the user's text files read with one clear error each; outputs written
atomically; CSV tables with one float format.

Every file is written to a temporary sibling and renamed over the target, so an interrupted run
leaves either the old file or the new one, never a truncated mix. Nothing written here depends on
the time, the machine or the working directory, so CI can diff outputs byte for byte.
"""

from __future__ import annotations

import os
import secrets
from pathlib import Path
from typing import Callable, Iterable, Sequence

from fivebar_cli.errors import InputError, OutputError

FLOAT_FORMAT = "%.10g"


def read_user_text(path: str | Path, error: type[InputError], what: str) -> str:
    """The UTF-8 text of `path`; `error` (an InputError class) names the file, `what` the expected kind."""
    source = str(path)
    try:
        raw = Path(path).read_bytes()
    except FileNotFoundError:
        raise error(source, "", "no such file") from None
    except IsADirectoryError:
        raise error(source, "", f"is a directory, not {what}") from None
    except OSError as exc:
        raise error(source, "", f"cannot read: {exc.strerror or exc}") from None
    try:
        text = raw.decode("utf-8")
    except UnicodeDecodeError:
        raise error(source, "", f"not {what} (binary data, not UTF-8 text)") from None
    if "\x00" in text:
        raise error(source, "", f"not {what} (binary data: NUL bytes)")
    return text


def ensure_dir(path: str | Path) -> Path:
    path = Path(path)
    try:
        path.mkdir(parents=True, exist_ok=True)
    except OSError as exc:
        raise OutputError(f"{path}: cannot create output folder: {exc.strerror or exc}") from None
    if not os.access(path, os.W_OK | os.X_OK):
        raise OutputError(f"{path}: output folder is not writable")
    return path


def atomic_write(path: str | Path, write: Callable[[Path], None]) -> Path:
    """Call `write(tmp_path)` and rename the result over `path` (same folder, so the rename is atomic).

    On any failure or interruption the temporary file is removed and `path` is untouched. Only a
    SIGKILL can leave a `.<name>.*.tmp` file behind (never in place of `path`).
    """
    path = Path(path)
    ensure_dir(path.parent)
    tmp = path.with_name(f".{path.name}.{secrets.token_hex(6)}.tmp")  # named before it exists, so
    try:  # an interruption at any point below can remove it
        os.close(os.open(tmp, os.O_WRONLY | os.O_CREAT | os.O_EXCL, 0o644))
        write(tmp)
        os.chmod(tmp, 0o644)
        os.replace(tmp, path)
    except OSError as exc:
        _discard(tmp)
        raise OutputError(f"{path}: cannot write: {exc.strerror or exc}") from None
    except BaseException:
        _discard(tmp)
        raise
    return path


def _discard(tmp: Path) -> None:
    tmp.unlink(missing_ok=True)


def write_text(path: str | Path, text: str) -> Path:
    """Atomically write UTF-8 text with `\\n` line ends."""
    data = text.encode("utf-8")

    def write(tmp: Path) -> None:
        with open(tmp, "wb") as fh:
            fh.write(data)
            fh.flush()
            os.fsync(fh.fileno())

    return atomic_write(path, write)


def format_value(value: object) -> str:
    """One fixed format for every CSV cell: floats as %.10g, everything else as str."""
    if isinstance(value, float) or type(value).__name__.startswith("float"):
        v = float(value)  # type: ignore[arg-type]
        if v == 0.0:
            return "0"  # no "-0"
        return FLOAT_FORMAT % v
    if type(value).__name__.startswith(("int", "uint")):
        return str(int(value))  # type: ignore[call-overload]
    return str(value)


def csv_text(header: Sequence[str], rows: Iterable[Sequence[object]]) -> str:
    """A CSV table as text: header row, fixed float format, `\\n` line ends, no quoting needed."""
    lines = [",".join(header)]
    for row in rows:
        cells = [format_value(v) for v in row]
        if len(cells) != len(header):
            raise ValueError(f"row has {len(cells)} cells, header has {len(header)}")
        for cell in cells:
            if any(c in cell for c in ',"\n\r'):
                raise ValueError(f"CSV cell {cell!r} would need quoting")
        lines.append(",".join(cells))
    return "\n".join(lines) + "\n"


def write_csv(path: str | Path, header: Sequence[str], rows: Iterable[Sequence[object]]) -> Path:
    return write_text(path, csv_text(header, rows))


def save_figure(fig, path: str | Path) -> Path:
    """Atomically save a matplotlib figure as PNG (no timestamp in the metadata)."""

    def write(tmp: Path) -> None:
        fig.savefig(tmp, format="png", dpi=fig.dpi, metadata={"Software": None})

    return atomic_write(path, write)
