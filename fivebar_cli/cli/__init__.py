"""The command line: a thin layer of click commands, one module per command group, over library calls.

`main` (the console script) takes Ctrl-C over before it imports anything else (the commands, click,
numpy, ...), so that a Ctrl-C during start-up is one line and exit status 130 too, never a traceback.
"""

from __future__ import annotations

import signal

__all__ = ["cli", "main"]

def main(argv: list[str] | None = None) -> None:
    """The console script `fivebar`: `fivebar_cli.cli.main.main` once the commands are imported."""
    held = None
    if signal.getsignal(signal.SIGINT) is signal.default_int_handler:
        held = HeldSignals()
        signal.signal(signal.SIGINT, held)  # until main.main installs the handlers
    _commands().main(argv, held)


class HeldSignals(list):
    """The start-up handler: notes the signal, raises nothing. An exception raised by a handler
    while a module is being compiled can be lost (the import goes on and the run completes), and a
    caught KeyboardInterrupt still made CPython kill the process with SIGINT at exit (status -2,
    not 130); `main.main` acts on a held signal as soon as its own handlers are in place."""

    def __call__(self, signum, frame) -> None:
        self.append(signum)


def _commands():
    """The module `fivebar_cli.cli.main` (importing it binds the package's name `main` to the
    module: the name is given back to the function above)."""
    import importlib

    module = importlib.import_module("fivebar_cli.cli.main")
    globals()["main"] = _entry
    return module


_entry = main


def __getattr__(name: str):
    """`from fivebar_cli.cli import cli`: the click group, imported on first use."""
    if name == "cli":
        return _commands().cli
    raise AttributeError(name)
