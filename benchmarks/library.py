"""A 19-point reflection-phase library at one frequency on a substrate (issue 33).

The library: a square patch in a 10 mm cell (paper mode, ``--subdivisions`` 8: 128
triangles and 176 unknowns at the largest patch), its size from 5 to 9.5 mm over 19
values, at 10 GHz, normal incidence, on 1.575 mm of ε_r = 2.2 (tan δ 0.0009) over a
ground plane: the issue's own example. Both incident polarisations are solved at every
value (the library is the whole 2 × 2). It runs

* ``here``: :func:`barymesh.mom.reflection_library` in this process, each value's TE and
  TM from one fill and one LU (the compiled fill and the LU on every core);
* ``two_points``: what it did before, each (value, polarisation) a point of its own
  (:func:`barymesh.study.point.solve_point`, two fills per value), in this process;
* ``dask``: ``reflection_library(..., client=client)`` on a ``LocalCluster`` of one
  single-threaded worker process per core (the study engine; 38 points), the cluster
  started first and timed apart.

Each is the best of ``--repeats`` runs (wall and this process's CPU time; the cluster's
workers' CPU is theirs), after one warm-up run of a value (imports, quadrature rules, the
compiled kernels' cache), and the results are checked against each other (to 1e-12 of
max |R|). The machine's load is written beside them.

Usage::

    python benchmarks/library.py --json benchmarks/results/library-2026-12-06.json
    python benchmarks/library.py --quick        # 4 values, no cluster (the test suite)
"""

from __future__ import annotations

import argparse
import json
import os
import time
from typing import Any

import numpy as np
from machine import machine

from barymesh.cell import cell_from_dict
from barymesh.mom import parse_stack, reflection_library

PARAMETER = "elements[0].patch_size"
FREQUENCY = 10e9
SUBSTRATE = "1.575mm eps=2.2 tand=0.0009; ground"


def patch_cell(subdivisions: int, size: float = 7.0) -> Any:
    """The 10 mm cell with one patch, its corner at (−4.75, −4.75) mm (room for 9.5 mm)."""
    return cell_from_dict(
        {
            "format": "barymesh-cell",
            "version": 1,
            "name": "patch",
            "mode": "paper",
            "lattice": {"rectangular": [10.0, 10.0]},
            "elements": [
                {
                    "structure": "patch",
                    "patch_size": size,
                    "subdivisions": subdivisions,
                    "position": [-4.75, -4.75],
                }
            ],
        }
    )


def timed(work: Any, repeats: int) -> tuple[float, float, Any]:
    """(best wall s, best CPU s, the last result) of ``work()``."""
    walls, cpus, out = [], [], None
    for _ in range(repeats):
        w, c = time.perf_counter(), time.process_time()
        out = work()
        cpus.append(time.process_time() - c)
        walls.append(time.perf_counter() - w)
    return min(walls), min(cpus), out


def two_points(cell: Any, values: np.ndarray, stack: Any) -> np.ndarray:
    """R (V, 2, 2) by one point per (value, polarisation), as before (the columns TE, TM
    incidence; each point's table holds R times the incident TE/TM component)."""
    from barymesh.cell import cell_to_dict
    from barymesh.mom.floquet import te_tm_polarizations
    from barymesh.mom.reflection_library import POLARIZATIONS
    from barymesh.study.point import StudyContext, solve_point
    from barymesh.study.spec import Base, Solve

    base = Base("cell", cell_to_dict(cell))
    solve = Solve(
        "infinite_array",
        (FREQUENCY,),
        incidence={"theta": 0.0, "phi": 0.0, "pol": "TM"},
        interpolate=True,
    )
    context = StudyContext(base, solve, (), stack)
    from barymesh.mom import PlaneWave

    out = np.empty((len(values), 2, 2), dtype=complex)
    for i, x in enumerate(values):
        for k, pol in enumerate(POLARIZATIONS):
            p = solve_point(context, 2 * i + k, {PARAMETER: float(x), "incidence.pol": pol})
            if p.status != "ok":
                raise RuntimeError(p.status)
            wave = PlaneWave.from_angles(0.0, 0.0, 90.0 if pol == "TE" else 0.0)
            c = te_tm_polarizations(wave.direction) @ np.asarray(wave.polarization)
            t = p.table
            r = np.array(
                [
                    t["reflection_te_real"][0] + 1j * t["reflection_te_imag"][0],
                    t["reflection_tm_real"][0] + 1j * t["reflection_tm_imag"][0],
                ]
            )
            out[i, :, k] = r / c[k]
    return out


def on_cluster(cell: Any, values: np.ndarray, stack: Any, workers: int, repeats: int):
    """(cluster start-up s, best wall s, the library) on a local process cluster."""
    from distributed import Client, LocalCluster

    start = time.perf_counter()
    with (
        LocalCluster(
            n_workers=workers,
            threads_per_worker=1,
            processes=True,
            host="127.0.0.1",
            dashboard_address="127.0.0.1:0",
        ) as cluster,
        Client(cluster) as client,
    ):
        startup = time.perf_counter() - start
        reflection_library(cell, PARAMETER, values[:workers], FREQUENCY, stack=stack, client=client)
        wall, _cpu, lib = timed(
            lambda: reflection_library(
                cell, PARAMETER, values, FREQUENCY, stack=stack, client=client
            ),
            repeats,
        )
    return startup, wall, lib


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--quick", action="store_true", help="4 values, no cluster, one run")
    ap.add_argument("--json", metavar="OUT", help="write the results as JSON")
    ap.add_argument("--subdivisions", type=int, default=8)
    ap.add_argument("--repeats", type=int, default=3)
    ap.add_argument("--workers", type=int, default=os.cpu_count() or 1)
    args = ap.parse_args(argv)
    count = 4 if args.quick else 19
    repeats = 1 if args.quick else args.repeats
    values = np.linspace(5.0, 9.5, count)
    cell = patch_cell(args.subdivisions)
    stack = parse_stack(SUBSTRATE)
    reflection_library(cell, PARAMETER, values[:1], FREQUENCY, stack=stack)  # warm up
    load_before = os.getloadavg()

    here_wall, here_cpu, lib = timed(
        lambda: reflection_library(cell, PARAMETER, values, FREQUENCY, stack=stack), repeats
    )
    print(f"here        {here_wall:7.3f} s wall, {here_cpu:7.3f} s CPU ({count} values)")
    old_wall, old_cpu, old = timed(lambda: two_points(cell, values, stack), repeats)
    print(f"two points  {old_wall:7.3f} s wall, {old_cpu:7.3f} s CPU")
    scale = float(np.abs(lib.reflection).max())
    differ = float(np.abs(lib.reflection[:, 0] - old).max()) / scale
    if differ > 1e-12:
        raise SystemExit(f"the two ways differ by {differ:.2e} of max |R|")
    rows: dict[str, Any] = {
        "here": {"wall_s": here_wall, "cpu_s": here_cpu, "per_value_s": here_wall / count},
        "two_points": {
            "wall_s": old_wall,
            "cpu_s": old_cpu,
            "per_value_s": old_wall / count,
            "largest_difference_to_here": differ,
        },
    }
    if not args.quick:
        try:
            import distributed  # noqa: F401
        except ImportError:
            print("dask          skipped (no distributed: the study extra)")
        else:
            startup, wall, on_dask = on_cluster(cell, values, stack, args.workers, repeats)
            d = float(np.abs(on_dask.reflection - lib.reflection).max()) / scale
            if d > 1e-12:
                raise SystemExit(f"the cluster's library differs by {d:.2e} of max |R|")
            rows["dask"] = {
                "workers": args.workers,
                "startup_s": startup,
                "wall_s": wall,
                "per_value_s": wall / count,
                "largest_difference_to_here": d,
            }
            print(f"dask        {wall:7.3f} s wall ({args.workers} workers; start {startup:.1f} s)")
    load_after = os.getloadavg()
    covers = float(lib.phase_deg[:, 0].max() - lib.phase_deg[:, 0].min())
    doc = {
        "benchmark": "library",
        "date": time.strftime("%Y-%m-%d"),
        "machine": {**machine(), "load_average_after": list(load_after)},
        "load_average_before": list(load_before),
        "library": {
            "cell": "square patch, 10 mm cell, paper mode",
            "subdivisions": args.subdivisions,
            "parameter": PARAMETER,
            "values_mm": [float(values[0]), float(values[-1]), count],
            "frequency_hz": FREQUENCY,
            "stack": SUBSTRATE,
            "largest_unknowns": _unknowns(args.subdivisions, float(values[-1])),
            "covers_deg": covers,
        },
        "repeats": repeats,
        "rows": rows,
        "speedup_of_one_fill": old_wall / here_wall,
    }
    print(f"one fill for TE and TM: {old_wall / here_wall:.2f}x; the curve covers {covers:.0f}°")
    if args.json:
        with open(args.json, "w") as fh:
            json.dump(doc, fh, indent=1)
            fh.write("\n")
    return 0


def _unknowns(subdivisions: int, size: float) -> int:
    from barymesh.cell import build_cell

    return len(build_cell(patch_cell(subdivisions, size)).mesh.rwg)


if __name__ == "__main__":
    raise SystemExit(main())
