"""fivebar: certified analysis of planar parallel robots (five-bar and 3-RPR)."""

__version__ = "0.1.0"
