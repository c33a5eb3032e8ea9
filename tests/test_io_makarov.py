"""The makarov-plate presets exported as .mat hold exactly the triangles of Makarov's files."""

from pathlib import Path

import numpy as np
import pytest
import scipy.io

from barymesh import build_mesh
from barymesh.io import read_mesh, write_mesh
from barymesh.presets import load_preset

REFERENCE = Path(__file__).resolve().parent / "data" / "makarov"


def triangle_set(p, t):
    """Triangles of a Makarov p (3 x N), t (3+ x M, 1-based) as sets of rounded coordinates."""
    coords = np.round(np.asarray(p, dtype=np.float64).T, 9) + 0.0
    corners = coords[np.asarray(t[:3], dtype=np.int64).T - 1]
    return {frozenset(map(tuple, tri)) for tri in corners.tolist()}


@pytest.mark.parametrize(
    ("preset", "reference", "nodes", "triangles"),
    [("makarov-plate", "plate.mat", 81, 128), ("makarov-platefine", "platefine.mat", 289, 512)],
)
def test_preset_matches_reference(tmp_path, preset, reference, nodes, triangles):
    ref_file = REFERENCE / reference
    ref = scipy.io.loadmat(ref_file)
    mesh = build_mesh(load_preset(preset)[0])
    ours = scipy.io.loadmat(write_mesh(mesh, tmp_path / f"{preset}.mat"))

    assert ours["p"].shape == ref["p"].shape == (3, nodes)
    assert ours["t"].shape == ref["t"].shape == (4, triangles)
    assert np.all(ours["t"][3] == 1) and np.all(ref["t"][3] == 1)
    expected = triangle_set(ref["p"], ref["t"])
    assert len(expected) == triangles
    assert triangle_set(ours["p"], ours["t"]) == expected


@pytest.mark.parametrize(
    ("reference", "interior", "boundary"), [("plate.mat", 176, 32), ("platefine.mat", 736, 64)]
)
def test_import_reference(reference, interior, boundary):
    ref_file = REFERENCE / reference
    stats = read_mesh(ref_file).stats()
    assert stats["interior_edges"] == interior
    assert stats["boundary_edges"] == boundary
    assert stats["area"] == pytest.approx(1e6)  # 1 m² in mm²
