"""The public functions: a mechanism in, an immutable result out (`values.py`); the commands of
`fivebar` call these too. Messages name the Python arguments (`errors.param`: `tolerance`,
`depth=12`), never a command-line flag: the CLI spells them as its options (`cli/options.as_flags`)."""

from __future__ import annotations

import os
import pathlib
from collections.abc import Mapping

from fivebar_cli.analyses.limits import (
    MAX_ASPECT_DEPTH, MAX_DEPTH, check_count, check_depth, check_paving_depth,
)
from fivebar_cli.api.values import Aspect, Aspects, Path, Paving, finite_points, motion_where
from fivebar_cli.errors import InputError, param
from fivebar_cli.io.files import user_path
from fivebar_cli.mechanisms.base import Mechanism, article, is_choice

DEFAULT_DEPTH = 10


def examples() -> dict[str, pathlib.Path]:
    """The mechanisms of both papers shipped with the package, by name (`m1`, `m2`, `rpr3-caro`,
    `rpr3-verify/table1-case1`, ...) -> the path of the YAML file (what `fivebar examples` lists)."""
    root = examples_folder()
    return {p.relative_to(root).with_suffix("").as_posix(): p for p in sorted(root.rglob("*.yaml"))}


def copy_examples(folder, *, replace: bool = False) -> list[pathlib.Path]:
    """Copy every shipped example into `folder` as `<name>.yaml` (`rpr3-verify/...` in its
    subfolder), byte for byte, to edit them or to run `reproduce` on them; the paths written.

    A file already there with other bytes is an edited copy: it is not replaced unless `replace`,
    and then nothing is copied at all (OutputError naming it), so that a second copy into the same
    folder never loses an edit. A file already holding the shipped bytes is left as it is (not
    in the paths written): its modification time stays, so `make`-like tools see nothing new.

    Examples
    --------
    >>> import tempfile, fivebar_cli as fb
    >>> with tempfile.TemporaryDirectory() as folder:
    ...     written = fb.copy_examples(folder)
    ...     (pathlib.Path(folder) / "m1.yaml").read_bytes() == fb.examples()["m1"].read_bytes()
    True
    """
    from fivebar_cli.errors import OutputError, Text
    from fivebar_cli.io.files import check_writable_dir, refuse_special, write_text

    folder = check_writable_dir(user_path(folder, "folder"))
    shipped = {folder / f"{name}.yaml": path.read_text(encoding="utf-8") for name, path in examples().items()}
    for target in shipped:
        refuse_special(target)  # (a link, a folder, a FIFO in the way: refused before anything is written)
    there = {target: target.read_bytes() for target in shipped if target.exists()}
    to_write = {target: text for target, text in shipped.items() if there.get(target) != text.encode()}
    edited = [target for target in to_write if target in there]
    if edited and not replace:
        one = len(edited) == 1
        which = f"{edited[0]}" if one else f"{edited[0]} and {len(edited) - 1} more"
        what = "the shipped example's bytes (an edited copy?)" if one else "the shipped examples' bytes (edited copies?)"
        raise OutputError(Text(f"{which}: not {what}: nothing copied; ", param("replace", True),
                               " replaces " + ("it" if one else "them")))
    return [write_text(target, text) for target, text in to_write.items()]


def examples_folder() -> pathlib.Path:
    """The folder of the shipped examples (the repository's configs/, as package data)."""
    return pathlib.Path(__file__).resolve().parent.parent / "examples"


def load(source, *, tolerance: float = 0.0, kind: str | None = None, space: str | None = None) -> Mechanism:
    """A mechanism from a YAML file, a mapping with the same schema, or the name of a shipped example.

    Parameters
    ----------
    source : str, os.PathLike or Mapping
        A config file (`configs/m1.yaml`), a dict (`{"type": "fivebar", "name": "M1", ...}`) or an
        example's name (`"m1"`, see `examples()`).
    tolerance : float
        Widen every link length to [L - T, L + T] (robust analyses); 0 keeps the nominal lengths.
    kind, space : str, optional
        Require this kind (`"rpr3"`) or this space (`"workspace"`): InputError otherwise.

    Examples
    --------
    >>> import fivebar_cli as fb
    >>> fb.load("m1").name
    'M1'
    """
    from fivebar_cli.mechanisms.registry import check_kind, load_config, parse

    for name, value, example in (("kind", kind, "rpr3"), ("space", space, "workspace")):
        if value is not None and not isinstance(value, str):
            raise InputError("", param(name), f"expected a name ({example}, ...) or None, got {value!r}")
    if isinstance(source, Mechanism):
        m = check_kind(source, source.name, kind, space)
    elif isinstance(source, Mapping):
        m = check_kind(parse(dict(source), "<mapping>"), "<mapping>", kind, space)
    else:
        m = load_config(file_or_example(source, "source", "a file path, a mapping or an example's name"), kind, space)
    return widened(m, tolerance, source_name(source))


def file_or_example(source, field: str, expected: str) -> pathlib.Path:
    """The file `source` names (`user_path`), or where no such file exists the shipped example of
    that name (`examples()`); ConfigError when neither, naming the example meant when one is close."""
    path = user_path(source, field, expected)
    if path.exists():
        return path
    example = examples().get(str(source))
    if example is None:
        raise _no_such_file(path)
    return example


def _no_such_file(path: pathlib.Path) -> InputError:
    """The ConfigError for a source that is no file and no example's name, naming the example
    meant when one is close (`m11`, `rpr3caro`, `M1`: a typo, not a missing file)."""
    import difflib

    from fivebar_cli.io.schema import ConfigError

    names = {name.lower(): name for name in examples()}
    close = difflib.get_close_matches(str(path).lower(), names, n=1)
    meant = f", nor a shipped example's name: did you mean {names[close[0]]!r}?" if close else ""
    return ConfigError(str(path), "", "no such file" + meant)


def source_name(source) -> str:
    """How messages name where a mechanism came from: its file, `<mapping>`, or its name."""
    if isinstance(source, Mechanism):
        return source.name
    return "<mapping>" if isinstance(source, Mapping) else str(source)


def widened(m: Mechanism, tolerance: float | None, source) -> Mechanism:
    """The mechanism with its lengths widened by `tolerance` (0 or None: unchanged); InputError for
    a kind without interval lengths, or for a tolerance that is no number (a str; a bool, not
    taken as 0 or 1)."""
    from fivebar_cli.io.schema import is_number

    if tolerance is None:
        return m
    if not is_number(tolerance):
        raise InputError(str(source), param("tolerance"), f"must be a finite number >= 0, got {tolerance!r}")
    if not tolerance:
        return m
    if not m.widens:
        raise InputError(str(source), param("tolerance"), f"{article(m.kind)} has no interval lengths")
    return m.widened(tolerance, str(source))


def with_aspects(m: Mechanism, source) -> Mechanism:
    """`m`, checked to have working and assembly modes or aspects over its poses (InputError on its
    `type` otherwise; a kind with poses whose space of poses is unbounded, on `legs.rho_max`)."""
    if m.aspect_model() is None and m.pose_aspect_model() is None:
        m.check_bounded(str(source))  # (a 3-RPR whose legs are unbounded: why)
        raise InputError(str(source), "type", f"{article(m.kind)} has no working and assembly modes (no aspects)")
    return m


def per_level(advance):
    """The pavings' hook `on_level(level, cells)` in the API's progress convention: one step of
    `advance(n=1)` per level paved (None stays None)."""
    return None if advance is None else (lambda level, cells: advance(1))


def _mechanism(mech) -> Mechanism:
    return mech if isinstance(mech, Mechanism) else load(mech)


# ---------------------------------------------------------------- pavings


def pave(mech, space: str = "workspace", depth: int = DEFAULT_DEPTH, *, tolerance: float | None = None,
         region: str | None = None, procedure: str = "exact", advance=None) -> Paving:
    """Certified paving of one space of a mechanism (or of one region of it) to `depth`.
    `advance(n=1)`: told of each level paved (depth + 1 steps at most: fewer when no cell is left
    undetermined).

    Examples
    --------
    >>> import fivebar_cli as fb
    >>> p = fb.pave(fb.load("m1"), "workspace", 6)
    >>> round(p.inside_area, 3) > 0
    True
    """
    from fivebar_cli.analyses import spaces

    depth = check_depth(depth, MAX_DEPTH)
    m = widened(_mechanism(mech), tolerance, source_name(mech))
    # (the call's own arguments: named without a source, as `depth` is)
    if not is_choice(space, m.spaces()):
        m.check_bounded(source_name(mech))  # (a 3-RPR whose legs are unbounded: why)
        raise InputError("", param("space"), f"{space!r} is not a space of {article(m.kind)} "
                         f"(it has: {', '.join(m.spaces())})")
    own = None if region is None or is_choice(region, (m.spaces()[space].region,)) else region
    if own is not None and not is_choice(own, m.regions(space)):
        raise InputError("", param("region"), f"{region!r} is not a region of its {space} "
                         f"(it has: {', '.join(m.regions(space))})")
    if not is_choice(procedure, m.procedures):
        raise InputError("", param("procedure"), f"{article(m.kind)} has no {procedure!r} procedure "
                         f"(it has: {', '.join(m.procedures)})")
    depth = check_paving_depth(depth, m.spaces()[space].dim)
    p = spaces.pave_space(m, space, depth, procedure, per_level(advance), own)
    return Paving(m, space, depth, procedure, own, p, p.evaluations)


def refine(paving, depth: int, *, advance=None) -> Paving:
    """A paving deepened to `depth`, testing only its undetermined cells; `paving` is a `Paving` or
    the path of a saved `.qt` file (either of its pair). Equals a fresh paving at `depth`; its
    `evaluations` count those of the saved paving too. `advance(n=1)`: told of each new level."""
    from fivebar_cli.analyses import spaces
    from fivebar_cli.paving import engine

    depth = check_depth(depth, MAX_DEPTH)
    if isinstance(paving, Paving):
        depth = check_paving_depth(depth, paving.inside.grid.dim)
        if depth < paving.depth:
            raise InputError(paving.mechanism.name, param("depth"), f"{depth} is below the paving's depth {paving.depth}")
        test = spaces._test(paving.mechanism, paving.space, paving.procedure, paving.region)
        p = engine.refine(paving.inside, paving.outside, test, depth, per_level(advance), paving.paving.band)
        return Paving(paving.mechanism, paving.space, depth, paving.procedure, paving.region, p,
                      paving.evaluations + p.evaluations)
    saved = paving if isinstance(paving, spaces.SavedPaving) else spaces.load_saved(
        user_path(paving, "paving", "a Paving or the path of a .qt file"))
    depth = check_paving_depth(depth, saved.inside.tree.grid.dim)
    if depth < saved.inside.tree.grid.depth:
        raise InputError(saved.source, param("depth"), f"{depth} is below the saved depth {saved.inside.tree.grid.depth}")
    p = spaces.refine_saved(saved, depth, per_level(advance))
    return Paving(saved.mechanism, saved.space, depth, saved.procedure, saved.region, p,
                  saved.evaluations + p.evaluations, saved.stem)


def read_qt(path):
    """A `.qt` file: its tree (`.tree`: cells, `.area`) and header fields (`.fields`)."""
    from fivebar_cli.io.qtfile import read_qt as read

    return read(user_path(path, "path"))


# ---------------------------------------------------------------- aspects


def aspects(mech, depth: int | None = None, *, budget: int | None = None, tolerance: float | None = None,
            shapes: bool = True, compare: bool = False, advance=None, jobs: int | None = 1) -> Aspects:
    """The generalized aspects of a five-bar or 2-RPR (in both spaces) or of a 3-RPR (over its
    space of poses), with a certified count (or its bounds).

    With `compare`, also what `fivebar aspects` reports beside them: for interval lengths the
    nominal aspects and what each becomes (`fates`), with constraints the unconstrained aspects
    and where each constrained one comes from (`split`). `depth`: None gives 10, or 7 over a space
    of poses (`depth_or_default`). `jobs`: worker processes for the
    independent pavings (None: one per core; 1: this process); the result is the same for any.
    `advance(n=1)`: told of each region paved (six for a five-bar, in each analysis) and of the end.

    Examples
    --------
    >>> import fivebar_cli as fb
    >>> a = fb.aspects(fb.load("rpr2"), 6)
    >>> a.count, a.certified
    (2, True)
    >>> a[0].working_mode, a[0].assembly_mode
    ('++', '+')
    """
    from fivebar_cli.analyses.aspects import DEFAULT_BUDGET

    source = source_name(mech)
    m = with_aspects(widened(_mechanism(mech), tolerance, source), source)
    depth = depth_or_default(m, depth)
    budget = check_count(budget, "budget", 0, none=f"None: {DEFAULT_BUDGET:,}")
    budget = DEFAULT_BUDGET if budget is None else budget
    step = advance or (lambda n=1: None)
    if m.pose_aspect_model() is not None:
        from fivebar_cli.analyses.pose_aspects import analyse_pose_aspects
        from fivebar_cli.api.pose_space import pose_depth, pose_mechanism

        depth = pose_depth(pose_mechanism(m, source=source), depth)
        analysis = analyse_pose_aspects(m, depth, step, budget, jobs)
        found = tuple(Aspect(a.number, dict(a.signs.fields), a.tree, None, tuple(a.pose), tuple(a.joints),
                             bool(a.certified)) for a in analysis.aspects)
        return Aspects(m, depth, analysis, found)
    from fivebar_cli.analyses.aspects import analyse_aspects, signs_text

    depth = check_depth(depth, MAX_ASPECT_DEPTH)
    analysis = analyse_aspects(m, depth, step, budget, shapes=shapes, jobs=jobs)
    fates, split, free = (), None, None
    if compare and m.is_interval:
        from fivebar_cli.analyses.tolerance import aspect_fates

        fates = tuple(aspect_fates(analyse_aspects(m.nominal(), depth, step, budget, shapes=False, jobs=jobs), analysis))
    if compare and m.constraints:
        from fivebar_cli.analyses.aspect_split import split_rows

        free = analyse_aspects(m.unconstrained(), depth, step, budget, shapes=False, jobs=jobs)
        split = tuple(split_rows(analysis, free))
    return Aspects(m, depth, analysis, tuple(_aspect(a, signs_text) for a in analysis.aspects), fates, split, free)


def comparisons(m: Mechanism) -> int:
    """How many analyses `aspects(m, compare=True)` runs (for a progress bar)."""
    return 1 + bool(m.is_interval) + bool(m.constraints)


def _aspect(a, signs_text) -> Aspect:
    circle = (a.circle.x, a.circle.y, a.circle.r) if a.circle is not None else None
    square = (a.square.x, a.square.y, a.square.side) if a.square is not None else None
    return Aspect(a.number, {"working_mode": signs_text(a.working), "assembly_mode": signs_text(a.assembly)},
                  a.workspace, a.jointspace, tuple(a.pose), tuple(a.joints), bool(a.certified), circle, square)


# ---------------------------------------------------------------- path (locate: locations.py)


def path(mech, start, goal, *, depth: int | None = None, allow_serial: bool = False,
         assembly_mode: str | None = None, working_mode: str | None = None, joints=None, legs=None,
         folder=None, source: str | None = None) -> Path:
    """A certified singularity-free motion from `start` to `goal` (NoPath, a FivebarError, when none
    is found at this depth, with the reason).

    Five-bar and 2-RPR: each endpoint is `{"joints": (th1, th2)}` (in the assembly mode
    `assembly_mode`), `{"pose": (x, y), "working_mode": "++"}` or a plain pose `(x, y)`; with `allow_serial` the motion
    may cross serial singularities, never parallel ones; `working_mode` is that of every pose
    endpoint that names none. 3-RPR, 3-RRR: each endpoint is a pose (x, y, phi_deg), for a 3-RRR
    in `working_mode` ('+-+': needed, as `fivebar path --working-mode`); or, with `joints` (`legs`,
    a 3-RPR's leg lengths), `start` and `goal` are two of their assembly modes, numbered from 1 as
    in `dkp`'s rows (a non-singular change of assembly mode). `folder`: an `aspects`
    output folder whose trees are reused (and whose workspace tree of the motion's aspect is the
    figure's backdrop). `source`: how messages name the mechanism (default: its file, or its
    name). `depth` is at most `MAX_ASPECT_DEPTH` (16; an octree of poses: 9; None: 10, or 7 over
    poses, as `depth_or_default`); the result's `notes`
    are the lines `fivebar path` prints, `save(folder, figures=True)` writes its path.csv and path.png.

    Examples
    --------
    >>> import fivebar_cli as fb
    >>> p = fb.path(fb.load("m1"), {"pose": (4, 5), "working_mode": "++"},
    ...             {"pose": (6, 8), "working_mode": "++"}, depth=8)
    >>> p.points.shape[1]
    4
    """
    source = source or source_name(mech)
    m = with_aspects(_mechanism(mech), source)
    depth = depth_or_default(m, depth)
    if m.pose_aspect_model() is not None:
        from fivebar_cli.api.pose_space import pose_path

        check_serial(m, allow_serial, source)  # (taken without a word before: the motion avoided every singularity)
        if assembly_mode is not None:
            raise InputError(source, param("assembly_mode"), f"{article(m.kind)}'s assembly modes are `start` and "
                             "`goal` themselves, numbered as in `dkp`'s rows, with " + param("joints") + " or "
                             + param("legs"))
        return pose_path(m, start, goal, depth, working_mode, joints, legs, folder, source)
    from fivebar_cli.analyses.paths import find_path, path_columns, path_points, resolve

    depth = check_depth(depth, MAX_ASPECT_DEPTH)
    if joints is not None or legs is not None:
        raise InputError(source, param("joints" if joints is not None else "legs"), f"{article(m.kind)}'s endpoints "
                         "give their own joints: {'joints': (th1, th2)}")
    check_serial(m, allow_serial, source)
    endpoints = [_endpoint(e, which, working_mode, source) for e, which in ((start, "start"), (goal, "goal"))]
    check_modes(m, source, [working_mode, *(e.working for e in endpoints)], assembly_mode)
    if working_mode is not None and all(e.kind == "joints" for e in endpoints):  # (taken without a word before)
        raise InputError(str(source), param("working_mode"), "is that of a pose endpoint: joints decide their own "
                         "working mode")
    first, last = resolve(m, endpoints, assembly_mode, source)
    trees = user_path(folder, "folder") if folder is not None else None
    result = find_path(m, depth, first, last, allow_serial, trees, max_depth=MAX_ASPECT_DEPTH)
    return Path(m, depth, path_columns(m), path_points(result), result.length, result, _path_notes(result, trees),
                trees)


def _endpoint(e, which: str, working_mode: str | None, source):
    """A five-bar's or 2-RPR's endpoint `e` as `path` takes it: `{"pose": (x, y), "working_mode":
    "++"}` (`working_mode`: the call's when it names none), `{"joints": (th1, th2)}`, or a plain
    `(x, y)`: a pose, in the call's `working_mode`. InputError naming `which` (start or goal) else."""
    from fivebar_cli.analyses.paths import Endpoint

    kinds = [k for k in ("pose", "joints") if k in e] if isinstance(e, Mapping) else ["pose"]
    value = (e[kinds[0]] if isinstance(e, Mapping) else e) if len(kinds) == 1 else None
    point = finite_points(value, 2)
    if point is None:
        raise InputError(str(source), param(which), f"expected (x, y), {{'pose': (x, y), 'working_mode': '++'}} "
                         f"or {{'joints': (th1, th2)}}, got {e!r}")
    # (a key of neither form, e.g. a joints endpoint's own assembly mode, would be ignored)
    unknown = sorted(set(e) - {"pose": {"pose", "working_mode"}, "joints": {"joints"}}[kinds[0]]) \
        if isinstance(e, Mapping) else []
    if unknown:
        raise InputError(str(source), param(which), f"unknown key {unknown[0]!r} in {e!r}: a pose takes 'pose' and "
                         "'working_mode', joints 'joints' only (" + param("assembly_mode") + " is the call's)")
    pair = tuple(map(float, point[0]))
    if kinds[0] == "joints":
        return Endpoint("joints", pair)
    return Endpoint("pose", pair, e.get("working_mode", working_mode) if isinstance(e, Mapping) else working_mode)


def check_modes(m: Mechanism, source, working_modes=(), assembly_mode: str | None = None) -> None:
    """A five-bar's or 2-RPR's modes as the calls take them ('+-', '+'): InputError naming the one
    that is none of its kind's (a typo used to filter every configuration out, or find no motion)."""
    from fivebar_cli.analyses.aspect_texts import signs_text

    model = m.aspect_model()
    for name, values, known in (("working_mode", working_modes, model.working_modes),
                                ("assembly_mode", (assembly_mode,), model.assembly_modes)):
        texts = [signs_text(k) for k in known]
        for value in values:
            if value is not None and not is_choice(value, texts):
                raise InputError(str(source), param(name), f"{value!r} is none of {article(m.kind)}'s: {', '.join(texts)}")


def check_aspects(aspects, m: Mechanism, source, depth: int | None = None) -> None:
    """`aspects`, when given, must be what `aspects` gives for this very mechanism: TypeError for
    another type, InputError for another mechanism's (whose trees were read as this one's: a
    wrong answer, or an AttributeError from deep inside), or for a `depth` given that is not
    theirs (theirs is the depth the call works at)."""
    if aspects is None:
        return
    if not isinstance(aspects, Aspects):
        raise TypeError(f"aspects: expected what fb.aspects gives (Aspects), got {type(aspects).__name__}")
    if aspects.mechanism != m:
        raise InputError(str(source), param("aspects"), f"were computed for another mechanism "
                         f"({aspects.mechanism.name!r}, {article(aspects.mechanism.kind)}), not for this one")
    if depth is not None and depth != aspects.depth:
        raise InputError(str(source), param("depth"), f"{depth!r} is not the depth of the aspects given "
                         f"({aspects.depth}): leave it out, or give aspects of depth {depth!r}")


def depth_or_default(m: Mechanism, depth):
    """`depth`, or when None the calls' default for this kind: `DEFAULT_DEPTH` (10), or
    `DEFAULT_POSE_DEPTH` (7) over a space of poses, whose octrees allow 9 at most (a default of 10
    refused every call that left it out)."""
    if depth is not None:
        return depth
    from fivebar_cli.api.pose_space import DEFAULT_POSE_DEPTH

    return DEFAULT_POSE_DEPTH if m.pose_aspect_model() is not None else DEFAULT_DEPTH


def check_serial(m: Mechanism, allow_serial: bool, source) -> None:
    """`allow_serial` needs a kind with a test for parallel singularities (InputError otherwise)."""
    if allow_serial and not m.crosses_serial:
        raise InputError(str(source), param("allow_serial"), f"{article(m.kind)} has no test for parallel singularities")


def _path_notes(result, trees) -> tuple[str, ...]:
    """What `fivebar path` prints about a motion of a five-bar or 2-RPR."""
    start, end = result.start, result.end
    if result.allow_serial:
        what = (f"motion free of parallel singularities, det A {start.assembly}, working mode {start.working} to "
                f"{end.working} (serial singularities may be crossed)")
    else:
        what = f"singularity-free motion in {motion_where(result.aspect)}: working mode {start.working}, det A {start.assembly}"
    notes = [f"{result.mechanism.name}: {what}, depth {result.depth}",
             f"  from {start.label} to {end.label}: {len(result.joints)} waypoints, joint-space length "
             f"{result.length:.6g}; every segment lies in the certified cells ({result.checked_cells} cells, "
             "checked in exact arithmetic)"]
    if result.source == "saved":
        notes.append(f"  aspect trees read from {trees}")
    return tuple(notes)


# ---------------------------------------------------------------- view


def view(paths) -> str:
    """The self-contained HTML page of `fivebar view` for output folders or `.qt` files (its text)."""
    from fivebar_cli.analyses.view import gather
    from fivebar_cli.webpage.page import render_page

    paths = [paths] if isinstance(paths, (str, bytes, os.PathLike)) or not hasattr(paths, "__iter__") else list(paths)
    if not paths:  # (as the command needs one PATH at least)
        raise InputError("", param("paths"), "give at least one .qt file or output folder")
    paths = [user_path(p, "paths") for p in paths]
    return render_page(gather(paths))
