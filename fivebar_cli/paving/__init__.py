"""Certified subdivision: grids, 2^n-trees (quadtrees, octrees) with their B/W/G codec, and the
breadth-first paving engine that fills them from a vectorised box test."""
