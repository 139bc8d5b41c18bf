"""Matplotlib figures of the analyses' results (imported lazily: only what plots loads matplotlib).
The library never chooses the backend: the CLI selects Agg itself (`cli.options.offscreen`), and a
notebook keeps its own."""

from __future__ import annotations


def pyplot():
    """matplotlib.pyplot, on whatever backend is in use."""
    import matplotlib.pyplot as plt

    return plt
