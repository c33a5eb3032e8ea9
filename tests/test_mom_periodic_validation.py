"""The infinite-array solver against exact results, Babinet, the isolated element and itself.

The issue's validation list (the identities and invariance are in test_mom_periodic.py):

- Collin's strip grating (Field Theory of Guided Waves, problem 10.6), both polarisations
  at every P/λ of the table, within 0.01 in magnitude and 2° in phase, on strips graded
  toward their edges (the current's 1/√d edge singularity; a uniform mesh converges at
  first order and misses 0.01 at P/λ = 0.8 and 0.9 with 1,024 triangles).
- Babinet: a patch array and its complement (square holes), T + T' = 1 within 1 %.
- The isolated limit: the split-ring array's resonance tends to the free-space resonance of
  one ring as the period grows to five times the ring.
- Convergence: the ring array's resonance moves by less than 0.5 % between the two finest
  of three meshes.

Measured numbers: ``benchmarks/periodic_validation.py`` and the Solving page of the docs.
"""

from __future__ import annotations

import doctest
import os

import numpy as np
import periodic_meshes
import pytest
from periodic_meshes import (
    array_resonance,
    graded_patch,
    graded_strips,
    split_ring,
    split_ring_cell,
)

from barymesh.constants import SPEED_OF_LIGHT
from barymesh.mom import PlaneWave, periodic_solve, sweep

SLOW = pytest.mark.skipif(
    not os.environ.get("BARYMESH_SLOW"),
    reason="about 20 s more (two more ring arrays); set BARYMESH_SLOW=1 to run it",
)

P = 10.0  # mm
#: Collin's exact values: P/λ -> (|Γ⊥|, ∠Γ⊥ in degrees, |Γ∥| = |T⊥|), E across / along.
COLLIN = {
    0.1: (0.0694, -94.0, 0.9976),
    0.3: (0.2106, -102.2, 0.9776),
    0.5: (0.3598, -111.1, 0.9330),
    0.8: (0.6231, -128.5, 0.7822),
    0.9: (0.7381, -137.6, 0.6747),
}
ACROSS = PlaneWave(polarization=(1, 0, 0))  # E across the strips (they run along y)
ALONG = PlaneWave(polarization=(0, 1, 0))


@pytest.fixture(scope="module")
def strips():
    return graded_strips(P, across=16, along=6)  # 192 triangles


def test_the_cell_helpers_examples_run():
    result = doctest.testmod(periodic_meshes)
    assert result.attempted >= 4 and result.failed == 0


def test_graded_strips_are_periodic_across_the_cell(strips):
    pairs = strips.periodic_pairs
    assert strips.n_triangles == 192
    assert pairs.matched and len(pairs.edges) == 16  # every edge of the strip's end
    assert set(pairs.edge_shift.tolist()) == {1}  # paired by a2, across y = ±P/2
    widths = np.diff(np.unique(strips.points[:, 0]))
    assert widths.max() / widths.min() > 50  # graded toward the edges x = ±P/4


@pytest.mark.parametrize("p_over_lambda", sorted(COLLIN))
def test_strip_grating_matches_collin_in_both_polarisations(strips, p_over_lambda):
    magnitude, phase, parallel = COLLIN[p_over_lambda]
    f = p_over_lambda * SPEED_OF_LIGHT / (P * 1e-3)
    across = periodic_solve(strips, f, ACROSS)
    along = periodic_solve(strips, f, ALONG)
    assert along.geometry.n_crossing == 16  # the current along the strips crosses y = ±P/2
    r, t = across.co_polar()
    assert abs(abs(r) - magnitude) < 0.01
    assert abs(np.degrees(np.angle(r)) - phase) < 2.0
    assert abs(abs(t) - parallel) < 0.01  # the strips of width P/2 are self-complementary
    r_along, t_along = along.co_polar()
    assert abs(abs(r_along) - parallel) < 0.01
    for s, (rr, tt) in ((across, (r, t)), (along, (r_along, t_along))):
        assert len(s.orders) == 1  # below the first grating lobe (P/λ < 1)
        assert abs(s.power_balance - 1) < 1e-3
        assert abs(tt - (1 + rr)) < 1e-3


def test_babinet_within_one_percent_on_graded_complementary_screens():
    # a patch of side P/2 under E along x, and the sheet with that square hole under E
    # along y, on the same grid graded toward the patch's edges: T + T' = 1
    patches = graded_patch(P, 10)  # 200 triangles
    holes = graded_patch(P, 10, complement=True)  # 600 triangles
    assert holes.periodic_pairs.matched
    t = periodic_solve(patches, 20e9, PlaneWave()).co_polar()[1]
    hole_solution = periodic_solve(holes, 20e9, PlaneWave(polarization=(0, 1, 0)))
    assert hole_solution.geometry.n_crossing > 0  # the sheet's current crosses every side
    t_prime = hole_solution.co_polar()[1]
    assert 0.1 < abs(t) < 0.95 and 0.1 < abs(t_prime) < 0.95  # neither screen is trivial
    assert abs(t + t_prime - 1) < 0.01


# -- the split-ring array: isolated limit and convergence ----------------------------------
#
# The srr-openmodes ring (outer radius 4 mm, 8 mm across) under E along y, in square cells of
# 3, 4 and 5 times its size (P/λ ≤ 0.83 at the resonance: one propagating order). The array
# resonance is where T = 0 (all power reflected), found by secant steps on Im(T/R).

RING = 8.0  # mm, the ring's outer diameter


@pytest.fixture(scope="module")
def free_space_resonance():
    result = sweep(split_ring(2), np.linspace(6.0e9, 6.4e9, 5), ALONG, scattering=False)
    (f0,) = result.resonances
    return f0


@pytest.fixture(scope="module")
def five_times(free_space_resonance):
    return array_resonance(split_ring_cell(5 * RING, 2), free_space_resonance, ALONG)[0]


def test_split_ring_array_tends_to_the_isolated_ring(free_space_resonance, five_times):
    assert 6.0e9 < free_space_resonance < 6.4e9  # OpenModes' ring resonates near 6.19 GHz
    nearer = [array_resonance(split_ring_cell(m * RING, 2), five_times, ALONG)[0] for m in (3, 4)]
    gaps = [abs(f / free_space_resonance - 1) for f in [*nearer, five_times]]
    assert gaps[-1] < 0.01
    assert gaps[0] > gaps[1] > gaps[2]  # closer with every period
    assert gaps[0] > 0.01  # at 3 x the neighbours still pull the resonance (not trivial)


def test_split_ring_array_resonance_converges_under_refinement(five_times):
    coarse = array_resonance(split_ring_cell(5 * RING, 1), five_times, ALONG)[0]
    finest = array_resonance(split_ring_cell(5 * RING, 3), five_times, ALONG)[0]
    assert abs(finest / five_times - 1) < 0.005
    assert abs(five_times / coarse - 1) < 0.01


@SLOW
def test_split_ring_array_at_twice_the_ring_is_further_still(free_space_resonance, five_times):
    twice = array_resonance(split_ring_cell(2 * RING, 2), free_space_resonance, ALONG)[0]
    three = array_resonance(split_ring_cell(3 * RING, 2), five_times, ALONG)[0]
    assert abs(twice / free_space_resonance - 1) > abs(three / free_space_resonance - 1)


def test_the_validation_benchmark_runs_and_reports_collin(tmp_path):
    from benchmark_runs import run_quick

    (row,) = run_quick("periodic_validation.py", tmp_path)["collin"]
    assert row["triangles"] == 144 and row["p_over_lambda"] == 0.9
    assert abs(row["gamma_perp"] - COLLIN[0.9][0]) == pytest.approx(abs(row["gamma_perp_error"]))
    assert abs(row["gamma_par_error"]) < 0.01  # a 144-triangle graded grating is within 0.01


def test_power_balance_error_falls_with_the_mesh_below_the_first_onset():
    # The fill approximates the smooth part of G_p by a second-order Taylor expansion per
    # triangle pair, so the discrete radiated power matches the Floquet orders' only up to
    # O(h³): a patch array 10 % below its first grating lobe, halving the triangles' size
    from barymesh.cell import Lattice, PixelGrid, UnitCell, build_cell

    mask = np.zeros((8, 8), dtype=bool)
    mask[2:6, 2:6] = True

    def imbalance(subdivisions: int) -> float:
        pixels = PixelGrid(
            mask, pixel_size=P / 8, origin=(-P / 2, -P / 2), subdivisions=subdivisions
        )
        cell = UnitCell(lattice=Lattice.rectangular(P), pixels=pixels, mode="conforming")
        s = periodic_solve(build_cell(cell).mesh, 0.9 * SPEED_OF_LIGHT / (P * 1e-3), ACROSS)
        assert len(s.orders) == 1
        return abs(s.power_balance - 1)

    coarse, fine = imbalance(1), imbalance(2)
    assert coarse < 1e-3  # the bound below the first grating lobe, on 128 triangles
    assert fine < coarse / 4  # third order: at least 1/8 per halving (measured 7.3e-4, 2.8e-5)
