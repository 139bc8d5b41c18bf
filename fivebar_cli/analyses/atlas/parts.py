"""The files of an atlas: finished batches under `OUT/atlas.parts/`, then `OUT/atlas.csv`.

`atlas.parts/manifest.json` ties the folder to one atlas (a hash of its grid, depth, tolerance,
batch size, columns, budget and fivebar's version); `part-NNNNNNNN.csv` holds the rows of batch N,
with the header of `atlas.csv`. Each file is written atomically, so a killed run leaves whole parts
(and possibly the atomic writer's `.tmp` files); a rerun keeps every part that is whole and
belongs to this atlas. `atlas.csv` is written once, atomically, from the parts in batch order, so
its bytes depend only on the spec. Layout: docs/formats.md, "Atlas parts".
"""

from __future__ import annotations

import hashlib
import json
import os
from pathlib import Path

from fivebar_cli import __version__
from fivebar_cli.analyses.aspects import DEFAULT_BUDGET
from fivebar_cli.analyses.atlas.metrics import columns
from fivebar_cli.analyses.atlas.spec import AtlasSpec
from fivebar_cli.errors import InputError
from fivebar_cli.io.files import atomic_write, ensure_dir, format_value, write_text

PARTS = "atlas.parts"
MANIFEST = "manifest.json"
ATLAS_CSV = "atlas.csv"
FORMAT = "fivebar-atlas-parts 1"


def manifest(spec: AtlasSpec) -> dict:
    """What the parts depend on, and its hash (`key`). The name is left out: renaming a spec keeps its parts."""
    content = {
        "format": FORMAT,
        "version": __version__,
        "lengths": [[repr(v) for v in values] for values in spec.grid],
        "depth": spec.depth,
        "tolerance": repr(spec.tolerance),
        "budget": DEFAULT_BUDGET,
        "batch": spec.batch_size,
        "columns": list(columns(spec.tolerance)),
    }
    if spec.constraints:  # only then: the keys of atlases without constraints stay as they were
        content["constraints"] = spec.constraints.words()
    key = hashlib.sha256(json.dumps(content, sort_keys=True).encode()).hexdigest()
    return {**content, "key": key, "designs": spec.size, "batches": batch_count(spec)}


def batch_count(spec: AtlasSpec) -> int:
    return -(-spec.size // spec.batch_size)


def batch_span(spec: AtlasSpec, index: int) -> range:
    """The design indices of batch `index`: contiguous, in grid order."""
    start = index * spec.batch_size
    return range(start, min(start + spec.batch_size, spec.size))


class Parts:
    """The `atlas.parts/` folder of one atlas: which batches are done, writing them, assembling."""

    def __init__(self, folder: Path, spec: AtlasSpec):
        self.folder = Path(folder) / PARTS
        self.spec = spec
        self.manifest = manifest(spec)
        self.header = ",".join(columns(spec.tolerance))

    def path(self, index: int) -> Path:
        return self.folder / f"part-{index:08d}.csv"

    def open(self, restart: bool = False) -> None:
        """Check the manifest, or start afresh: with `restart`, or when there is no manifest (parts
        without one are not known to belong to this atlas). Parts of another atlas are refused."""
        ensure_dir(self.folder)
        path = self.folder / MANIFEST
        if path.exists() and not restart:
            try:
                old = json.loads(path.read_text(encoding="utf-8")).get("key")
            except (OSError, ValueError, AttributeError):
                old = None
            if old == self.manifest["key"]:
                return
            raise InputError(str(self.folder), "", "holds the parts of another atlas (other lengths, depth, batch, "
                             "columns or fivebar version): rerun with --restart to discard them, or choose another -o")
        path.unlink(missing_ok=True)  # first: a run killed below then leaves no manifest, so no stale part is kept
        for stale in self.folder.glob("part-*.csv"):
            stale.unlink()
        write_text(path, json.dumps(self.manifest, indent=1, sort_keys=True) + "\n")

    def done(self) -> set[int]:
        """The batches whose part is whole: the expected header, one row per design, the designs' lengths."""
        found = set()
        for index in range(batch_count(self.spec)):
            if self.path(index).exists() and self._whole(index):
                found.add(index)
        return found

    def _whole(self, index: int) -> bool:
        try:
            text = self.path(index).read_text(encoding="utf-8")
        except (OSError, UnicodeDecodeError):
            return False
        lines = text.split("\n")
        span = batch_span(self.spec, index)
        if not text.endswith("\n") or lines[0] != self.header or len(lines) != len(span) + 2:
            return False
        width = self.header.count(",")
        for design, line in zip(span, lines[1:]):
            lengths = ",".join(format_value(v) for v in self.spec.design(design))
            if line.count(",") != width or not line.startswith(lengths + ","):
                return False
        return True

    def write(self, index: int, text: str) -> Path:
        return write_text(self.path(index), text)

    def assemble(self, target: Path) -> Path:
        """`atlas.csv`: the header, then every part's rows in batch order (atomically, streamed)."""

        def write(tmp: Path) -> None:
            with open(tmp, "wb") as out:
                out.write((self.header + "\n").encode())
                for index in range(batch_count(self.spec)):
                    data = self.path(index).read_bytes()
                    out.write(data[data.index(b"\n") + 1:])
                out.flush()
                os.fsync(out.fileno())

        return atomic_write(target, write)


def read_table(path: Path) -> dict[str, list[str]]:
    """`atlas.csv` as columns of text cells (header name -> cells in row order)."""
    lines = Path(path).read_text(encoding="utf-8").split("\n")[:-1]
    header = lines[0].split(",")
    cells = list(zip(*(line.split(",") for line in lines[1:]))) or [()] * len(header)
    return {name: list(column) for name, column in zip(header, cells)}
