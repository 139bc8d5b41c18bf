"""Designs that cannot work (issue 12, item 4): a five-bar whose loop never closes is a
configuration error (exit 2, one line naming the violated inequality) for every command; the
inequalities are checked against a dense sampling of |B1B2| over the torus; `aspects` too shallow
to certify anything says so; the paper's claim is only judged for the paper's mechanisms."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest
from cli_helpers import ok, one_line, run_cli
from hypothesis import given, settings
from hypothesis import strategies as st

from fivebar_cli.mechanisms.fivebar.model import assembles

REPO = Path(__file__).resolve().parents[1]

IMPOSSIBLE = {  # lengths L0..L4 -> words of the inequality
    "base too long": ((30, 8, 5, 5, 8), "L0 = 30 > L1 + L2 + L3 + L4 = 26"),
    "couplers too different": ((1, 1, 1, 10, 2), "|L3 - L4| = 8 > L0 + L1 + L2 = 3"),
    "cranks too different": ((1, 10, 1, 2, 2), "|L1 - L2| = 9 > L0 + L3 + L4 = 5"),
    "flat only": ((26, 8, 5, 5, 8), "L0 = L1 + L2 + L3 + L4 = 26"),
}
COMMANDS = {
    "workspace": ["workspace", "{cfg}", "--depth", "4", "--no-plot"],
    "jointspace": ["jointspace", "{cfg}", "--depth", "4", "--no-plot"],
    "aspects": ["aspects", "{cfg}", "--depth", "4", "--no-plot"],
    "locate": ["locate", "{cfg}", "--pose", "1", "1"],
    "path": ["path", "{cfg}", "--joints", "0", "1", "--joints", "1", "0", "--assembly-mode", "+"],
    "kratio": ["kratio", "{cfg}", "--depths", "3", "--no-plot"],
}


def config(folder: Path, lengths) -> Path:
    path = folder / "bad.yaml"
    items = ", ".join(f"L{k}: {v}" for k, v in enumerate(lengths))
    path.write_text(f"name: bad\ntype: fivebar\nlengths: {{{items}}}\n")
    return path


@pytest.mark.parametrize("command", list(COMMANDS))
@pytest.mark.parametrize("design", list(IMPOSSIBLE))
def test_every_command_names_the_violated_inequality(tmp_path, command, design):
    lengths, words = IMPOSSIBLE[design]
    cfg = config(tmp_path, lengths)
    args = [a.format(cfg=cfg) for a in COMMANDS[command]] + ["-o", tmp_path / "out"]
    line = one_line(run_cli(*args), 2, "bad.yaml: lengths:", words)
    assert "closes" in line
    assert not (tmp_path / "out").exists() or not list((tmp_path / "out").rglob("*.*"))


def test_refine_of_a_tree_whose_mechanism_cannot_close(tmp_path):
    ok(run_cli("workspace", REPO / "configs" / "m1.yaml", "--depth", 3, "-o", tmp_path, "--no-plot", "-q"))
    qt = tmp_path / "workspace.qt"
    for name in ("workspace.qt", "workspace.complement.qt"):
        p = tmp_path / name
        p.write_text(p.read_text().replace("L0=9.0", "L0=30.0"))
    one_line(run_cli("refine", qt, "--depth", 4, "--no-plot"), 2, "L0 = 30 > L1 + L2 + L3 + L4 = 26")


def sampled_range(lengths, n=181) -> tuple[float, float]:
    """min and max of |B1B2| over a dense grid of the torus (independent of the formula)."""
    L0, L1, L2, _, _ = lengths
    t = np.linspace(-np.pi, np.pi, n)
    th1, th2 = np.meshgrid(t, t)
    d = np.hypot(L0 + L2 * np.cos(th2) - L1 * np.cos(th1), L2 * np.sin(th2) - L1 * np.sin(th1))
    return float(d.min()), float(d.max())


@settings(max_examples=100, deadline=None)
@given(lengths=st.tuples(*[st.floats(0.1, 10)] * 5))
def test_the_inequalities_against_sampling(lengths):
    """The loop closes on an open set exactly when the sampled range of |B1B2| meets the open
    interval (|L3 - L4|, L3 + L4); designs within 2 % of the boundary are skipped (sampling)."""
    L0, L1, L2, L3, L4 = lengths
    lo, hi = sampled_range(lengths)
    inner, outer = abs(L3 - L4), L3 + L4
    margin = 0.02 * sum(lengths)
    if abs(hi - inner) < margin or abs(lo - outer) < margin:
        return
    closes = hi > inner and lo < outer
    problem = assembles({"L0": L0, "L1": L1, "L2": L2, "L3": L3, "L4": L4})
    assert (problem is None) == closes, (lengths, lo, hi, problem)
    assert assembles(lengths) == problem  # a sequence works too


def test_assembles_for_the_paper_mechanisms():
    assert assembles((9, 8, 5, 5, 8)) is None and assembles((2.55, 2.3, 2.3, 2.3, 2.3)) is None


# ---------------------------------------------------------------- aspects: plain answers


def test_too_shallow_says_so_and_suggests_a_depth_that_helps(tmp_path):
    r = ok(run_cli("aspects", REPO / "configs" / "m1.yaml", "--depth", 1, "-o", tmp_path, "--no-plot"))
    assert "no aspect has certified cells at depth 1" in r.stdout and "try --depth 8" in r.stdout
    r = ok(run_cli("aspects", REPO / "configs" / "m2.yaml", "--depth", 2, "-o", tmp_path, "--no-plot"))
    assert "no aspect has certified cells at depth 2" in r.stdout


def test_paper_claim_only_for_the_papers_mechanisms(tmp_path):
    r = ok(run_cli("aspects", REPO / "configs" / "m1.yaml", "--depth", 8, "-o", tmp_path / "m1", "--no-plot"))
    assert "paper's claim on single working-mode changes (det A +): holds" in r.stdout
    assert "crossing graph" not in r.stdout
    other = tmp_path / "other.yaml"
    other.write_text("name: other\ntype: fivebar\nlengths: {L0: 9, L1: 8, L2: 5, L3: 5, L4: 7.5}\n")
    r = ok(run_cli("aspects", other, "--depth", 8, "-o", tmp_path / "other", "--no-plot"))
    assert "paper's claim" not in r.stdout
    assert "crossing graph (det A +): K_{2,3}" in r.stdout or "crossing graph (det A +): not K_{2,3}" in r.stdout
