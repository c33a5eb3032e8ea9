"""The Infinite array tab's stack editor without Qt: its typed rows read into a Stack,
and the names of the planes R and T are referred to.

The editor lists the layers top first, with the sheet as a row among them: the layers
above that row are ``Stack.above``, those below it ``Stack.below``
(:class:`barymesh.mom.Stack`). Each layer row holds four typed texts, read here exactly
(:func:`barymesh.app.model.typed_text.read_number`); a text that is not a valid value
raises a ValueError naming the layer, the column, the text and what was expected, so the
editor can say it in one line and keep the last good stack.

>>> rows = (LayerRow("1.575", "2.2", "0.0009"),)
>>> read_stack(rows, sheet=0, ground=True).describe()
'1.575mm eps=2.2 tand=0.0009; ground'
>>> read_stack((LayerRow("30mil", "3"),), sheet=0, ground=False).below[0].thickness
0.762
"""

from __future__ import annotations

import re
from collections.abc import Sequence
from dataclasses import dataclass
from typing import TYPE_CHECKING

from barymesh.app.model.typed_text import read_number

if TYPE_CHECKING:  # barymesh.mom is imported when a stack is first read (seconds to load)
    from barymesh.mom import Layer, Stack

#: Units a thickness may be typed in, in mm (no unit: mm).
THICKNESS_UNITS = {"mm": 1.0, "um": 1e-3, "µm": 1e-3, "mil": 0.0254, "cm": 10.0, "in": 25.4}
#: The typed columns of a layer, in the editor's order (the fields of Layer).
COLUMNS = ("thickness", "eps_r", "loss_tangent", "mu_r")
#: Largest thickness (mm) and εr or μr (those of barymesh.mom.stack).
MAX_THICKNESS, MAX_MATERIAL = 1e6, 1e4
#: A new layer: RT/duroid 5880's 1.575 mm, εr 2.2, tan δ 0.0009 (a common substrate).
NEW_LAYER = ("1.575", "2.2", "0.0009", "1")
_UNIT = re.compile(r"^(.*?)\s*(mm|um|µm|mil|cm|in)$")


@dataclass(frozen=True)
class LayerRow:
    """One layer as typed: thickness (mm, or with a unit), εr, tan δ ("" = 0), μr ("" = 1)."""

    thickness: str
    eps_r: str
    loss_tangent: str = ""
    mu_r: str = ""


def layer_row(layer: Layer) -> LayerRow:
    """The texts the editor shows for ``layer``.

    >>> from barymesh.mom import Layer
    >>> layer_row(Layer(1.575, 2.2, 0.0009))
    LayerRow(thickness='1.575', eps_r='2.2', loss_tangent='0.0009', mu_r='1')
    """
    return LayerRow(
        f"{layer.thickness:g}", f"{layer.eps_r:g}", f"{layer.loss_tangent:g}", f"{layer.mu_r:g}"
    )


def read_thickness(text: str, where: str = "thickness") -> float:
    """A typed thickness in mm ("1.575", "30mil", "35 um"); ValueError naming ``where``.

    >>> read_thickness("35um"), read_thickness(" 2 ")
    (0.035, 2.0)
    """
    s = text.strip()
    scale = 1.0
    m = _UNIT.match(s)
    if m is not None:
        s, scale = m.group(1), THICKNESS_UNITS[m.group(2)]
    value = read_number(s).value
    expected = "a thickness >= 0 in mm, or with a unit (35um, 30mil)"
    if not isinstance(value, float) or not 0.0 <= value * scale <= MAX_THICKNESS:
        raise ValueError(f"{where}: thickness {text.strip()!r} is invalid; expected {expected}")
    return value * scale


def _material(
    text: str, name: str, where: str, default: float | None, low_open: bool, high: float
) -> float:
    s = text.strip()
    if not s and default is not None:
        return default
    value = read_number(s).value
    ok = isinstance(value, float) and (value > 0.0 if low_open else value >= 0.0)
    if not ok or value > high:
        bound = f"0 {'<' if low_open else '<='} {name} <= {high:g}"
        raise ValueError(f"{where}: {name} {s!r} is invalid; expected a number, {bound}")
    return value


def read_column(column: str, text: str, where: str) -> float:
    """The value of one typed cell (``column`` one of :data:`COLUMNS`); ValueError
    naming ``where``, the column, the text and what was expected.

    >>> read_column("loss_tangent", "", "Layer 1"), read_column("mu_r", "", "Layer 1")
    (0.0, 1.0)
    >>> read_column("eps_r", "0", "Layer 1")
    Traceback (most recent call last):
    ...
    ValueError: Layer 1: εr '0' is invalid; expected a number, 0 < εr <= 10000
    """
    if column == "thickness":
        return read_thickness(text, where)
    if column == "eps_r":
        return _material(text, "εr", where, None, True, MAX_MATERIAL)
    if column == "loss_tangent":
        return _material(text, "tan δ", where, 0.0, False, 100.0)
    if column == "mu_r":
        return _material(text, "μr", where, 1.0, True, MAX_MATERIAL)
    raise ValueError(f"column {column!r}; expected one of {', '.join(COLUMNS)}")


def read_layer(row: LayerRow, where: str) -> Layer:
    """The :class:`barymesh.mom.Layer` of one typed row; ValueError naming ``where``."""
    from barymesh.mom import Layer

    return Layer(*(read_column(c, getattr(row, c), where) for c in COLUMNS))


def layer_name(index: int, above: bool) -> str:
    """How the editor and its messages name a layer: "Layer 2 (below the sheet)"
    (``index`` counts from 0, top first; the name from 1)."""
    return f"Layer {index + 1} ({'above' if above else 'below'} the sheet)"


def read_stack(rows: Sequence[LayerRow], sheet: int, ground: bool) -> Stack:
    """The stack of the editor: ``rows`` top first, the first ``sheet`` of them above the
    sheet, a ground plane under the last if ``ground``.

    Raises ValueError naming the first bad value, or a ground plane with no layer of
    non-zero thickness below the sheet.

    >>> read_stack((LayerRow("-1", "2.2"),), 0, False)
    Traceback (most recent call last):
    ...
    ValueError: Layer 1 (below the sheet): thickness '-1' is invalid; expected a thickness >= 0 in mm, or with a unit (35um, 30mil)
    >>> read_stack((LayerRow("1", "2"),), 1, True)
    Traceback (most recent call last):
    ...
    ValueError: Ground plane: it needs a layer of non-zero thickness below the sheet (a sheet lying on the ground is shorted); add a layer below the sheet or untick Ground plane
    """  # noqa: E501 - doctest output
    from barymesh.mom import Stack

    if not 0 <= sheet <= len(rows):
        raise ValueError(f"sheet={sheet}; expected 0 to {len(rows)} (layers above it)")
    layers = [read_layer(row, layer_name(i, i < sheet)) for i, row in enumerate(rows)]
    above, below = tuple(layers[:sheet]), tuple(layers[sheet:])
    if ground and not sum(layer.thickness for layer in below) > 0:
        raise ValueError(
            "Ground plane: it needs a layer of non-zero thickness below the sheet (a sheet "
            "lying on the ground is shorted); add a layer below the sheet or untick Ground plane"
        )
    return Stack(above, below, bool(ground))


def _mm(z: float) -> str:
    return f"{z:.4g} mm".replace("-", "−") if z else "0 mm"


def reference_plane_names(stack: Stack | None) -> tuple[str, str | None]:
    """Where R and T of a wave from above are referred: (R's plane, T's plane or None
    behind a ground plane), each as "the top face, z = 1.575 mm".

    >>> from barymesh.mom import Layer, Stack
    >>> reference_plane_names(None)
    ('the sheet, z = 0 mm', 'the sheet, z = 0 mm')
    >>> reference_plane_names(Stack(below=(Layer(1.575, 2.2),), ground=True))
    ('the sheet, z = 0 mm', None)
    >>> reference_plane_names(Stack(above=(Layer(0.5, 3),), below=(Layer(1, 2.2),)))
    ('the top face, z = 0.5 mm', 'the bottom face, z = −1 mm')
    """
    if stack is None or stack.is_free_standing:
        return "the sheet, z = 0 mm", "the sheet, z = 0 mm"
    top, bottom = stack.reference_planes
    r = f"the top face, z = {_mm(top)}" if top > 0 else "the sheet, z = 0 mm"
    if stack.ground:
        return r, None
    t = f"the bottom face, z = {_mm(bottom)}" if bottom < 0 else "the sheet, z = 0 mm"
    return r, t
