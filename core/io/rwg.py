"""The RWG table and the triangle connectivity as ``.npz`` or CSV.

All indices are 0-based (vertices and triangles as in the mesh file written
alongside). Lengths and centroids are in the chosen unit.

``.npz`` keys
    ``unit`` (str), ``points`` (V, 3), ``triangles`` (T, 3), ``centroids`` (T, 3),
    ``areas`` (T,), ``edge`` (N,), ``vertices`` (N, 2), ``t_plus``, ``t_minus``,
    ``free_vertex_plus``, ``free_vertex_minus``, ``length`` (N,) and the
    connectivity matrix as triplets ``connectivity_row``, ``connectivity_col``,
    ``connectivity_data`` with ``connectivity_shape`` (2,).

CSV
    ``NAME.csv`` holds the RWG table (one row per interior edge), and two
    files beside it hold ``NAME_connectivity.csv`` (row, col, value) and
    ``NAME_centroids.csv`` (triangle, x, y, z, area).
"""

from __future__ import annotations

import io
from collections.abc import Callable
from pathlib import Path

import numpy as np

from ..mesh import TriMesh
from .atomic import atomic_paths

RWG_COLUMNS = (
    "edge",
    "vertex_1",
    "vertex_2",
    "t_plus",
    "t_minus",
    "free_vertex_plus",
    "free_vertex_minus",
    "length",
)


def rwg_arrays(mesh: TriMesh, per_mm: float, unit: str) -> dict[str, np.ndarray]:
    """Everything the ``.npz`` holds, as a dict of arrays (see the module docstring)."""
    rwg = mesh.rwg
    conn = mesh.connectivity.tocoo()
    return {
        "unit": np.array(unit),
        "points": np.asarray(mesh.points) * per_mm,
        "triangles": np.asarray(mesh.triangles),
        "centroids": np.asarray(mesh.centroids) * per_mm,
        "areas": np.asarray(mesh.areas) * per_mm**2,
        "edge": np.asarray(rwg.edge),
        "vertices": np.asarray(rwg.vertices),
        "t_plus": np.asarray(rwg.t_plus),
        "t_minus": np.asarray(rwg.t_minus),
        "free_vertex_plus": np.asarray(rwg.free_vertex_plus),
        "free_vertex_minus": np.asarray(rwg.free_vertex_minus),
        "length": np.asarray(rwg.length) * per_mm,
        "connectivity_row": conn.row.astype(np.int64),
        "connectivity_col": conn.col.astype(np.int64),
        "connectivity_data": conn.data,
        "connectivity_shape": np.array(conn.shape, dtype=np.int64),
    }


def write_rwg_npz(mesh: TriMesh, path: Path, per_mm: float, unit: str) -> None:
    """Write the RWG bundle as an uncompressed ``.npz``."""
    with open(path, "wb") as fh:
        # the keys are array names (never savez's allow_pickle), so ** passes arrays only
        np.savez(fh, **rwg_arrays(mesh, per_mm, unit))  # type: ignore[arg-type]


def _csv(header: str, columns: list[np.ndarray], fmts: list[str]) -> str:
    buf = io.StringIO()
    table: np.ndarray | list[float] = (
        np.column_stack([np.asarray(c, dtype=np.float64) for c in columns]) if columns else []
    )
    np.savetxt(buf, table, fmt=fmts, delimiter=",", header=header, comments="")
    return buf.getvalue()


def csv_tables(mesh: TriMesh, per_mm: float, unit: str) -> dict[str, str]:
    """``{"": rwg table, "_connectivity": triplets, "_centroids": centroids}`` as CSV text."""
    rwg = mesh.rwg
    conn = mesh.connectivity.tocoo()
    c = np.asarray(mesh.centroids) * per_mm
    header = ",".join(RWG_COLUMNS[:-1]) + f",length_{unit}"
    rwg_cols = [
        rwg.edge,
        rwg.vertices[:, 0],
        rwg.vertices[:, 1],
        rwg.t_plus,
        rwg.t_minus,
        rwg.free_vertex_plus,
        rwg.free_vertex_minus,
        np.asarray(rwg.length) * per_mm,
    ]
    return {
        "": _csv(header, rwg_cols, ["%d"] * 7 + ["%.17g"]),
        "_connectivity": _csv(
            "row,col,value", [conn.row, conn.col, conn.data], ["%d", "%d", "%.17g"]
        ),
        "_centroids": _csv(
            f"triangle,x_{unit},y_{unit},z_{unit},area_{unit}2",
            [
                np.arange(mesh.n_triangles),
                c[:, 0],
                c[:, 1],
                c[:, 2],
                np.asarray(mesh.areas) * per_mm**2,
            ],
            ["%d"] + ["%.17g"] * 4,
        ),
    }


def csv_paths(path: Path) -> dict[str, Path]:
    """The three CSV files written for ``path``: the RWG table and its two companions."""
    return {
        key: path.with_name(f"{path.stem}{key}{path.suffix}")
        for key in ("", "_connectivity", "_centroids")
    }


def write_rwg_csv(
    mesh: TriMesh,
    path: Path,
    per_mm: float,
    unit: str,
    before_rename: Callable[[], None] | None = None,
) -> None:
    """Write the three CSV files as one set: all to temporary files, then all renamed.

    ``before_rename()``, if given, runs once all are written; an exception from it
    (a cancelled export) removes the temporary files and leaves the targets alone.
    """
    paths = csv_paths(path)
    keys = ("", "_connectivity", "_centroids")
    with atomic_paths([paths[key] for key in keys]) as tmps:
        tables = csv_tables(mesh, per_mm, unit)
        for key, tmp in zip(keys, tmps, strict=True):
            tmp.write_text(tables[key], encoding="utf-8")
        if before_rename is not None:
            before_rename()
