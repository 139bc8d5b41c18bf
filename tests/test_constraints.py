"""Joint limits and obstacles (issue 18): the YAML contract, and the soundness of every constrained
box test in both spaces.

- Parsing: the issue's example, the `.qt` description round trip, and every bad input as one
  line, exit 2, nothing written.
- Soundness (hypothesis): random five-bars with random limits, discs, polygons and clearances;
  boxes of every size, many of them tiny and centred on constraint boundaries (found by bisection
  on the reference), sampled against independent geometry: `reference_kinematics` (IKP, DKP) and
  `reference_constrained.allowed` (the constraints from their definitions). Checked: the per-mode
  constraint status, the mode tests, the space tests, with exact and with interval lengths.
- Exact arithmetic: boxes a hair wide straddling configurations exactly on a boundary (the P limit
  at |B1B2|^2 = L3^2 + L4^2 and a link tangent to a disc, computed with mpmath at 40 digits) must
  stay undecided; those a hair away on either side must not be decided wrongly.
"""

from __future__ import annotations

import math

import mpmath
import numpy as np
import pytest
from hypothesis import HealthCheck, assume, example, given, settings
from hypothesis import strategies as st

import reference_constrained as rc
from conftest import box_samples
from cli_helpers import run_cli
from reference_kinematics import ref_dkp, ref_ikp
from fivebar_cli.mechanisms.fivebar import constrained
from fivebar_cli.mechanisms.fivebar.constraints import LIMIT_NAMES, Constraints, Limit, base_problem
from fivebar_cli.mechanisms.fivebar.model import FiveBar, assembles
from fivebar_cli.mechanisms.registry import from_description, load_config
from fivebar_cli.numerics.obstacles import Disc, Polygon

SETTINGS = settings(max_examples=12, deadline=None, suppress_health_check=[HealthCheck.too_slow])
WORKING = ((1, 1), (1, -1), (-1, 1), (-1, -1))
ISSUE_EXAMPLE = """\
name: M1-limited
type: fivebar
lengths: {L0: 9, L1: 8, L2: 5, L3: 5, L4: 8}
limits:
  theta1: [-120, 150]
  theta2: [-150, 120]
  B1: [-160, 160]
  B2: [-160, 160]
  P: [-90, 90]
obstacles:
  - disc: {centre: [4.5, 0], radius: 1}
  - polygon: [[10, -2], [12, -2], [12, 2], [10, 2]]
clearance: 0.0
"""


# ---------------------------------------------------------------- the YAML contract


def test_the_issues_example_parses_and_round_trips_through_the_qt_description(tmp_path):
    path = tmp_path / "limited.yaml"
    path.write_text(ISSUE_EXAMPLE)
    m = load_config(path)
    c = m.constraints
    assert [(lim.name, lim.lo, lim.hi) for lim in c.limits] == [
        ("theta1", -120, 150), ("theta2", -150, 120), ("B1", -160, 160), ("B2", -160, 160), ("P", -90, 90)]
    assert c.obstacles == (Disc((4.5, 0.0), 1.0), Polygon(((10, -2), (12, -2), (12, 2), (10, 2))))
    assert c.clearance == 0.0
    assert from_description(m.describe(), m.name, "header") == m
    # the actuated limits are the joint space's root, no longer periodic
    (t1, t2) = m.spaces()["jointspace"].axes
    assert not t1.periodic and not t2.periodic
    assert math.radians(-120) < t1.lo < math.radians(-120) + 1e-14 and math.radians(150) - 1e-14 < t1.hi < math.radians(150)
    assert m.unconstrained().describe() == "fivebar L0=9.0 L1=8.0 L2=5.0 L3=5.0 L4=8.0"


def test_a_clearance_and_a_full_turn_limit_round_trip(tmp_path):
    path = tmp_path / "c.yaml"
    path.write_text("name: c\ntype: fivebar\nlengths: {L0: 9, L1: 8, L2: 5, L3: 5, L4: 8}\n"
                    "limits: {theta2: [-180, 180]}\nobstacles: [{disc: {centre: [4.5, -3], radius: 0.5}}]\n"
                    "clearance: 0.25\n")
    m = load_config(path)
    assert "clearance=0.25" in m.describe() and "theta2=[-180.0,180.0]" in m.describe()
    assert from_description(m.describe(), "c", "header") == m
    assert m.spaces()["jointspace"].axes[1].periodic  # a whole turn restricts nothing


BAD = [
    ("limits: {P: [90, -90]}", "limits.P: needs lo < hi, got [90.0, -90.0]"),
    ("limits: {B1: [-200, 10]}", "limits.B1[0]: must be within [-180, 180] degrees, got -200.0"),
    ("limits: {Q: [0, 1]}", "limits.Q: unknown key (allowed: B1, B2, P, theta1, theta2)"),
    ("limits: {P: 90}", "limits.P: expected [lo, hi] in degrees, got 90"),
    ("obstacles: [{disc: {centre: [4.5, 0], radius: -1}}]", "obstacles[0].disc.radius: must be positive, got -1"),
    ("obstacles: [{disc: {center: [4.5, 0], radius: 1}}]", "obstacles[0].disc.center: unknown key (allowed: centre, radius)"),
    ("obstacles: [{polygon: [[0, 3], [3, 5], [3, 3], [0, 6]]}]",
     "obstacles[0].polygon: edges 0 and 2 intersect (the polygon is not simple)"),
    ("obstacles: [{polygon: [[0, 3], [1, 4], [2, 5]]}]", "obstacles[0].polygon: the polygon has zero area (degenerate)"),
    ("obstacles: [{polygon: [[0, 3], [1, 4]]}]", "obstacles[0].polygon: a polygon needs at least 3 vertices, got 2"),
    ("obstacles: [{disc: {centre: [0.5, 0.5], radius: 1}}]", "obstacles[0]: covers the base joint A1 = (0, 0)"),
    ("obstacles: [{polygon: [[8, -1], [10, -1], [10, 1], [8, 1]]}]", "obstacles[0]: covers the base joint A2 = (9, 0)"),
    ("obstacles: [{disc: {centre: [3, 0], radius: 1}}]\nclearance: 2.5",
     "obstacles[0]: comes within the clearance 2.5 of the base joint A1 = (0, 0)"),
    ("obstacles: [{box: [0, 1]}]", "obstacles[0]: expected one of 'disc: {centre: [x, y], radius: r}'"),
    ("clearance: -1", "clearance: must not be negative, got -1"),
    ("limits: {theta1: [170, 180], theta2: [-10, 10]}",
     "limits: the limits and obstacles together leave no configuration of this five-bar"),
]


@pytest.mark.parametrize("extra, message", BAD)
def test_bad_constraints_are_one_line_exit_2_and_nothing_written(tmp_path, extra, message):
    path = tmp_path / "bad.yaml"
    path.write_text("name: bad\ntype: fivebar\nlengths: {L0: 9, L1: 8, L2: 5, L3: 5, L4: 8}\n" + extra + "\n")
    out = tmp_path / "out"
    r = run_cli("workspace", path, "--depth", "4", "-o", out)
    assert r.status == 2, r
    assert r.stderr.count("\n") == 1 and r.stderr.startswith(f"fivebar: error: {path}: {message}"), r.stderr
    assert not out.exists()


def test_a_limit_that_alone_empties_the_joint_space_is_named(tmp_path):
    """L0 = 20, cranks 5, couplers 8: |B1B2| >= 10, so the angle at P is at least 77 degrees."""
    path = tmp_path / "far.yaml"
    path.write_text("name: far\ntype: fivebar\nlengths: {L0: 20, L1: 5, L2: 5, L3: 8, L4: 8}\n"
                    "limits: {B1: [-170, 170], P: [-60, 60]}\n")
    r = run_cli("aspects", path, "--depth", "4", "-o", tmp_path / "out")
    assert r.status == 2 and r.stderr == (f"fivebar: error: {path}: limits.P: the P limit alone leaves no "
                                          "configuration of this five-bar\n")


@settings(max_examples=25, deadline=None)
@given(st.integers(0, 10**6))
def test_the_emptiness_check_stopping_at_a_certified_cell_is_the_whole_pavings_answer(seed):
    """`leaves_nothing` stops paving at the first box certified inside; its answer must be the whole
    paving's (no inside, undetermined or band cell). Random P limits and L0 put designs on both sides:
    the P limit alone can empty the joint space (test above)."""
    from fivebar_cli.mechanisms.fivebar.boxtests import joint_space_test
    from fivebar_cli.paving.engine import pave

    rng = np.random.default_rng(seed)
    lo = float(rng.uniform(-90, 60))
    m = FiveBar("r", float(rng.uniform(8, 20)), 5.0, 5.0, 8.0, 8.0,
                constraints=Constraints(limits=(Limit("P", lo, lo + float(rng.uniform(5, 120))),)))
    space = m.spaces()["jointspace"]
    whole = pave(space.grid(constrained.EMPTY_DEPTH), constrained.space_test(m, "jointspace", joint_space_test(m)))
    assert constrained.leaves_nothing(m) == (len(whole.inside) == len(whole.undetermined) == len(whole.band) == 0)


def test_the_paper_procedure_refuses_constraints(tmp_path):
    path = tmp_path / "p.yaml"
    path.write_text("name: p\ntype: fivebar\nlengths: {L0: 9, L1: 8, L2: 5, L3: 5, L4: 8}\nlimits: {P: [-90, 90]}\n")
    r = run_cli("jointspace", path, "--procedure", "paper", "-o", tmp_path / "out")
    assert r.status == 2 and "--procedure: a fivebar has no 'paper' procedure (it has: exact)" in r.stderr
    assert not (tmp_path / "out").exists()


# ---------------------------------------------------------------- random constrained mechanisms


@st.composite
def constrained_mechanisms(draw, interval: bool = False):
    """A five-bar that assembles, with random limits, discs, polygons (star-shaped, so simple) and
    clearance, none over A1 or A2. Returns (FiveBar, the reference's (lengths, limits, obstacles,
    clearance))."""
    lengths = [draw(st.floats(0.5, 3.0)) for _ in range(5)]
    assume(assembles(lengths) is None)
    limits = {}
    for name in draw(st.lists(st.sampled_from(LIMIT_NAMES), unique=True, max_size=5)):
        lo = draw(st.floats(-180, 150))
        limits[name] = (lo, min(180.0, lo + draw(st.floats(20, 340))))
    reach = lengths[1] + lengths[3]
    obstacles, shapes = [], []
    for _ in range(draw(st.integers(0, 2))):
        cx, cy = draw(st.floats(-reach, reach)), draw(st.floats(-reach, reach))
        size = draw(st.floats(0.05, 0.4)) * reach
        if draw(st.booleans()):
            shapes.append(Disc((cx, cy), size))
            obstacles.append(("disc", ((cx, cy), size)))
        else:
            k = draw(st.integers(3, 6))
            angles = np.sort(np.array([draw(st.floats(0, 2 * np.pi)) for _ in range(k)]))
            gaps = np.diff(np.r_[angles, angles[0] + 2 * np.pi])
            assume(np.all(gaps > 0.3) and np.all(gaps < 0.9 * np.pi))  # centre inside: star-shaped, so simple
            radii = [size * draw(st.floats(0.4, 1.0)) for _ in range(k)]
            points = tuple((cx + r * math.cos(a), cy + r * math.sin(a)) for r, a in zip(radii, angles))
            shapes.append(Polygon(points))
            obstacles.append(("polygon", points))
    clearance = draw(st.sampled_from([0.0, 0.0, 0.05 * reach]))
    c = Constraints(tuple(Limit(n, *limits[n]) for n in LIMIT_NAMES if n in limits), tuple(shapes), clearance)
    assume(base_problem(c, (lengths[0], 0.0)) is None)
    if interval:
        width = draw(st.floats(0.005, 0.05))
        m = FiveBar.with_bounds("random", [(v - width, v + width) for v in lengths], c)
    else:
        m = FiveBar("random", *lengths, constraints=c)
    return m, (tuple(lengths), limits, obstacles, clearance)


def boundary_points(valid, lo, hi, rng, n: int = 1500) -> np.ndarray:
    """Points on the boundary of the set `valid` (boolean function of (n, 2) points) inside the box
    [lo, hi]: random short segments crossing it, bisected."""
    a = lo + rng.random((n, 2)) * (hi - lo)
    b = a + (hi - lo) * 0.02 * rng.standard_normal((n, 2))
    va, vb = valid(a), valid(b)
    a, b, va = a[va != vb], b[va != vb], va[va != vb]
    for _ in range(34):
        mid = 0.5 * (a + b)
        vm = valid(mid)
        same = vm == va
        a = np.where(same[:, None], mid, a)
        b = np.where(same[:, None], b, mid)
    return a


def boxes(points, lo, hi, rng, n: int):
    """Boxes of random sizes (10^-9 to 1 of the root), half of them at the given points."""
    centres = lo + rng.random((n, 2)) * (hi - lo)
    if len(points):
        near = rng.random(n) < 0.6
        centres[near] = points[rng.integers(0, len(points), int(near.sum()))]
    widths = (hi - lo) * 10.0 ** rng.uniform(-9, 0, (n, 2))
    blo = np.clip(centres - widths * rng.random((n, 2)), lo, hi)
    return blo, np.minimum(blo + widths, hi)  # within the root: a limited joint axis ends there


def samples(lo, hi, rng) -> np.ndarray:
    """(boxes, k, 2): a 6 x 6 grid with corners and edges, and random points."""
    return box_samples(lo, hi, rng, 6, 16)


class Reference:
    """Configurations and their constraints at sample points, from the independent references."""

    def __init__(self, m: FiveBar, data, lengths=None):
        self.m = m if lengths is None else FiveBar("sample", *lengths)
        self.lengths, self.limits, self.obstacles, self.clearance = data
        if lengths is not None:
            self.lengths = tuple(lengths)

    def work(self, pts, wm):
        """(exists, allowed, regular) at workspace points in a working mode."""
        th1, th2, u, v, t, ok = ref_ikp(self.m, pts[..., 0], pts[..., 1], wm)
        allowed = rc.allowed(self.lengths, self.limits, self.obstacles, self.clearance, np.nan_to_num(th1),
                             np.nan_to_num(th2), pts)
        return ok, ok & allowed, _regular(self.m, u, v, t)

    def joint(self, pts, am):
        x, y, u, v, t, ok = ref_dkp(self.m, pts[..., 0], pts[..., 1], am)
        p = np.nan_to_num(np.stack([x, y], -1))
        allowed = rc.allowed(self.lengths, self.limits, self.obstacles, self.clearance, pts[..., 0], pts[..., 1], p)
        return ok, ok & allowed, _regular(self.m, u, v, t)


def _regular(m, u, v, t):
    tol = 1e-9 * (m.L0 + m.L1 + m.L2 + m.L3 + m.L4) ** 2
    return (np.abs(u) > tol) & (np.abs(v) > tol) & (np.abs(t) > tol)


def assert_sound(status, exists, allowed, lo, hi, what):
    """1: every existing sampled configuration allowed; -1: none allowed."""
    bad_in = (status == 1) & (exists & ~allowed).any(axis=1)
    bad_out = (status == -1) & allowed.any(axis=1)
    assert not bad_in.any(), f"{what}: box {lo[bad_in][0]}..{hi[bad_in][0]} certified but holds a violating point"
    assert not bad_out.any(), f"{what}: box {lo[bad_out][0]}..{hi[bad_out][0]} excluded but holds an allowed point"


def _space_setup(m, space, rng, valid_any):
    root = np.array(m.spaces()[space].root)
    lo, hi = root[:, 0], root[:, 1]
    pts = boundary_points(valid_any, lo, hi, rng)
    return boxes(pts, lo, hi, rng, 120)


@SETTINGS
@given(case=constrained_mechanisms(), seed=st.integers(0, 2**32 - 1))
def test_workspace_constraint_tests_are_sound(case, seed):
    m, data = case
    rng = np.random.default_rng(seed)
    ref = Reference(m, data)
    valid_any = lambda p: np.any([ref.work(p, wm)[1] for wm in WORKING], axis=0)  # noqa: E731
    lo, hi = _space_setup(m, "workspace", rng, valid_any)
    pts = samples(lo, hi, rng)
    model = m.aspect_model()
    union = np.zeros(pts.shape[:2], bool)
    for wm in WORKING:
        exists, allowed, regular = ref.work(pts, wm)
        union |= allowed
        assert_sound(constrained.workspace_status(m, wm, lo, hi), exists, allowed, lo, hi, f"constraints {wm} of {m}")
        status = model.workspace_test(wm)(lo, hi)
        assert not ((status == 1) & ~(allowed & regular).all(axis=1)).any(), f"mode test {wm} of {m}"
        assert not ((status == -1) & allowed.any(axis=1)).any(), f"mode test {wm} of {m}"
    assert_sound(m.box_test("workspace")(lo, hi), np.ones_like(union), union, lo, hi, f"workspace of {m}")


# a box ending at theta1's limit (the root's end): lo + 1 * (hi - lo) once sampled an ulp past it
EDGE_OF_A_LIMIT = (FiveBar("random", 1.0, 1.0, 1.0, 1.0, 1.5, constraints=Constraints((Limit("theta1", -93.0, -3.5),))),
                   ((1.0, 1.0, 1.0, 1.0, 1.5), {"theta1": (-93.0, -3.5)}, [], 0.0))


@SETTINGS
@given(case=constrained_mechanisms(), seed=st.integers(0, 2**32 - 1))
@example(case=EDGE_OF_A_LIMIT, seed=1)
def test_jointspace_constraint_tests_are_sound(case, seed):
    m, data = case
    rng = np.random.default_rng(seed)
    ref = Reference(m, data)
    valid_any = lambda p: ref.joint(p, 1)[1] | ref.joint(p, -1)[1]  # noqa: E731
    lo, hi = _space_setup(m, "jointspace", rng, valid_any)
    pts = samples(lo, hi, rng)
    model = m.aspect_model()
    union = np.zeros(pts.shape[:2], bool)
    for am in (1, -1):
        exists, allowed, regular = ref.joint(pts, am)
        union |= allowed
        assert_sound(constrained.jointspace_status(m, am, lo, hi), exists, allowed, lo, hi, f"constraints {am} of {m}")
        status = model.jointspace_test(am)(lo, hi)
        assert not ((status == 1) & ~(allowed & regular).all(axis=1)).any(), f"mode test {am} of {m}"
        assert not ((status == -1) & allowed.any(axis=1)).any(), f"mode test {am} of {m}"
        free = model.parallel_free_test(am)(lo, hi)
        assert not ((free == 1) & ~allowed.all(axis=1)).any() and not ((free == -1) & allowed.any(axis=1)).any()
        possible, _ = model.jointspace_signs(am, lo, hi)
        assert not (~possible & (allowed & regular).any(axis=1)).any(), f"classifier {am} of {m}"
    assert_sound(m.box_test("jointspace")(lo, hi), np.ones_like(union), union, lo, hi, f"joint space of {m}")


@settings(max_examples=4, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(case=constrained_mechanisms(interval=True), seed=st.integers(0, 2**32 - 1))
def test_constraint_tests_with_interval_lengths_are_sound_for_every_length_vector(case, seed):
    """1: allowed for every length vector (the box's corners and random ones); -1: for none."""
    m, data = case
    rng = np.random.default_rng(seed)
    bounds = np.array(m.bounds)
    vectors = [bounds[np.arange(5), rng.integers(0, 2, 5)] for _ in range(3)] + \
        [bounds[:, 0] + rng.random(5) * (bounds[:, 1] - bounds[:, 0]) for _ in range(2)]
    refs = [Reference(m, data, lengths=v) for v in vectors]
    for space, keys, of in (("workspace", WORKING, constrained.workspace_status),
                            ("jointspace", (1, -1), constrained.jointspace_status)):
        root = np.array(m.spaces()[space].root)
        nominal = Reference(m.nominal(), data)
        get = (lambda r, p, k: r.work(p, k)) if space == "workspace" else (lambda r, p, k: r.joint(p, k))  # noqa: E731
        pts0 = boundary_points(lambda p: np.any([get(nominal, p, k)[1] for k in keys], axis=0), root[:, 0], root[:, 1], rng)
        lo, hi = boxes(pts0, root[:, 0], root[:, 1], rng, 80)
        pts = samples(lo, hi, rng)
        for key in keys:
            status = of(m, key, lo, hi)
            for r in refs:
                exists, allowed, _ = get(r, pts, key)
                assert_sound(status, exists, allowed, lo, hi, f"{space} {key} of {m} at {r.lengths}")


# ---------------------------------------------------------------- exact arithmetic at boundaries


M1 = (9, 8, 5, 5, 8)
mpmath.mp.dps = 40


def _exact_on_p_limit(th1: float) -> mpmath.mpf:
    """th2 with |B1B2|^2 = L3^2 + L4^2 exactly (the P angle at 90 degrees), near th2 = 0."""
    L0, L1, L2, L3, L4 = (mpmath.mpf(v) for v in M1)
    b1 = (L1 * mpmath.cos(th1), L1 * mpmath.sin(th1))

    def f(t):
        return (L0 + L2 * mpmath.cos(t) - b1[0]) ** 2 + (L2 * mpmath.sin(t) - b1[1]) ** 2 - (L3 ** 2 + L4 ** 2)

    grid = np.linspace(-np.pi, np.pi, 721)
    k = next(i for i in range(720) if f(grid[i]) * f(grid[i + 1]) < 0)
    return mpmath.findroot(f, (mpmath.mpf(grid[k]), mpmath.mpf(grid[k + 1])), solver="anderson")


@pytest.mark.parametrize("th1", [0.9, 1.2, 1.7])
def test_boxes_at_the_p_limit_are_decided_only_when_exactly_on_one_side(th1):
    """Joint-space boxes of width 1e-13 .. 1e-7 in th2 at exact distances -1e-6 .. +1e-6 from the
    curve where the P angle is exactly 90 degrees: a box holding the curve is never decided, a box
    off it is decided only on its own side (mpmath decides the side of each box's th2 interval)."""
    m = FiveBar("M1", *M1, constraints=Constraints((Limit("P", -90, 90),)))
    star = _exact_on_p_limit(mpmath.mpf(th1))
    offsets = [s * 10.0 ** e for e in range(-14, -5) for s in (-1, 1)] + [0.0]
    lo, hi, side = [], [], []
    for off in offsets:
        for width in (1e-13, 1e-10, 1e-7):
            a = float(star + mpmath.mpf(off))
            lo.append((th1, a - width / 2))
            hi.append((th1, a + width / 2))
            b0, b1 = mpmath.mpf(a - width / 2), mpmath.mpf(a + width / 2)
            side.append(0 if b0 <= star <= b1 else (1 if b0 > star else -1))
    lo, hi = np.array(lo), np.array(hi)
    for am in (1, -1):
        status = constrained.jointspace_status(m, am, lo, hi)
        # |B1B2| grows with th2 here (check the sign of the derivative at the root)
        for s, got in zip(side, status):
            if s == 0:
                assert got == 0
            elif got != 0:
                d2 = lambda t: (9 + 5 * mpmath.cos(t) - 8 * mpmath.cos(th1)) ** 2 + (5 * mpmath.sin(t) - 8 * mpmath.sin(th1)) ** 2  # noqa: E731
                grows = mpmath.diff(d2, star) > 0
                inside = (s < 0) == grows  # below the root the distance is smaller: |P angle| < 90
                assert got == (1 if inside else -1)


def test_a_crank_tangent_to_a_disc_is_never_certified_free():
    """M1 with a disc tangent (exactly, mpmath at 40 digits) to the crank A1B1 at th1 = t0, on the
    side of growing th1: joint-space boxes of width 1e-13 .. 1e-6 around t0 hold a touching
    configuration, so none is certified within the constraints; boxes from a hair past t0 on (where
    mpmath says the crank enters the disc) are never certified either."""
    t0 = mpmath.mpf("0.7")
    radius = mpmath.mpf("0.5")
    centre = (4 * mpmath.cos(t0) - radius * mpmath.sin(t0), 4 * mpmath.sin(t0) + radius * mpmath.cos(t0))
    disc = Disc((float(centre[0]), float(centre[1])), float(radius))
    m = FiveBar("M1", *M1, constraints=Constraints((), (disc,)))

    def crank_gap(th1):  # exact distance from the disc to the crank at th1, minus the radius
        u = (mpmath.cos(th1), mpmath.sin(th1))
        c = (mpmath.mpf(disc.centre[0]), mpmath.mpf(disc.centre[1]))
        along = min(max(c[0] * u[0] + c[1] * u[1], 0), 8)
        return mpmath.hypot(c[0] - along * u[0], c[1] - along * u[1]) - mpmath.mpf(disc.radius)

    lo, hi = [], []
    for width in (1e-13, 1e-10, 1e-6):
        lo += [(float(t0) - width, -2.5), (float(t0) + 1e-9, -2.5)]
        hi += [(float(t0) + width, -2.5 + width), (float(t0) + 1e-9 + width, -2.5 + width)]
        assert crank_gap(mpmath.mpf(lo[-1][0])) < 0 and crank_gap(mpmath.mpf(hi[-1][0])) < 0
    lo, hi = np.array(lo), np.array(hi)
    assert abs(crank_gap(t0)) < mpmath.mpf(10) ** -15  # the float disc is tangent to within rounding
    for am in (1, -1):
        assert (constrained.jointspace_status(m, am, lo, hi) != 1).all()


def test_arc_status_on_the_seam_and_a_whole_turn():
    lo, hi = np.array([3.0, -3.2, 0.1]), np.array([3.3, -3.0, 0.2])
    # [170, 190] degrees wraps across the seam: both first boxes are within it
    assert constrained.arc_status(lo, hi, math.radians(170), math.radians(180)).tolist() == [0, 0, -1]
    assert constrained.arc_status(lo, hi, -math.pi, math.pi).tolist() == [1, 1, 1]
    assert constrained.arc_status(np.array([3.0]), np.array([3.1]), math.radians(160), math.radians(180)).tolist() == [1]
    # [-183.3, -180.5] degrees is [176.7, 179.5]: inside [170, 180], outside [-180, -170]
    assert constrained.arc_status(np.array([-3.2]), np.array([-3.15]), math.radians(170), math.radians(180)).tolist() == [1]
    assert constrained.arc_status(np.array([-3.2]), np.array([-3.15]), math.radians(-180), math.radians(-170)).tolist() == [-1]
