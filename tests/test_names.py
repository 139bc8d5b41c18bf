"""A mechanism's `name:` with any printable character (issue 20, item 2): either refused when the
file is read, with one line naming the field, or written safely by every command that writes it:
the default folder `outputs/<name>/`, the `.qt` header, every CSV (RFC 4180 quoting, read back by
the csv module to the very name), the view page, the figures' titles.
"""

from __future__ import annotations

import csv
import json
from pathlib import Path

import yaml

from cli_helpers import PNG_MAGIC, ok, one_line, run_cli
from conftest import CONFIGS, M2_YAML
from hypothesis import HealthCheck, example, given, settings
from hypothesis import strategies as st

from fivebar_cli.io.qtfile import read_qt
from fivebar_cli.io.schema import ConfigError, name_field

RPR3 = CONFIGS / "rpr3-equilateral.yaml"
PRINTABLE = st.text(st.characters(min_codepoint=0x20, max_codepoint=0x2FF) | st.sampled_from(list(',"\'$-.:&#%{}[]!?~ 名✓')),
                    min_size=1, max_size=14)
NAMES = PRINTABLE | st.text(st.characters(blacklist_categories=("Cs",)), min_size=1, max_size=14)


def config(folder: Path, source: Path, name: str) -> Path:
    """`source` with its `name:` replaced by `name`, as a YAML double-quoted string that reads back
    as exactly `name` (YAML escapes: a raw NEL or LINE SEPARATOR inside quotes is a line break,
    which YAML folds into a space)."""
    lines = source.read_text().splitlines()
    path = folder / source.name
    quoted = yaml.safe_dump(name, allow_unicode=True, default_style='"', width=1 << 20).strip()
    path.write_text("\n".join(f"name: {quoted}" if line.startswith("name:") else line for line in lines) + "\n")
    return path


def csv_names(path: Path, column: str) -> set[str]:
    with open(path, newline="", encoding="utf-8") as fh:
        return {row[column] for row in csv.DictReader(fh)}


def accepted(name: str) -> bool:
    try:
        return name_field({"name": name}, "x") == name
    except ConfigError:
        return False


@settings(max_examples=12, deadline=None, suppress_health_check=[HealthCheck.function_scoped_fixture])
@given(name=NAMES)
@example(name="0\x850")  # a NEL: a line break inside YAML quotes unless escaped (found by hypothesis)
def test_every_writing_command_writes_the_name_or_the_file_is_refused(tmp_path_factory, name):
    root = tmp_path_factory.mktemp("name")
    fivebar, rpr3 = config(root, M2_YAML, name), config(root, RPR3, name)
    if not accepted(name):
        for args in (["workspace", fivebar, "--depth", 2], ["rpr3", "area", rpr3], ["kratio", fivebar, "--depths", 2]):
            one_line(run_cli(*args, cwd=root), 2, "name")
        assert not (root / "outputs").exists()
        return
    folder = root / "outputs" / name
    for args in (["workspace", fivebar, "--depth", 3], ["aspects", fivebar, "--depth", 6],
                 ["tolerance", fivebar, "--tolerances", "0", "--depth", 2], ["rpr3", "area", rpr3],
                 ["kratio", fivebar, "--depths", 2]):
        ok(run_cli(*args, "--no-plot", "-q", cwd=root))
    assert folder.is_dir() and folder.parent == root / "outputs"
    ok(run_cli("refine", folder / "workspace.qt", "--depth", 4, "--no-plot", "-q", cwd=root))
    assert read_qt(folder / "workspace.qt").get("name") == name and read_qt(folder / "workspace.qt").tree.grid.depth == 4
    assert read_qt(folder / "aspects" / "aspect-01.jointspace.qt").get("name") == name
    assert csv_names(folder / "workspace.csv", "name") == {name}
    assert csv_names(root / "outputs" / "kratio.csv", "mechanism") == {name}
    assert (folder / "area.csv").is_file() and len((folder / "tolerance.csv").read_text().splitlines()) > 2
    ok(run_cli("view", folder, "-o", root / "page.html", "-q", cwd=root))
    page = (root / "page.html").read_text()
    data = json.loads(page.split('id="fivebar-data">', 1)[1].split("</script>", 1)[0])
    assert data["title"] == f"fivebar view: {name}"


def test_names_the_file_system_or_a_reader_could_not_take_are_refused(tmp_path):
    for name, why in (("a/b", "folder name"), ("..", "folder name"), ("x\ny", "folder name"), (" x", "folder name"),
                      ("x" * 101, "folder name"), ("€" * 90, "at most 255"), ('a"b', "folder name")):
        one_line(run_cli("workspace", config(tmp_path, M2_YAML, name), "--depth", 2, cwd=tmp_path), 2, "name", why)
    assert not (tmp_path / "outputs").exists()


def test_names_with_commas_quotes_dashes_and_dollars_in_every_file_and_figure(tmp_path):
    for name in ("a,b 'c'", "-x", "..x", "$x^$ 50%", "名前 ✓"):
        ok(run_cli("workspace", config(tmp_path, M2_YAML, name), "--depth", 3, "-q", cwd=tmp_path))
        folder = tmp_path / "outputs" / name
        assert csv_names(folder / "workspace.csv", "name") == {name}
        assert (folder / "workspace.png").read_bytes().startswith(PNG_MAGIC)
    ok(run_cli("rpr3", "sweep", config(tmp_path, RPR3, "tri,angle"), "--over", "rho_min", "--steps", 3, "-q",
               cwd=tmp_path))
    assert csv_names(tmp_path / "outputs" / "tri,angle" / "area-vs-rho-min.csv", "config") == {"tri,angle"}
