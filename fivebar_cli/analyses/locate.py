"""Which aspect a configuration lies in, and which configurations a singularity-free motion joins.

A configuration is in an aspect when its pose lies in the aspect's workspace cells and its joint
values in its joint-space cells, with the aspect's modes; on or near a singularity (a mode value
below `SINGULAR_TOL * scale^2`) it is in none.
"""

from __future__ import annotations

import numpy as np

from fivebar_cli.analyses.aspects import Aspect
from fivebar_cli.mechanisms.base import AspectModel, Mechanism, Space

SINGULAR_TOL = 1e-9  # |B11|, |B22| or |det A| below this times scale^2 is a singularity
SAME_TOL = 1e-9  # two configurations closer than this times the scale are one


def locate_configurations(m: Mechanism, aspects: list[Aspect], points: np.ndarray, space: str) -> list[dict]:
    """Every configuration at the given poses (workspace) or joint values (joint space), with its
    modes and the aspect containing it (None when on or near a singularity at this depth).

    On a singularity two branches coincide (a stretched leg has one elbow): such a configuration is
    listed once, with the sign that vanishes written 0.
    """
    model, joint_space = m.aspect_model(), m.spaces()["jointspace"]
    out = []
    for k, point in enumerate(np.atleast_2d(np.asarray(points, float))):
        seen: list[np.ndarray] = []
        if space == "workspace":
            candidates = [(point, joints[0]) for joints, ok in (model.ikp(point[None, :], wm) for wm in model.working_modes)
                          if ok[0]]
        else:
            candidates = [(pose[0], point) for pose, ok in (model.dkp(point[None, :], am) for am in model.assembly_modes)
                          if ok[0]]
        for pose, joints in candidates:
            key = np.concatenate([pose, _joint_key(joint_space, joints)])
            if any(np.allclose(key, other, rtol=0, atol=SAME_TOL * model.length_scale) for other in seen):
                continue
            seen.append(key)
            out.append(_configuration(model, joint_space, aspects, k, pose, joints))
    return with_violations(m, out)


def with_violations(m: Mechanism, rows: list[dict]) -> list[dict]:
    """Rows of a mechanism with limits or obstacles get `violates`: the constraints each
    configuration violates ('' when none), e.g. 'P limit; obstacle 1'."""
    if not rows or not getattr(m, "constraints", None):
        return rows
    names = [a.name for a in m.spaces()["jointspace"].axes]
    joints = np.array([[r[names[0]], r[names[1]]] for r in rows])
    for row, labels in zip(rows, m.violated_constraints(joints, np.array([[r["x"], r["y"]] for r in rows]))):
        row["violates"] = "; ".join(labels)
    return rows


def _joint_key(space: Space, joints: np.ndarray) -> np.ndarray:
    """Joint values as a point to compare: periodic axes through (cos, sin)."""
    parts = []
    for axis, value in zip(space.axes, joints):
        parts += [np.cos(value), np.sin(value)] if axis.periodic else [value]
    return np.array(parts)


def _wrap(space: Space, joints: np.ndarray) -> np.ndarray:
    """Periodic joint values wrapped into the root interval (-pi, pi] style: [lo, lo + period)."""
    out = joints.astype(float).copy()
    for i, axis in enumerate(space.axes):
        if axis.periodic:
            period = axis.hi - axis.lo
            out[i] = (out[i] - axis.lo) % period + axis.lo
    return out


def _configuration(model: AspectModel, joint_space: Space, aspects: list[Aspect], index: int,
                   pose: np.ndarray, joints: np.ndarray) -> dict:
    values = model.mode_values(joints[None, :], pose[None, :])[0]
    tol = SINGULAR_TOL * model.length_scale ** 2
    *working, sa = (0 if abs(x) <= tol else int(np.sign(x)) for x in values)
    joints = _wrap(joint_space, joints)
    number, certified = None, None
    for a in aspects:
        if (a.working, a.assembly) == (tuple(working), sa):
            if a.workspace.locate(pose[None, :])[0] >= 0 and a.jointspace.locate(joints[None, :])[0] >= 0:
                number, certified = a.number, a.certified
    singular = [f"serial ({name} = 0)" for name, s in zip(model.serial_names, working) if s == 0]
    singular += ["parallel (det A = 0)"] if sa == 0 else []
    axes = [a.name for a in joint_space.axes]
    return {
        "input": index, "x": float(pose[0]), "y": float(pose[1]),
        axes[0]: float(joints[0]), axes[1]: float(joints[1]),
        "working_mode": "".join({1: "+", -1: "-", 0: "0"}[s] for s in working),
        "assembly_mode": {1: "+", -1: "-", 0: "0"}[sa],
        "aspect": number, "singular": "; ".join(singular), "aspect_certified": certified,
    }


def motions(configurations: list[dict], count: int) -> list[tuple[int, int, list[int]]]:
    """For every pair i < j of the `count` inputs (numbered from 1): the aspects holding a
    configuration of both. A singularity-free motion joins them exactly when this is not empty."""
    held = {i: {r["aspect"] for r in configurations if r["input"] == i and r["aspect"] is not None}
            for i in range(1, count + 1)}
    return [(i, j, sorted(held[i] & held[j])) for i in range(1, count + 1) for j in range(i + 1, count + 1)]
