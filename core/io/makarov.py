"""MATLAB ``.mat`` files in the layout of S. N. Makarov's RWG codes.

``p`` is 3 x N float64 vertex coordinates (metres by default), ``t`` is
4 x M with 1-based vertex indices in rows 1–3 and 1 in row 4 (his
``rwg1.m`` drops triangles whose row 4 is above 1).
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
import scipy.io

from ..mesh import TriMesh


def makarov_arrays(mesh: TriMesh, per_mm: float) -> dict[str, np.ndarray]:
    """``{"p": (3, N) float64, "t": (4, M) float64}`` with ``p`` in the file's unit."""
    p = (np.asarray(mesh.points, dtype=np.float64) * per_mm).T
    t = np.ones((4, mesh.n_triangles), dtype=np.float64)
    t[:3] = mesh.triangles.T + 1
    return {"p": np.ascontiguousarray(p), "t": t}


def write_makarov(mesh: TriMesh, path: Path, per_mm: float) -> None:
    """Write ``p`` and ``t`` as a MATLAB v5 file."""
    with open(path, "wb") as fh:
        scipy.io.savemat(fh, makarov_arrays(mesh, per_mm), format="5", oned_as="column")


def read_makarov(path: Path) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """``(points (V, 3) in the file's unit, triangles (T, 3) 0-based, regions (T,))``.

    Raises ``ValueError`` naming the problem when ``p`` or ``t`` is missing
    or malformed.
    """
    data = scipy.io.loadmat(path)
    missing = [k for k in ("p", "t") if k not in data]
    if missing:
        keys = sorted(k for k in data if not k.startswith("__"))
        raise ValueError(
            f"no variable {missing[0]!r}; expected Makarov's p (3 x N) and t (4 x M), "
            f"found {', '.join(keys) or 'no variables'}"
        )
    p = np.asarray(data["p"], dtype=np.float64)
    t = np.asarray(data["t"])
    if p.ndim != 2 or p.shape[0] not in (2, 3):
        raise ValueError(f"p has shape {p.shape}; expected 3 x N coordinates")
    if t.ndim != 2 or t.shape[0] not in (3, 4):
        raise ValueError(f"t has shape {t.shape}; expected 4 x M (or 3 x M) vertex indices")
    if not np.issubdtype(t.dtype, np.number) or not np.all(np.isfinite(t)):
        raise ValueError("t holds non-numeric or non-finite values; expected vertex indices")
    if t.size and np.any(np.asarray(t[:3], dtype=np.float64) % 1 != 0):
        raise ValueError("t holds non-integer vertex indices")
    tri = np.asarray(t[:3], dtype=np.int64).T - 1
    if tri.size and (tri.min() < 0 or tri.max() >= p.shape[1]):
        raise ValueError(
            f"t refers to vertex {int(tri.max()) + 1 if tri.max() >= p.shape[1] else 0} "
            f"but p has {p.shape[1]} vertices (indices are 1-based)"
        )
    regions = np.asarray(t[3], dtype=np.int64) if t.shape[0] == 4 else np.ones(len(tri), int)
    points = p.T
    if points.shape[1] == 2:
        points = np.column_stack([points, np.zeros(len(points))])
    return points, tri, regions
