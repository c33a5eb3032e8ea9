"""The sector planner: how a conforming circular ring is cut into sectors.

Conforming mode cuts each ring's band [r, r + patch_size] into sectors no wider than
``angle_step`` whose vertices lie on the true circles (at most 120° wide, so a closed
ring has at least three). With the uniform scheme a sector is n cells across its track
(n = ``subdivisions``) and as many along its arc, and each ring as many sectors, as make
the cells nearly square (see :func:`_plan_sectors`), never more cells round a circle than
n per asked sector; the barycentric scheme keeps its square template per sector.

The plan is made from the parameters alone, before any mesh: validation
(:class:`barymesh.params.MeshParams`), the triangle count (:mod:`barymesh.placement`) and
the layout (:mod:`barymesh.structures`) all ask for it. This module sits below
:mod:`barymesh.params`: it reads the fields of :class:`RingFields` and imports no module
that imports the parameters.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, fields
from functools import lru_cache
from typing import Protocol, overload

import numpy as np

from .kinds import DOUBLE_STRUCTURES
from .quality import triangle_quality
from .subdivision import (
    PatchTemplate,
    graded_cell_count,
    graded_nodes,
    patch_template,
    tensor_template,
)
from .values import InvalidValue


class RingFields(Protocol):
    """The fields of :class:`barymesh.params.MeshParams` that decide the sectors (read only)."""

    @property
    def structure(self) -> str: ...
    @property
    def scheme(self) -> str: ...
    @property
    def subdivisions(self) -> int: ...
    @property
    def diagonal(self) -> str: ...
    @property
    def inner_radius(self) -> float: ...
    @property
    def outer_radius(self) -> float: ...
    @property
    def patch_size(self) -> float: ...
    @property
    def angle_step(self) -> float: ...
    @property
    def gap_width(self) -> float: ...
    @property
    def gap_angle(self) -> float: ...
    @property
    def max_triangles(self) -> int: ...
    @property
    def weld_tolerance(self) -> float: ...
    @property
    def grading(self) -> bool: ...
    @property
    def growth_ratio(self) -> float: ...
    @property
    def min_edge(self) -> float | None: ...


#: (start, end, closed): an arc of a ring, angles in degrees at the slot axis.
_Arc = tuple[float, float, bool]


@dataclass(frozen=True)
class _ArcKey:
    """The :class:`RingFields` of one set of parameters, hashable: the key of the plan cache."""

    structure: str
    scheme: str
    subdivisions: int
    diagonal: str
    inner_radius: float
    outer_radius: float
    patch_size: float
    angle_step: float
    gap_width: float
    gap_angle: float
    max_triangles: int
    weld_tolerance: float
    grading: bool
    growth_ratio: float
    min_edge: float | None


#: Widest conforming sector: a closed ring has at least three sectors, so no
#: straight chord spans half a circle.
MAX_SECTOR_DEG = 120.0
#: Template points evaluated at once when checking a split ring's sectors for folds.
_SECTOR_CHECK_POINTS = 1 << 14
#: Times a conforming arc's sectors are narrowed (by a third) before giving up (1.5**12 = 130).
_MAX_NARROWING = 12
#: Slack below which floating-point counts such as 360 / Δθ are integers.
_COUNT_SLACK = 1e-9
#: The most steps counted (an integer float64 still holds).
_MAX_STEPS = 2**62


def count_steps(span: float, step: float) -> int:
    """Steps of at most ``step`` that cover ``span`` (at least one; 360 / 1.0000000001 is 360).

    >>> count_steps(360.0, 1.0), count_steps(360.0, 7.0), count_steps(0.5, 1.0)
    (360, 52, 1)

    A ratio past 2**62 (a step of 5e-324 mm gives inf) counts as 2**62, beyond any budget.
    """
    ratio = span / step - _COUNT_SLACK
    return max(1, math.ceil(ratio)) if ratio < _MAX_STEPS else _MAX_STEPS


def ring_radii(params: RingFields) -> list[float]:
    """Inner radius of every ring (mm), the inner ring first."""
    if params.structure in DOUBLE_STRUCTURES:
        return [params.inner_radius, params.outer_radius]
    return [params.inner_radius]


def gap_directions(params: RingFields) -> list[float]:
    """Directions (degrees) of the slots from the centre: none, one, or two opposite."""
    s = params.structure
    if s == "split_ring":
        return [params.gap_angle]
    if s in ("split_double_ring", "square_split_double_ring"):
        return [params.gap_angle, params.gap_angle + 180.0]
    return []


#: The parameters that decide a conforming ring's arcs, sector counts and template.
_ARC_FIELDS = tuple(f.name for f in fields(_ArcKey))
#: Smallest angle (degrees) the conforming sectors aim at: PSSFSS meshes with a 30° minimum.
TARGET_MIN_ANGLE = 30.0
#: A coarser arc division (fewer, longer sectors) is taken when its smallest angle is
#: within this many degrees of the best one and still at the target.
_ANGLE_SLACK = 2.0


@dataclass(frozen=True)
class SectorPlan:
    """How the arcs of a conforming circular structure are cut into sectors.

    Attributes
    ----------
    arcs : tuple of (start, end, closed)
        Angular extent (degrees, at the slot axis) of the arcs of one ring.
    sectors : tuple of int
        Sectors per arc of each ring (inner ring first).
    base : int
        The sector count ``angle_step`` asks for (after any narrowing against
        folds); every ring's arc holds at most ``segments x base`` cells along
        it, so no more triangles than sectors of ``segments x segments`` cells.
    template : PatchTemplate
        The template of every sector: ``segments`` cells across the track by
        n_v along the arc (uniform scheme), or the square patch template
        (barycentric scheme).
    min_angle_floor : float or None
        The best smallest angle (degrees) any arc division of this
        construction reaches with this track width, sector bound, slot and
        triangle budget; None for the barycentric scheme and graded meshes.
    boundaries : tuple of (tuple of float or None)
        Per ring: where its sectors start and end along a slotted arc, as
        fractions of it (m + 1 increasing values), when ``grading`` narrows
        the sectors toward the slot's sides; None for evenly spaced sectors.
    """

    arcs: tuple[tuple[float, float, bool], ...]
    sectors: tuple[int, ...]
    base: int
    template: PatchTemplate
    min_angle_floor: float | None
    boundaries: tuple[tuple[float, ...] | None, ...] = ()

    def sector_bounds(self, ring: int) -> tuple[float, ...] | None:
        """The ``boundaries`` of one ring (None: evenly spaced sectors)."""
        return self.boundaries[ring] if self.boundaries else None


def arc_theta(
    lo: np.ndarray | float,
    hi: np.ndarray | float,
    ks: np.ndarray,
    v: np.ndarray,
    m: int,
    bounds: tuple[float, ...] | None,
) -> np.ndarray:
    """(K, Nv) angles (radians) of template rows v in sectors ks of an arc from lo to hi.

    ``bounds``: the sectors' ends as fractions of the arc, or None for m equal sectors.
    """
    if bounds is None:
        return np.radians(lo + (ks[:, None] + v) * (hi - lo) / m)
    t = np.asarray(bounds)
    k = ks.astype(np.intp)
    return np.radians(lo + (t[k][:, None] + v * (t[k + 1] - t[k])[:, None]) * (hi - lo))


def sector_plan(params: RingFields) -> SectorPlan:
    """The sectors and template of a conforming circular structure (cached).

    Validation, the triangle count and the layout all ask for it.
    """
    return _cached_plan(_ArcKey(**{name: getattr(params, name) for name in _ARC_FIELDS}))


def graded_track_nodes(params: RingFields) -> tuple[float, ...]:
    """Nodes across a conforming track, 0 at the inner circle and 1 at the outer.

    n uniform cells, or with ``grading`` cells from ``min_edge`` (default
    h / n / growth_ratio²) at both circles growing by ``growth_ratio`` to h / n
    (:func:`barymesh.subdivision.graded_nodes`).
    """
    n, h = params.subdivisions, params.patch_size
    if not params.grading:
        return tuple(np.arange(n + 1) / n)
    # relative to the track: 1 / (n ratio²) by default, written so that it cannot underflow
    # to 0 for tracks of a few 1e-324 mm (graded_nodes needs a first cell > 0)
    if params.min_edge is None:
        first = 1.0 / n / params.growth_ratio**2
    else:
        first = params.min_edge / h
    return graded_nodes(n, first, params.growth_ratio)


def narrowest_sector(params: RingFields) -> float:
    """The narrowest sector of a graded slotted arc against the even ones asked (<= 1)."""
    plan = sector_plan(params)
    widths = [min(np.diff(b)) * plan.base for b in plan.boundaries if b is not None]
    return min([1.0, *widths])


@lru_cache(maxsize=64)
def _cached_plan(params: _ArcKey) -> SectorPlan:
    directions = gap_directions(params)
    step = min(params.angle_step, MAX_SECTOR_DEG)
    arcs: tuple[_Arc, ...]
    if not directions:
        arcs = ((0.0, 360.0, True),)
        m = count_steps(360.0, step)
    else:
        phi = params.gap_angle
        if len(directions) == 1:
            arcs = ((phi, phi + 360.0, False),)
        else:
            arcs = ((phi, phi + 180.0, False), (phi + 180.0, phi + 360.0, False))
        widest = arcs[0][1] - arcs[0][0] - 2 * float(slot_half_angle(params, _outermost(params)))
        m = count_steps(widest, step)
    for _ in range(_MAX_NARROWING):
        plan = _plan_sectors(params, arcs, m)
        if _sectors_proper(params, arcs[0], plan):
            return plan
        total = sum(plan.sectors) * len(arcs) * len(plan.template.triangles)
        if total > params.max_triangles:
            return plan  # over the budget anyway: refused with the triangle count
        m = m + max(1, m // 2)
    if directions:
        raise InvalidValue(
            "gap_width",
            f"gap_width={params.gap_width!r} mm and angle_step={params.angle_step!r}° give no "
            "proper conforming mesh of the split ring; use a narrower gap or a smaller angle step",
        )
    raise InvalidValue(
        "inner_radius",
        f"inner_radius={params.inner_radius!r} mm and patch_size={params.patch_size!r} mm give "
        "no proper conforming mesh of the ring: its sectors fold even when narrowed; use a "
        "larger inner_radius",
    )


def rings_touch(params: RingFields) -> bool:
    """Whether the outer circle of the inner ring is the inner circle of the outer one.

    Within the welding tolerance: touching rings share that circle's vertices.
    """
    radii = ring_radii(params)
    return len(radii) == 2 and abs(radii[1] - (radii[0] + params.patch_size)) <= (
        params.weld_tolerance
    )


def _plan_sectors(params: RingFields, arcs: tuple[_Arc, ...], m: int) -> SectorPlan:
    """Choose the cells along the arc of every ring, for at least m sectors per arc.

    Uniform scheme: a sector is n (``subdivisions``) cells across its track and
    n_v along its arc, each cell cut by one diagonal. For every n_v in 1..n
    each ring (or pair of touching rings, which share a circle) takes the
    sector count m' ≥ m nearest to square cells at the geometric mean radius of
    its track, with m' n_v ≤ n m (never more triangles than n x n sectors);
    the smallest angle of the cells at the sectors' ends (where tracks are
    widest, narrowest and most skewed by a slot) ranks the choices. The
    coarsest n_v within ``_ANGLE_SLACK`` of the best that still reaches
    ``TARGET_MIN_ANGLE`` (or the best when none does) is taken.
    The barycentric scheme keeps m sectors of its square template.
    """
    radii = ring_radii(params)
    if params.scheme != "uniform":
        template = patch_template(params.scheme, params.subdivisions, params.diagonal)
        return SectorPlan(arcs, (m,) * len(radii), m, template, None)
    n, h = params.subdivisions, params.patch_size
    u_nodes = graded_track_nodes(params)
    groups = [[0, 1]] if rings_touch(params) else [[i] for i in range(len(radii))]
    arc = arcs[0]
    choices = []  # (smallest angle, n_v, sectors per ring, template)
    for nv in range(1, n + 1):
        template = tensor_template(u_nodes, tuple(np.arange(nv + 1) / nv), params.diagonal)
        cap = max(m, n * m // nv)
        sectors = [m] * len(radii)
        score = math.inf
        for group in groups:
            r_lo, r_hi = radii[group[0]], radii[group[-1]] + h
            mid = math.sqrt(r_lo * r_hi)
            span = arc[1] - arc[0]
            if not arc[2]:
                span -= 2 * float(slot_half_angle(params, mid))
            ideal = math.radians(span) * mid * n / (h * nv)
            candidates = {min(cap, max(m, c)) for c in (math.floor(ideal), math.ceil(ideal))}
            best = max(
                (min(_end_cells_min_angle(params, radii[i], arc, c, template) for i in group), -c)
                for c in candidates
            )
            for i in group:
                sectors[i] = -best[1]
            score = min(score, best[0])
        choices.append((score, nv, tuple(sectors), template))
    top = max(c[0] for c in choices)
    threshold = max(min(top, TARGET_MIN_ANGLE), top - _ANGLE_SLACK)
    good = [c for c in choices if c[0] >= threshold]
    score, nv, chosen, template = max(good, key=lambda c: c[1])
    if not params.grading:
        return SectorPlan(arcs, chosen, m, template, top)
    if arc[2]:
        return SectorPlan(arcs, chosen, m, template, None)
    # graded toward the slot's sides: the end sectors hold cells about min_edge long
    fine = params.min_edge if params.min_edge is not None else h / n / params.growth_ratio**2
    firsts: dict[int, float] = {}
    for group in groups:
        mid = math.sqrt(radii[group[0]] * (radii[group[-1]] + h))
        span = math.radians(arc[1] - arc[0] - 2 * float(slot_half_angle(params, mid)))
        first = min(1.0 / chosen[group[0]], fine * nv / (span * mid))
        for i in group:
            firsts[i] = first
    # counted before the nodes are made: a growth ratio next to 1 asks for millions
    counts = tuple(
        graded_cell_count(chosen[i], firsts[i], params.growth_ratio) for i in range(len(radii))
    )
    if sum(counts) * len(arcs) * len(template.triangles) > params.max_triangles:
        return SectorPlan(arcs, counts, m, template, None)  # refused with its triangle count
    ends = tuple(graded_nodes(chosen[i], firsts[i], params.growth_ratio) for i in range(len(radii)))
    return SectorPlan(arcs, tuple(len(b) - 1 for b in ends), m, template, None, ends)


def _end_columns(template: PatchTemplate) -> tuple[np.ndarray, np.ndarray]:
    """Triangles of the first and last column of cells along v, and the vertices they use."""
    v = template.uv[:, 1]
    first, last = np.unique(v)[[1, -2]]
    corner_v = v[template.triangles]
    ends = np.flatnonzero((corner_v.max(1) <= first) | (corner_v.min(1) >= last))
    used = np.unique(template.triangles[ends])
    return ends, used


def _end_cells_min_angle(
    params: RingFields, radius: float, arc: _Arc, m: int, template: PatchTemplate
) -> float:
    """Smallest angle (degrees) of the end cells of the sectors of one ring's arc.

    A closed ring's sectors and their columns of cells are congruent: the first
    column of one sector is measured. Along a slotted arc the sides of the
    sectors lean most next to the slot and least in the middle: the end
    columns of the first, middle and last sectors are measured.
    """
    ends, used = _end_columns(template)
    uv = template.uv[used]
    rho = radius + uv[:, 0] * params.patch_size
    start, end, closed = arc
    if closed:
        lo, hi = start, end
        sectors = np.zeros(1)
    else:
        alpha = slot_half_angle(params, rho)
        lo, hi = start + alpha, end - alpha
        sectors = np.unique([0, m // 2, m - 1]).astype(float)
    theta = np.radians(lo + (sectors[:, None] + uv[:, 1]) * (hi - lo) / m)  # (K, U)
    xy = np.stack([rho * np.cos(theta), rho * np.sin(theta)], axis=-1).reshape(-1, 2)
    local = np.searchsorted(used, template.triangles[ends])
    tri = (local[None] + (np.arange(len(sectors)) * len(used))[:, None, None]).reshape(-1, 3)
    return float(triangle_quality(xy, tri).min_angles_deg.min())


def _sectors_proper(params: RingFields, arc: _Arc, plan: SectorPlan) -> bool:
    """Whether the sectors of an arc hold only positively oriented triangles.

    ``plan.sectors[i]`` is the sector count of ring i. The template is mapped to
    polar coordinates, so a wide sector bends its sub-triangles; thin ones
    (the barycentric scheme's) fold over when the sector is too wide. A closed
    ring's sectors are congruent: one is checked. Next to a slot the inner and
    outer circles end at different angles (the slot's sides are straight), and
    the sides between sectors bend from that straight line at the slot to a
    radius in the middle of the arc, most at neither end; with a wide slot
    they fold thin sectors. Every sector is checked, or, for large templates,
    sectors spread evenly along the arc (the mesh's own invariant check
    catches a fold between them). A triangle counts as flat when its area is
    below 1e-9 of its longest edge squared.
    """
    template = plan.template
    u, v = template.uv[:, 0], template.uv[:, 1]
    a, b, c = template.triangles.T
    start, end, closed = arc
    for ring, (radius, m) in enumerate(zip(ring_radii(params), plan.sectors, strict=True)):
        if closed:
            ks = np.zeros(1)
        else:
            samples = min(m, max(3, _SECTOR_CHECK_POINTS // len(template.uv)))
            ks = np.unique(np.round(np.linspace(0, m - 1, samples)))
        rho = radius + u * params.patch_size
        lo: np.ndarray | float
        hi: np.ndarray | float
        if closed:
            lo, hi = start, end
        else:
            alpha = slot_half_angle(params, rho)
            lo, hi = start + alpha, end - alpha
        theta = arc_theta(lo, hi, ks, v, m, plan.sector_bounds(ring))  # (K, Nv)
        x, y = rho * np.cos(theta), rho * np.sin(theta)
        ab = (x[:, b] - x[:, a], y[:, b] - y[:, a])
        ac = (x[:, c] - x[:, a], y[:, c] - y[:, a])
        cross = ab[0] * ac[1] - ab[1] * ac[0]
        longest = np.maximum.reduce(
            [
                ab[0] ** 2 + ab[1] ** 2,
                ac[0] ** 2 + ac[1] ** 2,
                (ac[0] - ab[0]) ** 2 + (ac[1] - ab[1]) ** 2,
            ]
        )
        if (cross <= 2e-9 * longest).any():  # folded or flat
            return False
        if not closed and (cross <= 1e-9 * (radius + params.patch_size) ** 2).any():
            return False
    return True


def _outermost(params: RingFields) -> float:
    return max(ring_radii(params)) + params.patch_size


@overload
def slot_half_angle(params: RingFields, rho: float) -> float: ...
@overload
def slot_half_angle(params: RingFields, rho: np.ndarray) -> np.ndarray: ...
def slot_half_angle(params: RingFields, rho: np.ndarray | float) -> np.ndarray | float:
    """Angle (degrees) between the slot axis and where a slot side meets radius ρ.

    A float for a float ρ (a NumPy scalar), an array of ρ's shape for an array.
    """
    return np.degrees(np.arcsin(params.gap_width / (2 * np.asarray(rho))))
