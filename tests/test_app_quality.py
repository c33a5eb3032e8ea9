"""The Quality panel in a real window (Xvfb, see conftest.py): its numbers are core's
quality_report, a click on a worst triangle frames it, the red layer is drawn and toggles."""

import threading

import numpy as np
import pytest

pytest.importorskip("pyvistaqt")

from app_user import click_check_box, settle  # noqa: E402
from gui_helpers import hex_rgb, near, widget_pos  # noqa: E402
from PySide6.QtCore import Qt  # noqa: E402
from PySide6.QtTest import QTest  # noqa: E402
from PySide6.QtWidgets import QTabBar  # noqa: E402

from barymesh import MeshParams  # noqa: E402
from barymesh.app.panels import quality_panel  # noqa: E402
from barymesh.app.view.quality_layer import WORST_COLOR  # noqa: E402
from barymesh.presets import load_preset  # noqa: E402
from barymesh.quality import quality_report  # noqa: E402

#: A 10 mm x 2 mm patch: every triangle has legs in the ratio 5:1, smallest angle
#: atan(0.2) = 11.31°, aspect ratio 3.267 (closed forms in test_core_quality_report.py).
#: At n = 64, 8,192 triangles: measured in a worker thread; at n = 8, 128: at once.
THIN = MeshParams(structure="patch", patch_size=10.0, patch_width=2.0, subdivisions=64)
THIN_SMALL = MeshParams(structure="patch", patch_size=10.0, patch_width=2.0, subdivisions=8)


def open_quality_tab(window, qtbot):
    """Click the dock tab titled Quality, as a user does (on the tab bar of its group: Qt
    keeps the bars of earlier arrangements around)."""
    group = [window.quality_dock, *window.tabifiedDockWidgets(window.quality_dock)]
    titles = sorted(d.windowTitle() for d in group if not d.isHidden())
    for bar in window.findChildren(QTabBar):
        texts = [bar.tabText(i) for i in range(bar.count())]
        if bar.isVisible() and sorted(texts) == titles:
            QTest.mouseClick(
                bar,
                Qt.MouseButton.LeftButton,
                Qt.KeyboardModifier.NoModifier,
                bar.tabRect(texts.index("Quality")).center(),
            )
            qtbot.waitUntil(lambda: window.quality_panel.seen, timeout=5_000)
            return
    raise AssertionError(f"no tab bar of {titles}")


def wait_report(window, qtbot):
    panel = window.quality_panel
    qtbot.waitUntil(lambda: panel.report is not None and panel.up_to_date, timeout=60_000)
    return panel.report


@pytest.fixture
def window_params():
    return THIN


def test_panel_shows_cores_report_and_a_click_frames_the_triangle(window, qtbot, monkeypatch):
    threads = []
    real = quality_panel.quality_report

    def spy(*args, **kwargs):
        threads.append(threading.current_thread())
        return real(*args, **kwargs)

    monkeypatch.setattr(quality_panel, "quality_report", spy)
    settle(window, qtbot)
    panel = window.quality_panel
    assert not panel.seen and panel.report is None  # behind the Statistics tab: not measured
    open_quality_tab(window, qtbot)
    report = wait_report(window, qtbot)
    mesh = window.model.result.mesh
    assert mesh.n_triangles == 8_192
    # above 5,000 triangles the report is measured off the GUI thread
    assert threads and all(t is not threading.main_thread() for t in threads)
    assert report == quality_report(mesh, worst=20)
    # what is on screen: the closed forms, the histograms, twenty worst triangles
    text = panel.figures.text()
    assert "11.3°" in text and "8,192 (100%)" in text and "3.27" in text
    for key in ("min_angle_deg", "aspect_ratio"):
        view = panel.histograms[key]
        assert view.counts.tolist() == report[key]["histogram"]["counts"]
        assert view.threshold == report[key]["threshold"]
    assert panel.histograms["edge_wavelength"].isHidden()  # no frequency: no edge/λ
    assert panel.worst_list.count() == 20
    assert panel.worst_list.item(0).text().startswith("1. triangle 0: 11.3°")
    assert not panel.layer.visible

    # click the third worst triangle in the list with the mouse
    row = 2
    item = panel.worst_list.item(row)
    panel.worst_list.scrollToItem(item)
    rect = panel.worst_list.visualItemRect(item)
    QTest.mouseClick(
        panel.worst_list.viewport(),
        Qt.MouseButton.LeftButton,
        Qt.KeyboardModifier.NoModifier,
        rect.center(),
    )
    t = report["worst"][row]["triangle"]
    assert panel.layer.chosen == t and panel.layer.visible and panel.show_layer.isChecked()
    corners = mesh.points[mesh.triangles[t]]
    lo, hi = corners[:, :2].min(axis=0), corners[:, :2].max(axis=0)
    camera = window.plotter.camera
    assert camera.focal_point[:2] == pytest.approx(0.5 * (lo + hi), abs=1e-9)
    half = 0.5 * float((hi - lo).max()) / 0.35  # the triangle fills about 35% of the view
    w, h = window.plotter.width(), window.plotter.height()
    assert camera.parallel_scale == pytest.approx(max(half, half * h / w), rel=1e-9)
    # the chosen triangle's marker is red where its centroid is seen
    qtbot.wait(50)
    image = window.view_image()
    pos = widget_pos(window.plotter, mesh.centroids[t])
    ratio = window.plotter.devicePixelRatioF()
    pixel = image[round(pos.y() * ratio), round(pos.x() * ratio)]
    assert near(tuple(int(v) for v in pixel[:3]), hex_rgb(WORST_COLOR), 40)


@pytest.fixture
def small(window, qtbot):
    settle(window, qtbot)
    return window


@pytest.mark.parametrize("window_params", [THIN_SMALL])
def test_small_mesh_measured_at_once_and_layer_toggles(small, qtbot, monkeypatch):
    threads = []
    real = quality_panel.quality_report
    monkeypatch.setattr(
        quality_panel,
        "quality_report",
        lambda *a, **k: threads.append(threading.current_thread()) or real(*a, **k),
    )
    window = small
    panel = window.quality_panel
    open_quality_tab(window, qtbot)
    report = wait_report(window, qtbot)
    assert threads == [threading.main_thread()]  # 128 triangles: on the GUI thread
    mesh = window.model.result.mesh
    assert report == quality_report(mesh, worst=20)
    assert report["min_angle_deg"]["min"] == pytest.approx(np.degrees(np.arctan(0.2)))
    assert report["min_angle_deg"]["below"] == 128
    click_check_box(panel.show_layer)
    assert panel.layer.visible and panel.act_layer.isChecked()
    assert panel.layer.actors["fill"].GetVisibility()
    assert panel.layer.datasets["fill"].n_cells == 20
    panel.act_layer.trigger()  # View → Layers → Worst triangles
    assert not panel.layer.visible and not panel.show_layer.isChecked()
    assert not panel.layer.actors["fill"].GetVisibility()


@pytest.mark.parametrize("window_params", [load_preset("conforming-double-ring")[0]])
def test_quality_dock_follows_the_narrow_and_wide_layouts(small, qtbot):
    window = small
    window.resize(1100, 760)
    qtbot.waitUntil(lambda: window.dock_layout.narrow, timeout=5_000)
    left = Qt.DockWidgetArea.LeftDockWidgetArea
    assert window.dockWidgetArea(window.quality_dock) == left
    assert window.quality_dock in window.tabifiedDockWidgets(window.parameters_dock)
    window.resize(1400, 860)
    qtbot.waitUntil(lambda: not window.dock_layout.narrow, timeout=5_000)
    right = Qt.DockWidgetArea.RightDockWidgetArea
    assert window.dockWidgetArea(window.quality_dock) == right
    assert window.quality_dock in window.tabifiedDockWidgets(window.statistics_dock)
    open_quality_tab(window, qtbot)
    # the panel keeps room for its histograms and the list at this size
    assert panel_fits(window)


def panel_fits(window):
    panel = window.quality_panel
    views = [v for v in panel.histograms.values() if v.isVisible()]
    return all(v.width() >= 200 for v in views) and panel.worst_list.height() >= 120


def test_a_new_mesh_is_measured_again(small, qtbot):
    window = small
    open_quality_tab(window, qtbot)
    first = wait_report(window, qtbot)
    assert first["triangles"] == window.model.result.mesh.n_triangles
    assert window.load_preset("srr-openmodes")  # Presets menu
    settle(window, qtbot)
    mesh = window.model.result.mesh
    assert mesh.n_triangles != first["triangles"]
    qtbot.waitUntil(
        lambda: window.quality_panel.report["triangles"] == mesh.n_triangles, timeout=30_000
    )
    assert window.quality_panel.report == quality_report(mesh, worst=20)
    assert window.quality_panel.report["min_angle_deg"]["min"] >= 30.0  # issue 12's floor


@pytest.mark.parametrize("window_params", [load_preset("paper-fig10")[0]])
def test_edge_over_wavelength_histogram_with_a_frequency(small, qtbot):
    """Parameters with a frequency (10 GHz: λ = 29.98 mm) add the edge/λ histogram: Fig. 10's
    32 triangles all have a longest side of 2.5√2 mm = 0.118 λ, above λ/10. The parameters
    are a stand-in with the attributes the sizing options add to MeshParams."""
    from types import SimpleNamespace

    window = small
    panel = window.quality_panel
    open_quality_tab(window, qtbot)
    wait_report(window, qtbot)
    assert panel.histograms["edge_wavelength"].isHidden()
    mesh = window.model.result.mesh
    params = SimpleNamespace(frequency=10e9, relative_permittivity=None)
    panel.mesh_changed(SimpleNamespace(mesh=mesh, params=params, source="parameters"))
    report = wait_report(window, qtbot)
    assert report == quality_report(mesh, wavelength=29.9792458, worst=20)
    over = report["edge_wavelength"]
    assert over["above"] == 32 and over["max"] == pytest.approx(2.5 * np.sqrt(2) / 29.9792458)
    view = panel.histograms["edge_wavelength"]
    assert not view.isHidden() and view.counts.sum() == 32 and view.threshold == 0.1
    assert "above λ/10: " in panel.figures.text() and "32 (100%)" in panel.figures.text()
    assert panel.worst_list.item(0).text().endswith("0.118 λ")


def test_a_hidden_panel_lets_go_of_the_old_mesh(small, qtbot):
    """Measured, then hidden behind Statistics: a new mesh on screen makes the panel drop
    the old report and every reference to the old mesh (issue 9: no cache keeps a dead
    mesh alive), and it measures the new one when shown again."""
    window = small
    panel = window.quality_panel
    open_quality_tab(window, qtbot)
    first = wait_report(window, qtbot)
    old = window.model.result.mesh
    assert panel.mesh is old and panel.layer._mesh is old
    window.statistics_dock.raise_()
    qtbot.waitUntil(lambda: not panel._wanted(), timeout=5_000)
    assert window.load_preset("srr-openmodes")  # Presets menu
    settle(window, qtbot)
    assert window.model.result.mesh is not old
    assert panel.report is None and panel.mesh is None
    assert panel.layer._mesh is None and panel.layer._lift_mesh is None
    open_quality_tab(window, qtbot)
    report = wait_report(window, qtbot)
    assert report["triangles"] == window.model.result.mesh.n_triangles != first["triangles"]
