"""Edge grading in the window: the Grading choice of the Structure group (real Xvfb window)."""

import numpy as np
import pytest

pytest.importorskip("pyvistaqt")

from app_user import choose, patch_counts, settle, shown_counts, type_into  # noqa: E402

from barymesh.grading import edge_nodes  # noqa: E402


def test_the_grading_choice_grades_the_patch_on_screen_and_keeps_its_counts(
    window, qtbot, tmp_path
):
    choose(window.controls.combos["structure"], "patch")
    type_into(window.controls.rows["subdivisions"].field, "8")
    settle(window, qtbot)
    n = window.model.params.subdivisions
    assert n == 8
    uniform = window.model.result.mesh
    assert shown_counts(window) == patch_counts(1, n)
    combo = window.controls.combos["grading"]
    assert combo.isEnabled() and combo.currentData() is False
    choose(combo, True)
    settle(window, qtbot)
    params = window.model.params
    assert params.grading and params.subdivisions == n  # the n on screen, now graded
    graded = window.model.result.mesh
    assert shown_counts(window) == patch_counts(1, n)  # the paper's counts, unchanged
    np.testing.assert_array_equal(graded.triangles, uniform.triangles)
    xs = np.unique(graded.points[:, 0]) - params.origin[0]
    np.testing.assert_allclose(xs, params.patch_size * edge_nodes(n), atol=1e-12)
    shortest = float(window.stats.text("min_edge").split()[0])
    assert shortest == pytest.approx(params.patch_size * edge_nodes(n)[1], rel=1e-3)
    assert shortest < 0.1 * params.patch_size / n  # 8.3 µm against 125 µm uniform
    assert window.grab().save(str(tmp_path / "grading-choice.png"))  # looked at: graded rows
    # the barycentric scheme has no graded form: refused by name, the graded mesh stays
    choose(window.controls.combos["scheme"], "barycentric")
    window.controller.flush()
    assert "grading=True needs scheme='uniform'" in window.model.errors["scheme"].message
    assert window.model.result.mesh is graded
