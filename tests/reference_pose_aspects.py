"""An independent dense-grid count of a 3-RPR's aspects over (x, y, phi) (written from the
definitions in docs/rpr3.md, with numpy, scipy.ndimage and tests/rpr3_reference.py only; nothing
from fivebar_cli).

The root box is sampled at n^3 cell centres; a centre is kept for a sign when every leg is in its
range and det J has that sign (and is not within a relative 1e-9 of 0). Kept centres of one sign
are labelled with 26-connectivity; when phi is a full turn, the first and last phi layers are
glued (with their diagonal neighbours). A grid sees nothing thinner than a cell, so components
are counted only with at least `MIN_FRACTION` of the kept centres of their sign scaled by n^3
(a real aspect grows with the grid, an island of a pixel does not), and the count is only
trusted when two resolutions agree (`stable_count`).
"""

from __future__ import annotations

import numpy as np
from scipy import ndimage

from reference_aspects import _merge
from rpr3_reference import arms, det_j, legs

TWENTY_SIX = np.ones((3, 3, 3), bool)
MIN_CELLS = 8  # at n = 64; scaled with n^3


def label(mask: np.ndarray, periodic_last: bool) -> np.ndarray:
    """26-connected labels (0: not kept), the last axis glued end to end when periodic."""
    labels, n = ndimage.label(mask, structure=TWENTY_SIX)
    if not periodic_last or n == 0:
        return labels
    first, last = labels[:, :, 0], labels[:, :, -1]
    pairs = []
    for dx in (-1, 0, 1):
        for dy in (-1, 0, 1):
            shifted = np.roll(np.roll(last, dx, axis=0), dy, axis=1)
            if dx:  # no wrap in x, y: clear the rolled-in border
                shifted[0 if dx > 0 else -1, :] = 0
            if dy:
                shifted[:, 0 if dy > 0 else -1] = 0
            pairs.append(np.stack([first.ravel(), shifted.ravel()], 1))
    pairs = np.concatenate(pairs)
    pairs = pairs[(pairs[:, 0] > 0) & (pairs[:, 1] > 0)]
    return _merge(labels, n, pairs)


def count(base, platform, rho_min, rho_max, root, periodic: bool, n: int = 64) -> int:
    """Aspects seen on an n^3 grid of the root box ((xlo, xhi), (ylo, yhi), (phi1, phi2))."""
    axes = [lo + (np.arange(n) + 0.5) / n * (hi - lo) for lo, hi in root]
    grid = np.stack(np.meshgrid(*axes, indexing="ij"), -1).reshape(-1, 3)
    # the arms turn with phi alone: computed on the n angles (the last axis), repeated over (x, y)
    turned = arms(platform, np.stack([np.zeros(n), np.zeros(n), axes[2]], -1))
    q = np.broadcast_to(turned, (n * n, *turned.shape)).reshape(-1, *turned.shape[1:])
    lengths = legs(base, platform, grid, q)
    ok = np.all((lengths > np.asarray(rho_min)) & (lengths < np.asarray(rho_max)), axis=1)
    d = det_j(base, platform, grid, q)
    scale = float(np.max(np.abs(d))) or 1.0
    total = 0
    for sign in (1, -1):
        mask = (ok & (sign * d > 1e-9 * scale)).reshape(n, n, n)
        labels = label(mask, periodic)
        sizes = np.bincount(labels.ravel())[1:]
        total += int(np.count_nonzero(sizes >= MIN_CELLS * (n / 64) ** 3))
    return total


def stable_count(base, platform, rho_min, rho_max, root, periodic: bool, sizes=(64, 96)) -> int | None:
    """The count when two resolutions agree, else None (the grids cannot tell)."""
    counts = {count(base, platform, rho_min, rho_max, root, periodic, n) for n in sizes}
    return counts.pop() if len(counts) == 1 else None
