"""The reflectarray designer's picture, drawn off the GUI thread (matplotlib Agg, no Qt).

:func:`draw_design` draws a :class:`~barymesh.app.model.reflectarray_design.DesignResult`:
over the top, the layout twice, each element its cell of the lattice (a tile), coloured by
the library's parameter chosen for it and by its phase error (degrees, achieved − required),
the feed's foot marked; under them the gain in the plane of the beam (dBi against θ, the
continuous design's in grey behind a quantised one), the main beam's direction and the
side-lobe level marked; between the two, the numbers (:meth:`DesignNumbers.lines`: the main
beam, the side lobes, the quantisation loss against the textbook value). Without a design
the axes say so.
"""

from __future__ import annotations

from typing import Any

import numpy as np

from barymesh.app.model.reflectarray_design import (
    element_outlines,
    minus,
    signed_theta,
)
from barymesh.app.panels.array_figures import R_COLOR, Picture, drawn_rgba, new_figure
from barymesh.app.panels.phase_figure import parameter_unit

#: Colour of the continuous design's cut behind a quantised one, and of the marks.
GREY = "#9a9a9a"
#: dB under the main beam's gain the cut's axis goes down to.
CUT_RANGE_DB = 40.0
#: Pixel heights of the picture's rows of text (a line of 8-point text and its gap).
LINE = 14.0


def _fractions(w: float, h: float) -> dict[str, tuple[float, float, float, float]]:
    """Where each axes goes (left, bottom, width, height, figure fractions) for a picture of
    ``w`` x ``h`` pixels: the header line, the two layouts and their colour bars, the
    numbers' three lines, the cut (room for its ticks and labels kept in pixels)."""
    head = 2 * LINE + 12  # the header's two lines and the layouts' titles
    numbers = 3 * LINE + 10
    cut_bottom = 38.0
    rest = h - head - numbers - cut_bottom - 30.0  # 30: the layouts' x labels
    top_h = max(0.55 * rest, 60.0)
    cut_h = max(rest - top_h, 40.0)
    # columns: y label and ticks | layout | colour bar and its labels | ticks | layout | bar
    left, bar, labels, ticks = 58.0, 12.0, 52.0, 40.0
    half = max((w - left - 2 * (6 + bar + labels) - ticks) / 2, 40.0)
    x_err = left + half + 6 + bar + labels + ticks
    y_top = h - head - top_h
    out = {
        "param": (left, y_top, half, top_h),
        "param_bar": (left + half + 6, y_top, bar, top_h),
        "error": (x_err, y_top, half, top_h),
        "error_bar": (x_err + half + 6, y_top, bar, top_h),
        "cut": (left, cut_bottom, w - left - 16.0, cut_h),
    }
    return {k: (x / w, y / h, a / w, b / h) for k, (x, y, a, b) in out.items()}


def _layout(ax: Any, array: Any, values: np.ndarray, cmap: str, lim: tuple[float, float]) -> Any:
    from matplotlib.collections import PolyCollection

    tiles = PolyCollection(
        list(element_outlines(array)), array=values, cmap=cmap, edgecolors="white", linewidths=0.3
    )
    tiles.set_clim(*lim)
    ax.add_collection(tiles)
    corners = element_outlines(array).reshape(-1, 2)
    lo, hi = corners.min(axis=0), corners.max(axis=0)
    pad = 0.03 * float((hi - lo).max())
    ax.set_xlim(lo[0] - pad, hi[0] + pad)
    ax.set_ylim(lo[1] - pad, hi[1] + pad)
    ax.set_aspect("equal", adjustable="box", anchor="C")
    fx, fy, _fz = array.feed
    if lo[0] <= fx <= hi[0] and lo[1] <= fy <= hi[1]:
        ax.plot([fx], [fy], marker="+", ms=9, mew=1.6, color="black")
    ax.tick_params(labelsize=7)
    ax.set_xlabel("x (mm)", fontsize=8, labelpad=1)
    return tiles


def draw_design(result: Any, size: tuple[int, int], ratio: float = 1.0) -> Picture:
    """The picture of a ``DesignResult`` (None: empty axes), ``size`` widget pixels (w, h)
    at ``ratio`` device pixels per pixel."""
    fig, canvas = new_figure(size, ratio)
    w, h = float(max(size[0], 50)), float(max(size[1], 50))
    at = _fractions(w, h)
    param = fig.add_axes(at["param"])
    error = fig.add_axes(at["error"])
    cut = fig.add_axes(at["cut"])
    cut.grid(alpha=0.3)
    cut.tick_params(labelsize=7)
    cut.set_ylabel("gain (dBi)", fontsize=8)
    top = 1.0 - 3.0 / h
    if result is None:
        for ax in (param, error, cut):
            ax.text(0.5, 0.5, "no design yet", transform=ax.transAxes, ha="center", fontsize=8)
        cut.set_xlabel("θ (°)", fontsize=8)
        fig.text(
            at["param"][0],
            top,
            "No design yet: type the inputs, press Design.",
            fontsize=8,
            va="top",
        )
        return Picture(drawn_rgba(canvas), ratio, fig)
    array, inputs, numbers = result.array, result.inputs, result.numbers
    lib = array.library
    n1, n2 = array.aperture
    unit = parameter_unit(lib.parameter)
    bits = "continuous phases" if array.bits is None else f"{array.bits}-bit phases"
    fx, fy, fz = array.feed
    fig.text(
        at["param"][0],
        top,
        f"{n1} × {n2} elements at {array.frequency / 1e9:.4g} GHz, {bits}; feed at "
        f"({fx:g}, {fy:g}, {fz:g}) mm (+), beam asked θ = {inputs.beam[0]:g}°, "
        f"φ = {inputs.beam[1]:g}°",
        fontsize=8,
        va="top",
    )
    fig.text(
        at["param"][0],
        top - LINE / h,
        "Each element as in an infinite array of itself (local periodicity); "
        "the phase the library's curve cannot reach is its nearest end.",
        fontsize=7,
        va="top",
        color="#555555",
    )
    values = np.asarray(array.parameter, dtype=float)
    v_lo, v_hi = float(lib.values.min()), float(lib.values.max())
    tiles = _layout(param, array, values, "viridis", (v_lo, v_hi))
    param.set_ylabel("y (mm)", fontsize=8, labelpad=1)
    param.set_title(f"{lib.parameter} of each element", fontsize=8, pad=3)
    bar = fig.colorbar(tiles, cax=fig.add_axes(at["param_bar"]))
    bar.ax.tick_params(labelsize=7)
    bar.set_label(
        f"{lib.parameter.rsplit('.', 1)[-1]}" + (f" ({unit})" if unit else ""), fontsize=7
    )
    err = np.asarray(array.phase_error, dtype=float)
    lim = max(float(np.abs(err).max()), 1.0)
    tiles = _layout(error, array, err, "RdBu_r", (-lim, lim))
    error.set_title(
        f"phase error (achieved − required): RMS {numbers.rms_error:.1f}°", fontsize=8, pad=3
    )
    bar = fig.colorbar(tiles, cax=fig.add_axes(at["error_bar"]))
    bar.ax.tick_params(labelsize=7)
    bar.set_label("phase error (°)", fontsize=7)
    # the numbers, between the layouts and the cut
    y = at["cut"][1] + at["cut"][3] + (3 * LINE + 4) / h
    for k, line in enumerate(numbers.lines()):
        fig.text(
            at["cut"][0],
            y - k * LINE / h,
            line,
            fontsize=8,
            va="top",
            weight="bold" if k == 0 else "normal",
        )
    theta, gain = result.cut
    phi_b = float(inputs.beam[1])
    if result.continuous_cut is not None:
        ct, cg = result.continuous_cut
        cut.plot(ct, cg, color=GREY, lw=1.0, label="continuous phases")
    cut.plot(theta, gain, color=R_COLOR, lw=1.3, label=bits)
    peak = numbers.gain
    cut.set_ylim(peak - CUT_RANGE_DB, peak + 4.0)
    cut.set_xlim(-90.0, 90.0)
    cut.set_xticks(np.arange(-90.0, 91.0, 15.0))
    beam_at = signed_theta(numbers.beam_direction, phi_b)
    cut.axvline(beam_at, color="black", lw=0.8, ls=":")
    cut.annotate(
        f"main beam {numbers.beam_direction[0]:.1f}°",
        (beam_at, peak + 4.0),
        xytext=(4, -3),
        textcoords="offset points",
        ha="left",
        va="top",
        fontsize=7,
    )
    if np.isfinite(numbers.side_lobe_level):
        level = peak + numbers.side_lobe_level
        cut.axhline(level, color=GREY, lw=0.8, ls="--")
        cut.annotate(
            f"side-lobe level {minus(numbers.side_lobe_level, 1)} dB (all directions)",
            (-88.0, level),
            xytext=(0, 2),
            textcoords="offset points",
            ha="left",
            va="bottom",
            fontsize=7,
            color="#555555",
        )
    cut.set_xlabel(f"θ (°) in the plane φ = {phi_b:g}° (θ < 0: φ = {phi_b + 180.0:g}°)", fontsize=8)
    cut.legend(loc="upper right", fontsize=7, framealpha=0.85)
    return Picture(drawn_rgba(canvas), ratio, fig)
