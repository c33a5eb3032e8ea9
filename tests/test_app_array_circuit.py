"""The Infinite array tab's circuit without Qt (issue 33 §3, the window): the fit of a
swept curve, Luukkonen et al.'s reference and when it applies, the schematic's geometry
and values, and the figure's curves, shade and schematic (Agg)."""

import math

import numpy as np
import pytest

from barymesh.app.panels.array_circuit import (
    LUUKKONEN,
    CircuitFit,
    circuit_labels,
    fit_circuit,
    luukkonen_applies,
    schematic,
    square_patch,
)
from barymesh.app.panels.array_figures import SCHEMATIC_UNITS, draw_curve, wrapped_degrees
from barymesh.app.panels.array_sweep import ArrayInputs, ArraySweep
from barymesh.cell import Lattice, PixelGrid, UnitCell, build_cell
from barymesh.mom import Layer, Stack
from barymesh.mom.circuit import luukkonen_patch_reflection, reflection_from_sheet

P = 5.0  # mm
GROUNDED = Stack(below=(Layer(1.575, 2.2),), ground=True)
L_H, C_F = 0.21e-9, 44.7e-15  # a series LC near the patch's


def patch_mesh(rows=slice(1, 9), cols=slice(1, 9)):
    mask = np.zeros((10, 10), dtype=bool)
    mask[rows, cols] = True
    grid = PixelGrid(mask, pixel_size=P / 10, origin=(-P / 2, -P / 2), subdivisions=1)
    cell = UnitCell(lattice=Lattice.rectangular(P), pixels=grid, mode="conforming")
    return build_cell(cell).mesh


def sweep_of(reflection_of, f, stack=GROUNDED, theta=0.0, onsets=()):
    inputs = ArrayInputs(tuple(f), theta, 0.0, "TE", 0j, stack)
    r = reflection_of(np.asarray(f), inputs)
    return ArraySweep(np.asarray(f), r, np.zeros_like(r), tuple(onsets), np.zeros(0), inputs)


def series_lc(f, inputs):
    w = 2 * math.pi * f
    z = 1j * (w * L_H - 1 / (w * C_F))
    return reflection_from_sheet(f, z, inputs.stack, inputs.incidence())


@pytest.fixture(scope="module")
def patch():
    return patch_mesh()


def test_square_patches_are_recognised_and_others_are_not(patch):
    assert square_patch(patch) == pytest.approx((5.0, 1.0), abs=1e-12)
    assert square_patch(patch_mesh(slice(1, 9), slice(2, 8))) is None  # a rectangle
    assert square_patch(patch_mesh(slice(0, 10), slice(0, 10))) is None  # no gap
    ring = np.zeros((10, 10), dtype=bool)
    ring[1:9, 1:9] = True
    ring[3:7, 3:7] = False  # a square loop: its bounding box is not filled
    grid = PixelGrid(ring, pixel_size=0.5, origin=(-2.5, -2.5), subdivisions=1)
    loop = build_cell(UnitCell(Lattice.rectangular(P), pixels=grid, mode="conforming")).mesh
    assert square_patch(loop) is None


def test_the_luukkonen_overlay_is_the_analytic_model_on_the_tabs_slab(patch):
    f = np.linspace(6e9, 16e9, 11)
    sweep = sweep_of(series_lc, f)
    fit = fit_circuit(sweep, patch)
    assert fit.patch == pytest.approx((5.0, 1.0))
    expected = luukkonen_patch_reflection(fit.frequencies, 5.0, 1.0, 1.575, 2.2)
    np.testing.assert_allclose(fit.reference, expected, rtol=0, atol=1e-12)
    assert fit.frequencies[0] == f[0] and fit.frequencies[-1] == f[-1]
    # drawn dotted on the phase axes, from the same numbers
    picture = draw_curve(sweep, (600, 300), 1.0, fit)
    mag, phase, _schematic = picture.figure.axes
    (line,) = [x for x in phase.lines if x.get_label() == LUUKKONEN]
    x, y = np.asarray(line.get_xdata()), np.asarray(line.get_ydata())
    keep = np.isfinite(y)
    np.testing.assert_allclose(
        y[keep],
        np.degrees(np.angle(luukkonen_patch_reflection(x[keep] * 1e9, 5.0, 1.0, 1.575, 2.2))),
        rtol=0,
        atol=1e-9,
    )
    assert line.get_linestyle() == ":"
    # the reference's zero phase, 11.66 GHz for the 0.5 mm gap, is higher for a 1 mm one
    # (less capacitance): between the samples it crosses 0 once
    assert np.sum(np.diff(np.sign(np.angle(expected))) != 0) == 1


@pytest.mark.parametrize(
    "change",
    [
        {"theta": 30.0},  # oblique: the model is at normal incidence
        {"stack": Stack(below=(Layer(1.575, 2.2),))},  # no ground
        {"stack": Stack(above=(Layer(0.5, 3.0),), below=(Layer(1.575, 2.2),), ground=True)},
        {"stack": Stack(below=(Layer(1.0, 2.2), Layer(0.575, 3.0)), ground=True)},
        {"stack": Stack(below=(Layer(1.575, 2.2, 0.0, 2.0),), ground=True)},  # μr 2
    ],
)
def test_luukkonen_is_drawn_only_for_patches_on_one_grounded_slab_at_normal_incidence(
    patch, change
):
    f = np.linspace(6e9, 16e9, 5)
    inputs = {"stack": GROUNDED, "theta": 0.0, **change}
    sweep = sweep_of(
        lambda f, i: np.exp(1j * np.linspace(2.5, -0.5, len(f))),
        f,
        inputs["stack"],
        inputs["theta"],
    )
    assert luukkonen_applies(sweep, patch) is None
    assert fit_circuit(sweep, patch).reference is None


def test_a_known_circuit_is_recovered_and_labelled(patch):
    f = np.linspace(6e9, 16e9, 11)
    fit = fit_circuit(sweep_of(series_lc, f), patch)
    c = fit.circuit
    assert c.kind == "series"
    assert c.inductance == pytest.approx(L_H, rel=1e-6)
    assert c.capacitance == pytest.approx(C_F, rel=1e-6)
    assert fit.stops_at is None  # follows the curve over the whole band
    np.testing.assert_allclose(fit.reflection, c.reflection(fit.frequencies), atol=1e-15)
    assert circuit_labels(c) == [
        "series LC",
        f"L = {c.inductance * 1e9:.4g} nH",
        f"C = {c.capacitance * 1e15:.4g} fF",
        f"f0 = {c.resonance / 1e9:.4g} GHz",
    ]
    assert fit.note().startswith(c.describe()) and LUUKKONEN in fit.note()


def test_where_the_circuit_stops_describing_the_curve_is_shaded(patch):
    """A second resonance the one LC has not got (a second series LC across the first,
    at 20 GHz): from where the circuit leaves the curve by 0.05, the band is shaded."""
    f = np.linspace(4.1e9, 24.1e9, 41)

    def two_modes(f, inputs):
        w = 2 * math.pi * f

        def lc(f0, inductance):
            return 1j * (w * inductance - 1 / (w / (2 * math.pi * f0) ** 2 / inductance))

        z1, z2 = lc(12e9, 0.3e-9), lc(20e9, 3e-9)
        return reflection_from_sheet(f, z1 * z2 / (z1 + z2))

    sweep = sweep_of(two_modes, f, stack=None)
    fit = fit_circuit(sweep, patch)
    assert fit.circuit is not None and fit.stops_at is not None
    assert fit.stops_at == fit.circuit.valid_below
    assert 15e9 < fit.stops_at < 20e9  # above the first resonance, below the second
    assert "Shaded from" in fit.note()
    mag, phase, _ = draw_curve(sweep, (600, 300), 1.0, fit).figure.axes
    (shade,) = mag.patches  # from where it stops to the band's end
    x0, x1 = shade.get_x(), shade.get_x() + shade.get_width()
    assert x0 == pytest.approx(fit.stops_at / 1e9) and x1 == pytest.approx(24.1)
    assert any(t.get_text() == "circuit ≠ cell" for t in phase.texts)


def test_a_refused_fit_is_a_sentence_and_the_curve_is_drawn(patch):
    f = np.linspace(20e9, 30e9, 4)
    sweep = sweep_of(series_lc, f, stack=None, onsets=((24.98e9, ((1, 0),)),))
    fit = fit_circuit(sweep, patch)
    assert fit.circuit is None and fit.reflection.size == 0
    assert fit.refused.startswith("2 frequencies to fit (below the first onset 24.98 GHz")
    assert fit.note() == f"No circuit: {fit.refused}"
    mag, _phase, schematic_axes = draw_curve(sweep, (600, 300), 1.0, fit).figure.axes
    assert [x.get_label() for x in mag.lines if x.get_label()[0] != "_"] == ["|R|", "|T|"]
    assert schematic_axes.texts[0].get_text() == "no circuit"


def test_a_narrow_figure_puts_the_values_in_the_legend(patch):
    sweep = sweep_of(series_lc, np.linspace(6e9, 16e9, 6))
    fit = fit_circuit(sweep, patch)
    figure = draw_curve(sweep, (360, 260), 1.0, fit).figure
    assert len(figure.axes) == 2
    title = figure.axes[0].get_legend().get_title().get_text()
    assert f"L = {fit.circuit.inductance * 1e9:.4g} nH" in title
    # a fit of another curve is not drawn
    other = sweep_of(series_lc, np.linspace(6e9, 16e9, 6))
    assert len(draw_curve(other, (600, 300), 1.0, fit).figure.axes) == 2


def test_schematic_geometry_follows_the_kind_and_the_stack():
    free = schematic("series")
    assert [e[0] for e in free.elements] == ["L", "C", "η0"]  # vacuum under the sheet
    assert free.ground is None and free.boxes == []
    (l_, top_l, bottom_l), (c_, top_c, bottom_c) = [(e[1], e[3], e[2]) for e in free.elements[:2]]
    assert l_ == c_ and bottom_l == pytest.approx(top_c)  # in series, one above the other
    grounded = schematic("parallel", GROUNDED, lossy=True)
    names = [e[0] for e in grounded.elements]
    assert names == ["L", "C", "R"]  # across each other, side by side, the short at the end
    assert len({e[1] for e in grounded.elements}) == 3
    assert grounded.ground == (grounded.width, 0.0)
    assert [b[4] for b in grounded.boxes] == ["εr 2.2\n1.575\nmm"]
    two = Stack(above=(Layer(0.5, 3.0),), below=(Layer(1.575, 2.2),), ground=True)
    boxes = schematic("series", two).boxes
    sheet_x = next(t[0] for t in schematic("series", two).texts if t[2] == "sheet")
    assert [b[4] for b in boxes] == ["εr 3\n0.5\nmm", "εr 2.2\n1.575\nmm"]
    assert boxes[0][0] + boxes[0][2] < sheet_x < boxes[1][0]  # above, the sheet, below


def test_phase_wraps_are_broken_not_drawn_across():
    x, y = wrapped_degrees(np.array([1.0, 2.0, 3.0]), np.exp(1j * np.radians([170, -170, -160])))
    np.testing.assert_allclose(x, [1.0, 1.5, 2.0, 3.0])
    assert np.isnan(y[1]) and y[[0, 2, 3]] == pytest.approx([170, -170, -160])


def test_circuit_fit_is_plain_data():
    fit = CircuitFit(sweep=None, refused="why")
    assert fit.circuit is None and fit.stops_at is None and fit.note() == "No circuit: why"


@pytest.mark.parametrize("ratio", [1.0, 2.0])
def test_more_layers_widen_the_schematic_and_its_labels_fit_their_boxes(patch, ratio):
    stacks = [
        GROUNDED,
        Stack(above=(Layer(0.5, 3.0),), below=(Layer(1.575, 2.2),), ground=True),
        Stack(above=(Layer(0.5, 3.0),), below=(Layer(1.0, 2.2), Layer(0.575, 3.0)), ground=True),
    ]
    f = np.linspace(6e9, 16e9, 6)
    scales = []
    for stack in stacks:
        sweep = sweep_of(series_lc, f, stack=stack)
        figure = draw_curve(sweep, (900, 420), ratio, fit_circuit(sweep, patch)).figure
        assert len(figure.axes) == 3  # the curves and the schematic's column
        column = figure.axes[2]
        units = schematic("series", stack).width
        scales.append(column.get_window_extent().width / units)  # device pixels per unit
        renderer = figure.canvas.get_renderer()
        boxes = [p.get_window_extent(renderer) for p in column.patches]
        labels = [t for t in column.texts if t.get_text().startswith("εr")]
        assert len(boxes) == len(labels) == len(stack.above) + len(stack.below)
        for box, label in zip(boxes, labels, strict=True):
            text = label.get_window_extent(renderer)
            assert box.x0 <= text.x0 and text.x1 <= box.x1, label.get_text()
            assert box.y0 <= text.y0 and text.y1 <= box.y1, label.get_text()
    # one scale whatever the stack: the column grows rather than the drawing shrinking
    assert scales == pytest.approx([scales[0]] * len(scales), rel=0.02)
    # the plain column is the width of a series sheet on one grounded layer
    assert schematic("series", GROUNDED).width == pytest.approx(SCHEMATIC_UNITS)
