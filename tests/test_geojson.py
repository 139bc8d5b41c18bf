"""GeoJSON of certified regions (issue 12, item 3), read back with shapely: valid (Multi)Polygons
whose areas equal the CSV areas, holes where the region has holes, every cell centre of the set
inside and every centre of the other cells outside, deterministic bytes."""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pytest
import shapely
from cli_helpers import csv_rows, one_line, run_cli
from hypothesis import given, settings
from hypothesis import strategies as st
from shapely.geometry import shape

from fivebar_cli.io.geojson import feature_text, geojson_text
from fivebar_cli.paving.grid import Grid
from fivebar_cli.paving.tree import Tree

REPO = Path(__file__).resolve().parents[1]
M1_YAML = REPO / "configs" / "m1.yaml"
RPR2_YAML = REPO / "configs" / "rpr2.yaml"


def read(path: Path) -> tuple[dict, object]:
    data = json.loads(path.read_text())
    assert data["type"] == "FeatureCollection" and len(data["features"]) == 1
    f = data["features"][0]
    assert f["type"] == "Feature" and f["geometry"]["type"] in ("Polygon", "MultiPolygon")
    return f["properties"], shape(f["geometry"])


def check_against_cells(tree: Tree, geometry) -> None:
    """Valid; the area of the cells; cell centres of the set inside, of its complement outside;
    exterior rings counter-clockwise and holes clockwise (RFC 7946)."""
    assert geometry.is_valid, shapely.is_valid_reason(geometry)
    assert geometry.area == pytest.approx(tree.area, rel=1e-9, abs=1e-12)
    inside = tree.centres()
    outside = tree.complement().centres()
    assert shapely.contains_xy(geometry, inside[:, 0], inside[:, 1]).all()
    if len(outside):
        assert not shapely.intersects_xy(geometry, outside[:, 0], outside[:, 1]).any()
    for part in shapely.get_parts(geometry):
        assert part.exterior.is_ccw and all(not hole.is_ccw for hole in part.interiors)


@pytest.fixture(scope="module")
def aspects_run(tmp_path_factory):
    out = tmp_path_factory.mktemp("geojson")
    result = run_cli("aspects", M1_YAML, "--depth", 8, "-o", out, "--no-plot", "-q", cwd=REPO)
    assert result.status == 0, result.stderr
    return out


def test_every_aspect_has_its_geojson(aspects_run):
    from fivebar_cli.io.qtfile import read_qt

    rows = csv_rows(aspects_run / "aspects.csv")
    holes = 0
    for r in rows:
        k = int(r["aspect"])
        props, geometry = read(aspects_run / "aspects" / f"aspect-{k:02d}.workspace.geojson")
        assert props["aspect"] == k and props["working_mode"] == r["working_mode"]
        assert props["assembly_mode"] == r["assembly_mode"] and props["depth"] == 8 and props["name"] == "M1"
        assert props["area"] == pytest.approx(float(r["workspace_area"]), rel=1e-9)
        assert geometry.area == pytest.approx(float(r["workspace_area"]), rel=1e-9)
        check_against_cells(read_qt(aspects_run / "aspects" / f"aspect-{k:02d}.workspace.qt").tree, geometry)
        holes += sum(len(p.interiors) for p in shapely.get_parts(geometry))
    assert holes >= 2  # aspects 4 and 7 of M1 go round a hole of the workspace


def test_geojson_bytes_are_deterministic(aspects_run, tmp_path):
    assert run_cli("aspects", M1_YAML, "--depth", 8, "-o", tmp_path, "--no-plot", "-q", cwd=REPO).status == 0
    for path in sorted((aspects_run / "aspects").glob("*.geojson")):
        assert (tmp_path / "aspects" / path.name).read_bytes() == path.read_bytes()
    text = path.read_text()
    assert text.endswith("\n") and text.count("\n") == 1 and "-0.0," not in text and "NaN" not in text


@pytest.mark.parametrize("space", ["workspace", "jointspace"])
def test_space_geojson(tmp_path, space):
    """--geojson: the certified inside region; the joint space in its [-pi, pi]^2 chart."""
    from fivebar_cli.io.qtfile import read_qt

    result = run_cli(space, M1_YAML, "--depth", 7, "--geojson", "-o", tmp_path, "--no-plot", cwd=REPO)
    assert result.status == 0, result.stderr
    assert f"wrote {tmp_path / (space + '.geojson')}" in result.stdout
    props, geometry = read(tmp_path / f"{space}.geojson")
    row = csv_rows(tmp_path / f"{space}.csv")[0]
    assert props == {"name": "M1", "space": space, "region": "reachable" if space == "workspace" else "assemblable",
                     "depth": 7, "procedure": "exact", "area": pytest.approx(float(row["inside_area"]), rel=1e-9)}
    check_against_cells(read_qt(tmp_path / f"{space}.qt").tree, geometry)
    if space == "jointspace":
        minx, miny, maxx, maxy = geometry.bounds
        assert -np.pi <= minx and maxx <= np.pi and -np.pi <= miny and maxy <= np.pi
    assert not (tmp_path / "workspace.geojson").exists() or space == "workspace"
    # the library writes the same file (the command wrote it itself before: a paving's GeoJSON
    # could not be had from Python)
    import fivebar_cli as fb

    paths = fb.pave("m1", space, 7).save(tmp_path / "api", geojson=True)
    assert paths[-1] == tmp_path / "api" / f"{space}.geojson"
    assert paths[-1].read_bytes() == (tmp_path / f"{space}.geojson").read_bytes()


def test_geojson_is_for_quadtrees(tmp_path):
    """A space of three axes has no GeoJSON: refused before anything is computed or written, by the
    command (on --geojson, as the library's parameter) and by `Paving.save`."""
    import fivebar_cli as fb

    one_line(run_cli("workspace", REPO / "configs" / "rpr3-caro.yaml", "--depth", 3, "--geojson", "-o",
                     tmp_path / "cli"), 2, "--geojson: GeoJSON is for 2-D spaces; the workspace of an rpr3 has 3 axes")
    with pytest.raises(fb.InputError, match="`geojson`: GeoJSON is for 2-D spaces"):
        fb.pave("rpr3-caro", "workspace", 2).save(tmp_path / "api", geojson=True)
    assert not (tmp_path / "cli").exists() and not (tmp_path / "api").exists()


def test_without_the_flag_no_geojson(tmp_path):
    assert run_cli("workspace", M1_YAML, "--depth", 5, "-o", tmp_path, "--no-plot", "-q", cwd=REPO).status == 0
    assert not list(tmp_path.glob("*.geojson"))


def test_rpr2_geojson(tmp_path):
    result = run_cli("workspace", RPR2_YAML, "--depth", 6, "--geojson", "-o", tmp_path, "--no-plot", "-q", cwd=REPO)
    assert result.status == 0, result.stderr
    _, geometry = read(tmp_path / "workspace.geojson")
    assert geometry.is_valid and geometry.area > 0


# ---------------------------------------------------------------- synthetic sets


GRID = Grid(((-2.0, 6.0), (1.0, 9.0)), 3, (False, False))


def tree_of(cells) -> Tree:
    return Tree.from_cells(GRID, 3, np.array(cells))


def geometry_of(tree: Tree) -> dict:
    """The geometry of the tree's Feature, as json reads it back."""
    return json.loads(feature_text(tree, {}))["geometry"]


def test_ring_has_one_hole():
    ring = [(x, y) for x in range(1, 7) for y in range(1, 7) if not (2 < x < 5 and 2 < y < 5)]
    geometry = shape(geometry_of(tree_of(ring)))
    assert geometry.geom_type == "Polygon" and len(geometry.interiors) == 1
    assert geometry.area == pytest.approx(32.0) and len(geometry.exterior.coords) == 5  # collinear edges merged


def test_cells_touching_at_a_corner_are_two_polygons():
    geometry = shape(geometry_of(tree_of([(0, 0), (1, 1)])))
    assert geometry.geom_type == "MultiPolygon" and len(geometry.geoms) == 2 and geometry.is_valid


def test_hole_touching_the_shell_at_a_corner():
    """A 3 x 3 block without its centre and one corner-adjacent cell: the region's hole touches
    its outline at one point; the result stays valid."""
    cells = [(x, y) for x in range(3) for y in range(3) if (x, y) not in ((1, 1), (2, 2))]
    geometry = shape(geometry_of(tree_of(cells)))
    assert geometry.is_valid and geometry.area == pytest.approx(7.0)


def test_island_in_a_hole():
    """A square ring around a hole holding a one-cell island, beside a second ring: three faces,
    two holes, each hole given to the smallest exterior around it (not the island's)."""
    grid = Grid(((-2.0, 6.0), (1.0, 9.0)), 4, (False, False))
    ring = [(x, y) for x in range(7) for y in range(7) if x in (0, 6) or y in (0, 6)]
    small = [(x, y) for x in range(9, 12) for y in range(3) if (x, y) != (10, 1)]
    tree = Tree.from_cells(grid, 4, np.array(ring + [(3, 3)] + small))
    geometry = shape(json.loads(feature_text(tree, {}))["geometry"])
    assert geometry.geom_type == "MultiPolygon" and geometry.is_valid
    assert sorted((p.area, len(p.interiors)) for p in geometry.geoms) == [(0.25, 0), (2.0, 1), (6.0, 1)]
    check_against_cells(tree, geometry)


def test_empty_tree():
    text = geojson_text([feature_text(Tree.empty(GRID), {"area": 0.0})])
    assert json.loads(text)["features"][0]["geometry"] == {"type": "MultiPolygon", "coordinates": []}


@settings(max_examples=40, deadline=None)
@given(seed=st.integers(0, 10 ** 6), density=st.floats(0.2, 0.9))
def test_random_sets(seed, density):
    """Random cells of three sizes (checkerboard-like pinches included)."""
    rng = np.random.default_rng(seed)
    grid = Grid(((-2.0, 6.0), (1.0, 9.0)), 5, (False, False))
    level = int(rng.integers(3, 6))
    n = 1 << level
    tree = Tree.from_cells(grid, level, np.argwhere(rng.random((n, n)) < density))
    check_against_cells(tree, shape(geometry_of(tree)))


def _polygonized(tree: Tree):
    """The reference: shapely's polygonizer over the boundary's lattice segments, the faces holding
    a cell of the set kept (how the GeoJSON was made before the rings were traced directly)."""
    from fivebar_cli.paving.outline import boundary_segments, lattice_to_space

    segments = boundary_segments(tree)
    if not len(segments):
        return shapely.MultiPolygon()
    faces = shapely.get_parts(shapely.polygonize(shapely.linestrings(segments.reshape(-1, 2, 2).astype(float))))
    cells = np.floor(shapely.get_coordinates(shapely.point_on_surface(faces))) + 0.5
    kept = shapely.normalize(shapely.MultiPolygon(list(faces[tree.locate(lattice_to_space(tree, cells)) >= 0])))
    return shapely.transform(shapely.orient_polygons(kept, exterior_cw=False), lambda xy: lattice_to_space(tree, xy))


def _reference_text(geometry, properties: dict) -> str:
    """The Feature as the writer made it before it wrote the text itself: the shapely polygons'
    coordinates as nested lists (`+ 0.0`: no -0.0) through json.dumps."""
    def ring(r) -> list:
        return (shapely.get_coordinates(r) + 0.0).tolist()

    def polygon(p) -> list:
        return [ring(p.exterior)] + [ring(h) for h in p.interiors]

    parts = list(shapely.get_parts(geometry)) if not geometry.is_empty else []
    if len(parts) == 1:
        value = {"type": "Polygon", "coordinates": polygon(parts[0])}
    else:
        value = {"type": "MultiPolygon", "coordinates": [polygon(p) for p in parts]}
    return json.dumps({"type": "Feature", "properties": properties, "geometry": value}, sort_keys=True,
                      separators=(",", ":"), allow_nan=False)


ROOTS = [((-2.0, 6.0), (1.0, 9.0)),  # integer-valued floats
         ((-1e-7, 3e-7), (-0.0, 1e-5)),  # exponents, a root at -0.0
         ((-3.0, 3.0), (-3.0, 5.0)),  # lattice values crossing 0 (no -0.0 written)
         ((0.1, 0.7), (-1e6, 1e22))]  # digits that do not round-trip short, large exponents


@settings(max_examples=60, deadline=None)
@given(seed=st.integers(0, 10 ** 6), density=st.floats(0.05, 0.95), periodic=st.booleans(), root=st.sampled_from(ROOTS))
def test_traced_rings_are_the_polygonizers_bytes(seed, density, periodic, root):
    """The rings traced from the cells (pinches, holes touching holes or the exterior, cells on a
    periodic axis, islands in holes) give the very text json.dumps gives of the polygons shapely's
    polygonizer finds from the boundary segments (floats with exponents, integer values, zeros)."""
    rng = np.random.default_rng(seed)
    grid = Grid(root, 6, (periodic, False))
    level = int(rng.integers(2, 7))
    n = 1 << level
    tree = Tree.from_cells(grid, level, np.argwhere(rng.random((n, n)) < density))
    properties = {"name": "m\u00e9\"1", "depth": 6, "area": tree.area}
    assert feature_text(tree, properties) == _reference_text(_polygonized(tree), properties)


def test_ragged_arrays_are_shapelys():
    """The writer's coordinates and offsets of a lattice MultiPolygon (`_ragged`, built from the
    geometry's parts) are those of shapely.to_ragged_array: random unions of squares, holes and
    islands included, and the empty set."""
    from fivebar_cli.io.geojson import _lattice_geometry, _ragged

    rng = np.random.default_rng(7)
    trees = [Tree.empty(GRID), tree_of([(x, y) for x in range(1, 7) for y in range(1, 7) if not (2 < x < 5 and 2 < y < 5)])]
    trees += [tree_of(np.argwhere(rng.random((8, 8)) < density)) for density in (0.3, 0.5, 0.7) for _ in range(4)]
    for tree in trees:
        geometry = _lattice_geometry(tree)
        _, coords, (rings, polygons, _) = shapely.to_ragged_array([geometry])
        got = _ragged(geometry)
        assert all(np.array_equal(g, w) for g, w in zip(got, (coords, rings, polygons), strict=True))


def test_cycles_of_random_permutations():
    """outline._cycles (pointer doubling) against walking each cycle from its smallest element:
    random permutations with fixed points, short and long cycles."""
    from fivebar_cli.paving.outline import _cycles

    rng = np.random.default_rng(3)
    for n in [1, 2, 3, 7, 64, 300] + [int(v) for v in rng.integers(1, 500, 20)]:
        succ = rng.permutation(n)
        ring, position = _cycles(succ)
        want_ring, want_position = np.full(n, -1), np.full(n, -1)
        for root in range(n):
            if want_ring[root] >= 0:
                continue
            i, k = root, 0
            while want_ring[i] < 0:
                want_ring[i], want_position[i], i, k = root, k, succ[i], k + 1
        assert ring.tolist() == want_ring.tolist() and position.tolist() == want_position.tolist()


def test_alternating_cycles_equal_cycles():
    """outline._alternating_cycles (the cycles of the square on the first half) against
    outline._cycles on random permutations that take [0, half) into [half, 2 half) and back."""
    from fivebar_cli.paving.outline import _alternating_cycles, _cycles

    rng = np.random.default_rng(5)
    for half in [1, 2, 5, 40] + [int(v) for v in rng.integers(1, 300, 12)]:
        succ = np.empty(2 * half, np.int64)
        succ[:half] = half + rng.permutation(half)
        succ[half:] = rng.permutation(half)
        got, want = _alternating_cycles(succ, half), _cycles(succ)
        assert np.array_equal(got[0], want[0]) and np.array_equal(got[1], want[1])


def test_value_texts_of_deep_and_shared_grids():
    """The coordinates' texts, from the table a grid's trees share (several trees, values made by
    one and looked up by the next) and made per tree on a grid deeper than the table's
    (`TABLE_DEPTH`), are the bytes json.dumps gives of the shapely polygons."""
    from fivebar_cli.io.geojson import TABLE_DEPTH

    rng = np.random.default_rng(11)
    for depth in (7, TABLE_DEPTH + 2):
        grid = Grid(((-3.0, 3.0), (0.1, 0.7)), depth, (False, False))
        for level in (depth - 2, depth - 1, depth):  # small cells: few lattice edges
            cells = np.argwhere(rng.random((6, 6)) < 0.5) + int(rng.integers(0, 20))
            tree = Tree.from_cells(grid, level, cells)
            properties = {"depth": depth}
            assert feature_text(tree, properties) == _reference_text(_polygonized(tree), properties)


@settings(max_examples=40, deadline=None)
@given(seed=st.integers(0, 10 ** 6), density=st.floats(0.1, 0.9))
def test_only_one_against_unit_edges(seed, density):
    """outline._only_one (each family sorted, touching intervals joined, the two merged) against
    the unit intervals of a minus b and of b minus a, counted one by one and joined where they
    touch: the leaves' low and high sides (mixed sizes: cells of three levels) on each line."""
    from fivebar_cli.paving.outline import _only_one

    rng = np.random.default_rng(seed)
    grid = Grid(((0.0, 1.0), (0.0, 1.0)), 5, (False, False))
    trees = [Tree.from_cells(grid, level, np.argwhere(rng.random((1 << level,) * 2) < density)) for level in (3, 4, 5)]
    tree = trees[0] | trees[1] | trees[2]
    size = 5 - tree.level
    lo = tree.coords << size[:, None]
    width = 33
    for axis in (0, 1):
        line_a, line_b = lo[:, 1 - axis] * width, (lo[:, 1 - axis] + (1 << size)) * width
        got = _only_one(line_a, line_b, lo[:, axis].copy(), size)
        units = [{int(line + s + u) for line, s, n in zip(lines, lo[:, axis], 1 << size) for u in range(n)}
                 for lines in (line_a, line_b)]
        for (start, end), only in zip(got, (units[0] - units[1], units[1] - units[0])):
            keys = sorted(only)
            first = [k for k in keys if k - 1 not in only]
            last = [k + 1 for k in keys if k + 1 not in only]
            assert start.tolist() == first and end.tolist() == last
