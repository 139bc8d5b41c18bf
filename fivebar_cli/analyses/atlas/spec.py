"""An atlas spec (`type: fivebar-atlas`): which five-bar designs to sweep, at which depth.

A spec is not a mechanism kind: it names a grid of five-bars, each length fixed (a number) or
swept (`[from, to, steps]`, evenly spaced, both ends included), and optionally a tolerance T
(robust metrics of every length widened to [L - T, L + T]); every value is rounded to the 10
significant digits of the CSV format, so `atlas.csv` names each design exactly. Designs are numbered in grid order,
L0 slowest, L4 fastest. Read with the strict YAML and field checks of `io.schema`: every problem is
one `file: field: message` line (exit status 2). Schema: docs/formats.md, "Atlas specs".
"""

from __future__ import annotations

from dataclasses import dataclass
from math import prod
from pathlib import Path

from fivebar_cli.analyses.limits import MAX_ASPECT_DEPTH
from fivebar_cli.io import schema
from fivebar_cli.io.files import FLOAT_FORMAT
from fivebar_cli.io.schema import ConfigError
from fivebar_cli.mechanisms.fivebar import constraints
from fivebar_cli.mechanisms.fivebar.constraints import NO_CONSTRAINTS, Constraints
from fivebar_cli.mechanisms.fivebar.model import LENGTHS

KIND = "fivebar-atlas"
DEFAULT_DEPTH = 10  # as `fivebar aspects`
MAX_DEPTH = MAX_ASPECT_DEPTH  # as `fivebar aspects`
MAX_STEPS = 100_000
MAX_DESIGNS = 10_000_000
MAX_BATCH = 10_000


@dataclass(frozen=True)
class AtlasSpec:
    """A grid of five-bars: `grid[k]` holds the values of length k (one value when fixed)."""

    name: str
    grid: tuple[tuple[float, ...], ...]
    depth: int = DEFAULT_DEPTH
    tolerance: float = 0.0
    batch: int | None = None  # designs per task; None: `default_batch(size)`
    constraints: Constraints = NO_CONSTRAINTS  # limits, obstacles, clearance of every design

    @property
    def shape(self) -> tuple[int, ...]:
        return tuple(len(v) for v in self.grid)

    @property
    def size(self) -> int:
        return prod(self.shape)

    @property
    def swept(self) -> tuple[str, ...]:
        """The names of the swept lengths, in L0..L4 order."""
        return tuple(k for k, v in zip(LENGTHS, self.grid) if len(v) > 1)

    @property
    def batch_size(self) -> int:
        return self.batch if self.batch is not None else default_batch(self.size)

    def design(self, index: int) -> tuple[float, ...]:
        """The lengths (L0..L4) of design `index` (grid order: L0 slowest, L4 fastest)."""
        if not 0 <= index < self.size:
            raise IndexError(index)
        values = []
        for axis in reversed(self.grid):
            index, k = divmod(index, len(axis))
            values.append(axis[k])
        return tuple(reversed(values))


def default_batch(size: int) -> int:
    """Designs per task: about 64 tasks or more, 1 to 100 designs each (tens to hundreds of tasks
    keep every worker busy; at most 100 designs keeps a lost task cheap and the scheduler idle)."""
    return max(1, min(100, size // 64))


def exact_in_csv(value: float) -> float:
    """`value` rounded to the CSV's 10 significant digits, so that a row of `atlas.csv` names its
    design exactly (0.6000000000000001 -> 0.6)."""
    return float(FLOAT_FORMAT % value)


def sweep_values(lo: float, hi: float, steps: int) -> tuple[float, ...]:
    """`steps` evenly spaced values from `lo` to `hi`, each rounded by `exact_in_csv`."""
    return tuple(exact_in_csv(lo + (hi - lo) * k / (steps - 1)) for k in range(steps))


def read_spec(path: str | Path) -> AtlasSpec:
    source = str(path)
    return parse_spec(schema.read_yaml(path, source), source)


def parse_spec(data: dict, source: str) -> AtlasSpec:
    keys = {"name", "type", "lengths", "depth", "tolerance", "batch", *constraints.KEYS}
    kind = data.get("type")
    if kind is None:
        raise ConfigError(source, "type", f"missing (an atlas spec has 'type: {KIND}')")
    if kind != KIND:
        raise ConfigError(source, "type", f"an atlas spec has 'type: {KIND}', got {schema.short(kind)}")
    schema.check_keys(data, keys, {"name", "type", "lengths"}, source)
    name = schema.name_field(data, source)
    lengths = schema.mapping(data, "lengths", source)
    schema.check_keys(lengths, set(LENGTHS), set(LENGTHS), source, "lengths.")
    grid = tuple(_length_values(lengths[k], source, f"lengths.{k}") for k in LENGTHS)
    size = prod(len(v) for v in grid)
    if size > MAX_DESIGNS:
        raise ConfigError(source, "lengths", f"{size} designs: at most {MAX_DESIGNS} in one atlas")
    depth = schema.integer(data.get("depth", DEFAULT_DEPTH), source, "depth", 0, MAX_DEPTH)
    tolerance = check_tolerance(data.get("tolerance", 0.0), grid, source, "tolerance")
    batch = schema.integer(data["batch"], source, "batch", 1, MAX_BATCH) if "batch" in data else None
    return AtlasSpec(name, grid, depth, tolerance, batch, constraints.parse(data, source))


def check_tolerance(tolerance, grid, source: str, field: str) -> float:
    """The tolerance, when it is a number >= 0 (`schema.number`: the spec's `tolerance:` and the
    library's argument alike) and every length of the grid stays positive once widened by it."""
    tolerance = schema.number(tolerance, source, field, nonnegative=True)
    shortest = min(min(values) for values in grid)
    if tolerance >= shortest:
        raise ConfigError(source, field, f"{tolerance!r} would make the shortest length ({shortest!r}) reach "
                                         f"{shortest - tolerance!r}: lengths must stay positive")
    return tolerance


def _length_values(value, source: str, field: str) -> tuple[float, ...]:
    """A number (fixed) or `[from, to, steps]` (swept), every value positive."""
    if not isinstance(value, list):
        if isinstance(value, dict):
            raise ConfigError(source, field, "expected a number or [from, to, steps], got a mapping")
        return (exact_in_csv(schema.number(value, source, field, positive=True)),)
    if len(value) == 2:
        raise ConfigError(source, field, "expected a number or [from, to, steps], got [lo, hi]: an atlas sweeps "
                                         "exact lengths; give 'tolerance: T' for robust metrics of [L - T, L + T]")
    if len(value) != 3:
        raise ConfigError(source, field, f"expected a number or [from, to, steps], got a list of {len(value)} items")
    lo = schema.number(value[0], source, f"{field}[0]", positive=True)
    hi = schema.number(value[1], source, f"{field}[1]", positive=True)
    steps = schema.integer(value[2], source, f"{field}[2]", 2, MAX_STEPS)
    if not lo < hi:
        raise ConfigError(source, field, f"from must be less than to, got [{schema.short(value[0])}, "
                                         f"{schema.short(value[1])}]")
    return sweep_values(lo, hi, steps)
