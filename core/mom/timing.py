"""How long an infinite-array solve takes: a model measured on the benchmark machine.

The periodic solver builds its tables over every pair of triangles once per cell (the
geometry, ∝ T²), then per frequency fills the matrix (∝ T²: every pair of triangles) and
factorises it (∝ N³: the LU). The three coefficients are least-squares fits of the times
``benchmarks/periodic.py`` measured on 392, 720 and 1,152 triangles (560 to 1,680
unknowns) on the 2-core benchmark machine, with one BLAS thread as the solver runs
(``benchmarks/results/periodic-2026-12-02.json``; ``tests/test_io_handoffs.py`` fits them
again from that file). A shared or slower machine takes longer: the figure is what to
expect, not a promise, and the command line says so.

>>> round(periodic_solve_seconds(6_976, 8_720))  # split-ring-pair: T, N
30
"""

from __future__ import annotations

from dataclasses import dataclass

from .periodic_sweep import INITIAL_SAMPLES

#: Seconds per triangle pair of the per-cell geometry (fit of ``periodic_geometry_s``).
GEOMETRY_S_PER_PAIR = 2.5e-7
#: Seconds per triangle pair of one frequency's fill (fit of ``periodic_fill_s``).
FILL_S_PER_PAIR = 1.8e-7
#: Seconds per N³ of one frequency's LU (fit of ``periodic_lu_s``).
LU_S_PER_N3 = 3.2e-11
#: The results file the coefficients come from.
MEASURED_IN = "benchmarks/results/periodic-2026-12-02.json"

__all__ = ["PeriodicTime", "periodic_solve_seconds", "periodic_sweep_time"]


def periodic_solve_seconds(triangles: int, unknowns: int) -> float:
    """Seconds of one frequency of an infinite-array solve: fill and LU (not the geometry)."""
    return FILL_S_PER_PAIR * float(triangles) ** 2 + LU_S_PER_N3 * float(unknowns) ** 3


@dataclass(frozen=True)
class PeriodicTime:
    """The expected time of a periodic sweep, from :func:`periodic_sweep_time`.

    Attributes
    ----------
    geometry_s : float
        Once per cell.
    per_solve_s : float
        Each frequency solved.
    fewest_solves, most_solves : int
        How many frequencies may be solved: all of them without interpolation; with it,
        between the first samples (the ends of every piece between grating-lobe onsets
        and a few inside) and every requested frequency plus two per onset.
    """

    geometry_s: float
    per_solve_s: float
    fewest_solves: int
    most_solves: int

    @property
    def fewest_s(self) -> float:
        """Seconds if the fewest frequencies are solved."""
        return self.geometry_s + self.fewest_solves * self.per_solve_s

    @property
    def most_s(self) -> float:
        """Seconds if the most frequencies are solved."""
        return self.geometry_s + self.most_solves * self.per_solve_s


def periodic_sweep_time(
    triangles: int, unknowns: int, frequencies: int, interpolate: bool = True, onsets: int = 0
) -> PeriodicTime:
    """The expected time of :func:`barymesh.mom.periodic_sweep` over ``frequencies``.

    Parameters
    ----------
    triangles, unknowns : int
        T and N of the cell.
    frequencies : int
        How many frequencies are asked for.
    interpolate : bool
        As for the sweep: True solves a few and fits the rest.
    onsets : int
        Grating-lobe onsets inside the band (each adds a piece with its own ends).

    Examples
    --------
    >>> t = periodic_sweep_time(6_976, 8_720, 21)
    >>> t.fewest_solves, t.most_solves, round(t.most_s / 60)
    (5, 21, 11)
    """
    per = periodic_solve_seconds(triangles, unknowns)
    geometry = GEOMETRY_S_PER_PAIR * float(triangles) ** 2
    n = int(frequencies)
    if not interpolate:
        return PeriodicTime(geometry, per, n, n)
    # the sweep's first samples: INITIAL_SAMPLES in each piece between onsets (its two
    # ends and a few evenly spread inside), never more than it may solve at most
    most = n + 2 * int(onsets)
    return PeriodicTime(geometry, per, min(most, INITIAL_SAMPLES * (int(onsets) + 1)), most)
