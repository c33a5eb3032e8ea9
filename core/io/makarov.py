"""MATLAB ``.mat`` files in the layout of S. N. Makarov's RWG codes.

``p`` is 3 x N float64 vertex coordinates (metres by default), ``t`` is
4 x M with 1-based vertex indices in rows 1–3 and 1 in row 4 (his
``rwg1.m`` drops triangles whose row 4 is above 1).
"""

from __future__ import annotations

import struct
from pathlib import Path

import numpy as np

from ..mesh import TriMesh
from .limits import MAX_CELLS, MAX_POINTS, Damaged, check_count

#: MATLAB classes that hold numbers (logical, char, cell and struct do not).
_NUMERIC = (
    "double",
    "single",
    "int8",
    "int16",
    "int32",
    "int64",
    "uint8",
    "uint16",
    "uint32",
    "uint64",
)


def makarov_arrays(mesh: TriMesh, per_mm: float) -> dict[str, np.ndarray]:
    """``{"p": (3, N) float64, "t": (4, M) float64}`` with ``p`` in the file's unit."""
    p = (np.asarray(mesh.points, dtype=np.float64) * per_mm).T
    t = np.ones((4, mesh.n_triangles), dtype=np.float64)
    t[:3] = mesh.triangles.T + 1
    return {"p": np.ascontiguousarray(p), "t": t}


def write_makarov(mesh: TriMesh, path: Path, per_mm: float) -> None:
    """Write ``p`` and ``t`` as a MATLAB v5 file."""
    import scipy.io  # here, not at the top: ``barymesh --help`` stays quick

    with open(path, "wb") as fh:
        # savemat writes to an open binary file too (its docs); the stubs name paths only
        scipy.io.savemat(fh, makarov_arrays(mesh, per_mm), format="5", oned_as="column")  # type: ignore[arg-type]


def read_makarov(path: Path) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """``(points (V, 3) in the file's unit, triangles (T, 3) 0-based, regions (T,))``.

    The variables' shapes and classes are checked (from the file's headers,
    before their data is read) against :mod:`barymesh.io.limits`; raises
    :class:`~barymesh.io.limits.Damaged` naming the problem when ``p`` or ``t`` is
    missing or malformed.
    """
    import scipy.io

    _check_v4_headers(path)
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
    for name, rows, limit, what in (
        ("p", (2, 3), MAX_POINTS, "vertices"),
        ("t", (3, 4), MAX_CELLS, "triangles"),
    ):
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
    triangles = tri.astype(np.int64) - 1
    regions = np.asarray(t[3], dtype=np.int64) if t.shape[0] == 4 else np.ones(len(tri), int)
    points = p.T
    if points.shape[1] == 2:
        points = np.column_stack([points, np.zeros(len(points))])
    return points, triangles, regions


#: MATLAB v4 precision digit -> bytes per value.
_V4_ITEMSIZE = {0: 8, 1: 4, 2: 4, 3: 2, 4: 2, 5: 1}


def _check_v4_headers(path: Path) -> None:
    """Walk the variable headers of a MATLAB v4 file; each must fit in the file.

    scipy trusts the sizes in v4 headers and allocates for them; v5 files
    (``MI``/``IM`` at bytes 126-128) are left to scipy, which checks them.
    """
    data = path.read_bytes()
    if len(data) >= 128 and data[126:128] in (b"IM", b"MI"):
        return
    pos = 0
    while pos < len(data):
        if pos + 20 > len(data):
            raise Damaged("it is not a MATLAB file (a variable header is cut short)")
        for order in "<>":
            mopt, rows, cols, imag, namelen = struct.unpack(f"{order}5i", data[pos : pos + 20])
            m, o, p, t = mopt // 1000, mopt // 100 % 10, mopt // 10 % 10, mopt % 10
            if 0 <= mopt < 5000 and m <= 4 and o == 0 and p in _V4_ITEMSIZE and t <= 2:
                break
        else:
            raise Damaged("it is not a MATLAB file (no v5 header and no valid v4 variable)")
        if rows < 0 or cols < 0 or imag not in (0, 1) or not 0 < namelen <= 64:
            raise Damaged("it is not a MATLAB file (a v4 variable header is invalid)")
        size = rows * cols * (1 + imag) * _V4_ITEMSIZE[p]
        pos += 20 + namelen + size
        if pos > len(data):
            raise Damaged(
                f"a MATLAB v4 variable declares {rows:,} x {cols:,} values but the "
                f"file has only {len(data):,} bytes"
            )
