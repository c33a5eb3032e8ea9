"""The Infinite array tab's two figures, drawn off the GUI thread (matplotlib Agg, no Qt).

A matplotlib draw of the R/T curve took 190 ms on a loaded 2-core machine, and 530 ms
while a sweep ran beside it (the two threads share the GIL): a live curve drawn on the GUI
thread froze the window at every new result. So the figures are drawn in the worker, after
the sweep or the solve, into an RGBA array (:class:`Picture`); the GUI thread only shows
it. A picture keeps what a click needs: the frequency axis' span in pixels.

:func:`draw_curve` draws |R| and |T| (dB) and their phase against frequency, the
grating-lobe onsets (dotted, labelled), the onsets of orders guided inside a layer
(dash-dotted) and the resonances (dashed, labelled in GHz). The phase axis names the
plane ∠R is referred to (the stack's top face, or the sheet): a reflection phase means
nothing without it. ∠T, referred to the bottom face, is drawn when the planes differ with
its own plane in the legend, and not at all over a ground plane (T = 0).
:func:`draw_orders` draws the propagating Floquet orders as arrows leaving the screen.
"""

from __future__ import annotations

import math
import textwrap
from dataclasses import dataclass
from typing import Any

import numpy as np

from barymesh.app.model.stack_rows import reference_plane_names
from barymesh.app.panels.array_circuit import LUUKKONEN, circuit_labels, schematic

#: Colours of |R| and |T|, of the grating-lobe onsets and of the resonances.
R_COLOR, T_COLOR = "#1f77b4", "#2ca02c"
ONSET_COLOR, RESONANCE_COLOR = "#7f3fbf", "#d62728"
GUIDED_COLOR = "#8c564b"
#: The fitted circuit's curves (dashed), the analytic reference's (dotted) and the shade
#: over the frequencies where the circuit no longer describes the cell.
CIRCUIT_COLOR, REFERENCE_COLOR, BEYOND_COLOR = "#ff7f0e", "#444444", "0.85"
#: Width (pixels) of the schematic's column beside the curve, and the narrowest curve
#: that gets one (narrower: the values go into the legend's title).
SCHEMATIC_WIDTH, SCHEMATIC_MIN_FIGURE = 135, 400
#: The width (in :func:`~barymesh.app.panels.array_circuit.schematic`'s units) drawn across
#: :data:`SCHEMATIC_WIDTH`: a series sheet on one grounded layer. A wider schematic (more
#: layers, a parallel circuit's side-by-side elements) widens its column at the same scale,
#: so that its labels keep their size and fit their boxes.
SCHEMATIC_UNITS = 5.8
#: The magnitude axis spans at least this many dB (a flat |R| = 1 over a ground plane
#: would otherwise be drawn as noise magnified around 0 dB).
MIN_DB_SPAN = 1.0
DPI = 90


@dataclass(frozen=True, eq=False)
class Picture:
    """A drawn figure and where its frequency axis lies.

    Attributes
    ----------
    rgba : (H, W, 4) uint8
        The image, H x W device pixels.
    ratio : float
        Device pixels per widget pixel.
    figure : matplotlib.figure.Figure
        What was drawn (read only after the draw: its axes, lines and texts).
    x_pixels : (2,) float
        Device-pixel x of the axes' left and right ends (from the image's left).
    y_pixels : (2,) float
        Device-pixel y (from the image's top) of the top and bottom of the axes.
    x_range : (2,) float
        Frequencies (GHz) at those ends; None-like (0, 0) for a figure without one.
        (The Reflection phase tab's curve: the parameter's values, ``x_scale`` 1.)
    x_scale : float
        What one unit of the x axis is worth in the units :meth:`value_at` returns and
        :meth:`widget_x` takes: 1e9 (GHz drawn, Hz meant), or 1 (a parameter in mm).
    """

    rgba: np.ndarray
    ratio: float
    figure: Any
    x_pixels: tuple[float, float] = (0.0, 0.0)
    y_pixels: tuple[float, float] = (0.0, 0.0)
    x_range: tuple[float, float] = (0.0, 0.0)
    x_scale: float = 1e9

    def value_at(self, x: float, y: float) -> float | None:
        """The x axis' value (times ``x_scale``) under widget pixel (x, y), or None
        outside the axes."""
        px, py = x * self.ratio, y * self.ratio
        (x0, x1), (y0, y1), (f0, f1) = self.x_pixels, self.y_pixels, self.x_range
        if x1 <= x0 or not (x0 <= px <= x1 and y0 <= py <= y1):
            return None
        return (f0 + (px - x0) / (x1 - x0) * (f1 - f0)) * self.x_scale

    def frequency_at(self, x: float, y: float) -> float | None:
        """Frequency (Hz) under widget pixel (x, y), or None outside the axes."""
        hz = self.value_at(x, y)
        return hz if hz is not None and hz > 0 else None

    def widget_x(self, hz: float) -> float:
        """Widget pixel x of frequency ``hz`` (Hz; or of an x value, see ``x_scale``)."""
        (x0, x1), (f0, f1) = self.x_pixels, self.x_range
        return (x0 + (hz / self.x_scale - f0) / (f1 - f0) * (x1 - x0)) / self.ratio

    def widget_y_middle(self) -> float:
        """Widget pixel y half way down the axes."""
        return 0.5 * (self.y_pixels[0] + self.y_pixels[1]) / self.ratio


def new_figure(size: tuple[int, int], ratio: float) -> tuple[Any, Any]:
    """An Agg figure of ``size`` widget pixels at ``ratio`` device pixels each, and its canvas."""
    from matplotlib.backends.backend_agg import FigureCanvasAgg
    from matplotlib.figure import Figure

    w, h = max(size[0], 50), max(size[1], 50)
    fig = Figure(figsize=(w / DPI, h / DPI), dpi=DPI * ratio)
    return fig, FigureCanvasAgg(fig)


def drawn_rgba(canvas: Any) -> np.ndarray:
    """(H, W, 4) uint8: the canvas drawn."""
    canvas.draw()
    return np.asarray(canvas.buffer_rgba()).copy()


def phase_label(stack: Any) -> tuple[str, str | None]:
    """The phase axis' label and ∠T's legend (None: ∠T not drawn, or on the same plane).

    >>> phase_label(None)
    ('∠R, ∠T (°) at the sheet,\\nz = 0 mm', None)
    """
    r_plane, t_plane = reference_plane_names(stack)
    wrapped = r_plane.replace(", z", ",\nz")  # two lines: the axis is short
    if t_plane == r_plane:
        return "∠R, ∠T (°) at " + wrapped, None
    r = "∠R (°) at " + wrapped
    return r, (None if t_plane is None else f"∠T at {t_plane}")


def draw_curve(
    result: Any, size: tuple[int, int], ratio: float = 1.0, circuit: Any = None
) -> Picture:
    """|R|, |T| (dB) and their phase against frequency of an ``ArraySweep`` (None: empty
    axes), ``size`` widget pixels (w, h) at ``ratio`` device pixels per pixel; with a
    :class:`~barymesh.app.panels.array_circuit.CircuitFit` of it, the circuit's curves
    (dashed), the reference's (dotted), the shade where the circuit stops describing the
    cell and the schematic in a column on the right."""
    fig, canvas = new_figure(size, ratio)
    w, h = max(size[0], 50), max(size[1], 50)
    left = min(0.3, 64.0 / w)  # 64 px: two lines of label and the ticks
    bottom = min(0.3, 38.0 / h)  # the ticks' labels and the axis' name
    if circuit is not None and circuit.sweep is not result:
        circuit = None  # a fit of another curve
    wide = 0.0 if circuit is None else schematic_column(circuit)
    # the curve keeps what a figure of SCHEMATIC_MIN_FIGURE gives it beside a plain column
    column = circuit is not None and w - wide >= SCHEMATIC_MIN_FIGURE - SCHEMATIC_WIDTH
    right = 1.0 - (wide + 8.0) / w if column else 0.97
    fig.subplots_adjust(left=left, right=right, top=1.0 - 8.0 / h, bottom=bottom, hspace=0.1)
    mag, ph = fig.subplots(2, 1, sharex=True)
    if column:
        draw_schematic(fig.add_axes((1.0 - wide / w, 0.0, wide / w, 1.0)), circuit)
    for ax in (mag, ph):
        ax.grid(alpha=0.3)
        ax.tick_params(labelsize=7)
    stack = None if result is None else result.inputs.stack
    grounded = stack is not None and stack.ground
    label, t_legend = phase_label(stack)
    mag.set_ylabel("|R|, |T| (dB)" if not grounded else "|R| (dB)", fontsize=8)
    ph.set_ylabel(label, fontsize=8)
    ph.set_xlabel("frequency (GHz)", fontsize=8)
    ph.set_ylim(-180, 180)
    ph.set_yticks([-180, -90, 0, 90, 180])
    if result is not None:
        f = np.asarray(result.frequencies) / 1e9
        with np.errstate(divide="ignore"):
            r_db = 20 * np.log10(np.abs(result.reflection))
            t_db = 20 * np.log10(np.abs(result.transmission))
        mag.plot(f, r_db, color=R_COLOR, marker=".", label="|R|")
        if not grounded:
            mag.plot(f, t_db, color=T_COLOR, marker=".", label="|T|")
        ph.plot(f, np.degrees(np.angle(result.reflection)), color=R_COLOR, marker=".", label="∠R")
        if not grounded:
            ph.plot(
                f,
                np.degrees(np.angle(result.transmission)),
                color=T_COLOR,
                marker=".",
                label=t_legend or "∠T",
            )
        shown = np.concatenate([r_db, t_db if not grounded else []])
        shown = shown[np.isfinite(shown)]
        title = "T = 0: ground plane" if grounded else None
        if circuit is not None:
            draw_circuit_curves(mag, ph, circuit)
            if not column and circuit.circuit is not None:  # no room for the schematic
                values = ", ".join(circuit_labels(circuit.circuit)[1:])
                title = values if title is None else f"{title}\n{values}"
        if t_legend is not None or circuit is not None:
            ph.legend(fontsize=6, loc="lower left")
        if len(shown) and np.ptp(shown) < MIN_DB_SPAN:
            top = max(float(shown.max()), 0.0) + 0.1 * MIN_DB_SPAN
            mag.set_ylim(top - 1.1 * MIN_DB_SPAN, top)
        mag.legend(fontsize=7, loc="best", title=title, title_fontsize=6)
        for n, (hz, orders) in enumerate(result.grating_lobe_onsets):
            for ax in (mag, ph):
                ax.axvline(hz / 1e9, color=ONSET_COLOR, lw=1.0, ls=":")
            first = orders[0]
            more = f" +{len(orders) - 1}" if len(orders) > 1 else ""
            ph.annotate(  # staggered: onsets close together keep their labels apart
                f"grating lobe\n({first[0]},{first[1]}){more} {hz / 1e9:.4g}",
                (hz / 1e9, 0.03 + 0.3 * (n % 3)),
                xycoords=("data", "axes fraction"),
                ha="right",
                va="bottom",
                fontsize=6,
                color=ONSET_COLOR,
            )
        for n, (hz, orders, layers) in enumerate(getattr(result, "guided_onsets", ())):
            for ax in (mag, ph):
                ax.axvline(hz / 1e9, color=GUIDED_COLOR, lw=1.0, ls="-.")
            first = orders[0]
            more = f" +{len(orders) - 1}" if len(orders) > 1 else ""
            where = ", ".join(str(i + 1) for i in layers)
            mag.annotate(  # at the bottom of the magnitude axes, staggered
                f"guided in layer {where}\n({first[0]},{first[1]}){more} {hz / 1e9:.4g}",
                (hz / 1e9, 0.03 + 0.22 * (n % 3)),
                xycoords=("data", "axes fraction"),
                ha="right",
                va="bottom",
                fontsize=6,
                color=GUIDED_COLOR,
            )
        for hz in getattr(result, "zero_phase", ()):
            ph.plot([hz / 1e9], [0.0], marker="D", ms=5, color="black", ls="none")
            near_end = hz / 1e9 > f[0] + 0.75 * (f[-1] - f[0])  # its label inside the axes
            ph.annotate(
                f"∠R = 0\n{hz / 1e9:.4g}",
                (hz / 1e9, 0.0),
                xytext=(-3 if near_end else 3, 3),
                textcoords="offset points",
                fontsize=6,
                va="bottom",
                ha="right" if near_end else "left",
                bbox={"fc": "white", "ec": "none", "alpha": 0.7, "pad": 0.3},
            )
        for n, hz in enumerate(result.resonances):
            mag.axvline(hz / 1e9, color=RESONANCE_COLOR, lw=1.0, ls="--")
            mag.annotate(  # staggered, as the onsets' labels
                f"{hz / 1e9:.4g}",
                (hz / 1e9, 0.97 - 0.12 * (n % 3)),
                xycoords=("data", "axes fraction"),
                ha="left",
                va="top",
                fontsize=7,
                color=RESONANCE_COLOR,
            )
        pad = 0.02 * (f[-1] - f[0]) if len(f) > 1 else 0.5
        mag.set_xlim(f[0] - pad, f[-1] + pad)
    else:
        mag.text(0.5, 0.5, "no curve yet", transform=mag.transAxes, ha="center", fontsize=8)
    rgba = drawn_rgba(canvas)
    height = rgba.shape[0]
    box_m, box_p = mag.get_window_extent(), ph.get_window_extent()
    return Picture(
        rgba,
        ratio,
        fig,
        (float(box_m.x0), float(box_m.x1)),
        (height - float(box_m.y1), height - float(box_p.y0)),
        (float(mag.get_xlim()[0]), float(mag.get_xlim()[1])),
    )


def draw_circuit_curves(mag: Any, ph: Any, fit: Any) -> None:
    """The circuit's |R| (dB) and ∠R dashed, the reference's ∠R dotted, and the shade
    from where the circuit stops describing the cell to the band's end."""
    f = np.asarray(fit.frequencies) / 1e9
    if fit.circuit is not None:
        with np.errstate(divide="ignore"):
            mag.plot(
                f,
                20 * np.log10(np.abs(fit.reflection)),
                color=CIRCUIT_COLOR,
                ls="--",
                lw=1.3,
                label=f"circuit ({fit.circuit.kind} LC)",
            )
        ph.plot(
            *wrapped_degrees(f, fit.reflection),
            color=CIRCUIT_COLOR,
            ls="--",
            lw=1.3,
            label="circuit",
        )
    if fit.reference is not None:
        ph.plot(
            *wrapped_degrees(f, fit.reference),
            color=REFERENCE_COLOR,
            ls=":",
            lw=1.5,
            label=LUUKKONEN,
        )
    stop = fit.stops_at
    if stop is not None:
        end = float(fit.sweep.frequencies[-1]) / 1e9
        for ax in (mag, ph):
            ax.axvspan(stop / 1e9, end, color=BEYOND_COLOR, alpha=0.5, lw=0, zorder=0)
        ph.annotate(  # at the top of the shade, on a white ground (curves pass there)
            "circuit ≠ cell",
            (stop / 1e9, 0.97),
            xycoords=("data", "axes fraction"),
            xytext=(2, 0),
            textcoords="offset points",
            ha="left",
            va="top",
            fontsize=6,
            color="0.3",
            bbox={"fc": "white", "ec": "none", "alpha": 0.8, "pad": 0.5},
        )


def wrapped_degrees(x: np.ndarray, values: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """(x, ∠ in degrees) with a NaN between two samples where ∠ wraps through ±180° (no
    vertical line across the axes); the samples themselves are kept, in order."""
    deg = np.degrees(np.angle(np.asarray(values))).astype(float)
    x = np.asarray(x, dtype=float)
    jumps = np.flatnonzero(np.abs(np.diff(deg)) > 180.0) + 1
    middle = 0.5 * (x[jumps - 1] + x[jumps])
    return np.insert(x, jumps, middle), np.insert(deg, jumps, np.nan)


def _lossy(circuit: Any) -> bool:
    """Whether the fitted circuit has a resistor to draw."""
    if circuit.kind == "series":
        return bool(circuit.resistance > 0)
    return math.isfinite(circuit.resistance)


def schematic_column(fit: Any) -> float:
    """Pixels of the column :func:`draw_schematic` needs for ``fit``'s circuit.

    :data:`SCHEMATIC_WIDTH`, or wider at the same scale when the schematic is wider than
    :data:`SCHEMATIC_UNITS` (layers on both sides of the sheet, several layers): the
    drawing is never shrunk to fit, where its labels would outgrow its boxes.
    """
    if fit.circuit is None:
        return float(SCHEMATIC_WIDTH)
    c = fit.circuit
    units = schematic(c.kind, fit.sweep.inputs.stack, _lossy(c)).width
    return float(math.ceil(SCHEMATIC_WIDTH * max(1.0, units / SCHEMATIC_UNITS)))


def draw_schematic(ax: Any, fit: Any) -> None:
    """The fitted circuit's schematic in ``ax`` with its values under it, or why there
    is none (grey) when the fit was refused."""
    ax.set_axis_off()
    ax.set_xlim(0, 1)
    ax.set_ylim(0, 1)
    if fit.circuit is None:
        ax.text(0.5, 0.75, "no circuit", ha="center", fontsize=8, color="#d0021b")
        ax.text(
            0.5,
            0.68,
            textwrap.fill(fit.refused, 26),
            ha="center",
            va="top",
            fontsize=6,
            color="0.35",
        )
        return
    c = fit.circuit
    from matplotlib.patches import Rectangle

    s = schematic(c.kind, fit.sweep.inputs.stack, _lossy(c))
    # the drawing in the column's top half, one scale in x and y
    x0, x1, y0, y1 = 0.14, 0.88, 0.50, 0.86
    bbox = ax.get_window_extent()
    aspect = bbox.height / bbox.width if bbox.width > 0 else 1.0  # pixels: y per x
    scale = min((x1 - x0) / s.width, (y1 - y0) * aspect / (s.height + 1.0))

    def at(x: float, y: float) -> tuple[float, float]:
        return x0 + x * scale, y0 + y * scale / aspect

    for (xa, ya), (xb, yb) in s.wires:
        (u0, v0), (u1, v1) = at(xa, ya), at(xb, yb)
        ax.plot([u0, u1], [v0, v1], color="black", lw=1.0)
    for y in (0.0, s.height):
        u, v = at(s.port, y)
        ax.plot([u], [v], marker="o", ms=3.5, mfc="white", color="black")
    for x, y, text, ha in s.texts:
        u, v = at(x, y)
        ax.text(u, v, text, ha=ha, va="center", fontsize=6)
    for x, y, bw, bh, label in s.boxes:
        (u0, v0), (u1, v1) = at(x, y), at(x + bw, y + bh)
        ax.add_patch(
            Rectangle((u0, v0), u1 - u0, v1 - v0, fill=True, fc="#fbf3d5", ec="black", lw=0.8)
        )
        ax.text((u0 + u1) / 2, (v0 + v1) / 2, label, ha="center", va="center", fontsize=6)
    for name, x, ya, yb in s.elements:
        (u, v0), (_, v1) = at(x, ya), at(x, yb)
        _element(ax, name, u, v0, v1)
    if s.ground is not None:
        u, v = at(*s.ground)
        for i, half in enumerate((0.035, 0.022, 0.01)):
            ax.plot([u - half, u + half], [v - 0.012 - 0.014 * i] * 2, color="black", lw=1.0)
        ax.text(u, v - 0.07, "ground", ha="center", va="top", fontsize=5)
    lines = circuit_labels(c)
    ax.text(0.5, 0.42, "\n".join(lines), ha="center", va="top", fontsize=7, linespacing=1.4)


def _element(ax: Any, name: str, u: float, v0: float, v1: float) -> None:
    """A lumped element drawn vertically between heights v0 and v1 at u (axes units)."""
    from matplotlib.patches import Rectangle

    span = v1 - v0
    body0, body1 = v0 + 0.25 * span, v1 - 0.25 * span
    ax.plot([u, u], [v0, body0], color="black", lw=1.0)
    ax.plot([u, u], [body1, v1], color="black", lw=1.0)
    if name == "L":  # a coil: four bumps
        t = np.linspace(0.0, 4.0 * np.pi, 80)
        ax.plot(
            u + 0.018 * np.abs(np.sin(t)),
            body0 + (body1 - body0) * t / t[-1],
            color="black",
            lw=1.0,
        )
    elif name == "C":  # two plates
        mid = 0.5 * (body0 + body1)
        gap = 0.08 * span
        ax.plot([u, u], [body0, mid - gap], color="black", lw=1.0)
        ax.plot([u, u], [mid + gap, body1], color="black", lw=1.0)
        for v in (mid - gap, mid + gap):
            ax.plot([u - 0.03, u + 0.03], [v, v], color="black", lw=1.6)
    else:  # R, or the vacuum's η0: a box
        ax.add_patch(
            Rectangle((u - 0.015, body0), 0.03, body1 - body0, fill=False, ec="black", lw=1.0)
        )
    ax.text(u + 0.035, 0.5 * (v0 + v1), name, ha="left", va="center", fontsize=6)


def order_arrows(solution: Any) -> list[tuple[str, int, int, float, float]]:
    """(side "R" or "T", p, q, dx, dz) of each propagating order's arrow.

    In the plane of incidence (κ projected on it), of length √(power fraction): up for
    the reflected waves, down for the transmitted ones.
    """
    d = np.asarray(solution.incidence.direction, dtype=float)
    plane = d[:2] / np.linalg.norm(d[:2]) if np.hypot(*d[:2]) > 1e-12 else np.array([1.0, 0.0])
    power_r, power_t = solution.power_fractions
    kappa = np.asarray(solution.kappa, dtype=float)
    k = np.sqrt(np.einsum("ij,ij->i", kappa, kappa) + np.real(solution.beta) ** 2)
    along = kappa @ plane / k
    up = np.real(solution.beta) / k
    out = []
    for i, (p, q) in enumerate(np.asarray(solution.orders).tolist()):
        for side, power, sign in (("R", power_r[i], 1.0), ("T", power_t[i], -1.0)):
            length = math.sqrt(max(float(power), 0.0))
            out.append((side, int(p), int(q), float(length * along[i]), sign * length * up[i]))
    return out


def draw_orders(solution: Any, size: tuple[int, int], ratio: float = 1.0) -> Picture:
    """The propagating orders of a ``PeriodicSolution`` (None: the bare screen) as arrows."""
    fig, canvas = new_figure(size, ratio)
    fig.subplots_adjust(left=0.02, right=0.98, top=0.9, bottom=0.02)
    ax = fig.add_subplot()
    ax.set_xlim(-1.3, 1.3)
    ax.set_ylim(-1.2, 1.2)
    ax.set_aspect("equal", adjustable="box")
    ax.set_xticks([])
    ax.set_yticks([])
    ax.axhline(0.0, color="0.2", lw=3)
    if solution is None:
        ax.set_title("Floquet orders: click the curve", fontsize=8)
        return Picture(drawn_rgba(canvas), ratio, fig)
    d = np.asarray(solution.incidence.direction, dtype=float)
    plane = d[:2] / np.linalg.norm(d[:2]) if np.hypot(*d[:2]) > 1e-12 else np.array([1.0, 0.0])
    ax.annotate(
        "",
        xy=(0.0, 0.0),
        xytext=(-float(d[:2] @ plane), -float(d[2])),
        arrowprops={"arrowstyle": "->", "ls": "--", "color": "0.45", "lw": 1.2},
    )
    for side, p, q, dx, dz in order_arrows(solution):
        if math.hypot(dx, dz) < 0.02:
            continue
        color = R_COLOR if side == "R" else T_COLOR
        ax.annotate(
            "",
            xy=(dx, dz),
            xytext=(0.0, 0.0),
            arrowprops={"arrowstyle": "-|>", "color": color, "lw": 1.5},
        )
        length = math.hypot(dx, dz)
        ax.text(  # beyond the tip, along the arrow
            dx + 0.16 * dx / length,
            dz + 0.16 * dz / length,
            f"({p},{q})",
            fontsize=7,
            color=color,
            ha="center",
            va="center",
        )
    ax.text(-1.25, 1.12, "reflected", fontsize=7, color=R_COLOR, va="top")
    ax.text(-1.25, -1.12, "transmitted", fontsize=7, color=T_COLOR, va="bottom")
    ax.text(1.25, 1.12, "incident - -", fontsize=7, color="0.45", va="top", ha="right")
    ax.set_title(f"Floquet orders at {solution.frequency / 1e9:.4g} GHz", fontsize=8)
    return Picture(drawn_rgba(canvas), ratio, fig)
