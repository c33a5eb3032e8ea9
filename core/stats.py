"""Mesh statistics: the counts and quality figures of :meth:`barymesh.mesh.TriMesh.stats`.

Which algorithm measures a mesh depends on its repetition record and nothing
else (never on what happens to be cached):

- a mesh without a record (imported, single triangle) is measured in general:
  every edge found and measured, every triangle's quality
  (:func:`general_measures`);
- a mesh of template copies (:class:`barymesh.repeat.Repetition`) counts its
  edges without making them and reduces its quality block by block
  (:func:`repeated_measures`); unwelded translated copies measure one patch
  (:func:`barymesh.repeat.translated_copy_measures`).

Both give the same counts and edge range as the general path, the other figures
to rounding (``tests/test_core_fast_paths.py``); the per-triangle arrays of the
mesh stay lazy.
"""

from __future__ import annotations

from typing import TYPE_CHECKING, Any

import numpy as np

from .quality import quality_summary
from .repeat import (
    lattice_diagonal,
    lattice_quality_summary,
    patch_edge_counts,
    sector_edge_counts,
    translated_copy_measures,
)
from .sizing import sizing_stats

if TYPE_CHECKING:
    from .mesh import TriMesh


def count_distinct(labels: np.ndarray) -> int:
    """Number of distinct values of integer labels, without sorting them.

    The smallest and the largest label are there; only labels strictly between
    them are looked for (none for one or two regions, the usual case).

    >>> count_distinct(np.array([1, 5, 3, 1, 3]))
    3
    """
    if len(labels) == 0:
        return 0
    lo, hi = int(labels.min()), int(labels.max())
    if hi - lo < 64:
        return min(2, hi - lo + 1) + sum(bool((labels == v).any()) for v in range(lo + 1, hi))
    if lo >= 0 and hi < 1 << 20:
        return int(np.count_nonzero(np.bincount(labels)))
    return len(np.unique(labels))


def _measures(counts: np.ndarray, side_range: tuple, summary: tuple) -> dict[str, Any]:
    """The nine measured keys, from edge counts by valence, the edge range and quality."""
    return {
        "edges": int(counts.sum()),
        "interior_edges": int(counts[2]),
        "boundary_edges": int(counts[1]),
        "junction_edges": int(counts[3:].sum()),
        "min_edge": float(side_range[0]),
        "max_edge": float(side_range[1]),
        "min_angle_deg": float(summary[0]),
        "max_aspect_ratio": float(summary[1]),
        "area": float(summary[2]),
    }


def general_measures(mesh: TriMesh) -> dict[str, Any]:
    """Edge counts and quality figures from every edge and triangle (the reference).

    Keys ``edges``, ``interior_edges``, ``boundary_edges``, ``junction_edges``,
    ``min_edge``, ``max_edge``, ``min_angle_deg``, ``max_aspect_ratio``,
    ``area``. Makes (and caches) the mesh's topology, edge lengths and quality.
    """
    counts = np.bincount(mesh.topology.valence, minlength=3)  # one pass, not three
    lengths = mesh.edge_lengths
    side_range = (lengths.min(), lengths.max()) if len(lengths) else (0.0, 0.0)
    empty = mesh.n_triangles == 0
    summary = (
        0.0 if empty else mesh.min_angles.min(),
        0.0 if empty else mesh.aspect_ratios.max(),
        mesh.areas.sum(),
    )
    return _measures(counts, side_range, summary)


def counted_measures(mesh: TriMesh) -> dict[str, Any]:
    """The keys of :func:`general_measures` for a mesh of template copies, nothing made.

    Edges are counted (sectors' chains by formula,
    :func:`barymesh.repeat.sector_edge_counts`, else
    :func:`barymesh.repeat.patch_edge_counts`); quality is reduced block by block,
    from grid edges for planar grid templates
    (:func:`barymesh.repeat.lattice_quality_summary`), else from every triangle's
    corners (:func:`barymesh.quality.quality_summary`, whose side range is the
    edge range).

    Raises
    ------
    ValueError
        When the mesh has no repetition record.
    """
    rep = mesh.repetition
    if rep is None:
        raise ValueError("counted_measures needs a mesh with a repetition record")
    t, vmap = rep.template, rep.vertex_map
    chains = (rep.sectors, rep.closed) if rep.kind == "chains" else None
    patch_regions = mesh.regions[:: len(t.triangles)]
    counts = sector_edge_counts(t, vmap, mesh.n_vertices, chains, patch_regions)
    if counts is None:
        counts = patch_edge_counts(t.edges, t.valence, vmap, mesh.n_vertices)
    cells = (len(t.sides[0]) - 1, len(t.sides[1]) - 1)  # n x n, or a sector's n x n_v
    diagonal = lattice_diagonal(t.triangles, len(t.uv), cells)
    columns = mesh.columns
    if diagonal is not None and len(columns) == 2:  # planar grid patches
        s = lattice_quality_summary(columns, vmap, diagonal, cells)
    else:
        s = quality_summary(mesh.points, mesh.triangles, columns)
    return _measures(
        counts, (s.shortest_side, s.longest_side), (s.min_angle_deg, s.max_aspect_ratio, s.area)
    )


def repeated_measures(mesh: TriMesh) -> dict[str, Any]:
    """The keys of :func:`general_measures` for a mesh with a repetition record.

    Unwelded copies that are translations of one patch measure that patch
    (:func:`barymesh.repeat.translated_copy_measures`); everything else is
    :func:`counted_measures`.
    """
    rep = mesh.repetition
    if rep is not None and rep.kind == "copies":
        measured = translated_copy_measures(
            rep.template, mesh.points, mesh.columns, mesh.translation_slack
        )
        if measured is not None:
            return measured
    return counted_measures(mesh)


def mesh_stats(mesh: TriMesh) -> dict[str, Any]:
    """Counts and quality figures of ``mesh`` as a plain, JSON-ready dict.

    The keys of :meth:`barymesh.mesh.TriMesh.stats` (which calls this), in its order.
    """
    if mesh.repetition is None:
        measured = general_measures(mesh)
    else:
        measured = repeated_measures(mesh)
    out: dict[str, Any] = {
        "patches": int(mesh.n_patches),
        "vertices": int(mesh.n_vertices),
        "triangles": int(mesh.n_triangles),
        **measured,  # edges ... area, in the order of the docstring
        "euler_characteristic": int(mesh.n_vertices - measured["edges"] + mesh.n_triangles),
        "regions": count_distinct(mesh.regions),
    }
    if mesh.min_angle_floor is not None:
        out["min_angle_floor_deg"] = float(mesh.min_angle_floor)
    if mesh.mode == "paper":
        out["overlap_ratio"] = mesh.overlap_ratio
    if mesh.ignored_cells:
        out["ignored_cells"] = dict(mesh.ignored_cells)
    if mesh.params is not None and mesh.params.sized:
        out.update(sizing_stats(mesh, measured["max_edge"]))
    return out
