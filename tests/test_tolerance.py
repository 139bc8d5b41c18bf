"""Manufacturing tolerances (issue 10): interval link lengths, robust and impossible pavings, robust
aspects and the `tolerance` study.

References are independent of the code under test: tests/reference_robust.py (exact robust and
possible membership, and validity for one length vector), tests/reference_aspects.py (modes for
any lengths), conftest.py (closed-form nominal areas).
"""

from __future__ import annotations

import functools
import math

import numpy as np
import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from cli_helpers import csv_rows, ok, one_line, run_cli
from conftest import (
    M1_YAML, M2_YAML, jointspace_area_numeric, leaf_bounds, mechanism, unchecked_fivebar, workspace_area_closed_form,
)
from reference_aspects import joint_modes, work_modes
from reference_robust import (
    length_vectors, possible_joint, possible_work, robust_joint, robust_work, valid_joint, valid_work,
)
from test_soundness_random import boxes_around, special_joint_points, special_work_points
from fivebar_cli.analyses.aspects import analyse_aspects
from fivebar_cli.analyses.tolerance import Fate, fate_text, jointspace_area, tolerance_study
from fivebar_cli.io.qtfile import read_qt
from fivebar_cli.io.schema import ConfigError
from fivebar_cli.mechanisms.fivebar import robust
from fivebar_cli.mechanisms.fivebar.model import FiveBar
from fivebar_cli.paving.engine import BAND, pave

VALID = {"workspace": valid_work, "jointspace": valid_joint}
ROBUST = {"workspace": robust_work, "jointspace": robust_joint}
POSSIBLE = {"workspace": possible_work, "jointspace": possible_joint}


def widened(name: str, t: float) -> FiveBar:
    return mechanism(name).widened(t)


def sample_points(lo: np.ndarray, hi: np.ndarray, rng, per_cell: int = 3, cells: int = 3000) -> np.ndarray:
    """Each cell's centre and corners and `per_cell` random points, for at most `cells` random cells."""
    if len(lo) > cells:
        pick = rng.choice(len(lo), cells, replace=False)
        lo, hi = lo[pick], hi[pick]
    pts = [0.5 * (lo + hi), lo, hi, np.column_stack([lo[:, 0], hi[:, 1]]), np.column_stack([hi[:, 0], lo[:, 1]])]
    pts += [lo + (hi - lo) * rng.random(lo.shape) for _ in range(per_cell)]
    return np.vstack(pts)


def check_decisions(m: FiveBar, space: str, status: np.ndarray, lo: np.ndarray, hi: np.ndarray, rng) -> int:
    """Every point sampled in a robust box is valid for every sampled length vector and robust by the
    exact reference; none in an impossible box is valid for any, nor possible; every point of a
    band box is possible and not robust. Returns the number of (point, length vector) pairs checked."""
    vectors = length_vectors(m.bounds, rng)
    checked = 0
    for code, name in ((1, "robust"), (-1, "impossible"), (BAND, "band")):
        sel = status == code
        if not sel.any():
            continue
        p = sample_points(lo[sel], hi[sel], rng)
        x, y = p[:, 0], p[:, 1]
        if code == 1:
            assert ROBUST[space](m.bounds, x, y).all(), (space, name, p[~ROBUST[space](m.bounds, x, y)][:3])
        else:
            assert not (ROBUST[space](m.bounds, x, y)).any(), (space, name)
        if code == -1:
            assert not POSSIBLE[space](m.bounds, x, y).any(), (space, name, p[POSSIBLE[space](m.bounds, x, y)][:3])
        if code == BAND:
            assert POSSIBLE[space](m.bounds, x, y).all(), (space, name)
        if code != BAND:  # every length vector at once: row k of `valid` is vector k's verdicts
            valid = VALID[space](vectors.T[..., None], x, y)
            wrong = ~valid.all(axis=1) if code == 1 else valid.any(axis=1)
            assert not wrong.any(), (space, name, vectors[np.argmax(wrong)])
            checked += len(p) * len(vectors)
    return checked


# ---------------------------------------------------------------- configuration and round trips


def test_interval_yaml_parses_and_round_trips(tmp_path):
    cfg = tmp_path / "tol.yaml"
    cfg.write_text("name: T\ntype: fivebar\nlengths: {L0: [8.95, 9.05], L1: 8, L2: [4.9, 5.1], L3: 5, L4: 8}\n")
    ok(run_cli("workspace", cfg, "--depth", "5", "--no-plot", "-q", "-o", tmp_path / "out"))
    m = FiveBar.parse({"name": "T", "type": "fivebar",
                       "lengths": {"L0": [8.95, 9.05], "L1": 8, "L2": [4.9, 5.1], "L3": 5, "L4": 8}})
    assert m.is_interval and m.bounds[0] == (8.95, 9.05) and m.bounds[1] == (8.0, 8.0)
    assert math.isclose(m.L0, 9.0) and math.isclose(m.L2, 5.0)
    header = read_qt(tmp_path / "out" / "workspace.qt").get("mechanism")
    assert "L0=[8.95,9.05]" in header and " L1=8.0 " in header
    assert FiveBar.from_description(dict(f.split("=") for f in header.split()[1:]), "T", "x") == m


@pytest.mark.parametrize("lengths, field, needle", [
    ("{L0: [9.05, 8.95], L1: 8, L2: 5, L3: 5, L4: 8}", "lengths.L0", "lo > hi"),
    ("{L0: [-1, 9], L1: 8, L2: 5, L3: 5, L4: 8}", "lengths.L0[0]", ""),
    ("{L0: 9, L1: [.nan, 8], L2: 5, L3: 5, L4: 8}", "lengths.L1[0]", ""),
    ("{L0: 9, L1: 8, L2: [4, 5, 6], L3: 5, L4: 8}", "lengths.L2", "[lo, hi]"),
])
def test_bad_interval_is_one_line_error(tmp_path, lengths, field, needle):
    cfg = tmp_path / "bad.yaml"
    cfg.write_text(f"name: B\ntype: fivebar\nlengths: {lengths}\n")
    one_line(run_cli("workspace", cfg, "-o", tmp_path / "out"), 2, str(cfg), field, needle)
    assert not (tmp_path / "out").exists()


def test_tolerance_reaching_zero_is_refused(tmp_path):
    one_line(run_cli("jointspace", M2_YAML, "--tolerance", "2.3", "-o", tmp_path), 2, "--tolerance", "positive")
    with pytest.raises(ConfigError):
        mechanism("M1").widened(float("nan"))


@pytest.mark.parametrize("space", ["workspace", "jointspace"])
def test_zero_tolerance_and_zero_width_intervals_are_the_nominal_trees(tmp_path, space):
    ok(run_cli(space, M1_YAML, "--depth", "7", "--no-plot", "-q", "-o", tmp_path / "plain"))
    ok(run_cli(space, M1_YAML, "--depth", "7", "--no-plot", "-q", "--tolerance", "0", "-o", tmp_path / "zero"))
    cfg = tmp_path / "m1-intervals.yaml"
    cfg.write_text("name: M1\ntype: fivebar\nlengths: {L0: [9, 9], L1: [8, 8], L2: 5, L3: [5, 5], L4: 8}\n")
    ok(run_cli(space, cfg, "--depth", "7", "--no-plot", "-q", "-o", tmp_path / "width0"))
    for name in (f"{space}.qt", f"{space}.complement.qt", f"{space}.csv"):
        plain = (tmp_path / "plain" / name).read_bytes()
        assert (tmp_path / "zero" / name).read_bytes() == plain
        assert (tmp_path / "width0" / name).read_bytes() == plain
    assert not (tmp_path / "zero" / f"{space}.band.qt").exists()


@pytest.mark.parametrize("space", ["workspace", "jointspace"])
def test_refine_resumes_an_interval_paving_byte_for_byte(tmp_path, space):
    ok(run_cli(space, M1_YAML, "--tolerance", "0.05", "--depth", "6", "--no-plot", "-q", "-o", tmp_path / "d6"))
    ok(run_cli("refine", tmp_path / "d6" / f"{space}.qt", "--depth", "9", "--no-plot", "-q", "-o", tmp_path / "r9"))
    ok(run_cli(space, M1_YAML, "--tolerance", "0.05", "--depth", "9", "--no-plot", "-q", "-o", tmp_path / "d9"))
    for name in (f"{space}.qt", f"{space}.complement.qt", f"{space}.band.qt"):
        assert (tmp_path / "r9" / name).read_bytes() == (tmp_path / "d9" / name).read_bytes(), name
    assert read_qt(tmp_path / "d9" / f"{space}.band.qt").tree.area > 0


def test_cli_reports_robust_possible_and_nominal_areas(tmp_path):
    out = ok(run_cli("workspace", M1_YAML, "--tolerance", "0.05", "--depth", "9", "--no-plot", "-o", tmp_path)).stdout
    inside = read_qt(tmp_path / "workspace.qt").tree.area
    outside = read_qt(tmp_path / "workspace.complement.qt").tree.area
    root = (2 * (8.05 + 5.05)) ** 2
    assert f"robust area {inside:.10g}" in out
    assert f"possible area {root - outside:.10g}" in out
    assert f"nominal exact area {workspace_area_closed_form(mechanism('M1')):.10g}" in out


# ---------------------------------------------------------------- soundness


@pytest.mark.parametrize("name, t", [("M1", 0.05), ("M1", 0.3), ("M2", 0.02), ("M2", 0.1)])
@pytest.mark.parametrize("space", ["workspace", "jointspace"])
def test_robust_paving_is_sound_by_points_and_length_vectors(name, t, space):
    m = widened(name, t)
    paving = pave(m.spaces()[space].grid(8), m.box_test(space))
    rng = np.random.default_rng(10)
    checked = 0
    for tree, code in ((paving.inside, 1), (paving.outside, -1), (paving.band, BAND)):
        lo, hi = leaf_bounds(tree)
        checked += check_decisions(m, space, np.full(len(lo), code), lo, hi, rng)
    assert checked > 300_000
    assert len(paving.band) > 0 and paving.inside.area > 0


@st.composite
def interval_fivebars(draw):
    """Random five-bars with random, asymmetric intervals (some zero-width) on random lengths."""
    nominal = [draw(st.floats(0.3, 3.0)) for _ in range(5)]
    bounds = []
    for v in nominal:
        if draw(st.booleans()):
            bounds.append((v, v))
        else:
            a, b = (draw(st.floats(0.0, 0.08)) * v for _ in range(2))
            bounds.append((v - a, v + b))
    return unchecked_fivebar("random", bounds=bounds)  # its nominal loop may not close: the box tests hold anyway


@settings(max_examples=60, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(interval_fivebars(), st.integers(0, 2**32 - 1))
def test_box_tests_sound_on_random_length_boxes(m, seed):
    """Boxes around the nominal mechanism's critical points and random places, at every scale."""
    rng = np.random.default_rng(seed)
    nominal = unchecked_fivebar(m.name, *m.lengths.values())
    for space, special in (("workspace", special_work_points(nominal)), ("jointspace", special_joint_points(nominal))):
        root = np.array(m.spaces()[space].root)
        anywhere = root[:, 0] + (root[:, 1] - root[:, 0]) * rng.random((60, 2))
        centres = np.vstack([special, anywhere]) if len(special) else anywhere
        lo, hi = boxes_around(centres, rng, 300, float(root[0, 1] - root[0, 0]) / 4)
        check_decisions(m, space, m.box_test(space)(lo, hi), lo, hi, rng)


def test_triangle_angle_range_is_exact_by_sampling():
    rng = np.random.default_rng(3)
    for _ in range(200):
        s_lo = rng.uniform(0.1, 3)
        s_hi = s_lo + rng.uniform(0, 1)
        a = tuple(sorted(rng.uniform(0.1, 3, 2)))
        o = tuple(sorted(rng.uniform(0.1, 3, 2)))
        lo, hi = robust.triangle_angle_range3(np.array([s_lo]), np.array([s_hi]), a, o)
        grid = np.meshgrid(*(np.linspace(*r, 41) for r in ((s_lo, s_hi), a, o)), indexing="ij")
        s, aa, oo = (g.ravel() for g in grid)
        angle = np.arccos(np.clip((s * s + aa * aa - oo * oo) / (2 * aa * s), -1, 1))
        assert lo[0] <= angle.min() + 1e-12 and angle.max() - 1e-12 <= hi[0]
        assert angle.min() - lo[0] < 0.02 and hi[0] - angle.max() < 0.02  # tight: no slack beyond the grid's


def test_crank_distance_bounds_hold_for_every_length_vector():
    rng = np.random.default_rng(4)
    for name, t in (("M1", 0.1), ("M2", 0.05)):
        m = widened(name, t)
        lo = rng.uniform(-np.pi, np.pi, (400, 2))
        hi = lo + 10.0 ** rng.uniform(-4, 0, (400, 2))
        b = robust.crank_distance_bounds(m, lo, hi)
        p = lo[:, None, :] + (hi - lo)[:, None, :] * rng.random((400, 30, 2))
        for L in length_vectors(m.bounds, rng, 8):
            L0, L1, L2, _, _ = L
            th1, th2 = p[..., 0], p[..., 1]
            d = np.hypot(L0 + L2 * np.cos(th2) - L1 * np.cos(th1), L2 * np.sin(th2) - L1 * np.sin(th1))
            assert (d.min(axis=1) >= b["low"] - 1e-12).all() and (d.max(axis=1) <= b["high"] + 1e-12).all()


# ---------------------------------------------------------------- tightness


@functools.lru_cache(maxsize=None)
def exact_area(m: FiveBar, space: str, n: int = 800) -> float:
    """The robust area by the exact membership at the centres of an n x n grid (good to ~0.1 %)."""
    root = np.array(m.spaces()[space].root)
    t = [(np.arange(n) + 0.5) / n * (hi - lo) + lo for lo, hi in root]
    x, y = np.meshgrid(*t, indexing="ij")
    inside = ROBUST[space](m.bounds, x.ravel(), y.ravel())
    return float(inside.mean() * np.prod(root[:, 1] - root[:, 0]))


@pytest.mark.parametrize("name, t", [("M1", 0.05), ("M2", 0.02)])
@pytest.mark.parametrize("space", ["workspace", "jointspace"])
def test_robust_area_at_depth_12_is_at_least_98_percent_of_the_exact_one(name, t, space):
    m = widened(name, t)
    robust_area = pave(m.spaces()[space].grid(12), m.box_test(space)).inside.area
    exact = exact_area(m, space)
    assert 0.98 * exact <= robust_area <= exact * 1.002  # the grid estimate is good to ~0.1 %


# ---------------------------------------------------------------- robust aspects


@pytest.mark.parametrize("name, t", [("M1", 0.05), ("M2", 0.01)])
def test_robust_aspects_hold_for_every_length_vector(name, t):
    m = widened(name, t)
    analysis = analyse_aspects(m, 8, shapes=False)
    assert analysis.aspects
    rng = np.random.default_rng(11)
    vectors = length_vectors(m.bounds, rng, 8)
    for a in analysis.aspects:
        for space, tree in (("workspace", a.workspace), ("jointspace", a.jointspace)):
            lo, hi = leaf_bounds(tree)
            p = sample_points(lo, hi, rng, per_cell=1, cells=400)
            for L in vectors:
                if space == "workspace":
                    valid, sign, _, _ = work_modes(L, p[:, 0], p[:, 1], a.working)
                    assert (valid & (sign == a.assembly)).all(), (a.number, space, L)
                else:
                    valid, u, v, _ = joint_modes(L, p[:, 0], p[:, 1], a.assembly)
                    assert (valid & (u == a.working[0]) & (v == a.working[1])).all(), (a.number, space, L)


def test_small_tolerance_keeps_m1s_ten_aspects_certified_and_smaller(tmp_path):
    out = ok(run_cli("aspects", M1_YAML, "--depth", "9", "--tolerance", "0.02", "--no-plot", "-o", tmp_path)).stdout
    assert "M1: 10 robust generalized aspects at depth 9 (certified;" in out
    nominal = analyse_aspects(mechanism("M1"), 9, shapes=False)
    robust_rows = csv_rows(tmp_path / "aspects.csv")
    assert len(robust_rows) == 10
    for a, row in zip(nominal.aspects, robust_rows):
        assert 0.5 * a.workspace.area < float(row["workspace_area"]) < a.workspace.area
        assert f"nominal aspect {a.number:2d}: shrinks to" in out
    located = ok(run_cli("locate", M1_YAML, "--depth", "9", "--tolerance", "0.02", "--pose", "4", "5",
                         "-o", tmp_path)).stdout
    assert f"robust aspects at depth 9 read from {tmp_path}" in located


# ---------------------------------------------------------------- the study


def test_jointspace_area_quadrature_matches_the_reference():
    for name in ("M1", "M2"):
        assert math.isclose(jointspace_area(mechanism(name)), jointspace_area_numeric(mechanism(name)), rel_tol=2e-5)


def test_tolerance_study_rows_are_ordered_and_bracket_the_nominal_areas(tmp_path):
    ok(run_cli("tolerance", M2_YAML, "--tolerances", "0.02,0,0.005", "--depth", "8", "-o", tmp_path, "-q"))
    rows = csv_rows(tmp_path / "tolerance.csv")
    assert list(rows[0]) == ["tolerance", "region", "robust_area", "possible_area", "nominal_area"]
    assert (tmp_path / "tolerance-bands.png").stat().st_size > 0 and (tmp_path / "tolerance-aspects.png").exists()
    m = mechanism("M2")
    exact = {"workspace": workspace_area_closed_form(m), "jointspace": jointspace_area_numeric(m)}
    for space in ("workspace", "jointspace"):
        mine = [r for r in rows if r["region"] == space]
        assert [float(r["tolerance"]) for r in mine] == [0.0, 0.005, 0.02]
        robust_areas = [float(r["robust_area"]) for r in mine]
        possible = [float(r["possible_area"]) for r in mine]
        assert robust_areas[0] <= exact[space] <= possible[0]
        assert robust_areas == sorted(robust_areas, reverse=True) and possible == sorted(possible)
        assert float(mine[-1]["robust_area"]) <= exact_area(m.widened(0.02), space) * 1.002
        assert all(math.isclose(float(r["nominal_area"]), exact[space], rel_tol=1e-4) for r in mine)
    aspects = [r for r in rows if r["region"].startswith("aspect-")]
    assert len(aspects) == 3 * 10 and all(r["possible_area"] == "" for r in aspects)
    for number in range(1, 11):
        areas = [float(r["robust_area"]) for r in aspects if r["region"] == f"aspect-{number:02d}"]
        assert areas == sorted(areas, reverse=True) and areas[0] > 0


def test_study_fates_agree_with_a_direct_robust_analysis():
    study = tolerance_study(mechanism("M2"), [0.0, 0.02], 8)
    direct = analyse_aspects(widened("M2", 0.02), 8, shapes=False)
    kept = [r for f in study.fates[0.02] for r in f.robust]
    assert sorted(kept) == [a.number for a in direct.aspects]  # each robust aspect in one nominal aspect
    for f in study.fates[0.02]:
        assert math.isclose(f.robust_area, sum(direct.aspects[r - 1].workspace.area for r in f.robust))
        assert f.verdict == "shrinks" and fate_text(f).startswith("shrinks to ")
    assert [f.verdict for f in study.fates[0.0]] == ["keeps its area"] * 10


def test_fate_verdicts():
    assert fate_text(Fate(3, (), 1.5, 0.0)) == "vanishes (no robust cell at this depth)"
    assert fate_text(Fate(3, (4, 5), 1.5, 1.0)) == "splits into robust aspects 4, 5"
    assert fate_text(Fate(3, (4,), 2.0, 1.0)) == "shrinks to 50% (robust aspect 4)"


def test_a_depth_too_small_for_any_aspect_draws_its_figures_without_a_warning(tmp_path):
    """At depth 1 no aspect is found: the aspects' figure has no curve, and no legend (matplotlib
    warned "No artists with labels found" on stderr)."""
    r = ok(run_cli("tolerance", M1_YAML, "--tolerances", "0,0.1", "--depth", 1, "-o", tmp_path, "-q"))
    assert r.stderr == ""
    assert {row["region"] for row in csv_rows(tmp_path / "tolerance.csv")} == {"workspace", "jointspace"}  # no aspect
    assert (tmp_path / "tolerance-aspects.png").read_bytes().startswith(b"\x89PNG")
