"""Where outputs go: the output folder of a mechanism and the names of the files inside it.

One place for the layout that users' scripts rely on (docs/formats.md, "Output layout"):
`outputs/<name>/<space>.qt` and `<space>.complement.qt`, `<space>.csv`, `aspects.csv`,
`aspects-adjacency.csv`, `aspects/aspect-NN.<space>.qt` and `aspect-NN.workspace.geojson`,
`aspect-NN.<space>.ply` (3-D aspects), `<space>.geojson`, `path.csv` and `path.png`, `dkp.csv`;
every figure a command draws (`*.png`); and the files each output set owns (`io.outputs`): the glob
patterns of every file a command may write in one of its runs.
"""

from __future__ import annotations

import re
from pathlib import Path

from fivebar_cli.errors import InputError

DEFAULT_ROOT = Path("outputs")
COMPLEMENT = ".complement.qt"
BAND = ".band.qt"


def output_dir(out: str | Path | None, name: str) -> Path:
    """The folder for a mechanism's outputs: `--out` if given, else `outputs/<name>/`."""
    return Path(out) if out is not None else DEFAULT_ROOT / name


def paving_paths(folder: Path, space: str) -> tuple[Path, Path]:
    """`<space>.qt` (certified inside) and `<space>.complement.qt` (certified outside)."""
    return folder / f"{space}.qt", folder / f"{space}{COMPLEMENT}"


def summary_path(folder: Path, stem: str) -> Path:
    """The one-row summary CSV of a paving (`workspace.csv`, `workspace-reachable.csv`)."""
    return folder / f"{stem}.csv"


def band_path(folder: Path, space: str) -> Path:
    """`<space>.band.qt`: the uncertain band of a paving with interval lengths (valid for some
    length vectors, invalid for others)."""
    return folder / f"{space}{BAND}"


def sibling_paths(path: Path) -> tuple[Path, Path]:
    """(inside, complement) paths of the pair a `.qt`, `.complement.qt` or `.band.qt` file belongs to."""
    name = path.name
    for suffix in (COMPLEMENT, BAND):
        if name.endswith(suffix):
            inside = path.with_name(name[: -len(suffix)] + ".qt")
            return inside, inside.with_name(name[: -len(suffix)] + COMPLEMENT)
    if name.endswith(".qt"):
        return path, path.with_name(name[: -len(".qt")] + COMPLEMENT)
    raise InputError(str(path), "", "expected a .qt file")


def aspect_path(folder: Path, number: int, space: str) -> Path:
    """`aspects/aspect-NN.<space>.qt`: one generalized aspect in one space."""
    return folder / "aspects" / f"aspect-{number:02d}.{space}.qt"


def aspect_mesh_path(folder: Path, number: int, space: str) -> Path:
    """`aspects/aspect-NN.<space>.ply`: one aspect's octree cells as a closed surface mesh."""
    return folder / "aspects" / f"aspect-{number:02d}.{space}.ply"


def aspect_geojson_path(folder: Path, number: int) -> Path:
    """`aspects/aspect-NN.workspace.geojson`: one generalized aspect's workspace region."""
    return folder / "aspects" / f"aspect-{number:02d}.workspace.geojson"


def geojson_path(folder: Path, space: str) -> Path:
    """`<space>.geojson`: the certified inside region of a paving."""
    return folder / f"{space}.geojson"


ASPECTS_CSV = "aspects.csv"
CROSSINGS_CSV = "aspects-adjacency.csv"
SPLIT_CSV = "aspects-split.csv"  # with limits or obstacles: what each constrained aspect comes from
PATH_CSV = "path.csv"
PATH_PNG = "path.png"
DKP_CSV = "dkp.csv"
DKP_PNG = "dkp.png"


# The stems of the pavings of regions other than a space's own (`rpr3 pave`): region -> stem.
REGION_STEMS = {"singularity-free det J > 0": "singularity-free.plus",
                "singularity-free det J < 0": "singularity-free.minus"}


def region_stem(space: str, region: str | None) -> str:
    """The stem of a paving's files: the space's name for its own region (None), else the region's
    stem (`singularity-free.plus`), else the region's name with '> 0' and '< 0' spelled `plus` and
    `minus` and every run of other characters than letters, digits, '.', '+' and '-' made one '-'
    (a 3-RRR's `singularity-free +-+ det A > 0`: `singularity-free-+-+-det-A-plus`, one stem per
    working mode and sign)."""
    if region is None:
        return space
    if region in REGION_STEMS:
        return REGION_STEMS[region]
    words = region.replace("> 0", "plus").replace("< 0", "minus")
    return re.sub(r"[^A-Za-z0-9.+-]+", "-", words).strip("-")


def paving_figure(stem: str, complement: bool = False) -> str:
    """`<stem>.png` (the paving, its certified inside in black) or `<stem>.complement.png`."""
    return f"{stem}.complement.png" if complement else f"{stem}.png"


def paving_files(stem: str) -> tuple[str, ...]:
    """The files of a paving written under `stem`: the trees, the summary, GeoJSON and figures."""
    return (f"{stem}.qt", f"{stem}{COMPLEMENT}", f"{stem}{BAND}", f"{stem}.csv", f"{stem}.geojson",
            paving_figure(stem), paving_figure(stem, True))


PAVE_SET = "rpr3-pave"  # the output set of `rpr3 pave` (and of `refine` of one of its pairs)
VOLUMES_CSV = "volumes.csv"
SINGULARITY_FREE_PNG = "singularity-free.png"  # `rpr3 pave`: both singularity-free regions in one figure


def pave_files() -> tuple[str, ...]:
    """The files of an `rpr3 pave` run: three pairs (the workspace and its two singularity-free
    regions), volumes.csv and the figures."""
    stems = ("workspace", *REGION_STEMS.values())
    return (*(f for stem in stems for f in paving_files(stem)), VOLUMES_CSV, SINGULARITY_FREE_PNG)


# The files of the 3-RPR studies (`rpr3 area | sweep | synthesize | verify`; `verify` of a 3-RRR
# too): the table(s), then the figures in the order they are drawn.
AREA_CSV = "area.csv"
AREA_FILES = (AREA_CSV, "singularity-free-workspace.png")
SYNTHESIS_CSV = "synthesis.csv"
TABLE1_CSV = "table1-comparison.csv"  # `rpr3 synthesize`: the paper's Table 1 beside ours
SYNTHESIS_FILES = (SYNTHESIS_CSV, TABLE1_CSV, "area-vs-phi-cases.png", "singularity-free-workspace-case2.png")
VERIFY_CSV = "verify.csv"
COUNTEREXAMPLE_CSV = "counterexample.csv"
COUNTEREXAMPLE_PNG = "counterexample.png"
VERIFY_FILES = (VERIFY_CSV, COUNTEREXAMPLE_CSV, COUNTEREXAMPLE_PNG)
SWEEP_FILES = {  # sweep -> its table, then its figures in the order it draws them
    "phi": ("area-vs-phi.csv", "area-vs-phi.png", "area-vs-small-phi.png", "area-vs-phi-optimal-rho-min.png",
            "optimal-rho-min-vs-phi.png"),
    "rho_min": ("area-vs-rho-min.csv", "area-vs-rho-min.png"),
    "t2": ("area-vs-t2.csv", "area-vs-t2.png"),
}


def sweep_files(over: str) -> tuple[str, ...]:
    """The table and figures of `rpr3 sweep --over OVER`."""
    return SWEEP_FILES[over]


# The figures of `aspects` (five-bar and 2-RPR: the workspace, the joint space per assembly mode;
# over a space of poses: slices and a map), `tolerance`, `kratio` and `atlas`.
ASPECTS_WORKSPACE_PNG = "aspects-workspace.png"
ASPECTS_SLICES_PNG = "aspects-slices.png"
ASPECTS_MAP_PNG = "aspects-map.png"
TOLERANCE_CSV = "tolerance.csv"
TOLERANCE_BANDS_PNG = "tolerance-bands.png"
TOLERANCE_ASPECTS_PNG = "tolerance-aspects.png"
KRATIO_CSV = "kratio.csv"
KRATIO_PNG = "kratio.png"
ATLAS_CSV = "atlas.csv"
ATLAS_PNG = "atlas.png"
VIEW_HTML = "view.html"


def view_page(first: Path) -> Path:
    """Where `fivebar view` writes its page without -o: `view.html` in the first folder given, or
    beside the first `.qt` file given."""
    return (first if first.is_dir() else first.parent) / VIEW_HTML


def aspects_jointspace_figure(assembly: str) -> str:
    """`aspects-jointspace-assembly+.png` or `...-.png`: the aspects of one assembly mode ('+', '-')."""
    return f"aspects-jointspace-assembly{assembly}.png"


# The output sets of the commands writing into a mechanism's folder (io.outputs): name -> owned files.
ASPECT_FILES = (ASPECTS_CSV, CROSSINGS_CSV, SPLIT_CSV, "aspects/aspect-*.qt", "aspects/aspect-*.geojson",
                "aspects/aspect-*.ply", "aspects-*.png")
PATH_FILES = (PATH_CSV, PATH_PNG)
DKP_FILES = (DKP_CSV, DKP_PNG)
TOLERANCE_FILES = (TOLERANCE_CSV, "tolerance-*.png")
KRATIO_FILES = (KRATIO_CSV, KRATIO_PNG)
