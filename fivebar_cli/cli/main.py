"""The `fivebar` command line: parse options, call one library function, write files, report.

Every command group lives in its own module of this package and is attached here, at import, so
`from fivebar_cli.cli import cli` has every command. Errors become one line on stderr and an exit
status: 2 for usage and configuration problems, 1 for anything else. Set FIVEBAR_DEBUG=1 to see
the traceback of an unexpected failure.
"""

from __future__ import annotations

import os
import signal
import sys
import threading
import warnings

import click

from fivebar_cli.version import __version__
from fivebar_cli.cli.aspects import aspects
from fivebar_cli.cli.atlas import atlas
from fivebar_cli.cli.dispatch import ByKind
from fivebar_cli.cli.examples import examples
from fivebar_cli.cli.kratio import kratio
from fivebar_cli.cli.locate import locate
from fivebar_cli.cli.path import path
from fivebar_cli.cli.dkp import dkp, joints_dkp
from fivebar_cli.cli.pose_aspects import pose_aspects
from fivebar_cli.cli.pose_locate import pose_locate
from fivebar_cli.cli.pose_path import pose_path
from fivebar_cli.cli.reproduce import reproduce
from fivebar_cli.cli.rpr3 import rpr3
from fivebar_cli.cli.rpr3_octree import pave_cmd as rpr3_pave
from fivebar_cli.cli.rpr3_octree import verify_cmd as rpr3_verify
from fivebar_cli.cli.refine import diff, refine
from fivebar_cli.cli.spaces import jointspace, workspace
from fivebar_cli.cli.tolerance import tolerance
from fivebar_cli.cli.verify import verify_cmd
from fivebar_cli.cli.view import view
from fivebar_cli.errors import INTERRUPTS, FivebarError, FivebarWarning, Interrupted

CONTEXT = {"help_option_names": ["-h", "--help"], "max_content_width": 100}


@click.group(context_settings=CONTEXT)
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
    """


for command in (rpr3_pave, rpr3_verify, dkp):  # dkp: `fivebar dkp` under its 3-RPR name, with --legs
    rpr3.add_command(command)
for command in (jointspace, workspace, ByKind(aspects, pose_aspects), ByKind(locate, pose_locate),
                ByKind(path, pose_path), joints_dkp, verify_cmd, atlas, kratio, refine, diff, tolerance, view, rpr3,
                reproduce, examples):
    cli.add_command(command)


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
        sys.unraisablehook = hook
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
