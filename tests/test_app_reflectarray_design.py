"""The reflectarray designer's Qt-free part (app/model/reflectarray_design.py): the typed
inputs read or refused in one sentence naming the field, the numbers and the cut of a
design against barymesh.reflectarray called directly, the layout's tiles; and the picture
(app/panels/reflectarray_figure.py, Agg) draws them. No Qt here."""

import doctest
import subprocess
import sys

import numpy as np
import pytest

from barymesh.app.model import reflectarray_design as rd
from barymesh.cell import Element, Lattice, UnitCell
from barymesh.mom import ReflectionLibrary
from barymesh.params import MeshParams
from barymesh.reflectarray import design, textbook_quantization_loss

GOOD = ("15", "15", ("0", "0", "150"), ("20", "0"), None)


def made_up_library(lattice=None):
    """A patch cell's made-up S-curve: 330° over the patch size 6 to 11 mm at 10 GHz."""
    lattice = lattice or Lattice.rectangular(15.0)
    cell = UnitCell(lattice, (Element(MeshParams(structure="patch", patch_size=8.0)),))
    values = np.linspace(6.0, 11.0, 12)
    r = np.zeros((12, 1, 2, 2), complex)
    r[:, 0, 1, 1] = np.exp(1j * np.radians(165.0 - 66.0 * (values - 6.0)))
    return ReflectionLibrary(
        "elements[0].patch_size",
        values,
        np.array([10e9]),
        r,
        "TM",
        {"theta": 0.0, "phi": 0.0, "pol": "TM"},
        0.0,
        cell=cell,
    )


def test_the_docstrings_examples():
    result = doctest.testmod(rd)
    assert result.attempted >= 8 and result.failed == 0


def test_typed_inputs_are_read():
    got = rd.read_design_inputs(" 9", "7 ", (" −10", "5.5", "120"), ("25", "-30"), 2)
    assert got == rd.DesignInputs((9, 7), (-10.0, 5.5, 120.0), (25.0, -30.0), 2)


@pytest.mark.parametrize(
    ("index", "text", "message"),
    [
        (0, "0", "Aperture N1 '0' is invalid; expected a whole number of elements, 1 or more"),
        (1, "7.5", "Aperture N2 '7.5' is invalid; expected a whole number"),
        (1, "", "Aperture N2 '' is invalid"),
        (2, "x", "Feed x 'x' is not a number; type e.g. 150"),
        (4, "0", "Feed z 0 mm is invalid; expected the feed above the aperture, z > 0 mm"),
        (4, "nan", "Feed z 'nan' is not finite"),
        (5, "90", "Beam θ 90° is out of range; expected 0 <= θ < 90°"),
        (5, "-1", "Beam θ -1° is out of range"),
        (6, "east", "Beam φ 'east' is not a number"),
    ],
)
def test_a_bad_field_is_named_in_one_sentence(index, text, message):
    fields = ["15", "15", "0", "0", "150", "20", "0"]
    fields[index] = text
    with pytest.raises(ValueError) as info:
        rd.read_design_inputs(fields[0], fields[1], tuple(fields[2:5]), tuple(fields[5:7]), 1)
    assert str(info.value).startswith(message), str(info.value)
    assert "\n" not in str(info.value)


def test_too_many_elements_and_bad_bits_are_refused():
    with pytest.raises(ValueError, match=r"Aperture 101 × 100 has 10,100 elements; the window"):
        rd.read_design_inputs("101", "100", *GOOD[2:])
    rd.read_design_inputs("100", "100", *GOOD[2:])  # 10,000: the most
    with pytest.raises(ValueError, match="Bits 4 is invalid"):
        rd.read_design_inputs(*GOOD[:4], 4)


def test_run_design_is_design_with_its_numbers_and_cuts():
    lib = made_up_library()
    inputs = rd.DesignInputs((15, 15), (0.0, 0.0, 150.0), (20.0, 0.0), 1)
    result = rd.run_design(lib, inputs)
    want = design(lib, (15, 15), (0.0, 0.0, 150.0), (20.0, 0.0), 10e9, bits=1)
    np.testing.assert_array_equal(result.array.parameter, want.parameter)
    n = result.numbers
    assert n.beam_direction == pytest.approx(want.beam_direction, abs=1e-9)
    assert abs(n.beam_direction[0] - 20.0) < 1.5
    assert n.gain == pytest.approx(want.gain)
    assert n.side_lobe_level == pytest.approx(want.side_lobe_level)
    assert n.quantization_loss == pytest.approx(want.quantization_loss)
    assert n.textbook_loss == pytest.approx(-3.92, abs=0.005)
    err = want.phase_error
    assert n.rms_error == pytest.approx(float(np.sqrt(np.mean(err**2))))
    assert n.largest_error == pytest.approx(float(np.abs(err).max()))
    assert n.pointing_error == pytest.approx(rd.angle_between((20.0, 0.0), want.beam_direction))
    lines = n.lines()
    assert lines[0].startswith(f"Main beam θ = {want.beam_direction[0]:.2f}°")
    assert lines[2] == (
        f"1-bit quantisation loss {want.quantization_loss:.2f} dB (textbook −3.9 dB for 1 bit)"
    ).replace("loss -", "loss −")
    # the cut: θ from −90° to 90° in the plane φ = 0, its peak at the beam
    theta, gain = result.cut
    assert theta[0] == -90.0 and theta[-1] == 90.0 and len(theta) == rd.CUT_POINTS
    np.testing.assert_allclose(gain[theta >= 0], want.pattern_db(theta[theta >= 0], 0.0))
    np.testing.assert_allclose(gain[theta < 0], want.pattern_db(-theta[theta < 0], 180.0))
    assert abs(theta[np.argmax(gain)] - n.beam_direction[0]) <= 0.5
    # the continuous design's cut beside it, a higher beam (the quantisation loss)
    ct, cg = result.continuous_cut
    np.testing.assert_allclose(
        cg, want.continuous().pattern_db(np.abs(ct), np.where(ct < 0, 180.0, 0.0))
    )
    assert cg.max() > gain.max() + 1.0


def test_a_continuous_design_has_no_quantisation_numbers():
    result = rd.run_design(
        made_up_library(), rd.DesignInputs((10, 12), (0.0, 0.0, 120.0), (10.0, 90.0))
    )
    assert result.continuous_cut is None
    assert result.numbers.quantization_loss is None and result.numbers.textbook_loss is None
    assert result.numbers.lines()[2].startswith("Continuous phases: no quantisation loss")
    assert rd.signed_theta(result.numbers.beam_direction, 90.0) > 0


def test_the_textbook_losses_are_the_designers():
    n = rd.DesignNumbers((0.0, 0.0), (0.1, 0.0), 20.0, -15.0, 10.0, 20.0, 3, -0.3, None)
    assert n.lines()[2].startswith("Continuous phases")  # no textbook value: not written
    for bits, said in ((1, "−3.9"), (2, "−0.9"), (3, "−0.2")):
        loss = textbook_quantization_loss(bits)
        n = rd.DesignNumbers((0.0, 0.0), (0.1, 0.0), 20.0, -15.0, 10.0, 20.0, bits, -1.0, loss)
        assert f"(textbook {said} dB for {bits} bit" in n.lines()[2]


def test_tiles_are_the_lattice_cells_around_the_elements():
    lattice = Lattice(a1=(12.0, 0.0), a2=(6.0, 10.392304845413264))  # hexagonal
    array = rd.run_design(
        made_up_library(lattice), rd.DesignInputs((3, 2), (0.0, 0.0, 100.0), (0.0, 0.0))
    ).array
    tiles = rd.element_outlines(array)
    assert tiles.shape == (6, 4, 2)
    np.testing.assert_allclose(tiles.mean(axis=1), array.positions[:, :2])
    np.testing.assert_allclose(tiles[:, 1] - tiles[:, 0], np.tile([12.0, 0.0], (6, 1)))
    np.testing.assert_allclose(
        tiles[:, 3] - tiles[:, 0], np.tile([6.0, 10.392304845413264], (6, 1))
    )


def test_the_picture_draws_the_design():
    pytest.importorskip("matplotlib")
    from barymesh.app.panels.reflectarray_figure import draw_design

    lib = made_up_library()
    result = rd.run_design(lib, rd.DesignInputs((15, 15), (0.0, 0.0, 150.0), (20.0, 0.0), 2))
    picture = draw_design(result, (1000, 640))
    assert picture.rgba.shape == (640, 1000, 4)
    fig = picture.figure
    param, error, cut = fig.axes[:3]
    np.testing.assert_array_equal(param.collections[0].get_array(), result.array.parameter)
    np.testing.assert_allclose(error.collections[0].get_array(), result.array.phase_error)
    assert [ln.get_label() for ln in cut.lines[:2]] == ["continuous phases", "2-bit phases"]
    texts = [t.get_text() for t in fig.texts]
    assert texts[2:5] == result.numbers.lines()
    # every text inside the picture, none over another (the numbers, the header)
    renderer = fig.canvas.get_renderer()
    boxes = [t.get_window_extent(renderer) for t in fig.texts]
    for box in boxes:
        assert box.x0 >= 0 and box.x1 <= 1000 and box.y0 >= 0 and box.y1 <= 640
    for i, a in enumerate(boxes):
        for b in boxes[i + 1 :]:
            assert not a.overlaps(b)
    empty = draw_design(None, (600, 400))
    assert "no design yet" in [t.get_text() for t in empty.figure.axes[0].texts]


def test_the_model_imports_neither_qt_nor_the_designer():
    code = (
        "import sys, barymesh.app.model.reflectarray_design; "
        "print(sorted(m for m in ('PySide6', 'barymesh.reflectarray', 'barymesh.mom', "
        "'matplotlib') if m in sys.modules))"
    )
    out = subprocess.run(
        [sys.executable, "-c", code], capture_output=True, text=True, check=True, timeout=120
    )
    assert out.stdout.strip() == "[]"
