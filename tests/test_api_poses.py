"""The API calls behind `fivebar dkp`, `locate` and `path` over a space of poses (api/poses.py) and
`fivebar diff` (api/trees.py): each value gives the command's rows, lines and files byte for byte;
the numbers agree with independent ones (the legs of every pose measured from the config's
geometry, a brute-force comparison of two trees' cells); bad input raises InputError naming the
field."""

from __future__ import annotations

import math
import re

import numpy as np
import pytest
import yaml

import fivebar_cli as fb
from fivebar_cli.cli.options import as_flags
from tests.cli_helpers import REPO, ok, one_line, run_cli

CARO = REPO / "configs" / "rpr3-caro.yaml"
# Table 1's design with legs from 2 on: rho_max auto is infinite (no singularity circle reaches the
# annuli), so no box holds its poses
UNBOUNDED = {"name": "unbounded", "type": "rpr3", "k": 0.6, "legs": {"rho_min": 2}, "phi": 100,
             "base": {"t1": 1.5196713713031851, "t2": 0.7598356856515925, "t3": 1.3160740129524924}}
LEGS = (20.6315, 23.2633, 16.0359)  # aspect 1's inner pose at depth 5: two assembly modes, in aspects 1 and 2


@pytest.fixture(scope="module")
def caro():
    return fb.aspects("rpr3-caro", 5)


def leg_lengths(pose) -> list[float]:
    """The legs of a 3-RPR pose (x, y, phi_deg) measured from the YAML's base and platform points
    (the platform's first point at (x, y)), independently of the library's model."""
    spec = yaml.safe_load(CARO.read_text())
    x, y, phi = pose[0], pose[1], math.radians(pose[2])
    c, s = math.cos(phi), math.sin(phi)
    return [math.hypot(x + c * p[0] - s * p[1] - b[0], y + s * p[0] + c * p[1] - b[1])
            for b, p in zip(spec["base"].values(), spec["platform"].values())]


def test_dkp_is_the_command_and_every_pose_has_the_legs(tmp_path, caro):
    d = fb.dkp(CARO, LEGS, 5, aspects=caro)
    assert len(d) == 2 and [r["certified"] for r in d.rows()] == ["true", "true"]
    for r in d.rows():
        assert np.allclose(leg_lengths((r["x"], r["y"], r["phi_deg"])), LEGS, atol=1e-9, rtol=0)
    assert [(r["det_sign"], r["aspect"]) for r in d.rows()] == [("+", 1), ("-", 2)]
    assert abs(d.rows()[0]["phi_deg"] - caro[0].pose[2]) < 1e-3  # the aspect's own inner pose is mode 1
    # the command (its aspects read from the folder an `aspects` run saved) prints the same lines, writes the same file
    caro.save(tmp_path)
    cli = ok(run_cli("dkp", CARO, "--joints", *LEGS, "--depth", 5, "-o", tmp_path, "--no-plot"))
    assert cli.stdout.splitlines()[:-1] == [line.replace("given", f"read from {tmp_path}") for line in d.notes]
    made = d.save(tmp_path / "api")
    assert [p.name for p in made] == ["dkp.csv"] and made[0].read_bytes() == (tmp_path / "dkp.csv").read_bytes()


def test_aspects_of_another_mechanism_are_refused(caro):
    """Aspects computed for one mechanism, given to a call on another: refused, naming `aspects`
    (they raised an AttributeError from deep inside, or located M1's poses in the 3-RPR's trees and
    answered); the mechanism's own aspects, however it was loaded, are taken."""
    m1 = fb.aspects("m1", 4)
    for call in (lambda: fb.dkp(CARO, LEGS, 3, aspects=m1), lambda: fb.locate(CARO, pose=(8, -9, -5.6), aspects=m1),
                 lambda: fb.locate("m1", pose=(4, 5), aspects=caro), lambda: fb.locate("m2", pose=(1, 2), aspects=m1)):
        with pytest.raises(fb.InputError, match="were computed for another mechanism") as caught:
            call()
        assert caught.value.field == "`aspects`"
    assert fb.locate(fb.load(REPO / "configs" / "m1.yaml"), pose=(4, 5), aspects=m1).depth == 4


@pytest.mark.parametrize("call, field", [
    (lambda: fb.dkp("rpr3-caro", (1, 15, 12), 2), "`joints`"),
    (lambda: fb.dkp("rpr3-caro", (1, 15, 12), 2, what="legs"), "`legs`"),
    (lambda: fb.dkp("rpr3-caro", (31, 31, 31, 31), 2), "`joints`"),
    (lambda: fb.dkp("rpr3-caro", "abc", 2), "`joints`"),
    (lambda: fb.dkp("rpr3-caro", (15, float("nan"), 12), 2), "`joints`"),
    # legs are lengths (a 3-RPR's): a 3-RRR's angles given as legs, and another word for `what`,
    # were taken as joints
    (lambda: fb.locate("rrr3-symmetric", legs=(1, 1, 1), depth=2), "`legs`"),
    (lambda: fb.path("rrr3-symmetric", 1, 2, legs=(1, 1, 1), depth=2), "`legs`"),
    (lambda: fb.dkp("rrr3-symmetric", (1, 1, 1), 2, what="legs"), "`legs`"),
    (lambda: fb.dkp("rpr3-caro", (14.98, 15.38, 12), 2, what="leg"), "`what`"),
    # a depth that is not the aspects' given (it was ignored: theirs was used)
    (lambda: fb.locate("m1", pose=(4, 5), depth=8, aspects=fb.aspects("m1", 4)), "`depth`"),
    (lambda: fb.dkp("rpr3-caro", (20.6315, 23.2633, 16.0359), 5, aspects=fb.aspects("rpr3-caro", 2)), "`depth`"),
    # a working mode with assembly modes of joint values (it was ignored: their classes decide)
    (lambda: fb.path("rpr3-caro", 1, 2, legs=(14.98, 15.38, 12), depth=4, working_mode="+++"), "`working_mode`"),
    (lambda: fb.dkp("rpr3-caro", 15, 2), "`joints`"),
    (lambda: fb.dkp("rpr3-caro", (14.98, 15.38, 12), 10), "`depth`"),
    # a kind without poses (x, y, phi) is told so on `type`; a 3-RPR whose legs leave its space of poses
    # unbounded, on `legs.rho_max` (the five-bar was once told to give a rho_max it has no field for)
    (lambda: fb.dkp("m1", (1, 1, 1), 2), "type"),
    (lambda: fb.dkp("rpr2", (1, 1, 1), 2), "type"),
    (lambda: fb.verify("m1", 4), "type"),
    (lambda: fb.dkp(UNBOUNDED, (1, 1, 1), 2), "legs.rho_max"),
    (lambda: fb.verify(UNBOUNDED, 4), "legs.rho_max"),
    (lambda: fb.aspects(UNBOUNDED, 3), "legs.rho_max"),  # (was: 'an rpr3 has no working and assembly modes')
    (lambda: fb.path("rpr3-caro", 1, 7, legs=(14.98, 15.38, 12), depth=5), "`goal`"),
    (lambda: fb.path("rpr3-caro", 1, 2, joints=(14.98, 15.38, 12), legs=(14.98, 15.38, 12), depth=5), "`legs`"),
    (lambda: fb.locate("rpr3-caro", legs=(1, 15, 12), depth=2), "`legs`"),
    (lambda: fb.locate("rpr3-caro", pose=(500, 0, 0), depth=2), "`pose`"),
    (lambda: fb.locate("rpr3-caro", pose=(8, -9), depth=2), "`pose`"),
    (lambda: fb.locate("rpr3-caro", legs=[(15, 15, 12), (15, "x", 12)], depth=2), "`legs`"),
    (lambda: fb.path("rpr3-caro", (8, -9), (1, 2, 3), depth=5), "`start`"),
    (lambda: fb.path("rpr3-caro", (8, -9, -5.6), {"pose": (1, 2, 3)}, depth=5), "`goal`"),
    (lambda: fb.path("rpr3-caro", (8, -9, float("inf")), (1, 2, 3), depth=5), "`start`"),
    (lambda: fb.compare(REPO / "tests/golden/M1/workspace.qt", REPO / "tests/golden/M2/workspace.qt"), "root"),
    # arguments of another kind's motion, once taken without a word (its motion avoided every singularity)
    (lambda: fb.path("rpr3-caro", (8, -9, -5.6), (-10.0195, -18.0352, -11.25), depth=5, allow_serial=True),
     "`allow_serial`"),
    (lambda: fb.path("rpr3-caro", (8, -9, -5.6), (-10.0195, -18.0352, -11.25), depth=5, assembly_mode="+"),
     "`assembly_mode`"),
    (lambda: fb.path("rpr2", (0, 8), (1, 8), working_mode="++", depth=5, allow_serial=True), "`allow_serial`"),
    (lambda: fb.locate("rpr3-caro", pose=(8, -9, -5.6), depth=2, assembly_mode="+"), "`assembly_mode`"),
    (lambda: fb.path("m1", {"joints": (-0.1, -2.06)}, {"joints": (0.88, 1.47)}, assembly_mode="+", working_mode="--",
                     depth=8), "`working_mode`"),
    # modes that are none of the kind's (every configuration was filtered out, or no motion found)
    (lambda: fb.locate("m1", joints=(0.3, 1.2), working_mode="xx", depth=6), "`working_mode`"),
    (lambda: fb.locate("rpr2", pose=(0, 8), assembly_mode="0", depth=6), "`assembly_mode`"),
    (lambda: fb.path("m1", (4, 5), (6, 8), working_mode="+", depth=6), "`working_mode`"),
    (lambda: fb.path("m1", {"pose": (4, 5), "working_mode": "++"}, {"pose": (6, 8), "working_mode": "+-+"}, depth=6),
     "`working_mode`"),
    (lambda: fb.path("m1", (4, 5), (6, 8), working_mode="++", assembly_mode="x", depth=6), "`assembly_mode`"),
])
def test_bad_input_names_the_field(call, field):
    with pytest.raises(fb.InputError) as caught:
        call()
    assert caught.value.field == field
    assert " a rpr" not in str(caught.value)  # (an rpr2, an rpr3: `article`)


def test_a_depth_left_out_is_the_kinds_default():
    """None is 10 for a five-bar or a 2-RPR and 7 over a space of poses, as the commands' defaults:
    a default of 10 refused every call over poses that left the depth out (an octree allows 9)."""
    from fivebar_cli.api.calls import depth_or_default

    assert [depth_or_default(fb.load(n), None) for n in ("m1", "rpr2", "rpr3-caro", "rrr3-symmetric")] == [10, 10, 7, 7]
    assert depth_or_default(fb.load("rpr3-caro"), 9) == 9
    # the calls get past their depth to the next check (leg lengths out of range: nothing computed)
    for call in (lambda: fb.locate("rpr3-caro", legs=(1, 15, 12)),
                 lambda: fb.path("rpr3-caro", 1, 2, legs=(1, 15, 12))):
        with pytest.raises(fb.InputError, match="rho1 = 1 is outside its range"):
            call()


def test_a_kind_without_poses_is_told_which_kinds_have_them(tmp_path):
    """The message itself, from the library and the command: a five-bar or a 2-RPR has no space of
    poses (x, y, phi), only a 3-RPR or a 3-RRR; the unbounded 3-RPR is told to give rho_max."""
    with pytest.raises(fb.InputError, match=r"^m1: type: a fivebar has no space of poses \(x, y, phi\): only a 3-RPR "
                       r"or a 3-RRR has one$"):
        fb.dkp("m1", (1, 1, 1), 2)
    one_line(run_cli("dkp", REPO / "configs" / "rpr2.yaml", "--joints", 1, 1, 1), 2,
             "rpr2.yaml: type: an rpr2 has no space of poses (x, y, phi)")
    # every call that needs the space of poses of a 3-RPR with unbounded legs gives the one reason
    # (`Mechanism.no_pose_space`), which the 3-RPR's own commands gave already
    reason = ("legs.rho_max: 'auto' is unbounded here (every point of the singularity circle is within rho_min "
              "of some C_i)")
    for call in (lambda: fb.verify(UNBOUNDED, 4), lambda: fb.aspects(UNBOUNDED, 3),
                 lambda: fb.pave(UNBOUNDED, "workspace", 3), lambda: fb.locate(UNBOUNDED, pose=(0, 0, 100)),
                 lambda: fb.rpr3.verify(UNBOUNDED)):
        with pytest.raises(fb.InputError, match=re.escape(reason)):
            call()
    path = tmp_path / "unbounded.yaml"
    path.write_text(yaml.safe_dump(UNBOUNDED))
    for args in (("workspace",), ("aspects",), ("rpr3", "pave")):
        one_line(run_cli(*args, path, "-o", tmp_path / "out"), 2, f"{path}: {reason}")
    assert not (tmp_path / "out").exists()
    # a mapping is named `<mapping>` by every call (aspects named it by the whole dict's repr)
    for call in (fb.verify, fb.aspects, lambda m, d: fb.dkp(m, (1, 1, 1), d)):
        with pytest.raises(fb.InputError) as caught:
            call(UNBOUNDED, 3)
        assert caught.value.source == "<mapping>", str(caught.value)


def test_locate_and_path_over_poses_are_the_commands(tmp_path, caro):
    """Two poses of aspect 1 and the two assembly modes of LEGS: the rows, CSV and lines of
    `fivebar locate`; the motion between the poses is `fivebar path`'s."""
    ends = [(8, -9, -5.6), (-10.0195, -18.0352, -11.25)]
    where = fb.locate(CARO, pose=ends, legs=LEGS, aspects=caro)
    assert [(r["location"], r["class"], r["aspect"]) for r in where.rows()] == [
        ("pose 8 -9 -5.6", {"det_sign": "+"}, 1), ("pose -10.0195 -18.0352 -11.25", {"det_sign": "+"}, 1),
        ("legs 20.6315 23.2633 16.0359", {"det_sign": "+"}, 1), ("legs 20.6315 23.2633 16.0359", {"det_sign": "-"}, 2)]
    for r in where.rows():
        assert np.allclose(leg_lengths(r["pose"]), r["joints"], atol=1e-9, rtol=0)
    assert where.lines()[-3:] == [f"  {i} -> {j}: yes, within aspect(s) 1" for i, j in ((1, 2), (1, 3), (2, 3))]
    caro.save(tmp_path)  # the command reads the saved aspects
    args = ("locate", CARO, "--pose", *ends[0], "--pose", *ends[1], "-d", 5, "-o", tmp_path)
    poses = fb.locate(CARO, pose=ends, aspects=caro)
    assert ok(run_cli(*args, "--csv")).stdout == poses.csv()
    assert ok(run_cli(*args)).stdout.splitlines()[1:] == poses.lines()[1:] == where.lines()[1:5] + where.lines()[8:10]

    motion = fb.path(CARO, *ends, depth=5)
    assert motion.labels == ("pose (8, -9, -5.6)", "pose (-10.0195, -18.0352, -11.25)")
    assert np.allclose(motion.points[[0, -1], :3], ends) and np.allclose(motion.points[:, 3:], [
        leg_lengths(p) for p in motion.points[:, :3]], atol=1e-9)
    cli = ok(run_cli("path", CARO, "--pose", *ends[0], "--pose", *ends[1], "-d", 5, "-o", tmp_path / "p", "--no-plot"))
    assert cli.stdout.splitlines()[:-1] == [as_flags(line) for line in motion.notes]
    assert motion.save(tmp_path / "api")[0].read_bytes() == (tmp_path / "p" / "path.csv").read_bytes()
    with pytest.raises(fb.FivebarError, match="different classes"):
        fb.path(CARO, 1, 2, legs=LEGS, depth=5)


def _finest_cells(tree, depth: int) -> set[tuple[int, int]]:
    """The cells of a quadtree as a set of finest-grid cells (brute force, cell by cell)."""
    (x0, x1), (y0, y1) = tree.grid.root
    wx, wy = (x1 - x0) / 2 ** depth, (y1 - y0) / 2 ** depth
    lo, hi = tree.bounds()
    out = set()
    for (ax, ay), (bx, by) in zip(lo, hi):
        i0, i1 = round((ax - x0) / wx), round((bx - x0) / wx)
        j0, j1 = round((ay - y0) / wy), round((by - y0) / wy)
        out.update((i, j) for i in range(i0, i1) for j in range(j0, j1))
    return out


def test_compare_is_a_cell_by_cell_comparison_and_the_command(tmp_path):
    coarse = fb.pave("m1", "workspace", 5)
    fine = fb.refine(coarse, 7)
    c = fb.compare(fine.inside, coarse.inside)  # the finer paving holds more black cells
    a, b = _finest_cells(fine.inside, 7), _finest_cells(coarse.inside, 7)
    (x0, x1), (y0, y1) = fine.inside.grid.root
    cell = (x1 - x0) * (y1 - y0) / 4 ** 7
    assert b <= a and len(a - b) > 0
    assert c.only_a.area == pytest.approx(len(a - b) * cell, rel=1e-12) and c.only_b.area == 0
    assert (c.same, c.equal, c.exit_code) == (False, False, 1)
    same = fb.compare(coarse.inside, coarse.inside)
    assert (same.same, same.exit_code, same.notes) == (True, 0, (f"same set: {len(coarse.inside)} cells, area "
                                                                 f"{coarse.inside.area:.10g}",))
    # a tree and its complement on the same grid: nothing in common; the command says the same
    coarse.save(tmp_path)
    qt, complement = tmp_path / "workspace.qt", tmp_path / "workspace.complement.qt"
    files = fb.compare(qt, complement)
    assert not (_finest_cells(files.only_a, 5) & _finest_cells(files.only_b, 5))
    assert ("colour", "inside", "outside") in files.headers
    cli = run_cli("diff", qt, complement)
    assert cli.status == files.exit_code == 1 and cli.stdout.splitlines() == [as_flags(x) for x in files.notes]
    assert run_cli("diff", qt, qt).status == fb.compare(qt, qt).exit_code == 0
    assert "0 cells only in A" not in repr(files) and "\n" not in repr(files)
    # two pavings: their inside trees with the headers of their saved files (a TypeError-like
    # refusal before), the same comparison as of the files
    fine.save(tmp_path / "fine")
    pavings, saved = fb.compare(fine, coarse), fb.compare(tmp_path / "fine" / "workspace.qt", qt)
    assert (pavings.same, pavings.headers, pavings.notes[2:]) == (saved.same, saved.headers, saved.notes[2:])
    assert ("evaluations", str(fine.evaluations), str(coarse.evaluations)) in pavings.headers
