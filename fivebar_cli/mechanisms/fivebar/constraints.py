"""A five-bar's limits and obstacles: its limited angles and links for the shared YAML keys
`limits`, `obstacles`, `clearance` (`mechanisms/constraints.py`), and which constraints a
configuration violates.

Five angles can be limited, each a signed angle atan2(u x v, u . v) from a vector u to a vector v:

    theta1  actuated at A1: from the x axis to A1 -> B1
    theta2  actuated at A2: from the x axis to A2 -> B2
    B1      passive elbow:  from A1 -> B1 to B1 -> P   (th3 - th1, th3 the direction of P - B1)
    B2      passive elbow:  from A2 -> B2 to B2 -> P   (th4 - th2)
    P       passive end:    from P -> B1 to P -> B2    (th4 - th3)

A configuration collides when one of its four links (segments A1B1, B1P, A2B2, B2P) comes within
`clearance` of an obstacle. The certified box tests are in `constrained.py`.
"""

from __future__ import annotations

from typing import Mapping

import numpy as np

from fivebar_cli.mechanisms import constraints as shared
from fivebar_cli.mechanisms.constraints import (  # noqa: F401 (the five-bar's names too)
    KEYS, MAX_OBSTACLES, MAX_VERTICES, NO_CONSTRAINTS, Constraints, Limit, in_arc,
)

LIMIT_NAMES = ("theta1", "theta2", "B1", "B2", "P")
ACTUATED = ("theta1", "theta2")
LINKS = ("A1B1", "B1P", "A2B2", "B2P")


def description_data(fields: Mapping[str, str], source: str) -> dict:
    """The YAML mapping (`limits`, `obstacles`, `clearance`) of a description's constraint words."""
    return shared.description_data(fields, source, LIMIT_NAMES)


def parse(data: Mapping, source: str) -> Constraints:
    """`limits`, `obstacles` and `clearance` of a five-bar's mapping (all optional)."""
    return shared.parse(data, source, LIMIT_NAMES)


def base_problem(c: Constraints, a2: tuple[float, float]) -> tuple[str, str] | None:
    """(field, message) when an obstacle comes within the clearance of A1 or A2 (every configuration
    then collides: the crank there always touches it), else None."""
    return shared.base_problem(c, {"A1": (0.0, 0.0), "A2": a2}, "crank")


# ---------------------------------------------------------------- configurations


def configuration_angles(m, joints: np.ndarray, poses: np.ndarray) -> dict[str, np.ndarray]:
    """The five limited angles (radians) of configurations (joint values (n, 2), poses (n, 2))."""
    th1, th2 = joints[:, 0], joints[:, 1]
    b1 = np.column_stack([m.L1 * np.cos(th1), m.L1 * np.sin(th1)])
    b2 = np.column_stack([m.L0 + m.L2 * np.cos(th2), m.L2 * np.sin(th2)])
    th3 = np.arctan2(poses[:, 1] - b1[:, 1], poses[:, 0] - b1[:, 0])
    th4 = np.arctan2(poses[:, 1] - b2[:, 1], poses[:, 0] - b2[:, 0])
    return {"theta1": th1, "theta2": th2, "B1": th3 - th1, "B2": th4 - th2, "P": th4 - th3}


def link_segments(m, joints: np.ndarray, poses: np.ndarray) -> dict[str, tuple[np.ndarray, np.ndarray]]:
    """The four links of configurations as (start, end) arrays (n, 2)."""
    th1, th2 = joints[:, 0], joints[:, 1]
    n = len(joints)
    a1, a2 = np.zeros((n, 2)), np.column_stack([np.full(n, m.L0), np.zeros(n)])
    b1 = np.column_stack([m.L1 * np.cos(th1), m.L1 * np.sin(th1)])
    b2 = np.column_stack([m.L0 + m.L2 * np.cos(th2), m.L2 * np.sin(th2)])
    return {"A1B1": (a1, b1), "B1P": (b1, poses), "A2B2": (a2, b2), "B2P": (b2, poses)}


def violated(m, joints: np.ndarray, poses: np.ndarray) -> np.ndarray:
    """(n, k) booleans: configuration i violates constraint j (`m.constraints.labels()` order)."""
    joints, poses = np.atleast_2d(np.asarray(joints, float)), np.atleast_2d(np.asarray(poses, float))
    links = link_segments(m, joints, poses).values() if m.constraints.obstacles else ()
    return shared.violated(m.constraints, configuration_angles(m, joints, poses), links)


def violated_labels(m, joints: np.ndarray, poses: np.ndarray) -> list[list[str]]:
    """Per configuration, the labels of the constraints it violates (empty: none)."""
    labels = m.constraints.labels()
    return [[labels[j] for j in np.flatnonzero(row)] for row in violated(m, joints, poses)]


def marks(c: Constraints, space: str) -> list[dict]:
    """What figures and `fivebar view` draw over a space: obstacles (with their clearance) on the
    workspace, the actuated limits as lines on the joint space (radians)."""
    if space == "workspace":
        return shared.obstacle_marks(c)
    if space == "jointspace":
        return shared.limit_marks(c, ACTUATED, degrees=False)
    return []
