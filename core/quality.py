"""Per-triangle quality: area, minimum angle and aspect ratio."""

from __future__ import annotations

import numpy as np


def triangle_areas(points: np.ndarray, triangles: np.ndarray) -> np.ndarray:
    """(T,) float64 areas of triangles in 3D (half the norm of the edge cross product)."""
    p = points[triangles]
    return 0.5 * np.linalg.norm(np.cross(p[:, 1] - p[:, 0], p[:, 2] - p[:, 0]), axis=1)


def side_lengths(points: np.ndarray, triangles: np.ndarray) -> np.ndarray:
    """(T, 3) float64: length of side k (vertex k to k + 1) of each triangle."""
    p = points[triangles]
    return np.linalg.norm(p[:, [1, 2, 0]] - p, axis=2)


def min_angles_deg(points: np.ndarray, triangles: np.ndarray) -> np.ndarray:
    """(T,) float64 smallest interior angle of each triangle, in degrees.

    Examples
    --------
    >>> pts = np.array([[0.0, 0, 0], [1, 0, 0], [0, 1, 0]])
    >>> round(float(min_angles_deg(pts, np.array([[0, 1, 2]]))[0]), 9)
    45.0
    """
    sides = side_lengths(points, triangles)
    a, b, c = sides[:, 1], sides[:, 2], sides[:, 0]  # opposite vertices 0, 1, 2
    with np.errstate(invalid="ignore", divide="ignore"):
        cos0 = (b * b + c * c - a * a) / (2 * b * c)
        cos1 = (a * a + c * c - b * b) / (2 * a * c)
        cos2 = (a * a + b * b - c * c) / (2 * a * b)
    cos = np.clip(np.stack([cos0, cos1, cos2], axis=1), -1.0, 1.0)
    return np.degrees(np.arccos(cos)).min(axis=1)


def aspect_ratios(points: np.ndarray, triangles: np.ndarray) -> np.ndarray:
    """(T,) float64 aspect ratio of each triangle.

    Defined as l_max (l_0 + l_1 + l_2) / (4 √3 A): 1 for an equilateral
    triangle, growing without bound as a triangle flattens.
    """
    sides = side_lengths(points, triangles)
    area = triangle_areas(points, triangles)
    with np.errstate(divide="ignore"):
        return sides.max(axis=1) * sides.sum(axis=1) / (4 * np.sqrt(3) * area)
