"""Slider-to-frame latency in the real barymesh window (under Xvfb when there is no display).

The window opens on the paper's Fig. 12(a) settings (23,040 triangles) with a 1000 x 800
3D view. A slider of the Parameters panel is set programmatically ``--frames`` times,
alternating between two values (inner radius 4.0 and 4.5 mm by default: same triangle
count, new geometry), and each frame is timed from ``QSlider.setValue`` to the end of
the first paint of the 3D view that shows the new mesh, split into

* meshing: ``build_mesh`` plus the statistics (``MeshResult.seconds``),
* update: the pyvista datasets (``scene_data``) plus copying them into the actors
  (``MeshScene.update``),
* rendering: ``plotter.render()`` and the widget's ``paintGL`` (where pyvistaqt draws),
* other: the rest (Qt signals, the controller's coalescing timer, panels).

Usage::

    python benchmarks/latency.py                    # 50 frames, table on stdout
    python benchmarks/latency.py --frames 10 --json out.json
    python benchmarks/latency.py --quick            # 6 frames (tests)

Without ``DISPLAY`` the script re-runs itself under ``xvfb-run``.
"""

from __future__ import annotations

import argparse
import json
import os
import re
import shutil
import statistics
import subprocess
import sys
import tempfile
import time
from collections.abc import Callable
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))

VIEW_SIZE = (1000, 800)
PARTS = ("meshing", "update", "rendering", "other", "total")
WARM_UP = 4


def _timed(record: dict[str, float], key: str, func: Callable) -> Callable:
    """``func`` that adds its run time (s) to ``record[key]``."""

    def wrapper(*args, **kwargs):
        start = time.perf_counter()
        try:
            return func(*args, **kwargs)
        finally:
            record[key] = record.get(key, 0.0) + time.perf_counter() - start

    return wrapper


def _percentile(values: list[float], q: float) -> float:
    ordered = sorted(values)
    k = (len(ordered) - 1) * q
    lo, hi = int(k), min(int(k) + 1, len(ordered) - 1)
    return ordered[lo] + (ordered[hi] - ordered[lo]) * (k - lo)


def measure(frames: int, name: str, values: tuple[float, float]) -> dict:
    """Open the window and time ``frames`` slider moves; returns the JSON document."""
    os.environ.setdefault("QT_QPA_PLATFORM", "xcb")
    from PySide6.QtCore import QSettings
    from PySide6.QtWidgets import QApplication

    import app.worker
    from app.window import MainWindow
    from core import MeshParams

    app_ = QApplication.instance() or QApplication([sys.argv[0]])
    settings_dir = tempfile.mkdtemp(prefix="barymesh-latency-")
    settings = QSettings(str(Path(settings_dir) / "settings.ini"), QSettings.Format.IniFormat)
    params = MeshParams()  # the paper's Fig. 12(a)
    window = MainWindow(params, settings=settings, scripted=True)
    window.show()
    deadline = time.perf_counter() + 30
    while not window.plotter.isVisible() and time.perf_counter() < deadline:
        app_.processEvents()
    # size the 3D view, not the window, to VIEW_SIZE
    for _ in range(3):
        app_.processEvents()
        dw = VIEW_SIZE[0] - window.plotter.width()
        dh = VIEW_SIZE[1] - window.plotter.height()
        if dw == 0 and dh == 0:
            break
        window.resize(window.width() + dw, window.height() + dh)
    window.controller.flush()
    app_.processEvents()

    record: dict[str, float] = {}
    app.worker.scene_data = _timed(record, "scene_data", app.worker.scene_data)
    window.scene.update = _timed(record, "scene_update", window.scene.update)
    window.plotter.render = _timed(record, "render", window.plotter.render)
    painted: list = []
    paint = _timed(record, "paint", window.plotter.paintGL)

    def paint_and_note() -> None:
        paint()
        painted.append(time.perf_counter())

    window.plotter.paintGL = paint_and_note  # Qt calls the Python override per instance
    shown: list = []
    window.model.result_changed.connect(lambda result: shown.append(time.perf_counter()))

    row = window.controls.rows[name]
    positions = [row.spec.to_slider(v) for v in values]
    if positions[0] == positions[1]:
        raise ValueError(f"{name}={values}: both values fall on slider position {positions[0]}")
    row.slider.setValue(positions[1])  # so that the first timed move changes the value
    samples: dict[str, list[float]] = {part: [] for part in PARTS}
    triangles = set()
    for i in range(WARM_UP + frames):
        record.clear()
        shown.clear()
        painted.clear()
        start = time.perf_counter()
        row.slider.setValue(positions[i % 2])
        deadline = start + 30
        # a frame is finished when the new mesh is in the datasets and the view has painted
        while not (shown and painted and painted[-1] > shown[0]) and time.perf_counter() < deadline:
            app_.processEvents()
        if not (shown and painted):
            raise RuntimeError(f"no frame within 30 s after setting {name}")
        total = painted[-1] - start
        result = window.model.result
        triangles.add(result.mesh.n_triangles)
        meshing = result.seconds
        update = record.get("scene_data", 0.0) + record.get("scene_update", 0.0)
        rendering = record.get("render", 0.0) + record.get("paint", 0.0)
        if i >= WARM_UP:
            parts = (meshing, update, rendering, total - meshing - update - rendering, total)
            for part, value in zip(PARTS, parts, strict=True):
                samples[part].append(value)
    size = tuple(window.plotter.ren_win.GetSize())
    info = window.plotter.ren_win.ReportCapabilities() or ""
    renderer = re.search(r"OpenGL renderer string:\s*(.+)", info)
    window.close()
    app_.processEvents()
    shutil.rmtree(settings_dir, ignore_errors=True)
    return {
        "slider": name,
        "values": list(values),
        "frames": frames,
        "triangles": sorted(triangles),
        "view_size": list(size),
        "renderer": renderer.group(1).strip() if renderer else "unknown",
        "seconds": {
            part: {
                "median": statistics.median(v),
                "p95": _percentile(v, 0.95),
                "min": min(v),
                "max": max(v),
                "samples": v,
            }
            for part, v in samples.items()
        },
    }


def table(doc: dict) -> str:
    s = doc["seconds"]
    lines = [
        f"slider {doc['slider']} {doc['values'][0]} <-> {doc['values'][1]}, "
        f"{doc['frames']} frames, triangles {', '.join(f'{t:,}' for t in doc['triangles'])}, "
        f"view {doc['view_size'][0]}x{doc['view_size'][1]}, renderer {doc['renderer']}",
        f"{'part':12} {'median ms':>10} {'p95 ms':>8} {'min ms':>8} {'max ms':>8}",
    ]
    for part in PARTS:
        v = s[part]
        lines.append(
            f"{part:12} {v['median'] * 1e3:10.1f} {v['p95'] * 1e3:8.1f} "
            f"{v['min'] * 1e3:8.1f} {v['max'] * 1e3:8.1f}"
        )
    mesh_update = statistics.median(
        m + u for m, u in zip(s["meshing"]["samples"], s["update"]["samples"], strict=True)
    )
    lines.append(
        f"meshing + update median {mesh_update * 1e3:.1f} ms (target <= 15), "
        f"whole frame median {s['total']['median'] * 1e3:.1f} ms (target <= 100)"
    )
    return "\n".join(lines)


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--frames", type=int, default=50, help="timed frames (default 50)")
    ap.add_argument("--quick", action="store_true", help="6 frames (for the test suite)")
    ap.add_argument("--slider", default="inner_radius", help="parameter whose slider moves")
    ap.add_argument(
        "--values", type=float, nargs=2, default=(4.0, 4.5), help="the two slider values"
    )
    ap.add_argument("--json", type=Path, help="also write the results here")
    args = ap.parse_args(argv)
    frames = 6 if args.quick else args.frames
    if frames < 1:
        ap.error(f"--frames={frames}: expected at least 1")
    if sys.platform == "linux" and not os.environ.get("DISPLAY"):
        if not os.environ.get("BARYMESH_LATENCY_XVFB") and shutil.which("xvfb-run"):
            env = dict(os.environ, BARYMESH_LATENCY_XVFB="1")
            cmd = ["xvfb-run", "-a", "-s", "-screen 0 1600x1200x24", sys.executable]
            cmd += [str(Path(__file__).resolve()), *(sys.argv[1:] if argv is None else argv)]
            return subprocess.call(cmd, env=env)
        ap.error("no display: run under Xvfb (xvfb-run -a python benchmarks/latency.py)")
    from app.model import SPECS

    if args.slider not in SPECS:
        ap.error(f"--slider={args.slider!r}: expected one of {', '.join(SPECS)}")
    doc = measure(frames, args.slider, tuple(args.values))
    print(table(doc))
    if args.json:
        args.json.write_text(json.dumps(doc, indent=2))
    return 0


if __name__ == "__main__":
    sys.exit(main())
