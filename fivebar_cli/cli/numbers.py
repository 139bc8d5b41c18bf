"""Numbers of the command line: finite (`Number`), and joint values in radians or in degrees with
the suffix deg (`JointValue`: `30deg`), checked against the joint axes (`check_joints`)."""

from __future__ import annotations

import math

import click

NUMBER_LIMIT = 1e50  # command-line numbers are finite and at most this in magnitude, as numbers in YAML files
ANGLE_LIMIT = 1e6  # radians: a motion's exact check counts whole turns with 2 pi to 40 digits (formats.md)


class Number(click.ParamType):
    """A finite number of magnitude at most NUMBER_LIMIT (`nan`, `inf`, `1e300` are refused), at
    least `lo` when given: every number of the command line."""

    name = "number"

    def __init__(self, lo: float | None = None):
        self.lo = lo

    def convert(self, value, param, ctx):
        try:
            number = float(value)
        except (TypeError, ValueError):
            self.fail(f"{value!r} is not a number", param, ctx)
        if not math.isfinite(number) or abs(number) > NUMBER_LIMIT:
            self.fail(f"{value!r} is not a finite number of magnitude at most {NUMBER_LIMIT:g}", param, ctx)
        if self.lo is not None and number < self.lo:
            self.fail(f"{value!r} is not >= {self.lo:g}", param, ctx)
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
