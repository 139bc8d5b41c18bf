"""The 2-RPR: two actuated prismatic legs from A1 = (0, 0) and A2 = (d, 0) meeting at P."""
