"""The near pairs' smooth kernel by its power series in k, against the kernel at every point.

:func:`barymesh.mom.near_series.near_moments_series` is a fast path of
:func:`barymesh.mom.operator.near_moments`: the two agree to 1e-12 of the largest moment
on a conforming ring and a pixel cell from 1 to 40 GHz (k R_max from 0.03 to 2.9),
and the series declines beyond its reach instead of losing digits.
"""

from __future__ import annotations

import numpy as np
import pytest

from barymesh import MeshParams, build_mesh
from barymesh.cell import Lattice, PixelGrid, UnitCell, build_cell
from barymesh.constants import SPEED_OF_LIGHT
from barymesh.mom.geometry import mom_geometry
from barymesh.mom.near_series import (
    SERIES_MAX_PHASE,
    SERIES_TOLERANCE,
    near_moments_series,
    power_tables,
    series_terms,
)
from barymesh.mom.operator import near_moments


def ring():
    """A conforming ring, 172 triangles."""
    return build_mesh(
        MeshParams(
            structure="ring",
            mode="conforming",
            inner_radius=3.0,
            outer_radius=4.0,
            subdivisions=2,
            angle_step=15.0,
        )
    )


def pixels():
    mask = np.zeros((8, 8), dtype=bool)
    mask[1:7, 2:6] = True
    mask[3:5, 3:5] = False
    grid = PixelGrid(mask, pixel_size=1.25, origin=(-5.0, -5.0), subdivisions=1)
    return build_cell(UnitCell(Lattice.rectangular(10.0), pixels=grid, mode="conforming")).mesh


@pytest.mark.parametrize("make", [ring, pixels])
@pytest.mark.parametrize("hz", [1e9, 12e9, 40e9])
def test_the_series_equals_the_kernel_at_every_point(make, hz):
    geom = mom_geometry(make())
    k = 2 * np.pi * hz / SPEED_OF_LIGHT
    series = near_moments_series(geom, k)
    assert series is not None
    direct = near_moments(geom, k)  # double precision throughout
    scale = np.abs(direct).max()
    assert np.abs(series - direct).max() < 1e-12 * scale
    # the smooth part alone (the static 1/R and R parts cancel in the difference)
    smooth = direct - geom.static_inv_r + 0.5 * k * k * geom.static_r
    assert np.abs(smooth).max() > 1e-6 * scale  # it is not negligible here
    assert np.abs(series - direct).max() < 1e-9 * np.abs(smooth).max()


def test_the_series_stops_where_its_terms_are_below_the_tolerance():
    for phase in (0.01, 0.3, 1.0, 2.5, SERIES_MAX_PHASE):
        n = series_terms(phase)
        terms = [phase**i / np.prod(np.arange(1, i + 1, dtype=float)) for i in range(1, n + 1)]
        assert terms[-1] <= SERIES_TOLERANCE * phase < terms[-2]
    assert series_terms(SERIES_MAX_PHASE * 1.01) is None


def test_beyond_its_reach_the_series_declines_and_its_tables_are_kept():
    geom = mom_geometry(ring())
    reach = SERIES_MAX_PHASE / geom.near_distances.max()
    assert near_moments_series(geom, 1.01 * reach) is None
    first = power_tables(geom, 5)
    assert power_tables(geom, 3) is not first and np.shares_memory(power_tables(geom, 3), first)
    longer = power_tables(geom, 8)  # extended when more terms are asked for
    np.testing.assert_array_equal(longer[:5], first)
    fresh = power_tables(mom_geometry(ring()), 8)  # built at once: the same tables
    np.testing.assert_allclose(longer, fresh, rtol=1e-12, atol=1e-12 * np.abs(fresh).max())
    # the m = 0 table is the product of the two triangles' frame moments
    upper = geom.near_upper
    obs, src = geom.near_pairs[upper, 0], geom.near_pairs[upper, 1]
    w = geom.near.weights
    np.testing.assert_allclose(longer[0][:, 0, 0], w[obs].sum(1) * w[src].sum(1), rtol=1e-13)
