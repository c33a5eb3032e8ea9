"""The infinite-array solver's validation numbers, for the docs (no timing is asserted).

What ``tests/test_mom_periodic_validation.py`` checks, measured with more meshes:

* ``collin``: the strip grating (Collin, problem 10.6) at P/λ = 0.1, 0.3, 0.5, 0.8, 0.9,
  E across and along the strips, on uniform pixel strips (the cell editor's mesh) and on
  strips graded toward their edges: the errors in |Γ⊥|, ∠Γ⊥, |Γ∥| and |T⊥|, the power
  balance and T − (1 + R);
* ``babinet``: |T + T' − 1| of a patch array and its complement, uniform pixels and graded;
* ``isolated``: the split-ring array's resonance (T = 0) for periods of 2–5.75 times the
  ring (P/λ up to 0.95), against the free-space resonance of the same ring mesh;
* ``convergence``: the ring array's resonance at 5 times the ring, n = 1, 2, 3.

Usage::

    python benchmarks/periodic_validation.py             # everything, a few minutes
    python benchmarks/periodic_validation.py --json out.json
    python benchmarks/periodic_validation.py --quick     # one Collin row (the test suite)
    python benchmarks/periodic_validation.py --plot docs/_static/periodic-validation.png \
        --from benchmarks/results/periodic-validation-2026-12-02.json
"""

from __future__ import annotations

import argparse
import json
import platform
import sys
import time
from pathlib import Path
from typing import Any

import numpy as np

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT / "tests"))

from periodic_meshes import (  # noqa: E402
    array_resonance,
    graded_patch,
    graded_strips,
    split_ring,
    split_ring_cell,
)

from barymesh.cell import Lattice, PixelGrid, UnitCell, build_cell  # noqa: E402
from barymesh.constants import SPEED_OF_LIGHT  # noqa: E402
from barymesh.mom import PlaneWave, periodic_solve, sweep  # noqa: E402

P = 10.0  # mm
COLLIN = {
    0.1: (0.0694, -94.0, 0.9976),
    0.3: (0.2106, -102.2, 0.9776),
    0.5: (0.3598, -111.1, 0.9330),
    0.8: (0.6231, -128.5, 0.7822),
    0.9: (0.7381, -137.6, 0.6747),
}
RING = 8.0  # mm, the split ring's outer diameter
ACROSS = PlaneWave(polarization=(1, 0, 0))
ALONG = PlaneWave(polarization=(0, 1, 0))


def pixel_cell(mask: np.ndarray, subdivisions: int):
    """The cell editor's conforming mesh of ``mask``'s pixels in a square cell of side P."""
    grid = PixelGrid(
        mask, pixel_size=P / len(mask), origin=(-P / 2, -P / 2), subdivisions=subdivisions
    )
    return build_cell(UnitCell(Lattice.rectangular(P), pixels=grid, mode="conforming")).mesh


def uniform_strips(pixels: int, subdivisions: int):
    mask = np.zeros((pixels, pixels), dtype=bool)
    mask[:, pixels // 4 : 3 * pixels // 4] = True
    return pixel_cell(mask, subdivisions)


def collin_row(name: str, mesh, p_over_lambda: float) -> dict[str, Any]:
    magnitude, phase, parallel = COLLIN[p_over_lambda]
    f = p_over_lambda * SPEED_OF_LIGHT / (P * 1e-3)
    start = time.perf_counter()
    across = periodic_solve(mesh, f, ACROSS)
    along = periodic_solve(mesh, f, ALONG)
    r, t = across.co_polar()
    r_along, t_along = along.co_polar()
    return {
        "mesh": name,
        "triangles": mesh.n_triangles,
        "p_over_lambda": p_over_lambda,
        "gamma_perp": abs(r),
        "gamma_perp_error": abs(r) - magnitude,
        "phase_perp_deg": float(np.degrees(np.angle(r))),
        "phase_perp_error_deg": float(np.degrees(np.angle(r))) - phase,
        "gamma_par": abs(r_along),
        "gamma_par_error": abs(r_along) - parallel,
        "t_perp_error": abs(t) - parallel,
        "power_balance_error": max(abs(across.power_balance - 1), abs(along.power_balance - 1)),
        "t_minus_1_plus_r": max(abs(t - 1 - r), abs(t_along - 1 - r_along)),
        "seconds": time.perf_counter() - start,
    }


def babinet_row(name: str, patches, holes) -> dict[str, Any]:
    t = periodic_solve(patches, 20e9, PlaneWave()).co_polar()[1]
    t_prime = periodic_solve(holes, 20e9, ALONG).co_polar()[1]
    return {
        "mesh": name,
        "patch_triangles": patches.n_triangles,
        "hole_triangles": holes.n_triangles,
        "t": [t.real, t.imag],
        "t_prime": [t_prime.real, t_prime.imag],
        "babinet_error": abs(t + t_prime - 1),
    }


def run(quick: bool) -> dict[str, Any]:
    out: dict[str, Any] = {
        "date": time.strftime("%Y-%m-%d"),
        "machine": platform.platform(),
        "python": platform.python_version(),
    }
    ratios = [0.9] if quick else sorted(COLLIN)
    meshes = [("graded 12 x 6", graded_strips(P, 12, 6))]
    if not quick:
        meshes = [
            ("uniform 8 x 8 pixels, n = 2", uniform_strips(8, 2)),
            ("uniform 16 x 16 pixels, n = 2", uniform_strips(16, 2)),
            ("graded 12 x 6", meshes[0][1]),
            ("graded 16 x 6", graded_strips(P, 16, 6)),
            ("graded 24 x 6", graded_strips(P, 24, 6)),
        ]
    out["collin"] = [collin_row(name, m, x) for name, m in meshes for x in ratios]
    print(f"collin: {len(out['collin'])} rows", flush=True)

    if quick:
        return out

    mask = np.zeros((8, 8), dtype=bool)
    mask[2:6, 2:6] = True
    rows = [
        babinet_row(f"uniform 8 x 8 pixels, n = {n}", pixel_cell(mask, n), pixel_cell(~mask, n))
        for n in (1, 2)
    ]
    rows += [
        babinet_row(f"graded n = {n}", graded_patch(P, n), graded_patch(P, n, True))
        for n in (10, 12, 14)
    ]
    out["babinet"] = rows
    print(f"babinet: {len(rows)} rows", flush=True)

    frequencies = np.linspace(6.0e9, 6.4e9, 5)
    f_free = float(sweep(split_ring(2), frequencies, ALONG, scattering=False).resonances[0])
    fine = np.linspace(6.1e9, 6.3e9, 9)
    f_free_fine = float(sweep(split_ring(2), fine, ALONG, scattering=False).resonances[0])
    isolated = []
    for multiple in (2, 3, 4, 5, 5.5, 5.75):
        f, solves = array_resonance(split_ring_cell(multiple * RING, 2), f_free, ALONG)
        isolated.append(
            {
                "period_mm": multiple * RING,
                "period_over_ring": multiple,
                "resonance_hz": f,
                "relative_to_free_space": f / f_free - 1,
                "solves": solves,
            }
        )
    out["isolated"] = {
        "free_space_resonance_hz": f_free,
        "free_space_resonance_fine_sweep_hz": f_free_fine,
        "free_space_triangles": split_ring(2).n_triangles,
        "arrays": isolated,
    }
    print("isolated: done", flush=True)
    convergence = []
    for n in (1, 2, 3):
        mesh = split_ring_cell(5 * RING, n)
        f, solves = array_resonance(mesh, f_free, ALONG)
        convergence.append(
            {"subdivisions": n, "triangles": mesh.n_triangles, "resonance_hz": f, "solves": solves}
        )
    for a, b in zip(convergence, convergence[1:], strict=False):
        b["change_from_previous"] = b["resonance_hz"] / a["resonance_hz"] - 1
    out["convergence"] = convergence
    return out


def plot(result: dict[str, Any], path: Path) -> None:
    """Two panels: Collin's |Γ∥| error by P/λ per mesh; the ring array's resonance by period."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, (left, right) = plt.subplots(1, 2, figsize=(9.0, 3.4), dpi=100)
    names = list(dict.fromkeys(row["mesh"] for row in result["collin"]))
    for name in names:
        rows = [row for row in result["collin"] if row["mesh"] == name]
        x = [row["p_over_lambda"] for row in rows]
        y = [max(abs(row["gamma_par_error"]), 1e-6) for row in rows]
        style = "--" if name.startswith("uniform") else "-"
        left.semilogy(x, y, style, marker="o", ms=4, label=f"{name} ({rows[0]['triangles']})")
    left.axhline(0.01, color="k", lw=0.8)
    left.set_xlabel("P/λ")
    left.set_ylabel("error in |Γ∥| (E along the strips)")
    left.set_title("Collin's strip grating", fontsize=10)
    left.set_ylim(1e-7, 0.1)  # room for the legend below the curves
    left.legend(fontsize=7, loc="lower right")
    iso = result["isolated"]
    x = [row["period_over_ring"] for row in iso["arrays"]]
    y = [100 * row["relative_to_free_space"] for row in iso["arrays"]]
    right.plot(x, y, "o-", label="array resonance (T = 0)")
    right.axhspan(-1, 1, color="0.9", label="within 1 % of one ring in free space")
    right.axhline(0, color="k", lw=0.8)
    right.set_xlabel("period / ring diameter")
    right.set_ylabel("f_array / f_free − 1 (%)")
    right.set_title("Split-ring array: the isolated limit", fontsize=10)
    right.legend(fontsize=7)
    fig.tight_layout()
    fig.savefig(path)
    plt.close(fig)


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--json", type=Path, help="write the results here")
    parser.add_argument("--quick", action="store_true", help="one Collin row (the test suite)")
    parser.add_argument("--plot", type=Path, help="draw the docs' figure (PNG) from --from")
    parser.add_argument("--from", dest="source", type=Path, help="a results file to plot")
    args = parser.parse_args(argv)
    if args.plot:
        if args.source is None:
            parser.error("--plot needs --from RESULTS.json")
        plot(json.loads(args.source.read_text()), args.plot)
        return 0
    result = run(args.quick)
    text = json.dumps(result, indent=2)
    if args.json:
        args.json.write_text(text + "\n")
    else:
        print(text)
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
