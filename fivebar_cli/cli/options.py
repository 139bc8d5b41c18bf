"""Pieces shared by the click commands: common options, progress bars, reporting, figures."""

from __future__ import annotations

import math
import sys
import time
from contextlib import contextmanager
from pathlib import Path
from typing import Iterator

import click

from fivebar_cli.io.files import ensure_dir, save_figure
from fivebar_cli.io.layout import output_dir

MAX_DEPTH = 20  # one 2-D paving: beyond this the boundary cells alone need several GiB
MAX_ASPECT_DEPTH = 16  # aspects pave six regions and label them: about 0.2 GiB at 14, x4 per two levels

CONFIG = click.Path(path_type=Path, dir_okay=False)


def common_options(func):
    """`-o/--out DIR`, `--no-plot`, `--quiet`: the options every analysis command takes."""
    func = click.option("--quiet", "-q", is_flag=True, help="Print nothing but errors; no progress bar.")(func)
    func = click.option("--no-plot", is_flag=True, help="Skip the PNG figures (faster).")(func)
    func = click.option(
        "--out", "-o", "out", type=click.Path(file_okay=False, path_type=Path), default=None,
        help="Output folder [default: outputs/<config name>/].",
    )(func)
    return func


def depth_option(default: int = 10, limit: int = MAX_DEPTH):
    return click.option("--depth", "-d", type=click.IntRange(0, limit), default=default, show_default=True,
                        help=f"Maximum depth d of the tree (cells are root/2^d wide; 0..{limit}).")


def tolerance_option(func):
    """`--tolerance T`: every link length widened to [L - T, L + T] (manufacturing tolerances)."""
    return click.option(
        "--tolerance", type=click.FloatRange(0, None), default=0.0, show_default=True,
        help="Widen every link length to [L - T, L + T]: black then means valid for every length in "
             "the box (robust), the complement valid for none (impossible).",
    )(func)


def with_tolerance(m, tolerance: float, source):
    """The mechanism with its lengths widened by `tolerance` (0: unchanged)."""
    if tolerance == 0:
        return m
    if not hasattr(m, "widened"):
        from fivebar_cli.io.schema import ConfigError

        raise ConfigError(str(source), "--tolerance", f"a {m.kind} has no interval lengths")
    return m.widened(tolerance, str(source))


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


def figure(make, path: Path) -> Path:
    """Draw a figure with `make()`, save it atomically as PNG, free it."""
    from fivebar_cli.plotting import pyplot

    fig = make()
    try:
        return save_figure(fig, path)
    finally:
        pyplot().close(fig)


@contextmanager
def progress(quiet: bool, length: int, label: str, unit: str | None = None) -> Iterator:
    """A progress bar on stderr, silent with --quiet or when stderr is not a terminal; with `unit`,
    it also shows the count done and the rate (`12.5 designs/s`).

    Yields a callable `advance(n=1)`.
    """
    if quiet or not sys.stderr.isatty():
        yield lambda n=1: None
        return
    start, done = time.monotonic(), [0]

    def rate(_item) -> str | None:
        elapsed = time.monotonic() - start
        return f"{done[0] / elapsed:.3g} {unit}/s" if unit and done[0] and elapsed > 0 else None

    with click.progressbar(length=length, label=label, file=sys.stderr, show_eta=True, show_pos=unit is not None,
                           item_show_func=rate) as bar:
        def advance(n: int = 1) -> None:
            done[0] += n
            bar.update(n, n)

        yield advance


# ---------------------------------------------------------------- command-line numbers and angles

NUMBER_LIMIT = 1e50  # command-line numbers are finite and at most this in magnitude, as numbers in YAML files
ANGLE_LIMIT = 1e6  # radians: a motion's exact check counts whole turns with 2 pi to 40 digits (formats.md)


class Number(click.ParamType):
    """A finite number of magnitude at most NUMBER_LIMIT (`nan`, `inf`, `1e300` are refused)."""

    name = "number"

    def convert(self, value, param, ctx):
        try:
            number = float(value)
        except (TypeError, ValueError):
            self.fail(f"{value!r} is not a number", param, ctx)
        if not math.isfinite(number) or abs(number) > NUMBER_LIMIT:
            self.fail(f"{value!r} is not a finite number of magnitude at most {NUMBER_LIMIT:g}", param, ctx)
        return number


class Degrees(float):
    """A joint value given in degrees on the command line (`30deg`), held in radians."""


class JointValue(Number):
    """A joint value: a number (radians for an angle, a length for a prismatic leg), or an angle in
    degrees with the suffix `deg` (`30deg`, `-45.5deg`), converted to radians (`Degrees`)."""

    name = "number[deg]"

    def convert(self, value, param, ctx):
        text = str(value).strip()
        if text.lower().endswith("deg"):
            return Degrees(math.radians(super().convert(text[:-3], param, ctx)))
        return super().convert(value, param, ctx)


NUMBER, JOINT = Number(), JointValue()


def check_joints(m, joints, source) -> None:
    """Joint values given in degrees only for angles; angles at most ANGLE_LIMIT rad (InputError)."""
    from fivebar_cli.errors import InputError

    axes = m.spaces()["jointspace"].axes
    for values in joints:
        for axis, value in zip(axes, values):
            if axis.unit != "rad" and isinstance(value, Degrees):
                what = "a length" if not axis.unit else f"in {axis.unit}"
                raise InputError(str(source), "--joints", f"{axis.name} is {what}, not an angle: drop the 'deg' suffix")
            if axis.unit == "rad" and abs(value) > ANGLE_LIMIT:
                raise InputError(str(source), "--joints", f"{axis.name} = {value:g} rad: angles must be at most "
                                 f"{ANGLE_LIMIT:g} rad ({math.degrees(ANGLE_LIMIT):g} deg) in magnitude")
