"""The reflectarray designer's inputs and what it shows, without Qt (issue 33 §2, window).

The designer window (:mod:`barymesh.app.dialogs.reflectarray_designer`) reads its typed
fields with :func:`read_design_inputs` (a refusal is one sentence naming the field) and
lays the array out in a worker with :func:`run_design`: :func:`barymesh.reflectarray.design`
of the Reflection phase tab's library, then the numbers written on the picture
(:class:`DesignNumbers`: the main beam, the side-lobe level, the quantisation loss against
the textbook value) and the pattern's cut in the beam's plane (:func:`pattern_cut`).
:func:`element_outlines` gives each element's cell of the lattice, the tiles the layout is
drawn with. ``barymesh.reflectarray`` is imported only when a design is made (the window's
first frame does not pay for it).
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any

import numpy as np

#: The bit choices of the window: (label, bits) with None continuous.
BIT_CHOICES: tuple[tuple[str, int | None], ...] = (
    ("Continuous", None),
    ("1 bit", 1),
    ("2 bits", 2),
    ("3 bits", 3),
)
#: Most elements the window designs and draws (each is a tile of the picture).
MAX_ELEMENTS = 10_000
#: Samples of the pattern's cut, from −90° to 90° (0.25° apart).
CUT_POINTS = 721


@dataclass(frozen=True)
class DesignInputs:
    """What the designer's fields say: the arguments of :func:`barymesh.reflectarray.design`
    besides the library and its frequency."""

    aperture: tuple[int, int]
    feed: tuple[float, float, float]
    beam: tuple[float, float]
    bits: int | None = None


def read_float(text: str, name: str) -> float:
    """A typed number (a minus sign "−" too); ValueError naming ``name`` otherwise.

    >>> read_float(" −2.5 ", "Feed x")
    -2.5
    """
    try:
        value = float(text.strip().replace("−", "-").replace("°", ""))
    except ValueError:
        raise ValueError(f"{name} {text.strip()[:30]!r} is not a number; type e.g. 150") from None
    if not math.isfinite(value):
        raise ValueError(f"{name} {text.strip()[:30]!r} is not finite; type a number")
    return value


def read_count(text: str, name: str) -> int:
    """A typed count of elements, a whole number ≥ 1; ValueError naming ``name``.

    >>> read_count("15", "Aperture N1")
    15
    """
    t = text.strip()
    if not t.isdigit() or int(t) < 1:
        raise ValueError(
            f"{name} {t[:30]!r} is invalid; expected a whole number of elements, 1 or more"
        )
    return int(t)


def read_design_inputs(
    n1: str,
    n2: str,
    feed: tuple[str, str, str],
    beam: tuple[str, str],
    bits: int | None,
) -> DesignInputs:
    """The designer's typed fields as :class:`DesignInputs`; ValueError naming the field.

    >>> read_design_inputs("15", "15", ("0", "0", "150"), ("20", "0"), None).aperture
    (15, 15)
    >>> read_design_inputs("15", "15", ("0", "0", "-5"), ("20", "0"), 1)
    Traceback (most recent call last):
    ...
    ValueError: Feed z -5 mm is invalid; expected the feed above the aperture, z > 0 mm
    """
    a = read_count(n1, "Aperture N1")
    b = read_count(n2, "Aperture N2")
    if a * b > MAX_ELEMENTS:
        raise ValueError(
            f"Aperture {a} × {b} has {a * b:,} elements; the window designs at most "
            f"{MAX_ELEMENTS:,} (the command line, barymesh reflectarray, more)"
        )
    x = read_float(feed[0], "Feed x")
    y = read_float(feed[1], "Feed y")
    z = read_float(feed[2], "Feed z")
    if z <= 0.0:
        raise ValueError(
            f"Feed z {z:g} mm is invalid; expected the feed above the aperture, z > 0 mm"
        )
    theta = read_float(beam[0], "Beam θ")
    phi = read_float(beam[1], "Beam φ")
    if not 0.0 <= theta < 90.0:
        raise ValueError(f"Beam θ {theta:g}° is out of range; expected 0 <= θ < 90°")
    if bits not in (None, 1, 2, 3):
        raise ValueError(f"Bits {bits!r} is invalid; expected continuous, 1, 2 or 3")
    return DesignInputs((a, b), (x, y, z), (theta, phi), bits)


@dataclass(frozen=True)
class DesignNumbers:
    """The numbers the designer writes on its picture (degrees, dB).

    ``quantization_loss`` and ``textbook_loss`` are None for a continuous design.
    """

    asked: tuple[float, float]
    beam_direction: tuple[float, float]
    gain: float
    side_lobe_level: float
    rms_error: float
    largest_error: float
    bits: int | None
    quantization_loss: float | None
    textbook_loss: float | None

    @property
    def pointing_error(self) -> float:
        """The angle (degrees) between the main beam and the beam asked for."""
        return angle_between(self.asked, self.beam_direction)

    def lines(self) -> list[str]:
        """Three lines: the main beam, the side lobes and phase error, the quantisation.

        >>> DesignNumbers((20.0, 0.0), (19.8, 0.0), 26.3, -28.3, 3.2, 9.0, 1, -3.27,
        ...               -3.92).lines()[2]
        '1-bit quantisation loss −3.27 dB (textbook −3.9 dB for 1 bit)'
        """
        theta, phi = self.beam_direction
        beam = (
            f"Main beam θ = {theta:.2f}°, φ = {phi:.2f}° (asked {self.asked[0]:g}°, "
            f"{self.asked[1]:g}°; off by {self.pointing_error:.2f}°), gain {self.gain:.1f} dBi"
        )
        if math.isinf(self.side_lobe_level):
            sll = "no side lobe"
        else:
            sll = f"side-lobe level {minus(self.side_lobe_level, 1)} dB"
        lobes = (
            f"{sll[0].upper()}{sll[1:]}; phase error RMS {self.rms_error:.1f}°, "
            f"largest {self.largest_error:.1f}°"
        )
        if self.bits is None or self.quantization_loss is None or self.textbook_loss is None:
            quant = "Continuous phases: no quantisation loss (1/2/3 bits: −3.9/−0.9/−0.2 dB)"
        else:
            bit = "bit" if self.bits == 1 else "bits"
            quant = (
                f"{self.bits}-bit quantisation loss {minus(self.quantization_loss, 2)} dB "
                f"(textbook {minus(self.textbook_loss, 1)} dB for {self.bits} {bit})"
            )
        return [beam, lobes, quant]


def minus(value: float, digits: int) -> str:
    """A number with a true minus sign.

    >>> minus(-3.271, 2), minus(0.5, 1)
    ('−3.27', '0.5')
    """
    return f"{value:.{digits}f}".replace("-", "−")


def angle_between(a: tuple[float, float], b: tuple[float, float]) -> float:
    """The angle (degrees) between the directions (θ, φ) ``a`` and ``b`` (degrees).

    >>> round(angle_between((20.0, 0.0), (20.0, 180.0)), 6)
    40.0
    """

    def unit(t: float, p: float) -> np.ndarray:
        t, p = math.radians(t), math.radians(p)
        return np.array([math.sin(t) * math.cos(p), math.sin(t) * math.sin(p), math.cos(t)])

    c = float(np.clip(unit(*a) @ unit(*b), -1.0, 1.0))
    return math.degrees(math.acos(c))


def design_numbers(array: Any) -> DesignNumbers:
    """The :class:`DesignNumbers` of a :class:`barymesh.reflectarray.Reflectarray`."""
    from barymesh.reflectarray import textbook_quantization_loss

    err = np.asarray(array.phase_error)
    bits = array.bits
    return DesignNumbers(
        asked=(float(array.beam[0]), float(array.beam[1])),
        beam_direction=tuple(float(a) for a in array.beam_direction),  # type: ignore[arg-type]
        gain=float(array.gain),
        side_lobe_level=float(array.side_lobe_level),
        rms_error=float(np.sqrt(np.mean(err**2))),
        largest_error=float(np.abs(err).max()),
        bits=bits,
        quantization_loss=None if bits is None else float(array.quantization_loss),
        textbook_loss=None if bits is None else textbook_quantization_loss(bits),
    )


def pattern_cut(array: Any, points: int = CUT_POINTS) -> tuple[np.ndarray, np.ndarray]:
    """The gain (dBi) in the plane of the beam asked for: (θ (P,), dBi (P,)).

    θ runs from −90° to 90°: θ ≥ 0 in the plane's half φ_b, θ < 0 the direction |θ| at
    φ_b + 180°, so that the cut is one line through the aperture's normal.
    """
    theta = np.linspace(-90.0, 90.0, points)
    phi_b = float(array.beam[1])
    phi = np.where(theta < 0, phi_b + 180.0, phi_b)
    return theta, np.asarray(array.pattern_db(np.abs(theta), phi), dtype=float)


def signed_theta(direction: tuple[float, float], phi_b: float) -> float:
    """θ of a direction on the cut's axis of the plane φ_b: −θ when it lies nearer the
    half φ_b + 180° (a direction off the plane is put by its nearer half).

    >>> signed_theta((20.0, 180.0), 0.0), signed_theta((20.0, 5.0), 0.0)
    (-20.0, 20.0)
    """
    theta, phi = direction
    off = abs((phi - phi_b + 180.0) % 360.0 - 180.0)
    return -theta if off > 90.0 else theta


def element_outlines(array: Any) -> np.ndarray:
    """(N, 4, 2) float: each element's cell of the lattice (a parallelogram, mm) in x, y.

    The tiles of the layout's picture: element n's centre ± a1/2 ± a2/2.
    """
    a1 = np.asarray(array.lattice.a1, dtype=float)[:2]
    a2 = np.asarray(array.lattice.a2, dtype=float)[:2]
    corners = 0.5 * np.array([-a1 - a2, a1 - a2, a1 + a2, -a1 + a2])  # (4, 2)
    centres = np.asarray(array.positions, dtype=float)[:, :2]
    return centres[:, None, :] + corners[None, :, :]


@dataclass(frozen=True)
class DesignResult:
    """A design made in a worker, with what the picture draws of it.

    Attributes
    ----------
    array : barymesh.reflectarray.Reflectarray
    inputs : DesignInputs
    numbers : DesignNumbers
    cut : ((P,), (P,)) float
        θ (degrees, signed) and the gain (dBi) of :func:`pattern_cut`.
    continuous_cut : ((P,), (P,)) float or None
        The same cut of the continuous design, for a quantised one.
    """

    array: Any
    inputs: DesignInputs
    numbers: DesignNumbers
    cut: tuple[np.ndarray, np.ndarray]
    continuous_cut: tuple[np.ndarray, np.ndarray] | None


def run_design(library: Any, inputs: DesignInputs) -> DesignResult:
    """:func:`barymesh.reflectarray.design` of ``library`` (at its first frequency) and
    ``inputs``, with its numbers and cuts (a worker's: a few tenths of a second for
    15 × 15 elements). ValueError from the designer passes through."""
    from barymesh.reflectarray import design

    array = design(
        library,
        inputs.aperture,
        inputs.feed,
        inputs.beam,
        float(library.frequencies[0]),
        bits=inputs.bits,
    )
    numbers = design_numbers(array)
    continuous = None if inputs.bits is None else pattern_cut(array.continuous())
    return DesignResult(array, inputs, numbers, pattern_cut(array), continuous)
