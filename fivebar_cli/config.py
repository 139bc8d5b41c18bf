"""YAML mechanism files -> validated, frozen dataclasses.

Every problem is reported as a `ConfigError` naming the file, the field and what is wrong,
so the CLI can print one line and exit with status 2. Unknown keys are errors, not ignored:
a typo such as `lenghts:` must not silently fall back to defaults.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from pathlib import Path
from typing import Any, Mapping

from fivebar_cli.errors import InputError
from fivebar_cli.inputs import read_user_text


class ConfigError(InputError):
    """A problem in a mechanism file: `file: field: message` (exit status 2)."""


@dataclass(frozen=True)
class FiveBar:
    """Five-bar with A1 = (0, 0), A2 = (L0, 0), crank lengths L1, L2 and coupler lengths L3, L4."""

    name: str
    L0: float
    L1: float
    L2: float
    L3: float
    L4: float

    @property
    def lengths(self) -> dict[str, float]:
        return {k: getattr(self, k) for k in ("L0", "L1", "L2", "L3", "L4")}

    def describe(self) -> str:
        """One-line, round-trippable description (used in .qt headers)."""
        return "fivebar " + " ".join(f"{k}={v!r}" for k, v in self.lengths.items())


@dataclass(frozen=True)
class Rpr3:
    """3-RPR with base B1 = (0, 0), B2 = (t1, 0), B3 = (t2, t3) and a platform similar to it (ratio k).

    `rho_max` is None for "auto" (largest singularity-free value at the first orientation).
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

    @property
    def phi(self) -> float:
        return self.phi_range[0]


# ---------------------------------------------------------------- loading


def load_config(path: str | Path) -> FiveBar | Rpr3:
    """Read and validate a mechanism file; raise ConfigError on any problem."""
    source = str(path)
    data = _read_yaml(Path(path), source)
    kind = data.get("type")
    if kind == "fivebar":
        return parse_fivebar(data, source)
    if kind == "rpr3":
        return parse_rpr3(data, source)
    if kind is None:
        raise ConfigError(source, "type", "missing (expected 'fivebar' or 'rpr3')")
    raise ConfigError(source, "type", f"unknown mechanism type {kind!r} (expected 'fivebar' or 'rpr3')")


def load_fivebar(path: str | Path) -> FiveBar:
    """Load a file that must describe a five-bar."""
    mech = load_config(path)
    if not isinstance(mech, FiveBar):
        raise ConfigError(str(path), "type", "this command needs a five-bar ('type: fivebar')")
    return mech


def load_rpr3(path: str | Path) -> Rpr3:
    """Load a file that must describe a 3-RPR."""
    mech = load_config(path)
    if not isinstance(mech, Rpr3):
        raise ConfigError(str(path), "type", "this command needs a 3-RPR ('type: rpr3')")
    return mech


def _read_yaml(path: Path, source: str) -> dict:
    import yaml  # imported here: the library never imports yaml at module level

    text = read_user_text(path, ConfigError, "a YAML file")
    try:
        data = yaml.load(text, Loader=_strict_loader())
    except yaml.YAMLError as exc:
        mark = getattr(exc, "problem_mark", None)
        where = f"line {mark.line + 1}" if mark is not None else "YAML"
        problem = getattr(exc, "problem", None) or str(exc).splitlines()[0]
        raise ConfigError(source, where, f"invalid YAML: {problem}") from None
    except RecursionError:
        raise ConfigError(source, "", "invalid YAML: nesting too deep") from None
    except ValueError as exc:  # e.g. an integer beyond Python's digit limit
        raise ConfigError(source, "", f"invalid YAML value: {str(exc).splitlines()[0]}") from None
    if data is None:
        raise ConfigError(source, "", "empty file (expected a mapping with 'name' and 'type')")
    if not isinstance(data, dict):
        raise ConfigError(source, "", f"expected a mapping at the top level, got {_kind(data)}")
    return data


def _strict_loader():
    """PyYAML's safe loader, refusing duplicate keys (the last one would silently win)."""
    import yaml

    class StrictLoader(yaml.SafeLoader):
        def construct_yaml_int(self, node):  # beyond Python's digit limit: as good as infinite
            try:
                return super().construct_yaml_int(node)
            except ValueError:
                return math.inf

        def construct_mapping(self, node, deep=False):
            keys = [k.value for k, _ in node.value if isinstance(k, yaml.ScalarNode)]
            for index, key_node in enumerate(k for k, _ in node.value if isinstance(k, yaml.ScalarNode)):
                if key_node.value in keys[:index]:
                    raise yaml.constructor.ConstructorError(
                        None, None, f"duplicate key {key_node.value!r}", key_node.start_mark)
            return super().construct_mapping(node, deep=deep)

    StrictLoader.add_constructor("tag:yaml.org,2002:int", StrictLoader.construct_yaml_int)
    return StrictLoader


# ---------------------------------------------------------------- field helpers

LIMIT = 1e50  # magnitude bound on every number: products of a few lengths (and their squares) stay finite


def _field(prefix: str, key: object) -> str:
    """A key as it appears in a message: printable, on one line."""
    text = key if isinstance(key, str) and key.isprintable() else repr(key)
    return f"{prefix}{text}"


def _kind(value: Any) -> str:
    return {list: "a list", dict: "a mapping", str: "a string", bool: "a boolean"}.get(
        type(value), type(value).__name__
    )


def _check_keys(data: Mapping, allowed: set[str], required: set[str], source: str, prefix: str = "") -> None:
    for key in data:
        if not isinstance(key, str) or key not in allowed:
            raise ConfigError(source, _field(prefix, key), f"unknown key (allowed: {', '.join(sorted(allowed))})")
    for key in sorted(required):
        if key not in data:
            raise ConfigError(source, f"{prefix}{key}", "missing")


def _mapping(data: Mapping, key: str, source: str) -> Mapping:
    value = data[key]
    if not isinstance(value, dict):
        raise ConfigError(source, key, f"expected a mapping, got {_kind(value)}")
    return value


def _number(value: Any, source: str, field: str, *, positive: bool = False, nonnegative: bool = False) -> float:
    """A finite float of magnitude at most LIMIT (and at least 1/LIMIT when positive)."""
    if isinstance(value, bool) or not isinstance(value, (int, float)):
        hint = ""
        if isinstance(value, str):
            try:
                float(value)
                hint = " (YAML reads 1e-3 as text: write 1.0e-3)"
            except ValueError:
                pass
        shown = repr(value) if len(repr(value)) <= 40 else repr(value)[:37] + "..."
        raise ConfigError(source, field, f"expected a number, got {_kind(value)} {shown}{hint}")
    try:
        x = float(value)
    except OverflowError:
        x = math.inf
    if not math.isfinite(x) or abs(x) > LIMIT:
        raise ConfigError(source, field, f"must be finite and at most {LIMIT:g} in magnitude, got {_short(value)}")
    if positive and x <= 0:
        raise ConfigError(source, field, f"must be positive, got {_short(value)}")
    if positive and x < 1.0 / LIMIT:
        raise ConfigError(source, field, f"must be at least {1.0 / LIMIT:g}, got {_short(value)}")
    if nonnegative and x < 0:
        raise ConfigError(source, field, f"must not be negative, got {_short(value)}")
    return x


def _short(value: Any) -> str:
    text = repr(value)
    return text if len(text) <= 40 else text[:37] + "..."


def _name(data: Mapping, source: str) -> str:
    if "name" not in data:
        raise ConfigError(source, "name", "missing")
    name = data["name"]
    if isinstance(name, bool) or not isinstance(name, (str, int, float)):
        raise ConfigError(source, "name", f"expected a string, got {_kind(name)}")
    name = str(name)
    try:
        name.encode("utf-8")
    except UnicodeEncodeError:
        raise ConfigError(source, "name", f"{name!r} is not valid text") from None
    if (not name or name.strip() != name or not name.isprintable() or any(c in name for c in '/\\:*?"<>|')
            or name in (".", "..") or len(name) > 100):
        raise ConfigError(source, "name", f"{_short(name)} is not usable as a folder name")
    return name


# ---------------------------------------------------------------- five-bar


def parse_fivebar(data: Mapping, source: str = "<config>") -> FiveBar:
    _check_keys(data, {"name", "type", "lengths"}, {"name", "type", "lengths"}, source)
    name = _name(data, source)
    lengths = _mapping(data, "lengths", source)
    keys = {"L0", "L1", "L2", "L3", "L4"}
    _check_keys(lengths, keys, keys, source, "lengths.")
    values = {k: _number(lengths[k], source, f"lengths.{k}", positive=True) for k in sorted(keys)}
    return FiveBar(name=name, **values)


# ---------------------------------------------------------------- 3-RPR


def parse_rpr3(data: Mapping, source: str = "<config>") -> Rpr3:
    _check_keys(
        data,
        {"name", "type", "base", "k", "platform", "legs", "phi", "phi_range"},
        {"name", "type", "base", "legs"},
        source,
    )
    name = _name(data, source)
    base = _mapping(data, "base", source)
    _check_keys(base, {"t1", "t2", "t3"}, {"t1", "t2", "t3"}, source, "base.")
    t1 = _number(base["t1"], source, "base.t1", positive=True)
    t2 = _number(base["t2"], source, "base.t2")
    t3 = _number(base["t3"], source, "base.t3")
    if abs(t3) <= 1e-12 * max(t1, abs(t2)):
        raise ConfigError(source, "base.t3", "the base is degenerate: B1, B2, B3 are collinear (t3 = 0)")

    k = _ratio(data, source, t1, t2, t3)

    legs = _mapping(data, "legs", source)
    _check_keys(legs, {"rho_min", "rho_max"}, {"rho_min"}, source, "legs.")
    rho_min = _number(legs["rho_min"], source, "legs.rho_min", nonnegative=True)
    rho_max_raw = legs.get("rho_max", "auto")
    if rho_max_raw == "auto":
        rho_max = None
    else:
        rho_max = _number(rho_max_raw, source, "legs.rho_max", positive=True)
        if rho_min >= rho_max:
            raise ConfigError(source, "legs", f"rho_min ({rho_min!r}) must be smaller than rho_max ({rho_max!r})")

    if ("phi" in data) == ("phi_range" in data):
        raise ConfigError(source, "phi", "give exactly one of 'phi' (degrees) or 'phi_range: [phi1, phi2]'")
    if "phi" in data:
        phi = _number(data["phi"], source, "phi")
        phi_range = (phi, phi)
        field = "phi"
    else:
        raw = data["phi_range"]
        if not isinstance(raw, list) or len(raw) != 2:
            raise ConfigError(source, "phi_range", f"expected a list [phi1, phi2], got {raw!r}")
        phi_range = (_number(raw[0], source, "phi_range[0]"), _number(raw[1], source, "phi_range[1]"))
        field = "phi_range"
        if phi_range[0] >= phi_range[1]:
            raise ConfigError(source, field, f"phi1 must be smaller than phi2, got {list(phi_range)}")
    lo, hi = phi_range
    if reaches_singular_orientation(lo, hi):
        what = f"{list(phi_range)} contains" if lo != hi else f"{lo!r} is"
        raise ConfigError(
            source, field, f"{what} a multiple of 180 degrees, where the whole plane is singular"
        )
    return Rpr3(name=name, t1=t1, t2=t2, t3=t3, k=k, rho_min=rho_min, rho_max=rho_max, phi_range=phi_range)


def reaches_singular_orientation(lo: float, hi: float) -> bool:
    """Whether [lo, hi] (degrees) holds a multiple of 180, where the whole plane is singular."""
    return math.floor(lo / 180.0) != math.floor(hi / 180.0) or lo % 180.0 == 0 or hi % 180.0 == 0


def _ratio(data: Mapping, source: str, t1: float, t2: float, t3: float) -> float:
    """The platform/base ratio k, from `k:` or from an explicit `platform:` that must be similar."""
    k = _number(data["k"], source, "k", positive=True) if "k" in data else None
    if "platform" not in data:
        if k is None:
            raise ConfigError(source, "k", "missing (the platform/base size ratio)")
        return k
    platform = _mapping(data, "platform", source)
    _check_keys(platform, {"t4", "t5", "t6"}, {"t4", "t5", "t6"}, source, "platform.")
    t4 = _number(platform["t4"], source, "platform.t4", positive=True)
    t5 = _number(platform["t5"], source, "platform.t5")
    t6 = _number(platform["t6"], source, "platform.t6")
    ratio = t4 / t1
    if not (1.0 / LIMIT <= ratio <= LIMIT):
        raise ConfigError(source, "platform.t4", f"the ratio k = t4 / t1 = {ratio!r} is out of range")
    tol = 1e-9 * max(t4, abs(t5), abs(t6))
    if abs(t5 - ratio * t2) > tol or abs(t6 - ratio * t3) > tol:
        raise ConfigError(
            source, "platform",
            f"not similar to the base: t4/t1 = {t4 / t1:.6g}, t5/t2 = {t5 / t2 if t2 else float('nan'):.6g}, "
            f"t6/t3 = {t6 / t3:.6g} must be equal",
        )
    if k is not None and abs(k - ratio) > tol * k:
        raise ConfigError(source, "k", f"{k!r} disagrees with the platform ratio t4/t1 = {ratio!r}")
    return ratio
