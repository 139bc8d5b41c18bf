"""`locate` and `path` share one decision (issue 20): "no" only when proven, "yes" when an aspect's
certified cells hold both configurations, otherwise "not decided at depth D" with the reason.

- The issue's two counter-examples, run through the command line.
- Random pairs of configurations on M1, M2, a robust M1 and random five-bars, at sampled depths:
  locate's verdict and path's answer agree on every pair (tests/locate_pairs.py), every motion
  path finds is checked against the independent kinematics of tests/reference_kinematics.py
  (for every length vector at the corners of the box for the robust M1), every "no" from the modes
  is checked with the same kinematics, and every "no" from two certified aspects survives a
  deeper `path`.
- Honest words: the depth, not a singularity, at depth 0; plurals; counts that say whether they
  are certified; unreachable locations, uncertified and robust aspects left undecided.
- Command-line numbers: degrees with the suffix deg, finite numbers only.
"""

from __future__ import annotations

import csv
import io
import math
from itertools import product
from pathlib import Path

import numpy as np
import pytest
from cli_helpers import one_line, run_cli
from locate_pairs import (
    M1, M2, ROBUST_M1, Setting, answers, disagreement, judge, random_five_bars, random_pair, recheck,
)
from reference_kinematics import ref_dkp, ref_ikp
from test_path import check_motion, read_path, samples

import fivebar_cli as fb
from fivebar_cli.analyses.aspects import analyse_aspects
from fivebar_cli.analyses.locate import NO, UNDECIDED, YES, Configuration, decide, mode_verdict
from fivebar_cli.cli.options import as_flags
from fivebar_cli.mechanisms.fivebar.model import FiveBar

REPO = Path(__file__).resolve().parents[1]
M1_YAML, M2_YAML, RPR2_YAML = (REPO / "configs" / f"{n}.yaml" for n in ("m1", "m2", "rpr2"))
SCALE2 = (9 + 8 + 5 + 5 + 8) ** 2


def run(*args):
    return run_cli(*args, cwd=REPO)


# ---------------------------------------------------------------- the counter-examples


@pytest.fixture(scope="module")
def m1_depth10(tmp_path_factory):
    out = tmp_path_factory.mktemp("m1")
    assert run("aspects", M1_YAML, "--depth", "10", "-o", out, "--no-plot", "-q").status == 0
    return out


def test_a_pose_near_the_workspace_edge_is_in_the_aspect_path_moves_in(m1_depth10, tmp_path):
    """(12.999, 0) is 0.001 inside the outer circle |P - A1| = 13: not singular (B11 = 1.02 by the
    independent kinematics), its joints lie in aspect 1's joint-space cells though its pose is in
    no workspace cell at depth 10. locate used to say "no" where path moves."""
    _, _, u, v, t, ok = ref_ikp(M1, 12.999, 0.0, (1, 1))
    assert ok and abs(u - 1.02) < 0.01 and v > 1 and t > 1
    args = ("--pose", "12.999", "0", "--pose", "4", "5", "--working-mode", "++")
    located = run("locate", M1_YAML, "-o", m1_depth10, *args)
    assert located.status == 0, located.stderr
    assert "12.999, y = 0, theta1 = -0.00980573, theta2 = -2.18382 -> aspect 1 (certified)" in located.stdout
    assert located.stdout.endswith("1 -> 2: yes: both lie in aspect 1\n")
    moved = run("path", M1_YAML, "-o", m1_depth10, *args, "--no-plot")
    assert moved.status == 0 and "in aspect 1, certified" in moved.stdout
    _, rows, _ = read_path(m1_depth10)
    check_motion(M1, rows, 1, (1, 1))


JOINTS_CLOSE = ("--joints", "0.3", "1.2", "--joints", "0.35", "1.25", "--assembly-mode", "+")


def test_two_close_configurations_in_no_certified_cell_are_not_decided(tmp_path):
    """Two configurations 0.07 rad apart deep inside aspect 1 (same modes, far from singular by the
    independent kinematics): at depth 4 no certified cell holds them, so neither command proves
    anything; at the depth both advise, both find the motion."""
    _, _, u, v, t, ok = ref_dkp(M1, np.array([0.3, 0.35]), np.array([1.2, 1.25]), 1)
    assert ok.all() and (u > 5).all() and (v > 5).all() and (t > 5).all()
    located = run("locate", M1_YAML, "--depth", "4", *JOINTS_CLOSE)
    assert located.status == 0, located.stderr
    assert located.stdout.endswith("1 -> 2: not decided at depth 4: location 1 lies in no certified cell (too close "
                                   "to a singularity for cells this size); try --depth 6\n")
    assert "-> 2: no:" not in located.stdout
    line = one_line(run("path", M1_YAML, "--depth", "4", *JOINTS_CLOSE, "-o", tmp_path, "--no-plot"), 1)
    assert line == ("fivebar: error: not decided at depth 4: joints (0.3, 1.2) lies in no certified cell (too close "
                    "to a singularity for cells this size); try --depth 6")
    assert run("locate", M1_YAML, "--depth", "6", *JOINTS_CLOSE).stdout.endswith("1 -> 2: yes: both lie in aspect 1\n")
    moved = run("path", M1_YAML, "--depth", "6", *JOINTS_CLOSE, "-o", tmp_path, "--no-plot")
    assert moved.status == 0, moved.stderr
    _, rows, _ = read_path(tmp_path)
    assert len(rows) == 2  # the straight segment lies in the cells
    check_motion(M1, rows, 1, (1, 1))


# ---------------------------------------------------------------- locate against path, random pairs


SETTINGS = [(M1, 4), (M1, 9), (M2, 5), (M2, 10), (ROBUST_M1, 7), *((m, 8) for m in random_five_bars(2, 20))]
PAIRS = 14


@pytest.fixture(scope="module")
def outcomes():
    rng = np.random.default_rng(2020)
    out = {}
    for m, depth in SETTINGS:  # keyed by the setting's place: M1 and the robust M1 share a name
        s = Setting.of(m, depth)
        found = []
        while len(found) < PAIRS:
            o = judge(s, *random_pair(rng, s))
            if o is not None:
                found.append(o)
        out[len(out)] = (s, found)
    return out


IDS = [f"{'robust ' if getattr(m, 'is_interval', False) else ''}{m.name} depth {d}" for m, d in SETTINGS]


@pytest.mark.parametrize("k", range(len(SETTINGS)), ids=IDS)
def test_locate_and_path_agree_on_random_pairs(outcomes, k):
    s, found = outcomes[k]
    assert [disagreement(o) for o in found] == [None] * len(found)
    assert any(o.result is not None for o in found)  # the sample exercises motions, not only failures


def test_the_random_pairs_reach_every_answer(outcomes):
    total = {YES: 0, NO: 0, UNDECIDED: 0}
    for _, found in outcomes.values():
        for k, v in answers(found).items():
            total[k] += v
    assert min(total.values()) >= 3, total
    assert any(o.separated for _, found in outcomes.values() for o in found)


def robust_check(m, rows, assembly: int, working: tuple[int, int], rng) -> None:
    """Every sample of the joint motion, for every corner of the length box and random length
    vectors inside it, assembles in `assembly` with the working mode and det A of fixed signs."""
    pts = samples(rows)
    bounds = list(m.bounds)
    vectors = list(product(*bounds)) + [tuple(rng.uniform(lo, hi) for lo, hi in bounds) for _ in range(8)]
    for lengths in vectors:
        x, y, u, v, t, ok = ref_dkp(FiveBar("corner", *lengths), pts[:, 0], pts[:, 1], assembly)
        assert ok.all()
        assert np.all(np.sign(t) == assembly) and np.all(np.sign(u) == working[0]) and np.all(np.sign(v) == working[1])


@pytest.mark.parametrize("k", range(len(SETTINGS)), ids=IDS)
def test_every_motion_and_every_no_is_right(outcomes, k):
    """Motions: sampled against the independent kinematics (robust: at every corner of the length
    box). A no from the modes: the modes differ by the same kinematics. A no from two certified
    aspects: path two levels deeper finds no motion either."""
    s, found = outcomes[k]
    depth = s.depth
    rng = np.random.default_rng(7)
    robust = getattr(s.mechanism, "is_interval", False)
    for o in found:
        start, end = o.endpoints
        signs = (1 if start.assembly == "+" else -1, tuple(1 if c == "+" else -1 for c in start.working))
        if o.result is not None:
            rows = [list(j) + list(p) for j, p in zip(o.result.joints, o.result.poses)]
            if robust:
                robust_check(s.mechanism, rows, signs[0], signs[1], rng)
            else:
                check_motion(s.mechanism, rows, *signs)
        elif o.verdict.answer == NO and not o.separated:
            nominal = s.mechanism.nominal() if robust else s.mechanism
            modes = []
            for c in (start, end):
                _, _, u, v, t, ok = ref_dkp(nominal, c.joints[0], c.joints[1], 1 if c.assembly == "+" else -1)
                assert ok
                modes.append((np.sign(u), np.sign(v), np.sign(t)))
            assert modes[0] != modes[1]
        elif o.separated:
            assert recheck(s.mechanism, depth + 2, o)


# ---------------------------------------------------------------- the decision's hedges


def configuration(m, joints, assembly: str, label: str) -> Configuration:
    x, y, u, v, t, ok = ref_dkp(m.nominal() if getattr(m, "is_interval", False) else m, *joints,
                                1 if assembly == "+" else -1)
    assert ok
    working = "".join("+" if w > 0 else "-" for w in (u, v))
    return Configuration(label, np.array(joints, float), np.array([x, y]), working, assembly)


def test_uncertified_aspects_apart_are_not_decided():
    """With local refinement off, a random design (tests/test_aspect_certificate.py) keeps aspects
    of the same modes uncertified at depth 8: two of them are not proven apart."""
    m = FiveBar("x", 3, 5, 2, 2, 5)
    analysis = analyse_aspects(m, 8, budget=0, shapes=False)
    pairs = [(a, b) for a in analysis.aspects for b in analysis.aspects
             if a.number < b.number and (a.working, a.assembly) == (b.working, b.assembly)
             and not (a.certified and b.certified)]
    assert pairs
    a, b = pairs[0]
    ca = configuration(m, a.joints, "+" if a.assembly > 0 else "-", "A")
    cb = configuration(m, b.joints, "+" if b.assembly > 0 else "-", "B")
    verdict = decide(m.aspect_model(), analysis.aspects, ca, cb, 8)
    assert verdict.answer == UNDECIDED
    assert verdict.text() == (f"not decided at depth 8: A is in aspect {a.number}, B in aspect {b.number}, not both "
                              "certified: they may be one aspect; try `depth=10`")
    certified = analyse_aspects(m, 8, shapes=False)  # with the default budget the certificate separates them
    if all(x.certified for x in certified.aspects):
        assert decide(m.aspect_model(), certified.aspects, ca, cb, 8).answer in (NO, YES)


def test_robust_aspects_apart_are_not_decided(outcomes):
    """With interval lengths, two robust aspects apart do not prove that the nominal robot cannot
    move: locate says not decided (never no), and says why."""
    s = next(s for s, _ in outcomes.values() if s.mechanism is ROBUST_M1)
    aspects = s.analysis.aspects
    a, b = next((a, b) for a in aspects for b in aspects
                if a.number < b.number and (a.working, a.assembly) == (b.working, b.assembly))
    ca = configuration(ROBUST_M1, a.joints, "+" if a.assembly > 0 else "-", "A")
    cb = configuration(ROBUST_M1, b.joints, "+" if b.assembly > 0 else "-", "B")
    verdict = decide(ROBUST_M1.aspect_model(), aspects, ca, cb, s.depth, robust=True)
    assert verdict.answer == UNDECIDED and "robust aspects apart do not prove" in verdict.reason


def test_locate_with_a_tolerance_never_says_no_for_aspects_apart():
    """M1's aspects 2 and 3 (working mode +-, det A +) are certified apart; with --tolerance the
    same two locations (in robust aspects 2 and 3) are not decided."""
    args = ("--joints", "-1.9352432682328933", "-1.6184140826254692", "--joints", "0.9829590321029409",
            "2.3298990239216373", "--assembly-mode", "+")
    nominal = run("locate", M1_YAML, "--depth", "7", *args)
    assert nominal.stdout.endswith("1 -> 2: no: location 1 is in aspect 2, location 2 in aspect 3, both certified: "
                                   "every motion between them crosses a singularity\n")
    robust = run("locate", M1_YAML, "--depth", "7", "--tolerance", "0.02", *args)
    assert robust.status == 0, robust.stderr
    assert "robust aspects apart do not prove that every motion crosses a singularity" in robust.stdout
    assert "1 -> 2: no:" not in robust.stdout
    # the library call takes the tolerance as the command does (it was a TypeError), and as a
    # mechanism loaded with it
    joints = [(float(args[1]), float(args[2])), (float(args[4]), float(args[5]))]
    library = fb.locate(M1_YAML, joints=joints, depth=7, assembly_mode="+", tolerance=0.02)
    assert [as_flags(line) for line in library.lines()] == robust.stdout.splitlines()
    assert library.rows() == fb.locate(fb.load(M1_YAML, tolerance=0.02), joints=joints, depth=7,
                                       assembly_mode="+").rows()


def test_modes_apart_are_no_even_when_one_is_on_a_serial_singularity():
    """A sign that vanishes at neither configuration decides: det A differs -> no, even if B11
    vanishes at one of them; the same modes with one on a singularity -> not decided."""
    model = M1.aspect_model()
    on = Configuration("S", np.zeros(2), np.zeros(2), "0+", "+")
    other = Configuration("T", np.zeros(2), np.zeros(2), "++", "-")
    same = Configuration("U", np.zeros(2), np.zeros(2), "++", "+")
    assert mode_verdict(model, on, other, 8).answer == NO
    verdict = mode_verdict(model, on, same, 8)
    assert verdict.answer == UNDECIDED and "S is on or near a serial singularity (B11 = 0)" in verdict.reason
    assert mode_verdict(model, Configuration("V", np.zeros(2), np.zeros(2), "-+", "+"), same, 8).answer == NO


# ---------------------------------------------------------------- honest words


def test_depth_0_is_blamed_on_the_depth_not_a_singularity():
    r = run("locate", M1_YAML, "--depth", "0", "--pose", "4", "5")
    assert r.status == 0, r.stderr
    assert "singularity:" not in r.stdout and "on or near" not in r.stdout
    assert r.stdout == (
        "M1: 0 aspects at depth 0 computed (none has certified cells at this depth)\n"
        "location 1: pose (4, 5): 4 configurations (floating-point kinematics, not certified)\n"
        + "".join(f"  working mode {wm}, assembly mode {am}: x = 4, y = 5, theta1 = {t1}, theta2 = {t2} -> in no "
                  "certified cell at depth 0 (too close to a singularity for cells this size: try --depth 2)\n"
                  for wm, am, t1, t2 in (("++", "+", "0.221314", "0.941596"), ("+-", "-", "0.221314", "-2.51239"),
                                         ("-+", "-", "1.5708", "0.941596"), ("--", "+", "1.5708", "-2.51239"))))


def test_counts_are_singular_when_one_and_say_whether_certified():
    r = run("locate", M1_YAML, "--depth", "8", "--pose", "4", "5", "--working-mode", "++")
    assert "location 1: pose (4, 5): 1 configuration in working mode ++ (floating-point kinematics, not certified)\n" \
        in r.stdout
    assert r.stdout.startswith("M1: 10 aspects at depth 8 computed (all certified)\n")
    r = run("locate", RPR2_YAML, "--depth", "6", "--pose", "4", "5")  # one working mode: one configuration
    assert r.stdout.startswith("rpr2-demo: 2 aspects at depth 6 computed (all certified)\n"), r.stdout
    assert "location 1: pose (4, 5): 1 configuration (floating-point kinematics, not certified)\n" in r.stdout


def test_an_unreachable_location_is_not_decided():
    r = run("locate", M1_YAML, "--depth", "6", "--pose", "30", "0", "--pose", "4", "5", "--working-mode", "++")
    assert r.status == 0, r.stderr
    assert "location 1: pose (30, 0): no configuration in working mode ++ (floating-point kinematics, not certified)" \
        in r.stdout
    assert r.stdout.endswith("1 -> 2: not decided: location 1 has no configuration in working mode ++ (floating-point "
                             "kinematics): there is nothing to join\n")


def test_several_configurations_per_location_list_the_pairs_the_modes_leave_open():
    r = run("locate", M1_YAML, "--depth", "8", "--pose", "4", "5", "--pose", "4.5", "5")
    assert r.stdout.endswith(
        "1 -> 2: yes, over the 16 pairs of their configurations:\n"
        "    working mode ++, det A +: yes: both lie in aspect 1\n"
        "    working mode +-, det A -: yes: both lie in aspect 7\n"
        "    working mode -+, det A -: yes: both lie in aspect 9\n"
        "    working mode --, det A +: yes: both lie in aspect 5\n"
        "    the other 12 pairs: no: different modes\n")
    r = run("locate", M1_YAML, "--depth", "8", "--pose", "4", "5", "--pose", "6", "-3")
    assert r.stdout.endswith("1 -> 2: no, over the 16 pairs: every pair has different modes, so every motion between "
                             "them crosses a singularity\n")


# ---------------------------------------------------------------- command-line numbers


def test_degrees_are_the_same_configuration_as_radians(tmp_path):
    degrees = run("locate", M2_YAML, "--depth", "8", "--joints", "10deg", "80deg", "--csv")
    radians = run("locate", M2_YAML, "--depth", "8", "--joints", repr(math.radians(10)), repr(math.radians(80)),
                  "--csv")
    assert degrees.status == 0 and degrees.stdout.replace("joints 0.174533 1.39626", "") \
        == radians.stdout.replace("joints 0.174533 1.39626", "")
    rows = list(csv.DictReader(io.StringIO(degrees.stdout)))
    assert rows and rows[0]["location"] == "joints 0.174533 1.39626"
    moved = run("path", M2_YAML, "--depth", "8", "--joints", "10deg", "80deg", "--joints", "20deg", "70deg",
                "--assembly-mode", "+", "-o", tmp_path, "--no-plot")
    assert moved.status == 0, moved.stderr
    _, rows, text = read_path(tmp_path)
    assert [float(v) for v in text[0][:2]] == [math.radians(10), math.radians(80)]
    assert [float(v) for v in text[-1][:2]] == [math.radians(20), math.radians(70)]


BAD_NUMBERS = [
    ("locate", ["--pose", "nan", "0"], "--pose"),
    ("locate", ["--pose", "inf", "0"], "--pose"),
    ("locate", ["--joints", "1e300", "0"], "--joints"),
    ("locate", ["--joints", "0.1", "-infdeg"], "--joints"),
    ("locate", ["--joints", "2e6", "0"], "--joints"),
    ("locate", ["--joints", "x", "0"], "--joints"),
    ("path", ["--pose", "4", "5", "--pose", "nan", "8", "--working-mode", "++"], "--pose"),
    ("path", ["--joints", "0.1", "0.7", "--joints", "1e300", "0", "--assembly-mode", "+"], "--joints"),
    ("path", ["--joints", "0.1", "0.7", "--joints", "1e8deg", "0", "--assembly-mode", "+"], "--joints"),
]


@pytest.mark.parametrize("command,args,needle", BAD_NUMBERS, ids=[f"{c} {' '.join(a)}" for c, a, _ in BAD_NUMBERS])
def test_numbers_must_be_finite(tmp_path, command, args, needle):
    out = ["-o", tmp_path / "out"] if command == "path" else []
    one_line(run(command, M1_YAML, *args, "--depth", "4", *out), 2, needle)
    assert not (tmp_path / "out").exists()


def test_degrees_are_refused_for_a_length(tmp_path):
    line = one_line(run("locate", RPR2_YAML, "--joints", "5deg", "6", "--depth", "4"), 2, "--joints")
    assert "rho1 is a length, not an angle" in line


def test_a_configuration_violating_an_obstacle_is_in_no_aspect_and_not_decided():
    """configs/m1-obstacle.yaml: at (4.5, 1.5) the ++ configuration's links meet the obstacle (issue
    18's `violates`); locate says so, and leaves the pair undecided (never yes, never no)."""
    r = run("locate", REPO / "configs" / "m1-obstacle.yaml", "--pose", "4.5", "1.5", "--pose", "4", "5",
            "--working-mode", "++", "--depth", "4")
    assert r.status == 0, r.stderr
    assert "-> violates the obstacle 1 (in no aspect)" in r.stdout
    assert r.stdout.endswith("1 -> 2: not decided at depth 4: location 1 violates the obstacle 1 (by a "
                             "floating-point check): it is in no aspect\n")
