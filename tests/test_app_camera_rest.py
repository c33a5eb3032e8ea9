"""A dense mesh's view gets its full detail whenever the camera comes to rest, however it
was moved (issue 30, section 1, item 2), in the real window (Xvfb): keys and clicks as a
user's."""

import numpy as np
import pytest

pytest.importorskip("pyvistaqt")

from gui_helpers import click_world  # noqa: E402
from PySide6.QtCore import Qt  # noqa: E402

from barymesh import MeshParams  # noqa: E402
from barymesh.app.view.overview import DETAIL_TRIANGLES  # noqa: E402

#: Fig. 12(a) at n = 12: 720 patches x 2 x 12² = 207,360 triangles (the issue's 200k).
DENSE = MeshParams(subdivisions=12)


@pytest.fixture
def window_params():
    return DENSE


@pytest.fixture
def dense(window, qtbot):
    """The window on the 200k mesh, drawn reduced, active, its view focused."""
    qtbot.waitUntil(
        lambda: window.model.result is not None and window.model.result.mesh.n_triangles == 207_360,
        timeout=120_000,
    )
    with qtbot.waitActive(window):
        window.activateWindow()
    window.plotter.setFocus()
    assert window.scene.reduced and window.scene.detail_rect is None
    return window


def _note(window) -> str:
    return window.scene.note.GetInput() or ""


def test_zoom_to_selection_on_a_dense_mesh_brings_the_full_detail(dense, qtbot):
    """Click a triangle, press Z and rest: the part in view is drawn in full (triangles,
    edges, centroids) without a wheel step; the note "Detail reduced… zoom in and rest"
    stayed, and one wheel step then brought "Full detail of 3,300 of 200,000"."""
    window = dense
    mesh = window.model.result.mesh
    t = int(np.argmin(np.linalg.norm(mesh.centroids[:, :2] - (4.5, 0.0), axis=1)))
    click_world(qtbot, window.plotter, mesh.centroids[t])  # on the inner ring
    qtbot.waitUntil(lambda: window.view_tools.selected is not None, timeout=60_000)
    assert "Detail reduced" in _note(window)
    qtbot.keyClick(window.plotter, Qt.Key.Key_Z)
    qtbot.waitUntil(lambda: window.scene.detail_rect is not None, timeout=30_000)
    qtbot.waitUntil(lambda: "Full detail of" in _note(window), timeout=10_000)
    ids = np.asarray(window.scene.datasets["faces"].cell_data["triangle"])
    assert 0 < len(ids) <= DETAIL_TRIANGLES and t in set(ids.tolist())
    for layer in ("faces", "triangle_edges", "shared_edges", "centroids"):
        assert window.scene.shows(layer), layer
    window.plotter.render()
    window.grab().save("/tmp/wb/shots/zoom_to_selection_200k.png")


def test_the_inspectors_zoom_after_r_brings_the_full_detail(dense, qtbot):
    """Every camera change that ends at rest asks for the detail, not only the mouse's:
    R (the whole mesh: no detail to ask for), then the RWG inspector's Zoom to edge."""
    window = dense
    mesh = window.model.result.mesh
    qtbot.keyClick(window.plotter, Qt.Key.Key_I)  # Teach → RWG basis inspector
    panel = window.teaching.inspector
    qtbot.waitUntil(lambda: window.teaching.inspector_dock.isVisible())
    qtbot.wait(200)  # its dock narrowed the view, which framed the mesh anew
    window.plotter.render()
    t = int(np.argmin(np.linalg.norm(mesh.centroids[:, :2] - (0.0, 4.5), axis=1)))
    click_world(qtbot, window.plotter, mesh.centroids[t])

    # (the inspector shows an edge of its own when it opens: wait for the clicked one, an
    # edge of a triangle under the click; paper patches overlap, so not always t's)
    def near_click() -> bool:
        if panel.edge is None:
            return False
        middle = mesh.points[mesh.edges[panel.edge]].mean(axis=0)
        return bool(np.linalg.norm(middle[:2] - mesh.centroids[t][:2]) < 0.2)

    qtbot.waitUntil(near_click, timeout=60_000)
    window.plotter.setFocus()
    qtbot.keyClick(window.plotter, Qt.Key.Key_R)
    qtbot.wait(600)  # at rest on the whole mesh: nothing to detail
    assert window.scene.detail_rect is None
    qtbot.mouseClick(panel.zoom_button, Qt.MouseButton.LeftButton)
    qtbot.waitUntil(lambda: window.scene.detail_rect is not None, timeout=30_000)
    qtbot.waitUntil(lambda: "Full detail of" in _note(window), timeout=10_000)
    ids = set(np.asarray(window.scene.datasets["faces"].cell_data["triangle"]).tolist())
    assert set(mesh.edge_triangles[panel.edge].tolist()) - {-1} <= ids
    window.plotter.render()
    window.grab().save("/tmp/wb/shots/inspector_zoom_200k.png")
