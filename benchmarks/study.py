"""A 64-point design study on the local Dask cluster against the serial loop (issue 20).

The study: the OpenModes split ring (``srr-openmodes``, 20° sectors: 144 triangles, 178
unknowns), inner radius × gap width, 8 × 8 points, 11 frequencies from 4 to 9 GHz. It runs

* ``serial``: :func:`barymesh.study.run_serial`, point after point in this process (BLAS
  may use every core here);
* ``processes``: :func:`barymesh.study.run` on a ``LocalCluster`` of one single-threaded
  worker process per core (the default of ``barymesh study``), the cluster started first
  and timed apart;
* ``threads``: the same with the workers as threads of this process (``--threads``).

The speed-up is the serial time over the cluster's (the target: 1.7 on 2 cores). The
scheduler's overhead per task is measured with empty tasks on the process cluster, and the
data per task is the pickled size of what a task is sent (the point's values; the shared
context is scattered once) and what it sends back (its :class:`PointResult`).

Usage::

    python benchmarks/study.py --json benchmarks/results/study-2026-12-02.json
    python benchmarks/study.py --quick          # 4 points, 3 frequencies (the test suite)
"""

from __future__ import annotations

import argparse
import json
import os
import pickle
import platform
import subprocess
import sys
import time
from pathlib import Path
from typing import Any

import numpy as np

from barymesh.presets import load_preset
from barymesh.study import parse_spec, run, run_serial
from barymesh.study.point import StudyContext


def study_spec(side: int, frequencies: int) -> dict[str, Any]:
    """``side`` x ``side`` points of the coarse split ring."""
    base = {**load_preset("srr-openmodes")[0].to_dict(), "angle_step": 20.0}
    return {
        "base": {"params": base},
        "axes": {
            "inner_radius": [float(v) for v in np.linspace(3.0, 3.4, side)],
            "gap_width": [float(v) for v in np.linspace(0.5, 1.2, side)],
        },
        "solve": {
            "kind": "free_space",
            "frequencies": f"4GHz:9GHz:{frequencies}",
            "direction": [0, 0, -1],
            "polarization": [0, 1, 0],
        },
        "derive": ["resonance_frequency", "quality_factor", "bandwidth_3db"],
    }


def timed_serial(spec: Any) -> tuple[float, Any]:
    """Seconds of :func:`run_serial` over ``spec`` (after one point to warm up), and its result."""
    from barymesh.study.point import solve_point

    solve_point(StudyContext.of(spec), 0, spec.points()[0])  # imports, quadrature rules
    start = time.perf_counter()
    result = run_serial(spec)
    return time.perf_counter() - start, result


def single_blas_thread(argv: list[str]) -> float:
    """The serial loop in a new process with one BLAS thread, as a Dask worker has."""
    env = {**os.environ, "OPENBLAS_NUM_THREADS": "1", "OMP_NUM_THREADS": "1"}
    env["MKL_NUM_THREADS"] = "1"
    keep = [a for a in argv if a == "--quick"]
    out = subprocess.run(
        [sys.executable, __file__, "--serial-only", *keep],
        env=env,
        capture_output=True,
        text=True,
        check=True,
    ).stdout
    return float(json.loads(out.strip().splitlines()[-1])["serial_s"])


def _warm_up(spec: Any) -> None:
    from barymesh.study.point import solve_point

    solve_point(StudyContext.of(spec), 0, spec.points()[0])


def _noop(x: int) -> int:
    return x


def scheduler_overhead(client: Any, n: int) -> dict[str, float]:
    """Seconds per empty task (submit to result) and the tasks per second, ``n`` tasks."""
    client.gather(client.map(_noop, range(20), pure=False))  # warm up
    start = time.perf_counter()
    client.gather(client.map(_noop, range(n), pure=False))
    seconds = time.perf_counter() - start
    return {"tasks": n, "seconds": seconds, "per_task_s": seconds / n, "tasks_per_s": n / seconds}


def cluster_run(spec: Any, processes: bool, workers: int, empty_tasks: int) -> dict[str, Any]:
    import dask
    from distributed import Client, LocalCluster

    from barymesh.study.run import MALLOC_TRIM, WORKER_TRIM_THRESHOLD

    start = time.perf_counter()
    with (
        dask.config.set({MALLOC_TRIM: str(WORKER_TRIM_THRESHOLD)}),  # as barymesh study does
        LocalCluster(
            n_workers=workers,
            threads_per_worker=1,
            processes=processes,
            dashboard_address="127.0.0.1:0",
            **({"host": "127.0.0.1"} if processes else {}),  # threads talk in-process
        ) as cluster,
        Client(cluster) as client,
    ):
        startup = time.perf_counter() - start
        client.gather(client.map(_noop, range(workers), pure=False))
        client.run(_warm_up, spec)  # each worker as the serial loop: imports, quadrature rules
        start = time.perf_counter()
        result = run(spec, client, resume=False)
        seconds = time.perf_counter() - start
        overhead = scheduler_overhead(client, empty_tasks) if processes else None
    return {
        "startup_s": startup,
        "seconds": seconds,
        "result": result,
        "overhead": overhead,
    }


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--quick", action="store_true", help="4 points, 3 frequencies")
    ap.add_argument("--json", metavar="OUT", help="write the results as JSON")
    ap.add_argument("--workers", type=int, default=os.cpu_count() or 1)
    ap.add_argument("--no-threads", action="store_true", help="skip the thread-worker run")
    ap.add_argument("--serial-only", action="store_true", help=argparse.SUPPRESS)
    args = ap.parse_args(argv)
    side, freqs, empty = (2, 3, 50) if args.quick else (8, 11, 1000)
    spec = parse_spec(study_spec(side, freqs))
    n = len(spec.points())
    if args.serial_only:  # the serial loop alone, in a process of its own (one BLAS thread)
        print(json.dumps({"serial_s": timed_serial(spec)[0]}))
        return 0
    load_before = os.getloadavg()
    print(f"{n} points x {freqs} frequencies, {args.workers} workers; load {load_before[0]:.2f}")

    from barymesh.study.point import solve_point

    serial_s, serial = timed_serial(spec)
    serial_all = serial_s
    print(f"serial      {serial_s:8.2f} s  ({serial_s / n:.3f} s per point, BLAS on all cores)")
    one = single_blas_thread(argv or [])
    print(f"serial      {one:8.2f} s  ({one / n:.3f} s per point, one BLAS thread)")
    serial_s = min(serial_s, one)  # the speed-up against the faster serial loop
    rows: dict[str, Any] = {}
    overhead: dict[str, float] = {}
    kinds = [("processes", True)] + ([] if args.no_threads else [("threads", False)])
    for name, processes in kinds:
        r = cluster_run(spec, processes, args.workers, empty)
        physical = ["extinction_cross_section_m2", "scattering_cross_section_m2"]
        a = r["result"].table[physical].to_numpy()  # (the residual is rounding noise)
        b = serial.table[physical].to_numpy()
        scale = np.max(np.where(np.isfinite(b), np.abs(b), 0.0), axis=0)
        with np.errstate(invalid="ignore"):
            rel = np.abs(a - b) / np.where(scale > 0, scale, 1.0)
        differ = float(np.max(rel[np.isfinite(rel)], initial=0.0))
        rows[name] = {
            "startup_s": r["startup_s"],
            "seconds": r["seconds"],
            "speedup": serial_s / r["seconds"],
            "seconds_per_point": r["seconds"] / n,
            # BLAS has one thread per worker, all cores in the serial loop: the last bits
            "largest_difference_to_serial": differ,
        }
        print(
            f"{name:11s} {r['seconds']:8.2f} s  speed-up {serial_s / r['seconds']:.2f}x "
            f"(cluster start {r['startup_s']:.1f} s)"
        )
        if r["overhead"] is not None:
            overhead = r["overhead"]
            rows[name]["scheduler_overhead"] = overhead
            print(
                f"  scheduler: {overhead['per_task_s'] * 1e3:.2f} ms per empty task, "
                f"{overhead['tasks_per_s']:.0f} tasks/s"
            )
    point = serial.spec.points()[0]
    sent = len(pickle.dumps((0, point)))
    context = len(pickle.dumps(StudyContext.of(spec)))
    sample = solve_point(StudyContext.of(spec), 0, point)
    returned = len(pickle.dumps(sample))
    print(f"data per task: {sent} B sent, {returned} B back; context {context} B (scattered once)")
    load_after = os.getloadavg()
    doc = {
        "benchmark": "study",
        "date": time.strftime("%Y-%m-%d"),
        "machine": {
            "cpus": os.cpu_count(),
            "platform": platform.platform(),
            "python": platform.python_version(),
            "load_average_before": list(load_before),
            "load_average_after": list(load_after),
        },
        "study": {
            "points": n,
            "frequencies": freqs,
            "unknowns": sample.unknowns,
            "workers": args.workers,
        },
        "serial_all_cores_blas_s": serial_all,
        "serial_one_blas_thread_s": one,
        "serial_s": serial_s,
        "serial_s_per_point": serial_s / n,
        **rows,
        "scheduler_overhead": overhead,
        "data_per_task_bytes": {"sent": sent, "returned": returned, "context_scattered": context},
    }
    if args.json:
        Path(args.json).write_text(json.dumps(doc, indent=2) + "\n")
        print(f"wrote {args.json}")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
