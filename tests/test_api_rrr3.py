"""`fb.locate` and `fb.path` of a 3-RRR in a working mode (`working_mode`, as the commands'
--working-mode): the same rows as `fivebar locate --csv` and the same path.csv as `fivebar path`."""

from __future__ import annotations

import csv
from pathlib import Path

import numpy as np
import pytest
import yaml

import fivebar_cli as fb
from tests.cli_helpers import csv_rows, ok, one_line, run_cli

SYMMETRIC = Path(__file__).resolve().parent.parent / "configs" / "rrr3-symmetric.yaml"


@pytest.fixture(scope="module")
def narrow(tmp_path_factory):
    """The symmetric robot, every working mode, phi in [0, 20] (the paths stay quick)."""
    path = tmp_path_factory.mktemp("rrr3-api") / "narrow.yaml"
    data = yaml.safe_load(SYMMETRIC.read_text())
    data.update(name="narrow", phi_range=[0, 20])
    path.write_text(yaml.safe_dump(data))
    return path


def test_locate_in_one_working_mode_or_all_as_the_command(narrow, tmp_path):
    m = fb.load(narrow)
    found = fb.aspects(m, 2, budget=0)
    for mode in ("+--", None):
        rows = fb.locate(m, pose=(5, 2.7, 8), aspects=found, working_mode=mode).rows()
        argv = ["locate", narrow, "--pose", 5, 2.7, 8, "--depth", 2, "--budget", 0, "-o", tmp_path, "--csv"]
        text = ok(run_cli(*argv, *(("--working-mode", mode) if mode else ()))).stdout
        expected = list(csv.DictReader(text.splitlines()))
        assert len(rows) == len(expected) == (1 if mode else 8)
        for r, e in zip(rows, expected):
            assert r["sheet"]["working_mode"] == e["working_mode"] == (mode or e["working_mode"])
            assert r["class"] == {"working_mode": e["working_mode"], "det_sign": e["det_sign"]}  # no singular pose here
            assert np.allclose(r["joints"], [float(e[f"theta{i}_deg"]) for i in (1, 2, 3)], atol=1e-9)
            assert (r["aspect"] or "") == (int(e["aspect"]) if e["aspect"] else "")


def test_path_in_a_working_mode_as_the_command(narrow, tmp_path):
    m = fb.load(narrow)
    motion = fb.path(m, (5, 2.7, 8), (5.5, 3, 12), depth=5, working_mode="+--")
    ok(run_cli("path", narrow, "--pose", 5, 2.7, 8, "--pose", 5.5, 3, 12, "--working-mode", "+--", "--depth", 5,
               "-o", tmp_path, "--no-plot"))
    rows = csv_rows(tmp_path / "path.csv")
    assert [tuple(map(float, r.values())) for r in rows] == [tuple(r.values()) for r in motion.rows()]
    # without a working mode: which one is not known; the library names its parameter, the CLI its option
    with pytest.raises(fb.InputError, match=r"8 working modes: say which one \(e.g. `working_mode='\+\+\+'`\)"):
        fb.path(m, (5, 2.7, 8), (5.5, 3, 12), depth=5)
    one_line(run_cli("path", narrow, "--pose", 5, 2.7, 8, "--pose", 5.5, 3, 12, "-d", 5, "-o", tmp_path / "no"), 2,
             "Invalid value for --working-mode: an rrr3 pose is reached in 8 working modes: say which one "
             "(e.g. --working-mode +++)")
    with pytest.raises(fb.InputError, match=r"`working_mode`: '\+\+' is not a working mode of this rrr3"):
        fb.locate(m, pose=(5, 2.7, 8), depth=2, working_mode="++")
