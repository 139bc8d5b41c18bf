"""Pieces shared by the click commands: common options, progress bars and result reporting."""

from __future__ import annotations

import sys
from contextlib import contextmanager
from pathlib import Path
from typing import Iterator

import click

from fivebar_cli.outputs import ensure_dir, output_dir


def common_options(func):
    """`-o/--out DIR`, `--no-plot`, `--quiet`: the options every analysis command takes."""
    func = click.option("--quiet", "-q", is_flag=True, help="Print nothing but errors; no progress bar.")(func)
    func = click.option("--no-plot", is_flag=True, help="Skip the PNG figures (faster).")(func)
    func = click.option(
        "--out", "-o", "out", type=click.Path(file_okay=False, path_type=Path), default=None,
        help="Output folder [default: outputs/<config name>/].",
    )(func)
    return func


def prepare_out(out: Path | None, name: str) -> Path:
    """Resolve and create the output folder (outputs/<name>/ unless --out is given)."""
    return ensure_dir(output_dir(out, name))


def report(quiet: bool, message: str) -> None:
    """A line of the run summary on stdout (silent with --quiet)."""
    if not quiet:
        click.echo(message)


def wrote(quiet: bool, paths) -> None:
    """List written files, relative where possible (stable and short)."""
    for path in paths:
        report(quiet, f"  wrote {path}")


@contextmanager
def progress(quiet: bool, length: int, label: str) -> Iterator:
    """A progress bar on stderr, silent with --quiet or when stderr is not a terminal.

    Yields a callable `advance(n=1)`.
    """
    if quiet or not sys.stderr.isatty():
        yield lambda n=1: None
        return
    with click.progressbar(length=length, label=label, file=sys.stderr, show_eta=True) as bar:
        yield bar.update
