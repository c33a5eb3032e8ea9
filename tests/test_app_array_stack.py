"""The Infinite array tab's stack without Qt (issue 29, Window): typed rows read into a
Stack, the side view's geometry to scale, the names of the reference planes, the onsets
of orders guided inside a layer (closed forms), the zero crossings of ∠R and the figure's
phase axis."""

import math

import numpy as np
import pytest

from barymesh.app.model.stack_rows import (
    LayerRow,
    read_stack,
    read_thickness,
    reference_plane_names,
)
from barymesh.app.model.stack_sketch import GROUND, VACUUM, sketch_layout
from barymesh.app.panels.array_sweep import (
    ArrayInputs,
    ArraySweep,
    guided_onsets,
    zero_phase_frequencies,
)
from barymesh.constants import SPEED_OF_LIGHT
from barymesh.mom import Layer, Stack, parse_stack

P = 0.012  # m: a 12 mm square lattice
SQUARE = np.eye(2) * P


def test_rows_read_into_the_stack_the_command_line_reads():
    rows = (LayerRow("0.5", "3"), LayerRow("62mil", "2.2", "0.0009"), LayerRow("35um", "1"))
    stack = read_stack(rows, sheet=1, ground=True)
    assert stack == parse_stack("0.5mm eps=3; sheet; 62mil eps=2.2 tand=0.0009; 35um; ground")
    assert stack.below[0].thickness == pytest.approx(1.5748)
    assert stack.below[1].thickness == pytest.approx(0.035)
    # empty tan δ and μr are 0 and 1
    assert read_stack((LayerRow("1", "2", "", ""),), 0, False).below[0] == Layer(1.0, 2.0)


@pytest.mark.parametrize(
    ("rows", "sheet", "ground", "message"),
    [
        (
            (LayerRow("-1", "2.2"),),
            0,
            False,
            "Layer 1 (below the sheet): thickness '-1' is invalid; expected a thickness >= 0",
        ),
        (
            (LayerRow("1", "2"), LayerRow("1", "0")),
            0,
            False,
            "Layer 2 (below the sheet): εr '0' is invalid; expected a number, 0 < εr <= 10000",
        ),
        (
            (LayerRow("1", "2", "-0.1"),),
            1,
            False,
            "Layer 1 (above the sheet): tan δ '-0.1' is invalid; expected a number, 0 <= tan δ",
        ),
        ((LayerRow("1", "2", "", "mu"),), 0, False, "Layer 1 (below the sheet): μr 'mu' is"),
        ((LayerRow("1,5", "2"),), 0, False, "Layer 1 (below the sheet): thickness '1,5' is"),
        ((LayerRow("1", ""),), 0, False, "Layer 1 (below the sheet): εr '' is invalid"),
        ((), 0, True, "Ground plane: it needs a layer of non-zero thickness below the sheet"),
        ((LayerRow("1", "2"),), 1, True, "Ground plane: it needs a layer of non-zero"),
        ((LayerRow("0", "2"),), 0, True, "Ground plane: it needs a layer of non-zero"),
    ],
)
def test_a_bad_row_names_the_layer_the_column_and_what_was_expected(rows, sheet, ground, message):
    with pytest.raises(ValueError) as caught:
        read_stack(rows, sheet, ground)
    assert str(caught.value).startswith(message), str(caught.value)


def test_thickness_units():
    assert read_thickness("30mil") == pytest.approx(0.762)
    assert read_thickness("0.1 in") == pytest.approx(2.54)
    assert read_thickness("0.2cm") == pytest.approx(2.0)
    assert read_thickness("35 µm") == pytest.approx(0.035)


def test_reference_planes_are_named_with_their_heights():
    assert reference_plane_names(Stack()) == ("the sheet, z = 0 mm", "the sheet, z = 0 mm")
    grounded = Stack(above=(Layer(0.5, 3), Layer(1.0, 2)), below=(Layer(1.575, 2.2),), ground=True)
    assert reference_plane_names(grounded) == ("the top face, z = 1.5 mm", None)
    below_only = Stack(below=(Layer(0.8, 4.4),))
    assert reference_plane_names(below_only) == (
        "the sheet, z = 0 mm",
        "the bottom face, z = −0.8 mm",
    )


def test_the_side_view_is_drawn_to_scale():
    stack = Stack(above=(Layer(0.5, 3),), below=(Layer(1.0, 2.2), Layer(2.5, 1)), ground=True)
    height = 200.0
    s = sketch_layout(stack, height)
    room = height - VACUUM - (GROUND + 2.0)
    heights = [b.bottom - b.top for b in s.bands]
    # every band's height over its thickness is one scale, the whole stack fills the room
    np.testing.assert_allclose(np.array(heights) / [0.5, 1.0, 2.5], room / 4.0)
    assert s.mm_per_pixel == pytest.approx(4.0 / room)
    assert s.top_face == VACUUM and s.bottom_face == pytest.approx(height - GROUND - 2.0)
    assert s.sheet == pytest.approx(s.bands[0].bottom)  # under the layer above it
    assert s.ground == (pytest.approx(s.bottom_face), pytest.approx(s.bottom_face + GROUND))
    assert [name for _y, name in s.planes] == ["R at the top face"]  # T = 0 on ground
    assert [b.label for b in s.bands] == ["0.5 mm, εr 3", "1 mm, εr 2.2", "2.5 mm, εr 1"]
    # without ground: T's plane at the bottom face; free-standing: one plane at the sheet
    open_ = sketch_layout(Stack(below=(Layer(1.0, 2.2),)), height)
    assert [(y, n) for y, n in open_.planes] == [
        (VACUUM, "R at the sheet"),
        (pytest.approx(height - VACUUM), "T at the bottom face"),
    ]
    alone = sketch_layout(None, height)
    assert alone.bands == () and alone.planes == ((height / 2, "R, T at the sheet"),)


def test_guided_onsets_at_normal_incidence_are_c_over_p_sqrt_eps():
    slab = Stack(below=(Layer(1.575, 2.2),), ground=True)
    (hz, orders, layers), *rest = guided_onsets(SQUARE, 0.0, 0.0, (5e9, 24e9), slab)
    assert hz == pytest.approx(SPEED_OF_LIGHT / (P * math.sqrt(2.2)), rel=1e-12)
    assert orders == ((-1, 0), (0, -1), (0, 1), (1, 0)) and layers == (0,)
    # the diagonal orders (±1, ±1) at √2 c / (P √εr)
    assert rest[0][0] == pytest.approx(math.sqrt(2) * hz, rel=1e-12)
    assert rest[0][1] == ((-1, -1), (-1, 1), (1, -1), (1, 1))
    # a vacuum layer or one of zero thickness guides nothing; two equal layers merge
    assert guided_onsets(SQUARE, 0, 0, (5e9, 24e9), Stack(below=(Layer(2, 1),))) == ()
    assert guided_onsets(SQUARE, 0, 0, (5e9, 24e9), Stack(below=(Layer(0, 4),))) == ()
    two = Stack(above=(Layer(1, 2.2),), below=(Layer(1, 2.2),))
    assert guided_onsets(SQUARE, 0, 0, (5e9, 20e9), two)[0][2] == (0, 1)


def test_guided_onsets_at_oblique_incidence():
    # θ = 20° in the xz plane: order (p, 0) guided in a layer of index n once
    # |−k sin θ + 2π p / P| = n k, i.e. f = c |p| / (P (n ± sin θ))
    n, s = math.sqrt(3.0 * 1.5), math.sin(math.radians(20.0))
    stack = Stack(below=(Layer(1.0, 3.0, mu_r=1.5),))
    found = guided_onsets(SQUARE, 20.0, 0.0, (1e9, 16e9), stack)
    first = {o: f for f, orders, _ in found for o in orders}
    assert first[(1, 0)] == pytest.approx(SPEED_OF_LIGHT / (P * (n + s)), rel=1e-12)
    assert first[(-1, 0)] == pytest.approx(SPEED_OF_LIGHT / (P * (n - s)), rel=1e-12)


def test_guided_onsets_search_far_enough_for_a_dense_layer():
    # εr = 100 (index 10): the orders up to |p| = 7 start inside 0-18 GHz, beyond the
    # vacuum search's ±4
    found = guided_onsets(SQUARE, 0, 0, (1e9, 18e9), Stack(below=(Layer(1, 100),)))
    largest = max(abs(p) for _f, orders, _l in found for p, _q in orders)
    expected = math.floor(18e9 * P * 10 / SPEED_OF_LIGHT)
    assert largest == expected == 7


def test_zero_phase_crossings_skip_the_jumps_through_180():
    f = np.linspace(1e9, 5e9, 5)
    phase = np.radians([170.0, 60.0, -20.0, -175.0, 175.0])  # 0 once, ±180 once
    (hz,) = zero_phase_frequencies(f, np.exp(1j * phase))
    assert hz == pytest.approx(2e9 + 1e9 * 60 / 80)


def _sweep(stack, r, t):
    f = np.linspace(5e9, 15e9, len(r))
    inputs = ArrayInputs(tuple(f), 0.0, 0.0, "TE", 0j, stack)
    return ArraySweep(f, np.asarray(r), np.asarray(t), (), np.zeros(0), inputs)


def test_the_phase_axis_names_the_reference_plane():
    pytest.importorskip("matplotlib")
    from barymesh.app.panels.array_figures import draw_curve

    r = np.exp(1j * np.radians([120.0, 30.0, -60.0]))
    grounded = Stack(above=(Layer(0.5, 3),), below=(Layer(1.575, 2.2),), ground=True)
    fig = draw_curve(_sweep(grounded, r, np.zeros(3)), (500, 300)).figure
    mag, ph = fig.axes
    assert ph.get_ylabel() == "∠R (°) at the top face,\nz = 0.5 mm"
    assert mag.get_ylabel() == "|R| (dB)"
    assert [line.get_label() for line in mag.lines] == ["|R|"]  # T = 0: not drawn
    np.testing.assert_allclose(ph.lines[0].get_ydata(), [120.0, 30.0, -60.0])
    # |R| = 1 is drawn over at least a decibel, not as noise around 0 dB
    low, high = mag.get_ylim()
    assert high - low >= 1.0 and low < 0.0 < high
    # on layers without ground ∠T has its own plane, in the legend
    open_ = Stack(below=(Layer(0.8, 4.4),))
    fig = draw_curve(_sweep(open_, r, 0.5 * r), (500, 300)).figure
    ph = fig.axes[1]
    assert ph.get_ylabel() == "∠R (°) at the sheet,\nz = 0 mm"
    assert [line.get_label() for line in ph.lines[:2]] == [
        "∠R",
        "∠T at the bottom face, z = −0.8 mm",
    ]
    fig = draw_curve(_sweep(None, r, 0.5 * r), (500, 300)).figure
    assert fig.axes[1].get_ylabel() == "∠R, ∠T (°) at the sheet,\nz = 0 mm"
