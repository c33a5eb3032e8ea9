"""Per-triangle quality: area, minimum angle and aspect ratio.

All three come from one pass over the corner coordinates, gathered column by
column (several times faster than gathering (T, 3, 3) blocks) in cache-sized
blocks of triangles, because the statistics panel recomputes them for every
new mesh.
"""

from __future__ import annotations

from typing import TYPE_CHECKING, Any, NamedTuple

import numpy as np

from .constants import wavelength
from .topology import BLOCK

if TYPE_CHECKING:
    from .mesh import TriMesh


class TriangleQuality(NamedTuple):
    """Per-triangle quality arrays, each (T,) float64."""

    areas: np.ndarray
    min_angles_deg: np.ndarray
    aspect_ratios: np.ndarray


#: Below this |cross product| its square is subnormal: the area takes the square root.
TINY_CROSS = 1e-150
#: What np.degrees multiplies by, without its slower loop.
RAD_TO_DEG = 180.0 / np.pi


def _sides_and_areas(
    columns: list[np.ndarray],
    triangles: np.ndarray,
    edge_lengths: np.ndarray | None = None,
    triangle_edges: np.ndarray | None = None,
) -> tuple[list[np.ndarray], np.ndarray]:
    """Lengths of sides k (vertex k to k + 1) and areas, from per-column gathers.

    ``columns`` are the 2 or 3 coordinate columns of the points, each (V,) float64.
    With ``edge_lengths`` (E,) and this block's ``triangle_edges`` (t, 3), the sides
    are taken from the edges: the same sums of squares, so the same values.
    """
    c = [[np.take(col, triangles[:, i]) for col in columns] for i in range(3)]  # c[i][k]
    u = [c[1][k] - c[0][k] for k in range(len(columns))]  # side 0
    v = [c[2][k] - c[0][k] for k in range(len(columns))]  # side 2 reversed: same squares
    if edge_lengths is not None and triangle_edges is not None:
        sides = [np.take(edge_lengths, triangle_edges[:, k]) for k in range(3)]
    else:
        w = [c[2][k] - c[1][k] for k in range(len(columns))]  # side 1
        sides = [np.sqrt(sum(x * x for x in d)) for d in (u, w, v)]
    if len(columns) == 2:
        cross = u[0] * v[1] - u[1] * v[0]
        # sqrt(c²) is |c| exactly unless c² underflows
        area = np.abs(cross)
        tiny = area < TINY_CROSS
        if tiny.any():
            area[tiny] = np.sqrt(cross[tiny] ** 2)
        area *= 0.5
        return sides, area
    cross2 = (
        (u[1] * v[2] - u[2] * v[1]) ** 2
        + (u[2] * v[0] - u[0] * v[2]) ** 2
        + (u[0] * v[1] - u[1] * v[0]) ** 2
    )
    return sides, 0.5 * np.sqrt(cross2)


def triangle_quality(
    points: np.ndarray,
    triangles: np.ndarray,
    columns: list[np.ndarray] | None = None,
    edge_lengths: np.ndarray | None = None,
    triangle_edges: np.ndarray | None = None,
) -> TriangleQuality:
    """Areas, smallest angles (degrees) and aspect ratios of all triangles at once.

    The smallest angle lies opposite the shortest side and is at most 60°, so it
    is ``arcsin(2 A / (b c))`` with b, c the two longer sides (accurate for
    slivers, where the law of cosines loses digits). The aspect ratio is
    l_max (l_0 + l_1 + l_2) / (4 √3 A): 1 for an equilateral triangle, growing
    without bound as a triangle flattens.

    Parameters
    ----------
    points : (V, 2) or (V, 3) float64
    triangles : (T, 3) int
    columns : list of (V,) float64, optional
        Contiguous copies of the x and y columns of ``points`` and of z unless it
        is zero everywhere, to save making them again.
    edge_lengths : (E,) float64, optional
    triangle_edges : (T, 3) int, optional
        Both or neither: the mesh's edge lengths and the edge of each triangle
        side; the sides are then taken from them instead of computed again.

    Examples
    --------
    >>> pts = np.array([[0.0, 0, 0], [1, 0, 0], [0, 1, 0]])
    >>> q = triangle_quality(pts, np.array([[0, 1, 2]]))
    >>> float(q.areas[0]), round(float(q.min_angles_deg[0]), 9)
    (0.5, 45.0)
    """
    points = np.asarray(points)
    triangles = np.asarray(triangles)
    n = len(triangles)
    out = TriangleQuality(np.empty(n), np.empty(n), np.empty(n))
    if columns is None:
        columns = [np.ascontiguousarray(points[:, k]) for k in range(points.shape[1])]
        if len(columns) == 3 and not columns[2].any():
            columns = columns[:2]  # z = 0 everywhere adds exact zeros: same values without it
    for lo in range(0, n, BLOCK):  # cache-sized blocks: no large temporaries
        hi = min(lo + BLOCK, n)
        sides_of = None if triangle_edges is None else triangle_edges[lo:hi]
        (l0, l1, l2), area = _sides_and_areas(columns, triangles[lo:hi], edge_lengths, sides_of)
        longest = np.maximum(np.maximum(l0, l1), l2)
        shortest = np.minimum(np.minimum(l0, l1), l2)
        perimeter = l0 + l1 + l2
        middle = perimeter - longest - shortest
        with np.errstate(invalid="ignore", divide="ignore"):
            sine = np.clip(2.0 * area / (longest * middle), 0.0, 1.0)
            np.divide(longest * perimeter, 4.0 * np.sqrt(3.0) * area, out=out.aspect_ratios[lo:hi])
        angle = np.arcsin(sine, out=sine)
        angle *= RAD_TO_DEG
        angle[~np.isfinite(angle)] = 0.0
        out.areas[lo:hi] = area
        out.min_angles_deg[lo:hi] = angle
    return out


class QualitySummary(NamedTuple):
    """What the statistics need of the per-triangle quality: extremes and a sum."""

    min_angle_deg: float
    max_aspect_ratio: float
    area: float
    shortest_side: float
    longest_side: float


def quality_summary(
    points: np.ndarray, triangles: np.ndarray, columns: list[np.ndarray] | None = None
) -> QualitySummary:
    """Smallest angle, largest aspect ratio, total area and side range, no per-triangle arrays.

    The figures of :func:`triangle_quality` reduced block by block: the smallest
    angle is the arcsine of the smallest sine (the arcsine rises with its
    argument), taken once per block instead of once per triangle; a triangle
    whose angle is undefined (0/0) gives 0 as there. Agrees with the reductions
    of :func:`triangle_quality` to rounding (the area sum is grouped by block);
    the side range is the range of the mesh's edge lengths bit for bit (every edge is
    a side of a triangle, and a side's length is computed from the same sum of squares). All zero
    without triangles.

    Parameters
    ----------
    points : (V, 2) or (V, 3) float64
    triangles : (T, 3) int
    columns : list of (V,) float64, optional
        As for :func:`triangle_quality`.
    """
    triangles = np.asarray(triangles)
    n = len(triangles)
    if n == 0:
        return QualitySummary(0.0, 0.0, 0.0, 0.0, 0.0)
    if columns is None:
        columns = [np.ascontiguousarray(points[:, k]) for k in range(points.shape[1])]
        if len(columns) == 3 and not columns[2].any():
            columns = columns[:2]
    sine_min, aspect_max, area_sum, short, long_ = [], [], [], [], []
    for lo in range(0, n, BLOCK):
        (l0, l1, l2), area = _sides_and_areas(columns, triangles[lo : lo + BLOCK])
        longest = np.maximum(np.maximum(l0, l1), l2)
        shortest = np.minimum(np.minimum(l0, l1), l2)
        perimeter = l0 + l1 + l2
        middle = perimeter - longest - shortest
        with np.errstate(invalid="ignore", divide="ignore"):
            sine = np.clip(2.0 * area / (longest * middle), 0.0, 1.0)
            aspect = longest * perimeter
            aspect /= 4.0 * np.sqrt(3.0) * area
        sine_min.append(sine.min())  # NaN when some angle is undefined
        aspect_max.append(aspect.max())  # NaN propagates as in the per-triangle maximum
        area_sum.append(area.sum())
        short.append(shortest.min())
        long_.append(longest.max())
    smallest_sine = np.min(sine_min)
    angle = float(np.arcsin(smallest_sine)) * RAD_TO_DEG
    return QualitySummary(
        min_angle_deg=angle if np.isfinite(angle) else 0.0,
        max_aspect_ratio=float(np.max(aspect_max)),
        area=float(np.sum(area_sum)),
        shortest_side=float(np.min(short)),
        longest_side=float(np.max(long_)),
    )


# -- the quality report: what a solver's user checks before a run -----------------------

#: Smallest angle below which a triangle counts as thin (degrees): PSSFSS meshes with a
#: 30° minimum angle, and the property tests hold conforming meshes to it.
MIN_ANGLE_THRESHOLD = 30.0
#: Aspect ratio (l_max × perimeter / (4√3 area), 1 for an equilateral triangle) above which
#: a triangle counts as distorted. A triangle whose smallest angle is at least 30° has an
#: aspect ratio of at most (2 + √3)/√3 ≈ 2.155 (the 30-30-120° triangle), so 3 flags only
#: triangles well beyond what the 30° rule tolerates: about a flat cap whose smallest
#: angle is below 21° or a needle below 11°.
ASPECT_RATIO_THRESHOLD = 3.0
#: Longest edge over the wavelength above which a triangle is too coarse (λ/10).
EDGE_WAVELENGTH_THRESHOLD = 0.1
#: Percentiles of the smallest angle in the report.
ANGLE_PERCENTILES = (1, 5, 25, 50)
#: Bins of the histograms.
HISTOGRAM_BINS = 30
#: The aspect-ratio histogram spans 1 .. at most this; larger (and infinite) ratios are
#: counted in its ``above_range``.
ASPECT_RATIO_RANGE_CAP = 20.0


def wavelength_mm(
    frequency: float | None, relative_permittivity: float | None = None
) -> float | None:
    """Wavelength (mm) at ``frequency`` (Hz) in a medium of ``relative_permittivity``.

    ``None`` without a frequency. λ = c / (f √ε_r).

    Examples
    --------
    >>> round(wavelength_mm(10e9), 6)
    29.979246
    >>> round(wavelength_mm(10e9, 4.0), 6)
    14.989623
    """
    if frequency is None:
        return None
    f = float(frequency)
    eps = 1.0 if relative_permittivity is None else float(relative_permittivity)
    if not (np.isfinite(f) and f > 0):
        raise ValueError(f"frequency={frequency!r} is invalid; expected a positive number of Hz")
    if not (np.isfinite(eps) and eps >= 1.0):
        raise ValueError(
            f"relative_permittivity={relative_permittivity!r} is invalid; expected a number >= 1"
        )
    return wavelength(f, eps)


def params_wavelength(params: object) -> float | None:
    """The wavelength (mm) that mesh parameters ask for, or None.

    Read defensively (``frequency`` and ``relative_permittivity`` are optional
    attributes), so any parameter object, or None, will do.
    """
    return wavelength_mm(
        getattr(params, "frequency", None), getattr(params, "relative_permittivity", None)
    )


def longest_sides(points: np.ndarray, triangles: np.ndarray) -> np.ndarray:
    """The longest side of every triangle, (T,) float64, in the unit of ``points``.

    Parameters
    ----------
    points : (V, 2) or (V, 3) float64
    triangles : (T, 3) int
    """
    points = np.asarray(points, dtype=np.float64)
    triangles = np.asarray(triangles)
    columns = [np.ascontiguousarray(points[:, k]) for k in range(points.shape[1])]
    out = np.empty(len(triangles))
    for lo in range(0, len(triangles), BLOCK):
        (l0, l1, l2), _ = _sides_and_areas(columns, triangles[lo : lo + BLOCK])
        np.maximum(np.maximum(l0, l1), l2, out=out[lo : lo + BLOCK])
    return out


def cell_figures(mesh: TriMesh, wavelength: float | None = None) -> dict[str, np.ndarray]:
    """Per-triangle data of a mesh as files and viewers carry it (the colour menu's names).

    Parameters
    ----------
    mesh : TriMesh
    wavelength : float, optional
        λ in mm: adds ``edge_wavelength``, each triangle's longest side over λ (the
        figure of :func:`quality_report`).

    Returns
    -------
    dict of str to (T,) array
        ``patch_id``, ``region`` (int64), ``area`` (mm²), ``min_angle`` (degrees),
        ``aspect_ratio`` (float64), and with ``wavelength`` ``edge_wavelength``.
        The integers are int64: VTK's legacy reader does not know meshio's
        ``vtktypeint32`` and drops every cell array of a file that has one (meshio
        issue 1410), while ``vtktypeint64`` it reads.
    """
    data: dict[str, np.ndarray] = {
        "patch_id": np.asarray(mesh.patch_ids).astype(np.int64),
        "region": np.asarray(mesh.regions).astype(np.int64),
        "area": np.asarray(mesh.areas, dtype=np.float64),
        "min_angle": np.asarray(mesh.min_angles, dtype=np.float64),
        "aspect_ratio": np.asarray(mesh.aspect_ratios, dtype=np.float64),
    }
    if wavelength is not None:
        data["edge_wavelength"] = longest_sides(mesh.points, mesh.triangles) / float(wavelength)
    return data


def _number(x: float) -> float | None:
    """A JSON-ready float: None for NaN and ±inf."""
    x = float(x)
    return x if np.isfinite(x) else None


def _histogram(values: np.ndarray, edges: np.ndarray) -> dict[str, Any]:
    """Bin edges, counts and what falls outside, of the finite and infinite values."""
    counts, _ = np.histogram(values, bins=edges)
    return {
        "edges": [float(e) for e in edges],
        "counts": counts.tolist(),
        "below_range": int(np.count_nonzero(values < edges[0])),
        "above_range": int(np.count_nonzero(values > edges[-1])),
    }


def _range_top(largest: float, floor: float, step: float) -> float:
    """``largest`` rounded up to a multiple of ``step``, at least ``floor``."""
    if not np.isfinite(largest):
        return floor
    return max(floor, float(np.ceil(largest / step - 1e-9)) * step)


def _worst_indices(min_angles: np.ndarray, k: int) -> np.ndarray:
    """The ``k`` triangles of smallest angle, smallest first, ties by index (deterministic)."""
    n = len(min_angles)
    k = min(int(k), n)
    if k <= 0:
        return np.empty(0, dtype=np.int64)
    kth = np.partition(min_angles, k - 1)[k - 1]
    less = np.flatnonzero(min_angles < kth)
    tied = np.flatnonzero(min_angles == kth)[: k - len(less)]
    picked = np.concatenate([less, tied])
    return picked[np.lexsort((picked, min_angles[picked]))]


def quality_report(
    mesh: TriMesh, wavelength: float | None = None, worst: int = 20
) -> dict[str, Any]:
    """The quality of a mesh as a solver's user checks it, as a plain JSON-ready dict.

    Smallest angle (minimum, percentiles, triangles below
    :data:`MIN_ANGLE_THRESHOLD`), aspect ratio (maximum, triangles above
    :data:`ASPECT_RATIO_THRESHOLD`), and with a wavelength the longest edge of each
    triangle over λ (maximum, triangles above :data:`EDGE_WAVELENGTH_THRESHOLD`),
    each with a histogram; and the ``worst`` triangles by smallest angle. Floats
    that are not finite (the aspect ratio of a degenerate triangle) are None, so
    ``json.dumps(..., allow_nan=False)`` takes the dict as it is.

    Parameters
    ----------
    mesh : TriMesh
    wavelength : float, optional
        λ in mm. Default: from ``mesh.params`` (``frequency``, ``relative_permittivity``)
        when the mesh has them, else no edge/λ figures.
    worst : int
        How many of the worst triangles to list (0 or more).

    Returns
    -------
    dict
        ``triangles``; ``min_angle_deg``: ``min``, ``percentiles`` (str(p) -> degrees),
        ``threshold``, ``below``, ``histogram``; ``aspect_ratio``: ``max``, ``median``,
        ``threshold``, ``above``, ``degenerate`` (area 0), ``histogram``;
        ``edge_wavelength``: None, or ``wavelength_mm``, ``max``, ``threshold``,
        ``above``, ``histogram``; ``worst``: list of dicts with ``triangle``,
        ``min_angle_deg``, ``aspect_ratio``, ``centroid`` (mm) and, with a wavelength,
        ``edge_wavelength``. A histogram is ``edges`` (bins + 1), ``counts`` (bins),
        ``below_range`` and ``above_range``.

    Examples
    --------
    >>> from barymesh import MeshParams, build_mesh
    >>> r = quality_report(build_mesh(MeshParams(structure="patch")), worst=1)
    >>> round(r["min_angle_deg"]["min"], 9), r["min_angle_deg"]["below"], r["worst"][0]["triangle"]
    (45.0, 0, 0)
    """
    if isinstance(worst, bool) or not isinstance(worst, (int, np.integer)) or worst < 0:
        raise ValueError(f"worst={worst!r} is invalid; expected a whole number >= 0")
    if wavelength is None:
        wavelength = params_wavelength(getattr(mesh, "params", None))
    elif not (np.isfinite(float(wavelength)) and float(wavelength) > 0):
        raise ValueError(f"wavelength={wavelength!r} is invalid; expected a positive length in mm")
    n = mesh.n_triangles
    angles = np.asarray(mesh.min_angles)
    ratios = np.asarray(mesh.aspect_ratios)
    finite = np.isfinite(ratios)
    out: dict[str, Any] = {"triangles": int(n)}

    angle_edges = np.linspace(0.0, 60.0, HISTOGRAM_BINS + 1)  # the smallest angle is ≤ 60°
    pct = np.percentile(angles, ANGLE_PERCENTILES) if n else [np.nan] * len(ANGLE_PERCENTILES)
    out["min_angle_deg"] = {
        "min": _number(angles.min()) if n else None,
        "percentiles": {str(p): _number(v) for p, v in zip(ANGLE_PERCENTILES, pct, strict=True)},
        "threshold": MIN_ANGLE_THRESHOLD,
        "below": int(np.count_nonzero(angles < MIN_ANGLE_THRESHOLD)),
        "histogram": _histogram(angles, angle_edges),
    }

    largest = float(ratios[finite].max()) if finite.any() else np.nan
    top = min(_range_top(largest, 2.0 * ASPECT_RATIO_THRESHOLD, 1.0), ASPECT_RATIO_RANGE_CAP)
    out["aspect_ratio"] = {
        "max": (None if not finite.all() else _number(largest)) if n else None,
        # a zero-area triangle's ratio is inf (or 0/0): ranked above every other
        "median": _number(np.median(np.where(np.isnan(ratios), np.inf, ratios))) if n else None,
        "threshold": ASPECT_RATIO_THRESHOLD,
        "above": int(np.count_nonzero(~(ratios <= ASPECT_RATIO_THRESHOLD))),
        "degenerate": int(np.count_nonzero(~finite)),
        "histogram": _histogram(
            ratios[~np.isnan(ratios)], np.linspace(1.0, top, HISTOGRAM_BINS + 1)
        ),
    }

    edge_ratio = None
    out["edge_wavelength"] = None
    if wavelength is not None:
        edge_ratio = longest_sides(mesh.points, mesh.triangles) / float(wavelength)
        biggest = float(edge_ratio.max()) if n else 0.0
        top = _range_top(biggest, 1.5 * EDGE_WAVELENGTH_THRESHOLD, 0.05)
        out["edge_wavelength"] = {
            "wavelength_mm": float(wavelength),
            "max": _number(biggest) if n else None,
            "threshold": EDGE_WAVELENGTH_THRESHOLD,
            "above": int(np.count_nonzero(edge_ratio > EDGE_WAVELENGTH_THRESHOLD)),
            "histogram": _histogram(edge_ratio, np.linspace(0.0, top, HISTOGRAM_BINS + 1)),
        }

    picked = _worst_indices(angles, worst)
    corners = np.asarray(mesh.points)[np.asarray(mesh.triangles)[picked]]  # (k, 3, 3)
    centroids = corners.mean(axis=1)
    rows = []
    for i, t in enumerate(picked.tolist()):  # at most ``worst`` rows, not a loop over the mesh
        row = {
            "triangle": t,
            "min_angle_deg": _number(angles[t]),
            "aspect_ratio": _number(ratios[t]),
            "centroid": [float(c) for c in centroids[i]],
        }
        if edge_ratio is not None:
            row["edge_wavelength"] = _number(edge_ratio[t])
        rows.append(row)
    out["worst"] = rows
    return out


def quality_lines(report: dict[str, Any]) -> list[str]:
    """A few lines of text summing up :func:`quality_report` (the command line's)."""
    a, r, e = report["min_angle_deg"], report["aspect_ratio"], report["edge_wavelength"]
    n = report["triangles"]

    def share(count: int) -> str:
        return f"{count:,} ({100.0 * count / n:.3g}%)" if n else f"{count:,}"

    def num(x: float | None, fmt: str) -> str:
        return "undefined" if x is None else format(x, fmt)

    p = a["percentiles"]
    lines = [
        f"  smallest angle {num(a['min'], '.3g')} deg (1%: {num(p['1'], '.3g')}, 5%: "
        f"{num(p['5'], '.3g')}, median {num(p['50'], '.3g')}); below {a['threshold']:g} deg: "
        f"{share(a['below'])}",
        f"  aspect ratio max {'inf' if r['degenerate'] else num(r['max'], '.4g')}, median "
        f"{num(r['median'], '.4g')}; above {r['threshold']:g}: {share(r['above'])}",
    ]
    if r["degenerate"]:
        lines.append(f"  degenerate (zero-area) triangles: {r['degenerate']:,}")
    if e is not None:
        lines.append(
            f"  longest edge / wavelength {num(e['max'], '.3g')} (lambda = "
            f"{e['wavelength_mm']:.4g} mm); above 1/10: {share(e['above'])}"
        )
    if report["worst"]:
        w = report["worst"][0]
        x, y, _ = w["centroid"]
        lines.append(
            f"  worst triangle #{w['triangle']:,}: {num(w['min_angle_deg'], '.3g')} deg at "
            f"({x:.4g}, {y:.4g}) mm"
        )
    return lines
