"""Robustness of every command against bad input, failed writes and interrupted runs (issue 5, item 3).

Every command runs as a user runs it: `python -m fivebar_cli ...` in a subprocess, with its working
directory and `-o` in a temporary folder. The contract (DESIGN.md):

- exit status 2 for usage and configuration errors, 1 for any other failure;
- exactly one line on stderr, naming the file (and the field where there is one), never a traceback;
- nothing written on failure: no new file, no temporary file left, an existing good output
  byte-identical; an interrupted run leaves every output either in its old version or complete.

The subprocess cases are independent: they are set up and started together (a pool of WORKERS)
by module fixtures, and each parametrized test only checks one result. test_cli_spaces.py,
test_rpr3_cli.py and test_qtfile.py already cover part of this (bad configs for `workspace`,
malformed .qt text in-process); the cases here are the ones they miss, for every command.
A case that shows a bug is a strict xfail whose reason starts with "BUG:".

After SIGKILL, temporary files named `.<output name>.<random>.tmp` may remain next to the outputs
(the atomic writer had no chance to remove them); they are the only leftovers allowed, and a later
run does not clean them up.
"""

from __future__ import annotations

import copy
import math
import os
import random
import re
import shutil
import signal
import struct
import subprocess
import sys
import time
import zlib
from concurrent.futures import ThreadPoolExecutor
from dataclasses import dataclass
from pathlib import Path
from typing import Callable

import pytest
import yaml
from hypothesis import HealthCheck, example, given, settings
from hypothesis import strategies as st

from fivebar_cli.errors import InputError
from fivebar_cli.io.qtfile import MAGIC, WRAP, format_qt, parse_qt, read_qt
from fivebar_cli.io.schema import ConfigError
from fivebar_cli.mechanisms.fivebar.model import FiveBar
from fivebar_cli.mechanisms.registry import load_config
from fivebar_cli.mechanisms.rpr3.model import Rpr3

REPO = Path(__file__).resolve().parents[1]
CONFIGS = REPO / "configs"
M1 = CONFIGS / "m1.yaml"
M2 = CONFIGS / "m2.yaml"
RPR3_EQ = CONFIGS / "rpr3-equilateral.yaml"
RPR3_TABLE1 = CONFIGS / "rpr3-table1.yaml"
WORKERS = 4
MEMORY_LIMIT = 3 << 30  # address-space cap for cases that could otherwise exhaust the machine
ENV = {k: v for k, v in os.environ.items() if k != "FIVEBAR_DEBUG"}
ENV.update(PYTHONPATH=str(REPO), MPLBACKEND="Agg")

PNG_MAGIC = b"\x89PNG\r\n\x1a\n"
PNG_END = b"IEND\xaeB`\x82"
TMP_NAME = re.compile(r"^\.(?P<target>.+)\.[A-Za-z0-9_]+\.tmp$")  # files.atomic_write: .<name>.<hex>.tmp


def tiny_png() -> bytes:
    """A real 1x1 PNG image (binary garbage for a YAML or .qt reader)."""
    def chunk(kind: bytes, data: bytes) -> bytes:
        return struct.pack(">I", len(data)) + kind + data + struct.pack(">I", zlib.crc32(kind + data))
    return (PNG_MAGIC + chunk(b"IHDR", struct.pack(">IIBBBBB", 1, 1, 8, 2, 0, 0, 0))
            + chunk(b"IDAT", zlib.compress(b"\x00\xff\x00\x00")) + chunk(b"IEND", b""))


PNG_BYTES = tiny_png()
RANDOM_BYTES = b"\xff\xfe" + random.Random(5).randbytes(254)


# ---------------------------------------------------------------- running the command line


def command(args, memory_limit: bool = False) -> list[str]:
    args = [str(a) for a in args]
    if not memory_limit:
        return [sys.executable, "-m", "fivebar_cli", *args]
    code = ("import resource, runpy, sys; resource.setrlimit(resource.RLIMIT_AS, (%d, %d)); "
            "runpy.run_module('fivebar_cli', run_name='__main__', alter_sys=True)" % (MEMORY_LIMIT, MEMORY_LIMIT))
    return [sys.executable, "-c", code, *args]


def run(args, cwd: Path, memory_limit: bool = False, timeout: float = 180) -> subprocess.CompletedProcess:
    return subprocess.run(command(args, memory_limit), cwd=cwd, env=ENV, capture_output=True, text=True,
                          timeout=timeout)


def run_ok(args, cwd: Path) -> subprocess.CompletedProcess:
    r = run(args, cwd)
    assert r.returncode == 0, (args, r.stderr)
    return r


def one_line(r: subprocess.CompletedProcess, status: int, *needles: str) -> str:
    """The failure contract: this status, no traceback, exactly one line on stderr holding every needle."""
    assert "Traceback" not in r.stderr and "Traceback" not in r.stdout, r.stderr[-2000:]
    assert r.returncode == status, (r.returncode, r.stderr[-2000:])
    lines = r.stderr.splitlines()
    assert len(lines) == 1, f"expected one line on stderr, got {len(lines)}: {r.stderr[-2000:]!r}"
    for needle in needles:
        assert needle in lines[0], (needle, lines[0])
    return lines[0]


def snapshot(folder: Path) -> dict[str, bytes]:
    """Every file below `folder` (relative path -> bytes); empty folders do not count."""
    return {p.relative_to(folder).as_posix(): p.read_bytes() for p in sorted(folder.rglob("*")) if p.is_file()}


def problem_with(path: Path, old: bytes | None) -> str | None:
    """None when `path` is whole: its old bytes, or a complete new file of its kind."""
    data = path.read_bytes()
    if old is not None and data == old:
        return None
    name = path.name
    if name.endswith(".qt"):
        try:
            read_qt(path)
        except InputError as exc:
            return f"not a whole .qt file: {exc}"
    elif name.endswith(".csv"):
        text = data.decode("utf-8", "replace")
        if not text.endswith("\n"):
            return "CSV cut short (no final newline)"
        lines = text.split("\n")[:-1]
        if not lines:
            return "empty CSV"
        if old is not None and lines[0] != old.decode().split("\n")[0]:
            return f"CSV header changed: {lines[0]!r}"
        width = lines[0].count(",")
        short = [i for i, line in enumerate(lines) if line.count(",") != width]
        if short:
            return f"CSV rows {short} do not have {width + 1} cells"
    elif name.endswith(".png"):
        if not (data.startswith(PNG_MAGIC) and data.endswith(PNG_END)):
            return "PNG cut short"
    return None


def check_whole(folder: Path, before: dict[str, bytes], allow_tmp: bool) -> list[str]:
    """Every file is old or complete, none disappeared; returns the temporary leftovers."""
    after = sorted(p for p in folder.rglob("*") if p.is_file())
    names = {p.relative_to(folder).as_posix() for p in after}
    missing = [rel for rel in before if rel not in names]
    assert not missing, f"outputs disappeared: {missing}"
    problems, leftovers = [], []
    for path in after:
        rel = path.relative_to(folder).as_posix()
        match = TMP_NAME.match(path.name)
        if match and rel not in before:
            leftovers.append(rel)
            continue
        problem = problem_with(path, before.get(rel))
        if problem:
            problems.append(f"{rel}: {problem}")
    assert not problems, problems
    if not allow_tmp:
        assert not leftovers, f"temporary files left: {leftovers}"
    return leftovers


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
    "synthesize": ["rpr3", "synthesize", RPR3_TABLE1],
}


@pytest.fixture(scope="module")
def seeds(tmp_path_factory) -> dict[str, Path]:
    """Good outputs (no figures) of each writing command, copied into the cases' output folders."""
    root = tmp_path_factory.mktemp("seeds")
    with ThreadPoolExecutor(WORKERS) as pool:
        list(pool.map(lambda kv: run_ok([*kv[1], "-o", kv[0], "--no-plot", "-q"], root), SEED_RUNS.items()))
    return {name: root / name for name in SEED_RUNS}


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
    slow: bool = False


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
    ("deep-nesting", "[" * 5000 + "\n", ""),
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


def add(id: str, make, bug: str | None = None, slow: bool = False) -> None:
    assert id not in {s.id for s in SPECS}, id
    SPECS.append(Spec(id, make, bug, slow))


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

# A config of the other mechanism type (a 3-RPR has a workspace since issue 11: `workspace` paves it).
for _name in FIVEBAR_COMMANDS:
    if _name != "workspace":
        add(f"wrong-type/{_name}", config_case(_name, RPR3_TABLE1.read_text(), "type"))
for _name in RPR3_COMMANDS:
    add(f"wrong-type/{_name}", config_case(_name, M1.read_text(), "type"))

# A bad file found half-way through `reproduce` (steps 1-7 have written their outputs, which stay whole).
add("reproduce/bad-rpr3-config-mid-run",
    config_case("reproduce", rp(phi_range=DROP, extra="phi: 180\n"), "phi", check="whole",
                config_file="rpr3-equilateral.yaml"), slow=True)


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

# Other failures (status 1): aspects too shallow to match every component (or success).
add("too-shallow/aspects", option_case(lambda f: out_args("aspects", M1, "--depth", 4), 1, seed="aspects",
                                       check="success-or-failure"))
add("too-shallow/locate", option_case(lambda f: ["locate", M1, "--pose", 4, 5, "--depth", 4], 1,
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
    "rpr3 synthesize": lambda f, o: ["rpr3", "synthesize", RPR3_TABLE1, "-o", o, "--no-plot"],
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
    "table1-comparison.csv"), slow=True)


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
def batch(seeds, tmp_path_factory) -> dict[str, tuple[Case, subprocess.CompletedProcess]]:
    root = tmp_path_factory.mktemp("cases")
    cases: dict[str, Case] = {}
    for i, spec in enumerate(sorted(SPECS, key=lambda s: not s.slow)):  # the slow ones first
        folder = root / f"case{i:03d}"
        folder.mkdir()
        case = spec.make(folder, seeds)
        case.cwd = folder
        case.before = snapshot(folder)
        cases[spec.id] = case
    with ThreadPoolExecutor(WORKERS) as pool:
        futures = {key: pool.submit(run, c.args, c.cwd, c.memory_limit) for key, c in cases.items()}
        return {key: (cases[key], futures[key].result()) for key in cases}


def _param(spec: Spec):
    marks = [pytest.mark.xfail(strict=True, reason=spec.bug)] if spec.bug else []
    return pytest.param(spec.id, id=spec.id, marks=marks)


@pytest.mark.parametrize("case_id", [_param(s) for s in SPECS])
def test_bad_input_one_line_and_nothing_written(batch, case_id):
    case, r = batch[case_id]
    if case.check == "quiet-or-error":  # a clean success is fine too; anything on stderr must be the one line
        if r.returncode == 0:
            assert r.stderr == "", r.stderr[-2000:]
        else:
            one_line(r, 2, *case.needles)
        return
    if case.check == "success-or-failure":
        if r.returncode == 0:
            return
        one_line(r, 1, *case.needles)
        assert snapshot(case.cwd) == case.before
        return
    if case.check == "diff-differs":  # a well-formed but different tree: a difference, not an error
        assert r.returncode == 1 and r.stderr == "" and "only in" in r.stdout, (r.returncode, r.stderr)
        assert snapshot(case.cwd) == case.before
        return
    one_line(r, case.status, *case.needles)
    if case.check == "unchanged":
        assert snapshot(case.cwd) == case.before, "a failing run changed files"
    else:
        check_whole(case.cwd, case.before, allow_tmp=False)


def test_reproduce_failing_mid_run_keeps_the_earlier_outputs(batch):
    """The bad file is read at step 8: the outputs of steps 1-7 are there (and whole, see above)."""
    case, r = batch["reproduce/bad-rpr3-config-mid-run"]
    out = case.cwd / "out"
    for rel in ("kratio.csv", "M1/workspace.qt", "M2/aspects.csv"):
        assert (out / rel).is_file(), rel
    assert not (out / "rpr3-equilateral").exists()


def test_every_command_is_covered():
    ids = [s.id for s in SPECS]
    for name in ALL_CONFIG_COMMANDS:
        assert sum(f"/{name}/" in i for i in ids) >= 10, name
    for name in ("refine", "diff", "locate"):
        assert sum(i.startswith(f"qt/{name}/") or f"/{name}/" in i or i.startswith(f"{name}/") for i in ids) >= 8, name


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
        r = run(args, tmp_path)
        one_line(r, 1, "out")
        assert snapshot(tmp_path) == before
    finally:
        for p in folders:
            os.chmod(p, 0o755)


# ---------------------------------------------------------------- help, version, unknown commands


HELP = [[], ["rpr3"], ["jointspace"], ["workspace"], ["aspects"], ["locate"], ["kratio"], ["refine"], ["diff"],
        ["reproduce"], ["rpr3", "area"], ["rpr3", "sweep"], ["rpr3", "synthesize"]]


@pytest.fixture(scope="module")
def help_runs(tmp_path_factory):
    cwd = tmp_path_factory.mktemp("help")
    jobs = [[*h, "--help"] for h in HELP] + [["-h"], ["--version"], ["-V"], ["frobnicate"], ["rpr3", "frobnicate"],
                                             ["--frobnicate"], ["jointspace", "--frobnicate", M1]]
    with ThreadPoolExecutor(WORKERS) as pool:
        results = list(pool.map(lambda a: run(a, cwd), jobs))
    assert list(cwd.iterdir()) == []
    return {" ".join(map(str, j)): r for j, r in zip(jobs, results)}


@pytest.mark.parametrize("words", [" ".join(h) for h in HELP])
def test_help_has_an_example(help_runs, words):
    r = help_runs[f"{words} --help".strip()]
    assert r.returncode == 0 and r.stderr == ""
    assert r.stdout.startswith("Usage: fivebar") and "Example" in r.stdout
    assert f"fivebar {words}".strip() in r.stdout


def test_short_help_and_version(help_runs):
    assert help_runs["-h"].stdout == help_runs["--help"].stdout
    for flag in ("--version", "-V"):
        r = help_runs[flag]
        assert r.returncode == 0 and r.stderr == ""
        assert re.fullmatch(r"fivebar, version \d+\.\d+\.\d+\S*\n", r.stdout), r.stdout


@pytest.mark.parametrize("words, needle", [("frobnicate", "frobnicate"), ("rpr3 frobnicate", "frobnicate"),
                                           ("--frobnicate", "--frobnicate"),
                                           (f"jointspace --frobnicate {M1}", "--frobnicate")])
def test_unknown_command_or_option(help_runs, words, needle):
    r = help_runs[words]
    one_line(r, 2, needle)
    assert r.stdout == ""


# ---------------------------------------------------------------- interrupted runs


@dataclass
class Interrupted:
    returncode: int
    stdout: str
    stderr: str
    fired: bool
    elapsed: float


def temporaries(folder: Path) -> set[str]:
    found = set()
    for root, _, names in os.walk(folder):
        found.update(os.path.join(root, n) for n in names if n.endswith(".tmp"))
    return found


def interrupt(args, cwd: Path, watch: Path, trigger: tuple[str, float], sig: int) -> Interrupted:
    """Run, and send `sig` at the trigger: ("time", seconds), ("tmp", n) once n temporary files have been
    seen (the run is then writing an output), ("png", n) the same for figures."""
    kind, value = trigger
    start = time.monotonic()
    proc = subprocess.Popen(command(args), cwd=cwd, env=ENV, stdout=subprocess.PIPE, stderr=subprocess.PIPE,
                            text=True)
    seen: set[str] = set()
    fired = False
    try:
        while proc.poll() is None and time.monotonic() - start < 120:
            if kind == "time":
                if time.monotonic() - start >= value:
                    break
            else:
                seen |= {t for t in temporaries(watch) if kind == "tmp" or ".png." in t}
                if len(seen) >= value:
                    break
            time.sleep(0.001)
        if proc.poll() is None:
            proc.send_signal(sig)
            fired = True
        out, err = proc.communicate(timeout=120)
    finally:
        if proc.poll() is None:
            proc.kill()
            proc.communicate()
    return Interrupted(proc.returncode, out, err, fired, time.monotonic() - start)


ASPECT_TRIGGERS = [("tmp", 1), ("tmp", 6), ("png", 1), ("time", 0.4), ("time", 2.5)]
REPRODUCE_TRIGGERS = [("tmp", 1), ("png", 2), ("time", 2.5)]


@pytest.fixture(scope="module")
def killed_aspects(tmp_path_factory):
    """`aspects --depth 12` (with figures) SIGKILLed while it replaces the outputs of a depth-6 run."""
    root = tmp_path_factory.mktemp("killed-aspects")
    run_ok(["aspects", M1, "--depth", 6, "-o", "old", "-q"], root)
    before = snapshot(root / "old")

    def one(i_trigger):
        i, trigger = i_trigger
        folder = root / f"run{i}"
        shutil.copytree(root / "old", folder)
        result = interrupt(["aspects", M1, "--depth", 12, "-o", folder, "-q"], root, folder, trigger, signal.SIGKILL)
        return trigger, folder, result

    with ThreadPoolExecutor(2) as pool:
        return before, list(pool.map(one, enumerate(ASPECT_TRIGGERS)))


@pytest.mark.parametrize("index", range(len(ASPECT_TRIGGERS)), ids=[f"{k}-{v}" for k, v in ASPECT_TRIGGERS])
def test_sigkill_during_aspects_leaves_old_or_complete_files(killed_aspects, index):
    before, results = killed_aspects
    trigger, folder, r = results[index]
    if trigger in (("tmp", 1), ("time", 0.4), ("time", 2.5)):
        assert r.fired, f"the run ended before the {trigger} trigger ({r.elapsed:.1f} s)"
    if r.fired:
        assert r.returncode == -signal.SIGKILL
    else:
        assert r.returncode == 0, r.stderr
    assert "Traceback" not in r.stderr
    leftovers = check_whole(folder, before, allow_tmp=True)
    for rel in leftovers:  # a leftover is the temporary copy of a real output, next to it
        target = (folder / rel).parent / TMP_NAME.match(Path(rel).name)["target"]
        assert target.relative_to(folder).as_posix() in before or target.exists(), rel


def test_sigkill_keeps_the_old_trees_until_replaced(killed_aspects):
    """Every aspect tree after a kill is the depth-6 one or the depth-12 one, never anything else; and the
    kills did hit writes in progress: their temporary files are still there (nothing removes them later)."""
    before, results = killed_aspects
    depths, leftovers = set(), []
    for _, folder, _ in results:
        for path in (folder / "aspects").glob("*.qt"):
            depths.add(read_qt(path).tree.grid.depth)
        leftovers += check_whole(folder, before, allow_tmp=True)
    assert depths <= {6, 12} and 6 in depths
    assert leftovers, "no kill happened while an output was being written"


@pytest.fixture(scope="module")
def killed_reproduce(tmp_path_factory):
    """`reproduce` (with figures) SIGKILLed while it rewrites a copy of the golden outputs (tests/golden)."""
    root = tmp_path_factory.mktemp("killed-reproduce")
    old = root / "old"
    shutil.copytree(REPO / "tests" / "golden", old, ignore=shutil.ignore_patterns(".*"))
    before = snapshot(old)

    def one(i_trigger):
        i, trigger = i_trigger
        folder = root / f"run{i}"
        shutil.copytree(old, folder)
        result = interrupt(["reproduce", "--configs", CONFIGS, "-o", folder, "-q"], root, folder, trigger,
                           signal.SIGKILL)
        return trigger, folder, result

    with ThreadPoolExecutor(2) as pool:
        return before, list(pool.map(one, enumerate(REPRODUCE_TRIGGERS)))


@pytest.mark.parametrize("index", range(len(REPRODUCE_TRIGGERS)), ids=[f"{k}-{v}" for k, v in REPRODUCE_TRIGGERS])
def test_sigkill_during_reproduce_leaves_old_or_complete_files(killed_reproduce, index):
    before, results = killed_reproduce
    trigger, folder, r = results[index]
    assert r.fired and r.returncode == -signal.SIGKILL, (trigger, r.returncode, r.elapsed)
    assert "Traceback" not in r.stderr
    check_whole(folder, before, allow_tmp=True)


@pytest.fixture(scope="module")
def interrupted_by_ctrl_c(tmp_path_factory):
    """SIGINT (Ctrl-C) while `aspects` draws and writes its figures, and while `reproduce` runs its steps.

    The moments are fixed times, not "as soon as a temporary file appears": a signal in the few
    microseconds between the creation of a temporary file and the cleanup block of atomic_write
    leaves that file behind (test_ctrl_c_right_after_the_temporary_file_is_created), which would
    make this test flaky rather than tell anything new."""
    root = tmp_path_factory.mktemp("ctrl-c")
    run_ok(["aspects", M1, "--depth", 6, "-o", "old", "-q"], root)
    jobs = [(["aspects", M1, "--depth", 12, "-o", "{folder}", "-q"], ("time", 2.5)),
            (["reproduce", "--configs", CONFIGS, "-o", "{folder}", "--no-plot"], ("time", 1.5))]

    def one(i_job):
        i, (args, trigger) = i_job
        folder = root / f"run{i}"
        shutil.copytree(root / "old", folder)
        args = [str(folder) if a == "{folder}" else a for a in args]
        return folder, interrupt(args, root, folder, trigger, signal.SIGINT)

    before = snapshot(root / "old")
    # A process started with SIGINT ignored (pytest run in the background, nohup) passes that on to its
    # children, and Python then leaves Ctrl-C ignored: give the children the default disposition.
    previous = signal.getsignal(signal.SIGINT)
    if previous == signal.SIG_IGN:
        signal.signal(signal.SIGINT, signal.default_int_handler)
    try:
        with ThreadPoolExecutor(2) as pool:
            return before, list(pool.map(one, enumerate(jobs)))
    finally:
        signal.signal(signal.SIGINT, previous)


def test_ctrl_c_exits_1_without_traceback_or_temporary_file(interrupted_by_ctrl_c):
    before, results = interrupted_by_ctrl_c
    for folder, r in results:
        assert r.fired
        assert r.returncode == 1, (r.returncode, r.stderr)
        assert "Traceback" not in r.stderr and "Traceback" not in r.stdout
        last = r.stderr.strip().splitlines()[-1]
        assert last.startswith("fivebar: ") and ("interrupt" in last or "abort" in last), r.stderr
        check_whole(folder, before, allow_tmp=False)


def test_ctrl_c_prints_exactly_one_line(interrupted_by_ctrl_c):
    for _, r in interrupted_by_ctrl_c[1]:
        one_line(r, 1)


def test_ctrl_c_while_writing_removes_the_temporary_file(tmp_path, monkeypatch):
    """KeyboardInterrupt inside the write (here: in fsync) leaves the old file and no temporary file."""
    from fivebar_cli.io import files

    def interrupted_fsync(fd):
        raise KeyboardInterrupt

    target = tmp_path / "table.csv"
    target.write_text("old\n")
    monkeypatch.setattr(files.os, "fsync", interrupted_fsync)
    with pytest.raises(KeyboardInterrupt):
        files.write_text(target, "new\n")
    monkeypatch.undo()
    assert target.read_text() == "old\n" and [p.name for p in tmp_path.iterdir()] == ["table.csv"]


def test_ctrl_c_right_after_the_temporary_file_is_created(tmp_path, monkeypatch):
    from fivebar_cli.io import files

    real_open = os.open

    def open_then_ctrl_c(path, flags, *args, **kwargs):
        fd = real_open(path, flags, *args, **kwargs)
        os.close(fd)
        raise KeyboardInterrupt  # as when SIGINT arrives once the file exists, before its name is used

    target = tmp_path / "table.csv"
    target.write_text("old\n")
    monkeypatch.setattr(files.os, "open", open_then_ctrl_c)
    with pytest.raises(KeyboardInterrupt):
        files.write_text(target, "new\n")
    monkeypatch.undo()
    assert target.read_text() == "old\n"
    assert [p.name for p in tmp_path.iterdir()] == ["table.csv"], "a temporary file was left"


# ---------------------------------------------------------------- fuzzing the YAML reader


VALID_CONFIGS = {p.name: p.read_text() for p in sorted(CONFIGS.glob("*.yaml"))}
VALID_DATA = [yaml.safe_load(t) for t in VALID_CONFIGS.values()]
VALID_DATA.append({"name": "platform", "type": "rpr3", "base": {"t1": 1.8, "t2": 1.2, "t3": 1.11},
                   "platform": {"t4": 1.08, "t5": 0.72, "t6": 0.666}, "legs": {"rho_min": 0.2, "rho_max": 1.5},
                   "phi": 45})
KEYS = ["name", "type", "lengths", "L0", "L1", "L2", "L3", "L4", "base", "t1", "t2", "t3", "k", "platform", "t4",
        "t5", "t6", "legs", "rho_min", "rho_max", "phi", "phi_range", "lenghts", "l1", "extra"]
TEXT = st.text(st.characters(blacklist_categories=("Cs", "Cc")), max_size=8)
SCALARS = st.one_of(
    st.none(), st.booleans(), st.integers(-10**12, 10**12),
    st.floats(allow_nan=True, allow_infinity=True), st.floats(-1e3, 1e3),
    st.sampled_from(["auto", "fivebar", "rpr3", "M1", "", "1e3", "0x10", "1:30"]), TEXT,
)
VALUES = st.recursive(SCALARS, lambda inner: st.lists(inner, max_size=4)
                      | st.dictionaries(st.sampled_from(KEYS) | TEXT, inner, max_size=5), max_leaves=12)


def key_paths(data, prefix=()) -> list[tuple]:
    paths = [prefix]
    if isinstance(data, dict):
        for k, v in data.items():
            paths += key_paths(v, prefix + (k,))
    elif isinstance(data, list):
        for i, v in enumerate(data):
            paths += key_paths(v, prefix + (i,))
    return paths


@st.composite
def mutated_configs(draw) -> str:
    """A valid config with one to four structural changes: a value replaced, a key deleted, renamed or added."""
    data = copy.deepcopy(draw(st.sampled_from(VALID_DATA)))
    for _ in range(draw(st.integers(1, 4))):
        path = draw(st.sampled_from(key_paths(data)))
        op = draw(st.sampled_from(["set", "set", "delete", "rename", "add"]))
        if not path:
            if op == "set":
                data = draw(VALUES)
            continue
        parent = data
        for step in path[:-1]:
            parent = parent[step]
        last = path[-1]
        if op == "set":
            parent[last] = draw(VALUES)
        elif op == "delete":
            del parent[last]
        elif op == "rename" and isinstance(parent, dict):
            parent[draw(st.sampled_from(KEYS) | TEXT)] = parent.pop(last)
        elif op == "add" and isinstance(parent, dict):
            parent[draw(st.sampled_from(KEYS) | TEXT)] = draw(VALUES)
    return yaml.safe_dump(data, allow_unicode=True)


YAML_ALPHABET = st.sampled_from(list(":{}[],-#&*!|>'\"%@`?~. \n\t0123456789eE+") + ["\n  ", ": ", ".nan", ".inf",
                                                                                    "null", "true", "- "])


@st.composite
def edited_texts(draw) -> str:
    """A valid config file with characters inserted, deleted or replaced, or cut short."""
    chars = list(draw(st.sampled_from(list(VALID_CONFIGS.values()))))
    for _ in range(draw(st.integers(1, 5))):
        op = draw(st.sampled_from(["insert", "delete", "replace", "truncate"]))
        pos = draw(st.integers(0, len(chars)))
        if op == "truncate":
            chars = chars[:pos]
        elif op == "insert":
            chars[pos:pos] = list(draw(YAML_ALPHABET))
        elif pos < len(chars):
            if op == "delete":
                del chars[pos]
            else:
                chars[pos] = draw(YAML_ALPHABET)
    return "".join(chars)


def assert_valid_mechanism(m) -> None:
    assert isinstance(m.name, str) and m.name and m.name.strip() == m.name and "/" not in m.name
    if isinstance(m, FiveBar):
        for key, v in m.lengths.items():
            assert isinstance(v, float) and math.isfinite(v) and v > 0, (key, v)
        return
    assert isinstance(m, Rpr3), type(m)
    values = [v for p in m.base + m.platform for v in p] + list(m.rho_min)
    assert all(isinstance(v, float) and math.isfinite(v) for v in values), values
    assert all(v >= 0 for v in m.rho_min)
    assert m.rho_max is None or all(math.isfinite(b) and b > a for a, b in zip(m.rho_min, m.rho_max))
    lo, hi = m.phi_range
    assert math.isfinite(lo) and math.isfinite(hi) and lo <= hi
    if m.similar is not None:  # the similar form (issue 4); any geometry otherwise (issue 11)
        t1, t2, t3, k = m.similar
        assert all(isinstance(v, float) and math.isfinite(v) for v in m.similar)
        assert t1 > 0 and t3 != 0 and k > 0
        assert lo % 180 != 0 and hi % 180 != 0 and math.floor(lo / 180) == math.floor(hi / 180)
    else:
        assert m.rho_max is not None


@pytest.fixture(scope="module")
def fuzz_file(tmp_path_factory) -> Path:
    return tmp_path_factory.mktemp("fuzz") / "config.yaml"


def load_or_config_error(path: Path, data: bytes) -> None:
    path.write_bytes(data)
    try:
        m = load_config(path)
    except ConfigError as exc:
        message = str(exc)
        assert message.startswith(str(path)), message
        assert "\n" not in message and "\r" not in message, message
        return
    assert_valid_mechanism(m)


FUZZ = settings(max_examples=300, deadline=None, derandomize=True, database=None,
                suppress_health_check=[HealthCheck.too_slow, HealthCheck.data_too_large])


@FUZZ
@given(st.one_of(st.text(max_size=300), st.binary(max_size=300).map(lambda b: b.decode("latin-1"))))
@example(text="")
@example(text="name: M1\ntype: fivebar\nlengths: {L0: 9, L1: 8, L2: 5, L3: 5, L4: 8}\n")
def test_fuzz_config_reader_on_random_text(fuzz_file, text):
    load_or_config_error(fuzz_file, text.encode("utf-8", "surrogatepass"))


@FUZZ
@given(st.binary(max_size=300))
def test_fuzz_config_reader_on_random_bytes(fuzz_file, data):
    load_or_config_error(fuzz_file, data)


@FUZZ
@given(VALUES)
def test_fuzz_config_reader_on_random_structures(fuzz_file, data):
    load_or_config_error(fuzz_file, yaml.safe_dump(data, allow_unicode=True).encode())


@settings(FUZZ, max_examples=1000)
@given(mutated_configs())
def test_fuzz_config_reader_on_mutated_configs(fuzz_file, text):
    load_or_config_error(fuzz_file, text.encode())


@settings(FUZZ, max_examples=1000)
@given(edited_texts())
def test_fuzz_config_reader_on_edited_files(fuzz_file, text):
    load_or_config_error(fuzz_file, text.encode())


def test_the_valid_configs_load(tmp_path):
    for name, text in VALID_CONFIGS.items():
        assert_valid_mechanism(load_config(CONFIGS / name))
    path = tmp_path / "platform.yaml"
    path.write_text(yaml.safe_dump(VALID_DATA[-1]))
    assert load_config(path).similar[3] == pytest.approx(0.6)


def test_platform_ratio_cannot_underflow_to_zero(tmp_path):
    path = tmp_path / "k0.yaml"
    path.write_text(rp(k=DROP, extra="platform: {t4: 5.0e-324, t5: 0, t6: 0}\n", base="{t1: 10, t2: 1.2, t3: 1.11}"))
    with pytest.raises(ConfigError):
        load_config(path)


# ---------------------------------------------------------------- fuzzing the .qt reader on real files


@pytest.fixture(scope="module")
def real_qt(seeds) -> list[str]:
    """.qt files written by the command line: a workspace (no periodic axis) and a joint space (torus)."""
    return [(seeds["workspace"] / "workspace.qt").read_text(),
            (seeds["jointspace"] / "jointspace.complement.qt").read_text()]


QT_ALPHABET = st.sampled_from(list("GBW#: \n\r.-0123456789eEinfa") + ["# ", "\n# ", "root", "depth", "periodic",
                                                                     "none", "colour", "GGGG", "BWBW"])


@st.composite
def qt_edits(draw):
    """(file index, list of operations) applied by `apply_edits` to one of the real files."""
    ops = []
    for _ in range(draw(st.integers(1, 5))):
        op = draw(st.sampled_from(["insert", "delete", "replace", "truncate", "dup_line", "del_line", "swap_lines"]))
        ops.append((op, draw(st.integers(0, 10**6)), draw(st.integers(0, 10**6)), draw(QT_ALPHABET)))
    return draw(st.integers(0, 1)), ops


def apply_edits(text: str, ops) -> str:
    for op, a, b, piece in ops:
        if op in ("dup_line", "del_line", "swap_lines"):
            lines = text.split("\n")
            i, j = a % len(lines), b % len(lines)
            if op == "dup_line":
                lines.insert(j, lines[i])
            elif op == "del_line":
                del lines[i]
            else:
                lines[i], lines[j] = lines[j], lines[i]
            text = "\n".join(lines)
            continue
        pos = a % (len(text) + 1)
        if op == "truncate":
            text = text[:pos]
        elif op == "insert":
            text = text[:pos] + piece + text[pos:]
        elif op == "delete":
            text = text[:pos] + text[pos + 1:]
        else:
            text = text[:pos] + piece + text[pos + 1:]
    return text


def formattable(key: str) -> bool:
    """Header keys format_qt accepts (it raises ValueError on others); 'tree' collides with its argument."""
    return key.replace("_", "").replace("-", "").isalnum() and key != "tree"


def assert_well_formed(text: str, tree, fields: dict) -> None:
    """The layout of DESIGN.md (magic line, '# key: value' lines, B/W/G body wrapped at 64), and it parses back."""
    lines = text.split("\n")[:-1]
    assert text.endswith("\n") and lines[0] == MAGIC
    n = 1
    while n < len(lines) and lines[n].startswith("#"):
        assert re.fullmatch(r"# [^:\s]+: .*", lines[n]) or re.fullmatch(r"# [^:\s]+:", lines[n]), lines[n]
        n += 1
    body = lines[n:]
    assert body and all(set(line) <= set("GBW") and line for line in body), body[:3]
    assert all(len(line) == WRAP for line in body[:-1]) and len(body[-1]) <= WRAP
    again = parse_qt(text, "again.qt")
    assert again.tree == tree and again.fields == fields


@settings(FUZZ, max_examples=1000)
@given(qt_edits())
def test_fuzz_qt_reader_on_edited_real_files(real_qt, edits):
    index, ops = edits
    text = apply_edits(real_qt[index], ops)
    try:
        qt = parse_qt(text, "fuzz.qt")
    except InputError as exc:
        message = str(exc)
        assert message.startswith("fuzz.qt: ") and "\n" not in message, message
        return
    assert_well_formed(format_qt(qt.tree), qt.tree, {})
    if all(formattable(k) for k in qt.fields):  # the other keys: test_qt_header_keys_round_trip below
        assert_well_formed(format_qt(qt.tree, **qt.fields), qt.tree, qt.fields)


def test_real_files_round_trip_byte_for_byte(real_qt):
    for text in real_qt:
        qt = parse_qt(text, "real.qt")
        assert format_qt(qt.tree, **qt.fields) == text


@pytest.mark.parametrize("key", ["na.me", "tree", "a/b"])
def test_qt_header_keys_round_trip(real_qt, key):
    lines = real_qt[0].split("\n")
    lines.insert(1, f"# {key}: x")
    qt = parse_qt("\n".join(lines), "extra.qt")
    assert qt.get(key) == "x"
    assert parse_qt(format_qt(qt.tree, **qt.fields), "again.qt").fields == qt.fields
