"""The connectivity matrix view (the paper's Eq. 27) in a real window (Xvfb, see conftest.py)."""

import time

import imageio.v3 as iio
import numpy as np
import pytest

pytest.importorskip("pyvistaqt")
pytest.importorskip("matplotlib")

import scipy.sparse as sp  # noqa: E402
from PySide6.QtCore import QPoint, Qt  # noqa: E402

from app.matrix_view import MatrixView, occupancy_image  # noqa: E402
from app.teaching_tools import shared_edge  # noqa: E402
from core import MeshParams, build_mesh  # noqa: E402

FIG10 = MeshParams(structure="patch", patch_size=10.0, subdivisions=4)  # 32 triangles


@pytest.fixture
def window_params():
    return FIG10


@pytest.fixture
def window(window, qtbot):
    """The main window on Fig. 10 with the matrix view on."""
    window.teaching.set_matrix_active(True)
    qtbot.waitUntil(lambda: not window.teaching.matrix.stale)
    return window


def canvas_point(view, row, col):
    """Qt widget position of matrix cell (row, col) on the spy plot."""
    view.canvas.draw()
    x, y = view.axes.transData.transform((col, row))
    ratio = view.canvas.devicePixelRatioF()
    return QPoint(round(x / ratio), round(view.canvas.height() - y / ratio))


def test_nonzeros_are_twice_the_interior_edges(window):
    mesh = window.model.result.mesh
    view = window.teaching.matrix
    assert view.nonzeros() == 2 * len(mesh.interior_edges) == 80
    assert view.table_nonzeros() == 80
    assert view.table_model.rowCount() == view.table_model.columnCount() == 32
    assert "80 ones = 2 × 40 interior edges" in view.caption.text()


def test_hovering_a_spy_cell_highlights_its_two_triangles(window, qtbot):
    mesh = window.model.result.mesh
    view = window.teaching.matrix
    i, j = int(mesh.rwg.t_plus[5]), int(mesh.rwg.t_minus[5])
    qtbot.mouseMove(view.canvas, canvas_point(view, i, j))
    qtbot.waitUntil(lambda: window.teaching.highlight.triangles == (i, j))
    assert view.cell == (i, j)
    centroid = mesh.centroids[i]
    row_poly = window.teaching.highlight.datasets["row"]
    assert np.allclose(row_poly.points.mean(axis=0)[:2], centroid[:2])


def test_clicking_a_spy_one_selects_the_shared_edge_in_the_inspector(window, qtbot):
    mesh = window.model.result.mesh
    window.teaching.set_inspector_active(True)
    window.teaching.set_matrix_active(True)
    view = window.teaching.matrix
    row = 11
    i, j = int(mesh.rwg.t_plus[row]), int(mesh.rwg.t_minus[row])
    qtbot.mouseClick(view.canvas, Qt.MouseButton.LeftButton, pos=canvas_point(view, i, j))
    assert window.teaching.inspector.edge == mesh.rwg.edge[row]
    assert view.row == i


def test_table_hover_and_click(window, qtbot):
    mesh = window.model.result.mesh
    view = window.teaching.matrix
    view.tabs.setCurrentIndex(1)
    qtbot.waitUntil(view.table.isVisible)
    i, j = 0, int(mesh.connectivity[0].indices[0])
    rect = view.table.visualRect(view.table_model.index(i, j))
    qtbot.mouseMove(view.table.viewport(), rect.center())
    qtbot.waitUntil(lambda: window.teaching.highlight.triangles == (i, j))
    i2, j2 = 3, 7
    rect = view.table.visualRect(view.table_model.index(i2, j2))
    qtbot.mouseClick(view.table.viewport(), Qt.MouseButton.LeftButton, pos=rect.center())
    assert window.teaching.highlight.triangles == (i2, j2)
    assert view.table_model.data(view.table_model.index(i, j)) == "1"


def test_picking_a_triangle_highlights_its_row(window, qtbot):
    mesh = window.model.result.mesh
    view = window.teaching.matrix
    renderer = window.plotter.renderer
    t = 13
    renderer.SetWorldPoint(*mesh.centroids[t], 1.0)
    renderer.WorldToDisplay()
    x, y, _ = renderer.GetDisplayPoint()
    window.teaching.picker.pick_display(x, y)
    assert view.row == t and view.row_band.get_visible()
    assert [ix.row() for ix in view.table.selectionModel().selectedRows()] == [t]
    assert window.teaching.highlight.triangles == (t,)


def test_view_follows_the_mesh_and_skips_work_while_hidden(window):
    view = window.teaching.matrix
    window.teaching.set_matrix_active(False)
    window.controls.rows["subdivisions"].spin.setValue(2)
    window.controller.flush()
    assert view.stale  # hidden: nothing redrawn yet
    window.teaching.set_matrix_active(True)
    view.refresh()  # (the view also does this itself once shown)
    mesh = window.model.result.mesh
    assert view.matrix.shape == (8, 8)
    assert view.nonzeros() == 2 * len(mesh.interior_edges)


def test_big_matrix_is_fast_and_drawn_as_occupancy(qtbot):
    mesh = build_mesh(MeshParams())  # the paper's Fig. 12(a): 23,040 triangles
    view = MatrixView()
    qtbot.addWidget(view)  # deleted with the test, not at interpreter exit
    view.set_mesh(mesh)
    start = time.perf_counter()
    view.refresh()
    view.canvas.draw()
    assert time.perf_counter() - start < 3.0
    assert view.nonzeros() == mesh.connectivity.nnz == 2 * len(mesh.interior_edges)
    assert view.image.get_array().shape == (600, 600)
    assert view.table_nonzeros() == 0 and not view.table_note.isHidden()


def test_occupancy_image_marks_blocks_with_a_nonzero():
    m = sp.csr_matrix(([1, 1], ([0, 9], [9, 0])), shape=(10, 10))
    image = occupancy_image(m, 5)
    assert image.sum() == 2 and image[0, 4] and image[4, 0]


def test_shared_edge_of_two_triangles():
    mesh = build_mesh(FIG10)
    row = 3
    assert shared_edge(mesh, int(mesh.rwg.t_plus[row]), int(mesh.rwg.t_minus[row])) == \
        mesh.rwg.edge[row]
    assert shared_edge(mesh, 0, 0) is None


def test_matrix_screenshot_is_not_blank(window, qtbot, tmp_path):
    view = window.teaching.matrix
    view.highlight_row(4)
    path = tmp_path / "matrix.png"
    window.grab().save(str(path))
    image = iio.imread(path)
    assert len(np.unique(image[..., :3].reshape(-1, 3), axis=0)) > 10
    spy = tmp_path / "spy.png"
    view.canvas.draw()
    view.figure.savefig(spy)
    assert len(np.unique(iio.imread(spy)[..., :3].reshape(-1, 3), axis=0)) > 3
