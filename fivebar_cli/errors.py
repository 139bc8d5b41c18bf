"""Error types the CLI turns into one line on stderr and an exit status (no traceback); the text
of library messages, which names parameters as data (`param`, `Text`) for a front end to spell its
own way; and the interruption by a signal, with the moments when it must wait
(`deferred_interrupts`)."""

from __future__ import annotations

import signal
import threading
from contextlib import contextmanager
from typing import Callable, Iterator, NamedTuple


class FivebarError(Exception):
    """A failure the user should see as one clear line; `exit_status` is what the CLI returns."""

    exit_status = 1


class InputError(FivebarError, ValueError):
    """Bad input (a file, a field, an option): `source: field: message`, exit status 2 (no
    source: a call's own parameter, `field: message`)."""

    exit_status = 2

    def __init__(self, source: str, field: str, message: str):
        self.source, self.field, self.message = source, field, message
        parts = [part for part in (source, field) if part]
        super().__init__(Text(*(piece for part in parts for piece in (part, ": ")), message))

    def __reduce__(self):  # (rebuilt from its three parts: it crosses from a worker process whole)
        return type(self), (self.source, self.field, self.message)


class Param(NamedTuple):
    """A library call's parameter that a message names, with the value it suggests (None: the
    name alone); written `name` or `name=value` (`depth=12`, `allow_serial=True`)."""

    name: str
    value: object = None

    def __str__(self) -> str:
        return f"`{self.name}`" if self.value is None else f"`{self.name}={self.value!r}`"


class Text(str):
    """Library text that names parameters: a str in the library's spelling ("try `depth=12`") that
    keeps the parameters as data (`parts`: its strings and `Param`s), so that a front end spells
    them its own way (`spelled`; the CLI: `cli/options.py`'s `as_flags`, "try --depth 12") and
    never rewrites the rest (a name, a path, a value). Joined with `+` to a str it stays a Text;
    an f-string or `str.join` gives a plain str in the library's spelling."""

    __slots__ = ("parts",)

    def __new__(cls, *parts: "str | Param") -> "Text":
        flat = tuple(q for p in parts for q in (p.parts if isinstance(p, Text) else (p,)) if q != "")
        text = super().__new__(cls, "".join(map(str, flat)))
        object.__setattr__(text, "parts", flat)
        return text

    def __setattr__(self, name, value):
        raise AttributeError("a Text is immutable")

    def __add__(self, other):
        return Text(self, other) if isinstance(other, str) else NotImplemented

    def __radd__(self, other):
        return Text(other, self) if isinstance(other, str) else NotImplemented

    def __reduce__(self):
        return Text, self.parts

    def spelled(self, spell: Callable[[Param], str]) -> str:
        """The text with each parameter written `spell(param)`, the rest as it is."""
        return "".join(spell(p) if isinstance(p, Param) else p for p in self.parts)


def param(name: str, value=None) -> Text:
    """A library call's parameter as messages name it: `name`, or `name=value` (`depth=12`,
    `allow_serial=True`, `procedure='exact'`), in backticks. The one way library messages name a
    parameter, never a command-line flag: a front end spells it with its own names (`Text`)."""
    return Text(Param(name, value))


class OutputError(FivebarError, OSError):
    """An output could not be written, exit status 1."""


class NotARegularFile(OutputError):
    """An output's path is a FIFO, a socket or a device, never replaced by a file
    (`io.files.refuse_special`); the command line adds how to write to standard output instead."""


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
