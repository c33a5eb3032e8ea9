"""Sizing from frequency in the window (issue 12): typed as a user types, under Xvfb.

The window opens on the conftest's coarse double ring: 48 separate 1 mm square patches at
n = 2. A patch split along its diagonal has its longest edge √2 / n, so a frequency asks
for the smallest n with √2 / n ≤ λ / cells (closed forms, not the code that displays them).
"""

import math
import os
from pathlib import Path

import pytest

pytest.importorskip("pyvistaqt")

from app_user import patch_counts, settle, shown_counts, type_into  # noqa: E402
from PySide6.QtCore import Qt  # noqa: E402
from PySide6.QtTest import QTest  # noqa: E402
from PySide6.QtWidgets import QApplication  # noqa: E402
from test_app_window import COARSE, COARSE_PATCHES  # noqa: E402

from barymesh import MeshParams, build_mesh  # noqa: E402

#: λ (mm) at 100 GHz in vacuum, c0 = 299,792,458 m/s.
LAMBDA_100GHZ = 2.99792458


def smallest_n(target):
    """The smallest n with √2 / n ≤ target (the 1 mm patch's diagonal cut n times)."""
    return math.ceil(math.sqrt(2) / target)


def save_shot(window, name):
    folder = os.environ.get("BARYMESH_TEST_SHOTS")
    if folder:
        for _ in range(3):
            QApplication.processEvents()
        window.grab().save(str(Path(folder) / f"{name}.png"))


def test_typing_a_frequency_meshes_the_smallest_n_and_shows_edge_per_lambda(window, qtbot):
    rows, stats = window.controls.rows, window.stats
    assert stats.text("max_edge_wavelengths") == "–" and stats.text("lambda_10_rule") == "–"
    assert rows["frequency"].field.text() == "" and rows["subdivisions"].field.isEnabled()
    type_into(rows["frequency"].field, "100")  # GHz: λ/10 = 0.2998 mm
    settle(window, qtbot)
    n = smallest_n(LAMBDA_100GHZ / 10)
    assert n == 5
    assert window.model.params.frequency == 100e9
    assert shown_counts(window) == patch_counts(COARSE_PATCHES, n)
    assert window.model.result.mesh.params.subdivisions == n
    assert stats.text("subdivisions_chosen") == "5"
    assert stats.text("max_edge_wavelengths") == f"{math.sqrt(2) / n / LAMBDA_100GHZ:.4f} λ"
    assert stats.text("max_edge_wavelengths") == "0.0943 λ"
    assert stats.text("lambda_10_rule") == "yes"
    assert stats.text("wavelength") == "2.998 mm"
    # the subdivisions field is the mesher's now: greyed, with the n it chose under it
    assert not rows["subdivisions"].field.isEnabled()
    assert rows["subdivisions"].note.isVisible() and "n = 5" in rows["subdivisions"].note.text()
    save_shot(window, "sizing_100GHz")

    # λ/20 in the Advanced group: n = ceil(√2 / 0.1499) = 10
    type_into(rows["cells_per_wavelength"].field, "20")
    settle(window, qtbot)
    assert shown_counts(window) == patch_counts(COARSE_PATCHES, smallest_n(LAMBDA_100GHZ / 20))
    assert stats.text("subdivisions_chosen") == "10"
    # λ/5: n = 3, whose edges (0.157 λ) break the λ/10 rule, and the panel says so
    type_into(rows["cells_per_wavelength"].field, "5")
    settle(window, qtbot)
    assert shown_counts(window) == patch_counts(COARSE_PATCHES, 3)
    assert stats.text("lambda_10_rule") == "no"
    assert stats.text("max_edge_wavelengths") == f"{math.sqrt(2) / 3 / LAMBDA_100GHZ:.4f} λ"

    # empty: off, back to the subdivisions typed before (n = 2)
    type_into(rows["frequency"].field, "")
    settle(window, qtbot)
    assert window.model.params.frequency is None
    assert shown_counts(window) == patch_counts(COARSE_PATCHES, 2)
    assert stats.text("max_edge_wavelengths") == "–" and stats.text("subdivisions_chosen") == "–"
    assert rows["subdivisions"].field.isEnabled()


@pytest.mark.parametrize("text", ["-3", "0", "abc", "1e400"])
def test_an_invalid_frequency_is_refused_under_the_field_and_the_mesh_kept(window, qtbot, text):
    rows = window.controls.rows
    type_into(rows["frequency"].field, "100")
    settle(window, qtbot)
    shown = window.model.result
    type_into(rows["frequency"].field, text)
    settle(window, qtbot)
    row = rows["frequency"]
    value = {"-3": -3e9, "0": 0.0, "abc": "abc", "1e400": math.inf}[text]
    with pytest.raises(ValueError) as refusal:
        MeshParams(**{**COARSE.to_dict(), "frequency": value})
    assert row.field.text() == text  # kept as typed
    assert row.error.isVisible() and row.error.text() == str(refusal.value)
    assert row.error.text().startswith("frequency=")
    assert window.model.params.frequency == 100e9 and window.model.result is shown
    assert shown_counts(window) == patch_counts(COARSE_PATCHES, 5)
    save_shot(window, f"sizing_refused_{text}")
    QTest.keyClick(row.field, Qt.Key.Key_Escape)
    assert row.field.text() == "100" and not row.error.isVisible()


def test_a_frequency_beyond_the_budget_is_refused_with_the_triangles_needed(window, qtbot):
    rows = window.controls.rows
    type_into(rows["max_triangles"].field, "5000")
    settle(window, qtbot)
    shown = window.model.result
    type_into(rows["frequency"].field, "300")  # λ/10 = 0.0999 mm: n = 15, 48 × 450 = 21,600
    settle(window, qtbot)
    with pytest.raises(ValueError) as refusal:
        build_mesh(COARSE.replace(max_triangles=5000, frequency=300e9))
    message = str(refusal.value)
    assert "21,600 triangles" in message
    row = rows["frequency"]
    assert row.error.isVisible() and row.error.text() == message
    assert window.model.params.frequency is None
    assert shown_counts(window) == patch_counts(COARSE_PATCHES, 2)
    assert window.model.result is shown


def test_the_frequency_is_remembered_with_the_parameters(qtbot):
    from barymesh.app.window import MainWindow

    win = MainWindow(COARSE.replace(frequency=24e9, cells_per_wavelength=12.0))
    qtbot.addWidget(win)
    win.close()
    again = MainWindow()
    qtbot.addWidget(again)
    assert again.model.params.frequency == 24e9
    assert again.model.params.cells_per_wavelength == 12.0
    assert again.controls.rows["frequency"].field.text() == "24"
    again.close()
