"""Joint limits and obstacles of any kind: the YAML keys `limits`, `obstacles`, `clearance`, their
one-line description in `.qt` headers, and which constraints configurations violate, given the
kind's angles and links (the five-bar's `fivebar/constraints.py`, the 3-RRR's `rrr3/constraints.py`).

Limits are closed arcs [lo, hi] (degrees, lo < hi, within [-180, 180]) of named angles, each a
signed angle atan2(u x v, u . v) from a vector u to a vector v; an angle satisfies [lo, hi] when
some turn of it lies in [lo, hi]. Obstacles are discs and simple polygons; a configuration collides
when one of its links (segments) comes within `clearance` of one (touching included). The kind
says which angles may be limited and which segments are links.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import TYPE_CHECKING, Mapping

import numpy as np

from fivebar_cli.io import schema

if TYPE_CHECKING:  # (the obstacles' module is imported where a file has obstacles: not by every analysis)
    from fivebar_cli.numerics.obstacles import Disc, Polygon

MAX_OBSTACLES = 64
MAX_VERTICES = 64
KEYS = ("limits", "obstacles", "clearance")  # the mechanism file's keys of this module


@dataclass(frozen=True)
class Limit:
    """The closed arc [lo, hi] (degrees) an angle must stay in."""

    name: str
    lo: float
    hi: float

    @property
    def full_turn(self) -> bool:
        """A limit of a whole turn restricts nothing."""
        return self.hi - self.lo >= 360.0

    @property
    def radians(self) -> tuple[float, float]:
        return math.radians(self.lo), math.radians(self.hi)


@dataclass(frozen=True)
class Constraints:
    """Limits (in LIMIT_NAMES order), obstacles and the clearance links keep from them."""

    limits: tuple[Limit, ...] = ()
    obstacles: tuple[Disc | Polygon, ...] = ()
    clearance: float = 0.0

    def __bool__(self) -> bool:
        return bool(self.limits or self.obstacles)

    def limit(self, name: str) -> Limit | None:
        return next((lim for lim in self.limits if lim.name == name), None)

    def only(self, index: int) -> "Constraints":
        """The constraint number `index` of `labels()` alone (with the clearance for an obstacle)."""
        if index < len(self.limits):
            return Constraints((self.limits[index],))
        return Constraints((), (self.obstacles[index - len(self.limits)],), self.clearance)

    def labels(self) -> list[str]:
        """One label per constraint, as messages and `locate` name them: 'B1 limit', 'obstacle 2'."""
        obstacles = [f"obstacle {k}" for k in range(1, len(self.obstacles) + 1)]
        return [f"{lim.name} limit" for lim in self.limits] + obstacles

    def fields(self) -> list[str]:
        """The YAML field of each constraint (for error messages), in `labels()` order."""
        return [f"limits.{lim.name}" for lim in self.limits] + [f"obstacles[{k}]" for k in range(len(self.obstacles))]

    def extent(self) -> float:
        """The largest coordinate an obstacle reaches (for the margins of the box tests)."""
        return max((o.extent() for o in self.obstacles), default=0.0) + self.clearance

    # -- the `.qt` description

    def words(self) -> str:
        """The description's words (empty without constraints): `P=[-90.0,90.0]`,
        `obstacle1=disc:4.5,0.0,1.0`, `obstacle2=polygon:10.0,-2.0,12.0,-2.0,...`, `clearance=0.5`."""
        out = [f" {lim.name}=[{lim.lo!r},{lim.hi!r}]" for lim in self.limits]
        for k, o in enumerate(self.obstacles, start=1):
            numbers = (*o.centre, o.radius) if o.kind == "disc" else [v for p in o.vertices for v in p]
            out.append(f" obstacle{k}={o.kind}:" + ",".join(repr(float(v)) for v in numbers))
        if self.clearance:
            out.append(f" clearance={self.clearance!r}")
        return "".join(out)


NO_CONSTRAINTS = Constraints()



def description_data(fields: Mapping[str, str], source: str, names: tuple[str, ...]) -> dict:
    """The YAML mapping (`limits`, `obstacles`, `clearance`) of a description's constraint words
    (`names`: the kind's limited angles)."""
    data: dict = {}

    def numbers(key: str, text: str) -> list[float]:
        try:
            return [float(v) for v in text.split(",")]
        except ValueError:
            raise schema.ConfigError(source, "mechanism", f"bad value {key}={text!r}") from None

    obstacles = {}
    for key, text in fields.items():
        if key in names:
            if not (text.startswith("[") and text.endswith("]")):
                raise schema.ConfigError(source, "mechanism", f"bad value {key}={text!r}")
            data.setdefault("limits", {})[key] = numbers(key, text[1:-1])
        elif key == "clearance":
            values = numbers(key, text)
            if len(values) != 1:
                raise schema.ConfigError(source, "mechanism", f"bad value {key}={text!r}")
            data["clearance"] = values[0]
        elif key.startswith("obstacle") and key[8:].isdigit():
            kind, sep, rest = text.partition(":")
            values = numbers(key, rest) if sep else []
            if kind == "disc" and len(values) == 3:
                obstacles[int(key[8:])] = {"disc": {"centre": values[:2], "radius": values[2]}}
            elif kind == "polygon" and values and len(values) % 2 == 0:
                obstacles[int(key[8:])] = {"polygon": [values[i:i + 2] for i in range(0, len(values), 2)]}
            else:
                raise schema.ConfigError(source, "mechanism", f"bad value {key}={text!r}")
        else:
            raise schema.ConfigError(source, "mechanism", f"unknown parameter {key!r} in the mechanism description")
    if obstacles:
        if sorted(obstacles) != list(range(1, len(obstacles) + 1)):
            raise schema.ConfigError(source, "mechanism", "obstacles must be numbered obstacle1, obstacle2, ...")
        data["obstacles"] = [obstacles[k] for k in sorted(obstacles)]
    return data


# ---------------------------------------------------------------- the YAML keys



# ---------------------------------------------------------------- the YAML keys


def parse(data: Mapping, source: str, names: tuple[str, ...]) -> Constraints:
    """`limits`, `obstacles` and `clearance` of a mechanism's mapping (all optional; `names`: the
    angles the kind can limit, in the order they are kept)."""
    limits = []
    if "limits" in data:
        raw = schema.mapping(data, "limits", source)
        schema.check_keys(raw, set(names), set(), source, "limits.")
        limits = [_limit(name, raw[name], source) for name in names if name in raw]
    obstacles = []
    if "obstacles" in data:
        raw = data["obstacles"]
        if not isinstance(raw, list):
            raise schema.ConfigError(source, "obstacles", f"expected a list of obstacles, got {schema.kind_of(raw)}")
        if len(raw) > MAX_OBSTACLES:
            raise schema.ConfigError(source, "obstacles", f"at most {MAX_OBSTACLES} obstacles, got {len(raw)}")
        obstacles = [_obstacle(item, source, f"obstacles[{k}]") for k, item in enumerate(raw)]
    clearance = schema.number(data["clearance"], source, "clearance", nonnegative=True) if "clearance" in data else 0.0
    return Constraints(tuple(limits), tuple(obstacles), clearance)


def _limit(name: str, value, source: str) -> Limit:
    field = f"limits.{name}"
    if not isinstance(value, list) or len(value) != 2:
        raise schema.ConfigError(source, field, f"expected [lo, hi] in degrees, got {schema.short(value)}")
    lo = schema.number(value[0], source, f"{field}[0]")
    hi = schema.number(value[1], source, f"{field}[1]")
    for k, v in enumerate((lo, hi)):
        if not -180.0 <= v <= 180.0:
            raise schema.ConfigError(source, f"{field}[{k}]", f"must be within [-180, 180] degrees, got {v!r}")
    if not lo < hi:
        raise schema.ConfigError(source, field, f"needs lo < hi, got [{lo!r}, {hi!r}]")
    return Limit(name, lo, hi)


def _point(value, source: str, field: str) -> tuple[float, float]:
    if not isinstance(value, list) or len(value) != 2:
        raise schema.ConfigError(source, field, f"expected a point [x, y], got {schema.short(value)}")
    return (schema.number(value[0], source, f"{field}[0]"), schema.number(value[1], source, f"{field}[1]"))


def _obstacle(item, source: str, field: str) -> Disc | Polygon:
    from fivebar_cli.numerics.obstacles import Disc, Polygon, polygon_problem

    if not isinstance(item, dict) or len(item) != 1 or next(iter(item)) not in ("disc", "polygon"):
        shown = f"the keys {', '.join(map(str, item))}" if isinstance(item, dict) else schema.kind_of(item)
        raise schema.ConfigError(source, field, f"expected one of 'disc: {{centre: [x, y], radius: r}}' or "
                                                f"'polygon: [[x, y], ...]', got {shown}")
    kind, value = next(iter(item.items()))
    if kind == "disc":
        if not isinstance(value, dict):
            raise schema.ConfigError(source, f"{field}.disc", f"expected a mapping, got {schema.kind_of(value)}")
        schema.check_keys(value, {"centre", "radius"}, {"centre", "radius"}, source, f"{field}.disc.")
        centre = _point(value["centre"], source, f"{field}.disc.centre")
        radius = schema.number(value["radius"], source, f"{field}.disc.radius", positive=True)
        return Disc(centre, radius)
    if not isinstance(value, list):
        raise schema.ConfigError(source, f"{field}.polygon", f"expected a list of points, got {schema.kind_of(value)}")
    if len(value) > MAX_VERTICES:
        raise schema.ConfigError(source, f"{field}.polygon", f"at most {MAX_VERTICES} vertices, got {len(value)}")
    vertices = tuple(_point(p, source, f"{field}.polygon[{k}]") for k, p in enumerate(value))
    problem = polygon_problem(vertices)
    if problem is not None:
        raise schema.ConfigError(source, f"{field}.polygon", problem)
    return Polygon(vertices)


def base_problem(c: Constraints, joints, link: str) -> tuple[str, str] | None:
    """(field, message) when an obstacle comes within the clearance of a base joint (`joints`:
    name -> (x, y)); every configuration then collides, the `link` there always touching it."""
    for k, o in enumerate(c.obstacles):
        for name, (x, y) in joints.items():
            sd = float(o.point_distance(np.array([x]), np.array([y]))[0])
            if sd <= c.clearance:
                where = "covers" if sd <= 0 else f"comes within the clearance {c.clearance!r} of"
                return (f"obstacles[{k}]", f"{where} the base joint {name} = ({x:g}, {y:g}): the {link} at {name} "
                        "always touches it, so no configuration is left")
    return None


# ---------------------------------------------------------------- configurations


def in_arc(angle: np.ndarray, lo: float, hi: float) -> np.ndarray:
    """Whether some turn of each angle (radians) lies in [lo, hi] (radians)."""
    k = np.ceil((lo - angle) / (2 * np.pi))
    return angle + k * 2 * np.pi <= hi



def violated(c: Constraints, angles: Mapping[str, np.ndarray], links) -> np.ndarray:
    """(n, k) booleans: configuration i violates constraint j (`c.labels()` order), from the
    limited angles (radians, by name) and the links ((start, end) arrays (n, 2) each)."""
    n = len(next(iter(angles.values())))
    columns = [~in_arc(angles[lim.name], *lim.radians) for lim in c.limits]
    for o in c.obstacles:
        near = np.zeros(n, bool)
        for a, b in links:
            near |= o.segment_distance(a, b) <= c.clearance
        columns.append(near)
    return np.column_stack(columns) if columns else np.zeros((n, 0), bool)


def obstacle_marks(c: Constraints) -> list[dict]:
    """The obstacles (with their clearance) as figures and `fivebar view` draw them on a workspace."""
    out = []
    for k, o in enumerate(c.obstacles, start=1):
        shape = ({"kind": "disc", "centre": list(o.centre), "radius": o.radius} if o.kind == "disc"
                 else {"kind": "polygon", "points": [list(p) for p in o.vertices]})
        out.append({**shape, "clearance": c.clearance, "label": f"obstacle {k}"})
    return out


def limit_marks(c: Constraints, actuated: tuple[str, ...], degrees: bool) -> list[dict]:
    """The limits of the joint-space axes `actuated` as lines (in degrees or radians, as the axes)."""
    return [{"kind": "line", "axis": actuated.index(lim.name), "value": v, "label": f"{lim.name} limit"}
            for lim in c.limits if lim.name in actuated and not lim.full_turn
            for v in ((lim.lo, lim.hi) if degrees else lim.radians)]
