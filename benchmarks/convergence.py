"""How the infinite-array solver's |R| and ∠R converge on uniform and edge-graded meshes.

Issue 29 asks the default meshes where a mesh is made to be solved to come within 0.005
of converged references in |R| and 0.5° in ∠R with 1,000 RWG unknowns or fewer, for
patches and strips in free space. This script measures it (accuracy only: no time is
asserted anywhere):

* ``patch``: the cell API's patch, 8 mm square in a 10 mm square cell (``UnitCell`` of one
  ``Element``), 5 to 35 GHz every 5 GHz at θ = 0°, 30° and 60° (φ = 0), TE and TM, on
  uniform meshes (n = 8 … 32) and graded ones (``grading=True``, n = 8 … 32). The
  reference at each point is the Richardson extrapolation of the graded n = 24, 28, 32
  (the order fitted to the three, or 2 when they do not converge monotonically), its
  uncertainty the last correction; the uniform n = 24 and 32, extrapolated at order 1,
  cross-check it.
* ``first-order``: the issue's 5 mm patch in a 10 mm cell at 20 GHz, normal incidence: the
  uniform meshes converge at first order in 1/n, the graded ones faster.
* ``strips``: strips of width P/2 across a 10 mm cell (a patch element 5 × 10 mm that
  reaches both sides, graded across and uniform along), E along and across, θ = 0°, 30°,
  60°, P/λ = 0.05 … 0.9, against the 1-D spectral-domain solution
  (``tests/strip_spectral.py``, free-standing: εr = 1, no ground), itself checked
  against Collin's table and, at P/λ ≤ 0.1, Marcuvitz's quasi-static formulas.
* ``babinet``: a 5 mm patch painted as 8 × 8 pixels of 0.625 mm and its complement (the
  16 × 16 grid spanning the cell, the patch's pixels left out), uniform and graded
  pixels: T + T' − 1 (Babinet: 0).

Usage::

    python benchmarks/convergence.py --json benchmarks/results/convergence-YYYY-MM-DD.json
    python benchmarks/convergence.py --quick --json out.json   # the test suite's run
"""

from __future__ import annotations

import argparse
import json
import sys
import time
from pathlib import Path
from typing import Any

import numpy as np
from scipy.optimize import brentq

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT / "tests"))

from machine import machine  # noqa: E402
from strip_spectral import marcuvitz_reflection, strip_reflection  # noqa: E402

POLARIZATION = {"along": "te", "across": "tm"}  # E along the strips: TE, across: TM

from barymesh import MeshParams  # noqa: E402
from barymesh.cell import Element, Lattice, PixelGrid, UnitCell, build_cell  # noqa: E402
from barymesh.constants import SPEED_OF_LIGHT  # noqa: E402
from barymesh.mesh import TriMesh  # noqa: E402
from barymesh.mom import PlaneWave, grating_lobe_onsets, periodic_solve_many  # noqa: E402

PERIOD = 10.0  # mm
TARGET_ABS = 0.005
TARGET_PHASE = 0.5  # degrees
TARGET_UNKNOWNS = 1000
COLLIN = {  # P/λ -> (|Γ⊥|, ∠Γ⊥ in degrees, |Γ∥|): Field Theory of Guided Waves, problem 10.6
    0.1: (0.0694, -94.0, 0.9976),
    0.3: (0.2106, -102.2, 0.9776),
    0.5: (0.3598, -111.1, 0.9330),
    0.8: (0.6231, -128.5, 0.7822),
    0.9: (0.7381, -137.6, 0.6747),
}


def log(*args: Any) -> None:
    print(*args, flush=True)


# -- meshes ----------------------------------------------------------------------------------


def patch_cell(size: float, n: int, graded: bool) -> TriMesh:
    """A square patch of side ``size`` (mm) centred in the 10 mm cell, by the cell API."""
    params = MeshParams(structure="patch", patch_size=size, subdivisions=n, grading=graded)
    element = Element(params, position=(-size / 2, -size / 2), name="patch")
    return build_cell(UnitCell(Lattice.rectangular(PERIOD), (element,))).mesh


def strip_cell(n: int, graded: bool) -> TriMesh:
    """Strips of width P/2 along y that reach both sides of the cell (n × n per primary)."""
    width = PERIOD / 2
    params = MeshParams(
        structure="patch", patch_size=width, patch_width=PERIOD, subdivisions=n, grading=graded
    )
    element = Element(params, position=(-width / 2, -PERIOD / 2), name="strip")
    return build_cell(UnitCell(Lattice.rectangular(PERIOD), (element,))).mesh


def pixel_cells(n: int, graded: bool, across: int = 16) -> tuple[TriMesh, TriMesh]:
    """A 5 mm patch as the centre half of a grid of ``across`` x ``across`` pixels spanning
    the cell, and its complement (every other pixel of the grid)."""
    mask = np.zeros((across, across), dtype=bool)
    mask[across // 4 : 3 * across // 4, across // 4 : 3 * across // 4] = True
    cells = []
    for m in (mask, ~mask):
        grid = PixelGrid(m, PERIOD / across, (-PERIOD / 2, -PERIOD / 2), n, grading=graded)
        cells.append(build_cell(UnitCell(Lattice.rectangular(PERIOD), pixels=grid)).mesh)
    return cells[0], cells[1]


def unknowns(mesh: TriMesh) -> int:
    """RWG unknowns of a cell: interior edges plus the pairs of edges across its sides."""
    return int(len(mesh.rwg) + len(mesh.periodic_pairs.edges) // 2)


# -- solving ---------------------------------------------------------------------------------


def waves(theta: float) -> tuple[PlaneWave, PlaneWave]:
    """TE (E along φ̂ = ŷ) and TM (E along θ̂) from θ in the xz plane."""
    return PlaneWave.from_angles(theta, 0.0, 90.0), PlaneWave.from_angles(theta, 0.0, 0.0)


def solve_grid(
    mesh: TriMesh, frequencies: list[float], angles: list[float]
) -> dict[tuple[float, float], tuple[complex, complex]]:
    """(θ, f) -> (R_TE, R_TM), co-polar (0, 0)."""
    out = {}
    for theta in angles:
        for f in frequencies:
            te, tm = periodic_solve_many(mesh, f, waves(theta))
            out[theta, f] = (complex(te.co_polar()[0]), complex(tm.co_polar()[0]))
    return out


def order_of(v: list[complex], n: list[int]) -> float | None:
    """Convergence order p in h = 1/n from three values, or None if not monotone."""
    d1, d2 = abs(v[1] - v[0]), abs(v[2] - v[1])
    if d2 == 0 or d1 <= d2:
        return None
    h = [1.0 / k for k in n]

    def gap(p: float) -> float:
        return (h[0] ** p - h[1] ** p) / (h[1] ** p - h[2] ** p) - d1 / d2

    try:
        return float(brentq(gap, 0.2, 8.0))
    except ValueError:
        return None


def richardson(v: list[complex], n: list[int], nominal: float) -> tuple[complex, float, float]:
    """(extrapolated value, order used, uncertainty = the last correction's size)."""
    p = order_of(v, n)
    if p is None:
        p = nominal
    r = n[2] / n[1]
    ext = v[2] + (v[2] - v[1]) / (r**p - 1.0)
    return ext, p, abs(ext - v[2])


def errors(
    values: dict[tuple[float, float], tuple[complex, complex]],
    reference: dict[tuple[float, float], tuple[complex, complex]],
) -> dict[str, Any]:
    """Worst |R| and ∠R errors over the grid, and where."""
    worst_abs = worst_phase = 0.0
    where_abs: Any = None
    where_phase: Any = None
    for key, pair in values.items():
        for pol, r, ref in zip(("TE", "TM"), pair, reference[key], strict=True):
            e_abs = abs(abs(r) - abs(ref))
            e_phase = abs(float(np.degrees(np.angle(r / ref))))
            if e_abs > worst_abs:
                worst_abs, where_abs = e_abs, [key[0], key[1], pol]
            if e_phase > worst_phase:
                worst_phase, where_phase = e_phase, [key[0], key[1], pol]
    return {
        "max_abs_r_error": worst_abs,
        "max_phase_error_deg": worst_phase,
        "worst_abs_at": where_abs,
        "worst_phase_at": where_phase,
    }


# -- the cases -------------------------------------------------------------------------------


def patch_case(quick: bool) -> dict[str, Any]:
    if quick:
        size, freqs, angles = 5.0, [20e9], [0.0, 30.0]
        graded_n, uniform_n, ref_n = [8], [8, 12], [12, 14, 16]
    else:
        size, freqs, angles = 8.0, [f * 1e9 for f in range(5, 40, 5)], [0.0, 30.0, 60.0]
        graded_n, uniform_n, ref_n = [8, 12, 14, 16, 18], [8, 12, 16, 18], [24, 28, 32]
    rows, solved, refused = [], {}, []
    for graded, ns in ((True, sorted(set(graded_n + ref_n))), (False, uniform_n)):
        for n in ns:
            t0 = time.perf_counter()
            mesh = patch_cell(size, n, graded)
            row = {
                "series": "graded" if graded else "uniform",
                "subdivisions": n,
                "triangles": mesh.n_triangles,
                "unknowns": unknowns(mesh),
            }
            try:
                solved[graded, n] = solve_grid(mesh, freqs, angles)
            except ValueError as exc:  # the solver's own limits (triangles too large)
                refused.append({**row, "refused": str(exc)})
                log(f"patch {row['series']} n={n}: refused: {exc}")
                continue
            rows.append({**row, "seconds": time.perf_counter() - t0})
            log(f"patch {row['series']} n={n}: {row['unknowns']} unknowns")
    reference, orders, uncertainty = {}, [], 0.0
    for key in solved[True, ref_n[0]]:
        pair = []
        for pol in range(2):
            ext, p, u = richardson([solved[True, k][key][pol] for k in ref_n], ref_n, 2.0)
            pair.append(ext)
            orders.append(p)
            uncertainty = max(uncertainty, u)
        reference[key] = tuple(pair)
    for row in rows:
        row.update(errors(solved[row["series"] == "graded", row["subdivisions"]], reference))
        row["meets_target"] = bool(
            row["max_abs_r_error"] <= TARGET_ABS
            and row["max_phase_error_deg"] <= TARGET_PHASE
            and row["unknowns"] <= TARGET_UNKNOWNS
        )
    out: dict[str, Any] = {
        "case": f"patch {size:g} mm in a {PERIOD:g} mm cell",
        "patch_mm": size,
        "frequencies_hz": freqs,
        "angles_deg": angles,
        "rows": rows,
        "refused": refused,
        "reference": {
            "from": f"graded n = {', '.join(map(str, ref_n))}",
            "subdivisions": ref_n,
            "orders": [min(orders), max(orders)],
            "uncertainty_abs": uncertainty,
            "values": [
                [
                    k[0],
                    k[1],
                    abs(v[0]),
                    float(np.degrees(np.angle(v[0]))),
                    abs(v[1]),
                    float(np.degrees(np.angle(v[1]))),
                ]
                for k, v in sorted(reference.items())
            ],
        },
        "onsets_hz": {
            str(theta): grating_lobe_onsets(
                Lattice.rectangular(PERIOD), waves(theta)[0], max(freqs) * 1.01
            ).tolist()
            for theta in angles
        },
    }
    if not quick:  # the uniform series extrapolated at first order: a second reference
        cross = {}
        for n in (24, 32):
            solved[False, n] = solve_grid(patch_cell(size, n, False), freqs, angles)
            log(f"patch uniform n={n} (cross-check)")
        for key in reference:
            cross[key] = tuple(
                solved[False, 32][key][pol]
                + (solved[False, 32][key][pol] - solved[False, 24][key][pol]) / (32 / 24 - 1)
                for pol in range(2)
            )
        out["reference"]["uniform_extrapolated_difference"] = errors(cross, reference)
    return out


def first_order_case(quick: bool) -> dict[str, Any]:
    """The issue's 5 mm patch at 20 GHz, normal incidence: R against n, both series."""
    f = 20e9
    uniform_n = [4, 8] if quick else [4, 8, 12, 16, 24, 32]
    graded_n = [8, 12] if quick else [8, 12, 16, 24, 28, 32]
    series = {}
    for graded, ns in ((False, uniform_n), (True, graded_n)):
        for n in ns:
            mesh = patch_cell(5.0, n, graded)
            r = complex(periodic_solve_many(mesh, f, [PlaneWave()])[0].co_polar()[0])
            series[graded, n] = (r, unknowns(mesh))
    ref_n = graded_n[-3:] if len(graded_n) >= 3 else None
    if ref_n is None:
        ref = series[True, graded_n[-1]][0]
        uncertainty = None
    else:
        ref, _, uncertainty = richardson([series[True, k][0] for k in ref_n], ref_n, 2.0)
    rows = [
        {
            "series": "graded" if g else "uniform",
            "subdivisions": n,
            "unknowns": u,
            "abs_r": abs(r),
            "phase_deg": float(np.degrees(np.angle(r))),
            "abs_r_error": abs(abs(r) - abs(ref)),
        }
        for (g, n), (r, u) in sorted(series.items(), key=lambda kv: (kv[0][0], kv[0][1]))
    ]
    return {
        "case": "patch 5 mm in a 10 mm cell, 20 GHz, normal incidence",
        "reference_abs_r": abs(ref),
        "reference_phase_deg": float(np.degrees(np.angle(ref))),
        "reference_uncertainty": uncertainty,
        "rows": rows,
    }


def free_strips(frequency: float, polarization: str, theta: float = 0.0) -> complex:
    """R of free-standing strips of width P/2 (the spectral solution, no substrate)."""
    return strip_reflection(
        frequency, PERIOD, PERIOD / 2, 1.0, 1.0, False, POLARIZATION[polarization], theta
    )


def strip_case(quick: bool) -> dict[str, Any]:
    ratios = [0.1, 0.5] if quick else [0.05, 0.1, 0.3, 0.5, 0.8, 0.9]
    angles = [0.0] if quick else [0.0, 30.0, 60.0]
    meshes = [(True, 8)] if quick else [(False, 16), (True, 8), (True, 12), (True, 16)]
    checks = []  # the spectral reference against Collin and Marcuvitz
    for ratio in sorted(set(ratios) | set(COLLIN)):
        f = ratio * SPEED_OF_LIGHT / (PERIOD * 1e-3)
        across = free_strips(f, "across")
        along = free_strips(f, "along")
        row: dict[str, Any] = {
            "p_over_lambda": ratio,
            "across_abs": abs(across),
            "across_phase_deg": float(np.degrees(np.angle(across))),
            "along_abs": abs(along),
        }
        if ratio in COLLIN:
            row["collin"] = list(COLLIN[ratio])
        if ratio <= 0.1:
            m_across = marcuvitz_reflection(f, PERIOD, PERIOD / 2, "tm")
            m_along = marcuvitz_reflection(f, PERIOD, PERIOD / 2, "te")
            row["marcuvitz_across_abs"] = abs(m_across)
            row["marcuvitz_along_abs"] = abs(m_along)
        checks.append(row)
    rows = []
    for graded, n in meshes:
        mesh = strip_cell(n, graded)
        worst_abs = worst_phase = 0.0
        for theta in angles:
            for ratio in ratios:
                f = ratio * SPEED_OF_LIGHT / (PERIOD * 1e-3)
                te, tm = periodic_solve_many(mesh, f, waves(theta))
                for pol, sol in (("along", te), ("across", tm)):
                    r = complex(sol.co_polar()[0])
                    ref = free_strips(f, pol, theta)
                    worst_abs = max(worst_abs, abs(abs(r) - abs(ref)))
                    worst_phase = max(worst_phase, abs(float(np.degrees(np.angle(r / ref)))))
        rows.append(
            {
                "series": "graded" if graded else "uniform",
                "subdivisions": n,
                "triangles": mesh.n_triangles,
                "unknowns": unknowns(mesh),
                "max_abs_r_error": worst_abs,
                "max_phase_error_deg": worst_phase,
                "meets_target": bool(
                    worst_abs <= TARGET_ABS
                    and worst_phase <= TARGET_PHASE
                    and unknowns(mesh) <= TARGET_UNKNOWNS
                ),
            }
        )
        log(f"strips {rows[-1]['series']} n={n}: {worst_abs:.2e}, {worst_phase:.3f} deg")
    return {
        "case": "strips of width P/2 across a 10 mm cell",
        "p_over_lambda": ratios,
        "angles_deg": angles,
        "spectral_checks": checks,
        "rows": rows,
    }


def babinet_case(quick: bool) -> dict[str, Any]:
    f = 20e9
    rows = []
    across = 8 if quick else 16
    for graded in (False, True):
        for n in [2] if quick else [2, 3]:
            patch, holes = pixel_cells(n, graded, across)
            t = periodic_solve_many(patch, f, [PlaneWave()])[0].co_polar()[1]
            t_prime = periodic_solve_many(holes, f, [PlaneWave(polarization=(0, 1, 0))])[0]
            t_prime = t_prime.co_polar()[1]
            rows.append(
                {
                    "series": "graded" if graded else "uniform",
                    "subdivisions": n,
                    "unknowns": [unknowns(patch), unknowns(holes)],
                    "babinet_error": abs(complex(t + t_prime) - 1.0),
                }
            )
            log(f"babinet {rows[-1]['series']} n={n}: {rows[-1]['babinet_error']:.4f}")
    return {
        "case": f"pixel patch and its complement ({across} x {across} pixels), 20 GHz, normal "
        "incidence",
        "rows": rows,
    }


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--quick", action="store_true", help="a tiny run (the test suite)")
    parser.add_argument("--json", type=Path, help="write the results here")
    parser.add_argument(
        "--only", choices=["patch", "first-order", "strips", "babinet"], action="append"
    )
    args = parser.parse_args(argv)
    chosen = args.only or ["patch", "first-order", "strips", "babinet"]
    t0 = time.perf_counter()
    doc: dict[str, Any] = {
        "date": time.strftime("%Y-%m-%d"),
        "quick": args.quick,
        "machine": machine(),
        "targets": {
            "abs_r": TARGET_ABS,
            "phase_deg": TARGET_PHASE,
            "unknowns": TARGET_UNKNOWNS,
        },
    }
    if "first-order" in chosen:
        doc["first_order"] = first_order_case(args.quick)
    if "strips" in chosen:
        doc["strips"] = strip_case(args.quick)
    if "babinet" in chosen:
        doc["babinet"] = babinet_case(args.quick)
    if "patch" in chosen:
        doc["patch"] = patch_case(args.quick)
    doc["seconds"] = time.perf_counter() - t0
    text = json.dumps(doc, indent=1)
    if args.json:
        args.json.write_text(text + "\n", encoding="utf-8")
    for key in ("first_order", "strips", "babinet", "patch"):
        if key in doc:
            for row in doc[key]["rows"]:
                log(key, row)
    return 0


if __name__ == "__main__":
    sys.exit(main())
