"""Issue 11, item 5: the closed-form commands on unusual but valid inputs.

Narrow and zero-width orientation ranges, cases 5 and 6 of the synthesis where W would be
empty, a nearly collinear base (against polygon clipping with shapely), and the arc list of one
region given at orientations 360 degrees apart.
"""

from __future__ import annotations

import math
import time
from pathlib import Path

import numpy as np
import pytest
from shapely.geometry import Point, Polygon

from fivebar_cli.cli import main
from fivebar_cli.mechanisms.rpr3 import closed_form as cf
from fivebar_cli.mechanisms.rpr3 import synthesis

ROOT = Path(__file__).resolve().parents[1]
CONFIGS = ROOT / "configs"
EQUI = (2 / 3**0.25, 1 / 3**0.25, 3**0.25, 0.6)
OBTUSE = (1.8, 2.2, 1.11, 0.6)


def cli(capsys, *args):
    with pytest.raises(SystemExit) as exc:
        main([str(a) for a in args])
    out = capsys.readouterr()
    return exc.value.code, out.out, out.err


def write(tmp_path: Path, name: str, text: str) -> Path:
    path = tmp_path / f"{name}.yaml"
    path.write_text(f"name: {name}\ntype: rpr3\n" + text)
    return path


# ---------------------------------------------------------------- narrow and zero-width ranges


def test_a_narrow_range_converges_quickly(tmp_path, capsys):
    path = write(tmp_path, "narrow", "base: {t1: 1.5196713713031851, t2: 0.7598356856515925, t3: 1.3160740129524924}\n"
                                     "k: 0.6\nlegs: {rho_min: 0.2}\nphi_range: [100, 100.001]\n")
    start = time.perf_counter()
    code, out, err = cli(capsys, "rpr3", "synthesize", path, "-o", tmp_path / "out", "--no-plot")
    assert code == 0, err
    assert time.perf_counter() - start < 10
    # the mean over a range a thousandth of a degree wide is the area at either end
    case4 = [line for line in out.splitlines() if line.startswith("4 ")][0].split()
    a1, a_a = float(case4[5]), float(case4[8])
    assert a_a == pytest.approx(a1, abs=1e-4)


def test_mean_area_where_w_vanishes_at_one_end():
    # rho_min at the limit of phi1: W is empty at phi1 and tiny after it (this never converged)
    t = EQUI
    p1, p2 = math.radians(100), math.radians(100.001)
    rho = float(cf.rho_min_limit(*t, p1)) * (1 - 1e-9)
    rmax = float(cf.rho_max_range(*t, p1, p2, rho))
    m = synthesis.mean_area(*t, p1, p2, rho, rmax)
    assert m.n <= 100 and 0 <= m.mean < 1e-9


def test_zero_width_range(tmp_path, capsys):
    path = write(tmp_path, "zero", "base: {t1: 1.8, t2: 1.2, t3: 1.11}\nk: 0.6\nlegs: {rho_min: 0.2}\n"
                                   "phi_range: [100, 100]\n")
    code, out, err = cli(capsys, "rpr3", "synthesize", path, "-o", tmp_path / "out", "--no-plot")
    assert code == 0, err
    assert "case 5: degenerate: phi1 = phi2" in out and "case 6: degenerate: phi1 = phi2" in out
    m = synthesis.mean_area(1.8, 1.2, 1.11, 0.6, 1.0, 1.0, 0.2, 1.0)
    assert m.n == 0 and m.fluctuation == 0 and m.mean == pytest.approx(float(cf.area(1.8, 1.2, 1.11, 0.6, 1.0, 0.2, 1.0)))


# ---------------------------------------------------------------- cases 5 and 6 never recommend an empty W


@pytest.mark.parametrize("design, phis, rho, area", [
    (EQUI, (100, 101), 0.57, 2.27),  # the issue: 1.0988 with A1 = 0 before
    (OBTUSE, (40, 60), 0.683, 0.41),  # the issue: 1.4228 with A1 = 0 before
])
def test_equal_areas_are_found_where_w_is_not_empty(design, phis, rho, area, obtuse_cases):
    p1, p2 = (math.radians(p) for p in phis)
    cases = obtuse_cases if design == OBTUSE else synthesis.synthesize(*design, p1, p2, 0.2)
    c5 = cases[4]
    assert c5.note == ""
    assert c5.rho_min == pytest.approx(rho, abs=0.01)
    assert c5.a1 == pytest.approx(area, abs=0.01) and c5.a2 == pytest.approx(c5.a1, abs=1e-6)
    # independent check: A1 = A2 there, from the closed-form areas
    rmax = float(cf.rho_max_range(*design, p1, p2, c5.rho_min))
    assert rmax == pytest.approx(c5.rho_max)
    a1, a2 = (float(cf.area(*design, p, c5.rho_min, rmax)) for p in (p1, p2))
    assert a1 > 0.3 and abs(a1 - a2) < 1e-6
    for c in cases[1:]:  # no case lands on an empty W without saying so
        assert min(c.a1, c.a2) > 1e-9 or c.note


@pytest.fixture(scope="module")
def obtuse_cases():
    return synthesis.synthesize(*OBTUSE, math.radians(40), math.radians(60), 0.2)


def test_case_6_says_when_its_minimum_is_where_w_vanishes(obtuse_cases):
    cases = obtuse_cases
    assert cases[5].note.startswith("degenerate: dA_a only decreases")
    assert cases[0].note == "W is empty at phi2"  # the given rho_min 0.2: W empty at 60 degrees


# ---------------------------------------------------------------- a nearly collinear base


def clipped_area(t1, t2, t3, k, phi, rho_min, rho_max) -> float:
    """W by polygon clipping: annuli as fine polygons, the (huge) singularity disc as a fine
    polygon of its arc near the annuli."""
    (centres, radii) = cf.region(t1, t2, t3, k, phi, rho_min, rho_max)
    shape = None
    for i in range(3):
        ring = Point(centres[1 + i]).buffer(rho_max, 4096).difference(Point(centres[4 + i]).buffer(rho_min, 4096))
        shape = ring if shape is None else shape.intersection(ring)
    if shape.is_empty:
        return 0.0
    o, r = centres[0], radii[0]
    c = np.array(shape.centroid.coords[0])
    a = math.atan2(c[1] - o[1], c[0] - o[0])
    th = np.linspace(a - 8 * rho_max / r, a + 8 * rho_max / r, 40001)
    disc = Polygon(np.vstack([np.column_stack([o[0] + r * np.cos(th), o[1] + r * np.sin(th)]), [o]]))
    return shape.intersection(disc).area


@pytest.mark.parametrize("t3", [1e-4, 1e-7])
@pytest.mark.parametrize("rho_min", [0.2, 1.0])
def test_nearly_collinear_base_areas_are_accurate(t3, rho_min):
    design = (1.8, 1.2, t3, 0.6)
    phi = math.radians(45)
    ours = float(cf.area(*design, phi, rho_min, 1.2))
    assert ours <= math.pi * 1.2**2
    assert ours == pytest.approx(clipped_area(*design, phi, rho_min, 1.2), abs=2e-6)


def test_nearly_collinear_base_with_auto_rho_max(tmp_path, capsys):
    path = write(tmp_path, "flat", "base: {t1: 1.8, t2: 1.2, t3: 1.0e-7}\nk: 0.6\nlegs: {rho_min: 0.2}\nphi: 45\n")
    code, out, err = cli(capsys, "rpr3", "area", path, "-o", tmp_path / "out", "--no-plot")
    assert code == 0, err
    area = float(out.split("area of W = ")[1].split(",")[0])
    rho_max = float(out.split("rho_max auto = ")[1].split()[0])
    assert 0 <= area <= math.pi * rho_max**2  # was 1493 (1.66e8 at t3 = 1e-9)
    flatter = write(tmp_path, "flatter", "base: {t1: 1.8, t2: 1.2, t3: 1.0e-9}\nk: 0.6\nlegs: {rho_min: 0.2}\nphi: 45\n")
    code, _, err = cli(capsys, "rpr3", "area", flatter, "-o", tmp_path / "out2", "--no-plot")
    assert code == 2 and f"{flatter}: base.t3: the base is nearly collinear" in err
    assert len(err.strip().splitlines()) == 1


# ---------------------------------------------------------------- one region, one list of arcs


def test_the_arc_list_is_a_property_of_the_region(tmp_path, capsys):
    outputs = []
    for phi in (45, 405, 765, -315):
        text = (CONFIGS / "rpr3-equilateral.yaml").read_text().replace("phi: 45", f"phi: {phi}")
        path = tmp_path / f"e{phi}.yaml"
        path.write_text(text)
        code, out, err = cli(capsys, "rpr3", "area", path, "-o", tmp_path / f"o{phi}", "--no-plot")
        assert code == 0, err
        outputs.append(out.split("area of W")[1].splitlines()[0])
        rows = (tmp_path / f"o{phi}" / "area.csv").read_text().splitlines()[1].split(",")
        assert rows[1:] == (tmp_path / "o45" / "area.csv").read_text().splitlines()[1].split(",")[1:]
    assert len(set(outputs)) == 1 and "6 arcs" in outputs[0]


def test_boundary_arcs_meet_end_to_start():
    # merged arcs: consecutive arcs of one circle never touch; the loops close
    from fivebar_cli.numerics import arcs

    centres, radii = cf.region(*EQUI, math.radians(45), 0.2, float(cf.rho_max_auto(*EQUI, math.radians(45), 0.2)))
    found = arcs.boundary_arcs(centres, radii, cf.SIDES)
    for a in found:
        for b in found:
            if a is not b and a.circle == b.circle:
                gap = (b.start - a.end) % (2 * math.pi)
                assert gap > 1e-9
    total = sum(a.green() for a in found)
    assert total == pytest.approx(float(arcs.area(centres, radii, cf.SIDES)), rel=1e-12)


def test_synthesize_help_says_rho_max_holds_over_the_whole_range(capsys):
    code, out, _ = cli(capsys, "rpr3", "synthesize", "--help")
    assert code == 0
    text = " ".join(out.split())
    assert "rho_max is, for each, the largest value keeping W singularity-free at every orientation of the range" in text
