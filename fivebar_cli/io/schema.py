"""Reading mechanism files: strict YAML, and the field checks every mechanism schema is built from.

Every problem is reported as a `ConfigError` naming the file, the field and what is wrong, so the
CLI can print one line and exit with status 2. Unknown keys are errors, not ignored: a typo such
as `lenghts:` must not silently fall back to defaults. A plain scalar that YAML 1.1 (PyYAML) and
YAML 1.2 read differently (`1:2` is 62 in 1.1, `yes` is true, `017` is 15, `1e-3` is text; in 1.2
they are text, text, 17 and 0.001) is refused with its field named: a file means one thing, whatever
YAML library reads it. The schemas themselves belong to the mechanism kinds
(`fivebar_cli/mechanisms/*/model.py`); docs/formats.md lists them.
"""

from __future__ import annotations

import math
import numbers
import re
from dataclasses import dataclass
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
    _refuse_ambiguous(data, source, "")
    return data


@dataclass(frozen=True)
class Ambiguous:
    """A plain scalar that YAML 1.1 and YAML 1.2 read differently (`read_yaml` refuses it)."""

    text: str
    yaml11: Any
    yaml12: Any

    def message(self) -> str:
        return (f"{self.text} is {_reading(self.yaml11)} in YAML 1.1 but {_reading(self.yaml12)} in YAML 1.2: write "
                "it so that both read the same (a plain decimal number such as 62 or 0.001, true or false, or "
                "quoted text)")


def _reading(value: Any) -> str:
    if value is None:
        return "null"
    if isinstance(value, bool):
        return "the boolean " + ("true" if value else "false")
    if isinstance(value, (int, float)):
        return f"the number {value!r}"
    if isinstance(value, str):
        return f"the text {value!r}"
    return f"a {type(value).__name__}"


# YAML 1.2 core schema (https://yaml.org/spec/1.2.2/#1032-tag-resolution)
_CORE = (
    (re.compile(r"(?:~|null|Null|NULL|)\Z"), lambda t: None),
    (re.compile(r"(?:true|True|TRUE)\Z"), lambda t: True),
    (re.compile(r"(?:false|False|FALSE)\Z"), lambda t: False),
    (re.compile(r"[-+]?[0-9]+\Z"), int),
    (re.compile(r"0o[0-7]+\Z"), lambda t: int(t[2:], 8)),
    (re.compile(r"0x[0-9a-fA-F]+\Z"), lambda t: int(t[2:], 16)),
    (re.compile(r"[-+]?(?:\.[0-9]+|[0-9]+(?:\.[0-9]*)?)(?:[eE][-+]?[0-9]+)?\Z"), float),
    (re.compile(r"[-+]?\.(?:inf|Inf|INF)\Z"), lambda t: -math.inf if t.startswith("-") else math.inf),
    (re.compile(r"\.(?:nan|NaN|NAN)\Z"), lambda t: math.nan),
)


def yaml12(text: str) -> Any:
    """What YAML 1.2's core schema reads a plain scalar as."""
    for pattern, value in _CORE:
        if pattern.match(text):
            try:
                return value(text)
            except (ValueError, OverflowError):  # beyond Python's digit limit: as good as infinite
                return math.inf
    return text


def _same(a: Any, b: Any) -> bool:
    if type(a) is not type(b) and not (isinstance(a, float) and isinstance(b, float)):
        return False
    if isinstance(a, float) and math.isnan(a):
        return math.isnan(b)
    return a == b


def _refuse_ambiguous(value: Any, source: str, field: str) -> None:
    """ConfigError at the first Ambiguous scalar (key or value), naming its field."""
    if isinstance(value, Ambiguous):
        raise ConfigError(source, field or "YAML", value.message())
    if isinstance(value, dict):
        for key, item in value.items():
            prefix = f"{field}." if field else ""
            if isinstance(key, Ambiguous):
                raise ConfigError(source, prefix + key.text, f"the key {key.message()}")
            name = field_name(prefix, key)
            _refuse_ambiguous(item, source, name)
    elif isinstance(value, list):
        for i, item in enumerate(value):
            _refuse_ambiguous(item, source, f"{field}[{i}]")


def _strict_loader():
    """PyYAML's safe loader (YAML 1.1), refusing duplicate keys (the last one would silently win),
    and marking the plain scalars that YAML 1.2 reads differently (`Ambiguous`)."""
    import yaml

    class StrictLoader(yaml.SafeLoader):
        def _checked(self, node, value):
            if node.style is not None or not isinstance(node, yaml.ScalarNode):
                return value  # quoted or block scalars are text in both
            other = yaml12(node.value)
            return value if _same(value, other) else Ambiguous(node.value, value, other)

        def construct_yaml_int(self, node):  # beyond Python's digit limit: as good as infinite
            try:
                value = super().construct_yaml_int(node)
            except ValueError:
                value = math.inf
            return value if value == math.inf and yaml12(node.value) == math.inf else self._checked(node, value)

        def construct_yaml_float(self, node):
            return self._checked(node, super().construct_yaml_float(node))

        def construct_yaml_bool(self, node):
            return self._checked(node, super().construct_yaml_bool(node))

        def construct_yaml_null(self, node):
            return self._checked(node, super().construct_yaml_null(node))

        def construct_yaml_timestamp(self, node):
            return self._checked(node, super().construct_yaml_timestamp(node))

        def construct_yaml_str(self, node):
            return self._checked(node, super().construct_yaml_str(node))

        def construct_mapping(self, node, deep=False):
            keys = [k.value for k, _ in node.value if isinstance(k, yaml.ScalarNode)]
            for index, key_node in enumerate(k for k, _ in node.value if isinstance(k, yaml.ScalarNode)):
                if key_node.value in keys[:index]:
                    raise yaml.constructor.ConstructorError(
                        None, None, f"duplicate key {key_node.value!r}", key_node.start_mark)
            return super().construct_mapping(node, deep=deep)

    for tag in ("int", "float", "bool", "null", "timestamp", "str"):
        StrictLoader.add_constructor(f"tag:yaml.org,2002:{tag}", getattr(StrictLoader, f"construct_yaml_{tag}"))
    return StrictLoader


# ---------------------------------------------------------------- field helpers

LIMIT = 1e50  # magnitude bound on every number: products of a few lengths (and their squares) stay finite
MAX_NAME_BYTES = 255  # a folder name's limit on Linux and macOS file systems


def field_name(prefix: str, key: object) -> str:
    """A key as it appears in a message: printable, on one line."""
    text = key if isinstance(key, str) and key.isprintable() else repr(key)
    return f"{prefix}{text}"


def kind_of(value: Any) -> str:
    if value is None:
        return "an empty value"
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


def is_number(value: Any) -> bool:
    """A real number of Python or numpy, not a boolean (Python's or numpy's, a real number to
    `numbers` but a yes or no to a user)."""
    return not (isinstance(value, bool) or type(value).__name__ == "bool_") and isinstance(value, numbers.Real)


def number(value: Any, source: str, field: str, *, positive: bool = False, nonnegative: bool = False) -> float:
    """A finite float of magnitude at most LIMIT (and at least 1/LIMIT when positive); any real
    number of Python or numpy (built from Python, a model takes numpy floats too), not a boolean."""
    if value is None:
        raise ConfigError(source, field, "expected a number, got an empty value")
    if not is_number(value):
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
    if len(name.encode("utf-8")) > MAX_NAME_BYTES:
        raise ConfigError(source, "name", f"{short(name)} is too long for a folder name ({len(name.encode())} bytes "
                          f"in UTF-8, at most {MAX_NAME_BYTES})")
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
