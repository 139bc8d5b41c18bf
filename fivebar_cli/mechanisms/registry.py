"""The registry of mechanism kinds: YAML `type` -> the class that models it.

Adding a kind inside fivebar: one subpackage under `fivebar_cli/mechanisms/` and one line in
`BUILTIN`. From a third-party package: an entry point in the group `fivebar.mechanisms` whose name
is the YAML `type` and whose object is the class (docs/architecture.md shows both).
"""

from __future__ import annotations

from functools import lru_cache
from importlib import import_module
from pathlib import Path

from fivebar_cli.io.schema import ConfigError, read_yaml
from fivebar_cli.mechanisms.base import Mechanism, article

BUILTIN = {  # type -> "module:Class", imported on first use
    "fivebar": "fivebar_cli.mechanisms.fivebar.model:FiveBar",
    "rpr3": "fivebar_cli.mechanisms.rpr3.model:Rpr3",
    "rpr2": "fivebar_cli.mechanisms.rpr2.model:Rpr2",
    "rrr3": "fivebar_cli.mechanisms.rrr3.model:Rrr3",
}
ENTRY_POINT_GROUP = "fivebar.mechanisms"


@lru_cache(maxsize=None)
def _plugins() -> dict[str, object]:
    from importlib.metadata import entry_points

    return {ep.name: ep for ep in entry_points(group=ENTRY_POINT_GROUP) if ep.name not in BUILTIN}


def kinds() -> list[str]:
    """Every known `type`, built-in first."""
    return list(BUILTIN) + sorted(_plugins())


def is_kind(kind: object) -> bool:
    """Whether `kind` is a known `type` (a built-in kind needs no look at the installed packages'
    entry points: importlib.metadata's import and scan are a tenth of a small analysis's time)."""
    return isinstance(kind, str) and (kind in BUILTIN or kind in kinds())


def kind_class(kind: str) -> type[Mechanism]:
    """The class of a kind (KeyError when unknown)."""
    if kind in BUILTIN:
        module, _, name = BUILTIN[kind].partition(":")
        return getattr(import_module(module), name)
    return _plugins()[kind].load()


def parse(data: dict, source: str) -> Mechanism:
    """A mechanism from the mapping of a YAML file, by its `type`."""
    kind = data.get("type")
    if not is_kind(kind):
        expected = " or ".join(repr(k) for k in kinds())
        if kind is None:
            raise ConfigError(source, "type", f"missing (expected {expected})")
        raise ConfigError(source, "type", f"unknown mechanism type {kind!r} (expected {expected})")
    return kind_class(kind).parse(data, source)


def load_config(path: str | Path, kind: str | None = None, space: str | None = None) -> Mechanism:
    """Read and validate a mechanism file; with `kind` or `space`, require that kind or that space."""
    source = str(path)
    return check_kind(parse(read_yaml(path, source), source), source, kind, space)


def check_kind(mech: Mechanism, source: str, kind: str | None = None, space: str | None = None) -> Mechanism:
    """`mech`, when it is of `kind` and has `space` (each when given); ConfigError otherwise."""
    if kind is not None and mech.kind != kind:
        raise ConfigError(source, "type", f"expected {article(kind)} ('type: {kind}') here, got {mech.kind!r}")
    if space is not None and space not in mech.spaces():
        mech.check_bounded(source)  # (a 3-RPR whose legs are unbounded: why)
        known = ", ".join(mech.spaces()) or "none"
        raise ConfigError(source, "type", f"{article(mech.kind)} has no {space} to pave (its spaces: {known})")
    return mech


def from_description(text: str, name: str, source: str) -> Mechanism:
    """A mechanism from a `.qt` `mechanism:` header line ('<type> key=value ...')."""
    if not text:
        raise ConfigError(source, "mechanism", "missing header line '# mechanism: <type> key=value ...'")
    kind, *words = text.split()
    if kind not in kinds():
        raise ConfigError(source, "mechanism", f"unsupported mechanism {kind!r}")
    fields = {}
    for word in words:
        key, sep, value = word.partition("=")
        if not sep or key in fields:
            raise ConfigError(source, "mechanism", f"bad parameter {word!r}")
        fields[key] = value
    return kind_class(kind).from_description(fields, name, source)
