"""Fuzzing the readers of user files (issue 5, item 3): every config text, byte string or YAML
structure either loads as a valid mechanism or raises ConfigError with one line naming the file;
every edit of a real .qt file either parses (and then formats back to the docs/formats.md layout) or
raises InputError naming the file. Hypothesis, derandomized: the same examples on every run.
"""

from __future__ import annotations

import copy
import math
import re
from pathlib import Path

import pytest
import yaml
from cli_helpers import ok, run_cli
from hypothesis import HealthCheck, example, given, settings
from hypothesis import strategies as st

from fivebar_cli.errors import InputError
from fivebar_cli.io.qtfile import MAGIC, WRAP, format_qt, parse_qt
from fivebar_cli.io.schema import ConfigError
from fivebar_cli.mechanisms.fivebar.model import FiveBar
from fivebar_cli.mechanisms.registry import load_config
from fivebar_cli.mechanisms.rpr2.model import Rpr2
from fivebar_cli.mechanisms.rpr3.model import Rpr3
from fivebar_cli.mechanisms.rrr3.model import Rrr3

REPO = Path(__file__).resolve().parents[1]
CONFIGS = REPO / "configs"
M1 = CONFIGS / "m1.yaml"


# ---------------------------------------------------------------- fuzzing the YAML reader


# mechanism files (configs/ also holds atlas specs, `type: fivebar-atlas`: test_atlas.py)
VALID_CONFIGS = {p.name: p.read_text() for p in sorted(CONFIGS.glob("*.yaml")) if "fivebar-atlas" not in p.read_text()}
VALID_DATA = [yaml.safe_load(t) for t in VALID_CONFIGS.values()]
VALID_DATA.append({"name": "platform", "type": "rpr3", "base": {"t1": 1.8, "t2": 1.2, "t3": 1.11},
                   "platform": {"t4": 1.08, "t5": 0.72, "t6": 0.666}, "legs": {"rho_min": 0.2, "rho_max": 1.5},
                   "phi": 45})
KEYS = ["name", "type", "lengths", "L0", "L1", "L2", "L3", "L4", "base", "t1", "t2", "t3", "k", "platform", "t4",
        "t5", "t6", "legs", "rho_min", "rho_max", "phi", "phi_range", "d", "lenghts", "l1", "extra"]
TEXT = st.text(st.characters(blacklist_categories=("Cs", "Cc")), max_size=8)
SCALARS = st.one_of(
    st.none(), st.booleans(), st.integers(-10**12, 10**12),
    st.floats(allow_nan=True, allow_infinity=True), st.floats(-1e3, 1e3),
    st.sampled_from(["auto", "fivebar", "rpr3", "rpr2", "M1", "", "1e3", "0x10", "1:30"]), TEXT,
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
    if isinstance(m, Rpr2):
        for key in ("d", "rho_min", "rho_max"):
            v = getattr(m, key)
            assert isinstance(v, float) and math.isfinite(v), (key, v)
        assert m.d > 0 and 0 <= m.rho_min < m.rho_max and 2 * m.rho_max >= m.d
        return
    if isinstance(m, Rrr3):
        values = [v for p in m.base + m.platform for v in p] + list(m.proximal) + list(m.distal)
        assert all(isinstance(v, float) and math.isfinite(v) for v in values), values
        assert all(v > 0 for v in m.proximal + m.distal)
        lo, hi = m.phi_range
        assert math.isfinite(lo) and math.isfinite(hi) and lo <= hi
        assert m.working_mode in (None, "+++", "++-", "+-+", "+--", "-++", "-+-", "--+", "---")
        assert m.spaces()["workspace"].dim == (2 if lo == hi else 3)
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


@settings(FUZZ, max_examples=400)
@given(mutated_configs())
def test_fuzz_config_reader_on_mutated_configs(fuzz_file, text):
    load_or_config_error(fuzz_file, text.encode())


@settings(FUZZ, max_examples=400)
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
    path.write_text("name: R\ntype: rpr3\nbase: {t1: 10, t2: 1.2, t3: 1.11}\nlegs: {rho_min: 0.2, rho_max: auto}\n"
                    "phi_range: [100, 165]\nplatform: {t4: 5.0e-324, t5: 0, t6: 0}\n")
    with pytest.raises(ConfigError):
        load_config(path)


# ---------------------------------------------------------------- fuzzing the .qt reader on real files


@pytest.fixture(scope="module")
def real_qt(tmp_path_factory) -> list[str]:
    """.qt files written by the command line: a workspace (no periodic axis) and a joint space (torus)."""
    root = tmp_path_factory.mktemp("real-qt")
    for space in ("workspace", "jointspace"):
        ok(run_cli(space, M1, "--depth", 4, "-o", "out", "--no-plot", "-q", cwd=root))
    return [(root / "out" / "workspace.qt").read_text(), (root / "out" / "jointspace.complement.qt").read_text()]


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
    """The layout of docs/formats.md (magic line, '# key: value' lines, B/W/G body wrapped at 64), and it parses back."""
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


@settings(FUZZ, max_examples=400)
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
