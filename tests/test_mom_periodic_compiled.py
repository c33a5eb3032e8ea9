"""The compiled periodic fill (barymesh.mom.compiled_periodic_fill, numba) against numpy's.

The reference is :mod:`barymesh.mom.periodic_fill`'s own assembly run in double precision
(``backend="numpy", double=True``) on the same per-frequency tables: by default it
computes the Taylor expansion, the Floquet phases and the RWG products in single
precision (about 1e-7 of the entries), the compiled loops in double. The two agree to
1e-12 of the largest entry of Z in vacuum and on a lossy grounded stack (complex k_A,
k_Φ: the decay and the separate charge tables), at normal and oblique incidence (the
images' Floquet phases and the unknowns across the cell's sides), and on a mesh whose
triangles differ in size. ``backend`` and ``BARYMESH_FILL`` pick the path.
"""

from __future__ import annotations

import numpy as np
import pytest

from barymesh.cell import Lattice, PixelGrid, UnitCell, build_cell
from barymesh.mom import Layer, PlaneWave, Stack
from barymesh.mom import periodic_fill as periodic_fill_module
from barymesh.mom.operator import wavenumber
from barymesh.mom.periodic import periodic_geometry, periodic_impedance_matrix

pytest.importorskip("numba")

#: Largest |Z_compiled − Z_numpy| allowed, relative to max |Z|.
TOLERANCE = 1e-12
P = 10.0  # mm


def _cell(mask: np.ndarray, subdivisions: int):
    grid = PixelGrid(
        mask, pixel_size=P / len(mask), origin=(-P / 2, -P / 2), subdivisions=subdivisions
    )
    cell = UnitCell(lattice=Lattice.rectangular(P), pixels=grid, mode="conforming")
    return build_cell(cell).mesh


@pytest.fixture(scope="module")
def patch():
    """A 4 × 4-pixel patch in an 8 × 8 grid: 32 triangles, 40 unknowns."""
    mask = np.zeros((8, 8), dtype=bool)
    mask[2:6, 2:6] = True
    return periodic_geometry(_cell(mask, 1))


@pytest.fixture(scope="module")
def touching():
    """Metal across the cell's sides (unknowns whose T− lies in the next cell), an L shape."""
    mask = np.zeros((8, 8), dtype=bool)
    mask[:, 2] = True
    mask[5, :] = True
    return periodic_geometry(_cell(mask, 1))


def _kt(frequency: float, theta: float, phi: float) -> np.ndarray:
    k = wavenumber(frequency)
    d = PlaneWave.from_angles(theta, phi, 0).direction
    return np.array([k * d[0], k * d[1]])


def _difference(pg, frequency: float, kt: np.ndarray, stack: Stack | None = None) -> float:
    k = wavenumber(frequency)
    compiled = periodic_impedance_matrix(pg, k, kt, stack, backend="numba")
    reference = periodic_impedance_matrix(pg, k, kt, stack, backend="numpy", double=True)
    return float(np.abs(compiled - reference).max() / np.abs(reference).max())


@pytest.mark.parametrize("theta, phi", [(0, 0), (35, 20)])
def test_vacuum_matches_numpy(patch, theta, phi):
    assert _difference(patch, 20e9, _kt(20e9, theta, phi)) <= TOLERANCE


def test_unknowns_across_the_sides_at_oblique_incidence(touching):
    assert len(touching.plan.crossing_rows)  # the case under test
    assert _difference(touching, 24e9, _kt(24e9, 40, 60)) <= TOLERANCE


def test_lossy_grounded_stack_matches_numpy(touching):
    stack = Stack(below=(Layer(1.0, 3.0, 0.02),), ground=True)
    assert _difference(touching, 18e9, _kt(18e9, 30, 45), stack) <= TOLERANCE


def test_graded_mesh_matches_numpy():
    """Pixels subdivided twice: triangles of several sizes, more near and close pairs."""
    mask = np.zeros((8, 8), dtype=bool)
    mask[2:6, 3:5] = True
    pg = periodic_geometry(_cell(mask, 2))
    assert _difference(pg, 22e9, _kt(22e9, 20, 0)) <= TOLERANCE


def test_default_numpy_path_is_the_single_precision_one(patch):
    """Without ``double`` the numpy path stays within single precision of the compiled one."""
    k, kt = wavenumber(20e9), _kt(20e9, 20, 0)
    compiled = periodic_impedance_matrix(patch, k, kt, backend="numba")
    single = periodic_impedance_matrix(patch, k, kt, backend="numpy")
    difference = np.abs(compiled - single).max() / np.abs(compiled).max()
    assert 1e-12 < difference < 1e-5


def test_selector_picks_the_path(patch, monkeypatch):
    """``backend`` first, then BARYMESH_FILL; a wrong name is named in the error."""
    calls = []
    real = periodic_fill_module.compiled_periodic_matrix

    def spy(*args, **kwargs):
        calls.append(1)
        return real(*args, **kwargs)

    monkeypatch.setattr(periodic_fill_module, "compiled_periodic_matrix", spy)
    k = wavenumber(20e9)
    monkeypatch.setenv("BARYMESH_FILL", "numpy")
    periodic_impedance_matrix(patch, k)
    assert calls == []
    periodic_impedance_matrix(patch, k, backend="numba")
    assert calls == [1]
    monkeypatch.setenv("BARYMESH_FILL", "numba")
    periodic_impedance_matrix(patch, k)
    assert calls == [1, 1]
    periodic_impedance_matrix(patch, k, backend="numpy")
    assert calls == [1, 1]
    with pytest.raises(ValueError, match="backend='fortran'"):
        periodic_impedance_matrix(patch, k, backend="fortran")


@pytest.mark.parametrize("loss", [0.0, 0.04])
@pytest.mark.parametrize("charge_only", [False, True])
def test_close_pairs_compiled_match_the_double_einsum(touching, loss, charge_only):
    """The near and close pairs' moments of the compiled loop (written in the plan's order)
    equal numpy's einsum in double precision, in vacuum and in a lossy medium, the six
    moments or the charge's alone; the single-precision ones are within float32 of them."""
    special = periodic_fill_module.special_moments
    k = wavenumber(24e9) * complex(1.7, -loss)
    compiled = special(touching, k, charge_only, compiled=True)
    reference = special(touching, k, charge_only, double=True)
    single = special(touching, k, charge_only)
    assert compiled.dtype == reference.dtype == np.float64 and single.dtype == np.float32
    shape = (1 if charge_only else 6, 2, len(touching.plan.special))
    assert compiled.shape == reference.shape == single.shape == shape
    size = np.abs(reference).max()
    assert np.abs(compiled - reference).max() <= 1e-14 * size
    assert 1e-10 * size < np.abs(single - reference).max() <= 1e-6 * size
