"""The reflection-phase library (issue 33, part 1): the API and ``barymesh library``.

The library is checked against single periodic solves of the same cells (its phases and
its 2 × 2 to 1e-6), against the power a lossless grounded stack must reflect, and against
itself (``lookup`` gives back the values its phases were solved at; the CSV, the xarray
Dataset and the command line hold the same numbers). No number the code printed before
is asserted.
"""

from __future__ import annotations

import copy
import csv
import json
import subprocess
import sys

import numpy as np
import pytest

from barymesh.app import cli
from barymesh.cell import build_cell, cell_from_dict
from barymesh.mom import (
    PlaneWave,
    ReflectionLibrary,
    Stack,
    parse_stack,
    periodic_solve,
    reflection_library,
    te_tm_polarizations,
)
from barymesh.mom.reflection_library import CSV_COLUMNS

#: A square patch in a 10 mm cell, its corner at (−4, −4) mm, n = 6: a few dozen unknowns,
#: a solve in a fraction of a second. Over a grounded substrate its phase falls as it grows.
PATCH = {
    "format": "barymesh-cell",
    "version": 1,
    "name": "patch",
    "mode": "paper",
    "tolerance": None,
    "lattice": {"rectangular": [10.0, 10.0]},
    "elements": [
        {
            "name": "patch",
            "position": [-4.0, -4.0],
            "rotation": 0.0,
            "structure": "patch",
            "patch_size": 6.0,
            "subdivisions": 6,
            "grading": False,
        }
    ],
    "pixels": None,
}
SUBSTRATE = "1.575mm eps=2.2; ground"
VALUES = (5.0, 6.5, 8.0)
FREQUENCIES = (8e9, 10e9)
PARAMETER = "elements[0].patch_size"


def patch_cell(size: float = 6.0):
    doc = copy.deepcopy(PATCH)
    doc["elements"][0]["patch_size"] = size
    return cell_from_dict(doc)


@pytest.fixture(scope="module")
def stack():
    return parse_stack(SUBSTRATE)


@pytest.fixture(scope="module")
def lib(stack):
    return reflection_library(patch_cell(), PARAMETER, VALUES, FREQUENCIES, stack=stack)


def test_the_shapes_and_the_reference_plane(lib):
    assert lib.values.shape == (3,) and lib.frequencies.shape == (2,)
    assert lib.reflection.shape == (3, 2, 2, 2) and lib.reflection.dtype == complex
    assert lib.phase_deg.shape == lib.magnitude.shape == (3, 2)
    assert lib.reference_plane == 0.0  # no layer above the sheet: its own plane
    assert lib.polarization == "TM" and lib.incidence == {"theta": 0.0, "phi": 0.0, "pol": "TM"}
    assert lib.cell == patch_cell()  # kept for the reflectarray designer's elements
    above = Stack.from_dict({"above": [{"thickness": 0.5, "eps_r": 3.0}]})
    one = reflection_library(patch_cell(), PARAMETER, [6.0], 10e9, stack=above)
    assert one.reference_plane == 0.5  # the top face of the layer over the sheet


def test_the_phases_equal_single_periodic_solves(lib, stack):
    """Each point solved directly, with both incident polarisations: the library's co-polar
    R, its phase and its whole 2 × 2 column agree to 1e-6."""
    for i in (0, len(VALUES) - 1):
        mesh = build_cell(patch_cell(VALUES[i])).mesh
        for j, f in enumerate(FREQUENCIES):
            for k, pol in enumerate((90.0, 0.0)):  # TE (E along y), TM (E along x)
                wave = PlaneWave.from_angles(0.0, 0.0, pol)
                s = periodic_solve(mesh, f, wave, stack=stack)
                c = te_tm_polarizations(wave.direction) @ wave.polarization
                np.testing.assert_allclose(
                    lib.reflection[i, j, :, k] * c[k], s.reflection[0], atol=1e-6
                )
                if k == 1:  # the default incidence: TM, E along x
                    r = s.co_polar()[0]
                    assert abs(lib.co_polar[i, j] - r) < 1e-6
                    step = (lib.phase_deg[i, j] - np.degrees(np.angle(r))) % 360.0
                    assert min(step, 360.0 - step) < 1e-6


def test_the_phase_is_unwrapped_along_the_values(lib):
    assert np.all(np.abs(np.diff(lib.phase_deg, axis=0)) <= 180.0)
    np.testing.assert_allclose(
        np.exp(1j * np.radians(lib.phase_deg)), lib.co_polar / lib.magnitude, atol=1e-12
    )


def test_a_lossless_grounded_stack_reflects_everything(lib):
    """Below the first grating lobe (30 GHz for 10 mm) and with no order guided in the
    substrate, all the incident power comes back in the (0, 0) order, co- and cross-polar."""
    power = (np.abs(lib.reflection) ** 2).sum(axis=2)  # (V, F, in)
    np.testing.assert_allclose(power, 1.0, atol=1e-4)
    assert np.all(lib.magnitude <= 1.0 + 1e-6)


def test_lookup_gives_back_the_sampled_values(lib):
    for j, f in enumerate(FREQUENCIES):
        phases = lib.phase_deg[:, j]
        assert np.all(np.diff(phases) < 0)  # the curve falls: one monotone piece
        np.testing.assert_allclose(lib.lookup(phases, f), VALUES, atol=1e-6)
        # phases are taken modulo 360
        np.testing.assert_allclose(lib.lookup(phases + 360.0, f), VALUES, atol=1e-6)
        np.testing.assert_allclose(lib.lookup(phases - 720.0, f), VALUES, atol=1e-6)
        # between two samples: between their values
        middle = lib.lookup(0.5 * (phases[0] + phases[1]), f)
        assert VALUES[0] < middle < VALUES[1]
        # a phase the curve does not reach, modulo 360, is NaN
        span = phases.max() - phases.min()
        assert span < 360.0
        assert np.isnan(lib.lookup(phases.max() + 0.5 * (360.0 - span), f))


def synthetic(phases_deg, values=None):
    """A library of one frequency whose co-polar phases are ``phases_deg``."""
    p = np.radians(np.asarray(phases_deg, dtype=float))
    v = np.arange(len(p), dtype=float) if values is None else np.asarray(values, dtype=float)
    r = np.zeros((len(p), 1, 2, 2), dtype=complex)
    r[:, 0, 1, 1] = np.exp(1j * p)
    r[:, 0, 0, 0] = 1.0
    inc = {"theta": 0.0, "phi": 0.0, "pol": "TM"}
    return ReflectionLibrary("x", v, np.array([1e9]), r, "TM", inc, 0.0)


def test_lookup_takes_the_first_monotone_piece():
    lib = synthetic([0.0, 50.0, 100.0, 60.0, 20.0])  # rises to value 2, then falls
    assert lib.lookup(80.0, 1e9) == pytest.approx(1.6)  # on the rise first
    assert lib.lookup(100.0, 1e9) == pytest.approx(2.0)
    assert lib.lookup(-10.0, 1e9) != lib.lookup(-10.0, 1e9)  # NaN: below all of it
    np.testing.assert_allclose(lib.lookup([0.0, 360.0, 50.0], 1e9), [0.0, 0.0, 1.0])
    flat = synthetic([0.0, 40.0, 40.0, 10.0])  # a flat top: two pieces, each monotone
    assert flat.lookup(20.0, 1e9) == pytest.approx(0.5)
    assert flat.lookup(40.0, 1e9) in (1.0, 2.0)  # both values give 40°
    one = synthetic([30.0], values=[7.0])  # one value: its phase alone, modulo 360
    assert one.lookup(-330.0, 1e9) == 7.0 and np.isnan(one.lookup(31.0, 1e9))


def test_lookup_refuses_a_frequency_not_in_the_library(lib):
    with pytest.raises(ValueError, match=r"frequency=9 GHz is not one of the library's"):
        lib.lookup(0.0, 9e9)
    with pytest.raises(ValueError, match="phase_deg"):
        lib.lookup(np.nan, 8e9)


@pytest.mark.parametrize(
    ("parameter", "values", "frequencies", "fragment"),
    [
        ("elements[0].nope", [5.0], 8e9, r"parameter 'elements\[0\].nope'.*has no 'nope'"),
        ("elements[3].patch_size", [5.0], 8e9, r"has no item \[3\]"),
        ("elements[0]patch", [5.0], 8e9, "is not a parameter path"),
        (PARAMETER, [], 8e9, "values is empty"),
        (PARAMETER, [5.0, np.nan], 8e9, r"values\[1\]=nan is not finite"),
        (PARAMETER, [5.0, 5.0], 8e9, "a value twice"),
        (PARAMETER, [5.0, -1.0], 8e9, r"elements\[0\].patch_size=-1: the cell refuses it"),
        (PARAMETER, [5.0], 0.0, r"frequencies\[0\]=0.0 is invalid; expected Hz > 0"),
        (PARAMETER, [5.0], [9e9, 8e9], "increasing"),
        ("stack.above[0].thickness", [1.0], 8e9, "above the sheet"),
        ("stack.below[0].thickness", [-1.0], 8e9, r"stack.below\[0\].thickness=-1 makes the"),
        ("incidence.pol", [1.0], 8e9, "incidence.theta or incidence.phi"),
    ],
)
def test_bad_input_is_named(stack, parameter, values, frequencies, fragment):
    with pytest.raises(ValueError, match=fragment):
        reflection_library(patch_cell(), parameter, values, frequencies, stack=stack)


def test_bad_incidence_cell_and_stack_are_named(stack):
    with pytest.raises(ValueError, match="incidence pol='x'"):
        reflection_library(patch_cell(), PARAMETER, [5.0], 8e9, incidence={"pol": "x"})
    with pytest.raises(ValueError, match="theta=95"):
        reflection_library(patch_cell(), PARAMETER, [5.0], 8e9, incidence={"theta": 95})
    with pytest.raises(ValueError, match="expected a UnitCell"):
        reflection_library(PATCH, PARAMETER, [5.0], 8e9)
    with pytest.raises(ValueError, match="expected a barymesh.mom.Stack"):
        reflection_library(patch_cell(), PARAMETER, [5.0], 8e9, stack=SUBSTRATE)


def test_a_layer_of_the_stack_is_a_parameter(stack):
    lib = reflection_library(patch_cell(), "stack.below[0].thickness", [1.0, 2.0], 8e9, stack=stack)
    mesh = build_cell(patch_cell()).mesh
    wave = PlaneWave.from_angles(0.0, 0.0, 0.0)
    s = periodic_solve(mesh, 8e9, wave, stack=stack.replaced("below[0].thickness", 2.0))
    assert abs(lib.co_polar[1, 0] - s.co_polar()[0]) < 1e-6


def test_the_incidence_angle_is_a_parameter(stack):
    lib = reflection_library(patch_cell(), "incidence.theta", [0.0, 20.0], 8e9, stack=stack)
    mesh = build_cell(patch_cell()).mesh
    s = periodic_solve(mesh, 8e9, PlaneWave.from_angles(20.0, 0.0, 0.0), stack=stack)
    assert abs(lib.co_polar[1, 0] - s.co_polar()[0]) < 1e-6


def read_csv(path):
    with open(path, newline="") as f:
        rows = list(csv.reader(f))
    return rows[0], np.array(rows[1:], dtype=float)


def test_the_csv_reads_back(lib, tmp_path):
    path = lib.to_csv(tmp_path / "lib.csv")
    header, data = read_csv(path)
    assert header == [PARAMETER, *CSV_COLUMNS]
    assert data.shape == (len(VALUES) * len(FREQUENCIES), 1 + len(CSV_COLUMNS))
    np.testing.assert_array_equal(data[:, 0], np.repeat(VALUES, len(FREQUENCIES)))
    np.testing.assert_array_equal(data[:, 1], np.tile(FREQUENCIES, len(VALUES)))
    np.testing.assert_array_equal(data[:, 2], lib.phase_deg.ravel())
    np.testing.assert_array_equal(data[:, 3], lib.magnitude.ravel())
    entries = data[:, 4:12:2] + 1j * data[:, 5:12:2]  # te_te, te_tm, tm_te, tm_tm
    np.testing.assert_array_equal(entries, lib.reflection.reshape(-1, 4))
    np.testing.assert_array_equal(data[:, 12], lib.reference_plane)
    assert [p.name for p in tmp_path.iterdir()] == ["lib.csv"]  # no temporary file left


def test_the_xarray_dataset_holds_the_library(lib):
    pytest.importorskip("xarray")
    ds = lib.to_xarray()
    np.testing.assert_array_equal(ds["reflection"].values, lib.reflection)
    np.testing.assert_array_equal(ds["phase_deg"].values, lib.phase_deg)
    assert ds.attrs["reference_plane_mm"] == 0.0 and ds.attrs["parameter"] == PARAMETER
    assert list(ds["in"].values) == ["TE", "TM"]


def test_without_the_study_extra_the_library_solves_and_to_xarray_names_it():
    """pandas and xarray made unimportable: the library is solved all the same (the study's
    spec and point solve need neither); only to_xarray asks for the extra."""
    code = (
        "import sys\n"
        "sys.modules['pandas'] = sys.modules['xarray'] = None\n"
        "from barymesh.cell import cell_from_dict\n"
        "from barymesh.mom import reflection_library\n"
        f"lib = reflection_library(cell_from_dict({PATCH!r}), {PARAMETER!r}, [6.0], 8e9)\n"
        "assert lib.reflection.shape == (1, 1, 2, 2)\n"
        "try:\n"
        "    lib.to_xarray()\n"
        "except ImportError as exc:\n"
        "    print(exc)\n"
    )
    out = subprocess.run(
        [sys.executable, "-c", code], capture_output=True, text=True, timeout=300, check=False
    )
    assert out.returncode == 0, out.stderr
    assert "pip install 'barymesh[study]'" in out.stdout


def test_a_dask_client_gives_the_same_library(lib, stack):
    distributed = pytest.importorskip("distributed")
    with distributed.Client(processes=False, n_workers=1, threads_per_worker=1) as client:
        on_dask = reflection_library(
            patch_cell(), PARAMETER, VALUES[:2], FREQUENCIES[:1], stack=stack, client=client
        )
    # here TE and TM share one LU (two right-hand sides); the study engine solves them as
    # two points: the same numbers to rounding
    np.testing.assert_allclose(on_dask.reflection, lib.reflection[:2, :1], rtol=0, atol=1e-12)


# -- the command line -------------------------------------------------------------------


@pytest.fixture(scope="module")
def cell_file(tmp_path_factory):
    path = tmp_path_factory.mktemp("cells") / "patch.cell.json"
    path.write_text(json.dumps(PATCH))
    return str(path)


def run(capsys, *args):
    code = cli.main(["library", *map(str, args)])
    out, err = capsys.readouterr()
    return code, out, err


def test_the_command_writes_the_apis_csv(lib, cell_file, capsys, tmp_path):
    out_csv = tmp_path / "lib.csv"
    code, out, err = run(
        capsys, "--cell", cell_file, "--parameter", PARAMETER, "--values", "5:8:3",
        "--freq", "8GHz:10GHz:2", "--stack", SUBSTRATE, "-o", out_csv,
    )  # fmt: skip
    assert code == 0, err
    assert "wrote" in out and "3 values x 2 frequencies" in out
    header, data = read_csv(out_csv)
    _, api = read_csv(lib.to_csv(tmp_path / "api.csv"))
    assert header[0] == PARAMETER
    np.testing.assert_array_equal(data, api)


def test_the_command_prints_a_table(lib, cell_file, capsys):
    code, out, err = run(
        capsys, "--cell", cell_file, "--parameter", PARAMETER, "--values", "5,6.5,8",
        "--freq", "8GHz", "--stack", SUBSTRATE,
    )  # fmt: skip
    assert code == 0, err
    lines = out.splitlines()
    assert lines[0].split()[:3] == [PARAMETER, "f", "(GHz)"]
    phases = [float(line.split()[2]) for line in lines[1:4]]
    np.testing.assert_allclose(phases, lib.phase_deg[:, 0], atol=0.006)
    assert "referred to the stack's top face: 0 mm over the sheet" in lines[4]


@pytest.mark.parametrize(
    ("args", "code", "fragment"),
    [
        (["--parameter", PARAMETER, "--values", "5:8:3", "--freq", "8GHz"], 2, "--cell"),
        (["--values", "5:8:x", "--freq", "8GHz"], 2, "--values '5:8:x' is invalid"),
        (["--values", "5:8:3", "--freq", "8 parsecs"], 2, "--freq"),
        (["--values", "5:8:3", "--freq", "8GHz", "--stack", "1mm eps=0"], 2, "--stack"),
        (["--values", "5:8:3", "--freq", "8GHz", "-o", "x.txt"], 2, "expected a .csv"),
        (["--values", "5,-1", "--freq", "8GHz"], 1, "patch_size=-1: the cell refuses it"),
    ],
)
def test_bad_usage_and_input_are_one_line(cell_file, capsys, args, code, fragment):
    if "--values" in args and "--parameter" not in args:
        args = ["--cell", cell_file, "--parameter", PARAMETER, *args]
    got, out, err = run(capsys, *args)
    assert got == code
    assert len(err.strip().splitlines()) == 1 and fragment in err
