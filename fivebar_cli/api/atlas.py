"""An atlas of five-bar designs (`fivebar atlas`): the spec with the call's depth and tolerance
(`atlas_spec`), the batches its folder of parts still lacks (`atlas_plan`, an `AtlasPlan`), run in
this process or on Dask (`AtlasPlan.run`), as a `Report` of `atlas.csv` with its heat maps;
`atlas` is plan and run in one call.

A run says what it is doing through `logging` (the logger `fivebar_cli.api.atlas`, level INFO:
the cluster it runs on and the workers connected), the standard library's channel for what a
library tells along the way: silent unless the caller asks (`logging.basicConfig(level="INFO")`),
printed by the command line; its progress goes to `advance`, as every long call's."""

from __future__ import annotations

import logging
from collections.abc import Mapping
from pathlib import Path

from fivebar_cli.analyses.limits import MAX_ASPECT_DEPTH, check_count, check_depth
from fivebar_cli.api.calls import file_or_example
from fivebar_cli.api.values import Drawing, Report
from fivebar_cli.errors import Text, param
from fivebar_cli.io.files import user_path
from fivebar_cli.mechanisms.base import plural

log = logging.getLogger(__name__)


def atlas(spec, folder=None, *, workers: int | None = 0, scheduler: str | None = None, depth: int | None = None,
          tolerance: float | None = None, restart: bool = False, advance=None) -> Report:
    """An atlas of five-bar designs (the `fivebar-atlas` spec: a YAML file, a shipped example's
    name or a mapping): one row per design of the metrics of `atlas.csv` (text cells, as written),
    the lines `fivebar atlas` prints after its run (`notes`) and `save(folder, figures=True)`, its
    files. The parts are kept in `folder` (a temporary folder when None), so a run resumes;
    `workers` local Dask processes (0: in this process; None: one per core), or an existing
    `scheduler` address; `advance(n)`: n more designs done.

    Examples
    --------
    >>> import fivebar_cli as fb
    >>> a = fb.atlas({"type": "fivebar-atlas", "name": "l1", "depth": 3,
    ...               "lengths": {"L0": 9, "L1": [7, 8, 2], "L2": 5, "L3": 5, "L4": 8}})
    >>> a.column("assemblable")
    ['true', 'true']
    """
    import tempfile
    from contextlib import nullcontext

    # (checked before the plan starts a folder of parts: `run` checks it again, for its own callers)
    workers = check_count(workers, "workers", 0, none="0: in this process; None: one per core")
    with (tempfile.TemporaryDirectory() if folder is None else nullcontext(user_path(folder, "folder"))) as where:
        plan = atlas_plan(spec, where, depth=depth, tolerance=tolerance, restart=restart)
        return plan.run(workers=workers, scheduler=scheduler, advance=advance)


def atlas_spec(spec, depth: int | None = None, tolerance: float | None = None):
    """An atlas spec (`fivebar-atlas`: a YAML file, a mapping or an `AtlasSpec`) with `depth` and
    `tolerance`, when given, in place of its own; InputError for a depth out of range or a
    tolerance that would make a length reach 0."""
    import dataclasses

    from fivebar_cli.analyses.atlas.spec import AtlasSpec, check_tolerance, parse_spec, read_spec

    s = spec if isinstance(spec, AtlasSpec) else parse_spec(dict(spec), "<mapping>") if isinstance(spec, Mapping) \
        else read_spec(file_or_example(spec, "spec", "a spec file, an example's name, a mapping or an AtlasSpec"))
    if depth is not None:
        s = dataclasses.replace(s, depth=check_depth(depth, MAX_ASPECT_DEPTH))
    if tolerance is not None:
        source = str(spec) if isinstance(spec, (str, Path)) else s.name
        s = dataclasses.replace(s, tolerance=check_tolerance(tolerance, s.grid, source, param("tolerance")))
    return s


def atlas_plan(spec, folder, *, depth: int | None = None, tolerance: float | None = None,
               restart: bool = False) -> "AtlasPlan":
    """The plan of an atlas run in `folder`: its spec (`atlas_spec`), and the batches its parts
    (`folder/atlas.parts/`, started here when missing or with `restart`) do not hold yet."""
    from fivebar_cli.analyses.atlas.engine import plan_atlas

    return AtlasPlan(plan_atlas(atlas_spec(spec, depth, tolerance), user_path(folder, "folder"), restart))


class AtlasPlan:
    """What an atlas run has to do: `spec`, `batches`, the batches done by earlier runs
    (`batches_done`) and the designs left (`designs_todo`); `summary`, the line `fivebar atlas`
    starts with; `run` computes what is left."""

    def __init__(self, plan):
        self._plan = plan  # the engine's plan (analyses.atlas.engine.Plan), with the open parts

    @property
    def spec(self):
        return self._plan.spec

    @property
    def batches(self) -> int:
        return self._plan.batches

    @property
    def batches_done(self) -> int:
        return self._plan.batches - len(self._plan.todo)

    @property
    def designs_todo(self) -> int:
        return self._plan.designs_todo

    @property
    def summary(self) -> str:
        s = self.spec
        robust = f", tolerance {s.tolerance:g}" if s.tolerance > 0 else ""
        return (f"{s.name}: {plural(s.size, 'design')} at depth {s.depth}{robust}, "
                f"{plural(self.batches, 'batch', 'batches')} of {s.batch_size}: {self.batches_done} done before, "
                f"{len(self._plan.todo)} to compute")

    def __repr__(self) -> str:
        return f"<AtlasPlan {self.summary}>"

    def run(self, *, workers: int | None = 0, scheduler: str | None = None, advance=None) -> Report:
        """Compute the batches left (each part kept as it finishes) and read the whole atlas: in this
        process (`workers=0`), on a local Dask cluster of `workers` processes (None: one per core) or
        on the cluster at `scheduler`; `advance(n)`: n more designs done."""
        from fivebar_cli.analyses.atlas.engine import compute_plan, in_process

        workers = check_count(workers, "workers", 0, none="0: in this process; None: one per core")
        plan = self._plan
        with atlas_runner(workers, scheduler, len(plan.todo)) as runner:
            if plan.todo and runner is not in_process:
                connected = runner.workers
                log.info("on %s (%s)", runner.where, plural(connected, "worker") + " connected"
                         + (": the batches wait for workers" if connected == 0 else ""))
            compute_plan(plan, runner, advance or (lambda n=1: None))
        return _report(plan.spec, *plan.parts.table())


def atlas_runner(workers: int | None, scheduler: str | None, needed: int):
    """The context of an atlas runner: in this process, a local Dask cluster of `workers` processes
    (None: one per core; no more than the `needed` batches), or an existing one."""
    from contextlib import nullcontext

    from fivebar_cli.analyses.atlas.engine import in_process
    from fivebar_cli.analyses.jobs import default_jobs

    if workers is None and scheduler is None:
        workers = default_jobs()
    if scheduler is not None and needed:
        from fivebar_cli.analyses.atlas.cluster import existing_cluster

        return existing_cluster(scheduler)
    if workers and needed:
        from fivebar_cli.analyses.atlas.cluster import local_cluster

        return local_cluster(min(workers, needed))
    return nullcontext(in_process)


def _report(spec, columns: tuple, data: tuple) -> Report:
    """The atlas as `fivebar atlas` writes and summarises it: atlas.csv, atlas.png (heat maps over
    the swept lengths; none when no length is swept) and the counts of designs certified."""
    from fivebar_cli.io.layout import ATLAS_CSV, ATLAS_PNG

    table = dict(zip(columns, zip(*data))) if data else {c: () for c in columns}
    assemblable = table["assemblable"].count("true")
    certified = _certified(table, "certified")
    short = Text(f" (not for {assemblable - certified}: raise ", param("depth"), ")") if certified < assemblable else ""
    notes = [Text(f"  {assemblable} can be assembled; the aspect count is certified for {certified} of them") + short]
    if spec.tolerance > 0:
        notes.append(f"  the robust aspect count (tolerance {spec.tolerance:g}) is certified for "
                     f"{_certified(table, 'robust_certified')} of them")

    from fivebar_cli.plotting.atlas import figure_atlas

    figure = Drawing(figure_atlas, (spec, {c: list(v) for c, v in table.items()}))
    return Report(f"Atlas {spec.name}", columns, data, tuple(notes), ("atlas", (ATLAS_CSV, ATLAS_PNG), "fivebar atlas",
                  ATLAS_CSV), ((ATLAS_PNG, figure),) if spec.swept else ())


def _certified(table: dict, column: str) -> int:
    """Designs that can be assembled and whose count in `column` is certified."""
    return sum(a == "true" and c == "true" for a, c in zip(table["assemblable"], table[column]))
