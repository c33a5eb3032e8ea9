"""Studies of a cell on dielectric layers and a ground plane (issue 29, part 4: studies).

The spec's ``stack``, the ``stack.…`` axes, the reflection phase and zero-phase figures
(checked against the grounded slab's exact reflection and against direct solves), the
warnings each point records, and a study of a patch high-impedance surface on Dask.
"""

from __future__ import annotations

import json
import math

import numpy as np
import pyarrow.parquet as pq
import pytest

from barymesh.app.cli_study import warning_lines
from barymesh.cell import build_cell, cell_from_dict
from barymesh.constants import SPEED_OF_LIGHT
from barymesh.mom import Layer, PlaneWave, Stack, periodic_solve, periodic_sweep
from barymesh.study import SpecError, parse_spec, read_result, run, run_serial
from barymesh.study.derive import reflection_phase, zero_phase_frequency
from barymesh.study.point import INFINITE_ARRAY_COLUMNS
from barymesh.study.results import PART_KEY, parts_folder

#: An 8 mm square patch in a 10 mm cell, n = 6 (72 triangles, 96 unknowns): over a
#: grounded substrate, a high-impedance surface whose reflection phase passes through 0
#: between 7 and 10 GHz. It says ``grading`` (false), so that studies take it as given rather
#: than solver-grade (:mod:`barymesh.solver_grade`): the tests compare with direct solves on
#: this very mesh, and its coarseness is what the warnings tests need.
HIS = {
    "format": "barymesh-cell",
    "version": 1,
    "name": "his",
    "mode": "paper",
    "tolerance": None,
    "lattice": {"rectangular": [10.0, 10.0]},
    "elements": [
        {
            "name": "patch",
            "position": [-4.0, -4.0],
            "rotation": 0.0,
            "structure": "patch",
            "patch_size": 8.0,
            "subdivisions": 6,
            "grading": False,
        }
    ],
    "pixels": None,
}
SUBSTRATE = "1.575mm eps=2.2; ground"
TM = PlaneWave.from_angles(0, 0, 0)  # normal incidence, E along x


def spec(**changes):
    doc = {
        "base": {"cell": HIS},
        "stack": SUBSTRATE,
        "axes": {"stack.below[0].thickness": [1.5, 2.0]},
        "solve": {"kind": "infinite_array", "frequencies": "5GHz:10.5GHz:12"},
        "derive": ["zero_phase_frequency"],
    }
    doc.update(changes)
    return doc


def his_mesh():
    return build_cell(cell_from_dict(HIS)).mesh


def co_phase(solution) -> float:
    return math.degrees(np.angle(solution.co_polar()[0]))


# -- the spec ----------------------------------------------------------------------------------


def test_the_stack_is_given_as_the_command_line_s_text_or_as_a_mapping():
    text = parse_spec(spec(stack="0.5mm eps=3 tand=0.01; sheet; 1.575mm eps=2.2; ground"))
    mapping = parse_spec(
        spec(
            stack={
                "above": [{"thickness": 0.5, "eps_r": 3.0, "loss_tangent": 0.01}],
                "below": [{"thickness": 1.575, "eps_r": 2.2}],
                "ground": True,
            }
        )
    )
    assert (
        text.stack
        == mapping.stack
        == Stack((Layer(0.5, 3.0, 0.01),), (Layer(1.575, 2.2),), ground=True)
    )
    # the canonical spec holds the mapping: the two forms are one study (one digest)
    assert text.document["stack"] == mapping.stack.to_dict()
    assert text.digest() == mapping.digest()
    # a spec without a stack has no "stack" in its canonical form: its digest, and so the
    # parts of its earlier runs, are those it had before stacks existed
    plain = {k: v for k, v in spec().items() if k != "stack"}
    plain["axes"] = {"elements[0].patch_size": [7.0, 8.0]}
    assert "stack" not in parse_spec(plain).document
    assert parse_spec(plain).stack is None


def test_each_stack_axis_point_gets_its_own_stack():
    from barymesh.study.layers import point_stack

    s = parse_spec(
        spec(
            stack="0.5mm eps=3; sheet; 1.575mm eps=2.2; ground",
            axes={"stack.above[0].thickness": [0.5, 1.0], "stack.below[0].eps_r": [2.2, 4]},
        )
    )
    stacks = [point_stack(s.stack, p) for p in s.points()]
    assert [x.describe() for x in stacks] == [
        "0.5mm eps=3; sheet; 1.575mm eps=2.2; ground",
        "0.5mm eps=3; sheet; 1.575mm eps=4; ground",
        "1mm eps=3; sheet; 1.575mm eps=2.2; ground",
        "1mm eps=3; sheet; 1.575mm eps=4; ground",
    ]


@pytest.mark.parametrize(
    ("changes", "message"),
    [
        (
            {"axes": {"stack.below[1].thickness": [1.0]}},
            "axes.stack.below[1].thickness: the stack has 1 layer(s) below the sheet, so no "
            "below[1] (1.575mm eps=2.2; ground)",
        ),
        (
            {"axes": {"stack.above[0].eps_r": [2.0]}},
            "axes.stack.above[0].eps_r: the stack has 0 layer(s) above the sheet, so no above[0]",
        ),
        (
            {"axes": {"stack.below[0].eps": [2.0]}},
            "axes.stack.below[0].eps: a layer has no 'eps'; expected stack.below[0].FIELD with "
            "FIELD one of thickness, eps_r, loss_tangent, mu_r",
        ),
        (
            {"axes": {"stack.middle[0].eps_r": [2.0]}},
            "axes.stack.middle[0].eps_r: expected stack.above[i].FIELD or stack.below[i].FIELD",
        ),
        (
            {"axes": {"stack.below.thickness": [2.0]}},
            "axes.stack.below.thickness: expected a layer index after stack.below",
        ),
        (
            {"axes": {"stack.below[0].thickness": [1.0, -1.0]}},
            "axes.stack.below[0].thickness: -1.0 makes the stack invalid: Layer.thickness=-1.0 "
            "is invalid; expected a number in [0, 1e+06]",
        ),
        (
            {"axes": {"stack.below[0].thickness": [0.0]}},
            "axes.stack.below[0].thickness: 0.0 makes the stack invalid: ground=True needs a "
            "layer of non-zero thickness below the sheet",
        ),
        (
            {"axes": {"stack.below[0].eps_r": [0]}},
            "axes.stack.below[0].eps_r: 0 makes the stack invalid: Layer.eps_r=0 is invalid",
        ),
        (
            {"axes": {"stack.below[0].loss_tangent": ["0.01"]}},
            "axes.stack.below[0].loss_tangent: a string '0.01'; expected a number",
        ),
        (
            {"sample": {"latin_hypercube": 4}, "axes": {"stack.below[0].mu_r": [-1.0, 2.0]}},
            "axes.stack.below[0].mu_r: -1.0 makes the stack invalid: Layer.mu_r=-1.0",
        ),
        (
            {"stack": None, "axes": {"stack.below[0].thickness": [1.0]}},
            "axes.stack.below[0].thickness: the stack has 0 layer(s) below the sheet, so no "
            "below[0] (the spec gives no stack)",
        ),
        ({"stack": "1.575 eps=2.2"}, "stack: stack '1.575 eps=2.2': layer '1.575 eps=2.2' must"),
        ({"stack": {"below": [{"eps_r": 2.2}]}}, "stack: stack.below[0]: expected keys"),
        ({"stack": 1.575}, "stack: a number 1.575; expected the command line's text"),
        (
            {"solve": {"kind": "free_space", "frequencies": "5GHz:10GHz:3"}},
            "stack: layers need solve.kind infinite_array",
        ),
        (
            {"derive": [{"reflection_phase_at": ["11GHz"]}]},
            "derive[0].reflection_phase_at: 11 GHz is outside the solved 5-10.5 GHz",
        ),
    ],
)
def test_a_bad_stack_or_stack_axis_is_one_error_naming_the_key(changes, message):
    with pytest.raises(SpecError) as err:
        parse_spec(spec(**changes))
    assert str(err.value).startswith(f"study spec: {message}"), str(err.value)


def test_the_phase_figures_need_an_infinite_array():
    doc = {
        "base": {"params": {"structure": "patch", "patch_size": 15.0, "subdivisions": 2}},
        "axes": {"patch_size": [14.0, 15.0]},
        "solve": {"kind": "free_space", "frequencies": "6GHz:12GHz:5"},
    }
    for figure, name in (("zero_phase_frequency", "zero_phase_frequency"),) + (
        ({"reflection_phase_at": ["8GHz"]}, "reflection_phase_at"),
    ):
        with pytest.raises(SpecError, match=f"derive\\[0\\]: {name} needs solve.kind infinite"):
            parse_spec({**doc, "derive": [figure]})


# -- the figures -------------------------------------------------------------------------------


def test_the_zero_phase_frequency_of_a_grounded_slab_is_its_quarter_wave_frequency():
    # The exact reference: a grounded slab with no metal reflects
    # Γ = (Z_d − η0)/(Z_d + η0), Z_d = j (η0/√εr) tan(k0 √εr h) at its top face; Γ = +1
    # (phase 0) where the slab is a quarter wave thick, f = c / (4 h √εr) = 32.0853 GHz
    # for 1.575 mm of εr = 2.2.
    stack = Stack(below=(Layer(1.575, 2.2),), ground=True)
    f = np.linspace(25e9, 40e9, 31)
    g = np.array([stack.reflection(x)[1] for x in f])
    exact = SPEED_OF_LIGHT / (4 * 1.575e-3 * math.sqrt(2.2))
    found, notes = zero_phase_frequency(f, np.degrees(np.angle(g)), np.abs(g))
    assert notes == ()
    # linear in phase between samples 0.5 GHz apart, where the phase falls by 28°
    assert found == pytest.approx(exact, rel=1e-3)
    # the three phases of the same slab, read back by reflection_phase
    f = np.array([5e9, 10e9, 15e9])
    phase = np.degrees(np.angle([stack.reflection(x)[0] for x in f]))
    np.testing.assert_allclose(
        reflection_phase(f, phase, f), [160.879, 140.476, 117.339], atol=1e-3
    )
    # over 5-15 GHz the slab's phase stays between +117° and +161°: NaN, and why
    value, notes = zero_phase_frequency(f, phase, np.ones(3))
    assert math.isnan(value)
    assert notes == (
        "zero phase: the phase of R_co does not pass through 0 over 5-15 GHz (it stays "
        "between +117.3° and +160.9°); zero_phase_frequency_hz is NaN",
    )


def test_the_zero_phase_frequency_skips_the_180_degree_wrap_and_names_further_passages():
    f = np.array([1.0, 2.0, 3.0, 4.0, 5.0, 6.0]) * 1e9
    # from +170° the phase wraps to −170° (not a zero), comes back up through 0 at 4.8 GHz
    # and falls through it again at 5.25 GHz
    phase = np.array([150.0, 170.0, -170.0, -40.0, 10.0, -30.0])
    value, notes = zero_phase_frequency(f, phase, np.ones(6))
    assert value == pytest.approx(4.8e9, rel=1e-12)
    assert notes == (
        "zero phase: the phase of R_co passes through 0 2 times over 1-6 GHz, at 4.8 GHz "
        "(zero_phase_frequency_hz, the lowest) and also at 5.25 GHz",
    )
    # where |R| is below the floor (no reflection), its phase is not read
    value, notes = zero_phase_frequency(f, phase, np.full(6, 1e-4))
    assert math.isnan(value) and notes[0].startswith("zero phase: |R_co| is below 0.001")
    # from +100° to −100° the shorter way is through 180°, but the step is too long to be sure
    value, notes = zero_phase_frequency(f[:2], np.array([100.0, -100.0]), np.ones(2))
    assert math.isnan(value) and notes[0].endswith(
        "zero_phase_frequency_hz is NaN, but it moves by up to 160° from one sample to the "
        "next, too far to tell which way it went: sample more finely"
    )
    # the phase between samples goes the shorter way round: 170° to −170° passes 180°
    np.testing.assert_allclose(reflection_phase(f, phase, [2.5e9, 2.25e9]), [180.0, 175.0])


# -- a study on layers ---------------------------------------------------------------------------


def test_a_stack_study_records_the_reference_plane_the_loss_and_equals_direct_solves(tmp_path):
    # layers on both sides: R is referred to the top face, above[0].thickness over the sheet
    s = parse_spec(
        spec(
            stack="0.5mm eps=3; sheet; 1.575mm eps=2.2; ground",
            axes={"stack.above[0].thickness": [0.5, 1.0], "stack.below[0].loss_tangent": [0, 0.05]},
            solve={
                "kind": "infinite_array",
                "frequencies": ["6GHz", "8GHz", "9GHz"],
                "interpolate": False,
            },
            derive=[{"reflection_phase_at": ["8GHz"]}, {"reflection_at": ["8GHz"]}],
            output=str(tmp_path / "layers.parquet"),
        )
    )
    result = run_serial(s)
    d = result.derived
    assert (d.status == "ok").all(), d.status.tolist()
    assert list(d.columns) == [
        "stack.above[0].thickness",
        "stack.below[0].loss_tangent",
        "status",
        "reflection_co_phase_deg_at_8GHz",
        "reflection_co_abs_at_8GHz",
        "reflection_reference_plane_mm",
        "warnings",
    ]
    assert d.reflection_reference_plane_mm.tolist() == [0.5, 0.5, 1.0, 1.0]
    mesh = his_mesh()
    for _, row in d.iterrows():
        stack = Stack(
            (Layer(row["stack.above[0].thickness"], 3.0),),
            (Layer(1.575, 2.2, row["stack.below[0].loss_tangent"]),),
            ground=True,
        )
        direct = periodic_solve(mesh, 8e9, TM, stack=stack)
        assert direct.reference_planes == (row.reflection_reference_plane_mm, -1.575)
        assert row["reflection_co_phase_deg_at_8GHz"] == pytest.approx(co_phase(direct), abs=1e-9)
        assert row["reflection_co_abs_at_8GHz"] == pytest.approx(
            abs(direct.co_polar()[0]), abs=1e-9
        )
    # over a ground plane all the power comes back in the (0, 0) order (TE and TM: the
    # mesh's diagonals turn a little of it), less what the lossy layer absorbs
    t = result.table
    power = sum(t[f"reflection_{p}_{c}"] ** 2 for p in ("te", "tm") for c in ("real", "imag"))
    np.testing.assert_allclose(power, 1.0 - t.absorption, atol=1e-12)
    lossless = t["stack.below[0].loss_tangent"] == 0
    assert (t.absorption[lossless].abs() < 1e-3).all()
    assert (t.absorption[~lossless] > 0.02).all()
    assert set(result.table.columns) == set(s.axis_names) | set(INFINITE_ARRAY_COLUMNS)

    # resumed: the parts give back every point with its warnings, nothing is solved again
    again = run_serial(s)
    assert again.computed == 0 and again.meta["resumed"] == 4
    assert again.derived.equals(result.derived)
    # a part written by a barymesh without the phase column is solved again
    part = parts_folder(s, s.output) / "point-0000002.parquet"
    old = pq.read_table(part)
    record = json.loads(old.schema.metadata[PART_KEY])
    del record["warnings"]
    pq.write_table(
        old.drop(["reflection_co_phase_deg"]).replace_schema_metadata(
            {PART_KEY: json.dumps(record).encode()}
        ),
        part,
    )
    third = run_serial(s)
    assert third.computed == 1 and third.meta["resumed"] == 3
    assert third.derived.equals(result.derived)
    assert read_result(s.output).derived.equals(result.derived)


pytest.importorskip("distributed")


@pytest.fixture(scope="module")
def his_study(tmp_path_factory):
    """A 3 x 2 study of the patch HIS on a 2-worker LocalCluster: substrate thickness x εr,
    6.5-10.5 GHz in steps of 0.5 GHz."""
    import distributed

    out = tmp_path_factory.mktemp("his") / "his.parquet"
    s = parse_spec(
        spec(
            axes={"stack.below[0].thickness": [1.5, 2.0, 2.5], "stack.below[0].eps_r": [2.2, 3.0]},
            solve={"kind": "infinite_array", "frequencies": "6.5GHz:10.5GHz:9"},
            derive=["zero_phase_frequency", {"reflection_phase_at": ["6.5GHz", "7.25GHz"]}],
            output=str(out),
        )
    )
    with (
        distributed.LocalCluster(
            n_workers=2,
            threads_per_worker=1,
            processes=True,
            host="127.0.0.1",
            dashboard_address="127.0.0.1:0",
        ) as cluster,
        distributed.Client(cluster) as client,
    ):
        result = run(s, client=client)
    return s, result


def test_the_zero_phase_frequency_falls_as_the_substrate_thickens_or_its_eps_r_grows(his_study):
    _, result = his_study
    d = result.derived
    assert (d.status == "ok").all(), d.status.tolist()
    f0 = d.pivot(
        index="stack.below[0].thickness",
        columns="stack.below[0].eps_r",
        values="zero_phase_frequency_hz",
    )
    assert f0.notna().all().all() and (f0 > 7e9).all().all() and (f0 < 10.5e9).all().all()
    # a thicker substrate (more inductance) or a larger εr (more capacitance): lower
    assert (np.diff(f0.to_numpy(), axis=0) < -0.3e9).all()
    assert (np.diff(f0.to_numpy(), axis=1) < -0.3e9).all()
    # the table of docs/study.rst ("A study on a substrate")
    np.testing.assert_allclose(
        f0.to_numpy() / 1e9, [[9.99, 8.79], [9.10, 8.03], [8.30, 7.34]], atol=0.006
    )
    np.testing.assert_allclose(
        d["reflection_co_phase_deg_at_7.25GHz"], [132.8, 115.9, 104.7, 67.7, 67.1, 8.0], atol=0.06
    )
    # the figure is a zero of the solver's phase: a direct solve there is within 0.5° of 0
    mesh = his_mesh()
    for (h, eps), f in f0.stack().items():
        direct = periodic_solve(mesh, f, TM, stack=Stack(below=(Layer(h, eps),), ground=True))
        assert abs(co_phase(direct)) < 0.5, (h, eps, co_phase(direct))
    # R is referred to the sheet itself: nothing above it
    assert (d.reflection_reference_plane_mm == 0.0).all()


def test_the_recorded_phase_equals_a_direct_solve_on_the_same_stack(his_study):
    _, result = his_study
    mesh = his_mesh()
    for _, row in result.derived.iterrows():
        stack = Stack(
            below=(Layer(row["stack.below[0].thickness"], row["stack.below[0].eps_r"]),),
            ground=True,
        )
        direct = periodic_solve(mesh, 6.5e9, TM, stack=stack)  # the band's end: solved
        assert row["reflection_co_phase_deg_at_6.5GHz"] == pytest.approx(co_phase(direct), abs=1e-9)
    # off the grid (7.25 GHz) the phase lies between its neighbours' (7 and 7.5 GHz)
    t = result.table.reset_index().set_index(["point", "frequency_hz"]).reflection_co_phase_deg
    for point, row in result.derived.iterrows():
        a, b = t[(point, 7e9)], t[(point, 7.5e9)]
        assert min(a, b) < row["reflection_co_phase_deg_at_7.25GHz"] < max(a, b)


def test_each_point_records_its_sweep_s_warnings_and_the_cli_sums_them_up(his_study):
    s, result = his_study
    d = result.derived
    mesh = his_mesh()
    freqs = np.array(s.solve.frequencies)
    # the 8 mm patch at n = 6 has edges of 1.89 mm: more than λ/10 in εr = 3 above 9.2 GHz
    # (the band reaches 10.5 GHz), less in εr = 2.2 up to 10.7 GHz
    for point in (0, 1):
        row = d.loc[point]
        stack = Stack(
            below=(Layer(row["stack.below[0].thickness"], row["stack.below[0].eps_r"]),),
            ground=True,
        )
        direct = periodic_sweep(mesh, freqs, TM, polarizations="incident", stack=stack)
        assert row.warnings == "\n".join(direct.warnings)
    coarse = d.warnings.str.startswith("coarse mesh: edges up to 1.89 mm")
    assert coarse.tolist() == (d["stack.below[0].eps_r"] == 3.0).tolist()
    assert result.warning_kinds() == {"coarse mesh": [1, 3, 5]}
    lines = warning_lines(result)
    assert lines[0] == "  warnings on 3 of 6 points (the derived table's warnings column):"
    assert lines[1].startswith("    coarse mesh (points 1, 3, 5): edges up to 1.89 mm, over a")
    assert lines[1].endswith("(point 1)") and len(lines) == 2
    # the files keep them, and so do the xarray's points
    back = read_result(s.output)
    assert back.derived.warnings.tolist() == d.warnings.tolist()
    ds = result.to_xarray()
    assert ds.warnings.dims == ("stack.below[0].thickness", "stack.below[0].eps_r")
    assert ds.warnings.values[0, 1].startswith("coarse mesh") and ds.warnings.values[0, 0] == ""


def test_barymesh_study_names_the_stack_and_sums_up_the_warnings(tmp_path, monkeypatch, capsys):
    from barymesh.app import cli

    monkeypatch.chdir(tmp_path)
    doc = spec(
        axes={"stack.below[0].eps_r": [2.2, 3.0]},
        solve={
            "kind": "infinite_array",
            "frequencies": ["6.5GHz", "10.5GHz"],
            "interpolate": False,
        },
        derive=["zero_phase_frequency"],
    )
    (tmp_path / "his.json").write_text(json.dumps(doc))
    assert cli.main(["study", "his.json", "--threads", "--workers", "1", "-o", "his.csv"]) == 0
    out = capsys.readouterr().out
    lines = out.splitlines()
    assert lines[1] == "  on the stack 1.575mm eps=2.2; ground"
    assert "2 points: 2 ok, 0 failed; 2 solved now" in out
    assert "  warnings on 2 of 2 points (the derived table's warnings column):" in lines
    # two samples 4 GHz apart: the phase moves by more than 180° between them, so whether
    # it passed through 0 cannot be told (the note says so, both points); and εr = 3 at
    # 10.5 GHz has the mesh coarse (point 1 only)
    zero = [x for x in lines if x.startswith("    zero phase (points 0, 1): the phase of R_co")]
    assert len(zero) == 1 and "sample more finely (point 0)" in zero[0], out
    coarse = [x for x in lines if x.startswith("    coarse mesh (point 1): edges up to 1.89 mm")]
    assert len(coarse) == 1, out
    derived = read_result(tmp_path / "his.csv").derived
    assert derived.warnings[1].startswith("coarse mesh: edges up to 1.89 mm")
    # a bad stack axis: one line naming the key, exit 1
    (tmp_path / "bad.json").write_text(json.dumps(spec(axes={"stack.below[2].eps_r": [3.0]})))
    assert cli.main(["study", "bad.json"]) == 1
    err = capsys.readouterr().err.strip()
    assert err.endswith(
        "study spec: axes.stack.below[2].eps_r: the stack has 1 layer(s) below the sheet, so no "
        "below[2] (1.575mm eps=2.2; ground)"
    ), err
    assert len(err.splitlines()) == 1
