"""fivebar: certified analysis of planar parallel robots (five-bar, 3-RPR, 2-RPR).

The Python API (docs/python.md)::

    import fivebar_cli as fb
    m = fb.load("m1")                      # a YAML file, a dict, or a shipped example's name
    a = fb.aspects(m, depth=8)             # a.count, a.certified, a.rows(), a.save(folder), a.plot(ax)

The names below are imported on first use, so that `import fivebar_cli` (and `fivebar --help`)
imports neither numpy's analyses nor click, matplotlib, shapely or dask.
"""

from fivebar_cli.version import __version__  # noqa: F401 - the package version

__all__ = [
    "load", "pave", "refine", "read_qt", "aspects", "locate", "path", "atlas", "atlas_plan", "view", "examples", "copy_examples", "rpr3",
    "tolerance", "kratio", "verify", "dkp", "compare", "Report",
    "Mechanism", "Paving", "Aspects", "Aspect", "Location", "Path", "Table", "Comparison", "FivebarError", "InputError",
]


def __getattr__(name: str):
    if name in __all__:
        from fivebar_cli import api

        value = getattr(api, name)
        globals()[name] = value
        return value
    raise AttributeError(f"module 'fivebar_cli' has no attribute {name!r}")


def __dir__():
    return sorted([*globals(), *__all__])
