"""`fivebar rpr3 dkp` and analyses/dkp.py: every pose of a 3-RPR with given leg lengths, certified,
checked against the ALIAS manual's example, the cuspidal robot of Innocenti and Parenti-Castelli,
and an independent solver (below) on random robots."""

from __future__ import annotations

import csv
import math

import numpy as np
import pytest
from scipy.optimize import brentq

from cli_helpers import REPO, one_line, ok, run_cli
from rpr3_reference import det_j, legs
from test_pose_aspects import robot

from fivebar_cli.analyses.dkp import solve
from fivebar_cli.mechanisms.rpr3.model import Rpr3

CARO = REPO / "configs" / "rpr3-caro.yaml"
GENERAL = REPO / "configs" / "rpr3-general.yaml"
CUSP_LEGS = (14.98, 15.38, 12.0)


ALIAS = robot([(0, 0), (10, 0), (3, 10)], [(0, 0), (4, 0), (2, 2)], 1, 12, name="alias")
ALIAS_LEGS = (math.sqrt(50), math.sqrt(26), 5.0)


def independent_poses(base, platform, rho, phi_range=(-180.0, 180.0), samples=36001):
    """Every pose with leg lengths rho, written from the geometry alone: at each orientation the
    differences of the three circle equations are linear in (x, y); the first equation left over
    is a function of phi whose roots (sign changes on a dense grid, refined by Brent's method)
    are the poses. Returns (poses (n, 3), smallest |f'| at a root relative to the scale of f)."""
    base, platform, rho = (np.asarray(v, float) for v in (base, platform, rho))

    def position(phi):
        a = np.radians(np.atleast_1d(phi))
        rot = np.stack([np.stack([np.cos(a), -np.sin(a)], -1), np.stack([np.sin(a), np.cos(a)], -1)], -2)
        c = base[None] - np.einsum("nab,ib->nia", rot, platform)  # |X - c_i| = rho_i
        m = 2 * (c[:, 1:] - c[:, :1])
        r = (rho[0] ** 2 - rho[1:] ** 2)[None] - np.sum(c[:, :1] ** 2, axis=2) + np.sum(c[:, 1:] ** 2, axis=2)
        return np.linalg.solve(m, r[..., None])[..., 0], c

    def f(phi):
        x, c = position(phi)
        return np.sum((x - c[:, 0]) ** 2, axis=1) - rho[0] ** 2

    grid = np.linspace(phi_range[0], phi_range[1], samples)
    values = f(grid)
    scale = float(np.max(np.abs(values)))
    change = np.flatnonzero(values[:-1] * values[1:] < 0)
    roots = np.array([brentq(lambda p: f(p)[0], grid[k], grid[k + 1], xtol=1e-14, rtol=1e-15) for k in change])
    slopes = np.abs(f(roots + 1e-6) - f(roots - 1e-6)) / 2e-6 / scale if len(roots) else np.array([np.inf])
    poses = np.column_stack([position(roots)[0], roots]) if len(roots) else np.zeros((0, 3))
    return poses, float(slopes.min())


def test_the_alias_example_has_exactly_two_poses_to_1e_9():
    result = solve(ALIAS.pose_aspect_model(), ALIAS.spaces()["workspace"], ALIAS_LEGS)
    assert result.certified
    poses = sorted((s.pose for s in result.solutions), key=lambda p: -p[0])
    assert len(poses) == 2
    np.testing.assert_allclose(poses[0], [5.0, 5.0, 0.0], atol=1e-9)
    np.testing.assert_allclose(poses[1][:2], [3.369707, 6.216516], atol=1e-6)
    assert abs(poses[1][2] - -46.2253) < 1e-4
    # and the second to 1e-9 against the independent solver
    reference, _ = independent_poses(ALIAS.base, ALIAS.platform, ALIAS_LEGS)
    np.testing.assert_allclose(sorted(map(tuple, reference), key=lambda p: -p[0]), poses, atol=1e-9)
    for s in result.solutions:  # each box holds its pose and is tiny
        assert np.all(s.lo <= s.pose) and np.all(s.pose <= s.hi) and np.max(s.hi - s.lo) < 1e-8


def test_the_cuspidal_robot_has_six_poses_three_of_each_sign():
    m = Rpr3.parse(__import__("yaml").safe_load(CARO.read_text()), str(CARO))
    result = solve(m.pose_aspect_model(), m.spaces()["workspace"], CUSP_LEGS)
    assert result.certified and len(result.solutions) == 6
    poses = np.array([s.pose for s in result.solutions])
    signs = np.sign(det_j(m.base, m.platform, poses))
    assert sorted(signs) == [-1, -1, -1, 1, 1, 1]
    assert [s.cls for s in result.solutions] == [0, 0, 0, 1, 1, 1]  # det J > 0 first
    assert np.array_equal(signs, [1, 1, 1, -1, -1, -1])
    np.testing.assert_allclose(legs(m.base, m.platform, poses), np.tile(CUSP_LEGS, (6, 1)), atol=1e-9)
    reference, _ = independent_poses(m.base, m.platform, CUSP_LEGS)
    assert len(reference) == 6
    for p in reference:
        assert np.min(np.max(np.abs(poses - p), axis=1)) < 1e-7
    # over [0, 60] degrees (configs/rpr3-general.yaml) only the three of them in that range
    general = Rpr3.parse(__import__("yaml").safe_load(GENERAL.read_text()), str(GENERAL))
    inside = solve(general.pose_aspect_model(), general.spaces()["workspace"], CUSP_LEGS)
    assert inside.certified
    np.testing.assert_allclose(sorted(s.pose[2] for s in inside.solutions),
                               sorted(p[2] for p in reference if 0 <= p[2] <= 60), atol=1e-7)


@pytest.mark.parametrize("seed", range(4))
def test_random_robots_and_legs_match_the_independent_solver(seed):
    rng = np.random.default_rng(100 + seed)
    while True:
        base, platform = rng.uniform(-10, 10, (3, 2)), rng.uniform(-6, 6, (3, 2))
        pose = np.array([rng.uniform(-5, 5), rng.uniform(-5, 5), rng.uniform(-180, 180)])
        rho = legs(base, platform, pose[None])[0]  # legs that have at least this pose
        reference, slope = independent_poses(base, platform, rho)
        if slope > 1e-6 and np.min(np.abs(det_j(base, platform, reference))) > 1e-3:
            break  # every root simple and non-singular: the scan sees them all
    m = robot(base, platform, 0.0, float(rho.max()) + 5.0)
    result = solve(m.pose_aspect_model(), m.spaces()["workspace"], rho)
    assert result.certified
    poses = np.array([s.pose for s in result.solutions])
    assert len(poses) == len(reference) and len(poses) % 2 == 0  # real roots of a degree-6 polynomial pair up
    for p in reference:
        assert np.min(np.max(np.abs(poses - p), axis=1)) < 1e-6
    assert np.min(np.max(np.abs(poses - pose), axis=1)) < 1e-6


def test_an_orientation_range_keeps_only_the_poses_inside_it():
    m = robot(ALIAS.base, ALIAS.platform, 1, 12, phi_range=(-30.0, 30.0))
    result = solve(m.pose_aspect_model(), m.spaces()["workspace"], ALIAS_LEGS)
    assert result.certified and len(result.solutions) == 1
    np.testing.assert_allclose(result.solutions[0].pose, [5, 5, 0], atol=1e-9)


def test_a_singular_pose_is_not_decided_never_dropped():
    # legs of a singular pose (det J = 0 there): no Krawczyk proof, so boxes are left undecided
    m = robot(ALIAS.base, ALIAS.platform, 1, 12)
    model = m.pose_aspect_model()
    from fivebar_cli.mechanisms.rpr3.boxtests import det_j as det

    phis = np.linspace(-60, 60, 2001)
    values = det(m, np.column_stack([np.full_like(phis, 5.0), np.full_like(phis, 5.0), phis]))
    k = int(np.flatnonzero(np.diff(np.sign(values)))[0])
    phi = brentq(lambda p: det(m, np.array([[5.0, 5.0, p]]))[0], phis[k], phis[k + 1], xtol=1e-14)
    rho = legs(m.base, m.platform, np.array([[5.0, 5.0, phi]]))[0]
    result = solve(model, m.spaces()["workspace"], rho, max_depth=30)
    assert not result.certified and len(result.undecided_lo) > 0
    held = np.all((result.undecided_lo <= [5, 5, phi]) & ([5, 5, phi] <= result.undecided_hi), axis=1)
    assert held.any() or any(np.allclose(s.pose, [5, 5, phi], atol=1e-6) for s in result.solutions)


# ---------------------------------------------------------------- the command


@pytest.fixture(scope="module")
def dkp_run(tmp_path_factory):
    folder = tmp_path_factory.mktemp("caro")
    result = ok(run_cli("rpr3", "dkp", CARO, "--legs", *CUSP_LEGS, "--depth", "6", "-o", folder, "--no-plot"))
    return folder, result


def test_dkp_csv_has_the_six_modes_with_signs_and_aspects(dkp_run):
    folder, result = dkp_run
    assert "6 assembly modes for legs (14.98, 15.38, 12) (certified" in result.stdout
    with open(folder / "dkp.csv", newline="") as fh:
        rows = list(csv.reader(fh))
    assert rows[0] == ["x", "y", "phi_deg", "det_sign", "aspect", "certified"]
    assert [r[3] for r in rows[1:]] == ["+", "+", "+", "-", "-", "-"]
    assert all(r[5] == "true" for r in rows[1:])
    poses = np.array([[float(v) for v in r[:3]] for r in rows[1:]])
    np.testing.assert_allclose(legs(*_geometry(), poses), np.tile(CUSP_LEGS, (6, 1)), atol=1e-6)
    aspects = {r[4] for r in rows[1:4] if r[4]} , {r[4] for r in rows[4:] if r[4]}
    assert aspects[0] == {"1"} and aspects[1] <= {"2"}  # one aspect per sign (Caro: 2 aspects)


def _geometry():
    m = Rpr3.parse(__import__("yaml").safe_load(CARO.read_text()), str(CARO))
    return m.base, m.platform


@pytest.mark.parametrize("args, needle", [
    (["--legs", "40", "15", "12"], "rho1 = 40 is outside its range [10, 32]"),
    (["--legs", "10", "10", "31"], "give no pose"),
])
def test_dkp_bad_legs_are_one_line_exit_2(tmp_path, args, needle):
    line = one_line(run_cli("rpr3", "dkp", CARO, *args, "-o", tmp_path, "--no-plot"), 2, "--legs", needle)
    assert not (tmp_path / "dkp.csv").exists(), line


def test_dkp_needs_an_orientation_range(tmp_path):
    config = tmp_path / "one.yaml"
    config.write_text(CARO.read_text().replace("phi_range: [-180, 180]", "phi: 30"))
    one_line(run_cli("rpr3", "dkp", config, "--legs", "15", "15", "12", "-o", tmp_path), 2, "one.yaml", "phi")
