"""A five-bar's limits and obstacles: the YAML keys `limits`, `obstacles`, `clearance`, their
one-line description in `.qt` headers, and which constraints a configuration violates.

Limits are closed arcs [lo, hi] (degrees, lo < hi, within [-180, 180]) of five angles, each a signed
angle atan2(u x v, u . v) from a vector u to a vector v:

    theta1  actuated at A1: from the x axis to A1 -> B1
    theta2  actuated at A2: from the x axis to A2 -> B2
    B1      passive elbow:  from A1 -> B1 to B1 -> P   (th3 - th1, th3 the direction of P - B1)
    B2      passive elbow:  from A2 -> B2 to B2 -> P   (th4 - th2)
    P       passive end:    from P -> B1 to P -> B2    (th4 - th3)

An angle satisfies [lo, hi] when some turn of it lies in [lo, hi]. Obstacles are discs and simple
polygons; a configuration collides when one of its four links (segments A1B1, B1P, A2B2, B2P) comes
within `clearance` of one (touching included). The certified box tests are in `constrained.py`.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Mapping

import numpy as np

from fivebar_cli.io import schema
from fivebar_cli.numerics.obstacles import Disc, Polygon, polygon_problem

LIMIT_NAMES = ("theta1", "theta2", "B1", "B2", "P")
ACTUATED = ("theta1", "theta2")
LINKS = ("A1B1", "B1P", "A2B2", "B2P")
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
            numbers = (*o.centre, o.radius) if isinstance(o, Disc) else [v for p in o.vertices for v in p]
            out.append(f" obstacle{k}={o.kind}:" + ",".join(repr(float(v)) for v in numbers))
        if self.clearance:
            out.append(f" clearance={self.clearance!r}")
        return "".join(out)


NO_CONSTRAINTS = Constraints()


def description_data(fields: Mapping[str, str], source: str) -> dict:
    """The YAML mapping (`limits`, `obstacles`, `clearance`) of a description's constraint words."""
    data: dict = {}

    def numbers(key: str, text: str) -> list[float]:
        try:
            return [float(v) for v in text.split(",")]
        except ValueError:
            raise schema.ConfigError(source, "mechanism", f"bad value {key}={text!r}") from None

    obstacles = {}
    for key, text in fields.items():
        if key in LIMIT_NAMES:
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


def parse(data: Mapping, source: str) -> Constraints:
    """`limits`, `obstacles` and `clearance` of a five-bar's mapping (all optional)."""
    limits = []
    if "limits" in data:
        raw = schema.mapping(data, "limits", source)
        schema.check_keys(raw, set(LIMIT_NAMES), set(), source, "limits.")
        limits = [_limit(name, raw[name], source) for name in LIMIT_NAMES if name in raw]
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


def base_problem(c: Constraints, a2: tuple[float, float]) -> tuple[str, str] | None:
    """(field, message) when an obstacle comes within the clearance of A1 or A2 (every configuration
    then collides: the crank there always touches it), else None."""
    for k, o in enumerate(c.obstacles):
        for name, (x, y) in (("A1", (0.0, 0.0)), ("A2", a2)):
            sd = float(o.point_distance(np.array([x]), np.array([y]))[0])
            if sd <= c.clearance:
                where = "covers" if sd <= 0 else f"comes within the clearance {c.clearance!r} of"
                return (f"obstacles[{k}]", f"{where} the base joint {name} = ({x:g}, {y:g}): the crank at {name} "
                        "always touches it, so no configuration is left")
    return None


# ---------------------------------------------------------------- configurations


def in_arc(angle: np.ndarray, lo: float, hi: float) -> np.ndarray:
    """Whether some turn of each angle (radians) lies in [lo, hi] (radians)."""
    k = np.ceil((lo - angle) / (2 * np.pi))
    return angle + k * 2 * np.pi <= hi


def configuration_angles(m, joints: np.ndarray, poses: np.ndarray) -> dict[str, np.ndarray]:
    """The five limited angles (radians) of configurations (joint values (n, 2), poses (n, 2))."""
    th1, th2 = joints[:, 0], joints[:, 1]
    b1 = np.column_stack([m.L1 * np.cos(th1), m.L1 * np.sin(th1)])
    b2 = np.column_stack([m.L0 + m.L2 * np.cos(th2), m.L2 * np.sin(th2)])
    th3 = np.arctan2(poses[:, 1] - b1[:, 1], poses[:, 0] - b1[:, 0])
    th4 = np.arctan2(poses[:, 1] - b2[:, 1], poses[:, 0] - b2[:, 0])
    return {"theta1": th1, "theta2": th2, "B1": th3 - th1, "B2": th4 - th2, "P": th4 - th3}


def link_segments(m, joints: np.ndarray, poses: np.ndarray) -> dict[str, tuple[np.ndarray, np.ndarray]]:
    """The four links of configurations as (start, end) arrays (n, 2)."""
    th1, th2 = joints[:, 0], joints[:, 1]
    n = len(joints)
    a1, a2 = np.zeros((n, 2)), np.column_stack([np.full(n, m.L0), np.zeros(n)])
    b1 = np.column_stack([m.L1 * np.cos(th1), m.L1 * np.sin(th1)])
    b2 = np.column_stack([m.L0 + m.L2 * np.cos(th2), m.L2 * np.sin(th2)])
    return {"A1B1": (a1, b1), "B1P": (b1, poses), "A2B2": (a2, b2), "B2P": (b2, poses)}


def violated(m, joints: np.ndarray, poses: np.ndarray) -> np.ndarray:
    """(n, k) booleans: configuration i violates constraint j (`m.constraints.labels()` order)."""
    c = m.constraints
    joints, poses = np.atleast_2d(np.asarray(joints, float)), np.atleast_2d(np.asarray(poses, float))
    angles = configuration_angles(m, joints, poses)
    columns = [~in_arc(angles[lim.name], *lim.radians) for lim in c.limits]
    if c.obstacles:
        links = link_segments(m, joints, poses)
        for o in c.obstacles:
            near = np.zeros(len(joints), bool)
            for a, b in links.values():
                near |= o.segment_distance(a, b) <= c.clearance
            columns.append(near)
    return np.column_stack(columns) if columns else np.zeros((len(joints), 0), bool)


def violated_labels(m, joints: np.ndarray, poses: np.ndarray) -> list[list[str]]:
    """Per configuration, the labels of the constraints it violates (empty: none)."""
    labels = m.constraints.labels()
    return [[labels[j] for j in np.flatnonzero(row)] for row in violated(m, joints, poses)]


def marks(c: Constraints, space: str) -> list[dict]:
    """What figures and `fivebar view` draw over a space: obstacles (with their clearance) on the
    workspace, the actuated limits as lines on the joint space (radians)."""
    if space == "workspace":
        out = []
        for k, o in enumerate(c.obstacles, start=1):
            shape = ({"kind": "disc", "centre": list(o.centre), "radius": o.radius} if isinstance(o, Disc)
                     else {"kind": "polygon", "points": [list(p) for p in o.vertices]})
            out.append({**shape, "clearance": c.clearance, "label": f"obstacle {k}"})
        return out
    if space == "jointspace":
        return [{"kind": "line", "axis": ACTUATED.index(lim.name), "value": v, "label": f"{lim.name} limit"}
                for lim in c.limits if lim.name in ACTUATED and not lim.full_turn for v in lim.radians]
    return []
