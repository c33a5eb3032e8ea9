"""The study spec (barymesh.study.spec), the derived figures, one point, and the serial run.

No Dask here: tests/test_study_run.py runs studies on a LocalCluster.
"""

from __future__ import annotations

import json

import grimp
import numpy as np
import pandas as pd
import pytest

from barymesh.app import cli_solve
from barymesh.frequencies import parse_frequencies
from barymesh.study import SpecError, load_spec, parse_spec, read_result, run_serial
from barymesh.study.derive import bandwidth_3db, resonance
from barymesh.study.point import FREE_SPACE_COLUMNS, StudyContext, solve_point
from barymesh.study.spec import parse_path

PATCH = {"structure": "patch", "patch_size": 15.0, "patch_width": 15.0, "subdivisions": 2}


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
