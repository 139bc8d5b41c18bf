"""Aspects in one space of poses (analyses/pose_aspects.py, `fivebar aspects` and `locate` for a
3-RPR): certified counts against Caro et al. and an independent dense-grid count on random robots
(tests/reference_pose_aspects.py), soundness of the aspect trees at sampled poses, the periodic
orientation axis, the surface meshes read back, the files, the page and bad input."""

from __future__ import annotations

import csv

import numpy as np
import pytest
import yaml

from cli_helpers import REPO, one_line, ok, run_cli
from reference_pose_aspects import count as grid_count
from reference_pose_aspects import stable_count
from rpr3_reference import det_j, legs

from fivebar_cli.analyses.pose_aspects import analyse_pose_aspects
from fivebar_cli.io.mesh import axis_scales
from fivebar_cli.mechanisms.rpr3.model import Rpr3

CARO = REPO / "configs" / "rpr3-caro.yaml"
GENERAL = REPO / "configs" / "rpr3-general.yaml"


def load(path) -> Rpr3:
    return Rpr3.parse(yaml.safe_load(path.read_text()), str(path))


def robot(base, platform, rho_min, rho_max, phi_range=(-180.0, 180.0), name="r") -> Rpr3:
    """A general 3-RPR from its points, leg ranges (one number or three) and orientation range."""
    def legs_of(v):
        return float(v) if np.isscalar(v) else [float(x) for x in v]

    data = {"name": name, "type": "rpr3",
            "base": {f"B{i + 1}": [float(v) for v in base[i]] for i in range(3)},
            "platform": {f"P{i + 1}": [float(v) for v in platform[i]] for i in range(3)},
            "legs": {"rho_min": legs_of(rho_min), "rho_max": legs_of(rho_max)},
            "phi_range": [float(v) for v in phi_range]}
    return Rpr3.parse(data, name)


def random_robot(seed: int, full_turn: bool) -> Rpr3:
    """Random base, platform, per-leg ranges and orientation range (a full turn or 40 to 200 degrees)."""
    rng = np.random.default_rng(seed)
    while True:
        base, platform = rng.uniform(-10, 10, (3, 2)), rng.uniform(-8, 8, (3, 2))
        rho_min = rng.uniform(0, 6, 3)
        rho_max = rho_min + rng.uniform(6, 22, 3)
        a = rng.uniform(-180, 180)
        phi_range = (a, a + 360.0) if full_turn else (a, a + rng.uniform(40, 200))
        try:
            return robot(base, platform, rho_min, rho_max, phi_range, f"random-{seed}")
        except Exception:  # legs that never meet: draw again
            continue


def sample_cells(tree, rng, per_leaf: int = 4, max_leaves: int = 3000) -> np.ndarray:
    """Random poses in the leaves (their corners included), at most max_leaves leaves."""
    lo, hi = tree.bounds()
    pick = rng.choice(len(lo), size=min(len(lo), max_leaves), replace=False)
    lo, hi = lo[pick], hi[pick]
    u = rng.random((len(lo), per_leaf, lo.shape[1]))
    u[:, 0] = 0.0
    u[:, 1] = 1.0
    return (lo[:, None] + u * (hi - lo)[:, None]).reshape(-1, lo.shape[1])


# ---------------------------------------------------------------- Caro's example


@pytest.fixture(scope="module")
def caro_run(tmp_path_factory):
    """`fivebar aspects` on Caro's example at depth 5 into a folder (in process), with the analysis
    that run computed: a spy on analyse_pose_aspects keeps it, so that the depth-5 checks below read
    the command's own analysis instead of computing the same one again."""
    from fivebar_cli.analyses import pose_aspects

    folder, seen = tmp_path_factory.mktemp("caro"), []
    with pytest.MonkeyPatch.context() as patch:
        patch.setattr(pose_aspects, "analyse_pose_aspects",
                      lambda *args, **kwargs: seen.append(analyse_pose_aspects(*args, **kwargs)) or seen[-1])
        result = ok(run_cli("aspects", CARO, "--depth", "5", "-o", folder, "--no-plot"))
    (analysis,) = seen
    return folder, result, analysis


@pytest.fixture(scope="module")
def caro(caro_run):
    m = load(CARO)
    return m, {5: caro_run[2], 6: analyse_pose_aspects(m, 6)}


def test_caros_example_is_a_certified_two_at_every_depth(caro):
    m, runs = caro
    assert m.spaces()["workspace"].axes[2].periodic
    for depth, analysis in runs.items():
        assert analysis.certified, (depth, analysis.headline())
        assert len(analysis.aspects) == 2 and analysis.lower == analysis.upper == 2
        assert [a.signs.fields for a in analysis.aspects] == [(("det_sign", "+"),), (("det_sign", "-"),)]
        assert "2 generalized aspects at depth" in analysis.headline() and "(certified;" in analysis.headline()


def test_aspect_cells_are_valid_poses_of_their_sign_at_sampled_poses(caro):
    m, runs = caro
    rng = np.random.default_rng(1)
    rho_min, rho_max = np.array(m.rho_min), np.array(m.rho_max)
    for a in runs[6].aspects:
        poses = sample_cells(a.tree, rng)
        lengths = legs(m.base, m.platform, poses)
        assert np.all((lengths >= rho_min - 1e-9) & (lengths <= rho_max + 1e-9))
        sign = 1 if a.signs.fields[0][1] == "+" else -1
        assert np.all(sign * det_j(m.base, m.platform, poses) > 0)
        np.testing.assert_allclose(legs(m.base, m.platform, np.array([a.pose]))[0], a.joints, rtol=1e-12)
    first, second = runs[6].aspects
    assert len(first.tree & second.tree) == 0


def test_the_aspects_wrap_across_the_seam_of_a_full_turn(caro):
    """A full turn glues phi = -180 to 180: each aspect runs across the seam (its cells meet both
    ends of the range), and the independent grid counts 2 only when it glues them too."""
    m, runs = caro
    root = m.spaces()["workspace"].root
    assert grid_count(m.base, m.platform, m.rho_min, m.rho_max, root, True, 64) == 2
    assert grid_count(m.base, m.platform, m.rho_min, m.rho_max, root, False, 64) > 2
    grid = runs[6].aspects[0].tree.grid
    for a in runs[6].aspects:
        lo, hi = a.tree.bounds()
        assert lo[:, 2].min() == grid.root[2][0] and hi[:, 2].max() == grid.root[2][1]
        assert a.tree.grid.periodic == (False, False, True)


# ---------------------------------------------------------------- random robots


@pytest.mark.parametrize("seed, full_turn", [(0, True), (1, False)])
def test_certified_counts_on_random_robots_match_the_grid_and_do_not_change_with_depth(seed, full_turn):
    m = random_robot(seed, full_turn)
    root = m.spaces()["workspace"].root
    reference = stable_count(m.base, m.platform, m.rho_min, m.rho_max, root, full_turn)
    counts = {}
    for depth in (5, 6):
        analysis = analyse_pose_aspects(m, depth, budget=1 << 18)
        assert analysis.lower <= len(analysis.aspects) <= analysis.upper
        assert analysis.lower <= (reference or analysis.lower) <= analysis.upper  # the bounds hold
        if analysis.certified:
            counts[depth] = len(analysis.aspects)
    assert counts, "no certified count at depths 5 and 6"
    assert len(set(counts.values())) == 1, counts
    assert reference is not None and set(counts.values()) == {reference}


# ---------------------------------------------------------------- the command and its files


@pytest.fixture(scope="module")
def caro_folder(caro_run):
    return caro_run[:2]


def test_aspects_command_writes_the_table_trees_and_meshes(caro_folder):
    folder, result = caro_folder
    assert "rpr3-caro: 2 generalized aspects at depth 5 (certified;" in result.stdout
    with open(folder / "aspects.csv", newline="") as fh:
        rows = list(csv.reader(fh))
    assert rows[0] == ["aspect", "det_sign", "volume", "cells", "x", "y", "phi_deg", "rho1", "rho2", "rho3",
                       "certified"]
    assert [r[1] for r in rows[1:]] == ["+", "-"] and all(r[-1] == "true" for r in rows[1:])
    m = load(CARO)
    for r in rows[1:]:
        pose = np.array([[float(v) for v in r[4:7]]])
        np.testing.assert_allclose(legs(m.base, m.platform, pose)[0], [float(v) for v in r[7:10]], rtol=1e-8)
        assert np.sign(det_j(m.base, m.platform, pose)[0]) == (1 if r[1] == "+" else -1)
    names = sorted(p.name for p in (folder / "aspects").iterdir())
    assert names == ["aspect-01.workspace.ply", "aspect-01.workspace.qt", "aspect-02.workspace.ply",
                     "aspect-02.workspace.qt"]


def read_ply(path):
    """An independent reader of binary little-endian PLY files (vertices double x, y, z; faces as a
    uchar count and int32 indices)."""
    data = path.read_bytes()
    head, _, body = data.partition(b"end_header\n")
    lines = head.decode("ascii").split("\n")
    assert lines[0] == "ply" and lines[1] == "format binary_little_endian 1.0"
    nv = int(next(ln for ln in lines if ln.startswith("element vertex")).split()[-1])
    nf = int(next(ln for ln in lines if ln.startswith("element face")).split()[-1])
    vertices = np.frombuffer(body[:24 * nv], "<f8").reshape(nv, 3)
    faces = np.frombuffer(body[24 * nv:], dtype=[("n", "u1"), ("v", "<i4", (3,))])
    assert len(faces) == nf and np.all(faces["n"] == 3)
    comments = [ln[len("comment "):] for ln in lines if ln.startswith("comment ")]
    return vertices, faces["v"].astype(np.int64), comments


def test_meshes_are_closed_and_enclose_the_aspects_volume(caro_folder):
    folder, _ = caro_folder
    m = load(CARO)
    scale = axis_scales(m.spaces()["workspace"].axes)
    with open(folder / "aspects.csv", newline="") as fh:
        volumes = {int(r["aspect"]): float(r["volume"]) for r in csv.DictReader(fh)}
    for number, volume in volumes.items():
        vertices, triangles, comments = read_ply(folder / "aspects" / f"aspect-{number:02d}.workspace.ply")
        assert any(c.startswith(f"scale phi {scale[2]!r}") for c in comments)
        t = vertices[triangles]
        enclosed = np.einsum("ij,ij->i", t[:, 0], np.cross(t[:, 1], t[:, 2])).sum() / 6.0  # divergence theorem
        assert enclosed == pytest.approx(volume * np.prod(scale), rel=1e-8)
        edges = np.sort(np.concatenate([triangles[:, [0, 1]], triangles[:, [1, 2]], triangles[:, [2, 0]]]), axis=1)
        _, uses = np.unique(edges, axis=0, return_counts=True)
        assert np.all(uses % 2 == 0)  # closed: every edge between two (or four) triangles
        # oriented: each directed edge once, its reverse once as often
        directed = np.concatenate([triangles[:, [0, 1]], triangles[:, [1, 2]], triangles[:, [2, 0]]])
        keys = directed[:, 0] * len(vertices) + directed[:, 1]
        back = directed[:, 1] * len(vertices) + directed[:, 0]
        assert np.array_equal(np.sort(keys), np.sort(back))


def test_a_rerun_leaves_exactly_its_own_files_and_reads_back(caro_folder, tmp_path):
    folder, _ = caro_folder
    from fivebar_cli.analyses.pose_aspect_files import load_pose_aspects

    m = load(CARO)
    saved = load_pose_aspects(folder, m, 5)
    assert saved is not None and [a.number for a in saved] == [1, 2]
    assert load_pose_aspects(folder, m, 6) is None  # another depth: recomputed, not reused
    stale = tmp_path / "aspects"
    stale.mkdir()
    (stale / "aspect-07.workspace.qt").write_text("old")
    (stale / "aspect-07.workspace.ply").write_text("old")
    ok(run_cli("aspects", CARO, "--depth", "3", "-o", tmp_path, "--no-plot", "--quiet"))
    assert not (stale / "aspect-07.workspace.qt").exists() and not (stale / "aspect-07.workspace.ply").exists()


def test_locate_a_pose_and_every_pose_of_given_legs(caro_folder):
    folder, _ = caro_folder
    with open(folder / "aspects.csv", newline="") as fh:
        inside = [[r["x"], r["y"], r["phi_deg"]] for r in csv.DictReader(fh)]  # a pose in each aspect
    result = ok(run_cli("locate", CARO, "--pose", *inside[0], "--legs", "14.98", "15.38", "12", "--depth", "5",
                        "-o", folder, "--csv"))
    rows = list(csv.DictReader(result.stdout.splitlines()))
    assert list(rows[0]) == ["input", "location", "x", "y", "phi_deg", "rho1", "rho2", "rho3", "det_sign", "aspect",
                             "aspect_certified"]
    assert [r["input"] for r in rows] == ["1"] + ["2"] * 6
    assert rows[0]["det_sign"] == "+" and rows[0]["aspect"] == "1" and rows[0]["aspect_certified"] == "true"
    assert [r["det_sign"] for r in rows[1:]] == ["+"] * 3 + ["-"] * 3
    assert {r["aspect"] for r in rows[1:4]} <= {"1", ""} and {r["aspect"] for r in rows[4:]} <= {"2", ""}
    text = ok(run_cli("locate", CARO, "--pose", *inside[0], "--pose", *inside[1], "--depth", "5", "-o", folder)).stdout
    assert "read from" in text and "det_sign + -> aspect 1" in text and "det_sign - -> aspect 2" in text
    assert "1 -> 2: no aspect holds a pose of both" in text


def test_the_view_colours_the_aspects_of_an_octree(caro_folder):
    from fivebar_cli.analyses.view import gather

    folder, _ = caro_folder
    view = gather([folder])
    (section,) = view.sections
    assert section["kind"] == "aspects" and [p["space"] for p in section["panels"]] == ["workspace"]
    assert [view.trees[ly["tree"]].qt.tree.grid.dim for ly in section["panels"][0]["layers"]] == [3, 3]
    assert [row["det_sign"] for row in section["aspects"]] == ["+", "-"]


# ---------------------------------------------------------------- bad input


def test_bad_input_is_one_line_exit_2(tmp_path):
    wide = tmp_path / "wide.yaml"
    wide.write_text(CARO.read_text().replace("phi_range: [-180, 180]", "phi_range: [-180, 200]"))
    one_line(run_cli("aspects", wide, "-o", tmp_path), 2, "wide.yaml", "phi_range", "wider than a full turn")
    one = tmp_path / "one.yaml"
    one.write_text(CARO.read_text().replace("phi_range: [-180, 180]", "phi: 30"))
    one_line(run_cli("locate", one, "--pose", "0", "0", "30", "-o", tmp_path), 2, "one.yaml", "phi")
    one_line(run_cli("locate", GENERAL, "--pose", "0", "0", "90", "-o", tmp_path), 2, "--pose",
             "outside the orientation range")
    one_line(run_cli("locate", CARO, "--pose", "0", "0", "0", "-o", tmp_path), 2, "--pose", "not a valid pose")
    one_line(run_cli("locate", CARO, "--legs", "5", "15", "12", "-o", tmp_path), 2, "--legs", "outside its range")
    one_line(run_cli("locate", CARO, "--pose", "0", "0", "-o", tmp_path), 2, "--pose")
    # a file of a pose kind goes to the pose command by its type alone, which reports what else is wrong
    # (it went to the five-bar command, which refused --pose X Y PHI: "unexpected extra argument")
    typo = tmp_path / "typo.yaml"
    typo.write_text(CARO.read_text() + "rho_min: 1\n")
    one_line(run_cli("locate", typo, "--pose", "0", "0", "0", "-o", tmp_path), 2, "typo.yaml", "rho_min", "unknown key")


def test_help_of_a_dispatched_command_shows_both_forms():
    text = ok(run_cli("aspects", "--help")).stdout
    assert "Usage: fivebar aspects [OPTIONS] CONFIG" in text and "--tolerance" in text  # the five-bar's
    assert "For a kind whose aspects live in one space of poses" in text and "phi_deg" in text
    assert "--pose X Y PHI" in ok(run_cli("locate", "--help")).stdout
