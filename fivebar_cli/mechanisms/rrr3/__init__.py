"""The 3-RRR: three legs, each an actuated revolute joint at the base, a proximal and a distal link, joined to a triangular platform."""
