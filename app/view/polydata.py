"""Layers as plain numpy arrays, wrapped as pyvista datasets on the thread that renders.

VTK objects are not thread-safe: a ``vtkPolyData`` made, changed or freed in a worker
thread while the GUI thread renders corrupts the heap (seen as ``malloc_consolidate():
unaligned fastbin chunk detected`` and aborts in the window and at exit). So worker
threads describe what to draw with :class:`Layer`, numpy arrays only, and the GUI thread
turns each into a ``pyvista.PolyData`` (:meth:`Layer.polydata`) when it shows it.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import TYPE_CHECKING

import numpy as np

from barymesh.quality import cell_figures

if TYPE_CHECKING:
    import pyvista as pv

    from barymesh.mesh import TriMesh


@dataclass(frozen=True, eq=False)
class Layer:
    """One layer of the scene as plain numpy arrays (made in any thread).

    At most one of ``lines`` and ``faces`` is given; with neither, the layer is
    the points themselves (centroid dots, label anchors). :meth:`polydata` wraps the
    arrays for VTK and must run on the thread that renders.

    Attributes
    ----------
    points : (n, 3) float64
    lines : (k, 2) int64, optional
        Vertex pairs of line cells.
    faces : (k, m) int64 or tuple of them, optional
        Vertex indices of k polygons of m corners each (triangles: m = 3); a tuple of
        such blocks for polygons of several sizes (pixels as squares beside triangles).
    cell_data : dict of str to (k,) array
        Per-cell arrays of ``faces`` (the colourings).
    """

    points: np.ndarray = field(default_factory=lambda: np.empty((0, 3)))
    lines: np.ndarray | None = None
    faces: np.ndarray | tuple[np.ndarray, ...] | None = None
    cell_data: dict[str, np.ndarray] = field(default_factory=dict)

    @property
    def n_points(self) -> int:
        return len(self.points)

    @property
    def face_blocks(self) -> tuple[np.ndarray, ...]:
        """``faces`` as a tuple of (k_i, m_i) blocks (empty without faces)."""
        if self.faces is None:
            return ()
        return tuple(self.faces) if isinstance(self.faces, tuple) else (self.faces,)

    @property
    def n_cells(self) -> int:
        if self.faces is not None:
            return sum(len(block) for block in self.face_blocks)
        return len(self.points) if self.lines is None else len(self.lines)

    def polydata(self) -> pv.PolyData:
        """The layer as a pyvista dataset (GUI thread only; shares the arrays)."""
        import pyvista as pv  # (here: a worker imports this module, never VTK)

        if self.n_points == 0 or self.n_cells == 0:
            return pv.PolyData()
        points = np.ascontiguousarray(self.points, dtype=np.float64)
        if self.faces is not None:
            blocks = [b for b in self.face_blocks if len(b)]
            if len(blocks) == 1:
                poly = pv.PolyData.from_regular_faces(points, blocks[0])
            else:  # VTK's flat layout: m, i_1, ..., i_m per polygon
                flat = np.concatenate(
                    [
                        np.column_stack([np.full(len(b), b.shape[1], dtype=np.int64), b]).ravel()
                        for b in blocks
                    ]
                )
                poly = pv.PolyData(points, faces=flat)
            for name, values in self.cell_data.items():
                poly.cell_data[name] = values
            return poly
        if self.lines is not None:
            # offsets and connectivity straight from the pairs: VTK's legacy "2, a, b" layout
            # was built and then converted back (a tenth of the time at 60,000 lines)
            poly = pv.PolyData()
            poly.points = points
            poly.lines = pv.CellArray.from_regular_cells(
                np.ascontiguousarray(self.lines, dtype=np.int64)
            )
            return poly
        return pv.PolyData(points)


def to_pyvista(mesh: TriMesh, wavelength: float | None = None) -> pv.PolyData:
    """The mesh as a ``pyvista.PolyData`` (VTK), with the cell data of ``mesh.to_meshio()``.

    Here, not in the core, which never imports VTK (it was ``TriMesh.to_pyvista`` up to
    barymesh 0.2). Made on the calling thread: call it where the dataset is used.

    Parameters
    ----------
    mesh : TriMesh
    wavelength : float, optional
        λ in mm: the cell data also get ``edge_wavelength``.

    Returns
    -------
    pyvista.PolyData
        ``points`` (V, 3) mm, one triangle per cell, ``cell_data`` the per-triangle figures
        of :func:`barymesh.quality.cell_figures` (``patch_id``, ``region``, ``area``,
        ``min_angle``, ``aspect_ratio``).

    Examples
    --------
    >>> from barymesh import MeshParams, build_mesh
    >>> poly = to_pyvista(build_mesh(MeshParams(structure="patch", subdivisions=2)))
    >>> poly.n_cells, sorted(poly.cell_data)
    (8, ['area', 'aspect_ratio', 'min_angle', 'patch_id', 'region'])
    """
    import pyvista as pv

    triangles = np.asarray(mesh.triangles, dtype=np.int64)
    poly = pv.PolyData.from_regular_faces(np.array(mesh.points, dtype=np.float64), triangles)
    for name, values in cell_figures(mesh, wavelength).items():
        poly.cell_data[name] = values
    return poly
