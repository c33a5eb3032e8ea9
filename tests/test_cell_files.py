"""Cell files (*.cell.json): round trips, presets, and errors naming the place in the document."""

import json

import numpy as np
import pytest
from helpers import assert_clear_message

from barymesh import MeshParams
from barymesh.cell import Element, Lattice, PixelGrid, UnitCell, build_cell, tile
from barymesh.cell.files import (
    CellFileError,
    cell_from_dict,
    cell_preset_names,
    cell_to_dict,
    load_cell,
    load_cell_preset,
    save_cell,
)
from barymesh.params import MAX_BUDGET


def test_presets_are_the_four_classic_cells():
    assert cell_preset_names() == [
        "coding-16x16",
        "double-ring-patch",
        "hexagonal-rings",
        "split-ring-pair",
    ]
    with pytest.raises(ValueError, match="unknown cell preset 'nope'; expected one of coding"):
        load_cell_preset("nope")


@pytest.mark.parametrize("name", cell_preset_names())
def test_presets_round_trip_through_a_file(name, tmp_path):
    cell = load_cell_preset(name)
    path = tmp_path / f"{name}.cell.json"
    save_cell(cell, path)
    again = load_cell(path)
    assert again == cell
    assert cell_to_dict(again) == cell_to_dict(cell)
    assert json.loads(path.read_text())["version"] == 1


def test_general_cell_round_trips(tmp_path):
    mask = np.zeros((3, 5), bool)
    mask[0, :2] = mask[2, 4] = True  # bottom-left and top-right: the file lists the top row first
    cell = UnitCell(
        lattice=Lattice((10.0, 1.0), (-2.0, 9.0)),
        elements=(
            Element(MeshParams(structure="split_ring", gap_angle=30.0), (1.0, -2.0), 12.5, "srr"),
            Element(
                MeshParams(structure="triangle", triangle_vertices=((0, 0), (1, 0), (0, 2))),
                name="tri",
            ),
        ),
        pixels=PixelGrid(mask, 0.25, (3.0, 3.0), subdivisions=2, diagonal="AD"),
        tolerance=1e-7,
        name="mixed",
        description="every field",
    )
    path = tmp_path / "mixed.cell.json"
    save_cell(cell, path)
    data = json.loads(path.read_text())
    assert data["lattice"] == {"a1": [10.0, 1.0], "a2": [-2.0, 9.0]}
    assert data["pixels"]["rows"] == ["00001", "00000", "11000"]
    assert "mode" not in data["elements"][0]  # elements take the cell's mode
    again = load_cell(path)
    assert again == cell
    assert np.array_equal(again.pixels.mask, mask)
    assert build_cell(again).mesh.n_triangles == build_cell(cell).mesh.n_triangles


def test_grading_keys_of_elements_and_pixels():
    doc = {
        "format": "barymesh-cell",
        "version": 1,
        "lattice": {"rectangular": 20},
        "elements": [
            {"name": "graded", "structure": "patch", "patch_size": 3.0, "grading": True},
            {"name": "as given", "structure": "patch", "patch_size": 3.0, "origin": [5, 5]},
        ],
        "pixels": {"rows": ["11"], "pixel_size": 0.5, "origin": [-9, -9], "grading": True},
    }
    cell = cell_from_dict(doc)
    graded, plain = (el.params for el in cell.elements)
    # a graded element without subdivisions takes the accuracy default, n = 16
    assert (graded.grading, graded.subdivisions) == (True, 16)
    assert (plain.grading, plain.subdivisions) == (False, 4)
    assert cell.pixels.grading and cell.pixels.subdivisions == 4
    written = cell_to_dict(cell)
    assert written["pixels"]["grading"] is True
    assert cell_from_dict(written) == cell
    # an ungraded grid's document is as before grading existed: no "grading" key
    assert (
        "grading"
        not in cell_to_dict(cell.replace(pixels=cell.pixels.replaced(grading=False)))["pixels"]
    )


def test_lattice_shorthands():
    base = cell_to_dict(load_cell_preset("hexagonal-rings"))
    assert base["lattice"] == {"hexagonal": 12.0}
    base["lattice"] = {"rectangular": 7.0}
    assert cell_from_dict(base).lattice == Lattice.rectangular(7.0)
    base["lattice"] = {"rectangular": [7.0, 3.0]}
    assert cell_from_dict(base).lattice == Lattice((7.0, 0.0), (0.0, 3.0))


def _preset_doc(name="split-ring-pair"):
    return cell_to_dict(load_cell_preset(name))


def _error(doc, tmp_path):
    path = tmp_path / "bad.cell.json"
    path.write_text(json.dumps(doc))
    with pytest.raises(CellFileError) as info:
        load_cell(path)
    message = str(info.value)
    assert message.startswith(f"{path}: ")
    return message[len(f"{path}: ") :]


@pytest.mark.parametrize(
    ("edit", "where", "what"),
    [
        (lambda d: d["elements"][1].update(inner_radius=-1), "elements[1].inner_radius", "> 0"),
        (
            lambda d: d["elements"][0].update(outer_radius=1.0, structure="double_ring"),
            "elements[0].outer_radius",
            "must be larger than inner_radius",
        ),
        (lambda d: d["elements"][0].update(colour="red"), "elements[0].colour", "unknown key"),
        (
            lambda d: d["elements"][1].update(rotation="left"),
            "elements[1].rotation",
            "not a number",
        ),
        (lambda d: d["elements"][1].update(position=[1]), "elements[1].position", "two numbers"),
        (lambda d: d["elements"][1].update(mode="conforming"), "elements[1].mode", "differs"),
        (lambda d: d["elements"][1].update(name="left ring"), "elements[1].name", "already"),
        (lambda d: d.update(lattice={"hexagonal": -3}), "lattice.hexagonal", "a=-3"),
        (lambda d: d.update(lattice={"square": 3}), "lattice", "expected 'rectangular'"),
        (lambda d: d.update(version=2), "version", "not supported"),
        (lambda d: d.update(mode="sloppy"), "mode", "unknown"),
        (lambda d: d.update(extra=1), "extra", "unknown key"),
        (lambda d: d.update(elements={}), "elements", "expected a list"),
        (lambda d: d.update(pixels={"rows": ["101", "10"]}), "pixels.rows[1]", "3 characters"),
        (lambda d: d.update(pixels={"rows": ["1"], "pixel_size": 0}), "pixels.pixel_size", "> 0"),
        (
            lambda d: d.update(pixels={"rows": ["1"], "subdivisions": 99}),
            "pixels.subdivisions",
            "outside",
        ),
        (lambda d: d.update(elements=[], pixels=None), "document", "no metal"),
        (
            lambda d: d.update(pixels={"rows": ["1"], "grading": "yes"}),
            "pixels.grading",
            "expected true or false",
        ),
        (
            lambda d: d.update(pixels={"rows": ["1"], "grading": True, "scheme": "barycentric"}),
            "pixels.grading",
            "scheme='uniform'",
        ),
        (
            lambda d: d["elements"][0].update(grading=True, scheme="barycentric"),
            "elements[0].grading",
            "scheme='uniform'",
        ),
    ],
)
def test_errors_name_the_path_in_the_document(edit, where, what, tmp_path):
    doc = _preset_doc()
    edit(doc)
    message = _error(doc, tmp_path)
    assert message.startswith(f"{where}: "), message
    assert what in message


def test_unreadable_files(tmp_path):
    with pytest.raises(CellFileError, match="no such cell file"):
        load_cell(tmp_path / "missing.cell.json")
    bad = tmp_path / "bad.cell.json"
    bad.write_text('{"version": 1,\n "lattice": }')
    with pytest.raises(CellFileError, match="invalid JSON at line 2"):
        load_cell(bad)
    bad.write_text("[1, 2]")
    with pytest.raises(CellFileError, match="document: expected a JSON object, got an array$"):
        load_cell(bad)


# -- issue 4: mutated copies of the preset cells (outside fuzz) -----------------------

NESTED = 1.0
for _ in range(900):
    NESTED = [NESTED]


def _refusal(doc):
    with pytest.raises(CellFileError) as err:
        cell_from_dict(doc)
    message = str(err.value)
    assert_clear_message(message)
    return message


def _uniform_patch_doc():
    """The double-ring-patch cell with its centre patch uniform at n = 4 (as before it was
    graded): edges of 0.75 mm."""
    doc = _preset_doc("double-ring-patch")
    doc["elements"][1].update(grading=False, subdivisions=4)
    return doc


def test_a_patch_far_from_the_cell_is_refused_naming_its_position():
    # the double-ring-patch cell with its patch at [1e16, 0] gave 16 triangles that repeat a
    # vertex (float64 spaces numbers near 1e16 by 2 mm; the patch's edges are 0.75 mm)
    doc = _uniform_patch_doc()
    doc["elements"][1]["position"] = [1e16, 0]
    message = _refusal(doc)
    assert message.startswith(
        "cell: elements[1].position: position=(1e+16, 0.0) puts metal 1e+16 mm from the "
        "cell's centre, too far for float64 to resolve its 0.75 mm sub-triangle edges"
    )
    assert message.endswith("keep it within 7.5e+07 mm")  # 1e-8 of the reach: the edge


def test_a_part_too_far_for_the_weld_tolerance_is_refused():
    # at 1e6 mm float64 rounds by ~1e-10 mm per operation: the default tolerance 2e-8 mm
    # (1e-9 of the 20 mm lattice) is below 1e-12 of the coordinates
    doc = _uniform_patch_doc()
    doc["elements"][1]["position"] = [1e6, 0]
    message = _refusal(doc)
    assert "float64 rounds metal 1e+06 mm from the cell's centre by more than the welding " in (
        message
    )
    assert "tolerance 2e-08 mm" in message and len(message) < 300
    doc["tolerance"] = 1e-5  # a tolerance float64 resolves there: the patch is only far away
    cm = build_cell(cell_from_dict(doc))
    assert cm.mesh.n_triangles == 2 * 180 * 32 + 32
    assert any("reaches beyond the cell boundary" in note for note in cm.notes)


@pytest.mark.parametrize("far", [[1e16, 0], [0, -1e12], [1e5, 1e16]])
def test_far_pixels_are_refused_naming_their_origin(far):
    doc = _preset_doc("coding-16x16")
    doc["pixels"]["origin"] = far
    assert _refusal(doc).startswith("cell: pixels.origin: origin=")


@pytest.mark.parametrize(
    ("edit", "where"),
    [
        (lambda d: d["elements"][0].update(inner_radius=NESTED), "elements[0].inner_radius"),
        (lambda d: d["elements"][0].update(position=NESTED), "elements[0].position"),
        (lambda d: d["elements"][0].update(rotation=NESTED), "elements[0].rotation"),
        (lambda d: d["elements"][0].update(name=NESTED), "elements[0].name"),
        (lambda d: d["elements"][0].update(origin=NESTED), "elements[0].origin"),
        (lambda d: d.update(lattice={"rectangular": NESTED}), "lattice.rectangular"),
        (lambda d: d.update(lattice={"hexagonal": NESTED}), "lattice.hexagonal"),
        (lambda d: d.update(lattice={"a1": NESTED, "a2": [0, 1]}), "lattice.a1"),
        (lambda d: d.update(lattice=NESTED), "lattice"),
        (lambda d: d.update(version=NESTED), "version"),
        (lambda d: d.update(mode=NESTED), "mode"),
        (lambda d: d.update(format=NESTED), "format"),
        (lambda d: d.update(tolerance=NESTED), "tolerance"),
        (lambda d: d.update(name=NESTED), "name"),
        (lambda d: d.update(pixels={"rows": ["1"], "pixel_size": NESTED}), "pixels.pixel_size"),
        (lambda d: d.update(pixels={"rows": ["1"], "origin": NESTED}), "pixels.origin"),
        (lambda d: d.update(pixels={"rows": ["1", "1" * 3000]}), "pixels.rows[1]"),
        (lambda d: d["elements"][0].update(structure="s" * 3000), "elements[0].structure"),
    ],
)
def test_a_900_deep_or_huge_value_gives_a_short_message_naming_its_place(edit, where):
    doc = _preset_doc()
    edit(doc)
    message = _refusal(doc)
    assert message.startswith(f"cell: {where}: "), message[:200]
    assert len(message) < 400


WRONG_KINDS = [None, True, "x", {}, [], [1, 2, 3], {"a": 1}, 1e-320, [None, None]]


@pytest.mark.parametrize("value", WRONG_KINDS, ids=repr)
@pytest.mark.parametrize(
    "path",
    [
        "document",
        "lattice",
        "lattice.rectangular",
        "lattice.hexagonal",
        "elements",
        "elements[0]",
        "elements[0].position",
        "elements[0].rotation",
        "elements[0].inner_radius",
        "elements[0].subdivisions",
        "elements[0].name",
        "pixels",
        "pixels.rows",
        "pixels.origin",
        "pixels.pixel_size",
        "mode",
        "version",
        "tolerance",
    ],
)
def test_messages_never_show_python_type_names(path, value):
    doc = _preset_doc()
    doc["pixels"] = {"rows": ["1"], "origin": [-9, -9]}
    if path == "document":
        doc = value
    else:
        target = doc
        keys = path.replace("[0]", ".0").split(".")
        for key in keys[:-1]:
            target = target[int(key)] if key.isdigit() else target[key]
        last = keys[-1]
        target[int(last) if last.isdigit() else last] = value
    try:
        cell = cell_from_dict(doc)
    except CellFileError as exc:
        assert_clear_message(str(exc))
        return
    build_cell(cell)  # a value that happens to be valid (a tiny tolerance) must build


def test_a_malformed_lattice_says_what_it_expected():
    # was "lattice: too many values to unpack (expected 2)"
    doc = _preset_doc()
    doc["lattice"] = {"rectangular": [1, 2, 3]}
    assert _refusal(doc) == (
        "cell: lattice.rectangular: [1, 2, 3] is invalid; expected a "
        "period in mm or two periods [px, py]"
    )
    doc["lattice"] = {"rectangular": [20]}  # one period: a square lattice
    assert cell_from_dict(doc).lattice == Lattice.rectangular(20.0)
    doc["lattice"] = {"a1": [1e300, 0], "a2": [0, 1e300]}
    assert "lattice.a1: a1=(1e+300, 0.0) is 1e+300 mm long; expected a lattice vector" in (
        _refusal(doc)
    )


def _many(doc, count):
    base = doc["elements"][0]
    doc["elements"] = [dict(base, name=f"e{k}", position=[0.05 * k, 0]) for k in range(count)]
    return doc


def test_a_cell_over_the_budget_is_refused_before_any_part_is_built():
    # 400 double rings of 2 x 180 x 32 = 11,520 triangles: 4,608,000, within the default
    # budget of 5,000,000; 500 are 5,760,000, refused (was a MemoryError or minutes)
    cell = cell_from_dict(_many(_preset_doc("double-ring-patch"), 500))
    assert cell.predicted_triangles() == 500 * 11_520
    with pytest.raises(
        ValueError,
        match=r"^the cell's parts would make 5,760,000 triangles, "
        r"above the budget max_triangles=5,000,000",
    ):
        build_cell(cell)
    small = cell_from_dict(_many(_preset_doc("double-ring-patch"), 3))
    with pytest.raises(
        ValueError, match="would make 34,560 triangles, above the budget max_triangles=30,000"
    ):
        build_cell(small, max_triangles=30_000)
    assert build_cell(small, max_triangles=34_560).mesh.n_triangles == 34_560
    with pytest.raises(
        ValueError,
        match=r"^3 x 2 copies of 34,560 triangles would make "
        "207,360 triangles, above the budget max_triangles=200,000",
    ):
        tile(small, 3, 2, max_triangles=200_000)


def test_a_budget_past_what_int32_indices_number_is_refused_naming_it():
    # issue 30's seventh fuzz run: a budget of 10**400 passed every count; no mesh past
    # 715,827,882 triangles (three int32 indices each) can be built
    small = cell_from_dict(_many(_preset_doc("double-ring-patch"), 1))
    with pytest.raises(ValueError, match=r"^max_triangles=1000.* is above 715,827,882"):
        build_cell(small, max_triangles=10**400)
    with pytest.raises(ValueError, match=r"^max_triangles=2147483648 is above 715,827,882"):
        tile(small, 2, 2, max_triangles=2**31)


def test_an_element_with_its_own_huge_budget_is_held_to_the_cell_budget():
    doc = _preset_doc("double-ring-patch")
    doc["elements"][0].update(
        inner_radius=1e3, outer_radius=2e3, angle_step=0.01, max_triangles=MAX_BUDGET
    )
    cell = cell_from_dict(doc)
    assert cell.predicted_triangles() == 2 * 36_000 * 32 + 2 * 16**2  # the graded patch
    with pytest.raises(ValueError, match="would make 2,304,512 triangles"):
        build_cell(cell, max_triangles=1_000_000)


@pytest.mark.parametrize("n", [1.0, 3.0])
def test_a_pixel_grid_s_whole_float_subdivisions_are_its_integer(n):
    # issue 30's third fuzz run: "subdivisions": 10.0 under pixels was kept a float, and the
    # build raised TypeError ('float' object cannot be interpreted as an integer)
    doc = _preset_doc("coding-16x16")
    doc["pixels"]["subdivisions"] = n
    cell = cell_from_dict(doc)
    assert type(cell.pixels.subdivisions) is int and cell.pixels.subdivisions == n
    per_pixel = 2 * int(n) ** 2
    assert build_cell(cell).mesh.n_triangles == int(cell.pixels.mask.sum()) * per_pixel
