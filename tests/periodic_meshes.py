"""Unit cells for the infinite-array validation, graded toward the metal's edges.

At a metal edge the current along it grows like 1/√d and the charge across it like
1/√d too; uniform meshes then converge at first order. A tensor-product grid whose
lines crowd toward the edges (power-law spacing on each interval between two edges)
resolves both with a few hundred triangles. Each rectangle is cut along a diagonal
(the paper's split of a patch into two primary triangles)::

    y3 +----+--+-+ ... each rectangle (x_i, x_i+1) x (y_j, y_j+1)
       | \\  |\\ |\\|     becomes (i, j)-(i+1, j)-(i+1, j+1)
    y2 +----+--+-+     and (i, j)-(i+1, j+1)-(i, j+1), counter-clockwise
       |  \\ | \\|\\|
    y1 +----+--+-+
       x0   x1 x2 x3

The cells are centred on the origin with a square lattice of side ``period``; metal
that reaches a side of the cell has the same grid lines on the opposite side, so every
boundary edge there has its periodic partner (:attr:`barymesh.mesh.TriMesh.periodic_pairs`).

Also here: the ``srr-openmodes`` split ring in a cell and in free space, and the array's
resonance (T = 0) found in a few solves.
"""

from __future__ import annotations

from dataclasses import replace

import numpy as np
from scipy.optimize import root_scalar

from barymesh import build_mesh
from barymesh.cell import Element, Lattice, UnitCell, build_cell
from barymesh.mesh import TriMesh
from barymesh.mom import PlaneWave, periodic_solve
from barymesh.presets import load_preset


def graded_nodes(a: float, b: float, n: int, power: float = 3.0) -> np.ndarray:
    """(n + 1,) float: grid lines on [a, b] crowded toward both ends.

    Symmetric power grading: node k is at s(k/n) of the way, s(t) = (2t)^power / 2 on
    the first half and its mirror image on the second. The first interval is
    (2/n)^power / 2 of the length (uniform: 1/n); power 3 resolves the 1/√d edge
    singularity of the current (with power 1 the grid is uniform).

    >>> graded_nodes(0.0, 1.0, 4)
    array([0.    , 0.0625, 0.5   , 0.9375, 1.    ])
    """
    t = np.linspace(0.0, 1.0, n + 1)
    s = np.where(t <= 0.5, 0.5 * (2 * t) ** power, 1.0 - 0.5 * (2 * (1 - t)) ** power)
    return a + (b - a) * s


def grid_cell(
    x: np.ndarray, y: np.ndarray, metal: np.ndarray, period: float, tolerance: float = 1e-9
) -> TriMesh:
    """The mesh of the rectangles ``metal[i, j]`` of the grid ``x`` × ``y``, two triangles each.

    Parameters
    ----------
    x, y : (nx + 1,), (ny + 1,) float
        Increasing grid lines (mm), within [-period/2, period/2].
    metal : (nx, ny) bool
        Which rectangles are metal.
    period : float
        Side of the square cell (mm); the mesh's lattice.
    tolerance : float
        Matching distance of the periodic pairs (mm), relative to ``period``.
    """
    x, y = np.asarray(x, float), np.asarray(y, float)
    nx, ny = len(x) - 1, len(y) - 1
    metal = np.asarray(metal, bool)
    if metal.shape != (nx, ny):
        raise ValueError(f"metal has shape {metal.shape}, expected ({nx}, {ny})")
    ii, jj = np.nonzero(metal)
    node = (np.arange(nx + 1)[:, None] * (ny + 1) + np.arange(ny + 1)[None, :]).ravel()
    gx, gy = np.meshgrid(x, y, indexing="ij")
    points = np.column_stack([gx.ravel(), gy.ravel(), np.zeros(gx.size)])

    def at(i: np.ndarray, j: np.ndarray) -> np.ndarray:
        return node[i * (ny + 1) + j]

    a, b, c, d = at(ii, jj), at(ii + 1, jj), at(ii + 1, jj + 1), at(ii, jj + 1)
    triangles = np.concatenate([np.stack([a, b, c], 1), np.stack([a, c, d], 1)])
    used, triangles = np.unique(triangles, return_inverse=True)
    triangles = triangles.reshape(-1, 3)
    n = len(triangles)
    return TriMesh(
        points=points[used],
        triangles=triangles,
        patch_ids=np.zeros(n, dtype=int),
        regions=np.ones(n, dtype=int),
        n_patches=1,
        mode="conforming",
        tolerance=tolerance * period,
        lattice=Lattice.rectangular(period),
    )


def graded_strips(period: float, across: int, along: int) -> TriMesh:
    """PEC strips of width period/2 along y, touching both sides y = ±period/2.

    ``across`` graded intervals across the width, ``along`` uniform ones along it:
    2 × across × along triangles.

    >>> mesh = graded_strips(10.0, 8, 6)
    >>> mesh.n_triangles, len(mesh.periodic_pairs.edges), mesh.periodic_pairs.matched
    (96, 8, True)
    """
    x = graded_nodes(-period / 4, period / 4, across)
    y = np.linspace(-period / 2, period / 2, along + 1)
    return grid_cell(x, y, np.ones((across, along), bool), period)


def patch_and_hole_grid(period: float, n: int) -> tuple[np.ndarray, np.ndarray]:
    """The grid lines of a square patch of side period/2 and of its complement.

    n graded intervals (n even) on [-period/4, period/4] (the patch) and n on the gap
    between two patches, graded toward both patch edges: the gap is the interval
    [period/4, 3 period/4], split at the cell's side period/2.
    """
    if n % 2:
        raise ValueError(f"n={n} must be even (the cell's side is the gap's middle line)")
    inner = graded_nodes(-period / 4, period / 4, n)
    gap = graded_nodes(period / 4, 3 * period / 4, n)
    right = gap[gap <= period / 2 + 1e-12]
    left = gap[gap >= period / 2 - 1e-12] - period
    lines = np.concatenate([left, inner[1:-1], right])
    return lines, lines


def graded_patch(period: float, n: int, complement: bool = False) -> TriMesh:
    """A square PEC patch of side period/2 in the middle of the cell, or (``complement``)
    the sheet with that square hole, on the same graded grid.

    >>> patch, holes = graded_patch(10.0, 4), graded_patch(10.0, 4, complement=True)
    >>> patch.n_triangles, holes.n_triangles, holes.periodic_pairs.matched
    (32, 96, True)
    """
    x, y = patch_and_hole_grid(period, n)
    cx, cy = 0.5 * (x[:-1] + x[1:]), 0.5 * (y[:-1] + y[1:])
    inside = (np.abs(cx)[:, None] < period / 4) & (np.abs(cy)[None, :] < period / 4)
    return grid_cell(x, y, ~inside if complement else inside, period)


def split_ring_cell(period: float, subdivisions: int = 2) -> TriMesh:
    """The ``srr-openmodes`` split ring (outer radius 4 mm) alone in a square cell of side
    ``period`` (mm), meshed as the free-space solver meshes it (``subdivisions`` n)."""
    params = replace(load_preset("srr-openmodes")[0], subdivisions=subdivisions)
    cell = UnitCell(Lattice.rectangular(period), elements=(Element(params),), mode="conforming")
    return build_cell(cell).mesh


def split_ring(subdivisions: int = 2) -> TriMesh:
    """The same ring in free space."""
    return build_mesh(replace(load_preset("srr-openmodes")[0], subdivisions=subdivisions))


def array_resonance(
    mesh: TriMesh, guess: float, incidence: PlaneWave, rtol: float = 1e-4
) -> tuple[float, int]:
    """The frequency (Hz) where the array of ``mesh`` reflects all the incident power.

    A lossless screen with one propagating order and T = 1 + R has R on the circle
    |R + 1/2| = 1/2, so T/R = −j cot(φ/2) is imaginary and passes through zero at the
    resonance (T = 0, |R| = 1, the peak of |R|). Secant iterations on Im(T/R), started
    at ``guess`` and 0.5 % above it, converge in a few solves.

    Returns
    -------
    frequency : float
    solves : int
        How many periodic solves it took.
    """
    solves = 0

    def t_over_r(f: float) -> float:
        nonlocal solves
        solves += 1
        r, t = periodic_solve(mesh, f, incidence).co_polar()
        return float((t / r).imag)

    found = root_scalar(t_over_r, x0=guess, x1=guess * 1.005, method="secant", rtol=rtol)
    if not found.converged:
        raise RuntimeError(f"no array resonance near {guess:.6g} Hz: {found.flag}")
    return float(found.root), solves
