"""The readout of a click's selection and clicks on big meshes (issue 30, section 1, items 3
and 4), in the real window (Xvfb): the mouse moves and clicks as a user's does."""

import threading

import numpy as np
import pytest

pytest.importorskip("pyvistaqt")

from gui_helpers import click_world, display_point, hover_world, widget_pos  # noqa: E402
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
