"""Every result of the public API pickles (issue 21: results are values): a notebook sends them to
a process pool (`concurrent.futures`, joblib) or caches them on disk, and a result that held a
closure (a region's box test, a report's figure) failed there with "Can't pickle local object".
A result back from pickle is the same value: its repr and rows, and, saved (a report with its
figures), the same files byte for byte."""

from __future__ import annotations

import pickle

import pytest

import fivebar_cli as fb
from tests.cli_helpers import REPO

ATLAS = {"name": "tiny", "type": "fivebar-atlas", "depth": 4,
         "lengths": {"L0": [2.5, 3, 2], "L1": 1, "L2": 1, "L3": 2, "L4": 2}}
RESULTS = {
    # the two kinds of regions (a five-bar's modes, a space of poses' classes), and a model with limits
    "aspects, five-bar": lambda: fb.aspects("m1", 4),
    "aspects, five-bar with joint limits": lambda: fb.aspects("m1-limited", 4),
    "aspects, 3-RPR": lambda: fb.aspects("rpr3-caro", 3),
    "paving": lambda: fb.pave("m1", "workspace", 5),
    "location": lambda: fb.locate("m1", pose=(4, 5), depth=5),
    "path": lambda: fb.path("m1", {"pose": (4, 5), "working_mode": "++"}, {"pose": (5, 6), "working_mode": "++"},
                            depth=6),
    "tolerance": lambda: fb.tolerance("m1", [0, 0.05], 3),
    "kratio": lambda: fb.kratio("m1", [3]),
    "verify with a counterexample": lambda: fb.verify(REPO / "configs" / "rrr3-symmetric.yaml", 2, working_mode="+-+"),
    "dkp": lambda: fb.dkp("rpr3-caro", (20.6315, 23.2633, 16.0359), 3),
    "rpr3 area": lambda: fb.rpr3.area("rpr3-table1"),
    "rpr3 sweep over phi": lambda: fb.rpr3.sweep(["rpr3-equilateral"], "phi", steps=5),
    "rpr3 sweep over rho_min": lambda: fb.rpr3.sweep(["rpr3-equilateral"], "rho_min", steps=5),
    "rpr3 sweep over t2": lambda: fb.rpr3.sweep(["rpr3-equilateral"], "t2", steps=5),
    "rpr3 synthesize": lambda: fb.rpr3.synthesize("rpr3-table1"),
    "rpr3 verify with a counterexample": lambda: fb.rpr3.verify(REPO / "configs" / "rpr3-verify" / "obtuse-phi1-rule.yaml"),
    "atlas": lambda: fb.atlas(ATLAS),
}


def _files(folder) -> dict[str, bytes]:
    return {p.relative_to(folder).as_posix(): p.read_bytes() for p in sorted(folder.rglob("*"))
            if p.is_file() and ".fivebar" not in p.parts}


@pytest.mark.parametrize("name", RESULTS)
def test_a_result_pickles_into_the_same_value(name, tmp_path):
    result = RESULTS[name]()
    back = pickle.loads(pickle.dumps(result))
    assert type(back) is type(result) and repr(back) == repr(result)
    if hasattr(result, "rows"):
        assert list(back.rows()) == list(result.rows())
    if not hasattr(result, "save"):  # (a location: its rows and lines)
        assert back.lines() == result.lines()
        return
    # (a report's figures are values it holds; the others' are drawn from their data by their methods)
    figures = isinstance(result, fb.Report)
    result.save(tmp_path / "before", figures=figures)
    back.save(tmp_path / "after", figures=figures)
    before = _files(tmp_path / "before")
    assert before and _files(tmp_path / "after") == before
    if name.endswith("counterexample"):  # (a figure drawn from the value that came back)
        assert any(f.endswith(".png") for f in before), sorted(before)
