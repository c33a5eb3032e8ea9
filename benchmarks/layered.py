"""The infinite-array solver on dielectric layers: speed, convergence of each part, validation.

The issue's targets, measured in one run on this machine:

* **one frequency** with a grounded substrate at about 1,000 unknowns within 2x of the
  free-standing solve (the same cell, the two alternating, best of ``--reps``);
* **a 651-frequency interpolating sweep** of a 1,500-triangle cell on a substrate within
  15 s on 2 cores (the split-ring slot of ``periodic_sweep.py`` on 0.787 mm of
  εr 2.2, tan δ 0.0009), its curve checked against point-by-point solves of every tenth
  frequency.

And what the docs' tables show:

* **convergence of each part** of the layered kernel (a 5 mm patch on 1.575 mm of εr 2.2,
  grounded, and on 0.5 mm of εr 4.4, tan δ 0.02, at 12 GHz, 20° TM): the spectral rest
  cut at looser tolerances (its terms relative to the leading 1/|κ|), and the blend of the
  exactly integrated harmonics made narrower or wider, each against the default;
* **validation**: strip gratings (width P/2) on a substrate against the independent 1-D
  spectral-domain Galerkin solution of ``tests/strip_spectral.py`` at three mesh sizes;
  the grounded slab without metal against Z_d = j (η0/√εr) tan(k0 √εr h); a fully
  metallised cell over the stack, R = −1.

Usage::

    python benchmarks/layered.py                  # everything, about 10 minutes
    python benchmarks/layered.py --json out.json
    python benchmarks/layered.py --quick          # small cells (the test suite)
"""

from __future__ import annotations

import argparse
import json
import math
import sys
import time
from pathlib import Path
from typing import Any

import numpy as np
from machine import machine

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT / "tests"))

from periodic import patch_cell  # noqa: E402
from periodic_meshes import graded_nodes, graded_strips, grid_cell  # noqa: E402
from periodic_sweep import split_ring_slot  # noqa: E402
from strip_spectral import strip_reflection  # noqa: E402

from barymesh.constants import ETA0, SPEED_OF_LIGHT  # noqa: E402
from barymesh.mom import (  # noqa: E402
    Layer,
    PlaneWave,
    Stack,
    periodic_layered,  # noqa: E402
    periodic_solve,
    periodic_sweep,
    te_tm_polarizations,
)
from barymesh.mom.periodic import periodic_geometry  # noqa: E402

P = 10.0  # mm
#: The issue's targets.
TARGET_RATIO = 2.0
TARGET_SWEEP_S = 15.0
GROUNDED = Stack(below=(Layer(1.575, 2.2, 0.0009),), ground=True)
SUBSTRATE = Stack(below=(Layer(0.787, 2.2, 0.0009),))


def speed(pixels: int, subdivisions: int, metal: Any, reps: int) -> dict[str, Any]:
    """One frequency: the free-standing solve and the grounded-substrate one, alternating."""
    mesh = patch_cell(pixels, subdivisions, metal)
    pg = periodic_geometry(mesh)
    wave = PlaneWave.from_angles(20, 0, 0)
    f = 20e9
    free, layered, lossy = [], [], []
    thin = Stack(below=(Layer(0.5, 4.4, 0.02),), ground=True)
    periodic_solve(mesh, f, wave)  # warm the geometry's caches
    for _ in range(reps):
        for times, stack in ((free, None), (layered, GROUNDED), (lossy, thin)):
            t = time.perf_counter()
            periodic_solve(mesh, f, wave, stack=stack)
            times.append(time.perf_counter() - t)
    best = {
        name: float(min(t)) for name, t in (("free", free), ("grounded", layered), ("thin", lossy))
    }
    return {
        "triangles": int(mesh.n_triangles),
        "unknowns": int(pg.n_unknowns),
        "frequency_hz": f,
        "free_standing_s": best["free"],
        "grounded_substrate_s": best["grounded"],
        "thin_lossy_grounded_s": best["thin"],
        "ratio": best["grounded"] / best["free"],
        "thin_ratio": best["thin"] / best["free"],
        "target_ratio": TARGET_RATIO,
        "target_met": best["grounded"] / best["free"] <= TARGET_RATIO,
    }


def sweep(pixels: int, n: int, check_every: int) -> dict[str, Any]:
    mesh = split_ring_slot(pixels)
    frequencies = np.linspace(2e9, 28e9, n)
    wave = PlaneWave(polarization=(0.0, 1.0, 0.0))
    t = time.perf_counter()
    pg = periodic_geometry(mesh)
    geometry = time.perf_counter() - t
    t = time.perf_counter()
    fitted = periodic_sweep(mesh, frequencies, wave, stack=SUBSTRATE)
    interpolating = time.perf_counter() - t
    check = frequencies[::check_every]
    t = time.perf_counter()
    plain = periodic_sweep(mesh, check, wave, stack=SUBSTRATE, interpolate=False)
    plain_s = time.perf_counter() - t
    r_fit, t_fit = (x[::check_every] for x in fitted.co_polar())
    r_plain, t_plain = plain.co_polar()
    return {
        "triangles": int(mesh.n_triangles),
        "unknowns": int(pg.n_unknowns),
        "stack": SUBSTRATE.describe(),
        "frequencies": n,
        "band_hz": [float(frequencies[0]), float(frequencies[-1])],
        "geometry_s": geometry,
        "interpolating_s": interpolating,
        "solves": int(fitted.n_solves),
        "curve_s": geometry + interpolating,
        "target_s": TARGET_SWEEP_S,
        "target_met": geometry + interpolating <= TARGET_SWEEP_S,
        "checked_frequencies": len(check),
        "point_by_point_s_per_solve": plain_s / len(check),
        "largest_difference_r": float(np.abs(r_fit - r_plain).max()),
        "largest_difference_t": float(np.abs(t_fit - t_plain).max()),
        "layer_onsets_hz": [float(o[0]) for o in fitted.layer_onsets],
        "resonances_hz": [float(f) for f in fitted.resonances],
        "warnings": list(fitted.warnings),
    }


def graded_patch(n: int) -> Any:
    x = graded_nodes(-2.5, 2.5, n, 2.0)
    return grid_cell(x, x, np.ones((n, n), bool), P)


def convergence(n: int, quick: bool = False) -> list[dict[str, Any]]:
    """R of a patch as each part of the kernel is cut more or less finely."""
    rows = []
    mesh = graded_patch(n)
    d = PlaneWave.from_angles(20, 0).direction
    wave = PlaneWave(d, te_tm_polarizations(d)[1])
    thin = Stack(below=(Layer(0.5, 4.4, 0.02),), ground=True)
    stacks = [("1.575 mm, εr 2.2, grounded", GROUNDED), ("0.5 mm, εr 4.4, tan δ 0.02", thin)]
    defaults = (periodic_layered.REMAINDER_TOLERANCE, periodic_layered.BLEND)
    parts = (("rest tolerance", (1e-3, 1e-4, 1e-5, 1e-6)), ("blend", (0.25, 1.0)))
    if quick:
        stacks, parts = stacks[1:], (("rest tolerance", (1e-3,)), ("blend", (1.0,)))
    for name, stack in stacks:
        reference = complex(periodic_solve(mesh, 12e9, wave, stack=stack).co_polar()[0])
        for part, values in parts:
            for value in values:
                if part == "rest tolerance":
                    periodic_layered.REMAINDER_TOLERANCE = value
                else:
                    periodic_layered.BLEND = value
                try:
                    r = complex(periodic_solve(mesh, 12e9, wave, stack=stack).co_polar()[0])
                finally:
                    periodic_layered.REMAINDER_TOLERANCE, periodic_layered.BLEND = defaults
                rows.append(
                    {
                        "stack": name,
                        "part": part,
                        "value": value,
                        "default": defaults[0] if part == "rest tolerance" else defaults[1],
                        "r": [r.real, r.imag],
                        "difference": abs(r - reference),
                    }
                )
    return rows


def validation(sizes: tuple[int, ...], quick: bool = False) -> list[dict[str, Any]]:
    rows = []
    cases = [
        ("strips, 1.575 mm εr 2.2 grounded", 2.2, 1.575, True, 6e9, "te"),
        ("strips, 1.575 mm εr 2.2 grounded", 2.2, 1.575, True, 12e9, "tm"),
        ("strips, 1 mm εr 4.4 tan δ 0.02", 4.4 - 0.088j, 1.0, False, 12e9, "te"),
        ("strips, 1 mm εr 4.4 tan δ 0.02", 4.4 - 0.088j, 1.0, False, 6e9, "tm"),
    ]
    for name, eps, d, ground, f, pol in cases[:1] if quick else cases:
        tand = -complex(eps).imag / complex(eps).real
        stack = Stack(below=(Layer(d, complex(eps).real, tand),), ground=ground)
        reference = strip_reflection(f, P, P / 2, complex(eps), d, ground, pol, 20.0, basis=10)
        direction = PlaneWave.from_angles(20, 0).direction
        wave = PlaneWave(direction, te_tm_polarizations(direction)[0 if pol == "te" else 1])
        for across in sizes:
            s = periodic_solve(graded_strips(P, across, max(6, across // 2)), f, wave, stack=stack)
            r = complex(s.co_polar()[0])
            rows.append(
                {
                    "case": name,
                    "frequency_hz": f,
                    "polarization": pol,
                    "unknowns": int(s.geometry.n_unknowns),
                    "r": [r.real, r.imag],
                    "reference": [reference.real, reference.imag],
                    "difference": abs(r - reference),
                    "phase_difference_deg": abs(
                        math.degrees(math.remainder(np.angle(r) - np.angle(reference), 2 * math.pi))
                    ),
                }
            )
    for f in (5e9, 10e9, 15e9):
        stack = Stack(below=(Layer(1.575, 2.2),), ground=True)
        k0 = 2 * math.pi * f / SPEED_OF_LIGHT
        zd = 1j * ETA0 / math.sqrt(2.2) * math.tan(k0 * math.sqrt(2.2) * 1.575e-3)
        exact = (zd - ETA0) / (zd + ETA0)
        g = stack.reflection(f)[0]
        rows.append(
            {
                "case": "grounded slab, no metal (exact)",
                "frequency_hz": f,
                "polarization": "te",
                "unknowns": 0,
                "r": [g.real, g.imag],
                "reference": [exact.real, exact.imag],
                "difference": abs(g - exact),
                "phase_difference_deg": abs(math.degrees(np.angle(g / exact))),
            }
        )
    x = np.linspace(-P / 2, P / 2, 13)
    sheet = grid_cell(x, x, np.ones((12, 12), bool), P)
    s = periodic_solve(sheet, 12e9, PlaneWave.from_angles(30, 20, 35), stack=GROUNDED)
    r = complex(s.co_polar()[0])
    rows.append(
        {
            "case": "fully metallised cell (R = -1)",
            "frequency_hz": 12e9,
            "polarization": "mixed",
            "unknowns": int(s.geometry.n_unknowns),
            "r": [r.real, r.imag],
            "reference": [-1.0, 0.0],
            "difference": abs(r + 1),
            "phase_difference_deg": abs(math.degrees(np.angle(-r))),
        }
    )
    return rows


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--json", type=Path, help="write the results here")
    ap.add_argument("--quick", action="store_true", help="small cells (the test suite)")
    ap.add_argument("--reps", type=int, default=3)
    args = ap.parse_args(argv)
    if args.quick:
        speed_row = speed(8, 1, None, 1)
        sweep_row = sweep(8, 41, 10)
        conv = convergence(6, quick=True)
        valid = validation((12,), quick=True)
    else:
        speed_row = speed(20, 2, (9, 10), args.reps)
        sweep_row = sweep(32, 651, 10)
        conv = convergence(14)
        valid = validation((12, 20, 30))
    doc = {
        "benchmark": "layered",
        "date": time.strftime("%Y-%m-%d"),
        "machine": machine(),
        "speed": speed_row,
        "sweep": sweep_row,
        "convergence": conv,
        "validation": valid,
    }
    s = speed_row
    print(
        f"one frequency, {s['unknowns']} unknowns: free-standing {s['free_standing_s']:.3f} s, "
        f"grounded substrate {s['grounded_substrate_s']:.3f} s (ratio {s['ratio']:.2f}, "
        f"target {TARGET_RATIO:g}); thin lossy {s['thin_lossy_grounded_s']:.3f} s"
    )
    w = sweep_row
    print(
        f"{w['frequencies']} frequencies, {w['triangles']} triangles on {w['stack']}: "
        f"{w['curve_s']:.1f} s with {w['solves']} solves (target {TARGET_SWEEP_S:g} s); "
        f"against point by point at {w['checked_frequencies']}: |dR| <= "
        f"{w['largest_difference_r']:.2g}, |dT| <= {w['largest_difference_t']:.2g}"
    )
    for row in conv:
        print(f"  {row['stack']}: {row['part']} {row['value']:g}: |dR| = {row['difference']:.2g}")
    for row in valid:
        print(
            f"  {row['case']}, {row['frequency_hz'] / 1e9:g} GHz {row['polarization']}, "
            f"{row['unknowns']} unknowns: |dR| = {row['difference']:.2g}"
        )
    if args.json:
        args.json.write_text(json.dumps(doc, indent=2) + "\n", encoding="utf-8")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
