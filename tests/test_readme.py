"""Every shell block of the README runs as pasted, and what it shows printed is what the tool prints
(issue 20): the blocks in order, in one temporary copy of the repository, as a reader following the
README would run them; see tests/examples.py. Blocks other helpers add are picked up the same way.
"""

from __future__ import annotations

import pytest
from examples import ELSEWHERE, check, readme_blocks, run, sandbox

BLOCKS = readme_blocks()
COMMANDS = [(b, c) for b in BLOCKS if b.not_run is None for c in b.commands]
MAX_NOT_RUN = 2  # the set-up block (make reproduce, make test) and the multi-machine cluster


@pytest.fixture(scope="module")
def ran(tmp_path_factory):
    root = sandbox(tmp_path_factory.mktemp("readme"))
    return [run(command, root) if command.line not in ELSEWHERE else None for _, command in COMMANDS]


def test_blocks_left_out_are_few_and_say_why():
    left_out = [(b.where, b.not_run) for b in BLOCKS if b.not_run is not None]
    assert len(left_out) <= MAX_NOT_RUN and all(reason for _, reason in left_out), left_out
    assert len(COMMANDS) >= 20


@pytest.mark.parametrize("index", range(len(COMMANDS)), ids=[c.line[:60] for _, c in COMMANDS])
def test_readme_command_runs_as_pasted(ran, index):
    block, command = COMMANDS[index]
    if ran[index] is None:
        pytest.skip(f"run as pasted by {ELSEWHERE[command.line]}")
    check(command, ran[index])


def test_the_table_1_figures_are_the_tools():
    """The README's depth-10 table (evaluations, K, the paper's procedure, printed K, saving) is the
    golden kratio.csv, which `fivebar reproduce` writes (tests/test_golden.py)."""
    import re

    from cli_helpers import csv_rows
    from examples import README

    rows = {(r["space"], r["mechanism"]): r for r in csv_rows(README.parent / "tests" / "golden" / "kratio.csv")
            if r["depth"] == "10"}
    shown = re.findall(r"^\| (M[12]) (joint space|workspace) \| (.+) \|$", README.read_text(), re.M)
    assert len(shown) == 4
    for mechanism, space, cells in shown:
        r = rows[("jointspace" if space == "joint space" else "workspace", mechanism)]
        percent = lambda x, digits: f"{100 * float(x):.{digits}f} %"  # noqa: E731 - the README writes "1.71 %"
        expected = (f"{int(r['evaluations']):,} ({percent(r['K'], 2)}) | "
                    f"{int(r['paper_procedure_evaluations']):,} ({percent(r['paper_procedure_K'], 2)}) | "
                    f"{r['paper_printed_percent']} % | {percent(r['saving_vs_paper'], 0)}")
        assert cells == expected, (mechanism, space, cells, expected)
