"""Speed of the infinite-array solver (barymesh.mom.periodic_solve) beside the free-space one.

Issue 32's targets: one frequency of a 1,000-unknown cell, fill plus solve, in 0.1 s on
this 2-core machine, and the periodic fill within 1.2x of the free-space fill at the same N
(both fills compiled; issue 17's were 0.2 s and 2x). Both solvers run on the same mesh in
the same run, alternating, each timed in wall and in CPU time (all threads):

* ``periodic``: the periodic EFIE matrix (compiled, ``backend="numba"``, and numpy's,
  ``backend="numpy"``, the reference) and its LU
  (``dense_solve``, TE and TM right-hand sides), with one BLAS thread as
  ``periodic_solve`` runs them, the per-mesh periodic geometry timed apart (cold, then
  cached), and the whole ``periodic_solve_many`` of TE and TM (Floquet amplitudes included);
* ``free space``: :func:`barymesh.mom.impedance_matrix` on the same mesh (the same
  triangles and rules; its unknowns are the interior edges only).

Three cells, 560, 1,042 and 1,680 unknowns; each time is the best of ``--reps`` runs
(the machine is shared: run it twice and compare). ``periodic_solve`` of one wave is
timed too: fill, LU, refinement and the Floquet amplitudes, the geometry cached.

Usage::

    python benchmarks/periodic.py                  # 560, 1,042 and 1,680 unknowns
    python benchmarks/periodic.py --json out.json
    python benchmarks/periodic.py --quick          # a tiny cell (the test suite)
"""

from __future__ import annotations

import argparse
import json
import os
import time
from pathlib import Path
from typing import Any

import numpy as np
from machine import machine

from barymesh.cell import Lattice, PixelGrid, UnitCell, build_cell
from barymesh.mom import (
    PlaneWave,
    impedance_matrix,
    mom_geometry,
    periodic_solve,
    periodic_solve_many,
)
from barymesh.mom.operator import wavenumber
from barymesh.mom.periodic import blas_threads, periodic_geometry, periodic_impedance_matrix
from barymesh.mom.solve import dense_solve

P = 10.0  # mm
#: Issue 32's targets: one frequency at about 1,000 unknowns (fill + LU), and the periodic
#: fill against the free-space fill of the same mesh.
TARGET_SECONDS = 0.1
TARGET_RATIO = 1.2


def patch_cell(pixels: int, subdivisions: int, metal: tuple[int, int] | None = None):
    """A rectangular patch of ``metal`` pixels (default half the cell's side) in the middle
    of a pixel grid (metal off the sides)."""
    mx, my = metal if metal is not None else (pixels // 2, pixels // 2)
    mask = np.zeros((pixels, pixels), dtype=bool)
    x0, y0 = (pixels - mx) // 2, (pixels - my) // 2
    mask[x0 : x0 + mx, y0 : y0 + my] = True
    grid = PixelGrid(
        mask, pixel_size=P / pixels, origin=(-P / 2, -P / 2), subdivisions=subdivisions
    )
    cell = UnitCell(lattice=Lattice.rectangular(P), pixels=grid, mode="conforming")
    return build_cell(cell).mesh


def _best(times: list[float]) -> float:
    return float(min(times))


def measure(
    pixels: int,
    subdivisions: int,
    reps: int,
    metal: tuple[int, int] | None = None,
    frequency: float = 20e9,
) -> dict[str, Any]:
    mesh = patch_cell(pixels, subdivisions, metal)
    k = wavenumber(frequency)
    wave = PlaneWave.from_angles(20, 0, 0)
    kt = (float(k * wave.direction[0]), float(k * wave.direction[1]))
    t = time.perf_counter()
    free_geom = mom_geometry(mesh)
    free_geometry = time.perf_counter() - t
    t = time.perf_counter()
    pg = periodic_geometry(mesh)
    geometry_cold = time.perf_counter() - t
    waves = [wave, PlaneWave.from_angles(20, 0, 90)]  # TM and TE: one fill, one LU
    periodic_fill, periodic_lu, free_fill, whole, one = [], [], [], [], []
    numpy_fill, fill_cpu, numpy_cpu, free_cpu, lu_cpu = [], [], [], [], []
    # the first compiled fills load (or compile) the kernels: not timed
    periodic_impedance_matrix(pg, k, kt, backend="numba")
    impedance_matrix(free_geom, k)
    for _ in range(reps):
        with blas_threads(pg.n_unknowns):  # as periodic_solve runs them
            t, c = time.perf_counter(), time.process_time()
            z = periodic_impedance_matrix(pg, k, kt, backend="numba")
            periodic_fill.append(time.perf_counter() - t)
            fill_cpu.append(time.process_time() - c)
            v = np.ones((len(z), 2), dtype=np.complex128)
            t, c = time.perf_counter(), time.process_time()
            dense_solve(z, v)
            periodic_lu.append(time.perf_counter() - t)
            lu_cpu.append(time.process_time() - c)
            del z
            t, c = time.perf_counter(), time.process_time()
            periodic_impedance_matrix(pg, k, kt, backend="numpy")
            numpy_fill.append(time.perf_counter() - t)
            numpy_cpu.append(time.process_time() - c)
        t = time.perf_counter()
        periodic_solve_many(mesh, frequency, waves)
        whole.append(time.perf_counter() - t)
        t = time.perf_counter()
        periodic_solve(mesh, frequency, wave)
        one.append(time.perf_counter() - t)
        t, c = time.perf_counter(), time.process_time()
        impedance_matrix(free_geom, k)
        free_fill.append(time.perf_counter() - t)
        free_cpu.append(time.process_time() - c)
    fill, lu, free = _best(periodic_fill), _best(periodic_lu), _best(free_fill)
    cpu, cpu_free, cpu_lu = _best(fill_cpu), _best(free_cpu), _best(lu_cpu)
    return {
        "load_average": os.getloadavg()[0],
        "triangles": int(mesh.n_triangles),
        "unknowns": int(pg.n_unknowns),
        "free_space_unknowns": int(free_geom.n_unknowns),
        "frequency_hz": frequency,
        "free_space_geometry_s": free_geometry,
        "periodic_geometry_s": geometry_cold,
        "periodic_fill_s": fill,
        "periodic_fill_cpu_s": cpu,
        "periodic_fill_numpy_s": _best(numpy_fill),
        "periodic_fill_numpy_cpu_s": _best(numpy_cpu),
        "periodic_lu_s": lu,
        "periodic_lu_cpu_s": cpu_lu,
        "periodic_fill_plus_solve_cpu_s": cpu + cpu_lu,
        "periodic_fill_plus_solve_s": fill + lu,
        "periodic_solve_te_tm_s": _best(whole),
        "periodic_solve_s": _best(one),
        "free_space_fill_s": free,
        "free_space_fill_cpu_s": cpu_free,
        "fill_ratio": fill / free,
        "fill_ratio_cpu": cpu / cpu_free,
        "target_fill_plus_solve_s": TARGET_SECONDS,
        "target_fill_ratio": TARGET_RATIO,
        "fill_ratio_met": fill / free <= TARGET_RATIO,
        "fill_plus_solve_met": fill + lu <= TARGET_SECONDS if pg.n_unknowns >= 1000 else None,
    }


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--json", type=Path, help="write the results here")
    ap.add_argument("--quick", action="store_true", help="a tiny cell, one repetition")
    ap.add_argument("--reps", type=int, default=3)
    args = ap.parse_args(argv)
    # (pixels, subdivisions, metal pixels): 32 triangles; or 392, 720 and 1,152 triangles
    # (560, 1,042 and 1,680 unknowns: a 7 x 7, 9 x 10 and 8 x 8 pixel patch)
    cases = [(8, 1, None)] if args.quick else [(14, 2, None), (20, 2, (9, 10)), (16, 3, None)]
    reps = 1 if args.quick else args.reps
    rows = [measure(pixels, subdivisions, reps, metal) for pixels, subdivisions, metal in cases]
    doc = {
        "benchmark": "periodic",
        "date": time.strftime("%Y-%m-%d"),
        "machine": machine(),
        "reps": reps,
        "rows": rows,
    }
    for row in rows:
        print(
            f"{row['unknowns']} unknowns ({row['triangles']} triangles, load "
            f"{row['load_average']:.1f}): periodic fill {row['periodic_fill_s']:.3f} s "
            f"({row['periodic_fill_cpu_s']:.3f} s CPU; "
            f"numpy's {row['periodic_fill_numpy_s']:.3f} s)"
            f" + LU {row['periodic_lu_s']:.3f} s = {row['periodic_fill_plus_solve_s']:.3f} s "
            f"(target {TARGET_SECONDS} s at 1,000; the whole "
            f"periodic_solve {row['periodic_solve_s']:.3f} s, TE + TM "
            f"{row['periodic_solve_te_tm_s']:.3f} s); free-space "
            f"fill {row['free_space_fill_s']:.3f} s ({row['free_space_fill_cpu_s']:.3f} s CPU), "
            f"ratio {row['fill_ratio']:.2f} wall, {row['fill_ratio_cpu']:.2f} CPU "
            f"(target {TARGET_RATIO}); "
            f"periodic geometry {row['periodic_geometry_s']:.3f} s once per mesh (free space "
            f"{row['free_space_geometry_s']:.3f} s)"
        )
    if args.json:
        args.json.write_text(json.dumps(doc, indent=2) + "\n", encoding="utf-8")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
