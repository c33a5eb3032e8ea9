"""What edge grading is for: |R| converging to references, on the infinite-array solver.

References: the 1-D spectral-domain solution of the strip grating (``tests/strip_spectral.py``,
free-standing), checked here against Collin's table and Marcuvitz's quasi-static formulas;
for patches the
Richardson extrapolation measured by ``benchmarks/convergence.py`` (whose ``--quick`` run is
checked here too).
"""

from __future__ import annotations

import numpy as np
import pytest
from strip_spectral import marcuvitz_reflection, strip_reflection

from barymesh import MeshParams
from barymesh.cell import Element, Lattice, UnitCell, build_cell
from barymesh.constants import SPEED_OF_LIGHT
from barymesh.mom import PlaneWave, periodic_solve, periodic_solve_many

P = 10.0  # mm
#: Collin, Field Theory of Guided Waves, problem 10.6: strips of width P/2 at normal
#: incidence, P/λ -> (|Γ⊥|, ∠Γ⊥ in degrees, |Γ∥|), E across / along the strips.
COLLIN = {
    0.1: (0.0694, -94.0, 0.9976),
    0.3: (0.2106, -102.2, 0.9776),
    0.5: (0.3598, -111.1, 0.9330),
    0.8: (0.6231, -128.5, 0.7822),
    0.9: (0.7381, -137.6, 0.6747),
}


def frequency(p_over_lambda):
    return p_over_lambda * SPEED_OF_LIGHT / (P * 1e-3)


def free_strips(f, polarization, theta=0.0, **options):
    """The spectral solution for free-standing strips of width P/2 (εr = 1, no ground);
    ``polarization`` "along" (TE) or "across" (TM) the strips."""
    pol = {"along": "te", "across": "tm"}[polarization]
    return strip_reflection(f, P, P / 2, 1.0, 1.0, False, pol, theta, **options)


@pytest.mark.parametrize("ratio", sorted(COLLIN))
def test_the_spectral_strip_solution_reproduces_collin_s_table(ratio):
    magnitude, phase, parallel = COLLIN[ratio]
    across = free_strips(frequency(ratio), "across")
    along = free_strips(frequency(ratio), "along")
    assert abs(abs(across) - magnitude) < 6e-5  # the table's four digits
    assert abs(np.degrees(np.angle(across)) - phase) < 0.05
    assert abs(abs(along) - parallel) < 6e-5


def test_the_spectral_solution_has_converged_in_its_basis_and_harmonics():
    for theta in (0.0, 30.0, 60.0):
        for pol in ("along", "across"):
            a = free_strips(20e9, pol, theta)
            b = free_strips(20e9, pol, theta, basis=14, terms=80_000)
            assert abs(a - b) < 1e-6


@pytest.mark.parametrize("ratio", [0.02, 0.05, 0.1])
def test_the_spectral_solution_meets_marcuvitz_in_the_quasi_static_range(ratio):
    for pol in ("along", "across"):
        exact = free_strips(frequency(ratio), pol)
        quasi = marcuvitz_reflection(frequency(ratio), P, P / 2, {"along": "te"}.get(pol, "tm"))
        assert abs(abs(exact) - abs(quasi)) < 0.02 * abs(exact) * ratio / 0.1 + 1e-4
        assert abs(np.degrees(np.angle(exact / quasi))) < 1.0


def strip_cell(n, graded):
    params = MeshParams(
        structure="patch", patch_size=P / 2, patch_width=P, subdivisions=n, grading=graded
    )
    cell = UnitCell(Lattice.rectangular(P), (Element(params, position=(-P / 4, -P / 2)),))
    return build_cell(cell).mesh


def test_a_graded_strip_grating_meets_the_spectral_solution_where_uniform_strips_do_not():
    """Strips of width P/2 across the cell (a patch element 5 x 10 mm reaching both sides,
    graded across only) at 30° in the plane across the strips, E along and across them, at
    P/λ = 0.3 and 0.6 (below the (-1) order's onset there, P/λ = 2/3), n = 8: 180
    unknowns."""
    graded, uniform = strip_cell(8, True), strip_cell(8, False)
    te, tm = PlaneWave.from_angles(30, 0, 90), PlaneWave.from_angles(30, 0, 0)
    worst = {True: 0.0, False: 0.0}
    for f in (frequency(0.3), frequency(0.6)):
        for mesh, key in ((graded, True), (uniform, False)):
            s_te, s_tm = periodic_solve_many(mesh, f, [te, tm])
            for pol, s in (("along", s_te), ("across", s_tm)):
                ref = free_strips(f, pol, 30.0)
                worst[key] = max(worst[key], abs(abs(s.co_polar()[0]) - abs(ref)))
    assert worst[True] < 0.005 < worst[False]
    assert worst[True] < worst[False] / 3


#: |R| and ∠R of the 5 mm patch in a 10 mm cell at 20 GHz, normal incidence: Richardson
#: extrapolation of the graded n = 24, 28, 32 (benchmarks/convergence.py, first_order, in
#: benchmarks/results/convergence-*.json; the uniform series extrapolated at first order
#: agrees within its own uncertainty).
REFERENCE_ABS_R = 0.42329


def test_a_graded_patch_converges_ahead_of_the_uniform_one():
    def r(n, graded):
        params = MeshParams(structure="patch", patch_size=5.0, subdivisions=n, grading=graded)
        cell = UnitCell(Lattice.rectangular(10.0), (Element(params, position=(-2.5, -2.5)),))
        return abs(periodic_solve(build_cell(cell).mesh, 20e9, PlaneWave()).co_polar()[0])

    uniform = [abs(r(n, False) - REFERENCE_ABS_R) for n in (6, 12)]
    graded = [abs(r(n, True) - REFERENCE_ABS_R) for n in (6, 12)]
    # uniform: first order (halving h halves the error), well off at 408 unknowns
    assert 1.6 < uniform[0] / uniform[1] < 2.4 and uniform[1] > 0.01
    # graded: within the 0.005 at 408 unknowns, 5 times closer than uniform
    assert graded[1] < 0.0025 and graded[1] < uniform[1] / 5
    # at n = 6 already 2.95 times closer (0.0086 against 0.0254; 3.2 times before the
    # near pairs' closed form was taken with the smaller triangle outside, whose error
    # had made up part of the coarse graded mesh's)
    assert graded[0] < uniform[0] / 2.5


def test_the_convergence_benchmark_runs_quick(tmp_path):
    from benchmark_runs import run_quick

    doc = run_quick("convergence.py", tmp_path)
    assert doc["targets"] == {"abs_r": 0.005, "phase_deg": 0.5, "unknowns": 1000}
    checks = {c["p_over_lambda"]: c for c in doc["strips"]["spectral_checks"]}
    for ratio, (magnitude, phase, parallel) in COLLIN.items():
        assert abs(checks[ratio]["across_abs"] - magnitude) < 6e-5
        assert abs(checks[ratio]["across_phase_deg"] - phase) < 0.05
        assert abs(checks[ratio]["along_abs"] - parallel) < 6e-5
    (strips,) = doc["strips"]["rows"]
    assert strips["series"] == "graded" and strips["max_abs_r_error"] < 0.005
    first = {(r["series"], r["subdivisions"]): r for r in doc["first_order"]["rows"]}
    # uniform n = 4 -> 8 halves the error (first order); graded n = 8 is 5 times closer
    assert 1.6 < first["uniform", 4]["abs_r_error"] / first["uniform", 8]["abs_r_error"] < 2.4
    assert first["graded", 8]["abs_r_error"] < first["uniform", 8]["abs_r_error"] / 5
    patch = {(r["series"], r["subdivisions"]): r for r in doc["patch"]["rows"]}
    assert patch["graded", 16]["meets_target"] and not patch["uniform", 12]["meets_target"]
    babinet = {r["series"]: r["babinet_error"] for r in doc["babinet"]["rows"]}
    assert babinet["graded"] < babinet["uniform"]
