"""Sizing from frequency: what choosing the subdivisions costs, and the statistics it adds.

For each workload a frequency is set whose λ/10 is just above the longest edge at the
workload's n, so the mesher must find that n (it builds the coarsest mesh, the estimate
and n − 1 to prove n minimal). Timed, alternating, ``--reps`` times after a warm-up:
``build_mesh`` without and with the frequency, and ``TriMesh.stats()`` on a fresh mesh
of each (with the frequency it adds λ, edge/λ, the largest area in λ² and the λ/10
rule). Medians and min–max in seconds.

    python benchmarks/sizing.py --reps 5
"""

from __future__ import annotations

import argparse
import statistics
import time

from barymesh import MeshParams, build_mesh
from barymesh.sizing import wavelength

WORKLOADS = {
    "paper double ring, n = 27 (1M)": MeshParams(subdivisions=27),
    "conforming double ring, n = 20 (576k)": MeshParams(
        mode="conforming", angle_step=1.0, subdivisions=20
    ),
}


def _timed(fn):
    start = time.perf_counter()
    out = fn()
    return time.perf_counter() - start, out


def _stats_time(params: MeshParams) -> float:
    mesh = build_mesh(params)
    return _timed(mesh.stats)[0]


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--reps", type=int, default=5)
    args = parser.parse_args()
    for name, plain in WORKLOADS.items():
        longest = build_mesh(plain).stats()["max_edge"]
        sized = plain.replace(frequency=wavelength(1.0) / (10 * longest) * (1 - 1e-9))
        chosen = build_mesh(sized).params.subdivisions
        assert chosen == plain.subdivisions, (chosen, plain.subdivisions)
        times: dict[str, list[float]] = {
            "build": [],
            "sized build": [],
            "stats": [],
            "sized stats": [],
        }
        for _ in range(args.reps):
            times["build"].append(_timed(lambda p=plain: build_mesh(p))[0])
            times["sized build"].append(_timed(lambda p=sized: build_mesh(p))[0])
            times["stats"].append(_stats_time(plain))
            times["sized stats"].append(_stats_time(sized))
        cells = ", ".join(
            f"{k} {statistics.median(v):.3f} ({min(v):.3f}–{max(v):.3f})" for k, v in times.items()
        )
        print(f"{name}: {build_mesh(plain).n_triangles:,} triangles, n = {chosen}: {cells}")


if __name__ == "__main__":
    main()
