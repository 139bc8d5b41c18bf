"""The library's depth limits (the API checks them, the command line's options take them as their
ranges): beyond them a run would need more memory than a workstation has; `check_depth` is the check,
`check_count` the one of the other whole numbers a call takes (a budget, processes, samples); both
give the value as a Python int, numpy's integers included."""

import numbers

from fivebar_cli.errors import InputError, param

MAX_DEPTH = 20  # one 2-D paving: beyond this the boundary cells alone need several GiB
MAX_ASPECT_DEPTH = 16  # aspects pave six regions and label them: about 0.2 GiB at 14, x4 per two levels
MAX_VERIFY_DEPTH = 17  # verify only splits what it cannot decide; 3 x 17 bits index an octree cell
MAX_POSE_DEPTH = 9  # octree aspects: about 4x the time and memory per level (depth 8: 40 s, 0.7 GiB; 9: ~3 GiB)
MAX_OCTREE_DEPTH = 12  # an octree's boundary surface has ~4^d cells: about 0.1 GiB per million
MAX_PLANE_DEPTH = MAX_ASPECT_DEPTH  # quadtree aspects over poses (a single orientation): as the five-bar's


def check_paving_depth(depth, dim: int) -> int:
    """`check_depth` for a paving of a space of `dim` axes, whichever call paves it (`pave`,
    `refine`, `rpr3.pave`): a quadtree to `MAX_DEPTH`, an octree to `MAX_OCTREE_DEPTH` (its
    boundary surface grows 4x a level, not 2x), said so when an octree's depth is too large."""
    limit = MAX_DEPTH if dim <= 2 else MAX_OCTREE_DEPTH
    if dim > 2 and isinstance(depth, numbers.Integral) and not isinstance(depth, bool) and depth > limit:
        raise InputError("", param("depth"), f"{depth} is too deep for a space of {dim} axes (an octree: at most "
                         f"{limit}, its boundary grows 4x a level)")
    return check_depth(depth, limit)


def check_depth(depth, limit: int, field: str = "depth") -> int:
    """A depth is an integer in 0..limit (InputError naming `field` otherwise); returned as a
    Python int, which the callers go on with: numpy's integers are depths too (a sweep over
    `np.arange`), and a depth reaches JSON manifests and text headers."""
    return check_count(depth, field, 0, limit)


def check_count(value, field: str, least: int = 0, most: int | None = None, none: str = "") -> int | None:
    """A count (box evaluations, worker processes, samples) is an integer of at least `least` (and
    at most `most`), or None where `none` says what None means (InputError naming `field` otherwise:
    a float, a bool or -1 would otherwise be taken for something else without a word); returned
    as a Python int (or None)."""
    if value is None and none:
        return None
    if (isinstance(value, bool) or not isinstance(value, numbers.Integral) or value < least
            or most is not None and value > most):
        span = f"of at least {least}" if most is None else f"in {least}..{most}"
        raise InputError("", param(field), f"must be an integer {span}" + (f" ({none})" if none else "")
                         + f", got {value!r}")
    return int(value)
