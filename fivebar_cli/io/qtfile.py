"""The `.qt` quadtree text format, version 1 (docs/formats.md): header lines, then the B/W/G body.

```
# fivebar-quadtree 1
# name: M1
# space: workspace
# region: reachable
# colour: inside
# root: -13.0 13.0 -13.0 13.0
# depth: 10
# periodic: none
GGBWB...            (preorder body, wrapped at 64 letters per line)
```
The reader is strict about what it needs (magic line, root, depth, periodic, a well-formed body)
and names the line of any problem; it keeps unknown `# key: value` lines so a round trip is lossless.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from pathlib import Path

from fivebar_cli.errors import InputError
from fivebar_cli.io.files import read_user_text, write_text
from fivebar_cli.paving.grid import MAX_INDEX_BITS, Grid
from fivebar_cli.paving.tree import BodyError, Tree

MAGIC = "# fivebar-quadtree 1"
WRAP = 64
STANDARD_KEYS = ("name", "space", "region", "colour", "root", "depth", "periodic")


@dataclass(frozen=True)
class QtFile:
    """A tree with its header fields (ordered; root, depth and periodic are derived from the tree)."""

    tree: Tree
    fields: dict[str, str] = field(default_factory=dict)

    def get(self, key: str, default: str = "") -> str:
        return self.fields.get(key, default)


def valid_key(key: str) -> bool:
    """Header keys: printable, without spaces or ':' (the reader and the writer agree, so round trips hold)."""
    return bool(key) and key.isprintable() and ":" not in key and not any(c.isspace() for c in key)


def format_qt(tree: Tree, /, **fields: object) -> str:
    """The file text for `tree`; `fields` are header keys (name, space, region, colour, extras)."""
    grid = tree.grid
    values = {k: str(v) for k, v in fields.items() if v is not None}
    values["root"] = " ".join(repr(float(v)) for r in grid.root for v in r)
    values["depth"] = str(grid.depth)
    axes = [str(i) for i, wrap in enumerate(grid.periodic) if wrap]
    values["periodic"] = " ".join(axes) if axes else "none"
    order = [k for k in STANDARD_KEYS if k in values] + [k for k in values if k not in STANDARD_KEYS]
    lines = [MAGIC]
    for key in order:
        value = values[key]
        if "\n" in value or "\r" in value or not valid_key(key):
            raise ValueError(f"bad header field {key!r}: {value!r}")
        lines.append(f"# {key}: {value}")
    body = tree.to_bwg()
    lines += [body[i:i + WRAP] for i in range(0, len(body), WRAP)]
    return "\n".join(lines) + "\n"


def write_qt(path: str | Path, tree: Tree, /, **fields: object) -> Path:
    """Atomically write a `.qt` file."""
    return write_text(path, format_qt(tree, **fields))


def read_qt(path: str | Path) -> QtFile:
    """Read and validate a `.qt` file; raises InputError naming the file and line."""
    source = str(path)
    text = read_user_text(path, InputError, "a fivebar quadtree file")
    return parse_qt(text, source)


def parse_qt(text: str, source: str = "<qt>") -> QtFile:
    lines = text.split("\n")
    if lines and lines[-1] == "":
        lines.pop()
    lines = [ln.rstrip("\r") for ln in lines]
    if not lines:
        raise InputError(source, "line 1", "empty file (expected '# fivebar-quadtree 1')")
    first = lines[0].strip()
    if first != MAGIC:
        if first.startswith("# fivebar-quadtree "):
            raise InputError(source, "line 1", f"unsupported format version {first.split()[-1]!r} (this reader knows 1)")
        raise InputError(source, "line 1", "not a fivebar quadtree file (expected '# fivebar-quadtree 1')")
    fields: dict[str, str] = {}
    n = 1
    while n < len(lines) and lines[n].startswith("#"):
        line = lines[n]
        key, sep, value = line[1:].strip().partition(":")
        key = key.strip()
        if not sep or not valid_key(key):
            raise InputError(source, f"line {n + 1}", f"malformed header line {line!r} (expected '# key: value')")
        if key in fields:
            raise InputError(source, f"line {n + 1}", f"duplicate header key {key!r}")
        fields[key] = value.strip()
        n += 1
    grid = _grid(fields, source, lines)
    body_lines = lines[n:]
    for i, line in enumerate(body_lines):
        if line.strip() == "" and i < len(body_lines) - 1:
            raise InputError(source, f"line {n + i + 1}", "blank line inside the tree body")
    body = "".join(line.strip() for line in body_lines)
    if not body:
        raise InputError(source, f"line {n + 1}", "missing tree body (expected B/W/G letters)")
    try:
        tree = Tree.from_bwg(grid, body)
    except BodyError as exc:
        raise InputError(source, _body_line(body_lines, n, exc.position), str(exc)) from None
    for key in ("root", "depth", "periodic"):
        fields.pop(key)
    return QtFile(tree, fields)


def _body_line(body_lines: list[str], first: int, position: int) -> str:
    """'line N' of the body letter at `position` (past the end: the last line)."""
    seen = 0
    for i, line in enumerate(body_lines):
        seen += len(line.strip())
        if position < seen:
            return f"line {first + i + 1}"
    return f"line {first + len(body_lines)}"


def _grid(fields: dict[str, str], source: str, lines: list[str]) -> Grid:
    def line_of(key: str) -> str:
        for i, line in enumerate(lines):
            if line.startswith("#") and line[1:].strip().partition(":")[0].strip() == key:
                return f"line {i + 1} ({key})"
        return key

    for key in ("root", "depth", "periodic"):
        if key not in fields:
            raise InputError(source, key, f"missing header line '# {key}: ...'")
    try:
        bounds = [float(v) for v in fields["root"].split()]
    except ValueError:
        raise InputError(source, line_of("root"), f"expected numbers, got {fields['root']!r}") from None
    if len(bounds) not in (4, 6):
        raise InputError(source, line_of("root"), f"expected 4 (quadtree) or 6 (octree) numbers, got {len(bounds)}")
    root = tuple((bounds[i], bounds[i + 1]) for i in range(0, len(bounds), 2))
    for lo, hi in root:
        if not (math.isfinite(lo) and math.isfinite(hi) and lo < hi):
            raise InputError(source, line_of("root"), f"each axis needs finite lo < hi, got [{lo}, {hi}]")
    dim = len(root)
    try:
        depth = int(fields["depth"])
    except ValueError:
        raise InputError(source, line_of("depth"), f"expected an integer, got {fields['depth']!r}") from None
    if not 0 <= depth <= MAX_INDEX_BITS // dim:
        raise InputError(source, line_of("depth"), f"must be between 0 and {MAX_INDEX_BITS // dim}, got {depth}")
    text = fields["periodic"].strip()
    periodic = [False] * dim
    if text != "none":
        for token in text.split():
            if not (token.isascii() and token.isdigit()) or int(token) >= dim:
                raise InputError(source, line_of("periodic"), f"expected 'none' or axis numbers below {dim}, got {text!r}")
            periodic[int(token)] = True
    return Grid(root, depth, tuple(periodic))
