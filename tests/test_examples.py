"""Every example of every `--help` text runs as pasted (issue 20): in one temporary copy of the
repository, in the order the help texts give them (the group's, then each command's); see
tests/examples.py. A command added later is walked like the others. A line the README also shows
is run once, by tests/test_readme.py (which checks what it prints, too).
"""

from __future__ import annotations

import pytest
from examples import ELSEWHERE, check, help_examples, readme_blocks, run, sandbox

EXAMPLES = help_examples()
IN_README = {c.line for b in readme_blocks() if b.not_run is None for c in b.commands}
ELSEWHERE = {**{line: "tests/test_readme.py" for line in IN_README}, **ELSEWHERE}


@pytest.fixture(scope="module")
def ran(tmp_path_factory):
    root = sandbox(tmp_path_factory.mktemp("help-examples"))
    results = {}
    for i, command in enumerate(EXAMPLES):
        if command.line not in ELSEWHERE and command.line not in {c.line for c, _ in results.values()}:
            results[i] = (command, run(command, root))
    return results


def test_every_command_has_an_example():
    from fivebar_cli.cli import cli

    def leaves(command, path):
        subs = getattr(command, "commands", None)
        if not subs:
            return [path]
        return [leaf for name in subs for leaf in leaves(subs[name], f"{path} {name}")]

    documented = {c.where.strip("`").removesuffix(" --help") for c in EXAMPLES}
    assert [leaf for leaf in leaves(cli, "fivebar") if leaf not in documented] == []


@pytest.mark.parametrize("index", range(len(EXAMPLES)), ids=[c.line[8:60] for c in EXAMPLES])
def test_help_example_runs_as_pasted(ran, index):
    command = EXAMPLES[index]
    if command.line in ELSEWHERE:
        pytest.skip(f"run as pasted by {ELSEWHERE[command.line]}")
    if index not in ran:
        return  # the same line, run earlier in this copy
    check(*ran[index])
