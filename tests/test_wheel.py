"""A built wheel, not the editable install: the package data (the shipped examples, the page of
`fivebar view`) is in it, and from a folder outside the repository the examples load, a command
runs on them and `fivebar reproduce` finds them."""

from __future__ import annotations

import os
import re
import shutil
import subprocess
import sys
import zipfile

import pytest

from fivebar_cli.cli import reproduce as reproduce_module
from tests.cli_helpers import REPO, ok, one_line, run_cli, snapshot


@pytest.fixture(scope="module")
def installed(tmp_path_factory):
    """The wheel built from a copy of the sources (the checkout stays clean) by the build backend that
    pyproject.toml names, through its PEP 517 hook, in a process of its own, as `pip wheel
    --no-build-isolation` would call it; then unpacked into a target folder, which is what installing a
    pure-Python wheel is (`pip install --target` does the same, at twice the set-up's cost): (wheel, target)."""
    root = tmp_path_factory.mktemp("wheel")
    source = root / "src"
    ignore = shutil.ignore_patterns("__pycache__", "*.pyc")
    shutil.copytree(REPO / "fivebar_cli", source / "fivebar_cli", symlinks=True, ignore=ignore)
    shutil.copytree(REPO / "configs", source / "configs", ignore=ignore)
    for name in ("pyproject.toml", "README.md"):
        shutil.copy(REPO / name, source / name)
    backend = re.search(r'^build-backend = "([\w.]+)"$', (source / "pyproject.toml").read_text(), re.M)[1]
    build = f"import sys, {backend} as backend; backend.build_wheel(sys.argv[1])"
    subprocess.run([sys.executable, "-c", build, str(root / "dist")], check=True, capture_output=True, cwd=source)
    (wheel,) = (root / "dist").glob("fivebar-*.whl")
    with zipfile.ZipFile(wheel) as archive:
        archive.extractall(root / "site")
    return wheel, root / "site"


def test_the_wheel_holds_the_examples_and_the_page(installed):
    wheel, _ = installed
    names = set(zipfile.ZipFile(wheel).namelist())
    shipped = {f"fivebar_cli/examples/{p.relative_to(REPO / 'configs').as_posix()}"
               for p in (REPO / "configs").rglob("*.yaml")}
    assert shipped <= names and "fivebar_cli/examples/rpr3-verify/table1-case1.yaml" in shipped
    assert {"fivebar_cli/webpage/page.js", "fivebar_cli/webpage/page.html", "fivebar_cli/webpage/page.css"} <= names


def test_the_installed_package_runs_from_any_folder(installed, tmp_path):
    _, site = installed
    env = {**{k: v for k, v in os.environ.items() if k != "FIVEBAR_DEBUG"}, "PYTHONPATH": str(site),
           "MPLBACKEND": "Agg"}
    code = ("import fivebar_cli as fb; print(fb.__file__); e = fb.examples(); print(len(e)); "
            "print(fb.load('m2').name, fb.rpr3.area(e['rpr3-equilateral']).rows()[0]['area'])")
    out = subprocess.run([sys.executable, "-c", code], env=env, cwd=tmp_path, capture_output=True, text=True,
                         check=True).stdout.split("\n")
    assert out[0].startswith(str(site)) and int(out[1]) == len(list((REPO / "configs").rglob("*.yaml")))
    golden = (REPO / "tests" / "golden" / "rpr3-equilateral" / "area.csv").read_text().split("\n")[1].split(",")
    name, area = out[2].split()
    assert name == "M2" and float(area) == pytest.approx(float(golden[3]), rel=1e-9)
    listed = subprocess.run([sys.executable, "-m", "fivebar_cli", "examples", "--copy", "mine"], env=env,
                            cwd=tmp_path, capture_output=True, text=True, check=True).stdout
    assert "wrote mine/m1.yaml" in listed and (tmp_path / "mine" / "rpr3-verify" / "table1-case6.yaml").is_file()
    assert (tmp_path / "mine" / "m1.yaml").read_bytes() == (REPO / "configs" / "m1.yaml").read_bytes()


def test_reproduce_reads_the_shipped_examples_outside_the_repository(tmp_path, monkeypatch):
    """From a folder without configs/, `fivebar reproduce` runs its steps on the shipped examples
    (here its two cheapest steps: the commands themselves are tested elsewhere)."""
    steps = [s for s in reproduce_module.REPRODUCTION if s[1][0] == "rpr3" and s[1][1] in ("area", "verify")][:2]
    monkeypatch.setattr(reproduce_module, "REPRODUCTION", tuple(steps))
    result = ok(run_cli("reproduce", "-o", "out", "--no-plot", cwd=tmp_path))
    shipped = REPO / "fivebar_cli" / "examples"
    assert f"fivebar rpr3 area {shipped.as_posix()}/rpr3-equilateral.yaml" in result.stdout
    assert (tmp_path / "out" / "rpr3-equilateral" / "area.csv").read_bytes() == \
        (REPO / "tests" / "golden" / "rpr3-equilateral" / "area.csv").read_bytes()


def test_commands_take_an_examples_name_where_no_such_file_exists(tmp_path):
    """`fivebar aspects rpr3-caro` from any folder is `fivebar aspects .../rpr3-caro.yaml` (the
    pose-space command: the name is resolved before the kind is read; it went to the five-bar's
    command and failed with an internal error), `fivebar workspace m1` likewise (it said "no such
    file"); a file of that name in the folder comes first."""
    configs = REPO / "configs"
    for by_name, by_file, name in [
        (("aspects", "rpr3-caro", "--depth", "3"), ("aspects", configs / "rpr3-caro.yaml", "--depth", "3"), "aspects.csv"),
        (("workspace", "m1", "--depth", "5"), ("workspace", configs / "m1.yaml", "--depth", "5"), "workspace.qt"),
        (("dkp", "rpr3-caro", "--joints", "14.98", "15.38", "12", "--depth", "3"),
         ("dkp", configs / "rpr3-caro.yaml", "--joints", "14.98", "15.38", "12", "--depth", "3"), "dkp.csv"),
    ]:
        ok(run_cli(*by_name, "-o", "name", "--no-plot", "-q", cwd=tmp_path))
        ok(run_cli(*by_file, "-o", "file", "--no-plot", "-q", cwd=tmp_path))
        assert (tmp_path / "name" / name).read_bytes() == (tmp_path / "file" / name).read_bytes()
    shutil.copy(configs / "m2.yaml", tmp_path / "m1")  # a file named m1 here: it is the one read
    ok(run_cli("workspace", "m1", "--depth", "5", "-o", "local", "--no-plot", "-q", cwd=tmp_path))
    assert "M2" in (tmp_path / "local" / "workspace.qt").read_text().split("\n", 3)[1]


def test_a_second_copy_never_replaces_an_edited_example(tmp_path):
    """`fivebar examples --copy DIR` writes the shipped bytes; run again over an edited copy it
    copies nothing (a file removed meanwhile stays removed), fails with one line naming the
    edited file, and `--replace` then restores every example, writing only the files that were
    edited or missing (the others keep their modification time); `fb.copy_examples` is the same call."""
    import fivebar_cli as fb

    shipped = {f"{name}.yaml": path.read_bytes() for name, path in fb.examples().items()}
    ok(run_cli("examples", "--copy", "mine", "-q", cwd=tmp_path))
    assert snapshot(tmp_path / "mine") == shipped
    (tmp_path / "mine" / "m1.yaml").write_text("name: mine\n")
    (tmp_path / "mine" / "m2.yaml").unlink()
    ok(run_cli("examples", "--copy", "elsewhere", "-q", cwd=tmp_path))  # (another folder: copied)
    before = snapshot(tmp_path / "mine")
    one_line(run_cli("examples", "--copy", "mine", cwd=tmp_path), 1, "mine/m1.yaml: not the shipped example's bytes",
             "nothing copied; --replace replaces it")
    assert snapshot(tmp_path / "mine") == before
    (tmp_path / "mine" / "hard" / "thin-lens.yaml").write_text("name: mine too\n")
    with pytest.raises(fb.FivebarError, match=r"hard/thin-lens\.yaml and 1 more: .* `replace=True` replaces them"):
        fb.copy_examples(tmp_path / "mine")
    assert snapshot(tmp_path / "mine") == before | {"hard/thin-lens.yaml": b"name: mine too\n"}
    one_line(run_cli("examples", "--replace", cwd=tmp_path), 2, "--replace goes with --copy DIR")
    untouched = tmp_path / "mine" / "m1-obstacle.yaml"
    os.utime(untouched, (1e9, 1e9))  # (2001: a copy that left it would keep this time)
    assert [p.relative_to(tmp_path / "mine").as_posix() for p in fb.copy_examples(tmp_path / "mine", replace=True)] \
        == [name for name in shipped if name in ("m1.yaml", "m2.yaml", "hard/thin-lens.yaml")]
    assert snapshot(tmp_path / "mine") == shipped and untouched.stat().st_mtime == 1e9
    again = run_cli("examples", "--copy", "mine", cwd=tmp_path)
    assert again.status == 0 and again.stdout.splitlines() == [
        f"  left {len(shipped)} files in mine as they were (already the shipped bytes)"]
    assert untouched.stat().st_mtime == 1e9
    (tmp_path / "mine" / "rpr2.yaml").unlink()
    os.symlink(tmp_path / "elsewhere" / "rpr2.yaml", tmp_path / "mine" / "rpr2.yaml")  # (refused before any write)
    (tmp_path / "mine" / "m1.yaml").write_text("name: mine\n")
    one_line(run_cli("examples", "--copy", "mine", "--replace", cwd=tmp_path), 1, "rpr2.yaml: is a symbolic link")
    assert (tmp_path / "mine" / "m1.yaml").read_text() == "name: mine\n"


@pytest.mark.parametrize("argv, typed, meant", [
    (("workspace", "m11", "--depth", "2"), "m11", "m1"), (("aspects", "M1", "--depth", "2"), "M1", "m1"),
    (("dkp", "rpr3caro", "--joints", "15", "15", "12"), "rpr3caro", "rpr3-caro"),
])
def test_a_mistyped_examples_name_is_told_the_name_meant(argv, typed, meant, tmp_path, monkeypatch):
    """A CONFIG (or `fb.load`'s source) that is no file and no example's name, but close to one
    (case aside), is a typo: the line names the example meant; a name close to none, or a path,
    gets the plain line."""
    import fivebar_cli as fb

    line = f"{typed}: no such file, nor a shipped example's name: did you mean '{meant}'?"
    one_line(run_cli(*argv, "--no-plot", "-o", "out", cwd=tmp_path), 2, line)
    monkeypatch.chdir(tmp_path)
    with pytest.raises(fb.InputError, match=re.escape(line)):
        fb.load(typed)
    for far in ("zz9", "configs/m1.yml"):
        with pytest.raises(fb.InputError, match=f"^{re.escape(far)}: no such file$"):
            fb.load(far)
    assert not (tmp_path / "out").exists()


def test_an_atlas_spec_is_an_examples_name_too(tmp_path):
    """`fb.atlas` and `fb.atlas_plan` take a shipped spec by name, as `fivebar atlas` and `fb.load`
    do (the library refused it: 'no such file'), and tell a typo the name meant."""
    import fivebar_cli as fb

    plan = fb.atlas_plan("atlas-small", tmp_path / "plan")
    assert plan.spec == fb.atlas_plan(fb.examples()["atlas-small"], tmp_path / "plan").spec
    with pytest.raises(fb.InputError, match="atlas-smal: no such file, nor a shipped example's name: did you mean "
                                            "'atlas-small'"):
        fb.atlas_plan("atlas-smal", tmp_path / "typo")

