"""The texts of one generalized aspect's files: its `.qt` tree in each space and its workspace
GeoJSON. Made where the aspect's other work is (`aspects.analyse_aspects` makes them in the
aspects' tasks when these run on workers, `aspect_files.write_aspects` otherwise), written by
`aspect_files.write_aspects`.
"""

from __future__ import annotations

import numpy as np

from fivebar_cli.io.geojson import feature_text, geojson_text
from fivebar_cli.io.qtfile import format_qt
from fivebar_cli.mechanisms.base import Mechanism


def signs_text(signs) -> str:
    """(+1, -1) -> '+-'; a vanishing sign is '0'."""
    return "".join({1: "+", -1: "-", 0: "0"}[int(np.sign(s))] for s in np.atleast_1d(signs))


def aspect_properties(m: Mechanism, a, depth: int) -> dict:
    """The properties of an aspect's GeoJSON feature (`area` equals `workspace_area`)."""
    return {"name": m.name, "space": "workspace", "depth": depth, "aspect": a.number,
            "working_mode": signs_text(a.working), "assembly_mode": signs_text(a.assembly), "area": a.workspace.area}


def qt_fields(m: Mechanism, a, space: str) -> dict:
    """The header fields of an aspect's `.qt` file in one space."""
    return {"name": m.name, "space": space, "region": f"aspect {a.number}", "colour": "inside",
            "mechanism": m.describe(), "working_mode": signs_text(a.working), "assembly_mode": signs_text(a.assembly)}


def aspect_texts(m: Mechanism, a, depth: int) -> tuple[str, str, str]:
    """One aspect's `.qt` texts (workspace, joint space) and workspace GeoJSON text (`a`: an
    `aspects.Aspect`, its number, modes and trees)."""
    return (format_qt(a.workspace, **qt_fields(m, a, "workspace")),
            format_qt(a.jointspace, **qt_fields(m, a, "jointspace")),
            geojson_text([feature_text(a.workspace, aspect_properties(m, a, depth))]))
