"""Floquet orders of an infinite array: which propagate, from which frequency, and their
TE and TM fields.

Above and below the screen the scattered field is a sum of orders (p, q) of transverse
wavevectors κ_pq = k_t + p b1 + q b2 (b1, b2 the reciprocal vectors) and normal
wavenumbers ±β_pq, β_pq = sqrt(k² − |κ_pq|²); an order propagates where β_pq is real, from
its onset |κ_pq| = k on (a grating lobe, or Wood-Rayleigh anomaly). Here are the orders
and their onsets over a band (:func:`order_onsets`, :func:`grating_lobe_onsets`), the
orders of one solve with the currents' harmonics (:func:`harmonics`), and the TE/TM
basis of each order (:func:`floquet_basis`; of an incident wave,
:func:`te_tm_polarizations`).

The convention: TE is ẑ × κ̂ (for κ = 0, the incident plane's φ̂); TM completes the
wave's triad with a tangential part that is the same above and below (TM = TE × k̂ for
waves going down, −TE × k̂ for waves going up).
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass
from typing import Any

import numpy as np

from ..constants import SPEED_OF_LIGHT
from .excitation import PlaneWave
from .geometry import METRES_PER_MESH_UNIT
from .periodic_geometry import cell_current
from .periodic_green import PeriodicGreen, reciprocal_vectors


def floquet_basis(kappa: np.ndarray, beta: np.ndarray, k: float, phi: float) -> tuple:
    """Unit TE and TM vectors (P, 3) of the waves going up and down of each order."""
    norm = np.linalg.norm(kappa, axis=1)
    plane = np.array([math.cos(phi), math.sin(phi)])  # the incidence plane, for κ = 0
    safe = np.where(norm > 1e-9 * k, norm, 1.0)[:, None]
    along = np.where(norm[:, None] > 1e-9 * k, kappa / safe, plane)
    # along is κ̂ (or the incidence plane's direction for κ = 0); TE = ẑ × κ̂
    te = np.stack([-along[:, 1], along[:, 0], np.zeros(len(along))], axis=1)
    kz = np.real_if_close(beta)
    up = np.concatenate([kappa, kz[:, None]], axis=1) / k
    down = np.concatenate([kappa, -kz[:, None]], axis=1) / k
    tm_down = np.cross(te, down)
    tm_up = -np.cross(te, up)
    return te, tm_up, tm_down


@dataclass(frozen=True, eq=False)
class Harmonics:
    """The propagating Floquet orders of a solve, (0, 0) first, and the currents' J̃ there."""

    orders: np.ndarray  # (P, 2) int
    kappa: np.ndarray  # (P, 2) rad/m
    beta: np.ndarray  # (P,) rad/m
    jt: np.ndarray  # (P, 3) complex J̃(κ_pq) = ∫ J e^(+jκ·ρ) dS over the cell
    te: np.ndarray  # (P, 3) unit TE, and TM going up and down
    tm_up: np.ndarray
    tm_down: np.ndarray
    phi: float  # the incidence plane's azimuth (rad)


def harmonics(pg, wave, k, kt, current) -> Harmonics:
    """The propagating orders of a solve at wavenumber ``k``, Floquet phase ``kt``, and the
    cell's currents ``current`` (N,) there: :class:`Harmonics`."""
    green = PeriodicGreen(tuple(pg.lattice[0]), tuple(pg.lattice[1]), k, kt)
    prop = green.propagating()
    orders, kappa = green.orders[prop], green.kappa[prop]
    first = np.flatnonzero(np.all(orders == 0, axis=1))
    order = np.concatenate([first, np.setdiff1d(np.arange(len(orders)), first)])
    orders, kappa = orders[order], kappa[order]
    beta = np.sqrt(k * k - np.einsum("ij,ij->i", kappa, kappa))
    rule = pg.base.near
    j = cell_current(pg, kt, current, rule.rho)  # (T, Q, 3)
    phase = np.exp(1j * (rule.points[:, :, :2] @ kappa.T))  # (T, Q, P)
    jt = np.einsum("tq,tqc,tqp->pc", rule.weights, j, phase)  # J̃(κ_pq), (P, 3)
    d = np.asarray(wave.direction)
    phi = math.atan2(d[1], d[0]) if np.hypot(d[0], d[1]) > 1e-12 else 0.0
    te, tm_up, tm_down = floquet_basis(kappa, beta, k, phi)
    return Harmonics(orders, kappa, beta, jt, te, tm_up, tm_down, phi)


def incidence_direction(incidence: PlaneWave) -> np.ndarray:
    """The incident wave's direction (3,), refused along the screen."""
    d = np.asarray(incidence.direction, dtype=np.float64)
    if abs(d[2]) < 1e-9:
        raise ValueError("the incident wave travels along the screen (direction_z = 0)")
    return d


def te_tm_polarizations(direction: Sequence[float] | np.ndarray) -> np.ndarray:
    """(2, 3) float: the unit TE and TM electric fields of a wave travelling along ``direction``.

    The convention of :mod:`barymesh.mom.periodic`: TE = ẑ × κ̂ (κ̂ the wave's in-plane
    direction, or x̂ at normal incidence), TM = TE × d̂ for a wave going down
    (−TE × d̂ going up), so that a :class:`PlaneWave` with E along row 0 has TE/TM
    components (1, 0) and one along row 1 has (0, 1).

    Examples
    --------
    >>> te_tm_polarizations((0, 0, -1)).round(12) + 0.0  # normal incidence from above
    array([[ 0.,  1.,  0.],
           [-1.,  0.,  0.]])
    """
    d = np.asarray(direction, dtype=np.float64)
    d = d / np.linalg.norm(d)
    along = d[:2]
    norm = float(np.hypot(*along))
    along = along / norm if norm > 1e-12 else np.array([1.0, 0.0])
    te = np.array([-along[1], along[0], 0.0])
    tm = np.cross(te, d) if d[2] < 0 else -np.cross(te, d)
    return np.stack([te, tm])


def order_onsets(
    vectors: np.ndarray, direction: np.ndarray, f_max: float, index: float = 1.0
) -> tuple:
    """Orders (p, q) that propagate somewhere below ``f_max`` and their onsets (Hz).

    κ_pq = k u + G_pq with u the incident direction's in-plane part; |κ_pq| = n k (n the
    medium's ``index``, 1 in vacuum) at k = (u·G + sqrt((u·G)² + (n² − |u|²) |G|²)) /
    (n² − |u|²), and above it the order propagates. Sorted by onset, (0, 0) first.
    """
    b1, b2 = reciprocal_vectors(vectors[0], vectors[1])
    recip = np.array([b1, b2])
    u = direction[:2]
    k_max = 2.0 * np.pi * f_max / SPEED_OF_LIGHT
    # an order propagates only if |G| <= |κ| + k|u| < k (n + |u|)
    radius = k_max * (index + np.linalg.norm(u))
    reach = np.ceil(radius * np.linalg.norm(np.linalg.inv(recip), axis=0)).astype(int)
    p, q = np.meshgrid(np.arange(-reach[0], reach[0] + 1), np.arange(-reach[1], reach[1] + 1))
    orders = np.stack([p.ravel(), q.ravel()], axis=1)
    g = orders @ recip
    ug = g @ u
    g2 = np.einsum("ij,ij->i", g, g)
    one = index * index - u @ u
    k_on = (ug + np.sqrt(ug * ug + one * g2)) / one
    onset = k_on * SPEED_OF_LIGHT / (2.0 * np.pi)
    keep = onset < f_max
    orders, onset = orders[keep], onset[keep]
    order = np.lexsort((orders[:, 1], orders[:, 0], onset))
    return orders[order], onset[order]


def grating_lobe_onsets(
    lattice: Any,
    incidence: PlaneWave | None = None,
    f_max: float = 1e12,
    f_min: float = 0.0,
) -> np.ndarray:
    """Frequencies (Hz) in (f_min, f_max) at which a Floquet order (p, q) ≠ (0, 0) starts
    to propagate, for a fixed incidence direction.

    Parameters
    ----------
    lattice : Lattice
        The array's lattice (mm), e.g. ``mesh.lattice`` of a unit cell.
    incidence : PlaneWave, optional
        Only its direction matters; default normal incidence.
    f_max, f_min : float
        Hz.

    Returns
    -------
    (G,) float
        Increasing; orders with the same onset count once.

    Examples
    --------
    A square lattice of 10 mm: c/P at normal incidence; at θ = 30° in the xz plane,
    c/(P (1 + sin θ)) for (1, 0), then (1, ±1), then c/(P cos θ) for (0, ±1).

    >>> from barymesh.cell import Lattice
    >>> (grating_lobe_onsets(Lattice.rectangular(10.0), f_max=40e9) / 1e9).round(3)
    array([29.979])
    >>> wave = PlaneWave.from_angles(30, 0)
    >>> (grating_lobe_onsets(Lattice.rectangular(10.0), wave, 35e9) / 1e9).round(3)
    array([19.986, 32.892, 34.617])
    """
    wave = PlaneWave() if incidence is None else incidence
    vectors = np.array([lattice.a1, lattice.a2], dtype=np.float64) * METRES_PER_MESH_UNIT
    _, onset = order_onsets(vectors, incidence_direction(wave), float(f_max))
    onset = onset[(onset > f_min) & (onset > 0)]
    return merged_onsets(onset)


def merged_onsets(onsets: np.ndarray, rtol: float = 1e-9) -> np.ndarray:
    """``onsets`` sorted, each once: those within ``rtol`` (relative) of the last kept go."""
    onsets = np.sort(onsets)
    if len(onsets) == 0:
        return onsets
    keep = np.concatenate([[True], np.diff(onsets) > rtol * onsets[1:]])
    return onsets[keep]
