"""`fivebar rpr3 ...`: outputs, determinism and bad input (through the entry point `main`, in-process)."""

import csv
import math
from pathlib import Path

import numpy as np
import pytest
from cli_helpers import ok, one_line, run_cli

from fivebar_cli.mechanisms.rpr3 import closed_form as rpr3
from fivebar_cli.mechanisms.rpr3 import paper as rpr3_paper

ROOT = Path(__file__).resolve().parents[1]
CONFIGS = ROOT / "configs"


def run(*args, cwd=None):
    """`fivebar rpr3 ARGS` (exit status, stdout and stderr as the user sees them)."""
    return run_cli("rpr3", *args, cwd=cwd)


def read(path):
    with open(path, newline="") as fh:
        rows = list(csv.reader(fh))
    return rows[0], rows[1:]


# ---------------------------------------------------------------- bad input


BASE = "name: bad\ntype: rpr3\n"
GOOD_BASE = "base: {t1: 1.8, t2: 1.2, t3: 1.11}\n"
BAD = {
    "non-similar platform": (GOOD_BASE + "platform: {t4: 1.08, t5: 0.72, t6: 0.7}\nlegs: {rho_min: 0.2}\nphi: 45\n",
                             "platform"),
    "collinear base": ("base: {t1: 1.8, t2: 1.2, t3: 0}\nk: 0.6\nlegs: {rho_min: 0.2}\nphi: 45\n", "base.t3"),
    "k zero": (GOOD_BASE + "k: 0\nlegs: {rho_min: 0.2}\nphi: 45\n", "k"),
    "k negative": (GOOD_BASE + "k: -0.6\nlegs: {rho_min: 0.2}\nphi: 45\n", "k"),
    "rho_min >= rho_max": (GOOD_BASE + "k: 0.6\nlegs: {rho_min: 1.5, rho_max: 1.5}\nphi: 45\n", "legs"),
    "range through 0": (GOOD_BASE + "k: 0.6\nlegs: {rho_min: 0.2}\nphi_range: [-20, 30]\n", "phi_range"),
    "range through 180": (GOOD_BASE + "k: 0.6\nlegs: {rho_min: 0.2}\nphi_range: [100, 200]\n", "phi_range"),
    "range ending at 180": (GOOD_BASE + "k: 0.6\nlegs: {rho_min: 0.2}\nphi_range: [100, 180]\n", "phi_range"),
    "phi 0": (GOOD_BASE + "k: 0.6\nlegs: {rho_min: 0.2}\nphi: 0\n", "phi"),
}


@pytest.mark.parametrize("case", sorted(BAD))
def test_bad_input_is_one_line_and_exit_2(tmp_path, case):
    text, field = BAD[case]
    path = tmp_path / "bad.yaml"
    path.write_text(BASE + text)
    command = "synthesize" if "range" in case else "area"
    one_line(run(command, path, "-o", tmp_path / "out", cwd=tmp_path), 2, f"{path}: {field}:")
    assert not (tmp_path / "out").exists()


def test_synthesize_at_one_orientation_and_sweep_checks_its_options(tmp_path):
    # a zero-width range (issue 11): the six cases exist, cases 5 and 6 are said to be degenerate
    result = run("synthesize", CONFIGS / "rpr3-equilateral.yaml", "-o", tmp_path, "--no-plot")
    assert result.status == 0, result.stderr
    assert "case 5: degenerate" in result.stdout and "case 6: degenerate" in result.stdout
    for args in (("--over", "phi", "--range", "0", "90"), ("--over", "t2", "--angles", "30,180"),
                 ("--over", "rho_min", "--range", "0.5", "0.1"), ("--over", "volume")):
        one_line(run("sweep", CONFIGS / "rpr3-equilateral.yaml", *args, "-o", tmp_path), 2)
    # orientations given to a sweep that takes none (taken without a word before)
    one_line(run("sweep", CONFIGS / "rpr3-equilateral.yaml", "--over", "phi", "--angles", "10,20", "-o", tmp_path), 2,
             "--angles", "only the sweep over t2 (--over t2) takes orientations; this one is over phi")
    import fivebar_cli as fb

    with pytest.raises(fb.InputError, match="only the sweep over t2") as e:
        fb.rpr3.sweep("rpr3-equilateral", "rho_min", angles=(10, 20))
    assert e.value.field == "`angles`"
    default = fb.rpr3.sweep("rpr3-equilateral", "t2", steps=3)  # None: the paper's five orientations
    assert sorted(set(default.column("phi_deg"))) == [30, 60, 90, 120, 150]
    assert default.rows() == fb.rpr3.sweep("rpr3-equilateral", "t2", steps=3, angles="30,60,90,120,150").rows()


# ---------------------------------------------------------------- area


def test_area_csv_values_and_determinism(tmp_path):
    config = CONFIGS / "rpr3-equilateral.yaml"
    ok(run("area", config, "-o", tmp_path / "a", "--quiet"))
    ok(run("area", config, "-o", tmp_path / "b", "--no-plot", "--quiet"))
    header, rows = read(tmp_path / "a" / "area.csv")
    assert header == ["phi_deg", "rho_min", "rho_max", "area"]
    phi, rho_min, rho_max, area = map(float, rows[0])
    t = rpr3_paper.PAPER_SETUP[:3]
    assert (phi, rho_min) == (45.0, 0.2)
    assert rho_max == pytest.approx(float(rpr3.rho_max_auto(*t, 0.6, math.radians(45), 0.2)), rel=1e-9)
    assert area == pytest.approx(float(rpr3.area(*t, 0.6, math.radians(45), 0.2, rho_max)), rel=1e-9)
    assert (tmp_path / "a" / "area.csv").read_bytes() == (tmp_path / "b" / "area.csv").read_bytes()
    assert (tmp_path / "a" / "singularity-free-workspace.png").read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
    assert not (tmp_path / "b" / "singularity-free-workspace.png").exists()


def test_area_over_a_range_uses_one_rho_max_and_default_folder(tmp_path):
    result = ok(run("area", CONFIGS / "rpr3-table1.yaml", "--no-plot", cwd=tmp_path))
    header, rows = read(tmp_path / "outputs" / "rpr3-table1" / "area.csv")
    assert [float(r[0]) for r in rows] == [100.0, 165.0]
    assert rows[0][2] == rows[1][2] and float(rows[0][2]) == pytest.approx(rpr3_paper.PAPER_TABLE1[1][1], abs=1e-6)
    assert float(rows[0][3]) == pytest.approx(rpr3_paper.PAPER_TABLE1[1][2], abs=1.5e-6)
    assert float(rows[1][3]) == pytest.approx(rpr3_paper.PAPER_TABLE1[1][3], abs=1.5e-6)
    assert "singularity circle" in result.stdout


# ---------------------------------------------------------------- sweeps


def test_sweeps_write_their_tables(tmp_path):
    names = ["rpr3-acute", "rpr3-equilateral", "rpr3-obtuse"]
    configs = [CONFIGS / f"{n}.yaml" for n in names]
    ok(run("sweep", *configs, "--over", "phi", "--steps", "5", "--range", "10", "170", "-q", cwd=tmp_path))
    folder = tmp_path / "outputs" / "+".join(names)  # several configs: one folder named after all
    header, rows = read(folder / "area-vs-phi.csv")
    assert len(list(folder.glob("*.png"))) == 4
    assert header == ["config", "phi_deg", "rho_min", "rho_max", "area", "rho_min_opt", "rho_max_opt", "area_opt"]
    assert [r[0] for r in rows] == [n for n in names for _ in range(5)]
    name, phi, rho_min, rho_max, area, rho_opt, _, area_opt = rows[7]
    t = (1 / 3**0.25 * 2, 1 / 3**0.25, 3**0.25)
    assert float(area) == pytest.approx(float(rpr3.area_auto(*t, 0.6, math.radians(float(phi)), 0.2)), rel=1e-9)
    assert float(area_opt) >= float(area) and float(area_opt) == pytest.approx(
        float(rpr3.area_auto(*t, 0.6, math.radians(float(phi)), float(rho_opt))), rel=1e-9)

    out = tmp_path / "rho"
    ok(run("sweep", configs[1], "--over", "rho_min", "--steps", "11", "--range", "0", "0.5", "-o", out,
           "--no-plot", "-q"))
    header, rows = read(out / "area-vs-rho-min.csv")
    assert header == ["config", "phi_deg", "rho_min", "rho_max", "area"]
    assert [float(r[2]) for r in rows] == pytest.approx(np.linspace(0, 0.5, 11).tolist())

    out = tmp_path / "t2"
    ok(run("sweep", configs[1], "--over", "t2", "--steps", "9", "--angles", "60,120", "-o", out, "--no-plot", "-q"))
    header, rows = read(out / "area-vs-t2.csv")
    assert header[:5] == ["config", "phi_deg", "t1", "t2", "t3"] and len(rows) == 18
    for phi in ("60", "120"):  # the equilateral base (t2 = t1 / 2, the middle sample) is the best of the row
        areas = [float(r[7]) for r in rows if r[1] == phi]
        assert int(np.argmax(areas)) == 4


# ---------------------------------------------------------------- synthesis


def test_synthesize_reproduces_table1(tmp_path):
    result = ok(run("synthesize", CONFIGS / "rpr3-table1.yaml", "-o", tmp_path, "--no-plot", cwd=tmp_path))
    header, rows = read(tmp_path / "table1-comparison.csv")
    assert header[:4] == ["case", "objective", "rho_min_paper", "rho_min_ours"] and header[-1] == "max_abs_diff"
    for row in rows:
        cells = dict(zip(header, row))
        assert float(cells["max_abs_diff"]) <= 1.5e-6
        for name in ("rho_max", "A1", "A2", "abs_A1_A2", "A_a", "dA_a"):
            assert abs(float(cells[name]) - float(cells[name + "_paper"])) <= 1.5e-6
        if cells["case"] in ("4", "5", "6"):
            assert abs(float(cells["rho_min_ours"]) - float(cells["rho_min_paper"])) <= 1e-6
    header, rows = read(tmp_path / "synthesis.csv")
    assert header == ["case", "objective", "rho_min", "rho_max", "A1", "A2", "abs_A1_A2", "A_a", "dA_a", "n"]
    assert "Recommended leg range" in result.stdout and "[0.412168, 2.075469]" in result.stdout
