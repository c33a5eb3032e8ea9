"""Unwelded copies of one patch: patch p owns vertices p Nv … p Nv + Nv − 1.

A paper mesh whose patches share no vertex (nothing welded) is the template
copied patch after patch, every id shifted by whole patches::

    template (Nv vertices, Nt triangles, Ne edges)     copy p of P
    local vertex   l                         ->  vertex    p Nv + l
    local triangle t                         ->  triangle  p Nt + t
    template edge  e                         ->  edge      p Ne + e
    -1 (no triangle, no free vertex)         ->  -1

    vertex_map = [[0,      1,      …, Nv − 1    ],     (the identity, row by row:
                  [Nv,     Nv + 1, …, 2 Nv − 1  ],      :func:`is_unwelded_copies`)
                  …
                  [(P−1)Nv,        …, P Nv − 1  ]]

Every array is the template's, written once per copy with its ids shifted
(:func:`fill_tiled`); no gather or sort of the size of the mesh. Up to a block, the
template's rows are kept flat with the template (:func:`template_plan`) and the
arrays of one width written together, in one broadcast add. When the
patches are also translations of one another (the paper's rings), their
edge lengths and triangle quality are the first patch's
(:func:`translated_copy_measures`). The results equal the general paths of
:mod:`barymesh.topology` and :mod:`barymesh.quality` (bit for bit; the
aggregates to 1e-13) in ``tests/test_core_chain_paths.py`` and
``tests/test_core_fast_paths.py``.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import TYPE_CHECKING, Any

import numpy as np

from ..invariants import FLAT
from ..quality import triangle_quality
from ..subdivision import PatchTemplate
from ..topology import (
    BLOCK,
    INDEX,
    EdgeTopology,
    RWGTable,
    adjacency_without_junctions,
    segment_lengths,
)
from .compiled import axes_of, kernels
from .patches import patch_topology

if TYPE_CHECKING:
    import scipy.sparse as sp

#: Translated copies stand in for the full computation only when every patch's vertices,
#: relative to its first, are within this fraction of the shortest side of where the
#: first patch has them (rounding included). On random paper rings the aggregates then
#: differ from the full computation by at most a quarter of this (below 1e-13).
COPY_TOLERANCE = 2.5e-13
#: The machine epsilon of float64 (``np.finfo`` is a Python-level lookup on every call).
_EPS = float(np.finfo(np.float64).eps)
#: ``a.max()``, ``a.min()``, ``np.max(list)`` without their Python wrappers (``_methods``,
#: ``fromnumeric``): the same reductions, NaN included, without Python frames that run
#: cold once per build; pass ``axis=None`` for all of an array.
_HI, _LO = np.maximum.reduce, np.minimum.reduce

#: Topologies of the templates seen last, by identity (templates are cached, so the
#: same object recurs; the topology, RWG table and connectivity of a build all need it).
_TEMPLATE_TOPOLOGIES: dict[int, tuple[PatchTemplate, EdgeTopology]] = {}
_TEMPLATE_ADJACENCY: dict[int, tuple[PatchTemplate, sp.csr_matrix | None]] = {}
_TEMPLATE_PLANS: dict[int, tuple[PatchTemplate, CopyPlan]] = {}


def is_unwelded_copies(vertex_map: np.ndarray) -> bool:
    """Whether patch p's local vertex l is vertex p Nv + l, for every entry (block by block).

    >>> is_unwelded_copies(np.arange(6).reshape(2, 3)), is_unwelded_copies(np.zeros((2, 3)))
    (True, False)
    """
    n_p, nv = vertex_map.shape
    rows = max(1, BLOCK // max(nv, 1))
    local = np.arange(nv, dtype=INDEX)
    for lo in range(0, n_p, rows):
        ids = vertex_map[lo : lo + rows]
        base = (np.arange(lo, lo + len(ids), dtype=INDEX) * INDEX(nv))[:, None]
        if not np.array_equal(ids - base, np.broadcast_to(local, ids.shape)):
            return False
    return True


def template_topology(template: PatchTemplate) -> EdgeTopology:
    """The topology of one copy of ``template`` (vertices 0 … Nv − 1), free vertices included.

    Kept for the last few templates (by identity): a build asks for it three times
    (topology, RWG table, connectivity), and at small sizes making it was a third of
    the build. Its arrays are read-only, shared by every caller.
    """
    found = _TEMPLATE_TOPOLOGIES.get(id(template))
    if found is not None and found[0] is template:
        return found[1]
    nv = len(template.uv)
    topo = patch_topology(template, np.arange(nv, dtype=INDEX)[None], nv)
    for name in ("edges", "triangle_edges", "edge_triangles", "valence", "free_vertices"):
        array = getattr(topo, name)
        if array is not None:
            array.flags.writeable = False
    if len(_TEMPLATE_TOPOLOGIES) >= 16:
        _TEMPLATE_TOPOLOGIES.pop(next(iter(_TEMPLATE_TOPOLOGIES)))
    _TEMPLATE_TOPOLOGIES[id(template)] = (template, topo)
    return topo


def template_adjacency(template: PatchTemplate) -> sp.csr_matrix | None:
    """The connectivity matrix of one copy of ``template``, kept as its topology is.

    :func:`barymesh.topology.adjacency_without_junctions` of :func:`template_topology`;
    None when two of its triangles share two edges. Read-only: shared by every caller.
    """
    found = _TEMPLATE_ADJACENCY.get(id(template))
    if found is not None and found[0] is template:
        return found[1]
    local = adjacency_without_junctions(len(template.triangles), template_topology(template))
    if local is not None:
        for array in (local.data, local.indices, local.indptr):
            array.flags.writeable = False
    if len(_TEMPLATE_ADJACENCY) >= 16:
        _TEMPLATE_ADJACENCY.pop(next(iter(_TEMPLATE_ADJACENCY)))
    _TEMPLATE_ADJACENCY[id(template)] = (template, local)
    return local


@dataclass(frozen=True)
class CopyPlan:
    """One template's rows as every copy writes them, shifts per copy alongside.

    Derived from the template alone (:func:`template_plan` keeps it with the template's
    topology), so that a build writes the arrays of all its copies in a few numpy calls,
    not a slicing, conversion and check per array: the arrays of one width and their
    shifts per copy go through a single broadcast add. Read-only, shared by every caller.

    Attributes
    ----------
    incidence : (3, 2 Ne) int
        Template ``edges``, ``edge_triangles`` and ``free_vertices``, flattened.
    incidence_steps : (3, 1) int
        What one copy shifts each of them by: Nv, Nt, Nv.
    missing : tuple of two (k,) intp
        Where ``edge_triangles`` and ``free_vertices`` (flattened) hold -1, which stays.
    triangles, triangle_edges : (3 Nt,) int
        The template's, flattened.
    interior : (5, K) int
        The RWG rows (valence 2) of the template: edge id, T+, T−, free vertex of T+
        and of T− (never -1 on an interior edge).
    interior_steps : (5, 1) int
        Their shifts per copy: Ne, Nt, Nt, Nv, Nv.
    interior_vertices : (2 K,) int
        The interior edges' vertex pairs, flattened.
    ends : (2, K) intp
        The same pairs as the rows start, end (:func:`copies_lengths`).
    """

    incidence: np.ndarray
    incidence_steps: np.ndarray
    missing: tuple[np.ndarray, np.ndarray]
    triangles: np.ndarray
    triangle_edges: np.ndarray
    interior: np.ndarray
    interior_steps: np.ndarray
    interior_vertices: np.ndarray
    ends: np.ndarray


def template_plan(template: PatchTemplate) -> CopyPlan:
    """The :class:`CopyPlan` of ``template``, kept for the last few templates as its topology is."""
    found = _TEMPLATE_PLANS.get(id(template))
    if found is not None and found[0] is template:
        return found[1]
    local = template_topology(template)
    assert local.free_vertices is not None  # a template's topology has them
    nv, nt, ne = len(template.uv), len(template.triangles), len(local.edges)
    rows = np.flatnonzero(local.valence == 2)
    pairs = local.edges[rows]
    flat = [
        np.ascontiguousarray(a, dtype=INDEX).reshape(-1)
        for a in (local.edges, local.edge_triangles, local.free_vertices)
    ]
    plan = CopyPlan(
        incidence=np.stack(flat),
        incidence_steps=np.array([[nv], [nt], [nv]], dtype=INDEX),
        missing=(np.flatnonzero(flat[1] < 0), np.flatnonzero(flat[2] < 0)),
        triangles=np.ascontiguousarray(template.triangles, dtype=INDEX).reshape(-1),
        triangle_edges=np.ascontiguousarray(local.triangle_edges, dtype=INDEX).reshape(-1),
        interior=np.stack(
            [
                rows.astype(INDEX),
                *(local.edge_triangles[rows].T.astype(INDEX)),
                *(local.free_vertices[rows].T.astype(INDEX)),
            ]
        ),
        interior_steps=np.array([[ne], [nt], [nt], [nv], [nv]], dtype=INDEX),
        interior_vertices=np.ascontiguousarray(pairs, dtype=INDEX).reshape(-1),
        ends=np.ascontiguousarray(pairs.T, dtype=np.intp),
    )
    for name, array in vars(plan).items():
        for a in array if name == "missing" else (array,):
            a.flags.writeable = False
    if len(_TEMPLATE_PLANS) >= 16:
        _TEMPLATE_PLANS.pop(next(iter(_TEMPLATE_PLANS)))
    _TEMPLATE_PLANS[id(template)] = (template, plan)
    return plan


def copies_topology(
    local: EdgeTopology,
    n_patches: int,
    n_vertices: int,
    n_tri: int,
    plan: CopyPlan | None = None,
) -> EdgeTopology:
    """Topology of ``n_patches`` unwelded copies of one patch, patch p's vertices from p Nv.

    Every edge is a template edge of one copy: the template's arrays shifted by
    p times the vertices, triangles and edges of a patch, written once each
    (no gathers). The same arrays as :func:`barymesh.repeat.patches.patch_topology` on an
    identity vertex map, bit for bit.

    Parameters
    ----------
    local : EdgeTopology
        The template's topology, edges ascending within each pair, free vertices
        filled in, no junctions.
    n_patches : int
    n_vertices : int
        Vertices of one patch (Nv).
    n_tri : int
        Triangles of one patch.
    plan : CopyPlan, optional
        The template's :func:`template_plan`: with it, up to a block of copies per array
        are written in a few numpy calls (the same values).
    """
    n_loc = len(local.edges)
    valence = np.empty((n_patches, n_loc), dtype=INDEX)
    assert local.free_vertices is not None  # a template's topology has them
    valence[...] = local.valence
    if plan is not None and n_patches * 2 * n_loc <= BLOCK:
        # edges, edge triangles and free vertices (2 Ne per copy each) in one add
        shift = np.arange(n_patches, dtype=INDEX)
        incidence = np.empty((3, n_patches, 2 * n_loc), dtype=INDEX)
        np.add(
            plan.incidence[:, None, :], (shift * plan.incidence_steps)[:, :, None], out=incidence
        )
        for rows, missing in zip(incidence[1:], plan.missing, strict=True):
            if len(missing):
                rows[:, missing] = -1
        edges, edge_triangles, free = (a.reshape(-1, 2) for a in incidence)
        return EdgeTopology(
            edges=edges,
            triangle_edges=shifted(plan.triangle_edges, shift, n_loc).reshape(-1, 3),
            edge_triangles=edge_triangles,
            valence=valence.reshape(-1),
            junction_incidence=np.empty((0, 2), dtype=INDEX),
            free_vertices=free,
        )
    return EdgeTopology(
        edges=tiled(local.edges, n_patches, n_vertices),
        triangle_edges=tiled(local.triangle_edges, n_patches, n_loc),
        edge_triangles=tiled(local.edge_triangles, n_patches, n_tri),
        valence=valence.reshape(-1),
        junction_incidence=np.empty((0, 2), dtype=INDEX),
        free_vertices=tiled(local.free_vertices, n_patches, n_vertices),
    )


def copies_triangles(template: PatchTemplate, n_patches: int) -> np.ndarray:
    """(P Nt, 3) int: the triangles of ``n_patches`` unwelded copies of ``template``.

    ``tiled(template.triangles, n_patches, Nv)``; up to a block, one add of the
    template's flat triangles (:func:`template_plan`) and each copy's shift.
    """
    nv = len(template.uv)
    if n_patches * 3 * len(template.triangles) <= BLOCK:
        flat = template_plan(template).triangles
        return shifted(flat, np.arange(n_patches, dtype=INDEX), nv).reshape(-1, 3)
    return tiled(template.triangles, n_patches, nv)


def tiled(a: np.ndarray, n_patches: int, step: int) -> np.ndarray:
    """``a`` once per patch, patch p's ids (not the -1 entries) shifted by p ``step``."""
    out = np.empty((n_patches,) + a.shape, dtype=INDEX)
    fill_tiled(out.reshape(-1), a, n_patches, step, 0)
    return out.reshape((-1,) + a.shape[1:])


def shifted(flat: np.ndarray, shift: np.ndarray, step: int) -> np.ndarray:
    """(P, K) int: the flat template row ``flat`` (no -1 entries), shifted ``step`` per copy.

    ``shift`` is ``arange(P)``; one add within a block (:func:`fill_tiled`'s small case,
    without its checks: the caller's template is known).
    """
    out = np.empty((len(shift), len(flat)), dtype=INDEX)
    np.add(flat, (shift * INDEX(step))[:, None], out=out)
    return out


def fill_tiled(out: np.ndarray, a: np.ndarray, copies: int, step: int, base: int) -> None:
    """Write ``copies`` copies of ``a`` into the flat ``out``, copy k's ids plus k ``step`` + base.

    Entries of -1 (none) stay -1. Within one block (at most :data:`BLOCK` values
    in all), ``out`` seen as (copies, len(a)) rows is ``a`` plus each row's shift,
    then the -1 columns put back: no pattern to build, which at small sizes cost
    as much as the copies. Beyond a block a pattern of whole copies is made once
    and added block by block: long, contiguous adds of one shift each, faster
    than a broadcast whose every row is a short inner loop.
    """
    flat = np.ascontiguousarray(a, dtype=INDEX).reshape(-1)
    k = len(flat)
    if copies == 0 or k == 0:
        return
    if copies * k <= BLOCK:  # few numpy calls: at small sizes their overhead is the cost
        step, base = int(step), int(base)
        if step > 0:  # base, base + step, ...: arange's own products, exact in int32
            shift = np.arange(base, base + copies * step, step, dtype=INDEX)
        else:
            shift = np.arange(copies, dtype=INDEX) * INDEX(step) + INDEX(base)
        rows = out[: copies * k].reshape(copies, k)
        np.add(flat, shift[:, None], out=rows)  # one pass over the output, not two
        if flat.min() < 0:
            rows[:, np.flatnonzero(flat < 0)] = -1
        return
    missing = flat < 0
    per = max(1, min(copies, BLOCK // k))  # copies per block
    ramp = np.repeat(np.arange(per, dtype=INDEX) * INDEX(step), k)
    if missing.any():
        keep = np.tile(~missing, per).astype(INDEX)  # 0 where -1 must stay
        pattern = np.tile(flat, per) + ramp * keep + INDEX(base) * keep
    else:
        keep = None
        pattern = np.tile(flat, per) + ramp + INDEX(base)
    for lo in range(0, copies, per):
        n = min(per, copies - lo) * k
        block = out[lo * k : lo * k + n]
        if keep is None:
            np.add(pattern[:n], INDEX(lo * step), out=block)
        else:
            np.multiply(keep[:n], INDEX(lo * step), out=block)
            block += pattern[:n]


def copies_rwg(
    local: EdgeTopology,
    n_patches: int,
    n_vertices: int,
    n_tri: int,
    points: np.ndarray,
    columns: list[np.ndarray] | None = None,
    plan: CopyPlan | None = None,
) -> RWGTable:
    """The RWG table of the topology :func:`copies_topology` makes, without gathers.

    :func:`barymesh.topology.rwg_table` of that topology, bit for bit.

    The template's interior edges, copy after copy; only the lengths are
    measured. Parameters as for :func:`copies_topology`, plus the mesh's
    ``points`` (and ``columns``, see :func:`barymesh.topology.segment_lengths`), and
    the template's ``plan`` (see :func:`copies_topology`).
    """
    assert local.free_vertices is not None  # a template's topology has them
    if plan is not None and n_patches * 2 * len(plan.ends[0]) <= BLOCK:
        # the five (K,) rows of a copy in one add, the vertex pairs (2 K) in another
        k = len(plan.ends[0])
        shift = np.arange(n_patches, dtype=INDEX) * plan.interior_steps  # (5, P)
        ids = np.empty((5, n_patches, k), dtype=INDEX)
        np.add(plan.interior[:, None, :], shift[:, :, None], out=ids)
        vertices = np.empty((n_patches, 2 * k), dtype=INDEX)
        np.add(plan.interior_vertices, shift[3][:, None], out=vertices)
        edge, t_plus, t_minus, free_plus, free_minus = (a.reshape(-1) for a in ids)
        return RWGTable(
            edge=edge,
            vertices=vertices.reshape(-1, 2),
            t_plus=t_plus,
            t_minus=t_minus,
            free_vertex_plus=free_plus,
            free_vertex_minus=free_minus,
            length=copies_lengths(
                plan.ends.T, n_patches, n_vertices, points, columns, ends=plan.ends
            ),
        )
    rows = np.flatnonzero(local.valence == 2)
    vertices = tiled(local.edges[rows], n_patches, n_vertices)
    return RWGTable(
        edge=tiled(rows.astype(INDEX), n_patches, len(local.edges)),
        vertices=vertices,
        t_plus=tiled(local.edge_triangles[rows, 0], n_patches, n_tri),
        t_minus=tiled(local.edge_triangles[rows, 1], n_patches, n_tri),
        free_vertex_plus=tiled(local.free_vertices[rows, 0], n_patches, n_vertices),
        free_vertex_minus=tiled(local.free_vertices[rows, 1], n_patches, n_vertices),
        length=copies_lengths(local.edges[rows], n_patches, n_vertices, points, columns),
    )


def copies_lengths(
    pairs: np.ndarray,
    n_patches: int,
    n_vertices: int,
    points: np.ndarray,
    columns: list[np.ndarray] | None = None,
    ends: np.ndarray | None = None,
) -> np.ndarray:
    """Lengths of the template segments ``pairs`` in each of ``n_patches`` unwelded copies.

    :func:`barymesh.topology.segment_lengths` of ``tiled(pairs, n_patches, n_vertices)``,
    bit for bit (the same differences, squares and sums in the same order), without
    that tiled index: copy p's vertices are rows p of each coordinate column seen as
    (P, Nv), so a block of copies is read by slicing and its segments' ends taken
    along the rows with the template's (K,) pairs. The general path gathers through
    two index arrays of the mesh's size, converted to ``intp`` first; this reads
    each coordinate once per block, from cache.

    Parameters
    ----------
    pairs : (K, 2) int
        Local vertex pairs of the template's segments.
    n_patches : int
    n_vertices : int
        Vertices of one copy (Nv).
    points : (P Nv, 2 or 3) float64
        The mesh's points, copy p's from p Nv.
    columns : list of (P Nv,) float64, optional
        Contiguous coordinate columns of ``points`` (all-zero ones may be left out).
    ends : (2, K) intp, optional
        ``pairs`` as contiguous start and end rows, when the caller keeps them
        (:attr:`CopyPlan.ends`).

    Returns
    -------
    (P K,) float64
        Copy after copy, segment k of copy p at p K + k.
    """
    if columns is None:
        columns = [np.ascontiguousarray(points[:, axis]) for axis in range(points.shape[1])]
    if ends is None:
        ends = np.array([pairs[:, 0], pairs[:, 1]], dtype=np.intp)
    start, end = ends
    k = len(start)
    compiled = kernels(n_patches * k)
    if compiled is not None:  # the same sums, each length written once
        found = np.empty(n_patches * k)
        padded, active = axes_of(columns)
        compiled.copies_lengths(*padded, active, n_patches, n_vertices, start, end, found)
        return found
    axes = [x.reshape(n_patches, n_vertices) for x in columns if np.logical_or.reduce(x)]
    if not axes:  # every point at the origin
        return np.zeros(n_patches * k)
    total = np.empty((n_patches, k))
    rows = max(1, BLOCK // max(k, 1))
    for lo in range(0, n_patches, rows):
        acc = total[lo : lo + rows]
        for axis, x in enumerate(axes):
            block = x[lo : lo + rows]
            d = block.take(end, axis=1)
            d -= block.take(start, axis=1)
            if axis == 0:  # the first square written, not added to zeros (0 + s is s)
                np.multiply(d, d, out=acc)
            else:
                d *= d
                acc += d
    return np.sqrt(total, out=total).reshape(-1)


def copies_adjacency(local: sp.csr_matrix, n_patches: int) -> sp.csr_matrix:
    """The connectivity matrix of ``n_patches`` unwelded copies of one patch.

    Block diagonal: the patch's matrix ``local`` (sorted rows, as
    :func:`barymesh.topology.triangle_adjacency` makes them) once per copy, its column ids
    shifted by the patch's triangles; the same matrix as
    :func:`barymesh.topology.triangle_adjacency` on the whole mesh, array for array.
    """
    import scipy.sparse as sp

    n_tri = local.shape[0]
    # row pointers tiled too: copy p's rows start p nnz after the template's
    indptr = np.zeros(n_patches * n_tri + 1, dtype=INDEX)
    local_indices = local.indices.astype(INDEX, copy=False)
    if n_patches * max(local.nnz, n_tri) <= BLOCK:  # one add each (fill_tiled's small case)
        shift = np.arange(n_patches, dtype=INDEX)
        starts = local.indptr[1:].astype(INDEX, copy=False)
        np.add(starts, (shift * INDEX(local.nnz))[:, None], out=indptr[1:].reshape(n_patches, -1))
        indices = shifted(local_indices, shift, n_tri).reshape(-1)
    else:
        fill_tiled(indptr[1:], local.indptr[1:], n_patches, local.nnz, 0)
        indices = tiled(local_indices, n_patches, n_tri)
    data = np.empty(len(indices), dtype=np.int8)
    data.fill(1)  # np.ones, without its Python frame
    return sp.csr_matrix((data, indices, indptr), shape=(n_patches * n_tri,) * 2)


def copy_slack(n_vertices: int, columns: list[np.ndarray]) -> float | None:
    """How far unwelded copies are from translations of the first one, rounding included.

    For every patch p and local vertex l, the coordinates of l relative to the
    patch's vertex 0 are compared with the first patch's; the largest difference,
    plus the rounding of the two subtractions that found it (twice the machine
    epsilon times the largest coordinate), bounds how far the exact relative
    positions of any patch are from the first patch's. Reading every coordinate
    once, block by block, this is the one pass over the points that
    :func:`translated_copy_measures` and :func:`translated_copies_sound` need.

    Parameters
    ----------
    n_vertices : int
        Vertices of one patch (Nv).
    columns : list of (P Nv,) float64
        Contiguous x, y (and z unless all zero) columns of the points, patch p's
        from p Nv (:func:`is_unwelded_copies`).

    Returns
    -------
    float or None
        The bound (mm), NaN when a coordinate is not finite; None when the
        points are not whole patches of ``n_vertices``.
    """
    nv = n_vertices
    n_p = len(columns[0]) // nv if nv else 0
    if n_p == 0 or n_p * nv != len(columns[0]):
        return None
    compiled = kernels(len(columns[0]))
    if compiled is not None and len(columns) <= 3:  # one pass, no temporaries
        padded = [*columns, *[np.zeros(0)] * (3 - len(columns))]
        return float(compiled.copy_slack(*padded, len(columns), nv))
    rows = max(1, BLOCK // nv)
    if n_p <= rows:  # one block: every column at once, in a few calls on one (C, P, Nv) array
        with np.errstate(invalid="ignore", over="ignore"):  # an infinity makes the bound NaN
            rel = np.array(columns).reshape(len(columns), n_p, nv)
            extent = _HI(np.array([_HI(rel, axis=None), -_LO(rel, axis=None)]))
            rel -= rel[:, :, :1]  # each vertex relative to its patch's vertex 0 ...
            rel -= rel[:, :1]  # ... minus the first patch's (numpy copies an overlapping operand)
            return float(
                _HI(np.array([_HI(rel, axis=None), -_LO(rel, axis=None)])) + 2.0 * _EPS * extent
            )
    # reductions gathered into arrays, so that a NaN anywhere makes the bound NaN
    extent = _HI(np.array([[_HI(x), -_LO(x)] for x in columns]), axis=None)
    deviations = []
    blocks = [x.reshape(n_p, nv) for x in columns]
    with np.errstate(invalid="ignore", over="ignore"):  # an infinity makes the bound NaN
        firsts = [x[0] - x[0, 0] for x in blocks]
        for lo in range(0, n_p, rows):
            for x, first in zip(blocks, firsts, strict=True):
                block = x[lo : lo + rows]
                rel = block - block[:, :1]
                rel -= first
                deviations += [_HI(rel, axis=None), -_LO(rel, axis=None)]
    return float(_HI(np.array(deviations)) + 2.0 * _EPS * extent)


def translated_copies_sound(
    template: PatchTemplate, columns: list[np.ndarray], slack: float | None
) -> bool:
    """Whether no triangle of translated copies can be clockwise or flat: the first
    patch's triangles clear the test by more than the copies can differ.

    :func:`barymesh.invariants.inverted_or_flat` flags a triangle whose twice
    area (cross product of two sides, as computed) is not at least ``2 FLAT``
    times its longest side squared. In every copy, each exact vertex position
    relative to the patch's vertex 0 is within ``slack`` (:func:`copy_slack`) of
    the first patch's, so a side differs by at most 2√2 ``slack`` and the cross
    product by at most 12 L ``slack`` + 8 ``slack``² (L the longest side); the
    computed cross product adds the rounding of differences of coordinates up
    to the largest one (``extent``) and of two products: a few ε (extent + L) L.
    When each of the first patch's triangles clears the test by 64 L (1.5 ``slack``
    + ε L), at least 64 L (``slack`` + ε (extent + L)) since :func:`copy_slack` adds
    2 ε extent to ``slack``, well above the sum of those, no triangle of any copy can
    be flagged, and the per-triangle pass (:func:`barymesh.repeat.inverted_or_flat_patches`)
    would find nothing: the answer is known without it. False (run the pass)
    when the copies are not translations to :data:`COPY_TOLERANCE`, when
    something is not finite, or when a triangle is too near the limit to tell.

    Parameters
    ----------
    template : PatchTemplate
    columns : list of (P Nv,) float64
        x and y (planar meshes only: with a z column this returns False).
    slack : float or None
        :func:`copy_slack` of the same columns (which bounds ε times their extent).
    """
    nv = len(template.uv)
    if slack is None or len(columns) != 2 or not len(template.triangles):
        return False
    # the first patch's corners (x or y, corner, triangle), then the sides u (corner 0 to
    # 1), v (0 to 2) and w = v - u, coordinate by coordinate, in a few calls on all of them
    corners = np.array([columns[0][:nv], columns[1][:nv]])[:, template.triangles.T]
    d = corners[:, 1:] - corners[:, :1]
    (ux, vx), (uy, vy) = d
    squares = np.concatenate([d, d[:, 1:] - d[:, :1]], axis=1)
    squares *= squares
    sides = squares[0] + squares[1]  # (3, Nt): ux² + uy², vx² + vy², wx² + wy²
    longest = _HI(sides, axis=0)
    shortest = float(np.sqrt(_LO(sides, axis=None)))
    if not (shortest > 0 and slack <= COPY_TOLERANCE * shortest):
        return False
    side = float(np.sqrt(_HI(longest)))
    # ε extent is at most slack / 2: copy_slack's bound adds 2 ε extent to a deviation >= 0,
    # so 1.5 slack + ε L covers slack + ε (extent + L) without reading the columns again
    margin = ux * vy - uy * vx - 2.0 * FLAT * longest
    return bool(_LO(margin) > 64.0 * side * (1.5 * slack + _EPS * side))


def translated_copy_measures(
    template: PatchTemplate,
    points: np.ndarray,
    columns: list[np.ndarray],
    slack: float | None = None,
) -> dict[str, Any] | None:
    """Topology counts and quality aggregates of unwelded copies that are translations.

    When every patch is the first one translated (checked: each patch's
    coordinates relative to its first vertex match the first patch's to
    :data:`COPY_TOLERANCE` of the shortest side, counting the rounding of the
    coordinates), the edges are the template's, patch by patch, and the edge
    lengths and triangle quality are the first patch's, so one patch is
    measured instead of all. None when that does not hold (deformed patches).

    Parameters
    ----------
    template : PatchTemplate
    points : (P Nv, 3) float64
        The mesh's points, patch p's from p Nv (:func:`is_unwelded_copies`).
    columns : list of (P Nv,) float64
        Contiguous x, y (and z unless all zero) columns of ``points``.
    slack : float, optional
        :func:`copy_slack` of ``columns``, when already found (the mesh keeps
        the one its check found); found here otherwise.

    Returns
    -------
    dict or None
        ``edges``, ``interior_edges``, ``boundary_edges``, ``junction_edges``,
        ``min_edge``, ``max_edge``, ``min_angle_deg``, ``max_aspect_ratio``, ``area``
        (the keys of :func:`barymesh.stats.general_measures`).
    """
    nv = len(template.uv)
    n_p = len(points) // nv if nv else 0
    if n_p == 0 or n_p * nv != len(points):
        return None
    if slack is None:
        slack = copy_slack(nv, columns)
    if slack is None:
        return None
    pts = points[:nv]
    lengths = segment_lengths(pts, template.edges)
    shortest = float(lengths.min()) if len(lengths) else 0.0
    if not (shortest > 0 and slack <= COPY_TOLERANCE * shortest):
        return None
    q = triangle_quality(pts, template.triangles)
    valence = np.bincount(template.valence, minlength=3)
    return {
        "edges": n_p * len(template.edges),
        "interior_edges": n_p * int(valence[2]),
        "boundary_edges": n_p * int(valence[1]),
        "junction_edges": n_p * int(valence[3:].sum()),
        "min_edge": shortest,
        "max_edge": float(lengths.max()),
        "min_angle_deg": float(q.min_angles_deg.min()),
        "max_aspect_ratio": float(q.aspect_ratios.max()),
        "area": n_p * float(q.areas.sum()),
    }
