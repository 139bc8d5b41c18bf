"""The command line (its entry point `main`, run in-process by cli_helpers.run_cli): jointspace,
workspace, refine, diff, kratio; determinism; and bad input (exit status, one line on stderr, no
half-written files)."""

from __future__ import annotations

import csv
import math
import os
import re
import shutil
from pathlib import Path

import numpy as np
import pytest
from cli_helpers import PNG_MAGIC, ok, one_line, run_cli

from conftest import (
    M1,
    M1_YAML,
    M2,
    M2_YAML,
    leaf_bounds,
    tree_to_bool,
    upsample,
    valid_joint,
    valid_work,
    workspace_area_closed_form,
)
import fivebar_cli as fb
from fivebar_cli.io.qtfile import read_qt

CSV_HEADER = ("space,name,procedure,depth,evaluations,K,inside_area,undetermined_area,outside_area,"
              "inside_cells,outside_cells,undetermined_cells,exact_area")


def files(folder: Path) -> dict[str, bytes]:
    return {p.name: p.read_bytes() for p in sorted(folder.iterdir()) if p.is_file()}


def no_temporary_files(*folders: Path) -> None:
    for folder in folders:
        if folder.exists():
            leftovers = [p.name for p in folder.rglob("*") if p.name.endswith(".tmp") or
                         (p.name.startswith(".") and p.name != ".fivebar")]  # .fivebar/: the runs' manifests
            assert leftovers == [], f"temporary files left in {folder}: {leftovers}"


def read_summary(path: Path) -> dict[str, str]:
    text = path.read_text()
    assert text.endswith("\n") and "\r" not in text
    lines = text.split("\n")[:-1]
    assert lines[0] == CSV_HEADER
    assert len(lines) == 2
    row = dict(zip(CSV_HEADER.split(","), lines[1].split(",")))
    for key in ("K", "inside_area", "undetermined_area", "outside_area"):  # one float format: %.10g
        assert row[key] == ("%.10g" % float(row[key]) if float(row[key]) != 0 else "0")
    return row


def check_summary(row: dict[str, str], space: str, name: str, depth: int, inside_qt, outside_qt) -> None:
    root_area = (2 * math.pi) ** 2 if space == "jointspace" else (2 * (inside_qt.tree.grid.root[0][1])) ** 2
    assert (row["space"], row["name"], row["procedure"], int(row["depth"])) == (space, name, "exact", depth)
    n = int(row["evaluations"])
    assert n % 4 == 1 and 1 < n <= sum(4**k for k in range(depth + 1))
    assert float(row["K"]) == pytest.approx(n / 4**depth, rel=1e-9)
    inside, und, outside = float(row["inside_area"]), float(row["undetermined_area"]), float(row["outside_area"])
    assert inside + und + outside == pytest.approx(root_area, rel=1e-9)
    cell = root_area / 4**depth
    assert inside == pytest.approx(tree_to_bool(inside_qt.tree).sum() * cell, rel=1e-9)
    assert outside == pytest.approx(tree_to_bool(outside_qt.tree).sum() * cell, rel=1e-9)
    assert und == pytest.approx(int(row["undetermined_cells"]) * cell, rel=1e-9)
    assert int(row["inside_cells"]) == len(inside_qt.tree)
    assert int(row["outside_cells"]) == len(outside_qt.tree)
    assert inside_qt.get("evaluations") == outside_qt.get("evaluations") == row["evaluations"]
    if space == "jointspace":
        assert row["exact_area"] == ""  # no closed form is known for the joint space
    else:  # the closed form of the workspace, independently: lens minus the holes (none for M2)
        exact = workspace_area_closed_form(M1 if name == "M1" else M2)
        assert float(row["exact_area"]) == pytest.approx(exact, rel=1e-9)
        assert inside <= float(row["exact_area"]) <= inside + und


# ---------------------------------------------------------------- jointspace / workspace


def test_jointspace_writes_the_pair_the_csv_and_figures_identically_from_any_folder(tmp_path):
    a, b = tmp_path / "a", tmp_path / "b"
    a.mkdir(), b.mkdir()
    ok(run_cli("jointspace", M1_YAML, "--depth", 6, "-o", "out", cwd=a))
    ok(run_cli("jointspace", M1_YAML, "--depth", 6, cwd=b))  # default folder outputs/M1/
    out_a, out_b = a / "out", b / "outputs" / "M1"
    fa = files(out_a)
    assert sorted(fa) == ["jointspace.complement.png", "jointspace.complement.qt", "jointspace.csv",
                          "jointspace.png", "jointspace.qt"]
    assert fa == files(out_b)  # byte-identical, figures included
    assert fa["jointspace.png"].startswith(PNG_MAGIC) and fa["jointspace.complement.png"].startswith(PNG_MAGIC)
    assert fa["jointspace.png"] != fa["jointspace.complement.png"]
    for data in fa.values():
        assert str(tmp_path).encode() not in data  # no absolute paths
    inside, outside = read_qt(out_a / "jointspace.qt"), read_qt(out_a / "jointspace.complement.qt")
    for qt, colour in ((inside, "inside"), (outside, "outside")):
        assert (qt.get("name"), qt.get("space"), qt.get("region"), qt.get("colour")) == (
            "M1", "jointspace", "assemblable", colour)
        assert qt.tree.grid.root == ((-math.pi, math.pi), (-math.pi, math.pi))
        assert qt.tree.grid.depth == 6 and qt.tree.grid.periodic == (True, True)
    text = fa["jointspace.qt"].decode()
    assert "# root: -3.141592653589793 3.141592653589793 -3.141592653589793 3.141592653589793\n" in text
    assert "# periodic: 0 1\n" in text
    check_summary(read_summary(out_a / "jointspace.csv"), "jointspace", "M1", 6, inside, outside)
    # the written cells are sound (points checked against the geometry)
    rng = np.random.default_rng(0)
    for qt, want in ((inside, True), (outside, False)):
        lo, hi = leaf_bounds(qt.tree)
        pts = (lo[None] + rng.random((5, len(lo), 2)) * (hi - lo)[None]).reshape(-1, 2)
        assert np.all(valid_joint(M1, pts[:, 0], pts[:, 1]) == want)
    no_temporary_files(out_a, out_b)


def test_workspace_no_plot_and_repeat_runs_are_byte_identical(tmp_path):
    a, b = tmp_path / "a", tmp_path / "b"
    a.mkdir(), b.mkdir()
    r = ok(run_cli("workspace", M2_YAML, "--depth", 7, "-o", "out", "--no-plot", cwd=a))
    assert "wrote" in r.stdout
    first = files(a / "out")
    assert sorted(first) == ["workspace.complement.qt", "workspace.csv", "workspace.qt"]
    quiet = ok(run_cli("workspace", M2_YAML, "--depth", 7, "-o", "out", "--no-plot", "--quiet", cwd=a))  # overwrite
    assert quiet.stdout == "" and quiet.stderr == ""
    ok(run_cli("workspace", M2_YAML, "--depth", 7, "-o", str(b / "deep" / "er"), "--no-plot", cwd=tmp_path))
    assert files(a / "out") == first == files(b / "deep" / "er")
    inside, outside = read_qt(a / "out" / "workspace.qt"), read_qt(a / "out" / "workspace.complement.qt")
    assert inside.tree.grid.root == ((-4.6, 4.6), (-4.6, 4.6)) and inside.tree.grid.periodic == (False, False)
    assert "# periodic: none\n" in first["workspace.qt"].decode()
    check_summary(read_summary(a / "out" / "workspace.csv"), "workspace", "M2", 7, inside, outside)
    rng = np.random.default_rng(1)
    for qt, want in ((inside, True), (outside, False)):
        lo, hi = leaf_bounds(qt.tree)
        pts = (lo[None] + rng.random((5, len(lo), 2)) * (hi - lo)[None]).reshape(-1, 2)
        assert np.all(valid_work(M2, pts[:, 0], pts[:, 1]) == want)
    no_temporary_files(a / "out", b / "deep")


# ---------------------------------------------------------------- refine


@pytest.mark.parametrize("config, space, d1, d2, procedure, via", [
    (M2_YAML, "workspace", 4, 7, "exact", "inside"),
    (M1_YAML, "jointspace", 3, 6, "exact", "complement"),
    (M1_YAML, "workspace", 5, 7, "paper", "inside"),
])
def test_refine_equals_a_fresh_run(tmp_path, config, space, d1, d2, procedure, via):
    ok(run_cli(space, config, "--depth", d1, "--procedure", procedure, "-o", "old", "--no-plot", cwd=tmp_path))
    ok(run_cli(space, config, "--depth", d2, "--procedure", procedure, "-o", "fresh", "--no-plot", cwd=tmp_path))
    name = f"{space}.qt" if via == "inside" else f"{space}.complement.qt"
    ok(run_cli("refine", Path("old") / name, "--depth", d2, "-o", "refined", "--no-plot", cwd=tmp_path))
    assert files(tmp_path / "refined") == files(tmp_path / "fresh")
    # to the same depth: nothing to test, the same files
    ok(run_cli("refine", Path("refined") / f"{space}.qt", "--depth", d2, "-o", "same", "--no-plot", cwd=tmp_path))
    assert files(tmp_path / "same") == files(tmp_path / "fresh")
    # in place (no -o): the old pair is replaced by the deeper one
    ok(run_cli("refine", Path("old") / f"{space}.qt", "--depth", d2, "--no-plot", cwd=tmp_path))
    assert files(tmp_path / "old") == files(tmp_path / "fresh")
    no_temporary_files(tmp_path / "old", tmp_path / "refined")


def test_refine_to_a_smaller_depth_is_a_usage_error(tmp_path):
    ok(run_cli("workspace", M2_YAML, "--depth", 5, "-o", "old", "--no-plot", cwd=tmp_path))
    before = files(tmp_path / "old")
    r = run_cli("refine", "old/workspace.qt", "--depth", 3, "--no-plot", cwd=tmp_path)
    one_line(r, 2, "old/workspace.qt", "--depth")
    assert files(tmp_path / "old") == before


# ---------------------------------------------------------------- diff


def printed_area(stdout: str, label: str) -> float:
    m = re.search(rf"^{re.escape(label)}: (\d+) cells, area (\S+)$", stdout, re.M)
    assert m, stdout
    return float(m.group(2))


def test_diff_exit_status_and_areas(tmp_path):
    ok(run_cli("workspace", M1_YAML, "--depth", 4, "-o", "d4", "--no-plot", cwd=tmp_path))
    ok(run_cli("workspace", M1_YAML, "--depth", 7, "-o", "d7", "--no-plot", cwd=tmp_path))
    ok(run_cli("workspace", M2_YAML, "--depth", 3, "-o", "m2", "--no-plot", cwd=tmp_path))
    shutil.copytree(tmp_path / "d7", tmp_path / "d7copy")
    r = run_cli("diff", "d7/workspace.qt", "d7copy/workspace.qt", cwd=tmp_path)
    assert r.status == 0 and "same set" in r.stdout and r.stderr == ""
    assert run_cli("diff", "d7/workspace.qt", "d7/workspace.qt", "--quiet", cwd=tmp_path).stdout == ""
    # a shallower paving is a subset of the deeper one: different sets, exit 1, areas printed
    r = run_cli("diff", "d4/workspace.qt", "d7/workspace.qt", cwd=tmp_path)
    assert r.status == 1 and "Traceback" not in r.stderr
    a, b = read_qt(tmp_path / "d4" / "workspace.qt").tree, read_qt(tmp_path / "d7" / "workspace.qt").tree
    ra, rb = upsample(tree_to_bool(a), 3), tree_to_bool(b)
    cell = 26.0**2 / 4**7
    assert printed_area(r.stdout, "only in A") == 0.0
    assert printed_area(r.stdout, "only in B") == pytest.approx((rb & ~ra).sum() * cell, rel=1e-9)
    assert (rb & ~ra).sum() > 0 and not (ra & ~rb).any()
    assert printed_area(r.stdout, "d4/workspace.qt") == pytest.approx(ra.sum() * cell, rel=1e-9)
    assert printed_area(r.stdout, "d7/workspace.qt") == pytest.approx(rb.sum() * cell, rel=1e-9)
    # the inside and the complement differ everywhere
    r = run_cli("diff", "d7/workspace.qt", "d7/workspace.complement.qt", cwd=tmp_path)
    assert r.status == 1
    assert printed_area(r.stdout, "only in A") == pytest.approx(rb.sum() * cell, rel=1e-9)
    # bad input: exit 2
    one_line(run_cli("diff", "d7/workspace.qt", "nope.qt", cwd=tmp_path), 2, "nope.qt")
    one_line(run_cli("diff", "d7/workspace.qt", "m2/workspace.qt", cwd=tmp_path), 2, "m2/workspace.qt", "root")
    bad = tmp_path / "bad.qt"
    lines = (tmp_path / "d7" / "workspace.qt").read_text().split("\n")
    lines[13] = lines[13][:10] + "Q" + lines[13][11:]
    bad.write_text("\n".join(lines))
    one_line(run_cli("diff", "d7/workspace.qt", "bad.qt", cwd=tmp_path), 2, "bad.qt", "line 14")


# ---------------------------------------------------------------- kratio


def test_kratio_csv(tmp_path):
    r = ok(run_cli("kratio", M1_YAML, M2_YAML, "--depths", "5-6", "-o", "k", "--no-plot", cwd=tmp_path))
    assert "saving" in r.stdout
    text = (tmp_path / "k" / "kratio.csv").read_text()
    assert text.endswith("\n")
    rows = list(csv.DictReader(text.splitlines()))
    assert list(rows[0]) == ["space", "mechanism", "depth", "discretization", "evaluations", "K",
                             "paper_procedure_evaluations", "paper_procedure_K", "paper_procedure_percent",
                             "paper_printed_percent", "saving_vs_paper"]
    printed = {("jointspace", "M1"): (99, 73), ("jointspace", "M2"): (111, 83),
               ("workspace", "M1"): (72, 45), ("workspace", "M2"): (65, 37)}
    assert [(r["space"], r["mechanism"], r["depth"]) for r in rows] == [
        (s, n, str(d)) for s in ("jointspace", "workspace") for n in ("M1", "M2") for d in (5, 6)]
    for r in rows:
        d = int(r["depth"])
        want = printed[r["space"], r["mechanism"]][d - 5]
        assert int(r["paper_printed_percent"]) == want == int(r["paper_procedure_percent"])
        assert int(r["discretization"]) == 4**d
        n, p = int(r["evaluations"]), int(r["paper_procedure_evaluations"])
        assert float(r["K"]) == pytest.approx(n / 4**d, rel=1e-9)
        assert float(r["saving_vs_paper"]) == pytest.approx(1 - n / p, rel=1e-9)
        if d == 6:
            assert n < p
    assert not (tmp_path / "k" / "kratio.png").exists()
    one_line(run_cli("kratio", M1_YAML, "--depths", "five", "--no-plot", cwd=tmp_path), 2, "'five'")


def test_kratio_bad_depths_names_the_option(tmp_path):
    r = run_cli("kratio", M1_YAML, "--depths", "5-99", "--no-plot", cwd=tmp_path)
    one_line(r, 2, "--depths")


# ---------------------------------------------------------------- bad input


BAD_CONFIGS = [
    # (label, file content or None for a missing file, field named in the message)
    ("missing file", None, ""),
    ("unknown key", "name: M1\ntype: fivebar\nlenghts: {L0: 9, L1: 8, L2: 5, L3: 5, L4: 8}\n", "lenghts"),
    ("unknown length", "name: M1\ntype: fivebar\nlengths: {L0: 9, L1: 8, L2: 5, L3: 5, L4: 8, L5: 1}\n", "lengths.L5"),
    ("missing key", "name: M1\ntype: fivebar\nlengths: {L0: 9, L1: 8, L2: 5, L4: 8}\n", "lengths.L3"),
    ("missing name", "type: fivebar\nlengths: {L0: 9, L1: 8, L2: 5, L3: 5, L4: 8}\n", "name"),
    ("missing lengths", "name: M1\ntype: fivebar\n", "lengths"),
    ("non-numeric", "name: M1\ntype: fivebar\nlengths: {L0: 9, L1: abc, L2: 5, L3: 5, L4: 8}\n", "lengths.L1"),
    ("quoted number", "name: M1\ntype: fivebar\nlengths: {L0: 9, L1: '8', L2: 5, L3: 5, L4: 8}\n", "lengths.L1"),
    ("boolean", "name: M1\ntype: fivebar\nlengths: {L0: 9, L1: 8, L2: true, L3: 5, L4: 8}\n", "lengths.L2"),
    ("negative", "name: M1\ntype: fivebar\nlengths: {L0: 9, L1: 8, L2: -5, L3: 5, L4: 8}\n", "lengths.L2"),
    ("zero", "name: M1\ntype: fivebar\nlengths: {L0: 0, L1: 8, L2: 5, L3: 5, L4: 8}\n", "lengths.L0"),
    ("nan", "name: M1\ntype: fivebar\nlengths: {L0: 9, L1: 8, L2: 5, L3: 5, L4: .nan}\n", "lengths.L4"),
    ("inf", "name: M1\ntype: fivebar\nlengths: {L0: 9, L1: 8, L2: 5, L3: .inf, L4: 8}\n", "lengths.L3"),
    ("lengths a list", "name: M1\ntype: fivebar\nlengths: [9, 8, 5, 5, 8]\n", "lengths"),
    ("empty", "", ""),
    ("only a comment", "# nothing here\n", ""),
    ("yaml list", "- name: M1\n- type: fivebar\n", ""),
    ("binary garbage", b"\x89PNG\r\n\x1a\n\x00\x00\xff\xfe\x00", ""),
    ("bad yaml", "name: M1\ntype: fivebar\nlengths: {L0: 9, L1: 8\n", "line"),
    # a 3-RPR has a workspace (issue 11), but not with unbounded legs (rho_max auto = inf here): told
    # why, on legs.rho_max (it was 'type: an rpr3 has no workspace to pave (its spaces: none)')
    ("no workspace", "name: R\ntype: rpr3\nbase: {t1: 1, t2: 0.5, t3: 1}\nk: 0.5\nlegs: {rho_min: 5}\nphi: 10\n",
     "legs.rho_max: 'auto' is unbounded here"),
]


@pytest.fixture(scope="module")
def good_output(tmp_path_factory) -> Path:
    folder = tmp_path_factory.mktemp("good")
    ok(run_cli("workspace", M1_YAML, "--depth", 4, "-o", "out", "--no-plot", cwd=folder))
    return folder / "out"


BAD_OPTIONS = [
    (["--depth=-1"], "--depth"),
    (["--depth", "-1"], "--depth"),
    (["--depth", "21"], "--depth"),
    (["--depth", "ten"], "--depth"),
    (["--procedure", "fast"], "--procedure"),
    (["--colour"], "--colour"),
]


@pytest.fixture(scope="module")
def bad_runs(tmp_path_factory, good_output) -> dict:
    """All bad-config and bad-option runs, each in its own folder."""
    jobs = {}
    for label, content, _ in BAD_CONFIGS:
        folder = tmp_path_factory.mktemp("bad")
        path = folder / "cfg.yaml"
        if content is not None:
            path.write_bytes(content if isinstance(content, bytes) else content.encode())
        out = folder / "out"
        shutil.copytree(good_output, out)
        jobs["config", label] = (("workspace", path, "--depth", 4, "-o", out, "--no-plot"), folder,
                                 {"path": path, "out": out, "before": files(out)})
    for i, (args, _) in enumerate(BAD_OPTIONS):
        folder = tmp_path_factory.mktemp("opt")
        jobs["option", i] = (("jointspace", M1_YAML, *args, "-o", "out", "--no-plot"), folder, {"folder": folder})
    return {key: (run_cli(*args, cwd=cwd), info) for key, (args, cwd, info) in jobs.items()}


@pytest.mark.parametrize("label, content, field", BAD_CONFIGS, ids=[c[0] for c in BAD_CONFIGS])
def test_bad_configs_exit_2_with_one_line(bad_runs, label, content, field):
    r, info = bad_runs["config", label]
    line = one_line(r, 2, str(info["path"]), field)
    assert line.startswith("fivebar")
    assert files(info["out"]) == info["before"]  # the existing good output is untouched
    no_temporary_files(info["out"])
    assert r.stdout == ""


@pytest.mark.parametrize("index", range(len(BAD_OPTIONS)), ids=[" ".join(a) for a, _ in BAD_OPTIONS])
def test_bad_options_exit_2(bad_runs, index):
    r, info = bad_runs["option", index]
    one_line(r, 2, BAD_OPTIONS[index][1])
    assert not (info["folder"] / "out").exists()


def test_output_folder_that_cannot_be_created(tmp_path):
    blocker = tmp_path / "a_file"
    blocker.write_text("not a folder\n")
    # -o naming an existing file is a usage error (status 2); a folder below a file cannot be created (1)
    for target, status in ((blocker, 2), (blocker / "sub", 1)):
        r = run_cli("workspace", M1_YAML, "--depth", 3, "-o", target, "--no-plot", cwd=tmp_path)
        one_line(r, status, str(target))
    assert blocker.read_text() == "not a folder\n"


def test_unwritable_output_folder_exits_1(tmp_path, good_output):
    out = tmp_path / "ro"
    shutil.copytree(good_output, out)
    before = files(out)
    os.chmod(out, 0o555)
    try:
        if os.access(out, os.W_OK):
            pytest.skip("running with privileges that ignore directory permissions (root)")
        r = run_cli("workspace", M1_YAML, "--depth", 5, "-o", out, "--no-plot", cwd=tmp_path)
        one_line(r, 1, str(out))
        assert files(out) == before
    finally:
        os.chmod(out, 0o755)


def test_a_failure_while_writing_leaves_no_temporary_file(tmp_path, good_output):
    """The CSV target is a folder: the run fails (status 1) after the .qt files; nothing is half-written."""
    out = tmp_path / "out"
    shutil.copytree(good_output, out)
    (out / "workspace.csv").unlink()
    (out / "workspace.csv").mkdir()
    r = run_cli("workspace", M1_YAML, "--depth", 5, "-o", out, "--no-plot", cwd=tmp_path)
    one_line(r, 1, "workspace.csv")
    no_temporary_files(out)
    for name in ("workspace.qt", "workspace.complement.qt"):  # whole files, old or new
        qt = read_qt(out / name)
        assert qt.tree.grid.depth in (4, 5)


def test_malformed_qt_files_for_refine_and_diff(tmp_path, good_output):
    out = tmp_path / "out"
    shutil.copytree(good_output, out)
    complement = out / "workspace.complement.qt"
    lines = complement.read_text().split("\n")
    lines[6] = "# depth: four"  # line 7
    complement.write_text("\n".join(lines))
    before = files(out)
    r = run_cli("refine", out / "workspace.qt", "--depth", 6, "--no-plot", cwd=tmp_path)
    one_line(r, 2, str(complement), "line 7")
    assert files(out) == before
    no_temporary_files(out)
    r = run_cli("diff", out / "workspace.qt", complement, cwd=tmp_path)
    one_line(r, 2, str(complement), "line 7")
    # a truncated inside file
    inside = out / "workspace.qt"
    text = inside.read_text()
    inside.write_text(text[:-5] + "\n")
    n_lines = len(text.split("\n")) - 1
    r = run_cli("diff", inside, inside, cwd=tmp_path)
    one_line(r, 2, str(inside), f"line {n_lines}")
    # binary garbage and a missing sibling
    garbage = tmp_path / "g.qt"
    garbage.write_bytes(b"\x00\xff\xfe garbage")
    one_line(run_cli("diff", garbage, garbage, cwd=tmp_path), 2, str(garbage))
    lonely = tmp_path / "lonely"
    lonely.mkdir()
    shutil.copy(good_output / "workspace.qt", lonely / "workspace.qt")
    r = run_cli("refine", lonely / "workspace.qt", "--depth", 6, "--no-plot", cwd=tmp_path)
    one_line(r, 2, str(lonely / "workspace.complement.qt"), "no such file: a paving is refined from its pair of files "
             "(workspace.qt and workspace.complement.qt, side by side)")
    # the tree of one aspect has no partner: it is no paving (it was told its .complement.qt was missing)
    ok(run_cli("aspects", M2_YAML, "--depth", 4, "-o", "asp", "--no-plot", cwd=tmp_path))
    tree = tmp_path / "asp" / "aspects" / "aspect-01.workspace.qt"
    before = files(tmp_path / "asp")
    one_line(run_cli("refine", tree, "--depth", 6, "--no-plot", cwd=tmp_path), 2,
             f"{tree}: region: 'aspect 1': the tree of one aspect, not a paving pair")
    with pytest.raises(fb.InputError, match="the tree of one aspect, not a paving pair"):
        fb.refine(tree, 6)
    assert files(tmp_path / "asp") == before


def test_refine_needs_the_mechanism_header(tmp_path, good_output):
    out = tmp_path / "out"
    shutil.copytree(good_output, out)
    for name in ("workspace.qt", "workspace.complement.qt"):
        p = out / name
        p.write_text("".join(ln for ln in p.read_text().splitlines(True) if not ln.startswith("# mechanism:")))
    r = run_cli("refine", out / "workspace.qt", "--depth", 6, "--no-plot", cwd=tmp_path)
    one_line(r, 2, str(out / "workspace.qt"), "mechanism")
    r = run_cli("refine", tmp_path / "x.txt", "--depth", 6, "--no-plot", cwd=tmp_path)
    one_line(r, 2, "x.txt")


def test_refine_a_paving_of_a_non_ascii_named_mechanism(tmp_path):
    cfg = tmp_path / "m.yaml"
    cfg.write_text("name: M\u00f6bius\ntype: fivebar\nlengths: {L0: 9, L1: 8, L2: 5, L3: 5, L4: 8}\n", encoding="utf-8")
    ok(run_cli("workspace", cfg, "--depth", 3, "-o", "out", "--no-plot", cwd=tmp_path))
    ok(run_cli("refine", "out/workspace.qt", "--depth", 5, "--no-plot", cwd=tmp_path))
