"""The compiled loops of the repeated paths give the numpy paths' arrays bit for bit.

:mod:`barymesh.repeat.kernels` runs for meshes of at least
:data:`barymesh.repeat.compiled.MIN_TRIANGLES` triangles; here that limit is lowered so
that small meshes of every repetition kind take them (asked for with
``BARYMESH_MESH_KERNELS=numba``), and each result is compared with the numpy reference (the
default) and with the general paths.
"""

import os
import subprocess
import sys

import numpy as np
import pytest
from helpers import with_points

from barymesh import MeshParams, TriMesh, build_mesh
from barymesh.repeat import compiled, copy_slack, patch_centroids
from barymesh.repeat.copies import copies_lengths, template_topology, tiled
from barymesh.topology import segment_lengths

pytest.importorskip("numba")

MESHES = [
    MeshParams(structure="double_ring", mode="paper", subdivisions=4, angle_step=2.5),
    MeshParams(structure="ring", mode="paper", subdivisions=3, angle_step=7.0, diagonal="AD"),
    MeshParams(structure="double_ring", mode="paper", subdivisions=2, scheme="barycentric"),
    MeshParams(structure="double_ring", mode="conforming", subdivisions=3),
    MeshParams(structure="square_split_double_ring", mode="paper", subdivisions=2),
    MeshParams(structure="cross", mode="conforming", subdivisions=3),
]


@pytest.fixture
def compiled_always(monkeypatch):
    monkeypatch.setattr(compiled, "MIN_TRIANGLES", 0)
    monkeypatch.setenv(compiled.BACKEND_VARIABLE, compiled.COMPILED)
    assert compiled.kernels(1) is not None


def reference(monkeypatch, func):
    """``func()`` on the numpy path."""
    with monkeypatch.context() as m:
        m.setenv(compiled.BACKEND_VARIABLE, "numpy")
        assert compiled.kernels(1 << 30) is None
        return func()


def same_bits(a, b):
    return a.dtype == b.dtype and a.shape == b.shape and a.tobytes() == b.tobytes()


def variants(mesh):
    """The mesh's points, with a z that is not zero, and with a column of negative zeros."""
    with_z = mesh.points.copy()
    with_z[:, 2] = 0.25 * with_z[:, 0] - 1.0
    negative_zero = mesh.points.copy()
    negative_zero[:, 2] = -0.0  # zero everywhere: left out, so +0 in the output
    return [mesh.points, with_z, negative_zero]


@pytest.mark.parametrize("params", MESHES, ids=lambda p: f"{p.structure}-{p.mode}")
def test_compiled_centroids_equal_the_numpy_path(params, compiled_always, monkeypatch):
    mesh = build_mesh(params)
    rep = mesh.repetition
    for points in variants(mesh):
        columns = with_points(mesh, points).columns
        for unwelded in {False, rep.kind == "copies"}:
            got = patch_centroids(columns, rep.vertex_map, rep.template.triangles, unwelded)
            want = reference(
                monkeypatch,
                lambda c=columns, u=unwelded: patch_centroids(
                    c, rep.vertex_map, rep.template.triangles, u
                ),
            )
            assert same_bits(got, want)
        plain = TriMesh(points, mesh.triangles, mesh.patch_ids, mesh.regions, mesh.n_patches)
        assert same_bits(with_points(mesh, points).centroids, plain.centroids)  # the general path


@pytest.mark.parametrize("params", MESHES[:3], ids=lambda p: f"{p.structure}-{p.mode}")
def test_compiled_lengths_equal_the_numpy_path(params, compiled_always, monkeypatch):
    mesh = build_mesh(params)
    rep = mesh.repetition
    nv, n_p = len(rep.template.uv), rep.n_patches
    local = template_topology(rep.template)
    for points in variants(mesh):
        columns = with_points(mesh, points).columns
        for pairs in (local.edges, local.edges[local.valence == 2]):
            got = copies_lengths(pairs, n_p, nv, points, columns)
            want = reference(
                monkeypatch, lambda p=pairs, c=columns, x=points: copies_lengths(p, n_p, nv, x, c)
            )
            assert same_bits(got, want)
            assert same_bits(got, segment_lengths(points, tiled(pairs, n_p, nv)))
        assert same_bits(
            with_points(mesh, points).rwg.length,
            reference(monkeypatch, lambda x=points: with_points(mesh, x).rwg.length),
        )


@pytest.mark.parametrize(
    ("backend", "angle_step", "imported"),
    [
        (None, 0.1152, False),  # the default: numpy at every size
        ("numpy", 0.1152, False),
        ("numba", 0.1152, True),  # asked for: from MIN_TRIANGLES on
        ("numba", 2.5, False),  # below it, never
    ],
)
def test_numba_is_imported_only_when_asked_for_and_the_mesh_is_large(backend, angle_step, imported):
    code = (
        "import sys\n"
        "from barymesh import MeshParams, build_mesh\n"
        "m = build_mesh(MeshParams(structure='double_ring', mode='paper', subdivisions=4, "
        f"angle_step={angle_step}))\n"
        "m.centroids, m.rwg\n"
        "print(m.n_triangles, 'numba' in sys.modules)\n"
    )
    env = {k: v for k, v in os.environ.items() if k != compiled.BACKEND_VARIABLE}
    if backend is not None:
        env[compiled.BACKEND_VARIABLE] = backend
    out = subprocess.run(
        [sys.executable, "-c", code], capture_output=True, text=True, check=True, env=env
    )
    triangles, loaded = out.stdout.split()
    assert (int(triangles) >= compiled.MIN_TRIANGLES) == (angle_step < 1)
    assert loaded == str(imported)


def test_a_large_mesh_equals_the_numpy_path(monkeypatch):
    monkeypatch.setenv(compiled.BACKEND_VARIABLE, compiled.COMPILED)
    params = MeshParams(structure="double_ring", mode="paper", subdivisions=4, angle_step=0.1152)
    mesh = build_mesh(params)
    assert mesh.n_triangles >= compiled.MIN_TRIANGLES
    assert compiled.kernels(mesh.n_triangles) is not None
    again = build_mesh(params)
    assert same_bits(mesh.centroids, reference(monkeypatch, lambda: again.centroids))
    assert same_bits(mesh.rwg.length, reference(monkeypatch, lambda: again.rwg.length))


@pytest.mark.parametrize("params", MESHES[:3], ids=lambda p: f"{p.structure}-{p.mode}")
def test_compiled_copy_slack_equals_the_numpy_path(params, compiled_always, monkeypatch):
    mesh = build_mesh(params)
    nv = len(mesh.repetition.template.uv)
    shifted = mesh.points.copy()
    shifted[nv + 3, 0] += 1e-9  # one copy moved off the translation
    broken = [mesh.points.copy() for _ in range(4)]
    broken[0][5, 1] = np.nan
    broken[1][nv + 2, 0] = np.inf
    broken[2][nv, 0] = -np.inf  # a patch's first vertex
    broken[3][7, 2] = np.nan  # in z
    for points in [*variants(mesh), shifted, *broken]:
        columns = with_points(mesh, points).columns
        got = copy_slack(nv, columns)
        want = reference(monkeypatch, lambda c=columns: copy_slack(nv, c))
        assert got == want or (np.isnan(got) and np.isnan(want)), (got, want)


@pytest.mark.parametrize("bad", [np.nan, np.inf, -np.inf])
def test_copies_with_a_coordinate_that_is_not_finite_are_still_refused(bad, compiled_always):
    from barymesh.check import check_mesh
    from barymesh.invariants import MeshInvariantError

    params = MESHES[0]
    mesh = build_mesh(params)
    for row, axis in ((0, 0), (40, 1), (len(mesh.points) - 1, 0)):
        points = mesh.points.copy()
        points[row, axis] = bad
        with pytest.raises(MeshInvariantError, match="not finite"):
            check_mesh(with_points(mesh, points), params)


@pytest.mark.parametrize("params", MESHES[:3], ids=lambda p: f"{p.structure}-{p.mode}")
def test_compiled_layout_points_equal_the_numpy_path(params, compiled_always, monkeypatch):
    from barymesh.structures import layout

    lay = layout(params)
    want = reference(monkeypatch, lambda: layout(params))
    if want.points is None:  # welded from the points: no points written by the layout
        assert lay.points is None
        return
    assert same_bits(lay.points, want.points) and same_bits(lay.xy, want.xy)
    for got_column, want_column in zip(lay.columns, want.columns, strict=True):
        assert same_bits(got_column, want_column)
    mesh = build_mesh(params)
    assert same_bits(mesh.points, reference(monkeypatch, lambda: build_mesh(params)).points)
