"""Any value where a public call takes a depth, a count (processes, a budget, samples), a point or an
endpoint: the call gives a result, or a FivebarError (an InputError naming that parameter when the
value is the fault), never another error and never a run without end (hypothesis). A float depth
paved on without end, `workers=-1` waited forever, `jobs=-1` ran in one process without a word, a
budget of -1 or 1.5 and `steps=0` were taken for something else, and bad poses raised broadcasting,
index or type errors from deep inside.

Values that are valid but costly (a depth of 12, four worker processes, a Dask cluster) are left to
the other tests: here each valid call is small.
"""

from __future__ import annotations

import math
import numbers as abc

import numpy as np
import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

import fivebar_cli as fb

def _modes(name: str) -> tuple[list[str], list[str]]:
    from fivebar_cli.analyses.aspect_texts import signs_text

    model = fb.load(name).aspect_model()
    return [signs_text(k) for k in model.working_modes], [signs_text(k) for k in model.assembly_modes]


RPR2_MODES = _modes("rpr2")
SPEC = {"type": "fivebar-atlas", "name": "t", "depth": 2,
        "lengths": {"L0": 9, "L1": [7, 8, 2], "L2": 5, "L3": 5, "L4": 8}}

numbers = st.one_of(st.integers(-10**12, 10**12), st.floats(allow_nan=True, allow_infinity=True), st.booleans(),
                    st.integers(-3, 30).map(np.int64))  # (numpy's integers: a sweep over np.arange)
anything = st.one_of(numbers, st.none(), st.text(max_size=3), st.sampled_from(["++", "+-", "--", "+", "-", "0", "+-+"]),
                     st.tuples(), st.tuples(numbers),
                     st.tuples(numbers, numbers), st.tuples(numbers, numbers, numbers),
                     st.lists(st.tuples(numbers, numbers), max_size=2),
                     st.dictionaries(st.text(max_size=4), numbers, max_size=2))


def _int(v) -> int | None:
    return v if isinstance(v, abc.Integral) and not isinstance(v, bool) else None


def depth(limit: int):
    return lambda v: _int(v) is not None and 0 <= v <= limit


def point(n: int):
    """n finite numbers (a pose or an endpoint; a bool among them is a number, as in numpy), or for
    locate a list of such."""
    def ok(v) -> bool:
        one = isinstance(v, tuple) and len(v) == n and all(isinstance(x, abc.Real) and math.isfinite(x) for x in v)
        return one or isinstance(v, list) and len(v) > 0 and all(ok(x) for x in v)
    return ok


# (parameter, call, the values it may take, which of them are too costly here)
CALLS = [
    ("depth", lambda v: fb.pave("m1", "workspace", v), depth(20), lambda v: v > 6),
    ("depth", lambda v: fb.refine(fb.pave("rpr2", "workspace", 2), v), depth(20), lambda v: v > 6),
    # (None: the kind's default depth, 10 here: costly)
    ("depth", lambda v: fb.aspects("rpr2", v), lambda v: v is None or depth(16)(v), lambda v: v is None or v > 6),
    ("depth", lambda v: fb.rpr3.pave("rpr3-general", v), depth(12), lambda v: v > 3),
    ("depth", lambda v: fb.rpr3.verify("rpr3-verify/table1-legs-1-1.5", v), depth(17), lambda v: False),
    ("jobs", lambda v: fb.aspects("rpr2", 3, jobs=v), lambda v: v is None or _int(v) is not None and v >= 1,
     lambda v: v is not None and v > 2),
    ("workers", lambda v: fb.atlas(SPEC, workers=v), lambda v: v is None or _int(v) is not None and v >= 0,
     lambda v: v is None or v > 0),  # (a Dask cluster: test_atlas_dask)
    ("budget", lambda v: fb.aspects("rpr2", 3, budget=v), lambda v: v is None or _int(v) is not None and v >= 0,
     lambda v: False),
    ("steps", lambda v: fb.rpr3.sweep("rpr3-equilateral", "rho_min", steps=v),
     lambda v: v is None or _int(v) is not None and 2 <= v <= 20001, lambda v: v is None or v > 50),
    ("pose", lambda v: fb.locate("rpr2", pose=v, depth=3), point(2), lambda v: False),
    ("pose", lambda v: fb.locate("rpr3-caro", pose=v, depth=2), point(3), lambda v: False),
    ("start", lambda v: fb.path("rpr2", v, (0, 8), working_mode="++", depth=4), point(2), lambda v: False),
    ("goal", lambda v: fb.path("rpr3-caro", (8, -9, -5.6), v, depth=3), point(3), lambda v: False),
    ("working_mode", lambda v: fb.locate("rpr2", pose=(0, 8), working_mode=v, depth=3),
     lambda v: v is None or isinstance(v, str) and v in RPR2_MODES[0], lambda v: False),
    ("assembly_mode", lambda v: fb.locate("rpr2", pose=(0, 8), assembly_mode=v, depth=3),
     lambda v: v is None or isinstance(v, str) and v in RPR2_MODES[1], lambda v: False),
]


@pytest.mark.parametrize("k", range(len(CALLS)), ids=[f"{c[0]}-{k}" for k, c in enumerate(CALLS)])
@settings(max_examples=30, deadline=None, derandomize=True, database=None,
          suppress_health_check=[HealthCheck.filter_too_much, HealthCheck.too_slow])
@given(value=anything)
def test_any_value_gives_a_result_or_an_error_naming_the_parameter(k, value):
    name, call, valid, costly = CALLS[k]
    if valid(value) and costly(value):
        return
    try:
        call(value)
    except fb.InputError as e:
        assert valid(value) or e.field.strip("`") == name, (value, str(e))  # a bad value is named
    except fb.FivebarError:
        assert valid(value), value  # (a valid one may give no motion, a pose no aspect holds, ...)
    else:
        assert valid(value), f"{name}={value!r} was taken"


@pytest.fixture(scope="module")
def results():
    """A small result of each kind that has a `save` (computed once)."""
    return {"paving": fb.pave("rpr2", "workspace", 2), "aspects": fb.aspects("rpr2", 3),
            "path": fb.path("rpr2", (0, 8), (0.1, 8), working_mode="++", depth=4),
            "report": fb.kratio("m1", [2]), "pave set": fb.rpr3.pave("rpr3-general", 1),
            "table": fb.Table("t", ("a",), ((1,),))}


# (the parameter, a call taking a path there, whether None is its default): every public path parameter
PATH_CALLS = [
    ("source", lambda r, v: fb.load(v), False),
    ("path", lambda r, v: fb.read_qt(v), False),
    ("paving", lambda r, v: fb.refine(v, 3), False),
    ("paths", lambda r, v: fb.view([v]), False),
    ("spec", lambda r, v: fb.atlas(v), False),
    ("folder", lambda r, v: fb.atlas(SPEC, v), True),
    ("folder", lambda r, v: fb.atlas_plan(SPEC, v), False),
    ("folder", lambda r, v: fb.copy_examples(v), False),
    ("folder", lambda r, v: fb.locate("rpr2", pose=(0, 8), depth=3, folder=v), True),
    ("folder", lambda r, v: fb.path("rpr2", (0, 8), (0.1, 8), working_mode="++", depth=4, folder=v), True),
    ("folder", lambda r, v: fb.path("rpr3-caro", (8, -9, -5.6), (8.1, -9, -5.6), depth=2, folder=v), True),
    *(("folder", lambda r, v, kind=kind: r[kind].save(v), False) for kind in ("paving", "aspects", "path", "report", "pave set")),
    ("path", lambda r, v: r["table"].save(v), False),
]
NOT_PATHS = [None, 3, 1.5, ("out",), b"out", "", b""]


@pytest.mark.parametrize("k, value", [(k, v) for k, (_, _, default) in enumerate(PATH_CALLS) for v in NOT_PATHS
                                      if not (v is None and default)],
                         ids=[f"{c[0]}-{k}-{v!r}" for k, c in enumerate(PATH_CALLS) for v in NOT_PATHS
                              if not (v is None and c[2])])
def test_a_path_that_is_none_or_empty_is_an_input_error_naming_it(results, k, value, tmp_path, monkeypatch):
    """None (where it is not the default), a number, a tuple or bytes where a path goes, or an empty
    one (which the system's calls take for the current folder: a `save("")` wrote there), is an
    InputError naming the parameter, and nothing is written in the working folder."""
    monkeypatch.chdir(tmp_path)
    name, call, _ = PATH_CALLS[k]
    with pytest.raises(fb.InputError) as e:
        call(results, value)
    assert e.value.field.strip("`") == name, str(e.value)
    assert ("an empty name" in str(e.value)) == (value in ("", b"")), str(e.value)
    assert list(tmp_path.iterdir()) == []


@pytest.mark.parametrize("call, name", [
    (lambda: fb.kratio(None, [3]), "mechs"), (lambda: fb.kratio(3, [3]), "mechs"), (lambda: fb.kratio([], [3]), "mechs"),
    (lambda: fb.view(3), "paths"), (lambda: fb.view(None), "paths"), (lambda: fb.view([]), "paths"),
], ids=["kratio-None", "kratio-3", "kratio-none", "view-3", "view-None", "view-none"])
def test_no_mechanism_or_path_where_a_sequence_of_them_goes_is_named(call, name):
    """kratio's mechanisms and view's paths: one of them or a sequence; anything else (None, a
    number, an empty list) is an InputError naming the parameter, not a TypeError or an empty table."""
    with pytest.raises(fb.InputError) as e:
        call()
    assert e.value.field.strip("`") == name, str(e.value)


# (the parameter, a call taking a name there: a space, a region, a mode, a kind, a choice)
NAME_CALLS = [
    ("space", lambda v: fb.pave("m1", v, 2)),
    ("region", lambda v: fb.pave("rpr3-general", "workspace", 1, region=v)),
    ("procedure", lambda v: fb.pave("m1", "workspace", 2, procedure=v)),
    ("working_mode", lambda v: fb.locate("rpr2", pose=(0, 8), working_mode=v, depth=3)),
    ("assembly_mode", lambda v: fb.path("rpr2", (0, 8), (0.1, 8), working_mode="++", assembly_mode=v, depth=4)),
    ("working_mode", lambda v: fb.verify("rrr3-symmetric", 2, working_mode=v)),
    ("over", lambda v: fb.rpr3.sweep("rpr3-equilateral", v, steps=3)),
    ("what", lambda v: fb.dkp("rpr3-caro", (14.98, 15.38, 12), 2, budget=0, what=v)),
    ("kind", lambda v: fb.load("m1", kind=v)),
    ("space", lambda v: fb.load("m1", space=v)),
]


@pytest.mark.parametrize("value", [3, 1.5, [], {}, ("workspace",), np.array([1.0, 2.0]), object()],
                         ids=["int", "float", "list", "dict", "tuple", "array", "object"])
@pytest.mark.parametrize("k", range(len(NAME_CALLS)), ids=[f"{c[0]}-{k}" for k, c in enumerate(NAME_CALLS)])
def test_what_is_no_name_where_a_name_goes_is_named(k, value):
    """A list, a dict or a numpy array where a name goes raised `unhashable type` or numpy's
    "truth value of an array is ambiguous" from a membership test, and a number where a kind goes
    "'int' object is not subscriptable": now an InputError naming the parameter, like a name that
    is none of the choices."""
    name, call = NAME_CALLS[k]
    with pytest.raises(fb.InputError) as e:
        call(value)
    assert e.value.field.strip("`") == name, str(e.value)


def test_numpy_integers_are_whole_numbers_too(tmp_path):
    """A sweep over `np.arange` gives numpy integers: the depths and counts of every call take them,
    as the Python ints they equal (a depth reaches the JSON manifest that `save` writes), with the
    same results; they used to be refused as "must be an integer"."""
    a = fb.aspects("rpr2", np.int64(5), jobs=np.int32(1), budget=np.uint16(500))
    assert type(a.depth) is int and a.rows() == fb.aspects("rpr2", 5, budget=500).rows()
    a.save(tmp_path / "numpy")
    fb.aspects("rpr2", 5, budget=500).save(tmp_path / "python")
    for path in sorted((tmp_path / "python").rglob("*")):
        if path.is_file():
            assert (tmp_path / "numpy" / path.relative_to(tmp_path / "python")).read_bytes() == path.read_bytes()
    k = fb.kratio("m1", np.arange(3, 5))
    assert {type(d) for d in k.column("depth")} == {int} and sorted(set(k.column("depth"))) == [3, 4]
    assert len(fb.rpr3.sweep("rpr3-equilateral", "rho_min", steps=np.int64(11))) == 11
    assert fb.pave("m1", "workspace", np.int8(4)).inside_area == fb.pave("m1", "workspace", 4).inside_area
    assert fb.locate("rpr3-caro", pose=(8, -9, -5.6), depth=np.int64(2)).rows() == \
        fb.locate("rpr3-caro", pose=(8, -9, -5.6), depth=2).rows()
