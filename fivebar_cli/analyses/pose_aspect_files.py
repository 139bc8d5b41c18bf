"""The files of a pose-space aspect analysis: `aspects.csv`, one `.qt` tree and (3-D) one PLY
surface per aspect; written so that a folder holds exactly one run's set, and read back so that
`locate`, `path` and `dkp` reuse them instead of recomputing.

`aspects.csv` columns: `aspect`, the class's fields (`det_sign` for a 3-RPR), `volume` (area for
a 2-D space), `cells`, a pose inside the aspect (the space's axes, `_deg` appended to an axis in
degrees: `x,y,phi_deg`), its joints (`rho1,rho2,rho3`) and `certified`.
"""

from __future__ import annotations

from pathlib import Path

from fivebar_cli.analyses.pose_aspects import PoseAspect, PoseAspectAnalysis, pose_model
from fivebar_cli.errors import InputError
from fivebar_cli.io.files import read_csv_table, write_csv
from fivebar_cli.io.layout import ASPECTS_CSV, aspect_mesh_path, aspect_path
from fivebar_cli.io.mesh import write_ply
from fivebar_cli.io.outputs import of_complete_runs
from fivebar_cli.io.qtfile import read_qt, write_qt
from fivebar_cli.mechanisms.base import Axis, Mechanism


def column(axis: Axis) -> str:
    """The CSV column of an axis: its name, with `_deg` for an axis in degrees (`phi_deg`)."""
    return f"{axis.name}_deg" if axis.unit == "deg" else axis.name


def pose_columns(m: Mechanism) -> tuple[str, ...]:
    model = pose_model(m)
    return tuple(column(a) for a in m.spaces()[model.space].axes)


def joint_columns(m: Mechanism) -> tuple[str, ...]:
    return tuple(column(a) for a in pose_model(m).joint_axes)


def aspect_header(m: Mechanism) -> tuple[str, ...]:
    model = pose_model(m)
    fields = tuple(k for k, _ in model.classes[0].fields)
    return ("aspect", *fields, "volume", "cells", *pose_columns(m), *joint_columns(m), "certified")


def aspect_rows(analysis: PoseAspectAnalysis) -> list[tuple]:
    return [(a.number, *(v for _, v in a.signs.fields), a.volume, len(a.tree), *a.pose, *a.joints,
             "true" if a.certified else "false") for a in analysis.aspects]


def _qt_fields(m: Mechanism, a: PoseAspect, space) -> dict:
    fields = {"name": m.name, "space": space.name, "region": f"aspect {a.number}", "colour": "inside"}
    if space.dim > 2:
        fields["axes"] = space.axes_header()
    fields["mechanism"] = m.describe()
    fields.update(dict(a.signs.fields))
    return fields


def write_pose_aspects(folder: Path, analysis: PoseAspectAnalysis, meshes: bool = True) -> list[Path]:
    """`aspects.csv`, every aspect's tree and (octrees, with `meshes`) surface; then the aspect files
    of an earlier run that this one does not have are removed."""
    m = analysis.mechanism
    space = m.spaces()[analysis.model.space]
    paths = [write_csv(folder / ASPECTS_CSV, aspect_header(m), aspect_rows(analysis))]
    for a in analysis.aspects:
        paths.append(write_qt(aspect_path(folder, a.number, space.name), a.tree, **_qt_fields(m, a, space)))
        if meshes and space.dim == 3:
            notes = [f"fivebar {m.name} aspect {a.number} ({a.signs.label}), depth {analysis.depth}",
                     f"volume {a.volume!r} in the space's units"]
            paths.append(write_ply(aspect_mesh_path(folder, a.number, space.name), a.tree, space.axes, notes))
    keep = {p.name for p in paths}
    for pattern in ("aspect-*.qt", "aspect-*.geojson", "aspect-*.ply"):
        for old in sorted((folder / "aspects").glob(pattern)):
            if old.name not in keep:
                old.unlink(missing_ok=True)
    return paths


def load_pose_aspects(folder: Path | None, m: Mechanism, depth: int) -> list[PoseAspect] | None:
    """The aspects an `aspects` run wrote into `folder` for this mechanism at this depth, or None
    when the folder does not hold such a complete set (the caller then computes them)."""
    if folder is None or not (folder / ASPECTS_CSV).is_file():
        return None
    model = pose_model(m)
    space = m.spaces()[model.space]
    header = aspect_header(m)
    try:
        found, rows = read_csv_table(folder / ASPECTS_CSV)
        if tuple(found) != header:
            return None
        names, nd = [k for k, _ in model.classes[0].fields], space.dim
        files = [folder / ASPECTS_CSV, *(aspect_path(folder, int(row["aspect"]), space.name) for _, row in rows)]
        if not of_complete_runs(folder, files, "the aspects are computed"):
            return None
        aspects = []
        for _, row in rows:
            number, fields = int(row["aspect"]), tuple(row[k] for k in names)
            cls = next(k for k, c in enumerate(model.classes) if tuple(v for _, v in c.fields) == fields)
            values = [float(row[c]) for c in (*pose_columns(m), *joint_columns(m))]
            qt = read_qt(aspect_path(folder, number, space.name))
            tree = qt.tree
            expected = {**dict(model.classes[cls].fields), "mechanism": m.describe(), "region": f"aspect {number}"}
            if tree.grid != space.grid(depth) or any(qt.get(k) != v for k, v in expected.items()) \
                    or row["certified"] not in ("true", "false"):
                return None
            aspects.append(PoseAspect(number, cls, model.classes[cls], tree, tuple(values[:nd]), tuple(values[nd:]),
                                      row["certified"] == "true"))
        return aspects
    except (OSError, ValueError, IndexError, StopIteration, UnicodeDecodeError, InputError):
        return None
