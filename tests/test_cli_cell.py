"""The command line on unit cells and arrays: --cell, --cell-preset, --array, --period,
outlines to DXF and GDSII (read back with ezdxf and gdstk), msh with $Periodic, errors.

Most runs call ``cli.main`` in-process (same code path as the console script, much
faster); one runs the real process to check the error line and exit code end to end.
"""

import json
import math
import os
import subprocess
import sys
from pathlib import Path

import meshio
import numpy as np
import pytest
from helpers import assert_clear_message

from barymesh import MeshParams, build_mesh
from barymesh.app import cli
from barymesh.cell import cell_preset_names
from barymesh.cell.files import CELL_PRESET_DIR
from barymesh.io import read_mesh

try:  # the optional "cell" extra: only the outline writers need it
    import ezdxf
    import gdstk
except ImportError:  # pragma: no cover
    ezdxf = gdstk = None

needs_writers = pytest.mark.skipif(
    ezdxf is None or gdstk is None, reason="ezdxf and gdstk (the cell extra) are not installed"
)
ROOT = Path(__file__).resolve().parents[1]


@pytest.fixture(autouse=True)
def in_tmp(tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)
    return tmp_path


def run(capsys, *args):
    """``barymesh ARGS`` in-process: (exit code, stdout, stderr)."""
    code = cli.main([str(a) for a in args])
    out, err = capsys.readouterr()
    return code, out, err


def stats_of(capsys, *args):
    code, out, err = run(capsys, *args, "--stats-json", "-")
    assert code == 0, err
    return json.loads(out)


def one_line_error(capsys, code, *args):
    got, out, err = run(capsys, *args)
    assert got == code, err
    assert out == ""
    lines = err.strip().splitlines()
    assert len(lines) == 1 and lines[0].startswith("barymesh: error: "), err
    return lines[0]


def files(folder):
    return sorted(p.name for p in Path(folder).iterdir())


def preset_document(name):
    """The preset's JSON, read here with json alone (independent of barymesh.cell's loader)."""
    return json.loads((CELL_PRESET_DIR / f"{name}.cell.json").read_text())


# -- arrays of one structure: closed forms in n ---------------------------------


@pytest.mark.parametrize(("n1", "n2", "n"), [(3, 2, 4), (1, 1, 4), (4, 3, 2), (2, 5, 3)])
def test_array_of_a_patch_is_one_welded_grid(capsys, n1, n2, n):
    """N1 x N2 touching 10 mm patches of n x n cells: one (n1 n) x (n2 n) grid of squares."""
    s = stats_of(
        capsys,
        "mesh",
        "--preset",
        "paper-fig10",
        "--set",
        f"subdivisions={n}",
        "--array",
        f"{n1}x{n2}",
    )
    cols, rows = n1 * n, n2 * n
    whole = s["cell"]
    assert whole["triangles"] == n1 * n2 * 2 * n**2  # 3 x 2 at n = 4: 6 x 32 = 192
    assert whole["vertices"] == (cols + 1) * (rows + 1)  # welded: 117 for 3 x 2 at n = 4
    assert whole["edges"] == cols * (rows + 1) + rows * (cols + 1) + cols * rows
    assert whole["boundary_edges"] == 2 * (cols + rows)
    assert whole["euler_characteristic"] == 1  # one piece of metal, no hole
    assert whole["patches"] == n1 * n2 and whole["area"] == pytest.approx(100.0 * n1 * n2)
    assert [(p["name"], p["triangles"]) for p in s["parts"]] == [("paper-fig10", 2 * n**2)]
    assert s["copies"] == [n1, n2]
    # the array's left and right sides carry n2 n edges each, bottom and top n1 n
    assert s["periodic_edge_pairs"] == n * (n1 + n2)
    assert s["unmatched_periodic_edges"] == 0 and s["notes"] == []


def test_array_summary_and_centring(capsys, in_tmp):
    code, out, err = run(capsys, "mesh", "--preset", "paper-fig10", "--array", "3x2", "-o", "a.vtu")
    assert code == 0, err
    assert "192 triangles, 117 vertices, 6 patches" in out
    assert "an array of 3 x 2 cells" in out
    assert "lattice rectangular: a1 = (10, 0) mm, a2 = (0, 10) mm" in out
    assert "periodic: yes, 20 edge pairs across the array's sides" in out
    xy = read_mesh(in_tmp / "a.vtu").points[:, :2]  # the array is centred on the origin
    assert xy.min(axis=0) == pytest.approx([-15.0, -10.0])
    assert xy.max(axis=0) == pytest.approx([15.0, 10.0])


def test_period_spaces_the_copies(capsys):
    # 12 mm period: the 10 mm patches do not touch, nothing welds, no edge on a side
    s = stats_of(capsys, "mesh", "--preset", "paper-fig10", "--period", "12", "--array", "3x1")
    assert s["cell"]["vertices"] == 3 * 25 and s["cell"]["triangles"] == 3 * 32
    assert s["cell"]["euler_characteristic"] == 3  # three separate pieces
    assert s["periodic_edge_pairs"] == 0
    # 12 x 10: the patches reach the top and bottom sides, 4 edges each
    s = stats_of(capsys, "mesh", "--preset", "paper-fig10", "--period", "12,10", "--array", "3x1")
    assert s["periodic_edge_pairs"] == 3 * 4 and s["unmatched_periodic_edges"] == 0


def test_period_smaller_than_the_structure_is_noted(capsys):
    code, out, err = run(capsys, "mesh", "--preset", "paper-fig10", "--period", "8")
    assert code == 0, err
    assert "note: 'paper-fig10' reaches beyond the cell boundary" in out


def test_array_of_a_ring_uses_its_bounding_box(capsys):
    from barymesh.presets import load_preset

    xy = build_mesh(load_preset("paper-fig12d")[0]).points[:, :2]
    width, height = xy.max(axis=0) - xy.min(axis=0)
    s = stats_of(capsys, "mesh", "--preset", "paper-fig12d", "--array", "2x2")
    assert s["cell"]["triangles"] == 4 * 1152
    code, out, err = run(capsys, "mesh", "--preset", "paper-fig12d", "--array", "2x1")
    assert f"a1 = ({width:.6g}, 0) mm, a2 = (0, {height:.6g}) mm" in out


# -- cell presets: counts computed from their elements ---------------------------


def _pixel_closed_forms(document):
    """Triangles, welded vertices and periodic pairs of a pixel cell, from its rows alone."""
    rows = document["pixels"]["rows"][::-1]  # bottom row first
    n = document["pixels"]["subdivisions"]
    mask = np.array([[c == "1" for c in row] for row in rows])
    r, c = np.nonzero(mask)
    a = np.arange(n + 1)
    gx = (c[:, None, None] * n + a[None, None, :]).repeat(n + 1, axis=1)
    gy = (r[:, None, None] * n + a[None, :, None]).repeat(n + 1, axis=2)
    vertices = len(set(zip(gx.ravel().tolist(), gy.ravel().tolist(), strict=True)))
    pairs = n * (int(mask[:, 0].sum()) + int(mask[0, :].sum()))
    assert (mask[:, 0] == mask[:, -1]).all() and (mask[0] == mask[-1]).all()  # periodic
    return 2 * n**2 * int(mask.sum()), vertices, pairs


def _element_params(element, mode):
    fields = {k: v for k, v in element.items() if k not in ("name", "position", "rotation")}
    return MeshParams(mode=mode, **fields)


def test_every_cell_preset_is_reachable(capsys):
    assert cell_preset_names() == [
        "coding-16x16",
        "double-ring-patch",
        "hexagonal-rings",
        "split-ring-pair",
    ]
    code, out, err = run(capsys, "presets")
    lines = dict(line.split(None, 1) for line in out.strip().splitlines())
    for name in cell_preset_names():
        assert lines[name] == f"cell: {preset_document(name)['description']}"


def test_coding_cell_counts(capsys):
    triangles, vertices, pairs = _pixel_closed_forms(preset_document("coding-16x16"))
    assert (triangles, vertices, pairs) == (124 * 32, 2433, 64)
    s = stats_of(capsys, "info", "--cell-preset", "coding-16x16")
    assert s["cell"]["triangles"] == triangles and s["cell"]["vertices"] == vertices
    assert s["cell"]["area"] == pytest.approx(124 * 0.5**2)
    assert s["periodic_edge_pairs"] == pairs and s["unmatched_periodic_edges"] == 0
    assert s["notes"] == []  # no corner-only contacts
    # a 2 x 2 array of it: every side pair welds, so the array is periodic too
    s = stats_of(capsys, "mesh", "--cell-preset", "coding-16x16", "--array", "2x2")
    assert s["cell"]["triangles"] == 4 * triangles
    assert s["periodic_edge_pairs"] == 2 * pairs


def test_element_cell_presets_counts(capsys):
    n = 4
    # double ring and patch, paper mode: 2 rings x 360 / 2 degrees of patches + the patch,
    # graded toward its edges at n = 16 (it says "grading": true and no subdivisions)
    s = stats_of(capsys, "info", "--cell-preset", "double-ring-patch")
    assert [(p["name"], p["triangles"]) for p in s["parts"]] == [
        ("rings", 2 * 180 * 2 * n**2),
        ("centre patch", 2 * 16**2),
    ]
    assert s["cell"]["triangles"] == 360 * 32 + 2 * 16**2
    # paper mode: patches are not merged
    assert s["cell"]["vertices"] == 360 * (n + 1) ** 2 + 17**2
    assert s["cell"]["regions"] == 2 and s["periodic_edge_pairs"] == 0
    # hexagonal rings, conforming: 43 sectors (≤ 10 degrees) of n x 2 cells glued side to
    # side, 86 cells round the circle (square-ish at the track's mean radius)
    s = stats_of(capsys, "info", "--cell-preset", "hexagonal-rings")
    assert s["cell"]["triangles"] == 43 * 2 * n * 2
    assert s["cell"]["vertices"] == 43 * (n + 1) * 3 - 43 * (n + 1)
    # split-ring pair: each ring as the structure alone would be meshed
    doc = preset_document("split-ring-pair")
    alone = [build_mesh(_element_params(e, doc["mode"])) for e in doc["elements"]]
    s = stats_of(capsys, "info", "--cell-preset", "split-ring-pair")
    assert [p["triangles"] for p in s["parts"]] == [m.n_triangles for m in alone]
    assert s["cell"]["triangles"] == sum(m.n_triangles for m in alone)
    assert s["cell"]["area"] == pytest.approx(sum(m.stats()["area"] for m in alone))


def test_cell_file_and_info_on_it(capsys, in_tmp):
    (in_tmp / "two.cell.json").write_text(
        json.dumps(
            {
                "format": "barymesh-cell",
                "version": 1,
                "name": "two",
                "mode": "conforming",
                "lattice": {"rectangular": [4, 2]},
                "elements": [
                    {"name": "left", "structure": "patch", "patch_size": 2, "position": [-2, -1]},
                    {"name": "right", "structure": "patch", "patch_size": 2, "position": [0, -1]},
                ],
            }
        )
    )
    by_option = stats_of(capsys, "info", "--cell", "two.cell.json")
    by_name = stats_of(capsys, "info", "two.cell.json")  # a .cell.json FILE is a cell
    assert by_option == by_name
    whole = by_option["cell"]
    assert whole["triangles"] == 64 and whole["vertices"] == 2 * 25 - 5  # welded side
    assert whole["boundary_edges"] == 2 * (8 + 4) and whole["junction_edges"] == 0
    # the 4 x 2 cell is filled: 4 edges on each of the short sides, 8 on the long ones
    assert by_option["periodic_edge_pairs"] == 4 + 8
    s = stats_of(capsys, "mesh", "--cell", "two.cell.json", "--array", "3x2")
    assert s["cell"]["vertices"] == (3 * 8 + 1) * (2 * 4 + 1)


# -- msh with $Periodic --------------------------------------------------------------


def test_cell_msh_has_periodic_section(capsys, in_tmp):
    code, out, err = run(capsys, "mesh", "--cell-preset", "coding-16x16", "-o", "c.msh")
    assert code == 0, err
    assert "wrote c.msh (Gmsh MSH 2.2 ASCII, mm) with $Periodic: 64 edge pairs" in out
    m = meshio.read(in_tmp / "c.msh")
    assert len(m.cells_dict["triangle"]) == 3968
    periodic = m.gmsh_periodic
    assert len(periodic) == 2
    shifts = []
    for dim, (slave, master), affine, nodes in periodic:
        assert dim == 1 and (slave, master) in [(2, 1), (4, 3)]  # plus side = minus side + a
        moved = m.points[np.asarray(nodes)[:, 1]] - m.points[np.asarray(nodes)[:, 0]]
        shifts.append(moved[0])
        assert np.allclose(moved, moved[0])  # every node pair differs by one lattice vector
        assert np.allclose(np.asarray(affine).reshape(4, 4)[:2, 3], -moved[0, :2])
    assert sorted(map(tuple, np.round(np.abs(shifts), 9)[:, :2])) == [(0, 8), (8, 0)]
    # our reader takes the triangles and reports the side lines as ignored
    back = read_mesh(in_tmp / "c.msh")
    assert back.n_triangles == 3968 and back.ignored_cells == {"line": 2 * 64}


def test_periodic_msh_in_metres(capsys, in_tmp):
    code, out, err = run(
        capsys, "mesh", "--preset", "paper-fig10", "--array", "2x1", "-o", "p.msh", "--unit", "m"
    )
    assert code == 0, err
    m = meshio.read(in_tmp / "p.msh")
    assert np.abs(m.points[:, :2]).max() == pytest.approx(0.01)
    shifts = sorted(
        abs(float(np.asarray(a).reshape(4, 4)[i, 3]))
        for _, _, a, _ in m.gmsh_periodic
        for i in (0, 1)
    )
    assert shifts == pytest.approx([0.0, 0.0, 0.01, 0.02])


def test_msh_without_periodic_when_no_edge_is_on_a_side(capsys, in_tmp):
    code, out, err = run(capsys, "mesh", "--cell-preset", "hexagonal-rings", "-o", "h.msh")
    assert code == 0, err
    assert "wrote h.msh (Gmsh MSH 2.2 ASCII, mm) without $Periodic (no mesh edge on its" in out
    assert "$Periodic" not in (in_tmp / "h.msh").read_text()
    assert read_mesh(in_tmp / "h.msh").n_triangles == 43 * 16  # 43 sectors of 4 x 2 cells


def test_plain_structure_msh_is_unchanged(capsys, in_tmp):
    assert run(capsys, "mesh", "--preset", "paper-fig10", "-o", "p.msh")[0] == 0
    assert "$Periodic" not in (in_tmp / "p.msh").read_text()


# -- outlines: DXF and GDSII read back --------------------------------------------


def shoelace(points):
    x, y = np.asarray(points, float).T
    return 0.5 * float(np.dot(x, np.roll(y, -1)) - np.dot(np.roll(x, -1), y))


def dxf_loops(path):
    doc = ezdxf.readfile(path)
    assert doc.units == ezdxf.units.MM
    polylines = list(doc.modelspace().query("LWPOLYLINE"))
    assert all(p.closed and p.dxf.layer == "METAL" for p in polylines)
    return [np.array(p.get_points("xy")) for p in polylines]


def gds_polygons(path):
    lib = gdstk.read_gds(path)
    assert lib.unit == pytest.approx(1e-3)  # user unit: mm
    [top] = lib.top_level()
    return top, top.polygons


@needs_writers
def test_patch_array_outline_is_one_rectangle(capsys, in_tmp):
    code, out, err = run(
        capsys, "mesh", "--preset", "paper-fig10", "--array", "3x2", "-o", "a.dxf", "-o", "a.gds"
    )
    assert code == 0, err
    assert "wrote a.dxf (DXF outline, mm: 1 polygon(s), 0 hole(s), metal area 600 mm^2" in out
    [loop] = dxf_loops(in_tmp / "a.dxf")  # six touching patches merge into one outline
    assert len(loop) == 4 and shoelace(loop) == pytest.approx(600.0)
    assert sorted(map(tuple, loop.tolist())) == [(-15, -10), (-15, 10), (15, -10), (15, 10)]
    top, polygons = gds_polygons(in_tmp / "a.gds")
    assert top.name == "paper-fig10"
    assert len(polygons) == 1 and polygons[0].area() == pytest.approx(600.0)


@needs_writers
def test_structure_outline_keeps_its_coordinates(capsys, in_tmp):
    assert run(capsys, "mesh", "--preset", "paper-fig10", "-o", "p.dxf")[0] == 0
    [loop] = dxf_loops(in_tmp / "p.dxf")
    assert loop.min(axis=0).tolist() == [0, 0] and loop.max(axis=0).tolist() == [10, 10]


@needs_writers
def test_coding_cell_outline_area_is_its_pixels(capsys, in_tmp):
    ones = sum(row.count("1") for row in preset_document("coding-16x16")["pixels"]["rows"])
    code, out, err = run(
        capsys, "mesh", "--cell-preset", "coding-16x16", "-o", "c.dxf", "-o", "c.gds"
    )
    assert code == 0, err
    loops = dxf_loops(in_tmp / "c.dxf")
    areas = np.array([shoelace(loop) for loop in loops])
    assert areas.sum() == pytest.approx(ones * 0.25, abs=1e-12)  # holes are clockwise
    assert (areas < 0).sum() == 8 and (areas > 0).sum() == 9
    top, polygons = gds_polygons(in_tmp / "c.gds")
    assert sum(p.area() for p in polygons) == pytest.approx(ones * 0.25, abs=1e-9)
    assert top.name == "coding-16x16"


@needs_writers
@pytest.mark.parametrize("chord_error", [0.05, 0.001])
def test_ring_outline_within_the_chord_error(capsys, in_tmp, chord_error):
    """The hexagonal-rings ring (3 to 4 mm): regular polygons inscribed in both circles."""
    code, out, err = run(
        capsys,
        "mesh",
        "--cell-preset",
        "hexagonal-rings",
        "-o",
        "r.dxf",
        "-o",
        "r.gds",
        "--chord-error",
        chord_error,
    )
    assert code == 0, err
    assert f"chord error {chord_error:g} mm" in out
    outer, hole = sorted(dxf_loops(in_tmp / "r.dxf"), key=lambda loop: -shoelace(loop))
    k = len(outer)
    assert len(hole) == k and shoelace(hole) < 0
    assert np.hypot(*outer.T) == pytest.approx(np.full(k, 4.0))
    assert np.hypot(*hole.T) == pytest.approx(np.full(k, 3.0))
    assert 4.0 * (1 - math.cos(math.pi / k)) <= chord_error  # the sagitta of a chord
    exact = 0.5 * k * math.sin(2 * math.pi / k) * (4.0**2 - 3.0**2)
    metal = shoelace(outer) + shoelace(hole)
    assert metal == pytest.approx(exact, rel=1e-12)
    assert abs(metal - 7 * math.pi) <= chord_error * 2 * math.pi * (4.0 + 3.0)
    _, polygons = gds_polygons(in_tmp / "r.gds")
    # gdstk's boolean (holes cut in) snaps vertices to 1e-6 mm: area within that x perimeter
    assert sum(p.area() for p in polygons) == pytest.approx(metal, abs=1e-6 * 2 * math.pi * 7)


# -- errors: one line naming the input, exit codes -----------------------------------


BAD_RADIUS = {
    "format": "barymesh-cell",
    "version": 1,
    "lattice": {"rectangular": 20},
    "elements": [
        {"structure": "patch"},
        {"structure": "patch", "position": [5, 5]},
        {"structure": "ring", "inner_radius": -1},
    ],
}
OVERLAP = {
    "format": "barymesh-cell",
    "version": 1,
    "mode": "conforming",
    "lattice": {"rectangular": 20},
    "elements": [
        {"name": "a", "structure": "patch", "patch_size": 4},
        {"name": "b", "structure": "patch", "patch_size": 4, "position": [1, 1]},
    ],
}


def _write_bad_cells(folder):
    (folder / "radius.cell.json").write_text(json.dumps(BAD_RADIUS))
    (folder / "overlap.cell.json").write_text(json.dumps(OVERLAP))
    paper = dict(OVERLAP, mode="paper")
    (folder / "paper-overlap.cell.json").write_text(json.dumps(paper))
    (folder / "broken.cell.json").write_text('{"format": "barymesh-cell",\n "version": 1,,}')
    (folder / "digits.cell.json").write_text('{"version": ' + "9" * 5000 + "}")
    (folder / "deep.cell.json").write_text("[" * 100_000 + "]" * 100_000)
    os.mkfifo(folder / "pipe.cell.json")


@pytest.mark.parametrize(
    ("args", "fragments"),
    [
        (
            ["mesh", "--cell", "radius.cell.json"],
            ["radius.cell.json: elements[2].inner_radius: inner_radius=-1 is invalid"],
        ),
        (["info", "radius.cell.json"], ["radius.cell.json: elements[2].inner_radius"]),
        (
            ["mesh", "--cell", "overlap.cell.json", "-o", "o.msh"],
            ["overlap.cell.json: element 'a' (elements[0]) and element 'b' (elements[1]) overlap"],
        ),
        (
            ["mesh", "--cell", "paper-overlap.cell.json", "-o", "o.msh", "-o", "o.dxf"],
            [
                "paper-overlap.cell.json: cannot write o.dxf: the outline needs parts that do not "
                "overlap"
            ],
        ),
        (["mesh", "--cell", "missing.cell.json"], ["missing.cell.json: the file does not exist"]),
        (["mesh", "--cell", "broken.cell.json"], ["broken.cell.json: invalid JSON at line 2"]),
        (
            ["mesh", "--cell", "digits.cell.json"],
            ["digits.cell.json: invalid JSON cell (a number is too long)"],
        ),
        (["mesh", "--cell", "deep.cell.json"], ["deep.cell.json: invalid JSON cell (nested"]),
        (["mesh", "--cell", "pipe.cell.json"], ["pipe.cell.json: the path is a named pipe"]),
        (
            ["mesh", "--cell-preset", "coding-16x16", "--array", "100x100"],
            [
                "cell preset 'coding-16x16': 100 x 100 copies of 3,968 triangles make 39,680,000 "
                "triangles, above the budget of max_triangles=5,000,000"
            ],
        ),
        (
            ["mesh", "--preset", "paper-fig10", "--array", "10x10", "--set", "max_triangles=3000"],
            [
                "10 x 10 copies of 32 triangles make 3,200 triangles, above the budget of "
                "max_triangles=3,000"
            ],
        ),
        (
            ["mesh", "--preset", "paper-fig10", "-o", "nowhere/p.dxf"],
            ["nowhere/p.dxf", "does not exist"],
        ),
    ],
)
def test_input_errors_exit_1_and_write_nothing(capsys, in_tmp, args, fragments):
    _write_bad_cells(in_tmp)
    before = files(in_tmp)
    line = one_line_error(capsys, 1, *args)
    for fragment in fragments:
        assert fragment in line
    assert files(in_tmp) == before  # no output, no temporary file


@pytest.mark.parametrize(
    ("args", "fragment"),
    [
        (
            ["mesh", "--cell-preset", "nope"],
            "unknown cell preset 'nope'; expected one of "
            "coding-16x16, double-ring-patch, hexagonal-rings, split-ring-pair",
        ),
        (["mesh", "--cell-preset", "paper-fig10"], "is a structure preset: use --preset"),
        (["mesh", "--preset", "coding-16x16"], "use --cell-preset coding-16x16"),
        (
            ["mesh", "--cell-preset", "coding-16x16", "--set", "subdivisions=2"],
            "--set sets the parameters of one structure",
        ),
        (["mesh", "--cell", "x.cell.json", "--params", "p.json"], "--params sets the parameters"),
        (["mesh", "--cell", "x.cell.json", "--cell-preset", "coding-16x16"], "give one"),
        (["mesh", "--cell-preset", "coding-16x16", "--period", "3"], "has its own lattice"),
        (["mesh", "--array", "0x2"], "'0x2' is invalid; expected at least 1x1"),
        (["mesh", "--array", "3"], "'3' is invalid; expected N1xN2"),
        (["mesh", "--period", "1,2,3"], "expected PX or PX,PY"),
        (["mesh", "--period", "-1"], "expected periods > 0 mm"),
        (["mesh", "--chord-error", "0.1"], "--chord-error needs an outline output"),
        (["mesh", "-o", "a.dxf", "--chord-error", "0"], "--chord-error 0 is invalid"),
        (["mesh", "-o", "a.gds", "--unit", "m"], "outlines are written in mm"),
        (["mesh", "-o", "a.svg"], "cannot write .svg; expected one of .msh"),
        (["info"], "the following arguments are required: FILE"),
        (["info", "a.msh", "--cell-preset", "coding-16x16"], "not both"),
        (["info", "a.msh", "--array", "2x2"], "--array needs a cell"),
        (["info", "--cell-preset", "coding-16x16", "--unit", "m"], "--unit is for mesh files"),
        (
            [
                "sweep",
                "--cell-preset",
                "coding-16x16",
                "--param",
                "angle_step",
                "--from",
                "1",
                "--to",
                "2",
                "--frames",
                "2",
                "-o",
                "s.gif",
            ],
            "sweep: --cell-preset is not supported: a sweep varies one parameter of one structure",
        ),
        (
            [
                "sweep",
                "--array",
                "2x2",
                "--param",
                "angle_step",
                "--from",
                "1",
                "--to",
                "2",
                "--frames",
                "2",
                "-o",
                "s.gif",
            ],
            "sweep: --array is not supported",
        ),
    ],
)
def test_usage_errors_exit_2(capsys, in_tmp, args, fragment):
    before = files(in_tmp)
    assert fragment in one_line_error(capsys, 2, *args)
    assert files(in_tmp) == before


def test_missing_outline_writer_is_named(capsys, in_tmp, monkeypatch):
    monkeypatch.setitem(sys.modules, "gdstk", None)  # import fails as if not installed
    line = one_line_error(capsys, 1, "mesh", "--preset", "paper-fig10", "-o", "p.gds")
    assert "cannot write p.gds: GDSII outlines need gdstk: pip install 'barymesh[cell]'" in line
    assert files(in_tmp) == []


def test_real_process_error_line(in_tmp):
    (in_tmp / "radius.cell.json").write_text(json.dumps(BAD_RADIUS))
    env = dict(os.environ, PYTHONPATH=str(ROOT))
    r = subprocess.run(
        [
            sys.executable,
            "-m",
            "barymesh.app.cli",
            "mesh",
            "--cell",
            "radius.cell.json",
            "-o",
            "x.msh",
        ],
        capture_output=True,
        text=True,
        env=env,
        timeout=120,
    )
    assert r.returncode == 1 and r.stdout == ""
    assert r.stderr == (
        "barymesh: error: radius.cell.json: elements[2].inner_radius: inner_radius=-1 is "
        "invalid; expected a finite length > 0 mm\n"
    )
    assert not (in_tmp / "x.msh").exists()


# -- issue 4: mutated preset cells on the command line ---------------------------------


def _mutated(folder, name, edit):
    doc = preset_document(name)
    edit(doc)
    path = Path(folder) / "mutated.cell.json"
    path.write_text(json.dumps(doc))
    return path


DEEP = 1.0
for _ in range(900):
    DEEP = [DEEP]


@pytest.mark.parametrize(
    ("name", "edit", "fragments"),
    [
        # the patch at [1e16, 0]: 16 triangles that repeat a vertex were written to the file
        # (the patch uniform at n = 4, as the preset had it before it was graded)
        (
            "double-ring-patch",
            lambda d: d["elements"][1].update(position=[1e16, 0], grading=False, subdivisions=4),
            [
                "elements[1].position: position=(1e+16, 0.0) puts metal 1e+16 mm",
                "float64 to resolve its 0.75 mm sub-triangle edges",
            ],
        ),
        # pixels of 1e-9 mm at x = 1e16 mm collapsed onto one point: std::bad_alloc in the weld
        (
            "coding-16x16",
            lambda d: d["pixels"].update(pixel_size=1e-9, origin=[1e16, -4]),
            ["pixels.origin: origin=(1e+16, -4.0) puts metal"],
        ),
        (
            "double-ring-patch",
            lambda d: d["elements"][0].update(inner_radius=DEEP),
            ["elements[0].inner_radius: inner_radius=[[[[...]]]] is not a number"],
        ),
        (
            "double-ring-patch",
            lambda d: d.update(lattice={"rectangular": [1, 2, 3]}),
            ["lattice.rectangular: [1, 2, 3] is invalid; expected a period in mm or two periods"],
        ),
        (
            "split-ring-pair",
            lambda d: d["elements"][0].update(inner_radius=True),
            ["elements[0].inner_radius: inner_radius=True is a true/false switch, not a number"],
        ),
    ],
)
def test_mutated_cells_exit_1_with_a_short_clear_line_and_write_nothing(
    capsys, in_tmp, name, edit, fragments
):
    path = _mutated(in_tmp, name, edit)
    before = files(in_tmp)
    line = one_line_error(capsys, 1, "mesh", "--cell", path, "-o", "out.msh")
    for fragment in fragments:
        assert fragment in line
    assert_clear_message(line)
    assert "unexpected" not in line
    assert files(in_tmp) == before
