"""Dielectric layers around the sheet of an infinite array, and a ground plane.

A metasurface sits on a substrate, often over a ground plane. The sheet of metal lies
at z = 0 between two stacks of homogeneous layers (:class:`Layer`), ``above`` (from the
incident half-space down to the sheet, top first) and ``below`` (from the sheet down,
top first); the half-spaces outside are vacuum, and ``ground=True`` puts a perfectly
conducting plane under the last layer of ``below``::

        vacuum (incident side)
      ─────────────────────────  z = H_above   (the top face: R is referred here)
        above[0] … above[-1]
      ═════════ sheet ═════════  z = 0
        below[0] … below[-1]
      ─────────────────────────  z = −H_below  (the bottom face: T is referred here)
        vacuum, or a ground plane (then T = 0)

Each Floquet harmonic of transverse wavevector κ sees the layers as a transmission line,
TE and TM (Michalski & Mosig, IEEE Trans. Antennas Propag. 45(3), 1997): a layer of
relative permittivity ε (ε_r (1 − j tan δ) with the time convention e^(jωt)) and
permeability μ has propagation constant γ = sqrt(κ² − k0² ε μ) and, normalised to the
vacuum's η0, characteristic admittances y_TE = γ / (j k0 μ) and y_TM = j k0 ε / γ. The
sheet is a shunt current source on that line: it sees the admittances ``y_up`` and
``y_down`` of the two sides in parallel. What this module computes, per harmonic and for
both polarisations, is the line; :mod:`barymesh.mom.periodic_layered` turns it into the
kernel of the EFIE.

Lengths of a :class:`Layer` are in mm, as every length of a mesh; frequencies in Hz.

>>> substrate = Stack(below=(Layer(1.575, 2.2),), ground=True)
>>> g = substrate.reflection(10e9)  # the grounded slab alone: |Γ| = 1
>>> np.round(np.abs(g), 12).tolist(), round(float(np.degrees(np.angle(g[0]))), 3)
([1.0, 1.0], 140.476)
"""

from __future__ import annotations

import math
import re
from collections.abc import Iterable, Mapping, Sequence
from dataclasses import dataclass
from typing import Any

import numpy as np

from ..constants import SPEED_OF_LIGHT
from .excitation import PlaneWave

#: Below this |γ d|, tanh(γ d)/γ is its Taylor series (the line is regular at γ = 0).
SMALL_ARGUMENT = 1e-4
#: Largest thickness of a layer (mm) and largest relative permittivity or permeability.
MAX_THICKNESS = 1e6
MAX_MATERIAL = 1e4

__all__ = ["Layer", "Stack", "parse_stack"]


def _number(name: str, value: Any, low: float, high: float, *, low_open: bool = False) -> float:
    """A finite float in [low, high] (or (low, high]), or a ValueError naming ``name``."""
    if isinstance(value, bool) or not isinstance(value, (int, float, np.integer, np.floating)):
        raise TypeError(f"{name}={value!r} is not a number")
    x = float(value)
    ok = math.isfinite(x) and (x > low if low_open else x >= low) and x <= high
    if not ok:
        bound = f"({low:g}" if low_open else f"[{low:g}"
        raise ValueError(f"{name}={value!r} is invalid; expected a number in {bound}, {high:g}]")
    return x


@dataclass(frozen=True)
class Layer:
    """A homogeneous dielectric (or magnetic) layer parallel to the sheet.

    Parameters
    ----------
    thickness : float
        mm, >= 0 (a layer of zero thickness changes nothing).
    eps_r : float
        Relative permittivity, > 0.
    loss_tangent : float
        tan δ >= 0: ε = ε_r (1 − j tan δ) with the time convention e^(jωt).
    mu_r : float
        Relative permeability, > 0 (lossless).

    Examples
    --------
    >>> Layer(1.575, 2.2, 0.0009).epsilon
    (2.2-0.00198j)
    """

    thickness: float
    eps_r: float = 1.0
    loss_tangent: float = 0.0
    mu_r: float = 1.0

    def __post_init__(self) -> None:
        values = (
            ("thickness", self.thickness, 0.0, MAX_THICKNESS, False),
            ("eps_r", self.eps_r, 0.0, MAX_MATERIAL, True),
            ("loss_tangent", self.loss_tangent, 0.0, 100.0, False),
            ("mu_r", self.mu_r, 0.0, MAX_MATERIAL, True),
        )
        for name, value, low, high, open_ in values:
            object.__setattr__(
                self, name, _number(f"Layer.{name}", value, low, high, low_open=open_)
            )

    @property
    def epsilon(self) -> complex:
        """Complex relative permittivity ε_r (1 − j tan δ)."""
        return complex(self.eps_r, -self.eps_r * self.loss_tangent)

    @property
    def is_vacuum(self) -> bool:
        return self.eps_r == 1.0 and self.mu_r == 1.0 and self.loss_tangent == 0.0

    @property
    def lossy(self) -> bool:
        return self.loss_tangent > 0.0

    def wavelength(self, frequency: float) -> float:
        """Wavelength in the layer (mm) at ``frequency`` (Hz), from Re(ε μ)."""
        return SPEED_OF_LIGHT * 1e3 / (frequency * math.sqrt(self.eps_r * self.mu_r))

    def describe(self) -> str:
        """The layer in the command line's syntax (:func:`parse_stack`)."""
        parts = [f"{self.thickness:g}mm", f"eps={self.eps_r:g}"]
        if self.loss_tangent:
            parts.append(f"tand={self.loss_tangent:g}")
        if self.mu_r != 1.0:
            parts.append(f"mu={self.mu_r:g}")
        return " ".join(parts)


def _layers(name: str, value: Any) -> tuple[Layer, ...]:
    if isinstance(value, Layer):
        raise TypeError(
            f"{name} must be a sequence of Layer, got a single Layer (write ({name}=(layer,))"
        )
    if isinstance(value, (str, bytes)) or not isinstance(value, Iterable):
        raise TypeError(f"{name} must be a sequence of Layer, got {type(value).__name__}")
    layers = tuple(value)
    for i, layer in enumerate(layers):
        if not isinstance(layer, Layer):
            raise TypeError(f"{name}[{i}] must be a Layer, got {type(layer).__name__}")
    return layers


@dataclass(frozen=True)
class Stack:
    """The layers around the sheet of an infinite array (see the module's docstring).

    Parameters
    ----------
    above : sequence of Layer
        Between the incident half-space and the sheet, top first.
    below : sequence of Layer
        Under the sheet, top first.
    ground : bool
        A perfectly conducting plane under the last layer of ``below`` (which must then
        be at least one layer of non-zero total thickness).

    ``Stack()`` is the free-standing sheet.

    Examples
    --------
    >>> s = Stack(below=(Layer(1.575, 2.2, 0.0009),), ground=True)
    >>> s.reference_planes, s.describe()
    ((0.0, -1.575), '1.575mm eps=2.2 tand=0.0009; ground')
    """

    above: tuple[Layer, ...] = ()
    below: tuple[Layer, ...] = ()
    ground: bool = False

    def __post_init__(self) -> None:
        object.__setattr__(self, "above", _layers("above", self.above))
        object.__setattr__(self, "below", _layers("below", self.below))
        if not isinstance(self.ground, (bool, np.bool_)):
            raise TypeError(f"ground={self.ground!r}; expected True or False")
        object.__setattr__(self, "ground", bool(self.ground))
        if self.ground and not self.thickness_below > 0:
            raise ValueError(
                "ground=True needs a layer of non-zero thickness below the sheet: a sheet "
                "lying on the ground plane is shorted (give below=(Layer(h, eps_r),))"
            )

    # -- what the stack is -----------------------------------------------------------------

    @property
    def layers(self) -> tuple[Layer, ...]:
        """Every layer, top first."""
        return self.above + self.below

    @property
    def is_free_standing(self) -> bool:
        """No layer and no ground: the sheet in vacuum (the free-standing solver's case)."""
        return not self.above and not self.below and not self.ground

    @property
    def lossy(self) -> bool:
        return any(layer.lossy for layer in self.layers)

    @property
    def thickness_above(self) -> float:
        """mm from the sheet up to the top face."""
        return float(sum(layer.thickness for layer in self.above))

    @property
    def thickness_below(self) -> float:
        """mm from the sheet down to the bottom face (the ground plane, if any)."""
        return float(sum(layer.thickness for layer in self.below))

    @property
    def reference_planes(self) -> tuple[float, float]:
        """(top, bottom) faces' heights (mm) over the sheet: where R and T are referred
        (for a wave from above; from below the two swap)."""
        return (self.thickness_above, -self.thickness_below)

    @property
    def max_index(self) -> float:
        """The largest sqrt(ε_r μ_r) of the stack and the vacuum (1)."""
        return max([1.0] + [math.sqrt(layer.eps_r * layer.mu_r) for layer in self.layers])

    def describe(self) -> str:
        """The stack in the command line's syntax (:func:`parse_stack`); "" if free-standing."""
        parts = [layer.describe() for layer in self.above]
        parts += ["sheet"] if self.above else []
        parts += [layer.describe() for layer in self.below]
        if self.ground:
            parts.append("ground")
        return "; ".join(parts)

    def to_dict(self) -> dict[str, Any]:
        """JSON-ready form (:meth:`from_dict` reads it back)."""

        def one(layer: Layer) -> dict[str, float]:
            return {
                "thickness": layer.thickness,
                "eps_r": layer.eps_r,
                "loss_tangent": layer.loss_tangent,
                "mu_r": layer.mu_r,
            }

        return {
            "above": [one(x) for x in self.above],
            "below": [one(x) for x in self.below],
            "ground": self.ground,
        }

    @classmethod
    def from_dict(cls, data: Mapping[str, Any]) -> Stack:
        """The stack of a mapping with keys ``above``, ``below`` (lists of layer mappings
        with ``thickness``, ``eps_r``, ``loss_tangent``, ``mu_r``) and ``ground``."""
        if not isinstance(data, Mapping):
            raise TypeError(f"a stack must be a mapping, got {type(data).__name__}")
        unknown = set(data) - {"above", "below", "ground"}
        if unknown:
            raise ValueError(
                f"unknown stack key(s) {sorted(unknown)}; expected above, below, ground"
            )

        def layers(side: str) -> list[Layer]:
            out = []
            items = data.get(side, [])
            if not isinstance(items, (list, tuple)):
                raise TypeError(f"stack.{side} must be a list of layers")
            for i, item in enumerate(items):
                if not isinstance(item, Mapping):
                    raise TypeError(f"stack.{side}[{i}] must be a mapping of layer values")
                extra = set(item) - {"thickness", "eps_r", "loss_tangent", "mu_r"}
                if extra or "thickness" not in item:
                    raise ValueError(
                        f"stack.{side}[{i}]: expected keys thickness, eps_r, loss_tangent, "
                        f"mu_r (thickness required); got {sorted(item)}"
                    )
                out.append(Layer(**item))
            return out

        return cls(tuple(layers("above")), tuple(layers("below")), data.get("ground", False))

    def replaced(self, path: str, value: float) -> Stack:
        """A copy with one value changed, by a path such as ``below[0].thickness``."""
        m = re.fullmatch(r"(above|below)\[(\d+)\]\.(thickness|eps_r|loss_tangent|mu_r)", path)
        if m is None:
            raise ValueError(
                f"stack path {path!r}; expected e.g. 'below[0].thickness' (above/below, a "
                "layer index, thickness/eps_r/loss_tangent/mu_r)"
            )
        side, index, name = m.group(1), int(m.group(2)), m.group(3)
        layers = list(getattr(self, side))
        if index >= len(layers):
            raise ValueError(f"stack path {path!r}: the stack has {len(layers)} layer(s) {side}")
        values = {
            "thickness": layers[index].thickness,
            "eps_r": layers[index].eps_r,
            "loss_tangent": layers[index].loss_tangent,
            "mu_r": layers[index].mu_r,
        }
        values[name] = value
        layers[index] = Layer(**values)
        if side == "above":
            return Stack(tuple(layers), self.below, self.ground)
        return Stack(self.above, tuple(layers), self.ground)

    # -- the background: the stack without the sheet --------------------------------------

    def reflection(self, frequency: float, wave: PlaneWave | None = None) -> np.ndarray:
        """(2,) complex TE and TM reflection of the stack without the sheet.

        Voltage (tangential field) ratios, which for a wave in vacuum are also the ratios
        of the TE and TM amplitudes of :mod:`barymesh.mom.periodic`; referred to the face
        the wave falls on (the top face for a wave from above).
        """
        line = self._background(frequency, wave)
        return line.reflection

    def transmission(self, frequency: float, wave: PlaneWave | None = None) -> np.ndarray:
        """(2,) complex TE and TM transmission of the stack without the sheet, from the
        face the wave falls on to the other (zero with a ground plane)."""
        return self._background(frequency, wave).transmission

    def _background(self, frequency: float, wave: PlaneWave | None) -> Background:
        frequency = _number("frequency", frequency, 0.0, math.inf, low_open=True)
        wave = PlaneWave() if wave is None else wave
        if not isinstance(wave, PlaneWave):
            raise TypeError(f"wave must be a PlaneWave, got {type(wave).__name__}")
        k0 = 2.0 * math.pi * frequency / SPEED_OF_LIGHT
        d = np.asarray(wave.direction)
        kappa = k0 * math.hypot(d[0], d[1])
        return background(self, k0, kappa, from_above=bool(d[2] < 0))

    # -- where orders propagate inside the stack -------------------------------------------

    def sides(self, from_above: bool = True) -> tuple[tuple[Layer, ...], tuple[Layer, ...], bool]:
        """(incident side's layers outward from the sheet, far side's, far side grounded).

        For a wave from above the incident side is ``above`` (outward: bottom first);
        from below it is ``below``, which a ground plane forbids.
        """
        if from_above:
            return tuple(reversed(self.above)), self.below, self.ground
        if self.ground:
            raise ValueError("a wave from below cannot reach a sheet over a ground plane")
        return self.below, tuple(reversed(self.above)), False


def parse_stack(text: str) -> Stack:
    """The stack of the command line's syntax.

    Layers are separated by ``;``, top first; each is a thickness with its unit (mm, um,
    mil, cm, in) and optional ``eps=``, ``tand=``, ``mu=``. The word ``sheet`` marks
    where the sheet lies (default: on top of the first layer, i.e. every layer is
    below); ``ground`` (last) puts a ground plane under the last layer.

    Examples
    --------
    >>> parse_stack("1.575mm eps=2.2 tand=0.0009; ground").describe()
    '1.575mm eps=2.2 tand=0.0009; ground'
    >>> s = parse_stack("0.5mm eps=3; sheet; 30mil eps=2.2")
    >>> [layer.thickness for layer in s.above], [round(layer.thickness, 4) for layer in s.below]
    ([0.5], [0.762])
    """
    if not isinstance(text, str):
        raise TypeError(f"a stack must be a string such as '1.575mm eps=2.2; ground', got {text!r}")
    units = {"mm": 1.0, "um": 1e-3, "µm": 1e-3, "mil": 0.0254, "cm": 10.0, "in": 25.4, "m": 1e3}
    above: list[Layer] = []
    below: list[Layer] = []
    side = below
    sheet_seen = ground = False
    parts = [p.strip() for p in text.split(";")]
    if not any(parts):
        raise ValueError("the stack is empty; expected e.g. '1.575mm eps=2.2 tand=0.0009; ground'")
    for i, part in enumerate(parts):
        if not part:
            raise ValueError(f"stack {text!r}: item {i + 1} is empty (two ';' in a row?)")
        word = part.lower()
        if word == "sheet":
            if sheet_seen or ground:
                raise ValueError(f"stack {text!r}: 'sheet' must appear once, before 'ground'")
            sheet_seen = True
            above, below = below, []
            side = below
            continue
        if word == "ground":
            if i != len(parts) - 1:
                raise ValueError(f"stack {text!r}: 'ground' must come last")
            ground = True
            continue
        tokens = part.split()
        m = re.fullmatch(r"([0-9.eE+-]+)\s*(mm|um|µm|mil|cm|in|m)", tokens[0])
        if m is None:
            raise ValueError(
                f"stack {text!r}: layer {part!r} must start with a thickness and its unit, "
                "e.g. '1.575mm' or '30mil'"
            )
        try:
            thickness = float(m.group(1)) * units[m.group(2)]
        except ValueError:
            raise ValueError(f"stack {text!r}: {tokens[0]!r} is not a thickness") from None
        values: dict[str, float] = {}
        names = {
            "eps": "eps_r",
            "er": "eps_r",
            "eps_r": "eps_r",
            "tand": "loss_tangent",
            "tan_d": "loss_tangent",
            "loss_tangent": "loss_tangent",
            "mu": "mu_r",
            "mu_r": "mu_r",
        }
        for token in tokens[1:]:
            key, sep, value = token.partition("=")
            if not sep or key.lower() not in names:
                raise ValueError(
                    f"stack {text!r}: {token!r} in layer {part!r}; expected eps=, tand= or mu="
                )
            try:
                values[names[key.lower()]] = float(value)
            except ValueError:
                raise ValueError(f"stack {text!r}: {token!r} is not a number") from None
        side.append(Layer(thickness, **values))
    if sheet_seen:
        return Stack(tuple(above), tuple(below), ground)
    return Stack((), tuple(side), ground)


# -- the transmission line of each Floquet harmonic ---------------------------------------


def _gamma(kappa2: np.ndarray, k2: complex) -> np.ndarray:
    """sqrt(κ² − k²) with Re ≥ 0 (imaginary, +j β, for a wave propagating in vacuum)."""
    return np.sqrt(kappa2 - k2 + 0j)


@dataclass(frozen=True, eq=False)
class Side:
    """One side of the sheet as seen by each harmonic (arrays of shape (P, 2): TE, TM).

    Attributes
    ----------
    admittance : (P, 2) complex
        y looking outward from the sheet, normalised to 1/η0.
    transfer : (P, 2) complex
        V(outer face) / V(sheet) for waves going outward (zero behind a ground plane).
    near : list of (P, 2) complex
        V at the sheet-side face of each layer, outward, over V(sheet).
    """

    admittance: np.ndarray
    transfer: np.ndarray


def _tanh_over_gamma(gamma: np.ndarray, d: float) -> np.ndarray:
    """tanh(γ d)/γ, regular at γ = 0 (its series below :data:`SMALL_ARGUMENT`)."""
    x = gamma * d
    small = np.abs(x) < SMALL_ARGUMENT
    safe = np.where(small, 1.0, gamma)
    e = np.exp(-2.0 * np.where(small, 1.0, x))
    t = (1.0 - e) / (1.0 + e) / safe
    return np.where(small, d * (1.0 - x * x / 3.0), t)


def _sech(x: np.ndarray) -> np.ndarray:
    e = np.exp(-x)
    return 2.0 * e / (1.0 + e * e)


def vacuum_admittance(kappa2: np.ndarray, k0: float) -> np.ndarray:
    """(P, 2) TE and TM admittances of vacuum, over 1/η0: γ/(j k0) and j k0/γ."""
    g = _gamma(kappa2, k0 * k0)
    with np.errstate(divide="ignore", invalid="ignore"):
        return np.stack([g / (1j * k0), 1j * k0 / g], axis=-1)


def line_section(
    layer: Layer, kappa2: np.ndarray, k0: float
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """One layer as a section of line, TE and TM: (y t, t/y, sech(γd)), each (P, 2) or (P, 1).

    y is the layer's characteristic admittance over 1/η0 (y_TE = γ/(j k0 μ), y_TM =
    j k0 ε/γ) and t = tanh(γ d), written so that both stay regular at γ = 0. A load y_L
    at one face is seen at the other as (y_L + y t)/(1 + y_L t/y), and the voltage there
    is sech(γd)/(1 + y_L t/y) of this face's.
    """
    d = layer.thickness * 1e-3
    eps, mu = layer.epsilon, layer.mu_r
    jk = 1j * k0
    g = _gamma(kappa2, k0 * k0 * eps * mu)
    s = _tanh_over_gamma(g, d)  # tanh(γd)/γ
    c = g * g * s  # γ tanh(γd)
    yt = np.stack([c / (jk * mu), jk * eps * s], axis=-1)
    t_over_y = np.stack([jk * mu * s, c / (jk * eps)], axis=-1)
    return yt, t_over_y, _sech(g * d)[..., None]


def side(layers: Sequence[Layer], grounded: bool, kappa2: np.ndarray, k0: float) -> Side:
    """The line outward from the sheet through ``layers`` (nearest first), ended by vacuum
    or, when ``grounded``, by a short (the ground plane)."""
    kappa2 = np.asarray(kappa2, dtype=np.float64)
    shape = kappa2.shape + (2,)
    if grounded:
        load = np.full(shape, np.inf + 0j)
        shorted = np.ones(shape, dtype=bool)
        transfer = np.zeros(shape, dtype=np.complex128)
    else:
        load = vacuum_admittance(kappa2, k0)
        shorted = np.zeros(shape, dtype=bool)
        transfer = np.ones(shape, dtype=np.complex128)
    for layer in reversed(tuple(layers)):
        if layer.thickness == 0.0:
            continue
        yt, t_over_y, sech = line_section(layer, kappa2, k0)
        with np.errstate(divide="ignore", invalid="ignore", over="ignore"):
            finite = np.where(shorted, 0.0, load)
            opened = (finite + yt) / (1.0 + finite * t_over_y)
            ratio = sech / (1.0 + finite * t_over_y)
            grounded_in = 1.0 / t_over_y  # y / tanh(γd): a shorted line
        load = np.where(shorted, grounded_in, opened)
        transfer = np.where(shorted, 0.0, transfer * ratio)
        shorted = np.zeros(shape, dtype=bool)
    return Side(admittance=load, transfer=transfer)


@dataclass(frozen=True, eq=False)
class Background:
    """The stack without the sheet, lit by a plane wave (TE, TM each).

    Attributes
    ----------
    reflection, transmission : (2,) complex
        At the two faces (voltage ratios).
    sheet : (2,) complex
        V(sheet) / V_incident (incident voltage at the face it falls on).
    """

    reflection: np.ndarray
    transmission: np.ndarray
    sheet: np.ndarray


def _outer_to_sheet(
    layers_outward: Sequence[Layer], load_at_sheet: np.ndarray, kappa2: np.ndarray, k0: float
) -> tuple[np.ndarray, np.ndarray]:
    """Looking in from the incident side's outer face: (admittance there, V(sheet)/V(face)).

    ``load_at_sheet`` is what the sheet's plane sees on the far side (P, 2).
    """
    load = np.asarray(load_at_sheet, dtype=np.complex128)
    ratio = np.ones_like(load)
    for layer in layers_outward:  # from the sheet outward: each seen from its outer face
        if layer.thickness == 0.0:
            continue
        yt, t_over_y, sech = line_section(layer, kappa2, k0)
        ratio = ratio * sech / (1.0 + load * t_over_y)  # V(inner face) / V(outer face)
        load = (load + yt) / (1.0 + load * t_over_y)
    return load, ratio


def background(stack: Stack, k0: float, kappa: float, from_above: bool = True) -> Background:
    """The stack without the sheet at wavenumber ``k0`` (rad/m) and |κ| = ``kappa``."""
    near, far, grounded = stack.sides(from_above)
    kappa2 = np.array([kappa * kappa])
    far_side = side(far, grounded, kappa2, k0)
    top, to_sheet = _outer_to_sheet(near, far_side.admittance, kappa2, k0)
    y0 = vacuum_admittance(kappa2, k0)
    gamma = (y0 - top) / (y0 + top)
    sheet = (1.0 + gamma) * to_sheet
    return Background(
        reflection=gamma[0],
        transmission=(sheet * far_side.transfer)[0],
        sheet=sheet[0],
    )


def _sinh_over_gamma(gamma: np.ndarray, d: float) -> np.ndarray:
    """sinh(γ d)/γ, regular at γ = 0."""
    x = gamma * d
    small = np.abs(x) < SMALL_ARGUMENT
    safe = np.where(small, 1.0, gamma)
    return np.where(small, d * (1.0 + x * x / 6.0), np.sinh(np.where(small, 0.0, x)) / safe)


def lit_side_loss(
    layers_outward: Sequence[Layer],
    kappa2: float,
    k0: float,
    sheet: np.ndarray,
    incoming: np.ndarray,
) -> float:
    """Power lost in the layers of the lit side for one harmonic (TE, TM), over 1/η0.

    The harmonic has tangential voltage ``sheet`` (2,) at the sheet and a wave of voltage
    ``incoming`` (2,) falling on the outer face from vacuum: the line between is solved
    layer by layer (ABCD, currents flowing outward), and the loss is the power flowing
    outward at the sheet minus that at the face, ½ Re(V I*) at each.
    """
    jk = 1j * k0
    m = np.broadcast_to(np.eye(2, dtype=np.complex128), (2, 2, 2)).copy()  # per polarisation
    for layer in layers_outward:
        d = layer.thickness * 1e-3
        if d == 0.0:
            continue
        eps, mu = layer.epsilon, layer.mu_r
        g = _gamma(np.array(kappa2), k0 * k0 * eps * mu)
        sg = _sinh_over_gamma(g, d)
        ch = np.cosh(g * d)
        # Z sinh and Y sinh of TE (y = γ/(jk0μ)) and TM (y = jk0ε/γ), regular at γ = 0
        z_sinh = np.array([jk * mu * sg, g * g * sg / (jk * eps)])
        y_sinh = np.array([g * g * sg / (jk * mu), jk * eps * sg])
        for p in range(2):
            step = np.array([[ch, -z_sinh[p]], [-y_sinh[p], ch]])  # outward: near to far
            m[p] = step @ m[p]
    y0 = vacuum_admittance(np.array([kappa2]), k0)[0]
    lost = 0.0
    for p in range(2):
        (a, b), (c, e) = m[p]
        current = (2.0 * y0[p] * incoming[p] - (y0[p] * a - c) * sheet[p]) / (y0[p] * b - e)
        v_face = a * sheet[p] + b * current
        i_face = c * sheet[p] + e * current
        lost += 0.5 * float(
            np.real(sheet[p] * np.conj(current)) - np.real(v_face * np.conj(i_face))
        )
    return lost


def transmission_map(
    stack: Stack, k0: float, kappa2: np.ndarray, from_above: bool = True
) -> tuple[np.ndarray, np.ndarray]:
    """(a, b), each (P, 2) complex: T = a δ + b R for each Floquet order, TE and TM.

    The sheet has no thickness: the tangential field is the same on its two faces. On the
    far side only outgoing waves run, so T = t_far V(sheet); on the lit side, for the
    incident order (the first of ``kappa2``), V(sheet) follows from the incident and
    reflected waves at the lit face through the lit layers' chain matrix M (face to
    sheet, currents toward the sheet): V(sheet) = (M11 + M12 y0) δ + (M11 − M12 y0) R
    (δ the incident component). Every other order runs outward on both sides, and
    T = (t_far / t_lit) R. In vacuum a = δ and b = 1: T = δ + R. A sweep fits R and takes
    T from it.
    """
    lit_layers, far_layers, grounded = stack.sides(from_above)
    kappa2 = np.asarray(kappa2, dtype=np.float64)
    far = side(far_layers, grounded, kappa2, k0)
    lit = side(lit_layers, False, kappa2, k0)
    with np.errstate(divide="ignore", invalid="ignore"):
        b = np.where(lit.transfer != 0, far.transfer / lit.transfer, 0.0)
    a = np.zeros_like(b)
    # the incident order: the chain matrix of the lit layers, face to sheet
    jk = 1j * k0
    m = np.broadcast_to(np.eye(2, dtype=np.complex128), (2, 2, 2)).copy()
    for layer in lit_layers[::-1]:  # outermost first, toward the sheet
        d = layer.thickness * 1e-3
        if d == 0.0:
            continue
        eps, mu = layer.epsilon, layer.mu_r
        g = _gamma(np.array(kappa2[0]), k0 * k0 * eps * mu)
        sg = _sinh_over_gamma(g, d)
        ch = np.cosh(g * d)
        z_sinh = np.array([jk * mu * sg, g * g * sg / (jk * eps)])
        y_sinh = np.array([g * g * sg / (jk * mu), jk * eps * sg])
        for p in range(2):
            m[p] = np.array([[ch, -z_sinh[p]], [-y_sinh[p], ch]]) @ m[p]
    y0 = vacuum_admittance(kappa2[:1], k0)[0]
    t0 = far.transfer[0]
    a[0] = t0 * (m[:, 0, 0] + m[:, 0, 1] * y0)
    b[0] = t0 * (m[:, 0, 0] - m[:, 0, 1] * y0)
    return a, b
