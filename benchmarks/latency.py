"""Slider-to-frame latency in the real barymesh window (under Xvfb when there is no display).

The window (1400 x 860) opens on the paper's Fig. 12(a) settings (23,040 triangles). A
slider of the Parameters panel is set programmatically ``--frames`` times,
alternating between two values (inner radius 4.0 and 4.5 mm by default: same triangle
count, new geometry), and each frame is timed from ``QSlider.setValue`` to the end of
the first paint of the 3D view that shows the new mesh, split into

* meshing: ``build_mesh`` plus the statistics (``MeshResult.seconds``),
* update: the pyvista datasets (``scene_data``) plus copying them into the actors
  (``MeshScene.update``),
* rendering: ``plotter.render()`` and the widget's ``paintGL`` (where pyvistaqt draws),
* other: the rest (Qt signals, the controller's coalescing timer, panels).

Then a real mouse drag of that slider's handle (QTest press, moves every ~8 ms,
release) counts the meshes shown per second, and ``--big`` rounds show the dense meshes
(Fig. 12(a) at n = 27, 1,049,760 triangles, and a conforming double ring of radii 45
and 65 mm at n = 58, 4,755,072 triangles of nearly square cells; before issue 12's
sectors the default radii gave 4,844,160 at that n), each followed by Fig. 12(a)
again: time until the view has painted the mesh, paints per mesh, camera rotation
frames per second at 1M, RSS per triangle above the idle window and after returning
to Fig. 12(a). A 10 ms heartbeat timer records the longest block of the event loop
throughout.

The ``--teaching`` round opens and steps the teaching windows as a user does, on Fig. 10
(one 10 mm patch at n = 4) and Fig. 12(a): the connectivity matrix (key M), the
construction window (F7: opening, its Next button, n + 1 in its spin box), the paper vs
conforming window (F8: opening, a new inner radius), a mouse drag of the patch-size slider
with auto-solve on (Solve tab, 40 unknowns) and 3 s of Animate; with ``--big`` above 0
also the matrix of Fig. 12(a) at n = 27 (1,049,760 triangles). For each case it reports
the event loop's longest block, in wall time and in the GUI thread's CPU time (a loaded
machine stretches the first, hardly the second); ``--profile DIR`` writes a cProfile
file per case.

The ``--interaction`` round (issue 30) times a hand on the mouse in the main view: a
mouse drag of Fig. 12(a)'s inner-radius slider and of Fig. 12(d)'s angle-step slider,
wheel steps into a 207,360-triangle mesh (each followed by its rest, when the detail of
the part in view comes) and a rotating mouse drag over 1,049,760 triangles. Each case
reports the longest block with the GUI thread's CPU time and the whole process's in that
same gap (Mesa's render threads and the workers), per step where there are steps, and the
load average, so that a loaded machine's stretched wall times can be told from the
window's own work.

Usage::

    python benchmarks/latency.py                    # 50 frames, drag, 3 big rounds
    python benchmarks/latency.py --frames 10 --json out.json
    python benchmarks/latency.py --quick            # 6 frames, 0.5 s drag (tests)
    python benchmarks/latency.py --big-only --big 3 # only the 1M and 4.8M rounds
    python benchmarks/latency.py --teaching --load "2 test runs" --json out.json
    python benchmarks/latency.py --interaction --load "quiet" --json out.json

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
import weakref
from collections.abc import Callable
from pathlib import Path

from machine import machine
from window_tools import Heartbeat, mouse, rss, wait_until

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))

WINDOW_SIZE = (1400, 860)
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


def _stats(values: list[float]) -> dict:
    return {
        "median": statistics.median(values),
        "p95": _percentile(values, 0.95),
        "min": min(values),
        "max": max(values),
        "samples": values,
    }


def _show(app_, window, params, beat: Heartbeat, timeout: float = 120.0) -> dict:
    """Set ``params`` as a preset would and time until the view has painted the mesh."""
    old = weakref.ref(window.model.result)  # not a reference: the old mesh must be freed
    paints = window.paint_counter.paints
    beat.reset()
    start = time.perf_counter()
    window.model.set_params(params)
    # shown: a new result and a paint since (the paint may come inside the result's
    # handling, when a panel relayout resizes the view: it then is the only one)
    ok = wait_until(
        lambda: (
            window.model.result is not old()
            and window.model.result.params == params
            and window.paint_counter.paints > paints
        ),
        timeout,
    )
    if not ok:
        c = window.controller
        raise RuntimeError(
            f"no mesh on screen {timeout:.0f} s after {params} (busy "
            f"{c.busy}, pending {c._pending is not None}, stale {len(c._stale)})"
        )
    seconds = window.paint_counter.last - start
    wait_until(lambda: False, 0.8)  # a late second paint would show here
    result = window.model.result
    return {
        "triangles": result.mesh.n_triangles,
        "shown": seconds,
        "paints": window.paint_counter.paints - paints,
        "longest_block": beat.longest,
        "timings": dict(result.timings),
        "reduced": bool(window.scene.reduced),
    }


def _rotate(app_, window, beat: Heartbeat, frames: int = 12) -> dict:
    """Turn the camera ``frames`` times by 3 degrees and render each (the render window's
    own ``Render``, what a rotating mouse drag costs per frame); frames per second."""
    camera = window.plotter.camera
    beat.reset()
    times = []
    for _ in range(frames):
        camera.Azimuth(3.0)
        start = time.perf_counter()
        window.plotter.ren_win.Render()
        times.append(time.perf_counter() - start)
        wait_until(lambda: False, 0.02)
    window.top_view()
    wait_until(lambda: False, 0.3)
    return {
        "frame": _stats(times),
        "fps": 1.0 / statistics.median(times),
        "longest_block": beat.longest,
    }


def _quality_panel(app_, window, beat: Heartbeat, timeout: float = 60.0) -> dict:
    """Raise the Quality dock over the mesh on screen: until its report is shown, and the
    event loop's longest block meanwhile (the report is measured when the tab is seen)."""
    panel = window.quality_panel
    n = window.model.result.mesh.n_triangles
    beat.reset()
    start = time.perf_counter()
    window.quality_dock.show()
    window.quality_dock.raise_()
    ok = wait_until(
        lambda: panel.report is not None and panel.up_to_date and panel.report["triangles"] == n,
        timeout,
    )
    seconds = time.perf_counter() - start
    wait_until(lambda: False, 0.3)
    longest = beat.longest
    window.statistics_dock.raise_()
    wait_until(lambda: False, 0.3)
    if not ok:
        raise RuntimeError(f"no quality report {timeout:.0f} s after raising the Quality dock")
    return {"triangles": n, "seconds": seconds, "longest_block": longest}


def _drag(
    app_, window, name: str, seconds: float, beat: Heartbeat, span_px: int | None = None
) -> dict:
    """A real mouse drag of ``name``'s slider handle: press, moves, release (QTest);
    back and forth over ``span_px`` pixels (default: 3.5 value units; negative: to the
    left of the handle)."""
    from PySide6.QtCore import QPoint, Qt
    from PySide6.QtTest import QTest
    from PySide6.QtWidgets import QStyle, QStyleOptionSlider

    slider = window.controls.rows[name].slider
    option = QStyleOptionSlider()
    slider.initStyleOption(option)
    handle = slider.style().subControlRect(
        QStyle.ComplexControl.CC_Slider, option, QStyle.SubControl.SC_SliderHandle, slider
    )
    start = handle.center()
    # stay among valid values: inner radius 4 mm up to about 7.5 mm (outer ring at 9 mm);
    # on the default slider one pixel is about 0.46 mm
    px_per_pos = max(slider.width() - handle.width(), 1) / max(slider.maximum(), 1)
    span = abs(span_px) if span_px else max(2, int(3.5 / row_step(window, name) * px_per_pos))
    sign = -1 if span_px is not None and span_px < 0 else 1
    meshes: list[float] = []

    def note(_result) -> None:
        meshes.append(time.perf_counter())

    window.model.result_changed.connect(note)
    beat.reset()
    QTest.mousePress(slider, Qt.MouseButton.LeftButton, Qt.KeyboardModifier.NoModifier, start)
    t0 = time.perf_counter()
    step = 0
    while time.perf_counter() - t0 < seconds:
        step += 1
        # back and forth over ``span`` pixels, a move every ~8 ms as a mouse reports them
        phase = step % (2 * span)
        dx = phase if phase <= span else 2 * span - phase
        QTest.mouseMove(slider, QPoint(start.x() + sign * dx, start.y()))
        wait_until(lambda: False, 0.008)
    QTest.mouseRelease(
        slider,
        Qt.MouseButton.LeftButton,
        Qt.KeyboardModifier.NoModifier,
        QPoint(start.x(), start.y()),
    )
    elapsed = time.perf_counter() - t0
    window.controller.flush()
    wait_until(lambda: not window.controller.busy, 30)
    window.model.result_changed.disconnect(note)
    return {
        "seconds": elapsed,
        "meshes": len(meshes),
        "meshes_per_second": len(meshes) / elapsed,
        "moves": step,
        "longest_block": beat.longest,
    }


def row_step(window, name: str) -> float:
    """The value step of one slider position of parameter ``name``."""
    return float(window.controls.rows[name].spec.step) or 1.0


def measure_big(app_, window, repeats: int) -> dict:
    """Dense meshes: shown time, paints, blocks, rotation, memory per triangle."""
    from barymesh import MeshParams

    beat = Heartbeat()
    fig12a = MeshParams()
    out: dict = {}
    idle = rss()
    cases = {
        "1M": MeshParams(subdivisions=27),  # Fig. 12(a) at n = 27: 1,049,760 triangles
        # the paper double ring at n = 4 with a 0.02304 degree step: 1,000,000 triangles
        # of 31,250 patches, overlap ratio 0.997 (hundreds of patches over each point)
        "1M-overlap": MeshParams(angle_step=0.02304),
        "4.8M": MeshParams(
            structure="double_ring",
            mode="conforming",
            subdivisions=58,
            inner_radius=45.0,
            outer_radius=65.0,
        ),
    }
    for key, params in cases.items():
        runs, back = [], []
        for _ in range(repeats):
            runs.append(_show(app_, window, params, beat))
            rss_big = rss()
            if key == "1M" and "rotation" not in out:
                out["rotation"] = _rotate(app_, window, beat)
                out["quality_panel"] = _quality_panel(app_, window, beat)
            back.append(_show(app_, window, fig12a, beat))
            runs[-1]["rss_above_idle"] = rss_big - idle
            back[-1]["rss_after_return"] = rss()
        shown = [r["shown"] for r in runs]
        out[key] = {
            "params": params.to_dict(),
            "triangles": runs[0]["triangles"],
            "shown": _stats(shown),
            "paints": [r["paints"] for r in runs],
            "longest_block": _stats([r["longest_block"] for r in runs]),
            "reduced": runs[0]["reduced"],
            "timings": runs[-1]["timings"],
            "bytes_per_triangle": statistics.median(
                r["rss_above_idle"] / r["triangles"] for r in runs
            ),
            "return_to_fig12a": {
                "rss_over_idle": statistics.median(b["rss_after_return"] / idle for b in back),
                "longest_block": max(b["longest_block"] for b in back),
            },
        }
    out["idle_rss"] = idle
    beat.timer.stop()
    return out


def measure(
    frames: int, name: str, values: tuple[float, float], drag: float = 3.0, big: int = 0
) -> dict:
    """Open the window (1400 x 860) and time ``frames`` slider moves, a ``drag``-second
    mouse drag and ``big`` rounds of the dense meshes; returns the JSON document."""
    os.environ.setdefault("QT_QPA_PLATFORM", "xcb")
    from PySide6.QtCore import QSettings
    from PySide6.QtWidgets import QApplication

    import barymesh.app.worker
    from barymesh import MeshParams
    from barymesh.app.window import MainWindow

    app_ = QApplication.instance() or QApplication([sys.argv[0]])
    settings_dir = tempfile.mkdtemp(prefix="barymesh-latency-")
    settings = QSettings(str(Path(settings_dir) / "settings.ini"), QSettings.Format.IniFormat)
    params = MeshParams()  # the paper's Fig. 12(a)
    window = MainWindow(params, settings=settings, scripted=True)
    window.resize(*WINDOW_SIZE)
    window.show()
    wait_until(lambda: window.plotter.isVisible(), 30)
    window.controller.flush()
    wait_until(lambda: window.model.result is not None, 30)
    wait_until(lambda: False, 1.0)

    record: dict[str, float] = {}
    barymesh.app.worker.scene_data = _timed(record, "scene_data", barymesh.app.worker.scene_data)
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

    def frame_done() -> bool:  # the new mesh is shown and painted (in either order)
        return bool(shown) and bool(painted) and window.model.result.params == target[0]

    target = [None]
    if frames == 0:  # --big-only
        big_doc = measure_big(app_, window, big) if big > 0 else None
        size = tuple(window.plotter.ren_win.GetSize())
        renderer = _renderer(window)
        window.close()
        wait_until(lambda: False, 0.2)
        shutil.rmtree(settings_dir, ignore_errors=True)
        return {
            "frames": 0,
            "window_size": list(WINDOW_SIZE),
            "view_size": list(size),
            "renderer": renderer,
            "big": big_doc,
        }

    row = window.controls.rows[name]
    positions = [row.slider_spec.to_slider(v) for v in values]  # its window around the value
    if positions[0] == positions[1]:
        raise ValueError(f"{name}={values}: both values fall on slider position {positions[0]}")
    shown.clear()
    painted.clear()
    row.slider.setValue(positions[1])  # so that the first timed move changes the value
    target[0] = window.model.params
    wait_until(frame_done, 30)
    beat = Heartbeat()
    samples: dict[str, list[float]] = {part: [] for part in PARTS}
    triangles = set()
    paints_per_mesh = []
    for i in range(WARM_UP + frames):
        record.clear()
        shown.clear()
        painted.clear()
        start = time.perf_counter()
        row.slider.setValue(positions[i % 2])
        target[0] = window.model.params
        # a frame is finished when the new mesh is in the datasets and the view has painted
        if not wait_until(frame_done, 30):
            raise RuntimeError(f"no frame within 30 s after setting {name}")
        total = painted[-1] - start
        wait_until(lambda: False, 0.05)
        paints_per_mesh.append(len(painted))
        result = window.model.result
        triangles.add(result.mesh.n_triangles)
        meshing = result.seconds
        update = record.get("scene_data", 0.0) + record.get("scene_update", 0.0)
        rendering = record.get("render", 0.0) + record.get("paint", 0.0)
        if i >= WARM_UP:
            parts = (meshing, update, rendering, total - meshing - update - rendering, total)
            for part, value in zip(PARTS, parts, strict=True):
                samples[part].append(value)
    slider_block = beat.longest
    drag_doc = _drag(app_, window, name, drag, beat) if drag > 0 else None
    beat.timer.stop()
    big_doc = measure_big(app_, window, big) if big > 0 else None
    size = tuple(window.plotter.ren_win.GetSize())
    renderer = _renderer(window)
    window.close()
    wait_until(lambda: False, 0.2)
    shutil.rmtree(settings_dir, ignore_errors=True)
    return {
        "slider": name,
        "values": list(values),
        "frames": frames,
        "triangles": sorted(triangles),
        "window_size": list(WINDOW_SIZE),
        "view_size": list(size),
        "renderer": renderer,
        "seconds": {part: _stats(v) for part, v in samples.items()},
        "paints_per_frame": max(paints_per_mesh[WARM_UP:]),
        "longest_block": slider_block,
        "drag": drag_doc,
        "big": big_doc,
    }


# -- the teaching windows (--teaching) ---------------------------------------------------


class _Profiles:
    """cProfile of each case into ``directory`` (``--profile``), or nothing."""

    def __init__(self, directory: Path | None) -> None:
        self.directory = directory
        self.profile = None

    def start(self) -> None:
        if self.directory is not None:
            import cProfile

            self.profile = cProfile.Profile()
            self.profile.enable()

    def stop(self, case: str) -> None:
        if self.profile is not None:
            self.profile.disable()
            self.directory.mkdir(parents=True, exist_ok=True)
            self.profile.dump_stats(str(self.directory / f"{case}.prof"))
            self.profile = None


def _key(app_, widget, key) -> None:
    """A key press and release on ``widget``, as a user types it."""
    from PySide6.QtCore import Qt
    from PySide6.QtTest import QTest

    QTest.keyClick(widget, key, Qt.KeyboardModifier.NoModifier)


def _focus(app_, window) -> None:
    """The main window active and its 3D view focused, where a user's key goes."""
    window.activateWindow()
    window.raise_()
    wait_until(lambda: app_.activeWindow() is window, 2.0)
    window.plotter.setFocus()


def _click(widget) -> None:
    from PySide6.QtCore import Qt
    from PySide6.QtTest import QTest

    QTest.mouseClick(widget, Qt.MouseButton.LeftButton)


def _block_of(
    app_,
    beat: Heartbeat,
    action: Callable[[], None],
    done: Callable[[], bool],
    settle: float = 0.5,
    timeout: float = 60.0,
) -> dict:
    """Run ``action`` (a user's key or click), wait until ``done()`` and ``settle`` s more;
    the seconds until done and the longest event-loop block meanwhile."""
    wait_until(lambda: False, 0.2)
    beat.reset()
    start = time.perf_counter()
    action()
    ok = wait_until(done, timeout)
    seconds = time.perf_counter() - start
    wait_until(lambda: False, settle)
    if not ok:
        raise RuntimeError(f"not done {timeout:.0f} s after the action")
    return {"seconds": seconds, "longest_block": beat.longest, "longest_cpu": beat.longest_cpu}


def _summary(runs: list[dict]) -> dict:
    blocks = [r["longest_block"] for r in runs]
    cpu = [r["longest_cpu"] for r in runs]
    return {
        "longest_block": max(blocks),
        "longest_block_median": statistics.median(blocks),
        "longest_cpu": max(cpu),
        "longest_cpu_median": statistics.median(cpu),
        "runs": runs,
    }


def measure_teaching(repeats: int = 3, profile: Path | None = None, big: bool = True) -> dict:
    """Open and step each teaching window as a user does (keys, clicks, a mouse drag) and
    record the event loop's longest block per case; returns the JSON document."""
    os.environ.setdefault("QT_QPA_PLATFORM", "xcb")
    from PySide6.QtCore import QSettings, Qt
    from PySide6.QtWidgets import QApplication

    from barymesh import MeshParams
    from barymesh.app.window import MainWindow

    app_ = QApplication.instance() or QApplication([sys.argv[0]])
    settings_dir = tempfile.mkdtemp(prefix="barymesh-latency-")
    settings = QSettings(str(Path(settings_dir) / "settings.ini"), QSettings.Format.IniFormat)
    fig10 = MeshParams(structure="patch", patch_size=10.0, subdivisions=4)
    fig12a = MeshParams()
    window = MainWindow(fig10, settings=settings, scripted=True)
    window.resize(*WINDOW_SIZE)
    window.show()
    wait_until(lambda: window.plotter.isVisible(), 30)
    window.activateWindow()
    window.controller.flush()
    wait_until(lambda: window.model.result is not None, 30)
    wait_until(lambda: False, 1.0)
    beat = Heartbeat()
    prof = _Profiles(profile)
    out: dict[str, dict] = {}

    def show(params) -> None:
        if window.model.result is None or window.model.result.params != params:
            _show(app_, window, params, beat)

    def matrix_open(case: str, params, other, runs_wanted: int = repeats) -> None:
        view = window.teaching.matrix
        runs = []
        for _ in range(runs_wanted):
            show(other)
            show(params)  # a new mesh while the dock is hidden: drawn when it opens
            draws = view.full_draws
            prof.start()
            runs.append(
                _block_of(
                    app_,
                    beat,
                    lambda: (_focus(app_, window), _key(app_, window.plotter, Qt.Key.Key_M)),
                    lambda d=draws: (
                        not view.stale and view.full_draws > d and view.matrix is not None
                    ),
                )
            )
            prof.stop(case)
            runs[-1]["nonzeros"] = view.nonzeros()
            runs[-1]["full_draws"] = view.full_draws - draws
            _focus(app_, window)
            _key(app_, window.plotter, Qt.Key.Key_M)  # closed again
            wait_until(lambda: not window.teaching.matrix_active, 5)
        out[case] = _summary(runs) | {"triangles": window.model.result.mesh.n_triangles}

    matrix_open("matrix_open_fig10", fig10, fig12a)
    matrix_open("matrix_open_fig12a", fig12a, fig10)
    if big:  # Fig. 12(a) at n = 27: 1,049,760 triangles (its picture made in a worker)
        matrix_open("matrix_open_1M", MeshParams(subdivisions=27), fig12a, 1)
        show(fig12a)

    # -- construction window (F7) ------------------------------------------------------
    show(fig12a)
    tw = window.teaching_windows
    runs = []
    for i in range(repeats):
        prof.start()
        runs.append(
            _block_of(
                app_,
                beat,
                lambda: (_focus(app_, window), _key(app_, window.plotter, Qt.Key.Key_F7)),
                lambda: tw.construction is not None and tw.construction.isVisible(),
                settle=1.0,
            )
        )
        prof.stop("construction_open")
        view = tw.construction
        runs[-1]["triangles_last_step"] = len(view.steps[-1].triangles)
        if i < repeats - 1:
            view.close()
            wait_until(lambda: False, 0.5)
    out["construction_open"] = _summary(runs)
    view = tw.construction
    runs = []
    view.set_step(0)
    wait_until(lambda: False, 0.3)
    prof.start()
    for _ in range(min(len(view.steps) - 1, 4 * repeats)):
        index = view.index
        runs.append(
            _block_of(
                app_,
                beat,
                lambda: _click(view.next_button),
                lambda i=index: view.index == i + 1,
                settle=0.3,
            )
        )
    prof.stop("construction_step")
    out["construction_step"] = _summary(runs) | {"steps": len(view.steps)}
    runs = []
    prof.start()
    for _ in range(repeats):
        n = view.n_spin.value()
        view.n_spin.setFocus()
        runs.append(
            _block_of(
                app_,
                beat,
                lambda: _key(app_, view.n_spin, Qt.Key.Key_Up),
                lambda n=n: (
                    view.params is not None
                    and view.params.subdivisions == n + 1
                    and window.model.result.params.subdivisions == n + 1
                ),
                settle=0.8,
            )
        )
        runs[-1]["subdivisions"] = n + 1
    prof.stop("construction_n_change")
    out["construction_n_change"] = _summary(runs)
    view.close()
    wait_until(lambda: False, 0.5)

    # -- compare window (F8) -----------------------------------------------------------
    show(fig12a)
    runs = []
    for i in range(repeats):
        prof.start()
        runs.append(
            _block_of(
                app_,
                beat,
                lambda: (_focus(app_, window), _key(app_, window.plotter, Qt.Key.Key_F8)),
                lambda: (
                    tw.compare is not None and tw.compare.shown_generation == tw.compare.generation
                ),
                settle=1.0,
            )
        )
        prof.stop("compare_open")
        if i < repeats - 1:
            tw.compare.close()
            wait_until(lambda: False, 0.5)
    out["compare_open"] = _summary(runs)
    compare = tw.compare
    row = window.controls.rows["inner_radius"]
    runs = []
    prof.start()
    for i in range(2 * repeats):
        target = row.slider.value() + (1 if i % 2 == 0 else -1)
        runs.append(
            _block_of(
                app_,
                beat,
                lambda t=target: row.slider.setValue(t),
                lambda: (
                    not compare.busy
                    and compare.shown_generation == compare.generation
                    and not window.controller.busy
                ),
                settle=0.8,
            )
        )
    prof.stop("compare_param_change")
    out["compare_param_change"] = _summary(runs)
    compare.close()
    wait_until(lambda: False, 0.5)

    # -- auto-solve while a slider is dragged (Solve tab) ------------------------------
    show(MeshParams(structure="patch", patch_size=100.0, subdivisions=4))  # 40 unknowns
    panel = window.solve_panel
    window.solve_dock.show()
    window.solve_dock.raise_()
    wait_until(panel.isVisible, 5)
    if panel.solver_grade.isChecked():  # auto-solve is of the mesh as drawn
        panel.solver_grade.setChecked(False)
    panel.frequency.setText("1.2")
    _click(panel.solve_button)
    wait_until(lambda: panel.solution is not None, 30)
    wait_until(lambda: False, 0.5)
    solved: list[float] = []
    panel.solved.connect(lambda _s: solved.append(time.perf_counter()))
    prof.start()
    _focus(app_, window)  # a closed teaching window left the main one inactive
    # from the slider's position of the patch size shown (its end, after the compare
    # window's parameters) to the left: a new mesh, and a solve, with every move
    drag = _drag(app_, window, "patch_size", 3.0, beat, span_px=-30)
    drag_cpu = beat.longest_cpu
    prof.stop("auto_solve_slider_step")
    wait_until(lambda: False, 0.5)
    out["auto_solve_slider_step"] = {
        "longest_block": drag["longest_block"],
        "longest_cpu": drag_cpu,
        "meshes": drag["meshes"],
        "solves": len(solved),
        "seconds": drag["seconds"],
        "unknowns": len(window.model.result.mesh.rwg),
    }

    # -- Animate (the surface current's phase) -----------------------------------------
    steps: list[float] = []
    panel.phase.valueChanged.connect(lambda _v: steps.append(time.perf_counter()))
    wait_until(lambda: False, 0.3)
    beat.reset()
    prof.start()
    _click(panel.animate)
    wait_until(lambda: False, 3.0)
    _click(panel.animate)
    prof.stop("animate_step")
    out["animate_step"] = {
        "longest_block": beat.longest,
        "longest_cpu": beat.longest_cpu,
        "phase_steps": len(steps),
        "steps_per_second": len(steps) / 3.0,
        "triangles": window.model.result.mesh.n_triangles,
    }
    beat.timer.stop()
    size = tuple(window.plotter.ren_win.GetSize())
    renderer = _renderer(window)
    window.close()
    wait_until(lambda: False, 0.3)
    shutil.rmtree(settings_dir, ignore_errors=True)
    return {
        "round": "teaching",
        "window_size": list(WINDOW_SIZE),
        "view_size": list(size),
        "renderer": renderer,
        "repeats": repeats,
        "cases": out,
    }


# -- drags, wheel and rotation on the main view (--interaction, issue 30 item 13) ---------


def _case_doc(beat: Heartbeat, blocks: list[tuple[float, float]] | None = None) -> dict:
    """The longest event-loop block since ``beat.reset()``: wall seconds, the GUI thread's
    CPU seconds in that same gap, and the busiest gap's CPU; ``blocks``: per step (wall,
    CPU) of each step's longest gap."""
    wall, cpu, _end = beat.longest_block()
    doc = {
        "longest_block": wall,
        "longest_block_cpu": cpu,
        "longest_block_process_cpu": beat.longest_block_process(),
        "longest_cpu": beat.longest_cpu,
    }
    if blocks:
        walls = [b[0] for b in blocks]
        doc["steps"] = [{"longest_block": b[0], "cpu": b[1], "process_cpu": b[2]} for b in blocks]
        doc["median_step_block"] = statistics.median(walls)
        doc["median_step_cpu"] = statistics.median(b[1] for b in blocks)
        doc["median_step_process_cpu"] = statistics.median(b[2] for b in blocks)
    doc["loadavg"] = list(os.getloadavg())
    return doc


def _wheel(window, steps: int, beat: Heartbeat, rest: float = 1.5) -> dict:
    """``steps`` wheel steps (one notch each, 120 units) into the view over the inner ring,
    each followed by ``rest`` seconds (the rest timer, the detail of the part in view);
    the longest block of each step."""
    from PySide6.QtCore import QPoint, QPointF, Qt
    from PySide6.QtGui import QWheelEvent
    from PySide6.QtWidgets import QApplication

    plotter = window.plotter
    renderer = plotter.renderer
    renderer.SetWorldPoint(4.5, 0.0, 0.0, 1.0)  # on the inner ring (radius 4 to 5 mm)
    renderer.WorldToDisplay()
    x, y, _ = renderer.GetDisplayPoint()
    ratio = plotter.devicePixelRatioF()
    at = QPoint(round(x / ratio), round(plotter.height() - 1 - y / ratio))
    blocks, details, busiest = [], [], []
    for _ in range(steps):
        beat.reset()
        event = QWheelEvent(
            QPointF(at),
            QPointF(plotter.mapToGlobal(at)),
            QPoint(0, 0),
            QPoint(0, 120),
            Qt.MouseButton.NoButton,
            Qt.KeyboardModifier.NoModifier,
            Qt.ScrollPhase.NoScrollPhase,
            False,
        )
        QApplication.sendEvent(plotter, event)
        wait_until(lambda: False, rest)
        wall, cpu, _end = beat.longest_block()
        blocks.append((wall, cpu, beat.longest_block_process()))
        busiest.append(beat.longest_cpu)
        details.append(window.scene.detail_triangles if window.scene.detail_rect else 0)
    doc = _case_doc(beat, blocks)
    worst = max(blocks)
    doc["longest_block"], doc["longest_block_cpu"], doc["longest_block_process_cpu"] = worst
    doc["longest_cpu"] = max(busiest)
    doc["detail_triangles"] = details
    return doc


def _rotate_drag(window, moves: int, beat: Heartbeat, dx: int = 6) -> dict:
    """A left-button mouse drag on the view (the camera turns), ``moves`` moves of ``dx``
    pixels about 16 ms apart; the longest block of each move."""
    from PySide6.QtCore import QEvent, Qt

    plotter = window.plotter
    x, y = plotter.width() // 2, plotter.height() // 2
    left, none = Qt.MouseButton.LeftButton, Qt.MouseButton.NoButton
    blocks, busiest = [], []  # per move: its longest block; the busiest gap's CPU
    beat.reset()
    mouse(plotter, QEvent.Type.MouseButtonPress, x, y, left, left)
    for i in range(1, moves + 1):
        beat.reset()
        mouse(plotter, QEvent.Type.MouseMove, x + dx * i, y + dx * i // 3, none, left)
        wait_until(lambda: False, 0.016)
        wall, cpu, _end = beat.longest_block()
        blocks.append((wall, cpu, beat.longest_block_process()))
        busiest.append(beat.longest_cpu)
    beat.reset()
    mouse(plotter, QEvent.Type.MouseButtonRelease, x + dx * moves, y, left, none)
    wait_until(lambda: False, 0.5)
    blocks.append((*beat.longest_block()[:2], beat.longest_block_process()))
    busiest.append(beat.longest_cpu)
    doc = _case_doc(beat, blocks)
    worst = max(blocks)
    doc["longest_block"], doc["longest_block_cpu"], doc["longest_block_process_cpu"] = worst
    doc["longest_cpu"] = max(busiest)
    doc["moves"] = moves
    window.top_view()
    window.reset_camera()
    wait_until(lambda: False, 0.5)
    return doc


def measure_interaction(profile: Path | None = None, seconds: float = 3.0) -> dict:
    """The four cases of issue 30, item 13 in the real window (1400 x 860): a mouse drag
    of Fig. 12(a)'s inner-radius slider, of Fig. 12(d)'s angle-step slider, wheel steps
    into a 207,360-triangle mesh and a rotating mouse drag over a 1,049,760-triangle
    one; for each the event loop's longest block, in wall time and in the GUI thread's
    CPU time in that same gap (a loaded machine stretches the first, not the second)."""
    os.environ.setdefault("QT_QPA_PLATFORM", "xcb")
    from PySide6.QtCore import QSettings
    from PySide6.QtWidgets import QApplication

    from barymesh import MeshParams
    from barymesh.app.window import MainWindow
    from barymesh.presets import load_preset

    app_ = QApplication.instance() or QApplication([sys.argv[0]])
    settings_dir = tempfile.mkdtemp(prefix="barymesh-latency-")
    settings = QSettings(str(Path(settings_dir) / "settings.ini"), QSettings.Format.IniFormat)
    fig12a = MeshParams()
    window = MainWindow(fig12a, settings=settings, scripted=True)
    window.resize(*WINDOW_SIZE)
    window.show()
    wait_until(lambda: window.plotter.isVisible(), 30)
    window.activateWindow()
    window.controller.flush()
    wait_until(lambda: window.model.result is not None, 30)
    wait_until(lambda: False, 1.0)
    beat = Heartbeat()
    prof = _Profiles(profile)
    out: dict[str, dict] = {}

    def show(params) -> None:
        if window.model.result is None or window.model.result.params != params:
            _show(app_, window, params, beat)
        wait_until(lambda: False, 1.0)

    for case, params, name, span in (
        ("slider_drag_fig12a", fig12a, "inner_radius", None),
        ("slider_drag_fig12d", load_preset("paper-fig12d")[0], "angle_step", -40),
    ):
        show(params)
        window.controls.rows[name].slider.setFocus()
        prof.start()
        drag = _drag(app_, window, name, seconds, beat, span_px=span)
        prof.stop(case)
        out[case] = _case_doc(beat) | {
            "meshes": drag["meshes"],
            "moves": drag["moves"],
            "seconds": drag["seconds"],
            "triangles_last": window.model.result.mesh.n_triangles,
        }
        wait_until(lambda: False, 0.5)

    dense = MeshParams(subdivisions=12)  # Fig. 12(a) at n = 12: 207,360 triangles
    show(dense)
    window.plotter.setFocus()
    prof.start()
    out["wheel_zoom_200k"] = _wheel(window, 8, beat) | {"triangles": 207_360}
    prof.stop("wheel_zoom_200k")
    window.reset_camera()
    wait_until(lambda: False, 0.5)

    big = MeshParams(subdivisions=27)  # Fig. 12(a) at n = 27: 1,049,760 triangles
    show(big)
    prof.start()
    out["rotate_1M"] = _rotate_drag(window, 30, beat) | {"triangles": 1_049_760}
    prof.stop("rotate_1M")
    beat.timer.stop()
    size = tuple(window.plotter.ren_win.GetSize())
    renderer = _renderer(window)
    window.close()
    wait_until(lambda: False, 0.3)
    shutil.rmtree(settings_dir, ignore_errors=True)
    return {
        "round": "interaction",
        "window_size": list(WINDOW_SIZE),
        "view_size": list(size),
        "renderer": renderer,
        "cases": out,
    }


def interaction_table(doc: dict) -> str:
    """The --interaction round: each case's longest block (target <= 100 ms)."""
    lines = [
        f"drags, wheel and rotation, view {doc['view_size'][0]}x{doc['view_size'][1]}, "
        f"renderer {doc['renderer']}, load average {doc['load']['loadavg_before'][0]:.1f} "
        f"before, {doc['load']['loadavg_after'][0]:.1f} after ({doc['load']['cores']} cores)",
        "longest event-loop block per case (target <= 100 ms): wall time, the GUI thread's "
        "CPU time and the process's in that gap (llvmpipe renders in threads of its own), "
        "and the median step's",
        f"{'case':22} {'wall ms':>8} {'gui cpu':>8} {'all cpu':>8} {'step ms':>8} "
        f"{'gui cpu':>8} {'all cpu':>8} {'load':>5}",
    ]
    for case, c in doc["cases"].items():
        row = [c["longest_block"], c["longest_block_cpu"], c.get("longest_block_process_cpu")]
        row += [c.get("median_step_block"), c.get("median_step_cpu")]
        row += [c.get("median_step_process_cpu")]
        cells = " ".join("       –" if v is None else f"{v * 1e3:8.0f}" for v in row)
        lines.append(f"{case:22} {cells} {c['loadavg'][0]:5.1f}")
    return "\n".join(lines)


def _renderer(window) -> str:
    info = window.plotter.ren_win.ReportCapabilities() or ""
    found = re.search(r"OpenGL renderer string:\s*(.+)", info)
    return found.group(1).strip() if found else "unknown"


def teaching_table(doc: dict) -> str:
    """The --teaching round: each case's longest event-loop block (target <= 100 ms)."""
    lines = [
        f"teaching windows, view {doc['view_size'][0]}x{doc['view_size'][1]}, "
        f"renderer {doc['renderer']}, {doc['repeats']} runs a case",
        "longest event-loop block per case (target <= 100 ms), wall time and the GUI "
        "thread's CPU time in its busiest gap",
        f"{'case':26} {'wall ms':>8} {'median':>8} {'cpu ms':>8} {'median':>8}",
    ]
    for case, c in doc["cases"].items():
        row = [c["longest_block"], c.get("longest_block_median")]
        row += [c["longest_cpu"], c.get("longest_cpu_median")]
        lines.append(
            f"{case:26} " + " ".join("       –" if v is None else f"{v * 1e3:8.0f}" for v in row)
        )
    return "\n".join(lines)


def table(doc: dict) -> str:
    if doc.get("round") == "teaching":
        return teaching_table(doc)
    if doc.get("round") == "interaction":
        return interaction_table(doc)
    if doc["frames"] == 0:
        lines = [f"view {doc['view_size'][0]}x{doc['view_size'][1]}, renderer {doc['renderer']}"]
        return "\n".join(lines + _big_lines(doc.get("big")))
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
        f"meshing + update median {mesh_update * 1e3:.1f} ms, "
        f"whole frame median {s['total']['median'] * 1e3:.1f} ms (target <= 60), "
        f"paints per frame {doc['paints_per_frame']}, "
        f"longest event-loop block {doc['longest_block'] * 1e3:.0f} ms (target <= 100)"
    )
    d = doc.get("drag")
    if d:
        lines.append(
            f"mouse drag: {d['meshes']} meshes in {d['seconds']:.1f} s = "
            f"{d['meshes_per_second']:.1f} meshes/s (target >= 10), {d['moves']} moves, "
            f"longest block {d['longest_block'] * 1e3:.0f} ms"
        )
    return "\n".join(lines + _big_lines(doc.get("big")))


def _big_lines(big: dict | None) -> list[str]:
    lines: list[str] = []
    if big:
        for key, target in (("1M", 1.5), ("1M-overlap", 1.5), ("4.8M", 6.0)):
            c = big[key]
            lines.append(
                f"{key} ({c['triangles']:,} triangles): shown median "
                f"{c['shown']['median']:.2f} s, p95 {c['shown']['p95']:.2f} s (target <= "
                f"{target:g}), paints {c['paints']}, longest block median "
                f"{c['longest_block']['median'] * 1e3:.0f} ms, p95 "
                f"{c['longest_block']['p95'] * 1e3:.0f} ms, max "
                f"{c['longest_block']['max'] * 1e3:.0f} ms, level of detail "
                f"{'on' if c['reduced'] else 'off'}, "
                f"{c['bytes_per_triangle']:.0f} B/triangle above idle (target <= 700), "
                f"back at Fig. 12(a): {100 * c['return_to_fig12a']['rss_over_idle']:.0f} % "
                f"of idle (target <= 120 %)"
            )
            stages = ", ".join(f"{k} {v:.2f} s" for k, v in c["timings"].items())
            lines.append(f"    worker stages: {stages}")
        r = big["rotation"]
        lines.append(
            f"1M camera rotation: {r['fps']:.1f} frames/s (frame median "
            f"{r['frame']['median'] * 1e3:.0f} ms, p95 {r['frame']['p95'] * 1e3:.0f} ms; "
            f"target >= 5), longest block {r['longest_block'] * 1e3:.0f} ms"
        )
        q = big.get("quality_panel")
        if q:
            lines.append(
                f"1M Quality dock raised: report shown after {q['seconds']:.2f} s "
                f"({q['triangles']:,} triangles), longest block {q['longest_block'] * 1e3:.0f} ms "
                "(target <= 100)"
            )
        lines.append(f"idle RSS {big['idle_rss'] / 2**20:.0f} MiB")
    return lines


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--frames", type=int, default=50, help="timed frames (default 50)")
    ap.add_argument("--quick", action="store_true", help="6 frames (for the test suite)")
    ap.add_argument("--slider", default="inner_radius", help="parameter whose slider moves")
    ap.add_argument(
        "--values", type=float, nargs=2, default=(4.0, 4.5), help="the two slider values"
    )
    ap.add_argument(
        "--drag",
        type=float,
        default=3.0,
        help="seconds of a real mouse drag of the slider (default 3, 0: none)",
    )
    ap.add_argument(
        "--big",
        type=int,
        default=3,
        help="rounds of the 1M, 1M-overlap and 4.8M meshes (default 3, 0: none)",
    )
    ap.add_argument(
        "--big-only",
        action="store_true",
        help="no slider frames and no drag: only the --big rounds",
    )
    ap.add_argument(
        "--teaching",
        action="store_true",
        help="only the teaching windows: opening and stepping each, an auto-solve slider "
        "drag and Animate, the longest event-loop block of each",
    )
    ap.add_argument(
        "--repeats", type=int, default=3, help="runs of each --teaching case (default 3)"
    )
    ap.add_argument(
        "--load",
        default="",
        help="what else loaded the machine meanwhile (written into the --teaching JSON)",
    )
    ap.add_argument(
        "--interaction",
        action="store_true",
        help="only the main view's drags: Fig. 12(a)'s and Fig. 12(d)'s sliders, wheel steps "
        "at 200k and a rotating drag at 1M triangles, the longest event-loop block of each "
        "with the GUI thread's CPU time",
    )
    ap.add_argument(
        "--profile", type=Path, help="--teaching, --interaction: a cProfile file per case here"
    )
    ap.add_argument("--json", type=Path, help="also write the results here")
    args = ap.parse_args(argv)
    frames = 6 if args.quick else args.frames
    drag = 0.5 if args.quick else args.drag
    big = 0 if args.quick else args.big
    if args.big_only:
        frames, drag = 0, 0.0
        if big < 1:
            ap.error(f"--big-only with --big={big}: expected at least 1 round")
    elif frames < 1:
        ap.error(f"--frames={frames}: expected at least 1")
    if sys.platform == "linux" and not os.environ.get("DISPLAY"):
        if not os.environ.get("BARYMESH_LATENCY_XVFB") and shutil.which("xvfb-run"):
            env = dict(os.environ, BARYMESH_LATENCY_XVFB="1")
            cmd = ["xvfb-run", "-a", "-s", "-screen 0 1600x1200x24", sys.executable]
            cmd += [str(Path(__file__).resolve()), *(sys.argv[1:] if argv is None else argv)]
            return subprocess.call(cmd, env=env)
        ap.error("no display: run under Xvfb (xvfb-run -a python benchmarks/latency.py)")
    if args.interaction:
        before = list(os.getloadavg())
        doc = measure_interaction(args.profile, seconds=args.drag if args.drag > 0 else 3.0)
        doc["machine"] = machine()
        doc["load"] = {
            "note": args.load,
            "cores": os.cpu_count(),
            "loadavg_before": before,
            "loadavg_after": list(os.getloadavg()),
        }
        print(table(doc))
        if args.json:
            args.json.write_text(json.dumps(doc, indent=2))
        return 0
    if args.teaching:
        if args.repeats < 1:
            ap.error(f"--repeats={args.repeats}: expected at least 1")
        before = list(os.getloadavg())
        doc = measure_teaching(args.repeats, args.profile, big=args.big > 0)
        doc["load"] = {
            "note": args.load,
            "cores": os.cpu_count(),
            "loadavg_before": before,
            "loadavg_after": list(os.getloadavg()),
        }
        print(table(doc))
        if args.json:
            args.json.write_text(json.dumps(doc, indent=2))
        return 0
    from barymesh.app.model import SPECS

    if args.slider not in SPECS:
        ap.error(f"--slider={args.slider!r}: expected one of {', '.join(SPECS)}")
    doc = measure(frames, args.slider, tuple(args.values), drag, big)
    print(table(doc))
    if args.json:
        args.json.write_text(json.dumps(doc, indent=2))
    return 0


if __name__ == "__main__":
    sys.exit(main())
