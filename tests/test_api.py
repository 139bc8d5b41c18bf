"""The public Python API (`import fivebar_cli as fb`, docs/python.md): the names work on M1, M2, a
3-RPR and the 2-RPR and give what the commands give (their files byte for byte, the golden
references, closed forms); results are immutable with one-line reprs; `import fivebar_cli` is
light; plots leave matplotlib's backend alone; the docstrings' examples run."""

from __future__ import annotations

import csv
import dataclasses
import doctest
import io
import math
import subprocess
import sys

import numpy as np
import pytest

import fivebar_cli as fb
from fivebar_cli.io.files import csv_text
from tests.cli_helpers import REPO, ok, run_cli

GOLDEN = REPO / "tests" / "golden"


@pytest.fixture(scope="module")
def m1_aspects():
    return fb.aspects(fb.load("m1"), 10)


def _csv(path) -> list[dict]:
    return list(csv.DictReader(io.StringIO(path.read_text())))


def test_import_is_light_and_fast():
    """`import fivebar_cli` imports neither click, matplotlib, shapely nor dask (nor numpy), quickly."""
    code = ("import sys, time; t = time.perf_counter(); import fivebar_cli; t = time.perf_counter() - t; "
            "print(t, *[m for m in ('click', 'matplotlib', 'shapely', 'dask', 'numpy') if m in sys.modules])")
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True, cwd=REPO).stdout
    seconds, *loaded = out.split()
    assert loaded == [] and float(seconds) < 0.15
    assert set(fb.__all__) <= set(dir(fb))
    assert all(getattr(fb, name) is not None for name in fb.__all__)


def test_load_file_mapping_and_example_agree():
    m = fb.load(REPO / "configs" / "m1.yaml")
    assert fb.load("m1") == m
    assert fb.load({"type": "fivebar", "name": "M1", "lengths": {"L0": 9, "L1": 8, "L2": 5, "L3": 5, "L4": 8}}) == m
    assert set(fb.examples()) >= {"m1", "m2", "rpr2", "rpr3-caro", "rpr3-verify/table1-case1", "atlas-small"}
    with pytest.raises(fb.InputError, match="`tolerance`: an rpr2 has no interval lengths"):
        fb.load("rpr2", tolerance=0.1)
    with pytest.raises(fb.InputError, match="type"):
        fb.load({"type": "nope"})


@pytest.mark.parametrize("name, space", [("M1", "workspace"), ("M2", "workspace")])
def test_pave_equals_the_golden_files(tmp_path, name, space):
    """The paving at depth 10 writes the golden .qt pair and summary byte for byte; its areas bracket
    the closed-form area."""
    p = fb.pave(fb.load(name.lower()), space, 10)
    written = p.save(tmp_path)
    assert sorted(f.name for f in written) == sorted([f"{space}.qt", f"{space}.complement.qt", f"{space}.csv"])
    for f in written:
        assert f.read_bytes() == (GOLDEN / name / f.name).read_bytes()
    row = p.rows()[0]
    assert csv_text(list(row), [list(row.values())]) == (GOLDEN / name / f"{space}.csv").read_text()
    exact = p.mechanism.exact_measure(space)
    assert p.inside_area <= exact <= p.inside_area + p.undetermined_area
    total = float(np.prod(p.inside.grid.size))
    assert math.isclose(p.inside_area + p.outside_area + p.undetermined_area, total)
    deeper = fb.refine(fb.pave(fb.load(name.lower()), space, 8), 10)
    assert deeper.inside_area == p.inside_area and deeper.evaluations < 2 * p.evaluations


def test_aspects_of_m1_equal_the_golden_tables(tmp_path, m1_aspects):
    a = m1_aspects
    assert (a.count, a.certified, a.bounds) == (10, True, (10, 10))
    assert [r["aspect"] for r in a.rows()] == [int(r["aspect"]) for r in _csv(GOLDEN / "M1" / "aspects.csv")]
    a.save(tmp_path)
    for name in ("aspects.csv", "aspects-adjacency.csv"):
        assert (tmp_path / name).read_bytes() == (GOLDEN / "M1" / name).read_bytes()
    for f in (GOLDEN / "M1" / "aspects").iterdir():
        assert (tmp_path / "aspects" / f.name).read_bytes() == f.read_bytes()
    adjacency = _csv(GOLDEN / "M1" / "aspects-adjacency.csv")
    assert a.adjacency == tuple((int(r["aspect_a"]), int(r["aspect_b"]), r["assembly_mode"], r["singularity"])
                                for r in adjacency)
    first = a[0]
    assert first.working_mode in ("++", "+-", "-+", "--") and first.assembly_mode in ("+", "-")
    assert first.workspace_area == first.workspace.area and first.jointspace_area == first.jointspace.area
    x, y, r = first.circle
    assert r > 0 and len(first.pose) == 2 and len(first.joints) == 2


def test_locate_and_path_on_m1(tmp_path, m1_aspects):
    """locate gives the rows of `fivebar locate --csv`; path writes the path.csv `fivebar path` writes."""
    m = fb.load("m1")
    loc = fb.locate(m, pose=(4, 5), depth=10, aspects=m1_aspects)
    cli = ok(run_cli("locate", "configs/m1.yaml", "--pose", "4", "5", "--csv", "-o", str(tmp_path / "none")))
    rows = list(csv.DictReader(io.StringIO(cli.stdout)))
    assert [r["working_mode"] for r in loc.rows()] == [r["working_mode"] for r in rows]
    assert [str(r["aspect"]) for r in loc.rows()] == [r["aspect"] for r in rows]
    p = fb.path(m, {"pose": (4, 5), "working_mode": "++"}, {"pose": (6, 8), "working_mode": "++"}, depth=10)
    assert p.columns == ("theta1", "theta2", "x", "y")
    assert tuple(p.points[0, 2:]) == (4.0, 5.0) and tuple(p.points[-1, 2:]) == (6.0, 8.0)
    p.save(tmp_path / "api")
    ok(run_cli("path", "configs/m1.yaml", "--pose", "4", "5", "--pose", "6", "8", "--working-mode", "++",
               "-o", str(tmp_path / "cli"), "--no-plot", "-q"))
    assert (tmp_path / "api" / "path.csv").read_bytes() == (tmp_path / "cli" / "path.csv").read_bytes()
    assert math.isclose(p.length, float(np.sum(np.hypot(*np.diff(p.points[:, :2], axis=0).T))))
    plain = fb.path(m, (4, 5), [6, 8], working_mode="++", depth=10)  # a plain pair: a pose, in `working_mode`
    assert np.array_equal(plain.points, p.points) and plain.length == p.length
    with pytest.raises(fb.FivebarError, match="no:|different"):
        fb.path(m, {"pose": (4, 5), "working_mode": "++"}, {"pose": (4, 5), "working_mode": "--"}, depth=8)


def test_rpr2_and_3rpr(tmp_path):
    r = fb.load("rpr2")
    p = fb.pave(r, "workspace", 8)
    assert p.inside_area <= r.exact_measure("workspace") <= p.inside_area + p.undetermined_area
    a = fb.aspects(r, 6)
    assert (a.count, a.certified) == (2, True)
    caro = fb.aspects("rpr3-caro", 5)
    assert (caro.count, caro.certified) == (2, True)
    assert sorted(x.modes["det_sign"] for x in caro) == ["+", "-"] and caro[0].jointspace is None
    from fivebar_cli.mechanisms.rpr3.boxtests import det_j, leg_lengths

    for x in caro:  # a pose inside each aspect has det J of its class's sign and the legs of the row
        pose = np.array([x.pose])
        assert np.sign(det_j(caro.mechanism, pose))[0] == (1 if x.modes["det_sign"] == "+" else -1)
        assert np.allclose(leg_lengths(caro.mechanism, pose)[0], x.joints)
    written = caro.save(tmp_path)
    assert {f.name for f in written} >= {"aspects.csv", "aspect-01.workspace.qt", "aspect-02.workspace.ply"}
    where = fb.locate("rpr3-caro", pose=caro[1].pose, depth=5, aspects=caro).rows()[0]
    assert where["aspect"] == caro[1].number and where["class"] == caro[1].modes


def _written(folder) -> dict:
    """Every file under `folder` (its output sets' manifests too): relative path -> bytes."""
    return {p.relative_to(folder): p.read_bytes() for p in sorted(folder.rglob("*")) if p.is_file()}


@pytest.mark.parametrize("name, depth", [("rpr2", 5), ("rpr3-caro", 3)])
def test_aspects_save_with_figures_writes_the_commands_files(tmp_path, name, depth):
    """`save(folder, figures=True)` writes the files `fivebar aspects` writes, figures included, the
    same bytes (a title naming a parameter spells it as Python does: `depth`, not --depth, so those
    figures and the manifest listing them differ); on the backend in use (a figure drawn by the
    library never switches it)."""
    import matplotlib

    backend = matplotlib.get_backend()
    a = fb.aspects(name, depth)
    written = a.save(tmp_path / "api", figures=True)
    assert matplotlib.get_backend() == backend
    ok(run_cli("aspects", REPO / "configs" / f"{name}.yaml", "--depth", depth, "-o", tmp_path / "cli", "-q"))
    api, cli = _written(tmp_path / "api"), _written(tmp_path / "cli")
    assert sorted(p.relative_to(tmp_path / "api") for p in written) == [f for f in cli if ".fivebar" not in f.parts]
    assert sum(f.suffix == ".png" for f in cli) >= 2 and api.keys() == cli.keys()
    for f in cli:
        if type(a.headline) is str or (f.suffix != ".png" and ".fivebar" not in f.parts):
            assert api[f] == cli[f], f


def test_rpr3_studies_save_the_commands_files(tmp_path):
    """`save(folder, figures=True)` of a 3-RPR study writes what its command writes, the same bytes
    (its output set's manifest too), the singular pose found by `verify` included."""
    for k, (study, args) in enumerate([(fb.rpr3.area("rpr3-equilateral"), ("area", "rpr3-equilateral")),
                                       (fb.rpr3.verify("rpr3-verify/obtuse-phi1-rule"),
                                        ("verify", "rpr3-verify/obtuse-phi1-rule"))]):
        written = study.save(tmp_path / f"api{k}", figures=True)
        status = run_cli("rpr3", *args, "-o", tmp_path / f"cli{k}", "-q").status
        assert status == study.rows()[0].get("exit", 0) == getattr(study, "exit_code", 0)
        cli = _written(tmp_path / f"cli{k}")
        assert sorted(p.relative_to(tmp_path / f"api{k}") for p in written) == [f for f in cli if ".fivebar" not in f.parts]
        assert any(f.suffix == ".png" for f in cli) and any(".fivebar" in f.parts for f in cli)
        assert _written(tmp_path / f"api{k}") == cli
    assert "counterexample.csv" in {p.name for p in written}


def test_rpr3_studies_equal_the_golden_tables():
    """(The synthesis is `fivebar rpr3 synthesize`'s one call: its golden table is tested through it.)"""
    area = fb.rpr3.area("rpr3-equilateral")
    assert area.columns == ("phi_deg", "rho_min", "rho_max", "area")
    golden = _csv(GOLDEN / "rpr3-equilateral" / "area.csv")
    assert [r["area"] for r in area.rows()] == pytest.approx([float(r["area"]) for r in golden], rel=1e-9)
    sweep = fb.rpr3.sweep(["rpr3-equilateral"], "rho_min", span=(0.0, 0.5), steps=6)
    assert [r["rho_min"] for r in sweep.rows()] == pytest.approx([0, 0.1, 0.2, 0.3, 0.4, 0.5])
    # cells as Python values, as the five-bar reports' (a sweep's were np.float64(...) in a notebook)
    assert {type(v) for r in sweep.rows() for v in r.values()} == {str, float}
    assert {type(v) for v in sweep.column("area")} == {float}
    # a numpy pair is a span too (its truth value raised a ValueError)
    assert fb.rpr3.sweep(["rpr3-equilateral"], "rho_min", span=np.array([0.0, 0.5]), steps=6).rows() == sweep.rows()
    v = fb.rpr3.verify("rpr3-verify/obtuse-phi1-rule", depth=14)
    # one kind of verify report for both kinds of verify (an exit status read alike)
    assert isinstance(v, type(fb.verify("rrr3-symmetric", 2, working_mode="+-+")))
    assert (v.status, v.exit_code) == ("singular pose found", 1) and v.counterexample.rows()[0]["det_j"] == pytest.approx(0, abs=1e-9)
    # the claim printed is zero to rounding, not the computed digits (they differ between machines)
    det_j = v.result.pose.value
    assert abs(det_j) < 1e-12 and v.notes[-1].endswith(f", det J = 0 to rounding ({det_j:.2g})")
    octree = fb.rpr3.pave("rpr3-general", 3)
    assert octree.volumes["reachable"] <= octree.volumes["root"] and len(octree.pavings) == 3
    with pytest.raises(fb.InputError, match="`span`: LO must be smaller than HI"):
        fb.rpr3.sweep("rpr3-equilateral", "phi", span=(3, 1))


def test_atlas_and_view():
    spec = {"type": "fivebar-atlas", "name": "tiny", "depth": 5,
            "lengths": {"L0": 9, "L1": [7, 8, 2], "L2": 5, "L3": 5, "L4": 8}}
    table = fb.atlas(spec)
    assert [float(v) for v in table.column("L1")] == [7, 8] and table.column("assemblable") == ["true", "true"]
    m1 = {float(r["L1"]): r for r in table.rows()}[8.0]
    assert int(m1["aspects"]) == len(fb.aspects("m1", 5))  # the aspects listed (not certified at depth 5)
    page = fb.view(GOLDEN / "M1")
    assert page.startswith("<!DOCTYPE html>") and "aspect-01.workspace.qt" in page
    with pytest.raises(fb.InputError, match="^`paths`: give at least one .qt file or output folder$"):
        fb.view([])  # (a page of nothing, once; the command needs a PATH)


def test_results_are_immutable_values_with_one_line_reprs(m1_aspects):
    p = fb.pave("m1", "workspace", 5)
    path = fb.path("m1", {"pose": (4, 5), "working_mode": "++"}, {"pose": (6, 8), "working_mode": "++"}, depth=8)
    for value in (p, m1_aspects, m1_aspects[0], path, fb.rpr3.area("rpr3-equilateral"),
                  fb.locate("m1", pose=(4, 5), aspects=m1_aspects)):
        assert "\n" not in repr(value) and repr(value).startswith("<")
        field = dataclasses.fields(value)[0].name
        with pytest.raises(dataclasses.FrozenInstanceError):
            setattr(value, field, None)
    with pytest.raises(ValueError):
        path.points[0, 0] = 1.0


def test_plots_draw_on_the_callers_axes_and_keep_the_backend(m1_aspects):
    import matplotlib

    before = matplotlib.get_backend()
    matplotlib.use("svg")
    try:
        from matplotlib.figure import Figure

        axes = Figure().subplots(1, 4)
        assert fb.pave("m1", "workspace", 6).plot(axes[0]) is axes[0] and axes[0].images
        assert m1_aspects.plot(axes[1]) is axes[1] and len(axes[1].texts) == 10
        path = fb.path("m1", {"pose": (4, 5), "working_mode": "++"}, {"pose": (6, 8), "working_mode": "++"}, depth=8)
        assert path.plot(axes[2]).lines
        assert fb.rpr3.sweep("rpr3-equilateral", "rho_min", steps=5).plot(axes[3], x="rho_min", y="area").lines
        fb.pave("rpr3-general", "workspace", 3).plot()  # 3-D: a slice, on new axes of the current backend
        assert matplotlib.get_backend() == "svg"
    finally:
        import matplotlib.pyplot as plt

        plt.close("all")
        matplotlib.use(before)


def test_docstring_examples_run():
    """Every example in the docstrings of the API's modules (found by walking the package, so a new
    module's examples run too)."""
    import importlib
    import pkgutil

    import fivebar_cli.api

    tried = {}
    for info in pkgutil.iter_modules(fivebar_cli.api.__path__):  # (modules: fb.atlas is a function too)
        module = importlib.import_module(f"fivebar_cli.api.{info.name}")
        result = doctest.testmod(module, optionflags=doctest.ELLIPSIS)
        assert result.failed == 0, info.name
        tried[info.name] = result.attempted
    assert {name for name, n in tried.items() if n} >= {"atlas", "calls", "locations", "poses", "rpr3", "studies",
                                                          "trees", "values"}, tried


def test_every_long_call_reports_progress_by_advance():
    """One convention (docs/python.md, "Progress"): `advance(n)` per step; M1's boundary is
    undetermined at every level, so a paving to depth 6 is the 7 levels 0..6 and a refinement from
    4 to 6 the 2 new ones; an atlas of 2 designs is 2 steps, a sweep of 2 mechanisms 2."""
    m1 = fb.load("m1")
    for call, steps in ((lambda a: fb.pave(m1, "workspace", 6, advance=a), 7),
                        (lambda a: fb.refine(fb.pave(m1, "workspace", 4), 6, advance=a), 2),
                        (lambda a: fb.atlas({"type": "fivebar-atlas", "name": "l1", "depth": 3, "lengths": {
                            "L0": 9, "L1": [7, 8, 2], "L2": 5, "L3": 5, "L4": 8}}, advance=a), 2),
                        (lambda a: fb.rpr3.sweep(["rpr3-equilateral", "rpr3-equilateral"], "phi", steps=3,
                                                 advance=a), 2)):
        done = []
        call(lambda n=1: done.append(n))
        assert sum(done) == steps
    done = []
    fb.aspects(m1, 4, advance=lambda n=1: done.append(n))
    more = []
    fb.locate(m1, pose=(4, 5), depth=4, advance=lambda n=1: more.append(n))
    assert sum(done) == sum(more) == 6 + 1  # six regions paved (options.MAX_ASPECT_DEPTH's note), then the end
    more = []
    fb.rpr3.pave("rpr3-general", 2, advance=lambda n=1: more.append(n))
    assert sum(more) == 3 * 3  # three pavings (reachable, det J > 0, det J < 0), levels 0..2 each


def test_count_is_none_unless_certified(m1_aspects):
    """M1 has 10 generalized aspects (the paper); at depth 5 they are not all told apart: the count is
    not a number then, the bounds hold 10 and `len` is how many were found (aspects.csv's rows)."""
    coarse = fb.aspects(fb.load("m1"), 5)
    assert not coarse.certified and coarse.count is None
    lo, hi = coarse.bounds
    assert lo <= 10 <= hi and len(coarse) == len(list(coarse)) == len(coarse.rows())
    assert m1_aspects.certified and m1_aspects.count == len(m1_aspects) == 10 and m1_aspects.bounds == (10, 10)


def test_a_save_into_a_file_and_an_unknown_column_are_told_so(tmp_path):
    """`save(folder)` where the folder is a file is refused before anything is written, as the
    commands' `-o` is (it was told 'FILE/kratio.csv: cannot write: Not a directory'); a column that
    the table does not have is a KeyError naming the columns (a ValueError of tuple.index before)."""
    k = fb.kratio("m1", [3])
    taken = tmp_path / "taken"
    taken.write_text("mine\n")
    for folder in (taken, taken / "below"):
        with pytest.raises(fb.FivebarError, match=f"^{folder}: cannot create output folder: {taken} exists and is "
                                                  "not a folder$"):
            k.save(folder)
    assert taken.read_text() == "mine\n"
    with pytest.raises(KeyError, match=r"no column 'nope' \(the columns: space, mechanism, depth, "):
        k.column("nope")
    # plot's columns alike, checked before any axes are made (a bare KeyError 'nope' came from the
    # middle of the drawing), and a table without two numeric columns asks for x and y (IndexError)
    import matplotlib.pyplot as plt

    before = plt.get_fignums()
    for kwargs in ({"x": "nope"}, {"x": "depth", "y": "K", "by": "nope"}):
        with pytest.raises(KeyError, match="no column 'nope'"):
            k.plot(**kwargs)
    with pytest.raises(ValueError, match="^t: no two numeric columns to plot by default: give x and y$"):
        fb.Table("t", ("a", "b"), ()).plot()
    assert plt.get_fignums() == before
