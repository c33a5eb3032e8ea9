"""What the solve and array tabs read from typed text, without Qt: frequencies with
their unit, a band, directions, points and impedances (doctested; the panels show the
ValueError's message beside the field)."""

from __future__ import annotations

import math

#: Frequency units of the unit boxes.
UNITS = {"Hz": 1.0, "kHz": 1e3, "MHz": 1e6, "GHz": 1e9}
#: Named directions (the direction boxes' presets and what they accept besides X, Y, Z).
AXES = {
    "x": (1.0, 0.0, 0.0),
    "y": (0.0, 1.0, 0.0),
    "z": (0.0, 0.0, 1.0),
}
DIRECTION_PRESETS = ("-z", "+z", "-x", "+x", "-y", "+y")
POLARIZATION_PRESETS = ("x", "y", "z")


def read_frequency(text: str, unit: str) -> float:
    """``("300", "MHz")`` -> 3e8 Hz; ValueError naming the field otherwise.

    >>> read_frequency("6.19", "GHz")
    6190000000.0
    """
    try:
        value = float(text.strip()) * UNITS[unit]
    except (ValueError, KeyError):
        raise ValueError(f"Frequency {text!r} is not a number; type e.g. 300") from None
    if not math.isfinite(value) or value <= 0:
        raise ValueError(f"Frequency {text!r} {unit} is invalid; expected a positive number")
    return value


def read_vector(text: str, name: str) -> tuple[float, float, float]:
    """``"-z"`` -> (0, 0, -1); ``"1, 1, 0"`` -> (1, 1, 0); ValueError naming ``name``.

    >>> read_vector("-z", "Direction"), read_vector("0, 1, 0", "Polarisation")
    ((0.0, 0.0, -1.0), (0.0, 1.0, 0.0))
    """
    t = text.strip().lower().replace("−", "-")
    name_ = t.lstrip("+-")
    if name_ in AXES:
        sign = -1.0 if t.startswith("-") else 1.0
        return tuple(sign * c + 0.0 for c in AXES[name_])  # type: ignore[return-value]
    try:
        values = tuple(float(v) for v in t.replace(";", ",").split(","))
    except ValueError:
        values = ()
    if len(values) != 3 or not all(math.isfinite(v) for v in values):
        raise ValueError(
            f"{name} {text!r} is invalid; expected an axis (x, -z, …) or three numbers x, y, z"
        )
    return values


def read_point(text: str, name: str) -> tuple[float, ...]:
    """``"0, -10"`` -> (0.0, -10.0) (mm; two or three numbers); ValueError naming ``name``.

    >>> read_point("0, -10", "Feed start"), read_point("1 2 3", "Feed end")
    ((0.0, -10.0), (1.0, 2.0, 3.0))
    """
    try:
        values = tuple(float(v) for v in text.replace(";", ",").replace(",", " ").split())
    except ValueError:
        values = ()
    if len(values) not in (2, 3) or not all(math.isfinite(v) for v in values):
        raise ValueError(f"{name} {text!r} is invalid; expected a point x, y in mm (e.g. 0, -10)")
    return values


def format_impedance(z: complex) -> str:
    """``"73.1 + j42.5 Ω"`` (5 significant digits)."""
    return f"{z.real:.5g} {'+-'[z.imag < 0]} j{abs(z.imag):.5g} Ω"


def format_frequency(hz: float) -> tuple[str, str]:
    """A frequency as (number, unit) for the fields: 6.19e9 -> ("6.19", "GHz")."""
    for unit in ("GHz", "MHz", "kHz"):
        if hz >= UNITS[unit]:
            return f"{hz / UNITS[unit]:.6g}", unit
    return f"{hz:.6g}", "Hz"


def read_band(start: str, stop: str, unit: str, name: str = "Band") -> tuple[float, float]:
    """The band (Hz) from its two fields and their unit; ValueError naming ``name``.

    >>> read_band("4", "9", "GHz")
    (4000000000.0, 9000000000.0)
    >>> read_band("9", "4", "GHz")
    Traceback (most recent call last):
    ...
    ValueError: Band 9 to 4 GHz: the end must be above the start
    """
    a = read_frequency(start, unit)
    b = read_frequency(stop, unit)
    if not b > a:
        raise ValueError(f"{name} {start} to {stop} {unit}: the end must be above the start")
    return a, b
