"""The API calls behind `fivebar tolerance`, `kratio`, `path` and `locate` (api/studies.py,
api/locations.py): each value gives the command's rows, its report lines and, through `save`, its
files byte for byte; the numbers agree with independent ones (closed-form areas, the paper's printed
K, the length of the polyline); bad input raises InputError naming the field."""

from __future__ import annotations

import csv
import doctest
import io
import math

import numpy as np
import pytest

import fivebar_cli as fb
from fivebar_cli.cli.options import as_flags
from fivebar_cli.io.files import csv_text
from tests.cli_helpers import REPO, ok, run_cli

M1_YAML = REPO / "configs" / "m1.yaml"
TINY_ATLAS = {"type": "fivebar-atlas", "name": "tiny", "depth": 3,
              "lengths": {"L0": 9, "L1": [7, 8, 2], "L2": 5, "L3": 5, "L4": 8}}


def _printed(lines) -> list[str]:
    """Library lines as the command line prints them (parameters spelled as its options)."""
    return [as_flags(line) for line in lines]


def _files(folder) -> dict[str, bytes]:
    return {p.name: p.read_bytes() for p in sorted(folder.iterdir()) if p.is_file()}


@pytest.fixture(scope="module")
def m1_at_6():
    return fb.aspects(fb.load("m1"), 6, shapes=False)


def test_tolerance_is_the_command_as_a_value(tmp_path):
    """fb.tolerance gives tolerance.csv's rows, the command's report lines and, saved with figures,
    the command's three files byte for byte; the nominal workspace area is the closed form and every
    robust area lies below its nominal one, every possible area above it."""
    t = fb.tolerance(M1_YAML, [0.1, 0], 5)  # sorted, as the command's --tolerances
    cli = ok(run_cli("tolerance", M1_YAML, "--tolerances", "0,0.1", "--depth", "5", "-o", tmp_path / "cli"))
    assert cli.stdout.splitlines()[:len(t.notes)] == _printed(t.notes)
    assert any("`depth`" in line for line in t.notes)  # the library names its parameters
    assert sorted(p.name for p in t.save(tmp_path / "api", figures=True)) == [
        "tolerance-aspects.png", "tolerance-bands.png", "tolerance.csv"]
    assert _files(tmp_path / "api") == _files(tmp_path / "cli")
    rows = t.rows()
    assert csv_text(t.columns, [list(r.values()) for r in rows]) == (tmp_path / "cli" / "tolerance.csv").read_text()
    assert [(r["tolerance"], r["region"]) for r in rows[:2]] == [(0.0, "workspace"), (0.0, "jointspace")]
    assert repr(t) == f"<Tolerance M1, depth 5: {len(rows)} rows of {', '.join(t.columns)}>"
    exact = fb.load("m1").exact_measure("workspace")
    for r in rows:
        if r["region"] == "workspace":
            assert math.isclose(r["nominal_area"], exact)
            assert r["robust_area"] <= exact <= r["possible_area"]
        if r["region"].startswith("aspect"):
            assert r["possible_area"] == "" and r["robust_area"] <= r["nominal_area"] + 1e-9
    shrunk = [r["robust_area"] for r in rows if r["region"] == "workspace"]
    assert shrunk[1] < shrunk[0]  # wider tolerances leave less robust area
    assert t.save(tmp_path / "bare") and _files(tmp_path / "bare") == {"tolerance.csv": _files(tmp_path / "cli")[
        "tolerance.csv"]}


def test_kratio_is_the_command_as_a_value(tmp_path):
    """fb.kratio gives kratio.csv (and its figure) as `fivebar kratio` writes them; its rows hold the
    paper's printed K of M1 (Table 1: 99% and 72% at depth 5) and the discretization 4^d."""
    k = fb.kratio(["m1", "rpr2"], [5, 4])
    cli = ok(run_cli("kratio", M1_YAML, REPO / "configs" / "rpr2.yaml", "--depths", "4,5", "-o", tmp_path / "cli"))
    assert cli.stdout.splitlines()[:len(k.notes)] == _printed(k.notes)
    k.save(tmp_path / "api", figures=True)
    assert _files(tmp_path / "api") == _files(tmp_path / "cli")
    rows = k.rows()
    assert all(r["discretization"] == 4 ** r["depth"] for r in rows)
    m1 = {(r["space"], r["depth"]): r for r in rows if r["mechanism"] == "M1"}
    assert (m1["jointspace", 5]["paper_printed_percent"], m1["workspace", 5]["paper_printed_percent"]) == (99, 72)
    assert all(r["paper_procedure_evaluations"] == "" for r in rows if r["mechanism"] != "M1")
    assert fb.kratio("m1", 5).rows() == [r for r in rows if r["mechanism"] == "M1" and r["depth"] == 5]  # one of each


def test_path_saves_the_commands_files(tmp_path):
    """Path.save(folder, figures=True) writes path.csv and path.png as `fivebar path`; its notes are
    the command's lines; the length is that of the joint-space polyline."""
    ends = ({"joints": (-0.1, -2.06)}, {"joints": (0.88, 1.47)})
    p = fb.path(M1_YAML, *ends, depth=8, assembly_mode="+")
    cli = ok(run_cli("path", M1_YAML, "--joints", "-0.1", "-2.06", "--joints", "0.88", "1.47", "--assembly-mode",
                     "+", "--depth", "8", "-o", tmp_path / "cli"))
    p.save(tmp_path / "api", figures=True)
    assert _files(tmp_path / "api") == _files(tmp_path / "cli")
    assert cli.stdout.splitlines()[:len(p.notes)] == _printed(p.notes)
    assert math.isclose(p.length, float(np.sum(np.hypot(*np.diff(p.result.unwrapped(), axis=0).T))))


def test_locate_several_locations_is_the_command(tmp_path, m1_at_6):
    """fb.locate with several poses and joints gives the rows of `locate --csv` and the command's
    report, with the answer for each pair; two configurations in different working modes are
    apart (a sign of det B changes on every motion between them)."""
    args = ("--pose", "4", "5", "--pose", "6", "-3", "--joints", "0.2", "1", "--depth", "6")
    cli_csv = ok(run_cli("locate", M1_YAML, *args, "--csv", "-o", tmp_path)).stdout
    cli_text = ok(run_cli("locate", M1_YAML, *args, "-o", tmp_path)).stdout
    where = fb.locate(M1_YAML, pose=[(4, 5), (6, -3)], joints=(0.2, 1), depth=6)
    assert where.csv() == cli_csv
    assert [str(r["aspect"] or "") for r in where.rows()] == [r["aspect"] for r in csv.DictReader(io.StringIO(cli_csv))]
    assert _printed(where.lines()) == cli_text.splitlines()
    given = fb.locate("m1", pose=[(4, 5), (6, -3)], depth=6, working_mode="++", aspects=m1_at_6)
    assert [r["working_mode"] for r in given.rows()] == ["++", "++"]
    assert {r["location"] for r in given.rows()} == {"pose 4 5", "pose 6 -3"}
    apart = fb.locate("m1", pose=(4, 5), joints=(0.2, 1), depth=6, working_mode="--", aspects=m1_at_6)
    assert any(str(line).startswith("  1 -> 2: ") for line in apart.lines())


def test_verify_is_the_command_as_a_value(tmp_path):
    """fb.verify gives verify.csv, counterexample.csv and counterexample.png as `fivebar verify`, its
    lines and its exit status; the singular pose it reports has det A = 0 up to its bisection."""
    rrr3 = REPO / "configs" / "rrr3-symmetric.yaml"
    v = fb.verify(rrr3, 2, working_mode="+-+")
    cli = run_cli("verify", rrr3, "--working-mode", "+-+", "--depth", "2", "-o", tmp_path / "cli")
    assert cli.status == v.exit_code == 1
    assert cli.stdout.splitlines()[:len(v.notes)] == _printed(v.notes)
    v.save(tmp_path / "api", figures=True)
    assert _files(tmp_path / "api") == _files(tmp_path / "cli")
    assert [r["status"] for r in v.rows()] == ["singular pose found"]
    pose = v.tables[0][2][0]
    assert abs(pose[-1]) < 1e-6  # det_a at the singular pose


@pytest.mark.parametrize("call, field", [
    # a tolerance that is no number: a TypeError from deep inside ('0.05'), or True taken as 1
    (lambda: fb.aspects("m1", 4, tolerance="0.05"), "`tolerance`"),
    (lambda: fb.pave("m1", "workspace", 4, tolerance=True), "`tolerance`"),
    (lambda: fb.locate("m1", pose=(4, 5), depth=4, tolerance=""), "`tolerance`"),
    (lambda: fb.load("m1", tolerance=[0.05]), "`tolerance`"),
    (lambda: fb.rpr3.sweep([], "phi"), "`mechs`"),  # (a table of no rows, before)
    # a key of neither endpoint form (a joints endpoint's own assembly mode was ignored), no sequence
    # of numbers or depths (True was a tolerance of 1; '3-5' was read character by character)
    (lambda: fb.path("m1", {"joints": (-0.1, -2.06), "assembly_mode": "+"}, {"joints": (0.88, 1.47)}, depth=8),
     "`start`"),
    (lambda: fb.tolerance("m1", [True], 3), "`tolerances`"),
    (lambda: fb.kratio("m1", "3-5"), "`depths`"),
    # an atlas's tolerance is checked as the spec's (a negative one was taken as none)
    (lambda: fb.atlas(TINY_ATLAS, tolerance=-1), "`tolerance`"),
    (lambda: fb.atlas(TINY_ATLAS, tolerance="0.1"), "`tolerance`"),
    (lambda: fb.tolerance("m1", [-0.1], 5), "`tolerances`"),
    (lambda: fb.tolerance("m1", [], 5), "`tolerances`"),
    (lambda: fb.tolerance("m1", [5.0], 5), "`tolerance`"),  # would make L2 reach 0
    (lambda: fb.tolerance("rpr2", [0.1], 5), "type"),
    (lambda: fb.tolerance("m1", [0.1], 25), "`depth`"),
    (lambda: fb.kratio("rpr3-caro", [5]), "type"),
    (lambda: fb.kratio(["m1"], [21]), "`depths`"),
    (lambda: fb.kratio(["m1"], []), "`depths`"),
    (lambda: fb.kratio(["m1"], 3.5), "`depths`"),
    (lambda: fb.kratio(["m1"], None), "`depths`"),
    (lambda: fb.path("m1", {"joints": (0, 1)}, {"joints": (1, 1)}, depth=17), "`depth`"),
    (lambda: fb.path("rpr2", {"pose": (0, 8)}, {"pose": (1, 7)}, allow_serial=True), "`allow_serial`"),
    (lambda: fb.pave("m1", "workspace", 1.5), "`depth`"),  # (a float depth paved on without end)
    (lambda: fb.pave("m1", "workspace", 21), "`depth`"),
    (lambda: fb.refine(fb.pave("m1", "workspace", 4), 3), "`depth`"),
    (lambda: fb.refine(fb.pave("m1", "workspace", 4), 5.0), "`depth`"),
    (lambda: fb.aspects("m1", float("nan")), "`depth`"),
    (lambda: fb.aspects("m1", 17), "`depth`"),
    (lambda: fb.rpr3.pave("rpr3-general", 13), "`depth`"),
    (lambda: fb.rpr3.verify("rpr3-verify/table1-legs-1-1.5", 18), "`depth`"),
    (lambda: fb.rpr3.verify("rpr3-verify/table1-legs-1-1.5", 2.5), "`depth`"),
    (lambda: fb.aspects("m1", 4, jobs=0), "`jobs`"),
    (lambda: fb.aspects("m1", 4, jobs=-1), "`jobs`"),  # ("every core" elsewhere: never one process silently)
    (lambda: fb.tolerance("m1", [0.01], 4, jobs=2.0), "`jobs`"),
    (lambda: fb.rpr3.pave("rpr3-general", 2, jobs="2"), "`jobs`"),
    (lambda: fb.atlas({"type": "fivebar-atlas", "name": "t", "depth": 3, "lengths": {"L0": 9, "L1": 8, "L2": 5,
                                                                                   "L3": 5, "L4": 8}}, workers=-1),
     "`workers`"),  # (a local cluster of -1 workers waited forever)
    (lambda: fb.atlas({"type": "fivebar-atlas", "name": "t", "depth": 3, "lengths": {"L0": 9, "L1": 8, "L2": 5,
                                                                                   "L3": 5, "L4": 8}}, depth=17),
     "`depth`"),
    (lambda: fb.atlas({"type": "fivebar-atlas", "name": "t", "depth": 3, "lengths": {"L0": 9, "L1": 8, "L2": 5,
                                                                                   "L3": 5, "L4": 8}}, tolerance=5),
     "`tolerance`"),
    (lambda: fb.locate("m1", depth=6), "`pose`"),
    (lambda: fb.locate("m1", pose=(4, 5, 6), depth=6), "`pose`"),
    (lambda: fb.locate("m1", pose=(4, float("nan")), depth=6), "`pose`"),
    (lambda: fb.locate("m1", pose="45", depth=6), "`pose`"),
    (lambda: fb.locate("m1", joints=[(1, 2), (3,)], depth=6), "`joints`"),
    (lambda: fb.path("m1", (4, 5, 6), (6, 8), working_mode="++"), "`start`"),
    (lambda: fb.path("m1", (4, 5), {"pos": (6, 8)}, working_mode="++"), "`goal`"),
    (lambda: fb.path("m1", {"pose": (4, 5), "joints": (0, 1)}, (6, 8)), "`start`"),
    (lambda: fb.path("m1", "45", (6, 8), working_mode="++"), "`start`"),
    (lambda: fb.path("m1", None, (6, 8), working_mode="++"), "`start`"),
    (lambda: fb.verify("m1", 5), "type"),
    (lambda: fb.verify("rrr3-symmetric", 5, working_mode="+++x"), "`working_mode`"),
    (lambda: fb.verify("rpr3-caro", 18), "`depth`"),
])
def test_bad_input_names_the_field(call, field):
    with pytest.raises(fb.InputError) as caught:
        call()
    assert caught.value.field == field


def test_a_calls_own_parameter_is_named_without_a_source():
    with pytest.raises(fb.InputError) as caught:
        fb.aspects("m1", 4, jobs=0)
    assert str(caught.value) == "`jobs`: must be an integer of at least 1 (None: one per core), got 0"
    with pytest.raises(TypeError, match="aspects: expected what fb.aspects gives"):
        fb.locate("m1", pose=(4, 5), aspects="m1-aspects")


def test_docstring_examples_run():
    from fivebar_cli.api import locations, poses, studies

    for module in (studies, locations, poses):
        result = doctest.testmod(module, optionflags=doctest.ELLIPSIS)
        assert result.failed == 0 and result.attempted > 0
