"""The infinite-array solver on dielectric layers and a ground plane, against physics.

- Exact: a grounded slab without metal has |Γ| = 1 and Γ = (Z_d − η0)/(Z_d + η0),
  Z_d = j (η0/√εr) tan(k0 √εr h) at normal incidence (the issue's values at 5, 10 and
  15 GHz), and the textbook TE/TM formulas at oblique incidence.
- An independent method: strip gratings on a slab (grounded, or lossy and open) against
  a 1-D spectral-domain Galerkin solution with edge-conditioned Chebyshev currents
  (tests/strip_spectral.py), both polarisations, oblique incidence.
- Identities: vacuum layers (with or without zero-thickness ones) are the free-standing
  sheet, up to the reference planes' phase; a layer split in two halves changes
  nothing; reciprocity Z(k_t)ᵀ = Z(−k_t); a fully metallised cell reflects R = −1 at the
  sheet whatever is under it; power balance for lossless stacks; the layers' loss
  equals the Poynting flux into them, harmonic by harmonic.
- The kernel: the two-half-space limit in closed form, the rest falling fast, the rest
  by tables equal to the rest integrated exactly.
"""

from __future__ import annotations

import dataclasses
import math

import numpy as np
import pytest
from periodic_meshes import graded_nodes, graded_strips, grid_cell
from strip_spectral import strip_reflection

from barymesh.cell import Lattice, PixelGrid, UnitCell, build_cell
from barymesh.constants import ETA0, SPEED_OF_LIGHT
from barymesh.mom import (
    Layer,
    PlaneWave,
    Stack,
    parse_stack,
    periodic_solve,
    periodic_sweep,
    te_tm_polarizations,
)
from barymesh.mom.operator import wavenumber
from barymesh.mom.periodic import periodic_geometry, periodic_impedance_matrix
from barymesh.mom.periodic_fill import fill
from barymesh.mom.periodic_geometry import cell_current
from barymesh.mom.periodic_green import reciprocal_vectors
from barymesh.mom.periodic_layered import (
    extraction,
    layered_kernel,
    sheet_coefficients,
    te_tm_basis,
)
from barymesh.mom.stack import side, vacuum_admittance

P = 10.0  # mm
GROUNDED = Stack(below=(Layer(1.575, 2.2),), ground=True)


def patch(n: int = 10, side_mm: float = 5.0):
    """A square patch of side ``side_mm`` in a P cell, graded toward its edges."""
    x = graded_nodes(-side_mm / 2, side_mm / 2, n, 2.0)
    return grid_cell(x, x, np.ones((n, n), bool), P)


def full_sheet(n: int = 8):
    x = np.linspace(-P / 2, P / 2, n + 1)
    return grid_cell(x, x, np.ones((n, n), bool), P)


def polarised(theta: float, phi: float, which: int) -> PlaneWave:
    d = PlaneWave.from_angles(theta, phi).direction
    return PlaneWave(d, te_tm_polarizations(d)[which])


# -- the stack without the sheet: exact --------------------------------------------------


@pytest.mark.parametrize(
    ("frequency", "degrees"), [(5e9, 160.879), (10e9, 140.476), (15e9, 117.339)]
)
def test_grounded_slab_reflects_everything_with_the_textbook_phase(frequency, degrees):
    gamma = GROUNDED.reflection(frequency)
    k0 = 2 * math.pi * frequency / SPEED_OF_LIGHT
    zd = 1j * ETA0 / math.sqrt(2.2) * math.tan(k0 * math.sqrt(2.2) * 1.575e-3)
    exact = (zd - ETA0) / (zd + ETA0)
    assert np.abs(gamma) == pytest.approx([1.0, 1.0], abs=1e-12)
    assert gamma[0] == pytest.approx(exact, abs=1e-12)
    assert math.degrees(np.angle(gamma[0])) == pytest.approx(degrees, abs=5e-4)


@pytest.mark.parametrize(("theta", "mu"), [(20.0, 1.0), (60.0, 1.0), (40.0, 1.5)])
def test_oblique_slab_reflection_matches_fresnel_through_the_layer(theta, mu):
    """An open lossy slab: TE and TM from the textbook's impedance transformation."""
    eps, d, f = 4.4 - 0.088j, 2.0e-3, 11e9
    stack = Stack(below=(Layer(2.0, 4.4, 0.02, mu),))
    k0 = 2 * math.pi * f / SPEED_OF_LIGHT
    s = math.sin(math.radians(theta))
    kz0 = k0 * math.cos(math.radians(theta))
    kzd = k0 * np.sqrt(eps * mu - s * s + 0j)
    kzd = kzd if kzd.imag <= 0 else -kzd
    expected = []
    for z0, zd in ((k0 / kz0, mu * k0 / kzd), (kz0 / k0, kzd / (k0 * eps))):  # TE, TM (× η0)
        t = np.tan(kzd * d)
        zin = zd * (z0 + 1j * zd * t) / (zd + 1j * z0 * t)
        expected.append((zin - z0) / (zin + z0))
    wave = PlaneWave.from_angles(theta, 30.0)
    assert stack.reflection(f, wave) == pytest.approx(np.array(expected), abs=1e-12)


def test_a_stack_is_checked_and_read_back():
    with pytest.raises(ValueError, match="ground=True needs a layer"):
        Stack(ground=True)
    with pytest.raises(ValueError, match="ground=True needs a layer"):
        Stack(below=(Layer(0.0, 3.0),), ground=True)
    with pytest.raises(ValueError, match=r"Layer.eps_r=-2"):
        Layer(1.0, -2)
    with pytest.raises(ValueError, match=r"Layer.thickness=nan"):
        Layer(float("nan"), 2.0)
    with pytest.raises(TypeError, match="single Layer"):
        Stack(below=Layer(1.0, 2.0))
    with pytest.raises(ValueError, match="'ground' must come last"):
        parse_stack("ground; 1mm eps=2")
    with pytest.raises(ValueError, match="thickness and its unit"):
        parse_stack("1.5 eps=2")
    with pytest.raises(ValueError, match="expected eps=, tand= or mu="):
        parse_stack("1mm er2")
    s = parse_stack("0.5mm eps=3 tand=0.01; sheet; 30mil eps=2.2; 1mm; ground")
    assert [x.thickness for x in s.above] == [0.5]
    assert [round(x.thickness, 6) for x in s.below] == [0.762, 1.0]
    assert s.ground and s.reference_planes == (0.5, pytest.approx(-1.762))
    assert Stack.from_dict(s.to_dict()) == s
    assert parse_stack(s.describe()) == s
    assert s.replaced("below[0].eps_r", 3.5).below[0].eps_r == 3.5
    with pytest.raises(ValueError, match="has 2 layer"):
        s.replaced("below[2].thickness", 1.0)
    with pytest.raises(TypeError, match="stack must be a barymesh.mom.Stack"):
        periodic_solve(patch(), 10e9, stack="1mm eps=2")
    with pytest.raises(ValueError, match="comes from below, where the ground plane is"):
        periodic_solve(patch(), 10e9, PlaneWave((0, 0, 1), (1, 0, 0)), stack=GROUNDED)


# -- the kernel -----------------------------------------------------------------------------


def test_the_kernel_of_two_thick_media_is_the_two_half_space_form():
    """Layers thick enough to be half-spaces: a = 2/(γ1 + γ2), φ = 2/(ε1 γ2 + ε2 γ1)."""
    e1, e2, k0 = 3.0, 2.2, wavenumber(12e9)
    stack = Stack(above=(Layer(400.0, e1),), below=(Layer(400.0, e2),))
    kappa = np.array([2.5, 4.0, 9.0, 30.0]) * k0  # evanescent in both: no reflections back
    a, phi, _, _ = sheet_coefficients(stack, kappa**2, k0)
    g1, g2 = np.sqrt(kappa**2 - e1 * k0**2), np.sqrt(kappa**2 - e2 * k0**2)
    np.testing.assert_allclose(a, 2 / (g1 + g2), rtol=1e-12)
    np.testing.assert_allclose(phi, 2 / (e1 * g2 + e2 * g1), rtol=1e-12)


def test_the_rest_after_the_averaged_media_falls_like_kappa_to_the_minus_five():
    """Δ = a − μ̃/γ_A and φ − 1/(ε̄ γ_Φ) fall like |κ|⁻⁵ (the 1/κ and 1/κ³ terms match)."""
    k0 = wavenumber(10e9)
    stack = Stack(above=(Layer(300.0, 1.0),), below=(Layer(300.0, 4.4, 0.02),))
    medium = extraction(stack, k0)
    kappa = np.array([20.0, 40.0, 80.0]) * k0
    a, phi, _, _ = sheet_coefficients(stack, kappa**2, k0)
    da = np.abs(a - medium.mu / np.sqrt(kappa**2 - medium.k_a**2 + 0j))
    dphi = np.abs(phi - 1 / (medium.eps * np.sqrt(kappa**2 - medium.k_phi**2 + 0j)))
    for rest in (da, dphi):
        slopes = np.diff(np.log(rest)) / np.diff(np.log(kappa))
        np.testing.assert_allclose(slopes, -5.0, atol=0.05)
    assert medium.k_phi.imag < 0 and medium.k_a.imag < 0  # lossy: complex wavenumbers


def test_vacuum_layers_make_the_vacuum_kernel():
    k0 = wavenumber(9e9)
    stack = Stack(above=(Layer(2.0),), below=(Layer(0.0, 5.0), Layer(3.0)))
    kappa = np.array([0.0, 0.3, 0.99, 1.7, 12.0]) * k0
    a, phi, _, _ = sheet_coefficients(stack, kappa**2, k0)
    gamma = np.sqrt(kappa**2 - k0**2 + 0j)
    np.testing.assert_allclose(a, 1 / gamma, rtol=1e-12)
    np.testing.assert_allclose(phi[1:], 1 / gamma[1:], rtol=1e-9)
    np.testing.assert_allclose(phi[0], 1 / gamma[0], rtol=1e-6)  # κ = 0: its limit


def test_the_rest_in_the_taylor_tables_equals_the_rest_integrated_exactly():
    """The spectral rest's harmonics as exact rank-3 terms instead of in the tables."""
    mesh = patch(10)
    pg = periodic_geometry(mesh)
    k = wavenumber(10e9)
    kt = np.array([0.3 * k, 0.1 * k])
    kernel = layered_kernel(GROUNDED, pg.lattice, k, kt)
    recip = np.array(reciprocal_vectors(pg.lattice[0], pg.lattice[1]))
    rest = kernel.rest_orders @ recip + kt
    exact = dataclasses.replace(
        kernel,
        exact_kappa=np.concatenate([kernel.exact_kappa, rest]),
        exact_a=np.concatenate([kernel.exact_a, kernel.rest_a * kernel.medium.mu]),
        exact_phi=np.concatenate([kernel.exact_phi, kernel.rest_phi / kernel.medium.eps]),
        taken_a=np.concatenate([kernel.taken_a, np.zeros(len(rest))]),
        taken_phi=np.concatenate([kernel.taken_phi, np.zeros(len(rest))]),
        rest_orders=kernel.rest_orders[:0],
        rest_a=kernel.rest_a[:0],
        rest_phi=kernel.rest_phi[:0],
    )
    tables, spectral = fill(pg, k, kt, kernel), fill(pg, k, kt, exact)
    vacuum = periodic_impedance_matrix(pg, k, kt)
    assert len(rest) > 100  # the rest is real work here, not a formality
    assert np.linalg.norm(tables - vacuum) > 0.3 * np.linalg.norm(vacuum)
    assert np.linalg.norm(tables - spectral) < 5e-4 * np.linalg.norm(spectral)


# -- identities ---------------------------------------------------------------------------


@pytest.mark.parametrize(
    "stack",
    [
        Stack(below=(Layer(2.0),)),
        Stack(above=(Layer(1.5), Layer(0.0, 3.0)), below=(Layer(0.0, 5.0), Layer(2.0))),
    ],
)
def test_vacuum_layers_are_the_free_standing_sheet(stack):
    mesh = patch()
    wave = PlaneWave.from_angles(30, 20, 35)
    f = 12e9
    free = periodic_solve(mesh, f, wave)
    layered = periodic_solve(mesh, f, wave, stack=stack)
    top, bottom = layered.reference_planes
    assert (top, bottom) == (stack.thickness_above, -stack.thickness_below)
    np.testing.assert_array_equal(layered.orders, free.orders)
    shift_r = np.exp(2j * free.beta * top * 1e-3)[:, None]
    shift_t = np.exp(1j * free.beta * (top - bottom) * 1e-3)[:, None]
    np.testing.assert_allclose(layered.reflection * shift_r, free.reflection, atol=1e-6)
    np.testing.assert_allclose(layered.transmission * shift_t, free.transmission, atol=1e-6)


def test_a_layer_split_in_two_halves_changes_nothing():
    mesh = patch()
    wave = PlaneWave.from_angles(25, 10, 30)
    one = periodic_solve(mesh, 11e9, wave, stack=Stack(below=(Layer(1.6, 3.0, 0.01),)))
    two = periodic_solve(
        mesh, 11e9, wave, stack=Stack(below=(Layer(0.8, 3.0, 0.01), Layer(0.8, 3.0, 0.01)))
    )
    np.testing.assert_allclose(two.reflection, one.reflection, atol=1e-9)
    np.testing.assert_allclose(two.transmission, one.transmission, atol=1e-9)
    assert two.absorption == pytest.approx(one.absorption, abs=1e-9)


def uniform_strips():
    """Strips of width P/2 touching the cell's sides, 8 pixels of subdivision 2: the
    unknowns across the sides make Z(k_t) far from symmetric."""
    mask = np.zeros((8, 8), dtype=bool)
    mask[:, 2:6] = True
    pixels = PixelGrid(mask, pixel_size=P / 8, origin=(-P / 2, -P / 2), subdivisions=2)
    return build_cell(
        UnitCell(lattice=Lattice.rectangular(P), pixels=pixels, mode="conforming")
    ).mesh


def test_reciprocity_of_the_layered_matrix():
    pg = periodic_geometry(uniform_strips())
    k = wavenumber(13e9)
    kt = np.array([0.4 * k, -0.2 * k])
    stack = Stack(above=(Layer(1.0, 3.0, 0.02),), below=(Layer(0.8, 2.2),), ground=True)
    forward = periodic_impedance_matrix(pg, k, kt, stack)
    backward = periodic_impedance_matrix(pg, k, -kt, stack)
    error = np.abs(forward.T - backward).max() / np.abs(forward).max()
    # the vacuum fill's own asymmetry (float32 Taylor tables): the layers add none
    vacuum = periodic_impedance_matrix(pg, k, kt)
    floor = np.abs(vacuum.T - periodic_impedance_matrix(pg, k, -kt)).max() / np.abs(vacuum).max()
    assert error < 2e-4
    assert error < 1.1 * floor + 1e-5
    assert np.abs(forward.T - forward).max() > 0.1 * np.abs(forward).max()  # not symmetric


@pytest.mark.parametrize(
    "stack",
    [
        GROUNDED,
        Stack(below=(Layer(0.7, 4.4, 0.02), Layer(1.0, 2.0))),
        Stack(below=(Layer(3.0, 10.0),)),
    ],
)
def test_a_fully_metallised_cell_reflects_minus_one_at_the_sheet(stack):
    solution = periodic_solve(full_sheet(12), 12e9, PlaneWave.from_angles(30, 20, 35), stack=stack)
    r, t = solution.co_polar()
    assert solution.reference_planes[0] == 0.0  # nothing above: R is referred to the sheet
    assert r == pytest.approx(-1.0, abs=2e-4)
    assert abs(t) < 2e-4


@pytest.mark.parametrize(
    "stack",
    [
        GROUNDED,
        Stack(below=(Layer(1.575, 2.2),)),
        Stack(above=(Layer(1.0, 3.0),), below=(Layer(0.8, 2.2),)),
    ],
)
@pytest.mark.parametrize("frequency", [8e9, 14e9])
def test_power_balance_of_lossless_stacks_below_the_first_onset(stack, frequency):
    s = periodic_solve(patch(), frequency, PlaneWave.from_angles(25, 10, 30), stack=stack)
    assert len(s.orders) == 1  # below the first onset in vacuum
    assert s.absorption == 0.0
    assert s.power_balance == pytest.approx(1.0, abs=1e-3)


def test_the_layers_loss_is_the_poynting_flux_into_them_harmonic_by_harmonic():
    """Lossy stack: the solver's layer absorption against Σ over harmonics of the power
    flowing into each side's layers less what leaves them (J̃ by quadrature, summed to
    |κ| h = 6: the sum converges slowly from below, like 1/|κ|)."""
    mesh = patch(14)
    stack = Stack(below=(Layer(1.575, 2.2, 0.02),), ground=True)
    wave = PlaneWave.from_angles(25, 10, 30)
    f = 13e9
    s = periodic_solve(mesh, f, wave, stack=stack)
    pg, k = s.geometry, wavenumber(f)
    rule = pg.base.near
    h = float(np.median(pg.base.sizes))
    b = np.array(reciprocal_vectors(pg.lattice[0], pg.lattice[1]))
    span = int(6.0 / h / np.linalg.norm(b, axis=1).min()) + 2
    p, q = np.meshgrid(np.arange(-span, span + 1), np.arange(-span, span + 1))
    kappa = np.stack([p.ravel(), q.ravel()], 1) @ b + s.kappa[0]
    kappa = kappa[np.linalg.norm(kappa, axis=1) <= 6.0 / h]
    zero = int(np.argmin(np.linalg.norm(kappa - s.kappa[0], axis=1)))
    j = cell_current(pg, s.kappa[0], s.coefficients, rule.rho)
    jt = np.einsum(
        "tq,tqc,tqp->pc", rule.weights, j[:, :, :2], np.exp(1j * (rule.points[:, :, :2] @ kappa.T))
    )
    kappa2 = np.einsum("ij,ij->i", kappa, kappa)
    norm = np.sqrt(kappa2)
    along = np.where(
        norm[:, None] > 1e-9 * k, kappa / np.maximum(norm, 1e-300)[:, None], [1.0, 0.0]
    )
    along[zero] = s.kappa[0] / np.linalg.norm(s.kappa[0])
    te = np.stack([-along[:, 1], along[:, 0]], 1)
    up = side((), False, kappa2, k)
    down = side(stack.below, True, kappa2, k)
    drive = np.stack([np.einsum("pc,pc->p", jt, te), np.einsum("pc,pc->p", jt, along)], 1)
    v = -ETA0 / pg.area * drive / (up.admittance + down.admittance)
    background = stack._background(f, wave).sheet
    te0, tm0, along0 = te_tm_basis(np.asarray(wave.direction))
    v_inc = np.array([wave.polarization @ te0, (wave.polarization @ tm0) * (tm0 @ along0)])
    v[zero] += background * v_inc
    into = 0.5 * np.abs(v) ** 2 * down.admittance.real  # grounded: nothing leaves below
    incident = 0.5 * np.sum(
        np.abs(v_inc) ** 2 * vacuum_admittance(kappa2[zero : zero + 1], k)[0].real
    )
    flux = float(into.sum()) / incident
    assert s.layer_absorption > 0.01
    assert flux == pytest.approx(s.layer_absorption, rel=0.05)
    assert flux < s.layer_absorption  # the truncated sum approaches from below


# -- an independent method: strip gratings on a substrate ------------------------------


@pytest.mark.parametrize(
    ("eps", "thickness", "ground", "frequency", "polarization"),
    [
        (2.2, 1.575, True, 6e9, "te"),
        (2.2, 1.575, True, 12e9, "tm"),
        (4.4 - 0.088j, 1.0, False, 12e9, "te"),
        (4.4 - 0.088j, 1.0, False, 6e9, "tm"),
    ],
)
def test_strips_on_a_substrate_match_the_spectral_domain_solution(
    eps, thickness, ground, frequency, polarization
):
    tand = -complex(eps).imag / complex(eps).real
    stack = Stack(below=(Layer(thickness, complex(eps).real, tand),), ground=ground)
    reference = strip_reflection(
        frequency, P, P / 2, complex(eps), thickness, ground, polarization, 20.0, basis=8
    )
    wave = polarised(20.0, 0.0, 0 if polarization == "te" else 1)
    errors = []
    for across in (12, 20):
        r = periodic_solve(graded_strips(P, across, across // 2), frequency, wave, stack=stack)
        errors.append(abs(r.co_polar()[0] - reference))
    assert errors[1] < 1e-3
    assert errors[1] < 0.5 * errors[0]  # and converging to it


# -- where orders propagate ----------------------------------------------------------------


def test_the_onset_of_the_first_order_inside_a_slab_shows_in_the_orders():
    """f = c/(P √εr) at normal incidence: above it (±1, 0) and (0, ±1) are guided inside
    the slab (listed in layer_orders, not among the vacuum's propagating orders)."""
    stack = Stack(below=(Layer(2.0, 4.0),))
    onset = SPEED_OF_LIGHT / (P * 1e-3 * 2.0)
    below = periodic_solve(patch(), onset * 0.99, stack=stack)
    above = periodic_solve(patch(), onset * 1.01, stack=stack)
    assert len(below.layer_orders) == 0
    assert sorted(map(tuple, above.layer_orders.tolist())) == [(-1, 0), (0, -1), (0, 1), (1, 0)]
    assert above.orders.tolist() == [[0, 0]]  # no grating lobe in vacuum
    sweep = periodic_sweep(patch(), np.linspace(0.9 * onset, 1.1 * onset, 5), stack=stack)
    assert len(sweep.grating_lobe_onsets) == 0
    assert sweep.layer_onsets[0][0] == pytest.approx(onset, rel=1e-9)


def test_a_layered_sweep_interpolates_r_and_t():
    stack = Stack(below=(Layer(1.0, 3.0),))
    f = np.linspace(6e9, 16e9, 21)
    fitted = periodic_sweep(patch(), f, PlaneWave.from_angles(20, 0), stack=stack)
    solved = periodic_sweep(
        patch(), f, PlaneWave.from_angles(20, 0), stack=stack, interpolate=False
    )
    assert fitted.n_solves < len(f)
    for a, b in zip(fitted.co_polar(), solved.co_polar(), strict=True):
        assert np.abs(a - b).max() < 1e-3
    assert fitted.reference_planes == (0.0, -1.0)


# -- warnings -------------------------------------------------------------------------------


def test_a_solve_says_when_not_to_trust_it():
    mesh = patch()
    onset = SPEED_OF_LIGHT / (P * 1e-3)
    near = periodic_solve(mesh, onset * (1 - 0.003))
    assert any(w.startswith("near an onset:") for w in near.warnings)
    assert not any(
        w.startswith("near an onset") for w in periodic_solve(mesh, 0.8 * onset).warnings
    )
    coarse = periodic_solve(mesh, 12e9, stack=Stack(below=(Layer(1.0, 40.0),)))
    assert any(w.startswith("coarse mesh:") and "the layer below[0]" in w for w in coarse.warnings)
    overlapping = periodic_solve(patch(20), 10e9, lattice=Lattice.rectangular(4.8))
    assert any(w.startswith("metal beyond the cell:") for w in overlapping.warnings)
    from barymesh.mom.periodic_caveats import condition_warning

    assert condition_warning(1e13)[0].startswith("ill-conditioned:")
    assert condition_warning(1e5) == ()


def test_the_layered_benchmark_runs_and_reports_each_part(tmp_path):
    from benchmark_runs import run_quick

    doc = run_quick("layered.py", tmp_path)
    speed, sweep = doc["speed"], doc["sweep"]
    assert speed["grounded_substrate_s"] > 0 and speed["free_standing_s"] > 0
    assert speed["ratio"] == pytest.approx(speed["grounded_substrate_s"] / speed["free_standing_s"])
    assert sweep["solves"] < sweep["frequencies"]
    assert sweep["largest_difference_r"] < 1e-3 and sweep["largest_difference_t"] < 1e-3
    assert all(row["difference"] < 1e-3 for row in doc["convergence"])
    cases = {row["case"]: row for row in doc["validation"]}
    assert cases["grounded slab, no metal (exact)"]["difference"] < 1e-12
    assert cases["fully metallised cell (R = -1)"]["difference"] < 2e-4
    strips = [row for row in doc["validation"] if row["case"].startswith("strips")]
    assert strips and all(row["difference"] < 2e-3 for row in strips)


def test_a_peak_beside_an_onset_that_is_not_total_reflection_is_flagged():
    from barymesh.mom.periodic_caveats import onset_resonance_warning

    onsets = np.array([32.8923e9])
    # a peak of |R| = 0.69 0.9 % below the onset: its kink, flagged; one of |R| = 0.99: real
    flagged = onset_resonance_warning(
        np.array([32.6e9, 32.7e9]),
        ("peak", "peak"),
        onsets,
        np.array([0.69, 0.99]),
        np.array([0.37, 0.1]),
    )
    assert len(flagged) == 1 and "32.6 GHz" in flagged[0] and "|T| = 0.37" in flagged[0]
    far = onset_resonance_warning(
        np.array([20e9]), ("dip",), onsets, np.array([0.3]), np.array([0.9])
    )
    assert far == ()
    # in a sweep: a 5 mm patch at 30°, TM, across the (1, ±1) onset at 32.89 GHz
    sweep = periodic_sweep(patch(10), np.linspace(31e9, 34e9, 61), PlaneWave.from_angles(30, 0, 90))
    assert sweep.grating_lobe_onsets[0] == pytest.approx(32.892e9, rel=1e-4)
    notes = [w for w in sweep.warnings if w.startswith("resonance next to an onset")]
    assert notes, sweep.resonances


@pytest.mark.parametrize(
    "stack",
    [
        Stack(below=(Layer(1.0, 3.0, 0.01),)),
        Stack(above=(Layer(0.7, 2.0, 0.02), Layer(0.3, 4.0)), below=(Layer(1.0, 3.0, 0.01),)),
        Stack(above=(Layer(1.0, 2.2),), below=(Layer(1.0, 3.0),), ground=True),
    ],
)
def test_t_follows_from_r_through_the_layers(stack):
    """The sheet has no thickness: T = a δ + b R, order by order, with a and b from the
    lines alone (what a sweep uses to take T from its fit of R)."""
    from barymesh.mom.stack import transmission_map

    for f, theta in ((12e9, 25.0), (33e9, 30.0)):  # one order; four above the onset
        s = periodic_solve(patch(), f, PlaneWave.from_angles(theta, 10, 30), stack=stack)
        a, b = transmission_map(stack, wavenumber(f), np.einsum("ij,ij->i", s.kappa, s.kappa))
        t = b * s.reflection
        t[0] += a[0] * s.incident_te_tm
        np.testing.assert_allclose(t, s.transmission, atol=1e-12)
