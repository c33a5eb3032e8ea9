"""The live infinite-array curve in the real barymesh window (under Xvfb when there is no display).

Issue 19's third speed target: after a slider move on a cell of about 500 unknowns, the
whole 201-point |R|/|T| curve of the Solve dock's **Infinite array** tab appears within
1.5 s, and the event loop never blocks for more than 100 ms.

The cell is the ``hexagonal-rings`` cell preset (one conforming ring, inner radius 3 mm,
1 mm wide, 10° sectors, on a hexagonal lattice of 12 mm spacing) with its ring at
n = 3 instead of the preset's 4: 390 triangles, 520 periodic RWG unknowns (the preset
itself has 688 triangles and 946 unknowns). It is opened as a user does (Cell ▸ Cell
presets), n is typed into the Parameters panel, and the slider moved is the ring's
**inner radius**: every position is a new cell mesh (a conforming ring's sectors follow
its radius, so the triangle count moves with it: about 350 to 460 triangles, 470 to 620
unknowns, for the radii 2.7 to 3.6 mm the drags go to; each round records its own).
Its first grating lobe, the (±1, 0)-like orders of the hexagonal lattice at
normal incidence, starts at c / (12 mm · √3/2) = 28.9 GHz, inside the band typed,
5 to 30 GHz: the interpolating sweep works on both sides of an onset.

What is done, as a user does it (QTest key clicks and mouse events):

1. the window (1400 x 860) opens; the cell preset is opened, ``3`` typed into the
   subdivisions field; the Solve dock is raised on its Infinite array tab;
2. the band is typed (5, 30, 201 points, θ = φ = 0), **Live** checked by a click if it
   is not, and **Run** clicked; the first curve is waited for;
3. ``--rounds`` times the inner-radius slider's handle is dragged with the mouse (press,
   a move every 40 ms, release) to a new value, and timed from the release to the end of
   the first paint of the tab's plot that shows the curve of the mesh now on screen
   (``tab.result_mesh is window.model.result.mesh`` and a paint of that picture since).

Each round records: the time to the painted curve; the time the worker took (the sweep in
the solver process plus the figure's Agg draw, ``Outcome.seconds``); the frequencies the
interpolating sweep solved; the longest event-loop block (a 10 ms heartbeat timer), during
the drag and from the release to the curve, in wall time and in the GUI thread's CPU time;
the RSS of the window's process and of the solver process before the first round and
after the last.

Usage::

    python benchmarks/array_live.py                     # 5 rounds, 201 points
    python benchmarks/array_live.py --json out.json
    python benchmarks/array_live.py --quick             # 1 round, 21 points (tests)
    python benchmarks/array_live.py --profile DIR       # cProfile of the GUI thread

Without ``DISPLAY`` the script re-runs itself under ``xvfb-run``.
"""

from __future__ import annotations

import argparse
import json
import os
import shutil
import subprocess
import sys
import tempfile
import time
from pathlib import Path
from typing import Any

from machine import machine
from window_tools import (
    Heartbeat,
    children_rss,
    click,
    click_check_box,
    mouse,
    rss,
    slider_rects,
    slider_x,
    type_into,
    wait_until,
)

ROOT = Path(__file__).resolve().parents[1]

WINDOW_SIZE = (1400, 860)
PRESET = "hexagonal-rings"
SUBDIVISIONS = 3
SLIDER = "inner_radius"
#: inner radii the drags go to, in turn (mm; the ring is 1 mm wide, the cell's inradius 6)
VALUES = (3.4, 2.8, 3.3, 2.9, 3.5, 3.0, 3.2, 2.7)
TARGET_CURVE_S = 1.5
TARGET_BLOCK_S = 0.1


# -- the measurement ---------------------------------------------------------------------


def _curve_shown(window: Any, swept: list, painted: list) -> bool:
    """The tab has shown a curve (``swept``: (time, ...) of each) of the mesh on screen, and has
    painted it since (``painted``: (time, picture) of each paint of the plot)."""
    tab, result = window.array_panel, window.model.result
    return (
        not window.controller.busy
        and result is not None
        and tab.result_mesh is result.mesh
        and bool(swept)
        and bool(painted)
        and painted[-1][0] > swept[-1][0]
        and painted[-1][1] is tab.plot.picture
    )


def measure(rounds: int, points: int, band: tuple[float, float], profile: Path | None) -> dict:
    """Open the window, sweep the cell live and time ``rounds`` slider drags; the JSON."""
    os.environ.setdefault("QT_QPA_PLATFORM", "xcb")
    from PySide6.QtCore import QEvent, QSettings, Qt
    from PySide6.QtWidgets import QApplication

    from barymesh import MeshParams
    from barymesh.app.window import MainWindow
    from barymesh.mom import periodic_geometry

    _app = QApplication.instance() or QApplication([sys.argv[0]])  # noqa: F841 - kept alive
    settings_dir = tempfile.mkdtemp(prefix="barymesh-array-live-")
    settings = QSettings(str(Path(settings_dir) / "settings.ini"), QSettings.Format.IniFormat)
    window = MainWindow(MeshParams(), settings=settings, scripted=True)
    window.resize(*WINDOW_SIZE)
    window.show()
    wait_until(lambda: window.plotter.isVisible(), 30)
    window.activateWindow()

    def settle(timeout: float = 60.0) -> None:
        window.controller.flush()
        wait_until(lambda: not window.controller.busy, timeout)

    settle()
    # the cell preset, its ring at n = 3 typed into the Parameters panel
    window.cell_tools.load_cell_preset(PRESET)
    settle()
    type_into(window.controls.rows["subdivisions"].spin, str(SUBDIVISIONS))
    settle()
    mesh = window.model.result.mesh
    if mesh.lattice is None or window.model.cell.elements[0].params.subdivisions != SUBDIVISIONS:
        raise RuntimeError(f"the {PRESET} cell at n = {SUBDIVISIONS} is not on screen")
    cell = {
        "preset": PRESET,
        "subdivisions": SUBDIVISIONS,
        "triangles": int(mesh.n_triangles),
        "unknowns": int(periodic_geometry(mesh).n_unknowns),
        "lattice": [list(mesh.lattice.a1), list(mesh.lattice.a2)],
        "slider": SLIDER,
    }
    print(
        f"cell {PRESET} at n = {SUBDIVISIONS}: {cell['triangles']} triangles, "
        f"{cell['unknowns']} unknowns",
        flush=True,
    )

    # the Solve dock's Infinite array tab
    window.solve_dock.show()
    window.solve_dock.raise_()
    tab = window.array_panel
    window.solve_panel.tabs.setCurrentWidget(tab)
    if not wait_until(tab.plot.isVisible, 10):
        raise RuntimeError("the Infinite array tab's plot is not visible")
    painted: list[tuple[float, Any]] = []  # (time after the paint, the picture painted)
    paint = tab.plot.paintEvent

    def paint_and_note(event: Any) -> None:
        paint(event)
        painted.append((time.perf_counter(), tab.plot.picture))

    tab.plot.paintEvent = paint_and_note  # Qt calls the instance's override
    # (time, the worker's seconds) when the tab showed a new curve (its picture set)
    swept: list[tuple[float, float]] = []
    meshes: list[tuple[float, Any]] = []  # (time, mesh) of each new mesh on screen
    tab.swept.connect(
        lambda _sweep: swept.append((time.perf_counter(), float(tab.last_outcome.seconds)))
    )
    window.model.result_changed.connect(
        lambda result: meshes.append((time.perf_counter(), getattr(result, "mesh", None)))
    )
    type_into(tab.band_start, f"{band[0]:g}")
    type_into(tab.band_stop, f"{band[1]:g}")
    type_into(tab.points.lineEdit(), str(points))
    type_into(tab.theta, "0")
    type_into(tab.phi, "0")
    if tab.unit.currentText() != "GHz":
        raise RuntimeError(f"the band's unit is {tab.unit.currentText()}, not GHz")
    if not tab.live.isChecked():
        click_check_box(tab.live)
    if not tab.live.isChecked():
        raise RuntimeError("Live did not switch on")
    start = time.perf_counter()
    click(tab.run_button)
    if not wait_until(lambda: _curve_shown(window, swept, painted), 300):
        raise RuntimeError(f"no first curve 300 s after Run ({tab.status.text()!r})")
    first = {
        "seconds": painted[-1][0] - start,
        "solves": len(tab.result.sampled),
        "frequencies": len(tab.result.frequencies),
    }
    print(f"first curve after {first['seconds']:.2f} s, {first['solves']} solves", flush=True)
    wait_until(lambda: False, 1.0)

    row = window.controls.rows[SLIDER]
    slider = row.slider
    beat = Heartbeat()
    rss_before, child_before = rss(), children_rss()
    profiler = None
    if profile is not None:
        import cProfile

        profiler = cProfile.Profile()
        profiler.enable()
    rows = []
    for i in range(rounds):
        value = VALUES[i % len(VALUES)]
        old_mesh = window.model.result.mesh
        x_end = slider_x(slider, row.slider_spec.to_slider(value))
        handle, _groove = slider_rects(slider)
        x0, y = handle.center().x(), handle.center().y()
        if x_end == x0:
            raise RuntimeError(f"{SLIDER} = {value}: the handle is there already")
        steps = max(4, min(12, abs(x_end - x0)))
        left, none = Qt.MouseButton.LeftButton, Qt.MouseButton.NoButton
        beat.reset()
        drag_start = time.perf_counter()
        mouse(slider, QEvent.Type.MouseButtonPress, x0, y, left, left)
        for k in range(1, steps + 1):
            wait_until(lambda: False, 0.04)
            mouse(slider, QEvent.Type.MouseMove, x0 + (x_end - x0) * k // steps, y, none, left)
        painted.clear()
        swept.clear()
        meshes.clear()
        mouse(slider, QEvent.Type.MouseButtonRelease, x_end, y, left, none)
        released = time.perf_counter()
        during_drag = beat.longest_block()
        beat.reset()
        ok = wait_until(lambda: _curve_shown(window, swept, painted), 120)
        if not ok:
            raise RuntimeError(
                f"round {i + 1}: no curve 120 s after the release ({tab.status.text()!r}, "
                f"error {tab.error.text()!r})"
            )
        shown = painted[-1][0]
        # when the mesh whose curve is shown came on screen (before the release: 0)
        mesh_at = next((t for t, m in meshes if m is tab.result_mesh), released)
        # the heartbeat's next beat closes the gap that holds the paint
        n_beats = len(beat.gaps)
        wait_until(lambda n=n_beats: len(beat.gaps) > n, 1.0)
        after_release = beat.longest_block()
        mesh = window.model.result.mesh
        result = tab.result
        element = window.model.cell.elements[0].params
        rows.append(
            {
                "round": i + 1,
                "inner_radius_mm": float(element.inner_radius),
                "target_inner_radius_mm": value,
                "mesh_changed": mesh is not old_mesh,
                "triangles": int(mesh.n_triangles),
                "unknowns": int(periodic_geometry(mesh).n_unknowns),  # after the timing
                "frequencies": len(result.frequencies),
                "band_hz": [float(result.frequencies[0]), float(result.frequencies[-1])],
                "solves": len(result.sampled),
                "drag_s": released - drag_start,
                "moves": steps,
                "time_to_curve_s": shown - released,
                "mesh_after_release_s": mesh_at - released,
                "worker_s": swept[-1][1],
                "shown_after_worker_s": shown - swept[-1][0],
                "longest_block_drag_s": during_drag[0],
                "longest_block_drag_cpu_s": during_drag[1],
                "longest_block_after_release_s": after_release[0],
                "longest_block_after_release_cpu_s": after_release[1],
                # where that block was: its start, from the release, beside the mesh's
                # arrival and the curve's (what held the loop then)
                "longest_block_after_release_start_s": after_release[2]
                - after_release[0]
                - released,
                "curve_arrived_after_release_s": swept[-1][0] - released,
                "paints": len(painted),
            }
        )
        r = rows[-1]
        print(
            f"round {r['round']}: inner radius {r['inner_radius_mm']:.2f} mm, curve after "
            f"{r['time_to_curve_s']:.2f} s ({r['solves']} solves of {r['frequencies']}, "
            f"worker {r['worker_s']:.2f} s), longest block drag "
            f"{r['longest_block_drag_s'] * 1e3:.0f} ms, after release "
            f"{r['longest_block_after_release_s'] * 1e3:.0f} ms",
            flush=True,
        )
        wait_until(lambda: False, 0.5)
    if profiler is not None:
        profiler.disable()
        profile.mkdir(parents=True, exist_ok=True)
        profiler.dump_stats(str(profile / "gui-thread.prof"))
    beat.timer.stop()
    memory = {
        "window_rss_before": rss_before,
        "window_rss_after": rss(),
        "solver_rss_before": child_before,
        "solver_rss_after": children_rss(),
    }
    window.close()
    wait_until(lambda: False, 0.3)
    shutil.rmtree(settings_dir, ignore_errors=True)
    worst_curve = max(r["time_to_curve_s"] for r in rows)
    worst_drag = max(r["longest_block_drag_s"] for r in rows)
    worst_after = max(r["longest_block_after_release_s"] for r in rows)
    return {
        "benchmark": "array-live",
        "date": time.strftime("%Y-%m-%d"),
        "machine": machine(),
        "window_size": list(WINDOW_SIZE),
        "cell": cell,
        "band_ghz": list(band),
        "points": points,
        "first_curve": first,
        "rounds": rounds,
        "rows": rows,
        "memory": memory,
        "targets": {"time_to_curve_s": TARGET_CURVE_S, "longest_block_s": TARGET_BLOCK_S},
        "met": {
            "time_to_curve": worst_curve <= TARGET_CURVE_S,
            "longest_block_after_release": worst_after <= TARGET_BLOCK_S,
            "longest_block_during_drag": worst_drag <= TARGET_BLOCK_S,
            "longest_block": max(worst_drag, worst_after) <= TARGET_BLOCK_S,
        },
    }


def table(doc: dict) -> str:
    c = doc["cell"]
    lines = [
        f"{c['preset']} at n = {c['subdivisions']}: {c['triangles']} triangles, "
        f"{c['unknowns']} unknowns; band {doc['band_ghz'][0]:g}-{doc['band_ghz'][1]:g} GHz, "
        f"{doc['points']} points; first curve {doc['first_curve']['seconds']:.2f} s",
        f"{'round':>5} {'curve s':>8} {'mesh s':>7} {'worker s':>8} {'solves':>6} {'drag ms':>8} "
        f"{'(cpu)':>6} {'after ms':>8} {'(cpu)':>6}",
    ]
    for r in doc["rows"]:
        lines.append(
            f"{r['round']:5d} {r['time_to_curve_s']:8.2f} {r['mesh_after_release_s']:7.2f} "
            f"{r['worker_s']:8.2f} {r['solves']:6d} "
            f"{r['longest_block_drag_s'] * 1e3:8.0f} {r['longest_block_drag_cpu_s'] * 1e3:6.0f} "
            f"{r['longest_block_after_release_s'] * 1e3:8.0f} "
            f"{r['longest_block_after_release_cpu_s'] * 1e3:6.0f}"
        )
    m, met = doc["memory"], doc["met"]
    lines.append(
        f"RSS window {m['window_rss_before'] / 2**20:.0f} -> {m['window_rss_after'] / 2**20:.0f}"
        f" MiB, solver {m['solver_rss_before'] / 2**20:.0f} -> "
        f"{m['solver_rss_after'] / 2**20:.0f} MiB; targets: curve <= {TARGET_CURVE_S} s "
        f"{'met' if met['time_to_curve'] else 'MISSED'}, block <= {TARGET_BLOCK_S * 1e3:.0f} ms"
        f" after release {'met' if met['longest_block_after_release'] else 'MISSED'}, during"
        f" the drag {'met' if met['longest_block_during_drag'] else 'MISSED'}; load "
        + ", ".join(f"{x:.2f}" for x in doc["machine"]["load_averages_1_5_15_min"])
    )
    return "\n".join(lines)


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--rounds", type=int, default=5, help="slider drags timed (default 5)")
    ap.add_argument("--points", type=int, default=201, help="frequencies (default 201)")
    ap.add_argument("--band", type=float, nargs=2, default=(5.0, 30.0), help="GHz (default 5 30)")
    ap.add_argument("--quick", action="store_true", help="1 round, 21 points (the tests)")
    ap.add_argument("--profile", type=Path, help="a cProfile of the GUI thread's rounds here")
    ap.add_argument("--json", type=Path, help="also write the results here")
    args = ap.parse_args(argv)
    rounds, points = (1, 21) if args.quick else (args.rounds, args.points)
    if rounds < 1:
        ap.error(f"--rounds={rounds}: expected at least 1")
    if not 2 <= points <= 1001:
        ap.error(f"--points={points}: expected 2 to 1001 (the tab's range)")
    if not 0 < args.band[0] < args.band[1]:
        ap.error(f"--band {args.band[0]:g} {args.band[1]:g}: expected 0 < start < stop")
    if sys.platform == "linux" and not os.environ.get("DISPLAY"):
        if not os.environ.get("BARYMESH_ARRAY_LIVE_XVFB") and shutil.which("xvfb-run"):
            env = dict(os.environ, BARYMESH_ARRAY_LIVE_XVFB="1")
            cmd = ["xvfb-run", "-a", "-s", "-screen 0 1600x1200x24", sys.executable]
            cmd += [str(Path(__file__).resolve()), *(sys.argv[1:] if argv is None else argv)]
            return subprocess.call(cmd, env=env)
        ap.error("no display: run under Xvfb (xvfb-run -a python benchmarks/array_live.py)")
    doc = measure(rounds, points, tuple(args.band), args.profile)
    print(table(doc))
    if args.json:
        args.json.write_text(json.dumps(doc, indent=2) + "\n", encoding="utf-8")
    return 0


if __name__ == "__main__":
    sys.exit(main())
