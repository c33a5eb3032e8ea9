"""The view's rulers (:class:`barymesh.app.view.rulers.Rulers`), drawn off screen.

They replaced ``vtkCubeAxesActor``, which rebuilt every label object of its twelve axes
inside the render that followed a new tick count: 40 to 70 ms of the GUI thread each
time a wheel zoom over a dense mesh came to rest (issue 30, item 13). What is checked
here: the labels, where the ink is (ticks, labels, titles, in pixels from the rules), a
k times larger font giving k times the measures, titles kept inside the view, and a new
tick count reusing the text actors already made.
"""

import numpy as np
import pytest

pv = pytest.importorskip("pyvista")

from barymesh.app.view.rulers import TICK_PX, Rulers  # noqa: E402

SIZE = (400, 300)


@pytest.fixture
def plotter():
    p = pv.Plotter(off_screen=True, window_size=SIZE)
    p.set_background("white")
    yield p
    p.close()


def labels(rulers, axis):
    array = rulers.GetAxisLabels(axis)
    return [array.GetValue(i) for i in range(array.GetNumberOfValues())]


def framed(plotter, box, margin=0.35):
    """A top view of ``box`` (x0, x1, y0, y1) with room around it for the labels."""
    x0, x1, y0, y1 = box
    camera = plotter.camera
    camera.parallel_projection = True
    camera.focal_point = (0.5 * (x0 + x1), 0.5 * (y0 + y1), 0.0)
    camera.position = (0.5 * (x0 + x1), 0.5 * (y0 + y1), 10.0)
    camera.up = (0.0, 1.0, 0.0)
    camera.parallel_scale = 0.5 * (y1 - y0) * (1.0 + 2.0 * margin)
    plotter.renderer.ResetCameraClippingRange()


def ink(plotter):
    """Where the picture is dark (the rulers are drawn in #303030 on white), rows
    counted from the top (a 1 px line between two pixel columns is two
    half-dark ones)."""
    plotter.render()
    image = np.asarray(plotter.screenshot(None, return_img=True))[..., :3].astype(int)
    return image.max(axis=-1) < 200


def display(plotter, point):
    renderer = plotter.renderer
    renderer.SetWorldPoint(*point, 1.0)
    renderer.WorldToDisplay()
    x, y, _ = renderer.GetDisplayPoint()
    return x, SIZE[1] - 1 - y  # image column, row


def test_labels_are_the_ticks_from_end_to_end_in_the_format(plotter):
    rulers = Rulers(plotter.renderer)
    rulers.n_xlabels, rulers.n_ylabels = 6, 3
    rulers.bounds = (-10.0, 15.0, 0.0, 0.5, 0.0, 0.0)
    assert labels(rulers, 0) == ["-10", "-5", "0", "5", "10", "15"]
    assert labels(rulers, 1) == ["0", "0.25", "0.5"]
    rulers.x_label_format = "{:.1f}"
    assert labels(rulers, 0) == ["-10.0", "-5.0", "0.0", "5.0", "10.0", "15.0"]
    with pytest.raises(ValueError, match="at least one label"):
        rulers.n_xlabels = 0


def test_ticks_labels_and_titles_sit_where_a_reader_looks(plotter):
    rulers = Rulers(plotter.renderer)
    rulers.n_xlabels = rulers.n_ylabels = 3
    rulers.bounds = (0.0, 10.0, 0.0, 10.0, 0.0, 0.0)
    framed(plotter, (0.0, 10.0, 0.0, 10.0))
    dark = ink(plotter)
    col0, row0 = display(plotter, (0.0, 0.0, 0.0))  # the rules' corner
    col5, _ = display(plotter, (5.0, 0.0, 0.0))
    c, r, c5 = round(col0), round(row0), round(col5)
    # the x rule runs along row r from the corner to x = 10, its tick at x = 5 points
    # down TICK_PX pixels; the y rule runs up column c
    assert dark[r - 1 : r + 2, c + 5 : c + 100].any(axis=0).all()
    assert dark[r + 2 : r + int(TICK_PX), c5 - 1 : c5 + 2].any()
    assert not dark[r + 2 : r + int(TICK_PX), c5 + 4 : c5 + 8].any()
    assert dark[r - 100 : r - 5, c - 1 : c + 2].any(axis=1).all()
    # the label "5" under its tick (centred on it, below the tick's end)
    band = dark[r + int(TICK_PX) + 1 : r + 30, c5 - 10 : c5 + 11]
    rows, cols = np.nonzero(band)
    assert len(rows) > 10 and abs(cols.mean() - 10) < 3
    # the x title "x (mm)" under the labels, centred under the rule
    below = dark[r + 30 : r + 60, c : c + 200]
    rows, cols = np.nonzero(below)
    assert len(rows) > 20 and abs(c + cols.mean() - col5) < 6
    # the y title, turned, left of the y labels and clear of them
    left = dark[r - 200 : r, max(c - 80, 0) : c - 30]
    assert left.any()


def test_a_k_times_larger_font_gives_k_times_the_measures(plotter):
    """A 3x screenshot draws its rulers at 3 times the fonts: ticks, gaps and titles
    3 times as far out, as in a 3 times larger view."""
    rulers = Rulers(plotter.renderer)
    rulers.n_xlabels = rulers.n_ylabels = 3
    rulers.bounds = (0.0, 10.0, 0.0, 10.0, 0.0, 0.0)
    framed(plotter, (0.0, 10.0, 0.0, 10.0), margin=0.6)

    def tick_and_label_rows():
        dark = ink(plotter)
        col, row = (round(v) for v in display(plotter, (10.0, 0.0, 0.0)))
        column = dark[row + 2 :, col]
        tick = int(np.argmin(column))  # dark pixels under the rule, then a gap
        label_top = tick + int(np.argmax(dark[row + 2 + tick :, col - 4 : col + 5].any(axis=1)))
        return tick + 2, label_top + 2

    tick1, label1 = tick_and_label_rows()
    for axis in range(3):
        rulers.GetLabelTextProperty(axis).SetFontSize(36)
        rulers.GetTitleTextProperty(axis).SetFontSize(36)
    tick3, label3 = tick_and_label_rows()
    assert tick1 == pytest.approx(TICK_PX, abs=1.5)
    assert tick3 == pytest.approx(3 * TICK_PX, abs=1.5)
    assert label3 == pytest.approx(3 * label1, abs=3)


def test_titles_move_in_to_stay_inside_the_view_but_not_onto_the_labels():
    """With 50 px under the x rule and 50 px left of the y rule (the titles sit 42 and
    51 px out), each title moves in to stay 10 px inside the edge, still clear of the
    labels; with less room than the labels and title need, it stays clear of the
    labels (cut by the edge, as a title that does not fit is)."""
    p = pv.Plotter(off_screen=True, window_size=(300, 300))
    try:
        p.set_background("white")
        rulers = Rulers(p.renderer)
        rulers.n_xlabels = rulers.n_ylabels = 3
        rulers.bounds = (0.0, 10.0, 0.0, 10.0, 0.0, 0.0)
        framed(p, (0.0, 10.0, 0.0, 10.0), margin=0.25)  # 20 px a mm, 50 px around
        p.render()
        image = np.asarray(p.screenshot(None, return_img=True))[..., :3].astype(int)
        dark = image.max(axis=-1) < 200
        rows = np.nonzero(dark.any(axis=1))[0]
        cols = np.nonzero(dark.any(axis=0))[0]
        assert rows.max() <= 300 - 10 and cols.min() >= 10  # inside by 10 px
        # the labels and the titles do not touch: a blank row between the x labels
        # (under the rule at row 250) and the x title, a blank column between the y
        # labels and the turned y title
        below = dark[251:, 60:240].any(axis=1)
        assert not below.all() and below[-30:].any()
        ink_rows = np.nonzero(below)[0]
        assert (np.diff(ink_rows) > 1).sum() >= 2  # tick | labels | title
        left = dark[60:240, :49].any(axis=0)
        ink_cols = np.nonzero(left)[0]
        assert (np.diff(ink_cols) > 1).sum() >= 2  # title | labels | tick
    finally:
        p.close()


def test_a_new_tick_count_reuses_the_text_actors_it_made(plotter):
    """The cost the cube axes had: a new count rebuilt every label. Here the pool of
    text actors grows to the largest count asked for and is reused, empty beyond it."""
    renderer = plotter.renderer
    rulers = Rulers(renderer)
    rulers.n_xlabels = rulers.n_ylabels = 9
    rulers.bounds = (0.0, 8.0, 0.0, 8.0, 0.0, 0.0)
    actors = set(map(id, rulers.props()))
    props = renderer.GetViewProps().GetNumberOfItems()
    for n in (5, 9, 3, 7, 9):
        rulers.n_xlabels = rulers.n_ylabels = n
        assert renderer.GetViewProps().GetNumberOfItems() == props
        assert set(map(id, rulers.props())) == actors
        texts = [a.GetInput() for a in rulers.props()[3:]]  # after the lines and titles
        assert sorted(filter(None, texts)) == sorted(labels(rulers, 0) + labels(rulers, 1))
        assert len(labels(rulers, 0)) == n and texts.count("") == 2 * (9 - n)
    rulers.SetVisibility(False)
    assert not any(a.GetVisibility() for a in rulers.props())
    rulers.SetVisibility(True)
    assert all(a.GetVisibility() for a in rulers.props())
