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
from .limits import MAX_CELLS, MAX_POINTS, Damaged, check_count

#: MATLAB classes that hold numbers (logical, char, cell and struct do not).
_NUMERIC = ("double", "single", "int8", "int16", "int32", "int64",
            "uint8", "uint16", "uint32", "uint64")  # fmt: skip


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

    The variables' shapes and classes are checked (from the file's headers,
    before their data is read) against :mod:`core.io.limits`; raises
    :class:`~core.io.limits.Damaged` naming the problem when ``p`` or ``t`` is
    missing or malformed.
    """
    try:
        found = {name: (shape, kind) for name, shape, kind in scipy.io.whosmat(path)}
    except NotImplementedError:
        raise Damaged("it is a MATLAB v7.3 (HDF5) file; save it with -v7 or older") from None
    missing = [k for k in ("p", "t") if k not in found]
    if missing:
        keys = sorted(found)
        raise Damaged(
            f"it has no variable {missing[0]!r}; expected Makarov's p (3 x N) and t (4 x M), "
            f"found {', '.join(keys) or 'no variables'}"
        )
    for name, rows, limit, what in (("p", (2, 3), MAX_POINTS, "vertices"),
                                    ("t", (3, 4), MAX_CELLS, "triangles")):  # fmt: skip
        shape, kind = found[name]
        if kind not in _NUMERIC:
            raise Damaged(f"its {name} is of MATLAB class {kind}; expected numbers (double)")
        if len(shape) != 2 or shape[0] not in rows:
            expected = "3 x N coordinates" if name == "p" else "4 x M (or 3 x M) vertex indices"
            raise Damaged(f"its {name} is {' x '.join(map(str, shape))}; expected {expected}")
        check_count(shape[1], f"{what} (columns of {name})", limit)
    data = scipy.io.loadmat(path, variable_names=["p", "t"])
    p, t = np.asarray(data["p"]), np.asarray(data["t"])
    for name, values in (("p", p), ("t", t)):
        if np.iscomplexobj(values):
            raise Damaged(f"its {name} holds complex numbers; expected real ones")
        if not np.issubdtype(values.dtype, np.number) or values.dtype == bool:
            raise Damaged(f"its {name} holds {values.dtype} values; expected numbers")
    p = p.astype(np.float64)
    if not np.all(np.isfinite(t)):
        raise Damaged("its t holds non-finite values; expected vertex indices")
    if t.size and np.any(np.asarray(t[:3], dtype=np.float64) % 1 != 0):
        raise Damaged("its t holds vertex indices that are not whole numbers")
    tri = np.asarray(t[:3], dtype=np.float64).T
    if tri.size and tri.min() < 1:
        raise Damaged(
            f"its t refers to vertex {tri.min():g}; indices are 1-based (1..{p.shape[1]})"
        )
    if tri.size and tri.max() > p.shape[1]:
        raise Damaged(
            f"its t refers to vertex {tri.max():g} but p has {p.shape[1]} vertices "
            "(indices are 1-based)"
        )
    tri = tri.astype(np.int64) - 1
    regions = np.asarray(t[3], dtype=np.int64) if t.shape[0] == 4 else np.ones(len(tri), int)
    points = p.T
    if points.shape[1] == 2:
        points = np.column_stack([points, np.zeros(len(points))])
    return points, tri, regions
