"""Meshes made of copies of one patch template: the repeated fast paths, in one place.

A structure of patches (the paper's squares, a ring's sectors, a cell's pixels)
is one :class:`barymesh.subdivision.PatchTemplate` copied P times, copy p's
local vertex l at global vertex ``vertex_map[p, l]``. Its topology, RWG table,
connectivity, statistics and invariant checks can then be had without sorting
or gathering the whole mesh. The build records the repetition once
(:class:`Repetition`), and the record's ``kind`` says which path applies:

- :mod:`barymesh.repeat.copies`: unwelded copies, every id shifted by whole patches;
- :mod:`barymesh.repeat.chains`: chains of sectors numbered by formula, a short
  chain's middle sector repeated;
- :mod:`barymesh.repeat.patches`: any vertex map; only the glued edges are sorted;
- :mod:`barymesh.repeat.lattice`: grid templates, quality and orientation read
  from grid edges.

Each module's docstring draws how copy k's vertices, triangles and edges are
numbered from the template's. The general paths over plain arrays
(:mod:`barymesh.topology`, :mod:`barymesh.quality`, :mod:`barymesh.invariants`)
are the reference: every path here gives their result bit for bit (the
aggregates of quality to rounding, as documented), and the tests
``tests/test_core_fast_paths.py``, ``tests/test_core_chain_paths.py``,
``tests/test_core_assembly.py`` are that contract.
"""

from .chains import CHAIN, MIDDLE, chain_valence, sector_chain_vertices, sector_edge_counts
from .copies import copy_slack, translated_copies_sound, translated_copy_measures
from .lattice import lattice_diagonal, lattice_quality_summary
from .patches import (
    glued_edge_valence,
    inverted_or_flat_patches,
    patch_centroids,
    patch_edge_counts,
    patch_topology,
    patch_triangles,
)
from .record import Kind, Repetition, repeated_connectivity, repeated_rwg, repeated_topology

__all__ = [
    "CHAIN",
    "MIDDLE",
    "Kind",
    "Repetition",
    "chain_valence",
    "copy_slack",
    "glued_edge_valence",
    "inverted_or_flat_patches",
    "lattice_diagonal",
    "lattice_quality_summary",
    "patch_centroids",
    "patch_edge_counts",
    "patch_topology",
    "patch_triangles",
    "repeated_connectivity",
    "repeated_rwg",
    "repeated_topology",
    "sector_chain_vertices",
    "sector_edge_counts",
    "translated_copies_sound",
    "translated_copy_measures",
]
