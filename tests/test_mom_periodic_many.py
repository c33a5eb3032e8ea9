"""Several incidences at one frequency: one fill and one LU per transverse wavevector.

- ``periodic_solve_many`` of TE and TM from one direction (and that direction's mirror
  from below, which shares k_t) equals separate ``periodic_solve`` calls to 1e-12, with a
  sheet impedance too (absorption), and across the Wood anomaly's propagating orders.
- It fills the matrix once per distinct k_t (counted by wrapping the fill).
- ``periodic_sweep(polarizations="both")`` fills once per frequency solved, not twice.
- ``dense_solve`` with an (N, K) right-hand side equals K one-column solves, in the
  refined single-precision path and in the double-precision fallback.
- A solve of this size runs on one BLAS thread (a loaded 2-core machine stalls
  threaded products), restored afterwards.
- Bad input is named.
"""

from __future__ import annotations

import numpy as np
import pytest

from barymesh.cell import Lattice, PixelGrid, UnitCell, build_cell
from barymesh.mom import PlaneWave, periodic_solve, periodic_solve_many, periodic_sweep
from barymesh.mom import periodic as periodic_module
from barymesh.mom.periodic_sweep import te_tm_polarizations
from barymesh.mom.solve import dense_solve

P = 10.0  # mm


@pytest.fixture(scope="module")
def ell():
    """An L-shaped patch (no mirror symmetry: TE and TM couple), 8 × 8 pixels."""
    mask = np.zeros((8, 8), dtype=bool)
    mask[1:7, 1:3] = True
    mask[1:3, 1:6] = True
    pixels = PixelGrid(mask, pixel_size=P / 8, origin=(-P / 2, -P / 2), subdivisions=1)
    cell = UnitCell(lattice=Lattice.rectangular(P), pixels=pixels, mode="conforming")
    return build_cell(cell).mesh


def _same(a, b, tol=1e-12):
    assert np.array_equal(a.orders, b.orders)
    scale = max(1.0, float(np.abs(b.reflection).max()))
    assert np.abs(a.reflection - b.reflection).max() <= tol * scale
    assert np.abs(a.transmission - b.transmission).max() <= tol * scale
    c = np.abs(b.coefficients).max()
    assert np.abs(a.coefficients - b.coefficients).max() <= tol * c
    assert a.condition_number == pytest.approx(b.condition_number, rel=1e-6)
    assert a.absorption == pytest.approx(b.absorption, rel=1e-12, abs=1e-15)
    assert a.residual < 1e-12 and b.residual < 1e-12


def _counting(monkeypatch):
    fills = []
    real = periodic_module.periodic_impedance_matrix

    def counted(pg, k, kt=(0.0, 0.0), stack=None):
        fills.append((k, tuple(kt)))
        return real(pg, k, kt, stack)

    monkeypatch.setattr(periodic_module, "periodic_impedance_matrix", counted)
    return fills


@pytest.mark.parametrize(
    ("frequency", "zs"), [(12e9, 0.0), (12e9, 50 - 20j), (25e9, 0.0)]
)  # 25 GHz at 30°: above the (−1, 0) onset (c / (P (1 + sin θ)) = 20 GHz)
def test_many_incidences_equal_separate_solves(ell, frequency, zs, monkeypatch):
    direction = np.asarray(PlaneWave.from_angles(30, 20, 0).direction)
    te, tm = te_tm_polarizations(direction)
    below = direction * (1, 1, -1)  # the mirror from below: the same k_t
    waves = [
        PlaneWave(direction, te),
        PlaneWave(direction, tm),
        PlaneWave(below, te, 2.0),
    ]
    fills = _counting(monkeypatch)
    many = periodic_solve_many(ell, frequency, waves, sheet_impedance=zs)
    assert len(fills) == 1  # one k_t, one fill
    separate = [periodic_solve(ell, frequency, w, sheet_impedance=zs) for w in waves]
    assert len(fills) == 4
    assert len(many) == 3
    for a, b, w in zip(many, separate, waves, strict=True):
        assert a.incidence is w
        _same(a, b)
    if frequency > 20e9:
        assert len(many[0].orders) > 1  # the comparison covers a grating lobe
    if zs:
        assert many[0].absorption > 1e-3


def test_each_distinct_transverse_wavevector_is_filled_once(ell, monkeypatch):
    normal, oblique = PlaneWave(), PlaneWave.from_angles(40, 0, 90)
    fills = _counting(monkeypatch)
    waves = [normal, oblique, PlaneWave(polarization=(0, 1, 0)), oblique]
    many = periodic_solve_many(ell, 9e9, waves)
    assert len(fills) == 2
    assert {kt for _, kt in fills} == {(0.0, 0.0), tuple(fills[1][1])}
    _same(many[1], many[3], tol=0.0)  # the same wave twice
    _same(many[2], periodic_solve(ell, 9e9, waves[2]))


def test_a_sweep_of_both_polarizations_fills_once_per_frequency(ell, monkeypatch):
    fills = _counting(monkeypatch)
    freqs = np.linspace(8e9, 14e9, 4)
    sweep = periodic_sweep(ell, freqs, PlaneWave.from_angles(20, 0, 45), interpolate=False)
    assert sweep.both_polarizations
    assert sweep.n_solves == 4
    assert len(fills) == 4  # was 8: TE and TM each filled the matrix
    # and the coefficients are those of separate solves of the incidence
    one = periodic_solve(ell, freqs[2], PlaneWave.from_angles(20, 0, 45))
    assert np.abs(sweep.reflection[2] - one.reflection[0]).max() < 1e-12


def _matrix(n, cond, seed):
    rng = np.random.default_rng(seed)
    q, _ = np.linalg.qr(rng.standard_normal((n, n)) + 1j * rng.standard_normal((n, n)))
    return (q * np.logspace(0, -np.log10(cond), n)) @ q.T


@pytest.mark.parametrize("cond", [1e3, 1e11])  # refined in single precision; the fallback
def test_dense_solve_of_several_columns_equals_one_column_solves(cond):
    z = _matrix(200, cond, seed=3)
    rng = np.random.default_rng(1)
    v = rng.standard_normal((200, 3)) + 1j * rng.standard_normal((200, 3))
    current, estimate, residual = dense_solve(z, v)
    assert current.shape == (200, 3) and residual.shape == (3,)
    for j in range(3):
        one, one_estimate, one_residual = dense_solve(z, v[:, j])
        assert isinstance(one_residual, float) and one.shape == (200,)
        assert np.abs(current[:, j] - one).max() <= 1e-12 * cond * np.abs(one).max()
        assert estimate == one_estimate
        exact = np.linalg.norm(z @ current[:, j] - v[:, j]) / np.linalg.norm(v[:, j])
        # at cond 1e11 the residual is rounding noise of Z I (gemm and gemv round apart)
        assert residual[j] == pytest.approx(exact, rel=1e-6 if cond < 1e6 else 0.1)


def test_bad_input_is_named(ell):
    with pytest.raises(ValueError, match="incidences is empty"):
        periodic_solve_many(ell, 1e10, [])
    with pytest.raises(TypeError, match=r"incidences\[1\] must be a PlaneWave"):
        periodic_solve_many(ell, 1e10, [PlaneWave(), "x"])
    with pytest.raises(TypeError, match="sequence of PlaneWave"):
        periodic_solve_many(ell, 1e10, PlaneWave())
    with pytest.raises(ValueError, match=r"v has shape \(3, 2, 2\)"):
        dense_solve(np.eye(3, dtype=complex), np.ones((3, 2, 2)))


def test_a_small_solve_runs_on_one_blas_thread(ell, monkeypatch):
    from threadpoolctl import threadpool_info

    seen = []
    real = periodic_module.dense_solve

    def recorded(z, v):
        seen.append([i["num_threads"] for i in threadpool_info() if i["user_api"] == "blas"])
        return real(z, v)

    before = [i["num_threads"] for i in threadpool_info() if i["user_api"] == "blas"]
    monkeypatch.setattr(periodic_module, "dense_solve", recorded)
    periodic_solve(ell, 9e9)
    # restored afterwards
    assert [i["num_threads"] for i in threadpool_info() if i["user_api"] == "blas"] == before
    assert seen and all(n == 1 for n in seen[0])
