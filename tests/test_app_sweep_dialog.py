"""File → Export sweep animation, in a real window under Xvfb (see conftest.py)."""

import imageio.v3 as iio
import numpy as np
import pytest

pytest.importorskip("pyvistaqt")


from barymesh import MeshParams  # noqa: E402
from barymesh.app.teach.sweep_dialog import SweepDialog  # noqa: E402
from barymesh.app.window import MainWindow  # noqa: E402

COARSE = MeshParams(angle_step=15.0, subdivisions=2)


@pytest.fixture
def dialog(qtbot, tmp_path):
    d = SweepDialog(COARSE, start_dir=str(tmp_path))
    qtbot.addWidget(d)
    d.show()
    qtbot.waitExposed(d)
    d.size.setCurrentIndex(d.size.findText("640 × 480"))
    yield d
    d.close()


def run(qtbot, d, **values):
    for name, value in values.items():
        if name == "param":
            d.param.setCurrentIndex(d.param.findData(value))
        elif name == "path":
            d.path.setText(str(value))
        else:
            getattr(d, name).setValue(value)
    started = d.start_export()
    if started:
        qtbot.waitUntil(lambda: not d.running, timeout=120_000)
    return started


def test_writes_a_gif_with_the_asked_frame_count(dialog, qtbot, tmp_path):
    out = tmp_path / "angle.gif"
    assert run(qtbot, dialog, param="angle_step", path=out, start=30.0, stop_value=10.0, frames=4)
    assert dialog.result == 4
    frames = iio.imread(out, index=None)
    assert frames.shape[0] == 4 and frames.shape[1:3] == (480, 640)
    assert not np.array_equal(frames[0], frames[-1])  # the mesh changes
    assert "Wrote 4 frames" in dialog.message.text()
    assert dialog.progress.value() == dialog.progress.maximum()


def test_writes_an_mp4(dialog, qtbot, tmp_path):
    import imageio.v2 as imageio

    out = tmp_path / "n.mp4"
    assert run(qtbot, dialog, param="subdivisions", path=out, start=1, stop_value=3, frames=3)
    assert dialog.result == 3
    reader = imageio.get_reader(out, format="FFMPEG")
    assert reader.count_frames() == 3
    reader.close()


def test_cancel_leaves_no_file(dialog, qtbot, tmp_path):
    out = tmp_path / "cancelled.gif"
    dialog.progressed.connect(lambda *_: dialog.cancel())  # cancel after frame one
    assert run(qtbot, dialog, param="angle_step", path=out, start=30.0, stop_value=5.0, frames=6)
    assert dialog.result == "cancelled"
    assert not out.exists() and not list(tmp_path.glob("*.gif*"))
    assert "no file" in dialog.message.text()
    assert dialog.export_button.isEnabled()


@pytest.mark.parametrize(
    ("values", "words"),
    [
        ({"param": "subdivisions", "start": 0, "stop_value": 4, "frames": 3}, "subdivisions"),
        ({"path": "anim.avi"}, ".gif or .mp4"),
        ({"path": "/no/such/folder/a.gif"}, "no such folder"),
        ({"path": ""}, "output file"),
    ],
)
def test_bad_inputs_are_shown_in_the_dialog(dialog, qtbot, tmp_path, values, words):
    values.setdefault("path", tmp_path / "x.gif")
    assert not run(qtbot, dialog, **values)
    assert words in dialog.message.text()
    assert "color" in dialog.message.styleSheet()
    assert not dialog.running and not list(tmp_path.glob("*.gif"))


def test_dialog_screenshot_is_not_blank(dialog, tmp_path):
    path = tmp_path / "dialog.png"
    assert dialog.grab().save(str(path))
    image = iio.imread(path)
    assert len(np.unique(image[..., :3].reshape(-1, 3), axis=0)) > 10


def test_opened_from_the_file_menu_with_the_window_parameters(qtbot, tmp_path):
    win = MainWindow(COARSE, scripted=True)
    qtbot.addWidget(win)
    win.show()
    qtbot.waitExposed(win)
    win.controller.flush()
    file_menu = win.menuBar().actions()[0].menu()
    assert win.teaching_windows.act_sweep in file_menu.actions()
    win.teaching_windows.act_sweep.trigger()
    d = win.teaching_windows.sweep
    assert d.params == COARSE and d.isVisible()
    d.size.setCurrentIndex(d.size.findText("640 × 480"))
    out = tmp_path / "from-window.gif"
    assert run(qtbot, d, param="angle_step", path=out, start=20.0, stop_value=15.0, frames=2)
    assert iio.imread(out, index=None).shape[0] == 2
    assert "Wrote 2 frames" in win.statusBar().currentMessage()
    win.close()


def test_export_uses_the_parameters_of_the_moment(qtbot, tmp_path):
    """Issue 9 #7: parameters changed while the dialog is open are the ones exported."""
    current = {"params": COARSE}
    d = SweepDialog(lambda: current["params"], start_dir=str(tmp_path))
    qtbot.addWidget(d)
    d.show()
    qtbot.waitExposed(d)
    d.size.setCurrentIndex(d.size.findText("640 × 480"))
    current["params"] = COARSE.replace(structure="patch", patch_size=4.0)  # the window moved on
    out = tmp_path / "now.gif"
    assert run(qtbot, d, param="subdivisions", path=out, start=1, stop_value=2, frames=2)
    assert d.result == 2
    assert d.sweep_kwargs()["base"] == current["params"]
    assert d.params.structure == "patch"
    d.close()


def test_default_output_is_absolute_and_not_the_working_directory(qtbot, tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)
    d = SweepDialog(COARSE)
    qtbot.addWidget(d)
    from pathlib import Path

    shown = Path(d.path.text())
    assert shown.is_absolute() and shown.parent == Path.home().absolute()
    folder = tmp_path / "exports"
    folder.mkdir()
    d2 = SweepDialog(COARSE, start_dir=str(folder))
    qtbot.addWidget(d2)
    d2.path.setText("relative.gif")
    assert d2.sweep_kwargs()["path"] == folder / "relative.gif"  # not tmp_path / relative.gif


def test_too_many_frames_for_the_size_is_refused_in_the_dialog(dialog, qtbot, tmp_path):
    dialog.size.setCurrentIndex(dialog.size.findText("1280 × 720 (16:9)"))
    assert not run(
        qtbot,
        dialog,
        param="angle_step",
        path=tmp_path / "big.gif",
        start=20.0,
        stop_value=1.0,
        frames=900,
    )
    assert "at most 582 frames" in dialog.message.text()
    assert not list(tmp_path.glob("*.gif*"))
