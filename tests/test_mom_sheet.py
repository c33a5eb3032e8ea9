"""Resistive and lossy surfaces: sheet_impedance= on solve and sweep.

Energy, not numbers the code printed: with E_tan = Z_s J on the surface, the power the
wave loses (extinction, from the currents) is the power scattered (the far field over the
sphere) plus the power the sheet dissipates (½ Re Z_s ∫|J|², from the Gram matrix); a
purely reactive sheet dissipates nothing; and Z_s → 0 is the perfect conductor.
"""

from __future__ import annotations

import numpy as np
import pytest

from barymesh import build_mesh
from barymesh.mom import PlaneWave, mom_geometry, solve, sweep
from barymesh.mom.operator import gram_matrix
from barymesh.presets import load_preset


@pytest.fixture(scope="module")
def plate():
    params, _ = load_preset("makarov-plate")
    return build_mesh(params)


WAVE = PlaneWave.from_angles(30, 20, 0)


@pytest.mark.parametrize("zs", [20.0, 100 + 50j, 377.0])
def test_extinction_is_scattering_plus_ohmic_loss(plate, zs):
    s = solve(plate, 300e6, WAVE, sheet_impedance=zs)
    ohmic = s.ohmic_power / s._incident_intensity
    assert ohmic > 0.05 * s.extinction_cross_section  # a real loss, not a rounding error
    assert abs(s.absorption_cross_section - ohmic) < 2e-3 * s.extinction_cross_section


def test_a_reactive_sheet_dissipates_nothing(plate):
    s = solve(plate, 300e6, WAVE, sheet_impedance=80j)
    assert s.ohmic_power == 0.0
    assert abs(s.absorption_cross_section) < 2e-3 * s.extinction_cross_section
    pec = solve(plate, 300e6, WAVE)
    assert abs(s.extinction_cross_section - pec.extinction_cross_section) > 0.01 * (
        pec.extinction_cross_section
    )  # the reactance changed the answer


def test_a_tiny_impedance_is_the_perfect_conductor(plate):
    pec = solve(plate, 300e6, WAVE)
    almost = solve(plate, 300e6, WAVE, sheet_impedance=1e-9)
    assert np.allclose(almost.coefficients, pec.coefficients, rtol=1e-6, atol=1e-12)


def test_the_gram_matrix_integrates_f_m_dot_f_n(plate):
    # symmetric, positive definite, and its diagonal is ∫|f|² from a fine rule directly
    geom = mom_geometry(plate)
    gram = gram_matrix(geom).toarray()
    assert np.allclose(gram, gram.T)
    assert np.all(np.linalg.eigvalsh(gram) > 0)
    n = 7
    rule = geom.near
    tri = geom.rwg_triangles[n]
    direct = 0.0
    for side, t in enumerate(tri):
        sign = 1.0 if side == 0 else -1.0
        free = geom.triangles[t][~np.isin(geom.triangles[t], geom.triangles[tri[1 - side]])][0]
        f = (
            sign
            * geom.rwg_lengths[n]
            / (2 * geom.areas[t])
            * (rule.points[t] - geom.vertices[free])
        )
        direct += float(np.sum(rule.weights[t] * np.einsum("qc,qc->q", f, f)))
    assert gram[n, n] == pytest.approx(direct, rel=1e-12)


def test_sweep_takes_the_sheet_impedance(plate):
    result = sweep(plate, [280e6, 300e6], WAVE, sheet_impedance=50.0, scattering=False)
    single = solve(plate, 300e6, WAVE, sheet_impedance=50.0)
    assert result.extinction_cross_section[1] == pytest.approx(
        single.extinction_cross_section, rel=1e-12
    )


@pytest.mark.parametrize("bad", [-5.0, "x", True, float("inf")])
def test_a_bad_sheet_impedance_is_named(plate, bad):
    with pytest.raises(ValueError, match="sheet_impedance"):
        solve(plate, 300e6, sheet_impedance=bad)
