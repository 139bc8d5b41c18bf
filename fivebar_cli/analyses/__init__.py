"""Analyses built on the mechanism kinds: pavings of spaces (and resuming them), generalized
aspects with their crossings and files, locating configurations, Table 1, tree comparison."""
