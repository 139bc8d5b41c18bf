"""The `.qt` quadtree text format (fivebar_cli.io.qtfile): exact layout of docs/formats.md, lossless round
trips, strict reading with the file and line named in every error, and fuzzing."""

from __future__ import annotations

import math
import os

import numpy as np
import pytest
from hypothesis import HealthCheck, example, given, settings
from hypothesis import strategies as st

from conftest import cells_of, ref_encode, tree_to_bool
from fivebar_cli.errors import InputError
from fivebar_cli.io.qtfile import QtFile, format_qt, parse_qt, read_qt, write_qt
from fivebar_cli.paving.grid import Grid
from fivebar_cli.paving.tree import Tree

WS_ROOT = ((-13.0, 13.0), (-13.0, 13.0))
JS_ROOT = ((-math.pi, math.pi), (-math.pi, math.pi))


def checker_tree(depth: int, root=WS_ROOT, periodic=(False, False)) -> tuple[Tree, np.ndarray]:
    n = 1 << depth
    x, y = np.indices((n, n))
    arr = ((x + y) % 2 == 0) | ((x < n // 2) & (y < n // 2))
    return Tree.from_cells(Grid(root, depth, periodic), depth, cells_of(arr)), arr


def wrapped(body: str) -> list[str]:
    return [body[i:i + 64] for i in range(0, len(body), 64)]


# ---------------------------------------------------------------- exact format


def test_exact_layout_of_a_workspace_file():
    tree, arr = checker_tree(4)
    body = ref_encode(arr)
    assert len(body) > 130  # at least three body lines
    text = format_qt(tree, name="M1", space="workspace", region="reachable", colour="inside")
    expected = "\n".join([
        "# fivebar-quadtree 1",
        "# name: M1",
        "# space: workspace",
        "# region: reachable",
        "# colour: inside",
        "# root: -13.0 13.0 -13.0 13.0",
        "# depth: 4",
        "# periodic: none",
        *wrapped(body),
    ]) + "\n"
    assert text == expected


def test_header_order_periodic_axes_and_repr_floats():
    tree, arr = checker_tree(3, root=JS_ROOT, periodic=(True, True))
    # fields given in a scrambled order come out in the standard order, extra keys after the standard ones
    text = format_qt(tree, evaluations=17, colour="outside", mechanism="fivebar L0=9.0", region="assemblable",
                     space="jointspace", name="M1")
    lines = text.split("\n")
    assert lines[0] == "# fivebar-quadtree 1"
    keys = [ln[2:].split(":")[0] for ln in lines if ln.startswith("# ") and ":" in ln]
    assert keys[:7] == ["name", "space", "region", "colour", "root", "depth", "periodic"]
    assert sorted(keys[7:]) == ["evaluations", "mechanism"]
    assert "# root: -3.141592653589793 3.141592653589793 -3.141592653589793 3.141592653589793" in lines
    assert "# periodic: 0 1" in lines
    assert "# depth: 3" in lines
    assert "# evaluations: 17" in lines
    assert text.endswith("\n" + wrapped(ref_encode(arr))[-1] + "\n")
    one_axis = Tree.empty(Grid(((0.1, 0.7), (-2.0, 1e-300)), 2, (False, True)))
    text = format_qt(one_axis)
    assert "# periodic: 1" in text.split("\n")
    assert "# root: 0.1 0.7 -2.0 1e-300" in text.split("\n")
    assert parse_qt(text).tree.grid == one_axis.grid  # repr floats come back bit for bit


def test_body_wrapping_and_trailing_newline():
    for depth in (0, 1, 3, 5, 6):
        tree, arr = checker_tree(depth)
        text = format_qt(tree, name="X")
        assert text.endswith("\n") and not text.endswith("\n\n") and "\r" not in text
        lines = text.split("\n")[:-1]
        body_lines = [ln for ln in lines if not ln.startswith("#")]
        assert "".join(body_lines) == ref_encode(arr)
        assert all(len(ln) == 64 for ln in body_lines[:-1])
        assert 1 <= len(body_lines[-1]) <= 64
        assert lines[: len(lines) - len(body_lines)] == [ln for ln in lines if ln.startswith("#")]  # header first


def test_octree_file():
    rng = np.random.default_rng(0)
    arr = rng.random((8, 8, 8)) < 0.4
    tree = Tree.from_cells(Grid(((0.0, 1.0), (0.0, 2.0), (1.5, 2.5)), 3, (False, False, True)), 3, cells_of(arr))
    text = format_qt(tree, name="oct")
    assert "# root: 0.0 1.0 0.0 2.0 1.5 2.5" in text.split("\n")
    assert "# periodic: 2" in text.split("\n")
    back = parse_qt(text)
    assert back.tree == tree
    assert np.array_equal(tree_to_bool(back.tree), arr)


# ---------------------------------------------------------------- round trips


@st.composite
def trees(draw):
    dim = draw(st.sampled_from([2, 2, 3]))
    depth = draw(st.integers(0, 5 if dim == 2 else 3))
    rng = np.random.default_rng(draw(st.integers(0, 2**32 - 1)))
    n = 1 << depth
    arr = rng.random((n,) * dim) < draw(st.floats(0, 1))
    if draw(st.booleans()) and depth >= 1:  # add solid blocks so that merged leaves appear
        h = n // 2
        arr[(slice(0, h),) * dim] = True
    lows = draw(st.lists(st.floats(-1e6, 1e6, allow_nan=False, allow_subnormal=False), min_size=dim, max_size=dim))
    sizes = draw(st.lists(st.floats(1e-6, 1e6), min_size=dim, max_size=dim))
    root = tuple((lo, lo + s) for lo, s in zip(lows, sizes) if lo + s > lo)
    if len(root) != dim:
        root = ((0.0, 1.0),) * dim
    periodic = tuple(draw(st.lists(st.booleans(), min_size=dim, max_size=dim)))
    return Tree.from_cells(Grid(root, depth, periodic), depth, cells_of(arr)), arr


HEADER_VALUE = st.text(st.characters(min_codepoint=32, max_codepoint=126), max_size=30).map(str.strip)


@settings(max_examples=80, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(trees(), st.dictionaries(st.from_regex(r"[a-z][a-z0-9_-]{0,12}", fullmatch=True), HEADER_VALUE, max_size=4),
       HEADER_VALUE)
def test_text_parse_format_is_lossless(case, extra, name):
    tree, arr = case
    extra = {k: v for k, v in extra.items() if k not in ("name", "colour", "root", "depth", "periodic")}
    text = format_qt(tree, name=name, colour="inside", **extra)
    qt = parse_qt(text, "mem.qt")
    assert isinstance(qt, QtFile)
    assert qt.tree == tree
    assert np.array_equal(tree_to_bool(qt.tree), arr)
    assert qt.fields == {"name": name, "colour": "inside", **extra}
    assert format_qt(qt.tree, **qt.fields) == text  # same bytes


def test_unknown_header_lines_are_kept(tmp_path):
    tree, _ = checker_tree(3)
    text = format_qt(tree, name="M1", space="workspace")
    lines = text.split("\n")
    lines.insert(3, "# made-by: someone else")
    lines.insert(1, "# note: kept")
    path = tmp_path / "extra.qt"
    path.write_text("\n".join(lines))
    qt = read_qt(path)
    assert qt.get("made-by") == "someone else" and qt.get("note") == "kept"
    assert qt.get("name") == "M1" and qt.get("missing", "dflt") == "dflt"
    again = format_qt(qt.tree, **qt.fields)
    assert "# made-by: someone else" in again and "# note: kept" in again
    assert parse_qt(again).fields == qt.fields


def test_write_and_read_files(tmp_path):
    tree, arr = checker_tree(5, root=JS_ROOT, periodic=(True, True))
    path = tmp_path / "sub" / "jointspace.qt"
    path.parent.mkdir()
    out = write_qt(path, tree, name="M2", space="jointspace", region="assemblable", colour="inside")
    assert out == path
    data = path.read_bytes()
    assert data == format_qt(tree, name="M2", space="jointspace", region="assemblable", colour="inside").encode()
    assert b"\r" not in data
    assert sorted(os.listdir(path.parent)) == ["jointspace.qt"]  # no temporary file left behind
    qt = read_qt(path)
    assert qt.tree == tree and qt.get("colour") == "inside"
    # overwriting replaces the file whole
    write_qt(path, Tree.empty(tree.grid), name="M2")
    assert read_qt(path).tree == Tree.empty(tree.grid)
    assert sorted(os.listdir(path.parent)) == ["jointspace.qt"]


def test_crlf_files_are_read():
    tree, _ = checker_tree(4)
    text = format_qt(tree, name="M1").replace("\n", "\r\n")
    assert parse_qt(text).tree == tree


def test_non_ascii_names_survive_a_file_round_trip(tmp_path):
    tree, _ = checker_tree(2)
    path = write_qt(tmp_path / "m.qt", tree, name="M\u00f6bius", space="workspace")
    assert read_qt(path).get("name") == "M\u00f6bius"


# ---------------------------------------------------------------- malformed files


def good_text(depth: int = 4) -> tuple[str, list[str]]:
    tree, _ = checker_tree(depth)
    text = format_qt(tree, name="M1", space="workspace", region="reachable", colour="inside")
    return text, text.split("\n")[:-1]


def set_line(lines: list[str], index: int, value: str | None) -> str:
    lines = list(lines)
    if value is None:
        del lines[index]
    else:
        lines[index] = value
    return "\n".join(lines) + "\n"


def malformed_cases():
    text, lines = good_text()
    # lines: 1 magic, 2 name, 3 space, 4 region, 5 colour, 6 root, 7 depth, 8 periodic, 9.. body
    body_lines = lines[8:]
    assert len(body_lines) >= 3
    n_lines = len(lines)
    cases = [
        ("empty", "", "line 1"),
        ("blank", "\n", "line 1"),
        ("wrong magic", set_line(lines, 0, "# quadtree 1"), "line 1"),
        ("no magic", set_line(lines, 0, None), "line 1"),
        ("version 2", set_line(lines, 0, "# fivebar-quadtree 2"), "line 1"),
        ("bad header", set_line(lines, 2, "# space workspace"), "line 3"),
        ("duplicate key", set_line(lines, 3, "# name: again"), "line 4"),
        ("root word", set_line(lines, 5, "# root: -13 thirteen -13 13"), "line 6"),
        ("root count", set_line(lines, 5, "# root: -13 13 -13"), "line 6"),
        ("root lo >= hi", set_line(lines, 5, "# root: 13 -13 -13 13"), "line 6"),
        ("root lo == hi", set_line(lines, 5, "# root: -13 13 1 1"), "line 6"),
        ("root nan", set_line(lines, 5, "# root: nan 13 -13 13"), "line 6"),
        ("root inf", set_line(lines, 5, "# root: -inf 13 -13 13"), "line 6"),
        ("depth word", set_line(lines, 6, "# depth: four"), "line 7"),
        ("depth float", set_line(lines, 6, "# depth: 4.0"), "line 7"),
        ("depth -1", set_line(lines, 6, "# depth: -1"), "line 7"),
        ("depth 27", set_line(lines, 6, "# depth: 27"), "line 7"),
        ("depth too small for the body", set_line(lines, 6, "# depth: 1"), "line 9"),
        ("periodic axis 2", set_line(lines, 7, "# periodic: 0 2"), "line 8"),
        ("periodic word", set_line(lines, 7, "# periodic: yes"), "line 8"),
        ("truncated body", set_line(lines, n_lines - 1, lines[-1][:-1]), f"line {n_lines}"),
        ("body cut after a line", "\n".join(lines[:-1]) + "\n", f"line {n_lines - 1}"),
        ("extra letters", text + "B\n", f"line {n_lines + 1}"),
        ("extra letter on the last line", set_line(lines, n_lines - 1, lines[-1] + "W"), f"line {n_lines}"),
        ("bad letter line 10", set_line(lines, 9, lines[9][:5] + "X" + lines[9][6:]), "line 10"),
        ("lowercase letter", set_line(lines, 8, "g" + lines[8][1:]), "line 9"),
        ("blank line in the body", "\n".join(lines[:10] + [""] + lines[10:]) + "\n", "line 11"),
        ("no body", "\n".join(lines[:8]) + "\n", "line 9"),
        ("header after body", "\n".join(lines[:9] + ["# late: key"] + lines[9:]) + "\n", "line 10"),
    ]
    for key, index in (("root", 5), ("depth", 6), ("periodic", 7)):
        cases.append((f"missing {key}", set_line(lines, index, None), key))
    return cases


@pytest.mark.parametrize("label, text, where", malformed_cases(), ids=[c[0] for c in malformed_cases()])
def test_malformed_text_names_the_file_and_line(label, text, where, tmp_path):
    with pytest.raises(InputError) as err:
        parse_qt(text, "some/file.qt")
    message = str(err.value)
    assert message.startswith("some/file.qt: ")
    assert where in message
    assert "\n" not in message
    # the same through a real file
    path = tmp_path / "bad.qt"
    path.write_text(text)
    with pytest.raises(InputError) as err:
        read_qt(path)
    assert str(path) in str(err.value) and where in str(err.value)


def test_line_numbers_are_exact():
    text, lines = good_text()
    with pytest.raises(InputError) as err:
        parse_qt(set_line(lines, 6, "# depth: x"), "f.qt")
    assert err.value.source == "f.qt" and err.value.field.startswith("line 7")
    with pytest.raises(InputError) as err:
        parse_qt(set_line(lines, 9, lines[9][:5] + "X" + lines[9][6:]), "f.qt")
    assert err.value.field == "line 10"  # and not line 9 or 11


@pytest.mark.parametrize("data", [b"", b"\x89PNG\r\n\x1a\n\x00\x00\x00\rIHDR\xff\xfe", b"\xff" * 100,
                                  "# fivebar-quadtree 1\n# name: \u00e9\n".encode("latin-1"), b"\x00\x01\x02"])
def test_binary_garbage_files(tmp_path, data):
    path = tmp_path / "garbage.qt"
    path.write_bytes(data)
    with pytest.raises(InputError) as err:
        read_qt(path)
    assert str(path) in str(err.value) and "\n" not in str(err.value)


def test_missing_and_directory_paths(tmp_path):
    for path in (tmp_path / "nope.qt", tmp_path):
        with pytest.raises(InputError) as err:
            read_qt(path)
        assert str(path) in str(err.value)


def test_unicode_digit_in_periodic_is_an_input_error():
    text, lines = good_text()
    with pytest.raises(InputError):
        parse_qt(set_line(lines, 7, "# periodic: \u00b2"), "f.qt")


# ---------------------------------------------------------------- fuzzing


VALID_TEXT, VALID_LINES = good_text(3)
ALPHABET = st.sampled_from(list("GBW#:\n\r .-0123456789eEinfa") + ["# ", "periodic", "root", "depth", "none", "\n#"])


@st.composite
def mutated(draw):
    chars = list(VALID_TEXT)
    for _ in range(draw(st.integers(1, 6))):
        op = draw(st.sampled_from(["delete", "insert", "replace", "truncate", "swap_lines", "dup_line"]))
        if op == "truncate":
            chars = chars[: draw(st.integers(0, len(chars)))]
        elif op in ("swap_lines", "dup_line"):
            lines = "".join(chars).split("\n")
            i = draw(st.integers(0, len(lines) - 1))
            j = draw(st.integers(0, len(lines) - 1))
            if op == "swap_lines":
                lines[i], lines[j] = lines[j], lines[i]
            else:
                lines.insert(j, lines[i])
            chars = list("\n".join(lines))
        else:
            pos = draw(st.integers(0, len(chars)))
            if op == "delete" and pos < len(chars):
                del chars[pos]
            elif op == "insert":
                chars[pos:pos] = list(draw(ALPHABET))
            elif pos < len(chars):
                chars[pos] = draw(st.characters(min_codepoint=1, max_codepoint=127))
    return "".join(chars)


def parse_or_input_error(text: str) -> None:
    try:
        qt = parse_qt(text, "fuzz.qt")
    except InputError as exc:
        assert str(exc).startswith("fuzz.qt")
        assert "\n" not in str(exc)
        return
    # whatever parses is a real tree that formats and parses back to itself
    assert isinstance(qt.tree, Tree)
    assert parse_qt(format_qt(qt.tree), "again.qt").tree == qt.tree


@settings(max_examples=300, deadline=None)
@given(mutated())
@example(VALID_TEXT)
@example(VALID_TEXT.replace("# depth: 3", "# depth: 99999999999999999999999"))
@example(VALID_TEXT.replace("# root: -13.0 13.0", "# root: -1e309 13.0"))
@example(VALID_TEXT.replace("# root: -13.0 13.0 -13.0 13.0", "# root: 0 1e-320 0 1"))
def test_fuzz_mutations_parse_or_raise_input_error(text):
    parse_or_input_error(text)


@settings(max_examples=200, deadline=None)
@given(st.text(st.characters(min_codepoint=1, max_codepoint=127), max_size=300))
def test_fuzz_ascii_text_parses_or_raises_input_error(text):
    parse_or_input_error(text)
    parse_or_input_error("# fivebar-quadtree 1\n" + text)


@settings(max_examples=100, deadline=None)
@given(st.binary(max_size=300))
def test_fuzz_binary_files_read_or_raise_input_error(tmp_path_factory, data):
    path = tmp_path_factory.mktemp("fuzz") / "x.qt"
    path.write_bytes(data)
    try:
        read_qt(path)
    except InputError as exc:
        assert str(path) in str(exc)


def test_the_worked_examples_of_the_format_are_what_the_code_gives():
    """docs/formats.md's worked examples, as it claims them ("Checked with the code"): its Python
    block's commented values; the complement body of `fivebar workspace configs/m1.yaml --depth 2`
    with its 4 outside leaves and 12 undetermined cells; the one-level octree `GWBWWBWWW`."""
    import re

    import fivebar_cli as fb
    from cli_helpers import REPO

    text = (REPO / "docs" / "formats.md").read_text()
    block = re.search(r"Checked with the code:\n\n```python\n(.*?)```", text, re.S).group(1)
    namespace: dict = {}
    exec(compile(block, "docs/formats.md", "exec"), namespace)
    claims = [(expr, value) for expr, value in re.findall(r"^([\w.()]+)\s+#\s*(\S+)", block, re.M)]
    assert len(claims) == 3
    for expr, value in claims:
        assert repr(eval(expr, namespace)) == value, expr
    m1 = fb.pave("m1", "workspace", 2)
    assert m1.inside.to_bwg() == "W" and "`GGBWBWWGBWBWW`" in text and m1.outside.to_bwg() == "GGBWBWWGBWBWW"
    assert len(m1.outside) == 4 and m1.undetermined_area == 12 * (26 / 4) ** 2  # 12 cells of the root [-13, 13]^2 / 4
    octree = Tree.from_cells(Grid(((0.0, 1.0),) * 3, 1, (False,) * 3), 1, np.array([[1, 0, 0], [0, 0, 1]]))
    assert "`GWBWWBWWW`" in text and octree.to_bwg() == "GWBWWBWWW"
