"""Running an atlas: the designs cut into batches (contiguous index ranges), the batches not yet
done handed to a runner, each result persisted as it arrives, then `atlas.csv` assembled.

A runner takes `(task, spec, indices)` and yields `(index, task(spec, index))` in any order:
`in_process` here (`--workers 0`), or the Dask runners of `cluster.py`. `batch_text` is the task:
a pure function of the spec and the batch index, so the bytes of a part, and of `atlas.csv`, do
not depend on where or in which order batches run.
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path
from typing import Callable, Iterable, Iterator

from fivebar_cli.analyses.atlas.metrics import columns, row
from fivebar_cli.analyses.atlas.parts import Parts, batch_count, batch_span
from fivebar_cli.analyses.atlas.spec import AtlasSpec
from fivebar_cli.errors import FivebarError, Interrupted, Text
from fivebar_cli.io.files import csv_text
from fivebar_cli.io.layout import ATLAS_CSV

Task = Callable[[AtlasSpec, int], str]
Runner = Callable[[Task, AtlasSpec, list], Iterable[tuple[int, str]]]


def batch_text(spec: AtlasSpec, index: int) -> str:
    """The part of batch `index`: the header and one row per design (what a worker computes)."""
    rows = []
    for design in batch_span(spec, index):
        lengths = spec.design(design)
        try:
            rows.append(row(lengths, spec.depth, spec.tolerance, spec.constraints))
        except Interrupted:
            raise
        except Exception as exc:  # name the design; plain FivebarError: it must cross process boundaries
            shown = " ".join(f"L{k}={v!r}" for k, v in enumerate(lengths))
            said = exc.args[0] if len(exc.args) == 1 and isinstance(exc.args[0], Text) else str(exc)
            raise FivebarError(f"design {design} ({shown}): {type(exc).__name__}: " + said) from None  # a Text stays one
    return csv_text(columns(spec.tolerance), rows)


def in_process(task: Task, spec: AtlasSpec, indices: list) -> Iterator[tuple[int, str]]:
    """Run the batches one after another in this process (no Dask)."""
    for index in indices:
        yield index, task(spec, index)


@dataclass
class Plan:
    """What a run has to do: the batches missing from `atlas.parts/`."""

    spec: AtlasSpec
    folder: Path
    parts: Parts
    todo: list[int]

    @property
    def batches(self) -> int:
        return batch_count(self.spec)

    @property
    def designs_todo(self) -> int:
        return sum(len(batch_span(self.spec, i)) for i in self.todo)


def plan_atlas(spec: AtlasSpec, folder: Path, restart: bool = False) -> Plan:
    """Open (or start) `folder/atlas.parts/` and list the batches still to compute."""
    parts = Parts(folder, spec)
    parts.open(restart)
    done = parts.done()
    return Plan(spec, Path(folder), parts, [i for i in range(batch_count(spec)) if i not in done])


def compute_plan(plan: Plan, runner: Runner = in_process, advance=lambda n=1: None) -> None:
    """Compute the missing batches, persisting each as it finishes (and, whatever stops the run,
    the manifest with the checksums of the parts written)."""
    try:
        for index, text in runner(batch_text, plan.spec, plan.todo):
            plan.parts.write(index, text)
            advance(len(batch_span(plan.spec, index)))
    finally:
        plan.parts.save()


def run_plan(plan: Plan, runner: Runner = in_process, advance=lambda n=1: None) -> Path:
    """Compute the missing batches, then write `atlas.csv`."""
    compute_plan(plan, runner, advance)
    return plan.parts.assemble(plan.folder / ATLAS_CSV)
