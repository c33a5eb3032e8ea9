"""The infinite array's frequency sweeps: the interpolating sweep against solves.

- The interpolating (AAA) sweep of a dipole array over 5–40 GHz, 651 frequencies, equals
  point-by-point solves within 1e-3 in |R| and 1° in phase, at frequencies it did not
  solve, below and above the grating lobe; it costs tens of solves, not 651; it has a
  sample just below and just above the onset; its resonance is total reflection.
- Grating-lobe onsets by hand: c/P at normal incidence, c/(P (1 + sin θ)) at 30°.
- A sheet impedance: the absorption from the coefficients equals the solver's ½ Re Z_s ∫|J|².
- Bad input is named in one line.
"""

from __future__ import annotations

import importlib
import math
import threading

import numpy as np
import pytest

from barymesh import MeshParams, build_mesh
from barymesh.cell import Lattice, PixelGrid, UnitCell, build_cell
from barymesh.constants import SPEED_OF_LIGHT
from barymesh.mom import (
    PlaneWave,
    SolveCancelled,
    grating_lobe_onsets,
    periodic_solve,
    periodic_sweep,
    te_tm_polarizations,
)
from barymesh.mom.periodic_sweep import ONSET_OFFSET

sweep_module = importlib.import_module("barymesh.mom.periodic_sweep")  # beside the function

P = 10.0  # mm
BAND = np.linspace(5e9, 40e9, 651)
ALONG = PlaneWave(polarization=(0, 1, 0))  # E along the dipoles


def pixel_cell(mask: np.ndarray) -> object:
    pixels = PixelGrid(mask, pixel_size=P / len(mask), origin=(-P / 2, -P / 2), subdivisions=1)
    cell = UnitCell(lattice=Lattice.rectangular(P), pixels=pixels, mode="conforming")
    return build_cell(cell).mesh


@pytest.fixture(scope="module")
def dipoles():
    """7.5 × 2.5 mm strips along y in a 10 mm cell: 24 triangles, resonant near 19 GHz."""
    mask = np.zeros((8, 8), dtype=bool)
    mask[1:7, 3:5] = True
    return pixel_cell(mask)


@pytest.fixture(scope="module")
def curve(dipoles):
    calls = []
    sweep = periodic_sweep(
        dipoles, BAND, ALONG, polarizations="incident", progress=lambda d, t: calls.append((d, t))
    )
    return sweep, calls


def test_the_interpolating_sweep_equals_point_by_point_solves(dipoles, curve):
    sweep, _ = curve
    onset = SPEED_OF_LIGHT / (P * 1e-3)
    # requested frequencies the sweep did not solve, away from the Wood anomaly
    picks = [8e9, 15e9, 19.5e9, 24e9, 28e9, 33e9, 38.5e9]
    index = [int(np.argmin(np.abs(BAND - f))) for f in picks]
    index = [i if BAND[i] not in sweep.sampled else i + 1 for i in index]
    assert not np.isin(BAND[index], sweep.sampled).any()
    assert min(abs(BAND[index] - onset)) > 0.02 * onset
    exact = periodic_sweep(dipoles, BAND[index], ALONG, interpolate=False, polarizations="incident")
    assert exact.n_solves == len(index)
    for fitted, solved in zip((c[index] for c in sweep.co_polar()), exact.co_polar(), strict=True):
        assert np.abs(np.abs(fitted) - np.abs(solved)).max() < 1e-3
        assert np.degrees(np.abs(np.angle(fitted / solved))).max() < 1.0
    assert np.abs(sweep.reflection[index] - exact.reflection).max() < 1e-3
    # the error estimate bounds the real error there
    real = np.abs(sweep.reflection[index] - exact.reflection).max(axis=1)
    assert np.all(real <= sweep.error_estimate[index])
    assert sweep.error_estimate.max() < 1e-3


def test_a_651_point_curve_costs_tens_of_solves(curve):
    sweep, calls = curve
    assert sweep.interpolated
    assert 10 <= sweep.n_solves <= 40, sweep.n_solves
    assert len(sweep.sampled) == sweep.n_solves
    assert [d for d, _ in calls[: sweep.n_solves]] == list(range(1, sweep.n_solves + 1))
    assert calls[-1][0] == calls[-1][1]  # the last report completes the bar
    assert sweep.reflection.shape == (651, 2)
    assert sweep.order_reflection.shape == (651, len(sweep.orders), 2, 1)


def test_a_sample_lies_just_below_and_above_the_onset(curve):
    sweep, _ = curve
    onset = SPEED_OF_LIGHT / (P * 1e-3)
    assert sweep.grating_lobe_onsets == pytest.approx([onset], rel=1e-12)
    gap = np.abs(sweep.sampled / onset - 1)
    at = np.isclose(gap, ONSET_OFFSET, rtol=1e-6)  # onset × (1 ± ONSET_OFFSET)
    assert np.count_nonzero(at) == 2
    assert np.any(at & (sweep.sampled < onset)) and np.any(at & (sweep.sampled > onset))
    # below the onset only (0, 0) propagates, above it the four first orders too
    below, above = BAND < onset, BAND > onset
    assert np.all(sweep.propagating[below].sum(axis=1) == 1)
    assert np.all(sweep.propagating[above].sum(axis=1) == 5)
    assert np.all(np.isnan(sweep.order_reflection[below, 1:]))
    assert np.all(np.isfinite(sweep.order_reflection[above, :5]))
    # every order's power, fitted: the lossless screen's balance holds at every frequency,
    # to the 1e-3 on this 24-triangle cell (the fill's Taylor expansion of the smooth
    # part of G_p is third order in the mesh: 1.4e-4 here, next to the onset; its fall with
    # the mesh is test_mom_periodic_validation's)
    assert np.abs(sweep.absorption).max() < 1e-3


def test_the_resonance_is_total_reflection(dipoles, curve):
    sweep, _ = curve
    peaks = [
        f for f, kind in zip(sweep.resonances, sweep.resonance_kinds, strict=True) if kind == "peak"
    ]
    assert len(peaks) == 1 and 15e9 < peaks[0] < 25e9
    # a lossless screen with one propagating order: |R| = 1 exactly where T = 1 + R = 0
    r, t = periodic_solve(dipoles, peaks[0], ALONG).co_polar()
    assert abs(r) > 0.999
    assert abs(t) < 0.01
    q = sweep.quality_factors[sweep.resonances == peaks[0]][0]
    assert 1.0 < q < 20.0  # a broad, radiating resonance


def test_grating_lobe_onsets_by_hand():
    c = SPEED_OF_LIGHT
    square = Lattice.rectangular(P)
    assert grating_lobe_onsets(square, f_max=40e9) == pytest.approx([c / 10e-3], rel=1e-12)
    theta = math.radians(30)
    oblique = grating_lobe_onsets(square, PlaneWave.from_angles(30, 0), f_max=35e9)
    # (1, 0) first, then (1, ±1): |k u + G| = k solved by hand, then (0, ±1) at c/(P cos θ)
    g = 2 * math.pi / 10e-3
    k11 = (-0.5 * g + math.sqrt(0.25 * g * g + 0.75 * 2 * g * g)) / 0.75
    expected = [
        c / (10e-3 * (1 + math.sin(theta))),
        k11 * c / (2 * math.pi),
        c / (10e-3 * math.cos(theta)),
    ]
    assert oblique == pytest.approx(expected, rel=1e-12)
    assert oblique[0] == pytest.approx(19.986e9, abs=1e6)
    # a rectangular lattice, 10 × 15 mm: c/15 mm, c/10 mm, the diagonal c |(1/10, 1/15)|,
    # then (0, ±2) at 2c/15 mm
    rect = grating_lobe_onsets(Lattice.rectangular(10.0, 15.0), f_max=40e9)
    assert rect == pytest.approx(
        [c / 15e-3, c / 10e-3, c * math.hypot(1 / 10e-3, 1 / 15e-3), 2 * c / 15e-3]
    )
    # the same direction and any other polarisation: the same onsets
    assert np.array_equal(
        grating_lobe_onsets(square, PlaneWave.from_angles(30, 0, 90), f_max=35e9), oblique
    )


def test_te_and_tm_polarizations_are_the_solvers(dipoles):
    wave = PlaneWave.from_angles(30, 40, 25)
    basis = te_tm_polarizations(wave.direction)
    assert np.allclose(basis @ basis.T, np.eye(2))
    assert np.allclose(basis @ wave.direction, 0)
    both = periodic_sweep(dipoles, [12e9], wave, interpolate=False)
    assert both.both_polarizations and both.order_reflection.shape[-1] == 2
    s = periodic_solve(dipoles, 12e9, wave)
    assert np.allclose(both.incident_te_tm, s.incident_te_tm)
    # the incidence's response is the TE/TM pair's combination
    assert np.abs(both.reflection[0] - s.reflection[0]).max() < 1e-9
    assert np.abs(both.transmission[0] - s.transmission[0]).max() < 1e-9
    assert abs(both.co_polar()[0][0] - s.co_polar()[0]) < 1e-9


def test_a_sheet_impedance_absorbs_what_the_solver_dissipates(dipoles):
    frequencies = [12e9, 19e9]
    sweep = periodic_sweep(
        dipoles,
        frequencies,
        ALONG,
        interpolate=False,
        polarizations="incident",
        sheet_impedance=50 + 10j,
    )
    for f, absorbed in zip(frequencies, sweep.absorption, strict=True):
        s = periodic_solve(dipoles, f, ALONG, sheet_impedance=50 + 10j)
        assert s.absorption > 0.05
        assert absorbed == pytest.approx(s.absorption, abs=1e-4)


def test_bad_input_is_named(dipoles):
    patch = build_mesh(MeshParams(structure="patch", patch_size=8.0, subdivisions=2))
    with pytest.raises(ValueError, match="no lattice"):
        periodic_sweep(patch, BAND)
    mask = np.zeros((8, 8), dtype=bool)
    mask[2:5, 0] = True  # metal on the left side of the cell, nothing on the right
    with pytest.raises(ValueError, match="no matching edge on the opposite side"):
        periodic_sweep(pixel_cell(mask), BAND)
    for bad, match in [([], "empty"), ([2e9, 1e9], "increasing"), ([-1.0], "frequencies")]:
        with pytest.raises(ValueError, match=match):
            periodic_sweep(dipoles, bad)
    with pytest.raises(ValueError, match="polarizations"):
        periodic_sweep(dipoles, BAND, polarizations="te")
    with pytest.raises(ValueError, match="tolerance"):
        periodic_sweep(dipoles, BAND, tolerance=0)
    with pytest.raises(ValueError, match="along the screen"):
        periodic_sweep(dipoles, BAND, PlaneWave(direction=(1, 0, 0), polarization=(0, 1, 0)))
    with pytest.raises(ValueError, match="Wood anomaly"):
        periodic_sweep(dipoles, [SPEED_OF_LIGHT / (P * 1e-3)], interpolate=False)
    with pytest.raises(SolveCancelled):
        periodic_sweep(dipoles, BAND, cancel=lambda: True)


# -- the overlapped solves ---------------------------------------------------------------


@pytest.fixture
def solve_threads(monkeypatch):
    """The names of the threads that ran each sweep solve (LU and amplitudes)."""
    names: list[str] = []
    real = sweep_module.solve_system

    def recording(system, waves):
        names.append(threading.current_thread().name)
        return real(system, waves)

    monkeypatch.setattr(sweep_module, "solve_system", recording)
    return names


def test_overlapped_solves_equal_solves_one_after_another(dipoles, solve_threads, monkeypatch):
    # each frequency's LU runs in the worker while the next one is filled; the values are
    # those of the solves one after another, to the refinement's floor
    band = np.linspace(8e9, 26e9, 7)
    overlapped = periodic_sweep(dipoles, band, ALONG, interpolate=False)
    assert len(solve_threads) == 7
    assert all(name.startswith("barymesh-sweep") for name in solve_threads)
    monkeypatch.setattr(sweep_module, "OVERLAP", False)
    solve_threads.clear()
    serial = periodic_sweep(dipoles, band, ALONG, interpolate=False)
    assert solve_threads == [threading.main_thread().name] * 7
    np.testing.assert_allclose(
        overlapped.order_reflection[:, 0], serial.order_reflection[:, 0], rtol=0, atol=1e-12
    )
    np.testing.assert_array_equal(overlapped.sampled, serial.sampled)


def test_without_memory_for_a_second_matrix_the_solves_run_one_after_another(
    dipoles, solve_threads, monkeypatch
):
    monkeypatch.setattr(sweep_module, "OVERLAP_BYTES_PER_N2", 1e15)  # no second matrix fits
    sweep = periodic_sweep(dipoles, np.linspace(8e9, 26e9, 3), ALONG, interpolate=False)
    assert sweep.n_solves == 3
    assert solve_threads == [threading.main_thread().name] * 3


def test_a_cancelled_or_failed_overlapped_sweep_leaves_no_thread_behind(dipoles, monkeypatch):
    asked = []

    def cancel_third() -> bool:
        asked.append(1)
        return len(asked) >= 3

    with pytest.raises(SolveCancelled, match="after 1 frequencies"):
        periodic_sweep(dipoles, BAND, ALONG, cancel=cancel_third)
    assert not [t for t in threading.enumerate() if t.name.startswith("barymesh-sweep")]

    def failing(system, waves):
        raise MemoryError(f"no room at {system.frequency:.3g} Hz")

    monkeypatch.setattr(sweep_module, "solve_system", failing)
    with pytest.raises(MemoryError, match="no room at 5e"):
        periodic_sweep(dipoles, BAND, ALONG)
    assert not [t for t in threading.enumerate() if t.name.startswith("barymesh-sweep")]


# -- files -------------------------------------------------------------------------------


@pytest.fixture(scope="module")
def l_cell_sweep():
    """An L with unequal arms (no mirror symmetry): cross-polarised, so S12 = S21 is
    reciprocity, not symmetry; normal incidence, below and above the grating lobe."""
    mask = np.zeros((8, 8), dtype=bool)
    mask[1:7, 1:3] = True
    mask[1:3, 1:5] = True
    return periodic_sweep(pixel_cell(mask), [10e9, 20e9, 35e9], interpolate=False)


def test_the_touchstone_file_reads_back_with_scikit_rf(l_cell_sweep, tmp_path):
    import skrf  # the test extra's scikit-rf, an independent Touchstone reader

    sweep = l_cell_sweep
    path = tmp_path / "rt.s4p"
    sweep.to_touchstone(path)
    network = skrf.Network(str(path))
    assert network.nports == 4
    assert np.allclose(network.f, sweep.frequencies, rtol=1e-12)
    s = network.s
    # from above: R and T of the (0, 0) order, TE/TM, both incidences
    assert np.abs(s[:, :2, :2] - sweep.order_reflection[:, 0]).max() < 1e-10
    assert np.abs(s[:, 2:, :2] - sweep.order_transmission[:, 0]).max() < 1e-10
    # reciprocity S_ij = S_ji, with a real cross-polarised coupling
    assert np.abs(s[:, 0, 1]).min() > 0.05
    assert np.abs(s - s.transpose(0, 2, 1)).max() < 1e-4  # the solver's quadrature error
    # a lossless screen: S is unitary below the grating lobe, not above it
    eye = np.eye(4)
    below, above = sweep.frequencies < sweep.grating_lobe_onsets[0], slice(-1, None)
    for m in s[below]:
        assert np.abs(m.conj().T @ m - eye).max() < 1e-3
    for m in s[above]:
        assert np.abs(m.conj().T @ m - eye).max() > 0.01
    text = path.read_text()
    assert "exp(+j w t)" in text and "# Hz S RI R 1" in text


def test_the_touchstone_file_needs_both_polarizations(dipoles, tmp_path):
    one = periodic_sweep(dipoles, [12e9], ALONG, interpolate=False, polarizations="incident")
    with pytest.raises(ValueError, match="polarizations='both'"):
        one.to_touchstone(tmp_path / "x.s4p")
    assert not (tmp_path / "x.s4p").exists()


def test_the_orders_csv_holds_every_propagating_order(l_cell_sweep, tmp_path):
    import csv

    from barymesh.io.floquet import ORDER_COLUMNS

    sweep = l_cell_sweep
    path = tmp_path / "orders.csv"
    sweep.to_csv(path)
    with open(path, newline="") as fh:
        rows = list(csv.DictReader(fh))
    assert tuple(rows[0]) == ORDER_COLUMNS
    by_f: dict[float, list] = {}
    for row in rows:
        by_f.setdefault(float(row["frequency_hz"]), []).append(row)
    assert sorted(by_f) == list(sweep.frequencies)
    counts = [len(by_f[f]) for f in sweep.frequencies]
    assert counts == [2, 2, 10]  # (0, 0) below the onset, five orders above, TE and TM each
    for f, group in by_f.items():
        power = sum(float(r["R_power"]) + float(r["T_power"]) for r in group)
        assert power == pytest.approx(1.0, abs=1e-3), f  # a lossless screen
        assert all(r["solved"] == "1" for r in group)
    above = by_f[sweep.frequencies[-1]]
    assert {(int(r["p"]), int(r["q"])) for r in above} == {(0, 0), (1, 0), (-1, 0), (0, 1), (0, -1)}
    assert sum(float(r["R_power"]) + float(r["T_power"]) for r in above[2:]) > 0.01
    first = rows[0]
    r = complex(float(first["R_re"]), float(first["R_im"]))
    assert abs(r - sweep.reflection[0, 0]) < 1e-12
    assert float(first["R_abs"]) == pytest.approx(abs(r))


def test_the_sweep_benchmark_runs_both_sweeps_and_they_agree(tmp_path):
    from benchmark_runs import run_quick

    (row,) = run_quick("periodic_sweep.py", tmp_path)["rows"]
    assert row["frequencies"] == 41 and row["point_by_point_solves"] == 41
    assert 5 <= row["interpolating_solves"] < 41  # fewer solves than frequencies
    # the interpolated curve against every point-by-point solve (no onset in 2-28 GHz)
    assert row["largest_abs_r_difference"] < 1e-3
    assert row["largest_abs_t_difference"] < 1e-3
    assert row["largest_phase_r_difference_deg"] < 1.0
    assert row["curve_s"] == pytest.approx(row["geometry_s"] + row["interpolating_s"])


def test_the_accuracy_benchmark_compares_the_sweep_with_every_frequency_solved(tmp_path):
    from benchmark_runs import run_quick

    (row,) = run_quick("sweep_accuracy.py", tmp_path)["rows"]
    assert row["case"] == "dipoles" and row["frequencies"] == 41
    assert 5 <= row["solves"] < 41  # fewer solves than frequencies
    # the interpolated R against all 41 solved, within the tolerance it was asked for
    assert 0 < row["largest_r_difference"] < row["tolerance"] == 1e-3
    assert row["largest_error_estimate"] < row["tolerance"]
