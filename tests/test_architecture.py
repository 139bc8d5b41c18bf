"""docs/architecture.md lists every module of the package (its module table), and the command line
keeps its shape: no command module imports another, none is 200 lines or more (a command parses,
makes one library call and writes/reports: issue 21)."""

from __future__ import annotations

import ast
import re

from tests.cli_helpers import REPO

PACKAGE = REPO / "fivebar_cli"
CLI = PACKAGE / "cli"
SHARED = {"__init__", "main", "options", "numbers", "dispatch", "poses"}  # not commands: the group and its helpers


def listed_modules() -> set[str]:
    """Module paths (relative to the package) named in the module table: `cli/spaces.py`, and the
    short names that follow a path in the same cell (`aspects.py` after `cli/spaces.py`), and the
    modules a package row (`mechanisms/rpr3/`) names in its text."""
    names = set()
    for line in (REPO / "docs" / "architecture.md").read_text().splitlines():
        if not line.startswith("| `"):
            continue
        cell, _, text = line[2:].partition(" | ")
        folder = ""
        for name in re.findall(r"`([^`]+)`", cell):
            if "/" in name:
                folder = name.rsplit("/", 1)[0] + "/" if not name.endswith("/") else name
                if name.endswith("/"):
                    names.update(folder + n for n in re.findall(r"`?(\w+\.py)`?", text))
                    names.add(folder + "__init__.py")
                    continue
                names.add(name)
            else:
                names.add(folder + name)
    return names


def test_architecture_lists_every_module():
    modules = {p.relative_to(PACKAGE).as_posix() for p in PACKAGE.rglob("*.py") if "examples" not in p.parts}
    modules -= {m for m in modules if m.endswith("__init__.py") and m != "__init__.py" and m != "api/__init__.py"
                and m != "cli/__init__.py"}
    missing = sorted(modules - listed_modules() - {"__main__.py"})
    assert not missing, f"docs/architecture.md does not list: {missing}"


def test_command_modules_are_small_and_import_no_other_command():
    commands = {p.stem for p in CLI.glob("*.py")} - SHARED
    for path in CLI.glob("*.py"):
        if path.stem == "main":
            continue
        tree = ast.parse(path.read_text())
        imported = {n.module.rsplit(".", 1)[-1] for n in ast.walk(tree)
                    if isinstance(n, ast.ImportFrom) and n.module and n.module.startswith("fivebar_cli.cli.")}
        assert not imported & commands, (path.name, imported & commands)
        if path.stem in commands:
            assert len(path.read_text().splitlines()) < 200, path.name
