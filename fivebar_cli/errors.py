"""Error types the CLI turns into one line on stderr and an exit status (no traceback); and the
interruption by a signal, with the moments when it must wait (`deferred_interrupts`)."""

from __future__ import annotations

import signal
import threading
from contextlib import contextmanager
from typing import Iterator


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


def param(name: str, value=None) -> str:
    """A library call's parameter as messages name it: `name`, or `name=value` (`depth=12`,
    `allow_serial=True`, `procedure='exact'`), in backticks. Library messages name parameters this
    way only, never a command-line flag: a front end respells them with its own names (the CLI:
    `cli/options.py`'s `as_flags`, `--depth 12`, `--allow-serial`)."""
    return f"`{name}`" if value is None else f"`{name}={value!r}`"


class OutputError(FivebarError, OSError):
    """An output could not be written, exit status 1."""


class Interrupted(BaseException):
    """Ctrl-C, SIGTERM or SIGHUP, raised by the CLI's signal handlers (cli/main.py); the atomic
    writer removes its temporary file on the way out. A BaseException, like KeyboardInterrupt, so
    that no library's `except Exception` swallows it (matplotlib reading a style file printed "Bad
    value in file ..." and went on), and not a KeyboardInterrupt, which click turns into its own
    Abort. Exit status 128 + the signal's number (130 for Ctrl-C), as a shell reports a process
    killed by it."""

    def __init__(self, message: str, signum: int = signal.SIGINT):
        super().__init__(message)
        self.signum = signum
        self.exit_status = 128 + int(signum)


@contextmanager
def deferred_interrupts() -> Iterator[None]:
    """Hold Ctrl-C, SIGTERM and SIGHUP during a block that must not stop half-way (closing a
    cluster, saving a manifest): a signal that arrives meanwhile raises its Interrupted when the
    block is done. Outside the main thread (where Python runs no handler) it does nothing."""
    if threading.current_thread() is not threading.main_thread():
        yield
        return
    held: list[int] = []
    previous = {}
    for sig in INTERRUPTS:
        handler = signal.getsignal(sig)
        if callable(handler):  # ours (or Python's Ctrl-C handler): hold it; an ignored signal stays ignored
            previous[sig] = handler
            signal.signal(sig, lambda signum, frame: held.append(signum))
    try:
        yield
    finally:
        for sig, handler in previous.items():
            signal.signal(sig, handler)
    if held and held[0] in previous:
        previous[held[0]](held[0], None)  # the handler raises (Interrupted, or KeyboardInterrupt)


INTERRUPTS = (signal.SIGINT, signal.SIGTERM, signal.SIGHUP)


class FivebarWarning(UserWarning):
    """Something the user should know that does not stop the run (a file not read, a part
    recomputed): the CLI prints it as one line, `fivebar: warning: <message>`."""
