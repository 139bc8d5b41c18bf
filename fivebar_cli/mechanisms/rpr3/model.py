"""The 3-RPR: model and YAML schema, in a general form and in Jiang & Gosselin's similar form.

General form: base points B1, B2, B3 (fixed frame) and platform points P1, P2, P3 (platform
frame); the pose (x, y, phi) puts the platform frame's origin at (x, y), turned by phi (degrees
in files, headers and trees). Leg i joins B_i to (x, y) + R(phi) P_i and its length must lie in
[rho_min_i, rho_max_i] (one range for all legs, or one per leg).

Similar form: B1 = (0, 0), B2 = (t1, 0), B3 = (t2, t3) and a platform similar to the base with
ratio k (`k:` or `platform: {t4, t5, t6}`); the platform frame is at the platform centroid, so
P_i = k (B_i - g), g the base centroid. Only this form has the closed forms (`rpr3 area`,
`sweep`, `synthesize`) and `rho_max: auto`; every instance has the general geometry too, which is
what `pave` and `verify` use.

The workspace is paved in (x, y, phi) (an octree; a single orientation gives the quadtree of
(x, y) at that phi) with three regions: reachable, singularity-free with det J > 0, and with
det J < 0 (sign convention in `boxtests.py`).
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from functools import lru_cache
from typing import Mapping

import numpy as np

from fivebar_cli.io import schema
from fivebar_cli.mechanisms.base import (
    Axis, Mechanism, Space, describe_fields, description_numbers, legs_word_value, pair_word, values_word, word_values,
)
from fivebar_cli.mechanisms.rpr3 import boxtests, closed_form
from fivebar_cli.mechanisms.rpr3.boxtests import MINUS, PLUS, REACHABLE
from fivebar_cli.numerics import platform as platform_geometry

SIMILAR_KEYS = ("t1", "t2", "t3", "k", "rho_min", "rho_max", "phi1", "phi2")
GENERAL_KEYS = ("B1", "B2", "B3", "P1", "P2", "P3", "rho_min", "rho_max", "phi1", "phi2")
FLAT_BASE = 1e7  # circumradius / longest side above which the closed forms refuse the base

Point = tuple[float, float]
Legs = tuple[float, float, float]


@dataclass(frozen=True)
class Rpr3(Mechanism):
    """3-RPR: base and platform points, leg ranges, orientation range (degrees).

    `rho_max` is None for "auto" (similar form only: the largest singularity-free value over the
    orientation range, in closed form); `similar` holds (t1, t2, t3, k) for the similar form.
    `phi_range` holds (phi1, phi2); for a single orientation phi1 == phi2.
    """

    name: str
    base: tuple[Point, Point, Point]
    platform: tuple[Point, Point, Point]
    rho_min: Legs
    rho_max: Legs | None
    phi_range: tuple[float, float]
    similar: tuple[float, float, float, float] | None = None

    kind = "rpr3"
    has_poses = True  # Mechanism's capability: a space of poses (x, y, phi), given rho_max

    # -- leg ranges and the closed forms

    def leg_limits(self) -> tuple[Legs, Legs]:
        """(rho_min, rho_max) per leg, with 'auto' resolved in closed form (possibly inf)."""
        if self.rho_max is not None:
            return self.rho_min, self.rho_max
        limit = self._design().rho_max_limit()
        return self.rho_min, (limit, limit, limit)

    def _design(self) -> "SimilarDesign":
        t1, t2, t3, k = self.similar
        rho_max = None if self.rho_max is None else self.rho_max[0]
        return SimilarDesign(t1, t2, t3, k, self.rho_min[0], rho_max, self.phi_range, self.name)

    def closed_form(self, source: str) -> "SimilarDesign":
        """What `rpr3 area | sweep | synthesize` need; ConfigError naming the field when the
        closed forms do not apply (a platform not similar to the base, per-leg ranges, a flat base)."""
        if self.similar is None:
            raise schema.ConfigError(source, "platform", "not similar to the base: the closed forms (area, sweep, "
                                     "synthesize) need base: {t1, t2, t3} with k or a similar platform: {t4, t5, t6}; "
                                     "`fivebar rpr3 pave` and `verify` take any platform")
        if len(set(self.rho_min)) != 1 or (self.rho_max is not None and len(set(self.rho_max)) != 1):
            raise schema.ConfigError(source, "legs", "the closed forms need one leg range for all three legs "
                                     "(`fivebar rpr3 pave` and `verify` take one range per leg)")
        t1, t2, t3, k = self.similar
        sides = (t1, math.hypot(t2, t3), math.hypot(t2 - t1, t3))
        circumradius = sides[0] * sides[1] * sides[2] / (2.0 * abs(t1 * t3))
        if circumradius > FLAT_BASE * max(sides):
            raise schema.ConfigError(source, "base.t3", f"the base is nearly collinear (circumradius "
                                     f"{circumradius:.3g} > {FLAT_BASE:g} x its longest side): its singularity "
                                     "circle is a line to rounding, and the closed forms lose their accuracy")
        return self._design()

    def closed_form_or_none(self) -> "SimilarDesign | None":
        """The similar-form design when the closed forms apply (see `closed_form`), else None."""
        try:
            return self.closed_form("<model>")
        except schema.ConfigError:
            return None

    # -- protocol

    @classmethod
    def parse(cls, data: Mapping, source: str = "<config>") -> "Rpr3":
        return _parse(cls, data, source)

    @classmethod
    def from_description(cls, fields: Mapping[str, str], name: str, source: str) -> "Rpr3":
        fields = dict(fields)
        general = "B1" in fields
        points = ("B1", "B2", "B3", "P1", "P2", "P3") if general else ()
        words = {key: fields.pop(key, None) for key in ("rho_min", "rho_max", *points)}
        keys = [k for k in (SIMILAR_KEYS if not general else GENERAL_KEYS) if k not in words]
        v = description_numbers(fields, keys, source)
        data: dict = {"name": name, "type": cls.kind}
        if general:
            data["base"] = {f"B{i}": word_values(words[f"B{i}"], (2,), f"B{i}", source) for i in (1, 2, 3)}
            data["platform"] = {f"P{i}": word_values(words[f"P{i}"], (2,), f"P{i}", source) for i in (1, 2, 3)}
        else:
            data["base"] = {k: v[k] for k in ("t1", "t2", "t3")}
            data["k"] = v["k"]
        legs = {"rho_min": legs_word_value(words["rho_min"], "rho_min", source)}
        legs["rho_max"] = "auto" if words["rho_max"] == "auto" else legs_word_value(words["rho_max"], "rho_max", source)
        data["legs"] = legs
        data.update({"phi": v["phi1"]} if v["phi1"] == v["phi2"] else {"phi_range": [v["phi1"], v["phi2"]]})
        return cls.parse(data, source)

    def describe(self) -> str:
        if self.similar is not None:
            t1, t2, t3, k = self.similar
            text = describe_fields(self.kind, {"t1": t1, "t2": t2, "t3": t3, "k": k})
        else:
            text = self.kind + "".join(f" B{i + 1}={pair_word(p)}" for i, p in enumerate(self.base))
            text += "".join(f" P{i + 1}={pair_word(p)}" for i, p in enumerate(self.platform))
        text += f" rho_min={values_word(self.rho_min)}"
        text += " rho_max=auto" if self.rho_max is None else f" rho_max={values_word(self.rho_max)}"
        return text + f" phi1={float(self.phi_range[0])!r} phi2={float(self.phi_range[1])!r}"

    def spaces(self) -> dict[str, Space]:
        """The workspace (x, y, phi[deg]) on a root box holding every reachable pose; (x, y) for a
        single orientation. No space when the legs are unbounded (rho_max auto = inf)."""
        root = workspace_root(self)
        if root is None:
            return {}
        (xlo, xhi), (ylo, yhi) = root
        axes = (Axis("x", xlo, xhi), Axis("y", ylo, yhi))
        phi1, phi2 = self.phi_range
        if phi1 < phi2:
            axes += (Axis("phi", phi1, phi2, "deg", periodic=self.full_turn, label=r"$\varphi$"),)
        return {"workspace": Space("workspace", REACHABLE, axes)}

    def no_pose_space(self, source: str) -> schema.ConfigError:
        """Its space of poses is missing only when rho_max auto is infinite (`spaces`)."""
        return schema.ConfigError(source, "legs.rho_max", "'auto' is unbounded here (every point of the singularity "
                                  "circle is within rho_min of some C_i): give rho_max to pave or verify")

    @property
    def full_turn(self) -> bool:
        """Whether the orientation range is one whole turn (phi2 - phi1 = 360 degrees exactly, e.g.
        [-180, 180]): phi is then a periodic axis, and regions wrap across phi1 = phi2."""
        return self.phi_range[1] - self.phi_range[0] == 360.0

    def pose_aspect_model(self):
        """Aspects over (x, y, phi) by sign of det J (`rpr3/aspects.py`); None for unbounded legs."""
        if "workspace" not in self.spaces():
            return None
        from fivebar_cli.mechanisms.rpr3.aspects import Rpr3PoseAspects

        return Rpr3PoseAspects(self)

    def regions(self, space: str) -> tuple[str, ...]:
        """Reachable, and reachable with det J > 0, resp. < 0 (the singularity-free parts)."""
        return (REACHABLE, PLUS, MINUS)

    def box_test(self, space: str, procedure: str = "exact", region: str | None = None):
        if space not in self.spaces() or procedure != "exact":
            raise KeyError((space, procedure))
        return boxtests.region_test(self, region or REACHABLE)

    def exact_measure(self, space: str, region: str | None = None) -> float | None:
        """Similar form with one leg range: the volume (area for one phi) of each region from the
        closed-form areas, integrated over phi (deg); None otherwise."""
        if space != "workspace" or self.closed_form_or_none() is None:
            return None
        return _exact_measure(self, region or REACHABLE)


@dataclass(frozen=True)
class SimilarDesign:
    """The similar-triangle design and its one leg range: what every closed form takes."""

    t1: float
    t2: float
    t3: float
    k: float
    rho_min: float
    rho_max: float | None
    phi_range: tuple[float, float]
    name: str = ""

    @property
    def design(self) -> tuple[float, float, float, float]:
        """(t1, t2, t3, k): the arguments every closed form starts with."""
        return self.t1, self.t2, self.t3, self.k

    @property
    def phi(self) -> float:
        return self.phi_range[0]

    @property
    def radians(self) -> tuple[float, float]:
        """phi1, phi2 in radians, both turned by the same multiple of 360 degrees into [0, 360)."""
        return tuple(to_radians(p, self.phi_range[0]) for p in self.phi_range)

    def rho_max_limit(self) -> float:
        """The largest rho_max keeping the singularity circle out of the annuli over phi_range (inf
        when every point of the circle is within rho_min of some C_i)."""
        p1, p2 = self.radians
        return float(closed_form.rho_max_range(*self.design, p1, p2, self.rho_min))

    def leg_range(self) -> tuple[float, float, bool]:
        """(rho_min, rho_max, auto): the configured rho_max, or the limit when it is 'auto'."""
        if self.rho_max is not None:
            return self.rho_min, self.rho_max, False
        return self.rho_min, self.rho_max_limit(), True


def to_radians(phi_deg: float, reference: float | None = None) -> float:
    """Radians of an orientation turned by the multiple of 360 degrees that brings `reference`
    (default: phi itself) into [0, 360): the same geometry gives the same numbers at 45, 405 or -315."""
    ref = phi_deg if reference is None else reference
    return math.radians(phi_deg - 360.0 * math.floor(ref / 360.0))


def reaches_singular_orientation(lo: float, hi: float) -> bool:
    """Whether [lo, hi] (degrees) holds a multiple of 180, where a similar platform is singular everywhere."""
    return math.floor(lo / 180.0) != math.floor(hi / 180.0) or lo % 180.0 == 0 or hi % 180.0 == 0


# ---------------------------------------------------------------- the root box


def workspace_root(m: Rpr3) -> tuple[tuple[float, float], tuple[float, float]] | None:
    """An (x, y) box holding every reachable pose over the orientation range, or None.

    Leg i reaches X only within rho_max_i of C_i(phi) = B_i - R(phi) P_i, and C_i runs along an
    arc of radius |P_i| about B_i: the box is the intersection over the legs of each arc's
    bounding box widened by rho_max_i (`numerics.platform.root_box`). None when unbounded or empty.
    """
    _, rho_max = m.leg_limits()
    if not all(math.isfinite(r) for r in rho_max):
        return None
    return platform_geometry.root_box(m.base, m.platform, rho_max, m.phi_range)


# ---------------------------------------------------------------- exact volumes (similar form)


def _exact_measure(m: Rpr3, region: str) -> float:
    """Volume (area for one phi) of a region from the closed-form areas: reachable, the
    intersection of the three annuli; the sign region of the inside of the singularity circle,
    its part inside the circle (W); the other sign, its part outside."""
    reach, inside_part, inside_sign = _exact_volumes(m)
    if region == REACHABLE:
        return reach
    return inside_part if (region == PLUS) == (inside_sign > 0) else max(reach - inside_part, 0.0)


@lru_cache(maxsize=64)
def _exact_volumes(m: Rpr3) -> tuple[float, float, int]:
    """(reachable, inside the singularity circle, sign of det J inside it), integrated over phi
    in degrees by 8-point Gauss-Legendre panels doubled until two estimates agree to 1e-10
    (relative; the areas are exact, piecewise smooth in phi)."""
    from fivebar_cli.numerics import arcs

    d = m._design()
    rho_min, rho_max = d.rho_min, m.leg_limits()[1][0]
    p1, p2 = d.radians

    def areas(phis):
        c, r = closed_form.region(*d.design, phis, rho_min, rho_max)
        reach = arcs.area(c[..., 1:, :], r[..., 1:], closed_form.SIDES[1:])
        return np.stack([reach, np.minimum(arcs.area(c, r, closed_form.SIDES), reach)], -1)

    sign = _inside_sign(m, 0.5 * (p1 + p2))
    if p1 == p2:
        a = areas(np.array([p1]))[0]
        return float(a[0]), float(a[1]), sign
    nodes, weights = np.polynomial.legendre.leggauss(8)
    previous, panels = None, 16
    while True:
        edges = np.linspace(p1, p2, panels + 1)
        half = 0.5 * np.diff(edges)
        phis = (0.5 * (edges[:-1] + edges[1:]))[:, None] + half[:, None] * nodes
        total = np.einsum("pnk,n,p->k", areas(phis), weights, half) * (180.0 / math.pi)  # area x degrees
        if previous is not None and np.all(np.abs(total - previous) <= 1e-10 * np.abs(total)) or panels >= 1 << 11:
            return float(total[0]), float(total[1]), sign
        previous, panels = total, 2 * panels


def _inside_sign(m: Rpr3, phi: float) -> int:
    """Sign of det J inside the singularity circle at orientation phi (radians): det J is a
    non-zero multiple of |X - o|^2 - R^2 there, so its centre o decides."""
    d = m._design()
    (ox, oy), _ = closed_form.singularity_circle(*d.design, phi)
    phi_deg = math.degrees(phi) + 360.0 * math.floor(m.phi_range[0] / 360.0)
    return int(np.sign(boxtests.det_j(m, np.array([[float(ox), float(oy), phi_deg]]))[0]))


# ---------------------------------------------------------------- YAML


def _parse(cls, data: Mapping, source: str) -> Rpr3:
    schema.check_keys(
        data,
        {"name", "type", "base", "k", "platform", "legs", "phi", "phi_range"},
        {"name", "type", "base", "legs"},
        source,
    )
    name = schema.name_field(data, source)
    base_map = schema.mapping(data, "base", source)
    if any(k in base_map for k in ("B1", "B2", "B3")):
        schema.check_keys(base_map, {"B1", "B2", "B3"}, {"B1", "B2", "B3"}, source, "base.")
        base = tuple(schema.point(base_map[f"B{i}"], source, f"base.B{i}") for i in (1, 2, 3))
        schema.distinct_points(base, source, "base", "B")
        if "k" in data:
            raise schema.ConfigError(source, "k", "only with base: {t1, t2, t3} (the similar form); with base "
                                     "points give platform: {P1, P2, P3}")
        if "platform" not in data:
            raise schema.ConfigError(source, "platform", "missing (platform: {P1: [x, y], P2: ..., P3: ...})")
        platform, similar, why = _general_platform(data, source, allow_t=False), None, ""
    else:
        schema.check_keys(base_map, {"t1", "t2", "t3"}, {"t1", "t2", "t3"}, source, "base.")
        t1 = schema.number(base_map["t1"], source, "base.t1", positive=True)
        t2 = schema.number(base_map["t2"], source, "base.t2")
        t3 = schema.number(base_map["t3"], source, "base.t3")
        if abs(t3) <= 1e-12 * max(t1, abs(t2)):
            raise schema.ConfigError(source, "base.t3", "the base is degenerate: B1, B2, B3 are collinear (t3 = 0)")
        base = ((0.0, 0.0), (t1, 0.0), (t2, t3))
        k, why = _ratio(data, source, t1, t2, t3)
        if k is not None:
            g = ((t1 + t2) / 3.0, t3 / 3.0)
            platform = tuple((k * (bx - g[0]), k * (by - g[1])) for bx, by in base)
            similar = (t1, t2, t3, k)
        else:
            platform, similar = _general_platform(data, source, allow_t=True), None

    rho_min, rho_max = _legs(data, source, similar is not None, why)
    phi_range, field = schema.orientations(data, source)
    lo, hi = phi_range
    if similar is not None and reaches_singular_orientation(lo, hi):
        what = f"{list(phi_range)} contains" if lo != hi else f"{lo!r} is"
        raise schema.ConfigError(
            source, field, f"{what} a multiple of 180 degrees, where the whole plane is singular"
        )
    m = cls(name=name, base=base, platform=platform, rho_min=rho_min, rho_max=rho_max, phi_range=phi_range,
            similar=similar)
    if rho_max is not None and workspace_root(m) is None:
        raise schema.ConfigError(source, "legs.rho_max", "the three legs can never reach a common pose "
                                 "(no point is within rho_max of all three over the orientation range)")
    return m


def _general_platform(data: Mapping, source: str, allow_t: bool) -> tuple[Point, Point, Point]:
    """Platform points in the platform frame: {P1, P2, P3} as given, or (with a t-form base)
    {t4, t5, t6} (not similar to the base) with the frame at the platform centroid."""
    platform = schema.mapping(data, "platform", source)
    if allow_t and any(k in platform for k in ("t4", "t5", "t6")):  # checked by _ratio: not similar
        t4 = float(platform["t4"])
        t5, t6 = float(platform["t5"]), float(platform["t6"])
        pts = ((0.0, 0.0), (t4, 0.0), (t5, t6))
        g = ((t4 + t5) / 3.0, t6 / 3.0)
        pts = tuple((x - g[0], y - g[1]) for x, y in pts)
    else:
        schema.check_keys(platform, {"P1", "P2", "P3"}, {"P1", "P2", "P3"}, source, "platform.")
        pts = tuple(schema.point(platform[f"P{i}"], source, f"platform.P{i}") for i in (1, 2, 3))
    schema.distinct_points(pts, source, "platform", "P")
    return pts


def _ratio(data: Mapping, source: str, t1: float, t2: float, t3: float) -> tuple[float | None, str]:
    """The platform/base ratio k, from `k:` or from a similar `platform: {t4, t5, t6}`; None and
    why for a platform that is not similar (given as points, or as t4, t5, t6 of another shape)."""
    k = schema.number(data["k"], source, "k", positive=True) if "k" in data else None
    if "platform" not in data:
        if k is None:
            raise schema.ConfigError(source, "k", "missing (the platform/base size ratio)")
        return k, ""
    platform = schema.mapping(data, "platform", source)
    if any(key in platform for key in ("P1", "P2", "P3")):
        if k is not None:
            raise schema.ConfigError(source, "k", "give either k or platform points, not both")
        return None, "given as points, not as a similar platform"
    schema.check_keys(platform, {"t4", "t5", "t6"}, {"t4", "t5", "t6"}, source, "platform.")
    t4 = schema.number(platform["t4"], source, "platform.t4", positive=True)
    t5 = schema.number(platform["t5"], source, "platform.t5")
    t6 = schema.number(platform["t6"], source, "platform.t6")
    ratio = t4 / t1
    if not (1.0 / schema.LIMIT <= ratio <= schema.LIMIT):
        raise schema.ConfigError(source, "platform.t4", f"the ratio k = t4 / t1 = {ratio!r} is out of range")
    tol = 1e-9 * max(t4, abs(t5), abs(t6))
    if abs(t5 - ratio * t2) > tol or abs(t6 - ratio * t3) > tol:
        why = (f"not similar to the base: t4/t1 = {t4 / t1:.6g}, t5/t2 = {t5 / t2 if t2 else float('nan'):.6g}, "
               f"t6/t3 = {t6 / t3:.6g} differ")
        if k is not None:
            raise schema.ConfigError(source, "platform", f"{why}, so k does not apply: drop k")
        return None, why
    if k is not None and abs(k - ratio) > tol * k:
        raise schema.ConfigError(source, "k", f"{k!r} disagrees with the platform ratio t4/t1 = {ratio!r}")
    return ratio, ""


def _legs(data: Mapping, source: str, similar: bool, why: str = "") -> tuple[Legs, Legs | None]:
    """rho_min and rho_max: a number for all legs or a list of three; rho_max may be 'auto'
    (the default) for the similar form (`why`: why the platform is not similar)."""
    legs = schema.mapping(data, "legs", source)
    schema.check_keys(legs, {"rho_min", "rho_max"}, {"rho_min"}, source, "legs.")
    rho_min = _leg_values(legs["rho_min"], source, "legs.rho_min", nonnegative=True)
    raw = legs.get("rho_max", "auto")
    if raw == "auto":
        if why.startswith("not similar"):  # a t4, t5, t6 platform meant to be similar, most likely
            raise schema.ConfigError(source, "platform", f"{why}; rho_max 'auto' and the closed forms need a "
                                     "similar platform (give legs.rho_max to pave or verify this one)")
        if not similar:
            raise schema.ConfigError(source, "legs.rho_max", ("missing" if "rho_max" not in legs else "'auto' "
                                     "needs a platform similar to the base") + ": give a number or a list of three "
                                     "(rho_max auto is for base: {t1, t2, t3} with k)")
        return rho_min, None
    rho_max = _leg_values(raw, source, "legs.rho_max", positive=True)
    for a, b in zip(rho_min, rho_max):
        if a >= b:
            raise schema.ConfigError(source, "legs", f"rho_min ({a!r}) must be smaller than rho_max ({b!r})")
    return rho_min, rho_max


def _leg_values(value, source: str, field: str, **checks) -> Legs:
    if isinstance(value, list):
        if len(value) != 3:
            raise schema.ConfigError(source, field, f"expected a number or a list of three, got {len(value)} values")
        return tuple(schema.number(v, source, f"{field}[{i}]", **checks) for i, v in enumerate(value))
    v = schema.number(value, source, field, **checks)
    return (v, v, v)
