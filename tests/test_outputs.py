"""Outputs (issue 20): output sets (one run's files, io/outputs.py) and the readers that refuse a
mix of two runs; targets that are not regular files; `-o -`; CSV quoting; `diff` of trees that
hold the same cells but claim different things.

Every case of the issue is run: an `aspects` run at a new depth interrupted over an older one, a
nominal `workspace` rerun over a tolerance run's band, `refine` of one 3-RPR region, a failed run.
Interruptions are raised in-process at a chosen file (KeyboardInterrupt from inside a writer, as a
Ctrl-C there would); tests/test_interrupts.py sends real signals at random moments.
"""

from __future__ import annotations

import csv
import io
import json
import os
import shutil
import signal
from pathlib import Path

import pytest
from cli_helpers import csv_rows, ok, one_line, PNG_MAGIC, run_cli, snapshot
from conftest import CONFIGS, M1_YAML, M2_YAML

from fivebar_cli.cli import cli  # noqa: F401 - the commands imported now, before any test patches what they import
from fivebar_cli.analyses.aspect_files import load_aspects
from fivebar_cli.analyses.view import gather
from fivebar_cli.errors import Interrupted
from fivebar_cli.io import files as files_module
from fivebar_cli.io.files import csv_text, write_text
from fivebar_cli.io.outputs import MANIFESTS, output_set, read_runs
from fivebar_cli.io.qtfile import read_qt
from fivebar_cli.mechanisms.registry import load_config

RPR3_GENERAL = CONFIGS / "rpr3-general.yaml"


def interrupt_at(monkeypatch, name_part: str, nth: int = 1) -> None:
    """Make the nth atomic write of a file whose name holds `name_part` raise Interrupted, as the
    CLI's handler does for a Ctrl-C arriving while that file is written."""
    real = files_module.atomic_write
    seen = [0]

    def atomic_write(path, write):
        if name_part in Path(path).name:
            seen[0] += 1
            if seen[0] == nth:
                raise Interrupted("interrupted (no output was left half-written)", signal.SIGINT)
        return real(path, write)

    monkeypatch.setattr(files_module, "atomic_write", atomic_write)
    monkeypatch.setattr(files_module, "write_text", lambda path, text: _write_text(atomic_write, path, text))


def _write_text(atomic_write, path, text):
    data = text.encode("utf-8")

    def write(tmp):
        Path(tmp).write_bytes(data)

    return atomic_write(path, write)


# ---------------------------------------------------------------- the mechanism


def test_a_set_records_its_files_and_removes_those_of_its_earlier_run(tmp_path):
    with output_set(tmp_path, "demo", ("demo-*.txt",)):
        write_text(tmp_path / "demo-a.txt", "a\n")
        write_text(tmp_path / "demo-b.txt", "b\n")
    write_text(tmp_path / "other.txt", "not the set's\n")
    with output_set(tmp_path, "demo", ("demo-*.txt",)):
        write_text(tmp_path / "demo-a.txt", "a2\n")
    assert sorted(p.name for p in tmp_path.iterdir()) == [MANIFESTS, "demo-a.txt", "other.txt"]
    manifest = json.loads((tmp_path / MANIFESTS / "demo.json").read_text())
    assert manifest["state"] == "complete" and list(manifest["files"]) == ["demo-a.txt"]
    import hashlib
    assert manifest["files"]["demo-a.txt"] == hashlib.sha256(b"a2\n").hexdigest()
    runs = read_runs(tmp_path)
    assert runs.accepts(tmp_path / "demo-a.txt") and runs.accepts(tmp_path / "other.txt")  # other: claimed by none
    (tmp_path / "demo-a.txt").write_text("edited by hand\n")
    runs = read_runs(tmp_path)
    assert not runs.accepts(tmp_path / "demo-a.txt") and "no longer whole" in runs.why(tmp_path / "demo-a.txt")
    write_text(tmp_path / "demo-z.txt", "z\n")  # a file of the set's kind that no run of it wrote
    (tmp_path / "demo-a.txt").write_text("a2\n")
    assert "did not write" in read_runs(tmp_path).why(tmp_path / "demo-z.txt")


def test_an_interrupted_set_is_refused_and_a_failure_before_writing_leaves_nothing(tmp_path):
    with pytest.raises(KeyboardInterrupt):
        with output_set(tmp_path / "a", "demo", ("demo-*.txt",)):
            write_text(tmp_path / "a" / "demo-1.txt", "1\n")
            raise KeyboardInterrupt
    runs = read_runs(tmp_path / "a")
    assert "did not complete" in runs.why(tmp_path / "a" / "demo-1.txt")
    with pytest.raises(RuntimeError):
        with output_set(tmp_path / "b" / "c", "demo", ("demo-*.txt",)):
            raise RuntimeError("failed before any file")
    assert not (tmp_path / "b").exists()


def test_a_failed_command_leaves_no_folder(tmp_path, monkeypatch):
    from fivebar_cli.analyses import spaces

    def fail(*args, **kwargs):
        raise MemoryError

    monkeypatch.setattr(spaces, "pave_space", fail)
    r = run_cli("workspace", M1_YAML, "--depth", 4, "-o", "new/m1", cwd=tmp_path)
    one_line(r, 1, "out of memory")
    assert list(tmp_path.iterdir()) == []


# ---------------------------------------------------------------- the cases


def test_aspects_interrupted_at_a_new_depth_is_never_read_as_one_run(tmp_path, monkeypatch):
    """Depth 6 written, then depth 8 interrupted while it writes its 5th tree: `view` shows none of
    the aspect trees (a warning names why), `load_aspects` reads neither depth, and a rerun writes
    one whole run again."""
    ok(run_cli("aspects", M1_YAML, "--depth", 6, "-o", "m1", "--no-plot", cwd=tmp_path))
    folder = tmp_path / "m1"
    m = load_config(M1_YAML)
    assert load_aspects(folder, m, 6) is not None
    with monkeypatch.context() as mp:
        interrupt_at(mp, "aspect-", 5)
        r = run_cli("aspects", M1_YAML, "--depth", 8, "-o", "m1", "--no-plot", cwd=tmp_path)
    one_line(r, 130, "interrupted")
    depths = {read_qt(p).tree.grid.depth for p in (folder / "aspects").glob("*.qt")}
    assert depths == {6, 8}  # the folder mixes two runs ...
    with pytest.warns(UserWarning, match="did not complete"):
        assert load_aspects(folder, m, 6) is None and load_aspects(folder, m, 8) is None
    ok(run_cli("workspace", M1_YAML, "--depth", 5, "-o", "m1", "--no-plot", cwd=tmp_path))
    view = gather([folder])  # ... which the view never shows as one
    assert [s["kind"] for s in view.sections] == ["paving"]
    assert any("aspect-01.workspace.qt" in line and "did not complete" in line for line in view.ignored)
    r = ok(run_cli("view", "m1", "-o", "page.html", cwd=tmp_path))
    warning = [line for line in r.stderr.splitlines() if line.startswith("fivebar: warning:")]
    assert len(warning) == 1 and "more files: not shown (the last run of `fivebar aspects` did not complete" in \
        warning[0], r.stderr  # one line for every file of that run
    ok(run_cli("aspects", M1_YAML, "--depth", 8, "-o", "m1", "--no-plot", cwd=tmp_path))
    assert {read_qt(p).tree.grid.depth for p in (folder / "aspects").glob("*.qt")} == {8}
    assert load_aspects(folder, m, 8) is not None and not gather([folder]).ignored


def test_a_nominal_workspace_rerun_removes_the_band_of_a_tolerance_run(tmp_path):
    ok(run_cli("workspace", M1_YAML, "--depth", 5, "--tolerance", 0.05, "-o", "m1", "--geojson", cwd=tmp_path))
    assert (tmp_path / "m1" / "workspace.band.qt").exists()
    ok(run_cli("workspace", M1_YAML, "--depth", 6, "-o", "m1", "--no-plot", cwd=tmp_path))
    names = sorted(p.name for p in (tmp_path / "m1").iterdir() if p.is_file())
    assert names == ["workspace.complement.qt", "workspace.csv", "workspace.qt"]  # band, GeoJSON, figures: gone
    view = gather([tmp_path / "m1"])
    assert {t.qt.tree.grid.depth for t in view.trees} == {6} and not view.ignored


def test_refine_of_one_rpr3_region_refines_its_whole_run(tmp_path):
    ok(run_cli("rpr3", "pave", RPR3_GENERAL, "--depth", 3, "-o", "g", "--no-plot", cwd=tmp_path))
    ok(run_cli("refine", "g/singularity-free.plus.qt", "--depth", 4, "--no-plot", cwd=tmp_path))
    volumes = csv_rows(tmp_path / "g" / "volumes.csv")[0]
    assert volumes["depth"] == "4"
    assert {read_qt(p).tree.grid.depth for p in (tmp_path / "g").glob("*.qt")} == {4}
    ok(run_cli("rpr3", "pave", RPR3_GENERAL, "--depth", 4, "-o", "fresh", "--no-plot", cwd=tmp_path))
    assert snapshot(tmp_path / "g") == snapshot(tmp_path / "fresh")


def test_refine_refuses_a_pair_of_two_runs(tmp_path):
    ok(run_cli("workspace", M2_YAML, "--depth", 4, "-o", "a", "--no-plot", cwd=tmp_path))
    ok(run_cli("workspace", M2_YAML, "--depth", 4, "-o", "b", "--no-plot", cwd=tmp_path))
    shutil.copy(tmp_path / "b" / "workspace.csv", tmp_path / "a" / "workspace.csv")  # same bytes: still one run
    ok(run_cli("refine", "a/workspace.qt", "--depth", 5, "-o", "r1", "--no-plot", cwd=tmp_path))
    # a complement written by hand next to the tree (same header, same cells: a pair refine accepts
    # by its contents), in a folder whose manifest says the run of workspace was replaced
    text = (tmp_path / "a" / "workspace.complement.qt").read_text()
    (tmp_path / "a" / "workspace.complement.qt").write_text(text.replace("# name: M2", "# name: M2 "))
    r = run_cli("refine", "a/workspace.qt", "--depth", 5, "-o", "r2", "--no-plot", cwd=tmp_path)
    one_line(r, 2, "a/workspace.qt", "not of one complete run", "no longer whole")
    assert not (tmp_path / "r2").exists()


# ---------------------------------------------------------------- targets that are not regular files


def test_a_fifo_a_symlink_or_a_device_is_never_replaced(tmp_path):
    ok(run_cli("workspace", M1_YAML, "--depth", 4, "-o", "m1", "--no-plot", cwd=tmp_path))
    out = tmp_path / "m1"
    os.mkfifo(out / "fifo.html")
    (tmp_path / "target.html").write_text("the link's target\n")
    (out / "link.html").symlink_to(tmp_path / "target.html")
    for page, what in (("fifo.html", "is a FIFO (named pipe), not a regular file: not replaced"),
                       ("link.html", "is a symbolic link: not replaced"),
                       ("/dev/null", "is a character device, not a regular file: not replaced")):
        r = run_cli("view", "m1", "-o", page if page.startswith("/") else f"m1/{page}", cwd=tmp_path)
        one_line(r, 1, what)
    assert (out / "fifo.html").is_fifo() and (out / "link.html").is_symlink()
    assert (tmp_path / "target.html").read_text() == "the link's target\n"
    # an output of a command: the run fails where it meets the FIFO, the earlier files stay whole
    (out / "workspace.csv").unlink()
    os.mkfifo(out / "workspace.csv")
    r = run_cli("workspace", M1_YAML, "--depth", 4, "-o", "m1", "--no-plot", cwd=tmp_path)
    one_line(r, 1, "workspace.csv: is a FIFO")
    assert (out / "workspace.csv").is_fifo()
    # a folder that is a link is the user's layout: followed
    (tmp_path / "real").mkdir()
    (tmp_path / "linked").symlink_to(tmp_path / "real")
    ok(run_cli("workspace", M1_YAML, "--depth", 3, "-o", "linked", "--no-plot", cwd=tmp_path))
    assert (tmp_path / "real" / "workspace.qt").is_file()


# ---------------------------------------------------------------- -o -


@pytest.mark.parametrize("args, name", [
    (["kratio", M1_YAML, "--depths", "3,4"], "kratio.csv"),
    (["tolerance", M2_YAML, "--tolerances", "0,0.01", "--depth", 4], "tolerance.csv"),
    (["rpr3", "area", CONFIGS / "rpr3-equilateral.yaml"], "area.csv"),
    (["rpr3", "sweep", CONFIGS / "rpr3-equilateral.yaml", "--over", "rho_min", "--steps", 5], "area-vs-rho-min.csv"),
])
def test_dash_writes_the_single_file_to_standard_output(tmp_path, args, name):
    ok(run_cli(*args, "-o", "folder", "--no-plot", "-q", cwd=tmp_path))
    r = ok(run_cli(*args, "-o", "-", cwd=tmp_path))
    assert r.stdout == (tmp_path / "folder" / name).read_text()
    assert sorted(p.name for p in tmp_path.iterdir()) == ["folder"]  # nothing else written, no figure


def test_dash_writes_the_view_page_and_is_refused_where_there_are_several_files(tmp_path):
    ok(run_cli("workspace", M1_YAML, "--depth", 4, "-o", "m1", "--no-plot", cwd=tmp_path))
    ok(run_cli("view", "m1", "-o", "page.html", "-q", cwd=tmp_path))
    r = ok(run_cli("view", "m1", "-o", "-", cwd=tmp_path))
    assert r.stdout == (tmp_path / "page.html").read_text() and "1 section" in r.stderr
    for args in (["workspace", M1_YAML], ["aspects", M1_YAML], ["rpr3", "pave", RPR3_GENERAL],
                 ["refine", "m1/workspace.qt"]):
        one_line(run_cli(*args, "--depth", 3, "-o", "-", cwd=tmp_path), 2, "-o -", "give a folder")
    assert not (tmp_path / "-").exists()


# ---------------------------------------------------------------- CSV quoting


def test_csv_cells_are_quoted_by_rfc_4180_only_when_needed():
    rows = [["plain", 1.5], ['a,b "q"', 2], ["line\nbreak", 0.0]]
    text = csv_text(["name", "x"], rows)
    assert text.split("\n")[1] == "plain,1.5" and '"a,b ""q"""' in text
    assert list(csv.reader(io.StringIO(text))) == [["name", "x"], ["plain", "1.5"], ['a,b "q"', "2"],
                                                   ["line\nbreak", "0"]]


# ---------------------------------------------------------------- diff: same cells, other claims


def test_diff_exits_1_for_the_same_cells_with_another_colour_or_mechanism(tmp_path):
    ok(run_cli("workspace", M1_YAML, "--depth", 4, "-o", "m1", "--no-plot", cwd=tmp_path))
    tree = (tmp_path / "m1" / "workspace.qt").read_text()
    (tmp_path / "outside.qt").write_text(tree.replace("# colour: inside", "# colour: outside"))
    (tmp_path / "other.qt").write_text(tree.replace("L4=8.0", "L4=8.5"))
    (tmp_path / "renamed.qt").write_text(tree.replace("# name: M1", "# name: M1b"))
    for other, key in (("outside.qt", "colour"), ("other.qt", "mechanism")):
        r = run_cli("diff", "m1/workspace.qt", other, cwd=tmp_path)
        assert r.status == 1 and "same set" in r.stdout and f"their {key} differ" in r.stdout, r.stdout
        r = run_cli("diff", "m1/workspace.qt", other, "--sets-only", cwd=tmp_path)
        assert r.status == 0 and "do not claim" not in r.stdout
    assert run_cli("diff", "m1/workspace.qt", "renamed.qt", cwd=tmp_path).status == 0  # a name is a label


def test_figures_draw_names_as_written(tmp_path):
    """A name with dollar signs is text in titles and legends, not mathtext (`$x^$` would not draw)."""
    (tmp_path / "m.yaml").write_text(M1_YAML.read_text().replace("name: M1", "name: 'cost $x^$, 50%'"))
    ok(run_cli("workspace", "m.yaml", "--depth", 3, "-o", "out", cwd=tmp_path))
    assert (tmp_path / "out" / "workspace.png").read_bytes().startswith(PNG_MAGIC)


def test_the_out_default_each_help_shows_is_where_the_command_writes(tmp_path):
    """refine in place, kratio in outputs/, atlas in outputs/<spec name>/, the others in
    outputs/<config name>/: as each --help says."""
    (tmp_path / "a.yaml").write_text("name: tiny\ntype: fivebar-atlas\nlengths: {L0: 1.0, L1: 0.4, L2: 0.4, "
                                     "L3: 0.3, L4: 0.3}\ndepth: 3\n")
    cases = [(["workspace", M1_YAML, "--depth", 3], "outputs/<config name>/", "outputs/M1/workspace.qt"),
             (["refine", "outputs/M1/workspace.qt", "--depth", 4], "the folder of TREE.qt, in place",
              "outputs/M1/workspace.qt"),
             (["kratio", M1_YAML, "--depths", 2], "outputs/", "outputs/kratio.csv"),
             (["atlas", "a.yaml", "--workers", 0], "outputs/<spec name>/", "outputs/tiny/atlas.csv")]
    for args, shown, written in cases:
        help_text = " ".join(run_cli(*args[:1], "--help").stdout.split())
        assert f"Output folder [default: {shown}]" in help_text, (args[0], help_text)
        ok(run_cli(*args, "--no-plot", "-q", cwd=tmp_path))
        assert (tmp_path / written).is_file(), written
    assert read_qt(tmp_path / "outputs" / "M1" / "workspace.qt").tree.grid.depth == 4


@pytest.mark.parametrize("setting, flushed", [(None, True), ("1", True), ("0", False)])
def test_text_is_flushed_to_the_disk_before_the_rename_unless_fivebar_fsync_is_0(tmp_path, monkeypatch,
                                                                                  setting, flushed):
    synced = []
    real = os.fsync
    monkeypatch.setattr(os, "fsync", lambda fd: (synced.append(os.fstat(fd).st_size), real(fd)))
    if setting is None:
        monkeypatch.delenv("FIVEBAR_FSYNC", raising=False)
    else:
        monkeypatch.setenv("FIVEBAR_FSYNC", setting)
    write_text(tmp_path / "a.csv", "x,y\n1,2\n")
    assert synced == ([8] if flushed else [])  # the whole file, before it takes the name
    assert (tmp_path / "a.csv").read_text() == "x,y\n1,2\n" and os.listdir(tmp_path) == ["a.csv"]
