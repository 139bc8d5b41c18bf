"""Sweeps of the singularity-free area over phi, rho_min or the base shape (the paper's figures 3-8).

Every sample is a design of its own: rho_max is rho_max_auto at its orientation.
"""

from __future__ import annotations

import numpy as np

from fivebar_cli.mechanisms.rpr3.closed_form import area, optimal_rho_min, rho_max_auto


def sweep_phi(t1, t2, t3, k, rho_min, phis) -> dict:
    """Figures 3, 4, 6, 7: area vs phi at a fixed rho_min and at the optimal rho_min of each phi.

    Each phi is a design of its own: rho_max is rho_max_auto at that phi.
    """
    phis = np.asarray(phis, float)
    rho_max = rho_max_auto(t1, t2, t3, k, phis, rho_min)
    rho_opt, area_opt, rho_max_opt = optimal_rho_min(t1, t2, t3, k, phis)
    return {
        "phi": phis,
        "rho_min": np.full(phis.shape, float(rho_min)),
        "rho_max": rho_max,
        "area": area(t1, t2, t3, k, phis, rho_min, rho_max),
        "rho_min_opt": rho_opt,
        "rho_max_opt": rho_max_opt,
        "area_opt": area_opt,
    }


def sweep_rho_min(t1, t2, t3, k, phi, rhos) -> dict:
    """Figure 5: area vs rho_min at one orientation (rho_max auto, inf past rho_min_limit)."""
    rhos = np.asarray(rhos, float)
    rho_max = rho_max_auto(t1, t2, t3, k, phi, rhos)
    return {"rho_min": rhos, "rho_max": rho_max, "area": area(t1, t2, t3, k, phi, rhos, rho_max)}


def sweep_t2(t1, t3, k, rho_min, phis, t2s) -> dict:
    """Figure 8: area vs t2 with t1 and t3 fixed (so the base area stays t1 t3 / 2), for each phi,
    at a fixed rho_min and at the optimal rho_min. Arrays are (len(phis), len(t2s))."""
    phi, t2 = np.meshgrid(np.asarray(phis, float), np.asarray(t2s, float), indexing="ij")
    rho_max = rho_max_auto(t1, t2, t3, k, phi, rho_min)
    rho_opt, area_opt, rho_max_opt = optimal_rho_min(t1, t2, t3, k, phi)
    return {
        "phi": phi,
        "t2": t2,
        "rho_min": np.full(phi.shape, float(rho_min)),
        "rho_max": rho_max,
        "area": area(t1, t2, t3, k, phi, rho_min, rho_max),
        "rho_min_opt": rho_opt,
        "rho_max_opt": rho_max_opt,
        "area_opt": area_opt,
    }
