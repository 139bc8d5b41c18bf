"""Certified motions of a 3-RPR in (x, y, phi) (analyses/pose_paths.py, `fivebar path` for a kind
with a pose-space aspect model): the non-singular change of assembly mode of the cuspidal robot,
every sampled point checked against an independent reference, the periodic seam, the exact
segment check, the reasons a motion does not exist, bad input."""

from __future__ import annotations

import csv

import numpy as np
import pytest
import yaml

from cli_helpers import REPO, one_line, ok, run_cli
from rpr3_reference import det_j, legs

from fivebar_cli.analyses.dkp import solve
from fivebar_cli.analyses.pose_paths import Chain, ExactCells, NoMotion, find_motion
from fivebar_cli.mechanisms.rpr3.model import Rpr3
from fivebar_cli.paving.grid import Grid
from fivebar_cli.paving.tree import Tree

CARO = REPO / "configs" / "rpr3-caro.yaml"
CUSP_LEGS = (14.98, 15.38, 12.0)


def load(path) -> Rpr3:
    return Rpr3.parse(yaml.safe_load(path.read_text()), str(path))


def samples(unwrapped: np.ndarray, per_segment: int = 200) -> np.ndarray:
    t = np.linspace(0.0, 1.0, per_segment)[:, None]
    return np.concatenate([a + t * (b - a) for a, b in zip(unwrapped[:-1], unwrapped[1:])])


@pytest.fixture(scope="module")
def caro_modes():
    """The six assembly modes of legs (14.98, 15.38, 12), solved once for the tests that start from them."""
    m = load(CARO)
    return m, solve(m.pose_aspect_model(), m.spaces()["workspace"], CUSP_LEGS).solutions


@pytest.fixture(scope="module")
def change(caro_modes):
    """The motion from assembly mode 1 to assembly mode 2 of legs (14.98, 15.38, 12): both det J > 0."""
    m, modes = caro_modes
    return m, modes, find_motion(m, 6, modes[0].pose, modes[1].pose, ("mode 1", "mode 2"), "test")


def test_a_non_singular_change_of_assembly_mode(change):
    m, modes, motion = change
    assert motion.cls == 0 and modes[0].cls == modes[1].cls == 0
    assert np.array_equal(motion.poses[0], modes[0].pose) and np.array_equal(motion.poses[-1], modes[1].pose)
    np.testing.assert_allclose(legs(m.base, m.platform, motion.poses[[0, -1]]), [CUSP_LEGS] * 2, atol=1e-9)
    points = samples(motion.motion.unwrapped())
    lengths = legs(m.base, m.platform, points)
    assert np.all((lengths >= 10.0) & (lengths <= 32.0))  # every leg in range all along
    assert np.all(det_j(m.base, m.platform, points) > 0)  # never singular
    np.testing.assert_allclose(motion.joints, legs(m.base, m.platform, motion.poses), rtol=1e-12)


def test_every_sampled_point_lies_in_the_chain_of_cells(change):
    _, _, motion = change
    chain = motion.motion.chain
    grid = chain.cells.grid
    lo, hi = chain.cells.bounds()
    shift = chain.shifts * grid.size
    lo, hi = lo[chain.leaves] + shift, hi[chain.leaves] + shift
    points = samples(motion.motion.unwrapped(), 50)
    tol = 1e-9 * float(np.max(np.abs(grid.root)))
    inside = np.any(np.all((points[:, None] >= lo[None] - tol) & (points[:, None] <= hi[None] + tol), axis=2), axis=1)
    assert inside.all()
    steps = np.abs(np.diff(motion.motion.unwrapped(), axis=0))[:, 2]
    assert np.all(steps < 0.45 * 360)
    assert np.all((motion.poses[:, 2] >= -180) & (motion.poses[:, 2] < 180))


def test_a_motion_across_the_seam_of_the_full_turn(change):
    """Two poses of aspect 1 just either side of phi = +-180: the motion wraps (a short step across
    the seam, rows written in [-180, 180))."""
    m, _, _ = change
    from fivebar_cli.analyses.pose_aspects import class_region

    cells = class_region(m.pose_aspect_model(), m.spaces()["workspace"].grid(5), 0).paving.inside
    lo, hi = cells.bounds()
    top = np.flatnonzero(hi[:, 2] == 180.0)
    bottom = np.flatnonzero(lo[:, 2] == -180.0)
    pairs = [(i, j) for i in top for j in bottom if np.all(lo[i, :2] < hi[j, :2]) and np.all(lo[j, :2] < hi[i, :2])]
    i, j = pairs[0]
    xy = 0.5 * (np.maximum(lo[i, :2], lo[j, :2]) + np.minimum(hi[i, :2], hi[j, :2]))
    start, end = np.array([*xy, 179.0]), np.array([*xy, -179.0])
    motion = find_motion(m, 5, start, end, ("a", "b"), "test")
    unwrapped = motion.motion.unwrapped()
    assert abs(unwrapped[-1, 2] - unwrapped[0, 2]) < 10  # 2 degrees the short way, not 358 back
    assert motion.motion.turns[:, 2].max() - motion.motion.turns[:, 2].min() == 1
    points = samples(unwrapped)
    assert np.all(det_j(m.base, m.platform, points) > 0)


def test_the_exact_check_says_no_to_a_segment_leaving_the_cells():
    grid = Grid(((0.0, 1.0), (0.0, 1.0), (-180.0, 180.0)), 2, (False, False, True))
    cells = Tree.from_cells(grid, 2, np.array([[0, 0, 1], [1, 0, 1], [1, 1, 1]]))
    chain = Chain(cells, np.array([0, 1, 2]), np.zeros((3, 3), np.int64))
    exact = ExactCells(chain)
    zero = (0, 0, 0)
    inside = [np.array([0.1, 0.1, -80.0]), np.array([0.4, 0.2, -60.0]), np.array([0.4, 0.45, -45.0])]
    assert exact.covers(inside[0], zero, inside[1], zero) and exact.covers(inside[1], zero, inside[2], zero)
    assert not exact.covers(inside[0], zero, inside[2], zero)  # cuts the corner of the missing cell
    eps = float(np.spacing(180.0)) * 4
    assert not exact.covers(inside[0], zero, np.array([0.1, 0.1, -90.0 - eps]), zero)  # one float too far
    assert exact.covers(inside[0], zero, np.array([0.1, 0.1, -90.0]), zero)  # the closed cell's face


def test_different_signs_and_undecided_depths_say_so(caro_modes):
    m, modes = caro_modes
    with pytest.raises(NoMotion, match="different classes: every motion between them crosses a singularity"):
        find_motion(m, 5, modes[0].pose, modes[3].pose, ("mode 1", "mode 4"), "test")
    with pytest.raises(NoMotion, match="not decided at depth 2"):
        find_motion(m, 2, modes[0].pose, modes[1].pose, ("mode 1", "mode 2"), "test")


def test_poses_in_two_certified_aspects_of_one_sign_have_no_motion():
    from test_pose_aspects import random_robot

    from fivebar_cli.analyses.pose_aspects import analyse_pose_aspects

    m = random_robot(1, False)
    analysis = analyse_pose_aspects(m, 5, budget=1 << 18)
    assert analysis.certified
    same = [(a, b) for a in analysis.aspects for b in analysis.aspects if a.number < b.number and a.cls == b.cls]
    a, b = same[0]
    with pytest.raises(NoMotion, match=f"is in aspect {a.number}, .* in aspect {b.number}: every motion"):
        find_motion(m, 5, np.array(a.pose), np.array(b.pose), ("p", "q"), "test", analysis.aspects)


# ---------------------------------------------------------------- the command


def test_path_command_writes_the_motion_and_its_figure(tmp_path):
    result = ok(run_cli("path", CARO, "--legs", *CUSP_LEGS, "--modes", "1", "2", "--depth", "6", "-o", tmp_path))
    assert "singularity-free motion in one generalized aspect: det_sign +, depth 6" in result.stdout
    with open(tmp_path / "path.csv", newline="") as fh:
        rows = list(csv.reader(fh))
    assert rows[0] == ["x", "y", "phi_deg", "rho1", "rho2", "rho3"]
    values = np.array([[float(v) for v in r] for r in rows[1:]])
    np.testing.assert_allclose(values[[0, -1], 3:], [CUSP_LEGS] * 2, atol=1e-9)
    m = load(CARO)
    np.testing.assert_allclose(legs(m.base, m.platform, values[:, :3]), values[:, 3:], rtol=1e-12)
    assert (tmp_path / "path.png").read_bytes().startswith(b"\x89PNG")


@pytest.mark.parametrize("args, status, needle", [
    (["--legs", *CUSP_LEGS, "--modes", "1", "9"], 2, "mode 9 is out of range: legs (14.98, 15.38, 12) have 6"),
    (["--legs", "10", "10", "31", "--modes", "1", "2"], 2, "give no pose"),
    (["--modes", "1", "2"], 2, "--modes needs --legs"),
    (["--pose", "0", "0", "0"], 2, "exactly two endpoints"),
    (["--pose", "-5.5", "-13.9", "-2.7", "--pose", "0", "0", "0"], 2, "not a valid pose"),
    (["--legs", *CUSP_LEGS, "--modes", "1", "4"], 1, "different classes"),
    # an option of the five-bar's command only: named as such, not as "no such option '-5'" (the
    # five-bar's reading of `--pose X Y PHI`, when neither command could parse the line)
    (["--pose", "-5.5", "-13.9", "-2.7", "--pose", "0", "0", "0", "--allow-serial"], 2,
     "No such option '--allow-serial'"),
])
def test_path_refusals_are_one_line(tmp_path, args, status, needle):
    one_line(run_cli("path", CARO, *args, "--depth", "4", "-o", tmp_path, "--no-plot"), status, needle)
    assert not (tmp_path / "path.csv").exists()


def test_a_pose_outside_the_orientation_range_is_exit_2(tmp_path):
    general = REPO / "configs" / "rpr3-general.yaml"
    one_line(run_cli("path", general, "--pose", "0", "0", "90", "--pose", "0", "0", "30", "-o", tmp_path), 2,
             "phi = 90 is outside the orientation range [0, 60]")
