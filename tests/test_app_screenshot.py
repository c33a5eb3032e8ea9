"""Screenshots at 2x to 4x and at the command line's sizes (issue 30, section 1, items 12
and 14), in the real window (Xvfb) and through ``barymesh mesh --window-size``.

A scaled export is drawn one render at a time (the annotation, then tiles of the mesh)
under a progress dialog with Cancel, the event loop running between the renders; what
it writes is the picture of the view at k times the pixels. The command line's
screenshot above 1024 x 768 is that picture too, its text scaled with its size.
"""

import os
import subprocess
import sys
from types import SimpleNamespace

import imageio.v3 as iio
import numpy as np
import pytest

pytest.importorskip("pyvistaqt")

from app_user import answer_file_dialogs, type_into  # noqa: E402
from PySide6.QtCore import Qt, QTimer  # noqa: E402
from PySide6.QtTest import QTest  # noqa: E402
from PySide6.QtWidgets import QApplication, QProgressDialog, QPushButton  # noqa: E402
from test_app_files import _export_screenshot, _grow, _shrunk  # noqa: E402

import barymesh.app.dialogs.step_progress as step_progress  # noqa: E402
import barymesh.app.view.scaled_shot as scaled_shot  # noqa: E402
from barymesh.presets import load_preset  # noqa: E402

#: A folder to keep the images in (to look at them), if set.
SHOTS = os.environ.get("BARYMESH_TEST_SHOTS")


@pytest.fixture
def window_params():
    return load_preset("paper-fig12c")[0]  # 2,304 triangles, about 10 px each


@pytest.fixture
def file_dialog(monkeypatch):
    return answer_file_dialogs(monkeypatch)


class Watch:
    """A 10 ms heartbeat timer; it also notes each visible progress dialog (its text and
    whether it has Cancel) and may act on it (``on_dialog(dialog, cancel_button)``)."""

    def __init__(self, on_dialog=None) -> None:
        self.beats = 0
        self.dialogs: list[tuple[str, bool]] = []
        self.on_dialog = on_dialog
        self.timer = QTimer()
        self.timer.setInterval(10)
        self.timer.timeout.connect(self._beat)
        self.timer.start()

    def _beat(self) -> None:
        self.beats += 1
        for widget in QApplication.topLevelWidgets():
            if isinstance(widget, QProgressDialog) and widget.isVisible():
                cancel = [b for b in widget.findChildren(QPushButton) if b.text() == "Cancel"]
                self.dialogs.append((widget.labelText(), bool(cancel)))
                if self.on_dialog is not None and cancel:
                    self.on_dialog(widget, cancel[0])


@pytest.fixture
def shots(monkeypatch):
    """Every ScaledShot drawn: ``shots.marks`` holds, per shot, the heartbeat's count
    (``shots.watch.beats``) at each of its steps; ``shots.closed`` whether its steps were
    stopped early (the generator closed)."""
    state = SimpleNamespace(marks=[], closed=[], watch=None, shots=[])
    real = scaled_shot.ScaledShot.steps

    def steps(self):
        marks = []
        state.marks.append(marks)
        state.shots.append(self)
        try:
            for item in real(self):
                marks.append(state.watch.beats if state.watch is not None else 0)
                yield item
        except GeneratorExit:
            state.closed.append(self)
            raise

    monkeypatch.setattr(scaled_shot.ScaledShot, "steps", steps)
    return state


def _keep(name, image):
    if SHOTS:
        iio.imwrite(os.path.join(SHOTS, name), image)


def _block_mean(image, k):
    """A k-times larger image back at 1x, each pixel the mean of its k x k block."""
    h, w = image.shape[0] // k, image.shape[1] // k
    blocks = image[: h * k, : w * k, :3].astype(float).reshape(h, k, w, k, 3)
    return blocks.mean(axis=(1, 3))


def _neighbourhood(image):
    """Per pixel and channel, the least and the greatest value of it and its 8 neighbours."""
    pad = np.pad(image, ((1, 1), (1, 1), (0, 0)), mode="edge")
    h, w = image.shape[:2]
    shifted = [pad[dy : dy + h, dx : dx + w] for dy in range(3) for dx in range(3)]
    return np.min(shifted, axis=0), np.max(shifted, axis=0)


def test_a_3x_export_is_drawn_in_steps_while_the_window_answers(
    window, qtbot, tmp_path, file_dialog, shots
):
    """File → Export screenshot at 3x froze the window for 7–12 s (three renders at 3x,
    no progress). Now: a progress dialog with Cancel, one render a step (the annotation,
    3 x 3 tiles of the view's size), the event loop running between
    them; the image is the view's picture at three times the pixels."""
    qtbot.waitUntil(lambda: window.model.result is not None, timeout=30_000)
    window.model.set_color_by("min_angle")  # a colour bar, its title and ticks
    qtbot.wait(200)
    one = _export_screenshot(window, qtbot, file_dialog, tmp_path / "one.png", 1)
    assert shots.marks == []  # 1x: the view's own frame, no steps
    shots.watch = watch = Watch()
    big = _export_screenshot(window, qtbot, file_dialog, tmp_path / "big.png", 3)
    watch.timer.stop()
    _keep("export_1x.png", one)
    _keep("export_3x.png", big)
    h, w = one.shape[:2]
    assert big.shape[:2] == (3 * h, 3 * w)
    # drawn in steps: the annotation and 9 tiles the view's size...
    (shot,) = shots.shots
    assert shot.view == (w, h) and len(shot.tiles) == 9
    (marks,) = shots.marks
    assert len(marks) == shot.total == 1 + 9
    # ...with the event loop running between them (the 10 ms heartbeat beat in most of
    # the gaps; one render at 3x blocked it from the click to the end) and after them
    # while the PNG was written in a worker thread
    gaps = np.diff(marks)
    assert (gaps > 0).sum() >= len(gaps) // 2, marks
    assert watch.beats > marks[-1]
    # a progress dialog with Cancel said what was drawn
    assert watch.dialogs and all(cancel for _text, cancel in watch.dialogs)
    assert any(f"{3 * w} × {3 * h} px" in text for text, _ in watch.dialogs)
    assert not any(
        d.isVisible() for d in QApplication.topLevelWidgets() if isinstance(d, QProgressDialog)
    )
    # the same picture: at 1x again (each 3 x 3 block's mean) each pixel lies within the
    # colours of the 1x pixel and its 8 neighbours (a 1 px line of the 1x image may fall
    # on either side of a block border at 3x), give or take the anti-aliasing of edges
    # and the hinting of text
    mean = _block_mean(big, 3)
    lo, hi = _neighbourhood(one[:h, :w, :3].astype(float))
    off = np.maximum(lo - mean, mean - hi).max(axis=-1)
    assert np.mean(off > 40) < 0.01, np.mean(off > 40)
    # and no seam between the tiles: a row and a column of pixels across each border
    # look like their neighbours (the faces' colours, edges and dots run through)
    for y in (h, 2 * h):
        row = y  # the first row of the tile below the border (image rows grow down)
        across = np.abs(big[row].astype(int) - big[row - 1].astype(int)).max(axis=-1)
        within = np.abs(big[row + 2].astype(int) - big[row + 1].astype(int)).max(axis=-1)
        assert (across > 60).mean() <= (within > 60).mean() + 0.02
    # the tiles' mesh is the one k times larger render the export was before, pixel for
    # pixel (a single render of the same copy at 3x)
    plotter, copy = scaled_shot._scene_copy(window.scene, 3)
    try:
        plotter.render()
        single = np.asarray(plotter.screenshot(None, return_img=True))
    finally:
        plotter.close()
    _keep("single_3x.png", single)
    same = np.abs(single.astype(int) - big[..., :3].astype(int)).max(axis=-1) <= 24
    assert same.mean() > 0.995, same.mean()


def test_cancel_stops_a_scaled_export_and_leaves_no_file(
    window, qtbot, tmp_path, file_dialog, shots, monkeypatch
):
    """Cancel in the progress dialog, after a few of the renders: no file and no
    temporary file, the off-screen renders are given up, the status bar says so and the
    Export screenshot dialog stays for another try."""
    from barymesh.app.dialogs.screenshot_dialog import ScreenshotDialog

    monkeypatch.setattr(step_progress, "SHOW_AFTER_MS", 0)  # the dialog at once
    qtbot.waitUntil(lambda: window.model.result is not None, timeout=30_000)
    folder = tmp_path / "out"
    folder.mkdir()
    clicked = []

    def cancel_after_three_steps(dialog, button):
        if not clicked and shots.marks and len(shots.marks[-1]) >= 3:
            clicked.append(dialog.labelText())
            QTest.mouseClick(button, Qt.MouseButton.LeftButton)

    shots.watch = watch = Watch(cancel_after_three_steps)
    kept = []

    def exec_(dialog):
        kept.append(dialog)
        dialog.show()
        type_into(dialog.scale.lineEdit(), "3")
        file_dialog(folder / "big.png")
        save = next(b for b in dialog.findChildren(QPushButton) if b.text() == "Save PNG…")
        QTest.mouseClick(save, Qt.MouseButton.LeftButton)
        return 1

    monkeypatch.setattr(ScreenshotDialog, "exec", exec_)
    window.act_shot.trigger()
    watch.timer.stop()
    assert clicked, "no progress dialog with Cancel came"
    (shot,) = shots.shots
    assert shots.closed == [shot] and shot.image is None
    assert 3 <= len(shots.marks[0]) < shot.total
    assert list(folder.iterdir()) == []
    assert window.statusBar().currentMessage() == "Screenshot big.png cancelled: no file written"
    assert kept[0].isVisible()  # not saved: the dialog stays
    kept[0].close()


def _cli_screenshot(tmp_path, name, size):
    """``barymesh mesh --preset paper-fig12c --screenshot NAME --window-size W H`` with no
    display (the off-screen path), as an (h, w, 3) image."""
    out = tmp_path / name
    env = dict(os.environ, XDG_CONFIG_HOME=str(tmp_path))
    env.pop("DISPLAY", None)
    args = ["mesh", "--preset", "paper-fig12c", "--screenshot", str(out), "--window-size"]
    proc = subprocess.run(
        [sys.executable, "-m", "barymesh.app.cli", *args, *map(str, size)],
        env=env,
        capture_output=True,
        text=True,
        timeout=600,
    )
    assert proc.returncode == 0, proc.stderr
    image = iio.imread(out)[..., :3]
    assert image.shape[:2] == (size[1], size[0])
    return image


def _dark(image):
    """Where ``image`` is grey ink: the rulers, their labels and titles (not the blue
    boundary edges, which the export tests' ink counts too, nor the blue-grey
    triangle edges)."""
    rgb = image[..., :3].astype(int)
    return (rgb.max(axis=-1) < 200) & (rgb.max(axis=-1) - rgb.min(axis=-1) < 25)


def _x_ruler(ink):
    """The image row of the x ruler's line: the row of the lower half with most ink."""
    h = ink.shape[0]
    return h // 2 + int(np.argmax(ink[h // 2 :].sum(axis=1)))


def _label_rows(ink, ruler):
    """(first, last) rows of the x ruler's tick labels: the first band of ink rows
    below the ruler's line and its ticks."""
    below = ink[ruler:].any(axis=1)
    rows = np.flatnonzero(below)
    gaps = np.flatnonzero(~below)
    start = rows[rows > gaps[0]][0] if len(gaps) else rows[0]  # past the line and ticks
    end = gaps[gaps > start][0] - 1
    return ruler + int(start), ruler + int(end)


def test_the_command_lines_big_screenshot_scales_its_text(tmp_path):
    """``barymesh mesh --window-size 3072 2304`` drew tick labels about 12 px tall on a
    3072 px image (the text of a 1024 px one). Now the image is the 1024 x 768 picture
    at 3 times the pixels, as File → Export screenshot draws the view at 3x: labels three
    times as tall, and its ink at 1x is the 1024 x 768 image's."""
    small = _cli_screenshot(tmp_path, "small.png", (1024, 768))
    big = _cli_screenshot(tmp_path, "big.png", (3072, 2304))
    _keep("cli_1024.png", small)
    _keep("cli_3072.png", big)
    ink_small, ink_big = _dark(small), _dark(big)
    ruler_small, ruler_big = _x_ruler(ink_small), _x_ruler(ink_big)
    assert abs(ruler_big - 3 * ruler_small) <= 4  # the same picture, 3 times the pixels
    lo, hi = _label_rows(ink_small, ruler_small)
    big_lo, big_hi = _label_rows(ink_big, ruler_big)
    ratio = (big_hi - big_lo + 1) / (hi - lo + 1)
    assert 2.6 < ratio < 3.4, (lo, hi, big_lo, big_hi)
    # below the x ruler (its labels and title) the ink is where the small image has it
    a = ink_small[ruler_small + 3 :]
    b = _shrunk(ink_big, 3)[ruler_small + 3 :]
    assert a.sum() > 100
    missing = (a & ~_grow(b)).sum() / a.sum()
    stray = (b & ~_grow(a)).sum() / max(b.sum(), 1)
    assert missing < 0.15 and stray < 0.25, (missing, stray)


def test_screenshot_scale_follows_the_smaller_side():
    assert scaled_shot.screenshot_scale(3072, 2304) == 3.0
    assert scaled_shot.screenshot_scale(2048, 2304) == 2.0  # as wide as two bases
    assert scaled_shot.screenshot_scale(1024, 768) == 1.0
    assert scaled_shot.screenshot_scale(320, 240) == 1.0  # never below 1: readable text
