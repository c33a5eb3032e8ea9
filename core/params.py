"""Mesh parameters: one frozen dataclass, validated at construction.

Every length is in millimetres and every angle in degrees. The names are the
ones the sliders, the preset files and the command line use.
"""

from __future__ import annotations

import dataclasses
import math
import numbers
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from .constants import wavelength
from .grading import edge_nodes, first_cell
from .kinds import (
    ANGULAR_STRUCTURES,
    DOUBLE_STRUCTURES,
    PATCH_STRUCTURES,
    SPLIT_STRUCTURES,
    STRUCTURES,
)
from .placement import predicted_triangles
from .sectors import (
    MAX_SECTOR_DEG,
    count_steps,
    graded_track_nodes,
    narrowest_sector,
    sector_plan,
    slot_half_angle,
)
from .subdivision import closest_vertices, edge_vectors
from .topology import INDEX
from .values import InvalidValue, expected_names
from .values import echo as _short
from .values import finite as _finite
from .values import number as _float
from .values import positive as _positive

MODES = ("paper", "conforming")
DIAGONALS = ("BC", "AD")
SCHEMES = ("uniform", "barycentric")

MAX_UNIFORM_SUBDIVISIONS = 64
#: Most cells across a graded track (grading from min_edge adds cells at both circles).
MAX_GRADED_CELLS = 256
MAX_BARYCENTRIC_LEVELS = 6
DEFAULT_MAX_TRIANGLES = 5_000_000
#: Largest triangle budget, 715,827,882: vertices, triangles and edges are numbered in int32
#: (:data:`barymesh.topology.INDEX`) and a mesh holds up to three of each per triangle
#: (corners, half-edges, unwelded vertices), so no larger mesh can be indexed. Any integer
#: was taken before: 10**400 let a 320-million-triangle ring through every count to the
#: build, which allocated until MemoryError (issue 30's seventh fuzz run).
MAX_BUDGET = int(np.iinfo(INDEX).max) // 3
#: Default welding tolerance, relative to the structure's size.
RELATIVE_TOLERANCE = 1e-9
#: Largest coordinate (mm) of a structure: fourth powers of lengths (quality measures) stay finite.
MAX_COORDINATE = 1e70
#: Shortest sub-triangle edge (mm): fourth powers of edges stay normal float64 numbers.
MIN_EDGE = 1e-70
#: Shortest sub-triangle edge relative to the largest coordinate: float64 resolves the
#: corners of every triangle (1e-16 relative rounding) and the default tolerance
#: (1e-9 of the size) stays below half the edge.
MIN_RELATIVE_EDGE = 1e-8
#: Smallest welding tolerance relative to the largest coordinate: below it, rounding of
#: the coordinates would keep shared points apart.
MIN_RELATIVE_TOLERANCE = 1e-12
#: Largest |gap_angle| (degrees); beyond it float64 cannot place the slot.
MAX_GAP_ANGLE = 1e6
#: More patches than this is beyond any budget; counted without rounding to an integer.
MAX_PATCH_COUNT = 1e15
#: Subdivisions when none is given.
DEFAULT_SUBDIVISIONS = 4
#: Subdivisions of a graded patch (or strip, or triangle) when none is given: 736 RWG
#: unknowns for a patch, within 0.005 in |R| and 0.5° of converged references from 5 to
#: 35 GHz at 0°, 30° and 60° (``benchmarks/convergence.py``).
GRADED_SUBDIVISIONS = 16
#: The same for a graded cross (five patches of n x n cells: 640 triangles at n = 8).
GRADED_CROSS_SUBDIVISIONS = 8
#: Structures that are one graded patch or triangle (the accuracy default above).
SINGLE_STRUCTURES = ("patch", "triangle")
#: Arm width of a cross without ``patch_width``, as a fraction of its length.
CROSS_WIDTH = 1.0 / 3.0


def default_subdivisions(structure: Any, grading: bool) -> int:
    """The subdivisions a structure gets when none is given.

    ``GRADED_SUBDIVISIONS`` for a graded patch or triangle and ``GRADED_CROSS_SUBDIVISIONS``
    for a graded cross (their accuracy defaults), else ``DEFAULT_SUBDIVISIONS`` (rings keep
    it graded: they are many patches or sectors).

    >>> default_subdivisions("patch", True), default_subdivisions("patch", False)
    (16, 4)
    """
    if grading and structure in SINGLE_STRUCTURES:
        return GRADED_SUBDIVISIONS
    if grading and structure == "cross":
        return GRADED_CROSS_SUBDIVISIONS
    return DEFAULT_SUBDIVISIONS


def budget_too_large(budget: int) -> str:
    """The refusal of a triangle budget above :data:`MAX_BUDGET` (shared with the cell build).

    The budget is refused itself, whatever the structure: a budget past what int32
    indices number can only have been meant as "no limit", and then every count up to it
    (hundreds of millions of triangles, tens of GB) would reach the build and end in a
    MemoryError instead of a refusal naming the parameter.

    >>> for part in budget_too_large(2**31).split("; "):
    ...     print(part)
    max_triangles=2147483648 is above 715,827,882, the most triangles int32 indices can number
    expected an integer from 1 to 715,827,882
    """
    return (
        f"max_triangles={_short(budget)} is above {MAX_BUDGET:,}, the most triangles int32 "
        f"indices can number; expected an integer from 1 to {MAX_BUDGET:,}"
    )


def _choice(name: str, value: Any, allowed: tuple[str, ...]) -> str:
    if not isinstance(value, str) or value not in allowed:
        raise InvalidValue(
            name, f"{name}={_short(value)} is unknown; expected one of {', '.join(allowed)}"
        )
    return value


def _point(name: str, value: Any, whole: Any = None) -> tuple[float, float]:
    shown = _short(value if whole is None else whole)
    expected = "two numbers (x, y)" if whole is None else "three (x, y) points"
    try:
        x, y = value
    except (TypeError, ValueError):
        raise InvalidValue(name, f"{name}={shown} is invalid; expected {expected} in mm") from None
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
        One of ``STRUCTURES``. ``"cross"``: two arms ``patch_size`` long tip to tip and
        ``patch_width`` wide, centred on ``origin``, laid out as five patches (the centre
        square and four arms) that meet side to side, in either mode.
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
        Lower-left corner A of a patch, first vertex of a triangle (mm). For
        rings, the point their patches turn about: in paper mode each patch's
        lower-left corner is at ``origin + r (cos θ, sin θ)`` (the paper's
        placement), so the ring's centre is at ``origin + (s/2, s/2)`` with ``s``
        = ``patch_size``; conforming rings and square rings are centred on
        ``origin``.
    tolerance : float or None
        Welding distance ε (mm); ``None`` is 1e-9 of the structure's size.
    patch_width : float or None
        Height w of a rectangular patch (mm); ``None`` makes it square. For a cross, the
        width of its arms; ``None`` is a third of ``patch_size`` (five equal squares).
    triangle_vertices : tuple or None
        Three (x, y) vertices of the ``triangle`` structure (mm); ``None`` is
        an equilateral triangle of side ``patch_size`` standing on ``origin``.
    scheme : str
        ``"uniform"`` (n x n, the paper's 16 for n = 4) or ``"barycentric"``
        (centroid and edge midpoints, 6 per level).
    max_triangles : int
        Triangle budget; larger meshes are refused before they are built. At most
        :data:`MAX_BUDGET` (715,827,882), the most triangles int32 indices can number.
    max_edge : float or None
        Longest edge allowed (mm); ``None``: no limit. With it (or ``frequency``) the
        mesher chooses ``subdivisions`` itself (see *Sizing* below).
    frequency : float or None
        Frequency (Hz) the mesh is sized for; ``None``: no sizing from frequency.
    cells_per_wavelength : float
        Edges per wavelength, at least 1 (default 10: edges ≤ λ/10; Feko's standard is 12).
    relative_permittivity : float
        εr of the medium the wavelength is measured in, at least 1 (default 1.0, vacuum):
        λ = c0 / (f √εr).

    grading : bool
        Conforming circular rings (uniform scheme): refine the cells across the
        track geometrically toward both circles (the metal edges, where the
        current is singular), from ``min_edge`` up to patch_size / subdivisions.
    growth_ratio : float
        Largest ratio of neighbouring cells when grading, in (1, 2].
    min_edge : float or None
        Width (mm) of the cells at the circles (and along the arc at a slot)
        when grading, below patch_size / subdivisions; ``None`` is that uniform
        width / growth_ratio². A track too narrow for the growth to reach the
        uniform width scales all its cells down alike (ends below min_edge).

    Notes
    -----
    *Sizing.* With ``frequency`` or ``max_edge`` set, :func:`barymesh.build.build_mesh`
    picks the smallest ``subdivisions`` (within the scheme's range and ``max_triangles``)
    whose mesh has every edge at most the target, λ / ``cells_per_wavelength`` or
    ``max_edge``; with both, the smaller (stricter) of the two. The ``subdivisions``
    given is then not used, and the budget is checked against the n chosen.
    ``cells_per_wavelength`` and ``relative_permittivity`` do nothing without a
    ``frequency``.
    """

    structure: str = "double_ring"
    mode: str = "paper"
    inner_radius: float = 4.0
    outer_radius: float = 9.0
    patch_size: float = 1.0
    angle_step: float = 1.0
    subdivisions: int = None  # type: ignore[assignment]  # None: chosen in __post_init__
    diagonal: str = "BC"
    gap_width: float = 1.0
    gap_angle: float = 0.0
    origin: tuple[float, float] = (0.0, 0.0)
    tolerance: float | None = None
    patch_width: float | None = None
    triangle_vertices: tuple[tuple[float, float], ...] | None = None
    scheme: str = "uniform"
    max_triangles: int = field(default=DEFAULT_MAX_TRIANGLES)
    # sizing from frequency (core/sizing.py): validated in _check_sizing
    max_edge: float | None = None
    frequency: float | None = None
    cells_per_wavelength: float = 10.0
    relative_permittivity: float = 1.0
    grading: bool = False
    growth_ratio: float = 1.5
    min_edge: float | None = None

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
            raise InvalidValue(
                "angle_step", f"angle_step={_short(self.angle_step)} is outside (0, 360] degrees"
            )
        if self.structure in ANGULAR_STRUCTURES and 360.0 / step > MAX_PATCH_COUNT:
            raise InvalidValue(
                "angle_step",
                f"angle_step={_short(self.angle_step)} degrees is too small: it would place "
                f"more than {MAX_PATCH_COUNT:.0e} patches on a ring",
            )
        put(self, "angle_step", step)
        gap_angle = _finite("gap_angle", self.gap_angle)
        if abs(gap_angle) > MAX_GAP_ANGLE:
            raise InvalidValue(
                "gap_angle",
                f"gap_angle={_short(self.gap_angle)} is invalid; expected an angle within "
                f"+-{MAX_GAP_ANGLE:.0e} degrees",
            )
        put(self, "gap_angle", gap_angle)
        put(self, "origin", _point("origin", self.origin))
        self._check_subdivisions()
        budget = self.max_triangles
        if isinstance(budget, numbers.Integral) and not isinstance(budget, bool):
            budget = int(budget)
            put(self, "max_triangles", budget)
        if isinstance(budget, bool) or not isinstance(budget, int) or budget < 1:
            raise InvalidValue(
                "max_triangles",
                f"max_triangles={_short(budget)} is invalid; expected an integer >= 1",
            )
        if budget > MAX_BUDGET:
            raise InvalidValue("max_triangles", budget_too_large(budget))
        if self.triangle_vertices is not None:
            self._check_triangle_vertices()
        if self.tolerance is not None:  # a number before the sector plan (keyed on it) is made
            put(self, "tolerance", _positive("tolerance", self.tolerance))
        self._check_sizing()
        self._check_grading()
        self._check_geometry()
        self._check_float64()
        if self.tolerance is not None:
            tol = _positive("tolerance", self.tolerance)
            put(self, "tolerance", tol)
            limit = 0.5 * self.min_spacing
            what = "the smallest sub-triangle edge"
            if self.structure == "triangle" and self.triangle_vertices is not None:
                # an obtuse triangle has vertices closer than its shortest edge
                closest = closest_vertices(
                    self.scheme,
                    self.subdivisions,
                    self.grading is True,
                    self.triangle_vertices,
                )
                if 0.5 * closest < limit:
                    limit, what = 0.5 * closest, "the smallest distance between its vertices"
            if tol >= limit:
                raise InvalidValue(
                    "tolerance",
                    f"tolerance={_short(self.tolerance)} mm is too large: it must be below half "
                    f"{what}, {limit:.6g} mm, or it would collapse triangles",
                )
            floor = MIN_RELATIVE_TOLERANCE * self.extent
            if tol < floor:
                raise InvalidValue(
                    "tolerance",
                    f"tolerance={_short(self.tolerance)} mm is too small: float64 rounds "
                    f"coordinates of {self.extent:.6g} mm by more, so shared points would stay "
                    f"apart; expected tolerance >= {floor:.6g} mm",
                )
        elif self.structure not in ("patch", "triangle") and self.weld_tolerance < 4 * math.ulp(
            self.extent
        ):
            # the default tolerance (1e-9 of the size) within float64's rounding out there:
            # points computed from two patches may round apart by more (a paper ring at
            # y = 7e7 mm, where float64 spaces numbers 1.5e-8 mm apart, left two pairs
            # unwelded at 9.1e-9 mm); a lone patch or triangle has no points from two patches
            lengths = self._lengths()
            name = max(lengths, key=lengths.__getitem__)
            raise InvalidValue(
                name,
                f"{name}={_short(getattr(self, name))} puts metal {self.extent:.3g} mm out, where "
                f"float64 rounds by more than the default welding tolerance "
                f"{self.weld_tolerance:.3g} mm; set a tolerance of at least "
                f"{MIN_RELATIVE_TOLERANCE * self.extent:.3g} mm, or place it nearer",
            )
        self._check_slot_width()
        self._check_paper_chain()
        budget = self.max_triangles
        predicted = self.predicted_triangles()
        if predicted == 0:
            raise InvalidValue(
                "gap_width",
                f"gap_width={self.gap_width!r} mm removes every patch of the {self.structure}; "
                "the slot must leave metal on both sides: use a narrower gap or larger radii",
            )
        if predicted > budget and not self.sized:  # sized: checked at the n chosen
            graded = "a larger growth_ratio or min_edge, " if self.grading else ""
            raise ValueError(
                f"these parameters would make {predicted:,} triangles, above the budget "
                f"max_triangles={budget:,}; use {graded}a larger angle_step or patch_size, "
                "fewer subdivisions, or raise max_triangles"
            )

    # -- validation helpers -------------------------------------------------

    def _check_subdivisions(self) -> None:
        n: Any = self.subdivisions  # as given: not yet known to be an int
        if n is None:  # not given: the default, or the accuracy default of a graded patch
            n = default_subdivisions(self.structure, self.grading is True)
            object.__setattr__(self, "subdivisions", n)
        if isinstance(n, float) and n.is_integer():
            n = int(n)
            object.__setattr__(self, "subdivisions", n)
        if isinstance(n, numbers.Integral) and not isinstance(n, bool):
            n = int(n)
            object.__setattr__(self, "subdivisions", n)
        if isinstance(n, bool) or not isinstance(n, int):
            raise InvalidValue(
                "subdivisions", f"subdivisions={_short(self.subdivisions)} is not an integer"
            )
        top = MAX_UNIFORM_SUBDIVISIONS if self.scheme == "uniform" else MAX_BARYCENTRIC_LEVELS
        if not 1 <= n <= top:
            raise InvalidValue(
                "subdivisions",
                f"subdivisions={_short(n)} is outside 1..{top} for the {self.scheme} scheme",
            )

    def _check_sizing(self) -> None:
        """Check the sizing fields: max_edge, frequency, cells per wavelength, εr."""
        put = object.__setattr__

        if self.max_edge is not None:
            put(self, "max_edge", _positive("max_edge", self.max_edge))
            extent = self.extent  # beyond MAX_COORDINATE the length is refused by name later
            floor = max(MIN_EDGE, MIN_RELATIVE_EDGE * extent if extent <= MAX_COORDINATE else 0)
            if not self.max_edge >= floor:
                raise InvalidValue(
                    "max_edge",
                    f"max_edge={_short(self.max_edge)} mm is too short: float64 cannot mesh "
                    f"edges below {floor:.3g} mm at coordinates up to {self.extent:.3g} mm; "
                    f"expected max_edge >= {floor:.3g} mm",
                )
        if self.frequency is not None:
            f = _float("frequency", self.frequency, "a frequency in Hz")
            if not math.isfinite(f) or f <= 0:
                ghz = f" (= {f / 1e9:g} GHz)" if math.isfinite(f) and f else ""
                raise InvalidValue(
                    "frequency",
                    f"frequency={_short(self.frequency)} Hz{ghz} is invalid; expected a "
                    "finite frequency > 0 Hz (10e9 for 10 GHz), or none for no sizing",
                )
            put(self, "frequency", f)
        for name, what in (
            ("cells_per_wavelength", "edges per wavelength"),
            ("relative_permittivity", "a relative permittivity"),
        ):
            value = getattr(self, name)
            x = _float(name, value, f"{what} >= 1")
            if not (math.isfinite(x) and x >= 1):
                raise InvalidValue(
                    name,
                    f"{name}={_short(value)} is invalid; expected {what}: a finite number >= 1",
                )
            put(self, name, x)
        if self.frequency is not None:
            lam = wavelength(self.frequency, self.relative_permittivity)
            if not lam / self.cells_per_wavelength >= MIN_EDGE:
                raise InvalidValue(
                    "frequency",
                    f"frequency={_short(self.frequency)} Hz is too high: edges of λ/"
                    f"{self.cells_per_wavelength:g} = {lam / self.cells_per_wavelength:.3g} mm "
                    f"are below the shortest edge float64 can mesh, {MIN_EDGE:g} mm",
                )

    @property
    def track_graded(self) -> bool:
        """Graded by adding cells across the track (conforming circular rings, ``grading``).

        Every other graded structure keeps its n x n grid per primary triangle and moves
        its nodes (:mod:`barymesh.grading`).
        """
        return (
            self.grading is True
            and self.mode == "conforming"
            and self.structure in ANGULAR_STRUCTURES
        )

    @property
    def sized(self) -> bool:
        """Whether the mesher chooses ``subdivisions`` (``max_edge`` or ``frequency`` set)."""
        return self.max_edge is not None or self.frequency is not None

    def _check_grading(self) -> None:
        if not isinstance(self.grading, (bool, np.bool_)):
            raise InvalidValue(
                "grading", f"grading={_short(self.grading)} is invalid; expected true or false"
            )
        object.__setattr__(self, "grading", bool(self.grading))
        ratio = _finite("growth_ratio", self.growth_ratio)
        if not 1.0 < ratio <= 2.0:
            raise InvalidValue(
                "growth_ratio",
                f"growth_ratio={_short(self.growth_ratio)} is outside (1, 2]: neighbouring "
                "cells may differ by at most a factor of 2",
            )
        object.__setattr__(self, "growth_ratio", ratio)
        if self.min_edge is not None:
            object.__setattr__(self, "min_edge", _positive("min_edge", self.min_edge))
        if not self.grading:
            return
        if self.scheme != "uniform":
            raise InvalidValue(
                "grading",
                "grading=True needs scheme='uniform' (the n x n grid of a primary triangle, "
                "its nodes moved toward the metal edges); the barycentric scheme is not graded",
            )
        if not self.track_graded:
            if self.min_edge is not None:
                raise InvalidValue(
                    "min_edge",
                    f"min_edge={_short(self.min_edge)} mm sets the graded cells across the "
                    f"track of conforming circular rings, not the {self.mode} "
                    f"{self.structure}, whose graded nodes follow from subdivisions; leave "
                    "min_edge unset",
                )
            return
        cell = self.patch_size / self.subdivisions
        if self.min_edge is not None and not self.min_edge < cell:
            raise InvalidValue(
                "min_edge",
                f"min_edge={_short(self.min_edge)} mm is not below the uniform cell "
                f"patch_size / subdivisions = {cell:.6g} mm; expected a smaller min_edge",
            )
        # cells added at each circle: log(cell / fine) / log(ratio), 2 by default (fine =
        # cell / ratio²); in logarithms, so that neither 0 mm cells nor a min_edge far
        # below the cell (a ratio beyond float64) divide by zero or overflow
        steps = (
            2.0
            if self.min_edge is None
            else (math.log(cell) - math.log(self.min_edge)) / math.log(ratio)
        )
        cells = self.subdivisions + 2 * math.ceil(steps)
        if cells > MAX_GRADED_CELLS:
            raise InvalidValue(
                "min_edge",
                f"min_edge={_short(self.min_edge)} mm with growth_ratio={ratio!r} grades the "
                f"track into about {cells} cells across; expected at most {MAX_GRADED_CELLS}: "
                "use a larger min_edge or growth_ratio",
            )

    def _check_triangle_vertices(self) -> None:
        given: Any = self.triangle_vertices  # as given: any iterable, or not one
        try:
            items = list(given)
        except TypeError:
            items = []
        if isinstance(given, (str, bytes)) or len(items) != 3:
            raise InvalidValue(
                "triangle_vertices",
                f"triangle_vertices={_short(given)} is invalid; expected three (x, y) points in mm",
            )
        pts = tuple(_point("triangle_vertices", p, given) for p in items)
        (ax, ay), (bx, by), (cx, cy) = pts
        twice_area = (bx - ax) * (cy - ay) - (by - ay) * (cx - ax)
        sides = ((bx - ax, by - ay), (cx - bx, cy - by), (ax - cx, ay - cy))
        longest = max(x * x + y * y for x, y in sides)  # inf, never OverflowError, when huge
        # as the mesh check has it (invariants.FLAT): the area against the longest edge
        # squared, which every sub-triangle of a uniform subdivision shares
        if not 0.5 * abs(twice_area) > 1e-12 * longest:
            raise InvalidValue(
                "triangle_vertices",
                f"triangle_vertices={_short(given)} are collinear; "
                "a primary triangle needs a non-zero area",
            )
        object.__setattr__(self, "triangle_vertices", pts)

    def _check_geometry(self) -> None:
        s = self.structure
        if s == "cross" and not self.patch_height < self.patch_size * (1 - 1e-9):
            raise InvalidValue(
                "patch_width",
                f"patch_width={_short(self.patch_width)} mm leaves the cross no arms: its arms "
                f"are patch_width wide and patch_size={_short(self.patch_size)} mm long tip to "
                "tip; expected patch_width < patch_size (a square is the patch structure)",
            )
        if s in DOUBLE_STRUCTURES and self.outer_radius <= self.inner_radius:
            raise InvalidValue(
                "outer_radius",
                f"outer_radius={self.outer_radius!r} mm must be larger than "
                f"inner_radius={self.inner_radius!r} mm",
            )
        if (
            s in DOUBLE_STRUCTURES
            and self.mode == "conforming"
            and self.outer_radius < self.inner_radius + self.patch_size - 1e-12
        ):
            raise InvalidValue(
                "outer_radius",
                f"outer_radius={self.outer_radius!r} mm makes the rings overlap in conforming "
                f"mode; expected outer_radius >= inner_radius + patch_size = "
                f"{self.inner_radius + self.patch_size:g} mm",
            )
        if (
            s == "square_split_double_ring"
            and self.mode == "conforming"
            and self.outer_radius <= self.inner_radius + self.patch_size + 1e-9 * self.outer_radius
        ):
            raise InvalidValue(
                "outer_radius",
                f"outer_radius={self.outer_radius!r} mm makes the square tracks touch; conforming "
                f"square rings need a gap between them: expected outer_radius > "
                f"{self.inner_radius + self.patch_size:g} mm",
            )
        if s in SPLIT_STRUCTURES and self.gap_width >= 2 * self.inner_radius:
            raise InvalidValue(
                "gap_width",
                f"gap_width={self.gap_width!r} mm is too wide for inner_radius="
                f"{self.inner_radius!r} mm; the slot must leave metal on both sides: "
                f"expected gap_width < {2 * self.inner_radius:g} mm",
            )
        if (
            s == "square_split_double_ring"
            and self.mode == "conforming"
            and not math.isclose(self.gap_angle / 90.0, round(self.gap_angle / 90.0), abs_tol=1e-9)
        ):
            raise InvalidValue(
                "gap_angle",
                f"gap_angle={self.gap_angle!r} is not supported for conforming square rings; "
                "expected a multiple of 90 degrees (slots through the middle of the sides)",
            )

    # -- derived quantities -------------------------------------------------

    @property
    def patch_height(self) -> float:
        """Height w of a patch (mm): ``patch_width`` or the square's side; a cross's arm
        width (``patch_width`` or a third of ``patch_size``)."""
        if self.patch_width is not None:
            return self.patch_width
        return self.patch_size * CROSS_WIDTH if self.structure == "cross" else self.patch_size

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
        """The shortest sub-triangle edge of the mesh (mm), or a close lower bound."""
        return self._shortest_edge()[0]

    def _shortest_edge(self, final: bool = True) -> tuple[float, str]:
        """(shortest sub-triangle edge in mm, the parameter that makes it short).

        With ``final=False`` conforming rings are measured with the sectors
        ``angle_step`` asks for, before they are narrowed so that no triangle
        folds (which needs the float64 checks to have passed).
        """
        s = self.structure
        graded = self.grading is True and not self.track_graded
        if s == "triangle":
            d = edge_vectors(self.scheme, self.subdivisions, None, graded)
            if self.triangle_vertices is None:
                h = self.patch_size
                p0, p1, p2 = (0.0, 0.0), (h, 0.0), (h / 2, h * math.sqrt(3) / 2)
                name = "patch_size"
            else:
                p0, p1, p2 = self.triangle_vertices
                name = "triangle_vertices"
            e1 = (p1[0] - p0[0], p1[1] - p0[1])
            e2 = (p2[0] - p0[0], p2[1] - p0[1])
            x = d[:, 0] * e1[0] + d[:, 1] * e2[0]
            y = d[:, 0] * e1[1] + d[:, 1] * e2[1]
            return float(np.hypot(x, y).min()), name
        d = edge_vectors(self.scheme, self.subdivisions, self.diagonal, graded)
        # (length along u, length along v, name of the parameter that sets the shorter one)
        h, w = self.patch_size, self.patch_height
        sides = [(h, w, "patch_size" if h <= w else "patch_width")]
        if graded and (
            s == "cross" or (s == "square_split_double_ring" and self.mode == "conforming")
        ):
            # pieces graded toward one end only have the finest cells (first_cell)
            d = d * (first_cell(self.subdivisions) / edge_nodes(self.subdivisions)[1])
        if s == "cross":  # arms (L − w)/2 x w each way, and the w x w centre
            arm = (h - w) / 2
            sides = [(arm, w, "patch_width"), (w, arm, "patch_width"), (w, w, "patch_width")]
        if self.track_graded:  # graded cells: the narrowest across the track, instead of h / n
            h *= self.subdivisions * graded_track_nodes(self)[1]
            sides = [(h, w, "min_edge" if self.min_edge is not None else "patch_size")]
        if self.mode == "conforming" and s in ANGULAR_STRUCTURES:
            r = self.inner_radius
            full = (
                360.0 if s in ("ring", "double_ring") else (360.0 if s == "split_ring" else 180.0)
            )
            span = full
            if s in SPLIT_STRUCTURES:
                span -= 2 * float(slot_half_angle(self, r))
            if final:
                m = sector_plan(self).base
            else:
                m = count_steps(max(span, 1e-300), min(self.angle_step, MAX_SECTOR_DEG))
            chord = 2 * r * math.sin(math.radians(span / m) / 2)
            if final and self.track_graded:
                chord *= narrowest_sector(self)
            if s in SPLIT_STRUCTURES and span < 0.5 * full:
                name = "gap_width"
            elif r < h or self.angle_step >= MAX_SECTOR_DEG:
                name = "inner_radius"
            else:
                name = "angle_step"
            sides.append((h, chord, name))
        elif self.mode == "conforming" and s == "square_split_double_ring":
            r, g = self.inner_radius, self.gap_width
            sides.append((h, (r - g / 2) / count_steps(r - g / 2, h), "gap_width"))
            sides.append((h, 2 * r / count_steps(2 * r, h), "inner_radius"))
            if graded:  # its graded first cells make the outer ring's pieces count too
                q = self.outer_radius
                sides.append((h, (q - g / 2) / count_steps(q - g / 2, h), "gap_width"))
                sides.append((h, 2 * q / count_steps(2 * q, h), "outer_radius"))
        best = (math.inf, "patch_size")
        for a, b, name in sides:
            edge = float(np.hypot(a * d[:, 0], b * d[:, 1]).min())
            if edge < best[0]:
                best = (edge, name)
        return best

    @property
    def extent(self) -> float:
        """Largest coordinate magnitude of the structure (mm), origin included."""
        s = self.structure
        shift = max(abs(self.origin[0]), abs(self.origin[1]))
        if s == "triangle" and self.triangle_vertices is not None:
            return max(abs(v) for p in self.triangle_vertices for v in p)
        if s in ("patch", "triangle", "cross"):
            return shift + max(self.patch_size, self.patch_height)
        radius = self.outer_radius if s in DOUBLE_STRUCTURES else self.inner_radius
        return shift + radius + max(self.patch_size, self.patch_height)

    def _lengths(self) -> dict[str, float]:
        """The lengths (mm) that place the structure's points, by parameter name."""
        s = self.structure
        out = {"origin": max(abs(self.origin[0]), abs(self.origin[1]))}
        if s == "triangle" and self.triangle_vertices is not None:
            return {"triangle_vertices": self.extent}
        out["patch_size"] = self.patch_size
        if self.patch_width is not None and s != "triangle":
            out["patch_width"] = self.patch_width
        if s not in ("patch", "triangle", "cross"):
            out["inner_radius"] = self.inner_radius
        if s in DOUBLE_STRUCTURES:
            out["outer_radius"] = self.outer_radius
        return out

    def _check_float64(self) -> None:
        """Refuse lengths that float64 cannot mesh at the requested subdivision."""
        extent = self.extent
        if not extent <= MAX_COORDINATE:
            lengths = self._lengths()
            name = max(lengths, key=lengths.__getitem__)
            raise InvalidValue(
                name,
                f"{name}={_short(getattr(self, name))} places points {extent:.3g} mm from "
                f"(0, 0); expected coordinates within {MAX_COORDINATE:.0e} mm",
            )
        floor = max(MIN_EDGE, MIN_RELATIVE_EDGE * extent)
        edge, name = self._shortest_edge(final=False)
        if edge >= floor:
            edge, name = self._shortest_edge()
        if not edge >= floor:
            lengths = self._lengths()
            if lengths.get("origin", 0.0) > 0.5 * extent and edge >= MIN_EDGE:
                name = "origin"
            limit = ""
            if name == "gap_width" and self.structure == "square_split_double_ring":
                piece = self.inner_radius - self.gap_width / 2  # the shortest cut side
                widest = 2 * (self.inner_radius - piece * floor / edge)
                limit = f"; expected gap_width <= {widest:.12g} mm"
            raise InvalidValue(
                name,
                f"{name}={_short(getattr(self, name))} makes sub-triangle edges of {edge:.3g} mm "
                f"at coordinates up to {extent:.3g} mm; float64 needs edges of at least "
                f"{floor:.3g} mm there ({MIN_RELATIVE_EDGE:g} of that){limit}",
            )

    def _check_slot_width(self) -> None:
        """Refuse a conforming slot narrower than the welding tolerance allows.

        The two faces of a slot are ``gap_width`` apart; closer than the tolerance
        they would be points the metric constraint calls one vertex, yet a
        conforming slot keeps them apart (an open slot must stay open).
        """
        if self.mode != "conforming" or self.structure not in SPLIT_STRUCTURES:
            return
        tol = self.weld_tolerance
        if not self.gap_width > 2 * tol:
            source = "tolerance" if self.tolerance is not None else "the default tolerance"
            raise InvalidValue(
                "gap_width",
                f"gap_width={_short(self.gap_width)} mm is too narrow: the faces of the slot "
                f"would be within the welding tolerance ({source} {tol:.3g} mm) of each other; "
                f"expected gap_width > {2 * tol:.3g} mm (twice the tolerance)",
            )

    def _check_paper_chain(self) -> None:
        """Refuse a paper ring whose neighbouring patches are within the welding tolerance.

        Corresponding points of neighbouring patches would be welded, and so on around
        the ring: a chain of near points, which the weld refuses anyway, but only after
        finding every pair. Checked here from the angle between neighbours in O(1).
        """
        if self.mode != "paper" or self.structure not in ANGULAR_STRUCTURES:
            return
        step = self.angle_step
        k = count_steps(360.0, step)
        if k < 2:
            return
        gap = min(step, 360.0 - (k - 1) * step)
        r = self.inner_radius
        chord = 2 * r * math.sin(math.radians(gap) / 2)
        tol = self.weld_tolerance
        if chord > tol:
            return
        patches = f"neighbouring patches of the ring of radius {r:.6g} mm"
        if self.tolerance is not None:
            raise InvalidValue(
                "tolerance",
                f"tolerance={_short(self.tolerance)} mm joins a chain of near points: {patches} "
                f"are only {chord:.3g} mm apart (angle_step={_short(self.angle_step)}); "
                f"use a tolerance below {chord:.3g} mm or a larger angle_step",
            )
        raise InvalidValue(
            "inner_radius",
            f"inner_radius={_short(self.inner_radius)} mm and angle_step="
            f"{_short(self.angle_step)} put {patches} {chord:.3g} mm apart, within the "
            f"welding tolerance {tol:.3g} mm: they would be welded into a chain; use a larger "
            "inner_radius or angle_step",
        )

    @property
    def size(self) -> float:
        """Characteristic size of the structure (mm), the scale of the default tolerance."""
        s = self.structure
        if s in PATCH_STRUCTURES:
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
        return predicted_triangles(self)

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
            raise ValueError(f"parameters must be a mapping of names to values, got {_short(data)}")
        known = {f.name for f in dataclasses.fields(cls)}
        unknown = sorted((k for k in data if k not in known), key=repr)
        if unknown:
            raise ValueError(
                f"unknown parameter {_short(unknown[0])}; {expected_names(unknown[0], known)}"
            )
        # lists (JSON) become tuples in __post_init__, where they are checked
        return cls(**data)

    def replace(self, **changes: Any) -> MeshParams:
        """A copy with some fields changed (validated again)."""
        return dataclasses.replace(self, **changes)
