"""The `fivebar` command line: parse options, call one library function, write files, report.

Every command group lives in its own module of this package, imported when the command is asked
for (`LazyGroup`: `fivebar aspects` imports neither the atlas's engine nor the other commands;
`fivebar --help` imports them all, for their one-line help). Errors become one line on stderr and
an exit status: 2 for usage and configuration problems, 1 for anything else. Set FIVEBAR_DEBUG=1 to see
the traceback of an unexpected failure.
"""

from __future__ import annotations

import importlib
import os
import signal
import sys
import threading
import warnings

import click

from fivebar_cli.cli import HeldSignals
from fivebar_cli.cli.dispatch import ByKind
from fivebar_cli.version import __version__
from fivebar_cli.errors import INTERRUPTS, FivebarError, FivebarWarning, Interrupted

CONTEXT = {"help_option_names": ["-h", "--help"], "max_content_width": 100}


# name -> "module:attribute" in this package, or two of them: `ByKind(five-bar command, pose command)`
COMMANDS = {
    "jointspace": "spaces:jointspace", "workspace": "spaces:workspace",
    "aspects": ("aspects:aspects", "pose_aspects:pose_aspects"), "locate": ("locate:locate", "pose_locate:pose_locate"),
    "path": ("path:path", "pose_path:pose_path"), "dkp": "dkp:joints_dkp", "verify": "verify:verify_cmd",
    "atlas": "atlas:atlas", "kratio": "kratio:kratio", "refine": "refine:refine", "diff": "refine:diff",
    "tolerance": "tolerance:tolerance", "view": "view:view", "rpr3": "rpr3:rpr3", "reproduce": "reproduce:reproduce",
    "examples": "examples:examples",
}
RPR3_COMMANDS = ("rpr3_octree:pave_cmd", "rpr3_octree:verify_cmd", "dkp:dkp")  # `fivebar rpr3 pave | verify | dkp`


class LazyGroup(click.Group):
    """A group whose commands (`COMMANDS`) are imported on first use: a run imports its own command's
    module only. The commands are listed in the same (sorted) order, with the same help."""

    def list_commands(self, ctx) -> list[str]:
        return sorted({*self.commands, *COMMANDS})

    def get_command(self, ctx, name: str):
        if name not in self.commands and name in COMMANDS:
            self.add_command(_load(COMMANDS[name]), name)
        return self.commands.get(name)

    def resolve_command(self, ctx, args):
        """click's, with its "Did you mean ...?" for an unknown command drawn from every command's
        name, not only from those loaded so far (none, at that point of a run; click >= 8.4)."""
        try:
            return super().resolve_command(ctx, args)
        except click.UsageError as exc:
            name = getattr(exc, "command_name", None)  # (click's NoSuchCommand)
            if name is None:
                raise
            raise type(exc)(name, possibilities=self.list_commands(ctx), ctx=ctx) from None


def _load(spec):
    """The command `spec` names (`COMMANDS`); the rpr3 group with its commands from other modules."""
    if isinstance(spec, tuple):
        return ByKind(_load(spec[0]), _load(spec[1]))
    module, attribute = spec.split(":")
    command = getattr(_import(f"fivebar_cli.cli.{module}"), attribute)
    if module == "rpr3":
        for sub in RPR3_COMMANDS:
            command.add_command(_load(sub))
    return command


def _import(name: str):
    """Import a command's module with the interruptions held (as during start-up, cli/__init__.py: an
    exception raised by a handler while a module compiles can be lost), then acted on."""
    held = HeldSignals()
    ours = [sig for sig in INTERRUPTS if signal.getsignal(sig) is _on_signal]
    for sig in ours:
        signal.signal(sig, held)
    try:
        module = importlib.import_module(name)
    finally:
        for sig in ours:
            signal.signal(sig, _on_signal)
    if held:
        _on_signal(held[0], None)
    return module


@click.group(cls=LazyGroup, context_settings=CONTEXT)
@click.version_option(__version__, "-V", "--version", prog_name="fivebar")
def cli() -> None:
    """Certified joint space, workspace and aspects of planar parallel robots.

    \b
    Examples (each also in its command's help; -o out/...: outputs/<name>/ without it):
      fivebar jointspace configs/m1.yaml --depth 10 -o out/m1
      fivebar workspace configs/m2.yaml --depth 12 -o out/m2
      fivebar aspects configs/m1.yaml --depth 10 -o out/m1
      fivebar locate configs/m1.yaml --pose 4 5
      fivebar path configs/m1.yaml --pose 4 5 --pose 6 8 --working-mode ++
      fivebar atlas configs/atlas-small.yaml --workers 2 -o out/atlas
      fivebar kratio configs/m1.yaml configs/m2.yaml --depths 5-10 -o out
      fivebar rpr3 synthesize configs/rpr3-table1.yaml
      fivebar verify configs/rrr3-symmetric.yaml --working-mode +-+ -o out/rrr3-symmetric  # exit 1: a singular pose
      fivebar view out/m1
      fivebar reproduce -o out/check --no-plot

    A CONFIG is a mechanism file (YAML), or the name of a shipped example where no such file
    exists (`fivebar examples` lists them): `fivebar aspects m1 --depth 10` from any folder.
    """


SIGNAL_WORDS = {signal.SIGINT: "interrupted", signal.SIGTERM: "terminated", signal.SIGHUP: "hung up"}


_received: list[int] = []  # the interruptions of this run, in order (`main` clears it)


def _on_signal(signum, frame):
    """Ctrl-C, SIGTERM, SIGHUP: stop the run where it is (the atomic writers clean up on the way out).
    Recorded too: a library that calls back into Python from C++ (matplotlib drawing a path) may
    clear the Interrupted and raise its own error instead; `_run` still reports the interruption."""
    _received.append(signum)
    raise _interruption(signum)


def _interruption(signum: int) -> Interrupted:
    return Interrupted(f"{SIGNAL_WORDS[signum]} (no output was left half-written)", signum)


def install_signal_handlers(held=None) -> dict:
    """`_on_signal` for every interruption whose handler is still the default one or `held`, the
    start-up handler of cli/__init__.py (a process started with a signal ignored, as `nohup` does,
    keeps ignoring it); returns the previous handlers."""
    previous = {}
    for sig in INTERRUPTS:
        handler = signal.getsignal(sig)
        ours = held is not None and handler is held
        if ours or handler is signal.default_int_handler or handler == signal.SIG_DFL:
            previous[sig] = handler
            signal.signal(sig, _on_signal)
    return previous


def _unraisable(hook):
    """An interruption raised inside a finaliser (`__del__`, a weakref callback) is swallowed by
    Python with an "Exception ignored ... Traceback" block: instead, say nothing and send the signal
    again a moment later, from another thread, so that it stops the run at the next ordinary line of
    the main thread (sent from here, its handler would raise inside this hook). Other cases go to
    `hook`."""
    def unraisable(info):
        if isinstance(info.exc_value, Interrupted):
            threading.Timer(0.01, _send_again, (info.exc_value.signum,)).start()
        elif not isinstance(info.exc_value, KeyboardInterrupt):
            hook(info)
    return unraisable


def _quiet(info) -> None:
    """The interpreter's teardown after an interruption, its one line printed: an object the
    interruption left half-built may fail in its finaliser (pyparsing's `Forward.__del__` reads an
    attribute its interrupted `__init__` never set), which Python would print as "Exception
    ignored ... Traceback" after the line. The run's status stands; nothing more is said."""


def _send_again(signum: int) -> None:
    """The signal again, if the command is still running under our handlers: once it has finished
    (handlers ignored) or the interpreter is shutting down (handlers back to the default, which
    would kill the process without a word), the run's status stands."""
    if signal.getsignal(signum) is _on_signal:
        os.kill(os.getpid(), signum)


def _show_warning(previous):
    """FivebarWarning as one line, `fivebar: warning: ...`; other warnings as before."""
    def show(message, category, filename, lineno, file=None, line=None):
        if issubclass(category, FivebarWarning):
            click.echo(f"fivebar: warning: {' '.join(str(message).split())}", err=True)
        else:
            previous(message, category, filename, lineno, file, line)
    return show


def main(argv: list[str] | None = None, held: list[int] | None = None) -> None:
    """Entry point of the console script: run the CLI and map every error to one line and an exit
    status (docs/formats.md, "Exit statuses"). With `argv` None (the console script), signals that
    arrive once the command has finished are ignored: the run completed, its status stands. `held`:
    the signals that arrived while the commands were being imported (cli/__init__.py)."""
    _received.clear()
    previous = install_signal_handlers(held)
    hook = sys.unraisablehook
    sys.unraisablehook = _unraisable(hook)
    try:
        if held:
            _on_signal(held[0], None)
        with warnings.catch_warnings():
            warnings.simplefilter("ignore", RuntimeWarning)  # numpy noise must not break the one-line promise
            warnings.simplefilter("always", FivebarWarning)
            warnings.showwarning = _show_warning(warnings.showwarning)
            status = _run(argv)
    except Interrupted as exc:  # between the command's end and here
        status = _fail(exc, exc.exit_status)
    finally:
        for sig in INTERRUPTS:
            if argv is None and signal.getsignal(sig) is _on_signal:
                signal.signal(sig, signal.SIG_IGN)  # the interpreter's teardown is not interrupted
        sys.unraisablehook = _quiet if argv is None and _received else hook
    if argv is not None:
        for sig, handler in previous.items():
            if sig != signal.SIGINT:  # run_cli (tests) restores SIGINT itself
                signal.signal(sig, handler)
    sys.exit(status)


def _fail(exc: BaseException, status: int, prefix: str = "fivebar: error: ") -> int:
    click.echo(f"{prefix}{' '.join(str(exc).split())}", err=True)
    return status


def _run(argv) -> int:
    """The command's exit status; every failure printed as one line."""
    try:
        status = cli.main(args=argv, prog_name="fivebar", standalone_mode=False)
    except click.exceptions.NoArgsIsHelpError as exc:  # `fivebar rpr3` alone: show the help
        click.echo(exc.ctx.get_help() if exc.ctx else str(exc))
        return 0
    except click.exceptions.UsageError as exc:
        prefix = exc.ctx.command_path if exc.ctx else "fivebar"
        return _fail(exc.format_message(), 2, f"{prefix}: error: ")
    except click.exceptions.Exit as exc:
        return exc.exit_code
    except click.exceptions.Abort:
        return _fail("aborted", 1, "fivebar: ")
    except (FivebarError, Interrupted) as exc:  # Interrupted: 130 for Ctrl-C, 143 for SIGTERM, 129 for SIGHUP
        return _fail(exc, exc.exit_status)
    except KeyboardInterrupt:
        return _fail("interrupted (no output was left half-written)", 130)
    except BrokenPipeError:  # `fivebar view DIR -o - | head`: the reader went away
        devnull = os.open(os.devnull, os.O_WRONLY)
        os.dup2(devnull, sys.stdout.fileno())  # so that flushing stdout at exit does not fail again
        return 141  # 128 + SIGPIPE, silently, as a process killed by SIGPIPE
    except MemoryError:
        return _fail("out of memory (try a smaller --depth)", 1)
    except Exception as exc:  # noqa: BLE001 - the promise is: no traceback, one line, status 1
        if _received:  # an interruption a library turned into an error of its own: still the interruption
            interrupted = _interruption(_received[0])
            return _fail(interrupted, interrupted.exit_status)
        if os.environ.get("FIVEBAR_DEBUG"):
            raise
        return _fail(f"{type(exc).__name__}: {exc}", 1, "fivebar: internal error: ")
    return status if isinstance(status, int) else 0
