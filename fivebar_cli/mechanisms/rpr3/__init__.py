"""The 3-RPR with similar base and platform (Jiang & Gosselin): model and schema, closed forms of
the singularity circle and the singularity-free workspace, sweeps, synthesis, the paper's Table 1."""
