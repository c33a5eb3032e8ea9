"""The free-space solver's results as a CSV: one row per frequency, one column per figure.

The same columns as ``barymesh solve -o sweep.csv`` and a study's per-frequency table
(:data:`CSV_COLUMNS`), full double precision (``repr`` of each float), NaN where a figure
does not apply (cross-sections for a voltage source, the input impedance for a plane
wave). Reads back with ``numpy.genfromtxt(path, delimiter=",", names=True)`` or
``pandas.read_csv``. The writers read the result's arrays only and import nothing of the
solver.
"""

from __future__ import annotations

import csv
import io
from pathlib import Path
from typing import Any

import numpy as np

from .atomic import atomic_write_text

#: Columns of the CSV, in order (units in the names).
CSV_COLUMNS = (
    "frequency_hz",
    "extinction_cross_section_m2",
    "scattering_cross_section_m2",
    "absorption_cross_section_m2",
    "input_impedance_real_ohm",
    "input_impedance_imag_ohm",
    "condition_number",
    "residual",
)

__all__ = ["CSV_COLUMNS", "cross_section_rows", "csv_text", "write_sweep_csv"]


def cross_section_rows(
    frequencies: Any,
    extinction: Any,
    scattering: Any,
    input_impedance: Any,
    condition_numbers: Any,
    residuals: Any,
) -> np.ndarray:
    """(F, 8) float64 rows of :data:`CSV_COLUMNS` (absorption = extinction − scattering)."""
    ext = np.atleast_1d(np.asarray(extinction, dtype=float))
    sca = np.atleast_1d(np.asarray(scattering, dtype=float))
    zin = np.atleast_1d(np.asarray(input_impedance, dtype=complex))
    return np.column_stack(
        [
            np.atleast_1d(np.asarray(frequencies, dtype=float)),
            ext,
            sca,
            ext - sca,
            zin.real,
            zin.imag,
            np.atleast_1d(np.asarray(condition_numbers, dtype=float)),
            np.atleast_1d(np.asarray(residuals, dtype=float)),
        ]
    )


def csv_text(rows: np.ndarray) -> str:
    """The CSV of ``rows`` (F, 8): a header of :data:`CSV_COLUMNS`, then exact floats."""
    buf = io.StringIO()
    w = csv.writer(buf, lineterminator="\n")
    w.writerow(CSV_COLUMNS)
    for row in np.asarray(rows, dtype=float):
        w.writerow([repr(float(v)) for v in row])
    return buf.getvalue()


def write_sweep_csv(path: str | Path, result: Any) -> None:
    """Write a :class:`barymesh.mom.SweepResult` to ``path`` (atomically), one row per frequency.

    Parameters
    ----------
    path : str or Path
    result : SweepResult
    """
    rows = cross_section_rows(
        result.frequencies,
        result.extinction_cross_section,
        result.scattering_cross_section,
        result.input_impedance,
        result.condition_numbers,
        result.residuals,
    )
    atomic_write_text(path, csv_text(rows))
