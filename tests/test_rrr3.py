"""The 3-RRR (mechanisms/rrr3): soundness of every box test at sampled points on random robots
(tests/rrr3_reference.py, written from the definitions), the exact fixed-orientation area against
shapely polygons and bracketed by the certified areas, certified aspect counts against a dense-grid
count on robots no config names, verify / dkp / locate through the commands, bad input."""

from __future__ import annotations

import csv

import numpy as np
import pytest
import yaml
from hypothesis import given, settings
from hypothesis import strategies as st

import rrr3_reference as ref
from cli_helpers import csv_rows, ok, one_line, REPO, run_cli

from fivebar_cli.analyses.pose_aspects import analyse_pose_aspects
from fivebar_cli.analyses.spaces import pave_space
from fivebar_cli.io.schema import ConfigError
from fivebar_cli.mechanisms.registry import from_description, load_config
from fivebar_cli.mechanisms.rrr3.model import WORKING_MODES, Rrr3, sign_region, signs_of

SYMMETRIC = REPO / "configs" / "rrr3-symmetric.yaml"
PHI0 = REPO / "configs" / "rrr3-symmetric-phi0.yaml"


def robot(base, platform, l1, l2, phi_range, mode=None, name="r") -> Rrr3:
    data = {"name": name, "type": "rrr3",
            "base": {f"A{i + 1}": [float(v) for v in base[i]] for i in range(3)},
            "platform": {f"C{i + 1}": [float(v) for v in platform[i]] for i in range(3)},
            "legs": {"proximal": [float(v) for v in l1], "distal": [float(v) for v in l2]}}
    if phi_range[0] == phi_range[1]:
        data["phi"] = float(phi_range[0])
    else:
        data["phi_range"] = [float(v) for v in phi_range]
    if mode:
        data["working_mode"] = mode
    return Rrr3.parse(data, name)


def random_robot(seed: int, fixed: bool, mode: str | None = None) -> Rrr3:
    """Random base, platform and links (unequal per leg), one orientation or a 20 to 120 degree range."""
    rng = np.random.default_rng(seed)
    while True:
        base, platform = rng.uniform(-8, 8, (3, 2)), rng.uniform(-2.5, 2.5, (3, 2))
        l1, l2 = rng.uniform(3, 8, 3), rng.uniform(2, 8, 3)
        a = float(np.round(rng.uniform(-90, 90), 3))
        phi_range = (a, a) if fixed else (a, a + float(np.round(rng.uniform(20, 120), 3)))
        try:
            m = robot(base, platform, l1, l2, phi_range, mode, f"random-{seed}")
        except ConfigError:  # legs that never meet
            continue
        if m.exact_measure("workspace") != 0.0:
            return m


def args(m: Rrr3):
    return m.base, m.platform, m.proximal, m.distal


def sample_boxes(lo, hi, rng, per_box: int = 6) -> np.ndarray:
    """Random points of each box (its two extreme corners included): (m, per_box, dim)."""
    u = rng.random((len(lo), per_box, lo.shape[1]))
    u[:, 0], u[:, 1] = 0.0, 1.0
    return lo[:, None] + u * (hi - lo)[:, None]


def random_boxes(m: Rrr3, rng, n: int) -> tuple[np.ndarray, np.ndarray]:
    """Boxes of poses of every size, centred in the root box, some around valid poses."""
    space = m.spaces()["workspace"]
    root = np.array(space.root, float)
    centre = root[:, 0] + rng.random((n, len(root))) * (root[:, 1] - root[:, 0])
    width = (root[:, 1] - root[:, 0]) * 2.0 ** -rng.uniform(2, 9, (n, 1))
    lo, hi = np.maximum(centre - width / 2, root[:, 0]), np.minimum(centre + width / 2, root[:, 1])
    return lo, hi


def full(m: Rrr3, points: np.ndarray) -> np.ndarray:
    """(m, 2) points of a single-orientation space -> (m, 3) poses."""
    return points if points.shape[1] == 3 else np.column_stack([points, np.full(len(points), m.phi_range[0])])


# ---------------------------------------------------------------- soundness of the box tests


@settings(max_examples=4, deadline=None, derandomize=True)
@given(seed=st.integers(0, 10 ** 6), fixed=st.booleans())
def test_every_workspace_box_test_is_sound_at_sampled_poses(seed, fixed):
    """Reachable and each (working mode, det A sign) region: a box said 1 holds only poses of it, a
    box said -1 none, at random poses of random boxes of random robots."""
    m = random_robot(seed, fixed)
    rng = np.random.default_rng(seed)
    lo, hi = random_boxes(m, rng, 300)
    points = sample_boxes(lo, hi, rng).reshape(-1, lo.shape[1])
    poses = full(m, points)
    valid = ref.valid(*args(m), poses).reshape(len(lo), -1)
    status = m.box_test("workspace", region="reachable")(lo, hi)
    assert np.all(valid[status == 1]) and not np.any(valid[status == -1])
    assert np.count_nonzero(status == 1) and np.count_nonzero(status == -1)  # the tests decide something
    decided = 0
    for mode in WORKING_MODES:
        det = ref.det_a(*args(m), poses, signs_of(mode)).reshape(len(lo), -1)
        for s, want in (("+", 1), ("-", -1)):
            status = m.box_test("workspace", region=sign_region(mode, s))(lo, hi)
            inside = valid & (want * det > 0)
            assert np.all(inside[status == 1]), (mode, s)
            assert not np.any(inside[status == -1]), (mode, s)
            decided += np.count_nonzero(status == 1)
    assert decided


def test_certified_cells_of_a_paving_are_sound(tmp_path):
    """The black and white cells of a paved region (depth 6) at random poses of their leaves."""
    m = random_robot(7, fixed=False, mode="+-+")
    region = sign_region("+-+", "-")
    paving = pave_space(m, "workspace", 6, region=region)
    rng = np.random.default_rng(1)
    for tree, inside in ((paving.inside, True), (paving.outside, False)):
        lo, hi = tree.bounds()
        assert len(lo)
        poses = sample_boxes(lo, hi, rng, 4).reshape(-1, 3)
        ok_ = ref.valid(*args(m), poses) & (ref.det_a(*args(m), poses, (1, -1, 1)) < 0)
        assert np.all(ok_) if inside else not np.any(ok_)


def test_joint_space_boxes_are_sound_against_a_scan_of_the_orientation():
    """A box of actuated angles said assemblable: every sampled triple assembles (a residual changes
    sign along phi); said not assemblable: none does. Boxes around the joints of valid poses and
    anywhere on the torus, on a random robot and on the symmetric one."""
    for m, seed in ((random_robot(3, fixed=False), 3), (load_config(SYMMETRIC), 4)):
        rng = np.random.default_rng(seed)
        root = np.array(m.spaces()["workspace"].root, float)
        poses = root[:, 0] + rng.random((4000, 3)) * (root[:, 1] - root[:, 0])
        poses = poses[ref.valid(*args(m), poses)][:40]
        modes = [signs_of(WORKING_MODES[k]) for k in rng.integers(0, 8, len(poses))]
        theta = np.degrees([ref.joint_angles(*args(m), p[None], s)[0] for p, s in zip(poses, modes)])
        width = rng.uniform(0.2, 3.0, (len(theta), 1))
        anywhere = rng.uniform(-180, 170, (40, 3))
        lo = np.vstack([theta - width / 2, anywhere])
        hi = np.vstack([theta + width / 2, anywhere + rng.uniform(0.5, 10, (40, 1))])
        status = m.box_test("jointspace")(lo, hi)
        assert np.count_nonzero(status == 1) >= 5 and np.count_nonzero(status == -1) >= 5
        checked = 0
        for k in np.flatnonzero(status != 0):
            for t in sample_boxes(lo[k:k + 1], hi[k:k + 1], rng, 3)[0]:
                found = ref.assembles(*args(m), t, m.phi_range)
                if found is not None:
                    assert found == (status[k] == 1), (k, t, status[k])
                    checked += 1
        assert checked >= 20


# ---------------------------------------------------------------- exact area


@pytest.mark.parametrize("seed", [11, 12, 13])
def test_fixed_orientation_area_matches_shapely_and_is_bracketed_by_the_paving(seed):
    m = random_robot(seed, fixed=True)
    exact = m.exact_measure("workspace")
    assert exact == pytest.approx(ref.annuli_area(*args(m), m.phi_range[0]), rel=1e-9)
    paving = pave_space(m, "workspace", 7)
    inside = paving.inside.area
    assert inside <= exact <= inside + paving.undetermined_area
    assert inside > 0.5 * exact


def test_the_symmetric_robots_area_at_phi_0():
    m = load_config(PHI0)
    assert m.exact_measure("workspace") == pytest.approx(ref.annuli_area(*args(m), 0.0), rel=1e-9)


# ---------------------------------------------------------------- aspect counts


@pytest.mark.parametrize("seed, mode", [(21, "+-+"), (22, "++-"), (25, "--+")])
def test_certified_fixed_orientation_counts_match_a_dense_grid(seed, mode):
    """Robots no config names, one working mode at one orientation (Caro's experiment): the
    certified count at depth 8 equals the count of an 8-connected dense grid, stable over two
    resolutions; the bounds of depth 7 hold it."""
    m = random_robot(seed, fixed=True, mode=mode)
    root = m.spaces()["workspace"].root
    reference = {ref.aspect_count_2d(*args(m), m.phi_range[0], signs_of(mode), root, n) for n in (400, 600)}
    assert len(reference) == 1, reference
    (count,) = reference
    coarse = analyse_pose_aspects(m, 7, budget=1 << 12)
    assert coarse.lower <= count <= coarse.upper
    analysis = analyse_pose_aspects(m, 8, budget=1 << 16)
    assert analysis.certified and len(analysis.aspects) == count


def test_certified_count_over_an_orientation_range_matches_a_dense_grid():
    """A robot no config names, one working mode over 20 degrees of phi: the certified count of the
    octrees (depth 4) equals a 26-connected dense-grid count, stable over two resolutions."""
    r = random_robot(31, fixed=False)
    m = robot(r.base, r.platform, r.proximal, r.distal, (r.phi_range[0], r.phi_range[0] + 20.0), "+-+")
    root = m.spaces()["workspace"].root
    reference = {ref.aspect_count_3d(*args(m), (1, -1, 1), root, n) for n in (48, 72)}
    assert len(reference) == 1, reference
    analysis = analyse_pose_aspects(m, 4, budget=1 << 15)
    assert analysis.certified and {len(analysis.aspects)} == reference


# ---------------------------------------------------------------- the commands


@pytest.fixture(scope="module")
def symmetric_one_mode(tmp_path_factory):
    """The symmetric robot in working mode +-- (one sheet: the commands stay quick)."""
    path = tmp_path_factory.mktemp("rrr3") / "one-mode.yaml"
    data = yaml.safe_load(SYMMETRIC.read_text())
    data.update(name="one-mode", working_mode="+--", phi_range=[0, 20])
    path.write_text(yaml.safe_dump(data))
    return path


def test_dkp_finds_every_assembly_mode_of_the_joints_of_a_pose(symmetric_one_mode, tmp_path):
    m = load_config(symmetric_one_mode)
    pose = np.array([[5.0, 2.7, 8.0]])
    theta = np.degrees(ref.joint_angles(*args(m), pose, (1, -1, -1)))[0]
    theta = np.round(theta, 6)
    ok(run_cli("dkp", symmetric_one_mode, "--joints", *theta, "--depth", "3", "--budget", "0", "-o", tmp_path,
               "--no-plot"))
    rows = csv_rows(tmp_path / "dkp.csv")
    found = np.array([[float(r["x"]), float(r["y"]), float(r["phi_deg"])] for r in rows])
    assert np.min(np.abs(found - pose).max(axis=1)) < 1e-4  # the pose the joints came from
    for r, p in zip(rows, found):
        assert r["working_mode"] == "+--" and r["certified"] == "true"
        assert ref.valid(*args(m), p[None])[0]
        back = np.degrees(ref.joint_angles(*args(m), p[None], (1, -1, -1)))[0]
        assert np.allclose((back - theta + 180) % 360 - 180, 0, atol=1e-6)  # the same joints
        assert r["det_sign"] == ("+" if ref.det_a(*args(m), p[None], (1, -1, -1))[0] > 0 else "-")
    # the reference: the poses where the three circles meet, scanning phi; those in mode +--
    poses = ref.assembly_poses(*args(m), theta, m.phi_range)
    signs = ref.mode_signs(m.base, m.platform, m.proximal, poses, np.tile(theta, (len(poses), 1)))
    mine = poses[np.all(signs == (1, -1, -1), axis=1)]
    assert len(mine) == len(rows) >= 1
    assert np.abs(np.sort(mine[:, 2]) - np.sort(found[:, 2])).max() < 1e-6


def test_locate_gives_the_working_mode_and_det_sign_of_the_reference(symmetric_one_mode, tmp_path):
    m = load_config(symmetric_one_mode)
    pose = (5.0, 2.7, 8.0)
    text = ok(run_cli("locate", symmetric_one_mode, "--pose", *pose, "--depth", "3", "--budget", "0", "-o",
                      tmp_path, "--csv")).stdout
    rows = list(csv.DictReader(text.splitlines()))
    det = ref.det_a(*args(m), np.array([pose]), (1, -1, -1))[0]
    assert rows and rows[0]["working_mode"] == "+--" and rows[0]["det_sign"] == ("+" if det > 0 else "-")


def test_path_is_a_motion_of_valid_poses_of_one_class_and_refuses_two_classes(symmetric_one_mode, tmp_path):
    m = load_config(symmetric_one_mode)
    ok(run_cli("path", symmetric_one_mode, "--pose", 5, 2.7, 8, "--pose", 5.5, 3, 12, "--working-mode", "+--",
               "--depth", "5", "-o", tmp_path, "--no-plot"))
    rows = csv_rows(tmp_path / "path.csv")
    way = np.array([[float(r[k]) for k in ("x", "y", "phi_deg")] for r in rows])
    assert np.allclose(way[0], (5, 2.7, 8)) and np.allclose(way[-1], (5.5, 3, 12))
    t = np.linspace(0, 1, 200)[:, None]
    along = np.vstack([a + t * (b - a) for a, b in zip(way[:-1], way[1:])])
    assert np.all(ref.valid(*args(m), along)) and np.all(ref.det_a(*args(m), along, (1, -1, -1)) < 0)
    joints = np.array([[float(r[f"theta{i}_deg"]) for i in (1, 2, 3)] for r in rows])
    back = np.degrees(ref.joint_angles(*args(m), way, (1, -1, -1)))
    assert np.allclose((back - joints + 180) % 360 - 180, 0, atol=1e-6)
    # a pose with det A > 0 in the same working mode: no singularity-free motion exists (exit 1)
    result = run_cli("path", symmetric_one_mode, "--pose", 5, 2.7, 8, "--pose", 6.37, 0.22, 17.17,
                     "--working-mode", "+--", "--depth", "5", "-o", tmp_path / "two", "--no-plot")
    assert result.status == 1 and "det_sign" in result.stderr, result.stderr


def test_verify_finds_a_valid_singular_pose_of_the_symmetric_robot(tmp_path):
    result = run_cli("verify", SYMMETRIC, "--working-mode", "+-+", "-o", tmp_path, "--no-plot")
    assert result.status == 1, result.stderr
    row = csv_rows(tmp_path / "counterexample.csv")[0]
    m = load_config(SYMMETRIC)
    pose = np.array([[float(row["x"]), float(row["y"]), float(row["phi_deg"])]])
    assert row["working_mode"] == "+-+" and ref.valid(*args(m), pose)[0]
    scale = np.prod(np.asarray(m.proximal) + np.asarray(m.distal)) * 12.0
    assert abs(ref.det_a(*args(m), pose, (1, -1, 1))[0]) < 1e-6 * scale
    verdict = csv_rows(tmp_path / "verify.csv")[0]
    assert verdict["status"] == "singular pose found" and verdict["exit"] == "1"


def test_the_description_words_round_trip():
    m = load_config(SYMMETRIC)
    assert from_description(m.describe(), m.name, "test") == m
    one = random_robot(5, fixed=True, mode="-+-")
    assert from_description(one.describe(), one.name, "test") == one


@pytest.mark.parametrize("change, field, words", [
    ({"working_mode": "+x+"}, "working_mode", "expected one of"),
    ({"legs": {"proximal": [5, 5], "distal": 5}}, "legs.proximal", "list of three"),
    ({"legs": {"proximal": -1, "distal": 5}}, "legs.proximal", ""),
    ({"legs": {"proximal": 0.1, "distal": 0.1}}, "legs", "never reach"),
    ({"base": {"A1": [0, 0], "A2": [0, 0], "A3": [5, 8]}}, "base", ""),
    ({"platform": {"C1": [0, 0], "C2": [1, 0]}}, "platform", ""),
    ({"phi_range": [30, 0]}, "phi_range", "must not exceed"),
    ({"elbows": 3}, "elbows", ""),
])
def test_bad_configs_are_one_line_and_exit_2(tmp_path, change, field, words):
    data = yaml.safe_load(SYMMETRIC.read_text())
    data.update(change)
    path = tmp_path / "bad.yaml"
    path.write_text(yaml.safe_dump(data))
    one_line(run_cli("workspace", path, "--depth", "2", "-o", tmp_path / "out"), 2, "bad.yaml", field, words)
    assert not (tmp_path / "out").exists()


def test_bad_options_are_one_line_and_exit_2(tmp_path):
    one_line(run_cli("verify", SYMMETRIC, "--working-mode", "+++-", "-o", tmp_path), 2, "--working-mode",
             "not a working mode")
    one_line(run_cli("dkp", SYMMETRIC, "--joints", "0", "0", "0", "--depth", "2", "-o", tmp_path), 2, "--joints")
    one_line(run_cli("locate", PHI0, "--pose", "5", "3", "0", "-o", tmp_path), 2, "phi")
    assert not any(tmp_path.iterdir())


@pytest.mark.parametrize("fixed", [False, True])
def test_det_a_legs_together_or_one_by_one_give_the_same_bounds(monkeypatch, fixed):
    """det A evaluates the three legs in one pass on few boxes and leg by leg on many: the same
    operations per element, so bit for bit the same bounds, Duals (mean-value form) included."""
    from fivebar_cli.mechanisms.rrr3 import boxtests as bt

    rng = np.random.default_rng(7)
    for seed in range(3):
        m = random_robot(seed, fixed)
        g = bt.Geometry.of(m)
        axes = m.spaces()["workspace"].axes
        lo, hi = np.array([a.lo for a in axes]), np.array([a.hi for a in axes])
        width = (hi - lo) * rng.choice([1e-3, 1e-2, 0.2], size=(400, 1))
        box_lo = lo + rng.random((400, len(axes))) * (hi - lo - width)
        valid = rng.random(400) < 0.8
        for signs in ((1, 1, 1), (1, -1, -1)):
            together = bt.det_enclosure(g, signs, box_lo, box_lo + width, valid)
            monkeypatch.setattr(bt, "ONE_PASS", 0)
            one_by_one = bt.det_enclosure(g, signs, box_lo, box_lo + width, valid)
            monkeypatch.undo()
            for a, b in zip(together, one_by_one):
                assert np.array_equal(a, b, equal_nan=True)
            assert np.any(together[0] > 0) or np.any(together[1] < 0)  # some boxes decided: a real check
