"""The live reflection-phase curve in the real barymesh window (under Xvfb without a display).

Issue 33 §1's window targets: after an input of the Solve dock's **Reflection phase** tab
changes, the first (preview) curve is painted within 0.5 s, the whole curve within 1.5 s,
and the event loop never blocks for more than 100 ms.

The cell is the ``hexagonal-rings`` cell preset made coarse as the window test makes it
(its ring at n = 2 and 20° sectors: 144 triangles), on 1.575 mm of RT/duroid 5880
(εr 2.2, tan δ 0.0009) over a ground plane, its ring's inner radius from 1 to 4 mm over
``--points`` values (9: a preview of 3, then 6 more), normal incidence, TM.

What is done, as a user does it (QTest key clicks and mouse clicks):

1. the window (1400 x 860) opens; the cell preset is opened, ``2`` and ``20`` typed into
   the subdivisions and angle-step fields; the Solve dock is raised on its Reflection
   phase tab; a layer is added and the ground plane ticked with the mouse;
2. the range, points and 10 GHz are typed, **Run** clicked, the first curve waited for;
3. ``--rounds`` times a new frequency is typed into the tab's field (Enter: Live solves
   again), timed from the Enter to the first paint of the preview and to the first paint
   of the whole curve, with a 10 ms heartbeat timer measuring the event loop's longest
   block meanwhile (wall time and the GUI thread's CPU time).

Usage::

    python benchmarks/phase_live.py                     # 5 rounds, 9 points
    python benchmarks/phase_live.py --json out.json
    python benchmarks/phase_live.py --quick             # 1 round, 5 points (tests)
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

import numpy as np
from machine import machine
from window_tools import Heartbeat, click, click_check_box, type_into, wait_until

WINDOW_SIZE = (1400, 860)
PRESET = "hexagonal-rings"
PATH = "elements[0].inner_radius"
#: frequencies typed in turn (GHz)
FREQUENCIES = (10.5, 9.5, 11.0, 9.0, 10.0)
TARGET_PREVIEW_S = 0.5
TARGET_CURVE_S = 1.5
TARGET_BLOCK_S = 0.1


def measure(rounds: int, points: int) -> dict:
    """Open the window, solve the curve and time ``rounds`` typed frequencies; the JSON."""
    os.environ.setdefault("QT_QPA_PLATFORM", "xcb")
    from PySide6.QtCore import QSettings
    from PySide6.QtWidgets import QApplication

    from barymesh import MeshParams
    from barymesh.app.window import MainWindow

    _app = QApplication.instance() or QApplication([sys.argv[0]])  # noqa: F841 - kept alive
    settings_dir = tempfile.mkdtemp(prefix="barymesh-phase-live-")
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
    window.cell_tools.load_cell_preset(PRESET)
    settle()
    type_into(window.controls.rows["subdivisions"].spin, "2")
    settle()
    type_into(window.controls.rows["angle_step"].field, "20")
    settle()
    mesh = window.model.result.mesh
    if mesh.lattice is None or mesh.n_triangles != 144:
        raise RuntimeError(f"the coarse {PRESET} cell is not on screen ({mesh.n_triangles})")
    window.solve_dock.show()
    window.solve_dock.raise_()
    tab = window.phase_panel
    window.solve_panel.tabs.setCurrentWidget(tab)
    if not wait_until(tab.plot.isVisible, 10):
        raise RuntimeError("the Reflection phase tab's plot is not visible")
    click(tab.stack_editor.add_button)
    click_check_box(tab.stack_editor.ground)
    painted: list[tuple[float, Any]] = []  # (time after the paint, the picture painted)
    paint = tab.plot.paintEvent

    def paint_and_note(event: Any) -> None:
        paint(event)
        painted.append((time.perf_counter(), tab.plot.picture))

    tab.plot.paintEvent = paint_and_note  # Qt calls the instance's override
    shown: dict[str, list[tuple[float, Any]]] = {"preview": [], "curve": []}
    tab.preview.connect(lambda lib: shown["preview"].append((time.perf_counter(), lib)))
    tab.swept.connect(lambda lib: shown["curve"].append((time.perf_counter(), lib)))
    index = tab.parameter.findData(PATH)
    tab.parameter.setCurrentIndex(index)  # (the tests choose it with the keys)
    type_into(tab.start, "1")
    type_into(tab.stop_edit, "4")
    type_into(tab.points.lineEdit(), str(points))
    type_into(tab.frequency, "10")
    if not tab.live.isChecked():
        click_check_box(tab.live)
    start = time.perf_counter()
    click(tab.run_button)
    if not wait_until(lambda: bool(shown["curve"]), 300):
        raise RuntimeError(f"no first curve 300 s after Run ({tab.error.text()!r})")
    first = shown["curve"][-1][0] - start
    print(f"first curve after {first:.2f} s", flush=True)
    wait_until(lambda: False, 1.0)

    def painted_after(when: float, picture_of: Any) -> float | None:
        for t, picture in painted:
            if t > when and picture is picture_of:
                return t
        return None

    beat = Heartbeat()
    rows = []
    for i in range(rounds):
        ghz = FREQUENCIES[i % len(FREQUENCIES)]
        for kind in shown:
            shown[kind].clear()
        painted.clear()
        beat.reset()
        typed = time.perf_counter()
        type_into(tab.frequency, f"{ghz:g}")
        if not wait_until(lambda: bool(shown["curve"]), 120):
            raise RuntimeError(f"round {i + 1}: no curve 120 s after Enter")
        curve_picture = tab.plot.picture
        wait_until(lambda p=curve_picture: painted_after(shown["curve"][-1][0], p), 5)
        n_beats = len(beat.gaps)
        wait_until(lambda n=n_beats: len(beat.gaps) > n, 1.0)
        block = beat.longest_block()
        preview_at = shown["preview"][0][0] if shown["preview"] else None
        curve_at = painted_after(shown["curve"][-1][0], curve_picture) or shown["curve"][-1][0]
        # the preview's paint: the first paint after it came
        preview_paint = (
            next((t for t, _p in painted if t > preview_at), preview_at)
            if preview_at is not None
            else None
        )
        library = tab.library
        rows.append(
            {
                "round": i + 1,
                "frequency_ghz": ghz,
                "values": len(library.values),
                "preview_values": len(shown["preview"][0][1].values) if shown["preview"] else 0,
                "time_to_preview_s": None if preview_paint is None else preview_paint - typed,
                "time_to_curve_s": curve_at - typed,
                "worker_s": float(tab.last_outcome.seconds),
                "longest_block_s": block[0],
                "longest_block_cpu_s": block[1],
                "covers_deg": float(np.ptp(library.phase_deg[:, 0])),
            }
        )
        r = rows[-1]
        preview = "-" if r["time_to_preview_s"] is None else f"{r['time_to_preview_s']:.2f} s"
        print(
            f"round {r['round']}: {ghz:g} GHz, preview {preview}, curve "
            f"{r['time_to_curve_s']:.2f} s (worker {r['worker_s']:.2f} s), longest block "
            f"{r['longest_block_s'] * 1e3:.0f} ms",
            flush=True,
        )
        wait_until(lambda: False, 0.5)
    beat.timer.stop()
    window.close()
    wait_until(lambda: False, 0.3)
    shutil.rmtree(settings_dir, ignore_errors=True)
    previews = [r["time_to_preview_s"] for r in rows if r["time_to_preview_s"] is not None]
    worst_curve = max(r["time_to_curve_s"] for r in rows)
    worst_block = max(r["longest_block_s"] for r in rows)
    return {
        "benchmark": "phase-live",
        "date": time.strftime("%Y-%m-%d"),
        "machine": machine(),
        "window_size": list(WINDOW_SIZE),
        "cell": {"preset": PRESET, "subdivisions": 2, "angle_step": 20.0, "triangles": 144},
        "parameter": PATH,
        "range_mm": [1.0, 4.0],
        "points": points,
        "first_curve_s": first,
        "rounds": rounds,
        "rows": rows,
        "targets": {
            "time_to_preview_s": TARGET_PREVIEW_S,
            "time_to_curve_s": TARGET_CURVE_S,
            "longest_block_s": TARGET_BLOCK_S,
        },
        "met": {
            "time_to_preview": bool(previews) and max(previews) <= TARGET_PREVIEW_S,
            "time_to_curve": worst_curve <= TARGET_CURVE_S,
            "longest_block": worst_block <= TARGET_BLOCK_S,
        },
    }


def table(doc: dict) -> str:
    lines = [
        f"{doc['cell']['preset']} (144 triangles), {doc['parameter']} 1-4 mm, "
        f"{doc['points']} values; first curve {doc['first_curve_s']:.2f} s",
        f"{'round':>5} {'GHz':>5} {'preview s':>9} {'curve s':>8} {'worker s':>8} "
        f"{'block ms':>8} {'(cpu)':>6}",
    ]
    for r in doc["rows"]:
        p = r["time_to_preview_s"]
        lines.append(
            f"{r['round']:5d} {r['frequency_ghz']:5g} {'-' if p is None else f'{p:.2f}':>9} "
            f"{r['time_to_curve_s']:8.2f} {r['worker_s']:8.2f} "
            f"{r['longest_block_s'] * 1e3:8.0f} {r['longest_block_cpu_s'] * 1e3:6.0f}"
        )
    met = doc["met"]
    lines.append(
        f"targets: preview <= {TARGET_PREVIEW_S} s {'met' if met['time_to_preview'] else 'MISSED'}"
        f", curve <= {TARGET_CURVE_S} s {'met' if met['time_to_curve'] else 'MISSED'}, block <= "
        f"{TARGET_BLOCK_S * 1e3:.0f} ms {'met' if met['longest_block'] else 'MISSED'}; load "
        + ", ".join(f"{x:.2f}" for x in doc["machine"]["load_averages_1_5_15_min"])
    )
    return "\n".join(lines)


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--rounds", type=int, default=5, help="typed frequencies timed (default 5)")
    ap.add_argument("--points", type=int, default=9, help="values of the parameter (default 9)")
    ap.add_argument("--quick", action="store_true", help="1 round, 5 points (the tests)")
    ap.add_argument("--json", type=Path, help="also write the results here")
    args = ap.parse_args(argv)
    rounds, points = (1, 5) if args.quick else (args.rounds, args.points)
    if rounds < 1:
        ap.error(f"--rounds={rounds}: expected at least 1")
    if not 2 <= points <= 201:
        ap.error(f"--points={points}: expected 2 to 201 (the tab's range)")
    if sys.platform == "linux" and not os.environ.get("DISPLAY"):
        if not os.environ.get("BARYMESH_PHASE_LIVE_XVFB") and shutil.which("xvfb-run"):
            env = dict(os.environ, BARYMESH_PHASE_LIVE_XVFB="1")
            cmd = ["xvfb-run", "-a", "-s", "-screen 0 1600x1200x24", sys.executable]
            cmd += [str(Path(__file__).resolve()), *(sys.argv[1:] if argv is None else argv)]
            return subprocess.call(cmd, env=env)
        ap.error("no display: run under Xvfb (xvfb-run -a python benchmarks/phase_live.py)")
    doc = measure(rounds, points)
    print(table(doc))
    if args.json:
        args.json.write_text(json.dumps(doc, indent=2) + "\n", encoding="utf-8")
    return 0


if __name__ == "__main__":
    sys.exit(main())
