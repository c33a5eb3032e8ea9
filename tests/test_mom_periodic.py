"""The infinite-array solver against an exact result and the identities of physics.

- Collin's strip grating (Field Theory of Guided Waves, problem 10.6; the check PSSFSS
  runs): PEC strips of width P/2 at normal incidence, exact |Γ| and ∠Γ. The strips touch
  the cell's sides, so the unknowns across the cell boundary carry the current.
- Power balance Σ (|R|² + |T|²) β/β₀₀ = 1 (lossless screens), below and above the first
  grating lobe; T = 1 + R for the co-polar (0, 0) order; reciprocity Z(k_t)ᵀ = Z(−k_t);
  invariance when the element moves inside the cell; the solution converges under
  refinement.
"""

from __future__ import annotations

import importlib
import math
import tracemalloc

import numpy as np
import pytest

from barymesh import MeshParams, build_mesh
from barymesh.cell import Lattice, PixelGrid, UnitCell, build_cell
from barymesh.constants import ETA0, SPEED_OF_LIGHT
from barymesh.mom import PlaneWave, ProblemTooLarge, periodic_sweep
from barymesh.mom.operator import wavenumber
from barymesh.mom.periodic import (
    periodic_geometry,
    periodic_impedance_matrix,
    periodic_memory_needed,
    periodic_solve,
)

geometry_module = importlib.import_module("barymesh.mom.periodic_geometry")  # beside the function

P = 10.0  # mm
#: Collin's exact values: P/λ -> (|Γ⊥|, ∠Γ⊥ in degrees, |Γ∥|), E across / along the strips.
COLLIN = {
    0.1: (0.0694, -94.0, 0.9976),
    0.3: (0.2106, -102.2, 0.9776),
    0.5: (0.3598, -111.1, 0.9330),
    0.8: (0.6231, -128.5, 0.7822),
    0.9: (0.7381, -137.6, 0.6747),
}


def pixel_cell(mask: np.ndarray, subdivisions: int = 2, shift=(0.0, 0.0)):
    """The conforming mesh of a square cell of side P holding ``mask``'s pixels."""
    pixels = PixelGrid(
        mask,
        pixel_size=P / len(mask),
        origin=(-P / 2 + shift[0], -P / 2 + shift[1]),
        subdivisions=subdivisions,
    )
    return build_cell(
        UnitCell(lattice=Lattice.rectangular(P), pixels=pixels, mode="conforming")
    ).mesh


def strips(pixels: int, subdivisions: int):
    mask = np.zeros((pixels, pixels), dtype=bool)
    mask[:, pixels // 4 : 3 * pixels // 4] = True  # along y, width P/2, touching both sides
    return pixel_cell(mask, subdivisions)


@pytest.fixture(scope="module")
def fine_strips():
    return strips(16, 2)  # 1,024 triangles


def frequency(p_over_lambda: float) -> float:
    return p_over_lambda * SPEED_OF_LIGHT / (P * 1e-3)


@pytest.mark.parametrize("p_over_lambda", sorted(COLLIN))
def test_strip_grating_matches_collin_across_the_strips(fine_strips, p_over_lambda):
    magnitude, phase, _ = COLLIN[p_over_lambda]
    s = periodic_solve(fine_strips, frequency(p_over_lambda), PlaneWave(polarization=(1, 0, 0)))
    r, t = s.co_polar()
    assert abs(abs(r) - magnitude) < 0.01
    assert abs(np.degrees(np.angle(r)) - phase) < 2.0
    assert abs(s.power_balance - 1) < 1e-3
    assert abs(t - (1 + r)) < 1e-3
    assert s.geometry.n_crossing == 16  # the strip end's 16 edges, each paired across the cell


@pytest.mark.parametrize("p_over_lambda", [0.1, 0.3, 0.5])
def test_strip_grating_matches_collin_along_the_strips(fine_strips, p_over_lambda):
    _, _, magnitude = COLLIN[p_over_lambda]
    s = periodic_solve(fine_strips, frequency(p_over_lambda), PlaneWave(polarization=(0, 1, 0)))
    r, _ = s.co_polar()
    assert abs(abs(r) - magnitude) < 0.01
    assert abs(s.power_balance - 1) < 1e-3


@pytest.mark.parametrize("p_over_lambda", [0.8, 0.9])
def test_strip_grating_along_the_strips_converges_to_collin(fine_strips, p_over_lambda):
    # near the grating lobe the current's edge singularity makes uniform meshes converge
    # at first order: the error halves from 256 to 1,024 triangles (not yet within 0.01)
    _, _, magnitude = COLLIN[p_over_lambda]
    wave = PlaneWave(polarization=(0, 1, 0))
    coarse = abs(
        abs(periodic_solve(strips(8, 2), frequency(p_over_lambda), wave).co_polar()[0]) - magnitude
    )
    fine = abs(
        abs(periodic_solve(fine_strips, frequency(p_over_lambda), wave).co_polar()[0]) - magnitude
    )
    assert fine < 0.6 * coarse
    assert fine < 0.02


def patch_cell(shift=(0.0, 0.0)):
    mask = np.zeros((8, 8), dtype=bool)
    mask[2:6, 2:6] = True
    return pixel_cell(mask, 2, shift)


@pytest.mark.parametrize(
    "wave",
    [
        PlaneWave(),
        PlaneWave.from_angles(30, 0, 0),
        PlaneWave.from_angles(30, 0, 90),
        PlaneWave.from_angles(45, 30, 20),
    ],
)
def test_power_balance_and_t_equals_one_plus_r(wave):
    s = periodic_solve(patch_cell(), 17e9, wave)  # below every grating lobe up to 45°
    assert len(s.orders) == 1
    assert abs(s.power_balance - 1) < 1e-3
    r, t = s.co_polar()
    assert abs(t - (1 + r)) < 1e-9
    assert 0.05 < abs(r) < 0.95  # a real scatterer, not a trivial answer


def test_power_balance_with_grating_lobes():
    # P = 1.5 λ at 30° incidence: several Floquet orders propagate, power goes into all
    s = periodic_solve(patch_cell(), frequency(1.5), PlaneWave.from_angles(30, 0, 0))
    assert len(s.orders) > 5
    reflected, transmitted = s.power_fractions
    assert reflected[1:].sum() + transmitted[1:].sum() > 0.01
    assert abs(s.power_balance - 1) < 1e-3


def test_power_balance_just_above_an_onset():
    # 0.15 % above the (0, ±1) onset at 30° (two orders have just started to propagate,
    # nearly grazing): their terms c e^(−jκ·ρ), c ~ 1/β, are integrated exactly, not by
    # the Taylor expansion of G_reg (measured 7.1e-6; expanded with the rest: 1.3e-4)
    from barymesh.mom import grating_lobe_onsets

    wave = PlaneWave.from_angles(30, 0, 90)
    mesh = patch_cell()
    onset = grating_lobe_onsets(mesh.lattice, wave, 40e9)[1]
    s = periodic_solve(mesh, onset * (1 + 1.5e-3), wave)
    assert len(s.orders) == 4
    assert abs(s.power_balance - 1) < 3e-5


@pytest.mark.parametrize("side", [math.sqrt(0.75), math.sqrt(1.25), math.sqrt(1.75), math.sqrt(3)])
def test_the_solution_is_continuous_where_an_order_starts_being_taken_out(side):
    # At normal incidence the order (p, q) has |γ| = b sqrt|p² + q² − (k/b)²|: it equals
    # the limit L = b/2 at k/b = sqrt(0.75), sqrt(1.25) ((1, 0), evanescent, propagating)
    # and sqrt(1.75) ((1, 1)), and 2L at sqrt(3) ((2, 0) and (1, 1)). A hard switch at L
    # made R jump by 1e-5-1e-4 there (a sweep's rational fit then needs a sample at every
    # grid point nearby);
    # the blend from L to 2L keeps R continuous: steps of 1e-7 relative change it by
    # about 1e-7 (|dR/df| f ~ 1)
    mesh = patch_cell()
    f0 = side * SPEED_OF_LIGHT / (P * 1e-3)
    below, above = (periodic_solve(mesh, f0 * (1 + e)).co_polar()[0] for e in (-1e-7, 1e-7))
    assert abs(above - below) < 2e-6


def test_the_orders_taken_out_of_g_reg_are_put_back_exactly(monkeypatch):
    # The slow Floquet orders leave the Taylor tables and come back as a rank-3 term of Z.
    # Taking 13 of them out (their term is 1.8e-2 of Z) or none must give nearly the same
    # matrix: measured 5e-5 apart, the Taylor expansion's error on those plane waves
    # (κh up to 1); a wrong sign or factor in either half would move Z by the term's size
    import barymesh.mom.periodic_fill as fill

    pg = periodic_geometry(strips(8, 2))
    k = wavenumber(17e9)
    kt = np.array([0.3 * k, -0.2 * k])
    # many orders out, propagating or not (all of them in full up to |γ| = b, in part to 2b)
    monkeypatch.setattr(fill, "SLOW_ORDERS", 1.0)
    kappa, c = fill.slow_orders(green_of(pg, k, kt), pg.lattice)
    assert len(c) >= 9
    u, v = fill.slow_order_terms(pg, k, kt, kappa, c)
    with_terms = periodic_impedance_matrix(pg, k, kt)
    monkeypatch.setattr(fill, "SLOW_ORDERS", 0.0)
    assert len(fill.slow_orders(green_of(pg, k, kt), pg.lattice)[1]) == 0
    without = periodic_impedance_matrix(pg, k, kt)
    scale = np.linalg.norm(without)
    assert np.linalg.norm(u @ v.T) > 1e-2 * scale
    assert np.linalg.norm(with_terms - without) < 1e-3 * scale


def green_of(pg, k, kt):
    from barymesh.mom import PeriodicGreen

    return PeriodicGreen(tuple(pg.lattice[0]), tuple(pg.lattice[1]), k, tuple(kt))


def test_reciprocity():
    # strips: the unknowns across the cell's sides make Z(k_t) far from symmetric
    pg = periodic_geometry(strips(8, 2))
    k = wavenumber(17e9)
    kt = (0.3 * k, -0.2 * k)
    forward = periodic_impedance_matrix(pg, k, kt)
    backward = periodic_impedance_matrix(pg, k, (-kt[0], -kt[1]))
    scale = np.abs(forward).max()
    assert np.abs(forward.T - backward).max() < 1e-3 * scale
    assert np.abs(forward.T - forward).max() > 0.1 * scale  # oblique: not symmetric itself


def test_the_rwg_maps_of_the_last_floquet_phase_are_kept_for_that_phase_only():
    # a solve asks for them three times at one k_t: the second call is the first's result,
    # and another k_t gets its own (the strips cross the cell's sides: the phase matters)
    pg = periodic_geometry(strips(8, 2))
    k = wavenumber(17e9)
    basis, test = pg.basis_maps((0.3 * k, -0.2 * k))
    again = pg.basis_maps(np.array([0.3 * k, -0.2 * k]))
    assert again[0] is basis and again[1] is test
    back, _ = pg.basis_maps((-0.3 * k, 0.2 * k))  # e^(+j k_t·a): the testing map of +k_t
    assert pg.n_crossing > 0 and abs(back - basis).max() > 0.1
    assert abs(back - test).max() < 1e-15


def test_moving_the_element_inside_the_cell_changes_nothing():
    wave = PlaneWave.from_angles(20, 30, 0)
    a = periodic_solve(patch_cell(), 20e9, wave)
    b = periodic_solve(patch_cell(shift=(1.3, 0.4)), 20e9, wave)
    for x, y in zip(a.co_polar(), b.co_polar(), strict=True):
        assert abs(abs(x) - abs(y)) < 1e-6


def test_bad_input_is_named():
    patch = build_mesh(MeshParams(structure="patch", patch_size=8.0, subdivisions=2))
    with pytest.raises(ValueError, match="no lattice"):
        periodic_solve(patch, 10e9)
    with pytest.raises(ValueError, match="too large"):
        periodic_solve(patch, 10e9, lattice=Lattice.rectangular(9.0))
    with pytest.raises(ValueError, match="Wood anomaly"):
        periodic_solve(patch_cell(), frequency(1.0))
    with pytest.raises(ValueError, match="frequency"):
        periodic_solve(patch_cell(), -1.0)
    with pytest.raises(ValueError, match="along the screen"):
        periodic_solve(patch_cell(), 10e9, PlaneWave(direction=(1, 0, 0), polarization=(0, 1, 0)))


def test_a_cell_too_large_for_the_memory_allowed_is_refused_before_allocating():
    mesh = pixel_cell(np.ones((16, 16), dtype=bool))  # 2,048 triangles, every side metal
    pg = periodic_geometry(mesh)  # the model's inputs; the cache is dropped next
    t, n = mesh.n_triangles, pg.n_unknowns
    need = periodic_memory_needed(t, n)
    cache = geometry_module._CACHE
    cache.pop(mesh, None)
    del pg
    tracemalloc.start()
    try:
        with pytest.raises(ProblemTooLarge) as refused:
            periodic_solve(mesh, 10e9, memory_limit=need - 1)
        _, peak = tracemalloc.get_traced_memory()
    finally:
        tracemalloc.stop()
    message = str(refused.value)
    assert f"T = {t:,} triangles, N = {n:,} unknowns" in message
    assert "memory_limit" in message and "coarser mesh" in message
    assert peak < 0.05 * need  # refused before any T² table or N² matrix
    assert not cache.get(mesh)  # and nothing half-built is cached
    with pytest.raises(ProblemTooLarge):
        periodic_sweep(mesh, [9e9, 11e9], memory_limit=need - 1)


def test_the_memory_model_covers_a_measured_solve():
    mesh = pixel_cell(np.pad(np.ones((12, 12), dtype=bool), 2))  # 1,152 triangles
    geometry_module._CACHE.pop(mesh, None)
    tracemalloc.start()
    try:
        solution = periodic_solve(mesh, 10e9)
        _, peak = tracemalloc.get_traced_memory()
    finally:
        tracemalloc.stop()
    need = periodic_memory_needed(mesh.n_triangles, len(solution.coefficients))
    assert peak <= need <= 2.5 * peak  # a bound, and not a vacuous one


def test_babinet_complementary_screens_converge_to_t_plus_t_prime_one():
    # a patch array under x-polarised light and its complement (square holes in a sheet,
    # metal across every side of the cell) under y-polarised light: T + T' = 1 exactly;
    # the discrete screens approach it at first order (the grid's corner singularities)
    def gap(subdivisions: int) -> float:
        mask = np.zeros((8, 8), dtype=bool)
        mask[2:6, 2:6] = True
        patches = periodic_solve(pixel_cell(mask, subdivisions), 20e9, PlaneWave())
        holes = periodic_solve(
            pixel_cell(~mask, subdivisions), 20e9, PlaneWave(polarization=(0, 1, 0))
        )
        assert holes.geometry.n_crossing > 0
        return abs(patches.co_polar()[1] + holes.co_polar()[1] - 1)

    coarse, fine = gap(1), gap(2)
    assert fine < 0.6 * coarse
    assert fine < 0.08


def test_the_benchmark_runs_and_reports_both_solvers(tmp_path):
    from benchmark_runs import run_quick

    (row,) = run_quick("periodic.py", tmp_path)["rows"]
    assert row["triangles"] == 32  # a 4 x 4 pixel patch, 2 triangles per pixel at n = 1
    assert row["unknowns"] == row["free_space_unknowns"]  # the patch is off the cell's sides
    assert row["periodic_fill_s"] > 0 and row["free_space_fill_s"] > 0
    assert row["periodic_fill_numpy_s"] > 0 and row["periodic_fill_cpu_s"] > 0


# -- sheet impedance -----------------------------------------------------------------------
#
# A uniform sheet of surface impedance Z_s filling the whole cell (metal across every side):
# the exact plane-wave answer is R = −η_w / (2 Z_s + η_w), T = 2 Z_s / (2 Z_s + η_w), with
# the wave impedance η_w = η/cos θ (TE) or η cos θ (TM); it absorbs 1 − |R|² − |T|².

SHEETS = [ETA0 / 2, 50.0, 100 + 80j, 1000.0]


@pytest.fixture(scope="module")
def full_sheet():
    return pixel_cell(np.ones((8, 8), dtype=bool), 1)  # 128 triangles, every side crossed


def sheet_answer(zs: complex, wave_impedance: float) -> tuple[complex, complex]:
    return -wave_impedance / (2 * zs + wave_impedance), 2 * zs / (2 * zs + wave_impedance)


@pytest.mark.parametrize("zs", SHEETS)
def test_uniform_resistive_sheet_at_normal_incidence(full_sheet, zs):
    s = periodic_solve(full_sheet, 12e9, PlaneWave(), sheet_impedance=zs)
    r, t = s.co_polar()
    expected_r, expected_t = sheet_answer(zs, ETA0)
    assert abs(r - expected_r) < 1e-4 and abs(t - expected_t) < 1e-4
    # the dissipated power (½ Re Z_s ∫|J|²) against what the Floquet amplitudes leave
    assert abs(s.absorption - (1 - abs(r) ** 2 - abs(t) ** 2)) < 1e-4
    assert abs(s.power_balance - 1) < 1e-4


@pytest.mark.parametrize("polarization_angle", [0, 90])  # TM, TE
def test_uniform_resistive_sheet_at_oblique_incidence(full_sheet, polarization_angle):
    wave = PlaneWave.from_angles(30, 0, polarization_angle)
    s = periodic_solve(full_sheet, 12e9, wave, sheet_impedance=100 + 80j)
    cos = abs(wave.direction[2])
    eta_w = ETA0 / cos if polarization_angle == 90 else ETA0 * cos
    r, t = s.co_polar()
    expected_r, expected_t = sheet_answer(100 + 80j, eta_w)
    assert abs(r - expected_r) < 2e-3 and abs(t - expected_t) < 2e-3
    assert abs(s.power_balance - 1) < 1e-4


def test_a_perfect_sheet_reflects_everything(full_sheet):
    s = periodic_solve(full_sheet, 12e9, PlaneWave())
    r, t = s.co_polar()
    assert abs(r + 1) < 1e-4 and abs(t) < 1e-4 and s.absorption == 0.0


@pytest.mark.parametrize("bad", [-1.0, "ten", True, float("nan"), complex(-1, 5)])
def test_a_bad_sheet_impedance_is_named(full_sheet, bad):
    with pytest.raises(ValueError, match="sheet_impedance"):
        periodic_solve(full_sheet, 12e9, sheet_impedance=bad)
