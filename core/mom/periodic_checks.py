"""What an infinite-array solve checks before it builds anything (issue 30).

Each check is cheap (formulas of the lattice and the frequency) and runs before the T²
tables of :func:`barymesh.mom.periodic_geometry` or the terms of
:class:`~barymesh.mom.periodic_green.PeriodicGreen` are made, so a problem that cannot be
solved is refused in seconds, naming what is wrong:

* :func:`as_lattice`: a :class:`~barymesh.cell.Lattice`, or two lattice vectors in mm;
* :func:`check_green_terms`: the terms the lattice sums would keep at the frequency and
  the memory of evaluating them (a million Floquet orders for a 10 mm cell at 1 THz).

Metal beyond its cell (copies that overlap, a 12 mm patch in a 10 mm lattice) is solved
with a warning (:func:`barymesh.mom.periodic_caveats.outside_warning`).

* :func:`check_periodic_memory`: the memory of the geometry's T² tables and of a solve's
  N² matrix, from a model measured with tracemalloc (:func:`periodic_memory_needed`),
  checked by the geometry before it builds its tables and by every solve.
"""

from __future__ import annotations

import math
from typing import Any

import numpy as np

from .caveats import MIN_KD
from .operator import wavenumber
from .periodic_green import MAX_LATTICE_BOX, PeriodicGreen, predicted_terms
from .solve import ProblemTooLarge, format_bytes, memory_allowance

#: Peak bytes per triangle pair (T²) while :func:`~barymesh.mom.periodic_geometry` builds
#: its tables (the fill plan's offsets, distances, σ codes and their temporaries), measured
#: with tracemalloc: 189-192 at T = 2,048-4,608 above a fixed ~0.1 GiB, plus a margin.
GEOMETRY_PEAK_BYTES_PER_T2 = 200.0
#: Bytes per triangle pair the built geometry keeps (measured 39-48 at T = 2,048-4,608),
#: plus the 32 of the compiled fill's copy of the plan's pair arrays, kept with the plan
#: from its first compiled fill (:func:`~barymesh.mom.compiled_periodic_fill.pair_rows`).
GEOMETRY_BYTES_PER_T2 = 74.0
#: Peak bytes per triangle pair while the compiled fill makes that copy for a geometry
#: built before (:func:`~barymesh.mom.compiled_periodic_fill.pair_rows`): the 32 it keeps
#: and one padded plane and its reordering at a time (measured with tracemalloc: 40.0 at
#: T = 128-512).
PAIR_COPY_BYTES_PER_T2 = 40.0
#: Peak bytes per N² of one periodic solve beyond the geometry: Z, the fill's float32
#: Taylor blocks and right factor, and the LU (measured 41.2-42.7 at N = 3,008-6,816).
SOLVE_BYTES_PER_N2 = 45.0
#: Bytes whatever the size (the O(T) tables, Taylor blocks of TAYLOR_BLOCK pairs, BLAS).
PERIODIC_FIXED_BYTES = 160 * 2**20


def as_lattice(lattice: Any) -> Any:
    """``lattice`` as a :class:`~barymesh.cell.Lattice` (or None, the mesh's own).

    Takes a Lattice (or anything with ``a1`` and ``a2``) as it is, and two lattice vectors
    ``((ax, ay), (bx, by))`` in mm (``lattice=((3, 0), (0, 3))`` raised AttributeError).

    Raises
    ------
    ValueError
        Naming ``lattice`` and what it expected.
    """
    if lattice is None or (hasattr(lattice, "a1") and hasattr(lattice, "a2")):
        return lattice
    from ..cell.model import Lattice

    try:
        a1, a2 = (tuple(float(x) for x in v) for v in lattice)
        if len(a1) != 2 or len(a2) != 2:
            raise ValueError
    except (TypeError, ValueError):
        from ..values import echo

        raise ValueError(
            f"lattice={echo(lattice)} is invalid; expected a Lattice or two lattice vectors "
            "((ax, ay), (bx, by)) in mm"
        ) from None
    return Lattice(a1, a2)


def check_green_terms(
    vectors: np.ndarray,
    frequency: float,
    direction: Any = (0.0, 0.0, -1.0),
    memory_limit: float | None = None,
    lowest: float | None = None,
) -> None:
    """Refuse a frequency whose lattice sums would not fit, then make them once (cheap).

    The terms are predicted (:func:`~barymesh.mom.periodic_green.predicted_terms`) and one
    block of their evaluation (:attr:`~barymesh.mom.periodic_green.GreenTerms.block_bytes`)
    compared with the memory allowed; then the Green's function is made, which refuses a
    Floquet order at or just past its onset. A frequency (or ``lowest``, the bottom of a
    sweep) whose k·D is below :data:`~barymesh.mom.caveats.MIN_KD` (D the cell's diagonal)
    is refused as the free-space solver refuses it: 1e-30 Hz gave NaN.

    Parameters
    ----------
    vectors : (2, 2) float
        Lattice vectors a1, a2 (m).
    frequency : float
        Hz.
    direction : 3 floats
        Of the incident wave (its transverse part sets k_t).
    memory_limit : float, optional
        Bytes, as for :func:`barymesh.mom.periodic_solve`.

    Raises
    ------
    ProblemTooLarge
        Naming the orders and images and the memory they need.
    ValueError
        A Floquet order at or within :data:`~barymesh.mom.periodic_green.GRAZING` of its
        onset.
    """
    low = frequency if lowest is None else lowest
    diagonal = float(
        max(np.linalg.norm(vectors[0] + vectors[1]), np.linalg.norm(vectors[0] - vectors[1]))
    )
    kd = wavenumber(low) * diagonal
    if not kd >= MIN_KD:
        least = MIN_KD * low / kd if kd > 0 else float("inf")
        raise ValueError(
            f"frequency={low:.6g} Hz is too low for this cell: k·D = {kd:.3g} (D its "
            f"diagonal), and below {MIN_KD:g} double precision cannot form the EFIE; expected "
            f"frequency >= {least:.3g} Hz"
        )
    k = wavenumber(frequency)
    d = np.asarray(direction, dtype=np.float64)
    kt = (float(k * d[0]), float(k * d[1]))
    a1 = (float(vectors[0][0]), float(vectors[0][1]))
    a2 = (float(vectors[1][0]), float(vectors[1][1]))
    terms = predicted_terms(a1, a2, k, kt)
    cell = f"{math.hypot(*a1) * 1e3:.4g} x {math.hypot(*a2) * 1e3:.4g} mm"
    where = f"at {frequency / 1e9:.6g} GHz the lattice sums of the {cell} cell"
    box = max(terms.orders_box, terms.images_box)
    if box > MAX_LATTICE_BOX:
        raise ProblemTooLarge(
            f"{where} would search {box:,} lattice points (at most {MAX_LATTICE_BOX:,}); use "
            "a lower frequency or a smaller cell"
        )
    need = terms.block_bytes
    allowed, source = memory_allowance(memory_limit)
    if need > allowed:
        raise ProblemTooLarge(
            f"{where} keep about {terms.orders:,} Floquet orders and {terms.images:,} "
            f"images: evaluating them needs {format_bytes(need)}, more than {source}; use a "
            "lower frequency or a smaller cell"
        )
    PeriodicGreen(a1, a2, k, kt)  # a Wood anomaly or a grazing order: refused by name


def periodic_memory_needed(
    n_triangles: int, n_unknowns: int, *, geometry: bool = True, pair_copy: bool = False
) -> int:
    """Peak bytes of a periodic solve of T triangles and N unknowns (a measured model).

    Parameters
    ----------
    n_triangles, n_unknowns : int
        T and N of the cell.
    geometry : bool
        Whether :func:`~barymesh.mom.periodic_geometry` is still to be built (its T² tables
        count); False counts only what one solve allocates beyond a built geometry.
    pair_copy : bool
        With ``geometry=False``: whether the built geometry still lacks the compiled
        fill's copy of its pair arrays
        (:func:`~barymesh.mom.compiled_periodic_fill.has_pair_rows`), which its first compiled
        fill makes (40 T² more).

    Returns
    -------
    int
        ``max(200 T², 74 T² + 45 N²) + 160 MiB`` (the geometry's build or a solve
        beside the built geometry, whichever is larger), or ``45 N² + 160 MiB``
        (``40 T² + 45 N² + 160 MiB`` with ``pair_copy``).

    Examples
    --------
    >>> periodic_memory_needed(1000, 1500) == 200 * 1000**2 + 160 * 2**20
    True
    """
    t2, n2 = float(n_triangles) ** 2, float(n_unknowns) ** 2
    solve = SOLVE_BYTES_PER_N2 * n2
    if geometry:
        solve = max(GEOMETRY_PEAK_BYTES_PER_T2 * t2, GEOMETRY_BYTES_PER_T2 * t2 + solve)
    elif pair_copy:
        solve += PAIR_COPY_BYTES_PER_T2 * t2
    return int(solve) + PERIODIC_FIXED_BYTES


def check_periodic_memory(
    n_triangles: int,
    n_unknowns: int,
    memory_limit: float | None = None,
    *,
    geometry: bool = True,
    pair_copy: bool = False,
) -> int:
    """Refuse a periodic cell whose solve would need more memory than allowed.

    Parameters
    ----------
    n_triangles, n_unknowns : int
        T and N of the cell.
    memory_limit : float, optional
        A cap in bytes (in addition to the memory available now).
    geometry, pair_copy : bool
        As for :func:`periodic_memory_needed`.

    Returns
    -------
    int
        The bytes needed.

    Raises
    ------
    ProblemTooLarge
        Naming T, N, the memory needed and the memory allowed, before anything of
        that size is allocated.
    """
    need = periodic_memory_needed(n_triangles, n_unknowns, geometry=geometry, pair_copy=pair_copy)
    allowed, source = memory_allowance(memory_limit)
    if need > allowed:
        what = f"about {SOLVE_BYTES_PER_N2:g} N² bytes for the dense matrix and its LU"
        if geometry:
            what = (
                f"about {GEOMETRY_PEAK_BYTES_PER_T2:g} bytes per triangle pair while its "
                f"tables are built, and {what}"
            )
        raise ProblemTooLarge(
            f"the infinite array of T = {n_triangles:,} triangles, N = {n_unknowns:,} "
            f"unknowns needs {format_bytes(need)} at its peak ({what}), more than "
            f"{source}; use a coarser mesh"
        )
    return need
