"""Design atlases: sweep a grid of five-bar designs and tabulate their metrics (`fivebar atlas`).

spec.py (the `fivebar-atlas` YAML and its grid of designs) · metrics.py (one design -> one row)
· parts.py (`atlas.parts/` and `atlas.csv` on disk) · engine.py (batches, resume, runners)
· cluster.py (Dask: a local cluster or an existing one; the only module that imports Dask).
"""
