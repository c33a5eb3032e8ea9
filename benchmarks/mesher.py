"""Mesher throughput: barymesh against the pipelines users would otherwise assemble.

Every workload is one structure at about 10k, 100k, 1M and 4M triangles. "Ours"
is the whole build from parameters: ``build_mesh`` (points, triangles) plus
centroids, edges, the RWG table with free vertices and the connectivity matrix.

Peer (a), from the same primary triangles (two per patch or sector, corner
coordinates taken from our welded mesh, one unshared copy per patch):
pyvista ``subdivide(k, "linear")`` (4**k sub-triangles per primary, so it
matches our n = 2**k) + ``clean()`` + ``cell_centers()`` + trimesh
``face_adjacency``, ``face_adjacency_unshared``, ``face_adjacency_edges`` + edge
lengths + a scipy CSR connectivity matrix. ``clean()`` merges exactly equal
points ("exact", its fastest configuration, correct here because shared
corners are bitwise equal) and, on the paper ring up to 1M triangles, also
with our weld tolerance ("tol").

The paper double ring is also run at the paper's own n = 4 at 1M and 4M
("paper double ring n=4": tens of thousands of small patches, where the weld,
the layout and the per-patch work dominate instead of the template copy).

The memory-bandwidth bound is measured in the same run, alternating with ours: a numpy
write (``fill``) of as many bytes as the whole build's outputs hold (points, triangles,
centroids, the edge topology, the RWG table, the connectivity matrix), into a buffer
written before ("warm": the machine's write bandwidth, the bound of issue 32) and into a
fresh one ("fresh": with the page faults that allocating new outputs costs, which the
build cannot avoid either). "ours / bound" is our median over the warm write's median;
the JSON also has it in CPU time (``ours_over_warm_cpu``), which other jobs on the machine
distort less. Two floors beside it: "computed", the same bytes of the warm buffer written
as values computed from a cache-resident pattern (one broadcast numpy add, the way a build
writes its tiled outputs; ``fill`` is a memset, whose string or non-temporal stores write
whole cache lines without reading them first, which numpy's arithmetic never does), and the
page faults (minor faults, ``ru_minflt``) of every timed call, ours and the bounds', so a
"fresh" write whose pages the allocator had kept shows as such.
The machine's load average is recorded before and after every workload.

For every workload the statistics are timed too: ``TriMesh.stats()`` (counts,
edge lengths, triangle quality and, in paper mode, the overlap ratio) on a
freshly built mesh, beside ``build_mesh`` alone, alternating.

Peer (b): gmsh's default 2D mesher on the conforming split ring's geometry
(an annulus cut by a straight slot) at a matching triangle count; its minimum
angle is reported beside ours.

Method: warm-up, then ours and the peers alternate (A B A B ...) for
``--reps`` repetitions; medians and min-max are reported. Before timing, the
triangle, welded-vertex and shared-edge counts of ours and peer (a) are
asserted equal. Our peak memory ("MiB", "B/tri") is tracemalloc's peak over
one extra build, exact for numpy buffers. For the peers, whose C++
allocations tracemalloc cannot see, the note gives the growth of the
process's peak resident set (``VmHWM``, reset through
``/proc/self/clear_refs``) during one extra run, beside ours measured the
same way.

Usage::

    python benchmarks/mesher.py                      # all sizes, table on stdout
    python benchmarks/mesher.py --sizes 10k,100k --reps 3 --json out.json
    python benchmarks/mesher.py --quick              # smallest size, 2 reps (tests)
    python benchmarks/mesher.py --stats-only --sizes 1M,4M  # build_mesh vs stats() only
"""

from __future__ import annotations

import argparse
import dataclasses
import gc
import json
import math
import os
import platform
import resource
import statistics
import subprocess
import sys
import time
import tracemalloc
from collections.abc import Callable
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np
import scipy.sparse as sp

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))
sys.path.insert(0, str(Path(__file__).resolve().parent))

from gmsh_peer import Gmsh, split_ring_fields  # noqa: E402

from barymesh import MeshParams, build_mesh  # noqa: E402
from barymesh.quality import triangle_quality  # noqa: E402
from barymesh.repeat import compiled  # noqa: E402
from barymesh.structures import layout  # noqa: E402

SIZES = ("10k", "100k", "1M", "4M")

#: (subdivisions, angle_step) of the paper's double ring (inner 4, outer 9, patch 1 mm).
RING = {"10k": (4, 2.5), "100k": (8, 0.9), "1M": (16, 0.36), "4M": (32, 0.36)}
#: (subdivisions, angle_step) of the same ring at the paper's n = 4: many small patches.
RING_N4 = {"1M": (4, 0.02304), "4M": (4, 0.00576)}
#: (subdivisions, inner_radius, outer_radius, angle_step) of the conforming double ring
#: (patch 1 mm). Its sectors are n cells across the track by n_v along it, nearly square,
#: so the triangle count grows with the rings' length in tracks, not with n² / angle_step:
#: 9,600, 105,984, 982,016 and 3,928,064 triangles.
CONFORMING = {
    "10k": (6, 4.0, 9.0, 0.9),
    "100k": (16, 12.0, 20.0, 0.9),
    "1M": (32, 30.0, 44.0, 0.9),
    "4M": (64, 30.0, 44.0, 0.9),
}
#: (subdivisions, patch_size) of the square patch array (square split double ring).
ARRAY = {"10k": (4, 0.25), "100k": (8, 0.125), "1M": (16, 0.05), "4M": (32, 0.05)}
#: The tolerance variant of peer (a) is ~8x slower; run it up to this size.
TOL_SIZES = ("10k", "100k", "1M")
#: gmsh takes about a minute per million triangles here; 4M only on request.
GMSH_SIZES = ("10k", "100k", "1M")
#: Most repetitions of the slow peers (a-tol, gmsh at 1M and more).
SLOW_REPS = 3
#: Words (int32) of the "computed" bound's pattern: 64 KiB, which stays in cache.
COMPUTED_BLOCK = 1 << 14


@dataclass
class Workload:
    name: str
    size: str
    params: MeshParams
    peers: list[str]
    results: dict = field(default_factory=dict)


def workloads(sizes: list[str], gmsh_sizes: list[str]) -> list[Workload]:
    out = []
    for size in sizes:
        n, step = RING[size]
        peers = ["a-exact"] + (["a-tol"] if size in TOL_SIZES else [])
        out.append(
            Workload(
                "paper double ring",
                size,
                MeshParams(structure="double_ring", mode="paper", subdivisions=n, angle_step=step),
                peers,
            )
        )
        if size in RING_N4:
            n4, step4 = RING_N4[size]
            out.append(
                Workload(
                    "paper double ring n=4",
                    size,
                    MeshParams(
                        structure="double_ring", mode="paper", subdivisions=n4, angle_step=step4
                    ),
                    ["a-exact"],
                )
            )
        n, inner, outer, step = CONFORMING[size]
        out.append(
            Workload(
                "conforming double ring",
                size,
                MeshParams(
                    structure="double_ring",
                    mode="conforming",
                    subdivisions=n,
                    inner_radius=inner,
                    outer_radius=outer,
                    angle_step=step,
                ),
                [],  # sectors of n x n_v cells: no subdivision of primary triangles matches them
            )
        )
        n, h = ARRAY[size]
        out.append(
            Workload(
                "square patch array",
                size,
                MeshParams(
                    structure="square_split_double_ring",
                    mode="paper",
                    subdivisions=n,
                    patch_size=h,
                    gap_width=1.0,
                ),
                ["a-exact"],
            )
        )
        if size in gmsh_sizes:  # sectors about as long as they are wide (gmsh_peer.SPLIT)
            params = MeshParams(**split_ring_fields(size))
            out.append(Workload("conforming split ring", size, params, ["gmsh"]))
    return out


# -- ours ------------------------------------------------------------------


def with_compiled_loops(func: Callable[[], dict]) -> dict:
    """``func()`` with the mesher's compiled loops asked for (:mod:`barymesh.repeat.compiled`)."""
    before = os.environ.get(compiled.BACKEND_VARIABLE)
    os.environ[compiled.BACKEND_VARIABLE] = compiled.COMPILED
    try:
        return func()
    finally:
        if before is None:
            del os.environ[compiled.BACKEND_VARIABLE]
        else:
            os.environ[compiled.BACKEND_VARIABLE] = before


def ours(params: MeshParams) -> dict:
    """The whole build: mesh, centroids, edges, RWG table, connectivity."""
    mesh = build_mesh(params)
    mesh.centroids  # noqa: B018
    rwg = mesh.rwg  # needs the edges (topology)
    conn = mesh.connectivity
    return {
        "mesh": mesh,
        "triangles": mesh.n_triangles,
        "vertices": mesh.n_vertices,
        "shared_edges": len(rwg),
        "edges": len(mesh.edges),
        "nnz": conn.nnz,
    }


# -- peer (a): pyvista + trimesh + scipy -------------------------------------


def primary_triangles(params: MeshParams):
    """Our primary triangles as a pyvista PolyData, with the subdivision level k."""
    import pyvista as pv

    lay = layout(params)
    t = lay.template
    if not t.lattice or t.segments & (t.segments - 1):
        raise ValueError(f"subdivisions={t.segments} is not a power of two: VTK cannot match it")
    corner = [
        int(np.flatnonzero((np.abs(t.uv - c) < 1e-12).all(axis=1))[0])
        for c in ([0, 0], [1, 0], [0, 1], [1, 1])
    ]
    flat = lay.xy.reshape(-1, 2)
    welded = flat[lay.representative][lay.vertex_of_point].reshape(len(lay.xy), -1, 2)
    corners = welded[:, corner].reshape(-1, 2)  # A, B, C, D of every patch
    points = np.zeros((len(corners), 3))
    points[:, :2] = corners
    base = (np.arange(len(lay.xy)) * 4)[:, None]
    if params.diagonal == "BC":
        faces = np.concatenate([base + [0, 1, 2], base + [3, 2, 1]], axis=1)
    else:
        faces = np.concatenate([base + [0, 1, 3], base + [0, 3, 2]], axis=1)
    k = int(round(math.log2(t.segments)))
    return pv.PolyData.from_regular_faces(points, faces.reshape(-1, 3)), k


def peer_a(poly, k: int, tolerance: float | None) -> dict:
    """pyvista subdivide + clean + cell_centers, trimesh adjacency, scipy CSR."""
    import trimesh

    sub = poly.subdivide(k, "linear")
    mesh = sub.clean(tolerance=tolerance) if tolerance else sub.clean()
    centres = mesh.cell_centers().points
    faces = mesh.regular_faces
    tm = trimesh.Trimesh(vertices=mesh.points, faces=faces, process=False, validate=False)
    adjacency = tm.face_adjacency  # (N, 2) triangles on each shared edge
    free = tm.face_adjacency_unshared  # (N, 2) their free vertices
    edges = tm.face_adjacency_edges  # (N, 2) the shared edges' vertices
    v = tm.vertices
    length = np.linalg.norm(v[edges[:, 1]] - v[edges[:, 0]], axis=1)
    n = len(faces)
    rows = np.concatenate([adjacency[:, 0], adjacency[:, 1]])
    cols = np.concatenate([adjacency[:, 1], adjacency[:, 0]])
    conn = sp.csr_matrix((np.ones(len(rows), dtype=np.int8), (rows, cols)), shape=(n, n))
    del centres, free, length
    return {
        "triangles": n,
        "vertices": mesh.n_points,
        "shared_edges": len(adjacency),
        "nnz": conn.nnz,
    }


# -- measurement -----------------------------------------------------------------


def _status_kib(key: str) -> int:
    with open("/proc/self/status") as f:
        for line in f:
            if line.startswith(key + ":"):
                return int(line.split()[1])
    raise KeyError(key)


def output_bytes(mesh) -> int:
    """Bytes held by the whole build's outputs: what a write at full bandwidth must cover.

    Points, triangles, centroids, the edge topology (every array of
    :class:`barymesh.topology.EdgeTopology`), the RWG table (every array of
    :class:`barymesh.topology.RWGTable`) and the connectivity matrix (data,
    indices, row pointers). Patch ids and regions are left out (the issue's list).
    """
    arrays = [mesh.points, mesh.triangles, mesh.centroids]
    for part in (mesh.topology, mesh.rwg):
        arrays += [getattr(part, f.name) for f in dataclasses.fields(part)]
    conn = mesh.connectivity
    arrays += [conn.data, conn.indices, conn.indptr]
    return int(sum(np.asarray(a).nbytes for a in arrays))


def bound_runners(nbytes: int) -> dict[str, Callable[[], object]]:
    """The bandwidth bounds: ``nbytes`` written into a warm buffer, into a fresh one, computed.

    The warm buffer is written once here, so that its pages exist and the timed
    write is the machine's bandwidth alone; the fresh one is allocated for each
    write, page faults and all, as the build's outputs are. "Computed" writes the
    warm buffer's words as a pattern of :data:`COMPUTED_BLOCK` words (kept in cache)
    plus a shift per row, in one broadcast add: ordinary stores, as every output the build
    computes is written, where ``fill`` is a memset. Whole blocks only: the last partial
    one (under 64 KiB, 4 % of the bytes at 10k, nothing to speak of at 1M) is left out.
    """
    warm = np.empty(nbytes, dtype=np.uint8)
    warm.fill(1)
    block = min(nbytes // 4, COMPUTED_BLOCK)
    rows = (nbytes // 4) // block
    words = warm[: rows * block * 4].view(np.int32).reshape(rows, block)
    pattern = np.arange(block, dtype=np.int32)
    shifts = (np.arange(rows, dtype=np.int32) * np.int32(block))[:, None]

    def fresh() -> None:
        np.empty(nbytes, dtype=np.uint8).fill(1)

    def computed() -> None:  # one broadcast add: the pattern's rows from cache, each shifted
        np.add(pattern, shifts, out=words)

    return {"bound-warm": lambda: warm.fill(1), "bound-fresh": fresh, "bound-computed": computed}


def alone(params: MeshParams, reps: int) -> dict:
    """Our whole build in a new process that does nothing else: its first build, then ``reps``.

    In the benchmark's own process the peers' allocations leave the C allocator holding
    memory, so our outputs land in pages that exist already (no faults); a script or
    ``barymesh mesh`` that only builds gets pages the allocator handed back to the
    kernel and faults them in again (about 14,000 faults per 1M build here). The first
    build also makes the template and its plans and loads the code.
    """
    child = (
        "import json, sys; sys.path[:0] = sys.argv[3:]; import mesher; "
        "print(json.dumps(mesher.alone_child(json.loads(sys.argv[1]), int(sys.argv[2]))))"
    )
    here = Path(__file__).resolve().parent
    proc = subprocess.run(
        [
            sys.executable,
            "-c",
            child,
            json.dumps(params.to_dict()),
            str(reps),
            str(here.parent),
            str(here),
        ],
        capture_output=True,
        text=True,
        check=False,
    )
    if proc.returncode != 0:
        raise RuntimeError(f"the build alone failed ({proc.returncode}):\n{proc.stderr[-3000:]}")
    return json.loads(proc.stdout)


def alone_child(params: dict, reps: int) -> dict:
    """:func:`alone`'s child: the first build, then ``reps`` timed ones with their faults."""
    p = MeshParams.from_dict(params)
    first = timed(lambda: ours(p))
    runs = [timed(lambda: ours(p)) for _ in range(reps)]
    out = summary(*(list(column) for column in zip(*runs, strict=True)))
    out["first"] = {"wall": first[0], "cpu": first[1], "faults": first[2]}
    return out


def load() -> list[float] | None:
    """The 1, 5 and 15 minute load averages, or None where the system does not say."""
    try:
        return [round(x, 2) for x in os.getloadavg()]
    except OSError:
        return None


def peak_traced_mib(func: Callable[[], object]) -> float:
    """Peak of Python and numpy allocations (MiB) while ``func`` runs (tracemalloc).

    numpy reports its array buffers to tracemalloc, so this is exact for our
    pure-numpy build; it does not see C++ allocations such as VTK's.
    """
    gc.collect()
    tracemalloc.start()
    try:
        result = func()
        peak = tracemalloc.get_traced_memory()[1]
    finally:
        tracemalloc.stop()
    del result
    return peak / 2**20


def peak_rss_mib(func: Callable[[], object]) -> float | None:
    """Growth of the peak resident set (MiB) while ``func`` runs, or None off Linux.

    Sees every allocation (numpy, VTK, gmsh), but pages the allocator kept
    from earlier runs are reused unseen, so it is a lower bound.
    """
    gc.collect()
    try:
        with open("/proc/self/clear_refs", "w") as f:
            f.write("5")  # reset VmHWM to the current resident set
        before = _status_kib("VmRSS")
    except (OSError, KeyError):
        return None
    result = func()
    peak = _status_kib("VmHWM") - before
    del result
    return peak / 1024


def minor_faults() -> int:
    """Minor page faults of this process so far (pages it touched for the first time)."""
    return resource.getrusage(resource.RUSAGE_SELF).ru_minflt


def timed(func: Callable[[], object]) -> tuple[float, float, int]:
    """Wall and CPU seconds and page faults of one call.

    CPU time is what a loaded machine distorts least; the faults say how many of the
    call's pages were new to the process (about 2.5 µs each on a virtual machine).
    """
    gc.collect()
    f0 = minor_faults()
    c0, t0 = time.process_time(), time.perf_counter()
    func()
    wall, used = time.perf_counter() - t0, time.process_time() - c0
    return wall, used, minor_faults() - f0


def time_stats(params: MeshParams, reps: int) -> tuple[dict, dict]:
    """``build_mesh`` alone and ``stats()`` on the fresh mesh, alternating (after a warm-up)."""
    build_mesh(params).stats()
    builds, stats = [], []
    for _ in range(reps):
        gc.collect()
        t0 = time.perf_counter()
        mesh = build_mesh(params)
        t1 = time.perf_counter()
        mesh.stats()
        t2 = time.perf_counter()
        builds.append(t1 - t0)
        stats.append(t2 - t1)
        del mesh
    return summary(builds), summary(stats)


def summary(
    times: list[float], cpu: list[float] | None = None, faults: list[int] | None = None
) -> dict:
    out = {
        "median": statistics.median(times),
        "min": min(times),
        "max": max(times),
        "times": times,
    }
    if cpu:
        out["cpu_median"] = statistics.median(cpu)
        out["cpu_times"] = cpu
    if faults:
        out["faults_median"] = statistics.median(faults)
        out["faults"] = faults
    return out


def run_workload(w: Workload, reps: int) -> None:
    p = w.params
    w.results["load_before"] = load()
    runners: dict[str, Callable[[], object]] = {"ours": lambda: ours(p)}
    check = ours(p)
    if check["triangles"] >= compiled.MIN_TRIANGLES and compiled.warm_up() > 0:
        # the opt-in compiled loops (BARYMESH_MESH_KERNELS=numba), alternating with the
        # default numpy paths; their one-time load (numba and the cached loops) is left out
        runners["ours-numba"] = lambda: with_compiled_loops(lambda: ours(p))
    mesh = check.pop("mesh")
    nbytes = output_bytes(mesh)
    bounds = bound_runners(nbytes)
    w.results["triangles"] = check["triangles"]
    w.results["vertices"] = check["vertices"]
    w.results["shared_edges"] = check["shared_edges"]
    peer_reps = {}
    for peer in w.peers:
        if peer.startswith("a-"):
            poly, k = primary_triangles(p)
            tol = p.weld_tolerance if peer == "a-tol" else None
            got = peer_a(poly, k, tol)
            for key in ("triangles", "vertices", "shared_edges", "nnz"):
                if got[key] != check[key]:
                    raise AssertionError(
                        f"{w.name} {w.size}: peer {peer} gives {key}={got[key]}, ours {check[key]}"
                    )
            runners[peer] = lambda poly=poly, k=k, tol=tol: peer_a(poly, k, tol)
            peer_reps[peer] = min(reps, SLOW_REPS) if peer == "a-tol" else reps
        elif peer == "gmsh":
            g = Gmsh(p, check["triangles"])
            nodes, tris = g.run()  # also gmsh's warm-up
            w.results["gmsh_triangles"] = len(tris)
            gmsh_angles = triangle_quality(nodes, tris).min_angles_deg
            w.results["gmsh_min_angle_deg"] = float(gmsh_angles.min())
            w.results["ours_min_angle_deg"] = float(mesh.min_angles.min())
            runners[peer] = g.run
            peer_reps[peer] = min(reps, SLOW_REPS) if len(tris) > 200_000 else reps
    del mesh, check
    timers = {**runners, **bounds}
    for name in [*bounds, "ours-numba"]:
        peer_reps[name] = reps
    times: dict[str, list[float]] = {name: [] for name in timers}
    cpu: dict[str, list[float]] = {name: [] for name in timers}
    faults: dict[str, list[int]] = {name: [] for name in timers}
    for name, func in timers.items():  # warm-up
        if name != "gmsh":
            func()
    for rep in range(reps):  # alternate: ours, peer, bounds, ours, peer, bounds ...
        for name, func in timers.items():
            if name == "ours" or rep < peer_reps[name]:
                wall, used, touched = timed(func)
                times[name].append(wall)
                cpu[name].append(used)
                faults[name].append(touched)
    for name in runners:
        w.results[name] = summary(times[name], cpu[name], faults[name])
    warm, fresh, computed = (summary(times[k], cpu[k], faults[k]) for k in bounds)
    w.results["bound"] = {
        "bytes": nbytes,
        "warm": warm,
        "fresh": fresh,
        "computed": computed,
        "warm_gb_per_s": nbytes / warm["median"] / 1e9,
        "ours_over_warm": w.results["ours"]["median"] / warm["median"],
        # CPU time: what a loaded machine distorts least (a descheduled write's wall time
        # grows while its CPU time does not)
        "ours_over_warm_cpu": w.results["ours"]["cpu_median"] / warm["cpu_median"],
        "ours_over_fresh": w.results["ours"]["median"] / fresh["median"],
        "ours_over_computed": w.results["ours"]["median"] / computed["median"],
        # the floors, in units of the bound
        "fresh_over_warm": fresh["median"] / warm["median"],
        "computed_over_warm": computed["median"] / warm["median"],
    }
    if "ours-numba" in runners:
        w.results["bound"]["numba_over_warm"] = w.results["ours-numba"]["median"] / warm["median"]
        w.results["bound"]["numba_over_warm_cpu"] = (
            w.results["ours-numba"]["cpu_median"] / warm["cpu_median"]
        )
    w.results["ours-alone"] = alone(p, reps)
    w.results["build_mesh"], w.results["stats"] = time_stats(p, reps)
    for name in w.peers:
        w.results[name]["ratio"] = w.results[name]["median"] / w.results["ours"]["median"]
    mib = peak_traced_mib(runners["ours"])
    w.results["ours"]["peak_mib"] = mib
    w.results["ours"]["bytes_per_triangle"] = mib * 2**20 / w.results["triangles"]
    for name, func in runners.items():  # gmsh's memory is not of interest here
        w.results[name]["peak_rss_mib"] = None if name == "gmsh" else peak_rss_mib(func)
    w.results["load_after"] = load()


# -- output ------------------------------------------------------------------------


def _span(s: dict) -> str:
    return f"{s['median']:8.3f} ({s['min']:.3f}-{s['max']:.3f})"


def table(ws: list[Workload]) -> str:
    head = (
        f"{'workload':23} {'size':>4} {'triangles':>9} {'ours s (min-max)':>23} "
        f"{'MiB':>6} {'B/tri':>5} {'bound s':>7} {'/bound':>6}  "
        f"{'peer':7} {'peer s (min-max)':>25} {'ratio':>6}  note"
    )
    lines = [head, "-" * len(head)]
    for w in ws:
        r = w.results
        o = r["ours"]
        b = r["bound"]
        ours_cols = (
            f"{w.name:23} {w.size:>4} {r['triangles']:>9} {_span(o):>23} "
            f"{o['peak_mib']:6.1f} {o['bytes_per_triangle']:5.0f} "
            f"{b['warm']['median']:7.4f} {b['ours_over_warm']:6.1f}"
        )
        bound_note = (
            f"{b['bytes'] / 1e6:.0f} MB at {b['warm_gb_per_s']:.1f} GB/s, "
            f"CPU {b['ours_over_warm_cpu']:.1f}x the bound, fresh "
            f"{b['fresh_over_warm']:.1f}x ({b['fresh']['faults_median']:.0f} faults), computed "
            f"{b['computed_over_warm']:.1f}x, ours {o['faults_median']:.0f} faults, alone "
            f"{r['ours-alone']['median']:.3f} s ({r['ours-alone']['faults_median']:.0f} faults, "
            f"first {r['ours-alone']['first']['wall']:.3f} s); "
            f"load {r['load_before']} -> {r['load_after']}"
        )
        if not w.peers:  # the conforming ring's n x n_v sectors: no peer (a) builds them
            lines.append(f"{ours_cols}  {'-':7} {'-':>25} {'-':>6}  no peer; {bound_note}")
        for i, peer in enumerate(w.peers):
            s = r[peer]
            note = ""
            if s["peak_rss_mib"] is not None:
                note = f"RSS +{s['peak_rss_mib']:.0f} MiB vs ours +{o['peak_rss_mib']:.0f}"
            if peer == "gmsh":
                note += (
                    f"; gmsh {r['gmsh_triangles']:,} tri, min angle "
                    f"{r['gmsh_min_angle_deg']:.1f} vs ours {r['ours_min_angle_deg']:.1f} deg"
                )
            left = ours_cols if i == 0 else " " * len(ours_cols)
            note = note.removeprefix("; ")
            if i == 0:
                note = f"{note}; {bound_note}".removeprefix("; ")
            lines.append(f"{left}  {peer:7} {_span(s):>25} {s['ratio']:6.1f}  {note}")
    return "\n".join(lines)


def stats_table(ws: list[Workload]) -> str:
    head = (
        f"{'workload':23} {'size':>4} {'triangles':>9} {'build_mesh s (min-max)':>23} "
        f"{'stats() s (min-max)':>23} {'ratio':>6}  target (issue 9: ratio <= 1)"
    )
    lines = [head, "-" * len(head)]
    for w in ws:
        r = w.results
        b, s = r["build_mesh"], r["stats"]
        lines.append(
            f"{w.name:23} {w.size:>4} {r['triangles']:>9} {_span(b):>23} {_span(s):>23} "
            f"{s['median'] / b['median']:6.2f}  "
            f"{'met' if s['median'] <= b['median'] else 'not met'}"
        )
    return "\n".join(lines)


def machine() -> dict:
    cpu = platform.processor()
    try:
        with open("/proc/cpuinfo") as f:
            cpu = next(line.split(":", 1)[1].strip() for line in f if line.startswith("model name"))
    except (OSError, StopIteration):
        pass
    return {
        "cpu": cpu,
        "cores": os.cpu_count(),
        "load_average": (load() or [None])[0],
        "python": platform.python_version(),
        "numpy": np.__version__,
    }


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--sizes", default=",".join(SIZES), help=f"comma list from {SIZES}")
    ap.add_argument("--reps", type=int, default=5, help="timed repetitions (default 5)")
    ap.add_argument("--quick", action="store_true", help="smallest size, 2 repetitions")
    ap.add_argument("--no-gmsh", action="store_true", help="skip peer (b)")
    ap.add_argument(
        "--gmsh-sizes",
        default=",".join(GMSH_SIZES),
        help="sizes at which to run peer (b) (default: up to 1M; 4M takes minutes per run)",
    )
    ap.add_argument(
        "--stats-only",
        action="store_true",
        help="time only build_mesh against stats() (no peers, no whole build)",
    )
    ap.add_argument("--json", type=Path, help="also write the results here")
    args = ap.parse_args(argv)
    sizes = ["10k"] if args.quick else [s.strip() for s in args.sizes.split(",") if s.strip()]
    reps = 2 if args.quick else args.reps
    unknown = [s for s in sizes if s not in SIZES]
    if unknown:
        ap.error(f"--sizes: unknown {unknown}; expected some of {', '.join(SIZES)}")
    if reps < 1:
        ap.error(f"--reps={reps}: expected at least 1")
    gmsh_sizes = [s.strip() for s in args.gmsh_sizes.split(",") if s.strip()]
    unknown = [s for s in gmsh_sizes if s not in SIZES]
    if unknown:
        ap.error(f"--gmsh-sizes: unknown {unknown}; expected some of {', '.join(SIZES)}")
    gmsh_sizes = [] if args.no_gmsh else [s for s in gmsh_sizes if s in sizes]
    if gmsh_sizes:
        try:
            import gmsh  # noqa: F401
        except ImportError:
            print("gmsh is not installed: skipping peer (b)", file=sys.stderr)
            gmsh_sizes = []
    ws = workloads(sizes, gmsh_sizes)
    load_at_start = load()
    if args.stats_only:
        for w in ws:
            print(f"timing stats() of {w.name} {w.size} ...", file=sys.stderr, flush=True)
            w.results["triangles"] = build_mesh(w.params).n_triangles
            w.results["build_mesh"], w.results["stats"] = time_stats(w.params, reps)
        print(stats_table(ws))
        return 0
    for w in ws:
        print(f"running {w.name} {w.size} ...", file=sys.stderr, flush=True)
        run_workload(w, reps)
        print("\n".join(table([w]).splitlines()[2:]), file=sys.stderr, flush=True)
    print(table(ws))
    print()
    print(stats_table(ws))
    info = machine()
    print(f"\n{info['cores']} cores, {info['cpu']}, Python {info['python']}, numpy {info['numpy']}")
    if args.json:
        doc = {
            "date": time.strftime("%Y-%m-%d", time.gmtime()),
            "load_at_start": load_at_start,
            "load_at_end": load(),
            "machine": info,
            "reps": reps,
            "workloads": [
                {"name": w.name, "size": w.size, "params": w.params.to_dict(), **w.results}
                for w in ws
            ],
        }
        args.json.write_text(json.dumps(doc, indent=2))
    return 0


if __name__ == "__main__":
    sys.exit(main())
