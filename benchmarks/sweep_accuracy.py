"""How many solves the interpolating sweep takes, and how close it is to point by point.

:func:`barymesh.mom.periodic_sweep` stops sampling when its error estimate (three folds of
cross-validation of the AAA fits) is below ``tolerance`` everywhere. This benchmark runs
it on eight cells and angles beside a point-by-point sweep of every requested frequency
and reports, per case: the frequencies solved, the largest estimate, the largest real
difference of the (0, 0) order's R (every TE/TM component, away from the grating-lobe
onsets by more than 1 % and everywhere), and at how many frequencies the real difference
exceeds the estimate.

The cases (incidence of the polarisation named, ``polarizations="incident"``, as the
window's Infinite array tab sweeps):

- ``hexring-0``, ``hexring27-0``: the ``hexagonal-rings`` cell preset at n = 3, inner
  radius 3 and 2.7 mm (the live benchmark's cell), normal incidence, TE, 5 to 30 GHz,
  201 frequencies (one onset, at 28.9 GHz);
- ``hexring-30``: the same at θ = 30°, TE; ``hexring33-30-40tm``: inner radius 3.3 mm,
  θ = 30°, φ = 40°, TM (several onsets);
- ``patch-30``: the paper's 8 mm patch (``paper-fig11-8mm``, n = 8) on a 10 mm lattice,
  θ = 30°, E along x, 5 to 40 GHz, 651 frequencies (four onsets, resonances next to them);
- ``ring-30``: a square split ring of 16 x 16 pixels in a 10 mm cell, θ = 30°, 5 to 40
  GHz, 651 frequencies;
- ``dipoles``: 8 x 8 pixel dipoles, normal incidence, E along y, 5 to 40 GHz, 651;
- ``slot-16``: the split-ring slot of ``benchmarks/periodic_sweep.py`` at 16 x 16 pixels,
  2 to 28 GHz, 651 frequencies.

Usage::

    python benchmarks/sweep_accuracy.py                 # every case, about 3 minutes
    python benchmarks/sweep_accuracy.py --json out.json
    python benchmarks/sweep_accuracy.py --quick         # the dipoles at 41 frequencies
"""

from __future__ import annotations

import argparse
import dataclasses
import json
import sys
import time
from pathlib import Path
from typing import Any

import numpy as np

from barymesh.cell import Lattice, PixelGrid, UnitCell, build_cell, load_cell_preset
from barymesh.mom import PlaneWave, periodic_sweep
from barymesh.mom.periodic import periodic_geometry

sys.path.insert(0, str(Path(__file__).resolve().parent))
from machine import machine  # noqa: E402
from periodic_sweep import split_ring_slot  # noqa: E402

P = 10.0  # mm, the square cells' period
TOLERANCE = 1e-3  # periodic_sweep's default


def pixel_cell(mask: np.ndarray) -> Any:
    grid = PixelGrid(mask, pixel_size=P / len(mask), origin=(-P / 2, -P / 2), subdivisions=1)
    return build_cell(UnitCell(Lattice.rectangular(P), pixels=grid, mode="conforming")).mesh


def hexagonal_ring(inner: float) -> Any:
    cell = load_cell_preset("hexagonal-rings")
    ring = cell.elements[0]
    params = dataclasses.replace(
        ring.params, subdivisions=3, inner_radius=inner, outer_radius=inner + 1.0
    )
    elements = (dataclasses.replace(ring, params=params),) + tuple(cell.elements[1:])
    return build_cell(dataclasses.replace(cell, elements=elements)).mesh


def patch() -> Any:
    """The docs' command-line example's cell, made as ``barymesh solve`` makes it."""
    from barymesh.app.cli import build_parser
    from barymesh.app.cli_periodic import cell_mesh

    args = build_parser().parse_args(
        ["solve", "--preset", "paper-fig11-8mm", "--set", "subdivisions=8", "--period", "10"]
        + ["--periodic", "--freq", "35GHz"]
    )
    return cell_mesh(args)[0]


def split_ring() -> Any:
    mask = np.zeros((16, 16), dtype=bool)
    mask[2:14, 2:14] = True
    mask[4:12, 4:12] = False
    mask[7:9, 2:4] = False
    return pixel_cell(mask)


def dipoles() -> Any:
    mask = np.zeros((8, 8), dtype=bool)
    mask[1:7, 3:5] = True
    return pixel_cell(mask)


def cases(quick: bool) -> dict[str, tuple[Any, np.ndarray, PlaneWave]]:
    along_y = PlaneWave(polarization=(0, 1, 0))  # normal incidence from above
    if quick:
        return {"dipoles": (dipoles(), np.linspace(5e9, 40e9, 41), along_y)}
    live, wide = np.linspace(5e9, 30e9, 201), np.linspace(5e9, 40e9, 651)
    return {
        "hexring-0": (hexagonal_ring(3.0), live, PlaneWave.from_angles(0, 0, 90.0)),
        "hexring27-0": (hexagonal_ring(2.7), live, PlaneWave.from_angles(0, 0, 90.0)),
        "hexring-30": (hexagonal_ring(3.0), live, PlaneWave.from_angles(30, 0, 90.0)),
        "hexring33-30-40tm": (hexagonal_ring(3.3), live, PlaneWave.from_angles(30, 40, 0.0)),
        "patch-30": (patch(), wide, PlaneWave.from_angles(30, 0)),
        "ring-30": (split_ring(), wide, PlaneWave.from_angles(30, 0)),
        "dipoles": (dipoles(), wide, along_y),
        "slot-16": (split_ring_slot(16), np.linspace(2e9, 28e9, 651), along_y),
    }


def measure(name: str, mesh: Any, frequencies: np.ndarray, wave: PlaneWave) -> dict[str, Any]:
    t = time.perf_counter()
    fitted = periodic_sweep(mesh, frequencies, wave, polarizations="incident")
    seconds = time.perf_counter() - t
    plain = periodic_sweep(mesh, frequencies, wave, polarizations="incident", interpolate=False)
    # every TE/TM component of the (0, 0) order's R
    diff = np.abs(fitted.order_reflection[:, 0] - plain.order_reflection[:, 0])
    error = diff.reshape(len(frequencies), -1).max(axis=1)
    onsets = np.asarray(fitted.grating_lobe_onsets, dtype=float)
    if len(onsets):
        away = np.min(np.abs(frequencies[:, None] / onsets[None, :] - 1.0), axis=1) > 0.01
    else:
        away = np.ones(len(frequencies), dtype=bool)
    estimate = np.asarray(fitted.error_estimate)
    return {
        "case": name,
        "triangles": int(mesh.n_triangles),
        "unknowns": int(periodic_geometry(mesh).n_unknowns),
        "frequencies": len(frequencies),
        "band_hz": [float(frequencies[0]), float(frequencies[-1])],
        "onsets_hz": [float(f) for f in onsets],
        "solves": int(fitted.n_solves),
        "interpolating_s": seconds,
        "largest_error_estimate": float(estimate.max()),
        "largest_r_difference": float(error.max()),
        "largest_r_difference_away_from_onsets": float(error[away].max()),
        "frequencies_above_estimate": int(np.count_nonzero(error > estimate + 1e-12)),
        "tolerance": TOLERANCE,
    }


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--json", type=Path, help="write the results here")
    ap.add_argument("--quick", action="store_true", help="the dipoles at 41 frequencies")
    args = ap.parse_args(argv)
    rows = []
    for name, (mesh, frequencies, wave) in cases(args.quick).items():
        row = measure(name, mesh, frequencies, wave)
        rows.append(row)
        print(
            f"{name}: {row['triangles']} triangles, {row['frequencies']} frequencies, "
            f"{row['solves']} solves; |dR| <= {row['largest_r_difference']:.2g} "
            f"({row['largest_r_difference_away_from_onsets']:.2g} away from onsets), "
            f"estimate {row['largest_error_estimate']:.2g}, above it at "
            f"{row['frequencies_above_estimate']}",
            flush=True,
        )
    doc = {
        "benchmark": "sweep-accuracy",
        "date": time.strftime("%Y-%m-%d"),
        "machine": machine(),
        "rows": rows,
    }
    if args.json:
        args.json.write_text(json.dumps(doc, indent=2) + "\n", encoding="utf-8")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
