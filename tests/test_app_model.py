"""The window's Qt-free state: undo/redo, invalid drafts, slider mapping, statistics text."""

import pytest

from app.model import (
    PARAM_SPECS,
    SPECS,
    AppModel,
    compute,
    format_bytes,
    mom_matrix_bytes,
    stats_texts,
)
from core import MeshParams, build_mesh


def test_undo_redo_restores_parameters():
    model = AppModel(MeshParams(structure="patch"))
    assert model.set_value("subdivisions", 2)
    assert model.set_value("patch_size", 3.0)
    model.undo()
    assert (model.params.subdivisions, model.params.patch_size) == (2, 1.0)
    model.undo()
    assert model.params.subdivisions == 4 and not model.can_undo
    model.redo()
    model.redo()
    assert (model.params.subdivisions, model.params.patch_size) == (2, 3.0)


def test_slider_drag_is_one_undo_step():
    model = AppModel()
    for n in (5, 6, 7):
        model.set_value("subdivisions", n, merge=True)
    model.end_merge()
    model.undo()
    assert model.params.subdivisions == 4


def test_invalid_value_keeps_params_and_names_the_control():
    model = AppModel()
    errors = []
    model.error_changed.connect(errors.append)
    assert not model.set_value("outer_radius", 2.0)
    assert model.params.outer_radius == 9.0
    assert model.draft["outer_radius"] == 2.0
    assert errors[-1].name == "outer_radius" and "outer_radius" in errors[-1].message
    # fixing the other side of the combination makes the draft valid
    assert model.set_value("inner_radius", 1.0)
    assert model.params.outer_radius == 2.0 and model.error is None


def test_stale_results_are_dropped():
    model = AppModel(MeshParams(structure="patch"))
    old = compute(model.params, model.generation)
    model.set_value("subdivisions", 2)
    assert not model.set_result(old)
    assert model.set_result(compute(model.params, model.generation))
    assert model.result.stats["triangles"] == 8


@pytest.mark.parametrize("spec", PARAM_SPECS, ids=lambda s: s.name)
def test_slider_positions_round_trip(spec):
    for pos in (0, 1, spec.slider_max // 2, spec.slider_max):
        assert spec.to_slider(spec.from_slider(pos)) == pos


def test_stats_texts_match_core():
    params = MeshParams(angle_step=10.0, subdivisions=2)
    texts = stats_texts(compute(params))
    stats = build_mesh(params).stats()
    assert texts["triangles"] == f"{stats['triangles']:,}"
    assert texts["interior_edges"] == f"{stats['interior_edges']:,}"
    assert texts["mom_memory"] == format_bytes(16 * stats["interior_edges"] ** 2)


def test_mom_memory():
    assert mom_matrix_bytes(1000) == 16_000_000
    assert format_bytes(16 * 28_800**2) == "12.4 GiB"
    assert SPECS["tolerance"].from_slider(0) is None
