"""``barymesh reflectarray``: the library, the design and its files, from the command line.

The design printed and written is the API's (:func:`barymesh.reflectarray.design` on the
library that ``barymesh library``'s options describe), element for element; bad usage is
one line and exit 2.
"""

from __future__ import annotations

import re

import numpy as np
import pytest

from barymesh.app import cli
from barymesh.cell import cell_from_dict, load_cell, save_cell
from barymesh.mom import parse_stack, reflection_library
from barymesh.reflectarray import design

CELL = {
    "format": "barymesh-cell",
    "version": 1,
    "lattice": {"rectangular": [15.0, 15.0]},
    "elements": [
        {"structure": "patch", "patch_size": 8.0, "subdivisions": 6, "position": [-6.0, -6.0]}
    ],
}
LIBRARY = [
    "--parameter", "elements[0].patch_size", "--values", "6:11:6", "--freq", "10GHz",
    "--stack", "1.575mm eps=2.2; ground",
]  # fmt: skip
DESIGN = ["--aperture", "15x15", "--feed", "0,0,150", "--beam", "20,0"]


@pytest.fixture(scope="module")
def cell_file(tmp_path_factory):
    path = tmp_path_factory.mktemp("cells") / "patch.cell.json"
    save_cell(cell_from_dict(CELL), path)
    return str(path)


def run(capsys, *args):
    code = cli.main(["reflectarray", *map(str, args)])
    out, err = capsys.readouterr()
    return code, out, err


def test_the_written_array_is_the_apis_design(cell_file, capsys, tmp_path):
    out_file = tmp_path / "array.cell.json"
    code, out, err = run(
        capsys, "--cell", cell_file, *LIBRARY, *DESIGN, "--bits", "2", "-o", out_file
    )
    assert code == 0, err
    assert re.search(r"covers \d+° of 360° at 10 GHz", out)
    assert "2-bit quantisation loss" in out and "wrote" in out and "(225 elements)" in out
    written = load_cell(out_file)
    assert len(written.elements) == 225
    lib = reflection_library(
        cell_from_dict(CELL),
        "elements[0].patch_size",
        np.linspace(6.0, 11.0, 6),
        10e9,
        incidence={"theta": 0.0, "phi": 0.0, "pol": "TM"},
        stack=parse_stack("1.575mm eps=2.2; ground"),
    )
    expected = design(lib, (15, 15), (0, 0, 150.0), (20.0, 0.0), 10e9, bits=2)
    sizes = sorted(e.params.patch_size for e in written.elements)
    np.testing.assert_allclose(sizes, sorted(expected.parameter), rtol=1e-12)
    theta = float(re.search(r"main beam: theta=([\d.]+)", out).group(1))
    assert theta == pytest.approx(expected.beam_direction[0], abs=0.01)


def test_an_outline_is_written(cell_file, capsys, tmp_path):
    out_file = tmp_path / "array.dxf"
    code, out, err = run(capsys, "--cell", cell_file, *LIBRARY, *DESIGN, "-o", out_file)
    assert code == 0, err
    assert out_file.read_text().count("LWPOLYLINE") >= 225  # one outline per patch at least


@pytest.mark.parametrize(
    "change, message",
    [
        ({"--aperture": "15by15"}, "--aperture '15by15' is invalid"),
        ({"--feed": "0,0"}, "expected X,Y,Z"),
        ({"--beam": "20,zero"}, "expected THETA,PHI"),
        ({"-o": "array.stl"}, "expected .cell.json, .dxf, .gds"),
        ({"--freq": "9GHz:11GHz:3"}, "choose one with --design-freq"),
        ({"--design-freq": "12GHz"}, "is not one of --freq's frequencies"),
    ],
)
def test_bad_usage_is_one_line(cell_file, capsys, tmp_path, change, message):
    args = dict(zip(LIBRARY[::2], LIBRARY[1::2], strict=True))
    args.update(zip(DESIGN[::2], DESIGN[1::2], strict=True))
    args.update(change)
    if "-o" in args:
        args["-o"] = str(tmp_path / args["-o"])
    flat = [item for pair in args.items() for item in pair]
    code, _, err = run(capsys, "--cell", cell_file, *flat)
    assert code == 2, err
    assert message in err and len(err.strip().splitlines()) == 1
