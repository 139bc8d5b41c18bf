"""The 3-RPR with a platform similar to its base (Jiang & Gosselin): model and YAML schema.

Base B1 = (0, 0), B2 = (t1, 0), B3 = (t2, t3); the platform is the base scaled by k (given as `k`
or as an explicit `platform: {t4, t5, t6}` that must be similar); the tracked point is the
platform centroid; angles in degrees in the file, radians in the closed forms. `rho_max: auto` is
the largest singularity-free value over the whole orientation range, in closed form.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Mapping

from fivebar_cli.io import schema
from fivebar_cli.mechanisms.base import Mechanism, describe_fields, description_numbers
from fivebar_cli.mechanisms.rpr3 import closed_form

DESCRIPTION_KEYS = ("t1", "t2", "t3", "k", "rho_min", "rho_max", "phi1", "phi2")


@dataclass(frozen=True)
class Rpr3(Mechanism):
    """3-RPR with base B1 = (0, 0), B2 = (t1, 0), B3 = (t2, t3) and a platform similar to it (ratio k).

    `rho_max` is None for "auto" (the largest singularity-free value over the orientation range).
    `phi_range` holds (phi1, phi2) in degrees; for a single orientation phi1 == phi2.
    """

    name: str
    t1: float
    t2: float
    t3: float
    k: float
    rho_min: float
    rho_max: float | None
    phi_range: tuple[float, float]

    kind = "rpr3"

    @property
    def phi(self) -> float:
        return self.phi_range[0]

    @property
    def design(self) -> tuple[float, float, float, float]:
        """(t1, t2, t3, k): the arguments every closed form starts with."""
        return self.t1, self.t2, self.t3, self.k

    def rho_max_limit(self) -> float:
        """The largest rho_max keeping the singularity circle out of the annuli over phi_range (inf
        when every point of the circle is within rho_min of some C_i)."""
        p1, p2 = (math.radians(p) for p in self.phi_range)
        return float(closed_form.rho_max_range(*self.design, p1, p2, self.rho_min))

    def leg_range(self) -> tuple[float, float, bool]:
        """(rho_min, rho_max, auto): the configured rho_max, or the limit when it is 'auto'."""
        if self.rho_max is not None:
            return self.rho_min, self.rho_max, False
        return self.rho_min, self.rho_max_limit(), True

    @classmethod
    def parse(cls, data: Mapping, source: str = "<config>") -> "Rpr3":
        return _parse(cls, data, source)

    @classmethod
    def from_description(cls, fields: Mapping[str, str], name: str, source: str) -> "Rpr3":
        fields = dict(fields)
        auto = fields.get("rho_max") == "auto"
        if auto:
            fields["rho_max"] = "inf"
        v = description_numbers(fields, DESCRIPTION_KEYS, source)
        data = {"name": name, "type": cls.kind, "base": {k: v[k] for k in ("t1", "t2", "t3")}, "k": v["k"],
                "legs": {"rho_min": v["rho_min"], "rho_max": "auto" if auto else v["rho_max"]}}
        data.update({"phi": v["phi1"]} if v["phi1"] == v["phi2"] else {"phi_range": [v["phi1"], v["phi2"]]})
        return cls.parse(data, source)

    def describe(self) -> str:
        text = describe_fields(self.kind, {"t1": self.t1, "t2": self.t2, "t3": self.t3, "k": self.k,
                                           "rho_min": self.rho_min})
        text += " rho_max=auto" if self.rho_max is None else f" rho_max={self.rho_max!r}"
        return text + f" phi1={self.phi_range[0]!r} phi2={self.phi_range[1]!r}"


def _parse(cls, data: Mapping, source: str):
    schema.check_keys(
        data,
        {"name", "type", "base", "k", "platform", "legs", "phi", "phi_range"},
        {"name", "type", "base", "legs"},
        source,
    )
    name = schema.name_field(data, source)
    base = schema.mapping(data, "base", source)
    schema.check_keys(base, {"t1", "t2", "t3"}, {"t1", "t2", "t3"}, source, "base.")
    t1 = schema.number(base["t1"], source, "base.t1", positive=True)
    t2 = schema.number(base["t2"], source, "base.t2")
    t3 = schema.number(base["t3"], source, "base.t3")
    if abs(t3) <= 1e-12 * max(t1, abs(t2)):
        raise schema.ConfigError(source, "base.t3", "the base is degenerate: B1, B2, B3 are collinear (t3 = 0)")

    k = _ratio(data, source, t1, t2, t3)

    legs = schema.mapping(data, "legs", source)
    schema.check_keys(legs, {"rho_min", "rho_max"}, {"rho_min"}, source, "legs.")
    rho_min = schema.number(legs["rho_min"], source, "legs.rho_min", nonnegative=True)
    rho_max_raw = legs.get("rho_max", "auto")
    if rho_max_raw == "auto":
        rho_max = None
    else:
        rho_max = schema.number(rho_max_raw, source, "legs.rho_max", positive=True)
        if rho_min >= rho_max:
            raise schema.ConfigError(source, "legs", f"rho_min ({rho_min!r}) must be smaller than rho_max ({rho_max!r})")

    if ("phi" in data) == ("phi_range" in data):
        raise schema.ConfigError(source, "phi", "give exactly one of 'phi' (degrees) or 'phi_range: [phi1, phi2]'")
    if "phi" in data:
        phi = schema.number(data["phi"], source, "phi")
        phi_range = (phi, phi)
        field = "phi"
    else:
        raw = data["phi_range"]
        if not isinstance(raw, list) or len(raw) != 2:
            raise schema.ConfigError(source, "phi_range", f"expected a list [phi1, phi2], got {raw!r}")
        phi_range = (schema.number(raw[0], source, "phi_range[0]"), schema.number(raw[1], source, "phi_range[1]"))
        field = "phi_range"
        if phi_range[0] >= phi_range[1]:
            raise schema.ConfigError(source, field, f"phi1 must be smaller than phi2, got {list(phi_range)}")
    lo, hi = phi_range
    if reaches_singular_orientation(lo, hi):
        what = f"{list(phi_range)} contains" if lo != hi else f"{lo!r} is"
        raise schema.ConfigError(
            source, field, f"{what} a multiple of 180 degrees, where the whole plane is singular"
        )
    return cls(name=name, t1=t1, t2=t2, t3=t3, k=k, rho_min=rho_min, rho_max=rho_max, phi_range=phi_range)


def reaches_singular_orientation(lo: float, hi: float) -> bool:
    """Whether [lo, hi] (degrees) holds a multiple of 180, where the whole plane is singular."""
    return math.floor(lo / 180.0) != math.floor(hi / 180.0) or lo % 180.0 == 0 or hi % 180.0 == 0


def _ratio(data: Mapping, source: str, t1: float, t2: float, t3: float) -> float:
    """The platform/base ratio k, from `k:` or from an explicit `platform:` that must be similar."""
    k = schema.number(data["k"], source, "k", positive=True) if "k" in data else None
    if "platform" not in data:
        if k is None:
            raise schema.ConfigError(source, "k", "missing (the platform/base size ratio)")
        return k
    platform = schema.mapping(data, "platform", source)
    schema.check_keys(platform, {"t4", "t5", "t6"}, {"t4", "t5", "t6"}, source, "platform.")
    t4 = schema.number(platform["t4"], source, "platform.t4", positive=True)
    t5 = schema.number(platform["t5"], source, "platform.t5")
    t6 = schema.number(platform["t6"], source, "platform.t6")
    ratio = t4 / t1
    if not (1.0 / schema.LIMIT <= ratio <= schema.LIMIT):
        raise schema.ConfigError(source, "platform.t4", f"the ratio k = t4 / t1 = {ratio!r} is out of range")
    tol = 1e-9 * max(t4, abs(t5), abs(t6))
    if abs(t5 - ratio * t2) > tol or abs(t6 - ratio * t3) > tol:
        raise schema.ConfigError(
            source, "platform",
            f"not similar to the base: t4/t1 = {t4 / t1:.6g}, t5/t2 = {t5 / t2 if t2 else float('nan'):.6g}, "
            f"t6/t3 = {t6 / t3:.6g} must be equal",
        )
    if k is not None and abs(k - ratio) > tol * k:
        raise schema.ConfigError(source, "k", f"{k!r} disagrees with the platform ratio t4/t1 = {ratio!r}")
    return ratio
