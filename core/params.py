"""Mesh parameters: one frozen dataclass, validated at construction.

Every length is in millimetres and every angle in degrees. The names are the
ones the sliders, the preset files and the command line use.
"""

from __future__ import annotations

import dataclasses
import math
from dataclasses import dataclass, field
from typing import Any

STRUCTURES = (
    "patch",
    "triangle",
    "ring",
    "double_ring",
    "split_ring",
    "split_double_ring",
    "square_split_double_ring",
)
MODES = ("paper", "conforming")
DIAGONALS = ("BC", "AD")
SCHEMES = ("uniform", "barycentric")

#: Structures made of two concentric rings (they use ``outer_radius``).
DOUBLE_STRUCTURES = ("double_ring", "split_double_ring", "square_split_double_ring")
#: Structures cut by slots (they use ``gap_width`` and ``gap_angle``).
SPLIT_STRUCTURES = ("split_ring", "split_double_ring", "square_split_double_ring")
#: Structures laid out on circles (they use ``angle_step``).
ANGULAR_STRUCTURES = ("ring", "double_ring", "split_ring", "split_double_ring")

MAX_UNIFORM_SUBDIVISIONS = 64
MAX_BARYCENTRIC_LEVELS = 6
DEFAULT_MAX_TRIANGLES = 5_000_000
#: Default welding tolerance, relative to the structure's size.
RELATIVE_TOLERANCE = 1e-9


def _positive(name: str, value: Any) -> float:
    try:
        x = float(value)
    except (TypeError, ValueError):
        raise ValueError(
            f"{name}={value!r} is not a number; expected a positive length in mm"
        ) from None
    if not math.isfinite(x) or x <= 0:
        raise ValueError(f"{name}={value!r} is invalid; expected a finite length > 0 mm")
    return x


def _finite(name: str, value: Any) -> float:
    try:
        x = float(value)
    except (TypeError, ValueError):
        raise ValueError(f"{name}={value!r} is not a number") from None
    if not math.isfinite(x):
        raise ValueError(f"{name}={value!r} is invalid; expected a finite number")
    return x


def _choice(name: str, value: Any, allowed: tuple[str, ...]) -> str:
    if value not in allowed:
        raise ValueError(f"{name}={value!r} is unknown; expected one of {', '.join(allowed)}")
    return value


def _point(name: str, value: Any) -> tuple[float, float]:
    try:
        x, y = value
    except (TypeError, ValueError):
        raise ValueError(
            f"{name}={value!r} is invalid; expected two numbers (x, y) in mm"
        ) from None
    return (_finite(name, x), _finite(name, y))


@dataclass(frozen=True)
class MeshParams:
    """Parameters of one meshed structure (mm and degrees).

    The defaults draw the paper's Fig. 12(a): a double ring of inner radius
    4 mm and outer radius 9 mm built from 1 mm square patches every degree,
    each patch split along BC into two primary triangles subdivided 4 x 4.

    Parameters
    ----------
    structure : str
        One of ``STRUCTURES``.
    mode : str
        ``"paper"``: independent axis-aligned patches placed at
        (r cos θ, r sin θ) and welded by distance, exactly as in the paper.
        ``"conforming"``: rings cut into sectors whose vertices lie on the true
        circles, one watertight mesh.
    inner_radius, outer_radius : float
        Ring radii (mm). For square rings the half side of the inner square.
    patch_size : float
        Side of a square patch, and width of a ring's track (mm).
    angle_step : float
        Angle between neighbouring patches (paper) or the widest sector
        (conforming), in degrees, in (0, 360].
    subdivisions : int
        Segments per primary-triangle edge, 1..64 (``scheme="uniform"``), or
        the number of barycentric levels, 1..6 (``scheme="barycentric"``).
    diagonal : str
        ``"BC"`` (the paper's) or ``"AD"`` (Makarov's plate meshes).
    gap_width, gap_angle : float
        Slot width (mm) and direction of its centre line (degrees from +x).
    origin : tuple of float
        Lower-left corner A of a patch, first vertex of a triangle, centre of
        the rings (mm).
    tolerance : float or None
        Welding distance ε (mm); ``None`` is 1e-9 of the structure's size.
    patch_width : float or None
        Height w of a rectangular patch (mm); ``None`` makes it square.
    triangle_vertices : tuple or None
        Three (x, y) vertices of the ``triangle`` structure (mm); ``None`` is
        an equilateral triangle of side ``patch_size`` standing on ``origin``.
    scheme : str
        ``"uniform"`` (n x n, the paper's 16 for n = 4) or ``"barycentric"``
        (centroid and edge midpoints, 6 per level).
    max_triangles : int
        Triangle budget; larger meshes are refused before they are built.
    """

    structure: str = "double_ring"
    mode: str = "paper"
    inner_radius: float = 4.0
    outer_radius: float = 9.0
    patch_size: float = 1.0
    angle_step: float = 1.0
    subdivisions: int = 4
    diagonal: str = "BC"
    gap_width: float = 1.0
    gap_angle: float = 0.0
    origin: tuple[float, float] = (0.0, 0.0)
    tolerance: float | None = None
    patch_width: float | None = None
    triangle_vertices: tuple[tuple[float, float], ...] | None = None
    scheme: str = "uniform"
    max_triangles: int = field(default=DEFAULT_MAX_TRIANGLES)

    def __post_init__(self) -> None:
        put = object.__setattr__
        _choice("structure", self.structure, STRUCTURES)
        _choice("mode", self.mode, MODES)
        _choice("diagonal", self.diagonal, DIAGONALS)
        _choice("scheme", self.scheme, SCHEMES)
        for name in ("inner_radius", "outer_radius", "patch_size", "gap_width"):
            put(self, name, _positive(name, getattr(self, name)))
        if self.patch_width is not None:
            put(self, "patch_width", _positive("patch_width", self.patch_width))
        step = _finite("angle_step", self.angle_step)
        if not 0 < step <= 360:
            raise ValueError(f"angle_step={self.angle_step!r} is outside (0, 360] degrees")
        put(self, "angle_step", step)
        put(self, "gap_angle", _finite("gap_angle", self.gap_angle))
        put(self, "origin", _point("origin", self.origin))
        self._check_subdivisions()
        if self.triangle_vertices is not None:
            self._check_triangle_vertices()
        self._check_geometry()
        if self.tolerance is not None:
            tol = _positive("tolerance", self.tolerance)
            put(self, "tolerance", tol)
            limit = 0.5 * self.min_spacing
            if tol >= limit:
                raise ValueError(
                    f"tolerance={self.tolerance!r} mm is too large: it must be below half the "
                    f"smallest sub-triangle edge, {limit:.6g} mm, or it would collapse triangles"
                )
        budget = self.max_triangles
        if isinstance(budget, bool) or not isinstance(budget, int) or budget < 1:
            raise ValueError(f"max_triangles={budget!r} is invalid; expected an integer >= 1")
        predicted = self.predicted_triangles()
        if predicted == 0:
            raise ValueError(
                f"gap_width={self.gap_width!r} mm removes every patch of the {self.structure}; "
                "the slot must leave metal on both sides: use a narrower gap or larger radii"
            )
        if predicted > budget:
            raise ValueError(
                f"these parameters would make {predicted:,} triangles, above the budget "
                f"max_triangles={budget:,}; use a larger angle_step or patch_size, fewer "
                f"subdivisions, or raise max_triangles"
            )

    # -- validation helpers -------------------------------------------------

    def _check_subdivisions(self) -> None:
        n = self.subdivisions
        if isinstance(n, float) and n.is_integer():
            n = int(n)
            object.__setattr__(self, "subdivisions", n)
        if isinstance(n, bool) or not isinstance(n, int):
            raise ValueError(f"subdivisions={self.subdivisions!r} is not an integer")
        top = MAX_UNIFORM_SUBDIVISIONS if self.scheme == "uniform" else MAX_BARYCENTRIC_LEVELS
        if not 1 <= n <= top:
            raise ValueError(
                f"subdivisions={n!r} is outside 1..{top} for the {self.scheme} scheme"
            )

    def _check_triangle_vertices(self) -> None:
        try:
            pts = tuple(_point("triangle_vertices", p) for p in self.triangle_vertices)
        except TypeError:
            pts = ()
        if len(pts) != 3:
            raise ValueError(
                f"triangle_vertices={self.triangle_vertices!r} is invalid; "
                "expected three (x, y) points in mm"
            )
        (ax, ay), (bx, by), (cx, cy) = pts
        twice_area = (bx - ax) * (cy - ay) - (by - ay) * (cx - ax)
        scale = max(abs(v) for p in pts for v in p) or 1.0
        if abs(twice_area) <= 1e-12 * scale * scale:
            raise ValueError(
                f"triangle_vertices={self.triangle_vertices!r} are collinear; "
                "a primary triangle needs a non-zero area"
            )
        object.__setattr__(self, "triangle_vertices", pts)

    def _check_geometry(self) -> None:
        s = self.structure
        if s in DOUBLE_STRUCTURES and self.outer_radius <= self.inner_radius:
            raise ValueError(
                f"outer_radius={self.outer_radius!r} mm must be larger than "
                f"inner_radius={self.inner_radius!r} mm"
            )
        if (
            s in DOUBLE_STRUCTURES
            and self.mode == "conforming"
            and self.outer_radius < self.inner_radius + self.patch_size - 1e-12
        ):
            raise ValueError(
                f"outer_radius={self.outer_radius!r} mm makes the rings overlap in conforming "
                f"mode; expected outer_radius >= inner_radius + patch_size = "
                f"{self.inner_radius + self.patch_size:g} mm"
            )
        if (
            s == "square_split_double_ring"
            and self.mode == "conforming"
            and self.outer_radius <= self.inner_radius + self.patch_size + 1e-9 * self.outer_radius
        ):
            raise ValueError(
                f"outer_radius={self.outer_radius!r} mm makes the square tracks touch; conforming "
                f"square rings need a gap between them: expected outer_radius > "
                f"{self.inner_radius + self.patch_size:g} mm"
            )
        if s in SPLIT_STRUCTURES and self.gap_width >= 2 * self.inner_radius:
            raise ValueError(
                f"gap_width={self.gap_width!r} mm is too wide for inner_radius="
                f"{self.inner_radius!r} mm; the slot must leave metal on both sides: "
                f"expected gap_width < {2 * self.inner_radius:g} mm"
            )
        if (
            s == "square_split_double_ring"
            and self.mode == "conforming"
            and not math.isclose(self.gap_angle / 90.0, round(self.gap_angle / 90.0), abs_tol=1e-9)
        ):
            raise ValueError(
                f"gap_angle={self.gap_angle!r} is not supported for conforming square rings; "
                "expected a multiple of 90 degrees (slots through the middle of the sides)"
            )

    # -- derived quantities -------------------------------------------------

    @property
    def patch_height(self) -> float:
        """Height w of a patch (mm): ``patch_width`` or the square's side."""
        return self.patch_size if self.patch_width is None else self.patch_width

    @property
    def segments(self) -> int:
        """Segments per primary-triangle edge (n, or 2**levels)."""
        if self.scheme == "uniform":
            return self.subdivisions
        return 2**self.subdivisions

    @property
    def triangles_per_primary(self) -> int:
        """Sub-triangles of one primary triangle (n² or 6**levels)."""
        if self.scheme == "uniform":
            return self.subdivisions**2
        return 6**self.subdivisions

    @property
    def min_spacing(self) -> float:
        """A lower bound of the shortest sub-triangle edge (mm), for the tolerance check."""
        if self.structure == "triangle" and self.triangle_vertices is not None:
            pts = self.triangle_vertices
            side = min(math.dist(pts[i], pts[(i + 1) % 3]) for i in range(3))
        else:
            side = min(self.patch_size, self.patch_height)
        if self.scheme == "uniform":
            return side / self.segments
        # A barycentric level shrinks the shortest edge by at most a factor of 6.
        return side / 6**self.subdivisions

    @property
    def size(self) -> float:
        """Characteristic size of the structure (mm), the scale of the default tolerance."""
        s = self.structure
        if s == "patch":
            return max(self.patch_size, self.patch_height)
        if s == "triangle":
            if self.triangle_vertices is None:
                return self.patch_size
            pts = self.triangle_vertices
            return max(math.dist(pts[i], pts[(i + 1) % 3]) for i in range(3))
        radius = self.outer_radius if s in DOUBLE_STRUCTURES else self.inner_radius
        return 2 * (radius + self.patch_size)

    @property
    def weld_tolerance(self) -> float:
        """The welding distance ε actually used (mm)."""
        if self.tolerance is not None:
            return self.tolerance
        return RELATIVE_TOLERANCE * self.size

    def predicted_triangles(self) -> int:
        """Number of triangles the mesh will have (computed without building it)."""
        from .structures import predicted_patches

        per_patch = self.triangles_per_primary * (1 if self.structure == "triangle" else 2)
        return predicted_patches(self) * per_patch

    # -- (de)serialisation --------------------------------------------------

    def to_dict(self) -> dict[str, Any]:
        """Plain JSON-ready dict of every field."""
        d = dataclasses.asdict(self)
        d["origin"] = list(self.origin)
        if self.triangle_vertices is not None:
            d["triangle_vertices"] = [list(p) for p in self.triangle_vertices]
        return d

    @classmethod
    def from_dict(cls, data: dict[str, Any]) -> MeshParams:
        """Build from a dict such as ``to_dict`` returns; unknown keys are an error."""
        if not isinstance(data, dict):
            raise ValueError(f"parameters must be a mapping of names to values, got {data!r}")
        known = {f.name for f in dataclasses.fields(cls)}
        unknown = sorted(set(data) - known)
        if unknown:
            raise ValueError(
                f"unknown parameter {unknown[0]!r}; expected one of {', '.join(sorted(known))}"
            )
        kwargs = dict(data)
        if kwargs.get("origin") is not None and isinstance(kwargs["origin"], list):
            kwargs["origin"] = tuple(kwargs["origin"])
        if isinstance(kwargs.get("triangle_vertices"), list):
            kwargs["triangle_vertices"] = tuple(tuple(p) for p in kwargs["triangle_vertices"])
        return cls(**kwargs)

    def replace(self, **changes: Any) -> MeshParams:
        """A copy with some fields changed (validated again)."""
        return dataclasses.replace(self, **changes)
