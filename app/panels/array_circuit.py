"""The Infinite array tab's circuit: a Foster LC fitted to the swept curve (no Qt).

With **Equivalent circuit** ticked, the tab fits the sheet's impedance with the simplest
circuit that has a resonance (:func:`barymesh.mom.circuit.equivalent_circuit`: a series
LC for metal in islands, a parallel LC for connected metal) and draws the circuit's R
dashed over the solved one, a schematic with the element values beside the curve, and
the frequencies above which the circuit stops following the cell shaded. For square
patches over a grounded slab at normal incidence, Luukkonen et al.'s analytic model
(IEEE TAP 56(6), 2008) is drawn dotted as a reference.

:func:`fit_circuit` runs in the worker thread that draws the curve (the fit took 20 to 30
ms on 11 to 21 frequencies, the drawing 190 ms), never on the GUI thread; a refusal
(too few frequencies under the first onset, no circuit of positive L and C) is kept as a
sentence, never raised. :func:`schematic` is the drawing's geometry, in the schematic's
own units, and :func:`circuit_labels` its values, both plain data for tests.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from typing import Any

import numpy as np

#: Points of the circuit's and the reference's curves over the band (smooth dashes).
CURVE_POINTS = 200
#: A square patch: its triangles fill its bounding box to this relative tolerance.
FILL_TOLERANCE = 1e-6
#: The reference's legend.
LUUKKONEN = "Luukkonen et al. 2008"


@dataclass(frozen=True, eq=False)
class CircuitFit:
    """The circuit of one swept curve, or why there is none.

    Attributes
    ----------
    sweep : ArraySweep
        The curve fitted.
    circuit : barymesh.mom.circuit.EquivalentCircuit or None
        None when the fit was refused (``refused`` says why).
    refused : str
        One sentence ("" with a circuit).
    frequencies : (N,) float
        Hz: where the circuit's and the reference's curves are drawn (the band, densely).
    reflection : (N,) complex
        The circuit's R at ``frequencies`` (empty without a circuit).
    reference : (N,) complex or None
        Luukkonen et al.'s R at ``frequencies`` (None when the cell is not square
        patches on a grounded slab at normal incidence).
    patch : (float, float) or None
        (period, gap) in mm of the square patch the reference is for.
    """

    sweep: Any
    circuit: Any = None
    refused: str = ""
    frequencies: np.ndarray = field(default_factory=lambda: np.zeros(0))
    reflection: np.ndarray = field(default_factory=lambda: np.zeros(0, dtype=complex))
    reference: np.ndarray | None = None
    patch: tuple[float, float] | None = None

    @property
    def stops_at(self) -> float | None:
        """Hz from which the circuit no longer follows the cell within the fit's
        agreement (to the band's end: shaded); None when it follows it all the way."""
        if self.circuit is None:
            return None
        top = float(self.sweep.frequencies[-1])
        valid = float(self.circuit.valid_below)
        if not math.isfinite(valid):
            return float(self.sweep.frequencies[0])
        return valid if valid < top else None

    def note(self) -> str:
        """The tab's line about the circuit: its values and where it stops, or why none."""
        if self.circuit is None:
            return f"No circuit: {self.refused}"
        text = self.circuit.describe()
        stop = self.stops_at
        if stop is not None:
            text += f". Shaded from {stop / 1e9:.4g} GHz: the circuit no longer describes the cell"
        if self.reference is not None:
            period, gap = self.patch or (0.0, 0.0)
            text += f". Dotted: {LUUKKONEN} (square patches, {period:g} mm, gap {gap:.4g} mm)"
        return text


def square_patch(mesh: Any) -> tuple[float, float] | None:
    """(period, gap) in mm when ``mesh`` is one axis-aligned square patch in a square
    cell (its triangles fill their bounding box), else None."""
    lattice = getattr(mesh, "lattice", None)
    if lattice is None or mesh.n_triangles == 0:
        return None
    a1, a2 = np.asarray(lattice.a1, dtype=float), np.asarray(lattice.a2, dtype=float)
    period = float(np.linalg.norm(a1))
    if not (
        abs(a1[1]) <= 1e-9 * period
        and abs(a2[0]) <= 1e-9 * period
        and abs(abs(a2[1]) - period) <= 1e-9 * period
    ):
        return None
    xy = np.asarray(mesh.points, dtype=float)[np.unique(mesh.triangles)][:, :2]
    lo, hi = xy.min(axis=0), xy.max(axis=0)
    width, height = hi - lo
    if not (width > 0 and abs(width - height) <= FILL_TOLERANCE * width):
        return None
    if abs(float(np.sum(mesh.areas)) - width * height) > FILL_TOLERANCE * width * height:
        return None
    gap = period - float(width)
    return (period, gap) if gap > 0 else None


def luukkonen_applies(sweep: Any, mesh: Any) -> tuple[float, float] | None:
    """(period, gap) mm when Luukkonen et al.'s model is this curve's reference: square
    patches of perfect conductor directly on one grounded layer, at normal incidence."""
    inputs = sweep.inputs
    stack = inputs.stack
    if stack is None or not stack.ground or stack.above or len(stack.below) != 1:
        return None
    layer = stack.below[0]
    if inputs.theta != 0 or inputs.sheet_impedance != 0 or layer.mu_r != 1:
        return None
    return square_patch(mesh)


def _curve_frequencies(sweep: Any) -> np.ndarray:
    f = np.asarray(sweep.frequencies, dtype=float)
    return np.linspace(f[0], f[-1], CURVE_POINTS) if len(f) > 1 else f.copy()


def fit_circuit(sweep: Any, mesh: Any) -> CircuitFit:
    """The circuit of ``sweep`` (an :class:`~barymesh.app.panels.array_sweep.ArraySweep`
    of ``mesh``'s cell) and, for square patches on a grounded slab, the reference."""
    from barymesh.mom.circuit import luukkonen_patch_reflection

    f = _curve_frequencies(sweep)
    reference, patch = None, luukkonen_applies(sweep, mesh)
    if patch is not None:
        layer = sweep.inputs.stack.below[0]
        reference = luukkonen_patch_reflection(f, patch[0], patch[1], layer.thickness, layer.eps_r)
    try:
        circuit = sweep.equivalent_circuit()
    except ValueError as exc:  # a refusal, said in a sentence (a LinAlgError is one too)
        return CircuitFit(sweep, None, str(exc), f, reference=reference, patch=patch)
    except (ArithmeticError, RuntimeError) as exc:  # the curve stays drawn all the same
        why = f"the fit failed ({type(exc).__name__}: {exc})"
        return CircuitFit(sweep, None, why, f, reference=reference, patch=patch)
    return CircuitFit(sweep, circuit, "", f, circuit.reflection(f), reference, patch)


def circuit_labels(circuit: Any) -> list[str]:
    """The schematic's lines: the kind, L, C, R (when lossy) and f0.

    >>> from types import SimpleNamespace as NS
    >>> c = NS(kind="series", inductance=2.1e-10, capacitance=4.471e-14, resistance=0.0,
    ...        resonance=5.195e10)
    >>> circuit_labels(c)
    ['series LC', 'L = 0.21 nH', 'C = 44.71 fF', 'f0 = 51.95 GHz']
    """
    lines = [
        f"{circuit.kind} LC",
        f"L = {circuit.inductance * 1e9:.4g} nH",
        f"C = {circuit.capacitance * 1e15:.4g} fF",
    ]
    r = circuit.resistance
    if (circuit.kind == "series" and r > 0) or (circuit.kind == "parallel" and math.isfinite(r)):
        lines.append(f"R = {r:.4g} Ω")
    lines.append(f"f0 = {circuit.resonance / 1e9:.4g} GHz")
    return lines


@dataclass(frozen=True)
class Schematic:
    """A circuit's drawing in its own units (x to the right, y up).

    The line runs left to right at heights ``top`` and ``bottom``: the port (the incident
    wave, η0) on the left, a line section per layer above the sheet, the sheet's shunt
    branch, a section per layer below, and the end on the right: a short (the ground
    plane) or η0 (vacuum under the stack).

    Attributes
    ----------
    wires : list of ((x0, y0), (x1, y1))
    boxes : list of (x, y, w, h, label)
        Line sections (the layers), label "εr 2.2\\n1.575\\nmm".
    elements : list of (kind, x, y0, y1)
        Lumped elements drawn vertically from y0 up to y1 at x: "L", "C" or "R".
    texts : list of (x, y, text, ha)
    ground : (x, y) or None
        Where the ground symbol hangs (the short's foot).
    port : float
        x of the port's two terminals (the incident wave, η0 written beside them).
    width, height : float
        The drawing's extent (from 0).
    """

    wires: list[tuple[tuple[float, float], tuple[float, float]]]
    boxes: list[tuple[float, float, float, float, str]]
    elements: list[tuple[str, float, float, float]]
    texts: list[tuple[float, float, str, str]]
    ground: tuple[float, float] | None
    port: float
    width: float
    height: float


def _layer_label(layer: Any) -> str:
    return f"εr {layer.eps_r:g}\n{layer.thickness:.4g}\nmm"  # narrow: the box is


def schematic(kind: str, stack: Any = None, lossy: bool = False) -> Schematic:
    """The geometry of a ``kind`` ("series" or "parallel") shunt LC on ``stack``'s line.

    >>> s = schematic("series")  # a free-standing sheet: the line ends in vacuum's η0
    >>> [e[0] for e in s.elements], s.ground, len(s.boxes)
    (['L', 'C', 'η0'], None, 0)
    """
    top, bottom = 4.0, 0.0
    wires: list[tuple[tuple[float, float], tuple[float, float]]] = []
    boxes: list[tuple[float, float, float, float, str]] = []
    elements: list[tuple[str, float, float, float]] = []
    texts: list[tuple[float, float, str, str]] = []
    above = [] if stack is None else [layer for layer in stack.above if layer.thickness > 0]
    below = [] if stack is None else [layer for layer in stack.below if layer.thickness > 0]
    ground = stack is not None and stack.ground
    x = 0.6  # the port: the incident wave, its two terminals at x = 0.6

    def section(layer: Any) -> None:
        nonlocal x
        wires.append(((x, top), (x + 0.5, top)))
        wires.append(((x, bottom), (x + 0.5, bottom)))
        boxes.append((x + 0.5, bottom - 0.3, 1.8, top - bottom + 0.6, _layer_label(layer)))
        x += 2.3

    texts.append((0.3, (top + bottom) / 2, "η0", "right"))
    for layer in above:
        section(layer)
    # the sheet's branch: wires to it, the elements between the rails (side by side for
    # a parallel circuit, 1.1 apart: room for each one's letter)
    parts = ["L", "C"] + (["R"] if lossy else [])
    spread = 0.0 if kind == "series" else 1.1 * (len(parts) - 1) / 2
    lead = max(1.2, spread + 0.7)
    wires.append(((x, top), (x + lead, top)))
    wires.append(((x, bottom), (x + lead, bottom)))
    x += lead
    if kind == "series":
        step = (top - bottom) / len(parts)
        for i, name in enumerate(parts):
            elements.append((name, x, top - (i + 1) * step, top - i * step))
    else:
        xs = [x - spread + 1.1 * i for i in range(len(parts))]
        wires.append(((xs[0], top - 0.6), (xs[-1], top - 0.6)))
        wires.append(((xs[0], bottom + 0.6), (xs[-1], bottom + 0.6)))
        wires.append(((x, top), (x, top - 0.6)))
        wires.append(((x, bottom), (x, bottom + 0.6)))
        for name, xe in zip(parts, xs, strict=True):
            elements.append((name, xe, bottom + 0.6, top - 0.6))
    texts.append((x, top + 0.5, "sheet", "center"))
    wires.append(((x, top), (x + lead, top)))
    wires.append(((x, bottom), (x + lead, bottom)))
    x += lead
    for layer in below:
        section(layer)
        wires.append(((x, top), (x + 0.5, top)))
        wires.append(((x, bottom), (x + 0.5, bottom)))
        x += 0.5
    foot = None
    if ground:  # a short across the line's end
        wires.append(((x, top), (x, bottom)))
        foot = (x, bottom)
    else:  # vacuum under the stack: the line ends in η0
        elements.append(("η0", x, bottom, top))
    return Schematic(wires, boxes, elements, texts, foot, 0.6, x, top)
