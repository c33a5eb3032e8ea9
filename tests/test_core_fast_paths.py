"""The fast paths taken for speed give exactly what the general paths give."""

import numpy as np
import pytest
from helpers import with_points
from hypothesis import HealthCheck, assume, event, given, settings
from hypothesis import strategies as st
from scipy.spatial import cKDTree
from test_core_properties import params

from barymesh import MeshParams, TriMesh, build_mesh
from barymesh.placement import paper_origins
from barymesh.quality import quality_summary, triangle_quality
from barymesh.repeat import Repetition, sector_edge_counts, translated_copy_measures
from barymesh.stats import counted_measures
from barymesh.topology import edge_topology, segment_lengths
from barymesh.weld import _lattice_candidates, _window_candidates, merge_pairs


def kd_tree_candidates(origins, frac, reach, radius):
    """The k-d tree search of ``_lattice_candidates`` alone (balanced tree)."""
    scaled = (origins - origins.min(axis=0)) / reach * radius
    span = float(scaled.max(initial=0.0))
    box = np.array([1.0, 1.0, 3 * span + 1.0, 3 * span + 1.0])
    tree = cKDTree(np.concatenate([frac, scaled], axis=1), boxsize=box)
    return tree.query_pairs(radius * 1.000001, p=np.inf, output_type="ndarray")


def lattice_inputs(origins, n, step, tolerance):
    steps = np.array([step, step])
    scaled = origins / steps
    frac = scaled - np.floor(scaled)
    frac[frac >= 1.0] = 0.0
    return origins, frac, n * steps + tolerance, tolerance / step * 1.000001


def pair_set(pairs):
    return set(map(tuple, np.sort(pairs, axis=1).tolist()))


@pytest.mark.parametrize("angle_step", [0.01, 0.5, 90.0])
def test_window_candidates_of_paper_rings_equal_the_kd_tree(angle_step):
    params = MeshParams(structure="double_ring", mode="paper", angle_step=angle_step)
    origins = paper_origins(params)[0]
    args = lattice_inputs(origins, 4, 0.25, params.weld_tolerance)
    assert pair_set(_lattice_candidates(*args)) == pair_set(kd_tree_candidates(*args))


@pytest.mark.parametrize("seed", range(4))
def test_window_candidates_with_phases_across_the_period_equal_the_kd_tree(seed):
    # scattered origins, plus pairs whose lattice phases sit just above 0 and just below 1
    # three lattice steps apart: the sorted window must wrap around the period to pair them
    rng = np.random.default_rng(seed)
    scattered = rng.uniform(0, 100, (2000, 2))
    base = rng.integers(0, 100, (30, 2)).astype(float)
    low = base + [1e-12, 0.0]
    high = base + [3 - 1e-12, 1.0]
    origins = np.concatenate([scattered, low, high])
    args = lattice_inputs(origins, 4, 1.0, 1e-6)
    scaled = (origins - origins.min(axis=0)) / args[2] * args[3]
    assert _window_candidates(args[1], scaled, args[3] * 1.000001) is not None  # no fallback
    found = pair_set(_lattice_candidates(*args))
    assert found == pair_set(kd_tree_candidates(*args))
    assert {(2000 + k, 2030 + k) for k in range(30)} <= found


def test_merge_without_pairs_is_the_identity():
    ids, rep = merge_pairs(6, np.empty((0, 2), dtype=np.int64))
    assert ids.tolist() == rep.tolist() == list(range(6))


def reference_quality(points, triangles):
    """Areas, smallest angles and aspect ratios as first written: (T, 3, 3) corner gathers."""
    p = np.asarray(points, dtype=np.float64)[np.asarray(triangles)]
    sides = [np.sqrt(sum(x * x for x in (p[:, (k + 1) % 3] - p[:, k]).T)) for k in range(3)]
    u, v = p[:, 1] - p[:, 0], p[:, 2] - p[:, 0]
    if p.shape[2] == 2:
        cross2 = (u[:, 0] * v[:, 1] - u[:, 1] * v[:, 0]) ** 2
    else:
        cross2 = (
            (u[:, 1] * v[:, 2] - u[:, 2] * v[:, 1]) ** 2
            + (u[:, 2] * v[:, 0] - u[:, 0] * v[:, 2]) ** 2
            + (u[:, 0] * v[:, 1] - u[:, 1] * v[:, 0]) ** 2
        )
    area = 0.5 * np.sqrt(cross2)
    l0, l1, l2 = sides
    longest = np.maximum(np.maximum(l0, l1), l2)
    shortest = np.minimum(np.minimum(l0, l1), l2)
    perimeter = l0 + l1 + l2
    middle = perimeter - longest - shortest
    with np.errstate(invalid="ignore", divide="ignore"):
        sine = np.clip(2.0 * area / (longest * middle), 0.0, 1.0)
        aspect = longest * perimeter / (4.0 * np.sqrt(3.0) * area)
    angle = np.degrees(np.arcsin(sine))
    angle[~np.isfinite(angle)] = 0.0
    return area, angle, aspect


def assert_same_bits(got, expect):
    for a, b in zip(got, expect, strict=True):
        assert np.array_equal(a, b, equal_nan=True)


@pytest.mark.parametrize("scale", [1.0, 1e-160])
@pytest.mark.parametrize("dims", [2, 3])
def test_quality_equals_the_reference_bit_for_bit(scale, dims):
    # random triangles, slivers and repeated corners, at scales where c² underflows
    rng = np.random.default_rng(dims)
    points = rng.normal(size=(300, dims)) * scale
    triangles = rng.integers(0, 300, (2000, 3))
    triangles[:50, 2] = triangles[:50, 1]  # degenerate: two corners the same
    expect = reference_quality(points, triangles)
    assert_same_bits(triangle_quality(points, triangles), expect)
    pts3 = np.column_stack([points, np.zeros(len(points))]) if dims == 2 else points
    mesh = TriMesh(pts3, triangles, np.zeros(len(triangles)), np.ones(len(triangles)), 1)
    mesh.stats()  # edge lengths first: the quality does not depend on what is cached
    assert_same_bits(mesh.quality, expect)
    # the sides taken from the edge lengths: the same sums of squares, the same bits
    sides = (mesh.edge_lengths, mesh.triangle_edges)
    assert_same_bits(triangle_quality(mesh.points, mesh.triangles, None, *sides), expect)


def test_planar_areas_do_not_overflow_where_the_square_would():
    # |cross| up to 1e300: its square overflowed to an infinite area before
    rng = np.random.default_rng(7)
    points = rng.normal(size=(300, 2)) * 1e150
    triangles = rng.integers(0, 300, (2000, 3))
    with np.errstate(over="ignore"):
        expect = reference_quality(points, triangles)[0]
    got = triangle_quality(points, triangles).areas
    assert np.isfinite(got).all() and not np.isfinite(expect).all()
    finite = np.isfinite(expect)
    assert np.array_equal(got[finite], expect[finite])


@pytest.mark.parametrize(
    "params",
    [
        MeshParams(),
        MeshParams(structure="double_ring", mode="conforming", subdivisions=6),
        MeshParams(structure="split_ring", mode="conforming", scheme="barycentric"),
        MeshParams(structure="square_split_double_ring", mode="paper", patch_size=0.5),
    ],
)
def test_quality_of_structures_equals_the_reference_bit_for_bit(params):
    fresh, after_stats = build_mesh(params), build_mesh(params)
    after_stats.stats()
    expect = reference_quality(fresh.points, fresh.triangles)
    assert_same_bits(fresh.quality, expect)
    assert_same_bits(after_stats.quality, expect)


# -- stats(): aggregates without the per-triangle arrays, checked against the general path


SETTINGS = settings(max_examples=100, deadline=None, suppress_health_check=[HealthCheck.too_slow])
STATS_KEYS_EXACT = ("edges", "interior_edges", "boundary_edges", "junction_edges")
STATS_KEYS_CLOSE = ("min_edge", "max_edge", "min_angle_deg", "max_aspect_ratio", "area")


def general_stats(mesh):
    """The stats' counts and figures from the general edge finder and every triangle."""
    topo = edge_topology(mesh.triangles, mesh.n_vertices)
    lengths = segment_lengths(mesh.points, topo.edges)
    valence = np.bincount(topo.valence, minlength=4)
    q = triangle_quality(mesh.points, mesh.triangles)
    return {
        "edges": len(topo.edges),
        "interior_edges": int(valence[2]),
        "boundary_edges": int(valence[1]),
        "junction_edges": int(valence[3:].sum()),
        "min_edge": float(lengths.min()),
        "max_edge": float(lengths.max()),
        "min_angle_deg": float(q.min_angles_deg.min()),
        "max_aspect_ratio": float(q.aspect_ratios.max()),
        "area": float(q.areas.sum()),
    }


def copy_measures(mesh):
    """The measures of translated copies, or None when the mesh is not such copies."""
    rep = mesh.repetition
    if rep is None or rep.kind != "copies":
        return None
    return translated_copy_measures(rep.template, mesh.points, mesh.columns)


def sector_counts(mesh):
    """The edge counts of chains or closed rings of sectors, or None for other meshes."""
    rep = mesh.repetition
    chains = (rep.sectors, rep.closed) if rep.kind == "chains" else None
    regions = mesh.regions[:: len(rep.template.triangles)]
    return sector_edge_counts(rep.template, rep.vertex_map, mesh.n_vertices, chains, regions)


def assert_stats_agree(got, mesh, edge_range_bits=False):
    expect = general_stats(mesh)
    for key in STATS_KEYS_EXACT:
        assert got[key] == expect[key], key
    for key in STATS_KEYS_CLOSE:
        assert got[key] == pytest.approx(expect[key], rel=1e-12, abs=0.0), key
    if edge_range_bits:
        assert (got["min_edge"], got["max_edge"]) == (expect["min_edge"], expect["max_edge"])


# unwelded translated copies (the paper rings): one patch measured instead of all


@pytest.mark.parametrize(
    "params",
    [
        MeshParams(),  # Fig. 12(a)
        MeshParams(structure="double_ring", mode="paper", subdivisions=4, angle_step=0.5),
        MeshParams(structure="double_ring", mode="paper", subdivisions=32, angle_step=20.0),
        MeshParams(structure="ring", mode="paper", patch_size=0.3, origin=(4.0, -2.5)),
        MeshParams(structure="split_double_ring", mode="paper", subdivisions=3, diagonal="AD"),
        MeshParams(structure="patch", mode="paper", subdivisions=7),
    ],
)
def test_stats_of_translated_copies_equal_the_general_ones(params):
    mesh = build_mesh(params)
    fast = copy_measures(mesh)
    assert fast is not None  # these layouts weld nothing: the fast path must be taken
    assert_stats_agree(fast, mesh)
    stats = build_mesh(params).stats()
    assert {k: stats[k] for k in fast} == fast
    assert stats["euler_characteristic"] == mesh.n_vertices - fast["edges"] + mesh.n_triangles


@pytest.mark.parametrize(
    "params",
    [
        MeshParams(structure="square_split_double_ring", mode="paper", patch_size=0.5),  # welded
        MeshParams(structure="double_ring", mode="conforming"),  # sectors, not translations
        MeshParams(structure="split_ring", mode="conforming", scheme="barycentric"),
    ],
)
def test_stats_fast_path_declines_welded_and_deformed_patches(params):
    assert copy_measures(build_mesh(params)) is None


@pytest.mark.parametrize("shift", [1e-9, 1e-3])
def test_stats_fast_path_declines_a_patch_moved_out_of_shape(shift):
    # one vertex of the last patch nudged: that patch is no longer a translated copy
    mesh = build_mesh(MeshParams(angle_step=30.0))
    points = mesh.points.copy()
    points[-1, 1] += shift
    moved = with_points(mesh, points)
    assert copy_measures(moved) is None
    assert_stats_agree(moved.stats(), moved)


@SETTINGS
@given(
    structure=st.sampled_from(["ring", "double_ring", "split_ring", "split_double_ring"]),
    inner=st.floats(0.8, 30.0),
    size=st.floats(0.02, 2.0),
    angle_step=st.floats(0.05, 120.0),
    subdivisions=st.integers(1, 12),
    diagonal=st.sampled_from(["BC", "AD"]),
    scheme=st.sampled_from(["uniform", "barycentric"]),
    origin=st.tuples(st.floats(-50, 50), st.floats(-50, 50)),
)
def test_stats_fast_path_agrees_on_random_paper_rings(
    structure, inner, size, angle_step, subdivisions, diagonal, scheme, origin
):
    try:
        params = MeshParams(
            structure=structure,
            mode="paper",
            inner_radius=inner,
            outer_radius=inner + 2 * size,
            patch_size=size,
            angle_step=angle_step,
            subdivisions=subdivisions,
            diagonal=diagonal,
            scheme=scheme,
            origin=origin,
            gap_width=0.5 * inner,
            max_triangles=200_000,
        )
        mesh = build_mesh(params)
    except ValueError:
        assume(False)
    fast = copy_measures(mesh)
    event("fast path" if fast is not None else "full path")
    if fast is not None:
        assert_stats_agree(fast, mesh)


# other patch structures: edges counted, not made; quality reduced, not stored


def assert_counted_stats_equal_the_general_ones(params):
    mesh = build_mesh(params)
    got = counted_measures(mesh)
    assert "topology" not in mesh.__dict__ and "quality" not in mesh.__dict__  # stayed lazy
    assert_stats_agree(got, mesh, edge_range_bits=True)
    stats = build_mesh(params).stats()
    assert_stats_agree(stats, mesh)


@pytest.mark.parametrize(
    "params",
    [
        MeshParams(structure="square_split_double_ring", mode="paper", patch_size=0.5),  # welded
        MeshParams(structure="square_split_double_ring", mode="paper", gap_angle=90.0),
        MeshParams(structure="double_ring", mode="conforming", subdivisions=3),
        MeshParams(structure="split_double_ring", mode="conforming", scheme="barycentric"),
        MeshParams(structure="double_ring", mode="conforming", outer_radius=5.0),  # touching
        MeshParams(structure="double_ring", mode="paper", angle_step=30.0),
        MeshParams(structure="patch", mode="paper", subdivisions=5),
    ],
)
def test_counted_stats_equal_the_general_edge_finder(params):
    assert_counted_stats_equal_the_general_ones(params)


@SETTINGS
@given(params())
def test_counted_stats_equal_the_general_edge_finder_on_random_parameters(p):
    assume(p.structure != "triangle")  # one patch without a template
    assert_counted_stats_equal_the_general_ones(p)


@pytest.mark.parametrize("scale", [1.0, 1e-160])
@pytest.mark.parametrize("dims", [2, 3])
def test_quality_summary_equals_the_reductions_of_the_per_triangle_quality(scale, dims):
    # random triangles, slivers and repeated corners (undefined angles), tiny and large
    rng = np.random.default_rng(10 + dims)
    points = rng.normal(size=(400, dims)) * scale
    triangles = rng.integers(0, 400, (160_000, 3))
    distinct = (triangles[:, 0] != triangles[:, 1]) & (triangles[:, 1] != triangles[:, 2])
    triangles = triangles[distinct & (triangles[:, 2] != triangles[:, 0])]  # > two blocks
    q = triangle_quality(points, triangles)
    lengths = segment_lengths(points, edge_topology(triangles, 400).edges)
    for degenerate in (False, True):
        if degenerate:
            triangles[70_000, 2] = triangles[70_000, 1]  # a zero side: aspect ratio inf
            triangles[90_000, :] = triangles[90_000, 0]  # a point: angle 0/0 (0), aspect NaN
            q = triangle_quality(points, triangles)
            lengths = segment_lengths(points, edge_topology(triangles, 400).edges)
        s = quality_summary(points, triangles)
        assert (s.shortest_side, s.longest_side) == (lengths.min(), lengths.max())
        assert s.min_angle_deg == pytest.approx(float(q.min_angles_deg.min()), rel=1e-12)
        if scale == 1.0:  # (at 1e-160 the area of 3-D triangles underflows to 0)
            assert (s.min_angle_deg > 0.0) != degenerate
        assert s.area == pytest.approx(float(q.areas.sum()), rel=1e-12)
        assert np.array_equal(s.max_aspect_ratio, q.aspect_ratios.max(), equal_nan=True)
        assert np.isnan(s.max_aspect_ratio) == degenerate
    assert quality_summary(points, triangles[:0]) == (0.0,) * 5


# closed conforming rings: edges counted for a chain of three sectors, then scaled


def general_counts(mesh):
    return np.bincount(edge_topology(mesh.triangles, mesh.n_vertices).valence, minlength=3)


@pytest.mark.parametrize(
    "params",
    [
        MeshParams(structure="double_ring", mode="conforming"),
        MeshParams(structure="double_ring", mode="conforming", subdivisions=3, diagonal="AD"),
        MeshParams(structure="ring", mode="conforming", scheme="barycentric", origin=(3.0, -7.0)),
        MeshParams(structure="ring", mode="conforming", subdivisions=1, angle_step=120.0),
    ],
)
def test_sector_edge_counts_of_closed_rings_equal_the_general_edge_finder(params):
    mesh = build_mesh(params)
    counts = sector_counts(mesh)
    assert counts is not None  # closed rings of glued sectors: the fast path must be taken
    np.testing.assert_array_equal(counts, general_counts(mesh))
    # V − E + F = 0 per closed ring
    assert mesh.n_vertices - counts.sum() + mesh.n_triangles == 0
    assert_counted_stats_equal_the_general_ones(params)


@pytest.mark.parametrize(
    "params",
    [
        MeshParams(structure="split_double_ring", mode="conforming"),  # two arcs per ring
        MeshParams(structure="split_ring", mode="conforming", grading=True),  # graded sectors
    ],
)
def test_sector_edge_counts_of_open_arcs_come_from_their_short_chains(params):
    # the build has checked the arcs' numbering (the invariant check reads the chains):
    # counts summed from the short chains, one arc of sectors per ring and slot side
    mesh = build_mesh(params)
    assert mesh.repetition.kind == "chains"
    ms, closed = mesh.repetition.sectors, mesh.repetition.closed
    assert not any(closed) and sum(ms) == mesh.n_patches
    counts = sector_counts(mesh)
    np.testing.assert_array_equal(counts, general_counts(mesh))
    # V − E + F = 1 per open arc
    assert mesh.n_vertices - counts.sum() + mesh.n_triangles == len(ms)
    assert_counted_stats_equal_the_general_ones(params)


@pytest.mark.parametrize(
    "params",
    [
        MeshParams(structure="double_ring", mode="conforming", outer_radius=5.0),  # touching
        MeshParams(structure="double_ring", mode="paper", angle_step=30.0),
        MeshParams(structure="square_split_double_ring", mode="conforming"),
    ],
)
def test_sector_edge_counts_decline_other_layouts(params):
    assert sector_counts(build_mesh(params)) is None


def test_sector_edge_counts_decline_renumbered_vertices():
    # the same ring with its vertices numbered at random: the vertex map is no longer
    # the chain's formula, so the edges are counted in general, with the same result
    mesh = build_mesh(MeshParams(structure="ring", mode="conforming", angle_step=30.0))
    new_id = np.random.default_rng(0).permutation(mesh.n_vertices)
    points = np.empty_like(mesh.points)
    points[new_id] = mesh.points
    renumbered = TriMesh(
        points,
        new_id[mesh.triangles],
        mesh.patch_ids,
        mesh.regions,
        mesh.n_patches,
        mesh.mode,
        mesh.tolerance,
        repetition=Repetition.of_triangles(
            mesh.repetition.template, new_id[mesh.triangles], mesh.n_vertices
        ),
    )
    assert sector_counts(renumbered) is None
    assert_stats_agree(renumbered.stats(), renumbered)
    assert renumbered.stats()["edges"] == mesh.stats()["edges"]


@SETTINGS
@given(params(modes=("conforming",)))
def test_sector_edge_counts_equal_the_general_edge_finder_on_random_rings(p):
    assume(p.structure != "triangle")
    mesh = build_mesh(p)
    counts = sector_counts(mesh)
    event("sector counts" if counts is not None else "declined")
    if counts is not None:
        np.testing.assert_array_equal(counts, general_counts(mesh))
