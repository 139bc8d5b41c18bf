"""The `aspects` and `locate` commands (issue 3, items 5 and 6; docs/formats.md: outputs, exit status).

Run through the console script's entry point (in-process, cli_helpers.run_cli), at depth 8 to stay fast.
Outputs are checked against the docs/formats.md contract (CSV columns, .qt layout and headers, file
names, determinism) and against geometry computed here (the representative configuration of each
aspect closes the loop with the aspect's modes; the crossing graph is K_{2,3}).
"""

from __future__ import annotations

import csv
import io
import math
from pathlib import Path

import numpy as np
import pytest
from cli_helpers import one_line, run_cli

from fivebar_cli.io.qtfile import read_qt

REPO = Path(__file__).resolve().parents[1]
M1_YAML = REPO / "configs" / "m1.yaml"
M2_YAML = REPO / "configs" / "m2.yaml"
L = {"L0": 9.0, "L1": 8.0, "L2": 5.0, "L3": 5.0, "L4": 8.0}  # M1, section 3 of the paper
DEPTH = "8"
HEADER = ("aspect,working_mode,assembly_mode,workspace_area,jointspace_area,workspace_cells,"
          "jointspace_cells,x,y,theta1,theta2,certified,circle_x,circle_y,circle_r,square_x,square_y,square_side")
LOCATE_HEADER = "input,location,x,y,theta1,theta2,working_mode,assembly_mode,aspect,singular,aspect_certified"
WM_ORDER = ["++", "+-", "-+", "--"]
PNGS = {"aspects-workspace.png", "aspects-jointspace-assembly+.png", "aspects-jointspace-assembly-.png"}


def run(*args):
    return run_cli(*args, cwd=REPO)


def ref_ikp(x, y, su, sv):
    """(th1, th2, t) of M1 at P = (x, y) in working mode (su, sv), from the geometry: B_i is the
    intersection of the circles (A_i, L_i) and (P, L_{i+2}) on the side that gives sign u = su
    (resp. sign v = sv): u = (b1 - a1) x (p - b1) = -s h |A1P| for B1 on side s of A1 -> P."""
    out = []
    for (ax, crank, coupler, sign) in ((0.0, L["L1"], L["L3"], su), (L["L0"], L["L2"], L["L4"], sv)):
        dx, dy = x - ax, y
        d = math.hypot(dx, dy)
        a = (crank ** 2 - coupler ** 2 + d * d) / (2 * d)
        h = math.sqrt(crank ** 2 - a * a)
        s = -sign
        out.append((ax + (a * dx - s * h * dy) / d, (a * dy + s * h * dx) / d))
    (b1x, b1y), (b2x, b2y) = out
    t = (x - b1x) * (y - b2y) - (y - b1y) * (x - b2x)
    return math.atan2(b1y, b1x), math.atan2(b2y, b2x - L["L0"]), t


def angle_diff(a, b):
    return abs(math.remainder(a - b, 2 * math.pi))


def read_csv(path: Path):
    text = path.read_text()
    return text, list(csv.DictReader(io.StringIO(text)))


@pytest.fixture(scope="module")
def runs(tmp_path_factory):
    """The same command twice: with figures into one folder (in process), with --no-plot and two
    worker processes into another."""
    a = tmp_path_factory.mktemp("aspects_plot")
    b = tmp_path_factory.mktemp("aspects_noplot")
    ra = run("aspects", M1_YAML, "--depth", DEPTH, "-o", a, "--jobs", "1")
    rb = run("aspects", M1_YAML, "--depth", DEPTH, "-o", b, "--no-plot", "--quiet", "--jobs", "2")
    return a, ra, b, rb


@pytest.fixture(scope="module")
def rows(runs):
    return read_csv(runs[0] / "aspects.csv")[1]


def test_aspects_command_succeeds(runs):
    a, ra, b, rb = runs
    assert ra.status == 0, ra.stderr
    assert rb.status == 0, rb.stderr
    assert "Traceback" not in ra.stderr + rb.stderr
    assert "10 generalized aspects" in ra.stdout
    assert rb.stdout == ""  # --quiet
    assert "holds" in ra.stdout and "does NOT hold" not in ra.stdout


def test_aspects_csv_columns_and_rows(runs, rows):
    text, _ = read_csv(runs[0] / "aspects.csv")
    lines = text.split("\n")
    assert lines[0] == HEADER
    assert text.endswith("\n") and "\r" not in text
    assert len(rows) == 10
    assert [int(r["aspect"]) for r in rows] == list(range(1, 11))
    keys = [(r["assembly_mode"] != "+", WM_ORDER.index(r["working_mode"])) for r in rows]
    assert keys == sorted(keys)  # assembly mode + first, then ++, +-, -+, --
    assert [r["assembly_mode"] for r in rows].count("+") == 5
    for r in rows:
        assert r["assembly_mode"] in ("+", "-") and r["working_mode"] in WM_ORDER
        assert float(r["workspace_area"]) > 0 and float(r["jointspace_area"]) > 0
        assert int(r["workspace_cells"]) > 0 and int(r["jointspace_cells"]) > 0
        assert r["certified"] == "true"  # M1's count is certified at this depth


def test_one_qt_file_per_aspect_and_space_matching_the_csv(runs, rows):
    out = runs[0]
    names = sorted(p.name for p in (out / "aspects").iterdir())
    assert names == sorted([f"aspect-{k:02d}.{s}.qt" for k in range(1, 11) for s in ("workspace", "jointspace")]
                           + [f"aspect-{k:02d}.workspace.geojson" for k in range(1, 11)])
    reach = L["L1"] + L["L3"]
    for r in rows:
        k = int(r["aspect"])
        for space in ("workspace", "jointspace"):
            qt = read_qt(out / "aspects" / f"aspect-{k:02d}.{space}.qt")
            tree = qt.tree
            assert qt.get("space") == space
            assert qt.get("region") == f"aspect {k}"
            assert qt.get("colour") == "inside"
            assert qt.get("name") == "M1"
            if qt.get("working_mode"):
                assert qt.get("working_mode") == r["working_mode"]
            if qt.get("assembly_mode"):
                assert qt.get("assembly_mode") == r["assembly_mode"]
            assert tree.grid.depth == int(DEPTH)
            if space == "workspace":
                assert tree.grid.root == ((-reach, reach), (-reach, reach))
                assert tree.grid.periodic == (False, False)
            else:
                assert tree.grid.root == ((-math.pi, math.pi), (-math.pi, math.pi))
                assert tree.grid.periodic == (True, True)
            assert tree.area == pytest.approx(float(r[f"{space}_area"]), rel=1e-9)
            assert len(tree) == int(r[f"{space}_cells"])
        text = (out / "aspects" / f"aspect-{k:02d}.jointspace.qt").read_text().split("\n")
        assert text[0] == "# fivebar-quadtree 1"
        assert "# periodic: 0 1" in text
        body = [line for line in text if line and not line.startswith("#")]
        assert all(len(line) <= 64 for line in body) and set("".join(body)) <= set("BWG")


def test_aspect_trees_of_one_region_are_disjoint(runs, rows):
    """Aspects of one assembly mode never overlap in the joint space, nor aspects of one working
    mode in the workspace (they are different components of one region)."""
    out = runs[0]
    trees = {int(r["aspect"]): {s: read_qt(out / "aspects" / f"aspect-{int(r['aspect']):02d}.{s}.qt").tree
                                for s in ("workspace", "jointspace")} for r in rows}
    for r in rows:
        for q in rows:
            i, j = int(r["aspect"]), int(q["aspect"])
            if i >= j:
                continue
            if r["assembly_mode"] == q["assembly_mode"]:
                assert (trees[i]["jointspace"] & trees[j]["jointspace"]).area == 0
            if r["working_mode"] == q["working_mode"]:
                assert (trees[i]["workspace"] & trees[j]["workspace"]).area == 0


def test_representative_configuration_lies_in_its_aspect(runs, rows):
    out = runs[0]
    for r in rows:
        k = int(r["aspect"])
        x, y, t1, t2 = (float(r[c]) for c in ("x", "y", "theta1", "theta2"))
        su, sv = (1 if c == "+" else -1 for c in r["working_mode"])
        th1, th2, t = ref_ikp(x, y, su, sv)
        assert angle_diff(th1, t1) < 1e-8 and angle_diff(th2, t2) < 1e-8
        assert (t > 0) == (r["assembly_mode"] == "+")
        ws = read_qt(out / "aspects" / f"aspect-{k:02d}.workspace.qt").tree
        js = read_qt(out / "aspects" / f"aspect-{k:02d}.jointspace.qt").tree
        assert ws.locate(np.array([[x, y]]))[0] >= 0
        assert js.locate(np.array([[t1, t2]]))[0] >= 0


def test_adjacency_csv_is_k23_per_assembly_mode(runs, rows):
    text, edges = read_csv(runs[0] / "aspects-adjacency.csv")
    assert text.split("\n")[0].startswith("aspect_a,aspect_b,")
    modes = {int(r["aspect"]): (r["working_mode"], r["assembly_mode"]) for r in rows}
    for am in ("+", "-"):
        mine = [e for e in edges if modes[int(e["aspect_a"])][1] == am]
        pairs = {(int(e["aspect_a"]), int(e["aspect_b"])) for e in mine}
        assert len(pairs) == 6
        for e in mine:
            wa, wb = modes[int(e["aspect_a"])][0], modes[int(e["aspect_b"])][0]
            assert modes[int(e["aspect_b"])][1] == am
            changed = [i for i in (0, 1) if wa[i] != wb[i]]
            assert len(changed) == 1
            if "singularity" in e:
                assert e["singularity"] == ("B11" if changed[0] == 0 else "B22")
        nodes = sorted(k for k, (w, a) in modes.items() if a == am)
        degree = {n: sum(n in p for p in pairs) for n in nodes}
        two = [n for n in nodes if degree[n] == 3]
        three = [n for n in nodes if degree[n] == 2]
        assert len(two) == 2 and len(three) == 3
        assert pairs == {tuple(sorted((p, q))) for p in two for q in three}


def test_figures_only_without_no_plot(runs):
    a, _, b, _ = runs
    pngs = {p.name for p in a.iterdir() if p.suffix == ".png"}
    assert pngs == PNGS
    for name in pngs:
        assert (a / name).read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
        assert (a / name).stat().st_size > 1000
    assert not [p for p in b.iterdir() if p.suffix == ".png"]


def test_two_runs_write_identical_bytes(runs):
    a, _, b, _ = runs
    files = ["aspects.csv", "aspects-adjacency.csv"] + [
        f"aspects/aspect-{k:02d}.{s}" for k in range(1, 11) for s in ("workspace.qt", "jointspace.qt", "workspace.geojson")]
    for f in files:
        assert (a / f).read_bytes() == (b / f).read_bytes(), f
    text = "".join((a / f).read_text() for f in files)
    assert str(a) not in text and str(b) not in text  # no absolute paths in the outputs


# ---------------------------------------------------------------- locate


def locate(folder, *args):
    """`fivebar locate` at DEPTH with -o `folder`: the module's aspects run (its trees reused), or an
    empty folder (the aspects computed; never the checkout's outputs/)."""
    return run("locate", M1_YAML, "--depth", DEPTH, "-o", folder, *args)


def locate_csv(folder, *args):
    r = locate(folder, *args, "--csv")
    assert r.status == 0, r.stderr
    lines = r.stdout.split("\n")
    assert lines[0] == LOCATE_HEADER
    return list(csv.DictReader(io.StringIO(r.stdout)))


def test_locate_pose_lists_every_configuration(runs, rows):
    """At the representative pose of aspect 1 all four working modes reach P; each row's joints
    close the loop with its working mode, and the ++ configuration lies in aspect 1."""
    first = rows[0]
    x, y = float(first["x"]), float(first["y"])
    out = locate_csv(runs[0], "--pose", x, y)
    assert sorted(r["working_mode"] for r in out) == sorted(WM_ORDER)
    for r in out:
        su, sv = (1 if c == "+" else -1 for c in r["working_mode"])
        th1, th2, t = ref_ikp(x, y, su, sv)
        assert angle_diff(th1, float(r["theta1"])) < 1e-8 and angle_diff(th2, float(r["theta2"])) < 1e-8
        assert r["assembly_mode"] == ("+" if t > 0 else "-")
        assert r["input"] == "1" and float(r["x"]) == pytest.approx(x) and float(r["y"]) == pytest.approx(y)
    own = [r for r in out if r["working_mode"] == first["working_mode"]]
    assert own[0]["aspect"] == first["aspect"] and own[0]["singular"] == ""
    # the other configurations lie in aspects of their own modes
    modes = {r["aspect"]: (r["working_mode"], r["assembly_mode"]) for r in rows}
    for r in out:
        if r["aspect"]:
            assert modes[r["aspect"]] == (r["working_mode"], r["assembly_mode"])


def test_locate_text_output(rows, tmp_path):
    first = rows[0]
    r = locate(tmp_path, "--pose", first["x"], first["y"])
    assert r.status == 0, r.stderr
    assert "location 1: pose" in r.stdout and ": 4 configurations (floating-point kinematics, not certified)" in r.stdout
    assert "working mode ++, assembly mode +: " in r.stdout
    assert "-> aspect 1 (certified)" in r.stdout
    assert r.stdout.startswith("M1: 10 aspects at depth 8 computed (all certified)\n")


def test_locate_joints_with_filters(runs, rows):
    """--joints lists the assemblies; --assembly-mode and --working-mode keep only theirs."""
    for q in (rows[0], rows[6]):
        t1, t2 = q["theta1"], q["theta2"]
        out = locate_csv(runs[0], "--joints", t1, t2, "--assembly-mode", q["assembly_mode"])
        assert len(out) == 1
        assert out[0]["aspect"] == q["aspect"] and out[0]["working_mode"] == q["working_mode"]
        assert float(out[0]["x"]) == pytest.approx(float(q["x"]), abs=1e-6)
        assert float(out[0]["y"]) == pytest.approx(float(q["y"]), abs=1e-6)
    out = locate_csv(runs[0], "--pose", rows[0]["x"], rows[0]["y"], "--working-mode", "+-")
    assert [r["working_mode"] for r in out] == ["+-"]
    out = locate_csv(runs[0], "--pose", rows[0]["x"], rows[0]["y"], "--assembly-mode", "-")
    assert out and all(r["assembly_mode"] == "-" for r in out)


def test_locate_outside_the_workspace(runs):
    r = locate(runs[0], "--pose", 30, 0)
    assert r.status == 0, r.stderr
    assert r.stdout.startswith(f"M1: 10 aspects at depth 8 read from {runs[0]} (all certified)\n")  # reused
    assert "no configuration" in r.stdout
    assert locate_csv(runs[0], "--pose", 30, 0) == []


def test_locate_on_a_serial_singularity(runs):
    """P on the outer circle |P - A1| = L1 + L3 = 13, inside the workspace: no aspect."""
    p = (13 * math.cos(math.pi / 3), 13 * math.sin(math.pi / 3))
    out = locate_csv(runs[0], "--pose", repr(p[0]), repr(p[1]))
    assert out
    assert all(r["aspect"] == "" for r in out)
    assert all("B11" in r["singular"] for r in out)


def _second_pose_in(out: Path, k: int, rep):
    """The centre of a large workspace cell of aspect k, other than its representative pose,
    whose configuration (by the reference IKP) lies in the aspect's joint-space cells."""
    ws = read_qt(out / "aspects" / f"aspect-{k:02d}.workspace.qt").tree
    js = read_qt(out / "aspects" / f"aspect-{k:02d}.jointspace.qt").tree
    order = np.argsort(ws.level, kind="stable")
    for c in ws.centres()[order]:
        if math.hypot(c[0] - rep[0], c[1] - rep[1]) < 1.0:
            continue
        th1, th2, _ = ref_ikp(c[0], c[1], 1, 1)
        if js.locate(np.array([[th1, th2]]))[0] >= 0:
            return c
    raise AssertionError("no second pose found")


def test_locate_motion_verdict(runs, rows):
    """Same aspect -> a singularity-free motion exists ("yes"); different aspects -> "no"."""
    out = runs[0]
    a1 = next(r for r in rows if r["working_mode"] == "++" and r["assembly_mode"] == "+")
    a6 = next(r for r in rows if r["working_mode"] == "++" and r["assembly_mode"] == "-")
    p1 = (float(a1["x"]), float(a1["y"]))
    p2 = _second_pose_in(out, int(a1["aspect"]), p1)
    r = locate(out, "--pose", *p1, "--pose", *p2, "--working-mode", "++")
    assert r.status == 0, r.stderr
    assert f"1 -> 2: yes: both lie in aspect {a1['aspect']}\n" in r.stdout
    r = locate(out, "--pose", *p1, "--pose", a6["x"], a6["y"], "--working-mode", "++")
    assert r.status == 0, r.stderr
    assert "1 -> 2: no: different assembly modes (+ for location 1, - for location 2)" in r.stdout
    assert "yes" not in r.stdout


# ---------------------------------------------------------------- bad input


def test_locate_needs_a_pose_or_joints():
    line = one_line(run("locate", M1_YAML), 2)
    assert "--pose" in line


def test_unknown_config_key_is_an_error(tmp_path):
    bad = tmp_path / "bad.yaml"
    bad.write_text("name: X\ntype: fivebar\nlengths: {L0: 9, L1: 8, L2: 5, L3: 5, L4: 8}\nlenghts_extra: 1\n")
    for cmd in (["locate", bad, "--pose", 1, 1], ["aspects", bad, "--depth", 4, "-o", tmp_path / "o"]):
        line = one_line(run(*cmd), 2)
        assert "bad.yaml" in line and "lenghts_extra" in line
    assert not (tmp_path / "o" / "aspects.csv").exists()


def test_unreadable_config_is_an_error(tmp_path):
    missing = tmp_path / "missing.yaml"
    line = one_line(run("locate", missing, "--pose", 1, 1), 2)
    assert "missing.yaml" in line
    broken = tmp_path / "broken.yaml"
    broken.write_text("name: [\n")
    line = one_line(run("aspects", broken, "-o", tmp_path / "o2"), 2)
    assert "broken.yaml" in line
    one_line(run("locate", tmp_path, "--pose", 1, 1), 2)  # a directory


def test_bad_pose_arguments_are_usage_errors():
    one_line(run("locate", M1_YAML, "--pose", 1), 2)
    one_line(run("locate", M1_YAML, "--pose", "a", "b"), 2)
    one_line(run("locate", M1_YAML, "--pose", 1, 1, "--working-mode", "+0"), 2)


def test_m2_aspects_command(tmp_path):
    """M2 (the paper's second mechanism) also has ten aspects with a K_{2,3} crossing graph."""
    r = run("aspects", M2_YAML, "--depth", DEPTH, "-o", tmp_path, "--no-plot")
    assert r.status == 0, r.stderr
    _, rows = read_csv(tmp_path / "aspects.csv")
    assert len(rows) == 10 and [r["assembly_mode"] for r in rows].count("+") == 5
    _, edges = read_csv(tmp_path / "aspects-adjacency.csv")
    assert len(edges) == 12
