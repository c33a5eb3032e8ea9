"""Edge refinement: how fast the current at a gap side converges, uniform vs graded meshes.

Structure: the split ring of the preset ``srr-openmodes`` (inner radius 3.5 mm,
0.5 mm track, one 1 mm slot at 180°, conforming), a perfect conductor in free
space, lit by a plane wave travelling along −z with E along y (across the
slot, the polarisation that drives the ring's LC resonance near 6.2 GHz) at
5 GHz, below that resonance, so that the answer is not dominated by how
far each mesh shifts the resonance. A plane wave rather than a delta-gap
source: the slot is empty, so there is no metal edge to feed across it, and a
delta-gap's own singular current would blur the edge singularity studied here.

Quantities:

* ``I_cut``: the total current crossing a straight cut across the track one
  sector away from the slot's side (the first sector boundary of the uniform
  conforming meshes, from 3.5 mm to 4 mm, about 0.3 mm from the slot side),
  ∫ J·n dl. It is integrated exactly: the cut is clipped against every
  triangle and J, linear on a triangle, is taken at the middle of each piece.
  By continuity it equals −jω times the charge between the slot side and the
  cut, which the script checks (``continuity_error``). The charge there is
  singular at the slot side (∝ s^(−1/2)): this is the quantity that edge
  refinement should help. Measured at both sides of the slot; the ring and
  the wave are mirror images of minus themselves, so the two currents are
  opposite, and their mean (``I_cut``) cancels the asymmetry of the
  triangles' diagonals (up to 1.3 % between the sides on the coarsest mesh).
* ``m_z``: the induced magnetic dipole moment ½ ∫ (r × J)_z dS about the ring's
  centre, a global quantity.

Reference: Richardson extrapolation in h = N^(−1/2) (N RWG unknowns) from
the two finest uniform meshes with order 1, Q∞ = Q₂ + (Q₂ − Q₁) h₂ / (h₁ − h₂).
Order 1 is assumed as the asymptotic rate of such integral quantities (the
square of a Galerkin error of order ½ in the energy norm, which the s^(−1/2)
edge singularity allows); the order fitted to the three finest meshes is
reported beside it and comes out below 1 (pre-asymptotic). The reference's
uncertainty is the larger of its change from the extrapolation of the two
meshes before and its change from the three-point extrapolation with the
fitted order. Errors are |Q − Q∞| / |Q∞|.

Series: uniform refinement (``subdivisions`` n = 1, 2, ... while N stays
under ``--max-unknowns``); graded meshes (``grading=True`` with a few
``growth_ratio`` / ``min_edge`` pairs) when :class:`barymesh.MeshParams` has those
fields, else skipped with a message.

Usage::

    python benchmarks/grading.py                       # figure, table on stdout
    python benchmarks/grading.py --json out.json --markdown out.md --png fig.png
    python benchmarks/grading.py --quick               # tiny sizes (the test suite)
"""

from __future__ import annotations

import argparse
import dataclasses
import json
import sys
import time
from pathlib import Path

import numpy as np
from scipy.optimize import brentq

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))

from barymesh import MeshParams, build_mesh  # noqa: E402
from barymesh.mesh import TriMesh  # noqa: E402
from barymesh.mom import PlaneWave, Solution, check_memory, solve  # noqa: E402
from barymesh.params import MAX_UNIFORM_SUBDIVISIONS  # noqa: E402
from barymesh.presets import load_preset  # noqa: E402

PRESET = "srr-openmodes"
FREQUENCY = 5e9
MAX_UNKNOWNS = 6000
WAVE = PlaneWave(direction=(0, 0, -1), polarization=(0, 1, 0))
GRADING_FIELDS = ("grading", "growth_ratio", "min_edge")
#: Graded series: (growth_ratio, min_edge in mm or None for the mesher's default).
GRADED = ((1.5, None), (2.0, None), (1.5, 0.05), (2.0, 0.03))
QUICK_GRADED = ((2.0, None),)
#: Offset (mm) of the cut from its nominal place, so that it never runs along a mesh edge.
CUT_JITTER = 1.234567e-7
MM = 1e-3


# -- the quantities -----------------------------------------------------------------------


def _cross2(u: np.ndarray, v: np.ndarray) -> np.ndarray:
    """z component of u × v for (..., 2) vectors."""
    return u[..., 0] * v[..., 1] - u[..., 1] * v[..., 0]


def segment_pieces(corners: np.ndarray, a: np.ndarray, b: np.ndarray) -> tuple[np.ndarray, ...]:
    """Where the segment a→b crosses each triangle.

    Parameters
    ----------
    corners : (T, 3, 2) float
        Triangle corners.
    a, b : (2,) float
        Segment ends.

    Returns
    -------
    tri : (M,) intp
        Triangles the segment crosses over a positive length.
    t0, t1 : (M,) float
        Parameters in [0, 1] of the piece inside each of them.
    """
    d = b - a
    cross = _cross2
    nxt = np.roll(corners, -1, axis=1)
    edge = nxt - corners  # (T, 3, 2)
    orient = np.sign(cross(edge[:, 0], edge[:, 1]))[:, None]  # +1 counter-clockwise
    # inside: orient * cross(edge, p - corner) >= 0 for p = a + t d, i.e. c0 + c1 t >= 0
    c0 = orient * cross(edge, a - corners)
    c1 = orient * cross(edge, d)
    with np.errstate(divide="ignore", invalid="ignore"):
        root = -c0 / c1
    lo = np.where(c1 > 0, root, -np.inf).max(axis=1)
    hi = np.where(c1 < 0, root, np.inf).min(axis=1)
    parallel_out = ((c1 == 0) & (c0 < 0)).any(axis=1)
    t0, t1 = np.maximum(lo, 0.0), np.minimum(hi, 1.0)
    keep = (t1 > t0) & ~parallel_out
    return np.flatnonzero(keep), t0[keep], t1[keep]


def cut_line(params: MeshParams, side: int) -> tuple[np.ndarray, ...]:
    """The cut across the track one sector away from one side of the slot.

    The straight line through the inner-circle and outer-circle corners of
    the first sector boundary next to the slot's side on the ``side`` × 90°
    side of its centre line (``side`` is +1 or −1), as the uniform conforming
    mesh lays it out (taken from the n = 1 mesh, so the same line for every
    mesh of the study; about 0.3 mm from the slot side for the preset). It
    runs across the whole track and a little beyond, offset by a hair
    (``CUT_JITTER``) so that it crosses triangles instead of running along
    their edges.

    Returns
    -------
    a, b : (2,) float
        Ends of the cut (mm).
    normal : (2,) float
        Unit normal of the cut pointing away from the slot.
    towards : (2,) float
        Unit normal of the slot's centre line pointing to that side.
    """
    uniform = dataclasses.replace(params, subdivisions=1, **_no_grading())
    mesh = build_mesh(uniform)
    origin = np.asarray(params.origin, dtype=float)
    xy = mesh.points[:, :2] - origin
    theta = np.radians(params.gap_angle)
    # angles measured from the slot's centre line, in (0, 360) towards the side
    angle = np.mod(side * (np.arctan2(xy[:, 1], xy[:, 0]) - theta), 2 * np.pi)
    radius = np.hypot(xy[:, 0], xy[:, 1])
    ends = []
    for r in (params.inner_radius, params.inner_radius + params.patch_size):
        on = np.flatnonzero(np.abs(radius - r) < 1e-6 * r)
        corner = on[np.argsort(angle[on])[1]]  # [0] is the slot side's own corner
        ends.append(mesh.points[corner, :2])
    a, b = ends
    d = b - a
    normal = np.array([-d[1], d[0]]) / np.linalg.norm(d)
    towards = side * np.array([-np.sin(theta), np.cos(theta)])
    if normal @ towards < 0:
        normal = -normal
    shift = CUT_JITTER * normal
    return a - 0.2 * d + shift, b + 0.2 * d + shift, normal, towards


def _no_grading() -> dict:
    return {"grading": False} if has_grading() else {}


def cut_current(
    sol: Solution, mesh: TriMesh, a: np.ndarray, b: np.ndarray, normal: np.ndarray
) -> complex:
    """∫ J·normal dl (A) over the segment a→b (mm): the current crossing it.

    Exact for the RWG current, which is linear on each triangle.
    """
    tri, t0, t1 = segment_pieces(mesh.points[mesh.triangles][:, :, :2], a, b)
    d = b - a
    mid = a + 0.5 * (t0 + t1)[:, None] * d
    j = sol.current_at(tri, np.column_stack([mid, np.zeros(len(mid))]))
    length = (t1 - t0) * np.linalg.norm(d) * MM
    return complex(np.sum(length * (j[:, :2] @ normal)))


def charge_before_cut(
    sol: Solution,
    mesh: TriMesh,
    params: MeshParams,
    a: np.ndarray,
    normal: np.ndarray,
    towards: np.ndarray,
) -> complex:
    """Charge (C) on the metal between the slot side and the cut through ``a``.

    Triangles in the quarter of the ring between the slot's centre line and
    ``towards`` are clipped by the half-plane on the slot's side of the cut.
    """
    xy = mesh.points[:, :2]
    s = -((xy - a) @ normal)  # > 0 between the slot and the cut
    corners_s = s[mesh.triangles]  # (T, 3)
    origin = np.asarray(params.origin, dtype=float)
    theta = np.radians(params.gap_angle)
    along = np.array([np.cos(theta), np.sin(theta)])
    c = mesh.centroids[:, :2] - origin
    near = (c @ towards > 0) & (c @ along > 0)  # the quarter of the ring at the slot's side
    inside = corners_s > 0
    count = inside.sum(axis=1)
    srt = np.sort(corners_s, axis=1)  # ascending
    frac = np.zeros(mesh.n_triangles)
    frac[count == 3] = 1.0
    one = count == 1  # the largest corner alone inside
    si, sj, sk = srt[one, 2], srt[one, 0], srt[one, 1]
    frac[one] = si**2 / ((si - sj) * (si - sk))
    two = count == 2  # the smallest corner alone outside
    so, sa, sb = srt[two, 0], srt[two, 1], srt[two, 2]
    frac[two] = 1.0 - so**2 / ((so - sa) * (so - sb))
    area = mesh.areas * MM**2
    return complex(np.sum((sol.charge_density * area * frac)[near]))


def magnetic_moment_z(sol: Solution, params: MeshParams) -> complex:
    """m_z (A·m²) about the ring's centre."""
    _, m = sol.dipole_moments(origin=(*params.origin, 0.0))
    return complex(m[2])


# -- the series ------------------------------------------------------------------------------


def has_grading() -> bool:
    """True when MeshParams has the grading fields (the feature has landed)."""
    names = {f.name for f in dataclasses.fields(MeshParams)}
    return all(name in names for name in GRADING_FIELDS)


def run_one(params: MeshParams, mesh: TriMesh, label: str, cut: tuple) -> dict:
    """Solve ``mesh`` (built from ``params``) and measure the quantities (a JSON-ready row)."""
    n_unknowns = len(mesh.rwg)
    check_memory(n_unknowns)
    start = time.perf_counter()
    sol = solve(mesh, FREQUENCY, WAVE)
    seconds = time.perf_counter() - start
    omega = 2 * np.pi * FREQUENCY
    currents, continuity = [], []
    for a, b, normal, towards in cut:
        current = cut_current(sol, mesh, a, b, normal)
        charge = charge_before_cut(sol, mesh, params, a, normal, towards)
        currents.append(current)
        continuity.append(abs(current + 1j * omega * charge) / abs(current))
    # the ring and the wave are mirror images of minus themselves across the slot's
    # centre line: the currents leaving the two slot sides are opposite; their mean
    # cancels the mirror asymmetry of the triangles' diagonals
    current = (currents[0] - currents[1]) / 2
    edges = mesh.points[mesh.triangles[:, [1, 2, 0]]] - mesh.points[mesh.triangles]
    lengths = np.linalg.norm(edges, axis=2)
    m_z = magnetic_moment_z(sol, params)
    row = {
        "series": label,
        "subdivisions": params.subdivisions,
        "triangles": int(mesh.n_triangles),
        "unknowns": int(n_unknowns),
        "min_edge_mm": float(lengths.min()),
        "max_edge_mm": float(lengths.max()),
        "I_cut": [current.real, current.imag],
        "m_z": [m_z.real, m_z.imag],
        "I_sides": [[c.real, c.imag] for c in currents],
        "continuity_error": max(continuity),
        "residual": sol.residual,
        "solve_s": seconds,
    }
    if has_grading():
        row.update({k: getattr(params, k) for k in GRADING_FIELDS})
    return row


def series(
    base: MeshParams, label: str, cut: tuple, max_unknowns: int, max_n: int, **grading
) -> list[dict]:
    """Rows for n = 1, 2, ... until a mesh would exceed ``max_unknowns`` RWG unknowns."""
    rows = []
    for n in range(1, max_n + 1):
        min_edge = grading.get("min_edge")
        if min_edge is not None and not min_edge < base.patch_size / n:
            continue  # the graded cells would be no finer than the uniform ones
        params = dataclasses.replace(base, subdivisions=n, **grading)
        mesh = build_mesh(params)
        if len(mesh.rwg) > max_unknowns:
            break
        rows.append(run_one(params, mesh, label, cut))
        r = rows[-1]
        print(f"  {label:<34} n={n}  N={r['unknowns']:>5}  {r['solve_s']:6.1f} s", flush=True)
    return rows


def value(row: dict, key: str) -> complex:
    return complex(*row[key])


def extrapolate(rows: list[dict], key: str, order: float) -> complex:
    """Q∞ from the last two rows, Q = Q∞ + C h^order, h = N^(−1/2)."""
    (h1, h2), (q1, q2) = _last(rows, key, 2)
    return q2 + (q2 - q1) * h2**order / (h1**order - h2**order)


def fitted_order(rows: list[dict], key: str) -> float | None:
    """The order p of Q = Q∞ + C h^p through the last three rows, or None if none fits."""
    h, q = _last(rows, key, 3)
    ratio = abs(q[2] - q[1]) / abs(q[1] - q[0])

    def gap(p: float) -> float:
        return (h[1] ** p - h[2] ** p) / (h[0] ** p - h[1] ** p) - ratio

    lo, hi = 0.02, 8.0
    return None if gap(lo) * gap(hi) > 0 else float(brentq(gap, lo, hi))


def _last(rows: list[dict], key: str, k: int) -> tuple[np.ndarray, np.ndarray]:
    if len(rows) < k:
        raise ValueError(f"{key}: extrapolation needs {k} meshes, got {len(rows)}")
    h = np.array([r["unknowns"] ** -0.5 for r in rows[-k:]])
    return h, np.array([value(r, key) for r in rows[-k:]])


def reference(uniform: list[dict], key: str) -> dict:
    """The Richardson reference of ``key`` from the uniform series (see the module doc)."""
    q = extrapolate(uniform, key, 1.0)
    ref = {
        "value": [q.real, q.imag],
        "order": 1.0,
        "from_unknowns": [r["unknowns"] for r in uniform[-2:]],
    }
    changes = []
    if len(uniform) >= 3:
        before = extrapolate(uniform[:-1], key, 1.0)
        ref["previous_pair"] = [before.real, before.imag]
        changes.append(abs(q - before) / abs(q))
        p = fitted_order(uniform, key)
        ref["fitted_order"] = p
        if p is not None:
            fitted = extrapolate(uniform, key, p)
            ref["fitted_order_value"] = [fitted.real, fitted.imag]
            changes.append(abs(q - fitted) / abs(q))
    ref["uncertainty"] = max(changes) if changes else None
    return ref


def add_errors(rows: list[dict], refs: dict) -> None:
    for r in rows:
        for key, ref in refs.items():
            q = complex(*ref["value"])
            r[f"{key}_error"] = abs(value(r, key) - q) / abs(q)


def slot_distance(params: MeshParams, cut: tuple[np.ndarray, ...]) -> list[float]:
    """Distances (mm) of the cut's two ends on the circles from the slot's side line."""
    a, b, _, side = cut
    d = b - a
    origin = np.asarray(params.origin, dtype=float)
    # the cut runs from 0.2 before the inner corner to 0.2 past the outer one (cut_line)
    corners = (a + 0.2 / 1.4 * d, a + 1.2 / 1.4 * d)
    return [float((c - origin) @ side - params.gap_width / 2) for c in corners]


# -- output ----------------------------------------------------------------------------------


def markdown(rows: list[dict], refs: dict, dist: list[float]) -> str:
    """The rows as a Markdown table, the reference above it."""
    i_ref, m_ref = refs["I_cut"], refs["m_z"]
    lines = [
        f"Reference: Richardson (order 1 in N^-1/2) from uniform N = "
        f"{' and '.join(f'{n:,}' for n in i_ref['from_unknowns'])}: "
        f"I_cut = {_c(i_ref['value'])} A (uncertainty {_pct(i_ref['uncertainty'])}, "
        f"fitted order {_order(i_ref)}), m_z = {_c(m_ref['value'])} A·m² (uncertainty "
        f"{_pct(m_ref['uncertainty'])}, fitted order {_order(m_ref)}); cut "
        f"{dist[0]:.2f}–{dist[1]:.2f} mm from the slot side, {FREQUENCY / 1e9:g} GHz.",
        "",
        "| series | n | triangles | N | shortest edge (mm) | I_cut error | m_z error |",
        "|---|---:|---:|---:|---:|---:|---:|",
    ]
    for r in rows:
        lines.append(
            f"| {r['series']} | {r['subdivisions']} | {r['triangles']:,} | {r['unknowns']:,} | "
            f"{r['min_edge_mm']:.3f} | {_pct(r['I_cut_error'])} | {_pct(r['m_z_error'])} |"
        )
    return "\n".join(lines)


def _c(v: list[float]) -> str:
    return f"{v[0]:.4g}{v[1]:+.4g}j"


def _pct(x: float | None) -> str:
    return "n/a" if x is None else f"{100 * x:.2f} %"


def _order(ref: dict) -> str:
    p = ref.get("fitted_order")
    return "none" if p is None else f"{p:.2f}"


def figure(rows: list[dict], refs: dict, path: Path, dist: list[float]) -> None:
    """Relative error vs RWG unknowns, one panel per quantity, one line per series."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    from matplotlib.ticker import FuncFormatter, LogLocator, NullFormatter

    fig, axes = plt.subplots(1, 3, figsize=(15, 4.6), constrained_layout=True)
    titles = {
        "I_cut": f"current across the track {dist[0]:.2f}–{dist[1]:.2f} mm from the slot side",
        "m_z": "magnetic dipole moment m_z",
    }
    labels = list(dict.fromkeys(r["series"] for r in rows))
    markers = "osD^v<>"
    for ax, key in zip(axes[:2], ("I_cut", "m_z"), strict=True):
        for i, label in enumerate(labels):
            sel = [r for r in rows if r["series"] == label]
            n = [r["unknowns"] for r in sel]
            e = [max(r[f"{key}_error"], 1e-6) for r in sel]
            style = "-" if label == "uniform" else "--"
            ax.loglog(n, e, style, marker=markers[i % len(markers)], label=label)
        unc = refs[key].get("uncertainty")
        if unc:
            ax.axhspan(
                1e-6,
                unc,
                color="grey",
                alpha=0.15,
                lw=0,
                label="within the reference's uncertainty",
            )
        _unknowns_axis(ax)
        ax.yaxis.set_major_locator(LogLocator(subs=(1.0, 2.0, 5.0)))
        ax.yaxis.set_major_formatter(FuncFormatter(lambda y, _: f"{100 * y:g} %"))
        ax.yaxis.set_minor_formatter(NullFormatter())
        errors = [r[f"{key}_error"] for r in rows] + ([unc] if unc else [])
        ax.set_ylim(max(min(errors) / 2, 1e-6), max(errors) * 1.5)
        ax.set_title(titles[key], fontsize=10)
        ax.set_xlabel("RWG unknowns N")
        ax.set_ylabel("relative error")
        ax.grid(True, which="both", alpha=0.3)
        ax.legend(fontsize=8)
    ax = axes[2]
    ref = abs(complex(*refs["I_cut"]["value"])) * 1e6
    for i, label in enumerate(labels):
        sel = [r for r in rows if r["series"] == label]
        style = "-" if label == "uniform" else "--"
        ax.semilogx(
            [r["unknowns"] for r in sel],
            [abs(value(r, "I_cut")) * 1e6 for r in sel],
            style,
            marker=markers[i % len(markers)],
            label=label,
        )
    unc = refs["I_cut"].get("uncertainty") or 0.0
    ax.axhline(ref, color="black", lw=0.8, label="reference")
    ax.axhspan(ref * (1 - unc), ref * (1 + unc), color="grey", alpha=0.15, lw=0)
    _unknowns_axis(ax)
    ax.set_title(
        f"|I| across the track {dist[0]:.2f}–{dist[1]:.2f} mm from the slot side", fontsize=10
    )
    ax.set_xlabel("RWG unknowns N")
    ax.set_ylabel("|I| (µA) for |E| = 1 V/m")
    ax.grid(True, which="both", alpha=0.3)
    ax.legend(fontsize=8, loc="upper left")
    fig.suptitle(
        f"{PRESET} at {FREQUENCY / 1e9:g} GHz, plane wave with E across the slot: "
        "errors against the Richardson reference of the uniform meshes (left, middle) and "
        "the current itself (right)",
        fontsize=10,
    )
    fig.savefig(path, dpi=110)
    plt.close(fig)


def _unknowns_axis(ax) -> None:
    from matplotlib.ticker import FixedLocator, FuncFormatter, NullFormatter

    ax.xaxis.set_major_locator(FixedLocator([100, 200, 500, 1000, 2000, 5000, 10000]))
    ax.xaxis.set_major_formatter(FuncFormatter(lambda x, _: f"{x:,.0f}"))
    ax.xaxis.set_minor_formatter(NullFormatter())


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--quick", action="store_true", help="tiny sizes (n ≤ 4, one graded series)")
    ap.add_argument(
        "--max-unknowns",
        type=int,
        default=MAX_UNKNOWNS,
        help=f"largest mesh, in RWG unknowns (default {MAX_UNKNOWNS})",
    )
    ap.add_argument("--json", metavar="PATH", help="write rows and reference as JSON")
    ap.add_argument("--markdown", metavar="PATH", help="write the table as Markdown")
    ap.add_argument(
        "--png",
        metavar="PATH",
        help="write the figure (default: assets/grading-convergence.png, none with --quick)",
    )
    args = ap.parse_args(argv)
    if args.max_unknowns < 500:
        ap.error(
            f"--max-unknowns={args.max_unknowns} is too small; expected at least 500 "
            "(three uniform meshes)"
        )
    base = load_preset(PRESET)[0]
    cut = (cut_line(base, +1), cut_line(base, -1))
    dist = slot_distance(base, cut[0])
    max_n = 4 if args.quick else MAX_UNIFORM_SUBDIVISIONS
    print(f"{PRESET}: uniform refinement", flush=True)
    uniform = series(base, "uniform", cut, args.max_unknowns, max_n)
    refs = {key: reference(uniform, key) for key in ("I_cut", "m_z")}
    rows = list(uniform)
    graded_note = None
    if has_grading():
        plan = QUICK_GRADED if args.quick else GRADED
        for ratio, min_edge in plan:
            label = f"graded r={ratio:g}, min_edge=" + (
                "default" if min_edge is None else f"{min_edge:g} mm"
            )
            rows += series(
                base,
                label,
                cut,
                args.max_unknowns,
                2 if args.quick else max_n,
                grading=True,
                growth_ratio=ratio,
                min_edge=min_edge,
            )
    else:
        graded_note = (
            "graded series skipped: barymesh.MeshParams has no grading fields "
            f"({', '.join(GRADING_FIELDS)}); uniform refinement only"
        )
        print(graded_note, flush=True)
    add_errors(rows, refs)
    table = markdown(rows, refs, dist)
    print(table)
    if args.json:
        doc = {
            "preset": PRESET,
            "frequency_hz": FREQUENCY,
            "excitation": {
                "direction": WAVE.direction.tolist(),
                "polarization": WAVE.polarization.real.tolist(),
            },
            "cuts": [
                {"start_mm": a.tolist(), "end_mm": b.tolist(), "normal": n.tolist()}
                for a, b, n, _ in cut
            ],
            "slot_distance_mm": dist,
            "reference": refs,
            "graded": graded_note or "run",
            "rows": rows,
        }
        Path(args.json).write_text(json.dumps(doc, indent=2) + "\n", encoding="utf-8")
    if args.markdown:
        Path(args.markdown).write_text(table + "\n", encoding="utf-8")
    png = args.png or (None if args.quick else str(ROOT / "assets" / "grading-convergence.png"))
    if png:
        figure(rows, refs, Path(png), dist)
        print(f"figure: {png}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
