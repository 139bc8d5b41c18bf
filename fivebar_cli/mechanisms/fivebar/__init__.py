"""The five-bar (Chablat 2010): model and schema, point kinematics, exact box tests, mode tests,
and the paper's own procedures."""
