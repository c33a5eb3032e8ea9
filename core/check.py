"""The invariant check of a built mesh: the general checks, or their repeated fast paths.

:func:`check_mesh` refuses a mesh that breaks an invariant of
:mod:`barymesh.invariants` (finite, counter-clockwise and not flat; in
conforming mode no duplicate vertex and no junction). A mesh with a repetition
record is read patch by patch (:mod:`barymesh.repeat`), any other by the
general functions of :mod:`barymesh.invariants` over its arrays; both find the
same defects (``tests/test_core_chain_paths.py``, ``tests/test_core_hostile.py``).
"""

from __future__ import annotations

import dataclasses
import math
from typing import TYPE_CHECKING, Any

import numpy as np

from .invariants import FLAT, MeshInvariantError, duplicate_vertices, inverted_or_flat
from .repeat import (
    chain_valence,
    glued_edge_valence,
    inverted_or_flat_patches,
    translated_copies_sound,
)

if TYPE_CHECKING:
    from .mesh import TriMesh


def check_mesh(mesh: TriMesh, params: Any) -> None:
    """Raise :class:`barymesh.invariants.MeshInvariantError` if ``mesh`` breaks an invariant.

    Parameters
    ----------
    mesh : TriMesh
        A freshly built mesh. With a repetition record (:class:`~barymesh.repeat.Repetition`),
        each patch's vertices are read once instead of every triangle corner,
        and only the vertices and edges on the patches' sides are compared.
    params : MeshParams
        Named in the message.
    """
    points, triangles = mesh.points, mesh.triangles
    rep = mesh.repetition
    # unwelded copies: the slack's pass reads every coordinate, and is finite only when
    # they all are (a NaN or an infinity makes it NaN or infinite)
    slack = mesh.translation_slack
    if not (slack is not None and math.isfinite(slack)) and not np.isfinite(points).all():
        _fail(params, "has coordinates that are not finite")
    if rep is not None and translated_copies_sound(rep.template, mesh.columns, slack):
        # translations of a first patch whose triangles clear the test by more than the
        # copies can differ: the pass below would flag nothing
        bad = np.empty(0, dtype=np.intp)
    elif rep is not None:
        # the mesh's own x and y columns, which centroids, lengths and quality reuse
        bad = inverted_or_flat_patches(points, rep.vertex_map, rep.template.triangles, mesh.columns)
    else:
        bad = inverted_or_flat(points, triangles)
    if len(bad):
        c = points[triangles[bad[0]]].mean(axis=0)
        _fail(
            params,
            f"has {len(bad):,} of {len(triangles):,} triangles clockwise or flat (area below "
            f"{FLAT:g} of the longest edge squared), the first near ({c[0]:.6g}, {c[1]:.6g})",
        )
    if mesh.mode != "conforming":
        return
    if rep is not None:
        # vertices on the patches' sides, where patches are glued; an interior vertex
        # of a patch is its own (a second vertex there would need overlapping triangles)
        dup = duplicate_vertices(points, rep.vertex_map[:, rep.template.side_vertices])
        if rep.kind == "chains":
            valence = chain_valence(rep.template, rep.closed)
        else:
            valence = glued_edge_valence(rep.template, rep.vertex_map, len(points))
    else:
        dup = duplicate_vertices(points)
        valence = int(mesh.topology.valence.max(initial=0))
    if dup:
        _fail(params, f"has {dup:,} vertices at the same point as another vertex")
    if valence >= 3:
        _fail(params, f"has edges on {valence} triangles (a junction)")


def _fail(params: Any, what: str) -> None:
    changed = _changed(params)
    raise MeshInvariantError(
        f"the {params.mode} mesh of {params.structure} with {changed} {what}; "
        "barymesh refuses it (a geometry it cannot mesh, or a bug to report)"
    )


def _changed(params: Any) -> str:
    """The parameters that differ from the defaults, as ``name=value`` pairs."""
    defaults = type(params)()
    pairs = [
        f"{f.name}={getattr(params, f.name)!r}"
        for f in dataclasses.fields(params)
        if f.name not in ("structure", "mode")
        and getattr(params, f.name) != getattr(defaults, f.name)
    ]
    return ", ".join(pairs) if pairs else "default parameters"
