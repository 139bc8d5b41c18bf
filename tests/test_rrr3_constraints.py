"""3-RRR joint limits and obstacles (issue 23 item 1, the five-bar's contract of issue 18): the
certified box tests against an independent numpy reference on random robots with random limits
and obstacles, the certified area against Monte Carlo, an aspect count against a dense grid, and
bad input.

The reference (`configuration_ok`) computes the elbows with `rrr3_reference` (law of cosines),
the angles as atan2(u x v, u . v), and segment-obstacle contact from point-segment distances,
segment crossings and even-odd containment, nothing from fivebar_cli.
"""

from __future__ import annotations

import csv
import io

import numpy as np
import pytest
import yaml
from hypothesis import given, settings
from hypothesis import strategies as st
from scipy import ndimage

import rrr3_reference as ref
from cli_helpers import REPO, ok, one_line, run_cli

from fivebar_cli.analyses.dkp import solve
from fivebar_cli.analyses.pose_aspects import analyse_pose_aspects
from fivebar_cli.io.schema import ConfigError
from fivebar_cli.mechanisms.registry import from_description, load_config
from fivebar_cli.mechanisms.rrr3 import constraints as rrr3_constraints
from fivebar_cli.mechanisms.rrr3.boxtests import Geometry
from fivebar_cli.mechanisms.rrr3.model import REACHABLE, WORKING_MODES, Rrr3, sign_region, signs_of
from fivebar_cli.paving.engine import pave

LIMITED = REPO / "configs" / "rrr3-symmetric-limited.yaml"
NAMES = ("theta1", "theta2", "theta3", "B1", "B2", "B3")


# ---------------------------------------------------------------- the independent reference


def _segment_point(px, py, ax, ay, bx, by):
    """Distance from points to segments (broadcast)."""
    dx, dy = bx - ax, by - ay
    den = dx * dx + dy * dy
    with np.errstate(invalid="ignore", divide="ignore"):
        t = np.clip(np.where(den > 0, ((px - ax) * dx + (py - ay) * dy) / den, 0.0), 0.0, 1.0)
    return np.hypot(ax + t * dx - px, ay + t * dy - py)


def _orient(ax, ay, bx, by, cx, cy):
    return np.sign((bx - ax) * (cy - ay) - (by - ay) * (cx - ax))


def _polygon_distance(poly, a, b):
    """Distance from segments [a, b] ((n, 2)) to a closed polygon (0 where they meet)."""
    v = np.asarray(poly, float)
    w = np.roll(v, -1, axis=0)
    ax, ay, bx, by = (t[:, None] for t in (a[:, 0], a[:, 1], b[:, 0], b[:, 1]))
    cx, cy, dx, dy = v[:, 0], v[:, 1], w[:, 0], w[:, 1]
    cross = ((_orient(ax, ay, bx, by, cx, cy) * _orient(ax, ay, bx, by, dx, dy) <= 0)
             & (_orient(cx, cy, dx, dy, ax, ay) * _orient(cx, cy, dx, dy, bx, by) <= 0))
    straddle = (cy > ay) != (dy > ay)
    with np.errstate(invalid="ignore", divide="ignore"):
        at = cx + (ay - cy) * (dx - cx) / (dy - cy)
    inside = np.count_nonzero(straddle & (ax < at), axis=1) % 2 == 1
    d = np.minimum.reduce([_segment_point(ax, ay, cx, cy, dx, dy), _segment_point(bx, by, cx, cy, dx, dy),
                           _segment_point(cx, cy, ax, ay, bx, by), _segment_point(dx, dy, ax, ay, bx, by)])
    return np.where(np.any(cross, axis=1) | inside, 0.0, d.min(axis=1))


def configuration_ok(m: Rrr3, spec: dict, poses: np.ndarray, signs) -> tuple[np.ndarray, np.ndarray]:
    """(reachable, every constraint of `spec` holds) at poses (n, 3) in working mode `signs`."""
    base, platform = np.asarray(m.base, float), m.platform
    reach = ref.valid(m.base, platform, m.proximal, m.distal, poses)
    theta = ref.joint_angles(m.base, platform, m.proximal, m.distal, poses, signs)
    b = base[None] + np.asarray(m.proximal)[:, None] * np.stack([np.cos(theta), np.sin(theta)], -1)
    c, _ = ref.platform_points(platform, poses)
    u, e = b - base[None], c - b
    angles = {f"theta{i + 1}": np.degrees(theta[:, i]) for i in range(3)}
    angles.update({f"B{i + 1}": np.degrees(np.arctan2(u[:, i, 0] * e[:, i, 1] - u[:, i, 1] * e[:, i, 0],
                                                      np.sum(u[:, i] * e[:, i], -1))) for i in range(3)})
    good = np.ones(len(poses), bool)
    for name, (lo, hi) in spec.get("limits", {}).items():
        good &= np.mod(angles[name] - lo, 360.0) <= hi - lo
    segments = [(np.broadcast_to(base[i], (len(poses), 2)), b[:, i]) for i in range(3)]
    segments += [(b[:, i], c[:, i]) for i in range(3)] + [(c[:, i], c[:, (i + 1) % 3]) for i in range(3)]
    for o in spec.get("obstacles", []):
        for s, t in segments:
            if "disc" in o:
                (cx, cy), r = o["disc"]["centre"], o["disc"]["radius"]
                gap = np.maximum(_segment_point(cx, cy, s[:, 0], s[:, 1], t[:, 0], t[:, 1]) - r, 0.0)
            else:
                gap = _polygon_distance(o["polygon"], s, t)
            good &= gap > spec.get("clearance", 0.0)
    return reach, good & reach


# ---------------------------------------------------------------- random constrained robots


def random_constrained(seed: int, fixed: bool) -> tuple[Rrr3, dict]:
    """A random 3-RRR (each leg reaches a random pose p0 strictly inside its annulus), random
    limits on some of the six angles, a disc and a triangle near the legs, a random clearance."""
    rng = np.random.default_rng(seed)
    while True:
        base, platform = rng.uniform(-8, 8, (3, 2)), rng.uniform(-2, 2, (3, 2))
        p0 = [*rng.uniform(-3, 3, 2), float(rng.uniform(-60, 60))]
        c, _ = ref.platform_points(platform, [p0])
        rho = np.linalg.norm(c[0] - base, axis=1)
        l1, l2 = rho * rng.uniform(0.45, 0.9, 3), rho * rng.uniform(0.45, 0.9, 3)
        if not np.all((np.abs(l1 - l2) < rho) & (rho < l1 + l2)):
            continue
        a = round(p0[2], 3)
        data = {"name": f"random-{seed}", "type": "rrr3",
                "base": {f"A{i + 1}": base[i].tolist() for i in range(3)},
                "platform": {f"C{i + 1}": platform[i].tolist() for i in range(3)},
                "legs": {"proximal": l1.tolist(), "distal": l2.tolist()}}
        data.update({"phi": a} if fixed else {"phi_range": [a - 15, a + 15]})
        limits = {}
        for name in NAMES:
            if rng.random() < 0.4:
                lo = float(rng.uniform(-180, 60))
                limits[name] = [round(lo, 2), round(float(rng.uniform(lo + 120, 180)), 2)]
        centre = c[0].mean(axis=0) + rng.uniform(1.5, 4) * np.array([np.cos(t := rng.uniform(0, 6.3)), np.sin(t)])
        tri = c[0].mean(axis=0) - 1.5 * (centre - c[0].mean(axis=0)) + rng.uniform(-1, 1, (3, 2))
        obstacles = [{"disc": {"centre": centre.tolist(), "radius": float(rng.uniform(0.2, 0.8))}},
                     {"polygon": tri.tolist()}]
        data.update(limits=limits, obstacles=obstacles, clearance=float(rng.choice([0.0, 0.1])))
        try:
            return Rrr3.parse(data, data["name"], check_empty=False), data
        except ConfigError:  # an obstacle over a base joint, a degenerate triangle
            continue


def boxes_and_samples(m: Rrr3, rng, n: int = 48, per_box: int = 10):
    """Boxes of every size in the root box and random poses of each (corners included): lo, hi
    (n, dim) and poses (n, per_box, 3)."""
    root = np.array(m.spaces()["workspace"].root, float)
    centre = root[:, 0] + rng.random((n, len(root))) * (root[:, 1] - root[:, 0])
    width = (root[:, 1] - root[:, 0]) * 2.0 ** -rng.uniform(2, 7, (n, 1))
    lo, hi = np.maximum(centre - width / 2, root[:, 0]), np.minimum(centre + width / 2, root[:, 1])
    u = rng.random((n, per_box, len(root)))
    u[:, 0], u[:, 1] = 0.0, 1.0
    pts = lo[:, None] + u * (hi - lo)[:, None]
    if pts.shape[-1] == 2:
        pts = np.concatenate([pts, np.full((n, per_box, 1), m.phi_range[0])], -1)
    return lo, hi, pts


# ---------------------------------------------------------------- soundness


@settings(max_examples=4, deadline=None, derandomize=True)
@given(seed=st.integers(0, 10 ** 6), fixed=st.booleans())
def test_every_constrained_box_test_is_sound_at_sampled_poses(seed, fixed):
    """Per working mode: the constraints' status, each singularity-free region, the aspects' valid
    test of the sheet; and the reachable region over every mode: 1 holds at every sampled pose,
    -1 at none."""
    m, spec = random_constrained(seed, fixed)
    rng = np.random.default_rng(seed + 1)
    lo, hi, pts = boxes_and_samples(m, rng)
    n, k, _ = pts.shape
    flat = pts.reshape(-1, 3)
    g, model = Geometry.of(m), m.pose_aspect_model()
    some_mode = np.zeros((n, k), bool)
    decided = 0
    for sheet, w in enumerate(WORKING_MODES):
        reach, good = (a.reshape(n, k) for a in configuration_ok(m, spec, flat, signs_of(w)))
        some_mode |= good
        status = rrr3_constraints.mode_status(g, m.constraints, signs_of(w), lo, hi)
        assert not np.any((status == 1)[:, None] & reach & ~good), (seed, w, "constraints certified held")
        assert not np.any((status == -1)[:, None] & good), (seed, w, "constraints certified violated")
        valid = model.valid_test(sheet)(lo, hi)
        assert np.all(good[valid == 1]) and not np.any(good[valid == -1]), (seed, w, "valid_test")
        det = ref.det_a(m.base, m.platform, m.proximal, m.distal, flat, signs_of(w)).reshape(n, k)
        for s, want in (("+", 1), ("-", -1)):
            t = m.box_test("workspace", region=sign_region(w, s))(lo, hi)
            inside = good & (want * det > 0)
            assert np.all(inside[t == 1]) and not np.any(inside[t == -1]), (seed, w, s)
        decided += np.count_nonzero(status != 0)
    reachable = m.box_test("workspace")(lo, hi)
    assert np.all(some_mode[reachable == 1]) and not np.any(some_mode[reachable == -1]), seed
    assert decided > n  # the statuses decide boxes (not all 0)
    assert np.array_equal(model.valid(flat).reshape(n, k), some_mode)


def test_dkp_keeps_the_solutions_within_the_constraints():
    """The limited config over [-30, 30] degrees at the joints of a pose in +-- (within the
    constraints) and in +++ (its third leg meets the obstacle, as the reference and `locate`'s
    labels say): every solution kept satisfies its working mode's constraints (reference); the
    pose is kept in +--, left out in +++, where the robot without constraints finds it."""
    spec = {k: v for k, v in yaml.safe_load(LIMITED.read_text()).items() if k != "phi"}
    m = Rrr3.parse({**spec, "phi_range": [-30, 30]}, "limited over a range")
    model, space = m.pose_aspect_model(), m.spaces()["workspace"]
    pose = np.array([[5.0, 1.5, 0.0]])
    assert model.violated_constraints(pose, WORKING_MODES.index("+++")) == [["obstacle 1"]]
    for signs, kept in (((1, -1, -1), True), ((1, 1, 1), False)):
        assert configuration_ok(m, spec, pose, signs)[1][0] == kept
        joints = np.degrees(ref.joint_angles(m.base, m.platform, m.proximal, m.distal, pose, signs))[0]
        joints = (joints + 180.0) % 360.0 - 180.0
        result = solve(model, space, joints)
        assert result.certified
        for s in result.solutions:
            assert s.cls >= 0 and configuration_ok(m, spec, s.pose[None], signs_of(model.modes[s.cls // 2]))[1][0]
        found = [s for s in result.solutions if np.abs(s.pose - pose[0]).max() < 1e-9]
        assert len(found) == kept
    free = solve(m.unconstrained().pose_aspect_model(), space, joints)
    assert any(np.abs(s.pose - pose[0]).max() < 1e-9 for s in free.solutions)


# ---------------------------------------------------------------- areas and counts


@pytest.fixture(scope="module")
def fixed_robot():
    return random_constrained(7, fixed=True)


def test_certified_area_brackets_a_monte_carlo_estimate(fixed_robot):
    m, spec = fixed_robot
    space = m.spaces()["workspace"]
    paving = pave(space.grid(7), m.box_test("workspace", region=REACHABLE))
    inside = paving.inside.area
    possible = inside + paving.undetermined_area
    rng = np.random.default_rng(3)
    root = np.array(space.root, float)
    n = 12000
    pts = root[:, 0] + rng.random((n, 2)) * (root[:, 1] - root[:, 0])
    poses = np.column_stack([pts, np.full(n, m.phi_range[0])])
    hit = np.zeros(n, bool)
    for w in WORKING_MODES:
        hit |= configuration_ok(m, spec, poses, signs_of(w))[1]
    area = float(np.prod(root[:, 1] - root[:, 0]))
    p = hit.mean()
    sigma = area * np.sqrt(p * (1 - p) / n)
    assert 0 < inside and inside - 4 * sigma <= p * area <= possible + 4 * sigma, (inside, p * area, possible)
    assert possible - inside < 0.5 * inside  # the paving is tight enough to mean something


def grid_count(m: Rrr3, spec: dict, signs, n: int) -> int:
    """Aspects of working mode `signs` at m's orientation on an n x n grid of cell centres of the
    root box: 8-connected components of the centres within the constraints (reference) of each
    sign of det A (not within a relative 1e-9 of 0), of at least 2e-4 of the grid's centres."""
    xs = [lo + (np.arange(n) + 0.5) / n * (hi - lo) for lo, hi in m.spaces()["workspace"].root]
    grid = np.stack(np.meshgrid(*xs, indexing="ij"), -1).reshape(-1, 2)
    poses = np.column_stack([grid, np.full(len(grid), m.phi_range[0])])
    _, good = configuration_ok(m, spec, poses, signs)
    d = np.where(good, ref.det_a(m.base, m.platform, m.proximal, m.distal, poses, signs), 0.0)
    scale = float(np.max(np.abs(d))) or 1.0
    total = 0
    for sign in (1, -1):
        labels, _ = ndimage.label((sign * d > 1e-9 * scale).reshape(n, n), structure=np.ones((3, 3), bool))
        total += int(np.count_nonzero(np.bincount(labels.ravel())[1:] >= 2e-4 * n * n))
    return total


def test_constrained_aspect_count_matches_a_dense_grid():
    """One working mode at one orientation of a random robot with limits and obstacles: the
    certified count at depth 7 equals the dense-grid count within the constraints, stable over two
    resolutions; without its constraints the grid counts another number (they matter here)."""
    m, spec = random_constrained(6, fixed=True)
    m = Rrr3.parse({**spec, "working_mode": "+-+"}, "r", check_empty=False)
    counts = {grid_count(m, spec, (1, -1, 1), n) for n in (250, 350)}
    assert len(counts) == 1, counts
    analysis = analyse_pose_aspects(m, 7, budget=1 << 14)
    assert analysis.certified and len(analysis.aspects) == counts.pop()
    free = ref.aspect_count_2d(m.base, m.platform, m.proximal, m.distal, m.phi_range[0], (1, -1, 1),
                               m.spaces()["workspace"].root, 300)
    assert free != len(analysis.aspects)


# ---------------------------------------------------------------- contract


def test_the_description_words_round_trip_with_constraints():
    m = load_config(LIMITED)
    assert m.constraints and from_description(m.describe(), m.name, "test") == m
    r, _ = random_constrained(5, fixed=False)
    assert from_description(r.describe(), r.name, "test") == r


def test_figures_and_view_marks():
    m = load_config(LIMITED)
    assert [mk["kind"] for mk in m.marks("workspace")] == ["disc"]
    data = {k: v for k, v in yaml.safe_load(LIMITED.read_text()).items() if k != "phi"}
    limited = Rrr3.parse({**data, "phi_range": [-10, 10],
                          "limits": {"theta2": [-90, 120]}}, "t", check_empty=False)
    axes = limited.spaces()["jointspace"].axes
    assert not axes[1].periodic and axes[1].lo == pytest.approx(-90) and axes[1].hi == pytest.approx(120)
    assert axes[0].periodic and [mk["value"] for mk in limited.marks("jointspace")] == [-90.0, 120.0]


@pytest.mark.parametrize("change, field, words", [
    ({"limits": {"B1": [90, -90]}}, "limits.B1", "lo < hi"),
    ({"limits": {"B4": [0, 90]}}, "limits.B4", "unknown"),
    ({"limits": {"theta1": [-200, 0]}}, "limits.theta1[0]", "[-180, 180]"),
    ({"obstacles": [{"disc": {"centre": [5, 3], "radius": -1}}]}, "obstacles[0].disc.radius", ""),
    ({"obstacles": [{"polygon": [[4, 3], [6, 5], [6, 3], [4, 6]]}]}, "obstacles[0].polygon", "not simple"),
    ({"obstacles": [{"disc": {"centre": [10, 0], "radius": 0.5}}]}, "obstacles[0]", "A2"),
    ({"limits": {"B1": [-170, -10], "B2": [10, 170], "B3": [10, 170]}, "working_mode": "+++"}, "limits.B1",
     "alone leaves no configuration"),
    ({"clearance": -1}, "clearance", ""),
])
def test_bad_constraints_are_one_line_and_exit_2(tmp_path, change, field, words):
    """Through `verify` (the workspace command's bad configs are tested in test_rrr3.py)."""
    path = tmp_path / "bad.yaml"
    path.write_text(yaml.safe_dump({**yaml.safe_load(LIMITED.read_text()), **change}))
    one_line(run_cli("verify", path, "-o", tmp_path / "out"), 2, "bad.yaml", field, words)
    assert not (tmp_path / "out").exists()


def test_the_limited_config_runs(tmp_path):
    ok(run_cli("workspace", LIMITED, "--depth", "5", "--no-plot", "-o", tmp_path))


# ---------------------------------------------------------------- verify, locate, path


def test_verify_looks_only_at_the_poses_within_its_working_modes_constraints():
    """B1 limited to [10, 170] leaves no pose in a working mode whose first elbow sign is -: such a
    mode is then vacuously singularity-free (without the limit it is singular); in +-- the
    singular pose found is within the constraints (reference) with det A at rounding level."""
    from fivebar_cli.analyses.pose_verify import FREE, SINGULAR, verify

    spec = yaml.safe_load(LIMITED.read_text())
    spec["limits"] = {**spec["limits"], "B1": [10, 170]}
    m = Rrr3.parse(spec, "B1 limited")
    assert verify(m, 8, WORKING_MODES.index("-+-")).status == FREE
    assert verify(m.unconstrained(), 8, WORKING_MODES.index("-+-")).status == SINGULAR
    found = verify(m, 10, WORKING_MODES.index("+--"))
    assert found.status == SINGULAR
    pose = np.array([[*found.pose.pose, 0.0]])
    assert configuration_ok(m, spec, pose, (1, -1, -1))[1][0]
    assert abs(ref.det_a(m.base, m.platform, m.proximal, m.distal, pose, (1, -1, -1))[0]) < 1e-6


@pytest.fixture(scope="module")
def limited_range(tmp_path_factory):
    """The limited robot over phi in [-10, 10] degrees, as a config file."""
    data = {k: v for k, v in yaml.safe_load(LIMITED.read_text()).items() if k != "phi"}
    path = tmp_path_factory.mktemp("limited") / "limited-range.yaml"
    path.write_text(yaml.safe_dump({**data, "name": "limited-range", "phi_range": [-10, 10]}))
    return path, data


def test_locate_names_the_constraints_a_pose_violates_in_each_working_mode(limited_range, tmp_path):
    path, spec = limited_range
    result = ok(run_cli("locate", path, "--pose", "5", "1.5", "0", "--depth", "2", "--budget", "0", "--csv",
                        "-o", tmp_path))
    rows = list(csv.DictReader(io.StringIO(result.stdout)))
    m = load_config(path)
    assert [r["working_mode"] for r in rows] == list(WORKING_MODES)
    for r in rows:
        good = configuration_ok(m, spec, np.array([[5.0, 1.5, 0.0]]), signs_of(r["working_mode"]))[1][0]
        assert r["violates"] == ("" if good else "obstacle 1")
    assert {r["violates"] for r in rows} == {"", "obstacle 1"}


def test_a_path_stays_within_the_constraints_and_refuses_a_violating_endpoint(limited_range, tmp_path):
    path, spec = limited_range
    one_line(run_cli("path", path, "--pose", "5", "1.5", "0", "--pose", "6", "2", "5", "--working-mode", "+++",
                     "--depth", "4", "-o", tmp_path / "refused"), 1, "violates the obstacle 1", "working_mode +++")
    ok(run_cli("path", path, "--pose", "5", "1.5", "0", "--pose", "6", "2", "5", "--working-mode", "+--",
               "--depth", "5", "--no-plot", "-o", tmp_path))
    rows = np.loadtxt(tmp_path / "path.csv", delimiter=",", skiprows=1)
    a, b = rows[:-1, :3], rows[1:, :3]
    dense = (a[:, None] + np.linspace(0, 1, 200)[None, :, None] * (b - a)[:, None]).reshape(-1, 3)
    assert configuration_ok(load_config(path), spec, dense, (1, -1, -1))[1].all()


# ---------------------------------------------------------------- the singularity-free regions as .qt pairs


def test_every_working_modes_singularity_free_regions_save_as_distinct_qt_pairs(tmp_path):
    """The README's generic path (`fb.pave(m, "workspace", depth, region=r).save(folder)` for each
    region of `m.regions("workspace")`, here four of its 16): distinct .qt pairs of the limited robot,
    each naming its region; the centres of the black cells of +-- det A < 0 are within the constraints in +-- with
    det A < 0 (reference), those of its complement are not."""
    import fivebar_cli as fb

    m = load_config(LIMITED)
    spec = yaml.safe_load(LIMITED.read_text())
    assert len(m.regions("workspace")) == 17
    for w in ("+--", "-++"):
        for s in "+-":
            fb.pave(m, "workspace", 5, region=sign_region(w, s)).save(tmp_path)
    pairs = sorted(p.name for p in tmp_path.glob("singularity-free-*.qt") if ".complement" not in p.name)
    assert pairs == [f"singularity-free-{w}-det-A-{s}.qt" for w in ("+--", "-++") for s in ("minus", "plus")]
    stem = "singularity-free-+---det-A-minus"
    for colour, name in ((1, f"{stem}.qt"), (-1, f"{stem}.complement.qt")):
        qt = fb.read_qt(tmp_path / name)
        assert qt.fields["region"] == sign_region("+--", "-")
        centres = qt.tree.centres()
        poses = np.column_stack([centres, np.zeros(len(centres))])
        inside = configuration_ok(m, spec, poses, (1, -1, -1))[1] & (
            ref.det_a(m.base, m.platform, m.proximal, m.distal, poses, (1, -1, -1)) < 0)
        assert len(centres) > 10 and np.all(inside == (colour == 1))
