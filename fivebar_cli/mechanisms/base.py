"""What a mechanism kind declares, so that every analysis handles every kind the same way.

A kind is one class deriving from `Mechanism` (an immutable dataclass of its parameters) in a
package of its own under `fivebar_cli/mechanisms/`, plus one line in `registry.py` (or an entry
point of group `fivebar.mechanisms` in a third-party package). It declares:

- its YAML schema: `parse(data, source)` builds the model from the file's mapping;
- a one-line, round-trippable `describe()` (the `.qt` `mechanism:` header) and its inverse
  `from_description(fields, name, source)`, so that `refine` can resume a saved paving;
- its spaces: name, what a black cell means, and the axes (name, unit, root interval, periodic);
- optionally more regions of a space than its own (`regions`: e.g. the singularity-free parts
  of a 3-RPR's workspace, one per sign of det J), each paved like the space itself;
- a box test per space, procedure and region (`box_test`), the exact measure of a space (or
  region) when a closed form is known, and, for 2-DOF mechanisms with working and assembly modes,
  an `AspectModel`; or, for mechanisms whose aspects live in one space of poses (the 3-RPR over
  (x, y, phi)), a `PoseAspectModel`.

A box test takes arrays lo, hi of shape (m, dim) and returns int8: 1 when every point of the box
belongs to the set, -1 when none does, 0 when it cannot tell. It must be sound (docs/formats.md,
"What certified means"); the paving engine already widens each box to cover its own rounding.
"""

from __future__ import annotations

from contextvars import ContextVar
from dataclasses import dataclass
from typing import Callable, ClassVar, Mapping, Protocol

import numpy as np

from fivebar_cli.io.schema import ConfigError
from fivebar_cli.paving.grid import Grid

BoxTest = Callable[[np.ndarray, np.ndarray], np.ndarray]
MultiTest = Callable[..., np.ndarray]  # paving.engine.MultiTest: (lo, hi, open, ends) -> statuses


@dataclass(frozen=True)
class Axis:
    """One axis of a space: its name, unit ('' for the mechanism's length unit), root interval."""

    name: str
    lo: float
    hi: float
    unit: str = ""
    periodic: bool = False
    label: str = ""  # for figures (matplotlib mathtext); the name when empty

    @property
    def title(self) -> str:
        """Axis title for a figure: label and unit."""
        text = self.label or self.name
        return f"{text} ({self.unit})" if self.unit else text


@dataclass(frozen=True)
class Space:
    """A space a mechanism is paved in, and what a black cell of it means (`region`)."""

    name: str
    region: str
    axes: tuple[Axis, ...]

    @property
    def dim(self) -> int:
        return len(self.axes)

    @property
    def root(self) -> tuple[tuple[float, float], ...]:
        return tuple((a.lo, a.hi) for a in self.axes)

    def grid(self, depth: int) -> Grid:
        return Grid(self.root, depth, tuple(a.periodic for a in self.axes))

    def axes_header(self) -> str:
        """The `.qt` `axes:` value, e.g. 'x y phi[deg]' (written for trees of 3 or more axes)."""
        return " ".join(f"{a.name}[{a.unit}]" if a.unit else a.name for a in self.axes)


def article(kind: str) -> str:
    """A kind's name with its article, as it is read aloud: 'a fivebar', 'an rpr3', 'an rpr2'."""
    return f"{'an' if kind[:1].lower() in 'aeiour' else 'a'} {kind}"


def is_choice(value, choices) -> bool:
    """Whether `value` is one of the names `choices` (a space, a region, a mode): a str among them.
    Anything else is none, without the membership test's own errors (a list or a dict is
    unhashable, a numpy array compares element-wise)."""
    return isinstance(value, str) and value in choices


def plural(n: int, word: str, words: str | None = None) -> str:
    """'1 aspect', '2 aspects' (`words`: an irregular plural): counts in messages."""
    return f"{n} {word if n == 1 else (words or word + 's')}"


_PARSING: ContextVar[bool] = ContextVar("fivebar_parsing_a_mechanism", default=False)


class Mechanism:
    """Base of every mechanism kind: subclasses are frozen dataclasses with a `name` field.

    A model built from Python (`FiveBar("M1", 9, 8, 5, 5, 8)`) is validated exactly as a YAML file
    is: by the kind's own `parse`, through `describe` and `from_description` (`check_model`), so a
    NaN, a negative length or a loop that never closes is the same ConfigError (a ValueError) either
    way. Inside `parse` the check is skipped: parse is the check.
    """

    kind: ClassVar[str] = ""  # the YAML `type`
    procedures: ClassVar[tuple[str, ...]] = ("exact",)  # box-test families; "exact" comes first
    name: str

    def __init_subclass__(cls, **kwargs):
        super().__init_subclass__(**kwargs)
        parse = cls.__dict__.get("parse")
        if isinstance(parse, classmethod):  # models built inside parse are checked by parse itself
            cls.parse = classmethod(_while_parsing(parse.__func__))

    def __post_init__(self) -> None:
        if not _PARSING.get():
            check_model(self)

    @classmethod
    def parse(cls, data: Mapping, source: str) -> "Mechanism":
        """The model from the YAML mapping of a mechanism file (ConfigError on any problem)."""
        raise NotImplementedError

    @classmethod
    def from_description(cls, fields: Mapping[str, str], name: str, source: str) -> "Mechanism":
        """Inverse of `describe`: `fields` are its `key=value` words."""
        raise NotImplementedError

    def describe(self) -> str:
        """One line '<kind> key=value ...' naming every parameter exactly (repr floats)."""
        raise NotImplementedError

    def spaces(self) -> dict[str, Space]:
        """The spaces this mechanism can be paved in, by name (may be empty)."""
        return {}

    def regions(self, space: str) -> tuple[str, ...]:
        """The regions a space can be paved for (the `.qt` `region:` values); the first is the
        space's own region, which is what `box_test` certifies when no region is given."""
        return (self.spaces()[space].region,)

    def box_test(self, space: str, procedure: str = "exact", region: str | None = None) -> BoxTest:
        """The box test of a region of a space (None: the space's own region)."""
        raise NotImplementedError

    def exact_measure(self, space: str, region: str | None = None) -> float | None:
        """The exact area (volume) of the set a space's (region's) black cells approximate, when known."""
        return None

    def printed_k_percent(self, space: str, depth: int) -> int | None:
        """K (whole percent) a paper prints for this mechanism, space and depth, if any."""
        return None

    def aspect_model(self) -> "AspectModel | None":
        """What the generalized-aspect analysis needs, or None when the kind has no aspects."""
        return None

    def pose_aspect_model(self) -> "PoseAspectModel | None":
        """What the one-space aspect analysis (aspects, dkp, locate, path over a space of poses)
        needs, or None when the kind has none."""
        return None

    def check_bounded(self, source: str) -> None:
        """A kind with poses whose space of poses is missing (a 3-RPR's, when rho_max auto is
        infinite) raises `no_pose_space`'s error; any other mechanism passes."""
        if self.has_poses and not self.spaces():
            raise self.no_pose_space(source)

    def no_pose_space(self, source: str) -> ConfigError:
        """The error to raise where a space of poses is needed and `pose_aspect_model` is None:
        this kind has none (`type`); a kind with poses says why its own is missing."""
        return ConfigError(source, "type", f"{article(self.kind)} has no space of poses (x, y, phi): "
                           "only a 3-RPR or a 3-RRR has one")

    # Capabilities a kind may declare (the five-bar declares them all), asked instead of probed.
    widens: ClassVar[bool] = False  # its lengths can be widened into intervals (`widened`)
    crosses_serial: ClassVar[bool] = False  # its aspect model has `parallel_free_test` (path --allow-serial)
    has_poses: ClassVar[bool] = False  # its configurations are poses (x, y, phi) (`pose_aspect_model`, once bounded)
    constraints = ()  # its joint limits and obstacles (falsy: none)

    @property
    def is_interval(self) -> bool:
        """Whether some parameter is an interval of positive width (robust analyses)."""
        return False

    def widened(self, tolerance: float, source: str) -> "Mechanism":
        """Every length widened to [L - T, L + T] (a kind with `widens`)."""
        raise NotImplementedError(f"{self.kind} has no interval lengths")

    def nominal(self) -> "Mechanism":
        """The mechanism with its nominal parameters (itself unless `is_interval`)."""
        return self

    def unconstrained(self) -> "Mechanism":
        """The mechanism without its joint limits and obstacles (itself when it has none)."""
        return self

    def marks(self, space: str) -> list[dict]:
        """What figures draw over a space: obstacles, joint limits (none by default)."""
        return []


def _while_parsing(parse):
    def parse_checked(cls, data, source="<config>", *args, **kwargs):
        token = _PARSING.set(True)
        try:
            return parse(cls, data, source, *args, **kwargs)
        finally:
            _PARSING.reset(token)

    parse_checked.__doc__, parse_checked.__name__ = parse.__doc__, parse.__name__
    return parse_checked


def check_model(m: Mechanism) -> None:
    """ConfigError (a ValueError) unless `m` is a model its kind's YAML would give: `m.describe()`
    read back by `from_description` (which calls `parse`) must succeed and give `m` again. Kinds of
    plugins without a description are not checked."""
    source = f"{type(m).__name__}(...)"
    try:
        text = m.describe()
    except NotImplementedError:
        return
    except (TypeError, ValueError) as exc:
        raise ConfigError(source, "", f"not a valid {m.kind or type(m).__name__}: {exc}") from None
    fields = dict(word.partition("=")[::2] for word in text.split()[1:])
    name = m.name if isinstance(m.name, str) else repr(m.name)
    token = _PARSING.set(True)
    try:
        parsed = type(m).from_description(fields, name, source)
    finally:
        _PARSING.reset(token)
    if parsed != m:
        raise ConfigError(source, "", f"its fields do not describe one {m.kind}: they read back as {parsed!r}")


def describe_fields(kind: str, fields: Mapping[str, float]) -> str:
    """The usual description: the kind, then `key=repr(value)` words."""
    return kind + "".join(f" {k}={float(v)!r}" for k, v in fields.items())


def description_numbers(fields: Mapping[str, str], keys, source: str) -> dict[str, float]:
    """Numbers of a description's `key=value` words, for `from_description`."""
    out = {}
    for key in keys:
        if key not in fields:
            raise ConfigError(source, "mechanism", f"missing {key}= in the mechanism description")
        try:
            out[key] = float(fields[key])
        except ValueError:
            raise ConfigError(source, "mechanism", f"bad value {key}={fields[key]!r}") from None
    extra = sorted(set(fields) - set(keys))
    if extra:
        raise ConfigError(source, "mechanism", f"unknown parameter {extra[0]!r} in the mechanism description")
    return out


def pair_word(point) -> str:
    """A point as a description word's value: 'x,y' (repr floats)."""
    return f"{float(point[0])!r},{float(point[1])!r}"


def values_word(values) -> str:
    """Per-leg values as a description word's value: one number when all are equal, else 'a,b,c'."""
    if len(set(values)) == 1:
        return repr(float(values[0]))
    return ",".join(repr(float(v)) for v in values)


def word_values(word: str | None, counts: tuple[int, ...], key: str, source: str) -> list[float]:
    """The comma-separated numbers of a description word's value (as many as one of `counts`)."""
    if word is None:
        raise ConfigError(source, "mechanism", f"missing {key}= in the mechanism description")
    try:
        values = [float(v) for v in word.split(",")]
    except ValueError:
        raise ConfigError(source, "mechanism", f"bad value {key}={word!r}") from None
    if len(values) not in counts:
        raise ConfigError(source, "mechanism", f"{key}= needs {' or '.join(map(str, counts))} comma-separated "
                          f"numbers, got {word!r}")
    return values


def legs_word_value(word: str | None, key: str, source: str):
    """A per-leg description value: one number (every leg) or a list of three, as the YAML has it."""
    values = word_values(word, (1, 3), key, source)
    return values[0] if len(values) == 1 else values


class AspectModel(Protocol):
    """What the generalized-aspect analysis (`analyses/aspects.py`) needs from a 2-DOF mechanism.

    Modes are signs: a working mode is the sign vector of the diagonal of the serial Jacobian B
    (one sign per leg; 0 on a serial singularity), an assembly mode the sign of det A (0 on a
    parallel singularity). The workspace is paved once per working mode (the IKP branch), the joint
    space once per assembly mode (the DKP branch); a black cell is valid and non-singular, so
    singularities stay undetermined and separate the regions.
    """

    working_modes: tuple[tuple[int, ...], ...]  # in the order aspects are numbered
    assembly_modes: tuple[int, ...]
    serial_names: tuple[str, ...]  # name of the serial singularity where each working sign vanishes
    length_scale: float  # a typical length (sum of link lengths): tolerances are relative to it

    def workspace_test(self, working: tuple[int, ...]) -> BoxTest: ...

    def jointspace_test(self, assembly: int) -> BoxTest: ...

    def workspace_tests(self, workings: tuple[tuple[int, ...], ...]) -> MultiTest:
        """The workspace tests of several working modes as one multi-test (`paving.engine`): the
        analysis paves a space once for all its modes (`paving.engine.stacked` when they share
        no work)."""

    def jointspace_tests(self, assemblies: tuple[int, ...]) -> MultiTest:
        """The joint-space tests of several assembly modes as one multi-test."""

    def assembly_signs(self, working: tuple[int, ...], points: np.ndarray) -> np.ndarray:
        """Sign of det A at workspace points in a working mode, shape (n,) (0: unreachable)."""

    def working_signs(self, assembly: int, points: np.ndarray) -> np.ndarray:
        """Working-mode signs at joint-space points in an assembly mode, shape (n, w) (0: none)."""

    def ikp(self, points: np.ndarray, working: tuple[int, ...]) -> tuple[np.ndarray, np.ndarray]:
        """Joint values (n, 2) of workspace points in a working mode, and where they exist."""

    def dkp(self, points: np.ndarray, assembly: int) -> tuple[np.ndarray, np.ndarray]:
        """Poses (n, 2) of joint-space points in an assembly mode, and where they exist."""

    def mode_values(self, joints: np.ndarray, poses: np.ndarray) -> np.ndarray:
        """(n, w + 1): the diagonal of B, then det A, at configurations (joints, poses)."""

    # The four classifiers below take the boxes (lo, hi) and, when the caller has them, their ends
    # as tables (`ends`: `grid.AxisEnds` per axis, as the paving's multi-tests do): a model may
    # compute what depends on one axis's interval alone per table entry, or ignore them.

    def workspace_signs(self, working: tuple[int, ...], lo: np.ndarray, hi: np.ndarray,
                        ends=None) -> tuple[np.ndarray, np.ndarray]:
        """Per workspace box, in a working mode: (may hold a reachable point, sign of det A over the
        box's reachable points as an (n, 1) array, 0 where it is not constant). A box where this
        sign is certified is certified outside the aspects of the other sign (the outer sets)."""

    def jointspace_signs(self, assembly: int, lo: np.ndarray, hi: np.ndarray, ends=None) -> tuple[np.ndarray, np.ndarray]:
        """Per joint-space box, in an assembly mode: (may hold an assemblable point, working signs
        over its assemblable points, (n, w), 0 where not constant)."""

    def serial_band_signs(self, assembly: int, lo: np.ndarray, hi: np.ndarray, ends=None) -> tuple[np.ndarray, np.ndarray]:
        """Per joint-space box: (certified free of parallel singularity, working signs with 0 where
        not constant), to find the cells crossed by one serial singularity only."""

    def jointspace_band_signs(self, assembly: int, lo: np.ndarray, hi: np.ndarray, ends=None) -> tuple[np.ndarray, ...]:
        """`jointspace_signs` and `serial_band_signs` of the same boxes (their working signs are the
        same), from one classification: (may hold an assemblable point, working signs, certified
        free of parallel singularity). The aspects classify a region's undetermined cells once."""

    # With `Mechanism.crosses_serial` (`fivebar path --allow-serial`): a joint-space box test, 1
    # where every point assembles in `assembly` with det A != 0 (serial singularities allowed), -1
    # where none does.
    # def parallel_free_test(self, assembly: int) -> BoxTest: ...


# ---------------------------------------------------------------- aspects in one space of poses


@dataclass(frozen=True)
class SignClass:
    """One class of poses of a `PoseAspectModel`: the signs that are constant on an aspect, as
    named columns of `aspects.csv` and header keys of the aspect trees, e.g. (("det_sign", "+"),)
    for a 3-RPR, (("working_mode", "+-+"), ("det_sign", "-")) for a 3-RRR."""

    fields: tuple[tuple[str, str], ...]

    @property
    def label(self) -> str:
        """'det_sign +' or 'working_mode +-+, det_sign -': for reports."""
        return ", ".join(f"{k} {v}" for k, v in self.fields)


class PoseSystem(Protocol):
    """The equations F(pose) = 0 of the poses with given joint values (the direct kinematic
    problem), in the units of the pose space's axes (phi in degrees for a 3-RPR)."""

    def values(self, poses: np.ndarray) -> np.ndarray:
        """F at poses (n, d), floating point: (n, d)."""

    def jacobian(self, poses: np.ndarray) -> np.ndarray:
        """dF/dpose at poses (n, d), floating point: (n, d, d)."""

    def enclosure(self, lo: np.ndarray, hi: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
        """Over boxes [lo, hi] (n, d): certified bounds of F, (n, d) each, and of the Jacobian,
        (n, d, d) each (outward rounded); a point box gives an enclosure of F at that point."""

    def classes_of_boxes(self, lo: np.ndarray, hi: np.ndarray) -> np.ndarray:
        """The class certified over each box of poses with these joints, -1 where not certified,
        below -1 where certified in none of the model's classes (a working mode the model leaves
        out: such a solution is not one of its configurations and is not counted). The model's
        `classes_of_boxes` on sheet 0, unless the joints decide a solution's sheet (a 3-RRR's
        working mode follows from its actuated angles)."""


class PoseAspectModel(Protocol):
    """What the one-space aspect analysis (`analyses/pose_aspects.py`), `dkp.py`, `pose_paths.py`
    and the commands on them need from a kind whose aspects live in a space of poses.

    The poses are split into sign classes (a 3-RPR: the sign of det J; a 3-RRR: working mode and
    sign of det A); an aspect is a connected component of the valid (legs in range), non-singular
    poses of one class. Each class has a box test whose black cells are valid and non-singular in
    that class (so singularities stay undetermined and separate the aspects) and whose -1 means no
    pose of the box is a valid pose of that class. The space may have a periodic axis (a full turn
    of the platform); the joint space may be a box or a torus (`joint_axes`).

    A configuration is a pose and, when the pose alone does not decide it, a choice the IKP makes
    (a 3-RRR's working mode: a pose is reached in eight). The classes are then grouped into
    `sheets`, one per choice, each a `SignClass` of the fields chosen (("working_mode", "+-+"),);
    a class belongs to the sheet whose fields it carries, and a pose has one class in each sheet.
    A kind whose pose decides has one sheet of no fields.
    """

    space: str  # the name of the space in `Mechanism.spaces()` (e.g. "workspace": x, y, phi)
    classes: tuple[SignClass, ...]  # in the order aspects are numbered
    sheets: tuple[SignClass, ...]  # the choices besides the pose; (SignClass(()),) when the pose decides
    joint_axes: tuple[Axis, ...]  # the actuated joints: names, units, ranges, periodic
    length_scale: float  # a typical length: tolerances are relative to it
    singularity_name: str  # the file column of `singularity` ("det_j", "det_a")

    def class_test(self, k: int) -> BoxTest:
        """1: every pose of the box is valid, non-singular and of class k; -1: none is."""

    # Optional: the tests of several classes at once (of any sheets), sharing their work (a
    # `paving.engine.MultiTest`, column c that of `class_test(ks[c])`): their pavings are made
    # together (`pose_aspects.class_regions`), as are their deeper pavings (`_deeper_pavings`).
    # def class_tests(self, ks: tuple[int, ...]) -> MultiTest: ...

    def valid_test(self, sheet: int | None = None) -> BoxTest:
        """1: every pose of the box is valid (joints in range, no serial singularity, within the
        constraints of `sheet`, or of some sheet when None); -1: none is."""

    def classes_of_boxes(self, lo: np.ndarray, hi: np.ndarray, sheet: int = 0) -> np.ndarray:
        """The class of `sheet` whose signs hold at every pose of each box, validity aside (the
        joint limits are not checked), certified; -1 where the signs are not certified constant."""

    def valid(self, poses: np.ndarray, sheet: int | None = None) -> np.ndarray:
        """Whether poses (n, d) satisfy every constraint (joints in range; joint limits and
        obstacles in `sheet`, or in some sheet when None), floating point."""

    # Optional, for a kind with joint limits or obstacles (`Mechanism.constraints`): per pose, the
    # labels of the constraints it violates in a sheet ('B1 limit', 'obstacle 2'), for `locate`.
    # def violated_constraints(self, poses: np.ndarray, sheet: int) -> list[list[str]]: ...

    def ikp(self, poses: np.ndarray, k: int) -> tuple[np.ndarray, np.ndarray]:
        """Joint values (n, j) of poses in class k, and where they exist."""

    def singularity(self, poses: np.ndarray, k: int) -> np.ndarray:
        """The value whose sign tells the classes of k's sheet apart (det J, det A), floating point (n,)."""

    def dkp_system(self, joints: np.ndarray) -> PoseSystem:
        """The equations of the poses with joint values `joints` (j,), for class-free solving."""

    def sketch(self, poses: np.ndarray, classes=0) -> dict[str, np.ndarray]:
        """Planar drawing of the mechanism at poses (n, d) in classes `classes` (one, or one per
        pose), for figures: 'base' (k, 2), a closed polygon; 'platform' (n, m, 2), closed
        polygons; 'links' (n, s, 2, 2), segments."""
