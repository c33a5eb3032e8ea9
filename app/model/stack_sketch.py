"""Where the stack editor's side view puts things (pixels, no Qt): the layers as bands
whose heights are their thicknesses to one scale, the sheet, the ground plane and the
reference planes of R and T.

The vacuum above and below gets a fixed margin (it has no thickness); everything between
the top and the bottom face is drawn to scale, ``mm_per_pixel``. y grows downwards, as
on a screen.

>>> from barymesh.mom import Layer, Stack
>>> s = sketch_layout(Stack(below=(Layer(0.5, 3), Layer(1.5, 2.2)), ground=True), 140)
>>> [round(b.bottom - b.top, 3) for b in s.bands]
[26.5, 79.5]
>>> s.sheet, s.ground, [name for _y, name in s.planes]
(22.0, (128.0, 138.0), ['R at the sheet'])
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import TYPE_CHECKING

if TYPE_CHECKING:
    from barymesh.mom import Layer, Stack

#: Pixels of vacuum drawn above the top face and below the bottom face.
VACUUM = 22.0
#: Height of the ground plane's hatched bar.
GROUND = 10.0


@dataclass(frozen=True)
class Band:
    """One layer's band: ``top`` and ``bottom`` y (pixels), its index in
    ``Stack.layers`` (top first) and its text."""

    top: float
    bottom: float
    index: int
    label: str


@dataclass(frozen=True)
class Sketch:
    """The side view of a stack in a widget ``height`` pixels tall.

    Attributes
    ----------
    bands : tuple of Band
        The layers, top first (zero-thickness layers are zero pixels tall).
    sheet : float
        y of the sheet.
    top_face, bottom_face : float
        y of the stack's top and bottom faces.
    ground : (float, float) or None
        Top and bottom y of the ground plane's bar.
    planes : tuple of (float, str)
        y and name of each reference plane ("R at the top face", "T at the bottom face";
        one "R, T at the sheet" free-standing).
    mm_per_pixel : float
        The scale of the bands (0 for a stack without thickness).
    """

    bands: tuple[Band, ...]
    sheet: float
    top_face: float
    bottom_face: float
    ground: tuple[float, float] | None
    planes: tuple[tuple[float, str], ...]
    mm_per_pixel: float


def layer_label(layer: Layer) -> str:
    """ "1.575 mm, εr 2.2, tan δ 0.0009" (tan δ and μr only when not 0 and 1)."""
    parts = [f"{layer.thickness:g} mm", f"εr {layer.eps_r:g}"]
    if layer.loss_tangent:
        parts.append(f"tan δ {layer.loss_tangent:g}")
    if layer.mu_r != 1.0:
        parts.append(f"μr {layer.mu_r:g}")
    return ", ".join(parts)


def sketch_layout(stack: Stack | None, height: float) -> Sketch:
    """The side view of ``stack`` (None: the sheet alone) in ``height`` pixels."""
    above = stack.above if stack is not None else ()
    below = stack.below if stack is not None else ()
    grounded = stack is not None and stack.ground
    bottom_space = VACUUM if not grounded else GROUND + 2.0
    room = max(height - VACUUM - bottom_space, 1.0)
    thickness_above = sum(layer.thickness for layer in above)
    total = thickness_above + sum(layer.thickness for layer in below)
    scale = room / total if total > 0 else 0.0
    top_face = VACUUM if total > 0 else 0.5 * height
    y = top_face
    bands = []
    for i, layer in enumerate(above + below):
        h = layer.thickness * scale
        bands.append(Band(y, y + h, i, layer_label(layer)))
        y += h
    bottom_face = y
    sheet = top_face + thickness_above * scale
    ground = (bottom_face, bottom_face + GROUND) if grounded else None
    if not above and not below and not grounded:
        planes: tuple[tuple[float, str], ...] = ((sheet, "R, T at the sheet"),)
    else:
        r = (top_face, "R at the top face" if above else "R at the sheet")
        t = (bottom_face, "T at the bottom face" if below else "T at the sheet")
        planes = (r,) if grounded else (r, t)
    return Sketch(
        tuple(bands),
        sheet,
        top_face,
        bottom_face,
        ground,
        planes,
        1.0 / scale if scale else 0.0,
    )
