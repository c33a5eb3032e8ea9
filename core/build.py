"""The public entry point: parameters in, finished mesh out.

A build goes from :class:`barymesh.params.MeshParams` to :class:`barymesh.mesh.TriMesh`
through each of these modules once, in this order (``tests/test_core_build_path.py``
records the calls :func:`build_mesh` makes and checks it):

1. :mod:`barymesh.params`: what the parameters derive (whether the sizing
   chooses the subdivisions, the weld tolerance);
2. :mod:`barymesh.structures` (:func:`~barymesh.structures.layout`): the patch
   template (:mod:`barymesh.subdivision`), where each patch or sector goes, and
   the weld of coincident vertices (:mod:`barymesh.weld`), as a vertex map;
3. :mod:`barymesh.repeat`: the triangles, the template's copied on the vertex
   map (:func:`~barymesh.repeat.patch_triangles`), and the record of the
   repetition (:meth:`~barymesh.repeat.Repetition.of`), which keeps that map;
4. :mod:`barymesh.mesh`: the :class:`~barymesh.mesh.TriMesh`, arrays plus the
   record, with the parameters as provenance;
5. :mod:`barymesh.check` (:func:`~barymesh.check.check_mesh`): the invariants,
   read through the record.

A single primary triangle (``structure="triangle"``) takes
:mod:`barymesh.subdivision` instead of 2 and 3 (no patches, no record). With
``frequency`` or ``max_edge`` set, :mod:`barymesh.sizing` comes after 1 and runs
1 to 4 for each subdivision it tries, then 5 on the one it chooses.
"""

from __future__ import annotations

from collections.abc import Callable

import numpy as np

from .check import check_mesh
from .grading import graded_barycentric
from .mesh import TriMesh
from .params import MeshParams
from .repeat import Repetition, patch_triangles
from .repeat.copies import copies_triangles
from .sizing import sized_mesh
from .structures import layout
from .subdivision import subdivide
from .topology import INDEX


class BuildCancelled(Exception):
    """Raised by :func:`build_mesh` when its ``cancel`` callable asked it to stop."""


def build_mesh(
    params: MeshParams | None = None,
    *,
    cancel: Callable[[], bool] | None = None,
    neighbours: np.ndarray | None = None,
) -> TriMesh:
    """Mesh the structure described by ``params``.

    Parameters
    ----------
    params : MeshParams, optional
        Defaults to ``MeshParams()``, the paper's Fig. 12(a).
    cancel : callable, optional
        Called without arguments between the stages of the build (layout and weld,
        triangle assembly, finishing); when it returns True the build is abandoned
        with :class:`BuildCancelled`. A window uses it to drop a stale build.
    neighbours : (K, 4) float64, optional
        Rectangles (x0, y0, x1, y1, mm, in the structure's frame) of metal that continues
        the structure beyond its sides: its copies in the neighbouring cells of a
        periodic array (:func:`barymesh.cell.build_cell` passes them for a graded patch
        that reaches across its cell, a strip). A graded patch or conforming square ring
        does not crowd its nodes toward sides it shares with them (they are no metal
        edges); nothing else uses them.

    Returns
    -------
    TriMesh
        Finite, counter-clockwise, without flat triangles and, in conforming mode,
        manifold without duplicate vertices (:func:`barymesh.check.check_mesh`).

    Raises
    ------
    ValueError
        :class:`barymesh.invariants.MeshInvariantError` when the mesh breaks one of
        those invariants (a geometry the core cannot mesh, or a bug); with
        ``frequency`` or ``max_edge`` set, naming that parameter when no
        subdivision within the scheme's range and ``max_triangles`` meets it.

    Notes
    -----
    With ``params.frequency`` or ``params.max_edge`` set, ``params.subdivisions``
    is not used: the smallest n whose mesh has every edge at most the target is
    chosen (:func:`barymesh.sizing.sized_mesh`); ``mesh.params`` holds the parameters
    with that n, and ``mesh.stats()["subdivisions_chosen"]`` reports it.

    Examples
    --------
    >>> mesh = build_mesh(MeshParams(structure="patch", patch_size=10.0))
    >>> s = mesh.stats()
    >>> s["triangles"], s["vertices"], s["interior_edges"], s["boundary_edges"]
    (32, 25, 40, 16)
    """
    if params is None:
        params = MeshParams()
    if not isinstance(params, MeshParams):
        raise TypeError(f"params must be a MeshParams, got {type(params).__name__}")

    def checkpoint() -> None:
        if cancel is not None and cancel():
            raise BuildCancelled("the build was cancelled")

    if params.sized:
        return sized_mesh(params, lambda p: _assemble(p, checkpoint, neighbours), _check_chosen)
    mesh = _assemble(params, checkpoint, neighbours)
    check_mesh(mesh, params)
    return mesh


def _check_chosen(mesh: TriMesh) -> None:
    """The invariant check of a mesh whose subdivisions the sizing chose."""
    check_mesh(mesh, mesh.params)


def _assemble(
    params: MeshParams, checkpoint: Callable[[], None], neighbours: np.ndarray | None = None
) -> TriMesh:
    """The mesh of ``params`` at its ``subdivisions``, unchecked."""
    checkpoint()
    tolerance = params.weld_tolerance  # (a property: the parameters are read first)
    if params.structure == "triangle":
        return _triangle(params, tolerance)
    lay = layout(params, neighbours)
    checkpoint()
    if lay.points is not None:  # nothing welded, and the layout wrote the mesh's points
        points = lay.points
    else:
        # (x, y) pairs gathered as single 16-byte items: much faster than rows of a 2-D array
        flat = np.ascontiguousarray(lay.xy).reshape(-1, 2).view(np.complex128).ravel()
        points = np.zeros((len(lay.representative), 3))
        if len(lay.representative) == len(flat):  # nothing welded: every point is a vertex
            points[:, :2] = lay.xy.reshape(-1, 2)
        else:
            points[:, :2] = flat.take(lay.representative).view(np.float64).reshape(-1, 2)
    per_patch = len(lay.template.triangles)
    n_patches = len(lay.xy)
    vertex_map = lay.vertex_of_point.reshape(n_patches, -1)
    if lay.points is not None:  # nothing welded: patch p's vertices are p Nv ... p Nv + Nv - 1
        repetition = Repetition.unwelded(lay.template, n_patches)
    else:
        repetition = Repetition.of(lay.template, vertex_map, len(points))
    if repetition.kind == "copies":  # the template's triangles shifted by whole patches
        triangles = copies_triangles(lay.template, n_patches)
    else:
        triangles = patch_triangles(lay.template, vertex_map)
    checkpoint()
    mesh = TriMesh(
        points=points,
        triangles=triangles,
        patch_ids=_per_triangle(np.arange(n_patches, dtype=INDEX), per_patch),
        regions=_per_triangle(lay.regions, per_patch),
        n_patches=n_patches,
        mode=params.mode,
        tolerance=tolerance,
        patch_rects=lay.rects if params.mode == "paper" else None,
        repetition=repetition,
        params=params,
        min_angle_floor=lay.min_angle_floor,
    )
    if lay.columns is not None:  # the layout's copies of x and y, made with the points
        mesh.__dict__["columns"] = list(lay.columns)  # a frozen dataclass: not setattr
    return mesh


def _per_triangle(per_patch_values: np.ndarray, per_patch: int) -> np.ndarray:
    """(P Nt,) int: each patch's value repeated for its triangles (faster than np.repeat)."""
    values = np.asarray(per_patch_values).astype(INDEX, copy=False)
    out = np.empty((len(values), per_patch), dtype=INDEX)
    out[...] = values[:, None]
    return out.reshape(-1)


def _triangle(params: MeshParams, tolerance: float) -> TriMesh:
    """One primary triangle, subdivided."""
    if params.triangle_vertices is None:
        side = params.patch_size
        corners = np.array([[0.0, 0.0], [side, 0.0], [side / 2, side * np.sqrt(3) / 2]])
        corners += np.asarray(params.origin)
    else:
        corners = np.asarray(params.triangle_vertices, dtype=np.float64)
    bary, tri = subdivide(params.scheme, params.subdivisions)
    if params.grading:  # nodes crowded toward the three edges (uniform scheme)
        bary = graded_barycentric(bary, params.subdivisions)
    p0, p1, p2 = corners
    xy = p0 + bary[:, :1] * (p1 - p0) + bary[:, 1:] * (p2 - p0)
    if (p1[0] - p0[0]) * (p2[1] - p0[1]) - (p1[1] - p0[1]) * (p2[0] - p0[0]) < 0:
        tri = tri[:, [0, 2, 1]]  # keep counter-clockwise seen from +z
    return TriMesh(
        points=np.column_stack([xy, np.zeros(len(xy))]),
        triangles=tri,
        patch_ids=np.zeros(len(tri), dtype=INDEX),
        regions=np.ones(len(tri), dtype=INDEX),
        n_patches=1,
        mode=params.mode,
        tolerance=tolerance,
        patch_rects=None,
        params=params,
    )
