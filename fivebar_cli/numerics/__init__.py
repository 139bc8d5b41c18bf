"""Numerical building blocks with no knowledge of mechanisms: outward-rounded interval arithmetic,
exact ranges over boxes, annuli and circular-arc regions, 1-D minimisers."""
