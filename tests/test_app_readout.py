"""The readout of a click's selection and clicks on big meshes (issue 30, section 1, items 3
and 4), in the real window (Xvfb): the mouse moves and clicks as a user's does."""

import threading

import numpy as np
import pytest

pytest.importorskip("pyvistaqt")

from gui_helpers import click_world, hover_world, widget_pos  # noqa: E402
from PySide6.QtCore import Qt  # noqa: E402
from PySide6.QtWidgets import QApplication  # noqa: E402

import barymesh.app.view.view_tools as view_tools  # noqa: E402
from barymesh import MeshParams  # noqa: E402
from barymesh.app.view.framing import pixels_per_mm  # noqa: E402
from barymesh.app.view.readout import decimals_for  # noqa: E402

FIG10 = MeshParams(structure="patch", patch_size=10.0, subdivisions=4)  # 32 triangles


@pytest.fixture
def window_params():
    return FIG10


@pytest.fixture
def active(window, qtbot):
    """The window, active (its shortcuts need that) with the 3D view focused."""
    with qtbot.waitActive(window):
        window.activateWindow()
    window.plotter.setFocus()
    qtbot.waitUntil(lambda: window.model.result is not None)
    return window


def _xy(point, decimals):
    return f"({point[0]:.{decimals}f}, {point[1]:.{decimals}f}) mm"


def test_the_selection_readout_keeps_the_coordinates(active, qtbot):
    """'selected: vertex 15776 at (Z: zoom to it)' lost the vertex's coordinates; a
    selected vertex, edge and triangle each say where they are, in mm."""
    window = active
    mesh = window.model.result.mesh
    readout = window.view_tools.readout
    decimals = decimals_for(pixels_per_mm(window.plotter))
    t = 13
    v = int(mesh.triangles[t][0])
    click_world(qtbot, window.plotter, mesh.points[v])
    assert window.view_tools.selected.kind == "vertex"
    assert window.view_tools.selected.index == v
    text = readout.text()
    assert f"selected: vertex {v} at {_xy(mesh.points[v], decimals)} (Z: zoom to it)" in text
    edge = int(mesh.triangle_edges[t][1])
    a, b = mesh.points[mesh.edges[edge]]
    click_world(qtbot, window.plotter, 0.5 * (a + b))
    assert window.view_tools.selected.kind == "edge"
    text = readout.text()
    assert f"selected: edge {edge} " in text
    assert f"midpoint {_xy(0.5 * (a + b), decimals)} (Z: zoom to it)" in text
    click_world(qtbot, window.plotter, mesh.centroids[t])
    assert window.view_tools.selected.kind == "triangle"
    text = readout.text()
    assert f"selected: triangle {t}, centroid {_xy(mesh.centroids[t], decimals)}" in text
    # the readout a user sees
    window.grab().save("/tmp/wb/shots/readout_selected_triangle.png")


@pytest.mark.parametrize("goes_to", ["select", "picker"])
def test_a_click_while_the_elements_are_still_being_found_is_answered(
    active, qtbot, monkeypatch, goes_to
):
    """On a big mesh the locator is built in a worker when the pointer first comes over
    the view; a click made meanwhile (moving and clicking at once) selected nothing while
    the readout said "(finding elements…)". It is kept and answered when the locator is
    ready. (SYNC_LOCATOR is lowered so that 32 triangles count as big; the worker waits
    until the click is in, as a 200k or 1M mesh's locator does.)"""
    window = active
    tools = window.view_tools
    monkeypatch.setattr(view_tools, "SYNC_LOCATOR", 10)
    gate = threading.Event()
    real = view_tools._build_locator

    def slow_build(mesh):
        gate.wait(30)
        return real(mesh)

    monkeypatch.setattr(view_tools, "_build_locator", slow_build)
    window.controls.rows["subdivisions"].field.setFocus()
    # a new mesh (n = 3, 18 triangles) whose locator is left to the worker
    from app_user import type_into

    type_into(window.controls.rows["subdivisions"].field, "3")
    window.controller.flush()
    qtbot.waitUntil(lambda: window.model.result.mesh.n_triangles == 18)
    mesh = window.model.result.mesh
    assert tools.mesh is mesh and tools.locator is None
    if goes_to == "picker":  # Teach → RWG basis inspector takes the clicks
        window.plotter.setFocus()
        qtbot.keyClick(window.plotter, Qt.Key.Key_I)
        qtbot.waitUntil(lambda: window.teaching.inspector_dock.isVisible())
        QApplication.processEvents()
        window.plotter.render()
    t = 7
    target = mesh.centroids[t]
    hover_world(qtbot, window.plotter, target + np.array([0.3, 0.2, 0.0]))  # moving…
    qtbot.mouseClick(
        window.plotter, Qt.MouseButton.LeftButton, pos=widget_pos(window.plotter, target)
    )
    assert tools.locator is None
    if goes_to == "select":
        qtbot.waitUntil(lambda: "(finding elements…)" in tools.readout.text())
        assert tools.selected is None
    gate.set()  # the locator is ready now
    if goes_to == "select":
        qtbot.waitUntil(lambda: tools.selected is not None, timeout=10_000)
        assert tools.selected.kind == "triangle" and tools.selected.index == t
        qtbot.waitUntil(lambda: f"selected: triangle {t}, centroid" in tools.readout.text())
    else:
        panel = window.teaching.inspector
        qtbot.waitUntil(lambda: panel.edge is not None, timeout=10_000)
        assert panel.edge in set(mesh.triangle_edges[t])
    window.grab().save(f"/tmp/wb/shots/queued_click_{goes_to}.png")
