"""Every column of the CSV RWG table holds the mesh's own array (found missing by mutation)."""

import numpy as np
import pytest

from barymesh import MeshParams, build_mesh
from barymesh.io import write_mesh

COLUMNS = (
    "edge",
    "vertex_1",
    "vertex_2",
    "t_plus",
    "t_minus",
    "free_vertex_plus",
    "free_vertex_minus",
)


@pytest.mark.parametrize("unit", ["mm", "um"])
def test_every_rwg_csv_column(tmp_path, unit):
    mesh = build_mesh(MeshParams(structure="split_ring", mode="conforming", angle_step=30))
    path = write_mesh(mesh, tmp_path / "table.csv", unit=unit)
    header = path.read_text().splitlines()[0].split(",")
    assert header == [*COLUMNS, f"length_{unit}"]
    table = np.loadtxt(path, delimiter=",", skiprows=1)
    rwg = mesh.rwg
    expect = [
        rwg.edge,
        rwg.vertices[:, 0],
        rwg.vertices[:, 1],
        rwg.t_plus,
        rwg.t_minus,
        rwg.free_vertex_plus,
        rwg.free_vertex_minus,
    ]
    for k, name in enumerate(COLUMNS):
        assert np.array_equal(table[:, k], expect[k]), name
    # vertex_1 < vertex_2: the edge's vertices in the mesh's edge order
    assert (table[:, 1] < table[:, 2]).all()
    scale = {"mm": 1.0, "um": 1e3}[unit]
    np.testing.assert_allclose(table[:, 7], rwg.length * scale, rtol=1e-15)
