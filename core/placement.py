"""Where the patches of a structure go, and how many triangles they make, before any mesh.

Paper mode is the paper's Eqs. 28–35: axis-aligned patches whose lower-left corner is
(r cos θ, r sin θ) for θ = 0, Δθ, 2Δθ, … below 360° (:func:`paper_ring_origins`), and
square rings tiled by patches along their sides; a slot removes the patches that share
area with it. Conforming square rings are tiled exactly by rectangles
(:func:`conforming_square_rects`); conforming circular rings are cut into the sectors of
:func:`barymesh.sectors.sector_plan`.

:func:`predicted_triangles` counts the triangles from that alone: the parameters
(:class:`barymesh.params.MeshParams`) check their triangle budget with it, so this module
sits below them and reads only the fields of :class:`PlacementFields`.
"""

from __future__ import annotations

import math
from typing import Any, Protocol

import numpy as np

from .kinds import ANGULAR_STRUCTURES
from .sectors import RingFields, count_steps, gap_directions, ring_radii, sector_plan


class PlacementFields(RingFields, Protocol):
    """The fields of :class:`barymesh.params.MeshParams` that place the patches (read only)."""

    @property
    def mode(self) -> str: ...
    @property
    def origin(self) -> tuple[float, float]: ...
    @property
    def patch_height(self) -> float: ...
    @property
    def triangles_per_primary(self) -> int: ...


#: Above this many patches the count is estimated from above instead of placed.
_EXACT_COUNT_LIMIT = 20_000_000
#: Patches next to a slot tested at once when counting (bounded memory).
_SLOT_CHUNK = 1 << 18


def paper_ring_origins(
    params: PlacementFields, radius: float, which: np.ndarray | None = None
) -> np.ndarray:
    """Lower-left corners (r cos θ, r sin θ) + centre, θ = 0, Δθ, … < 360° (Eqs. 28–29).

    ``which``: the indices of the patches wanted (default all), bit for bit as in the whole.
    """
    k = count_steps(360.0, params.angle_step)
    index = np.arange(k) if which is None else which
    theta = np.radians(index * params.angle_step)
    centre = np.asarray(params.origin)
    return centre + radius * np.stack([np.cos(theta), np.sin(theta)], axis=1)


def _spread(lo: float, hi: float, k: int, which: np.ndarray) -> np.ndarray:
    """``np.linspace(lo, hi, k)[which]`` (``[lo]`` for k = 1) without the whole array."""
    if k == 1:
        return np.full(len(which), lo)
    out = which * ((hi - lo) / (k - 1)) + lo  # linspace's own arithmetic
    out[which == k - 1] = hi
    return out


def _square_sides(params: PlacementFields, half_side: float) -> list[tuple]:
    """The four sides of a paper square track: (k, x(which), y(which)) each."""
    r, h = half_side, params.patch_size
    k_long = count_steps(2 * (r + h), h)
    k_short = count_steps(2 * r, h)

    def along(lo: float, hi: float, k: int, fixed: float, axis: int) -> tuple:
        def at(which: np.ndarray) -> np.ndarray:
            moving = _spread(lo, hi, k, which)
            other = np.full_like(moving, fixed)
            return np.stack([moving, other] if axis == 0 else [other, moving], axis=1)

        return k, at

    return [
        along(-r - h, r, k_long, -r - h, 0),  # bottom
        along(-r, r - h, k_short, r, 1),  # right
        along(-r - h, r, k_long, r, 0),  # top
        along(-r, r - h, k_short, -r - h, 1),  # left
    ]


def square_ring_origins(params: PlacementFields, half_side: float) -> np.ndarray:
    """Lower-left corners of square patches tiling a square track (paper mode).

    The track lies between the squares of half side R and R + h. Each side's
    strip is covered by h x h patches spread evenly from end to end; they tile
    it exactly when its length is a multiple of h and overlap slightly
    otherwise, as the paper's patches do.
    """
    sides = [at(np.arange(k)) for k, at in _square_sides(params, half_side)]
    return np.asarray(params.origin) + np.concatenate(sides)


def rects_touching_slots(
    rects: np.ndarray,
    centre: tuple[float, float],
    directions: list[float],
    width: float,
    scale: float | None = None,
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
    scale : float, optional
        The distance (mm) from ``centre`` the rounding slack (1e-12 of it) is relative
        to; default the farthest corner of ``rects``. Give it to test some of a
        structure's rectangles exactly as all of them are.
    """
    rel = rects - np.array([centre[0], centre[1], centre[0], centre[1]])
    cx = rel[:, [0, 2, 2, 0]]
    cy = rel[:, [1, 1, 3, 3]]
    if scale is None:
        scale = float(np.abs(rel).max(initial=0.0))
    eps = 1e-12 * max(1.0, scale)
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


def paper_origins(params: PlacementFields) -> tuple[np.ndarray, np.ndarray]:
    """Patch origins and regions of a paper-mode ring structure, slots applied."""
    radii = ring_radii(params)
    if params.structure == "square_split_double_ring":
        parts = [square_ring_origins(params, radius) for radius in radii]
        origins = np.concatenate(parts)
        regions = np.concatenate([np.full(len(o), i) for i, o in enumerate(parts, start=1)])
    else:
        # every circular ring has the same angles: paper_ring_origins' products and sums,
        # its cosines and sines found once for all rings (r u is u r, c + x is x + c);
        # numpy's C entry points rather than its Python wrappers (np.stack, np.repeat),
        # which cost most right after other work has evicted them
        k = count_steps(360.0, params.angle_step)
        theta = np.radians(np.arange(k) * params.angle_step)
        unit = np.array([np.cos(theta), np.sin(theta)]).T
        rings = np.empty((len(radii), k, 2))
        np.multiply(unit, np.array(radii)[:, None, None], out=rings)
        rings += np.asarray(params.origin)
        origins = rings.reshape(-1, 2)
        regions = np.arange(1, len(radii) + 1).repeat(k)
    directions = gap_directions(params)
    if directions:
        keep = ~_touching_slots(params, origins)
        origins, regions = origins[keep], regions[keep]
    return origins, regions


def _touching_slots(params: PlacementFields, origins: np.ndarray) -> np.ndarray:
    """Which patches at ``origins`` (P, 2) share area with the structure's slots."""
    h, w = params.patch_size, params.patch_height
    rects = np.concatenate([origins, origins + [h, w]], axis=1)
    scale = max(ring_radii(params)) + max(h, w)  # every corner is within it of the centre
    directions = gap_directions(params)
    return rects_touching_slots(rects, params.origin, directions, params.gap_width, scale)


def _slot_candidates(params: PlacementFields, radius: float, angle: float) -> np.ndarray:
    """Indices of a paper ring's patches whose origin is near a slot axis (a superset).

    A patch touches a slot only if its lower-left corner is within half the slot's width
    plus the patch's diagonal of the slot's axis, the line through the centre at
    ``angle``; on a ring of radius r that is within arcsin((g/2 + d) / r) of the axis.
    """
    k = count_steps(360.0, params.angle_step)
    reach = params.gap_width / 2 + 2 * math.hypot(params.patch_size, params.patch_height)
    if reach >= radius:
        return np.arange(k)
    half = math.degrees(math.asin(reach / radius)) + 2 * params.angle_step
    found = []
    for centre in (angle, angle + 180.0):
        for turn in (-360.0, 0.0, 360.0, 720.0):
            lo = math.floor((centre + turn - half) / params.angle_step)
            hi = math.ceil((centre + turn + half) / params.angle_step)
            found.append(np.arange(max(lo, 0), min(hi, k - 1) + 1))
    return np.unique(np.concatenate(found))


def _side_candidates(params: PlacementFields, k: int, at: Any, angle: float) -> np.ndarray:
    """Indices of a straight row of patches whose origin is near the slot axis (a superset)."""
    reach = params.gap_width / 2 + 2 * math.hypot(params.patch_size, params.patch_height)
    c, s = math.cos(math.radians(angle)), math.sin(math.radians(angle))
    ends = at(np.array([0, k - 1]))
    d0, d1 = ends @ np.array([-s, c])  # distance across the axis, affine in the index
    if k == 1 or abs(d1 - d0) <= 1e-12 * (abs(d0) + abs(d1)):
        return np.arange(k) if min(abs(d0), abs(d1)) <= reach else np.arange(0)
    slope = (d1 - d0) / (k - 1)
    lo, hi = sorted(((-reach - d0) / slope, (reach - d0) / slope))
    return np.arange(max(math.floor(lo) - 2, 0), min(math.ceil(hi) + 2, k - 1) + 1)


def _paper_slot_count(params: PlacementFields) -> int:
    """Patches of a slotted paper-mode structure, counting only those next to a slot.

    The candidates are tested in chunks of :data:`_SLOT_CHUNK` (bounded memory; a slot
    nearly as wide as the ring makes most patches candidates).
    """
    square = params.structure == "square_split_double_ring"
    centre = np.asarray(params.origin)
    angle = params.gap_angle % 360.0
    rows: list[tuple[int, np.ndarray, Any]] = []  # (patches, candidate indices, origins of)
    for radius in ring_radii(params):
        if square:
            for k, at in _square_sides(params, radius):
                near = _side_candidates(params, k, at, angle)
                rows.append((k, near, lambda which, at=at: centre + at(which)))
        else:
            k = count_steps(360.0, params.angle_step)
            near = _slot_candidates(params, radius, angle)
            rows.append((k, near, lambda which, r=radius: paper_ring_origins(params, r, which)))
    total = sum(k for k, _, _ in rows)
    for _, near, origins_of in rows:
        for lo in range(0, len(near), _SLOT_CHUNK):
            total -= int(_touching_slots(params, origins_of(near[lo : lo + _SLOT_CHUNK])).sum())
    return total


def _conforming_square_count(params: PlacementFields) -> int:
    """``len(conforming_square_rects(params)[0])`` by arithmetic: the rectangles are not
    placed (16 million of them, a few GB of Python tuples, for 1e-6 mm steps round a 1 mm
    ring, a count still under the exact-count limit)."""
    h, g = params.patch_size, params.gap_width
    phi = round(params.gap_angle / 90.0) % 2
    total = 0
    for r in ring_radii(params):
        whole = count_steps(2 * r, h)
        cut = 2 * count_steps(r - g / 2, h)
        along_x, along_y = (cut, whole) if phi == 1 else (whole, cut)
        total += 4 + 2 * along_x + 2 * along_y
    return total


def conforming_square_rects(params: PlacementFields) -> tuple[np.ndarray, np.ndarray]:
    """(x0, y0, wx, wy) rectangles tiling the square tracks exactly, slots cut out."""
    h, g = params.patch_size, params.gap_width
    phi = round(params.gap_angle / 90.0) % 2  # 0: horizontal slot, 1: vertical slot
    rects: list[tuple[float, float, float, float]] = []
    regions: list[int] = []
    for region, r in enumerate(ring_radii(params), start=1):
        corners = [(-r - h, -r - h), (r, -r - h), (r, r), (-r - h, r)]
        rs = [(x, y, h, h) for x, y in corners]
        full = np.linspace(-r, r, count_steps(2 * r, h) + 1)
        pieces = np.linspace(-r, -g / 2, count_steps(r - g / 2, h) + 1)
        cut = np.concatenate(
            [np.stack([pieces[:-1], pieces[1:]], 1), np.stack([-pieces[1:], -pieces[:-1]], 1)]
        )
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
    out = np.array(rects)
    out[:, :2] += np.asarray(params.origin)
    return out, np.array(regions)


def cross_rects(params: PlacementFields) -> np.ndarray:
    """(5, 4) rectangles (x0, y0, wx, wy) of a cross centred on ``origin``.

    The centre square C, then the right, top, left and bottom arms R, T, L, B::

        arms        +--+
                    |T |        (L - w) / 2 long, w = patch_height wide
                +---+--+---+
                | L | C| R |    L = patch_size, tip to tip
                +---+--+---+
                    |B |
                    +--+
    """
    length, w = params.patch_size, params.patch_height
    arm = (length - w) / 2
    half = w / 2
    rects = np.array(
        [
            (-half, -half, w, w),
            (half, -half, arm, w),
            (-half, half, w, arm),
            (-length / 2, -half, arm, w),
            (-half, -length / 2, w, arm),
        ]
    )
    rects[:, :2] += np.asarray(params.origin)
    return rects


def predicted_patches(params: PlacementFields) -> int:
    """Number of patches (or sectors) of the structure, computed cheaply."""
    s = params.structure
    if s in ("patch", "triangle"):
        return 1
    if s == "cross":
        return 5
    if s == "square_split_double_ring":
        h = params.patch_size
        upper = sum(
            2 * count_steps(2 * (r + h), h) + 2 * count_steps(2 * r, h) + 8
            for r in ring_radii(params)
        )
    elif params.mode == "conforming":
        plan = sector_plan(params)
        return len(plan.arcs) * sum(plan.sectors)
    else:
        upper = len(ring_radii(params)) * count_steps(360.0, params.angle_step)
    if upper > _EXACT_COUNT_LIMIT:
        return upper  # far beyond any budget: not worth placing the patches to count them
    if s == "square_split_double_ring" and params.mode == "conforming":
        return _conforming_square_count(params)
    if gap_directions(params):
        return _paper_slot_count(params)
    return upper


def predicted_triangles(params: PlacementFields) -> int:
    """Number of triangles of the structure, computed cheaply."""
    if params.structure == "triangle":
        return params.triangles_per_primary
    if params.mode == "conforming" and params.structure in ANGULAR_STRUCTURES:
        plan = sector_plan(params)
        return len(plan.arcs) * sum(plan.sectors) * len(plan.template.triangles)
    return predicted_patches(params) * 2 * params.triangles_per_primary
