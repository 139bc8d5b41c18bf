"""Mechanism kinds (five-bar, 3-RPR, 2-RPR): each a package with its model, kinematics and box
tests, registered by YAML `type` in `registry.py`; `base.py` says what a kind declares."""
