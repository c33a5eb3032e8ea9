"""The shortcuts taken for unwelded copies of one patch give what the general paths give.

A paper ring is its template copied patch after patch, nothing welded
(``barymesh.repeat.copies``). Its RWG lengths are taken along rows of the
coordinates seen as (P, Nv), its centroids patch by patch, its connectivity's
row pointers tiled, and its invariant check skips the per-triangle pass when
the copies are translations whose first patch clears the test by a margin.
Each is compared with the general path (integers exactly, floats bit for bit
where the sums are the same), and defects planted in such a mesh must still be
refused.
"""

import dataclasses

import numpy as np
import pytest
from helpers import with_points

from barymesh import MeshParams, TriMesh, build_mesh
from barymesh.check import check_mesh
from barymesh.invariants import MeshInvariantError, inverted_or_flat
from barymesh.repeat import (
    Repetition,
    copy_slack,
    patch_centroids,
    translated_copies_sound,
)
from barymesh.repeat.copies import copies_lengths, template_topology, tiled
from barymesh.topology import segment_lengths, triangle_adjacency

PAPER = [
    MeshParams(structure="double_ring", mode="paper", subdivisions=4, angle_step=2.5),
    MeshParams(structure="ring", mode="paper", subdivisions=3, angle_step=7.0, diagonal="AD"),
    MeshParams(structure="double_ring", mode="paper", subdivisions=2, scheme="barycentric"),
    MeshParams(structure="split_ring", mode="paper", subdivisions=5, angle_step=4.0),
]
#: Meshes of other repetition kinds (chains, welded patches), for the centroids.
OTHERS = [
    MeshParams(structure="double_ring", mode="conforming", subdivisions=3),
    MeshParams(structure="square_split_double_ring", mode="paper", subdivisions=2),
    MeshParams(structure="cross", mode="conforming", subdivisions=3),
]


def general_centroids(mesh):
    """The general path of ``TriMesh.centroids`` (the same mesh without its record)."""
    return plain(mesh).centroids


def plain(mesh, points=None):
    """The mesh without its repetition record, optionally with other points."""
    return TriMesh(
        mesh.points if points is None else points,
        mesh.triangles,
        mesh.patch_ids,
        mesh.regions,
        mesh.n_patches,
        mesh.mode,
        mesh.tolerance,
        mesh.patch_rects,
    )


@pytest.mark.parametrize("params", PAPER, ids=lambda p: f"{p.structure}-n{p.subdivisions}")
def test_paper_rings_are_copies(params):
    assert build_mesh(params).repetition.kind == "copies"


@pytest.mark.parametrize("params", PAPER, ids=lambda p: f"{p.structure}-n{p.subdivisions}")
@pytest.mark.parametrize("z", [False, True])
def test_copies_lengths_equal_the_general_lengths_bit_for_bit(params, z):
    mesh = build_mesh(params)
    points = mesh.points.copy()
    if z:  # a coordinate that is not zero everywhere is measured too
        points[:, 2] = np.sin(points[:, 0])
    rep = mesh.repetition
    nv, n_p = len(rep.template.uv), rep.n_patches
    local = template_topology(rep.template)
    for pairs in (local.edges, local.edges[local.valence == 2]):
        want = segment_lengths(points, tiled(pairs, n_p, nv))
        got = copies_lengths(pairs, n_p, nv, points)
        assert got.dtype == want.dtype and got.shape == want.shape
        assert np.array_equal(got, want)
        got = copies_lengths(pairs, n_p, nv, points, with_points(mesh, points).columns)
        assert np.array_equal(got, want)


@pytest.mark.parametrize("params", PAPER + OTHERS, ids=lambda p: f"{p.structure}-{p.mode}")
def test_patch_centroids_equal_the_general_centroids_bit_for_bit(params):
    mesh = build_mesh(params)
    got = mesh.centroids
    want = general_centroids(mesh)
    assert got.dtype == want.dtype and got.shape == want.shape and got.flags.c_contiguous
    assert np.array_equal(got, want)
    moved = mesh.points.copy()
    moved[:, 2] = 0.25 * moved[:, 0] - 1.0  # a z that is not zero everywhere
    assert np.array_equal(with_points(mesh, moved).centroids, plain(mesh, moved).centroids)
    rep = mesh.repetition
    direct = patch_centroids(mesh.columns, rep.vertex_map, rep.template.triangles)
    assert np.array_equal(direct, want)  # the gathered path also for unwelded copies


@pytest.mark.parametrize("params", PAPER, ids=lambda p: f"{p.structure}-n{p.subdivisions}")
def test_copies_connectivity_equals_the_general_one(params):
    mesh = build_mesh(params)
    got = mesh.connectivity
    want = triangle_adjacency(mesh.n_triangles, plain(mesh).topology)
    for name in ("data", "indices", "indptr"):
        a, b = getattr(got, name), getattr(want, name)
        assert a.dtype == b.dtype and np.array_equal(a, b), name


@pytest.mark.parametrize("params", PAPER, ids=lambda p: f"{p.structure}-n{p.subdivisions}")
def test_translated_paper_rings_skip_the_per_triangle_pass(params):
    mesh = build_mesh(params)
    rep = mesh.repetition
    slack = copy_slack(len(rep.template.uv), mesh.columns)
    assert slack is not None and slack == mesh.translation_slack
    assert translated_copies_sound(rep.template, mesh.columns, slack)
    assert len(inverted_or_flat(mesh.points, mesh.triangles)) == 0  # what the skip stands for


def test_a_folded_copy_is_still_refused():
    mesh = build_mesh(PAPER[0])
    rep = mesh.repetition
    nv = len(rep.template.uv)
    moved = mesh.points.copy()
    moved[7 * nv + 6, :2] += [0.4, 0.3]  # an interior vertex of patch 7 across its neighbours
    assert len(inverted_or_flat(moved, mesh.triangles)) > 0
    bad = with_points(mesh, moved)
    assert not translated_copies_sound(rep.template, bad.columns, bad.translation_slack)
    with pytest.raises(MeshInvariantError, match="clockwise or flat"):
        check_mesh(bad, PAPER[0])


def test_the_same_fold_in_every_copy_is_still_refused():
    """Every copy the same (translations), each with one triangle clockwise: refused."""
    mesh = build_mesh(PAPER[0])
    rep = mesh.repetition
    nv, n_p = len(rep.template.uv), rep.n_patches
    moved = mesh.points.copy().reshape(n_p, nv, 3)
    moved[:, 6, :2] = moved[:, 0, :2] - [0.05, 0.05]  # the same fold in every patch
    moved = moved.reshape(-1, 3)
    bad = with_points(mesh, moved)
    assert bad.translation_slack <= 1e-12  # still translations of one another
    assert not translated_copies_sound(rep.template, bad.columns, bad.translation_slack)
    want = inverted_or_flat(moved, mesh.triangles)
    assert len(want) >= n_p
    with pytest.raises(MeshInvariantError, match=f"has {len(want):,} of"):
        check_mesh(bad, PAPER[0])


def test_flat_triangles_in_every_copy_are_still_refused():
    mesh = build_mesh(PAPER[0])
    rep = mesh.repetition
    nv, n_p = len(rep.template.uv), rep.n_patches
    a, b, c = rep.template.triangles[0]
    moved = mesh.points.copy().reshape(n_p, nv, 3)
    moved[:, c, :2] = 0.5 * (moved[:, a, :2] + moved[:, b, :2])  # on its opposite side
    moved = moved.reshape(-1, 3)
    bad = with_points(mesh, moved)
    assert not translated_copies_sound(rep.template, bad.columns, bad.translation_slack)
    with pytest.raises(MeshInvariantError, match="clockwise or flat"):
        check_mesh(bad, PAPER[0])


def test_a_triangle_near_the_flat_limit_takes_the_per_triangle_pass():
    """Translations whose first patch is within the margin of the limit are not skipped."""
    mesh = build_mesh(PAPER[0])
    rep = mesh.repetition
    columns = mesh.columns
    slack = mesh.translation_slack
    x, y = (c.copy() for c in columns)
    nv, n_p = len(rep.template.uv), rep.n_patches
    a, b, c = rep.template.triangles[0]
    xs, ys = x.reshape(n_p, nv), y.reshape(n_p, nv)
    # corner c pulled onto line a-b but for a sliver a little above 2 FLAT longest²:
    # the general test passes it, the margin does not
    ux, uy = xs[:, b] - xs[:, a], ys[:, b] - ys[:, a]
    length = np.hypot(ux[0], uy[0])
    lift = 3e-12 * length  # twice area 3e-12 L², limit 2e-12 L² (of L² = |a-b|² here)
    xs[:, c] = xs[:, a] + 0.5 * ux - uy / length * lift
    ys[:, c] = ys[:, a] + 0.5 * uy + ux / length * lift
    assert not translated_copies_sound(rep.template, [x, y], copy_slack(nv, [x, y]))
    assert translated_copies_sound(rep.template, columns, slack)


def test_the_check_skip_declines_what_is_not_translations_or_not_planar():
    mesh = build_mesh(PAPER[0])
    rep = mesh.repetition
    x, y = mesh.columns
    assert not translated_copies_sound(rep.template, [x, y], None)
    assert not translated_copies_sound(rep.template, [x, y, x], mesh.translation_slack)
    stretched = x.copy()
    stretched[len(rep.template.uv) :] *= 1.001  # copies scaled about the origin
    slack = copy_slack(len(rep.template.uv), [stretched, y])
    assert not translated_copies_sound(rep.template, [stretched, y], slack)
    nan = x.copy()
    nan[-1] = np.nan
    assert np.isnan(copy_slack(len(rep.template.uv), [nan, y]))
    assert not translated_copies_sound(rep.template, [nan, y], np.nan)
    assert build_mesh(OTHERS[0]).translation_slack is None  # chains: no such record
    assert copy_slack(len(rep.template.uv), [x[:-1], y[:-1]]) is None  # not whole patches


@pytest.mark.parametrize("params", PAPER, ids=lambda p: f"{p.structure}-{p.subdivisions}")
def test_copy_slack_in_one_block_equals_block_by_block(params, monkeypatch):
    """The one-block path (all columns in one array) gives the block loop's bound bit for bit,
    NaN for a NaN or an infinity, and at least 2 ε extent (what the check skip relies on)."""
    import barymesh.repeat.copies as copies

    mesh = build_mesh(params)
    nv = len(mesh.repetition.template.uv)
    x, y = mesh.columns
    moved = x.copy()
    moved[3 * nv + 2] += 1e-9  # copies no longer exact translations
    z = np.linspace(-1.0, 2.0, len(x))
    cases = [[x, y], [moved, y], [x, y, z]]
    for bad in (np.nan, np.inf, -np.inf):
        broken = y.copy()
        broken[-5] = bad
        cases.append([x, broken])
    whole = [copy_slack(nv, c) for c in cases]
    monkeypatch.setattr(copies, "BLOCK", 7 * nv)  # blocks of 7 patches
    blocks = [copy_slack(nv, c) for c in cases]
    for got, want in zip(whole, blocks, strict=True):
        assert np.isnan(want) == np.isnan(got)
        assert np.isnan(want) or got == want
    for columns, slack in zip(cases[:3], whole[:3], strict=True):
        extent = max(float(np.abs(c).max()) for c in columns)
        assert slack >= 2.0 * np.finfo(np.float64).eps * extent


def test_stats_share_the_checks_slack():
    mesh = build_mesh(PAPER[0])
    assert "translation_slack" in mesh.__dict__  # found by the check, kept
    fresh = with_points(mesh, mesh.points)
    assert fresh.stats() == mesh.stats()


def test_a_record_of_copies_rebuilt_from_triangles_takes_the_same_paths():
    mesh = build_mesh(PAPER[1])
    rep = Repetition.of_triangles(mesh.repetition.template, mesh.triangles, mesh.n_vertices)
    assert rep.kind == "copies"
    assert np.array_equal(rep.vertex_map, mesh.repetition.vertex_map)


@pytest.mark.parametrize("copies", [1, 7, 300, 5000])
@pytest.mark.parametrize("k", [1, 3, 40, 112])
@pytest.mark.parametrize(("step", "base", "none"), [(25, 2, True), (25, 0, False), (0, 5, True)])
def test_fill_tiled_equals_the_plain_broadcast_on_both_sides_of_a_block(
    copies, k, step, base, none
):
    from barymesh.repeat.copies import fill_tiled
    from barymesh.topology import INDEX

    a = np.arange(k, dtype=INDEX) * 3
    if none:
        a[::4] = -1  # "none" entries stay -1
    want = a[None, :] + (np.arange(copies, dtype=INDEX) * INDEX(step) + INDEX(base))[:, None]
    want[:, a < 0] = -1
    out = np.full(copies * k + 3, 99, dtype=INDEX)
    fill_tiled(out, a, copies, INDEX(step), INDEX(base))  # numpy scalars, as chains pass
    assert np.array_equal(out[: copies * k], want.ravel())
    assert (out[copies * k :] == 99).all()  # nothing written past the copies


def test_template_topology_and_adjacency_are_kept_read_only():
    from barymesh.repeat.copies import template_adjacency, template_topology
    from barymesh.topology import adjacency_without_junctions

    template = build_mesh(PAPER[0]).repetition.template
    topo = template_topology(template)
    assert template_topology(template) is topo and not topo.edges.flags.writeable
    local = template_adjacency(template)
    assert template_adjacency(template) is local and not local.indices.flags.writeable
    want = adjacency_without_junctions(len(template.triangles), topo)
    for name in ("data", "indices", "indptr"):
        assert np.array_equal(getattr(local, name), getattr(want, name))


@pytest.mark.parametrize("params", PAPER, ids=lambda p: f"{p.structure}-n{p.subdivisions}")
def test_unwelded_layouts_write_the_points_and_columns_the_general_assembly_makes(params):
    from barymesh.placement import paper_origins
    from barymesh.structures import _rect_layout, layout

    lay = layout(params)
    if not lay.template.lattice:  # welded from the points: the layout keeps no points
        assert lay.points is None and lay.columns is None
        return
    assert lay.points is not None and lay.columns is not None
    origins = paper_origins(params)[0]
    sizes = np.broadcast_to([params.patch_size, params.patch_height], origins.shape)
    rects = np.concatenate([origins, sizes], axis=1)
    # the interleaved layout of welded structures, and the points assembled from it
    xy = _rect_layout(lay.template, rects)
    assert np.array_equal(lay.xy, xy) and not lay.xy.flags.writeable
    points = np.zeros((xy.shape[0] * xy.shape[1], 3))
    points[:, :2] = xy.reshape(-1, 2)
    mesh = build_mesh(params)
    assert mesh.points.tobytes() == points.tobytes()
    # the columns the build handed over are the ones the mesh would have made
    assert len(mesh.columns) == 2
    for axis, column in enumerate(mesh.columns):
        assert column.tobytes() == np.ascontiguousarray(points[:, axis]).tobytes()
    assert len(plain(mesh).columns) == 2


@pytest.mark.parametrize("params", PAPER, ids=lambda p: f"{p.structure}-n{p.subdivisions}")
def test_the_triangles_of_copies_are_the_templates_on_the_vertex_map(params):
    from barymesh.repeat import patch_triangles

    mesh = build_mesh(params)
    rep = mesh.repetition
    assert np.array_equal(mesh.triangles, patch_triangles(rep.template, rep.vertex_map))


@pytest.mark.parametrize("params", PAPER, ids=lambda p: f"{p.structure}-n{p.subdivisions}")
def test_the_record_of_an_unwelded_layout_is_the_one_of_finds(params):
    mesh = build_mesh(params)
    rep = mesh.repetition
    found = Repetition.of(rep.template, rep.vertex_map, mesh.n_vertices)
    assert found.kind == rep.kind == "copies"
    assert same_map(found.vertex_map, rep.vertex_map) and not rep.vertex_map.flags.writeable


def same_map(a, b):
    return a.dtype == b.dtype and a.shape == b.shape and np.array_equal(a, b)


@pytest.mark.parametrize("params", PAPER, ids=lambda p: f"{p.structure}-n{p.subdivisions}")
def test_a_templates_plan_writes_what_the_tiled_copies_write(params):
    # the plan's broadcast adds (views of one buffer per width) against one tiled array each
    from barymesh.repeat.copies import copies_rwg, copies_topology, copies_triangles, template_plan

    mesh = build_mesh(params)
    template, n_p = mesh.repetition.template, mesh.n_patches
    plan, local = template_plan(template), template_topology(template)
    assert template_plan(template) is plan and not plan.interior.flags.writeable
    nv, nt = len(template.uv), len(template.triangles)
    pairs = [
        (copies_topology(local, n_p, nv, nt, plan), copies_topology(local, n_p, nv, nt)),
        (
            copies_rwg(local, n_p, nv, nt, mesh.points, mesh.columns, plan),
            copies_rwg(local, n_p, nv, nt, mesh.points, mesh.columns),
        ),
    ]
    got = [copies_triangles(template, n_p)]
    want = [tiled(template.triangles, n_p, nv)]
    for planned, plain_ in pairs:
        got += [getattr(planned, f.name) for f in dataclasses.fields(planned)]
        want += [getattr(plain_, f.name) for f in dataclasses.fields(plain_)]
    for a, b in zip(got, want, strict=True):
        assert a.dtype == b.dtype and a.shape == b.shape and a.flags.c_contiguous
        assert np.array_equal(a, b)


@pytest.mark.parametrize("structure", ["ring", "double_ring", "split_double_ring"])
@pytest.mark.parametrize("angle_step", [0.7, 2.5, 13.3])
def test_paper_origins_are_each_rings_own_origins_bit_for_bit(structure, angle_step):
    # paper_origins finds the angles once for all rings; the counting path places each ring
    from barymesh.placement import _touching_slots, paper_origins, paper_ring_origins
    from barymesh.sectors import gap_directions, ring_radii

    params = MeshParams(
        structure=structure, mode="paper", angle_step=angle_step, origin=(0.3, -1.7)
    )
    parts = [paper_ring_origins(params, r) for r in ring_radii(params)]
    want = np.concatenate(parts)
    regions = np.concatenate([np.full(len(o), i) for i, o in enumerate(parts, start=1)])
    if gap_directions(params):
        keep = ~_touching_slots(params, want)
        want, regions = want[keep], regions[keep]
    got, got_regions = paper_origins(params)
    assert np.array_equal(got.view(np.int64), want.view(np.int64))
    assert got_regions.dtype == regions.dtype and np.array_equal(got_regions, regions)
