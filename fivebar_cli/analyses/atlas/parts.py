"""The files of an atlas: finished batches under `OUT/atlas.parts/`, then `OUT/atlas.csv`.

`atlas.parts/manifest.json` ties the folder to one atlas (a hash of its grid, depth, tolerance,
batch size, columns, budget and fivebar's version) and holds the SHA-256 of every part written;
`part-NNNNNNNN.csv` holds the rows of batch N, with the header of `atlas.csv`. Each file is written
atomically, so a killed run leaves whole parts (and possibly the atomic writer's `.tmp` files); a
rerun keeps every part that is whole, belongs to this atlas and matches its checksum (a part edited
by hand, or written after the manifest was last saved, is computed again with a warning).
`atlas.csv` is written once, atomically, from the parts in batch order, so its bytes depend only on
the spec. Layout: docs/formats.md, "Atlas parts".
"""

from __future__ import annotations

import hashlib
import json
import time
import warnings
from pathlib import Path

from fivebar_cli.version import __version__
from fivebar_cli.analyses.aspects import DEFAULT_BUDGET
from fivebar_cli.analyses.atlas.metrics import columns
from fivebar_cli.analyses.atlas.spec import AtlasSpec
from fivebar_cli.errors import FivebarWarning, InputError, deferred_interrupts, param
from fivebar_cli.io.files import ensure_dir, format_value, write_csv, write_text

PARTS = "atlas.parts"
MANIFEST = "manifest.json"
FORMAT = "fivebar-atlas-parts 1"
SAVE_SHARE = 0.05  # the manifest is saved after every part unless that would take more than this share of the time


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
        self.checksums: dict[str, str] = {}  # part name -> SHA-256, as saved in the manifest's `parts`
        self.saved = 0.0  # when the manifest was last saved (time.monotonic)
        self.save_seconds = 0.0  # how long that took

    def path(self, index: int) -> Path:
        return self.folder / f"part-{index:08d}.csv"

    def open(self, restart: bool = False) -> None:
        """Check the manifest, or start afresh: with `restart`, or when there is no manifest (parts
        without one are not known to belong to this atlas). Parts of another atlas are refused."""
        ensure_dir(self.folder)
        path = self.folder / MANIFEST
        if path.exists() and not restart:
            try:
                old = json.loads(path.read_text(encoding="utf-8"))
                key, checksums = old.get("key"), old.get("parts", {})
            except (OSError, ValueError, AttributeError):
                key, checksums = None, {}
            if key == self.manifest["key"]:
                self.checksums = {k: v for k, v in checksums.items() if isinstance(k, str) and isinstance(v, str)}
                return
            raise InputError(str(self.folder), "", "holds the parts of another atlas (other lengths, depth, batch, "
                             "columns or fivebar version): rerun with " + param("restart", True)
                             + " to discard them, or choose another " + param("folder"))
        path.unlink(missing_ok=True)  # first: a run killed below then leaves no manifest, so no stale part is kept
        for stale in self.folder.glob("part-*.csv"):
            stale.unlink()
        self.save()

    def save(self) -> None:
        """Write the manifest with the checksums of the parts written so far (never half-way)."""
        start = time.monotonic()
        with deferred_interrupts():
            write_text(self.folder / MANIFEST,
                       json.dumps({**self.manifest, "parts": self.checksums}, indent=1, sort_keys=True) + "\n")
        self.saved = time.monotonic()
        self.save_seconds = self.saved - start

    def done(self) -> set[int]:
        """The batches whose part is whole (the expected header, one row per design, the designs'
        lengths) and matches its checksum; a part that is there but fails is named in a warning."""
        found, failed = set(), []
        for index in range(batch_count(self.spec)):
            if not self.path(index).exists():
                continue
            if self._whole(index):
                found.add(index)
            else:
                failed.append(self.path(index).name)
        if failed:
            shown = ", ".join(failed[:3]) + (f" and {len(failed) - 3} more" if len(failed) > 3 else "")
            warnings.warn(FivebarWarning(
                f"{self.folder}: {shown} {'is' if len(failed) == 1 else 'are'} not whole or not "
                "the part the manifest's checksum names (cut short, edited, or written after the manifest was last "
                "saved): computed again"))
        return found

    def _whole(self, index: int) -> bool:
        try:
            data = self.path(index).read_bytes()
            text = data.decode("utf-8")
        except (OSError, UnicodeDecodeError):
            return False
        if self.checksums.get(self.path(index).name) != hashlib.sha256(data).hexdigest():
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
        """A finished batch: its checksum in the manifest, then its part (a kill between the two
        leaves a checksum without a part: the batch is simply missing). The manifest is saved
        before every part, unless saving it (it grows with the parts) would cost more than
        SAVE_SHARE of the run's time: then once per that much time (and by `save` when the run
        stops), and a kill may leave parts without a checksum, computed again by the next run."""
        self.checksums[self.path(index).name] = hashlib.sha256(text.encode("utf-8")).hexdigest()
        if time.monotonic() - self.saved >= self.save_seconds / SAVE_SHARE:
            self.save()
        return write_text(self.path(index), text)

    def table(self) -> tuple[tuple[str, ...], tuple[tuple[str, ...], ...]]:
        """`atlas.csv` as (columns, rows of text cells, as written): every part's rows in batch order."""
        rows = []
        for index in range(batch_count(self.spec)):
            lines = self.path(index).read_text(encoding="utf-8").split("\n")[1:-1]
            rows += [tuple(line.split(",")) for line in lines]
        return tuple(self.header.split(",")), tuple(rows)

    def assemble(self, target: Path) -> Path:
        """`atlas.csv` (atomically): the header, then every part's rows in batch order."""
        return write_csv(target, *self.table())
