"""Frequencies written as text: ``'6.19GHz'``, ``'300 MHz'``, ``'1e9'`` or a sweep ``'A:B:K'``.

The command line's ``--freq`` (:mod:`barymesh.app.cli_solve`) and a study's
``solve.frequencies`` (:mod:`barymesh.study.spec`) read them alike; a bad text is a
``ValueError`` naming the option or key it was given for.

>>> parse_frequencies("3GHz:12GHz:4")
[3000000000.0, 6000000000.0, 9000000000.0, 12000000000.0]
"""

from __future__ import annotations

import re

from .values import echo

#: Frequency units understood (case-insensitive); a bare number is in Hz.
FREQUENCY_UNITS = {"hz": 1.0, "khz": 1e3, "mhz": 1e6, "ghz": 1e9, "thz": 1e12}
#: Most frequencies of one sweep ``A:B:K``: each is a solve (a 1e9 list took 16 GB).
MAX_FREQUENCIES = 100_000


def parse_frequency(text: str, name: str = "--freq") -> float:
    """``'6.19GHz'`` -> 6.19e9 (Hz); a bare number is in Hz.

    Parameters
    ----------
    text : str
    name : str
        The option or key the text was given for, named in the error.

    Raises
    ------
    ValueError
        Not a positive, finite frequency with a known unit.

    Examples
    --------
    >>> parse_frequency("6.19GHz"), parse_frequency("300 MHz"), parse_frequency("1e9")
    (6190000000.0, 300000000.0, 1000000000.0)
    """
    if not isinstance(text, str):
        raise ValueError(f"{name} {echo(text)} is invalid; expected a text such as 6.19GHz")
    m = re.fullmatch(r"\s*([-+0-9.eE]+)\s*([a-zA-Z]*)\s*", text)
    unit = m.group(2).lower() if m else ""
    if not m or unit not in FREQUENCY_UNITS and unit != "":
        raise ValueError(
            f"{name} {echo(text)} is invalid; expected a number with Hz, kHz, MHz, GHz "
            "or THz, e.g. 6.19GHz"
        )
    try:
        value = float(m.group(1)) * FREQUENCY_UNITS.get(unit, 1.0)
    except ValueError:
        raise ValueError(f"{name} {echo(text)} is not a number") from None
    if not value > 0 or value == float("inf"):
        raise ValueError(f"{name} {echo(text)} is invalid; expected a positive frequency")
    return value


def parse_frequencies(text: str, name: str = "--freq") -> list[float]:
    """One frequency, or ``A:B:K`` -> K frequencies from A to B inclusive, evenly spaced.

    Examples
    --------
    >>> parse_frequencies("3GHz:12GHz:4")
    [3000000000.0, 6000000000.0, 9000000000.0, 12000000000.0]
    >>> parse_frequencies("6GHz")
    [6000000000.0]
    """
    if not isinstance(text, str):
        raise ValueError(f"{name} {echo(text)} is invalid; expected a text F or A:B:K")
    parts = text.split(":")
    if len(parts) == 1:
        return [parse_frequency(text, name)]
    if len(parts) != 3:
        raise ValueError(f"{name} {echo(text)} is invalid; expected F or A:B:K")
    a, b = parse_frequency(parts[0], name), parse_frequency(parts[1], name)
    digits = parts[2].strip()
    if not re.fullmatch(r"[+-]?\d{1,30}", digits):
        raise ValueError(f"{name} {echo(text)}: K={echo(digits)} is not a whole number")
    k = int(digits)
    if k > MAX_FREQUENCIES:
        raise ValueError(
            f"{name} {echo(text)}: K={k:,} frequencies is more than a sweep takes "
            f"({MAX_FREQUENCIES:,}); use fewer"
        )
    if k < 2 or not b > a:
        raise ValueError(f"{name} {echo(text)} is invalid; expected A < B and K >= 2 frequencies")
    step = (b - a) / (k - 1)
    return [a + i * step for i in range(k - 1)] + [b]
