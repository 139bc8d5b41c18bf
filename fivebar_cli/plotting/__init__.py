"""Matplotlib figures of the analyses' results (imported lazily: only commands that plot load
matplotlib, always with the Agg backend)."""

from __future__ import annotations


def pyplot():
    """matplotlib.pyplot on the Agg backend (no display needed)."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    return plt
