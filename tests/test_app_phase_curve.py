"""The Reflection phase tab's numbers without Qt (barymesh.app.panels.phase_curve): the
cell's parameter paths, the window's cell with a value set (hidden elements kept), the
two passes, and their joined library against one call of reflection_library."""

import numpy as np
import pytest

from barymesh import MeshParams
from barymesh.app.model.cell_document import CellState
from barymesh.app.panels.phase_curve import (
    PhaseInputs,
    cell_with,
    check_values,
    curve_key,
    default_range,
    parameter_paths,
    passes,
    solve_curve,
    state_with,
    value_of,
)
from barymesh.cell import Element, Lattice, UnitCell, load_cell_preset
from barymesh.mom import parse_stack, reflection_library

PATCH = MeshParams(structure="patch", patch_size=6.0, subdivisions=3)


def two_patches() -> UnitCell:
    return UnitCell(
        Lattice.rectangular(20.0),
        (
            Element(PATCH, position=(-8.0, -3.0), name="left"),
            Element(PATCH.replace(patch_size=4.0), position=(2.0, -2.0), name="right"),
        ),
    )


def test_parameter_paths_are_the_structures_sizes_then_placement_then_lattice():
    paths = dict(parameter_paths(load_cell_preset("split-ring-pair")))
    assert list(paths)[:7] == [
        "elements[0].inner_radius",
        "elements[0].patch_size",
        "elements[0].gap_width",
        "elements[0].gap_angle",
        "elements[0].position[0]",
        "elements[0].position[1]",
        "elements[0].rotation",
    ]
    assert paths["elements[1].rotation"] == 180.0
    assert paths["lattice.rectangular[0]"] == 24.0
    assert not any("subdivisions" in p or "angle_step" in p for p in paths)
    # every path is one the study's setter takes, and reads back what the cell holds
    cell = load_cell_preset("split-ring-pair")
    for path, value in paths.items():
        assert value_of(cell, path) == value
        assert value_of(cell_with(cell, path, value), path) == value
    pixels = dict(parameter_paths(load_cell_preset("coding-16x16")))
    assert pixels == {
        "lattice.rectangular[0]": 8.0,
        "lattice.rectangular[1]": 8.0,
        "pixels.pixel_size": 0.5,
    }


def test_a_value_the_cell_refuses_is_named_in_one_line():
    cell = two_patches()
    with pytest.raises(ValueError, match=r"^elements\[1\]\.patch_size = -2: the cell refuses"):
        check_values(cell, "elements[1].patch_size", (3.0, -2.0))
    with pytest.raises(ValueError, match="the cell has no parameter 'elements\\[5\\].x'"):
        value_of(cell, "elements[5].x")
    assert default_range(cell, "elements[1].patch_size") == (2.0, 6.0)
    assert default_range(cell, "elements[0].rotation") == (0.0, 90.0)


def test_state_with_sets_the_visible_cells_path_in_the_whole_cell():
    # the left patch hidden: the solved cell's elements[0] is the whole cell's elements[1]
    state = CellState(two_patches(), (True, False), 0)
    assert state.visible.elements[0].name == "right"
    new = state_with(state, "elements[0].patch_size", 5.0)
    assert [e.params.patch_size for e in new.cell.elements] == [6.0, 5.0]
    assert new.hidden == (True, False) and new.selected == 0
    wider = state_with(state, "lattice.rectangular[0]", 22.0)
    assert wider.cell.lattice.a1[0] == 22.0
    # the curve's key ignores the parameter, not the others
    key = curve_key(state.visible, "elements[0].patch_size")
    assert curve_key(new.visible, "elements[0].patch_size") == key
    assert curve_key(wider.visible, "elements[0].patch_size") != key


def test_passes_cover_every_value_once_the_ends_first():
    for n in range(1, 30):
        first, rest = passes(n)
        assert sorted(first + rest) == list(range(n))
        assert first[0] == 0 and first[-1] == n - 1
        assert first == tuple(sorted({*range(0, n, 4), n - 1}))


def test_two_passes_joined_are_one_reflection_library_call():
    fine = PATCH.replace(subdivisions=6)
    cell = UnitCell(Lattice.rectangular(10.0), (Element(fine, position=(-3.0, -3.0)),))
    stack = parse_stack("1.575mm eps=2.2; ground")
    values = (4.0, 4.5, 5.0, 5.5, 6.0, 6.5)
    inputs = PhaseInputs("elements[0].patch_size", values, 9e9, 10.0, 30.0, "TE", stack)
    previews, counts = [], []
    got = solve_curve(
        cell,
        inputs,
        previews.append,
        lambda done, total: counts.append((done, total)),
        in_process=False,
    )
    want = reflection_library(
        cell,
        "elements[0].patch_size",
        values,
        9e9,
        incidence={"theta": 10.0, "phi": 30.0, "pol": "TE"},
        stack=stack,
    )
    np.testing.assert_array_equal(got.values, want.values)
    np.testing.assert_allclose(got.reflection, want.reflection, rtol=0, atol=1e-12)
    np.testing.assert_allclose(got.phase_deg, want.phase_deg, atol=1e-9)
    assert (got.polarization, got.reference_plane, got.stack) == ("TE", 0.0, stack)
    (preview,) = previews
    np.testing.assert_array_equal(preview.values, [4.0, 6.0, 6.5])
    assert counts[-1] == (6, 6) and [d for d, _t in counts] == sorted(d for d, _t in counts)
