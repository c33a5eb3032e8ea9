"""The unit-cell document: a lattice, placed elements and an optional pixel grid.

A unit cell is the parallelogram ``{s a1 + t a2 : -1/2 <= s, t <= 1/2}``
centred on the origin; it repeats by the lattice vectors ``a1`` and ``a2``.
Every element is one structure of :class:`barymesh.params.MeshParams`, built in
its own frame, turned by ``rotation`` degrees about its local point (0, 0)
and moved by ``position``. The pixel grid is a rows x columns mask of square
metal pixels whose lower-left corner is ``origin``; row 0 is the bottom row
(smallest y), column 0 the left one::

    row 2   . # .          mask[i, j]: pixel of row i (y), column j (x)
    row 1   # # #          the square [x0 + j p, x0 + (j + 1) p]
    row 0   . # .                   x [y0 + i p, y0 + (i + 1) p]
          col 0 1 2

All lengths are in mm and angles in degrees.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from ..params import (
    MAX_COORDINATE,
    MIN_EDGE,
    MIN_RELATIVE_EDGE,
    MIN_RELATIVE_TOLERANCE,
    MODES,
    RELATIVE_TOLERANCE,
    MeshParams,
)
from ..values import InvalidValue, echo, number, pair, positive

#: Largest |rotation| (degrees) of an element; beyond it float64 cannot place the turn.
MAX_ROTATION = 1e6
#: Symmetries the pixel helpers know (a painter's modes).
SYMMETRIES = ("none", "mirror_x", "mirror_y", "4-fold", "8-fold")


def _vector(name: str, value: Any) -> tuple[float, float]:
    return pair(name, value)


def _positive(name: str, value: Any) -> float:
    return positive(name, value)


@dataclass(frozen=True)
class Lattice:
    """Two lattice vectors (mm): the cell repeats by ``i a1 + j a2``.

    Examples
    --------
    >>> Lattice.rectangular(20.0, 10.0).kind, Lattice.hexagonal(12.0).kind
    ('rectangular', 'hexagonal')
    >>> round(Lattice.hexagonal(2.0).area, 6)
    3.464102
    """

    a1: tuple[float, float] = (20.0, 0.0)
    a2: tuple[float, float] = (0.0, 20.0)

    def __post_init__(self) -> None:
        a1, a2 = _vector("a1", self.a1), _vector("a2", self.a2)
        object.__setattr__(self, "a1", a1)
        object.__setattr__(self, "a2", a2)
        for vname, vec in (("a1", a1), ("a2", a2)):
            length = math.hypot(*vec)
            if not MIN_EDGE <= length <= MAX_COORDINATE:
                raise InvalidValue(
                    vname,
                    f"{vname}={vec!r} is {length:.3g} mm long; expected a lattice vector "
                    f"between {MIN_EDGE:.0e} and {MAX_COORDINATE:.0e} mm",
                )
        cross = a1[0] * a2[1] - a1[1] * a2[0]
        if abs(cross) <= 1e-12 * math.hypot(*a1) * math.hypot(*a2) or cross == 0:
            raise InvalidValue(
                "a1",
                f"a1={a1!r} and a2={a2!r} are parallel (or zero); a lattice needs two "
                "independent vectors",
            )

    @classmethod
    def rectangular(cls, px: float, py: float | None = None) -> Lattice:
        """Periods ``px`` along x and ``py`` along y (square when ``py`` is None)."""
        px = _positive("px", px)
        py = px if py is None else _positive("py", py)
        return cls((px, 0.0), (0.0, py))

    @classmethod
    def hexagonal(cls, a: float) -> Lattice:
        """Hexagonal lattice of spacing ``a``: a1 = (a, 0), a2 = (a/2, a √3/2)."""
        a = _positive("a", a)
        return cls((a, 0.0), (a / 2, a * math.sqrt(3) / 2))

    @property
    def matrix(self) -> np.ndarray:
        """(2, 2) float64 with the lattice vectors as columns."""
        return np.array([self.a1, self.a2], dtype=np.float64).T

    @property
    def area(self) -> float:
        """Area of the cell (mm²)."""
        return abs(self.a1[0] * self.a2[1] - self.a1[1] * self.a2[0])

    @property
    def kind(self) -> str:
        """``"rectangular"``, ``"hexagonal"`` or ``"oblique"``."""
        if self.a1[1] == 0.0 and self.a2[0] == 0.0 and self.a1[0] > 0 and self.a2[1] > 0:
            return "rectangular"
        a = self.a1[0]
        if self.a1[1] == 0.0 and a > 0 and self == Lattice.hexagonal(a):
            return "hexagonal"
        return "oblique"

    @property
    def size(self) -> float:
        """Length of the longer lattice vector (mm)."""
        return max(math.hypot(*self.a1), math.hypot(*self.a2))

    def corners(self) -> np.ndarray:
        """(4, 2) float64 corners of the cell, counter-clockwise from (-a1 - a2)/2."""
        s = np.array([[-0.5, -0.5], [0.5, -0.5], [0.5, 0.5], [-0.5, 0.5]])
        if self.a1[0] * self.a2[1] - self.a1[1] * self.a2[0] < 0:
            s = s[::-1]
        return s @ self.matrix.T

    def fractional(self, xy: np.ndarray) -> np.ndarray:
        """(N, 2) lattice coordinates (s, t) of points ``xy`` (N, 2): xy = s a1 + t a2."""
        return np.linalg.solve(self.matrix, np.asarray(xy, dtype=np.float64)[:, :2].T).T


@dataclass(frozen=True)
class Element:
    """One structure placed in the cell.

    Parameters
    ----------
    params : MeshParams
        The structure, in its own frame (a ring centred on ``params.origin``).
    position : (x, y)
        Translation applied after the rotation (mm).
    rotation : float
        Counter-clockwise turn about the local point (0, 0), in degrees.
    name : str
        A label, unique in the cell (errors and statistics use it).
    """

    params: MeshParams = field(default_factory=MeshParams)
    position: tuple[float, float] = (0.0, 0.0)
    rotation: float = 0.0
    name: str = "element"

    def __post_init__(self) -> None:
        if not isinstance(self.params, MeshParams):
            raise TypeError(f"params must be a MeshParams, got {echo(self.params)}")
        object.__setattr__(self, "position", _vector("position", self.position))
        rot = number("rotation", self.rotation, "an angle in degrees")
        if not (math.isfinite(rot) and abs(rot) <= MAX_ROTATION):
            raise InvalidValue(
                "rotation",
                f"rotation={echo(self.rotation)} is invalid; expected a finite angle within "
                f"+-{MAX_ROTATION:.0e} degrees",
            )
        object.__setattr__(self, "rotation", rot)
        if not isinstance(self.name, str) or not self.name.strip():
            raise InvalidValue(
                "name", f"name={echo(self.name)} is invalid; expected a non-empty string"
            )

    def place(self, xy: np.ndarray) -> np.ndarray:
        """(N, 2) points ``xy`` (N, 2) of the local frame, rotated then translated."""
        xy = np.asarray(xy, dtype=np.float64)
        c, s = math.cos(math.radians(self.rotation)), math.sin(math.radians(self.rotation))
        if self.rotation % 90.0 == 0.0:  # exact quarter turns: no rounding noise
            c, s = round(c), round(s)
        out = np.empty((len(xy), 2))
        out[:, 0] = c * xy[:, 0] - s * xy[:, 1] + self.position[0]
        out[:, 1] = s * xy[:, 0] + c * xy[:, 1] + self.position[1]
        return out


@dataclass(frozen=True, eq=False)
class PixelGrid:
    """A rows x columns mask of square metal pixels (a coding metasurface).

    Parameters
    ----------
    mask : (R, C) bool
        ``mask[i, j]`` is the pixel of row i (from the bottom) and column j.
    pixel_size : float
        Side of a pixel (mm).
    origin : (x, y)
        Lower-left corner of pixel (0, 0) (mm).
    subdivisions, scheme, diagonal
        How each pixel patch is meshed, as in :class:`barymesh.params.MeshParams`
        (n = 4: 32 triangles per pixel).
    grading : bool
        Crowd each pixel's nodes toward the outline of the painted region
        (:func:`barymesh.grading.outline_sides`): a pixel side keeps its n segments, its
        nodes clustered toward the ends where the outline runs across it; sides inside
        the metal away from the outline stay even. Pixels that continue across the
        cell's sides into the next cell (a grid that spans a rectangular cell exactly)
        are not graded toward those sides. Uniform scheme only.
    """

    mask: np.ndarray
    pixel_size: float = 1.0
    origin: tuple[float, float] = (0.0, 0.0)
    subdivisions: int = 4
    scheme: str = "uniform"
    diagonal: str = "BC"
    grading: bool = False

    def __post_init__(self) -> None:
        try:
            mask = np.asarray(self.mask)
        except (TypeError, ValueError):
            raise ValueError("mask is invalid; expected rows x columns of booleans") from None
        if mask.ndim != 2 or mask.size == 0:
            raise ValueError(
                f"mask has shape {mask.shape}; expected a non-empty rows x columns array"
            )
        if mask.dtype != bool:
            if not np.isin(mask, (0, 1)).all():
                raise ValueError("mask is invalid; expected booleans (or 0 and 1) only")
            mask = mask.astype(bool)
        mask = mask.copy()
        mask.flags.writeable = False
        object.__setattr__(self, "mask", mask)
        object.__setattr__(self, "pixel_size", _positive("pixel_size", self.pixel_size))
        object.__setattr__(self, "origin", _vector("origin", self.origin))
        params = self.patch_params()  # validates subdivisions, scheme, diagonal and grading
        # as the patch has it: a whole float (10.0 in a JSON file) becomes the int 10
        object.__setattr__(self, "subdivisions", params.subdivisions)
        object.__setattr__(self, "grading", bool(self.grading))

    def __eq__(self, other: object) -> bool:
        if not isinstance(other, PixelGrid):
            return NotImplemented
        return np.array_equal(self.mask, other.mask) and (
            self.pixel_size,
            self.origin,
            self.subdivisions,
            self.scheme,
            self.diagonal,
            self.grading,
        ) == (
            other.pixel_size,
            other.origin,
            other.subdivisions,
            other.scheme,
            other.diagonal,
            other.grading,
        )

    __hash__ = None  # type: ignore[assignment]

    @property
    def shape(self) -> tuple[int, int]:
        return self.mask.shape

    def patch_params(self, origin: tuple[float, float] = (0.0, 0.0)) -> MeshParams:
        """The square patch of one pixel as :class:`MeshParams` (validates the mesh settings).

        A graded grid's pixel is a graded patch (every side graded at both ends): its
        ``min_spacing`` bounds the finest cell of any pixel from below, within the
        one-sided layers' factor (:func:`barymesh.grading.first_cell`).
        """
        return MeshParams(
            structure="patch",
            patch_size=self.pixel_size,
            subdivisions=self.subdivisions,
            scheme=self.scheme,
            diagonal=self.diagonal,
            origin=origin,
            grading=self.grading,
        )

    def pixel_origins(self) -> np.ndarray:
        """(K, 2) float64 lower-left corners of the set pixels, row by row from the bottom."""
        rows, cols = np.nonzero(self.mask)
        return np.asarray(self.origin) + self.pixel_size * np.stack([cols, rows], axis=1)

    def corner_contacts(self) -> np.ndarray:
        """(K, 2, 2) int pairs of set pixels (row, column) that meet at a corner only.

        Two diagonal neighbours touch at one point when neither of the two
        pixels completing their 2 x 2 block is set: a pinch that many MoM
        solvers treat badly.
        """
        m = self.mask
        a, b, c, d = m[:-1, :-1], m[:-1, 1:], m[1:, :-1], m[1:, 1:]
        main = np.argwhere(a & d & ~b & ~c)  # (i, j) and (i + 1, j + 1)
        anti = np.argwhere(b & c & ~a & ~d)  # (i, j + 1) and (i + 1, j)
        pairs = [np.stack([main, main + 1], axis=1), np.stack([anti + [0, 1], anti + [1, 0]], 1)]
        return np.concatenate(pairs).astype(np.int64).reshape(-1, 2, 2)

    def replaced(self, **changes: Any) -> PixelGrid:
        """A copy with some fields changed (validated again)."""
        data: dict[str, Any] = {  # the fields as they are, then the changes (validated)
            "mask": self.mask,
            "pixel_size": self.pixel_size,
            "origin": self.origin,
            "subdivisions": self.subdivisions,
            "scheme": self.scheme,
            "diagonal": self.diagonal,
            "grading": self.grading,
        }
        data.update(changes)
        return PixelGrid(**data)


def symmetrized(mask: np.ndarray, symmetry: str) -> np.ndarray:
    """(R, C) bool: ``mask`` OR its images under ``symmetry`` (one of ``SYMMETRIES``).

    ``mirror_x`` mirrors across the vertical centre line (x -> -x),
    ``mirror_y`` across the horizontal one, ``4-fold`` adds the quarter turns
    and ``8-fold`` the quarter turns and both diagonals (square masks only).

    Examples
    --------
    >>> m = np.zeros((4, 4), bool); m[0, 1] = True
    >>> int(symmetrized(m, "4-fold").sum()), int(symmetrized(m, "8-fold").sum())
    (4, 8)
    """
    m = np.asarray(mask, dtype=bool)
    if symmetry not in SYMMETRIES:
        raise InvalidValue(
            "symmetry", f"symmetry={symmetry!r} is unknown; expected one of {', '.join(SYMMETRIES)}"
        )
    if symmetry in ("4-fold", "8-fold") and m.shape[0] != m.shape[1]:
        raise InvalidValue(
            "symmetry", f"symmetry={symmetry!r} needs a square mask, got shape {m.shape}"
        )
    if symmetry == "mirror_x":
        return m | m[:, ::-1]
    if symmetry == "mirror_y":
        return m | m[::-1, :]
    if symmetry == "none":
        return m.copy()
    out = m | np.rot90(m, 1) | np.rot90(m, 2) | np.rot90(m, 3)
    if symmetry == "8-fold":
        out = out | out.T
    return out


@dataclass(frozen=True)
class UnitCell:
    """A unit cell: lattice, elements and an optional pixel grid.

    Parameters
    ----------
    lattice : Lattice
    elements : tuple of Element
        Names must be unique. Each element's ``params.mode`` is set to the
        cell's ``mode``.
    pixels : PixelGrid or None
    mode : str
        ``"paper"``: the union of all patches welded by distance (overlaps
        allowed). ``"conforming"``: overlapping elements are refused, touching
        ones must share their vertices.
    tolerance : float or None
        Welding distance between elements (mm); ``None`` is 1e-9 of the
        lattice size.
    name, description : str
    """

    lattice: Lattice = field(default_factory=Lattice)
    elements: tuple[Element, ...] = ()
    pixels: PixelGrid | None = None
    mode: str = "paper"
    tolerance: float | None = None
    name: str = "cell"
    description: str = ""

    def __post_init__(self) -> None:
        if not isinstance(self.lattice, Lattice):
            raise TypeError(f"lattice must be a Lattice, got {echo(self.lattice)}")
        if not isinstance(self.mode, str) or self.mode not in MODES:
            raise InvalidValue(
                "mode", f"mode={echo(self.mode)} is unknown; expected one of {', '.join(MODES)}"
            )
        elements = tuple(self.elements)
        seen: dict[str, int] = {}
        fixed = []
        for k, el in enumerate(elements):
            if not isinstance(el, Element):
                raise TypeError(f"elements[{k}] must be an Element, got {echo(el)}")
            if el.name in seen:
                raise InvalidValue(
                    f"elements[{k}].name",
                    f"elements[{k}].name={echo(el.name)} is already the name of "
                    f"elements[{seen[el.name]}]; element names must be unique",
                )
            seen[el.name] = k
            if el.params.mode != self.mode:
                try:
                    params = el.params.replace(mode=self.mode)
                except ValueError as exc:
                    raise InvalidValue(
                        f"elements[{k}]",
                        f"elements[{k}] ({echo(el.name)}) in {self.mode} mode: {exc}",
                    ) from None
                el = Element(params, el.position, el.rotation, el.name)
            fixed.append(el)
        object.__setattr__(self, "elements", tuple(fixed))
        if self.pixels is not None and not isinstance(self.pixels, PixelGrid):
            raise TypeError(f"pixels must be a PixelGrid, got {echo(self.pixels)}")
        if not fixed and (self.pixels is None or not self.pixels.mask.any()):
            raise ValueError("the cell has no metal: add an element or set a pixel")
        if self.tolerance is not None:
            object.__setattr__(self, "tolerance", _positive("tolerance", self.tolerance))
        if not isinstance(self.name, str) or not isinstance(self.description, str):
            raise ValueError("name and description must be strings")
        self._check_float64()

    def _check_float64(self) -> None:
        """Refuse parts placed where float64 cannot resolve their edges or the weld.

        A part's coordinates reach ``|position| + sqrt(2) x`` its own extent (any
        rotation); its shortest sub-triangle edge must be at least
        ``MIN_RELATIVE_EDGE`` of that, or corners round onto each other (a patch
        at x = 1e16 mm has triangles that repeat a vertex), and the welding
        tolerance at least ``MIN_RELATIVE_TOLERANCE`` of it, or shared points stay apart.
        """
        tol = self.weld_tolerance
        for where, shift, reach, edge in self._part_reaches():
            if not edge >= MIN_RELATIVE_EDGE * reach:
                far = edge / MIN_RELATIVE_EDGE
                name = where.rsplit(".", 1)[-1]  # the caller names the whole path
                raise InvalidValue(
                    where,
                    f"{name}={echo(shift)} puts metal {reach:.3g} mm from the cell's centre, too "
                    f"far for float64 to resolve its {edge:.3g} mm sub-triangle edges; keep it "
                    f"within {far:.3g} mm",
                )
            if not tol >= MIN_RELATIVE_TOLERANCE * reach:
                name = "tolerance" if self.tolerance is not None else where
                value = self.tolerance if self.tolerance is not None else shift
                raise InvalidValue(
                    name,
                    f"{name}={echo(value)}: float64 rounds metal {reach:.3g} mm from the "
                    f"cell's centre by more than the welding tolerance {tol:.3g} mm; expected "
                    f"the part within {tol / MIN_RELATIVE_TOLERANCE:.3g} mm of the centre, or a "
                    f"tolerance of at least {MIN_RELATIVE_TOLERANCE * reach:.3g} mm",
                )

    def _part_reaches(self) -> list[tuple[str, tuple[float, float], float, float]]:
        """(field, its value, largest coordinate in mm, shortest edge in mm) of every part."""
        out = []
        for k, el in enumerate(self.elements):
            shift = max(abs(el.position[0]), abs(el.position[1]))
            reach = shift + math.sqrt(2) * el.params.extent
            out.append((f"elements[{k}].position", el.position, reach, el.params.min_spacing))
        if self.pixels is not None:
            g = self.pixels
            shift = max(abs(g.origin[0]), abs(g.origin[1]))
            reach = shift + g.pixel_size * max(g.shape)
            out.append(("pixels.origin", g.origin, reach, g.patch_params().min_spacing))
        return out

    def predicted_triangles(self) -> int:
        """Triangles of the cell's mesh, computed without building it (the parts' sum).

        An element that chooses its own subdivisions (``max_edge`` or ``frequency``)
        counts with the smallest n sizing may choose (1, or a graded patch's accuracy
        default: :func:`barymesh.sizing.accuracy_floor`), a lower bound (its own
        ``max_triangles`` bounds the rest).
        """
        from ..sizing import accuracy_floor

        total = sum(
            (
                el.params.replace(subdivisions=accuracy_floor(el.params))
                if el.params.sized
                else el.params
            ).predicted_triangles()
            for el in self.elements
        )
        if self.pixels is not None:
            per = self.pixels.patch_params().predicted_triangles()
            total += int(self.pixels.mask.sum()) * per
        return total

    @property
    def weld_tolerance(self) -> float:
        """Welding distance between parts (mm)."""
        if self.tolerance is not None:
            return self.tolerance
        return RELATIVE_TOLERANCE * self.lattice.size

    @property
    def part_names(self) -> tuple[str, ...]:
        """Names of the parts: the elements, then ``"pixels"`` when there is a grid."""
        names = tuple(el.name for el in self.elements)
        return names + (("pixels",) if self.pixels is not None else ())

    def replace(self, **changes: Any) -> UnitCell:
        """A copy with some fields changed (validated again)."""
        data: dict[str, Any] = {  # the fields as they are, then the changes (validated)
            "lattice": self.lattice,
            "elements": self.elements,
            "pixels": self.pixels,
            "mode": self.mode,
            "tolerance": self.tolerance,
            "name": self.name,
            "description": self.description,
        }
        data.update(changes)
        return UnitCell(**data)
