"""The command line: a thin layer of click commands, one module per command group, over library calls.

`main` (the console script) takes Ctrl-C over before it imports anything else (the commands, click,
numpy, ...), so that a Ctrl-C during start-up is one line and exit status 130 too, never a traceback.
"""

from __future__ import annotations

import signal

__all__ = ["cli", "main"]

INTERRUPTED = "fivebar: error: interrupted (no output was left half-written)\n"


def main(argv: list[str] | None = None) -> None:
    """The console script `fivebar`: `fivebar_cli.cli.main.main` once the commands are imported."""
    default = signal.getsignal(signal.SIGINT) is signal.default_int_handler
    if default:
        signal.signal(signal.SIGINT, _early)  # until main.main installs the handlers
    try:
        module = _commands()
    except KeyboardInterrupt:
        import sys

        sys.stderr.write(INTERRUPTED)
        sys.exit(130)
    if default:
        signal.signal(signal.SIGINT, signal.default_int_handler)
    module.main(argv)


def _early(signum, frame):
    raise KeyboardInterrupt


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
