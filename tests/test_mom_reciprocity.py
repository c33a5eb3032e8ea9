"""Galerkin testing of a reciprocal operator gives a symmetric matrix: Z = Zᵀ.

The closed-form (inner) integrals of the singular 1/R and R parts are exact on the source
triangle whatever its size, while the outer rule samples the source's potential at a few
points of the observation triangle. With a small source beside a large observer (a graded
mesh: edge triangles a tenth of their neighbours) that potential peaks between them and
the rule misses it: the two orders of such a pair differed by up to 18 % of the entry.
Each mirrored pair is now computed once, with the smaller triangle under the rule, in the
cell and across its sides. The reference here is outside the code under test: the outer
triangle cut into 256 pieces with the degree-8 rule on each.
"""

from __future__ import annotations

import numpy as np
import pytest

from barymesh import MeshParams, build_mesh
from barymesh.cell import Lattice, PixelGrid, UnitCell, build_cell
from barymesh.mom import geometry as geometry_module
from barymesh.mom.geometry import mom_geometry
from barymesh.mom.operator import impedance_matrix, wavenumber
from barymesh.mom.periodic import periodic_geometry, periodic_impedance_matrix
from barymesh.mom.quadrature import triangle_rule

P = 10.0  # mm, the cell's side


@pytest.fixture(scope="module")
def graded_patch():
    params = MeshParams(
        structure="patch", mode="conforming", patch_size=8.0, subdivisions=16, grading=True
    )
    return build_mesh(params)


def _asymmetry(z: np.ndarray) -> float:
    return float(np.abs(z - z.T).max() / np.abs(z).max())


def test_free_space_matrix_of_a_graded_mesh_is_symmetric(graded_patch):
    geo = mom_geometry(graded_patch)
    assert geo.sizes.max() / geo.sizes.min() > 5  # graded: the rule's weak case is there
    z = impedance_matrix(geo, wavenumber(15e9))
    assert _asymmetry(z) < 1e-6  # was 3.4e-3


@pytest.mark.parametrize("grading", [False, True])
def test_periodic_matrix_at_normal_incidence_is_symmetric_across_the_sides(grading):
    # strips touching both sides of the cell: pairs near through an image
    mask = np.zeros((8, 8), dtype=bool)
    mask[:, 2:6] = True
    pixels = PixelGrid(
        mask, pixel_size=P / 8, origin=(-P / 2, -P / 2), subdivisions=4, grading=grading
    )
    mesh = build_cell(
        UnitCell(lattice=Lattice.rectangular(P), pixels=pixels, mode="conforming")
    ).mesh
    pg = periodic_geometry(mesh, Lattice.rectangular(P))
    assert pg.n_crossing > 0
    z = periodic_impedance_matrix(pg, wavenumber(15e9), (0.0, 0.0))
    assert _asymmetry(z) < 1e-6  # was 7e-5 (uniform) and 6e-4 (graded)


def _subdivided_rule(geo, triangles: np.ndarray, levels: int = 4):
    """The degree-8 rule on each of the 4**levels pieces of each of ``triangles``, with
    ρ measured from the whole triangle's centroid (as the moments are)."""
    bary, w = triangle_rule(8)
    pieces = [np.eye(3)]
    for _ in range(levels):
        finer = []
        for a, b, c in pieces:
            ab, bc, ca = (a + b) / 2, (b + c) / 2, (c + a) / 2
            finer += [np.array(t) for t in ((a, ab, ca), (ab, b, bc), (ca, bc, c), (ab, bc, ca))]
        pieces = finer
    points_bary = np.concatenate([bary @ t for t in pieces])
    weights = np.concatenate([w / len(pieces)] * len(pieces))
    corners = geo.vertices[geo.triangles[triangles]]
    points = np.einsum("qk,tkc->tqc", points_bary, corners)
    return geometry_module.Rule(
        8,
        points,
        geo.areas[triangles, None] * weights[None, :],
        points - geo.centroids[triangles, None, :],
    )


def test_static_moments_of_unequal_pairs_match_a_subdivided_rule(graded_patch):
    geo = mom_geometry(graded_patch)
    obs, src = geo.near_pairs[:, 0], geo.near_pairs[:, 1]
    ratio = geo.sizes[obs] / geo.sizes[src]
    # pairs with the observation triangle 3x the source (and their mirrors)
    rows = np.flatnonzero(ratio > 3)[::9][:40]
    assert len(rows) == 40
    rule = _subdivided_rule(geo, obs[rows])
    corners = geo.vertices[geo.triangles]
    reference, _ = geometry_module.static_moments(
        rule, corners, geo.centroids, np.arange(len(rows)), src[rows]
    )
    err = np.abs(geo.static_inv_r[rows] - reference).max(axis=1)
    err /= np.abs(reference).max(axis=1)
    # the large triangle under the default rule was off by 4e-4 (median), 0.13 at worst
    assert np.median(err) < 1e-6
    mirrors = np.flatnonzero(ratio < 1 / 3)
    assert len(mirrors) == (ratio > 3).sum()
