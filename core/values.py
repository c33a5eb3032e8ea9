"""Checking one value at the boundary: numbers, and how a bad value is shown.

Parameters, unit-cell documents and the command line take values from users
and files. These helpers turn a value into a float or refuse it with a
``ValueError`` that names the field, shows the value (cut short, however
large or deeply nested) and says what was expected, in the words of a JSON
document rather than Python's type names.

Examples
--------
>>> echo([[[[[[1.0]]]]]])
'[[[[...]]]]'
>>> kind({}), kind([1]), kind("a"), kind(None), kind(True), kind(2.5)
('an object', 'an array', 'a string', 'null', 'true/false', 'a number')
"""

from __future__ import annotations

import difflib
import math
import numbers
import reprlib
from typing import Any

import numpy as np

#: Longest echo of a value in a message (characters).
ECHO_LENGTH = 60

_ECHO = reprlib.Repr()  # (keyword arguments need Python 3.12)
_ECHO.maxlevel = 3
_ECHO.maxtuple = _ECHO.maxlist = _ECHO.maxdict = _ECHO.maxset = _ECHO.maxfrozenset = 4
_ECHO.maxstring = 40
_ECHO.maxlong = _ECHO.maxother = ECHO_LENGTH


class InvalidValue(ValueError):
    """A value refused at the boundary, with the field it was given for.

    Its message names the field too; ``field`` is that name as data, for callers that
    point at where the value came from (a preset file, a ``--set``, a key of a
    document) without reading it back out of the message.

    Attributes
    ----------
    field : str
        The parameter (``"gap_width"``) or a path in a unit cell
        (``"elements[2].position"``, ``"pixels.origin"``).

    Examples
    --------
    >>> try:
    ...     positive("patch_size", -1)
    ... except InvalidValue as exc:
    ...     print(exc.field, "|", exc)
    patch_size | patch_size=-1 is invalid; expected a finite length > 0 mm
    """

    def __init__(self, field: str, message: str) -> None:
        super().__init__(message)
        self.field = field


def echo(value: Any) -> str:
    """``repr`` of a value, cut to a readable length (a 5000-digit integer is still named).

    Containers are shown a few items and three levels deep, so a 900-deep
    nested list neither floods a message nor exhausts the recursion limit.
    """
    if isinstance(value, (list, tuple, dict, set, frozenset)):
        text = _ECHO.repr(value)
        return text if len(text) <= ECHO_LENGTH else f"{text[: ECHO_LENGTH - 3]}..."
    if isinstance(value, int) and value.bit_length() > 14_000:  # past repr's 4,300 digits
        return f"an integer of about {value.bit_length() * 0.30103:,.0f} digits"
    text = repr(value)
    if len(text) <= ECHO_LENGTH:
        return text
    return f"{text[:28]}...{text[-28:]} ({len(text)} characters)"


#: Names listed in full when a name is unknown and none of them is close to it.
LISTED_NAMES = 8


def expected_names(given: Any, known: Any) -> str:
    """``did you mean inner_radius?`` (difflib's closest names), else a short list.

    What to say after "unknown parameter 'inner_radiu'": the closest known names, or all
    of them when there are few, or the first few and how many there are: never all 23
    field names of the parameters in one message.

    >>> expected_names("inner_radiu", ["inner_radius", "outer_radius", "patch_size"])
    'did you mean inner_radius or outer_radius?'
    >>> expected_names("gap", ["gap_angle", "gap_width", "patch_size"])
    'did you mean gap_angle or gap_width?'
    >>> expected_names("x", ["a", "b"])
    'expected one of a, b'
    >>> expected_names("zzz", [f"name_{i}" for i in range(23)])
    'expected one of 23 names (name_0, name_1, name_10, ...)'
    """
    names = sorted(str(k) for k in known)
    close: list[str] = []
    if isinstance(given, str) and given:
        close = [n for n in names if n.startswith(given) or given.startswith(n)]
        close += difflib.get_close_matches(given, names, n=3, cutoff=0.6)
        close = list(dict.fromkeys(close))[:3]
    if close:
        return f"did you mean {' or '.join(close)}?"
    if len(names) <= LISTED_NAMES:
        return f"expected one of {', '.join(names)}"
    return f"expected one of {len(names)} names ({', '.join(names[:3])}, ...)"


def kind(value: Any) -> str:
    """What a value is, in a JSON document's words (``"an array"``, ``"an object"``, ...)."""
    if value is None:
        return "null"
    if isinstance(value, (bool, np.bool_)):
        return "true/false"
    if isinstance(value, numbers.Number):
        return "a number"
    if isinstance(value, str):
        return "a string"
    if isinstance(value, dict):
        return "an object"
    if isinstance(value, (list, tuple, np.ndarray)):
        return "an array"
    return "a value of another kind"


def number(name: str, value: Any, expected: str) -> float:
    """``float(value)``, or a ``ValueError`` naming ``name`` and what was ``expected``.

    Booleans are refused: ``float(True)`` is 1.0, but a switch is no length.
    """
    if isinstance(value, (bool, np.bool_)):
        raise InvalidValue(
            name, f"{name}={value!r} is a true/false switch, not a number; expected {expected}"
        )
    try:
        return float(value)
    except OverflowError:
        raise InvalidValue(
            name, f"{name}={echo(value)} is too large; expected {expected}"
        ) from None
    except (TypeError, ValueError):
        raise InvalidValue(
            name, f"{name}={echo(value)} is not a number; expected {expected}"
        ) from None


def positive(name: str, value: Any) -> float:
    """A finite length > 0 (mm), or a ``ValueError`` naming ``name``."""
    x = number(name, value, "a positive length in mm")
    if not math.isfinite(x) or x <= 0:
        raise InvalidValue(
            name, f"{name}={echo(value)} is invalid; expected a finite length > 0 mm"
        )
    return x


def finite(name: str, value: Any) -> float:
    """A finite number, or a ``ValueError`` naming ``name``."""
    x = number(name, value, "a finite number")
    if not math.isfinite(x):
        raise InvalidValue(name, f"{name}={echo(value)} is invalid; expected a finite number")
    return x


def pair(name: str, value: Any) -> tuple[float, float]:
    """Two finite numbers (x, y) in mm, or a ``ValueError`` naming ``name``."""
    if isinstance(value, (str, bytes, dict)) or not hasattr(value, "__len__") or len(value) != 2:
        raise InvalidValue(
            name, f"{name}={echo(value)} is invalid; expected two numbers (x, y) in mm"
        )
    x, y = value
    return (finite(name, x), finite(name, y))
