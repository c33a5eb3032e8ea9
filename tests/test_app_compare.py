"""Teach → Paper vs conforming, in a real window under Xvfb (see conftest.py)."""

import numpy as np
import pytest

pytest.importorskip("pyvistaqt")

from gui_helpers import near, pixel, share, type_into  # noqa: E402
from PySide6.QtCore import Qt  # noqa: E402

from barymesh import MeshParams, build_mesh  # noqa: E402
from barymesh.app.model import AppModel  # noqa: E402
from barymesh.app.teach.compare_view import CompareView, patch_coverage  # noqa: E402
from barymesh.app.window import MainWindow  # noqa: E402

COARSE = MeshParams(angle_step=15.0, subdivisions=2)
COUNTS = ("triangles", "vertices", "interior_edges", "boundary_edges")


def wait_shown(qtbot, view):
    qtbot.waitUntil(
        lambda: not view.busy and view.shown_generation == view.generation, timeout=30_000
    )


@pytest.fixture
def view(qtbot):
    win = CompareView(AppModel(COARSE))
    qtbot.addWidget(win)
    win.resize(1200, 700)
    win.show()
    qtbot.waitExposed(win)
    wait_shown(qtbot, win)
    yield win
    win.close()


def assert_half(view, params, mode):
    stats = build_mesh(params.replace(mode=mode)).stats()
    shown = view.stats_of(mode)
    text = view.stats[mode].text()
    for key in COUNTS:
        assert shown[key] == stats[key], (mode, key)
        assert f"{stats[key]:,}" in text, (mode, key)
    assert view.scenes[mode].datasets["faces"].n_cells == stats["triangles"]


def test_both_modes_with_the_counts_of_build_mesh(view):
    for mode in ("paper", "conforming"):
        assert_half(view, COARSE, mode)
    assert "Overlap ratio" in view.stats["paper"].text()
    assert "%" in view.stats["paper"].text()


def test_the_cameras_are_linked(view):
    renderers = view.plotter.renderers
    assert len(renderers) == 2
    assert (
        renderers[0].camera is renderers[1].camera
        or renderers[0].GetActiveCamera() is renderers[1].GetActiveCamera()
    )


def test_overlap_of_paper_mode_is_shaded(view, qtbot):
    view.model.set_value("angle_step", 5.0)  # 1 mm patches, 5 degrees apart: they overlap
    wait_shown(qtbot, view)
    overlay = view.overlays["paper"]
    mesh = build_mesh(view.model.params)
    assert 0 < overlay.n_cells < mesh.n_triangles
    assert set(np.unique(overlay.cell_data["coverage"])) <= {2.0, 3.0}
    assert "2+ patches" in view.stats["paper"].text()


def test_patch_coverage_counts_covering_patches():
    one = build_mesh(MeshParams(structure="patch", subdivisions=2))
    assert (patch_coverage(one) == 1).all()
    conforming = build_mesh(COARSE.replace(mode="conforming"))
    assert patch_coverage(conforming) is None


def test_an_invalid_mode_shows_its_error_in_its_half(view, qtbot):
    bad = COARSE.replace(inner_radius=4.0, outer_radius=4.5, patch_size=1.0)
    view.model.set_params(bad)  # paper accepts it; conforming rings would overlap
    wait_shown(qtbot, view)
    assert_half(view, bad, "paper")
    assert view.stats_of("conforming") is None
    assert "outer_radius" in view.stats["conforming"].text()
    message = view.messages["conforming"]
    assert message.GetVisibility() and "outer_radius" in message.GetInput()
    assert not view.scenes["conforming"].actors["faces"].GetVisibility()
    view.model.set_params(COARSE)  # and back
    wait_shown(qtbot, view)
    assert not message.GetVisibility()
    assert_half(view, COARSE, "conforming")


def test_follows_the_parameters_latest_wins(view, qtbot):
    view.model.set_value("subdivisions", 3)
    view.model.set_value("subdivisions", 1)
    wait_shown(qtbot, view)
    assert_half(view, COARSE.replace(subdivisions=1), "paper")
    assert_half(view, COARSE.replace(subdivisions=1), "conforming")


def test_screenshot_shows_faces_and_background_where_they_are(view, tmp_path):
    """Pixels, not colour counts: inside triangles of each half the face colour (or, in
    paper mode, the shade of a face under two patches), at the rings' centre the white
    background."""
    import imageio.v3 as iio

    from barymesh.app.teach.compare_view import COVERAGE_COLORS
    from barymesh.app.view.scene_data import COLORS

    # triangles of about 8 px get their edges drawn (from 4 px; in paper mode the patch
    # borders too): this test is about the faces, so those lines are switched off
    for scene in view.scenes.values():
        for layer in ("triangle_edges", "shared_edges", "boundary_edges"):
            scene.set_visible(layer, False)
    view.plotter.ren_win.Render()  # (the widget's render() only schedules a paint)
    image = view.view_image()
    iio.imwrite(tmp_path / "compare.png", image)
    for col, mode in enumerate(("paper", "conforming")):
        renderer = view.plotter.renderers[col]
        mesh = view.halves[mode].result.mesh
        assert near(pixel(image, view.plotter, (0.0, 0.0, 0.0), renderer), "#ffffff", 3), mode
        faces = [
            share(
                image,
                view.plotter,
                mesh.points[mesh.triangles[t]],
                colour,
                tol=25,
                renderer=renderer,
            )
            for t in range(0, mesh.n_triangles, 37)
            for colour in (COLORS["faces"], *COVERAGE_COLORS)
        ]
        # inside a triangle most samples show a face colour (the rest: its edge lines)
        per_triangle = np.array(faces).reshape(-1, 3).sum(axis=1)
        assert np.median(per_triangle) > 0.5, (mode, per_triangle)
    assert view.grab().save(str(tmp_path / "compare-window.png"))


def test_opened_from_the_teach_menu_and_closed_with_the_window(qtbot):
    win = MainWindow(COARSE, scripted=True)
    qtbot.addWidget(win)
    win.show()
    qtbot.waitExposed(win)
    win.controller.flush()
    assert win.teaching_windows.act_compare in win.teach_menu.actions()
    with qtbot.waitActive(win):
        win.activateWindow()
    win.plotter.setFocus()
    qtbot.keyClick(win.plotter, Qt.Key.Key_F8)  # Teach → Paper vs conforming
    view = win.teaching_windows.compare
    wait_shown(qtbot, view)
    assert_half(view, COARSE, "paper")
    type_into(qtbot, win.controls.rows["subdivisions"].spin, 3)
    win.controller.flush()
    wait_shown(qtbot, view)
    assert_half(view, COARSE.replace(subdivisions=3), "conforming")
    win.close()
    assert view._closed


@pytest.mark.parametrize("preset", ["paper-fig12c", "srr-openmodes"])
def test_both_halves_show_triangle_edges_at_the_default_size(qtbot, preset):
    from barymesh.presets import load_preset

    params, _ = load_preset(preset)
    win = CompareView(AppModel(params))  # its own default size (no resize)
    qtbot.addWidget(win)
    win.show()
    qtbot.waitExposed(win)
    wait_shown(qtbot, win)
    try:
        for mode in ("paper", "conforming"):
            scene = win.scenes[mode]
            if win.stats_of(mode) is None:  # a mode the core refuses for this preset
                continue
            mesh = build_mesh(params.replace(mode=mode))
            assert scene.edge_px >= 4.0, (mode, scene.edge_px)
            assert not scene.light, mode
            for layer in ("triangle_edges", "shared_edges"):
                assert scene.shows(layer), (mode, layer)
            assert scene.datasets["triangle_edges"].n_cells == len(mesh.edges)
            assert scene.datasets["shared_edges"].n_cells == len(mesh.interior_edges)
            assert "hidden" not in scene.note.GetInput(), mode
        assert win.stats_of("paper") is not None or win.stats_of("conforming") is not None
    finally:
        win.close()


def test_shading_legend_counts_each_shade_and_edges_show_on_it(qtbot):
    from gui_helpers import colour_pixels

    from barymesh.app.teach.compare_view import COVERAGE_COLORS
    from barymesh.app.view.scene_data import COLORS
    from barymesh.presets import load_preset

    params, _ = load_preset("srr-openmodes")
    win = CompareView(AppModel(params))
    qtbot.addWidget(win)
    win.show()
    qtbot.waitExposed(win)
    wait_shown(qtbot, win)
    try:
        mesh = build_mesh(params.replace(mode="paper"))
        coverage = patch_coverage(mesh)
        two, more = np.mean(coverage == 2), np.mean(coverage >= 3)
        text = win.stats["paper"].text()
        # one swatch per shade, each with the share of triangles it marks
        assert f"{COVERAGE_COLORS[0]}'>■</span> under 2 patches" in text
        assert f"{COVERAGE_COLORS[1]}'>■</span> under 3 or more" in text
        assert f"under 2 patches</td><td align='right'>&nbsp;&nbsp;{100 * two:.1f} %" in text
        assert f"under 3 or more</td><td align='right'>&nbsp;&nbsp;{100 * more:.1f} %" in text
        # the shading lies under the edge layers: the paper half shows its shared edges
        overlay = win.overlays["paper"]
        edges = win.scenes["paper"].datasets["triangle_edges"]
        assert overlay.n_cells == int((coverage >= 2).sum()) > 0
        assert overlay.points[:, 2].max() < edges.points[:, 2].min()
        image = win.view_image()
        left = image[:, : image.shape[1] // 2]
        assert colour_pixels(left, COLORS["shared_edges"]) > 2_000
        assert colour_pixels(left, COVERAGE_COLORS[0]) > 2_000
    finally:
        win.close()


def test_right_half_tick_labels_sit_on_its_rulers_with_axis_titles(view):
    """The right half's tick values sit at its ruler lines (the cube axes placed 2D
    labels as if every viewport began at the window's left edge)."""
    from gui_helpers import display_point, text_display_box

    from barymesh.app.view.rulers import nice_span

    x0, x1, y0, y1 = view.scenes["conforming"].bounds
    (a, b, nx), (c, d, ny) = nice_span(x0, x1), nice_span(y0, y1)
    axes = view.scenes["conforming"].axes
    assert axes.bounds[0] == a and axes.bounds[2] == c  # where the ruler lines are
    view.plotter.ren_win.Render()
    renderer = view.plotter.renderers[1]
    xs, ys = np.linspace(a, b, nx), np.linspace(c, d, ny)
    x_labels, y_labels = axes.label_actors(0), axes.label_actors(1)
    assert [t.GetInput() for t in x_labels] == [f"{v:.4g}" for v in xs]
    assert [t.GetInput() for t in y_labels] == [f"{v:.4g}" for v in ys]
    # x values centred under their ticks, within 25 px under the bottom ruler (the box
    # holds the font's descent too); y values centred on theirs, within 30 px left of
    # the left one
    for actor, x in zip(x_labels, xs, strict=True):
        px, py = display_point(view.plotter, (x, c, 0.0), renderer)
        box = text_display_box(actor, renderer)
        assert abs(0.5 * (box[0] + box[1]) - px) < 2 and py - 25 < box[2] < box[3] < py
    for actor, y in zip(y_labels, ys, strict=True):
        px, py = display_point(view.plotter, (a, y, 0.0), renderer)
        box = text_display_box(actor, renderer)
        assert abs(0.5 * (box[2] + box[3]) - py) < 2 and px - 30 < box[0] < box[1] < px
    # the titles: "x (mm)" under the x values, "y (mm)" left of the y values
    assert axes.x_title == "x (mm)" and axes.y_title == "y (mm)"
    x_title = text_display_box(axes.title_actor(0), renderer)
    assert x_title[3] < min(text_display_box(t, renderer)[2] for t in x_labels)
    y_title = text_display_box(axes.title_actor(1), renderer)
    assert y_title[1] < min(text_display_box(t, renderer)[0] for t in y_labels)


def text_box(prop, text, dpi, centre=None, corner=None):
    """The display box (x0, x1, y0, y1) of ``text`` drawn with ``prop``: centred on
    ``centre`` (a labelled point) or from the lower-left ``corner`` (a text actor)."""
    from vtkmodules.vtkRenderingCore import vtkTextRenderer

    box = [0, 0, 0, 0]
    assert vtkTextRenderer().GetBoundingBox(prop, text, box, dpi)
    w, h = box[1] - box[0], box[3] - box[2]  # the rotation is in the box
    if centre is not None:
        return centre[0] - w / 2, centre[0] + w / 2, centre[1] - h / 2, centre[1] + h / 2
    return corner[0], corner[0] + w, corner[1], corner[1] + h


def test_right_half_y_title_keeps_clear_of_its_half_title(view, tmp_path):
    """Issue 30, 1.10: the right half's "y (mm)" sat over the top end of its ruler, on the
    "Conforming mode" title. It is drawn upright left of the tick values, half-way up the
    ruler, as on the left half."""
    from gui_helpers import display_point, text_display_box
    from vtkmodules.vtkRenderingCore import vtkTextActor

    from barymesh.app.teach.compare_view import TITLES

    view.plotter.ren_win.Render()
    renderer = view.plotter.renderers[1]
    dpi = view.plotter.ren_win.GetDPI()
    w, h = view.plotter.window_size
    axes = view.scenes["conforming"].axes
    y_box = text_display_box(axes.title_actor(1), renderer)
    props = renderer.GetViewProps()
    props.InitTraversal()
    title = next(
        a
        for a in (props.GetNextProp() for _ in range(props.GetNumberOfItems()))
        if isinstance(a, vtkTextActor) and a.GetInput() == TITLES["conforming"]
    )
    x_vp, y_vp = title.GetPosition()  # normalised in the half's viewport
    v0, v1, v2, v3 = renderer.GetViewport()
    corner = ((v0 + x_vp * (v2 - v0)) * w, (v1 + y_vp * (v3 - v1)) * h)
    title_box = text_box(title.GetTextProperty(), title.GetInput(), dpi, corner=corner)
    apart = (
        y_box[1] < title_box[0]
        or title_box[1] < y_box[0]
        or y_box[3] < title_box[2]
        or title_box[3] < y_box[2]
    )
    assert apart, (y_box, title_box)
    # as on the left half: upright (taller than wide), left of the tick values, and
    # half-way up the ruler
    from barymesh.app.view.rulers import nice_span

    x0, x1, y0, y1 = view.scenes["conforming"].bounds
    (a, _b, _nx), (c, d, _ny) = nice_span(x0, x1), nice_span(y0, y1)
    assert y_box[3] - y_box[2] > y_box[1] - y_box[0]
    ticks = [text_display_box(t, renderer) for t in axes.label_actors(1)]
    assert y_box[1] < min(t[0] for t in ticks)
    bottom = display_point(view.plotter, (a, c, 0.0), renderer)[1]
    top = display_point(view.plotter, (a, d, 0.0), renderer)[1]
    assert bottom < 0.5 * (y_box[2] + y_box[3]) < top
    assert view.grab().save(str(tmp_path / "compare.png"))


def test_worker_meshes_at_a_lower_priority_and_a_slow_build_says_so(view, qtbot, monkeypatch):
    """The halves are meshed in a worker thread of nice WORKER_NICE (Linux), still with
    build_mesh's counts; "meshing…" appears only when a build outlasts BUSY_NOTE_MS."""
    import os
    import sys
    import threading

    import barymesh.app.teach.compare_view as compare_view

    seen = []
    gate = threading.Event()
    real = compare_view.compute_halves

    def recorded(params, generation):
        out = real(params, generation)  # sets the thread's priority first
        if sys.platform.startswith("linux"):
            seen.append(os.getpriority(os.PRIO_PROCESS, threading.get_native_id()))
        gate.wait(20)
        return out

    monkeypatch.setattr(compare_view, "compute_halves", recorded)
    fine = COARSE.replace(subdivisions=3)
    view.request(fine)
    qtbot.wait(compare_view.BUSY_NOTE_MS // 3)
    assert view.busy and view.status.text() == ""  # a short wait: nothing said yet
    qtbot.waitUntil(lambda: "meshing" in view.status.text(), timeout=5_000)
    gate.set()
    wait_shown(qtbot, view)
    assert view.status.text() == ""
    for mode in ("paper", "conforming"):
        assert_half(view, fine, mode)
    if sys.platform.startswith("linux"):
        assert seen and all(nice >= compare_view.WORKER_NICE for nice in seen)


def test_closing_while_the_first_meshes_wait_for_their_second_pass(qtbot):
    """Closed between the paper half's paint and the conforming half's: no crash, and the
    window is not left busy."""
    win = CompareView(AppModel(COARSE))
    qtbot.addWidget(win)
    win.show()
    qtbot.waitExposed(win)
    qtbot.waitUntil(lambda: win.halves.get("conforming") is not None, timeout=30_000)
    win.close()
    qtbot.wait(50)
    assert win._closed and not win.busy
