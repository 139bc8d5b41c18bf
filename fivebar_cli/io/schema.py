"""Reading mechanism files: strict YAML, and the field checks every mechanism schema is built from.

Every problem is reported as a `ConfigError` naming the file, the field and what is wrong, so the
CLI can print one line and exit with status 2. Unknown keys are errors, not ignored: a typo such
as `lenghts:` must not silently fall back to defaults. The schemas themselves belong to the
mechanism kinds (`fivebar_cli/mechanisms/*/model.py`); docs/formats.md lists them.
"""

from __future__ import annotations

import math
from pathlib import Path
from typing import Any, Mapping

from fivebar_cli.errors import InputError
from fivebar_cli.io.files import read_user_text


class ConfigError(InputError):
    """A problem in a mechanism file: `file: field: message` (exit status 2)."""


def read_yaml(path: str | Path, source: str | None = None) -> dict:
    """The top-level mapping of a YAML file (duplicate keys refused)."""
    source = str(path) if source is None else source
    import yaml  # imported here: the library never imports yaml at module level

    text = read_user_text(Path(path), ConfigError, "a YAML file")
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
        raise ConfigError(source, "", f"expected a mapping at the top level, got {kind_of(data)}")
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


def field_name(prefix: str, key: object) -> str:
    """A key as it appears in a message: printable, on one line."""
    text = key if isinstance(key, str) and key.isprintable() else repr(key)
    return f"{prefix}{text}"


def kind_of(value: Any) -> str:
    return {list: "a list", dict: "a mapping", str: "a string", bool: "a boolean"}.get(
        type(value), type(value).__name__
    )


def check_keys(data: Mapping, allowed: set[str], required: set[str], source: str, prefix: str = "") -> None:
    for key in data:
        if not isinstance(key, str) or key not in allowed:
            raise ConfigError(source, field_name(prefix, key), f"unknown key (allowed: {', '.join(sorted(allowed))})")
    for key in sorted(required):
        if key not in data:
            raise ConfigError(source, f"{prefix}{key}", "missing")


def mapping(data: Mapping, key: str, source: str) -> Mapping:
    value = data[key]
    if not isinstance(value, dict):
        raise ConfigError(source, key, f"expected a mapping, got {kind_of(value)}")
    return value


def number(value: Any, source: str, field: str, *, positive: bool = False, nonnegative: bool = False) -> float:
    """A finite float of magnitude at most LIMIT (and at least 1/LIMIT when positive)."""
    if isinstance(value, bool) or not isinstance(value, (int, float)):
        hint = ""
        if isinstance(value, str):
            try:
                float(value)
                hint = " (YAML reads numbers such as 1e-3 or 1.0e3 as text: write 1.0e-3, 1.0e+3)"
            except ValueError:
                pass
        shown = repr(value) if len(repr(value)) <= 40 else repr(value)[:37] + "..."
        raise ConfigError(source, field, f"expected a number, got {kind_of(value)} {shown}{hint}")
    try:
        x = float(value)
    except OverflowError:
        x = math.inf
    if not math.isfinite(x) or abs(x) > LIMIT:
        raise ConfigError(source, field, f"must be finite and at most {LIMIT:g} in magnitude, got {short(value)}")
    if positive and x <= 0:
        raise ConfigError(source, field, f"must be positive, got {short(value)}")
    if positive and x < 1.0 / LIMIT:
        raise ConfigError(source, field, f"must be at least {1.0 / LIMIT:g}, got {short(value)}")
    if nonnegative and x < 0:
        raise ConfigError(source, field, f"must not be negative, got {short(value)}")
    return x


def integer(value: Any, source: str, field: str, lo: int, hi: int) -> int:
    """A YAML integer (not a boolean, not a float) in [lo, hi]."""
    if isinstance(value, bool) or not isinstance(value, int):
        raise ConfigError(source, field, f"expected an integer, got {kind_of(value)} {short(value)}")
    if not lo <= value <= hi:
        raise ConfigError(source, field, f"must be between {lo} and {hi}, got {short(value)}")
    return value


def short(value: Any) -> str:
    text = repr(value)
    return text if len(text) <= 40 else text[:37] + "..."


def name_field(data: Mapping, source: str) -> str:
    if "name" not in data:
        raise ConfigError(source, "name", "missing")
    name = data["name"]
    if isinstance(name, bool) or not isinstance(name, (str, int, float)):
        raise ConfigError(source, "name", f"expected a string, got {kind_of(name)}")
    name = str(name)
    try:
        name.encode("utf-8")
    except UnicodeEncodeError:
        raise ConfigError(source, "name", f"{name!r} is not valid text") from None
    if (not name or name.strip() != name or not name.isprintable() or any(c in name for c in '/\\:*?"<>|')
            or name in (".", "..") or len(name) > 100):
        raise ConfigError(source, "name", f"{short(name)} is not usable as a folder name")
    return name


def point(value: Any, source: str, field: str) -> tuple[float, float]:
    """A point [x, y] of two numbers."""
    if not isinstance(value, list) or len(value) != 2:
        raise ConfigError(source, field, f"expected a point [x, y], got {kind_of(value)} {short(value)}")
    return (number(value[0], source, f"{field}[0]"), number(value[1], source, f"{field}[1]"))


PHI_LIMIT = 1e6  # degrees: beyond, a float angle has no resolution left for the box tests


def orientations(data: Mapping, source: str) -> tuple[tuple[float, float], str]:
    """A platform's orientation range in degrees from `phi: X` or `phi_range: [phi1, phi2]` (exactly
    one of them; phi1 <= phi2), and the key it came from."""
    if ("phi" in data) == ("phi_range" in data):
        raise ConfigError(source, "phi", "give exactly one of 'phi' (degrees) or 'phi_range: [phi1, phi2]'")
    if "phi" in data:
        phi = number(data["phi"], source, "phi")
        phi_range, field = (phi, phi), "phi"
    else:
        raw = data["phi_range"]
        if not isinstance(raw, list) or len(raw) != 2:
            raise ConfigError(source, "phi_range", f"expected a list [phi1, phi2], got {raw!r}")
        phi_range = (number(raw[0], source, "phi_range[0]"), number(raw[1], source, "phi_range[1]"))
        field = "phi_range"
        if phi_range[0] > phi_range[1]:
            raise ConfigError(source, field, f"phi1 must not exceed phi2, got {list(phi_range)}")
    if max(abs(p) for p in phi_range) > PHI_LIMIT:
        raise ConfigError(source, field, f"orientations must be within +-{PHI_LIMIT:g} degrees")
    return phi_range, field


def distinct_points(points, source: str, field: str, letter: str) -> None:
    """ConfigError when two of the points coincide (to a relative 1e-12), naming them `<letter>i`."""
    scale = max(abs(v) for p in points for v in p) or 1.0
    for i in range(len(points)):
        for j in range(i + 1, len(points)):
            if math.dist(points[i], points[j]) <= 1e-12 * scale:
                raise ConfigError(source, field, f"{letter}{i + 1} and {letter}{j + 1} coincide")
