"""The verdict of a box test, one vectorised helper for every test."""

from __future__ import annotations

import numpy as np


def verdict(inside: np.ndarray, outside: np.ndarray) -> np.ndarray:
    """int8 per box: 1 where `inside` is certain, else -1 where `outside` is, else 0 (undecided).

    Also the certified sign of an enclosure: `verdict(lo > 0, hi < 0)`."""
    return np.where(inside, 1, np.where(outside, -1, 0)).astype(np.int8)
