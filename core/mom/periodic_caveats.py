"""What an infinite-array solve cannot vouch for: ``PeriodicSolution.warnings`` and
``PeriodicSweep.warnings``.

Each function returns a tuple of sentences (empty when there is nothing to say), each
starting with a short kind and a colon, so that a sweep can keep one of each kind and
the command line, the window and studies can show or record them as they are.

* :func:`condition_warning`: the dense solve keeps few digits.
* :func:`onset_warning`: the frequency is within :data:`ONSET_WARNING` of the onset of
  a Floquet order in vacuum (a Rayleigh-Wood anomaly: the array's Green's function is
  singular there and the results change fast and lose accuracy).
* :func:`coarse_warning`: triangles longer than a tenth of the shortest wavelength in
  the stack (the densest layer's).
* :func:`outside_warning`: metal beyond the unit cell (copies would overlap).
* :func:`onset_resonance_warning` (sweeps): a listed peak or dip of |R| next to an
  onset, where |R| is not near 0 or 1: the onset's kink, not a resonance.
"""

from __future__ import annotations

import math
from typing import Any

import numpy as np

from ..constants import SPEED_OF_LIGHT
from .caveats import CONDITION_LIMIT
from .periodic_green import reciprocal_vectors

#: Relative distance in frequency from a vacuum onset under which a solve is flagged.
ONSET_WARNING = 0.01
#: Largest edge, in wavelengths of the densest medium of the stack (λ/10).
EDGES_PER_WAVELENGTH = 10.0
#: A listed resonance this close to an onset (relative) is checked for being one.
ONSET_RESONANCE = 0.02
#: A peak is a total-reflection resonance only if |R| reaches this (and a dip only if
#: |R| falls below 1 minus it).
TOTAL_REFLECTION = 0.95


def condition_warning(condition_number: float) -> tuple[str, ...]:
    """A sentence when the solve's condition number is above :data:`CONDITION_LIMIT`."""
    if condition_number <= CONDITION_LIMIT:
        return ()
    return (
        f"ill-conditioned: the condition number is {condition_number:.3g} (above "
        f"{CONDITION_LIMIT:.0e}): the currents keep few digits (a mesh far finer than the "
        "wavelength, a frequency at a resonance of the cell, or an onset)",
    )


def onsets_near(
    lattice: np.ndarray, frequency: float, direction: np.ndarray, reach: float
) -> list[tuple[tuple[int, int], float]]:
    """Orders (p, q) whose vacuum onset lies within ``reach`` (relative) of ``frequency``.

    For a fixed incidence direction an order (p, q) propagates above the frequency at
    which |k u + G_pq| = k (u the direction's in-plane part): returned with that onset.
    """
    b1, b2 = reciprocal_vectors(lattice[0], lattice[1])
    recip = np.array([b1, b2])
    u = np.asarray(direction, dtype=np.float64)[:2]
    k_max = 2.0 * math.pi * frequency * (1.0 + reach) / SPEED_OF_LIGHT
    radius = k_max * (1.0 + np.linalg.norm(u))
    span = np.ceil(radius * np.linalg.norm(np.linalg.inv(recip), axis=0)).astype(int)
    p, q = np.meshgrid(np.arange(-span[0], span[0] + 1), np.arange(-span[1], span[1] + 1))
    orders = np.stack([p.ravel(), q.ravel()], axis=1)
    orders = orders[np.any(orders != 0, axis=1)]
    g = orders @ recip
    ug, g2, one = g @ u, np.einsum("ij,ij->i", g, g), 1.0 - u @ u
    onset = (ug + np.sqrt(ug * ug + one * g2)) / one * SPEED_OF_LIGHT / (2.0 * math.pi)
    near = np.abs(onset - frequency) <= reach * onset
    return [
        ((int(o[0]), int(o[1])), float(f)) for o, f in zip(orders[near], onset[near], strict=True)
    ]


def onset_warning(lattice: np.ndarray, frequency: float, direction: np.ndarray) -> tuple[str, ...]:
    """A sentence when ``frequency`` is within :data:`ONSET_WARNING` of a vacuum onset."""
    near = onsets_near(lattice, frequency, direction, ONSET_WARNING)
    if not near:
        return ()
    order, onset = min(near, key=lambda item: abs(item[1] - frequency))
    side = "above" if frequency > onset else "below"
    return (
        f"near an onset: {frequency / 1e9:.6g} GHz is {abs(frequency / onset - 1) * 100:.2g} % "
        f"{side} the onset of order ({order[0]}, {order[1]}) at {onset / 1e9:.6g} GHz "
        "(a Rayleigh-Wood anomaly): the coefficients change fast there and lose accuracy "
        "closer than about 1e-4; solve a little further from it",
    )


def coarse_warning(
    longest_edge: float, frequency: float, index: float, where: str
) -> tuple[str, ...]:
    """A sentence when ``longest_edge`` (m) exceeds λ/10 in the densest medium.

    ``index`` is that medium's sqrt(ε_r μ_r) (1 in vacuum), ``where`` names it.
    """
    wavelength = SPEED_OF_LIGHT / (frequency * index)
    if longest_edge <= wavelength / EDGES_PER_WAVELENGTH:
        return ()
    return (
        f"coarse mesh: edges up to {longest_edge * 1e3:.3g} mm, over a tenth of the "
        f"wavelength in {where} ({wavelength * 1e3:.3g} mm at {frequency / 1e9:.4g} GHz); "
        f"refine it to edges of {wavelength / EDGES_PER_WAVELENGTH * 1e3:.3g} mm or less",
    )


def outside_warning(vertices: np.ndarray, lattice: np.ndarray) -> tuple[str, ...]:
    """A sentence when metal (``vertices`` (V, 2 or 3), m) reaches beyond the unit cell.

    The cell is centred on the origin and spans ±½ in lattice coordinates; vertices on
    its sides are allowed (periodic edges).
    """
    xy = np.asarray(vertices, dtype=np.float64)[:, :2]
    frac = xy @ np.linalg.inv(lattice)
    beyond = np.abs(frac) - 0.5
    worst = float(beyond.max()) if len(beyond) else 0.0
    if worst <= 1e-6:
        return ()
    reach = worst * float(np.linalg.norm(lattice, axis=1).max()) * 1e3
    return (
        f"metal beyond the cell: it reaches about {reach:.3g} mm past the cell's sides, so "
        "neighbouring copies of the cell overlap; the array solved is not a physical one "
        "(shrink the metal or enlarge the lattice)",
    )


def periodic_warnings(
    pg: Any, stack: Any, frequency: float, direction: np.ndarray, condition_number: float
) -> tuple[str, ...]:
    """Every caveat of one periodic solve, in a fixed order.

    ``pg`` is the solve's :class:`~barymesh.mom.periodic_geometry.PeriodicGeometry` and ``stack``
    its :class:`~barymesh.mom.stack.Stack` or None.
    """
    index, where = 1.0, "vacuum"
    if stack is not None:
        named = [(f"above[{i}]", x) for i, x in enumerate(stack.above)]
        named += [(f"below[{i}]", x) for i, x in enumerate(stack.below)]
        for name, layer in named:
            n = math.sqrt(layer.eps_r * layer.mu_r)
            if layer.thickness > 0 and n > index:
                index, where = n, f"the layer {name} (eps_r {layer.eps_r:g})"
    longest = float(pg.base.sizes.max())
    return (
        condition_warning(condition_number)
        + onset_warning(pg.lattice, frequency, direction)
        + coarse_warning(longest, frequency, index, where)
        + outside_warning(pg.base.vertices, pg.lattice)
    )


def onset_resonance_warning(
    resonances: np.ndarray,
    kinds: tuple[str, ...],
    onsets: np.ndarray,
    reflection: np.ndarray,
    transmission: np.ndarray,
) -> tuple[str, ...]:
    """Sentences for listed resonances next to an onset that are not total reflection
    (a peak of |R| under :data:`TOTAL_REFLECTION`, a dip above 1 − it).

    ``reflection`` and ``transmission`` are |R_co| and |T_co| at each resonance.
    """
    out = []
    for f, kind, r, t in zip(resonances, kinds, reflection, transmission, strict=True):
        if not len(onsets):
            break
        nearest = float(onsets[np.argmin(np.abs(onsets - f))])
        if abs(f - nearest) > ONSET_RESONANCE * nearest:
            continue
        total = r >= TOTAL_REFLECTION if kind == "peak" else r <= 1.0 - TOTAL_REFLECTION
        if total:
            continue
        out.append(
            f"resonance next to an onset: the {kind} of |R| at {f / 1e9:.6g} GHz is "
            f"{abs(f / nearest - 1) * 100:.2g} % from the onset at {nearest / 1e9:.6g} GHz, with "
            f"|R| = {r:.3g} and |T| = {t:.3g}: the onset's kink (a Rayleigh-Wood anomaly), not "
            "a total-reflection or total-transmission resonance"
        )
    return tuple(out)
