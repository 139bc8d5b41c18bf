"""Issue 12 with interval lengths (issue 10) and the view page (issue 14): the circles and squares
of robust aspects, certified motions of a five-bar with interval lengths, the nominal closure
check, and `fivebar view` reading the aspects.csv columns and path.csv that `aspects` and `path`
write.

Robust means for every length vector of the box: the samples are checked against the reference
kinematics at the box's 32 corners and its centre (a necessary condition that can fail)."""

from __future__ import annotations

import itertools
from pathlib import Path

import numpy as np
import pytest
from cli_helpers import csv_rows, ok, one_line, run_cli
from reference_kinematics import ref_dkp, ref_ikp
from test_inscribed import closed_member, sample_disc, sample_square
from test_path import check_motion, read_path, samples

from fivebar_cli.analyses.aspects import analyse_aspects
from fivebar_cli.analyses.view import gather
from fivebar_cli.mechanisms.fivebar.model import FiveBar

REPO = Path(__file__).resolve().parents[1]
M1_YAML = REPO / "configs" / "m1.yaml"
NOMINAL = (9.0, 8.0, 5.0, 5.0, 8.0)
T = 0.05
BOX = FiveBar.with_bounds("M1", [(v - T, v + T) for v in NOMINAL])
CORNERS = [FiveBar("c", *c) for c in itertools.product(*[(v - T, v + T) for v in NOMINAL])] + [FiveBar("n", *NOMINAL)]
DEPTH = 8


@pytest.fixture(scope="module")
def robust_run(tmp_path_factory):
    folder = tmp_path_factory.mktemp("robust")
    ok(run_cli("aspects", M1_YAML, "--depth", DEPTH, "--tolerance", T, "-o", folder, "--no-plot", "-q"))
    return folder, analyse_aspects(BOX, DEPTH), analyse_aspects(BOX.nominal(), DEPTH)


def test_robust_circles_and_squares_are_in_every_robust_aspect(robust_run):
    _, robust, _ = robust_run
    assert len(robust.aspects) == 10
    for a in robust.aspects:
        for pts in (sample_disc(a.circle.x, a.circle.y, a.circle.r, n=1500),
                    sample_square(a.square.x, a.square.y, a.square.side, n=1500)):
            assert closed_member(a.workspace, pts).all()
            for m in CORNERS:
                *_, u, v, t, found = ref_ikp(m, pts[:, 0], pts[:, 1], a.working)
                assert found.all()
                assert np.all(np.sign(u) == a.working[0]) and np.all(np.sign(v) == a.working[1])
                assert np.all(np.sign(t) == a.assembly)


def test_robust_shapes_are_smaller_than_nominal_ones(robust_run):
    _, robust, nominal = robust_run
    for a, b in zip(robust.aspects, nominal.aspects):  # same numbering on M1 at +-0.05 (no split, none vanishes)
        assert (a.working, a.assembly) == (b.working, b.assembly)
        assert 0.5 * b.circle.r < a.circle.r < b.circle.r and 0.5 * b.square.side < a.square.side < b.square.side


def test_aspects_csv_with_tolerance_has_the_robust_shapes(robust_run):
    folder, robust, _ = robust_run
    rows = csv_rows(folder / "aspects.csv")
    assert [int(r["aspect"]) for r in rows] == [a.number for a in robust.aspects]
    for r, a in zip(rows, robust.aspects):
        assert [float(r[k]) for k in ("circle_x", "circle_y", "circle_r")] == [a.circle.x, a.circle.y, a.circle.r]
        assert [float(r[k]) for k in ("square_x", "square_y", "square_side")] == [a.square.x, a.square.y, a.square.side]


@pytest.mark.parametrize("allow_serial", [False, True], ids=["aspect", "allow-serial"])
def test_interval_path_is_free_for_every_length_vector(tmp_path, allow_serial):
    cfg = tmp_path / "box.yaml"
    cfg.write_text("name: box\ntype: fivebar\nlengths: {"
                   + ", ".join(f"L{k}: [{v - T}, {v + T}]" for k, v in enumerate(NOMINAL)) + "}\n")
    extra = ["--allow-serial"] if allow_serial else []
    ok(run_cli("path", cfg, "--joints", "-0.09817477", "-2.06167018", "--joints", "0.88357293", "1.47262156",
               "--assembly-mode", "+", "--depth", DEPTH, "-o", tmp_path, "--no-plot", "-q", *extra))
    _, rows, _ = read_path(tmp_path)
    working = None if allow_serial else (1, 1)
    check_motion(CORNERS[-1], rows, 1, working)  # the nominal five-bar, poses included
    pts = samples(rows)
    for m in CORNERS[:-1]:
        *_, u, v, t, found = ref_dkp(m, pts[:, 0], pts[:, 1], 1)
        assert found.all() and np.all(t > 0)
        if working is not None:
            assert np.all(u > 0) and np.all(v > 0)


def test_interval_design_whose_nominal_never_closes(tmp_path):
    cfg = tmp_path / "bad.yaml"
    cfg.write_text("name: bad\ntype: fivebar\nlengths: {L0: [29, 31], L1: 8, L2: 5, L3: 5, L4: 8}\n")
    one_line(run_cli("workspace", cfg, "--depth", 4, "-o", tmp_path / "out", "--no-plot"), 2,
             "bad.yaml: lengths: nominal lengths: L0 = 30 > L1 + L2 + L3 + L4 = 26")


def test_view_draws_the_circles_squares_and_path_written(tmp_path):
    ok(run_cli("aspects", M1_YAML, "--depth", DEPTH, "-o", tmp_path, "--no-plot", "-q"))
    ok(run_cli("path", M1_YAML, "--joints", "-0.09817477", "-2.06167018", "--joints", "0.88357293", "1.47262156",
               "--assembly-mode", "+", "--depth", DEPTH, "-o", tmp_path, "--no-plot", "-q"))
    view = gather([tmp_path])
    section = next(s for s in view.sections if s["kind"] == "aspects")
    rows = csv_rows(tmp_path / "aspects.csv")
    assert len(section["aspects"]) == len(rows) == 10
    for shown, r in zip(section["aspects"], rows):
        assert shown["circle"] == [float(r["circle_x"]), float(r["circle_y"]), float(r["circle_r"])]
        assert shown["square"] == [float(r["square_x"]), float(r["square_y"]), float(r["square_side"])]
    header, values, _ = read_path(tmp_path)
    assert section["path"] == 0 and view.paths[0]["columns"] == header == ["theta1", "theta2", "x", "y"]
    assert view.paths[0]["rows"] == values and len(values) >= 2
