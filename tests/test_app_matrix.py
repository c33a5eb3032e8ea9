"""The connectivity matrix view (the paper's Eq. 27) in a real window (Xvfb, see conftest.py)."""

import time

import imageio.v3 as iio
import numpy as np
import pytest

pytest.importorskip("pyvistaqt")
pytest.importorskip("matplotlib")

import scipy.sparse as sp  # noqa: E402
from gui_helpers import blend, click_world, near, type_into  # noqa: E402
from PySide6.QtCore import QPoint, Qt  # noqa: E402
from PySide6.QtWidgets import QApplication  # noqa: E402

from barymesh import MeshParams, build_mesh  # noqa: E402
from barymesh.app.teach.matrix_view import MatrixView, occupancy_image  # noqa: E402
from barymesh.app.teach.teaching_tools import shared_edge  # noqa: E402

FIG10 = MeshParams(structure="patch", patch_size=10.0, subdivisions=4)  # 32 triangles


@pytest.fixture
def window_params():
    return FIG10


@pytest.fixture
def window(window, qtbot):
    """The main window on Fig. 10 with the matrix view on (key M)."""
    with qtbot.waitActive(window):
        window.activateWindow()
    window.plotter.setFocus()
    qtbot.keyClick(window.plotter, Qt.Key.Key_M)
    qtbot.waitUntil(lambda: not window.teaching.matrix.stale)
    qtbot.wait(50)  # the dock's layout settles before a test reads cell positions
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
    window.plotter.setFocus()
    qtbot.keyClick(window.plotter, Qt.Key.Key_I)  # the inspector too (the matrix stays on)
    assert window.teaching.inspector_active and window.teaching.matrix_active
    view = window.teaching.matrix
    row = 11
    i, j = int(mesh.rwg.t_plus[row]), int(mesh.rwg.t_minus[row])
    qtbot.mouseClick(view.canvas, Qt.MouseButton.LeftButton, pos=canvas_point(view, i, j))
    assert window.teaching.inspector.edge == mesh.rwg.edge[row]
    assert view.row == i


def test_table_hover_and_click(window, qtbot):
    mesh = window.model.result.mesh
    view = window.teaching.matrix
    bar = view.tabs.tabBar()
    qtbot.mouseClick(bar, Qt.MouseButton.LeftButton, pos=bar.tabRect(1).center())
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
    assert renderer is window.plotter.renderer
    click_world(qtbot, window.plotter, mesh.centroids[t])
    assert view.row == t and view.row_band.get_visible()
    assert [ix.row() for ix in view.table.selectionModel().selectedRows()] == [t]
    assert window.teaching.highlight.triangles == (t,)


def test_view_follows_the_mesh_and_skips_work_while_hidden(window, qtbot):
    view = window.teaching.matrix
    window.plotter.setFocus()
    qtbot.keyClick(window.plotter, Qt.Key.Key_M)  # off
    assert not window.teaching.matrix_active
    type_into(qtbot, window.controls.rows["subdivisions"].spin, 2)
    window.controller.flush()
    assert view.stale  # hidden: nothing redrawn yet
    window.plotter.setFocus()
    qtbot.keyClick(window.plotter, Qt.Key.Key_M)  # on: redrawn once shown
    qtbot.waitUntil(lambda: not view.stale)
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
    assert (
        shared_edge(mesh, int(mesh.rwg.t_plus[row]), int(mesh.rwg.t_minus[row]))
        == mesh.rwg.edge[row]
    )
    assert shared_edge(mesh, 0, 0) is None


def test_matrix_screenshot_shows_ones_zeros_and_the_picked_row(window, qtbot, tmp_path):
    """Pixels, not colour counts: a one is blue, a zero white, the picked row orange."""
    from barymesh.app.teach.matrix_view import ONE_COLOR, ROW_COLOR

    mesh = window.model.result.mesh
    view = window.teaching.matrix
    t = 4
    click_world(qtbot, window.plotter, mesh.centroids[t])  # picks T4: its row is marked
    assert view.row == t
    QApplication.processEvents()
    path = tmp_path / "matrix.png"
    window.grab().save(str(path))
    image = iio.imread(path)[..., :3]
    corner = view.canvas.mapTo(window, QPoint(0, 0))

    def at(row, col):
        p = canvas_point(view, row, col)
        return tuple(int(v) for v in image[corner.y() + p.y(), corner.x() + p.x()])

    dense = mesh.connectivity.toarray()
    one = tuple(int(v) for v in np.argwhere(dense[10:] == 1)[0] + (10, 0))
    zero = tuple(int(v) for v in np.argwhere(dense[10:] == 0)[0] + (10, 0))
    assert near(at(*one), ONE_COLOR, 30) and near(at(*zero), "#ffffff", 3)
    # the row band: orange at 35 % over white (a zero) and over blue (a one)
    zero_in_row = int(np.flatnonzero(dense[t] == 0)[0])
    one_in_row = int(np.flatnonzero(dense[t] == 1)[0])
    assert near(at(t, zero_in_row), blend(ROW_COLOR, 0.35), 12)
    assert near(at(t, one_in_row), blend(ROW_COLOR, 0.35, ONE_COLOR), 12)


def _picture_in_a_worker(monkeypatch, gate=None):
    """Every mesh's matrix picture computed in a worker thread (the threshold below Fig.
    10's size); returns the threads that computed them."""
    import threading

    import barymesh.app.teach.matrix_view as matrix_view

    threads = []
    real = matrix_view.matrix_picture

    def recorded(mesh):
        threads.append(threading.get_ident())
        if gate is not None:
            gate.wait(20)
        return real(mesh)

    monkeypatch.setattr(matrix_view, "matrix_picture", recorded)
    monkeypatch.setattr(matrix_view, "WORKER_TRIANGLES", 10)
    return threads


def test_a_big_mesh_gets_its_matrix_from_a_worker_with_the_right_nonzeros(
    window, qtbot, monkeypatch
):
    import threading

    threads = _picture_in_a_worker(monkeypatch)
    view = window.teaching.matrix
    type_into(qtbot, window.controls.rows["subdivisions"].spin, 5)  # 50 triangles
    window.controller.flush()
    assert view.computing and view.stale  # the event loop goes on meanwhile
    qtbot.waitUntil(lambda: not view.stale, timeout=20_000)
    mesh = window.model.result.mesh
    assert threads and threads[-1] != threading.get_ident()
    # a patch at n = 5: 3n² − 2n = 65 interior edges, each two ones of the matrix
    assert view.matrix.shape == (50, 50)
    assert view.nonzeros() == 2 * len(mesh.interior_edges) == 130
    assert view.table_nonzeros() == 130
    assert "130 ones = 2 × 65 interior edges" in view.caption.text()
    assert view.full_draws >= 1


def test_a_newer_mesh_wins_over_a_picture_still_computed(window, qtbot, monkeypatch):
    import threading

    gate = threading.Event()
    _picture_in_a_worker(monkeypatch, gate)
    view = window.teaching.matrix
    type_into(qtbot, window.controls.rows["subdivisions"].spin, 5)  # 50 triangles, held
    window.controller.flush()
    assert view.computing
    type_into(qtbot, window.controls.rows["subdivisions"].spin, 3)  # 18 triangles
    window.controller.flush()
    gate.set()
    qtbot.waitUntil(lambda: not view.stale, timeout=20_000)
    qtbot.wait(200)  # the n = 5 picture arrives late and is dropped
    assert view.matrix.shape == (18, 18)
    assert view.nonzeros() == 2 * (3 * 9 - 2 * 3) == 42


def test_closing_the_window_while_the_matrix_is_computed(window, qtbot, monkeypatch):
    import threading

    gate = threading.Event()
    _picture_in_a_worker(monkeypatch, gate)
    view = window.teaching.matrix
    type_into(qtbot, window.controls.rows["subdivisions"].spin, 5)
    window.controller.flush()
    assert view.computing
    window.close()
    gate.set()  # the picture comes after the window closed: no crash, nothing drawn
    qtbot.waitUntil(lambda: not view.computing, timeout=20_000)
    assert view.nonzeros() == 130 and not view.isVisible()
