"""What the MSH 2.2 and 4.1 readers share: the element types, the ``$Section`` bodies
of an ASCII file, and the checks of node tags and of the elements' references to them.
"""

from __future__ import annotations

import re

import numpy as np

from .limits import Damaged

#: Element type -> (name, nodes per element), from the MSH 2.2 specification.
ELEMENT_TYPES = {
    1: ("line", 2),
    2: ("triangle", 3),
    3: ("quad", 4),
    4: ("tetra", 4),
    5: ("hexahedron", 8),
    6: ("wedge", 6),
    7: ("pyramid", 5),
    8: ("line3", 3),
    9: ("triangle6", 6),
    10: ("quad9", 9),
    11: ("tetra10", 10),
    12: ("hexahedron27", 27),
    13: ("wedge18", 18),
    14: ("pyramid14", 14),
    15: ("vertex", 1),
    16: ("quad8", 8),
    17: ("hexahedron20", 20),
    18: ("wedge15", 15),
    19: ("pyramid13", 13),
    20: ("triangle9", 9),
    21: ("triangle10", 10),
    26: ("line4", 4),
}
TRIANGLE = 2


def section(text: str, name: str) -> str | None:
    """The body of ``$name`` … ``$Endname``, or None when absent."""
    start = re.search(rf"^\${name}[ \t\r]*$", text, flags=re.MULTILINE)
    if start is None:
        return None
    end = re.compile(rf"^\$End{name}[ \t\r]*$", flags=re.MULTILINE).search(text, start.end())
    if end is None:
        raise Damaged(f"its ${name} section has no $End{name} (the file is truncated)")
    return text[start.end() : end.start()]


def node_indices(tags: np.ndarray, refs: np.ndarray, elements: np.ndarray) -> np.ndarray:
    """Row indices in ``$Nodes`` of node tags ``refs``; Damaged for tags not defined.

    ``elements`` holds the element number of each entry of ``refs`` (flattened), for the
    message.
    """
    order = np.argsort(tags, kind="stable")
    sorted_tags = tags[order]
    where = np.searchsorted(sorted_tags, refs)
    where = np.minimum(where, max(len(tags) - 1, 0))
    found = (sorted_tags[where] == refs) if len(tags) else np.zeros(refs.shape, dtype=bool)
    if not np.all(found):
        first = int(np.flatnonzero(~found.reshape(-1))[0])
        bad, element = int(refs.reshape(-1)[first]), int(elements.reshape(-1)[first])
        raise Damaged(
            f"element {element} refers to node {bad}, which the $Nodes section does not define"
        )
    return order[where]


def tags_valid(tags: np.ndarray) -> np.ndarray:
    """``tags`` as int64 after checking they are positive, whole and defined once."""
    tags = np.asarray(tags, dtype=np.float64)
    bad = (tags % 1 != 0) | (tags < 1) | (tags > 2**62)
    if np.any(bad):
        raise Damaged(
            f"node tag {tags[bad][0]:g} is invalid; Gmsh node tags are positive whole numbers"
        )
    tags = tags.astype(np.int64)
    unique, counts = np.unique(tags, return_counts=True)
    if np.any(counts > 1):
        raise Damaged(f"node tag {int(unique[counts > 1][0])} is defined twice")
    return tags
