"""Layouts of patches for every structure, in both modes.

A layout places copies of the patch template: ``xy[p, i]`` is where local
vertex i of patch p lands, and ``vertex_of_point`` says which global vertex
each of those points is (after the weld of the chosen mode).

Paper mode is the paper's Eqs. 28–35: axis-aligned patches whose lower-left
corner is (r cos θ, r sin θ) for θ = 0, Δθ, 2Δθ, … below 360°, welded by the
metric constraint. Conforming mode cuts each ring's band [r, r + patch_size]
into sectors no wider than ``angle_step`` whose vertices lie on the true
circles (at most 120° wide, so a closed ring has at least three);
neighbouring sectors are glued topologically (exactly). With the uniform
scheme a sector is n cells across its track (n = ``subdivisions``) and as
many along its arc, and each ring as many sectors, as make the cells nearly
square (see :func:`_plan_sectors`), never more cells round a circle than n per
asked sector; the barycentric scheme keeps its square template per sector.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from functools import lru_cache
from types import SimpleNamespace

import numpy as np

from .params import ANGULAR_STRUCTURES, DOUBLE_STRUCTURES, RELATIVE_TOLERANCE, MeshParams
from .quality import triangle_quality
from .repeat import sector_chain_vertices
from .subdivision import PatchTemplate, graded_nodes, patch_template, tensor_template
from .weld import merge_pairs, weld_lattice_patches, weld_points

#: Widest conforming sector: a closed ring has at least three sectors, so no
#: straight chord spans half a circle.
MAX_SECTOR_DEG = 120.0
#: Above this many patches the count is estimated from above instead of placed.
_EXACT_COUNT_LIMIT = 20_000_000
#: Template points evaluated at once when checking a split ring's sectors for folds.
_SECTOR_CHECK_POINTS = 1 << 14
#: Times a conforming arc's sectors are narrowed (by a third) before giving up (1.5**12 = 130).
_MAX_NARROWING = 12
#: Slack below which floating-point counts such as 360 / Δθ are integers.
_COUNT_SLACK = 1e-9


@dataclass(frozen=True)
class Layout:
    """Patches of one structure, ready to be assembled into a mesh.

    Attributes
    ----------
    template : PatchTemplate
    xy : (P, Nv, 2) float64
        Position of every patch-local vertex.
    regions : (P,) int
        Region of each patch (1 = the patch or the inner ring, 2 = the outer ring).
    vertex_of_point : (P * Nv,) int
        Global vertex of every patch-local vertex.
    representative : (V,) int
        One patch-local point per global vertex (its coordinates are used).
    rects : (P, 4) float64 or None
        (x0, y0, x1, y1) of each axis-aligned patch in paper mode.
    min_angle_floor : float or None
        Conforming circular rings (uniform scheme): the best smallest angle
        (degrees) their geometry allows this construction (see :class:`SectorPlan`).
    """

    template: PatchTemplate
    xy: np.ndarray
    regions: np.ndarray
    vertex_of_point: np.ndarray
    representative: np.ndarray
    rects: np.ndarray | None
    min_angle_floor: float | None = None


def _count(span: float, step: float) -> int:
    return max(1, math.ceil(span / step - _COUNT_SLACK))


def _radii(params: MeshParams) -> list[float]:
    if params.structure in DOUBLE_STRUCTURES:
        return [params.inner_radius, params.outer_radius]
    return [params.inner_radius]


def _gap_directions(params: MeshParams) -> list[float]:
    s = params.structure
    if s == "split_ring":
        return [params.gap_angle]
    if s in ("split_double_ring", "square_split_double_ring"):
        return [params.gap_angle, params.gap_angle + 180.0]
    return []


# -- paper mode ------------------------------------------------------------


def paper_ring_origins(params: MeshParams, radius: float) -> np.ndarray:
    """Lower-left corners (r cos θ, r sin θ) + centre, θ = 0, Δθ, … < 360° (Eqs. 28–29)."""
    k = _count(360.0, params.angle_step)
    theta = np.radians(np.arange(k) * params.angle_step)
    centre = np.asarray(params.origin)
    return centre + radius * np.stack([np.cos(theta), np.sin(theta)], axis=1)


def square_ring_origins(params: MeshParams, half_side: float) -> np.ndarray:
    """Lower-left corners of square patches tiling a square track (paper mode).

    The track lies between the squares of half side R and R + h. Each side's
    strip is covered by h x h patches spread evenly from end to end; they tile
    it exactly when its length is a multiple of h and overlap slightly
    otherwise, as the paper's patches do.
    """
    r, h = half_side, params.patch_size
    k_long = _count(2 * (r + h), h)
    k_short = _count(2 * r, h)
    xs = np.linspace(-r - h, r, k_long) if k_long > 1 else np.array([-r - h])
    ys = np.linspace(-r, r - h, k_short) if k_short > 1 else np.array([-r])
    bottom = np.stack([xs, np.full_like(xs, -r - h)], axis=1)
    top = np.stack([xs, np.full_like(xs, r)], axis=1)
    left = np.stack([np.full_like(ys, -r - h), ys], axis=1)
    right = np.stack([np.full_like(ys, r), ys], axis=1)
    return np.asarray(params.origin) + np.concatenate([bottom, right, top, left])


def rects_touching_slots(
    rects: np.ndarray, centre: tuple[float, float], directions: list[float], width: float
) -> np.ndarray:
    """Which axis-aligned rectangles share area with a slot (separating-axis test).

    A slot is the half-strip of the given ``width`` starting at ``centre`` and
    running in direction φ (degrees); two opposite directions make a full
    strip through the centre. Rectangles that only touch a slot's side line
    are kept.

    Parameters
    ----------
    rects : (P, 4) float64
        (x0, y0, x1, y1).
    """
    rel = rects - np.array([centre[0], centre[1], centre[0], centre[1]])
    cx = rel[:, [0, 2, 2, 0]]
    cy = rel[:, [1, 1, 3, 3]]
    eps = 1e-12 * max(1.0, float(np.abs(rel).max(initial=0.0)))
    half = width / 2
    hit = np.zeros(len(rects), dtype=bool)
    angles = [d % 360.0 for d in directions]
    full = len(angles) == 2 and math.isclose((angles[1] - angles[0]) % 360.0, 180.0, abs_tol=1e-9)
    for phi in angles[:1] if full else angles:
        c, s = math.cos(math.radians(phi)), math.sin(math.radians(phi))
        d = -s * cx + c * cy  # across the slot
        t = c * cx + s * cy  # along the slot
        ok = (d.max(1) > -half + eps) & (d.min(1) < half - eps)
        if not full:
            ok &= t.max(1) > eps
            for axis_lo, axis_hi, along, across in (
                (rel[:, 0], rel[:, 2], c, -s),
                (rel[:, 1], rel[:, 3], s, c),
            ):
                ends = (half * across, -half * across)
                lo, hi = min(ends), max(ends)
                if along > 1e-15:
                    ok &= axis_hi > lo + eps
                elif along < -1e-15:
                    ok &= axis_lo < hi - eps
                else:
                    ok &= (axis_hi > lo + eps) & (axis_lo < hi - eps)
        hit |= ok
    return hit


def _paper_origins(params: MeshParams) -> tuple[np.ndarray, np.ndarray]:
    """Patch origins and regions of a paper-mode ring structure, slots applied."""
    square = params.structure == "square_split_double_ring"
    origins, regions = [], []
    for region, radius in enumerate(_radii(params), start=1):
        o = square_ring_origins(params, radius) if square else paper_ring_origins(params, radius)
        origins.append(o)
        regions.append(np.full(len(o), region))
    origins = np.concatenate(origins)
    regions = np.concatenate(regions)
    directions = _gap_directions(params)
    if directions:
        h, w = params.patch_size, params.patch_height
        rects = np.concatenate([origins, origins + [h, w]], axis=1)
        keep = ~rects_touching_slots(rects, params.origin, directions, params.gap_width)
        origins, regions = origins[keep], regions[keep]
    return origins, regions


# -- conforming mode -------------------------------------------------------


#: The parameters that decide a conforming ring's arcs, sector counts and template.
_ARC_FIELDS = (
    "structure",
    "scheme",
    "subdivisions",
    "diagonal",
    "inner_radius",
    "outer_radius",
    "patch_size",
    "angle_step",
    "gap_width",
    "gap_angle",
    "max_triangles",
    "tolerance",
    "grading",
    "growth_ratio",
    "min_edge",
)
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


def _arc_theta(lo, hi, ks: np.ndarray, v: np.ndarray, m: int, bounds) -> np.ndarray:
    """(K, Nv) angles (radians) of template rows v in sectors ks of an arc from lo to hi.

    ``bounds``: the sectors' ends as fractions of the arc, or None for m equal sectors.
    """
    if bounds is None:
        return np.radians(lo + (ks[:, None] + v) * (hi - lo) / m)
    t = np.asarray(bounds)
    k = ks.astype(np.intp)
    return np.radians(lo + (t[k][:, None] + v * (t[k + 1] - t[k])[:, None]) * (hi - lo))


def _arcs(params: MeshParams) -> tuple[list[tuple[float, float, bool]], int]:
    """Angular extent of the arcs of one ring, and the base sector count per arc.

    Returns ``([(start, end, closed), ...], m)`` with angles in degrees at the
    slot axis; the slot sides are added per radius by :func:`_slot_half_angle`.
    Every ring's arc holds at most ``segments x m`` cells along it.
    """
    plan = sector_plan(params)
    return list(plan.arcs), plan.base


def sector_plan(params: MeshParams) -> SectorPlan:
    """The sectors and template of a conforming circular structure (cached).

    Validation, the triangle count and the layout all ask for it.
    """
    return _cached_plan(tuple(getattr(params, name) for name in _ARC_FIELDS))


def graded_track_nodes(params) -> tuple[float, ...]:
    """Nodes across a conforming track, 0 at the inner circle and 1 at the outer.

    n uniform cells, or with ``grading`` cells from ``min_edge`` (default
    h / n / growth_ratio²) at both circles growing by ``growth_ratio`` to h / n
    (:func:`barymesh.subdivision.graded_nodes`).
    """
    n, h = params.subdivisions, params.patch_size
    if not params.grading:
        return tuple(np.arange(n + 1) / n)
    fine = params.min_edge if params.min_edge is not None else h / n / params.growth_ratio**2
    return graded_nodes(n, fine / h, params.growth_ratio)


def narrowest_sector(params) -> float:
    """The narrowest sector of a graded slotted arc against the even ones asked (<= 1)."""
    plan = sector_plan(params)
    widths = [min(np.diff(b)) * plan.base for b in plan.boundaries if b is not None]
    return min([1.0, *widths])


@lru_cache(maxsize=64)
def _cached_plan(key: tuple) -> SectorPlan:
    params = SimpleNamespace(**dict(zip(_ARC_FIELDS, key, strict=True)))
    directions = _gap_directions(params)
    step = min(params.angle_step, MAX_SECTOR_DEG)
    if not directions:
        arcs = ((0.0, 360.0, True),)
        m = _count(360.0, step)
    else:
        phi = params.gap_angle
        if len(directions) == 1:
            arcs = ((phi, phi + 360.0, False),)
        else:
            arcs = ((phi, phi + 180.0, False), (phi + 180.0, phi + 360.0, False))
        widest = arcs[0][1] - arcs[0][0] - 2 * _slot_half_angle(params, _outermost(params))
        m = _count(widest, step)
    for _ in range(_MAX_NARROWING):
        plan = _plan_sectors(params, arcs, m)
        if _sectors_proper(params, arcs[0], plan):
            return plan
        total = sum(plan.sectors) * len(arcs) * len(plan.template.triangles)
        if total > params.max_triangles:
            return plan  # over the budget anyway: refused with the triangle count
        m = m + max(1, m // 2)
    if directions:
        raise ValueError(
            f"gap_width={params.gap_width!r} mm and angle_step={params.angle_step!r}° give no "
            "proper conforming mesh of the split ring; use a narrower gap or a smaller angle step"
        )
    raise ValueError(
        f"inner_radius={params.inner_radius!r} mm and patch_size={params.patch_size!r} mm give "
        "no proper conforming mesh of the ring: its sectors fold even when narrowed; use a "
        "larger inner_radius"
    )


def _touching(params) -> bool:
    radii = _radii(params)
    return len(radii) == 2 and abs(radii[1] - (radii[0] + params.patch_size)) <= (
        params.tolerance
        if params.tolerance is not None
        else RELATIVE_TOLERANCE * 2 * (radii[-1] + params.patch_size)
    )


def _plan_sectors(params, arcs: tuple, m: int) -> SectorPlan:
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
    radii = _radii(params)
    if params.scheme != "uniform":
        template = patch_template(params.scheme, params.subdivisions, params.diagonal)
        return SectorPlan(arcs, (m,) * len(radii), m, template, None)
    n, h = params.subdivisions, params.patch_size
    u_nodes = graded_track_nodes(params)
    groups = [[0, 1]] if _touching(params) else [[i] for i in range(len(radii))]
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
                span -= 2 * float(_slot_half_angle(params, mid))
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
    score, nv, sectors, template = max(good, key=lambda c: c[1])
    if not params.grading:
        return SectorPlan(arcs, sectors, m, template, top)
    if arc[2]:
        return SectorPlan(arcs, sectors, m, template, None)
    # graded toward the slot's sides: the end sectors hold cells about min_edge long
    fine = params.min_edge if params.min_edge is not None else h / n / params.growth_ratio**2
    bounds = [None] * len(radii)
    for group in groups:
        mid = math.sqrt(radii[group[0]] * (radii[group[-1]] + h))
        span = math.radians(arc[1] - arc[0] - 2 * float(_slot_half_angle(params, mid)))
        k = sectors[group[0]]
        first = min(1.0 / k, fine * nv / (span * mid))
        for i in group:
            bounds[i] = graded_nodes(k, first, params.growth_ratio)
    sectors = tuple(len(b) - 1 for b in bounds)
    return SectorPlan(arcs, sectors, m, template, None, tuple(bounds))


def _end_columns(template: PatchTemplate) -> tuple[np.ndarray, np.ndarray]:
    """Triangles of the first and last column of cells along v, and the vertices they use."""
    v = template.uv[:, 1]
    first, last = np.unique(v)[[1, -2]]
    corner_v = v[template.triangles]
    ends = np.flatnonzero((corner_v.max(1) <= first) | (corner_v.min(1) >= last))
    used = np.unique(template.triangles[ends])
    return ends, used


def _end_cells_min_angle(
    params, radius: float, arc: tuple[float, float, bool], m: int, template: PatchTemplate
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
        alpha = _slot_half_angle(params, rho)
        lo, hi = start + alpha, end - alpha
        sectors = np.unique([0, m // 2, m - 1]).astype(float)
    theta = np.radians(lo + (sectors[:, None] + uv[:, 1]) * (hi - lo) / m)  # (K, U)
    xy = np.stack([rho * np.cos(theta), rho * np.sin(theta)], axis=-1).reshape(-1, 2)
    local = np.searchsorted(used, template.triangles[ends])
    tri = (local[None] + (np.arange(len(sectors)) * len(used))[:, None, None]).reshape(-1, 3)
    return float(triangle_quality(xy, tri).min_angles_deg.min())


def _sectors_proper(params, arc: tuple[float, float, bool], plan: SectorPlan) -> bool:
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
    for ring, (radius, m) in enumerate(zip(_radii(params), plan.sectors, strict=True)):
        if closed:
            ks = np.zeros(1)
        else:
            samples = min(m, max(3, _SECTOR_CHECK_POINTS // len(template.uv)))
            ks = np.unique(np.round(np.linspace(0, m - 1, samples)))
        rho = radius + u * params.patch_size
        if closed:
            lo, hi = start, end
        else:
            alpha = _slot_half_angle(params, rho)
            lo, hi = start + alpha, end - alpha
        theta = _arc_theta(lo, hi, ks, v, m, plan.sector_bounds(ring))  # (K, Nv)
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


def _outermost(params: MeshParams) -> float:
    return max(_radii(params)) + params.patch_size


def _slot_half_angle(params: MeshParams, rho: np.ndarray | float) -> np.ndarray | float:
    """Angle (degrees) between the slot axis and where a slot side meets radius ρ."""
    return np.degrees(np.arcsin(params.gap_width / (2 * np.asarray(rho))))


def _conforming_ring_layout(params: MeshParams) -> Layout:
    plan = sector_plan(params)
    arcs, template = plan.arcs, plan.template
    split = bool(_gap_directions(params))
    h = params.patch_size
    u, v = template.uv[:, 0], template.uv[:, 1]
    nv = len(u)
    n_total = len(arcs) * sum(plan.sectors)
    xy = np.empty((n_total, nv, 2))
    regions, pairs, chains = [], [], []
    sides = template.sides
    n_patches = 0
    first_patch = {}  # (ring, arc) -> first patch index
    for ring, radius in enumerate(_radii(params)):
        rho = radius + u * h  # (Nv,)
        m = plan.sectors[ring]
        for a, (start, end, closed) in enumerate(arcs):
            if split:
                alpha = _slot_half_angle(params, rho)
                lo, hi = start + alpha, end - alpha
            else:
                lo, hi = np.full(nv, start), np.full(nv, end)
            if split:
                theta = _arc_theta(lo, hi, np.arange(m), v, m, plan.sector_bounds(ring))
                cos, sin = np.cos(theta), np.sin(theta)
            else:
                # the angle depends on v alone: evaluate cos and sin once per row of the template
                rows, row_of = np.unique(v, return_inverse=True)
                first = np.unique(row_of, return_index=True)[1]
                k = np.arange(m)[:, None] + rows[None, :]
                theta = np.radians(lo[first] + k * (hi[first] - lo[first]) / m)
                cos, sin = np.cos(theta).take(row_of, axis=1), np.sin(theta).take(row_of, axis=1)
            pts = xy[n_patches : n_patches + m]
            np.multiply(rho, cos, out=pts[..., 0])
            np.multiply(rho, sin, out=pts[..., 1])
            regions.append(np.full(m, ring + 1))
            first_patch[ring, a] = n_patches
            chains.append((m, closed))
            # glue side 2 (v = 1) of sector k to side 0 (v = 0) of sector k + 1
            nxt = np.arange(1, m + 1)
            cur = np.arange(m)
            if closed:
                nxt %= m
            else:
                cur, nxt = cur[:-1], nxt[:-1]
            base = n_patches * nv
            pairs.append(
                np.stack(
                    [
                        (base + cur[:, None] * nv + sides[2][None, :]).ravel(),
                        (base + nxt[:, None] * nv + sides[0][None, :]).ravel(),
                    ],
                    axis=1,
                )
            )
            n_patches += m
    touching = _touching(params)
    if any(params.origin):
        xy += np.asarray(params.origin)
    floor = plan.min_angle_floor
    if not touching and _sides_in_rows(template):
        ids, rep = sector_chain_vertices(template, [c[0] for c in chains], [c[1] for c in chains])
        return Layout(template, xy, np.concatenate(regions), ids, rep, None, floor)
    if touching:
        # touching rings (as many sectors): the inner ring's outer circle is the
        # outer ring's inner circle
        for a in range(len(arcs)):
            p0 = first_patch[0, a] + np.arange(plan.sectors[0])
            p1 = first_patch[1, a] + np.arange(plan.sectors[1])
            pairs.append(
                np.stack(
                    [
                        (p0[:, None] * nv + sides[1][None, :]).ravel(),
                        (p1[:, None] * nv + sides[3][None, :]).ravel(),
                    ],
                    axis=1,
                )
            )
    vertex_of_point, rep = merge_pairs(n_patches * nv, np.concatenate(pairs))
    return Layout(template, xy, np.concatenate(regions), vertex_of_point, rep, None, floor)


def _sides_in_rows(template: PatchTemplate) -> bool:
    """True when side 0 (v = 0) is the first local vertices and side 2 (v = 1) the last."""
    sides, nv = template.sides, len(template.uv)
    s = len(sides[0])
    return (
        len(sides[2]) == s
        and np.array_equal(sides[0], np.arange(s))
        and np.array_equal(sides[2], np.arange(nv - s, nv))
    )


def _conforming_square_rects(params: MeshParams) -> tuple[np.ndarray, np.ndarray]:
    """(x0, y0, wx, wy) rectangles tiling the square tracks exactly, slots cut out."""
    h, g = params.patch_size, params.gap_width
    phi = round(params.gap_angle / 90.0) % 2  # 0: horizontal slot, 1: vertical slot
    rects, regions = [], []
    for region, r in enumerate(_radii(params), start=1):
        corners = [(-r - h, -r - h), (r, -r - h), (r, r), (-r - h, r)]
        rs = [(x, y, h, h) for x, y in corners]
        full = np.linspace(-r, r, _count(2 * r, h) + 1)
        pieces = np.linspace(-r, -g / 2, _count(r - g / 2, h) + 1)
        cut = [np.stack([pieces[:-1], pieces[1:]], 1), np.stack([-pieces[1:], -pieces[:-1]], 1)]
        cut = np.concatenate(cut)
        whole = np.stack([full[:-1], full[1:]], 1)
        # sides running along x (bottom, top) and along y (left, right)
        along_x = cut if phi == 1 else whole
        along_y = cut if phi == 0 else whole
        for y0 in (-r - h, r):
            rs += [(a, y0, b - a, h) for a, b in along_x]
        for x0 in (-r - h, r):
            rs += [(x0, a, h, b - a) for a, b in along_y]
        rects += rs
        regions += [region] * len(rs)
    rects = np.array(rects)
    rects[:, :2] += np.asarray(params.origin)
    return rects, np.array(regions)


def _rect_layout(template: PatchTemplate, rects: np.ndarray) -> np.ndarray:
    """(P, Nv, 2) template points on the axis-aligned rectangles (x0, y0, wx, wy)."""
    u, v = template.uv[:, 0], template.uv[:, 1]
    x = rects[:, :1] + u[None, :] * rects[:, 2:3]
    y = rects[:, 1:2] + v[None, :] * rects[:, 3:4]
    return np.stack([x, y], axis=-1)


# -- entry points ----------------------------------------------------------


def predicted_patches(params: MeshParams) -> int:
    """Number of patches (or sectors) of the structure, computed cheaply."""
    s = params.structure
    if s in ("patch", "triangle"):
        return 1
    if s == "square_split_double_ring":
        h = params.patch_size
        upper = sum(2 * _count(2 * (r + h), h) + 2 * _count(2 * r, h) + 8 for r in _radii(params))
    elif params.mode == "conforming":
        plan = sector_plan(params)
        return len(plan.arcs) * sum(plan.sectors)
    else:
        upper = len(_radii(params)) * _count(360.0, params.angle_step)
    if upper > _EXACT_COUNT_LIMIT:
        return upper  # far beyond any budget: not worth placing the patches to count them
    if s == "square_split_double_ring" and params.mode == "conforming":
        return len(_conforming_square_rects(params)[0])
    if _gap_directions(params):
        return len(_paper_origins(params)[0])
    return upper


def predicted_triangles(params: MeshParams) -> int:
    """Number of triangles of the structure, computed cheaply."""
    if params.structure == "triangle":
        return params.triangles_per_primary
    if params.mode == "conforming" and params.structure in ANGULAR_STRUCTURES:
        plan = sector_plan(params)
        return len(plan.arcs) * sum(plan.sectors) * len(plan.template.triangles)
    return predicted_patches(params) * 2 * params.triangles_per_primary


def layout(params: MeshParams) -> Layout:
    """Place and weld the patches of ``params.structure`` (not ``triangle``)."""
    s = params.structure
    if s == "triangle":
        raise ValueError("the triangle structure has no patch layout")
    template = patch_template(params.scheme, params.subdivisions, params.diagonal)
    h, w = params.patch_size, params.patch_height
    nv = len(template.uv)
    if s == "patch":
        rects = np.array([[params.origin[0], params.origin[1], h, w]])
        xy = _rect_layout(template, rects)
        ids = np.arange(nv, dtype=np.int32)
        return Layout(template, xy, np.ones(1, dtype=np.int32), ids, ids, _corners(rects))
    if params.mode == "conforming":
        if s == "square_split_double_ring":
            rects, regions = _conforming_square_rects(params)
            xy = _rect_layout(template, rects)
            ids, rep = _welded(params, weld_points, xy.reshape(-1, 2), params.weld_tolerance)
            return Layout(template, xy, regions.astype(np.int32), ids, rep, None)
        return _conforming_ring_layout(params)
    origins, regions = _paper_origins(params)
    rects = np.concatenate([origins, np.broadcast_to([h, w], origins.shape)], axis=1)
    xy = _rect_layout(template, rects)
    if template.lattice:
        step = (h / template.segments, w / template.segments)
        ids, rep = _welded(
            params, weld_lattice_patches, origins, step, template.segments, params.weld_tolerance
        )
    else:
        ids, rep = _welded(params, weld_points, xy.reshape(-1, 2), params.weld_tolerance)
    return Layout(template, xy, regions.astype(np.int32), ids, rep, _corners(rects))


def _welded(params: MeshParams, weld, *args) -> tuple[np.ndarray, np.ndarray]:
    """``weld(*args)``, its chain error reworded when the user set no tolerance."""
    try:
        return weld(*args)
    except ValueError as err:
        if params.tolerance is not None:
            raise
        found = str(err).split("; points farther")[0]
        raise ValueError(
            f"{found}, with the default tolerance ({RELATIVE_TOLERANCE:g} of the structure's "
            "size): patches nearly, but not exactly, coincide; move them apart with "
            "angle_step, patch_size or the radii, or set a tolerance"
        ) from None


def _corners(rects: np.ndarray) -> np.ndarray:
    """(x0, y0, wx, wy) to (x0, y0, x1, y1)."""
    return np.concatenate([rects[:, :2], rects[:, :2] + rects[:, 2:]], axis=1)
