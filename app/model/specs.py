"""How each parameter is shown as a control: labels, units, slider ranges, where it applies.

Also what follows from the descriptions: whether a parameter applies to a structure, the
subdivisions carried over a scheme change, and which parameter a core message names.
"""

from __future__ import annotations

import math
import re
from dataclasses import dataclass, replace
from typing import Any, TypedDict

from barymesh import MeshParams
from barymesh.params import (
    ANGULAR_STRUCTURES,
    DOUBLE_STRUCTURES,
    MAX_BARYCENTRIC_LEVELS,
    MAX_UNIFORM_SUBDIVISIONS,
    SPLIT_STRUCTURES,
    STRUCTURES,
)

STRUCTURE_TITLES = {
    "patch": "Square patch",
    "cross": "Cross",
    "triangle": "Triangle",
    "ring": "Ring",
    "double_ring": "Double ring",
    "split_ring": "Split ring",
    "split_double_ring": "Doubly split double ring (circular)",
    "square_split_double_ring": "Doubly split double ring (square)",
}
MODE_TITLES = {"paper": "Paper (overlapping patches)", "conforming": "Conforming (watertight)"}
RING_STRUCTURES = tuple(s for s in STRUCTURES if s not in ("patch", "cross", "triangle"))
NOT_TRIANGLE = tuple(s for s in STRUCTURES if s != "triangle")


#: A logarithmic slider spans this many decades each side of the value it is centred on
#: (:meth:`ParamSpec.around`); the typed field takes anything beyond.
SLIDER_DECADES = 1


@dataclass(frozen=True)
class ParamSpec:
    """How one parameter is shown: a field that takes typed values, and maybe a slider.

    The field takes any value and hands it to the core, which accepts or refuses it; the
    slider only offers convenient values between ``minimum`` and ``maximum``: linearly in
    ``step`` increments, or, with ``per_decade > 0``, on a logarithmic scale of that many
    positions per decade (values rounded to three significant figures). ``optional``
    parameters may be ``None``, typed as an empty field or ``empty_text`` and sitting at
    slider position 0. ``structures`` lists where the parameter applies.
    """

    name: str
    label: str
    unit: str
    minimum: float
    maximum: float
    step: float = 0.0
    per_decade: int = 0
    structures: tuple[str, ...] = STRUCTURES
    integer: bool = False
    optional: bool = False
    empty_text: str = "auto"
    slider: bool = True
    tooltip: str = ""
    #: The field shows value / scale in ``unit`` (frequency: Hz shown in GHz, scale 1e9).
    scale: float = 1.0
    #: The slider spans :data:`SLIDER_DECADES` each side of the value, not the whole
    #: range (lengths, the angle step: :meth:`around`).
    follows_value: bool = False

    @property
    def log_scale(self) -> bool:
        return self.per_decade > 0

    @property
    def _offset(self) -> int:
        return 1 if self.optional else 0

    @property
    def slider_max(self) -> int:
        if self.log_scale:
            decades = math.log10(self.maximum / self.minimum)
            return self._offset + math.ceil(self.per_decade * decades - 1e-9)
        return self._offset + int(round((self.maximum - self.minimum) / self.step))

    def to_slider(self, value: Any) -> int:
        """Slider position of ``value`` (nearest; clamped to the slider's range)."""
        if value is None or isinstance(value, str):
            return 0
        try:
            value = float(value)
        except (TypeError, ValueError, OverflowError):
            return 0
        if not math.isfinite(value):
            return self.slider_max if value > 0 else 0
        if value >= self.maximum:
            return self.slider_max
        if self.log_scale:
            if value <= 0:
                return 0
            pos = self._offset + int(round(self.per_decade * math.log10(value / self.minimum)))
        else:
            pos = self._offset + int(round((value - self.minimum) / self.step))
        return max(0, min(self.slider_max, pos))

    def from_slider(self, pos: int) -> float | int | None:
        """Value at slider position ``pos``."""
        if self.optional and pos <= 0:
            return None
        if pos >= self.slider_max:
            value = self.maximum
        elif self.log_scale:
            value = self.minimum * 10 ** ((pos - self._offset) / self.per_decade)
            value = float(f"{value:.3g}")
        else:
            value = round(self.minimum + (pos - self._offset) * self.step, 10)
        return int(round(value)) if self.integer else float(value)

    @property
    def windowed(self) -> bool:
        """Whether the slider shows a window around the value rather than the whole range
        (a logarithmic scale over more than ``2 * SLIDER_DECADES`` decades)."""
        return (
            self.follows_value
            and self.slider
            and self.log_scale
            and self.maximum > self.minimum * 10 ** (2 * SLIDER_DECADES) * (1 + 1e-9)
        )

    def around(self, value: Any) -> ParamSpec:
        """The slider's spec centred on ``value``: :data:`SLIDER_DECADES` each side.

        Within ``minimum`` … ``maximum`` (at an end the window keeps its width, shifted
        inwards). Itself when not :attr:`windowed` or ``value`` is not a positive number.

        >>> spec = SPECS["patch_size"]
        >>> w = spec.around(10.0)
        >>> w.minimum, w.maximum, w.from_slider(w.to_slider(10.0)), w.slider_max
        (1.0, 100.0, 10.0, 96)
        >>> spec.around(0.02).minimum, spec.around(0.02).maximum
        (0.01, 1.0)
        """
        if not self.windowed or isinstance(value, (str, bool)) or value is None:
            return self
        try:
            centre = float(value)
        except (TypeError, ValueError, OverflowError):
            return self
        if not math.isfinite(centre) or centre <= 0:
            return self
        factor = 10.0**SLIDER_DECADES
        lo, hi = centre / factor, centre * factor
        if lo < self.minimum:
            lo, hi = self.minimum, self.minimum * factor**2
        elif hi > self.maximum:
            lo, hi = self.maximum / factor**2, self.maximum
        return replace(self, minimum=lo, maximum=hi)

    def holds(self, value: Any) -> bool:
        """Whether ``value`` is a number on this spec's slider (``minimum`` … ``maximum``)."""
        try:
            v = float(value)
        except (TypeError, ValueError, OverflowError):
            return False
        return self.minimum * (1 - 1e-9) <= v <= self.maximum * (1 + 1e-9)

    def applies(self, structure: str) -> bool:
        return structure in self.structures


#: Lengths span what the presets use (0.5 mm split-ring tracks to Makarov's 1000 mm plate)
#: with room on both sides, so their sliders are logarithmic.
class _Scale(TypedDict):
    unit: str
    minimum: float
    maximum: float
    per_decade: int
    follows_value: bool


_LENGTH: _Scale = {
    "unit": "mm",
    "minimum": 0.01,
    "maximum": 10_000.0,
    "per_decade": 48,
    "follows_value": True,
}

PARAM_SPECS = (
    ParamSpec(
        "inner_radius",
        "Inner radius",
        structures=RING_STRUCTURES,
        **_LENGTH,
        tooltip="Radius of the (inner) ring; half side of the inner square ring",
    ),
    ParamSpec(
        "outer_radius",
        "Outer radius",
        structures=DOUBLE_STRUCTURES,
        **_LENGTH,
        tooltip="Radius of the outer ring of a double ring",
    ),
    ParamSpec(
        "patch_size",
        "Patch size",
        **_LENGTH,
        tooltip="Side of a square patch, and width of a ring's track",
    ),
    ParamSpec(
        "angle_step",
        "Angle step",
        "°",
        0.001,
        360.0,
        per_decade=48,
        structures=ANGULAR_STRUCTURES,
        follows_value=True,
        tooltip="Angle between neighbouring patches (paper) or the widest sector "
        "(conforming), in (0, 360]",
    ),
    ParamSpec(
        "subdivisions",
        "Subdivisions n",
        "",
        1,
        MAX_UNIFORM_SUBDIVISIONS,
        1,
        integer=True,
        tooltip="Segments per primary-triangle edge: n² sub-triangles each (uniform), "
        "or barycentric levels",
    ),
    ParamSpec(
        "gap_width",
        "Gap width",
        structures=SPLIT_STRUCTURES,
        **_LENGTH,
        tooltip="Width of the slots cut through split rings",
    ),
    ParamSpec(
        "gap_angle",
        "Gap angle",
        "°",
        -180.0,
        180.0,
        1.0,
        structures=SPLIT_STRUCTURES,
        tooltip="Direction of the slots' centre line, degrees from +x",
    ),
    ParamSpec(
        "tolerance",
        "Tolerance ε",
        "mm",
        1e-9,
        1e-1,
        per_decade=4,
        optional=True,
        tooltip="Welding distance: vertices closer than ε are one vertex (the paper's "
        "metric constraint). auto (empty) = 1e-9 of the structure's size",
    ),
    ParamSpec(
        "frequency",
        "Frequency",
        "GHz",
        0.0,
        math.inf,
        optional=True,
        empty_text="off",
        slider=False,
        scale=1e9,
        tooltip="Size the mesh for this frequency: the smallest subdivisions whose edges "
        "are all at most λ / cells per wavelength; off (empty) = subdivisions n",
    ),
)
#: The Advanced group: rarely changed parameters.
ADVANCED_SPECS = (
    ParamSpec(
        "patch_width",
        "Patch height w",
        optional=True,
        empty_text="square",
        structures=NOT_TRIANGLE,
        **_LENGTH,
        tooltip="Height of a rectangular patch; square (empty) = the patch size. For a "
        "cross, the width of its arms (empty: a third of its length)",
    ),
    ParamSpec(
        "max_triangles",
        "Triangle budget",
        "",
        1,
        1e9,
        integer=True,
        slider=False,
        tooltip="Meshes predicted above this many triangles are refused before they are built",
    ),
    ParamSpec(
        "cells_per_wavelength",
        "Cells per λ",
        "",
        1.0,
        math.inf,
        slider=False,
        tooltip="With a frequency: edges at most λ / this (10 is the common rule, "
        "Feko's standard 12)",
    ),
    ParamSpec(
        "relative_permittivity",
        "Permittivity εr",
        "",
        1.0,
        math.inf,
        slider=False,
        tooltip="With a frequency: the wavelength in a medium of this εr, λ = c0 / (f √εr)",
    ),
    ParamSpec(
        "max_edge",
        "Largest edge",
        "mm",
        0.0,
        math.inf,
        optional=True,
        empty_text="off",
        slider=False,
        tooltip="The smallest subdivisions whose edges are all at most this; with a "
        "frequency too, the stricter of the two; off (empty) = no limit",
    ),
)
SPECS = {s.name: s for s in PARAM_SPECS + ADVANCED_SPECS}
#: Choice parameters: name -> (label, {value: title}).
CHOICES: dict[str, tuple[str, dict[Any, str]]] = {
    "structure": ("Structure", STRUCTURE_TITLES),
    "mode": ("Mode", MODE_TITLES),
    "diagonal": ("Diagonal", {"BC": "BC (paper)", "AD": "AD (Makarov)"}),
    "scheme": ("Scheme", {"uniform": "Uniform n × n", "barycentric": "Barycentric levels"}),
    "grading": (
        "Grading",
        {False: "Even nodes (the paper's)", True: "Graded toward the metal edges"},
    ),
}
CHOICE_STRUCTURES = {"diagonal": NOT_TRIANGLE}
#: Parameters typed as coordinates in the Advanced group: name -> (label, structures).
POINT_PARAMS = {
    "origin": ("Origin x, y", STRUCTURES),
    "triangle_vertices": ("Triangle A; B; C", ("triangle",)),
}


def applies(name: str, structure: str) -> bool:
    """Whether parameter ``name`` has an effect on ``structure``."""
    if name in SPECS:
        return SPECS[name].applies(structure)
    if name in POINT_PARAMS:
        return structure in POINT_PARAMS[name][1]
    return structure in CHOICE_STRUCTURES.get(name, STRUCTURES)


def subdivisions_limit(scheme: str) -> int:
    return MAX_UNIFORM_SUBDIVISIONS if scheme == "uniform" else MAX_BARYCENTRIC_LEVELS


def carried_subdivisions(n: Any, old_scheme: str, new_scheme: str) -> Any:
    """The subdivisions of ``new_scheme`` closest to ``n`` of ``old_scheme`` in triangles.

    Uniform n makes n² sub-triangles per primary triangle, barycentric L levels 6^L; the
    result is the one whose count is nearest on a log scale, within the new scheme's range.
    Anything but a valid integer comes back unchanged (the core refuses it).

    >>> carried_subdivisions(16, "uniform", "barycentric"), carried_subdivisions(3, "barycentric", "uniform")
    (3, 15)
    """  # noqa: E501
    if old_scheme == new_scheme or isinstance(n, bool) or not isinstance(n, int):
        return n
    if not 1 <= n <= subdivisions_limit(old_scheme):
        return n
    log_count = 2 * math.log(n) if old_scheme == "uniform" else n * math.log(6)
    if new_scheme == "uniform":
        best = round(math.exp(log_count / 2))
    else:
        best = round(log_count / math.log(6))
    return max(1, min(subdivisions_limit(new_scheme), best))


def named_parameter(message: str) -> str | None:
    """The first parameter a core error message names as ``name=value``."""
    for match in re.finditer(r"\b(\w+)=", message):
        if match.group(1) in MeshParams.__dataclass_fields__:
            return match.group(1)
    return None


def carry_note(n: int, m: int, old_scheme: str, new_scheme: str) -> str:
    def what(k: int, scheme: str) -> str:
        if scheme == "uniform":
            return f"n = {k} ({k * k} sub-triangles per primary triangle)"
        return f"{k} barycentric level{'s' if k > 1 else ''} ({6**k} sub-triangles)"

    return f"{new_scheme} scheme: {what(n, old_scheme)} carried over as {what(m, new_scheme)}"
