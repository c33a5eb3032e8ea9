"""The study spec (barymesh.study.spec), the derived figures, one point, and the serial run.

No Dask here: tests/test_study_run.py runs studies on a LocalCluster.
"""

from __future__ import annotations

import functools
import json
import os

import grimp
import numpy as np
import pandas as pd
import pytest
from helpers import address_space_cap, assert_clear_message

from barymesh.app import cli_solve
from barymesh.frequencies import parse_frequencies
from barymesh.study import SpecError, load_spec, parse_spec, read_result, run_serial
from barymesh.study.derive import bandwidth_3db, resonance
from barymesh.study.point import FREE_SPACE_COLUMNS, StudyContext, solve_point
from barymesh.study.spec import parse_path

# says "grading": taken as given (a study makes the parts that do not solver-grade)
PATCH = {
    "structure": "patch",
    "patch_size": 15.0,
    "patch_width": 15.0,
    "subdivisions": 2,
    "grading": False,
}


def spec(**changes):
    doc = {
        "base": {"params": dict(PATCH)},
        "axes": {"patch_size": [14.0, 15.0], "patch_width": [12.0, 14.0]},
        "sample": "product",
        "solve": {"kind": "free_space", "frequencies": "6GHz:12GHz:11"},
        "derive": ["resonance_frequency", "quality_factor"],
    }
    doc.update(changes)
    return doc


# -- parsing ---------------------------------------------------------------------------------


def test_the_issue_example_parses_into_its_points():
    s = parse_spec(
        {
            "base": {"preset": "srr-openmodes"},
            "axes": {"inner_radius": [3.0, 3.5, 4.0], "gap_width": [0.5, 1.0]},
            "sample": "product",
            "solve": {
                "kind": "free_space",
                "frequencies": "4GHz:9GHz:51",
                "direction": [0, 0, -1],
                "polarization": [0, 1, 0],
            },
            "derive": ["resonance_frequency", "quality_factor"],
            "output": "study.parquet",
        }
    )
    assert s.axis_names == ("inner_radius", "gap_width")
    assert len(s.solve.frequencies) == 51
    assert s.solve.frequencies[0] == 4e9 and s.solve.frequencies[-1] == 9e9
    points = s.points()
    assert len(points) == 6  # 3 x 2, the last axis fastest
    assert points[0] == {"inner_radius": 3.0, "gap_width": 0.5}
    assert points[1] == {"inner_radius": 3.0, "gap_width": 1.0}
    assert points[5] == {"inner_radius": 4.0, "gap_width": 1.0}
    assert s.derived_columns == ("resonance_frequency_hz", "quality_factor")
    assert s.base.kind == "params" and s.base.data["structure"] == "split_ring"


def test_the_spec_reads_frequencies_as_the_solve_command_does():
    s = parse_spec(spec())
    assert list(s.solve.frequencies) == parse_frequencies("6GHz:12GHz:11")
    assert list(s.solve.frequencies) == cli_solve.parse_frequencies("6GHz:12GHz:11")
    assert parse_spec(
        spec(solve={"kind": "free_space", "frequencies": [6e9, "7GHz"]})
    ).solve.frequencies == (6e9, 7e9)


def test_the_digest_is_of_the_canonical_spec_without_the_output():
    a = parse_spec(spec(output="a.parquet"))
    b = parse_spec({**spec(), "output": "b.csv"})
    assert a.digest() == b.digest() and len(a.digest()) == 16
    c = parse_spec(spec(axes={"patch_size": [14.0, 15.5], "patch_width": [12.0, 14.0]}))
    assert c.digest() != a.digest()
    assert json.loads(a.canonical())["axes"]["patch_size"] == [14.0, 15.0]
    d = parse_spec(spec(derive=["bandwidth_3db", {"extinction_cross_section_at": ["7GHz"]}]))
    for s in (a, d):  # the canonical form is a spec, read back to the same canonical form
        assert parse_spec(json.loads(s.canonical())).canonical() == s.canonical()


def test_paths_into_a_cell_set_one_element():
    s = parse_spec(
        {
            "base": {"cell_preset": "split-ring-pair"},
            "axes": {"elements[1].gap_width": [0.5, 1.5], "incidence.theta": [0.0, 30.0]},
            "solve": {"kind": "free_space", "frequencies": "4GHz:9GHz:3", "pol": "TE"},
        }
    )
    assert parse_path("elements[1].gap_width") == ("elements", 1, "gap_width")
    data = s.base.design({"elements[1].gap_width": 1.5})
    assert data["elements"][1]["gap_width"] == 1.5
    assert data["elements"][0]["gap_width"] == s.base.data["elements"][0]["gap_width"] == 1.0
    cell = s.base.build(data)
    assert cell.elements[1].params.gap_width == 1.5
    assert len(s.points()) == 4


def test_a_latin_hypercube_puts_one_point_in_each_slice_of_every_axis():
    s = parse_spec(
        spec(
            sample={"latin_hypercube": 8, "seed": 3},
            axes={"patch_size": [10.0, 18.0], "patch_width": [8.0, 16.0]},
        )
    )
    points = s.points()
    assert len(points) == 8
    for name, low in (("patch_size", 10.0), ("patch_width", 8.0)):
        slices = sorted(int((p[name] - low) // 1.0) for p in points)
        assert slices == list(range(8))
    again = parse_spec(
        spec(
            sample={"latin_hypercube": 8, "seed": 3},
            axes={"patch_size": [10.0, 18.0], "patch_width": [8.0, 16.0]},
        )
    )
    assert again.points() == points


@pytest.mark.parametrize(
    ("changes", "message"),
    [
        ({"extra": 1}, "study spec: extra: unknown key"),
        ({"base": {"preset": "nope"}}, "base.preset: unknown preset 'nope'"),
        ({"base": {"params": {"structure": "blob"}}}, "base.params: structure='blob'"),
        ({"base": {"cell_preset": "nope"}}, "base.cell_preset: unknown cell preset"),
        ({"axes": {"inner_radiu": [1.0]}}, "axes.inner_radiu: the base has no 'inner_radiu'"),
        ({"axes": {"elements[1].gap_width": [1.0]}}, "the base has no 'elements'"),
        ({"axes": {"patch_size": []}}, "axes.patch_size: an array; expected a non-empty list"),
        ({"axes": {"patch_size": [1.0, 1.0]}}, "axes.patch_size: a value is listed twice"),
        ({"axes": {"patch_size..x": [1.0]}}, "axes.patch_size..x: is not a parameter path"),
        ({"axes": {"incidence.psi": [1.0]}}, "axes.incidence.psi: expected incidence.theta"),
        ({"sample": "random"}, "sample: 'random'; expected \"product\""),
        ({"sample": {"latin_hypercube": 0}}, "sample.latin_hypercube: 0; expected a whole"),
        (
            {"sample": {"latin_hypercube": 4}, "axes": {"patch_size": [1.0, 2.0, 3.0]}},
            "axes.patch_size: a Latin-hypercube axis is [low",
        ),
        ({"solve": {"kind": "static", "frequencies": "1GHz"}}, "solve.kind: 'static'"),
        ({"solve": {"kind": "free_space"}}, "solve.frequencies: missing"),
        ({"solve": {"kind": "free_space", "frequencies": "4GHz:3GHz:5"}}, "expected A < B"),
        (
            {"solve": {"kind": "free_space", "frequencies": "1 parsec"}},
            "solve.frequencies '1 parsec'",
        ),
        (
            {"solve": {"kind": "free_space", "frequencies": "1GHz", "polarization": [0, 0, 1]}},
            "solve: polarization=[0.0, 0.0, 1.0] is not perpendicular",
        ),
        ({"solve": {"kind": "free_space", "frequencies": "1GHz", "theta": 95}}, "theta=95"),
        ({"solve": {"kind": "free_space", "frequencies": "1GHz", "pol": "XX"}}, "pol='XX'"),
        ({"derive": ["resonance"]}, "derive[0]: unknown figure 'resonance'"),
        (
            {"derive": [{"reflection_at": ["7GHz"]}]},
            "reflection_at needs solve.kind infinite_array",
        ),
        (
            {"derive": [{"extinction_cross_section_at": ["20GHz"]}]},
            "20 GHz is outside the solved 6-12 GHz",
        ),
        ({"output": "x.h5"}, "output: 'x.h5': expected a .parquet or .csv file"),
    ],
)
def test_a_bad_spec_is_one_error_naming_the_key(changes, message):
    with pytest.raises(SpecError) as info:
        parse_spec(spec(**changes))
    assert message in str(info.value)
    assert "\n" not in str(info.value)


@pytest.mark.parametrize(
    ("changes", "message"),
    [
        # issue 30: sizes that blew up memory are refused with the key named
        (
            {"solve": {"kind": "free_space", "frequencies": "4GHz:9GHz:1000000000"}},
            "solve.frequencies: solve.frequencies '4GHz:9GHz:1000000000': K=1,000,000,000 "
            "frequencies is more than a sweep takes (100,000)",
        ),
        (
            {"axes": {"patch_size": {"start": 10, "stop": 20, "num": 10**12}}},
            "axes.patch_size.num: 1,000,000,000,000 values, more than a study takes (100,000)",
        ),
        (
            {"sample": {"latin_hypercube": 10**12}, "axes": {"patch_size": [10, 20]}},
            "sample.latin_hypercube: 1,000,000,000,000 points, more than a study takes",
        ),
        (
            {
                "axes": {
                    "patch_size": [10 + i / 1e3 for i in range(400)],
                    "patch_width": [10 + i / 1e3 for i in range(400)],
                }
            },
            "axes: 400 x 400 = 160,000 points, more than a study takes (100,000)",
        ),
        (
            {
                "axes": {"patch_size": [10 + i / 1e4 for i in range(20_000)]},
                "solve": {"kind": "free_space", "frequencies": "6GHz:12GHz:1000"},
            },
            "solve.frequencies: 1,000 frequencies at 20,000 points make 20,000,000 rows",
        ),
        # NaN passed and failed later as "Out of range float values are not JSON compliant"
        ({"axes": {"patch_size": [14.0, float("nan")]}}, "axes.patch_size: nan in the list"),
        ({"axes": {"patch_size": [14.0, float("inf")]}}, "axes.patch_size: inf in the list"),
        ({"axes": {"patch_size": [10**5000]}}, "axes.patch_size: an integer of about 5,000"),
    ],
)
def test_a_spec_too_large_or_not_finite_is_refused_naming_the_key(changes, message):
    with pytest.raises(SpecError) as info:
        parse_spec(spec(**changes))
    assert message in str(info.value)
    assert "\n" not in str(info.value) and len(str(info.value)) < 300


def test_a_damaged_spec_file_is_one_clear_error_naming_the_file(tmp_path):
    # issue 30: the raw codec message without the file (17 of 59 damaged specs), Python's
    # set_int_max_str_digits hint, and a RecursionError at 100,000 levels
    text = json.dumps(spec())
    cases = {
        "latin1.json": (text.replace("patch", "p\u00e4tch").encode("latin-1"), "byte "),
        "digits.json": (text.replace("15.0", "1" * 5000, 1).encode(), "a number has more"),
        "deep.json": (("[" * 100_000 + "]" * 100_000).encode(), "nested too deeply"),
    }
    for name, (data, fragment) in cases.items():
        path = tmp_path / name
        path.write_bytes(data)
        with pytest.raises(SpecError) as info:
            load_spec(path)
        message = str(info.value)
        assert message.startswith(str(path)) and fragment in message, message
        assert "sys." not in message and "codec" not in message and len(message) < 300


def test_a_spec_file_that_is_not_json_names_the_file(tmp_path):
    path = tmp_path / "s.json"
    path.write_text("{nope")
    with pytest.raises(SpecError, match=r"s.json is not JSON"):
        load_spec(path)
    with pytest.raises(SpecError, match=r"cannot read the study spec"):
        load_spec(tmp_path / "missing.json")


# -- derived figures -------------------------------------------------------------------------


def test_the_figures_of_a_lorentzian():
    f = np.linspace(5e9, 7e9, 401)
    gamma = 0.1e9
    y = 1.0 / ((f - 6.19e9) ** 2 + gamma**2)
    f0, q = resonance(f, y)
    assert f0 == pytest.approx(6.19e9, rel=1e-12)
    assert q == pytest.approx(6.19e9 / (2 * gamma), rel=1e-9)
    assert bandwidth_3db(f, y) == pytest.approx(2 * gamma, rel=1e-3)  # FWHM = 2 gamma
    assert np.isnan(bandwidth_3db(f[:150], y[:150]))  # no half-power point above the band
    assert np.isnan(resonance(f, f)[0])  # rising: no peak inside


# -- one point -------------------------------------------------------------------------------


def test_a_point_is_the_solve_command_s_sweep():
    from barymesh import MeshParams, build_mesh
    from barymesh.mom import PlaneWave, sweep

    s = parse_spec(
        spec(solve={"kind": "free_space", "frequencies": "6GHz:12GHz:7", "polarization": [0, 1, 0]})
    )
    p = solve_point(StudyContext.of(s), 2, {"patch_size": 15.0, "patch_width": 12.0})
    mesh = build_mesh(MeshParams(**{**PATCH, "patch_width": 12.0}))
    r = sweep(mesh, parse_frequencies("6GHz:12GHz:7"), PlaneWave((0, 0, -1), (0, 1, 0)))
    assert p.status == "ok" and p.index == 2 and p.unknowns == len(mesh.rwg)
    assert tuple(p.table) == FREE_SPACE_COLUMNS == cli_solve.CSV_COLUMNS
    np.testing.assert_array_equal(
        p.table["extinction_cross_section_m2"], r.extinction_cross_section
    )
    np.testing.assert_array_equal(p.table["residual"], r.residuals)
    strongest = np.argmax(np.interp(r.resonances, r.frequencies, r.extinction_cross_section))
    assert p.derived["resonance_frequency_hz"] == r.resonances[strongest]
    assert p.derived["quality_factor"] == r.quality_factors[strongest]


def test_a_point_the_mesher_refuses_is_an_error_row():
    s = parse_spec(spec(axes={"patch_size": [15.0, -2.0]}))
    p = solve_point(StudyContext.of(s), 1, {"patch_size": -2.0})
    assert p.status.startswith("patch_size=-2.0 is invalid")
    assert p.table == {} and all(np.isnan(v) for v in p.derived.values())
    assert set(p.derived) == {"resonance_frequency_hz", "quality_factor"}


# -- serial runs and files -------------------------------------------------------------------


def test_a_serial_run_writes_csv_that_reads_back_exactly(tmp_path):
    s = parse_spec(spec(axes={"patch_size": [14.0, -1.0, 15.0]}, output=str(tmp_path / "s.csv")))
    result = run_serial(s)
    assert list(result.table.columns) == ["patch_size", *FREE_SPACE_COLUMNS]
    assert list(result.derived.columns) == [
        "patch_size",
        "status",
        "resonance_frequency_hz",
        "quality_factor",
        "warnings",
    ]
    assert list(result.derived.status[[0, 2]]) == ["ok", "ok"]
    assert result.derived.status[1].startswith("patch_size=-1.0 is invalid")
    assert sorted(set(result.table.index)) == [0, 2] and len(result.table) == 22
    back = read_result(tmp_path / "s.csv")
    pd.testing.assert_frame_equal(back.table, result.table, check_exact=True)
    pd.testing.assert_frame_equal(back.derived, result.derived, check_exact=True)
    assert (tmp_path / "s.derived.csv").exists() and back.meta["digest"] == s.digest()
    assert {"barymesh", "numpy", "pandas", "pyarrow"} <= set(back.meta["versions"])


def test_a_latin_hypercube_study_has_a_point_dimension():
    s = parse_spec(
        spec(
            sample={"latin_hypercube": 3, "seed": 1},
            axes={"patch_size": [13.0, 16.0], "patch_width": [11.0, 14.0]},
        )
    )
    ds = run_serial(s).to_xarray()
    assert ds["extinction_cross_section_m2"].dims == ("point", "frequency_hz")
    assert ds["resonance_frequency_hz"].dims == ("point",)
    assert list(ds["patch_size"].values) == [p["patch_size"] for p in s.points()]
    assert ds.sizes == {"point": 3, "frequency_hz": 11}


def test_the_xarray_variables_carry_their_units():
    s = parse_spec(
        spec(
            axes={"patch_size": [14.0, 15.0], "incidence.theta": [0.0, 30.0]},
            derive=[
                "resonance_frequency",
                "quality_factor",
                "bandwidth_3db",
                {"extinction_cross_section_at": ["9GHz"]},
            ],
        )
    )
    result = run_serial(s)
    ds = result.to_xarray()
    units = {name: ds[name].attrs.get("units") for name in [*ds.data_vars, *ds.coords]}
    assert units == {
        "extinction_cross_section_m2": "m2",
        "scattering_cross_section_m2": "m2",
        "absorption_cross_section_m2": "m2",
        "input_impedance_real_ohm": "ohm",
        "input_impedance_imag_ohm": "ohm",
        "condition_number": "1",
        "residual": "1",
        "status": None,  # text
        "warnings": None,  # text
        "resonance_frequency_hz": "Hz",
        "quality_factor": "1",
        "bandwidth_3db_hz": "Hz",
        "extinction_cross_section_m2_at_9GHz": "m2",
        "frequency_hz": "Hz",
        "patch_size": "mm",
        "incidence.theta": "degree",
    }
    # a Latin hypercube too: the axes are coordinates along the points
    lhs = parse_spec(spec(sample={"latin_hypercube": 2, "seed": 1}, axes={"gap_angle": [0, 90]}))
    ds = run_serial(lhs).to_xarray()
    assert ds["gap_angle"].attrs["units"] == "degree" and "units" not in ds["point"].attrs
    assert ds["resonance_frequency_hz"].attrs["units"] == "Hz"


# -- dependencies ----------------------------------------------------------------------------


def test_only_the_study_package_imports_dask_and_the_table_libraries():
    graph = grimp.build_graph(
        "barymesh",
        include_external_packages=True,
        exclude_type_checking_imports=True,
        cache_dir=None,
    )
    allowed = ("barymesh.study", "barymesh.app.cli_study", "barymesh.app.dialogs.study_dialog")
    for package in ("dask", "distributed", "pyarrow", "xarray", "pandas"):
        importers = (
            graph.find_modules_that_directly_import(package) if package in graph.modules else set()
        )
        outside = sorted(m for m in importers if not m.startswith(allowed))
        assert outside == [], (package, outside)
    assert "barymesh.study.run" in graph.find_modules_that_directly_import("distributed")


# -- the infinite array ----------------------------------------------------------------------

#: A 10 mm square lattice of square patches (lower-left corner at -3.5 mm), 50 triangles at
#: 7 mm: edges under 0.2 of the period, as the periodic solver asks.
PATCH_ARRAY = {
    "format": "barymesh-cell",
    "version": 1,
    "name": "patch-array",
    "mode": "paper",
    "tolerance": None,
    "lattice": {"rectangular": [10.0, 10.0]},
    "elements": [
        {
            "name": "patch",
            "position": [-3.5, -3.5],
            "rotation": 0.0,
            "structure": "patch",
            "patch_size": 6.0,
            "subdivisions": 5,
            "grading": False,  # taken as given (not made solver-grade)
        }
    ],
    "pixels": None,
}


def test_an_infinite_array_study_is_periodic_sweep_per_point():
    from barymesh.cell import build_cell, cell_from_dict
    from barymesh.mom import PlaneWave, periodic_sweep
    from barymesh.study.point import INFINITE_ARRAY_COLUMNS

    s = parse_spec(
        {
            "base": {"cell": PATCH_ARRAY},
            "axes": {"elements[0].patch_size": [6.5, 7.0]},
            "solve": {
                "kind": "infinite_array",
                "frequencies": "24GHz:29GHz:6",
                "theta": 0,
                "phi": 0,
                "pol": "TM",
                "interpolate": False,
            },
            "derive": ["resonance_frequency", {"reflection_at": ["26.5GHz"]}],
        }
    )
    result = run_serial(s)
    assert (result.derived.status == "ok").all(), result.derived.status.tolist()
    assert list(result.table.columns) == ["elements[0].patch_size", *INFINITE_ARRAY_COLUMNS]
    cell = dict(PATCH_ARRAY, elements=[{**PATCH_ARRAY["elements"][0], "patch_size": 7.0}])
    mesh = build_cell(cell_from_dict(cell)).mesh
    direct = periodic_sweep(
        mesh,
        parse_frequencies("24GHz:29GHz:6"),
        PlaneWave.from_angles(0, 0, 0),  # TM: E along theta-hat, x at normal incidence
        interpolate=False,
        polarizations="incident",
    )
    row = result.table.loc[1]
    np.testing.assert_array_equal(row["reflection_tm_real"], direct.reflection[:, 1].real)
    np.testing.assert_array_equal(row["transmission_te_imag"], direct.transmission[:, 0].imag)
    np.testing.assert_array_equal(row["reflection_co_abs"], np.abs(direct.co_polar()[0]))
    # a perfect conductor below the first grating lobe (30 GHz): the (0, 0) order's TE and
    # TM powers, reflected and transmitted, add up to the incident power
    # (within 2e-3: the periodic solver's power balance worsens toward the onset, 1e-3
    # a few percent below it, as barymesh.mom.periodic_sweep documents)
    t = result.table
    assert np.abs(t["absorption"]).max() < 2e-3
    power = sum(
        t[f"{side}_{p}_real"] ** 2 + t[f"{side}_{p}_imag"] ** 2
        for side in ("reflection", "transmission")
        for p in ("te", "tm")
    )
    np.testing.assert_allclose(power, 1.0 - t["absorption"], atol=1e-9)
    assert (t["reflection_co_abs"] <= 1.0 + 2e-3).all()
    r = result.derived.set_index("elements[0].patch_size")
    # the resonance is the peak of the reflected power |R_co|^2 (total reflection, near
    # 27 GHz here, below the first grating lobe at 30 GHz)
    f0 = resonance(row["frequency_hz"].to_numpy(), row["reflection_co_abs"].to_numpy() ** 2)[0]
    assert r.resonance_frequency_hz[7.0] == f0 and 25e9 < f0 < 29e9
    at = np.interp(26.5e9, row["frequency_hz"], row["reflection_co_abs"])
    assert r["reflection_co_abs_at_26.5GHz"][7.0] == at


def test_a_study_makes_the_parts_that_do_not_say_grading_solver_grade():
    from barymesh.cell import cell_from_dict

    # a patch without "grading": graded toward its edges at n = 16 (the accuracy default);
    # the canonical spec says so, and reads back to itself
    plain = {k: v for k, v in PATCH.items() if k != "grading"}
    s = parse_spec(spec(base={"params": plain}))
    base = json.loads(s.canonical())["base"]["params"]
    assert (base["grading"], base["subdivisions"]) == (True, 16)
    assert parse_spec(json.loads(s.canonical())).canonical() == s.canonical()
    assert parse_spec(spec()).document["base"]["params"]["subdivisions"] == 2  # said: as given
    # a cell: the element that says nothing is graded, the pixels too; up to 29 GHz the
    # λ/10 rule (1.03 mm) leaves the graded 6 mm patch at n = 16 (core cells 0.56 mm)
    element = {k: v for k, v in PATCH_ARRAY["elements"][0].items() if k != "grading"}
    pixels = {"pixel_size": 1.0, "origin": [-5.0, 3.0], "rows": ["1"]}
    cell_doc = dict(PATCH_ARRAY, elements=[element], pixels=pixels)
    s = parse_spec(
        {
            "base": {"cell": cell_doc},
            "axes": {"elements[0].patch_size": [6.5, 7.0]},
            "solve": {"kind": "infinite_array", "frequencies": "24GHz:29GHz:6"},
        }
    )
    cell = cell_from_dict(json.loads(s.canonical())["base"]["cell"])
    assert cell.elements[0].params.grading and cell.elements[0].params.subdivisions == 16
    assert cell.pixels.grading and cell.pixels.subdivisions == 4
    assert parse_spec(json.loads(s.canonical())).canonical() == s.canonical()


def test_an_infinite_array_needs_a_cell():
    with pytest.raises(SpecError, match="solve.kind: infinite_array needs a unit cell"):
        parse_spec(spec(solve={"kind": "infinite_array", "frequencies": "8GHz:12GHz:5"}))


def test_an_infinite_array_point_too_large_is_refused_by_the_periodic_memory_model():
    # a 6 mm patch at n = 20: 800 triangles, up to 1,200 unknowns. The free-space model
    # allows it in 200 MiB (81 MiB), the infinite array's does not (its geometry's T²
    # tables: 282 MiB), so the point is refused before submission, and the small one solved
    s = parse_spec(
        {
            "base": {"cell": PATCH_ARRAY},
            "axes": {"elements[0].subdivisions": [5, 20]},
            "solve": {
                "kind": "infinite_array",
                "frequencies": "24GHz:26GHz:2",
                "interpolate": False,
                "memory_limit": 200 * 2**20,
            },
        }
    )
    result = run_serial(s)
    status = result.derived.set_index("elements[0].subdivisions")["status"]
    assert status[5] == "ok"
    assert status[20] == (
        "up to T = 800 triangles and N = 1,200 unknowns of an infinite array need 0.275 GB "
        "at the peak of a solve, more than a worker's 0.195 GB; use a coarser mesh"
    )
    assert result.computed == 1 and result.meta["refused"] == 1


# -- issue 30: hostile specs, drawn at random ----------------------------------------------

from hypothesis import HealthCheck, example, given, settings  # noqa: E402
from hypothesis import strategies as st  # noqa: E402

from barymesh.study.spec import MAX_POINTS, MAX_ROWS  # noqa: E402

#: Hostile values anywhere in a spec: sizes, non-finite numbers, huge integers, nesting.
HOSTILE = st.one_of(
    st.sampled_from(
        [
            float("nan"),
            float("inf"),
            -float("inf"),
            10**5000,
            -(10**400),
            10**12,
            1e12,
            0,
            -1,
            True,
            None,
            "",
            "x" * 5000,
            "4GHz:9GHz:1000000000",
            "4GHz:9GHz:" + "9" * 5000,
            "1e-300Hz",
            [],
            {},
            [float("nan")],
            {"num": 10**12},
            {"start": 0, "stop": 1, "num": 10**12},
            {"latin_hypercube": 10**12},
            functools.reduce(lambda v, _: [v], range(2000), 1.0),
        ]
    ),
    st.floats(allow_nan=True, allow_infinity=True),
    st.integers(-(10**20), 10**20),
)
PLACES = [
    ("axes", "patch_size"),
    ("axes", "patch_width"),
    ("axes", "patch_size", 0),
    ("axes", "patch_size", "num"),
    ("sample",),
    ("sample", "latin_hypercube"),
    ("sample", "seed"),
    ("solve", "frequencies"),
    ("solve", "frequencies", 0),
    ("solve", "theta"),
    ("solve", "memory_limit"),
    ("derive", 0),
    ("output",),
    ("base", "params", "patch_size"),
]
SPEC_FUZZ_EXAMPLES = max(50, int(os.environ.get("BARYMESH_FUZZ_EXAMPLES", "2000")) // 10)


def put(doc, place, value):
    node = doc
    for key in place[:-1]:
        if isinstance(node, dict):
            node = node.setdefault(key, {})
        elif isinstance(node, list) and isinstance(key, int) and -len(node) <= key < len(node):
            node = node[key]
        else:
            return
    last = place[-1]
    if isinstance(node, dict) and not isinstance(last, int):
        node[last] = value
    elif isinstance(node, list) and isinstance(last, int) and -len(node) <= last < len(node):
        node[last] = value
    elif isinstance(node, dict) and isinstance(last, int) and node.get("num") is None:
        node[str(last)] = value


@settings(
    max_examples=SPEC_FUZZ_EXAMPLES,
    deadline=None,
    suppress_health_check=[HealthCheck.too_slow],
)
@given(st.lists(st.tuples(st.sampled_from(PLACES), HOSTILE), min_size=1, max_size=3))
@example(changes=[(("derive", 0), "x" * 5000)])  # found by the fuzz: a 5,101-character line
def test_hostile_specs_give_one_clear_line_or_a_spec_of_bounded_size(changes):
    doc = spec(
        sample={"latin_hypercube": 4} if ("sample",) in [c[0] for c in changes] else "product"
    )
    if isinstance(doc["sample"], dict):
        doc["axes"] = {"patch_size": [14.0, 15.0], "patch_width": [12.0, 14.0]}
    for place, value in changes:
        put(doc, place, value)
    try:
        with address_space_cap(1 << 30):  # sizes are refused, never allocated
            s = parse_spec(doc)
            n = len(s.points())
    except SpecError as err:
        message = str(err)
        assert message.startswith("study spec: ") and "\n" not in message, message
        assert_clear_message(message)
        return
    assert 1 <= n <= MAX_POINTS and n * len(s.solve.frequencies) <= MAX_ROWS
    assert all(np.isfinite(f) and f > 0 for f in s.solve.frequencies)
    json.loads(s.canonical())  # JSON, without NaN: what the results' metadata holds
