"""The window's Qt-free state: undo/redo, refused values, typed numbers, slider mapping."""

import math

import pytest

from barymesh import MeshParams
from barymesh.app.model import (
    ADVANCED_SPECS,
    PARAM_SPECS,
    SPECS,
    AppModel,
    MeshResult,
    carried_subdivisions,
    compute,
    format_bytes,
    format_value,
    mom_matrix_bytes,
    read_number,
    read_points,
    stats_texts,
)
from barymesh.presets import load_preset, preset_names


def core_message(**kwargs) -> str:
    with pytest.raises(ValueError) as refusal:
        MeshParams(**kwargs)
    return str(refusal.value)


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
    assert errors[-1] == model.errors["outer_radius"]
    assert errors[-1].message == core_message(outer_radius=2.0)
    # fixing the other side of the combination takes both
    assert model.set_value("inner_radius", 1.0)
    assert (model.params.inner_radius, model.params.outer_radius) == (1.0, 2.0)
    assert model.error is None and not model.refused


def test_other_changes_are_taken_while_one_value_is_refused():
    """Issue 9 item 4: the refusal stays on its own control; other values still apply."""
    model = AppModel(MeshParams(angle_step=15.0, subdivisions=2))
    assert not model.set_value("outer_radius", 3.0)
    assert model.set_value("subdivisions", 3)
    assert model.params.subdivisions == 3 and model.params.outer_radius == 9.0
    assert list(model.errors) == ["outer_radius"]
    assert model.errors["outer_radius"].message == core_message(
        angle_step=15.0, subdivisions=3, outer_radius=3.0
    )
    assert model.draft["outer_radius"] == 3.0
    model.revert("outer_radius")  # Esc
    assert model.draft["outer_radius"] == 9.0 and model.error is None


def test_a_refused_value_that_fits_after_another_change_is_taken():
    model = AppModel()
    assert not model.set_value("subdivisions", 65)
    assert not model.set_value("outer_radius", 3.0)
    assert model.set_value("inner_radius", 1.0)  # 3 now fits outside 1; 65 still does not
    assert (model.params.inner_radius, model.params.outer_radius) == (1.0, 3.0)
    assert list(model.errors) == ["subdivisions"] and model.refused == {"subdivisions": 65}
    assert model.errors["subdivisions"].message == core_message(subdivisions=65)


def test_a_failed_build_is_not_committed():
    """Issue 9 item 3: params go back to the mesh on screen; the failed value is marked."""
    model = AppModel(MeshParams(subdivisions=1))
    assert model.set_result(compute(model.params, model.generation))
    assert model.set_value("tolerance", 0.0562)
    result = compute(model.params, model.generation)
    assert result.error is not None and "tolerance" in result.error
    assert not model.set_result(result)
    assert model.params == MeshParams(subdivisions=1) and not model.can_undo
    assert model.refused == {"tolerance": 0.0562}
    assert model.errors["tolerance"].message == result.error.removeprefix("meshing failed: ")


def test_stale_results_are_dropped():
    model = AppModel(MeshParams(structure="patch"))
    old = compute(model.params, model.generation)
    model.set_value("subdivisions", 2)
    assert not model.set_result(old)
    assert model.set_result(compute(model.params, model.generation))
    assert model.result.stats["triangles"] == 8


def test_file_source_and_return_to_parameters():
    model = AppModel(MeshParams(structure="patch"))
    assert model.set_result(compute(model.params, model.generation)) and model.file_source is None
    other = compute(MeshParams(structure="patch", subdivisions=3)).mesh
    assert model.set_result(model.show_imported(other, "/data/other.msh"))
    assert model.file_source == "/data/other.msh"
    built = []
    model.params_changed.connect(built.append)
    model.return_to_parameters()
    assert built == [model.params]
    assert model.set_result(compute(model.params, model.generation))
    assert model.file_source is None and isinstance(model.result, MeshResult)


@pytest.mark.parametrize(
    ("text", "value"),
    [
        ("4.5", 4.5),
        ("-3", -3.0),
        ("1e-3", 0.001),
        (" 400 ", 400.0),
        ("0.0562", 0.0562),
        ("4.5 mm", 4.5),
        ("1e400", math.inf),
    ],
)
def test_typed_numbers_are_read_exactly(text, value):
    assert read_number(text, SPECS["inner_radius"]).value == value


@pytest.mark.parametrize("text", ["4,5", "1,000", "abc", "4.5.1", "nan", "0x10", "1_000"])
def test_text_that_is_not_a_plain_number_goes_to_the_core_as_typed(text):
    reading = read_number(text, SPECS["inner_radius"])
    assert reading.value == text
    model = AppModel()
    assert not model.set_text("inner_radius", text)
    assert model.errors["inner_radius"].message == core_message(inner_radius=text)


def test_the_locale_decimal_separator_is_read_and_said():
    reading = read_number("4,5", SPECS["inner_radius"], decimal_point=",")
    assert reading.value == 4.5 and "','" in reading.note and "4.5" in reading.note
    dot = read_number("4.5", SPECS["inner_radius"], decimal_point=",")
    assert dot.value == 4.5 and "a dot is always" in dot.note
    assert read_number("4.5", SPECS["inner_radius"]).note is None  # nothing to say
    model = AppModel()
    assert model.set_text("inner_radius", "4,5", decimal_point=",")
    assert model.params.inner_radius == 4.5 and "4.5" in model.notes["inner_radius"]


def test_integers_are_not_truncated_and_optionals_take_empty():
    sub = SPECS["subdivisions"]
    assert read_number("65", sub).value == 65 and read_number("3.0", sub).value == 3
    assert read_number("3.5", sub).value == 3.5  # the core refuses it, naming 3.5
    model = AppModel()
    for text in ("65", "-1", "3.5"):
        assert not model.set_text("subdivisions", text)
        assert model.errors["subdivisions"].message == core_message(
            subdivisions=read_number(text, sub).value
        )
    assert read_number("", SPECS["tolerance"]).value is None
    assert read_number("auto", SPECS["tolerance"]).value is None
    assert read_number("", SPECS["inner_radius"]).value == ""


def test_points_are_read_as_pairs():
    assert read_points("-500, -500", 1).value == (-500.0, -500.0)
    assert read_points("0 0; 4 0; 0 3", 3).value == ((0.0, 0.0), (4.0, 0.0), (0.0, 3.0))
    assert read_points("0,5 1", 1, decimal_point=",").value == (0.5, 1.0)
    assert read_points("1, 2, 3", 1).value == "1, 2, 3"
    assert read_points("", 3).value is None
    model = AppModel(MeshParams(structure="triangle"))
    assert model.set_text("triangle_vertices", "0 0; 4 0; 0 3")
    assert model.params.triangle_vertices == ((0.0, 0.0), (4.0, 0.0), (0.0, 3.0))
    assert not model.set_text("triangle_vertices", "0 0; 1 1; 2 2")  # collinear
    assert "collinear" in model.errors["triangle_vertices"].message


def test_format_value_round_trips():
    for value in (4.5, 0.0562, 1e-9, 1000.0, 1 / 3, -180.0, 7, None):
        text = format_value(value)
        back = read_number(text, SPECS["tolerance"]).value
        assert back == value, (value, text)


def test_scheme_change_carries_subdivisions_over_and_says_so():
    """Issue 9 item 5: n = 16 uniform (256 per primary) becomes 3 levels (216)."""
    assert carried_subdivisions(16, "uniform", "barycentric") == 3
    assert carried_subdivisions(4, "uniform", "barycentric") == 2  # 16 -> 36, nearer than 6
    assert carried_subdivisions(64, "uniform", "barycentric") == 5  # 4096 -> 7776
    assert carried_subdivisions(3, "barycentric", "uniform") == 15  # 216 -> 225
    assert carried_subdivisions(6, "barycentric", "uniform") == 64  # 46656 -> 4096 (the top)
    model = AppModel(MeshParams(angle_step=15.0, subdivisions=16))
    assert model.set_value("scheme", "barycentric")
    assert (model.params.scheme, model.params.subdivisions) == ("barycentric", 3)
    assert (
        "16" in model.notes["subdivisions"]
        and "3 barycentric levels" in model.notes["subdivisions"]
    )
    model.undo()
    assert (model.params.scheme, model.params.subdivisions) == ("uniform", 16)


@pytest.mark.parametrize(
    "spec", [s for s in PARAM_SPECS + ADVANCED_SPECS if s.slider], ids=lambda s: s.name
)
def test_slider_positions_round_trip(spec):
    for pos in range(spec.slider_max + 1):
        assert spec.to_slider(spec.from_slider(pos)) == pos
    assert spec.from_slider(spec.slider_max) == spec.maximum


@pytest.mark.parametrize(
    "spec", [s for s in PARAM_SPECS + ADVANCED_SPECS if s.windowed], ids=lambda s: s.name
)
@pytest.mark.parametrize("value", [0.01, 0.037, 1.0, 4.0, 10.0, 360.0, 1000.0, 10_000.0])
def test_a_windowed_slider_spans_a_decade_each_side_of_its_value(spec, value):
    """Issue section 3 item 5: not 0.01 mm to 10 m on a few dozen pixels."""
    if not spec.holds(value):
        return
    w = spec.around(value)
    # two decades at 48 positions each, within the whole range, the value on it
    assert w.slider_max == w._offset + 2 * spec.per_decade
    assert math.isclose(w.maximum / w.minimum, 100.0)
    assert spec.minimum * (1 - 1e-12) <= w.minimum and w.maximum <= spec.maximum * (1 + 1e-12)
    assert w.holds(value)
    if spec.minimum * 10 <= value <= spec.maximum / 10:  # away from the ends: centred
        assert math.isclose(w.minimum, value / 10) and math.isclose(w.maximum, value * 10)
        assert w.to_slider(value) == w._offset + spec.per_decade
        assert w.from_slider(w.to_slider(value)) == float(f"{value:.3g}")
    for pos in range(w.slider_max + 1):  # every position a value of the window, in order
        assert w.to_slider(w.from_slider(pos)) == pos


def test_around_leaves_other_sliders_alone():
    for name in ("subdivisions", "tolerance", "gap_angle"):
        assert SPECS[name].around(1.0) is SPECS[name]
    assert SPECS["patch_size"].around(None) is SPECS["patch_size"]
    assert SPECS["patch_size"].around(-1.0) is SPECS["patch_size"]


@pytest.mark.parametrize("name", preset_names())
def test_every_preset_value_fits_its_control(name):
    """Issue 9 item 6: slider ranges hold every preset's values."""
    params = load_preset(name)[0]
    for spec in PARAM_SPECS + ADVANCED_SPECS:
        value = getattr(params, spec.name)
        if value is None or not spec.slider:
            continue
        assert spec.minimum <= value <= spec.maximum, (spec.name, value)
        nearest = spec.from_slider(spec.to_slider(value))
        if spec.log_scale:
            assert abs(math.log10(nearest / value)) <= 0.5 / spec.per_decade + 1e-3
        else:
            assert abs(nearest - value) <= spec.step / 2


def test_stats_texts_of_separate_patches():
    # 36 patches on each ring, none sharing a point: 72 x (2 x 2²) triangles, 72 x 8 interior
    texts = stats_texts(compute(MeshParams(angle_step=10.0, subdivisions=2)))
    assert texts["triangles"] == "576" and texts["interior_edges"] == "576"
    assert texts["vertices"] == f"{72 * 9:,}" and texts["boundary_edges"] == "576"
    assert texts["mom_memory"] == format_bytes(16 * 576**2) == "5.1 MiB"


def test_mom_memory():
    assert mom_matrix_bytes(1000) == 16_000_000
    assert format_bytes(16 * 28_800**2) == "12.4 GiB"
    assert SPECS["tolerance"].from_slider(0) is None
    assert SPECS["tolerance"].from_slider(32) == 0.0562  # the position 32


def test_a_whole_new_parameter_set_is_announced_apart_from_edits():
    """``params_replaced`` comes with set_params (a preset, a file, Reset), after
    ``params_changed``, and not with one value's edit: the sliders are centred on it."""
    model = AppModel()
    order = []
    model.params_changed.connect(lambda p: order.append(("changed", p.angle_step)))
    model.params_replaced.connect(lambda p: order.append(("replaced", p.angle_step)))
    assert model.set_value("angle_step", 3.0)
    assert order == [("changed", 3.0)]
    model.set_params(load_preset("paper-fig12d")[0])
    assert order[1:] == [("changed", 20.0), ("replaced", 20.0)]
    model.reset()
    assert order[3:] == [("changed", 1.0), ("replaced", 1.0)]
