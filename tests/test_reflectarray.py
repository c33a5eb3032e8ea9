"""The reflectarray designer (issue 33 §2): phases, parameters, pattern, the array as a cell.

Most tests build a made-up S-curve (a smooth, monotone phase over 330° with |R| = 1) as a
:class:`ReflectionLibrary` directly, so no solve is needed; one small real library checks
the path from a solved cell. The numbers asserted come from the physics, not from the code:
the progressive phase of a beam, the coherent sum of an aperture without phase error,
sinc(π/2^b) for quantisation, brute-force integration of the pattern, the lookup of the
library itself.
"""

from __future__ import annotations

import copy

import numpy as np
import pytest

from barymesh import reflectarray
from barymesh.cell import cell_from_dict, load_cell, save_cell
from barymesh.constants import SPEED_OF_LIGHT_MM
from barymesh.mom import ReflectionLibrary, parse_stack, reflection_library
from barymesh.reflectarray import pattern as far

F = 10e9
WAVELENGTH = SPEED_OF_LIGHT_MM / F  # 29.98 mm
K = 2 * np.pi / WAVELENGTH
FAR = (0.0, 0.0, 1e8)  # a feed 100 km up: a plane wave at normal incidence
#: A 15 mm cell with one square patch whose lower-left corner is at (−6, −6) mm.
PATCH_CELL = {
    "format": "barymesh-cell",
    "version": 1,
    "name": "patch",
    "lattice": {"rectangular": [15.0, 15.0]},
    "elements": [
        {
            "name": "patch",
            "position": [-6.0, -6.0],
            "structure": "patch",
            "patch_size": 8.0,
            "subdivisions": 1,
        }
    ],
}
SIZES = np.linspace(3.0, 12.0, 34)  # mm: the patch sizes of the made-up curve


def s_curve(sizes, span=330.0):
    """A patch-like S-curve: the phase falls smoothly and monotonically over ``span``."""
    x = (sizes - sizes[0]) / (sizes[-1] - sizes[0])
    return span / 2 - span * (3 * x**2 - 2 * x**3)  # smooth step: flat at both ends


def synthetic(span=330.0, cell=True, magnitude=1.0):
    """A library of the made-up curve at F, with the patch cell (or none)."""
    r = np.zeros((len(SIZES), 1, 2, 2), dtype=complex)
    r[:, 0, 1, 1] = magnitude * np.exp(1j * np.radians(s_curve(SIZES, span)))
    r[:, 0, 0, 0] = 1.0
    inc = {"theta": 0.0, "phi": 0.0, "pol": "TM"}
    return ReflectionLibrary(
        "elements[0].patch_size",
        SIZES,
        np.array([F]),
        r,
        "TM",
        inc,
        0.0,
        cell=cell_from_dict(copy.deepcopy(PATCH_CELL)) if cell else None,
    )


@pytest.fixture(scope="module")
def lib():
    return synthetic()


# -- the phases ---------------------------------------------------------------------------


@pytest.mark.parametrize(
    ("aperture", "beam"), [((60, 1), (20.0, 0.0)), ((1, 60), (35.0, 90.0)), ((80, 1), (50.0, 0.0))]
)
def test_a_progressive_phase_steers_the_beam(lib, aperture, beam):
    """A plane wave lights a line of cells: the phase steps by −k p sin θ from one to the
    next, and the pattern's peak, sampled every 0.01°, is the beam asked for within 0.5°."""
    ra = reflectarray.design(lib, aperture, FAR, beam, F)
    theta_b, phi_b = np.radians(beam)
    step = np.diff(ra.required_phase)
    expected = -np.degrees(K * 15.0 * np.sin(theta_b))
    # within the curvature of a wave from 100 km: k x² / 2z < 0.03° over 600 mm
    np.testing.assert_allclose(reflectarray.wrapped(step - expected), 0.0, atol=3e-3)
    theta = np.arange(0.0, 89.99, 0.01)
    peak = theta[np.argmax(ra.pattern_db(theta, beam[1]))]
    assert abs(peak - beam[0]) < 0.5
    found, _ = ra.beam_direction
    assert abs(found - beam[0]) < 0.5 and abs(found - peak) < 0.02
    # steering the other way is the mirror image
    mirror = reflectarray.design(lib, aperture, FAR, (beam[0], beam[1] + 180.0), F)
    assert abs(theta[np.argmax(mirror.pattern_db(theta, beam[1] + 180.0))] - beam[0]) < 0.5


def test_a_hexagonal_lattice_steers_and_tiles():
    """Cells on a hexagonal lattice (a2 at 60°): the pattern's peak is still the beam asked
    for, and the array's cell is N1 a1 by N2 a2."""
    doc = copy.deepcopy(PATCH_CELL)
    doc["lattice"] = {"hexagonal": 16.0}
    lib = synthetic()
    hexa = ReflectionLibrary(lib.parameter, lib.values, lib.frequencies, lib.reflection, "TM",
                             lib.incidence, 0.0, cell=cell_from_dict(doc))  # fmt: skip
    ra = reflectarray.design(hexa, (30, 30), FAR, (30.0, 70.0), F)
    theta, phi = ra.beam_direction
    assert abs(theta - 30.0) < 0.5 and abs(phi - 70.0) < 1.0
    assert np.allclose(ra.positions.mean(axis=0), 0.0, atol=1e-9)  # centred on the origin
    cell = ra.to_cell()
    assert len(cell.elements) == 900
    np.testing.assert_allclose(cell.lattice.a2, (240.0, 240.0 * np.sqrt(3)), rtol=1e-12)


def test_without_phase_error_the_aperture_adds_coherently():
    """A curve covering all 360° leaves no phase error, so towards the beam every element's
    field arrives in phase: the gain is the coherent bound (4π A/λ²) (Σ w)² / Σ w² cos² θ_b,
    w the illumination (the taper's efficiency), cos θ the element's field pattern, for a
    feed at a finite distance and off the axis."""
    lib = synthetic(span=359.999)
    ra = reflectarray.design(lib, (12, 10), (-40.0, 20.0, 160.0), (30.0, 60.0), F)
    assert np.abs(ra.phase_error).max() < 1e-6
    w = np.abs(ra.excitation)
    bound = 4 * np.pi * 15.0**2 / WAVELENGTH**2 * w.sum() ** 2 / (w**2).sum()
    bound *= np.cos(np.radians(30.0)) ** 2  # the element's field pattern, cos θ
    got = abs(ra.pattern(30.0, 60.0)) ** 2
    assert got == pytest.approx(bound, rel=1e-9)
    # the delay from the feed is made up: phase − k d is the same for every element
    d = np.linalg.norm(ra.positions - np.array(ra.feed), axis=1)
    advance = ra.positions @ np.array([np.sin(np.pi / 6) * np.cos(np.pi / 3),
                                       np.sin(np.pi / 6) * np.sin(np.pi / 3),
                                       np.cos(np.pi / 6)])  # fmt: skip
    rest = reflectarray.wrapped(ra.achieved_phase - np.degrees(K * (d - advance)))
    np.testing.assert_allclose(reflectarray.wrapped(rest - rest[0]), 0.0, atol=1e-6)


def test_the_parameters_are_the_librarys_lookup(lib):
    """Unquantised, an element whose phase the curve reaches gets lookup's value and exactly
    that phase; one in the curve's 30° gap gets the nearer end, at most 15° off."""
    ra = reflectarray.design(lib, (24, 24), (30.0, 0.0, 300.0), (15.0, 45.0), F)
    looked = lib.lookup(ra.required_phase, F)
    covered = ~np.isnan(looked)
    assert 0 < (~covered).sum() < covered.sum()  # some do fall in the gap
    np.testing.assert_allclose(ra.parameter[covered], looked[covered], rtol=1e-9, atol=1e-9)
    np.testing.assert_allclose(ra.phase_error[covered], 0.0, atol=1e-7)
    np.testing.assert_allclose(
        reflectarray.wrapped(ra.achieved_phase - ra.required_phase)[covered], 0.0, atol=1e-7
    )
    gap = ~covered
    assert np.all(np.abs(ra.phase_error[gap]) <= 15.0 + 1e-9)
    assert np.all(np.isin(ra.parameter[gap], [SIZES[0], SIZES[-1]]))
    ends = np.where(ra.parameter[gap] == SIZES[0], 165.0, -165.0)
    np.testing.assert_allclose(ra.achieved_phase[gap], ends, atol=1e-9)
    assert ra.magnitude.shape == (576,)
    np.testing.assert_allclose(ra.magnitude, 1.0, rtol=1e-12)
    # C is the scan's best: no constant of a finer scan does much better
    w = np.abs(ra.excitation)
    best = np.sum(w * ra.phase_error**2) / w.sum()
    for shift in np.arange(-2.0, 2.01, 0.1):
        other = reflectarray.closest_on_curve(
            ra.required_phase + shift, SIZES, lib.phase_deg[:, 0], lib.magnitude[:, 0]
        )
        assert np.sum(w * other.distance**2) / w.sum() >= best - 0.2


@pytest.mark.parametrize("bits", [1, 2, 3])
def test_quantisation_uses_the_levels(lib, bits):
    ra = reflectarray.design(lib, (16, 16), (0.0, -50.0, 250.0), (25.0, 0.0), F, bits)
    n = 2**bits
    assert len(np.unique(ra.parameter)) <= n and len(np.unique(ra.target_phase)) <= n
    steps = np.mod(ra.target_phase - ra.target_phase[0], 360.0) / (360.0 / n)  # 360/2^b apart
    np.testing.assert_allclose(steps, np.round(steps), atol=1e-9)
    # each element takes the level nearest its phase; every level is on the curve here
    assert np.all(np.abs(ra.phase_error) <= 180.0 / n + 1e-9)
    np.testing.assert_allclose(reflectarray.wrapped(ra.achieved_phase - ra.target_phase), 0.0,
                               atol=1e-7)  # fmt: skip


@pytest.mark.parametrize(("bits", "tolerance"), [(1, 0.5), (2, 0.15), (3, 0.1)])
def test_the_quantisation_loss_is_the_textbooks(lib, bits, tolerance):
    """40 × 40 cells under a distant feed, beam at (25°, 30°): the phases sweep the
    quantisation interval evenly, and the main beam loses 20 log10 sinc(π/2^b) (3.92, 0.91,
    0.22 dB). Why the tolerances: the 1600 errors sample the uniform distribution, they are
    not it. Over five beam directions the loss came within 0.18 dB of the textbook at 1 bit
    (the worst, (20°, 0°), steps along x only: 40 distinct phases), 0.04 dB at 2 bits and
    0.01 dB at 3; the sample's deviation shrinks with the interval, and so do the bounds."""
    ra = reflectarray.design(lib, (40, 40), FAR, (25.0, 30.0), F, bits)
    textbook = reflectarray.textbook_quantization_loss(bits)
    assert textbook == pytest.approx(20 * np.log10(np.sin(np.pi / 2**bits) / (np.pi / 2**bits)))
    assert abs(ra.quantization_loss - textbook) < tolerance
    assert ra.continuous().quantization_loss == 0.0
    theta, phi = ra.beam_direction
    assert abs(theta - 25.0) < 0.5 and abs(phi - 30.0) < 1.0
    if bits == 1:  # a real aperture phase: the mirror beam at (25°, 210°) is as strong
        assert ra.side_lobe_level > -0.5
        assert ra.pattern_db(25.0, 210.0) == pytest.approx(ra.gain, abs=0.5)
    else:
        assert ra.side_lobe_level < -10.0


def test_a_uniform_aperture_has_the_textbook_directivity():
    """A broadside beam from a uniformly lit, in-phase 20 × 20 aperture of λ/2 cells:
    directivity and gain 4π A / λ² (A the aperture's area), within 0.1 dB; the first side
    lobe of a uniform line is −13.26 dB."""
    lib = synthetic(cell=False)
    ra = reflectarray.design(lib, (20, 20), FAR, (0.0, 0.0), F, q=0.0, period=WAVELENGTH / 2)
    expected = 10 * np.log10(4 * np.pi * (20 * WAVELENGTH / 2) ** 2 / WAVELENGTH**2)
    assert ra.gain == pytest.approx(expected, abs=0.1)
    assert ra.directivity == pytest.approx(expected, abs=0.1)
    assert ra.side_lobe_level == pytest.approx(-13.26, abs=0.3)
    assert "main beam: theta=0.00" in ra.summary()


# -- the pattern's sums, against brute force ------------------------------------------------


def test_the_radiated_power_equals_the_integral_of_the_pattern():
    """The autocorrelation sum against a fine θ, φ quadrature of |E|², on an oblique lattice
    (so a wrong sign of the separation would show) with a random excitation."""
    rng = np.random.default_rng(3)
    a = rng.normal(size=(5, 4)) + 1j * rng.normal(size=(5, 4))
    a1, a2 = np.array([12.0, 1.0]), np.array([4.0, 11.0])
    for q in (0.0, 1.0):
        exact = far.radiated_power(a, a1, a2, K, q)
        t, wt = np.polynomial.legendre.leggauss(200)
        theta = (t + 1) * np.pi / 4  # [0, π/2]
        phi = np.arange(400) * 2 * np.pi / 400
        tt, pp = np.meshgrid(theta, phi, indexing="ij")
        u, v = np.sin(tt) * np.cos(pp), np.sin(tt) * np.sin(pp)
        e = far.array_field(a, a1, a2, K, u.ravel(), v.ravel(), q).reshape(tt.shape)
        brute = ((np.abs(e) ** 2).sum(axis=1) * 2 * np.pi / 400) @ (wt * np.pi / 4 * np.sin(theta))
        assert exact == pytest.approx(brute, rel=1e-8)
    # one element: 2π/(2q + 1); isotropic: 2π sin(kρ)/(kρ)
    rho = np.array([0.0, 7.0, 40.0])
    np.testing.assert_allclose(far.hemisphere_kernel(rho[:1], K, 2.0), [2 * np.pi / 5])
    np.testing.assert_allclose(
        far.hemisphere_kernel(rho[1:], K, 0.0), 2 * np.pi * np.sinc(K * rho[1:] / np.pi), rtol=1e-12
    )


def test_the_pattern_is_the_direct_sum(lib):
    """pattern(θ, φ) against Σ a_i e^(jk û·r_i) cos θ written out, normalised by the
    intercepted power; nothing behind the aperture."""
    ra = reflectarray.design(lib, (7, 5), (10.0, 5.0, 90.0), (10.0, 20.0), F, 2)
    theta, phi = np.array([0.0, 10.0, 33.0, 71.0]), np.array([0.0, 20.0, -120.0, 300.0])
    t, p = np.radians(theta), np.radians(phi)
    uhat = np.stack([np.sin(t) * np.cos(p), np.sin(t) * np.sin(p), np.cos(t)], axis=1)
    direct = np.exp(1j * K * uhat @ ra.positions.T) @ ra.excitation * np.cos(t)
    direct *= np.sqrt(4 * np.pi / ra.intercepted_power)
    np.testing.assert_allclose(ra.pattern(theta, phi), direct, rtol=1e-9)
    assert ra.pattern(95.0, 0.0) == 0 and ra.pattern_db(120.0, 10.0) == -np.inf
    assert ra.pattern(np.zeros((2, 3)), 0.0).shape == (2, 3)


# -- the array as a cell ------------------------------------------------------------------


def test_the_array_is_a_cell_that_reads_back(lib, tmp_path):
    ra = reflectarray.design(lib, (15, 15), (0.0, 0.0, 150.0), (20.0, 0.0), F, 2)
    cell = ra.to_cell()
    assert len(cell.elements) == 225
    assert cell.lattice.a1 == (225.0, 0.0) and cell.lattice.a2 == (0.0, 225.0)
    save_cell(cell, tmp_path / "array.cell.json")
    back = load_cell(tmp_path / "array.cell.json")
    assert len(back.elements) == 225 and back.lattice == cell.lattice
    sizes = np.array([el.params.patch_size for el in back.elements])
    np.testing.assert_allclose(sizes, ra.parameter, rtol=1e-12)
    corners = np.array([el.position for el in back.elements])
    np.testing.assert_allclose(corners, ra.positions[:, :2] - 6.0, atol=1e-12)
    assert back.elements[16].name == "patch (1, 1)"
    assert "15 x 15" in back.description and "2-bit" in back.description


def test_the_array_exports_as_dxf(lib, tmp_path):
    pytest.importorskip("ezdxf")
    from barymesh.cell import export_outline

    ra = reflectarray.design(lib, (15, 15), (0.0, 0.0, 150.0), (20.0, 0.0), F, 1)
    polygons = export_outline(ra.to_cell(), tmp_path / "array.dxf")
    assert len(polygons) == 225
    assert sum(p.area for p in polygons) == pytest.approx(np.sum(ra.parameter**2), rel=1e-9)
    import ezdxf

    doc = ezdxf.readfile(tmp_path / "array.dxf")
    assert len(doc.modelspace().query("LWPOLYLINE")) == 225


def test_the_array_exports_as_gds(lib, tmp_path):
    gdstk = pytest.importorskip("gdstk")
    from barymesh.cell import export_outline

    ra = reflectarray.design(lib, (15, 15), (0.0, 0.0, 150.0), (20.0, 0.0), F, 3)
    export_outline(ra.to_cell(), tmp_path / "array.gds")
    [top] = gdstk.read_gds(tmp_path / "array.gds").top_level()
    assert len(top.polygons) == 225
    areas = sorted(p.area() for p in top.polygons)
    np.testing.assert_allclose(areas, np.sort(ra.parameter**2), rtol=1e-6)


def test_a_real_library_designs_and_builds():
    """A solved S-curve of a grounded patch (5 sizes, one frequency): the designer's
    parameters are its lookup, and the array's cell carries them."""
    cell = cell_from_dict(
        {"format": "barymesh-cell", "version": 1, "lattice": {"rectangular": [10.0, 10.0]},
         "elements": [{"structure": "patch", "patch_size": 6.0, "subdivisions": 6,
                       "position": [-4.0, -4.0]}]}
    )  # fmt: skip
    stack = parse_stack("1.575mm eps=2.2; ground")
    real = reflection_library(cell, "elements[0].patch_size", np.linspace(5.0, 8.0, 5), 10e9,
                              stack=stack)  # fmt: skip
    assert real.cell is cell
    ra = reflectarray.design(real, (6, 6), (0.0, 0.0, 80.0), (15.0, 0.0), 10e9)
    looked = real.lookup(ra.required_phase, 10e9)
    covered = ~np.isnan(looked)
    np.testing.assert_allclose(ra.parameter[covered], looked[covered], rtol=1e-9)
    sizes = [el.params.patch_size for el in ra.to_cell().elements]
    np.testing.assert_allclose(sizes, ra.parameter, rtol=1e-12)


# -- bad input ----------------------------------------------------------------------------


@pytest.mark.parametrize(
    ("changes", "fragment"),
    [
        ({"aperture": (15, 0)}, r"aperture=\(15, 0\) is invalid; expected two positive whole"),
        ({"aperture": (15.0, 15.0)}, "aperture=.* is invalid"),
        ({"aperture": 15}, "aperture=15 is invalid"),
        ({"aperture": (True, 3)}, "aperture=.* is invalid"),
        ({"feed": (0.0, 0.0, 0.0)}, r"lies in the aperture's plane \(z = 0\)"),
        ({"feed": (0.0, 0.0, -100.0)}, "below the aperture"),
        ({"feed": (0.0, 100.0)}, r"feed=\(0.0, 100.0\) is invalid; expected three numbers"),
        ({"beam": (90.0, 0.0)}, "beam theta=90 is invalid; expected 0 <= theta < 90"),
        ({"beam": (-5.0, 0.0)}, "beam theta=-5 is invalid"),
        ({"beam": (np.nan, 0.0)}, "beam=.* is invalid"),
        ({"bits": 4}, r"bits=4 is invalid; expected None \(continuous\), 1, 2 or 3"),
        ({"bits": 0}, "bits=0 is invalid"),
        ({"bits": True}, "bits=True is invalid"),
        ({"frequency": 12e9}, "frequency=12 GHz is not one of the library's"),
        ({"q": -1.0}, "q=-1.0 is invalid"),
        ({"period": 20.0}, r"period=20.0 differs from the library's cell's lattice"),
    ],
)
def test_bad_input_is_named(lib, changes, fragment):
    args = {"aperture": (15, 15), "feed": (0.0, 0.0, 150.0), "beam": (20.0, 0.0),
            "frequency": F, "bits": None}  # fmt: skip
    args.update(changes)
    with pytest.raises(ValueError, match=fragment):
        reflectarray.design(lib, **args)


def test_a_library_without_a_cell():
    bare = synthetic(cell=False)
    with pytest.raises(ValueError, match="has no cell.*give period="):
        reflectarray.design(bare, (4, 4), (0.0, 0.0, 50.0), (0.0, 0.0), F)
    ra = reflectarray.design(bare, (4, 4), (0.0, 0.0, 50.0), (0.0, 0.0), F, 1, period=15.0)
    assert ra.continuous().bits is None  # the continuous twin needs the period too
    with pytest.raises(ValueError, match="the library has no cell.*cannot be built"):
        ra.to_cell()
    with pytest.raises(ValueError, match="expected a ReflectionLibrary"):
        reflectarray.design("lib.csv", (4, 4), (0.0, 0.0, 50.0), (0.0, 0.0), F)


def test_to_cell_needs_an_element_parameter(lib):
    r = lib.reflection
    layer = ReflectionLibrary("stack.below[0].thickness", SIZES / 10, lib.frequencies, r, "TM",
                              lib.incidence, 0.0, cell=lib.cell)  # fmt: skip
    ra = reflectarray.design(layer, (3, 3), (0.0, 0.0, 50.0), (0.0, 0.0), F)
    with pytest.raises(ValueError, match="'stack.below\\[0\\].thickness' is not an element's"):
        ra.to_cell()
