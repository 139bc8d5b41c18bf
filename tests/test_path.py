"""`fivebar path` (issue 12): certified singularity-free motions.

Every segment of every motion is sampled densely (SAMPLES points, each angle moving the short way
as docs/formats.md says) and checked against the independent kinematics of
tests/reference_kinematics.py: the loop closes in the assembly mode, det A keeps its sign and
stays away from zero, and, without --allow-serial, B11 and B22 keep the aspect's signs. The
channel geometry (chains of cells, string pulling, the exact segment check) is also tested on
synthetic cell sets, where the true answer is known.
"""

from __future__ import annotations

import csv
import io
import math
from fractions import Fraction
from pathlib import Path

import numpy as np
import pytest
from cli_helpers import one_line, run_cli
from hypothesis import HealthCheck, example, given, settings
from hypothesis import strategies as st
from reference_kinematics import ref_dkp, ref_ikp
from reference_paths import shortest_through_tree

from fivebar_cli.analyses.aspects import analyse_aspects
from fivebar_cli.analyses.channel import (
    ExactCells, Waypoint, certified_polyline, covering, find_chain, lift, segment_span,
)
from fivebar_cli.analyses.paths import Endpoint, NoPath, find_path, mode_cells, resolve
from fivebar_cli.mechanisms.fivebar.model import FiveBar
from fivebar_cli.mechanisms.registry import load_config
from fivebar_cli.paving.grid import Grid
from fivebar_cli.paving.tree import Tree

REPO = Path(__file__).resolve().parents[1]
M1_YAML, M2_YAML = REPO / "configs" / "m1.yaml", REPO / "configs" / "m2.yaml"
M1 = FiveBar("M1", 9.0, 8.0, 5.0, 5.0, 8.0)
M2 = FiveBar("M2", 2.55, 2.3, 2.3, 2.3, 2.3)
SAMPLES = 200
DEPTH = "8"
SCALE2 = (9 + 8 + 5 + 5 + 8) ** 2
TWO_PI = 2 * math.pi


def read_path(folder: Path) -> tuple[str, list[list[float]], list[list[str]]]:
    text = (folder / "path.csv").read_text()
    rows = list(csv.reader(io.StringIO(text)))
    return rows[0], [[float(v) for v in r] for r in rows[1:]], rows[1:]


def short(delta: np.ndarray) -> np.ndarray:
    return (delta + math.pi) % TWO_PI - math.pi


def samples(rows: list[list[float]]) -> np.ndarray:
    """SAMPLES points per segment of the written joints, each angle taking the short way."""
    joints = np.array([r[:2] for r in rows])
    steps = short(np.diff(joints, axis=0))
    assert np.all(np.abs(steps) < math.pi - 0.1)  # the short way is unambiguous
    t = np.linspace(0, 1, SAMPLES)[None, :, None]
    return (joints[:-1, None, :] + t * steps[:, None, :]).reshape(-1, 2)


def check_motion(m: FiveBar, rows, assembly: int, working: tuple[int, int] | None) -> None:
    """Every sample assembles in `assembly`, away from parallel singularities; with `working`,
    away from serial singularities and in that working mode."""
    pts = samples(rows)
    x, y, u, v, t, ok = ref_dkp(m, pts[:, 0], pts[:, 1], assembly)
    assert ok.all()
    assert np.all(np.sign(t) == assembly) and np.min(np.abs(t)) > 1e-6 * SCALE2
    if working is not None:
        assert np.all(np.sign(u) == working[0]) and np.all(np.sign(v) == working[1])
        assert min(np.min(np.abs(u)), np.min(np.abs(v))) > 1e-6 * SCALE2
    # the x, y columns are the pose of each waypoint
    joints = np.array([r[:2] for r in rows])
    x, y, *_ = ref_dkp(m, joints[:, 0], joints[:, 1], assembly)
    assert np.allclose(np.column_stack([x, y]), np.array([r[2:] for r in rows]), rtol=0, atol=1e-9)


def run_path(folder: Path, *args):
    return run_cli("path", *args, "--depth", DEPTH, "-o", folder, cwd=REPO)


# ---------------------------------------------------------------- motions that exist


CASES = {  # name: (config, mechanism, arguments, assembly, working mode or None with --allow-serial)
    "M1 aspect 1": (M1_YAML, M1, ["--joints", "-0.09817477", "-2.06167018", "--joints", "0.88357293", "1.47262156",
                                  "--assembly-mode", "+"], 1, (1, 1)),
    "M1 across theta = pi": (M1_YAML, M1, ["--joints", "-2.94524311", "-2.94524311", "--joints", "2.55254403",
                                           "2.94524311", "--assembly-mode", "+"], 1, (-1, -1)),
    "M1 det A < 0": (M1_YAML, M1, ["--joints", "-1.76714587", "-1.76714587", "--joints", "0.9817477", "2.94524311",
                                   "--assembly-mode", "-"], -1, (1, -1)),
    "M1 across a serial singularity": (M1_YAML, M1, ["--joints", "0.1164051378", "0.7301535101", "--joints",
                                                     "-0.4745300446", "-3.107052197", "--assembly-mode", "+",
                                                     "--allow-serial"], 1, None),
    "M2 aspect 4": (M2_YAML, M2, ["--joints", "-0.9817477", "-2.94524311", "--joints", "2.94524311", "2.15984495",
                                  "--assembly-mode", "+"], 1, (-1, 1)),
    "M2 poses": (M2_YAML, M2, ["--pose", "0.575", "1.725", "--pose", "1.5", "3.0", "--working-mode", "++"], 1, (1, 1)),
}


@pytest.fixture(scope="module")
def motions(tmp_path_factory):
    out = {}
    for name, (config, m, args, assembly, working) in CASES.items():
        folder = tmp_path_factory.mktemp("path")
        out[name] = (folder, run_path(folder, config, *args, "--no-plot" if name != "M1 aspect 1" else "-q"))
    return out


@pytest.mark.parametrize("name", list(CASES))
def test_every_segment_is_free_of_singularities(motions, name):
    config, m, args, assembly, working = CASES[name]
    folder, result = motions[name]
    assert result.status == 0, result.stderr
    header, rows, _ = read_path(folder)
    assert header == ["theta1", "theta2", "x", "y"]
    if "--allow-serial" in args:
        check_motion(m, rows, assembly, None)
    else:
        own = working
        if own is None:  # the working mode of the first configuration
            _, _, u, v, _, _ = ref_dkp(m, rows[0][0], rows[0][1], assembly)
            own = (int(np.sign(u)), int(np.sign(v)))
        check_motion(m, rows, assembly, own)


@pytest.mark.parametrize("name", list(CASES))
def test_first_and_last_rows_are_the_requested_configurations(motions, name):
    config, m, args, assembly, working = CASES[name]
    folder, _ = motions[name]
    _, rows, text = read_path(folder)
    kind = args[0]
    values = [a for a in args if a[:1].isdigit() or a[:1] == "-" and a[1:2].isdigit()]
    first, last = values[:2], values[2:4]
    if kind == "--joints":
        assert text[0][:2] == first and text[-1][:2] == last  # the very strings given
    else:
        assert [float(v) for v in text[0][2:]] == [float(v) for v in first]
        assert [float(v) for v in text[-1][2:]] == [float(v) for v in last]
        th1, th2, *_ = ref_ikp(m, float(first[0]), float(first[1]), working)
        assert abs(short(np.array([rows[0][0] - th1]))[0]) < 1e-9 and abs(short(np.array([rows[0][1] - th2]))[0]) < 1e-9


def test_the_motion_is_pulled_straight(motions):
    """String pulling: no staircase. The polyline is no longer than 1.2 times the straight line
    when the aspect is convex enough there, and much shorter than the chain of cell centres."""
    folder, _ = motions["M2 poses"]
    _, rows, _ = read_path(folder)
    joints = np.array([r[:2] for r in rows])
    length = np.sum(np.hypot(*short(np.diff(joints, axis=0)).T))
    straight = np.hypot(*short(joints[-1] - joints[0]))
    assert length <= 1.2 * straight
    folder, result = motions["M1 aspect 1"]
    assert "waypoints" in result.stdout or result.stdout == ""
    _, rows, _ = read_path(folder)
    assert len(rows) < 30


def test_crossing_theta_pi_writes_wrapped_angles(motions):
    folder, _ = motions["M1 across theta = pi"]
    _, rows, _ = read_path(folder)
    joints = np.array([r[:2] for r in rows])
    assert np.all(np.abs(joints) <= math.pi)
    assert np.any(np.abs(np.diff(joints, axis=0)) > math.pi)  # the motion crosses the seam


def test_allow_serial_changes_working_mode(motions):
    """The motion joins ++ to -+: B11 changes sign along it (a serial singularity is crossed)."""
    folder, _ = motions["M1 across a serial singularity"]
    _, rows, _ = read_path(folder)
    pts = samples(rows)
    _, _, u, v, t, ok = ref_dkp(M1, pts[:, 0], pts[:, 1], 1)
    assert ok.all() and np.sign(u[0]) == 1 and np.sign(u[-1]) == -1 and np.all(t > 0)


def test_path_figure(motions):
    folder, result = motions["M1 aspect 1"]
    assert result.stdout == ""
    data = (folder / "path.png").read_bytes()
    assert data[:8] == b"\x89PNG\r\n\x1a\n" and len(data) > 10000


def test_saved_aspect_trees_give_the_same_path(tmp_path):
    """With the aspect trees of an `aspects` run in -o, the motion is the same, byte for byte, and
    the report names the aspect."""
    args = CASES["M1 aspect 1"][2]
    cold, warm = tmp_path / "cold", tmp_path / "warm"
    assert run_cli("aspects", M1_YAML, "--depth", DEPTH, "-o", warm, "--no-plot", "-q", cwd=REPO).status == 0
    r_cold = run_path(cold, M1_YAML, *args, "--no-plot")
    r_warm = run_path(warm, M1_YAML, *args, "--no-plot")
    assert r_cold.status == 0 and r_warm.status == 0, r_warm.stderr
    assert (cold / "path.csv").read_bytes() == (warm / "path.csv").read_bytes()
    assert "in aspect 1, certified" in r_warm.stdout and "aspect trees read from" in r_warm.stdout
    assert "in one generalized aspect" in r_cold.stdout
    # and again: same bytes
    assert run_path(cold, M1_YAML, *args, "--no-plot", "-q").status == 0
    assert (cold / "path.csv").read_bytes() == (warm / "path.csv").read_bytes()


# ---------------------------------------------------------------- motions that do not exist


def serial_joints() -> tuple[list[str], str]:
    """Joints of M1 with leg 1 stretched (P on the ray A1 B1 at 13: B11 = 0), and their assembly
    mode, from the geometry: B2 on the circles (A2, L2) and (P, L4)."""
    p = 13 * np.array([math.cos(0.5), math.sin(0.5)])
    d = math.hypot(p[0] - 9, p[1])
    th2 = math.atan2(p[1], p[0] - 9) + math.acos((25 + d * d - 64) / (10 * d))
    for sign in (1, -1):
        x, y, u, *_ = ref_dkp(M1, 0.5, th2, sign)
        if abs(x - p[0]) + abs(y - p[1]) < 1e-9:
            assert abs(u) < 1e-9
            return ["0.5", repr(th2)], "+" if sign > 0 else "-"
    raise AssertionError("no assembly reaches the stretched pose")


def parallel_pose() -> tuple[list[str], str]:
    """A pose of M1 with B1, P, B2 aligned (det A = 0) and its working mode: B1 = (-8, 0), B2 on the
    circles (B1, L3 + L4) and (A2, L2), P = B1 + L3 (B2 - B1) / 13."""
    b1 = np.array([-8.0, 0.0])
    a = (169 - 25 + 17 ** 2) / (2 * 17)
    b2 = b1 + np.array([a, math.sqrt(169 - a * a)])
    p = b1 + 5 * (b2 - b1) / 13
    cross = lambda a, b: a[0] * b[1] - a[1] * b[0]  # noqa: E731
    u, v = cross(b1, p - b1), cross(b2 - np.array([9.0, 0.0]), p - b2)
    return [repr(float(p[0])), repr(float(p[1]))], ("+" if u > 0 else "-") + ("+" if v > 0 else "-")


FAILURES = [  # (label, arguments, exit status, words the one line must hold)
    ("different assembly modes", ["--pose", "4.875", "4.875", "--pose", "4.875", "-8.125", "--working-mode", "++"], 1,
     ["assembly mode", "parallel singularity"]),
    ("different aspects", ["--joints", "-2.25801972", "-2.06167018", "--joints", "1.05537878", "2.03712649",
                           "--assembly-mode", "+"], 1, ["aspect 2", "aspect 3", "crosses a singularity"]),
    ("different working modes", ["--joints", "0.1164051378", "0.7301535101", "--joints", "-0.4745300446",
                                 "-3.107052197", "--assembly-mode", "+"], 1, ["different working modes", "--allow-serial"]),
    ("serial singularity", ["--joints", *serial_joints()[0], "--joints", *serial_joints()[0], "--assembly-mode",
                            serial_joints()[1]], 1, ["serial singularity", "B11 = 0"]),
    ("parallel singularity", ["--pose", *parallel_pose()[0], "--pose", "4.875", "4.875", "--working-mode",
                              parallel_pose()[1], "--allow-serial"], 1, ["parallel singularity", "det A = 0"]),
    ("not assemblable", ["--joints", "4", "2", "--joints", "0.1", "0.7", "--assembly-mode", "+"], 1,
     ["cannot be assembled"]),
    ("unreachable pose", ["--pose", "30", "0", "--pose", "4.875", "4.875", "--working-mode", "++"], 1,
     ["not reachable"]),
    ("assembly mode needed", ["--joints", "0.1", "0.7", "--joints", "0.2", "0.8"], 2, ["--assembly-mode"]),
    ("working mode needed", ["--pose", "4", "5", "--pose", "6", "8"], 2, ["--working-mode", "++, +-, -+, --"]),
    ("one endpoint", ["--joints", "0.1", "0.7", "--assembly-mode", "+"], 2, ["two endpoints"]),
    ("three endpoints", ["--joints", "0.1", "0.7", "--joints", "0.2", "0.8", "--pose", "4", "5"], 2, ["two endpoints"]),
    ("working modes miscounted", ["--pose", "4", "5", "--pose", "6", "8", "--working-mode", "++", "--working-mode",
                                  "+-", "--working-mode", "--"], 2, ["--working-mode"]),
    ("working mode of joints", ["--joints", "-0.1", "-2.06", "--joints", "0.88", "1.47", "--assembly-mode", "+",
                                "--working-mode", "--"], 2, ["--working-mode", "joints decide their own working mode"]),
]


@pytest.mark.parametrize("label,args,status,needles", FAILURES, ids=[f[0] for f in FAILURES])
def test_no_motion_is_one_line_with_the_reason(tmp_path, label, args, status, needles):
    result = run_path(tmp_path, M1_YAML, *args, "--no-plot")
    one_line(result, status, *needles)
    assert not (tmp_path / "path.csv").exists()


# ---------------------------------------------------------------- random motions in the aspects


@pytest.fixture(scope="module")
def analyses():
    return {m.name: analyse_aspects(m, 8, shapes=False) for m in (M1, M2)}


@settings(max_examples=25, deadline=None, suppress_health_check=[HealthCheck.function_scoped_fixture])
@given(data=st.data())
def test_random_motions_inside_aspects(analyses, data):
    """Two random points of the black cells of one aspect: when a chain of edge-sharing cells joins
    them, the motion exists and every sample of it is in the aspect's modes; otherwise NoPath."""
    m = data.draw(st.sampled_from([M1, M2]))
    a = data.draw(st.sampled_from(analyses[m.name].aspects))
    lo, hi = a.jointspace.bounds()
    picks = [data.draw(st.integers(0, len(lo) - 1)) for _ in range(2)]
    fractions = [data.draw(st.tuples(st.floats(0.05, 0.95), st.floats(0.05, 0.95))) for _ in range(2)]
    points = [lo[k] + np.array(f) * (hi[k] - lo[k]) for k, f in zip(picks, fractions)]
    sign = "+" if a.assembly > 0 else "-"
    endpoints = [Endpoint("joints", tuple(float(v) for v in p)) for p in points]
    start, end = resolve(m, endpoints, sign, "random")
    try:
        result = find_path(m, 8, start, end)
    except NoPath as exc:
        assert "no chain of certified cells" in str(exc) or "aspect" in str(exc)
        return
    rows = [list(j) + list(p) for j, p in zip(result.joints, result.poses)]
    check_motion(m, rows, a.assembly, a.working)
    assert list(result.joints[0]) == list(points[0]) and list(result.joints[-1]) == list(points[1])


# ---------------------------------------------------------------- the geometry on synthetic cells


def cells(grid: Grid, coords) -> Tree:
    return Tree.from_cells(grid, grid.depth, np.array(coords))


def inside_closed(tree: Tree, pts: np.ndarray, tol: float = 1e-12) -> np.ndarray:
    lo, hi = tree.bounds()
    return np.any(np.all((pts[:, None, :] >= lo[None] - tol) & (pts[:, None, :] <= hi[None] + tol), axis=2), axis=1)


def test_u_shaped_channel_goes_round_the_corner():
    """Cells of a U (root [0, 8]^2, unit cells): from the top of the left arm to the top of the
    right arm the shortest polyline hugs the two inner corners (2, 2) and (6, 2)."""
    grid = Grid(((0.0, 8.0), (0.0, 8.0)), 3, (False, False))
    u = [(x, y) for x in range(8) for y in range(8) if x < 2 or x >= 6 or y < 2]
    tree = cells(grid, u)
    start, end = np.array([1.0, 7.5]), np.array([7.0, 7.5])
    chain = find_chain(tree, int(tree.locate(start[None])[0]), int(tree.locate(end[None])[0]), start)
    points, _ = certified_polyline(chain, start, lift(chain, end))
    path = np.array([p.at for p in points])
    expected = np.hypot(1, 5.5) * 2 + 4  # down to the corner, across, up
    length = np.sum(np.hypot(*np.diff(path, axis=0).T))
    assert expected <= length <= expected + 4 * 2.0 ** -10 * 2  # portals keep 2^-10 cell off the corners
    assert len(path) <= 6
    t = np.linspace(0, 1, 500)[None, :, None]
    pts = (path[:-1, None] + t * (path[1:, None] - path[:-1, None])).reshape(-1, 2)
    assert inside_closed(tree, pts).all()


def test_corner_contact_is_not_a_channel():
    grid = Grid(((0.0, 4.0), (0.0, 4.0)), 2, (False, False))
    tree = cells(grid, [(0, 0), (1, 1)])
    assert find_chain(tree, 0, 1, np.array([0.5, 0.5])) is None


def test_channel_wraps_around_the_torus():
    """A band of cells along theta1 = +-pi: the motion from theta1 = 3 to theta1 = -3 crosses the
    seam (4 cells), it does not go the long way (the band does not reach theta1 = 0)."""
    grid = Grid(((-np.pi, np.pi), (-np.pi, np.pi)), 4, (True, True))
    band = [(x, y) for x in (0, 1, 14, 15) for y in range(6, 10)]
    tree = cells(grid, band)
    start, end = np.array([3.0, 0.1]), np.array([-3.0, -0.1])
    chain = find_chain(tree, int(tree.locate(start[None])[0]), int(tree.locate(end[None])[0]), start)
    points, _ = certified_polyline(chain, start, lift(chain, end))
    assert [float(v) for v in points[0].at] == [3.0, 0.1] and [float(v) for v in points[-1].at] == [-3.0, -0.1]
    unwrapped = np.array([p.unwrapped(grid) for p in points])
    assert unwrapped[-1, 0] == pytest.approx(-3.0 + 2 * np.pi)
    assert np.sum(np.hypot(*np.diff(unwrapped, axis=0).T)) == pytest.approx(np.hypot(2 * np.pi - 6, 0.2))


def test_exact_check_refuses_a_segment_leaving_the_cells_by_a_hair():
    """Along the shared edge of two cells: covered; 1e-12 outside the union: not covered; a
    segment through a cell that is not in the chain: not covered."""
    grid = Grid(((0.0, 4.0), (0.0, 4.0)), 2, (False, False))
    tree = cells(grid, [(0, 0), (1, 0), (1, 1)])
    chain = find_chain(tree, 0, 2, np.array([0.5, 0.5]))
    exact = ExactCells(chain)

    def w(x, y):
        return Waypoint(np.array([x, y]), (0, 0))

    assert exact.covers(w(0.0, 1.0), w(2.0, 1.0))  # the top edge of the bottom row
    assert exact.covers(w(1.0, 0.0), w(1.0, 2.0))  # the left edges of (1, 0) and (1, 1)
    assert exact.covers(w(0.5, 0.5), w(1.5, 1.5))  # exactly through the corner (1, 1)
    assert not exact.covers(w(0.5, 0.5), w(1.5, 1.5 + 1e-12))  # misses the corner: through (0, 1) by 5e-13
    assert not exact.covers(w(0.2, 0.2), w(0.9, 1.9))  # through the cell (0, 1), not in the set
    assert not exact.covers(w(0.0, 1.0), w(1.0, 1.0 + 2.0 ** -40))  # above y = 1 left of x = 1
    assert not exact.covers(w(0.5, 0.5), w(2.0 + 2.0 ** -40, 0.5))  # ends outside the cells
    assert exact.covers(w(0.5, 0.5), w(2.0 + 2.0 ** -52, 0.5))  # within the one-ulp widening (4 ulp tested)


small_fractions = st.fractions(min_value=-4, max_value=4, max_denominator=8)


@settings(max_examples=200, deadline=None)
@given(box=st.lists(st.tuples(small_fractions, small_fractions).map(sorted), min_size=1, max_size=3),
       data=st.data())
def test_segment_span_is_where_the_segment_is_in_the_box(box, data):
    """`segment_span` (the exact check's clipping, shared by `path` and the 3-D paths) against the
    definition: at t = k/48 on [0, 1] (and at the span's ends), start + t * step is in the closed box
    exactly when t is in the span."""
    start = data.draw(st.lists(small_fractions, min_size=len(box), max_size=len(box)))
    step = data.draw(st.lists(small_fractions, min_size=len(box), max_size=len(box)))

    def inside(t):
        return all(lo <= x + t * d <= hi for (lo, hi), x, d in zip(box, start, step))

    span = segment_span(box, start, step)
    ts = [Fraction(k, 48) for k in range(49)]
    if span is None:
        assert not any(inside(t) for t in ts)
    else:
        t0, t1 = span
        assert 0 <= t0 <= t1 <= 1 and inside(t0) and inside(t1)
        assert all(inside(t) == (t0 <= t <= t1) for t in ts)


def test_covering_needs_the_whole_unit_interval_and_names_the_spans_that_extend_it():
    f = Fraction
    assert covering([(f(1, 2), f(1), "b"), (f(0), f(1, 2), "a")]) == ["a", "b"]  # touching at 1/2
    assert covering([(f(0), f(3, 4), "a"), (f(1, 4), f(1, 2), "inner"), (f(1, 2), f(1), "b")]) == ["a", "b"]
    assert covering([(f(0), f(1, 2), "a"), (f(2, 3), f(1), "b")]) is None  # a gap (1/2, 2/3)
    assert covering([(f(1, 8), f(1), "a")]) is None  # 0 itself is not covered
    assert covering([(f(0), f(7, 8), "a")]) is None
    assert covering([]) is None


def random_motion(seed: int, periodic: bool, depth: int, density: float):
    """Random cells of a 2^depth x 2^depth grid (a torus, or [0, 2^depth]^2), two random points of
    two of them and the certified motion between them: (tree, start, end, waypoints), or None when
    no chain of cells joins them."""
    rng = np.random.default_rng(seed)
    n = 1 << depth
    root = ((-np.pi, np.pi), (-np.pi, np.pi)) if periodic else ((0.0, float(n)), (0.0, float(n)))
    coords = np.argwhere(rng.random((n, n)) < density)
    if len(coords) < 2:
        return None
    tree = cells(Grid(root, depth, (periodic, periodic)), coords)
    a, b = rng.choice(len(tree), 2, replace=False)
    lo, hi = tree.bounds()
    start = lo[a] + rng.uniform(0.1, 0.9, 2) * (hi[a] - lo[a])
    end = lo[b] + rng.uniform(0.1, 0.9, 2) * (hi[b] - lo[b])
    chain = find_chain(tree, int(a), int(b), start)
    if chain is None:
        return None
    return tree, start, end, certified_polyline(chain, start, lift(chain, end))[0]


@settings(max_examples=40, deadline=None)
@given(seed=st.integers(0, 10 ** 6), periodic=st.booleans())
def test_random_cell_sets(seed, periodic):
    """Random cells on an 8 x 8 grid: whenever a chain joins two cells, every sampled point of the
    polyline lies in the union of the closed cells (wrapped on a torus)."""
    motion = random_motion(seed, periodic, 3, 0.6)
    if motion is None:
        return
    tree, start, end, points = motion
    path = np.array([p.unwrapped(tree.grid) for p in points])
    t = np.linspace(0, 1, 300)[None, :, None]
    pts = (path[:-1, None] + t * (path[1:, None] - path[:-1, None])).reshape(-1, 2)
    if periodic:  # wrapped, and on the seam theta = -pi also as theta = pi
        pts = (pts + np.pi) % (2 * np.pi) - np.pi
        copies = [pts + 2 * np.pi * np.array(s) for s in ((0, 0), (1, 0), (0, 1), (1, 1))]
        assert np.any([inside_closed(tree, c, tol=1e-9) for c in copies], axis=0).all()
    else:
        assert inside_closed(tree, pts, tol=1e-9).all()
    assert np.allclose(points[0].at, start) and np.allclose(points[-1].at, end)


# ---------------------------------------------------------------- short motions (issue 20)


@pytest.mark.parametrize("config,m,start,end,assembly,straight", [
    (REPO / "configs" / "rpr2.yaml", None, ("5", "6"), ("10", "12"), "+", math.sqrt(61)),
    (M1_YAML, M1, ("0", "1"), ("0.6", "0.6"), "+", math.sqrt(0.52)),
], ids=["2-RPR (5, 6) -> (10, 12)", "M1 (0, 1) -> (0.6, 0.6)"])
def test_a_straight_segment_in_the_cells_comes_back_as_it_is(tmp_path, config, m, start, end, assembly, straight):
    """The issue's two motions: the straight segment lies in the certified cells (shapely's
    shortest polyline through the same cells is that long), so the motion is that segment."""
    r = run_cli("path", config, "--joints", *start, "--joints", *end, "--assembly-mode", assembly, "--depth", "10",
                "-o", tmp_path, "--no-plot", cwd=REPO)
    assert r.status == 0, r.stderr
    assert f"2 waypoints, joint-space length {straight:.6g}" in r.stdout
    _, rows, text = read_path(tmp_path)
    assert [t[:2] for t in text] == [[f"{float(v)!r}" if v != "0" else "0" for v in p] for p in (start, end)]
    if m is not None:
        check_motion(m, rows, 1, (1, 1))
    mech = load_config(config)
    ends = [Endpoint("joints", tuple(float(v) for v in p)) for p in (start, end)]
    first, last = resolve(mech, ends, assembly, "test")
    cells = mode_cells(mech, 10, first.working, first.assembly)
    best = shortest_through_tree(cells, first.joints, last.joints, straight * 1.01)
    assert best == pytest.approx(straight, rel=1e-9)


@settings(max_examples=30, deadline=None)
@given(seed=st.integers(0, 10 ** 6), periodic=st.booleans(), density=st.floats(0.55, 0.8))
@example(seed=288, periodic=True, density=0.625)  # the motion winds two periods round the torus
def test_motions_are_as_short_as_the_cells_allow(seed, periodic, density):
    """Random cells on a 16 x 16 grid, holes and corner contacts included: the certified motion is
    at most 0.1 % longer than shapely's shortest polyline through the same cells (visibility graph,
    corner contacts cut), and never shorter."""
    motion = random_motion(seed, periodic, 4, density)
    if motion is None:
        return
    tree, start, end, points = motion
    path = np.array([p.unwrapped(tree.grid) for p in points])
    length = float(np.sum(np.hypot(*np.diff(path, axis=0).T)))
    best = shortest_through_tree(tree, start, end, length)
    assert best * (1 - 1e-9) <= length <= best * 1.001
