"""Speed and accuracy of the MoM solver (barymesh.mom) against a Makarov-style fill.

The reference point is a straightforward vectorised numpy version of the
scheme of S. N. Makarov's MATLAB codes (``rwg1``–``rwg5``, *Antenna and EM
Modeling with MATLAB*, 2002), written here for the comparison: each
triangle cut into 9 sub-triangles; the potential from the centroid of one
triangle to the 9 sub-centroids of another; the k-th ρ of one triangle
paired with the k-th ρ of the other; no singularity treatment; the
excitation sampled at the centroids. Accuracy is measured against a
converged solve of the same mesh (barymesh.mom with its highest rules).

Workloads (each solver on the same machine in the same run, the two alternating):

* ``plate 736``: Makarov's platefine, 736 unknowns, 300 MHz: fill + solve, cold.
* ``plate 1408``, ``plate 3008``, ``plate 5985``: the same 1 m plate at n = 22, 32 and 45
  (968, 2,048 and 4,050 triangles), 300 MHz, with our time split into the per-mesh
  geometry, the fill and the LU (a second cold run), the fill both compiled (numba, the
  default) and numpy (the reference), in wall and CPU time.
* ``plate 9976`` (n = 58): our geometry, compiled fill and LU only (the Makarov-style
  solver would take most of an hour): the fill against the LU.
* ``ring 1976``: the split ring of srr-openmodes at n = 4 (1,976 unknowns on the nearly
  square conforming sectors; 3,076 on the earlier n x n sectors).
* ``sweep 50 x 698``: srr-openmodes (n = 2, 698 unknowns), 50 frequencies
  3–12 GHz, first resonance found by each.

The file also records the compiled fill's first-call cost in fresh processes (numba's
compilation with an empty cache, and the load from a warm one), the rate of the LU
against the machine's single-precision rate measured by a complex64 matrix product, and
the numba threads.

``--bempp`` runs the comparison with bempp-cl instead (``pip install -e '.[bench]'``
installs it): the EFIE matrix of the same plates (176 and 736 unknowns; ``--bempp-sizes``
adds more) assembled by bempp-cl 0.4 (its numba backend, double precision: RWG trial and
test space with the SNC dual, ``operators.boundary.maxwell.electric_field(...).weak_form()``)
and by barymesh (per-mesh geometry and compiled fill, from a fresh mesh), the two
alternating, best of ``--reps``; bempp-cl's first assembly in the process (its numba
compilation; it keeps no cache) is recorded on its own. Only times are compared: bempp-cl
scales its RWG functions and the operator differently, so the matrices are not equal
entry by entry; the unknown counts are checked to agree.

Usage::

    python benchmarks/solver.py                 # all workloads, table on stdout
    python benchmarks/solver.py --json out.json
    python benchmarks/solver.py --quick         # tiny sizes (the test suite)
    python benchmarks/solver.py --bempp --json benchmarks/results/solver-bempp-DATE.json
"""

from __future__ import annotations

import argparse
import importlib.metadata
import importlib.util
import json
import os
import platform
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import numpy as np
import scipy.linalg as sla

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))

from barymesh import build_mesh  # noqa: E402
from barymesh.constants import ETA0, MU0, SPEED_OF_LIGHT  # noqa: E402
from barymesh.mesh import TriMesh  # noqa: E402
from barymesh.mom import (  # noqa: E402
    PlaneWave,
    excitation_vector,
    find_peaks,
    impedance_matrix,
    mom_geometry,
    solve,
    sweep,
    wavenumber,
)
from barymesh.mom.solve import dense_solve  # noqa: E402
from barymesh.presets import load_preset, resolve_params  # noqa: E402

REFERENCE = {"order": 8, "far_order": 6, "near_factor": 3.0}


# -- the Makarov-style solver ---------------------------------------------------------


def makarov_solve(mesh: TriMesh, frequency: float, wave: PlaneWave) -> np.ndarray:
    """Centroid currents (T, 3) by the vectorised rwg1–rwg5 scheme (see the module doc)."""
    eps0 = 1.0 / (MU0 * SPEED_OF_LIGHT**2)
    omega = 2 * np.pi * frequency
    k = omega / SPEED_OF_LIGHT
    p = mesh.points * 1e-3
    tri = mesh.triangles
    corners = p[tri]  # (T, 3, 3)
    centre = corners.mean(axis=1)
    # the 9 sub-triangle centroids of a triangle cut into 9 (n = 3)
    grid = {(i, j) for i in range(4) for j in range(4 - i)}
    sub = []
    for i, j in grid:
        if (i + 1, j) in grid and (i, j + 1) in grid:
            sub.append([(i, j), (i + 1, j), (i, j + 1)])
        if (i + 1, j) in grid and (i, j + 1) in grid and (i + 1, j + 1) in grid:
            sub.append([(i + 1, j), (i + 1, j + 1), (i, j + 1)])
    sub_bary = np.array(
        [np.mean([[a / 3, b / 3, 1 - a / 3 - b / 3] for a, b in s], axis=0) for s in sub]
    )  # (9, 3)
    points = np.einsum("kv,tvc->tkc", sub_bary, corners)  # (T, 9, 3)

    rwg = mesh.rwg
    length = rwg.length * 1e-3
    tp, tm = rwg.t_plus.astype(np.intp), rwg.t_minus.astype(np.intp)
    fp, fm = p[rwg.free_vertex_plus], p[rwg.free_vertex_minus]
    rho_p = points[tp] - fp[:, None]  # (N, 9, 3)
    rho_m = fm[:, None] - points[tm]
    n = len(rwg)
    t = mesh.n_triangles
    c_a = 1j * omega * MU0 / (4 * np.pi) / 4 / 9
    c_phi = 1 / (1j * 4 * np.pi * omega * eps0) / 9
    z = np.zeros((n, n), complex)
    sides = ((tp, rho_p, 1.0), (tm, rho_m, -1.0))
    # as impmet.m: for each test triangle, g from its centroid to the 9 points of every
    # triangle (computed once per triangle pair), then gathered for the RWG pairs
    block = max(1, (1 << 21) // (9 * max(n, t)))
    for lo in range(0, t, block):
        hi = min(t, lo + block)
        r = np.linalg.norm(points[None, :, :, :] - centre[lo:hi, None, None, :], axis=-1)
        g = np.exp(-1j * k * r) / r  # (b, T, 9)
        g_sum = g.sum(axis=2)  # (b, T)
        for t_obs, rho_obs, s_obs in sides:
            cols = np.flatnonzero((t_obs >= lo) & (t_obs < hi))
            local = t_obs[cols] - lo
            for t_src, rho_src, s_src in sides:
                gg = g[local][:, t_src, :]  # (c, N, 9)
                # the k-th ρ of the test triangle with the k-th ρ of the source triangle
                dots = np.einsum("ckd,nkd->cnk", rho_obs[cols], rho_src)
                part = c_a * np.einsum("cnk,cnk->cn", gg, dots)
                part += s_obs * s_src * c_phi * g_sum[local][:, t_src]
                z[:, cols] += part.T
    z *= length[:, None] * length[None, :]
    e_p = wave.field(centre[tp], k)
    e_m = wave.field(centre[tm], k)
    rc_p = centre[tp] - fp
    rc_m = fm - centre[tm]
    v = length * (np.sum(e_p * rc_p, axis=1) + np.sum(e_m * rc_m, axis=1)) / 2
    current = sla.solve(z, v)
    j = np.zeros((mesh.n_triangles, 3), complex)
    area = 0.5 * np.linalg.norm(
        np.cross(corners[:, 1] - corners[:, 0], corners[:, 2] - corners[:, 0]), axis=1
    )
    np.add.at(j, tp, (current * length / (2 * area[tp]))[:, None] * rc_p)
    np.add.at(j, tm, (current * length / (2 * area[tm]))[:, None] * rc_m)
    return j


def makarov_extinction(mesh: TriMesh, frequency: float, wave: PlaneWave, j: np.ndarray) -> float:
    """σ_ext = η Re ∫ E_inc·J* / |E0|² with centroid sampling."""
    k = 2 * np.pi * frequency / SPEED_OF_LIGHT
    centre = mesh.centroids * 1e-3
    area = mesh.areas * 1e-6
    e = wave.field(centre, k)
    return float(ETA0 * np.real(np.sum(area * np.sum(e * np.conj(j), axis=1))))


# -- helpers ---------------------------------------------------------------------------


def fresh(mesh: TriMesh) -> TriMesh:
    """The same mesh as a new object: no cached solver geometry (cold timings).

    Its RWG table and centroids are computed here, outside the timings: they are the
    mesher's output, which the Makarov-style solver reads from the cached mesh too.
    """
    out = TriMesh(
        mesh.points, mesh.triangles, mesh.patch_ids, mesh.regions, mesh.n_patches, mode=mesh.mode
    )
    _ = out.rwg, out.centroids, out.areas
    return out


def best_of(func, reps: int) -> tuple[float, object]:
    best, out = float("inf"), None
    for _ in range(reps):
        start = time.perf_counter()
        out = func()
        best = min(best, time.perf_counter() - start)
    return best, out


def current_error(j: np.ndarray, ref: np.ndarray) -> float:
    """max over triangles of | |J| − |J_ref| | / max |J_ref|."""
    a, b = np.linalg.norm(j, axis=1), np.linalg.norm(ref, axis=1)
    return float(np.abs(a - b).max() / b.max())


def bempp_available() -> bool:
    return importlib.util.find_spec("bempp_cl") is not None


def bempp_efie(mesh: TriMesh, freq: float) -> tuple[int, float, float]:
    """bempp-cl's dense EFIE matrix of ``mesh`` at ``freq``: (unknowns, wall s, CPU s),
    from the grid to the assembled matrix."""
    import bempp_cl.api as bempp

    bempp.DEFAULT_DEVICE_INTERFACE = "numba"

    def assemble() -> int:
        grid = bempp.Grid(
            np.asarray(mesh.points, float).T * 1e-3, np.asarray(mesh.triangles).T.copy()
        )
        rwg = bempp.function_space(grid, "RWG", 0)
        snc = bempp.function_space(grid, "SNC", 0)
        op = bempp.operators.boundary.maxwell.electric_field(rwg, rwg, snc, wavenumber(freq))
        matrix = op.weak_form().to_dense()
        return int(matrix.shape[0])

    n, wall, cpu = _timed(assemble)
    return n, wall, cpu


def bempp_rows(extra_sizes: list[int], reps: int) -> dict:
    """Our EFIE matrix (geometry + compiled fill) against bempp-cl's, same plates."""
    import bempp_cl

    meshes = [
        ("plate 176", build_mesh(load_preset("makarov-plate")[0])),
        ("plate 736", build_mesh(load_preset("makarov-platefine")[0])),
    ]
    for sub in extra_sizes:
        mesh = build_mesh(resolve_params("makarov-platefine", None, [f"subdivisions={sub}"]))
        meshes.append((f"plate {len(mesh.rwg)}", mesh))
    # bempp-cl compiles its kernels on the first assembly of a process (no cache)
    _n, first, first_cpu = bempp_efie(meshes[0][1], 300e6)
    rows = []
    for name, mesh in meshes:
        k = wavenumber(300e6)
        best = {"ours": (np.inf, np.inf), "bempp": (np.inf, np.inf)}
        for _ in range(reps):  # alternating: both see the same load
            cold = fresh(mesh)
            _, wall, cpu = _timed(
                lambda cold=cold, k=k: impedance_matrix(mom_geometry(cold), k, backend="numba")
            )
            best["ours"] = min(best["ours"], (wall, cpu))
            n, wall, cpu = bempp_efie(mesh, 300e6)
            best["bempp"] = min(best["bempp"], (wall, cpu))
            if n != len(mesh.rwg):
                raise SystemExit(f"{name}: bempp-cl has {n} unknowns, barymesh {len(mesh.rwg)}")
        rows.append(
            {
                "name": name,
                "unknowns": len(mesh.rwg),
                "ours_matrix_s": best["ours"][0],
                "ours_matrix_cpu_s": best["ours"][1],
                "bempp_matrix_s": best["bempp"][0],
                "bempp_matrix_cpu_s": best["bempp"][1],
                "speedup": best["bempp"][0] / best["ours"][0],
                "speedup_cpu": best["bempp"][1] / best["ours"][1],
            }
        )
        r = rows[-1]
        print(
            f"{name:<12} {r['unknowns']:>6}  ours {r['ours_matrix_s']:8.3f} s "
            f"(CPU {r['ours_matrix_cpu_s']:.3f})  bempp-cl {r['bempp_matrix_s']:8.3f} s "
            f"(CPU {r['bempp_matrix_cpu_s']:.3f})  {r['speedup']:.1f}x",
            flush=True,
        )
    return {
        "bempp_version": getattr(bempp_cl, "__version__", None)
        or importlib.metadata.version("bempp-cl"),
        "bempp_first_assembly_s": first,
        "bempp_first_assembly_cpu_s": first_cpu,
        "reps": reps,
        "rows": rows,
    }


# -- workloads ------------------------------------------------------------------------


def _timed(func):
    """(result, wall s, CPU s of the process: all its threads) of ``func()``."""
    start, cpu = time.perf_counter(), time.process_time()
    out = func()
    return out, time.perf_counter() - start, time.process_time() - cpu


def split_times(mesh: TriMesh, freq: float, wave: PlaneWave, numpy_fill: bool = True) -> dict:
    """Our cold solve in its three steps: per-mesh geometry, fill, LU (seconds, wall and CPU).

    The fill is timed compiled (the default) and, with ``numpy_fill``, by the numpy path.
    """
    cold = fresh(mesh)
    geom, t_geom, _ = _timed(lambda: mom_geometry(cold))
    k = wavenumber(freq)
    z, t_fill, c_fill = _timed(lambda: impedance_matrix(geom, k, backend="numba"))
    row = {"ours_geometry_s": t_geom, "ours_fill_s": t_fill, "ours_fill_cpu_s": c_fill}
    if numpy_fill:
        del z
        z, t_np, c_np = _timed(lambda: impedance_matrix(geom, k, backend="numpy"))
        row.update(ours_fill_numpy_s=t_np, ours_fill_numpy_cpu_s=c_np)
    v = excitation_vector(geom, k, wave)
    _, t_lu, c_lu = _timed(lambda: dense_solve(z, v))
    n = len(v)
    row.update(
        ours_lu_s=t_lu,
        ours_lu_cpu_s=c_lu,
        fill_over_lu=t_fill / t_lu,
        lu_gflops=8.0 / 3.0 * n**3 / t_lu / 1e9,  # complex64 getrf: 8/3 N³ real flops
    )
    return row


def compile_cost() -> dict:
    """The first compiled fill of a fresh process (176 unknowns): cold cache and warm one.

    Each in its own interpreter; the cold one with NUMBA_CACHE_DIR set to an empty folder,
    so that numba compiles the kernels (and leaves the project's cache as it was).
    """
    code = (
        "import time\n"
        "from barymesh import build_mesh\n"
        "from barymesh.presets import load_preset\n"
        "from barymesh.mom import mom_geometry, wavenumber\n"
        "from barymesh.mom.operator import impedance_matrix\n"
        "geom = mom_geometry(build_mesh(load_preset('makarov-plate')[0]))\n"
        "t, c = time.perf_counter(), time.process_time()\n"
        "impedance_matrix(geom, wavenumber(300e6), backend='numba')\n"
        "print(time.perf_counter() - t, time.process_time() - c)\n"
    )
    out = {}
    with tempfile.TemporaryDirectory() as empty:
        for name, extra in (("cold", {"NUMBA_CACHE_DIR": empty}), ("cached", {})):
            env = {**os.environ, **extra}
            if name == "cached":
                env.pop("NUMBA_CACHE_DIR", None)
                subprocess.run(
                    [sys.executable, "-c", code], env=env, check=True, capture_output=True
                )
            res = subprocess.run(
                [sys.executable, "-c", code], env=env, check=True, capture_output=True, text=True
            )
            wall, cpu = (float(x) for x in res.stdout.split()[-2:])
            out[f"first_fill_{name}_s"] = wall
            out[f"first_fill_{name}_cpu_s"] = cpu
    return out


def single_precision_rate(n: int = 2000) -> float:
    """GFLOP/s of a complex64 (n, n) matrix product: the machine's practical SP peak."""
    rng = np.random.default_rng(0)
    a = (rng.standard_normal((n, n)) + 1j * rng.standard_normal((n, n))).astype(np.complex64)
    b = a.T.copy()
    a @ b
    best = min(_timed(lambda: a @ b)[1] for _ in range(3))
    return 8.0 * n**3 / best / 1e9


def fill_only(name: str, mesh: TriMesh, freq: float, wave: PlaneWave, numpy_fill: bool) -> dict:
    """A size the Makarov-style solver is not run at: our geometry, fill and LU."""
    row = {"name": name, "unknowns": len(mesh.rwg), "frequency_hz": freq}
    row.update(split_times(mesh, freq, wave, numpy_fill=numpy_fill))
    return row


def single(
    name: str,
    mesh: TriMesh,
    freq: float,
    wave: PlaneWave,
    reps: int,
    accuracy: bool,
    split: bool = False,
):
    n = len(mesh.rwg)
    # the two solvers alternate, so that both see the same load on a shared machine
    t_ours = t_mak = float("inf")
    for _ in range(reps):
        cold = fresh(mesh)
        t, sol = best_of(lambda cold=cold: solve(cold, freq, wave), 1)
        t_ours = min(t_ours, t)
        t, j_mak = best_of(lambda: makarov_solve(mesh, freq, wave), 1)
        t_mak = min(t_mak, t)
    row = {
        "name": name,
        "unknowns": n,
        "frequency_hz": freq,
        "ours_s": t_ours,
        "makarov_s": t_mak,
        "speedup": t_mak / t_ours,
        "ours_max_j": float(np.linalg.norm(sol.current_density, axis=1).max()),
        "makarov_max_j": float(np.linalg.norm(j_mak, axis=1).max()),
    }
    if split:
        row.update(split_times(mesh, freq, wave))
    if accuracy:
        ref = solve(fresh(mesh), freq, wave, **REFERENCE)
        row["ours_error"] = current_error(sol.current_density, ref.current_density)
        row["makarov_error"] = current_error(j_mak, ref.current_density)
        row["reference_max_j"] = float(np.linalg.norm(ref.current_density, axis=1).max())
    return row


def sweep_workload(mesh: TriMesh, freqs: np.ndarray, wave: PlaneWave, accuracy: bool):
    n = len(mesh.rwg)
    cold = fresh(mesh)
    start = time.perf_counter()
    ours = sweep(cold, freqs, wave, scattering=False)
    t_ours = time.perf_counter() - start
    start = time.perf_counter()
    ext = [makarov_extinction(mesh, f, wave, makarov_solve(mesh, f, wave)) for f in freqs]
    t_mak = time.perf_counter() - start
    row = {
        "name": f"sweep {len(freqs)} x {n}",
        "unknowns": n,
        "frequencies": len(freqs),
        "ours_s": t_ours,
        "makarov_s": t_mak,
        "speedup": t_mak / t_ours,
        "ours_resonance_hz": float(ours.resonances[0]) if len(ours.resonances) else None,
        "makarov_resonance_hz": float(find_peaks(freqs, np.array(ext))[0])
        if len(find_peaks(freqs, np.array(ext)))
        else None,
    }
    if accuracy and row["ours_resonance_hz"]:
        f0 = row["ours_resonance_hz"]
        fine = np.linspace(f0 * 0.97, f0 * 1.03, 7)
        ref = sweep(fresh(mesh), fine, wave, scattering=False, **REFERENCE)
        row["reference_resonance_hz"] = float(ref.resonances[0])
    return row


def machine() -> dict:
    return {
        "python": platform.python_version(),
        "numpy": np.__version__,
        "cpus": os.cpu_count(),
        "load_average": os.getloadavg()[0] if hasattr(os, "getloadavg") else None,
        "openblas_threads": os.environ.get("OPENBLAS_NUM_THREADS"),
        "platform": platform.platform(),
        **numba_threads(),
    }


def numba_threads() -> dict:
    """numba's thread count and threading layer (after a compiled fill has run)."""
    try:
        import numba
    except ImportError:
        return {"numba": None}
    try:
        layer = numba.threading_layer()
    except ValueError:  # no parallel region has run yet
        layer = None
    return {
        "numba": numba.__version__,
        "numba_threads": numba.get_num_threads(),
        "numba_threading_layer": layer,
    }


def table(rows: list[dict]) -> str:
    lines = [
        f"{'workload':<18} {'N':>6} {'ours s':>8} {'Makarov-style s':>16} {'speed-up':>9}"
        "  accuracy",
    ]
    for r in rows:
        if "ours_error" in r:
            acc = (
                f"|J| error vs converged: ours {100 * r['ours_error']:.2f} %, "
                f"Makarov-style {100 * r['makarov_error']:.2f} %"
            )
        elif "ours_resonance_hz" in r:
            ref = r.get("reference_resonance_hz")
            acc = (
                f"resonance ours {r['ours_resonance_hz'] / 1e9:.4f} GHz, Makarov-style "
                f"{(r['makarov_resonance_hz'] or float('nan')) / 1e9:.4f} GHz"
                + (f", converged {ref / 1e9:.4f} GHz" if ref else "")
            )
        else:
            acc = (
                f"max |J| ours {r['ours_max_j']:.5g}, Makarov-style {r['makarov_max_j']:.5g} A/m"
                if "makarov_s" in r
                else ""
            )
        if "ours_geometry_s" in r:
            acc += (
                f"; ours split: geometry {r['ours_geometry_s']:.3f} s, fill "
                f"{r['ours_fill_s']:.3f} s (CPU {r['ours_fill_cpu_s']:.3f} s"
                + (f"; numpy {r['ours_fill_numpy_s']:.3f} s" if "ours_fill_numpy_s" in r else "")
                + f"), LU {r['ours_lu_s']:.3f} s (fill/LU {r['fill_over_lu']:.2f})"
            )
        if "makarov_s" in r:
            times = f"{r['ours_s']:>8.3f} {r['makarov_s']:>16.3f} {r['speedup']:>8.1f}x"
        else:
            times = f"{'-':>8} {'-':>16} {'-':>9}"
            acc = acc.lstrip("; ")
        lines.append(f"{r['name']:<18} {r['unknowns']:>6} {times}  {acc}")
    return "\n".join(lines)


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--quick", action="store_true", help="tiny sizes, one repetition")
    ap.add_argument("--reps", type=int, default=3, help="repetitions (best time is kept)")
    ap.add_argument("--json", metavar="PATH", help="also write the results as JSON")
    ap.add_argument("--skip", action="append", default=[], help="skip a workload by name")
    ap.add_argument("--bempp", action="store_true", help="only the comparison with bempp-cl")
    ap.add_argument(
        "--bempp-sizes",
        type=int,
        nargs="*",
        default=[],
        metavar="n",
        help="with --bempp: also the plate at these subdivisions (22: 1,408 unknowns)",
    )
    args = ap.parse_args(argv)
    if args.bempp:
        if not bempp_available():
            raise SystemExit("bempp-cl is not installed: pip install -e '.[bench]'")
        from barymesh.mom.compiled_fill import warm_up

        warm_up()
        doc = {"machine": machine(), **bempp_rows(args.bempp_sizes, args.reps)}
        print(f"bempp-cl's first assembly (its compilation): {doc['bempp_first_assembly_s']:.1f} s")
        if args.json:
            Path(args.json).write_text(json.dumps(doc, indent=2) + "\n", encoding="utf-8")
        return 0
    wave_x = PlaneWave(direction=(0, 0, -1), polarization=(1, 0, 0))
    wave_y = PlaneWave(direction=(0, 0, -1), polarization=(0, 1, 0))
    rows = []
    # numba imported and its kernels loaded before any timing (the first-call cost is
    # measured on its own, in fresh processes: compile_cost)
    from barymesh.mom.compiled_fill import warm_up

    warm_up()
    if args.quick:
        plate = build_mesh(load_preset("makarov-plate")[0])
        rows.append(single("plate 176", plate, 300e6, wave_x, 1, accuracy=True, split=True))
        ring = build_mesh(resolve_params("srr-openmodes", None, ["subdivisions=1"]))
        rows.append(sweep_workload(ring, np.linspace(4e9, 9e9, 6), wave_y, accuracy=False))
    else:
        plate = build_mesh(load_preset("makarov-platefine")[0])
        if "plate" not in args.skip:
            rows.append(single("plate 736", plate, 300e6, wave_x, args.reps, accuracy=True))
        for sub in (22, 32, 45):
            name = f"plate {3 * sub * sub - 2 * sub}"
            if name.replace(" ", "") not in args.skip and "plates" not in args.skip:
                big_plate = build_mesh(
                    resolve_params("makarov-platefine", None, [f"subdivisions={sub}"])
                )
                reps = args.reps if sub < 30 else 1
                rows.append(
                    single(name, big_plate, 300e6, wave_x, reps, accuracy=False, split=True)
                )
        if "plate9976" not in args.skip:
            huge = build_mesh(resolve_params("makarov-platefine", None, ["subdivisions=58"]))
            numpy_fill = "numpy9976" not in args.skip
            rows.append(fill_only("plate 9976", huge, 300e6, wave_x, numpy_fill))
        if "ring" not in args.skip:
            big = build_mesh(resolve_params("srr-openmodes", None, ["subdivisions=4"]))
            rows.append(single(f"ring {len(big.rwg)}", big, 6.19e9, wave_y, 1, accuracy=False))
        if "sweep" not in args.skip:
            ring = build_mesh(load_preset("srr-openmodes")[0])
            freqs = np.linspace(3e9, 12e9, 50)
            rows.append(sweep_workload(ring, freqs, wave_y, accuracy=True))
    print(table(rows))
    extra = {}
    if not args.quick and "compile" not in args.skip:
        extra["compile"] = compile_cost()
        print(
            "compiled fill, first call in a fresh process: "
            f"{extra['compile']['first_fill_cold_s']:.1f} s compiling (empty cache), "
            f"{extra['compile']['first_fill_cached_s']:.2f} s from the cache"
        )
    if not args.quick:
        extra["single_precision_gflops"] = single_precision_rate()
        print(f"complex64 matrix product: {extra['single_precision_gflops']:.1f} GFLOP/s")
    bempp = "installed: --bempp compares" if bempp_available() else "not installed"
    print(f"bempp-cl: {bempp}")
    if args.json:
        doc = {"machine": machine(), "workloads": rows, "bempp": bempp, **extra}
        Path(args.json).write_text(json.dumps(doc, indent=2) + "\n", encoding="utf-8")
    return 0


if __name__ == "__main__":
    sys.exit(main())
