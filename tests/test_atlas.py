"""`fivebar atlas` in this process (`--workers 0`): the spec and its grid, the closed-form
assembly test, rows against the single-design commands, parts and resuming, figures, bad input
(docs/formats.md: "Atlas specs", "atlas.csv", "Atlas parts"). Dask runs: test_atlas_dask.py."""

from __future__ import annotations

import csv
import io
import json
import shutil

import numpy as np
import pytest
from cli_helpers import PNG_MAGIC, REPO, modules_imported, ok, one_line, run_cli
from conftest import unchecked_fivebar

from fivebar_cli.analyses.atlas.engine import batch_text, plan_atlas, run_plan
from fivebar_cli.analyses.atlas.metrics import METRICS, assemblable, columns
from fivebar_cli.analyses.atlas.parts import batch_span
from fivebar_cli.analyses.atlas.spec import AtlasSpec, default_batch, parse_spec, read_spec
from fivebar_cli.analyses.spaces import pave_space

HEADER = "L0,L1,L2,L3,L4,assemblable,aspects,certified,workspace_area,largest_aspect_area,circle_r"
ROBUST = ",robust_aspects,robust_certified,robust_workspace_area,robust_largest_aspect_area,robust_circle_r"  # with a tolerance
# the designs of ATLAS_SPEC (conftest.py, fixture spec_file) that cannot be assembled
UNASSEMBLABLE = {(1.75, 0.3), (1.75, 0.6), (3.0, 0.3), (3.0, 0.6), (3.0, 0.9), (3.0, 1.2)}


def table(text: str) -> list[dict]:
    return list(csv.DictReader(io.StringIO(text)))


@pytest.fixture(scope="module")
def atlas_run(spec_file, tmp_path_factory):
    """`fivebar atlas t.yaml --workers 0` with figures."""
    root = tmp_path_factory.mktemp("run")
    result = ok(run_cli("atlas", spec_file, "--workers", "0", "-o", "out", cwd=root))
    return root / "out", result


# ---------------------------------------------------------------- spec and grid


def test_grid_order_l0_slowest_l4_fastest():
    spec = parse_spec({"name": "g", "type": "fivebar-atlas",
                       "lengths": {"L0": [1, 2, 2], "L1": 0.5, "L2": [0.1, 0.3, 3], "L3": 1, "L4": [1, 1.5, 2]}}, "g")
    assert spec.shape == (2, 1, 3, 1, 2) and spec.size == 12 and spec.swept == ("L0", "L2", "L4")
    designs = [spec.design(i) for i in range(spec.size)]
    assert designs[:3] == [(1.0, 0.5, 0.1, 1.0, 1.0), (1.0, 0.5, 0.1, 1.0, 1.5), (1.0, 0.5, 0.2, 1.0, 1.0)]
    assert designs[-1] == (2.0, 0.5, 0.3, 1.0, 1.5)
    assert designs == sorted(designs)  # grid order is lexicographic order of (L0, ..., L4)
    assert spec.depth == 10 and spec.tolerance == 0.0


def test_swept_values_are_exact_in_the_csv_format():
    """0.4 + 0.2 k is not exact in binary; the grid holds the values the CSV prints."""
    spec = parse_spec({"name": "g", "type": "fivebar-atlas",
                       "lengths": {"L0": 1, "L1": [0.4, 1.6, 7], "L2": 1, "L3": [0.1, 0.2, 4], "L4": 1}}, "g")
    assert spec.grid[1] == (0.4, 0.6, 0.8, 1.0, 1.2, 1.4, 1.6)
    assert spec.grid[3] == (0.1, float("%.10g" % (0.1 + 0.1 / 3)), float("%.10g" % (0.1 + 0.2 / 3)), 0.2)


def test_batches_are_contiguous_ranges_covering_every_design_once():
    spec = AtlasSpec("b", ((1.0,), tuple(np.linspace(0.5, 2, 10)), (1.0,), tuple(np.linspace(0.5, 2, 7)), (1.0,)),
                     batch=8)
    spans = [batch_span(spec, i) for i in range(-(-spec.size // 8))]
    assert [d for s in spans for d in s] == list(range(70)) and all(len(s) == 8 for s in spans[:-1])
    assert len(spans[-1]) == 6
    assert (default_batch(10), default_batch(625), default_batch(10**4), default_batch(10**6)) == (1, 9, 100, 100)


# ---------------------------------------------------------------- closed-form assembly


def test_assemblable_is_exact_at_the_touching_limit():
    # |B1B2| >= L0 - L1 - L2 = 0.5 = L3 + L4 (dyadic: exact in floats): one configuration, assemblable
    assert assemblable(1.0, 0.25, 0.25, 0.25, 0.25)
    assert not assemblable(1.0, 0.25, 0.25, 0.25, 0.25 - 2.0**-40)
    # |L3 - L4| = L0 + L1 + L2: the couplers just reach
    assert assemblable(1.0, 0.5, 0.5, 4.0, 2.0) and not assemblable(1.0, 0.5, 0.5, 4.0 + 2.0**-40, 2.0)
    # |B1B2| >= |L1 - L2| - L0 (one long crank)
    assert not assemblable(0.5, 3.0, 1.0, 0.5, 0.5) and assemblable(0.5, 3.0, 1.0, 0.75, 0.75)


def test_assemblable_agrees_with_the_certified_joint_space_and_the_exact_workspace():
    """Random designs, kept away from the touching limit: assemblable exactly when the depth-7
    joint-space paving leaves some cell not certified outside, and when the closed-form workspace
    area is positive."""
    rng = np.random.default_rng(13)
    seen = {True: 0, False: 0}
    for _ in range(200):
        L = (float(rng.uniform(0.1, 6.0)), *(float(v) for v in rng.uniform(0.1, 2.0, 4)))
        near = max(0.0, L[0] - L[1] - L[2], abs(L[1] - L[2]) - L[0])
        gaps = [near - (L[3] + L[4]), abs(L[3] - L[4]) - (L[0] + L[1] + L[2])]
        if min(abs(g) for g in gaps) < 0.05 or min(seen.values()) >= 15 and seen[assemblable(*L)] >= 15:
            continue
        expected = assemblable(*L)
        seen[expected] += 1
        m = unchecked_fivebar("r", *L)  # designs that cannot be assembled too (a file would refuse them)
        paving = pave_space(m, "jointspace", 7)
        assert (paving.outside.area < 4 * np.pi**2 - 1e-12) == expected, L
        assert (m.exact_measure("workspace") > 0) == expected, L
    assert seen[True] >= 15 and seen[False] >= 15, seen


# ---------------------------------------------------------------- rows


def test_atlas_csv_rows_in_grid_order(atlas_run):
    out, result = atlas_run
    text = (out / "atlas.csv").read_text()
    assert text.split("\n")[0] == HEADER and text.endswith("\n") and "\r" not in text
    rows = table(text)
    assert [(float(r["L0"]), float(r["L3"])) for r in rows] == [(a, b) for a in (0.5, 1.75, 3.0)
                                                                 for b in (0.3, 0.6, 0.9, 1.2)]
    for r in rows:
        assert (r["L1"], r["L2"], r["L4"]) == ("0.4", "0.4", "0.3")
        dead = (float(r["L0"]), float(r["L3"])) in UNASSEMBLABLE
        assert r["assemblable"] == ("false" if dead else "true")
        if dead:  # documented values: no aspect, a certified (closed-form) zero, empty workspace
            assert (r["aspects"], r["certified"], r["workspace_area"], r["largest_aspect_area"], r["circle_r"]) == (
                "0", "true", "0", "0", "0")
        else:
            assert int(r["aspects"]) > 0 and float(r["largest_aspect_area"]) > 0
            assert float(r["workspace_area"]) > float(r["largest_aspect_area"])
            # the disc lies in one aspect: its area is at most the largest aspect's
            assert 0 < np.pi * float(r["circle_r"]) ** 2 <= float(r["largest_aspect_area"])
    assert "12 designs at depth 6, 12 batches of 1: 0 done before, 12 to compute" in result.stdout
    assert "6 can be assembled" in result.stdout


def test_rows_agree_with_fivebar_aspects_and_workspace(atlas_run, tmp_path):
    """Every assemblable row against `fivebar aspects` (count, certified, largest aspect) and `fivebar
    workspace` (exact_area) run on the same design at the same depth."""
    out, _ = atlas_run
    uncertified = 0
    for k, r in enumerate(table((out / "atlas.csv").read_text())):
        if r["assemblable"] == "false":
            continue
        config = tmp_path / f"d{k}.yaml"
        lengths = ", ".join(f"{n}: {r[n]}" for n in ("L0", "L1", "L2", "L3", "L4"))
        config.write_text(f"name: d{k}\ntype: fivebar\nlengths: {{{lengths}}}\n")
        res = ok(run_cli("aspects", config, "--depth", "6", "-o", tmp_path / f"a{k}", "--no-plot", cwd=tmp_path))
        aspects = table((tmp_path / f"a{k}" / "aspects.csv").read_text())
        certified = "(certified;" in res.stdout.splitlines()[0]
        assert r["aspects"] == str(len(aspects))
        assert r["certified"] == ("true" if certified else "false")
        assert not certified or all(a["certified"] == "true" for a in aspects)
        largest = max(aspects, key=lambda a: float(a["workspace_area"]))["workspace_area"]
        assert r["largest_aspect_area"] == largest
        assert float(r["circle_r"]) == max(float(a["circle_r"] or 0) for a in aspects)
        ok(run_cli("workspace", config, "--depth", "2", "-o", tmp_path / f"w{k}", "--no-plot", "-q", cwd=tmp_path))
        assert r["workspace_area"] == table((tmp_path / f"w{k}" / "workspace.csv").read_text())[0]["exact_area"]
        uncertified += r["certified"] == "false"
    assert uncertified >= 1  # an uncertified count is in the table, marked as such


def test_one_metric_is_one_entry():
    assert columns() == tuple(HEADER.split(","))
    assert [m.name for m in METRICS] == (HEADER + ROBUST).split(",")[5:]
    assert columns(0.01) == tuple((HEADER + ROBUST).split(","))


# ---------------------------------------------------------------- parts, resume, determinism


def test_parts_layout_and_atlas_csv_is_their_concatenation(atlas_run):
    out, _ = atlas_run
    parts = sorted((out / "atlas.parts").glob("part-*.csv"))
    assert [p.name for p in parts] == [f"part-{i:08d}.csv" for i in range(12)]
    body = "".join(p.read_text().split("\n", 1)[1] for p in parts)
    assert all(p.read_text().split("\n")[0] == HEADER for p in parts)
    assert (out / "atlas.csv").read_text() == HEADER + "\n" + body
    assert (out / "atlas.parts" / "manifest.json").exists()


def test_rerun_computes_only_missing_or_damaged_parts(atlas_run, spec_file, tmp_path):
    out, _ = atlas_run
    folder = tmp_path / "o"
    (folder / "atlas.parts").mkdir(parents=True)
    for name in ("manifest.json", "part-00000000.csv", "part-00000003.csv", "part-00000007.csv"):
        (folder / "atlas.parts" / name).write_bytes((out / "atlas.parts" / name).read_bytes())
    cut = (out / "atlas.parts" / "part-00000005.csv").read_bytes()[:-3]  # a damaged part is computed again
    (folder / "atlas.parts" / "part-00000005.csv").write_bytes(cut)
    stale = (out / "atlas.parts" / "part-00000002.csv").read_text().replace(",8,", ",99,")
    (folder / "atlas.parts" / "part-00000001.csv").write_text(stale)  # another design's row
    res = ok(run_cli("atlas", spec_file, "--workers", "0", "-o", folder, "--no-plot", cwd=tmp_path))
    assert "3 done before, 9 to compute" in res.stdout
    assert (folder / "atlas.csv").read_bytes() == (out / "atlas.csv").read_bytes()
    res = ok(run_cli("atlas", spec_file, "--workers", "0", "-o", folder, "--no-plot", cwd=tmp_path))
    assert "12 done before, 0 to compute" in res.stdout and "computed" not in res.stdout
    assert (folder / "atlas.csv").read_bytes() == (out / "atlas.csv").read_bytes()


def test_parts_edited_by_hand_fail_their_checksum_and_are_computed_again(atlas_run, spec_file, tmp_path):
    """A part edited into another whole-looking part (a count 'banana', an area 'NaN', the row of
    the right design) is never taken into atlas.csv: its checksum in the manifest fails, a warning
    names it, and it is computed again."""
    out, _ = atlas_run
    folder = tmp_path / "o"
    shutil.copytree(out / "atlas.parts", folder / "atlas.parts")
    manifest = json.loads((folder / "atlas.parts" / "manifest.json").read_text())
    assert sorted(manifest["parts"]) == [f"part-{i:08d}.csv" for i in range(12)]
    for index, bad in ((0, lambda row: row[:6] + ["banana"] + row[7:]), (4, lambda row: row[:8] + ["NaN"] + row[9:])):
        path = folder / "atlas.parts" / f"part-{index:08d}.csv"
        header, row = path.read_text().splitlines()
        path.write_text(header + "\n" + ",".join(bad(row.split(","))) + "\n")
    res = ok(run_cli("atlas", spec_file, "--workers", "0", "-o", folder, "--no-plot", cwd=tmp_path))
    assert "10 done before, 2 to compute" in res.stdout
    warning = [line for line in res.stderr.splitlines() if line.startswith("fivebar: warning:")]
    assert len(warning) == 1 and "part-00000000.csv, part-00000004.csv are not whole" in warning[0], res.stderr
    assert (folder / "atlas.csv").read_bytes() == (out / "atlas.csv").read_bytes()
    assert "banana" not in (folder / "atlas.csv").read_text() and "NaN" not in (folder / "atlas.csv").read_text()


def test_parts_of_another_atlas_are_refused_then_discarded_with_restart(atlas_run, spec_file, tmp_path):
    """Parts of batches of 1 in the folder, a spec with batches of 5: refused (one line, exit 2), then
    discarded with --restart; the batch size does not change the bytes of atlas.csv."""
    out, _ = atlas_run
    folder = tmp_path / "o"
    shutil.copytree(out / "atlas.parts", folder / "atlas.parts")
    (tmp_path / "s.yaml").write_text(spec_file.read_text().replace("batch: 1", "batch: 5"))
    r = run_cli("atlas", tmp_path / "s.yaml", "--workers", "0", "-o", folder, "--no-plot", cwd=tmp_path)
    one_line(r, 2, "atlas.parts: holds the parts of another atlas", "--restart")
    assert len(list((folder / "atlas.parts").iterdir())) == 13 and not (folder / "atlas.csv").exists()
    res = ok(run_cli("atlas", tmp_path / "s.yaml", "--workers", "0", "-o", folder, "--no-plot", "--restart",
                     cwd=tmp_path))
    assert "3 batches of 5: 0 done before, 3 to compute" in res.stdout
    assert sorted(p.name for p in (folder / "atlas.parts").iterdir()) == [
        "manifest.json", "part-00000000.csv", "part-00000001.csv", "part-00000002.csv"]
    assert (folder / "atlas.csv").read_bytes() == (out / "atlas.csv").read_bytes()


def test_library_run_matches_the_cli(atlas_run, spec_file, tmp_path):
    """The engine (plan, compute, assemble) and the API (`fb.atlas_plan`, `run`, `save`) give the
    command's bytes, figure and manifest included, and the lines it prints; planned again, the
    finished folder has nothing left, and its run computes nothing and reads the same atlas."""
    import fivebar_cli as fb
    from fivebar_cli.cli.options import as_flags

    out, result = atlas_run
    spec = read_spec(spec_file)
    plan = plan_atlas(spec, tmp_path / "engine")
    done = []
    path = run_plan(plan, advance=done.append)
    assert path.read_bytes() == (out / "atlas.csv").read_bytes() and sum(done) == 12
    assert batch_text(spec, 4) == (out / "atlas.parts" / "part-00000004.csv").read_text()

    plan = fb.atlas_plan(spec_file, tmp_path / "api")
    assert (plan.batches, plan.batches_done, plan.designs_todo) == (12, 0, 12)
    assert plan.summary == result.stdout.splitlines()[0] and repr(plan) == f"<AtlasPlan {plan.summary}>"
    steps = []
    atlas = plan.run(advance=steps.append)
    assert sum(steps) == 12 and len(atlas) == 12 and atlas.columns == tuple(HEADER.split(","))
    assert sorted(p.name for p in atlas.save(tmp_path / "api", figures=True)) == ["atlas.csv", "atlas.png"]
    for name in ("atlas.csv", "atlas.png", ".fivebar/atlas.json"):
        assert (tmp_path / "api" / name).read_bytes() == (out / name).read_bytes(), name
    assert [as_flags(line) for line in atlas.notes] == [line for line in result.stdout.splitlines()
                                                        if line.startswith("  ") and "can be assembled" in line]
    assert any("`depth`" in line for line in atlas.notes)  # the library names its parameter

    again = fb.atlas_plan(spec_file, tmp_path / "api")
    assert (again.batches_done, again.designs_todo) == (12, 0) and again.summary.endswith("12 done before, 0 to compute")
    steps = []
    assert again.run(advance=steps.append) == atlas and steps == []


def test_what_a_run_logs_is_printed_under_the_commands_first_line_and_the_logger_left_as_it_was(capsys):
    """The cluster an atlas runs on is told through `logging` (test_atlas_dask.py sees the line of a
    real cluster): the command prints it indented, not with --quiet, and leaves the logger as it
    found it (no handler, no level: a later call, in this process, is silent again)."""
    import logging

    from fivebar_cli.cli.options import narrated

    logger, told = logging.getLogger("fivebar_cli"), logging.getLogger("fivebar_cli.api.atlas")
    before = (logger.level, logger.propagate, list(logger.handlers))
    with narrated(False):
        told.info("on %s (%s)", "a local cluster of 2 worker processes", "2 workers connected")
    with narrated(True):
        told.info("not with --quiet")
    told.info("nor after the command")
    assert capsys.readouterr() == ("  on a local cluster of 2 worker processes (2 workers connected)\n", "")
    assert (logger.level, logger.propagate, list(logger.handlers)) == before


# ---------------------------------------------------------------- figures


def test_heat_map_figure(atlas_run):
    out, result = atlas_run
    assert (out / "atlas.png").read_bytes().startswith(PNG_MAGIC)
    assert "wrote out/atlas.png" in result.stdout


@pytest.mark.parametrize("lengths, figure", [
    ("{L0: [0.5, 3.0, 3], L1: 0.4, L2: 0.4, L3: 0.9, L4: 0.3}", True),  # one swept: line plots
    ("{L0: [0.5, 3.0, 2], L1: 0.4, L2: 0.4, L3: [0.6, 1.2, 2], L4: [0.2, 0.3, 2]}", True),  # three: facets
    ("{L0: 3, L1: 0.4, L2: 0.4, L3: 0.9, L4: 0.3}", False),  # one design: no figure
])
def test_figures_for_one_or_three_swept_lengths(tmp_path, lengths, figure):
    """The figure's layout follows the swept lengths, not the depth: depth 2 draws the same panels."""
    (tmp_path / "s.yaml").write_text(f"name: s\ntype: fivebar-atlas\nlengths: {lengths}\ndepth: 2\n")
    res = ok(run_cli("atlas", tmp_path / "s.yaml", "--workers", "0", "-o", "o", cwd=tmp_path))
    assert (tmp_path / "o" / "atlas.png").exists() == figure
    assert ("no figure" in res.stdout) != figure


# ---------------------------------------------------------------- bad input


@pytest.mark.parametrize("body, field, needle", [
    ("type: fivebar\nlengths: {L0: 1, L1: 1, L2: 1, L3: 1, L4: 1}", "type", "fivebar-atlas"),
    ("type: fivebar-atlas\nlengths: {L0: 1, L1: 1, L2: 1, L3: 1}", "lengths.L4", "missing"),
    ("type: fivebar-atlas\nlenghts: {L0: 1, L1: 1, L2: 1, L3: 1, L4: 1}", "lenghts", "unknown key"),
    ("type: fivebar-atlas\nlengths: {L0: 1, L1: [0.4, 1.6], L2: 1, L3: 1, L4: 1}", "lengths.L1", "give 'tolerance: T'"),
    ("type: fivebar-atlas\nlengths: {L0: 1, L1: [0.4, 1.6, 2, 3], L2: 1, L3: 1, L4: 1}", "lengths.L1", "[from, to, steps]"),
    ("type: fivebar-atlas\nlengths: {L0: 1, L1: [0.4, 1.6, 2.5], L2: 1, L3: 1, L4: 1}", "lengths.L1[2]", "integer"),
    ("type: fivebar-atlas\nlengths: {L0: 1, L1: [0.4, 1.6, 1], L2: 1, L3: 1, L4: 1}", "lengths.L1[2]", "between 2"),
    ("type: fivebar-atlas\nlengths: {L0: 1, L1: [1.6, 0.4, 5], L2: 1, L3: 1, L4: 1}", "lengths.L1", "less than"),
    ("type: fivebar-atlas\nlengths: {L0: 1, L1: [-1, 0.4, 5], L2: 1, L3: 1, L4: 1}", "lengths.L1[0]", "positive"),
    ("type: fivebar-atlas\nlengths: {L0: 0, L1: 1, L2: 1, L3: 1, L4: 1}", "lengths.L0", "positive"),
    ("type: fivebar-atlas\nlengths: {L0: 1, L1: [0.4, 1.6, 3], L2: 1, L3: 1, L4: 1}\ntolerance: 0.4", "tolerance",
     "would make the shortest length (0.4) reach 0.0"),
    ("type: fivebar-atlas\nlengths: {L0: 1, L1: 1, L2: 1, L3: 1, L4: 1}\ntolerance: -0.1", "tolerance", "must not be negative"),
    ("type: fivebar-atlas\nlengths: {L0: 1, L1: 1, L2: 1, L3: 1, L4: 1}\ndepth: 17", "depth", "between 0 and 16"),
    ("type: fivebar-atlas\nlengths: {L0: 1, L1: 1, L2: 1, L3: 1, L4: 1}\nbatch: 0", "batch", "between 1"),
    ("type: fivebar-atlas\nlengths: {L0: [1, 2, 10000], L1: [1, 2, 10000], L2: 1, L3: 1, L4: 1}", "lengths",
     "at most 10000000"),
])
def test_bad_spec_is_one_line_naming_file_and_field(tmp_path, body, field, needle):
    (tmp_path / "bad.yaml").write_text(f"name: bad\n{body}\n")
    r = run_cli("atlas", tmp_path / "bad.yaml", "--workers", "0", "-o", "o", cwd=tmp_path)
    one_line(r, 2, f"bad.yaml: {field}: ", needle)
    assert not (tmp_path / "o").exists()


def test_tolerance_zero_is_accepted(tmp_path):
    (tmp_path / "s.yaml").write_text("name: s\ntype: fivebar-atlas\nlengths: {L0: 9, L1: 8, L2: 5, L3: 5, L4: 8}\n"
                                     "tolerance: 0.0\ndepth: 2\n")
    ok(run_cli("atlas", tmp_path / "s.yaml", "--workers", "0", "-o", "o", "-q", cwd=tmp_path))
    assert (tmp_path / "o" / "atlas.csv").read_text().split("\n")[0] == HEADER


def test_tolerance_rows_agree_with_fivebar_aspects_and_workspace_with_tolerance(tmp_path):
    """--tolerance T: the robust columns of each row equal `fivebar aspects --tolerance T` (count,
    certified, largest aspect) and `fivebar workspace --tolerance T` (inside_area) on that design."""
    (tmp_path / "r.yaml").write_text("name: r\ntype: fivebar-atlas\n"
                                     "lengths: {L0: [0.5, 2.0, 3], L1: 0.4, L2: 0.4, L3: 0.6, L4: 0.3}\ndepth: 5\n")
    res = ok(run_cli("atlas", tmp_path / "r.yaml", "--workers", "0", "--tolerance", "0.01", "-o", "o", cwd=tmp_path))
    text = (tmp_path / "o" / "atlas.csv").read_text()
    assert text.split("\n")[0] == HEADER + ROBUST
    assert "tolerance 0.01" in res.stdout.splitlines()[0]
    rows = table(text)
    assert [r["assemblable"] for r in rows] == ["true", "true", "false"]
    assert (rows[2]["robust_aspects"], rows[2]["robust_certified"], rows[2]["robust_workspace_area"]) == ("0", "true", "0")
    assert [r["robust_certified"] for r in rows[:2]] == ["true", "false"]  # an uncertified count is marked
    assert (tmp_path / "o" / "atlas.png").read_bytes()[:8] == PNG_MAGIC  # with the robust panels
    for k, r in enumerate(rows):
        if r["assemblable"] == "false":
            continue
        config = tmp_path / f"d{k}.yaml"
        config.write_text(f"name: d{k}\ntype: fivebar\nlengths: {{{', '.join(f'{n}: {r[n]}' for n in 'L0 L1 L2 L3 L4'.split())}}}\n")
        a = ok(run_cli("aspects", config, "--depth", "5", "--tolerance", "0.01", "-o", f"a{k}", "--no-plot", cwd=tmp_path))
        aspects = table((tmp_path / f"a{k}" / "aspects.csv").read_text())
        assert r["robust_aspects"] == str(len(aspects))
        assert r["robust_certified"] == ("true" if "(certified;" in a.stdout.splitlines()[0] else "false")
        largest = max((float(x["workspace_area"]) for x in aspects), default=0.0)
        assert float(r["robust_largest_aspect_area"]) == largest
        assert float(r["robust_circle_r"]) == max((float(x["circle_r"] or 0) for x in aspects), default=0.0)
        assert float(r["robust_circle_r"]) <= float(r["circle_r"])  # within tolerance: never a larger disc
        ok(run_cli("workspace", config, "--depth", "5", "--tolerance", "0.01", "-o", f"w{k}", "--no-plot", "-q", cwd=tmp_path))
        inside = table((tmp_path / f"w{k}" / "workspace.csv").read_text())[0]["inside_area"]
        assert r["robust_workspace_area"] == inside
        # the robust workspace lies in the nominal one: less area than its exact area
        assert 0 < float(inside) < float(r["workspace_area"])


def test_tolerance_in_the_spec_and_too_large_on_the_command_line(spec_file, tmp_path):
    spec = parse_spec({"name": "s", "type": "fivebar-atlas", "tolerance": 0.05,
                       "lengths": {"L0": 1, "L1": 1, "L2": 1, "L3": 1, "L4": [0.5, 1, 2]}}, "s")
    assert spec.tolerance == 0.05 and columns(spec.tolerance) == tuple((HEADER + ROBUST).split(","))
    r = run_cli("atlas", spec_file, "--workers", "0", "--tolerance", "0.3", "-o", "o", cwd=tmp_path)
    one_line(r, 2, "t.yaml: --tolerance: ", "would make the shortest length (0.3) reach 0.0")
    assert not (tmp_path / "o").exists()


def test_the_readme_spec_reads_and_other_commands_refuse_it(tmp_path):
    spec = read_spec(REPO / "configs" / "atlas-l1-l3.yaml")
    assert (spec.size, spec.shape, spec.depth, spec.swept) == (625, (1, 25, 1, 25, 1), 9, ("L1", "L3"))
    assert spec.grid[1][:3] == (0.4, 0.45, 0.5) and spec.grid[1][-1] == 1.6
    r = run_cli("aspects", REPO / "configs" / "atlas-l1-l3.yaml", "-o", "o", cwd=tmp_path)
    one_line(r, 2, "atlas-l1-l3.yaml: type: ", "fivebar-atlas")


def test_workers_and_scheduler_together_is_a_usage_error(spec_file, tmp_path):
    r = run_cli("atlas", spec_file, "--workers", "2", "--scheduler", "tcp://127.0.0.1:1", cwd=tmp_path)
    one_line(r, 2, "fivebar atlas: error:", "--workers or --scheduler")


def test_missing_spec_file(tmp_path):
    one_line(run_cli("atlas", tmp_path / "nope.yaml", "--workers", "0", cwd=tmp_path), 2, "nope.yaml", "no such file")


def test_help_and_in_process_runs_do_not_import_dask(spec_file, tmp_path):
    runs = [["--help"], ["atlas", "--help"], ["atlas", spec_file, "--workers", "0", "--depth", "2", "-o", "o", "-q",
                                              "--no-plot"]]
    assert modules_imported(runs, ("dask", "distributed"), tmp_path) == []


def test_a_designs_error_keeps_the_parameters_it_names(spec_file, monkeypatch):
    """A design's error crosses processes as a FivebarError naming the design; a parameter its
    message names stays data (`errors.Text`), so the command line spells it as an option."""
    import pickle

    from fivebar_cli.analyses.atlas import engine
    from fivebar_cli.cli.options import as_flags
    from fivebar_cli.errors import FivebarError, InputError, Text, param

    def failing(lengths, *args):
        raise InputError("L1", "depth", "try " + param("depth", 12))

    monkeypatch.setattr(engine, "row", failing)
    spec = read_spec(spec_file)
    with pytest.raises(FivebarError) as info:
        batch_text(spec, 0)
    said = pickle.loads(pickle.dumps(info.value)).args[0]  # as a worker process sends it
    first = " ".join(f"L{k}={v!r}" for k, v in enumerate(spec.design(batch_span(spec, 0)[0])))
    assert isinstance(said, Text) and said.startswith(f"design {batch_span(spec, 0)[0]} ({first}): InputError: ")
    assert said.endswith("L1: depth: try `depth=12`") and as_flags(said).endswith("L1: depth: try --depth 12")
