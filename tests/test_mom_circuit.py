"""The cell as a circuit (barymesh.mom.circuit, issue 33 §3): sheet impedance, Foster LC fit.

Checked against exact formulas (a free-standing sheet's R = −η0/(η0 + 2 Z_s), the round
trip through the stack's transmission line), against circuits of known L and C, against
the published analytic model of patches over a grounded slab (Luukkonen et al., IEEE
TAP 56(6), 2008: a 5 mm period, 0.5 mm gap, h = 1.575 mm and ε_r = 2.2 reflect with zero
phase near 11.66 GHz), and against solved infinite arrays of that patch.
"""

from __future__ import annotations

import math

import numpy as np
import pytest

from barymesh.cell import Lattice, PixelGrid, UnitCell, build_cell
from barymesh.constants import ETA0
from barymesh.mom import Layer, PlaneWave, Stack, periodic_sweep
from barymesh.mom.circuit import (
    EquivalentCircuit,
    equivalent_circuit,
    luukkonen_patch_reflection,
    reflection_from_sheet,
    sheet_impedance,
)

GROUNDED = Stack(below=(Layer(1.575, 2.2),), ground=True)
STACKS = [
    None,
    GROUNDED,
    Stack(above=(Layer(0.5, 3.0, 0.01),), below=(Layer(0.8, 4.4, 0.02),), ground=True),
    Stack(above=(Layer(0.3, 2.0),), below=(Layer(1.0, 10.2),)),
]
P = 5.0  # mm: Luukkonen et al.'s example
GAP = 0.5


def zero_phase(frequencies: np.ndarray, reflection: np.ndarray) -> float:
    """Where ∠R crosses 0 (linear between samples; the first crossing with |∠R| < 90°)."""
    phase = np.angle(reflection)
    for j in np.flatnonzero(np.diff(np.sign(phase)) != 0):
        if abs(phase[j]) < math.pi / 2:
            f0, f1 = frequencies[j], frequencies[j + 1]
            return float(f0 - phase[j] * (f1 - f0) / (phase[j + 1] - phase[j]))
    raise AssertionError("no zero-phase crossing")


def test_luukkonen_patches_reflect_with_zero_phase_at_the_published_frequency():
    f = np.linspace(10e9, 13e9, 3001)
    r = luukkonen_patch_reflection(f, P, GAP, 1.575, 2.2)
    assert np.allclose(np.abs(r), 1.0, atol=1e-12)  # lossless over a ground plane
    assert zero_phase(f, r) == pytest.approx(11.66e9, abs=0.01e9)


def test_free_standing_sheet_reflects_by_the_closed_form():
    f = np.linspace(1e9, 30e9, 7)
    z = np.array([50.0, -300j, 120 + 80j, 1e-3, 1e4j, 377.0, 20 - 5j])
    expected = -ETA0 / (ETA0 + 2.0 * z)
    assert np.allclose(reflection_from_sheet(f, z), expected, rtol=0, atol=1e-14)
    assert np.allclose(sheet_impedance(f, expected), z, rtol=1e-10)


@pytest.mark.parametrize("stack", STACKS)
@pytest.mark.parametrize(
    "wave",
    [
        PlaneWave(),
        PlaneWave.from_angles(35, 20, 0),
        PlaneWave.from_angles(35, 20, 90),
    ],
)
def test_sheet_impedance_inverts_the_line(stack, wave):
    """Z_s → R → Z_s through layers above and below, lossy ones, at oblique TE and TM."""
    f = np.linspace(2e9, 18e9, 9)
    z = 40.0 + 1j * (2 * np.pi * f * 1.2e-9 - 1.0 / (2 * np.pi * f * 60e-15))
    r = reflection_from_sheet(f, z, stack, wave)
    assert np.all(np.abs(r) <= 1.0 + 1e-12)  # a passive sheet on a passive stack
    assert np.allclose(sheet_impedance(f, r, stack, wave), z, rtol=1e-9)


def test_a_short_across_the_sheet_reflects_minus_one():
    f = np.array([5e9, 10e9])
    assert np.allclose(reflection_from_sheet(f, [0.0, 0.0], GROUNDED), -1.0)


@pytest.mark.parametrize(
    "kind, inductance, capacitance, resistance",
    [
        ("series", 2.0e-9, 50e-15, 0.0),
        ("series", 0.5e-9, 120e-15, 3.0),
        ("parallel", 3e-9, 40e-15, math.inf),
    ],
)
@pytest.mark.parametrize("stack", [None, GROUNDED])
def test_fit_recovers_a_known_circuit_and_its_kind(
    kind, inductance, capacitance, resistance, stack
):
    f = np.linspace(3e9, 30e9, 60)
    w = 2 * np.pi * f
    if kind == "series":
        z = resistance + 1j * (w * inductance - 1 / (w * capacitance))
    else:
        z = 1 / (1j * (w * capacitance - 1 / (w * inductance)))
    fit = equivalent_circuit(f, reflection_from_sheet(f, z, stack), stack)
    assert fit.kind == kind
    assert fit.inductance == pytest.approx(inductance, rel=1e-6)
    assert fit.capacitance == pytest.approx(capacitance, rel=1e-6)
    assert fit.resonance == pytest.approx(1 / (2 * np.pi * math.sqrt(inductance * capacitance)))
    if kind == "series":
        assert fit.resistance == pytest.approx(resistance, abs=1e-6)
    assert fit.error < 1e-8 and fit.valid_below == f[-1]
    assert np.allclose(fit.impedance(f), z, rtol=1e-5)


def test_bad_input_is_named():
    f = np.linspace(1e9, 10e9, 10)
    r = reflection_from_sheet(f, np.full(10, -200j))
    with pytest.raises(ValueError, match="kind='lc'"):
        equivalent_circuit(f, r, kind="lc")
    with pytest.raises(ValueError, match="start < stop"):
        equivalent_circuit(f, r, band=(5e9, 2e9))
    with pytest.raises(ValueError, match="at least 3"):
        equivalent_circuit(f, r, onsets=[2.5e9])
    with pytest.raises(ValueError, match="expected two"):
        equivalent_circuit(f, r[:5])
    with pytest.raises(ValueError, match="mix of TE"):
        sheet_impedance(f, r, None, PlaneWave.from_angles(30, 0, 45))
    with pytest.raises(ValueError, match="gap"):
        luukkonen_patch_reflection(f, 5.0, 6.0, 1.0, 2.2)


@pytest.fixture(scope="module")
def patch():
    """Luukkonen's patch: 4.5 mm of metal in a 5 mm cell (a 0.5 mm gap), 648 triangles."""
    mask = np.zeros((20, 20), dtype=bool)
    mask[1:19, 1:19] = True
    grid = PixelGrid(mask, pixel_size=P / 20, origin=(-P / 2, -P / 2), subdivisions=1)
    cell = UnitCell(lattice=Lattice.rectangular(P), pixels=grid, mode="conforming")
    return build_cell(cell).mesh


def test_solved_patches_over_a_grounded_slab_are_a_series_lc_near_luukkonen(patch):
    """The solved array's circuit reproduces its curve, and its zero-phase frequency is
    within 3 % of the analytic model's (a quasi-static grid impedance: its own error is a
    few per cent at a period of λ/5 in the slab)."""
    f = np.linspace(6e9, 16e9, 51)
    sweep = periodic_sweep(patch, f, stack=GROUNDED, polarizations="incident")
    fit = sweep.equivalent_circuit()
    assert fit.kind == "series"  # islands of metal: capacitive below resonance
    assert fit.error < 0.01 and fit.valid_below == f[-1]
    assert fit.resistance == 0.0  # perfect conductors on a lossless slab: no loss fitted
    solved = zero_phase(f, sweep.co_polar()[0])
    assert zero_phase(f, fit.reflection(f)) == pytest.approx(solved, rel=1e-3)
    assert solved == pytest.approx(11.66e9, rel=0.03)
    # the same patches in vacuum: the grid's fringing field is half in the slab, so the
    # capacitance on it is (ε_r + 1)/2 = 1.6 times that in vacuum (quasi-static)
    free = periodic_sweep(patch, np.linspace(5e9, 40e9, 36), polarizations="incident")
    vacuum = free.equivalent_circuit()
    assert vacuum.kind == "series"
    assert fit.capacitance / vacuum.capacitance == pytest.approx(1.6, rel=0.05)


@pytest.mark.parametrize("kind", ["series", "parallel"])
def test_a_resonance_on_a_sample_is_fitted_quietly(kind, capfd):
    # a lossless sheet sampled exactly at its resonance: a short (series, Z = 0, R = -1)
    # or an open sheet (parallel, Z infinite). The other kind's linear fit saw an infinite
    # row there; LAPACK printed "On entry to DLASCL parameter number 4 had an illegal
    # value" and the series fit was refused ("SVD did not converge")
    f = np.linspace(5e9, 15e9, 11)
    inductance, f0 = 1e-9, 10e9
    capacitance = 1.0 / ((2 * math.pi * f0) ** 2 * inductance)
    r_loss = 0.0 if kind == "series" else math.inf
    circuit = EquivalentCircuit(kind, inductance, capacitance, r_loss, (5e9, 15e9), 0.0, 15e9)
    r = circuit.reflection(f)
    assert np.all(np.isfinite(r))
    assert r[5] == (-1.0 if kind == "series" else 0.0)
    fit = equivalent_circuit(f, r)
    assert fit.kind == kind
    assert fit.inductance == pytest.approx(inductance, rel=1e-9)
    assert fit.capacitance == pytest.approx(capacitance, rel=1e-9)
    assert fit.resonance == pytest.approx(f0, rel=1e-9)
    out, err = capfd.readouterr()
    assert "DLASCL" not in out + err and err == ""
