"""Library messages name the Python parameters (`errors.param`), never a command-line flag; the
command line spells the same messages with its options (`cli/options.as_flags`), word for word as
it always did, and rewrites nothing else: a mechanism's name or a path that looks like a
parameter (`depth`) is printed as it is."""

from __future__ import annotations

import pickle
import re
from pathlib import Path

import pytest

import fivebar_cli as fb
from fivebar_cli.cli.options import as_flags
from fivebar_cli.errors import Param, Text, param
from tests.cli_helpers import one_line, run_cli

REPO = Path(__file__).resolve().parent.parent
M1 = REPO / "configs" / "m1.yaml"
TABLE1 = REPO / "configs" / "rpr3-table1.yaml"
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
    deepest = "try " + param("depth", 12) + "; " + param("depth", 20) + " is the deepest"
    assert isinstance(deepest, Text) and deepest == "try `depth=12`; `depth=20` is the deepest"
    assert as_flags(deepest) == "try --depth 12; --depth 20 is the deepest"
    advice = "(use " + param("procedure", "exact") + "), " + param("sets_only", True) + ", another " + param("folder")
    assert advice == "(use `procedure='exact'`), `sets_only=True`, another `folder`"
    assert as_flags(advice) == "(use --procedure exact), --sets-only, another -o"
    assert as_flags(param("range") + ": bad", {"range": "--range"}) == "--range: bad"
    assert as_flags("the run of " + param("workspace")) == "the run of `workspace`"  # no option: as the library says
    assert as_flags("`depth` and `depth=12`, typed by a user") == "`depth` and `depth=12`, typed by a user"


def test_text_keeps_its_parameters_as_data():
    text = "M1 `depth`: raise " + param("depth")
    assert text.parts == ("M1 `depth`: raise ", Param("depth"))
    assert pickle.loads(pickle.dumps(text)).parts == text.parts  # errors cross process boundaries
    assert str(fb.FivebarError(text)) == "M1 `depth`: raise `depth`"
    assert as_flags(text) == "M1 `depth`: raise --depth"
    with pytest.raises(AttributeError):
        text.parts = ()


@pytest.fixture(scope="module")
def named(tmp_path_factory):
    """M1 under other names that look like parameters, and M1 in a folder named like one."""
    folder = tmp_path_factory.mktemp("named")
    text = M1.read_text()
    for name in ("`depth`", "`depth=3`"):
        (folder / f"{name.strip('`')}.yaml").write_text(text.replace("name: M1", f'name: "{name}"'))
    (folder / "`depth=3`").mkdir()
    (folder / "`depth=3`" / "m1.yaml").write_text(text)
    (folder / "table1.yaml").write_text(TABLE1.read_text().replace("name: rpr3-table1", 'name: "raise the depth"'))
    return folder


def test_cli_never_rewrites_a_name_or_a_path(named):
    """What a name or a path holds is printed as it is: the lines are M1's with its name replaced."""
    workspace = ("workspace", "-d", 4, "--no-plot", "-o")
    m1 = run_cli(*workspace, "m1", M1, cwd=named).stdout.splitlines()
    assert m1[0].startswith("M1 workspace, depth 4 ")
    lines = run_cli(*workspace, "`depth`/out", "depth.yaml", cwd=named).stdout.splitlines()
    assert lines == [m1[0].replace("M1", "`depth`", 1)] + [line.replace("m1/", "`depth`/out/") for line in m1[1:]]
    aspects = ("aspects", "-d", 3, "--no-plot", "-o")
    m1 = run_cli(*aspects, "m1", M1, cwd=named).stdout.splitlines()[0]
    assert m1.startswith("M1: between ") and m1.endswith(" undecided (raise --depth or --budget)")
    assert run_cli(*aspects, "d3", "depth=3.yaml", cwd=named).stdout.splitlines()[0] == "`depth=3`" + m1[2:]
    config = Path("`depth=3`") / "m1.yaml"
    assert one_line(run_cli("workspace", config, "--tolerance", 5, cwd=named), 2) == \
        f"fivebar: error: {config}: --tolerance: 5.0 would make L2 reach 0.0: lengths must stay positive"
    verify = run_cli("rpr3", "verify", "table1.yaml", "-d", 3, "-o", "v", cwd=named)  # undecided: exit 3
    assert verify.status == 3 and verify.stdout.startswith("raise the depth: legs ")
    assert verify.stdout.splitlines()[2].endswith(" at depth 3: raise --depth")


def test_library_spelling_of_names_and_paths(named):
    """The library's own text: the name and the path as they are, the parameters in backticks."""
    headline = fb.aspects(fb.load(named / "depth=3.yaml"), 3).headline
    assert headline.startswith("`depth=3`: between ") and headline.endswith(" (raise `depth` or `budget`)")
    config = named / "`depth=3`" / "m1.yaml"
    assert raised(lambda: fb.load(config, tolerance=5)) == \
        f"{config}: `tolerance`: 5 would make L2 reach 0.0: lengths must stay positive"
    notes = fb.rpr3.verify(named / "table1.yaml", 3).notes
    assert notes[0].startswith("raise the depth: legs ") and notes[2].endswith(" at depth 3: raise `depth`")


def test_both_verify_commands_advise_depth_from_the_one_library_line(tmp_path):
    """`fivebar verify` and `fivebar rpr3 verify` print the library's undecided line (one owner:
    `VerifyResult.undecided_line`), the parameter as data: `depth` in Python, --depth on the line."""
    from fivebar_cli.analyses.pose_verify import verify

    config = REPO / "configs" / "rpr3-verify" / "table1-legs-1-1.5.yaml"
    result = verify(fb.load(config), 2)
    line = result.undecided_line()
    assert result.status == "undecided" and 0 < result.undecided_volume < result.root_volume
    assert isinstance(line, Text) and line.endswith(": raise `depth`") and not FLAG.search(line)
    expected = f"  undecided volume {result.undecided_volume:.6g} of {result.root_volume:.6g} at depth 2: raise --depth"
    for argv in (("verify",), ("rpr3", "verify")):
        r = run_cli(*argv, config, "--depth", 2, "-o", tmp_path / "-".join(argv), "--no-plot")
        assert r.status == 3 and expected in r.stdout.splitlines(), r.stdout
        assert f"undecided (depth 2 of 2, {result.evaluations} boxes tested)" in r.stdout


def test_a_target_that_is_not_a_file_names_no_flag_in_the_library(tmp_path):
    """A FIFO where an output goes: the library's error says what it is (`NotARegularFile`, no flag);
    the command line adds its way around it, `-o -` (standard output)."""
    import os

    from fivebar_cli.errors import NotARegularFile

    folder = tmp_path / "out"
    folder.mkdir()
    os.mkfifo(folder / "workspace.csv")
    with pytest.raises(NotARegularFile) as info:
        fb.pave(fb.load("m1"), "workspace", 2).save(folder)
    assert str(info.value) == f"{folder / 'workspace.csv'}: is a FIFO (named pipe), not a regular file: not replaced"
    line = one_line(run_cli("workspace", M1, "-d", 2, "--no-plot", "-o", "out", cwd=tmp_path), 1)
    assert line == ("fivebar: error: out/workspace.csv: is a FIFO (named pipe), not a regular file: not replaced "
                    "(-o - writes a single-file output to standard output)")
    assert (folder / "workspace.csv").is_fifo()
