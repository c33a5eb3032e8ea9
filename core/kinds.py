"""The structures the mesher knows, by name, and the groups of them that share a parameter.

The lowest module of the mesher: the parameters (:mod:`barymesh.params`) check names
against these tuples, and the sector planner (:mod:`barymesh.sectors`) and the patch
placement (:mod:`barymesh.placement`), which the parameters ask, group structures by them.
"""

from __future__ import annotations

STRUCTURES = (
    "patch",
    "cross",
    "triangle",
    "ring",
    "double_ring",
    "split_ring",
    "split_double_ring",
    "square_split_double_ring",
)
#: Structures made of two concentric rings (they use ``outer_radius``).
DOUBLE_STRUCTURES = ("double_ring", "split_double_ring", "square_split_double_ring")
#: Structures cut by slots (they use ``gap_width`` and ``gap_angle``).
SPLIT_STRUCTURES = ("split_ring", "split_double_ring", "square_split_double_ring")
#: Structures of patches that meet side to side (a patch, a cross): no rings, no radii.
PATCH_STRUCTURES = ("patch", "cross")
#: Structures laid out on circles (they use ``angle_step``).
ANGULAR_STRUCTURES = ("ring", "double_ring", "split_ring", "split_double_ring")
