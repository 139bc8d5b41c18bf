"""Robustness of every command against bad input and failed writes (issue 5, item 3).

Every command runs through the console script's entry point, `fivebar_cli.cli.main`, in this process
(cli_helpers.run_cli: the very code that turns every error into one line and an exit status), with its
working directory and `-o` in a temporary folder; the one run that needs an address-space limit, and
the end-to-end checks of the entry point, are subprocesses (cli_helpers.run_process). The contract
(docs/formats.md):

- exit status 2 for usage and configuration errors, 1 for any other failure;
- exactly one line on stderr, naming the file (and the field where there is one), never a traceback;
- nothing written on failure: no new file, no temporary file left, an existing good output
  byte-identical.

The cases are independent: they are set up and run by a module fixture, and each parametrized test
only checks one result. test_cli_spaces.py, test_rpr3_cli.py and test_qtfile.py already cover part
of this (bad configs for `workspace`, malformed .qt text in-process); the cases here are the ones
they miss, for every command. A case that shows a bug is a strict xfail whose reason starts with "BUG:".
Interrupted runs (SIGKILL, Ctrl-C) are in test_interrupts.py, the fuzzing of the readers in
test_fuzz_readers.py.
"""

from __future__ import annotations

import os
import random
import re
import shutil
import struct
import subprocess
import sys
import zlib
from concurrent.futures import ThreadPoolExecutor
from dataclasses import dataclass
from pathlib import Path
from typing import Callable

import pytest
from cli_helpers import ENV, PNG_MAGIC, CliResult, check_whole, ok, one_line, run_cli, run_process, snapshot

REPO = Path(__file__).resolve().parents[1]
CONFIGS = REPO / "configs"
GOLDEN = REPO / "tests" / "golden"
M1 = CONFIGS / "m1.yaml"
M2 = CONFIGS / "m2.yaml"
RPR3_EQ = CONFIGS / "rpr3-equilateral.yaml"
RPR3_TABLE1 = CONFIGS / "rpr3-table1.yaml"


def tiny_png() -> bytes:
    """A real 1x1 PNG image (binary garbage for a YAML or .qt reader)."""
    def chunk(kind: bytes, data: bytes) -> bytes:
        return struct.pack(">I", len(data)) + kind + data + struct.pack(">I", zlib.crc32(kind + data))
    return (PNG_MAGIC + chunk(b"IHDR", struct.pack(">IIBBBBB", 1, 1, 8, 2, 0, 0, 0))
            + chunk(b"IDAT", zlib.compress(b"\x00\xff\x00\x00")) + chunk(b"IEND", b""))


PNG_BYTES = tiny_png()
RANDOM_BYTES = b"\xff\xfe" + random.Random(5).randbytes(254)


# ---------------------------------------------------------------- seeds: good outputs of every command


SEED_RUNS = {
    "jointspace": ["jointspace", M1, "--depth", 4],
    "workspace": ["workspace", M1, "--depth", 4],
    "workspace5": ["workspace", M1, "--depth", 5],
    "workspaceM2": ["workspace", M2, "--depth", 4],
    "aspects": ["aspects", M1, "--depth", 6],
    "kratio": ["kratio", M1, "--depths", "2-3"],
    "area": ["rpr3", "area", RPR3_EQ],
    "sweep": ["rpr3", "sweep", RPR3_EQ, "--over", "phi", "--steps", 5],
}
# `rpr3 synthesize configs/rpr3-table1.yaml --no-plot` takes seconds: its outputs are the golden ones
# (`fivebar reproduce` writes them there; test_golden.py checks they are what the command writes).
GOLDEN_SEEDS = {"synthesize": GOLDEN / "rpr3-table1"}


@pytest.fixture(scope="module")
def seeds(tmp_path_factory) -> dict[str, Path]:
    """Good outputs (no figures) of each writing command, copied into the cases' output folders."""
    root = tmp_path_factory.mktemp("seeds")
    for name, args in SEED_RUNS.items():
        ok(run_cli(*args, "-o", name, "--no-plot", "-q", cwd=root))
    for name, folder in GOLDEN_SEEDS.items():
        shutil.copytree(folder, root / name, ignore=shutil.ignore_patterns(".*"))
    return {name: root / name for name in [*SEED_RUNS, *GOLDEN_SEEDS]}


# ---------------------------------------------------------------- cases


@dataclass
class Case:
    args: list
    status: int
    needles: tuple = ()
    check: str = "unchanged"  # unchanged | whole | quiet-or-error | diff-differs | success-or-failure
    memory_limit: bool = False
    cwd: Path | None = None
    before: dict | None = None


@dataclass
class Spec:
    id: str
    make: Callable[[Path, dict], Case]
    bug: str | None = None


DIRECTORY, MISSING = object(), object()


def put(path: Path, content) -> Path:
    if content is DIRECTORY:
        path.mkdir()
    elif content is MISSING:
        pass
    elif isinstance(content, bytes):
        path.write_bytes(content)
    else:
        path.write_bytes(content.encode("utf-8", "surrogatepass"))
    return path


def out_args(*args):
    return [*args, "-o", "out", "--no-plot"]


# command -> (seed copied into ./out, arguments for a CONFIG path)
COMMANDS: dict[str, tuple[str | None, Callable]] = {
    "jointspace": ("jointspace", lambda c: out_args("jointspace", c, "--depth", 4)),
    "workspace": ("workspace", lambda c: out_args("workspace", c, "--depth", 4)),
    "aspects": ("aspects", lambda c: out_args("aspects", c, "--depth", 6)),
    "locate": (None, lambda c: ["locate", c, "--pose", 4, 5, "--depth", 6]),
    "kratio": ("kratio", lambda c: out_args("kratio", c, "--depths", "2-3")),
    "reproduce": ("kratio", lambda c: ["reproduce", "--configs", c.parent, "-o", "out", "--no-plot", "-q"]),
    "rpr3 area": ("area", lambda c: out_args("rpr3", "area", c)),
    "rpr3 sweep": ("sweep", lambda c: out_args("rpr3", "sweep", c, "--over", "phi", "--steps", 5)),
    "rpr3 synthesize": ("synthesize", lambda c: out_args("rpr3", "synthesize", c)),
}


def config_case(name: str, content, *fields: str, status: int = 2, check: str = "unchanged",
                config_file: str = "m1.yaml") -> Callable[[Path, dict], Case]:
    """CONFIG holds `content`; -o points at a folder already holding this command's good outputs."""
    def make(folder: Path, seeds: dict) -> Case:
        seed, build = COMMANDS[name]
        if name == "reproduce":  # the bad file is one of the --configs folder
            shutil.copytree(CONFIGS, folder / "configs")
            cfg = folder / "configs" / config_file
            cfg.unlink()
        else:
            cfg = folder / "cfg.yaml"
        put(cfg, content)
        if seed:
            shutil.copytree(seeds[seed], folder / "out")
        return Case(build(cfg), status, (str(cfg), *fields), check=check)
    return make


FB_LENGTHS = {"L0": "9", "L1": "8", "L2": "5", "L3": "5", "L4": "8"}
DROP = object()


def fb(head: str = "name: M1\ntype: fivebar\n", extra: str = "", **lengths) -> str:
    values = {**FB_LENGTHS, **lengths}
    items = ", ".join(f"{k}: {v}" for k, v in values.items() if v is not DROP)
    return f"{head}lengths: {{{items}}}\n{extra}"


RP_FIELDS = {"base": "{t1: 1.8, t2: 1.2, t3: 1.11}", "k": "0.6", "legs": "{rho_min: 0.2, rho_max: auto}",
             "phi_range": "[100, 165]"}


def rp(head: str = "name: R\ntype: rpr3\n", extra: str = "", **fields) -> str:
    values = {**RP_FIELDS, **fields}
    return head + "".join(f"{k}: {v}\n" for k, v in values.items() if v is not DROP) + extra


FB_TEXT = fb()

# Problems of the file itself (the shared reader); the field is a needle of the error line.
YAML_CASES = [
    ("unclosed-bracket", FB_TEXT.replace("L4: 8}", "L4: 8"), "line"),
    ("bad-indentation", "name: M1\ntype: fivebar\nlengths:\n  L0: 9\n L1: 8\n", "line"),
    ("tab-indentation", "name: M1\ntype: fivebar\nlengths:\n\tL0: 9\n\tL1: 8\n", "line"),
    ("empty", "", "empty"),
    ("whitespace-only", "   \n\n      \n", "empty"),
    ("whitespace-with-tabs", " \t \n\t\n", ""),
    ("random-bytes", RANDOM_BYTES, ""),
    ("png-image", PNG_BYTES, ""),
    ("nul-bytes", b"name: M1\x00\ntype: fivebar\n", ""),
    ("utf16", FB_TEXT.encode("utf-16"), ""),
    ("top-level-list", "- name: M1\n- type: fivebar\n", "top level"),
    ("top-level-number", "42\n", "top level"),
    ("top-level-string", "fivebar\n", "top level"),
    ("two-documents", FB_TEXT + "---\n" + FB_TEXT, "line"),
    ("deep-nesting", "[" * 1000 + "\n", "nesting too deep"),  # deeper than the recursion limit
    ("python-tag", fb(L4="!!python/object/apply:os.system ['true']"), "line"),
    ("directory", DIRECTORY, ""),
    ("missing-file", MISSING, ""),
]

FIVEBAR_FIELD_CASES = [
    ("length-string", fb(L1="eight"), "lengths.L1"),
    ("length-bool", fb(L2="true"), "lengths.L2"),
    ("length-bool-yes", fb(L0="yes"), "lengths.L0"),
    ("length-list", fb(L3="[5]"), "lengths.L3"),
    ("length-mapping", fb(L3="{value: 5}"), "lengths.L3"),
    ("length-null", fb(L4="~"), "lengths.L4"),
    ("length-date", fb(L0="2024-01-01"), "lengths.L0"),
    ("length-zero", fb(L1="0"), "lengths.L1"),
    ("length-minus-zero", fb(L1="-0.0"), "lengths.L1"),
    ("length-negative", fb(L4="-8"), "lengths.L4"),
    ("length-1e400-a-string-in-yaml-1.1", fb(L0="1e400"), "lengths.L0"),
    ("length-1.0e+400-inf", fb(L0="1.0e+400"), "lengths.L0"),
    ("length-nan", fb(L2=".nan"), "lengths.L2"),
    ("length-inf", fb(L3=".inf"), "lengths.L3"),
    ("length-minus-inf", fb(L1="-.inf"), "lengths.L1"),
    ("length-missing", fb(L3=DROP), "lengths.L3"),
    ("lengths-a-number", "name: M1\ntype: fivebar\nlengths: 9\n", "lengths"),
    ("lengths-missing", "name: M1\ntype: fivebar\n", "lengths"),
    ("typo-lenghts", fb().replace("lengths:", "lenghts:"), "lenghts"),
    ("nested-typo-l1", fb().replace("L1:", "l1:"), "lengths.l1"),
    ("nested-unknown-L5", fb(L5="1"), "lengths.L5"),
    ("top-level-unknown-key", fb(extra="joint_limits: [0, 1]\n"), "joint_limits"),
    ("type-missing", fb(head="name: M1\n"), "type"),
    ("type-unknown", fb(head="name: M1\ntype: five-bar\n"), "type"),
    ("type-a-list", fb(head="name: M1\ntype: [fivebar]\n"), "type"),
    ("name-with-slash", fb(head="name: a/b\ntype: fivebar\n"), "name"),
    ("name-a-list", fb(head="name: [M1]\ntype: fivebar\n"), "name"),
    ("name-empty", fb(head="name: ''\ntype: fivebar\n"), "name"),
    ("name-null", fb(head="name: ~\ntype: fivebar\n"), "name"),
]

RPR3_FIELD_CASES = [
    ("t1-string", rp(base="{t1: one, t2: 1.2, t3: 1.11}"), "base.t1"),
    ("t2-bool", rp(base="{t1: 1.8, t2: false, t3: 1.11}"), "base.t2"),
    ("t3-null", rp(base="{t1: 1.8, t2: 1.2, t3: ~}"), "base.t3"),
    ("base-a-list", rp(base="[1.8, 1.2, 1.11]"), "base"),
    ("t1-zero", rp(base="{t1: 0, t2: 1.2, t3: 1.11}"), "base.t1"),
    ("t1-negative", rp(base="{t1: -1.8, t2: 1.2, t3: 1.11}"), "base.t1"),
    ("t3-nan", rp(base="{t1: 1.8, t2: 1.2, t3: .nan}"), "base.t3"),
    ("t2-inf", rp(base="{t1: 1.8, t2: .inf, t3: 1.11}"), "base.t2"),
    ("k-a-list", rp(k="[0.6]"), "k"),
    ("k-bool", rp(k="true"), "k"),
    ("k-nan", rp(k=".nan"), "k"),
    ("k-1.0e+400-inf", rp(k="1.0e+400"), "k"),
    ("legs-a-list", rp(legs="[0.2, 1]"), "legs"),
    ("rho_min-negative", rp(legs="{rho_min: -0.1}"), "legs.rho_min"),
    ("rho_min-inf", rp(legs="{rho_min: .inf}"), "legs.rho_min"),
    ("rho_max-minus-inf", rp(legs="{rho_min: 0.2, rho_max: -.inf}"), "legs.rho_max"),
    ("rho_max-zero", rp(legs="{rho_min: 0.2, rho_max: 0}"), "legs.rho_max"),
    ("rho_max-unknown-word", rp(legs="{rho_min: 0.2, rho_max: automatic}"), "legs.rho_max"),
    ("rho_max-below-rho_min", rp(legs="{rho_min: 0.5, rho_max: 0.3}"), "legs"),
    ("rho_min-missing", rp(legs="{rho_max: 1}"), "legs.rho_min"),
    ("phi_range-nan", rp(phi_range="[100, .nan]"), "phi_range[1]"),
    ("phi_range-string", rp(phi_range="[a, 165]"), "phi_range[0]"),
    ("phi_range-reversed", rp(phi_range="[165, 100]"), "phi_range"),
    ("phi_range-three-values", rp(phi_range="[100, 165, 170]"), "phi_range"),
    ("phi_range-a-number", rp(phi_range="100"), "phi_range"),
    ("phi-and-phi_range", rp(extra="phi: 45\n"), "phi"),
    ("phi-minus-inf", rp(phi_range=DROP, extra="phi: -.inf\n"), "phi"),
    ("base-missing", rp(base=DROP), "base"),
    ("legs-missing", rp(legs=DROP), "legs"),
    ("k-and-platform-missing", rp(k=DROP), "k"),
    ("typo-phi_rnage", rp(phi_range=DROP, extra="phi_rnage: [100, 165]\n"), "phi_rnage"),
    ("nested-typo-rho_mx", rp(legs="{rho_min: 0.2, rho_mx: 1}"), "legs.rho_mx"),
    ("nested-unknown-t4", rp(base="{t1: 1.8, t2: 1.2, t3: 1.11, t4: 1}"), "base.t4"),
    ("platform-missing-t6", rp(k=DROP, extra="platform: {t4: 1.08, t5: 0.72}\n"), "platform.t6"),
    ("platform-bool", rp(k=DROP, extra="platform: {t4: true, t5: 0.72, t6: 0.666}\n"), "platform.t4"),
    ("type-wrong-case", rp(head="name: R\ntype: RPR3\n"), "type"),
]

FIVEBAR_COMMANDS = ["jointspace", "workspace", "aspects", "locate", "kratio", "reproduce"]
RPR3_COMMANDS = ["rpr3 area", "rpr3 sweep", "rpr3 synthesize"]
ALL_CONFIG_COMMANDS = FIVEBAR_COMMANDS + RPR3_COMMANDS
SPECS: list[Spec] = []


def add(id: str, make, bug: str | None = None) -> None:
    assert id not in {s.id for s in SPECS}, id
    SPECS.append(Spec(id, make, bug))


# The shared reader: every case on one command of each family, a rotation of them on the others,
# and the commonest (empty, garbage, a directory) on every command.
_others = [c for c in ALL_CONFIG_COMMANDS if c not in ("aspects", "rpr3 area")]
for _i, (_label, _content, _field) in enumerate(YAML_CASES):
    _on = {"aspects", "rpr3 area", _others[_i % len(_others)], _others[(_i + 3) % len(_others)]}
    if _label in ("empty", "random-bytes", "directory"):
        _on = set(ALL_CONFIG_COMMANDS)
    for _name in sorted(_on, key=ALL_CONFIG_COMMANDS.index):
        add(f"yaml/{_name}/{_label}", config_case(_name, _content, _field))

# Field errors: each case once, the commands of its family in turn (workspace is covered by
# test_cli_spaces.py).
_fb_rotation = ["aspects", "jointspace", "locate", "kratio", "reproduce"]
for _i, (_label, _content, _field) in enumerate(FIVEBAR_FIELD_CASES):
    _name = _fb_rotation[_i % len(_fb_rotation)]
    add(f"field/{_name}/{_label}", config_case(_name, _content, _field))
for _i, (_label, _content, _field) in enumerate(RPR3_FIELD_CASES):
    _name = RPR3_COMMANDS[_i % len(RPR3_COMMANDS)]
    add(f"field/{_name}/{_label}", config_case(_name, _content, _field))

# A config of the other mechanism type (a 3-RPR has a workspace since issue 11: `workspace` paves it;
# aspects over (x, y, phi) and `locate --pose X Y PHI` since issue 19).
for _name in FIVEBAR_COMMANDS:
    if _name not in ("workspace", "aspects", "locate"):
        add(f"wrong-type/{_name}", config_case(_name, RPR3_TABLE1.read_text(), "type"))
for _name in RPR3_COMMANDS:
    add(f"wrong-type/{_name}", config_case(_name, M1.read_text(), "type"))

# A bad file found half-way through `reproduce` (steps 1-9 have written their outputs, which stay whole):
# the first file of the constrained steps, read at step 10 (the cheapest mid-run point).
add("reproduce/bad-config-mid-run",
    config_case("reproduce", fb(extra="limits:\n  P: [90, -90]\n"), "limits.P", check="whole",
                config_file="m1-passive-limit.yaml"))


def option_case(args: Callable[[Path], list], status: int, *needles: str, seed: str | None = None,
                memory_limit: bool = False, check: str = "unchanged") -> Callable[[Path, dict], Case]:
    def make(folder: Path, seeds: dict) -> Case:
        if seed:
            shutil.copytree(seeds[seed], folder / "out")
        return Case(args(folder), status, needles, check=check, memory_limit=memory_limit)
    return make


# Depths: above the maximum, huge, negative, not an integer.
DEPTHS = ["21", "1000000000", "-1", "2.5", "", "1e3", "ten"]
for _value in DEPTHS:
    add(f"depth/aspects/{_value!r}", option_case(lambda f, v=_value: out_args("aspects", M1, f"--depth={v}"),
                                                  2, "--depth", seed="aspects"))
    add(f"depth/locate/{_value!r}", option_case(lambda f, v=_value: ["locate", M1, "--pose", 4, 5, f"--depth={v}"],
                                                 2, "--depth"))
    add(f"depth/refine/{_value!r}", option_case(
        lambda f, v=_value: ["refine", f / "out" / "workspace.qt", f"--depth={v}", "--no-plot"], 2, "--depth",
        seed="workspace"))
for _value in ("1000000000", "2.5", "1e3"):
    add(f"depth/workspace/{_value!r}", option_case(lambda f, v=_value: out_args("workspace", M1, f"--depth={v}"),
                                                    2, "--depth", seed="workspace"))
for _value in ("21", "0-21", "5-", "x", "1-2-3", "-1", "10-5", "1,,2", "99999999999999999999"):
    add(f"depths/kratio/{_value!r}", option_case(lambda f, v=_value: out_args("kratio", M1, f"--depths={v}"),
                                                  2, "--depths", seed="kratio"))
add("depths/kratio/'1-1000000000'", option_case(
    lambda f: out_args("kratio", M1, "--depths=1-1000000000"), 2, "--depths", seed="kratio", memory_limit=True))
for _value in ("1", "1000000000", "-1", "2.5", "many"):
    add(f"steps/rpr3 sweep/{_value!r}", option_case(
        lambda f, v=_value: out_args("rpr3", "sweep", RPR3_EQ, "--over", "phi", f"--steps={v}"), 2, "--steps",
        seed="sweep"))
for _over, _option, _value in (("phi", "--range", "10 inf"), ("rho_min", "--range", "0 inf"),
                               ("t2", "--angles", "nan"), ("t2", "--angles", "inf")):
    _extra = ["--range", *_value.split()] if _option == "--range" else ["--angles", _value]
    add(f"options/rpr3 sweep/--over {_over} {_option} {_value}", option_case(
        lambda f, o=_over, e=_extra: out_args("rpr3", "sweep", RPR3_EQ, "--over", o, *e), 2, _option, seed="sweep"))

# Numbers a config accepts but the computation cannot handle.
_HUGE = fb(**{k: "1.0e+300" for k in FB_LENGTHS})
for _name in ("jointspace", "workspace", "aspects", "locate", "kratio"):
    add(f"huge-lengths/{_name}", config_case(_name, _HUGE, "lengths"))
_BIG_INT = "1" + "0" * 400
add("big-integer/workspace", config_case("workspace", fb(L0=_BIG_INT), "lengths.L0"))
add("big-integer/rpr3 area", config_case("rpr3 area", rp(phi_range=f"[{_BIG_INT}, {_BIG_INT}1]"), "phi_range"))
add("huge-integer/aspects", config_case("aspects", fb(L0="1" + "0" * 5000), "lengths.L0"))
add("huge-base/rpr3 area", config_case("rpr3 area", rp(base="{t1: 1.0e+300, t2: 1.2, t3: 1.0e+300}"), "base"))
add("huge-k/rpr3 area", config_case("rpr3 area", rp(k="1.0e+300"), "k", check="quiet-or-error"))
add("huge-rho_min/rpr3 sweep", config_case("rpr3 sweep", rp(legs="{rho_min: 1.0e+300}"), "rho_min",
                                           check="quiet-or-error"))
add("surrogate-name/workspace", config_case("workspace", fb(head='name: "\\ud800"\ntype: fivebar\n'), "name"))
add("newline-in-key/aspects", config_case("aspects", fb(extra='"lengths\\nL5": 1\n'), "unknown key"))
add("carriage-return-in-key/rpr3 area", config_case("rpr3 area", rp(legs='{rho_min: 0.2, "rho\\rmax": 1}'),
                                                    "unknown key"))

# Other failures (status 1): aspects too shallow to match every component (or success); the line
# names the problem.
add("too-shallow/aspects", option_case(lambda f: out_args("aspects", M1, "--depth", 3), 1, "counterpart",
                                       seed="aspects", check="success-or-failure"))
add("too-shallow/locate", option_case(lambda f: ["locate", M1, "--pose", 4, 5, "--depth", 3], 1, "counterpart",
                                      check="success-or-failure"))

# locate: locations and modes.
for _label, _args, _needle in (
    ("no-location", [], "--pose"),
    ("pose-missing-a-value", ["--pose", "1"], "--pose"),
    ("pose-without-values", ["--pose"], "--pose"),
    ("pose-not-a-number", ["--pose", "x", "1"], "--pose"),
    ("joints-missing-a-value", ["--joints", "0.1"], "--joints"),
    ("unknown-working-mode", ["--pose", "4", "5", "--working-mode", "+*"], "--working-mode"),
    ("unknown-assembly-mode", ["--pose", "4", "5", "--assembly-mode", "0"], "--assembly-mode"),
    ("unknown-option", ["--pose", "4", "5", "--aspect", "1"], "--aspect"),
):
    add(f"locate/{_label}", option_case(lambda f, a=_args: ["locate", M1, *a, "--depth", 6], 2, _needle))
add("locate/config-after-options-missing", option_case(lambda f: ["locate", "--pose", 4, 5], 2, "CONFIG"))


# Output folders: below a regular file (cannot be created, status 1), or a regular file (usage, status 2).
WRITERS = {
    "jointspace": lambda f, o: ["jointspace", M1, "--depth", 4, "-o", o, "--no-plot"],
    "aspects": lambda f, o: ["aspects", M1, "--depth", 6, "-o", o, "--no-plot"],
    "kratio": lambda f, o: ["kratio", M1, "--depths", "2", "-o", o, "--no-plot"],
    "refine": lambda f, o: ["refine", f / "in" / "workspace.qt", "--depth", 5, "-o", o, "--no-plot"],
    "reproduce": lambda f, o: ["reproduce", "--configs", CONFIGS, "-o", o, "--no-plot", "-q"],
    "rpr3 area": lambda f, o: ["rpr3", "area", RPR3_EQ, "-o", o, "--no-plot"],
    "rpr3 sweep": lambda f, o: ["rpr3", "sweep", RPR3_EQ, "--over", "t2", "--steps", 5, "-o", o, "--no-plot"],
    # the one-orientation config: its synthesis takes 0.1 s, Table 1's 0.8 s (computed before the write fails)
    "rpr3 synthesize": lambda f, o: ["rpr3", "synthesize", RPR3_EQ, "-o", o, "--no-plot"],
}


def blocked_case(name: str, below: bool) -> Callable[[Path, dict], Case]:
    def make(folder: Path, seeds: dict) -> Case:
        shutil.copytree(seeds["workspace"], folder / "in")
        blocker = folder / "blocker"
        blocker.write_text("a regular file\n")
        target = blocker / "sub" if below else blocker
        return Case(WRITERS[name](folder, target), 1 if below else 2, (str(target),))
    return make


for _name in WRITERS:
    add(f"out-below-a-file/{_name}", blocked_case(_name, below=True))
    add(f"out-is-a-file/{_name}", blocked_case(_name, below=False))

# An empty name where a path goes (`-o "$OUT"` with OUT unset) is a usage error naming the option,
# not the current folder: nothing is written in the working folder, which '' would otherwise mean.
EMPTY = "an empty name (an unset shell variable?)"
for _name in WRITERS:
    add(f"empty-name/-o/{_name}", option_case(lambda f, n=_name: WRITERS[n](f, ""), 2, "'--out' / '-o'",
                                              EMPTY + "; . is the current folder"))
for _name in ALL_CONFIG_COMMANDS:
    if _name != "reproduce":
        add(f"empty-name/CONFIG/{_name}", option_case(lambda f, n=_name: COMMANDS[n][1](""), 2, "'CONFIG", EMPTY))
for _label, _args, _named in [
    ("reproduce --configs", ["reproduce", "--configs", "", "--no-plot"], "'--configs'"),
    ("refine TREE.qt", ["refine", "", "--depth", 5], "'TREE.qt'"),
    ("view PATH", ["view", ""], "'PATH...'"),
    ("view -o", ["view", CONFIGS, "-o", ""], "'--out' / '-o'"),
    ("examples --copy", ["examples", "--copy", ""], "'--copy'"),
    ("atlas SPEC", ["atlas", "", "--no-plot"], "'SPEC'"),
]:
    add(f"empty-name/{_label}", option_case(lambda f, a=_args: a, 2, _named, EMPTY))


def target_is_folder(name: str, seed: str, args: Callable[[Path], list], target: str) -> Callable[[Path, dict], Case]:
    """One output file of the run is a folder: the run fails (status 1) when it gets there; every other
    file is old or complete, and no temporary file is left."""
    def make(folder: Path, seeds: dict) -> Case:
        shutil.copytree(seeds[seed], folder / "out")
        path = folder / "out" / target
        path.unlink()
        path.mkdir()
        (path / "keep").write_text("a file inside the folder\n")
        return Case(args(folder), 1, (target,), check="whole")
    return make


add("target-is-a-folder/aspects", target_is_folder(
    "aspects", "aspects", lambda f: out_args("aspects", M1, "--depth", 7), "aspects/aspect-03.workspace.qt"))
add("target-is-a-folder/kratio", target_is_folder(
    "kratio", "kratio", lambda f: out_args("kratio", M1, "--depths", "2-4"), "kratio.csv"))
add("target-is-a-folder/refine", target_is_folder(
    "refine", "workspace", lambda f: ["refine", f / "out" / "workspace.qt", "--depth", 6, "--no-plot"],
    "workspace.csv"))
add("target-is-a-folder/rpr3 area", target_is_folder(
    "rpr3 area", "area", lambda f: out_args("rpr3", "area", RPR3_TABLE1), "area.csv"))
add("target-is-a-folder/rpr3 synthesize", target_is_folder(
    "rpr3 synthesize", "synthesize", lambda f: out_args("rpr3", "synthesize", RPR3_TABLE1),
    "table1-comparison.csv"))


# ---------------------------------------------------------------- corrupted .qt files


def header_end(text: str) -> int:
    """Offset of the first body letter."""
    offset = 0
    for line in text.split("\n"):
        if not line.startswith("#"):
            return offset
        offset += len(line) + 1
    return offset


def cut_mid_body(path: Path) -> None:
    text = path.read_text()
    start = header_end(text)
    path.write_text(text[: start + (len(text) - start) // 2])


def replace_body_letter(path: Path, old: str, new: str, nth: int = 1) -> None:
    text = path.read_text()
    start = header_end(text)
    pos = start - 1
    for _ in range(nth):
        pos = text.index(old, pos + 1)
    path.write_text(text[:pos] + new + text[pos + 1:])


def edit_header(path: Path, key: str, value: str | None) -> None:
    """Replace (or delete, value None) the header line `# key: ...`."""
    lines = path.read_text().split("\n")
    index = next(i for i, line in enumerate(lines) if line.startswith(f"# {key}:"))
    if value is None:
        del lines[index]
    else:
        lines[index] = f"# {key}: {value}"
    path.write_text("\n".join(lines))


def set_body(path: Path, body: str) -> None:
    text = path.read_text()
    path.write_text(text[: header_end(text)] + body + "\n")


def qt_case(kind: str, corrupt: Callable[[Path, Path, dict], Path], *needles: str, status: int = 2,
            check: str = "unchanged") -> Callable[[Path, dict], Case]:
    """A good workspace pair in ./out, corrupted; `corrupt` returns the file the error must name.
    refine reads the pair and would write into its folder; diff compares out/workspace.qt with out/b.qt."""
    def make(folder: Path, seeds: dict) -> Case:
        out = folder / "out"
        shutil.copytree(seeds["workspace"], out)
        shutil.copy(out / "workspace.qt", out / "b.qt")
        named = corrupt(out, folder, seeds)
        if kind == "refine":
            args = ["refine", out / "workspace.qt", "--depth", 6, "--no-plot"]
        else:
            args = ["diff", out / "workspace.qt", out / "b.qt"]
        return Case(args, status, (str(named), *needles), check=check)
    return make


INSIDE, COMPLEMENT = "workspace.qt", "workspace.complement.qt"


def _cut(name):
    def corrupt(out, folder, seeds):
        cut_mid_body(out / name)
        return out / name
    return corrupt


def _letter(name, old, new, nth=3):
    def corrupt(out, folder, seeds):
        replace_body_letter(out / name, old, new, nth)
        return out / name
    return corrupt


def _header(name, key, value, both=False):
    def corrupt(out, folder, seeds):
        for n in ((INSIDE, COMPLEMENT) if both else (name,)):
            edit_header(out / n, key, value)
        return out / name
    return corrupt


def _magic_deleted(name):
    def corrupt(out, folder, seeds):
        path = out / name
        path.write_text(path.read_text().split("\n", 1)[1])
        return path
    return corrupt


def _duplicate_header(name):
    def corrupt(out, folder, seeds):
        lines = (out / name).read_text().split("\n")
        lines.insert(2, lines[1])
        (out / name).write_text("\n".join(lines))
        return out / name
    return corrupt


def _replace(name, source: Callable[[Path, dict], object]):
    def corrupt(out, folder, seeds):
        content = source(out, seeds)
        target = out / name
        if isinstance(content, Path):
            shutil.copy(content, target)
        else:
            target.unlink()
            put(target, content)
        return target
    return corrupt


QT_CASES = [
    ("refine", "inside-cut-mid-body", _cut(INSIDE), ("line",)),
    ("refine", "complement-cut-mid-body", _cut(COMPLEMENT), ("line",)),
    ("refine", "inside-grey-letter-flipped-to-white", _letter(INSIDE, "G", "W"), ("line",)),
    ("refine", "complement-letter-flipped-to-X", _letter(COMPLEMENT, "B", "X"), ("line",)),
    ("refine", "inside-magic-line-deleted", _magic_deleted(INSIDE), ("line 1",)),
    ("refine", "complement-depth-line-deleted", _header(COMPLEMENT, "depth", None), ("depth",)),
    ("refine", "inside-root-line-deleted", _header(INSIDE, "root", None), ("root",)),
    ("refine", "complement-of-a-deeper-run", _replace(COMPLEMENT, lambda o, s: s["workspace5"] / COMPLEMENT), ()),
    ("refine", "complement-of-another-mechanism", _replace(COMPLEMENT, lambda o, s: s["workspaceM2"] / COMPLEMENT),
     ()),
    ("refine", "complement-is-a-copy-of-the-inside", _replace(COMPLEMENT, lambda o, s: o / INSIDE), ("colour",)),
    ("refine", "complement-of-the-joint-space",
     _replace(COMPLEMENT, lambda o, s: s["jointspace"] / "jointspace.complement.qt"), ()),
    ("refine", "mechanism-not-a-number", _header(INSIDE, "mechanism", "fivebar L0=9.0 L1=abc L2=5.0 L3=5.0 L4=8.0",
                                                 both=True), ("mechanism",)),
    ("refine", "mechanism-negative-length", _header(INSIDE, "mechanism", "fivebar L0=-9.0 L1=8.0 L2=5.0 L3=5.0 L4=8.0",
                                                    both=True), ("L0",)),
    ("refine", "mechanism-of-a-3rpr", _header(INSIDE, "mechanism", "rpr3 t1=1", both=True), ("mechanism",)),
    ("refine", "space-relabelled-jointspace", _header(INSIDE, "space", "jointspace", both=True), ()),
    ("refine", "evaluations-not-a-number", _header(INSIDE, "evaluations", "many", both=True), ("evaluations",)),
    ("refine", "inside-empty", _replace(INSIDE, lambda o, s: b""), ()),
    ("refine", "inside-png-image", _replace(INSIDE, lambda o, s: PNG_BYTES), ()),
    ("refine", "inside-is-a-folder", _replace(INSIDE, lambda o, s: DIRECTORY), ()),
    ("diff", "a-cut-mid-body", _cut(INSIDE), ("line",)),
    ("diff", "b-grey-letter-flipped-to-black", _letter("b.qt", "G", "B"), ("line",)),
    ("diff", "b-root-line-deleted", _header("b.qt", "root", None), ("root",)),
    ("diff", "b-depth-too-small-for-the-body", _header("b.qt", "depth", "3"), ("line",)),
    ("diff", "b-duplicated-header-line", _duplicate_header("b.qt"), ("duplicate",)),
    ("diff", "b-root-nan", _header("b.qt", "root", "nan 13.0 -13.0 13.0"), ("root",)),
    ("diff", "a-png-image", _replace(INSIDE, lambda o, s: PNG_BYTES), ()),
    ("diff", "a-nul-bytes", _replace(INSIDE, lambda o, s: b"# fivebar-quadtree 1\x00\n"), ()),
    ("diff", "b-random-bytes", _replace("b.qt", lambda o, s: RANDOM_BYTES), ()),
    ("diff", "b-is-a-folder", _replace("b.qt", lambda o, s: DIRECTORY), ()),
    ("diff", "b-missing", _replace("b.qt", lambda o, s: MISSING), ()),
    ("diff", "b-another-root", _replace("b.qt", lambda o, s: s["jointspace"] / "jointspace.qt"), ("root",)),
]


for _kind, _label, _corrupt, _needles in QT_CASES:
    add(f"qt/{_kind}/{_label}", qt_case(_kind, _corrupt, *_needles))

def _overlapping_pair(out, folder, seeds):
    """The complement claims the whole root box: well-formed, headers matching, but it overlaps the inside."""
    set_body(out / COMPLEMENT, "B")
    return out


add("qt/refine/pair-overlaps", qt_case("refine", _overlapping_pair, "overlap"))
add("qt/diff/b-black-and-white-swapped", qt_case("diff", _letter("b.qt", "B", "W", nth=1), status=1,
                                                 check="diff-differs"))


# ---------------------------------------------------------------- the batch


@pytest.fixture(scope="module")
def batch(seeds, tmp_path_factory) -> dict[str, tuple[Case, CliResult]]:
    """Every case's result: in-process, but the runs under an address-space limit are subprocesses
    (started first, in the background)."""
    root = tmp_path_factory.mktemp("cases")
    cases: dict[str, Case] = {}
    for i, spec in enumerate(SPECS):
        folder = root / f"case{i:03d}"
        folder.mkdir()
        case = spec.make(folder, seeds)
        case.cwd = folder
        case.before = snapshot(folder)
        cases[spec.id] = case
    with ThreadPoolExecutor(2) as pool:
        limited = {key: pool.submit(run_process, *c.args, cwd=c.cwd, memory_limit=True)
                   for key, c in cases.items() if c.memory_limit}
        results = {key: run_cli(*c.args, cwd=c.cwd) for key, c in cases.items() if not c.memory_limit}
        results.update((key, future.result()) for key, future in limited.items())
    return {key: (cases[key], results[key]) for key in cases}


def _param(spec: Spec):
    marks = [pytest.mark.xfail(strict=True, reason=spec.bug)] if spec.bug else []
    return pytest.param(spec.id, id=spec.id, marks=marks)


@pytest.mark.parametrize("case_id", [_param(s) for s in SPECS])
def test_bad_input_one_line_and_nothing_written(batch, case_id):
    case, r = batch[case_id]
    if case.check == "quiet-or-error":  # a clean success is fine too; anything on stderr must be the one line
        if r.status == 0:
            assert r.stderr == "", r.stderr[-2000:]
        else:
            one_line(r, 2, *case.needles)
        return
    if case.check == "success-or-failure":
        if r.status == 0:
            return
        one_line(r, 1, *case.needles)
        assert snapshot(case.cwd) == case.before
        return
    if case.check == "diff-differs":  # a well-formed but different tree: a difference, not an error
        assert r.status == 1 and r.stderr == "" and "only in" in r.stdout, (r.status, r.stderr)
        assert snapshot(case.cwd) == case.before
        return
    one_line(r, case.status, *case.needles)
    if case.check == "unchanged":
        assert snapshot(case.cwd) == case.before, "a failing run changed files"
    else:
        check_whole(case.cwd, case.before, allow_tmp=False)


def test_every_path_a_command_takes_refuses_an_empty_name():
    """Every path parameter of every command (a command added later too) is a `NamedPath`: the
    cases "empty-name/..." above run the ones there are today."""
    import click

    from fivebar_cli.cli import cli
    from fivebar_cli.cli.options import NamedPath

    def paths(command, name):
        ctx = click.Context(command, info_name=name)
        found = [(name, p.name, p.type) for p in command.params if isinstance(p.type, click.Path)]
        if isinstance(command, click.Group):
            for sub in command.list_commands(ctx):
                found += paths(command.get_command(ctx, sub), f"{name} {sub}")
        return found

    found = paths(cli, "fivebar")
    assert len(found) >= 20 and [(c, p) for c, p, t in found if not isinstance(t, NamedPath)] == []


def test_reproduce_failing_mid_run_keeps_the_earlier_outputs(batch):
    """The bad file is read at step 10: the outputs of steps 1-9 are there (and whole, see above)."""
    case, r = batch["reproduce/bad-config-mid-run"]
    out = case.cwd / "out"
    for rel in ("kratio.csv", "M1/workspace.qt", "M2/aspects.csv"):
        assert (out / rel).is_file(), rel
    assert not (out / "M1-passive-limit").exists() and not (out / "rpr3-equilateral").exists()


# ---------------------------------------------------------------- read-only folders (skipped as root)


@pytest.mark.parametrize("name", ["aspects", "kratio", "refine", "rpr3 area"])
def test_read_only_output_folder_exits_1(seeds, tmp_path, name):
    seed = {"aspects": "aspects", "kratio": "kratio", "refine": "workspace", "rpr3 area": "area"}[name]
    out = tmp_path / "out"
    shutil.copytree(seeds[seed], out)
    args = {"aspects": out_args("aspects", M1, "--depth", 6),
            "kratio": out_args("kratio", M1, "--depths", "2-3"),
            "refine": ["refine", out / "workspace.qt", "--depth", 5, "--no-plot"],
            "rpr3 area": out_args("rpr3", "area", RPR3_EQ)}[name]
    before = snapshot(tmp_path)
    folders = [out, *(p for p in out.rglob("*") if p.is_dir())]
    for p in folders:
        os.chmod(p, 0o555)
    try:
        if os.access(out, os.W_OK):
            pytest.skip("directory permissions are not enforced for this user (root)")
        r = run_cli(*args, cwd=tmp_path)
        one_line(r, 1, "out")
        assert snapshot(tmp_path) == before
    finally:
        for p in folders:
            os.chmod(p, 0o755)


# ---------------------------------------------------------------- help, version, unknown commands


HELP = [[], ["rpr3"], ["jointspace"], ["workspace"], ["aspects"], ["locate"], ["atlas"], ["kratio"], ["refine"], ["diff"],
        ["tolerance"], ["view"],
        ["reproduce"], ["rpr3", "area"], ["rpr3", "sweep"], ["rpr3", "synthesize"]]


@pytest.fixture(scope="module")
def help_runs(tmp_path_factory):
    cwd = tmp_path_factory.mktemp("help")
    jobs = [[*h, "--help"] for h in HELP] + [["-h"], ["--version"], ["-V"], ["frobnicate"], ["rpr3", "frobnicate"],
                                             ["--frobnicate"], ["jointspace", "--frobnicate", M1]]
    results = [run_cli(*a, cwd=cwd) for a in jobs]
    assert list(cwd.iterdir()) == []
    return {" ".join(map(str, j)): r for j, r in zip(jobs, results)}


@pytest.mark.parametrize("words", [" ".join(h) for h in HELP])
def test_help_has_an_example(help_runs, words):
    r = help_runs[f"{words} --help".strip()]
    assert r.status == 0 and r.stderr == ""
    assert r.stdout.startswith("Usage: fivebar") and "Example" in r.stdout
    assert f"fivebar {words}".strip() in r.stdout


def test_short_help_and_version(help_runs):
    assert help_runs["-h"].stdout == help_runs["--help"].stdout
    for flag in ("--version", "-V"):
        r = help_runs[flag]
        assert r.status == 0 and r.stderr == ""
        assert re.fullmatch(r"fivebar, version \d+\.\d+\.\d+\S*\n", r.stdout), r.stdout


@pytest.mark.parametrize("words, needle", [("frobnicate", "frobnicate"), ("rpr3 frobnicate", "frobnicate"),
                                           ("--frobnicate", "--frobnicate"),
                                           (f"jointspace --frobnicate {M1}", "--frobnicate")])
def test_unknown_command_or_option(help_runs, words, needle):
    r = help_runs[words]
    one_line(r, 2, needle)
    assert r.stdout == ""


@pytest.mark.parametrize("words, typed, meant", [("aspcts m1", "aspcts", "aspects"), ("exampels", "exampels", "examples"),
                                                 ("rpr3 pavee", "pavee", "pave")])
def test_a_mistyped_command_is_told_the_name_meant(words, typed, meant, monkeypatch):
    """click (from 8.4) offers the close names of a group's commands; the top group imports its
    commands on first use, so it offers every command's name, not only those loaded so far (none
    at the start of a run: emptied here, as in a fresh process)."""
    import click

    from fivebar_cli.cli import cli

    monkeypatch.setattr(cli, "commands", {})
    line = one_line(run_cli(*words.split()), 2, f"No such command '{typed}'.")
    if hasattr(click.exceptions, "NoSuchCommand"):  # (click 8.1-8.3: the line alone)
        assert line.endswith(f"Did you mean '{meant}'?"), line


# ---------------------------------------------------------------- the entry point as a process


def test_python_m_fivebar_cli_writes_what_the_in_process_run_writes(tmp_path):
    """`python -m fivebar_cli`, as users run it: the same report and byte-identical files as `main`
    called in-process (which every other test here uses)."""
    (tmp_path / "process").mkdir(), (tmp_path / "in-process").mkdir()
    args = ["workspace", M2, "--depth", 5, "-o", "out", "--no-plot"]
    process = ok(run_process(*args, cwd=tmp_path / "process"))
    in_process = ok(run_cli(*args, cwd=tmp_path / "in-process"))
    assert process.stdout == in_process.stdout and "wrote out/workspace.qt" in process.stdout
    assert process.stderr == in_process.stderr == ""
    files = snapshot(tmp_path / "process" / "out")
    assert sorted(files) == [".fivebar/workspace.json", "workspace.complement.qt", "workspace.csv", "workspace.qt"]
    assert files == snapshot(tmp_path / "in-process" / "out")


def test_console_script_error_is_one_line_and_exit_2(tmp_path):
    script = Path(sys.executable).parent / "fivebar"
    if not script.is_file():
        pytest.skip(f"no console script next to {sys.executable} (package not installed)")
    r = subprocess.run([script, "jointspace", tmp_path / "missing.yaml", "-o", "out"], cwd=tmp_path, env=ENV,
                       capture_output=True, text=True, timeout=120)
    one_line(CliResult(r.returncode, r.stdout, r.stderr), 2, str(tmp_path / "missing.yaml"))
    assert r.stdout == "" and list(tmp_path.iterdir()) == []
