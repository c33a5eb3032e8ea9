"""Cell files (*.cell.json): round trips, presets, and errors naming the place in the document."""

import json

import numpy as np
import pytest

from core import MeshParams
from core.cell import Element, Lattice, PixelGrid, UnitCell, build_cell
from core.cell.files import (
    CellFileError,
    cell_from_dict,
    cell_preset_names,
    cell_to_dict,
    load_cell,
    load_cell_preset,
    save_cell,
)


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


def test_lattice_shorthands():
    base = cell_to_dict(load_cell_preset("hexagonal-rings"))
    assert base["lattice"] == {"hexagonal": 12.0}
    base["lattice"] = {"rectangular": 7.0}
    assert cell_from_dict(base).lattice == Lattice.rectangular(7.0)
    base["lattice"] = {"rectangular": [7.0, 3.0]}
    assert cell_from_dict(base).lattice == Lattice((7.0, 0.0), (0.0, 3.0))


def _preset_doc():
    return cell_to_dict(load_cell_preset("split-ring-pair"))


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
