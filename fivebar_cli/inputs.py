"""Reading the user's files: one clear InputError per problem (missing, a folder, unreadable, binary)."""

from __future__ import annotations

from pathlib import Path

from fivebar_cli.errors import InputError


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
