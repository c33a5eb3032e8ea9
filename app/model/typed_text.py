"""Typed text read exactly: numbers (the locale's decimal separator too) and points."""

from __future__ import annotations

import math
import re
from dataclasses import dataclass
from typing import Any

from barymesh.app.model.formatting import format_value
from barymesh.app.model.specs import ParamSpec

_NUMBER = re.compile(r"[+-]?(?:\d+(?:\.\d*)?|\.\d+)(?:[eE][+-]?\d+)?")
_INTEGER = re.compile(r"[+-]?\d+")


@dataclass(frozen=True)
class Reading:
    """What a typed text was read as: a number, ``None`` (empty), or the text itself.

    ``value`` is the text unchanged when it is not a number, so that the core's refusal
    names what the user typed. ``note`` says how the text was read when that is not
    obvious (the locale's decimal separator).
    """

    value: Any
    note: str | None = None


def _locale_note(text: str, value: Any, decimal_point: str) -> str:
    if decimal_point == ".":
        why = "a dot is always read as the decimal separator"
    else:
        why = f"{decimal_point!r} is this system's decimal separator"
    return f"read {text.strip()!r} as {format_value(value)} ({why})"


def read_number(text: str, spec: ParamSpec | None = None, decimal_point: str = ".") -> Reading:
    """Read a typed number exactly: no clamping, no rounding, no guessing.

    A dot is always the decimal separator; the locale's own ``decimal_point`` is accepted
    as well. Where the locale's separator is not a dot, the note says which one was read.
    Group separators, which differ between locales, are not accepted: such text is
    returned unchanged for the core to refuse.

    >>> read_number("4.5").value, read_number("1e-3").value, read_number("-3").value
    (4.5, 0.001, -3.0)
    >>> r = read_number("4,5", decimal_point=","); r.value, r.note
    (4.5, "read '4,5' as 4.5 (',' is this system's decimal separator)")
    >>> read_number("4.5", decimal_point=",").note
    "read '4.5' as 4.5 (a dot is always read as the decimal separator)"
    >>> read_number("4,5").value
    '4,5'
    """
    s = text.strip()
    if spec is not None and spec.unit and s.endswith(spec.unit):
        s = s[: -len(spec.unit)].strip()
    if spec is not None and spec.optional and s.lower() in ("", spec.empty_text.lower()):
        return Reading(None)
    localized = decimal_point not in (".", "") and decimal_point in s and "." not in s
    if localized:
        s = s.replace(decimal_point, ".")
    if spec is not None and spec.integer and _INTEGER.fullmatch(s):
        value: Any = int(s)
    elif _NUMBER.fullmatch(s):
        value = float(s)
        if spec is not None and spec.integer and math.isfinite(value) and value.is_integer():
            value = int(value)
    else:
        return Reading(text.strip())
    if localized:
        return Reading(value, _locale_note(text, value, decimal_point))
    if decimal_point not in (".", "") and "." in s:
        return Reading(value, _locale_note(text, value, "."))
    return Reading(value)


def read_points(text: str, count: int, decimal_point: str = ".") -> Reading:
    """Read ``count`` points typed as ``x, y; x, y; ...`` (``x y`` works too).

    With a decimal comma the coordinates are separated by spaces only. Anything that is
    not ``count`` pairs of numbers comes back as the text for the core to refuse.

    >>> read_points("1, 2", 1).value, read_points("0 0; 4 0; 0 3", 3).value
    ((1.0, 2.0), ((0.0, 0.0), (4.0, 0.0), (0.0, 3.0)))
    """
    s = text.strip()
    if count > 1 and s == "":
        return Reading(None)
    points, notes = [], []
    for part in s.split(";"):
        if decimal_point == ",":
            coords = part.split()
        else:
            coords = [c for c in re.split(r"[,\s]+", part.strip()) if c]
        readings = [read_number(c, None, decimal_point) for c in coords]
        if len(readings) != 2 or not all(isinstance(r.value, float) for r in readings):
            return Reading(s)
        points.append(tuple(r.value for r in readings))
        notes += [r.note for r in readings if r.note]
    if len(points) != count:
        return Reading(s)
    value = points[0] if count == 1 else tuple(points)
    which = decimal_point if decimal_point in s else "."
    return Reading(value, _locale_note(s, value, which) if notes else None)


# -- results -------------------------------------------------------------------------------
