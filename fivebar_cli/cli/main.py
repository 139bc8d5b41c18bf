"""The `fivebar` command line: parse options, call one library function, write files, report.

Every command group lives in its own module of this package and is attached here, at import, so
`from fivebar_cli.cli import cli` has every command. Errors become one line on stderr and an exit
status: 2 for usage and configuration problems, 1 for anything else. Set FIVEBAR_DEBUG=1 to see
the traceback of an unexpected failure.
"""

from __future__ import annotations

import os
import sys

import click

from fivebar_cli import __version__
from fivebar_cli.cli.aspects import aspects, locate
from fivebar_cli.cli.atlas import atlas
from fivebar_cli.cli.dispatch import ByKind
from fivebar_cli.cli.kratio import kratio
from fivebar_cli.cli.path import path
from fivebar_cli.cli.pose_aspects import dkp, joints_dkp, pose_aspects, pose_locate, pose_path
from fivebar_cli.cli.reproduce import reproduce
from fivebar_cli.cli.rpr3 import rpr3
from fivebar_cli.cli.spaces import diff, jointspace, refine, workspace
from fivebar_cli.cli.tolerance import tolerance
from fivebar_cli.cli.verify import verify_cmd
from fivebar_cli.cli.view import view
from fivebar_cli.errors import FivebarError, Interrupted

CONTEXT = {"help_option_names": ["-h", "--help"], "max_content_width": 100}


@click.group(context_settings=CONTEXT)
@click.version_option(__version__, "-V", "--version", prog_name="fivebar")
def cli() -> None:
    """Certified joint space, workspace and aspects of planar parallel robots.

    \b
    Examples:
      fivebar jointspace configs/m1.yaml --depth 10
      fivebar workspace configs/m2.yaml --depth 12 -o out/m2
      fivebar aspects configs/m1.yaml --depth 10
      fivebar locate configs/m1.yaml --pose 4 5 --pose 6 -3
      fivebar path configs/m1.yaml --pose 4 5 --pose 6 8 --working-mode ++
      fivebar atlas configs/atlas-l1-l3.yaml --workers 2
      fivebar kratio configs/m1.yaml configs/m2.yaml --depths 5-10
      fivebar rpr3 synthesize configs/rpr3-table1.yaml
      fivebar dkp configs/rrr3-symmetric.yaml --joints 30 150 -90 --depth 4
      fivebar verify configs/rrr3-symmetric.yaml --working-mode +-+ --depth 6
      fivebar view outputs/M1
      fivebar reproduce
    """


rpr3.add_command(dkp)  # `fivebar dkp` under its 3-RPR name, with --legs
for command in (jointspace, workspace, ByKind(aspects, pose_aspects), ByKind(locate, pose_locate),
                ByKind(path, pose_path), joints_dkp, verify_cmd, atlas, kratio, refine, diff, tolerance, view, rpr3,
                reproduce):
    cli.add_command(command)


def _on_sigint(signum, frame):
    raise Interrupted("interrupted (no output was left half-written)")


def _on_sigterm(signum, frame):
    raise Interrupted("terminated (no output was left half-written)")


def main(argv: list[str] | None = None) -> None:
    """Entry point of the console script: run the CLI and map every error to one line."""
    import signal
    import warnings

    if signal.getsignal(signal.SIGINT) is signal.default_int_handler:
        signal.signal(signal.SIGINT, _on_sigint)
    if signal.getsignal(signal.SIGTERM) == signal.SIG_DFL:
        signal.signal(signal.SIGTERM, _on_sigterm)
    warnings.simplefilter("ignore", RuntimeWarning)  # numpy noise must not break the one-line promise
    try:
        status = cli.main(args=argv, prog_name="fivebar", standalone_mode=False)
    except click.exceptions.NoArgsIsHelpError as exc:  # `fivebar rpr3` alone: show the help
        click.echo(exc.ctx.get_help() if exc.ctx else str(exc))
        sys.exit(0)
    except click.exceptions.UsageError as exc:
        prefix = exc.ctx.command_path if exc.ctx else "fivebar"
        click.echo(f"{prefix}: error: {' '.join(exc.format_message().split())}", err=True)
        sys.exit(2)
    except click.exceptions.Exit as exc:
        sys.exit(exc.exit_code)
    except click.exceptions.Abort:
        click.echo("fivebar: aborted", err=True)
        sys.exit(1)
    except FivebarError as exc:
        click.echo(f"fivebar: error: {' '.join(str(exc).split())}", err=True)
        sys.exit(exc.exit_status)
    except KeyboardInterrupt:
        click.echo("fivebar: interrupted (no output was left half-written)", err=True)
        sys.exit(1)
    except MemoryError:
        click.echo("fivebar: error: out of memory (try a smaller --depth)", err=True)
        sys.exit(1)
    except Exception as exc:  # noqa: BLE001 - the promise is: no traceback, one line, status 1
        if os.environ.get("FIVEBAR_DEBUG"):
            raise
        click.echo(f"fivebar: internal error: {type(exc).__name__}: {' '.join(str(exc).split())}", err=True)
        sys.exit(1)
    sys.exit(status if isinstance(status, int) else 0)
