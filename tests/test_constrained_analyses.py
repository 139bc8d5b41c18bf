"""Every five-bar analysis under joint limits and obstacles (issue 18).

- Certified aspect counts against the independent dense grid of `reference_constrained.py`, per
  working and assembly mode: the peer's two cases (M1 with P in [-90, 90]: 12; M1 with the disc:
  28, where the peer's lower bound says 26), an actuated limit that cuts the torus open, and random
  constrained five-bars at two depths (a certified count never changes with depth).
- `aspects-split.csv`: which unconstrained aspects split, from the reference's per-mode counts.
- Paths: every segment sampled densely and checked against the independent kinematics and
  constraints (no collision, every limit, no singularity, the aspect's modes).
- locate names the violated constraint; atlas, GeoJSON, refine, view and figures under constraints.
"""

from __future__ import annotations

import csv
import json
import math
from pathlib import Path

import numpy as np
import pytest

import reference_constrained as rc
from cli_helpers import csv_rows, ok, run_cli
from reference_kinematics import ref_dkp
from fivebar_cli.analyses.aspects import analyse_aspects
from fivebar_cli.io.qtfile import read_qt
from fivebar_cli.mechanisms.fivebar.constraints import Constraints, Limit
from fivebar_cli.mechanisms.fivebar.model import FiveBar
from fivebar_cli.mechanisms.registry import load_config
from fivebar_cli.numerics.obstacles import Disc

REPO = Path(__file__).resolve().parents[1]
PASSIVE, OBSTACLE = REPO / "configs" / "m1-passive-limit.yaml", REPO / "configs" / "m1-obstacle.yaml"
M1 = (9.0, 8.0, 5.0, 5.0, 8.0)
DISC = [("disc", ((4.5, 0.0), 1.0))]
SIGN = {"+": 1, "-": -1}


def per_mode(folder: Path) -> dict:
    """Aspects per (working mode, assembly mode) from an `aspects.csv`, in the reference's keys."""
    out: dict = {}
    with open(folder / "aspects.csv") as fh:
        for row in csv.DictReader(fh):
            key = (tuple(SIGN[c] for c in row["working_mode"]), SIGN[row["assembly_mode"]])
            out[key] = out.get(key, 0) + 1
    return out


@pytest.fixture(scope="module")
def peer(tmp_path_factory) -> dict:
    """The peer's two cases at depth 10 (`fivebar aspects` into a folder) and their references."""
    out = {}
    for name, config, limits, obstacles in (("passive", PASSIVE, {"P": (-90, 90)}, ()), ("obstacle", OBSTACLE, {}, DISC)):
        folder = tmp_path_factory.mktemp(name)
        result = ok(run_cli("aspects", config, "--depth", "10", "-o", folder, "--no-plot"))
        out[name] = (folder, result.stdout, rc.stable_counts(M1, limits, obstacles, sizes=(384, 512)))
    return out


def test_m1_with_the_passive_limit_has_12_certified_aspects_per_mode_as_the_reference(peer):
    folder, stdout, reference = peer["passive"]
    assert sum(reference.values()) == 12  # the peer's count
    assert "M1-passive-limit: 12 generalized aspects at depth 10 (certified" in stdout
    assert per_mode(folder) == {k: v for k, v in reference.items() if v}
    a8 = analyse_aspects(load_config(PASSIVE), 8, shapes=False)
    assert a8.certified and len(a8.aspects) == 12  # the same certified count at depth 8


def test_m1_with_the_disc_has_28_certified_aspects_per_mode_as_the_reference(peer):
    """The peer counts 26 (a lower bound that drops small components); the grid and fivebar agree
    on 28: the two extra ones are the tiny aspects of the README's comparison."""
    folder, stdout, reference = peer["obstacle"]
    assert sum(reference.values()) == 28
    assert "M1-obstacle: 28 generalized aspects at depth 10 (certified" in stdout
    assert per_mode(folder) == {k: v for k, v in reference.items() if v}


def test_aspects_split_names_what_each_constrained_aspect_comes_from(peer):
    """P in [-90, 90]: the reference has two aspects in modes (--, +) and (++, -), where M1 has one
    each (rc.counts without constraints): exactly those two unconstrained aspects split in two."""
    folder, stdout, reference = peer["passive"]
    free = rc.counts(M1, {}, (), 0.0, 384)
    split_modes = {k for k in reference if reference[k] > free[k]}
    assert split_modes == {((-1, -1), 1), ((1, 1), -1)}
    rows = csv_rows(folder / "aspects-split.csv")
    assert list(rows[0]) == ["constrained_aspect", "unconstrained_aspect", "working_mode", "assembly_mode", "parts",
                             "workspace_area", "unconstrained_workspace_area", "workspace_kept", "jointspace_area",
                             "unconstrained_jointspace_area", "jointspace_kept", "certified"]
    assert sorted(int(r["constrained_aspect"]) for r in rows) == list(range(1, 13))
    by_parent: dict = {}
    for r in rows:
        by_parent.setdefault(int(r["unconstrained_aspect"]), []).append(r)
        assert r["certified"] == "true"
        assert float(r["workspace_area"]) <= float(r["unconstrained_workspace_area"])
        assert math.isclose(float(r["workspace_kept"]), float(r["workspace_area"]) / float(r["unconstrained_workspace_area"]),
                            rel_tol=1e-9)
    assert sorted(by_parent) == list(range(1, 11))  # every unconstrained aspect keeps a part
    split = {(tuple(SIGN[c] for c in rs[0]["working_mode"]), SIGN[rs[0]["assembly_mode"]])
             for rs in by_parent.values() if len(rs) == 2}
    assert split == split_modes and all(int(r["parts"]) == len(by_parent[int(r["unconstrained_aspect"])]) for r in rows)
    assert "constraints: the 10 unconstrained aspects give 12: 2 split (into 2, 2 parts), 8 whole" in stdout
    # the aspects' own areas: aspects.csv and aspects-split.csv agree
    areas = {int(r["aspect"]): r["workspace_area"] for r in csv_rows(folder / "aspects.csv")}
    assert all(areas[int(r["constrained_aspect"])] == r["workspace_area"] for r in rows)


def test_a_run_without_constraints_removes_an_earlier_split_table(tmp_path):
    (tmp_path / "aspects-split.csv").write_text("stale\n")
    ok(run_cli("aspects", REPO / "configs" / "m1.yaml", "--depth", "6", "-o", tmp_path, "--no-plot", "--quiet"))
    assert not (tmp_path / "aspects-split.csv").exists()


def test_an_actuated_limit_cuts_the_torus_open():
    """theta2 limited to [-170, 170]: the joint space is a plain rectangle in theta2; aspects of M1
    that crossed theta2 = 180 are cut there. Certified counts per mode equal the reference's."""
    m = FiveBar("M1-cut", *M1, constraints=Constraints((Limit("theta2", -170, 170),)))
    reference = rc.stable_counts(M1, {"theta2": (-170, 170)}, (), sizes=(384, 512))
    a = analyse_aspects(m, 8, shapes=False)
    assert a.certified
    got: dict = {}
    for x in a.aspects:
        got[(x.working, x.assembly)] = got.get((x.working, x.assembly), 0) + 1
    assert got == {k: v for k, v in reference.items() if v}
    assert sum(reference.values()) > 10  # the cut splits some aspect of M1
    grid = a.regions[-1].paving.grid
    assert grid.periodic == (True, False) and grid.root[1] == m.spaces()["jointspace"].root[1]


def test_a_joint_space_only_aspect_under_actuated_limits_is_split_by_overlap(tmp_path):
    """M1 with its limits, robust for T = 0.05, at depth 6: two constrained aspects have joint-space
    cells only, on a root cut by the actuated limits, so no centre of theirs lies in a black cell of
    the whole torus's paving (the command failed: "internal error: constrained aspect 5 lies in no
    unconstrained aspect"). The aspect named is one whose black cells overlap theirs: checked here
    with shapely (box unions, an intersection of positive area), on the torus's coordinates."""
    import shapely

    import fivebar_cli as fb

    a = fb.aspects(REPO / "configs" / "m1-limited.yaml", 6, tolerance=0.05, compare=True, budget=0)  # (1 s)
    thin = [x for x in a if x.workspace_area == 0]
    assert len(thin) == 2
    rows = {r.constrained.number: r for r in a.split if r.constrained is not None}
    for x in thin:
        row = rows[x.number]
        u, c = row.unconstrained, row.constrained
        assert (u.working, u.assembly) == (c.working, c.assembly)

        def union(tree):
            lo, hi = tree.bounds()
            return shapely.union_all(shapely.box(lo[:, 0], lo[:, 1], hi[:, 0], hi[:, 1]))

        assert union(x.jointspace).intersection(union(row.unconstrained.jointspace)).area > 0
        assert not row.certified  # (not every cell of it overlaps: hedged)
    ok(run_cli("aspects", REPO / "configs" / "m1-limited.yaml", "--tolerance", "0.05", "--depth", "6", "--budget", "0",
               "-o", tmp_path, "--no-plot", "--quiet"))
    assert len(csv_rows(tmp_path / "aspects-split.csv")) == len(a.split)


RANDOM = [  # (lengths, limits, obstacles): random designs whose grid count is stable at 384 and 512 pixels
    ((0.86, 0.9, 1.41, 0.69, 1.2), {"B2": (-90, 81)}, [("disc", ((0.2, -0.23), 0.16))]),
    ((0.73, 1.1, 1.2, 0.63, 0.75), {"theta1": (-68, 68)}, [("disc", ((0.2, 0.45), 0.15))]),
][:1]


def _mechanism(lengths, limits, obstacles) -> FiveBar:
    c = Constraints(tuple(Limit(n, *limits[n]) for n in ("theta1", "theta2", "B1", "B2", "P") if n in limits),
                    tuple(Disc(*v) for _, v in obstacles))
    return FiveBar("random", *lengths, constraints=c)


@pytest.mark.parametrize("case", range(len(RANDOM)))
def test_random_constrained_counts_match_the_reference_and_do_not_change_with_depth(case):
    lengths, limits, obstacles = RANDOM[case]
    m = _mechanism(lengths, limits, obstacles)
    reference = rc.stable_counts(lengths, limits, obstacles, sizes=(384, 512))
    runs = {d: analyse_aspects(m, d, shapes=False) for d in (8, 9)}
    counts = {len(a.aspects) for a in runs.values() if a.certified}
    assert len(counts) == 1  # certified at least once, and never two different certified counts
    if reference is not None:
        assert counts == {sum(reference.values())}
        assert all(a.lower <= sum(reference.values()) <= a.upper for a in runs.values())


# ---------------------------------------------------------------- paths, point by point


def _segment_samples(rows, periodic, n: int = 400) -> np.ndarray:
    joints = np.array([r[:2] for r in rows])
    steps = np.diff(joints, axis=0)
    for axis, wrap in enumerate(periodic):
        if wrap:
            steps[:, axis] = (steps[:, axis] + math.pi) % (2 * math.pi) - math.pi
    t = np.linspace(0, 1, n)[None, :, None]
    return (joints[:-1, None, :] + t * steps[:, None, :]).reshape(-1, 2)


def check_path(folder: Path, config: Path, limits, obstacles, assembly: int, working=None):
    m = load_config(config)
    with open(folder / "path.csv") as fh:
        rows = [[float(v) for v in r] for r in list(csv.reader(fh))[1:]]
    pts = _segment_samples(rows, m.spaces()["jointspace"].grid(1).periodic)
    ref = FiveBar("ref", *M1)
    x, y, u, v, t, exists = ref_dkp(ref, pts[:, 0], pts[:, 1], assembly)
    assert exists.all()
    p = np.stack([x, y], -1)
    assert rc.allowed(M1, limits, obstacles, 0.0, pts[:, 0], pts[:, 1], p).all()  # no collision, every limit
    tol = 1e-9 * sum(M1) ** 2
    assert (np.sign(t) == assembly).all() and (np.abs(t) > tol).all()  # no parallel singularity
    if working is not None:
        assert (np.sign(u) == working[0]).all() and (np.sign(v) == working[1]).all()
        assert (np.abs(u) > tol).all() and (np.abs(v) > tol).all()
    space = m.spaces()["jointspace"]
    for axis, a in enumerate(space.axes):
        if not a.periodic:  # a limited axis: the motion stays within its limits, never wraps
            assert ((pts[:, axis] >= a.lo - 1e-12) & (pts[:, axis] <= a.hi + 1e-12)).all()
    return rows


def _far_apart_cells(folder: Path, aspect: int) -> tuple[np.ndarray, np.ndarray]:
    tree = read_qt(folder / "aspects" / f"aspect-{aspect:02d}.jointspace.qt").tree
    big = np.argsort(tree.level)[:40]
    centres = tree.centres()[big]
    d = np.linalg.norm(centres[:, None] - centres[None], axis=2)
    i, j = np.unravel_index(np.argmax(d), d.shape)
    return centres[i], centres[j]


def test_paths_around_the_disc_are_collision_and_singularity_free_point_by_point(peer):
    folder = peer["obstacle"][0]
    rows = csv_rows(folder / "aspects.csv")
    biggest = max(rows, key=lambda r: float(r["jointspace_area"]))
    a, b = _far_apart_cells(folder, int(biggest["aspect"]))
    am = biggest["assembly_mode"]
    ok(run_cli("path", OBSTACLE, "--joints", *a, "--joints", *b, "--assembly-mode", am, "--depth", "10", "-o", folder,
               "--no-plot"))
    path = check_path(folder, OBSTACLE, {}, DISC, SIGN[am], tuple(SIGN[c] for c in biggest["working_mode"]))
    assert len(path) >= 2


def test_paths_across_serial_singularities_stay_within_the_constraints(tmp_path):
    """--allow-serial under the P limit: the motion may change working mode, never crosses a
    parallel singularity and never leaves [-90, 90] at P."""
    start, end = (0.1, 0.7), (-0.5, -3.1)
    ok(run_cli("path", PASSIVE, "--joints", *start, "--joints", *end, "--assembly-mode", "+", "--allow-serial",
               "--depth", "8", "-o", tmp_path, "--no-plot"))
    check_path(tmp_path, PASSIVE, {"P": (-90, 90)}, (), 1)


def test_a_path_on_a_limited_joint_axis_never_wraps(tmp_path):
    """theta1 in [-60, 150]: a non-periodic axis; a motion between its two ends stays inside."""
    config = tmp_path / "lim.yaml"
    config.write_text("name: lim\ntype: fivebar\nlengths: {L0: 9, L1: 8, L2: 5, L3: 5, L4: 8}\n"
                      "limits: {theta1: [-60, 150]}\n")
    ok(run_cli("path", config, "--joints", 2.3, 2.5, "--joints", -0.8, -1.4, "--assembly-mode", "+", "--allow-serial",
               "--depth", "8", "-o", tmp_path, "--no-plot"))
    rows = check_path(tmp_path, config, {"theta1": (-60, 150)}, (), 1)
    assert all(-math.radians(60) <= r[0] <= math.radians(150) for r in rows)


def test_a_path_from_a_colliding_configuration_is_refused_with_the_constraint(tmp_path):
    r = run_cli("path", OBSTACLE, "--pose", 4.5, 1.5, "--pose", 4, 5, "--working-mode", "++", "--depth", "6",
                "-o", tmp_path)
    assert r.status == 1 and r.stderr == ("fivebar: error: pose (4.5, 1.5) violates the obstacle 1: no motion within "
                                          "the constraints starts or ends there\n")


# ---------------------------------------------------------------- locate, atlas, GeoJSON, refine, view, figures


def test_locate_names_the_violated_constraint(peer):
    folder = peer["obstacle"][0]
    result = ok(run_cli("locate", OBSTACLE, "--pose", 4.5, 1.5, "--depth", "10", "-o", folder, "--csv"))
    rows = list(csv.DictReader(result.stdout.splitlines()))
    assert list(rows[0])[-1] == "violates"
    for r in rows:
        joints = np.array([[float(r["theta1"]), float(r["theta2"])]])
        allowed = rc.allowed(M1, {}, DISC, 0.0, joints[:, 0], joints[:, 1], np.array([[4.5, 1.5]]))[0]
        assert r["violates"] == ("" if allowed else "obstacle 1")
        assert (r["aspect"] == "") == (not allowed)
    text = ok(run_cli("locate", OBSTACLE, "--pose", 4.5, 1.5, "--depth", "10", "-o", folder)).stdout
    assert "-> violates the obstacle 1 (in no aspect)" in text


def test_locate_without_constraints_keeps_its_columns():
    result = ok(run_cli("locate", REPO / "configs" / "m1.yaml", "--pose", 4, 5, "--depth", "6", "--csv"))
    assert result.stdout.splitlines()[0] == ("input,location,x,y,theta1,theta2,working_mode,assembly_mode,aspect,"
                                             "singular,aspect_certified")


def test_atlas_designs_carry_the_specs_constraints(tmp_path):
    spec = tmp_path / "atlas.yaml"
    spec.write_text("name: atlas-limit\ntype: fivebar-atlas\nlengths: {L0: 9, L1: 8, L2: 5, L3: 5, L4: [8, 8.5, 2]}\n"
                    "limits: {P: [-90, 90]}\ndepth: 8\n")
    ok(run_cli("atlas", spec, "--workers", "0", "-o", tmp_path / "atlas", "--no-plot", "--quiet"))
    first = csv_rows(tmp_path / "atlas" / "atlas.csv")[0]
    assert (first["aspects"], first["certified"]) == ("12", "true")  # as `fivebar aspects` (the peer's count)
    ok(run_cli("workspace", PASSIVE, "--depth", "8", "-o", tmp_path / "ws", "--no-plot", "--quiet"))
    ws = csv_rows(tmp_path / "ws" / "workspace.csv")[0]
    assert float(first["workspace_area"]) == pytest.approx(float(ws["inside_area"]), rel=1e-9)
    assert ws["exact_area"] == ""  # no closed form under constraints: the certified area instead
    manifest = json.loads((tmp_path / "atlas" / "atlas.parts" / "manifest.json").read_text())
    assert manifest["constraints"] == " P=[-90.0,90.0]"


def test_tolerance_and_kratio_under_constraints(tmp_path):
    """The tolerance study's nominal areas are the certified constrained ones (no closed form), the
    robust ones smaller; kratio counts the constrained pavings' evaluations, with no paper columns."""
    # depth 8, not 7: at 7 the 12 aspects need the join refinement (four times the time), at 8 they
    # are certified at once
    ok(run_cli("tolerance", PASSIVE, "--tolerances", "0,0.05", "--depth", "8", "-o", tmp_path / "t", "--no-plot",
               "--quiet"))
    rows = {(r["tolerance"], r["region"]): r for r in csv_rows(tmp_path / "t" / "tolerance.csv")}
    ok(run_cli("workspace", PASSIVE, "--depth", "8", "-o", tmp_path / "w", "--no-plot", "--quiet"))
    inside = float(csv_rows(tmp_path / "w" / "workspace.csv")[0]["inside_area"])
    nominal = float(rows["0", "workspace"]["nominal_area"])
    assert nominal == pytest.approx(float(rows["0", "workspace"]["robust_area"]), rel=1e-9)
    assert nominal == pytest.approx(inside, rel=0.02)  # the study paves on the widest root box
    assert float(rows["0.05", "workspace"]["robust_area"]) < nominal
    assert sum(1 for key in rows if key[0] == "0" and key[1].startswith("aspect-")) == 12
    ok(run_cli("kratio", OBSTACLE, "--depths", "6", "-o", tmp_path / "k", "--no-plot", "--quiet"))
    k = {r["space"]: r for r in csv_rows(tmp_path / "k" / "kratio.csv")}
    ok(run_cli("jointspace", OBSTACLE, "--depth", "6", "-o", tmp_path / "j", "--no-plot", "--quiet"))
    assert k["jointspace"]["evaluations"] == csv_rows(tmp_path / "j" / "jointspace.csv")[0]["evaluations"]
    assert k["jointspace"]["paper_procedure_evaluations"] == "" and k["workspace"]["saving_vs_paper"] == ""


def test_the_certified_workspace_geojson_keeps_clear_of_the_disc(tmp_path):
    from shapely.geometry import Point, shape

    ok(run_cli("workspace", OBSTACLE, "--depth", "8", "--geojson", "-o", tmp_path, "--no-plot", "--quiet"))
    region = shape(json.loads((tmp_path / "workspace.geojson").read_text())["features"][0]["geometry"])
    assert region.area == pytest.approx(read_qt(tmp_path / "workspace.qt").tree.area, rel=1e-9)
    assert region.intersection(Point(4.5, 0).buffer(0.999, 256)).area == 0  # P never inside the disc


def test_refine_resumes_a_constrained_paving_with_a_limited_axis(tmp_path):
    config = tmp_path / "lim.yaml"
    config.write_text("name: lim\ntype: fivebar\nlengths: {L0: 9, L1: 8, L2: 5, L3: 5, L4: 8}\n"
                      "limits: {theta1: [-120, 150], B2: [-150, 150]}\nobstacles: [{disc: {centre: [4.5, 2], radius: 0.8}}]\n")
    ok(run_cli("jointspace", config, "--depth", "6", "-o", tmp_path / "a", "--no-plot", "--quiet"))
    ok(run_cli("refine", tmp_path / "a" / "jointspace.qt", "--depth", "8", "-o", tmp_path / "r", "--no-plot", "--quiet"))
    ok(run_cli("jointspace", config, "--depth", "8", "-o", tmp_path / "b", "--no-plot", "--quiet"))
    for name in ("jointspace.qt", "jointspace.complement.qt"):
        refined, direct = read_qt(tmp_path / "r" / name), read_qt(tmp_path / "b" / name)
        assert refined.tree == direct.tree
    header = (tmp_path / "b" / "jointspace.qt").read_text().splitlines()
    assert "# periodic: 1" in header  # theta1 is a plain interval, theta2 still wraps
    assert any(line.startswith("# mechanism: fivebar L0=9.0") and "theta1=[-120.0,150.0]" in line for line in header)


def test_view_and_figures_mark_obstacles_and_limits(tmp_path):
    from fivebar_cli.analyses.view import gather
    from fivebar_cli.webpage.page import page_data

    config = tmp_path / "lim.yaml"
    config.write_text("name: lim\ntype: fivebar\nlengths: {L0: 9, L1: 8, L2: 5, L3: 5, L4: 8}\n"
                      "limits: {theta1: [-120, 150]}\nobstacles: [{disc: {centre: [4.5, 0], radius: 1}}]\nclearance: 0.2\n")
    ok(run_cli("workspace", config, "--depth", "6", "-o", tmp_path / "out", "--quiet"))
    ok(run_cli("jointspace", config, "--depth", "6", "-o", tmp_path / "out", "--quiet", "--no-plot"))
    data = page_data(gather([tmp_path / "out"]))
    marks = {t["space"]: t["marks"] for t in data["trees"]}
    assert marks["workspace"] == [{"kind": "disc", "centre": [4.5, 0.0], "radius": 1.0, "clearance": 0.2,
                                   "label": "obstacle 1"}]
    assert [(k["axis"], round(k["value"], 12)) for k in marks["jointspace"]] == [
        (0, round(math.radians(-120), 12)), (0, round(math.radians(150), 12))]
    joint = next(t for t in data["trees"] if t["space"] == "jointspace")
    assert joint["periodic"] == [False, True] and joint["root"][0] == list(load_config(config).spaces()["jointspace"].root[0])
    # the workspace figure shows the disc in the marks' blue at its centre
    import matplotlib.image as mpimg

    image = mpimg.imread(tmp_path / "out" / "workspace.png")[..., :3]
    blue = (image[..., 2] > 0.6) & (image[..., 0] < 0.5) & (image[..., 1] < 0.6)
    assert blue.sum() > 100
    plain = page_data(gather([REPO / "tests" / "golden" / "M1" / "workspace.qt"]))
    assert all(t["marks"] == [] for t in plain["trees"])
