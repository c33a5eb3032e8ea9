"""The performance page's tables, written at build time from ``benchmarks/results/*.json``.

``.. benchmark-table:: NAME`` (in MyST: a ``{benchmark-table}`` fence) reads the newest
``benchmarks/results/NAME*.json`` (``NAME:PART`` for one of several tables of a file;
newest by the date in its name, ``NAME-YYYY-MM-DD.json``, else by the date of the commit
that last changed it) and writes one table of it, with a line naming the file, the
machine and the date. A benchmark that has no result file yet gets a line saying so and
how to make one. Each renderer knows its benchmark's JSON, as written by
``benchmarks/NAME.py --json``.
"""

from __future__ import annotations

import json
import re
import subprocess
from collections.abc import Callable
from pathlib import Path
from typing import Any

from docutils import nodes
from sphinx.util.docutils import SphinxDirective

ROOT = Path(__file__).resolve().parents[2]
RESULTS = ROOT / "benchmarks" / "results"
_DATE = re.compile(r"(\d{4}-\d{2}-\d{2})")


def _date(path: Path, doc: dict[str, Any]) -> str:
    """The day the result was measured: its ``date`` key, its name, or its commit."""
    if isinstance(doc.get("date"), str):
        return doc["date"]
    match = _DATE.search(path.name)
    if match:
        return match.group(1)
    try:
        out = subprocess.run(
            ["git", "log", "-1", "--format=%cs", "--", str(path)],
            cwd=ROOT,
            capture_output=True,
            text=True,
            timeout=10,
            check=False,
        ).stdout.strip()
    except (OSError, subprocess.SubprocessError):
        out = ""
    return f"{out} (the day the file was committed)" if out else "undated"


def newest(name: str) -> Path | None:
    """The newest result file of benchmark ``name``, or None."""
    files = [p for p in RESULTS.glob(f"{name}*.json") if p.is_file()]
    # "periodic-2026-12-02.json" before "periodic-validation-2026-12-02.json" (another
    # benchmark's file); names with only variants ("latency-big-...") take those
    own = [p for p in files if _DATE.sub("", p.stem).rstrip("-") == name]
    files = own or files
    if not files:
        return None

    def key(p: Path) -> tuple[str, str]:
        match = _DATE.search(p.name)
        return (match.group(1) if match else "0000-00-00", p.name)

    return max(files, key=key)


def _s(seconds: float | None, digits: int = 3) -> str:
    return "–" if seconds is None else f"{seconds:.{digits}f}"


def _spread(t: dict[str, float] | None) -> str:
    if not t:
        return "–"
    return f"{t['median']:.3f} ({t['min']:.3f}–{t['max']:.3f})"


def _n(value: int | None) -> str:
    return "–" if value is None else f"{value:,}"


def _machine(m: dict[str, Any] | None) -> str:
    if not m:
        return "a machine the file does not describe"
    parts = []
    cpu = m.get("cpu")
    cores = m.get("cores", m.get("cpus"))
    if cpu or cores:
        parts.append(" ".join(str(x) for x in (cpu, f"{cores} cores" if cores else None) if x))
    if m.get("platform"):
        parts.append(m["platform"])
    if m.get("python"):
        parts.append(f"Python {m['python']}")
    if m.get("numpy"):
        parts.append(f"numpy {m['numpy']}")
    if m.get("openblas_threads"):
        parts.append(f"{m['openblas_threads']} BLAS thread(s)")
    if m.get("load_average") is not None:
        parts.append(f"load average {m['load_average']:.1f} when the file was written")
    return ", ".join(parts)


Table = tuple[list[str], list[list[str]], str]


def _cpu_ratio(ours: dict[str, Any], bound: dict[str, Any]) -> str:
    """The " (CPU n×)" of a bound cell: our CPU median over the warm write's, if both are there."""
    mine, write = ours.get("cpu_median"), bound["warm"].get("cpu_median")
    return f" (CPU {mine / write:.1f}×)" if mine and write else ""


def _alone(alone: dict[str, Any] | None) -> str:
    """Our build in a process of its own: median (page faults per build; its first build)."""
    if not alone:
        return "–"
    return (
        f"{alone['median']:.4f} ({alone['faults_median']:,.0f}; first {alone['first']['wall']:.3f})"
    )


def mesher(doc: dict[str, Any]) -> Table:
    head = [
        "workload",
        "size",
        "triangles",
        "ours s",
        "alone s (faults)",
        "MiB (B/tri)",
        "bound s (GB/s)",
        "ours / bound",
        "peer",
        "peer s",
        "ratio",
        "stats() / build_mesh",
    ]
    rows = []
    for w in doc["workloads"]:
        ours = w.get("ours", {})
        bound = w.get("bound")
        bound_cells = (
            [
                f"{bound['warm']['median']:.4f} ({bound['warm_gb_per_s']:.1f})",
                f"{bound['ours_over_warm']:.1f}×"
                + _cpu_ratio(ours, bound)
                + (f"; numba {bound['numba_over_warm']:.1f}×" if "numba_over_warm" in bound else "")
                + (
                    f"; floors: computed {bound['computed_over_warm']:.1f}×, "
                    f"fresh {bound['fresh_over_warm']:.1f}×"
                    if "computed_over_warm" in bound
                    else ""
                ),
            ]
            if bound
            else ["–", "–"]
        )
        stats = w.get("stats", {}).get("median")
        build = w.get("build_mesh", {}).get("median")
        ratio = f"{stats / build:.2f}" if stats and build else "–"
        peers = [k for k in ("a-exact", "a-tol", "gmsh") if k in w] or [None]
        for i, peer in enumerate(peers):
            p = w.get(peer, {}) if peer else {}
            first = i == 0
            rows.append(
                [
                    w["name"] if first else "",
                    w["size"] if first else "",
                    _n(w.get("triangles")) if first else "",
                    _spread(ours) if first else "",
                    _alone(w.get("ours-alone")) if first else "",
                    f"{ours['peak_mib']:.0f} ({ours['bytes_per_triangle']:.0f})"
                    if first and "peak_mib" in ours
                    else "",
                    *(bound_cells if first else ["", ""]),
                    {"a-exact": "(a) exact", "a-tol": "(a) tolerance", "gmsh": "(b) gmsh"}.get(
                        peer, "none"
                    ),
                    _spread(p) if p else "–",
                    f"{p['ratio']:.1f}×" if p.get("ratio") else "–",
                    ratio if first else "",
                ]
            )
    note = (
        f"Times in seconds, median (min–max) of {doc.get('reps', '?')} repetitions, ours and "
        "the peer alternating; ratio = peer median / our median. Bound: a numpy write of as "
        "many bytes as the build's outputs hold (points, triangles, centroids, topology, RWG "
        "table, connectivity) into a written buffer, timed in the same run; in brackets "
        "the same ratio of CPU times, which other jobs on the machine distort less. "
        "From 131,072 triangles, numba: the same build with the opt-in compiled loops "
        "(BARYMESH_MESH_KERNELS=numba; their one-time load of about 0.5 s left out). "
        "Floors, in units of the bound and timed in the same run: computed, the same bytes "
        "written as values computed from a cache-resident pattern (ordinary stores, as any "
        "computed output is written; the bound's fill is a memset); fresh, the bound's write "
        "into newly allocated memory (page faults included). Alone: the same build in a new "
        "process that does nothing else (the median of as many builds after its first, with "
        "the page faults of one; then its first build): there the C allocator hands freed "
        "memory back to the kernel and each build faults its pages in again, where in the "
        "benchmark's process the peers leave it holding memory."
    )
    if doc.get("load_at_start") is not None:
        note += f" Load average {doc['load_at_start'][0]:.1f} at the start of the run."
    return head, rows, note


def solver(doc: dict[str, Any]) -> Table:
    head = [
        "workload",
        "N",
        "frequency",
        "ours s",
        "Makarov-style s",
        "speed-up",
        "fill s: compiled (CPU) / numpy",
        "LU s",
        "largest |J|",
    ]
    rows = []
    for w in doc["workloads"]:
        if "frequencies" in w:
            freq = f"{w['frequencies']} frequencies"
            extra = (
                f"resonance {w['ours_resonance_hz'] / 1e9:.4f} vs "
                f"{w['makarov_resonance_hz'] / 1e9:.4f} GHz"
            )
        else:
            freq = f"{w['frequency_hz'] / 1e6:g} MHz"
            extra = (
                f"{w['ours_max_j']:.5g} vs {w['makarov_max_j']:.5g} A/m"
                if "ours_max_j" in w
                else "–"
            )
        fill = "–"
        if "ours_fill_s" in w:
            fill = f"{w['ours_fill_s']:.3f}"
            if "ours_fill_cpu_s" in w:
                fill += f" ({w['ours_fill_cpu_s']:.3f})"
            if "ours_fill_numpy_s" in w:
                fill += f" / {w['ours_fill_numpy_s']:.3f}"
        rows.append(
            [
                w["name"],
                _n(w["unknowns"]),
                freq,
                _s(w.get("ours_s")),
                _s(w.get("makarov_s")),
                f"{w['speedup']:.1f}×" if "speedup" in w else "–",
                fill,
                _s(w.get("ours_lu_s")),
                extra,
            ]
        )
    note = "Fill + solve, cold, best of the repetitions; ours against the Makarov-style solver."
    compiled = doc.get("compile")
    if compiled:
        note += (
            " The compiled fill's first call in a fresh process: "
            f"{compiled['first_fill_cold_s']:.1f} s compiling with an empty cache, "
            f"{compiled['first_fill_cached_s']:.2f} s loading from the cache."
        )
    if doc.get("single_precision_gflops"):
        note += (
            " A complex64 matrix product runs at "
            f"{doc['single_precision_gflops']:.0f} GFLOP/s on this machine."
        )
    bempp = doc.get("bempp")
    if bempp:
        note += f" bempp-cl: {bempp}."
    return head, rows, note


def solver_bempp(doc: dict[str, Any]) -> Table:
    head = ["plate", "N", "ours s (CPU)", "bempp-cl s (CPU)", "speed-up (CPU)"]
    rows = [
        [
            r["name"],
            _n(r["unknowns"]),
            f"{r['ours_matrix_s']:.3f} ({r['ours_matrix_cpu_s']:.3f})",
            f"{r['bempp_matrix_s']:.3f} ({r['bempp_matrix_cpu_s']:.3f})",
            f"{r['speedup']:.0f}× ({r['speedup_cpu']:.0f}×)",
        ]
        for r in doc["rows"]
    ]
    note = (
        f"The dense EFIE matrix at 300 MHz, from the mesh: barymesh's geometry and compiled "
        f"fill against bempp-cl {doc['bempp_version']} (numba backend, double precision, RWG "
        f"with the SNC dual), alternating, best of {doc['reps']}. bempp-cl's first assembly "
        f"in a process, its compilation, took {doc['bempp_first_assembly_s']:.0f} s."
    )
    return head, rows, note


def quality(doc: dict[str, Any]) -> Table:
    gmsh = doc.get("gmsh_algorithm") is not None
    head = ["mesh", "mode", "triangles", "unknowns", "min angle °", "max aspect"]
    if gmsh:
        head += ["gmsh triangles", "gmsh min angle °", "gmsh max aspect"]
    rows = []
    for r in doc["rows"]:
        row = [
            r["name"],
            r["mode"],
            _n(r["triangles"]),
            _n(r["unknowns"]),
            f"{r['min_angle_deg']:.1f}",
            f"{r['max_aspect_ratio']:.2f}",
        ]
        if gmsh:
            g = r.get("gmsh") or {}
            row += [
                _n(g.get("triangles")),
                f"{g['min_angle_deg']:.1f}" if g else "–",
                f"{g['max_aspect_ratio']:.2f}" if g else "–",
            ]
        rows.append(row)
    note = "Figures from TriMesh.stats(); unknowns = interior edges = rows of the RWG table."
    if not gmsh:
        note += " This run had no gmsh columns (gmsh not installed or --no-gmsh)."
    return head, rows, note


def latency(doc: dict[str, Any]) -> Table:
    head = ["case", "triangles", "result", "longest block ms", "paints", "B/triangle"]
    rows = []
    if doc.get("frames"):
        total = doc["seconds"]["total"]
        rows.append(
            [
                f"slider frame ({doc['slider']}, {doc['frames']} frames)",
                ", ".join(f"{t:,}" for t in doc["triangles"]),
                f"{total['median'] * 1e3:.1f} ms median, {total['p95'] * 1e3:.1f} ms p95",
                f"{doc['longest_block'] * 1e3:.0f}",
                str(doc["paints_per_frame"]),
                "",
            ]
        )
    drag = doc.get("drag")
    if drag:
        rows.append(
            [
                "mouse drag of the slider",
                "",
                f"{drag['meshes_per_second']:.1f} meshes/s",
                f"{drag['longest_block'] * 1e3:.0f}",
                "",
                "",
            ]
        )
    big = doc.get("big") or {}
    for key, case in big.items():
        if not isinstance(case, dict) or "shown" not in case:
            continue
        rows.append(
            [
                f"{key}: until shown",
                _n(case["triangles"]),
                f"{case['shown']['median']:.2f} s",
                f"{case['longest_block']['median'] * 1e3:.0f}",
                ", ".join(str(p) for p in case.get("paints", [])),
                f"{case['bytes_per_triangle']:.0f}",
            ]
        )
    if "rotation" in big:
        r = big["rotation"]
        fps = f"{r['fps']:.0f} frames/s"
        rows.append(["camera rotation (1M)", "", fps, f"{r['longest_block'] * 1e3:.0f}", "", ""])
    if "quality_panel" in big:
        q = big["quality_panel"]
        rows.append(
            [
                "Quality dock over the 1M mesh",
                _n(q["triangles"]),
                f"{q['seconds']:.2f} s",
                f"{q['longest_block'] * 1e3:.0f}",
                "",
                "",
            ]
        )
    note = (
        f"The real window at {doc['window_size'][0]} × {doc['window_size'][1]} under Xvfb, "
        f"{doc.get('renderer', 'renderer not recorded')}."
    )
    if doc.get("conditions"):
        note += f" Conditions: {doc['conditions']}."
    return head, rows, note


#: The cases of ``benchmarks/latency.py --interaction``, as the table names them.
INTERACTION_CASES = {
    "slider_drag_fig12a": "mouse drag of Fig. 12(a)'s inner-radius slider",
    "slider_drag_fig12d": "mouse drag of Fig. 12(d)'s angle-step slider",
    "wheel_zoom_200k": "wheel steps into the view, each followed by its rest",
    "rotate_1M": "rotating mouse drag over the view (per move)",
}


def latency_interaction(doc: dict[str, Any]) -> Table:
    head = [
        "case",
        "triangles",
        "longest block ms",
        "GUI thread CPU ms",
        "process CPU ms",
        "median step ms (GUI CPU)",
        "load average",
    ]
    rows = []
    for key, c in doc["cases"].items():
        triangles = c.get("triangles", c.get("triangles_last"))
        step = c.get("median_step_block")
        rows.append(
            [
                INTERACTION_CASES.get(key, key),
                _n(triangles),
                f"{c['longest_block'] * 1e3:.0f}",
                f"{c['longest_block_cpu'] * 1e3:.0f}",
                _s(c.get("longest_block_process_cpu") and c["longest_block_process_cpu"] * 1e3, 0),
                "–" if step is None else f"{step * 1e3:.0f} ({c['median_step_cpu'] * 1e3:.0f})",
                f"{c['loadavg'][0]:.1f}",
            ]
        )
    load = doc.get("load", {})
    note = (
        f"The real window at {doc['window_size'][0]} × {doc['window_size'][1]} under Xvfb, "
        f"{doc.get('renderer', 'renderer not recorded')}; the event loop's longest block "
        "(a 10 ms heartbeat timer) with the GUI thread's CPU time and the whole process's "
        "(Mesa's render threads, workers) in that same gap: on a loaded machine the wall "
        "time grows with the other processes' share of the cores, the GUI thread's CPU "
        "time hardly. Target: no block over 100 ms on a quiet machine."
    )
    if load.get("loadavg_before"):
        note += (
            f" Load average {load['loadavg_before'][0]:.1f} at the start and "
            f"{load['loadavg_after'][0]:.1f} at the end on {load.get('cores', '?')} cores"
            + (f" ({load['note']})" if load.get("note") else "")
            + "."
        )
    return head, rows, note


def startup(doc: dict[str, Any]) -> Table:
    head = ["case", "median s", "min s", "CPU s", "target s", "before: median s", "load average"]
    rows = []
    for name, c in doc["cases"].items():
        before = c.get("baseline")
        target = c.get("target")
        met = "" if target is None else (" (met)" if c["median"] <= target else " (not met)")
        rows.append(
            [
                name,
                _s(c["median"]),
                _s(c["min"]),
                _s(c.get("cpu_median")),
                "–" if target is None else f"{target:.2f}{met}",
                "–" if before is None else _s(before["median"]),
                "–".join(f"{x:.1f}" for x in c["loadavg"]),
            ]
        )
    note = (
        f"Median of {doc['repeats']} runs of each case in a new process, wall time from start "
        "to exit (the window: to its first frame showing the mesh), with the bytecode caches "
        "written (as after an install); CPU is user + system time, which a loaded machine "
        "stretches less than the wall time."
    )
    base = doc.get("baseline")
    if base:
        note += (
            f" Before: the same case on {base['revision']} ({base['commit'][:10]}), each run "
            "right after this tree's, under the same load."
        )
    return head, rows, note


def _pct(x: float | None) -> str:
    return "–" if x is None else f"{100 * x:.2f} %"


def grading(doc: dict[str, Any]) -> Table:
    head = ["series", "n", "triangles", "N", "shortest edge (mm)", "I_cut error", "m_z error"]
    rows = [
        [
            r["series"],
            str(r["subdivisions"]),
            _n(r["triangles"]),
            _n(r["unknowns"]),
            f"{r['min_edge_mm']:.3f}",
            _pct(r.get("I_cut_error")),
            _pct(r.get("m_z_error")),
        ]
        for r in doc["rows"]
    ]
    i_ref, m_ref = doc["reference"]["I_cut"], doc["reference"]["m_z"]
    note = (
        f"Errors against the Richardson reference from the uniform meshes of "
        f"{' and '.join(f'{n:,}' for n in i_ref['from_unknowns'])} unknowns (uncertainty "
        f"{_pct(i_ref['uncertainty'])} for I_cut, {_pct(m_ref['uncertainty'])} for m_z), "
        f"at {doc['frequency_hz'] / 1e9:g} GHz; accuracy figures, the same on any machine."
    )
    return head, rows, note


def periodic(doc: dict[str, Any]) -> Table:
    compiled = any("periodic_fill_cpu_s" in r for r in doc["rows"])
    head = [
        "unknowns",
        "triangles",
        "periodic fill s",
        "LU s",
        "fill + solve s",
        "free-space fill s",
        "fill ratio",
        "periodic geometry s",
    ]
    if compiled:  # since the compiled periodic fill: CPU times and numpy's fill beside
        head[2:] = [
            "periodic fill s (CPU)",
            "numpy's periodic fill s",
            "LU s",
            "fill + solve s",
            "free-space fill s (CPU)",
            "fill ratio wall, CPU",
            "periodic geometry s",
            "load",
        ]
    rows = []
    for r in doc["rows"]:
        if compiled:
            rows.append(
                [
                    _n(r["unknowns"]),
                    _n(r["triangles"]),
                    f"{_s(r['periodic_fill_s'])} ({_s(r['periodic_fill_cpu_s'])})",
                    _s(r["periodic_fill_numpy_s"]),
                    _s(r["periodic_lu_s"]),
                    _s(r["periodic_fill_plus_solve_s"]),
                    f"{_s(r['free_space_fill_s'])} ({_s(r['free_space_fill_cpu_s'])})",
                    f"{r['fill_ratio']:.2f}, {r['fill_ratio_cpu']:.2f}",
                    _s(r.get("periodic_geometry_s")),
                    f"{r['load_average']:.1f}",
                ]
            )
            continue
        rows.append(
            [
                _n(r["unknowns"]),
                _n(r["triangles"]),
                _s(r["periodic_fill_s"]),
                _s(r["periodic_lu_s"]),
                _s(r["periodic_fill_plus_solve_s"]),
                _s(r["free_space_fill_s"]),
                f"{r['fill_ratio']:.2f}",
                _s(r.get("periodic_geometry_s")),
            ]
        )
    target_s = doc["rows"][0].get("target_fill_plus_solve_s", 0.2)
    target_ratio = doc["rows"][0].get("target_fill_ratio", 2.0)
    note = (
        f"One frequency of a patch cell, best of {doc.get('reps', '?')} repetitions, the "
        "periodic and the free-space fill of the same mesh alternating; the geometry once "
        f"per mesh. Targets: fill + solve within {target_s:g} s at 1,000 unknowns, the fill "
        f"within {target_ratio:g} times the free-space fill."
    )
    if compiled:
        note += (
            " Both fills compiled (numba, two threads; CPU time over all threads), numpy's "
            "periodic fill beside; the load average (other jobs) as the row was measured."
        )
    return head, rows, note


def array_live(doc: dict[str, Any]) -> Table:
    head = [
        "round",
        "time to curve s",
        "worker s",
        "solves",
        "longest block during drag ms",
        "longest block after release ms",
    ]
    rows = [
        [
            str(r["round"]),
            _s(r["time_to_curve_s"], 2),
            _s(r["worker_s"], 2),
            _n(r["solves"]),
            f"{r['longest_block_drag_s'] * 1e3:.0f}",
            f"{r['longest_block_after_release_s'] * 1e3:.0f}",
        ]
        for r in doc["rows"]
    ]
    c, t = doc["cell"], doc["targets"]
    note = (
        f"The {c['preset']} cell at n = {c['subdivisions']} ({c['triangles']:,} triangles, "
        f"{c['unknowns']:,} unknowns) in the window, a {doc['points']}-point band of "
        f"{doc['band_ghz'][0]:g} to {doc['band_ghz'][1]:g} GHz with Live on; each round a "
        "mouse drag of the ring's inner radius, timed from the release to the paint of the "
        "new curve (worker: the sweep in the solver process and the figure's draw). "
        f"Targets: the curve within {t['time_to_curve_s']:g} s, no event-loop block over "
        f"{t['longest_block_s'] * 1e3:.0f} ms."
    )
    return head, rows, note


def periodic_sweep(doc: dict[str, Any]) -> Table:
    head = [
        "triangles",
        "unknowns",
        "frequencies",
        "geometry s",
        "interpolating s",
        "solves",
        "s per solve",
        "point by point s",
        "largest |R| difference",
        "largest arg R difference °",
    ]
    rows = [
        [
            _n(r["triangles"]),
            _n(r["unknowns"]),
            _n(r["frequencies"]),
            _s(r["geometry_s"], 2),
            _s(r["interpolating_s"], 1),
            _n(r["interpolating_solves"]),
            _s(r["interpolating_s_per_solve"], 2),
            _s(r.get("point_by_point_s"), 0),
            f"{r['largest_abs_r_difference']:.1e}" if "largest_abs_r_difference" in r else "",
            f"{r['largest_phase_r_difference_deg']:.1e}"
            if "largest_phase_r_difference_deg" in r
            else "",
        ]
        for r in doc["rows"]
    ]
    r = doc["rows"][0]
    note = (
        f"The split-ring slot cell, normal incidence, {r['band_hz'][0] / 1e9:g} to "
        f"{r['band_hz'][1] / 1e9:g} GHz, TE and TM solved at each frequency; the geometry "
        "once. Target: the whole curve (geometry and interpolating sweep) within "
        f"{r['target_s']:g} s."
    )
    return head, rows, note


def sweep_accuracy(doc: dict[str, Any]) -> Table:
    head = [
        "case",
        "triangles",
        "frequencies",
        "onsets",
        "solves",
        "largest estimate",
        "largest |ΔR|",
        "away from onsets",
        "frequencies above the estimate",
    ]
    rows = [
        [
            r["case"],
            _n(r["triangles"]),
            _n(r["frequencies"]),
            _n(len(r["onsets_hz"])),
            _n(r["solves"]),
            f"{r['largest_error_estimate']:.1e}",
            f"{r['largest_r_difference']:.1e}",
            f"{r['largest_r_difference_away_from_onsets']:.1e}",
            _n(r["frequencies_above_estimate"]),
        ]
        for r in doc["rows"]
    ]
    note = (
        "The interpolating sweep at its default tolerance "
        f"({doc['rows'][0]['tolerance']:g}) against a point-by-point sweep of every "
        "frequency: |ΔR| is the largest difference of any TE/TM component of the (0, 0) "
        'order\'s R; "away from onsets" leaves out the frequencies within 1 % of a '
        "grating-lobe onset."
    )
    return head, rows, note


def convergence(doc: dict[str, Any]) -> Table:
    head = [
        "case",
        "mesh",
        "n",
        "unknowns",
        "largest |R| error",
        "largest ∠R error °",
        "within the targets",
    ]
    rows = []

    def add(case: str, r: dict[str, Any], phase: float | None = None) -> None:
        met = r.get("meets_target")
        if met is None:
            met = r["unknowns"] <= doc["targets"]["unknowns"] and (
                r["abs_r_error"] <= doc["targets"]["abs_r"]
                and (phase or 0.0) <= doc["targets"]["phase_deg"]
            )
        rows.append(
            [
                case,
                r["series"],
                str(r["subdivisions"]),
                _n(r["unknowns"]),
                f"{r.get('max_abs_r_error', r.get('abs_r_error')):.4f}",
                f"{r.get('max_phase_error_deg', phase):.2f}",
                "yes" if met else "no",
            ]
        )

    if "patch" in doc:
        ref = doc["patch"]["reference"]
        # the reference's own meshes (graded n = 24, 28, 32) are left out of the table
        members = ref.get("subdivisions") or [int(x) for x in re.findall(r"\d+", ref["from"])]
        for r in doc["patch"]["rows"]:
            if not (r["series"] == "graded" and r["subdivisions"] in members):
                add(doc["patch"]["case"], r)
    if "strips" in doc:
        for r in doc["strips"]["rows"]:
            add(doc["strips"]["case"], r)
    if "first_order" in doc:
        f = doc["first_order"]
        members = sorted(r["subdivisions"] for r in f["rows"] if r["series"] == "graded")[-3:]
        for r in f["rows"]:
            if not (r["series"] == "graded" and r["subdivisions"] in members):
                add("patch 5 mm, 20 GHz, 0°", r, abs(r["phase_deg"] - f["reference_phase_deg"]))
    t = doc["targets"]
    note = (
        f"Targets: |R| within {t['abs_r']:g} and ∠R within {t['phase_deg']:g}° with at most "
        f"{t['unknowns']:,} unknowns. "
    )
    if "patch" in doc:
        p, ref = doc["patch"], doc["patch"]["reference"]
        angles = ", ".join(f"{a:g}°" for a in p["angles_deg"])
        freqs = p["frequencies_hz"]
        note += (
            f"{p['case'].capitalize()}: {freqs[0] / 1e9:g} to {freqs[-1] / 1e9:g} GHz "
            f"({len(freqs)} frequencies) at {angles}, TE and TM, against the Richardson "
            f"extrapolation of the {ref['from']} (orders {ref['orders'][0]:.1f} to "
            f"{ref['orders'][1]:.1f}, largest correction {ref['uncertainty_abs']:.1e}). "
        )
        for r in p.get("refused", []):
            note += (
                f"The {r['series']} n = {r['subdivisions']} is refused by the solver "
                f"({r['refused'].split(';')[0]}). "
            )
    if "strips" in doc:
        s = doc["strips"]
        note += (
            f"Strips: P/λ = {', '.join(f'{x:g}' for x in s['p_over_lambda'])} at "
            f"{', '.join(f'{a:g}°' for a in s['angles_deg'])}, E along and across, against "
            "the 1-D spectral-domain solution. "
        )
    if "first_order" in doc:
        f = doc["first_order"]
        note += (
            f"The 5 mm patch: against R = {f['reference_abs_r']:.5f} at "
            f"{f['reference_phase_deg']:.3f}° (graded n = 24, 28, 32 extrapolated)."
        )
    return head, rows, note


def layered(doc: dict[str, Any]) -> Table:
    s, w = doc["speed"], doc["sweep"]
    head = ["what", "size", "ours", "beside it", "target"]
    rows = [
        [
            "one frequency, grounded substrate (1.575 mm, εr 2.2)",
            f"{s['unknowns']:,} unknowns",
            f"{s['grounded_substrate_s']:.3f} s",
            f"free-standing {s['free_standing_s']:.3f} s ({s['ratio']:.2f}×)",
            f"≤ {s['target_ratio']:g}× ({'met' if s['target_met'] else 'missed'})",
        ],
        [
            "one frequency, thin lossy grounded substrate (0.5 mm, εr 4.4, tan δ 0.02)",
            f"{s['unknowns']:,} unknowns",
            f"{s['thin_lossy_grounded_s']:.3f} s",
            f"free-standing {s['free_standing_s']:.3f} s ({s['thin_ratio']:.2f}×)",
            "–",
        ],
        [
            f"{w['frequencies']}-frequency interpolating sweep on {w['stack']}",
            f"{w['triangles']:,} triangles, {w['unknowns']:,} unknowns",
            f"{w['curve_s']:.1f} s, {w['solves']} solves",
            f"point by point {w['point_by_point_s_per_solve']:.2f} s per frequency; "
            f"|ΔR| ≤ {w['largest_difference_r']:.1e}, |ΔT| ≤ {w['largest_difference_t']:.1e} "
            f"at {w['checked_frequencies']} frequencies",
            f"≤ {w['target_s']:g} s ({'met' if w['target_met'] else 'missed'})",
        ],
    ]
    note = (
        "The free-standing and the layered solves of the same cell alternate, best of the "
        "repetitions; the sweep's curve (geometry included) is checked against "
        "point-by-point solves of every tenth frequency."
    )
    return head, rows, note


def layered_convergence(doc: dict[str, Any]) -> Table:
    head = ["stack", "part of the kernel", "setting", "default", "|ΔR| from the default"]
    rows = [
        [r["stack"], r["part"], f"{r['value']:g}", f"{r['default']:g}", f"{r['difference']:.1e}"]
        for r in doc["convergence"]
    ]
    note = (
        "R of a graded 5 mm patch in a 10 mm cell at 12 GHz, 20° TM, as the spectral rest "
        "is cut at looser tolerances (its terms over the leading 1/|κ|) and the blend of "
        "the exactly integrated harmonics is made narrower or wider (in smallest "
        "reciprocal vectors)."
    )
    return head, rows, note


def layered_validation(doc: dict[str, Any]) -> Table:
    head = ["case", "GHz", "pol.", "unknowns", "|R| ours", "reference", "|ΔR|", "Δ∠R °"]
    rows = [
        [
            r["case"],
            f"{r['frequency_hz'] / 1e9:g}",
            r["polarization"],
            _n(r["unknowns"]) if r["unknowns"] else "–",
            f"{abs(complex(*r['r'])):.5f}",
            f"{abs(complex(*r['reference'])):.5f}",
            f"{r['difference']:.1e}",
            f"{r['phase_difference_deg']:.3f}",
        ]
        for r in doc["validation"]
    ]
    note = (
        "Strip gratings (width P/2, P = 10 mm, 20° incidence) against an independent 1-D "
        "spectral-domain Galerkin solution with edge-conditioned Chebyshev currents "
        "(tests/strip_spectral.py) on meshes graded toward the strip edges; the grounded "
        "slab without metal against the closed form; a fully metallised cell over the "
        "grounded substrate, R = −1 at the sheet."
    )
    return head, rows, note


def library(doc: dict[str, Any]) -> Table:
    head = ["how", "wall s", "s per value", "CPU s (this process)"]
    names = {
        "here": "here: TE and TM from one fill per value",
        "two_points": "two points per value (before)",
        "dask": "Dask cluster, {workers} worker processes (a point per polarisation)",
    }
    rows = []
    for key, r in doc["rows"].items():
        rows.append(
            [
                names[key].format(**r),
                _s(r["wall_s"], 2),
                _s(r["per_value_s"], 3),
                _s(r.get("cpu_s"), 2),
            ]
        )
    lib = doc["library"]
    lo, hi, count = lib["values_mm"]
    note = (
        f"A {count}-value reflection-phase library: {lib['cell']}, n = {lib['subdivisions']} "
        f"({lib['largest_unknowns']:,} unknowns at the largest patch), its size from {lo:g} "
        f"to {hi:g} mm at {lib['frequency_hz'] / 1e9:g} GHz, normal incidence, on "
        f'"{lib["stack"]}"; both polarisations at every value. Best of {doc["repeats"]} '
        f"runs; the ways agree to 1e-12 of max |R|. The curve covers {lib['covers_deg']:.0f}°."
    )
    return head, rows, note


RENDERERS: dict[str, Callable[[dict[str, Any]], Table]] = {
    "library": library,
    "convergence": convergence,
    "layered": layered,
    "layered:convergence": layered_convergence,
    "layered:validation": layered_validation,
    "array-live": array_live,
    "sweep-accuracy": sweep_accuracy,
    "periodic-sweep": periodic_sweep,
    "grading": grading,
    "mesher": mesher,
    "solver": solver,
    "solver-bempp": solver_bempp,
    "quality": quality,
    "latency": latency,
    "latency-big": latency,  # the dense rounds (--big-only), not the teaching round's file
    "latency-interaction": latency_interaction,
    "periodic": periodic,
    "startup": startup,
}


def table_data(name: str) -> tuple[list[str], list[list[str]], str] | None:
    """Benchmark ``name``'s header, rows and the line under them; None without a result."""
    path = newest(name.split(":")[0])
    if path is None:
        return None
    doc = json.loads(path.read_text(encoding="utf-8"))
    head, rows, note = RENDERERS[name](doc)
    rel = path.relative_to(ROOT)
    if name in ("quality", "grading", "convergence"):  # accuracy: the same on any machine
        line = f"From {rel}, measured {_date(path, doc)}. {note}"
    else:
        line = f"From {rel}, measured {_date(path, doc)} on {_machine(doc.get('machine'))}. {note}"
    return head, rows, line


def _table(head: list[str], rows: list[list[str]]) -> nodes.table:
    table = nodes.table(classes=["benchmark-table"])
    group = nodes.tgroup(cols=len(head))
    table += group
    for _ in head:
        group += nodes.colspec(colwidth=1)
    for part, lines in ((nodes.thead(), [head]), (nodes.tbody(), rows)):
        for cells in lines:
            row = nodes.row()
            for text in cells:
                row += nodes.entry("", nodes.paragraph(text=text))
            part += row
        group += part
    return table


class BenchmarkTable(SphinxDirective):
    required_arguments = 1
    has_content = False

    def run(self) -> list[nodes.Node]:
        name = self.arguments[0]
        if name not in RENDERERS:
            known = sorted(RENDERERS)
            raise self.error(f"benchmark-table: unknown benchmark {name!r}; known: {known}")
        base = name.split(":")[0]
        path = newest(base)
        if path is None:
            text = (
                f"No stored result of benchmarks/{base}.py yet: run it with "
                f"--json benchmarks/results/{base}-YYYY-MM-DD.json."
            )
            return [nodes.paragraph(text=text)]
        self.env.note_dependency(str(path))
        head, rows, line = table_data(name)
        return [_table(head, rows), nodes.paragraph(text=line)]


def setup(app):  # noqa: ANN001
    app.add_directive("benchmark-table", BenchmarkTable)
    return {"parallel_read_safe": True, "parallel_write_safe": True}
