"""A surface current on a triangle mesh as a VTU file for ParaView (meshio).

Cell data per triangle: ``J_abs`` (A/m), ``J_real`` and ``J_imag`` (3 components each),
and any further arrays given (e.g. ``charge_abs``).
"""

from __future__ import annotations

from pathlib import Path
from typing import Any

import numpy as np

from .atomic import atomic_path

__all__ = ["write_current_vtu"]


def write_current_vtu(
    path: str | Path, mesh: Any, current_density: np.ndarray, **cell_data: np.ndarray
) -> None:
    """Write ``current_density`` (T, 3) complex, one value per triangle of ``mesh``, to ``path``.

    Parameters
    ----------
    path : str or Path
        A ``.vtu`` file, written atomically.
    mesh : TriMesh
        ``points`` (V, 3) mm and ``triangles`` (T, 3).
    current_density : (T, 3) complex
        J at the centroids (A/m).
    **cell_data : (T,) or (T, k) float
        More arrays per triangle, written under their keyword.
    """
    import meshio

    j = np.asarray(current_density)
    triangles = np.asarray(mesh.triangles, dtype=np.int64)
    if j.shape != (len(triangles), 3):
        raise ValueError(
            f"current_density has shape {j.shape}; expected ({len(triangles)}, 3), one "
            "3-vector per triangle"
        )
    data = {
        "J_abs": [np.linalg.norm(j, axis=1)],
        "J_real": [np.ascontiguousarray(j.real)],
        "J_imag": [np.ascontiguousarray(j.imag)],
    }
    data.update({name: [np.asarray(value)] for name, value in cell_data.items()})
    with atomic_path(path) as tmp:
        meshio.write(
            str(tmp),
            meshio.Mesh(mesh.points, [("triangle", triangles)], cell_data=data),
            file_format="vtu",
        )
