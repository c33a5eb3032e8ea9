"""The window's file operations: open, export, parameter files, presets; and keyboard focus."""

import json

import pytest

pytest.importorskip("pyvistaqt")

from PySide6.QtCore import Qt  # noqa: E402
from PySide6.QtTest import QTest  # noqa: E402

from core import MeshParams, build_mesh  # noqa: E402
from core.io import read_mesh, write_mesh  # noqa: E402
from tests.app_user import (  # noqa: E402
    answer_file_dialogs,
    export_through_dialog,
    patch_counts,
)
from tests.test_app_window import COARSE, COARSE_PATCHES, assert_counts  # noqa: E402


@pytest.fixture
def file_dialog(monkeypatch):
    return answer_file_dialogs(monkeypatch)


def test_open_mesh_file_shows_its_statistics(window, tmp_path, file_dialog):
    other = build_mesh(MeshParams(structure="patch", subdivisions=3))
    path = tmp_path / "other.msh"
    write_mesh(other, path)
    file_dialog(path)
    window.act_open.trigger()
    window.controller.flush()
    assert window.model.file_source == str(path)
    assert_counts(window, patch_counts(1, 3))  # 16 vertices, 18 triangles, 21 interior edges
    assert window.scene.datasets["faces"].n_cells == 18


def test_damaged_mesh_file_keeps_the_last_mesh(window, tmp_path, file_dialog):
    bad = tmp_path / "bad.msh"
    bad.write_text("$MeshFormat\n2.2 0 8\nthis is not gmsh\n")
    file_dialog(bad)
    window.act_open.trigger()
    assert "bad.msh" in window.statusBar().currentMessage()
    assert window.model.file_source is None
    assert_counts(window, patch_counts(COARSE_PATCHES, 2))


@pytest.mark.parametrize("suffix", [".msh", ".vtu", ".stl", ".mat", ".npz"])
def test_export_mesh_writes_the_current_mesh(window, tmp_path, suffix, file_dialog):
    path = tmp_path / f"out{suffix}"
    file_dialog(path)
    export_through_dialog(window)
    assert path.exists()
    if suffix != ".npz":
        assert read_mesh(path).n_triangles == 384  # 48 patches x 2 x 2²


def test_export_without_a_suffix_takes_the_chosen_format(window, tmp_path, file_dialog):
    file_dialog(tmp_path / "plain", "VTK XML polydata (*.vtp)")
    export_through_dialog(window)
    written = list(tmp_path.iterdir())
    assert [p.name for p in written] == ["plain.vtp"]
    assert read_mesh(written[0]).n_triangles == 384


def test_export_to_a_missing_folder_says_so_and_writes_nothing(window, tmp_path, file_dialog):
    path = tmp_path / "missing" / "out.msh"
    file_dialog(path)
    export_through_dialog(window)
    assert "out.msh" in window.statusBar().currentMessage()
    assert not path.parent.exists()


def test_parameter_file_round_trip(window, tmp_path, file_dialog):
    path = tmp_path / "params"  # the dialog adds .json
    file_dialog(path)
    window.act_save.trigger()
    saved = json.loads(path.with_suffix(".json").read_text())
    assert saved["angle_step"] == COARSE.angle_step and saved["subdivisions"] == 2
    other = tmp_path / "other.json"
    other.write_text(json.dumps({"structure": "patch", "patch_size": 10.0}))
    file_dialog(other)
    window.act_load.trigger()
    window.controller.flush()
    assert window.model.params == MeshParams(structure="patch", patch_size=10.0)
    assert_counts(window, patch_counts(1, 4))  # the paper's 32 triangles of Fig. 10
    file_dialog(path.with_suffix(".json"))
    window.act_load.trigger()
    window.controller.flush()
    assert window.model.params == COARSE


def test_bad_parameter_file_is_refused_with_its_key(window, tmp_path, file_dialog):
    path = tmp_path / "bad.json"
    path.write_text(json.dumps({"radius": 3}))
    file_dialog(path)
    window.act_load.trigger()
    assert "radius" in window.statusBar().currentMessage()
    assert window.model.params == COARSE


def test_a_cancelled_dialog_changes_nothing(window, tmp_path, file_dialog):
    for action in (window.act_open, window.act_load, window.act_save):
        action.trigger()  # the dialog returns no path
    window.act_export.trigger()
    QTest.keyClick(window.export_dialog, Qt.Key.Key_Escape)  # Esc cancels the export dialog
    assert not window.export_dialog.isVisible()
    assert window.model.params == COARSE and window.model.file_source is None
    assert list(tmp_path.iterdir()) == []


def test_presets_menu_loads_each_preset(window):
    menu = next(a.menu() for a in window.menuBar().actions() if "Presets" in a.text())
    names = [a.text().replace("&", "") for a in menu.actions() if a.text()]
    assert any(name.startswith("paper-fig10") for name in names)
    next(a for a in menu.actions() if a.text() == "paper-fig12d").trigger()
    window.controller.flush()
    # Fig. 12(d): 1 mm patches every 20 degrees on both rings, n = 4 (the paper's 32 each)
    assert_counts(window, patch_counts(2 * 18, 4))


def test_tab_order_reaches_every_control_top_to_bottom(window):
    """Tab walks the focus chain: each slider, then its field, in the panel's order.

    Checked on Qt's focus chain itself (without a window manager Xvfb gives no keyboard
    focus to a window, so real Tab presses would not be delivered reliably).
    """
    rows = list(window.controls.rows.values())
    tabbable = []
    w = rows[0].slider
    for _ in range(500):
        if w.focusPolicy() & Qt.FocusPolicy.TabFocus and w.isEnabled():
            tabbable.append(w)
        w = w.nextInFocusChain()
        if w is rows[0].slider:
            break
    order = [tabbable.index(x) for r in rows if r.field.isEnabled()
             for x in (r.slider, r.field) if x is not None]
    assert order == sorted(order)
    for r in rows:
        for w in (r.slider, r.field):
            assert w is None or (w in tabbable) == w.isEnabled()
