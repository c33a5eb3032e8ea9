"""Our square-patch subdivision reproduces Makarov's plate meshes exactly.

Reference: tests/data/makarov/, copied from the shared reference folder (see its README)
(plate.mat: n = 8, platefine.mat: n = 16;
a 1 m square centred on the origin, diagonal AD). Compared as sets of triangles,
each a set of vertex coordinates rounded to 1e-9 m.
"""

from pathlib import Path

import numpy as np
import pytest
import scipy.io

from barymesh import MeshParams, build_mesh

REFERENCE = Path(__file__).resolve().parent / "data" / "makarov"


def triangle_set(points_m, triangles):
    key = np.round(points_m[:, :2] * 1e9).astype(np.int64)
    return {frozenset(map(tuple, key[t].tolist())) for t in triangles}


@pytest.mark.parametrize(
    ("name", "n", "nodes", "tris", "interior", "boundary"),
    [("plate", 8, 81, 128, 176, 32), ("platefine", 16, 289, 512, 736, 64)],
)
def test_same_triangles_as_makarov(name, n, nodes, tris, interior, boundary):
    path = REFERENCE / f"{name}.mat"
    assert path.exists(), f"reference mesh {path} is missing from the checkout"
    ref = scipy.io.loadmat(path)
    p_ref, t_ref = ref["p"].T, ref["t"][:3].T.astype(np.int64) - 1
    mesh = build_mesh(
        MeshParams(
            structure="patch",
            patch_size=1000.0,
            origin=(-500.0, -500.0),
            diagonal="AD",
            subdivisions=n,
        )
    )
    s = mesh.stats()
    assert (s["vertices"], s["triangles"], s["interior_edges"], s["boundary_edges"]) == (
        nodes,
        tris,
        interior,
        boundary,
    )
    assert triangle_set(mesh.points / 1000.0, mesh.triangles) == triangle_set(p_ref, t_ref)
