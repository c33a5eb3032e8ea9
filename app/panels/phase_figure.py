"""The Reflection phase tab's S-curve, drawn off the GUI thread (matplotlib Agg, no Qt).

:func:`draw_phase_curve` draws the co-polar ∠R (degrees, unwrapped along the parameter)
over |R| against the parameter, the cell on screen marked on both (a dashed line, a dot
on each curve and its value), and over the axes two lines: where ∠R is referred (the
stack's top face, or the sheet) and how much of the 360° the curve covers. A preview (the
first pass of :func:`barymesh.app.panels.phase_curve.solve_curve`) is drawn the same
way, its title saying so. The picture keeps the parameter axis' span in pixels
(:class:`barymesh.app.panels.array_figures.Picture` with ``x_scale`` 1), so that a click
reads a value.
"""

from __future__ import annotations

from typing import Any

import numpy as np

from barymesh.app.model.stack_rows import reference_plane_names
from barymesh.app.panels.array_figures import R_COLOR, Picture, drawn_rgba, new_figure
from barymesh.app.panels.phase_curve import coverage

#: Colour of the cell on screen's mark.
MARK_COLOR = "#d62728"


def parameter_unit(path: str) -> str:
    """The unit of a parameter path's values, for the axis' label.

    >>> parameter_unit("elements[0].rotation"), parameter_unit("elements[1].gap_width")
    ('°', 'mm')
    """
    name = path.rsplit(".", 1)[-1].split("[")[0]
    if name in ("rotation", "angle_step", "gap_angle") or name.endswith("_angle"):
        return "°"
    if name in ("eps_r", "mu_r", "loss_tangent"):
        return ""
    return "mm"


def coverage_text(degrees: float) -> str:
    """ "covers 310° of 360°", or more than a turn said as such.

    >>> coverage_text(309.6), coverage_text(410.0)
    ('covers 310° of 360°', 'covers 410°: more than a full turn')
    """
    if degrees > 360.0:
        return f"covers {degrees:.0f}°: more than a full turn"
    return f"covers {degrees:.0f}° of 360°"


def plane_text(library: Any) -> str:
    """Where the curve's ∠R is referred, in words and z (mm)."""
    stack = library.stack
    if stack is not None and library.reference_plane > 0:
        return f"∠R referred to the stack's top face, z = {library.reference_plane:g} mm"
    r_plane, _t = reference_plane_names(stack)
    return f"∠R referred to {r_plane}"


def label_corner(
    x: np.ndarray,
    y: np.ndarray,
    marked: float,
    xlim: tuple[float, float],
    ylim: tuple[float, float],
) -> tuple[bool, bool]:
    """(right of the mark, at the top) for the mark's label: the one of the four places
    beside the mark's line (a box 0.3 wide and 0.3 high in axes fractions) that the curve
    ``x``, ``y`` (sorted by x) crosses least.

    >>> x = np.array([0.0, 1.0, 2.0]); y = np.array([0.0, 1.0, 2.0])  # rising
    >>> label_corner(x, y, 1.0, (0.0, 2.0), (0.0, 2.0))  # right-bottom or left-top: free
    (True, False)
    """
    xs = np.linspace(x[0], x[-1], 400) if len(x) > 1 else x
    ys = np.interp(xs, x, y)
    fx = (xs - xlim[0]) / (xlim[1] - xlim[0])
    fy = (ys - ylim[0]) / (ylim[1] - ylim[0])
    m = (marked - xlim[0]) / (xlim[1] - xlim[0])
    best, choice = None, (True, True)
    for right in (True, False):
        for top in (True, False):
            a, b = (m, m + 0.3) if right else (m - 0.3, m)
            c, d = (0.65, 1.0) if top else (0.0, 0.35)
            crossed = int(np.count_nonzero((fx >= a) & (fx <= b) & (fy >= c) & (fy <= d)))
            crossed += 1000 * int(a < 0.0 or b > 1.0)  # out of the axes: last resort
            if best is None or crossed < best:
                best, choice = crossed, (right, top)
    return choice


def draw_phase_curve(
    library: Any,
    marked: float | None,
    size: tuple[int, int],
    ratio: float = 1.0,
    preview: int = 0,
) -> Picture:
    """The S-curve of a ``ReflectionLibrary`` of one frequency (None: empty axes),
    ``marked`` the cell on screen's value (None: not drawn), ``size`` widget pixels (w, h)
    at ``ratio`` device pixels per pixel; ``preview`` > 0: the values still to come."""
    fig, canvas = new_figure(size, ratio)
    w, h = max(size[0], 50), max(size[1], 50)
    left = min(0.3, 58.0 / w)
    bottom = min(0.3, 36.0 / h)
    top = 1.0 - min(0.3, 34.0 / h)  # two lines of text over the axes
    fig.subplots_adjust(left=left, right=0.97, top=top, bottom=bottom, hspace=0.08)
    ph, mag = fig.subplots(2, 1, sharex=True, gridspec_kw={"height_ratios": [2.2, 1.0]})
    for ax in (ph, mag):
        ax.grid(alpha=0.3)
        ax.tick_params(labelsize=7)
    ph.set_ylabel("∠R (°)", fontsize=8)
    mag.set_ylabel("|R|", fontsize=8)
    mag.set_ylim(0.0, 1.08)
    if library is None:
        ph.text(0.5, 0.5, "no curve yet", transform=ph.transAxes, ha="center", fontsize=8)
        mag.set_xlabel("parameter", fontsize=8)
    else:
        unit = parameter_unit(library.parameter)
        mag.set_xlabel(library.parameter + (f" ({unit})" if unit else ""), fontsize=8)
        x = np.asarray(library.values, dtype=float)
        phase = np.asarray(library.phase_deg)[:, 0]
        magnitude = np.asarray(library.magnitude)[:, 0]
        order = np.argsort(x, kind="stable")  # drawn left to right (unwrapped as given)
        ph.plot(x[order], phase[order], color=R_COLOR, marker="o", ms=3.5, lw=1.4)
        mag.plot(x[order], magnitude[order], color=R_COLOR, marker="o", ms=3.0, lw=1.2)
        span = float(np.ptp(phase)) if len(phase) else 0.0
        middle = 0.5 * (float(phase.max()) + float(phase.min()))
        half = max(0.5 * span, 20.0) * 1.12
        ph.set_ylim(middle - half, middle + half)
        pad = 0.03 * (x.max() - x.min()) if len(x) > 1 else 0.5
        ph.set_xlim(x.min() - pad, x.max() + pad)
        f = float(library.frequencies[0])
        inc = library.incidence
        head = (
            f"{f / 1e9:.4g} GHz, {library.polarization}, θ {inc['theta']:g}°, φ {inc['phi']:g}°"
            f": {coverage_text(coverage(library))}"
        )
        if preview:
            head += f" (preview, {preview} more values coming)"
        fig.text(left, 1.0 - 3.0 / h, head, fontsize=8, va="top", ha="left")
        fig.text(left, 1.0 - 18.0 / h, plane_text(library), fontsize=7, va="top", ha="left")
        if marked is not None and len(x) and x.min() - pad <= marked <= x.max() + pad:
            for ax in (ph, mag):
                ax.axvline(marked, color=MARK_COLOR, lw=1.0, ls="--")
            if len(x) > 1:
                at_phase = float(np.interp(marked, x[order], phase[order]))
                at_mag = float(np.interp(marked, x[order], magnitude[order]))
                ph.plot([marked], [at_phase], marker="o", ms=7, mfc="none", color=MARK_COLOR)
                mag.plot([marked], [at_mag], marker="o", ms=6, mfc="none", color=MARK_COLOR)
                corner = label_corner(x[order], phase[order], marked, ph.get_xlim(), ph.get_ylim())
                right, top = corner
                ph.annotate(
                    f"this cell: {marked:.4g}{unit and ' ' + unit}\n∠R ≈ {at_phase:.0f}°",
                    (marked, 0.96 if top else 0.04),
                    xycoords=("data", "axes fraction"),
                    xytext=(5 if right else -5, 0),
                    textcoords="offset points",
                    ha="left" if right else "right",
                    va="top" if top else "bottom",
                    fontsize=7,
                    color=MARK_COLOR,
                )
    rgba = drawn_rgba(canvas)
    height = rgba.shape[0]
    box_p, box_m = ph.get_window_extent(), mag.get_window_extent()
    return Picture(
        rgba,
        ratio,
        fig,
        (float(box_p.x0), float(box_p.x1)),
        (height - float(box_p.y1), height - float(box_m.y0)),
        (float(ph.get_xlim()[0]), float(ph.get_xlim()[1])),
        x_scale=1.0,
    )
