"""Library messages name the Python parameters (`errors.param`), never a command-line flag; the
command line spells the same messages with its options (`cli/options.as_flags`), word for word as
it always did."""

from __future__ import annotations

import re
from pathlib import Path

import pytest

import fivebar_cli as fb
from fivebar_cli.cli.options import as_flags
from tests.cli_helpers import one_line, run_cli

REPO = Path(__file__).resolve().parent.parent
M1 = REPO / "configs" / "m1.yaml"
FLAG = re.compile(r"(?<![\w-])--?[a-z]")  # --depth, -o; not "det A = 0", "x-axis" or "rho1 = -3"


def raised(call) -> str:
    with pytest.raises(fb.FivebarError) as info:
        call()
    return str(info.value)


# (the library call, the parameter its message names, the CLI run of the same case, its old line)
CASES = [
    (lambda: fb.path(fb.load("m1"), {"pose": (4, 5), "working_mode": "++"}, {"pose": (4, 5), "working_mode": "--"},
                     depth=6),
     "(`allow_serial=True` allows that)",
     ("path", M1, "--pose", 4, 5, "--pose", 4, 5, "--working-mode", "++", "--working-mode", "--", "-d", 6),
     (1, "crosses a serial singularity (--allow-serial allows that)")),
    (lambda: fb.path(fb.load("m1"), {"joints": (0.2213, 0.9416)}, {"joints": (1.5708, 0.9416)}, depth=6),
     "M1: `assembly_mode`: joints (0.2213, 0.9416) assembles in both assembly modes: give `assembly_mode` + or -",
     ("path", M1, "--joints", 0.2213, 0.9416, "--joints", 1.5708, 0.9416, "-d", 6),
     (2, f"{M1}: --assembly-mode: joints (0.2213, 0.9416) assembles in both assembly modes: "
         "give --assembly-mode + or -")),
    (lambda: fb.load("m1", tolerance=5),
     "m1: `tolerance`: 5 would make L2 reach 0.0",
     ("workspace", M1, "--tolerance", 5, "-d", 2, "--no-plot", "-o", "out"),
     (2, f"{M1}: --tolerance: 5.0 would make L2 reach 0.0: lengths must stay positive")),
]


@pytest.mark.parametrize("call, named, argv, old", CASES)
def test_library_names_parameters_and_cli_its_options(call, named, argv, old, tmp_path):
    message = raised(call)
    assert named in message and not FLAG.search(message), message
    one_line(run_cli(*argv, cwd=tmp_path), *old)


def test_uncertified_headline_names_parameters():
    a = fb.aspects(fb.load("m1"), 3)
    assert not a.certified
    assert a.headline.endswith("undecided (raise `depth` or `budget`)") and not FLAG.search(a.headline)
    assert as_flags(a.headline).endswith("undecided (raise --depth or --budget)")


def test_as_flags_spells_every_form():
    assert as_flags("try `depth=12`; `depth=20` is the deepest") == "try --depth 12; --depth 20 is the deepest"
    assert as_flags("(use `procedure='exact'`), `sets_only=True`, another `folder`") == \
        "(use --procedure exact), --sets-only, another -o"
    assert as_flags("`range`: bad", {"range": "--range"}) == "--range: bad"
    assert as_flags("the run of `workspace` and `fivebar aspects`") == "the run of `workspace` and `fivebar aspects`"
