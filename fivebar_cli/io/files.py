"""Files in and out: the user's text files read with one clear error each; outputs written
atomically; CSV tables with one float format.

Every file is written to a temporary sibling and renamed over the target, so an interrupted run
leaves either the old file or the new one, never a truncated mix. A target that is not a regular
file (a FIFO, a device, a socket, a folder) or that is a symbolic link is never replaced: the write
is refused with one line. Every file written here is also recorded by the output set being written
(`io.outputs`), if any. Nothing written here depends on the time, the machine or the working
directory, so CI can diff outputs byte for byte.
"""

from __future__ import annotations

import csv
import io
import os
import secrets
import stat
from contextvars import ContextVar
from pathlib import Path
from typing import Callable, Iterable, Sequence

from fivebar_cli.errors import InputError, NotARegularFile, OutputError, param

FLOAT_FORMAT = "%.10g"
NEEDS_QUOTES = frozenset(',"\n\r')  # RFC 4180: a cell holding one of these is quoted
_KINDS = ((stat.S_ISDIR, "a folder"), (stat.S_ISFIFO, "a FIFO (named pipe)"), (stat.S_ISCHR, "a character device"),
          (stat.S_ISBLK, "a block device"), (stat.S_ISSOCK, "a socket"))
# The output set being written (io.outputs.OutputSet), told before and after each file: set by io.outputs.
ACTIVE_SET: ContextVar = ContextVar("fivebar_output_set", default=None)


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


def read_csv_table(path: str | Path, required: Sequence[str] = ()) -> tuple[list[str], list[tuple[int, dict[str, str]]]]:
    """(header, [(line number, row as a dict by column name)]) of a CSV file, cells stripped and
    blank lines skipped; InputError naming the file and line for a missing `required` column or a
    row whose cells do not match the header. Readers take columns by name, so that tables with
    extra or reordered columns still read."""
    text = read_user_text(path, InputError, "a CSV table")
    reader = csv.reader(io.StringIO(text))
    try:
        header = [h.strip() for h in next(reader)]
    except StopIteration:
        raise InputError(str(path), "line 1", "empty table (expected a header row)") from None
    missing = [c for c in required if c not in header]
    if missing:
        raise InputError(str(path), "line 1", f"missing column {missing[0]!r}")
    rows = []
    for number, cells in enumerate(reader, start=2):
        if not cells:
            continue
        if len(cells) != len(header):
            raise InputError(str(path), f"line {number}", f"{len(cells)} cells, the header has {len(header)}")
        rows.append((number, {h: c.strip() for h, c in zip(header, cells)}))
    return header, rows


def ensure_dir(path: str | Path) -> Path:
    """Create a folder (and its parents) if needed; OutputError if it cannot be a writable folder.
    A symbolic link to a folder is followed: it is the user's layout, not an output."""
    path = Path(path)
    try:
        path.mkdir(parents=True, exist_ok=True)
    except FileExistsError:
        raise OutputError(f"{path}: cannot create output folder: it exists and is not a folder") from None
    except OSError as exc:
        raise OutputError(f"{path}: cannot create output folder: {exc.strerror or exc}") from None
    if not os.access(path, os.W_OK | os.X_OK):
        raise OutputError(f"{path}: output folder is not writable")
    return path


def user_path(value, field: str, expected: str = "a path (str or os.PathLike)") -> Path:
    """A path given to a library call (its parameter `field`), as a Path. InputError naming the
    parameter for anything else (None, a number) and for the empty string, which the system's calls
    take for the current folder: outputs would land there unnoticed, or a folder be read for a file."""
    if isinstance(value, (str, bytes)) and not value:
        raise InputError("", param(field), "an empty name ('.' is the current folder)")
    if not isinstance(value, (str, os.PathLike)):
        raise InputError("", param(field), f"expected {expected}, got {value!r}")
    return Path(value)


def check_writable_dir(path: str | Path) -> Path:
    """OutputError unless `path` is, or can be created as, a writable folder; creates nothing (a
    command checks its folder before computing, and creates it only when it writes)."""
    path = Path(path)
    probe = path
    while not os.path.lexists(probe) and probe != probe.parent:
        probe = probe.parent  # the nearest part of the path that exists
    if os.path.lexists(probe) and not probe.is_dir():
        raise OutputError(f"{path}: cannot create output folder: {probe} exists and is not a folder")
    if not os.access(probe, os.W_OK | os.X_OK):
        raise OutputError(f"{path}: output folder is not writable" if probe == path
                          else f"{path}: cannot create output folder: {probe} is not writable")
    return path


def refuse_special(path: Path) -> None:
    """OutputError when `path` exists and is a symbolic link or not a regular file: such a target
    is never replaced by an output (a FIFO's reader would get nothing, a device node would become a
    file, a link would be replaced instead of its target)."""
    try:
        st = os.lstat(path)
    except FileNotFoundError:
        return
    except OSError as exc:
        raise OutputError(f"{path}: cannot write: {exc.strerror or exc}") from None
    if stat.S_ISLNK(st.st_mode):
        raise OutputError(f"{path}: is a symbolic link: not replaced (write to its target, or remove the link)")
    for test, kind in _KINDS:
        if test(st.st_mode):
            raise (OutputError if kind == "a folder" else NotARegularFile)(f"{path}: is {kind}, not a regular file: "
                                                                           "not replaced")


def atomic_write(path: str | Path, write: Callable[[Path], None]) -> Path:
    """Call `write(tmp_path)` and rename the result over `path` (same folder, so the rename is atomic).

    On any failure or interruption the temporary file is removed and `path` is untouched. Only a
    SIGKILL can leave a `.<name>.*.tmp` file behind (never in place of `path`). A `path` that is a
    symbolic link or not a regular file is refused (`refuse_special`).
    """
    path = Path(path)
    refuse_special(path)
    output_set = ACTIVE_SET.get()
    if output_set is not None:
        output_set.before_write(path)  # the set is marked as being written before its first file changes
    ensure_dir(path.parent)
    tmp = path.with_name(f".{path.name}.{secrets.token_hex(6)}.tmp")  # named before it exists, so
    try:  # an interruption at any point below can remove it
        os.close(os.open(tmp, os.O_WRONLY | os.O_CREAT | os.O_EXCL, 0o644))
        write(tmp)
        os.chmod(tmp, 0o644)
        refuse_special(path)  # again: it may have appeared while this file was being written
        os.replace(tmp, path)
    except OSError as exc:
        _discard(tmp)
        if isinstance(exc, OutputError):
            raise
        raise OutputError(f"{path}: cannot write: {exc.strerror or exc}") from None
    except BaseException:
        _discard(tmp)
        raise
    if output_set is not None:
        output_set.written(path)
    return path


def _discard(tmp: Path) -> None:
    tmp.unlink(missing_ok=True)


def write_text(path: str | Path, text: str) -> Path:
    """Atomically write UTF-8 text with `\\n` line ends, flushed to the disk before the rename
    (unless FIVEBAR_FSYNC=0: scratch files need not survive a power cut)."""
    data = text.encode("utf-8")

    def write(tmp: Path) -> None:
        with open(tmp, "wb") as fh:
            fh.write(data)
            fh.flush()
            if os.environ.get("FIVEBAR_FSYNC") != "0":  # see docs/formats.md, "Output layout"
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


def csv_cell(text: str) -> str:
    """A cell as RFC 4180 writes it: quoted (inner quotes doubled) only when it holds `,`, `"` or a
    line break, so every file of numbers and plain words reads the same as before quoting existed."""
    if NEEDS_QUOTES.isdisjoint(text):
        return text
    return '"' + text.replace('"', '""') + '"'


def csv_text(header: Sequence[str], rows: Iterable[Sequence[object]]) -> str:
    """A CSV table as text: header row, fixed float format, `\\n` line ends, RFC 4180 quoting where
    a cell needs it (text such as a mechanism's name)."""
    lines = [",".join(csv_cell(h) for h in header)]
    for row in rows:
        cells = [format_value(v) for v in row]
        if len(cells) != len(header):
            raise ValueError(f"row has {len(cells)} cells, header has {len(header)}")
        lines.append(",".join(csv_cell(c) for c in cells))
    return "\n".join(lines) + "\n"


def write_csv(path: str | Path, header: Sequence[str], rows: Iterable[Sequence[object]]) -> Path:
    return write_text(path, csv_text(header, rows))


def save_figure(fig, path: str | Path) -> Path:
    """Atomically save a matplotlib figure as PNG (no timestamp in the metadata)."""

    def write(tmp: Path) -> None:
        fig.savefig(tmp, format="png", dpi=fig.dpi, metadata={"Software": None})

    return atomic_write(path, write)
