"""The RWG table and connectivity as .npz and CSV."""

import numpy as np
import pytest
import scipy.sparse as sp
from helpers import canonical_meshes

from barymesh.io import write_mesh


@pytest.fixture(scope="module")
def mesh():
    return canonical_meshes()["double-ring"]


@pytest.mark.parametrize(("unit", "scale"), [(None, 1.0), ("m", 1e-3), ("um", 1e3)])
def test_npz(tmp_path, unit, scale, mesh):
    data = np.load(write_mesh(mesh, tmp_path / "rwg.npz", unit=unit))
    rwg = mesh.rwg
    assert str(data["unit"]) == (unit or "mm")
    for key in ("edge", "vertices", "t_plus", "t_minus", "free_vertex_plus", "free_vertex_minus"):
        assert np.array_equal(data[key], getattr(rwg, key)), key
    np.testing.assert_allclose(data["length"], rwg.length * scale)
    np.testing.assert_allclose(data["centroids"], mesh.centroids * scale)
    np.testing.assert_allclose(data["points"], mesh.points * scale)
    np.testing.assert_allclose(data["areas"], mesh.areas * scale**2)
    assert np.array_equal(data["triangles"], mesh.triangles)
    conn = sp.coo_matrix(
        (data["connectivity_data"], (data["connectivity_row"], data["connectivity_col"])),
        shape=tuple(data["connectivity_shape"]),
    )
    assert (conn != mesh.connectivity).nnz == 0
    assert len(data["edge"]) == mesh.stats()["interior_edges"]


def test_csv(tmp_path, mesh):
    write_mesh(mesh, tmp_path / "rwg.csv", unit="m")
    table = np.loadtxt(tmp_path / "rwg.csv", delimiter=",", skiprows=1)
    header = (tmp_path / "rwg.csv").read_text().splitlines()[0]
    assert header == (
        "edge,vertex_1,vertex_2,t_plus,t_minus,free_vertex_plus,free_vertex_minus,length_m"
    )
    rwg = mesh.rwg
    assert table.shape == (len(rwg), 8)
    assert np.array_equal(table[:, 3], rwg.t_plus)
    assert np.array_equal(table[:, 6], rwg.free_vertex_minus)
    np.testing.assert_allclose(table[:, 7], rwg.length * 1e-3, rtol=1e-15)

    triplets = np.loadtxt(tmp_path / "rwg_connectivity.csv", delimiter=",", skiprows=1)
    conn = sp.coo_matrix(
        (triplets[:, 2], (triplets[:, 0].astype(int), triplets[:, 1].astype(int))),
        shape=mesh.connectivity.shape,
    )
    assert (conn != mesh.connectivity).nnz == 0

    cent = np.loadtxt(tmp_path / "rwg_centroids.csv", delimiter=",", skiprows=1)
    np.testing.assert_allclose(cent[:, 1:4], mesh.centroids * 1e-3, rtol=1e-15, atol=1e-18)
    np.testing.assert_allclose(cent[:, 4], mesh.areas * 1e-6)
