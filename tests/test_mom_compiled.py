"""The compiled fill (barymesh.mom.compiled_fill, numba) against the numpy fill, its reference.

The reference is the numpy path's own formulas with its far kernel in double precision
(``impedance_matrix(..., backend="numpy", double=True)``): the numpy path by default
takes the far kernel's cosine and sine in single precision (about 1e-7 of |G|), the
compiled one in double. The two agree to 1e-12 of the largest entry of Z on Makarov's
plates, a split ring, a curved closed surface, a junction of three sheets, and at a
frequency where k R reaches ~90 rad (the phase reduction of the compiled sine and
cosine). The numpy path stays selectable, and it is what runs when numba cannot be
imported.
"""

from __future__ import annotations

import os
import subprocess
import sys

import numpy as np
import pytest

from barymesh import build_mesh
from barymesh.mesh import TriMesh
from barymesh.mom import compiled_fill, mom_geometry, wavenumber
from barymesh.mom.operator import impedance_matrix
from barymesh.presets import load_preset, resolve_params

pytest.importorskip("numba")

#: Largest |Z_compiled − Z_numpy| allowed, relative to max |Z|.
TOLERANCE = 1e-12


def y_junction(n: int = 4, size: float = 10.0) -> TriMesh:
    """Three strips (mm) meeting on the z axis at 120°: each axis edge carries 3 triangles."""
    axis = [(0.0, 0.0, size * j) for j in range(n + 1)]
    points = list(axis)
    triangles = []
    for wing in range(3):
        angle = 2 * np.pi * wing / 3
        d = np.array([np.cos(angle), np.sin(angle), 0.0])
        columns = [list(range(n + 1))]
        for c in (1, 2):
            columns.append(list(range(len(points), len(points) + n + 1)))
            points += [tuple(d * size * c + (0.0, 0.0, size * j)) for j in range(n + 1)]
        for c in range(2):
            for j in range(n):
                a, b = columns[c][j], columns[c + 1][j]
                e, f = columns[c + 1][j + 1], columns[c][j + 1]
                triangles += [(a, b, e), (a, e, f)]
    tri = np.array(triangles)
    zeros = np.zeros(len(tri), dtype=int)
    return TriMesh(np.array(points), tri, zeros, zeros + 1, 1, mode="imported")


def _difference(mesh: TriMesh, frequency: float) -> float:
    geom = mom_geometry(mesh)
    k = wavenumber(frequency)
    compiled = impedance_matrix(geom, k, backend="numba")
    reference = impedance_matrix(geom, k, backend="numpy", double=True)
    return float(np.abs(compiled - reference).max() / np.abs(reference).max())


@pytest.mark.parametrize(
    "preset, frequency",
    [
        ("makarov-plate", 300e6),
        ("makarov-platefine", 300e6),
        ("makarov-plate", 3e9),  # the 1 m plate at 10 λ: k R up to 89 rad
        ("srr-openmodes", 6.19e9),
    ],
)
def test_compiled_fill_matches_the_numpy_fill(preset, frequency):
    mesh = build_mesh(load_preset(preset)[0])
    assert _difference(mesh, frequency) < TOLERANCE


def test_compiled_fill_matches_on_a_curved_closed_surface():
    trimesh = pytest.importorskip("trimesh")
    s = trimesh.creation.icosphere(subdivisions=2, radius=1.0)
    zeros = np.zeros(len(s.faces), dtype=int)
    mesh = TriMesh(s.vertices, s.faces, zeros, zeros + 1, 1, mode="imported")
    assert np.ptp(mesh.points, axis=0).min() > 0  # x, y and z all active
    assert _difference(mesh, 48e9) < TOLERANCE  # k a = 1


def test_compiled_fill_matches_on_a_junction():
    # three sheets on one line (the junction edges carry no unknown; the sheets are
    # coupled through the kernel only), in three dimensions
    mesh = y_junction()
    assert len(mesh.junction_edges) == 4
    assert np.ptp(mesh.points, axis=0).min() > 0
    assert _difference(mesh, 3e9) < TOLERANCE


def test_compiled_fill_spans_several_blocks(monkeypatch):
    # the plate at n = 22 (968 triangles) in blocks of 50: pairs inside a block, across
    # blocks and mirrored ones all occur, and the ragged last block
    monkeypatch.setattr(compiled_fill, "BLOCK_BYTES", 128 * 968 * 50)
    mesh = build_mesh(resolve_params("makarov-platefine", None, ["subdivisions=22"]))
    assert compiled_fill.block_size(968) == 50
    assert _difference(mesh, 300e6) < TOLERANCE


def test_compiled_matrix_is_symmetric_but_for_the_self_pairs():
    # Z + Zᵀ builds the matrix; the self pairs' rule-versus-closed-form difference is
    # given back, as the numpy fill keeps it: the asymmetry is that of the numpy fill
    mesh = build_mesh(load_preset("makarov-plate")[0])
    geom = mom_geometry(mesh)
    k = wavenumber(300e6)
    z = impedance_matrix(geom, k, backend="numba")
    ref = impedance_matrix(geom, k, backend="numpy", double=True)
    scale = np.abs(ref).max()
    asymmetry = np.abs(z - z.T).max() / scale
    assert 1e-9 < asymmetry < 1e-5
    assert np.abs((z - z.T) - (ref - ref.T)).max() / scale < TOLERANCE


def test_compiled_sine_and_cosine_agree_with_numpy():
    kernels = compiled_fill.kernels()
    x = np.concatenate([np.linspace(0.0, 10.0, 100_001), np.geomspace(10.0, 1e4, 100_000)])
    s, c = kernels.sincos_array(x)
    assert np.abs(s - np.sin(x)).max() < 1e-15
    assert np.abs(c - np.cos(x)).max() < 1e-15


def test_one_compilation_serves_the_warm_up_and_the_fills():
    # warm_up's tiny arrays have the types of a real fill's: no second compilation
    compiled_fill.warm_up()
    mesh = build_mesh(load_preset("makarov-plate")[0])
    impedance_matrix(mom_geometry(mesh), wavenumber(300e6), backend="numba")
    kernels = compiled_fill.kernels()
    for kernel in (kernels.far_block, kernels.assemble_block, kernels.symmetrize):
        assert len(kernel.signatures) == 1, kernel


def test_backend_is_chosen_by_argument_variable_and_availability(monkeypatch):
    monkeypatch.delenv(compiled_fill.BACKEND_VARIABLE, raising=False)
    assert compiled_fill.resolve_backend(None) == "numba"
    assert compiled_fill.resolve_backend("numpy") == "numpy"
    monkeypatch.setenv(compiled_fill.BACKEND_VARIABLE, "numpy")
    assert compiled_fill.resolve_backend(None) == "numpy"
    assert compiled_fill.resolve_backend("numba") == "numba"  # the argument wins
    monkeypatch.setenv(compiled_fill.BACKEND_VARIABLE, "fortran")
    with pytest.raises(ValueError, match="BARYMESH_FILL='fortran'"):
        compiled_fill.resolve_backend(None)
    with pytest.raises(ValueError, match="backend='cuda'"):
        compiled_fill.resolve_backend("cuda")
    monkeypatch.delenv(compiled_fill.BACKEND_VARIABLE)
    monkeypatch.setattr(compiled_fill, "numba_available", lambda: False)
    assert compiled_fill.resolve_backend(None) == "numpy"
    with pytest.raises(ValueError, match="not installed"):
        compiled_fill.resolve_backend("numba")


def test_fill_threads_follow_numba_then_omp_num_threads(monkeypatch):
    monkeypatch.delenv("NUMBA_NUM_THREADS", raising=False)
    monkeypatch.delenv("OMP_NUM_THREADS", raising=False)
    assert compiled_fill.fill_threads(8) == 8
    monkeypatch.setenv("OMP_NUM_THREADS", "1")  # a Dask worker's, one thread each
    assert compiled_fill.fill_threads(8) == 1
    monkeypatch.setenv("OMP_NUM_THREADS", "16")
    assert compiled_fill.fill_threads(8) == 8
    monkeypatch.setenv("OMP_NUM_THREADS", "lots")
    assert compiled_fill.fill_threads(8) == 8
    monkeypatch.setenv("OMP_NUM_THREADS", "1")
    monkeypatch.setenv("NUMBA_NUM_THREADS", "8")  # numba's own setting wins
    assert compiled_fill.fill_threads(8) == 8


def test_without_numba_the_numpy_fill_runs():
    # a fresh process in which numba cannot be imported (as if it were not installed)
    code = (
        "import sys\n"
        "sys.modules['numba'] = None\n"
        "import numpy as np\n"
        "from barymesh import build_mesh\n"
        "from barymesh.presets import load_preset\n"
        "from barymesh.mom import mom_geometry, wavenumber\n"
        "from barymesh.mom.compiled_fill import resolve_backend\n"
        "from barymesh.mom.operator import impedance_matrix\n"
        "geom = mom_geometry(build_mesh(load_preset('makarov-plate')[0]))\n"
        "z = impedance_matrix(geom, wavenumber(300e6))\n"
        "ref = impedance_matrix(geom, wavenumber(300e6), backend='numpy')\n"
        "assert resolve_backend(None) == 'numpy'\n"
        "assert np.array_equal(z, ref)\n"
        "assert 'barymesh.mom.fill_kernels' not in sys.modules\n"
        "print('numpy fill', z.shape)\n"
    )
    env = dict(os.environ)
    env.pop(compiled_fill.BACKEND_VARIABLE, None)
    out = subprocess.run(
        [sys.executable, "-c", code], capture_output=True, text=True, env=env, timeout=300
    )
    assert out.returncode == 0, out.stderr
    assert "numpy fill (176, 176)" in out.stdout
