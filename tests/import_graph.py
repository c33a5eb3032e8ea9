"""Import circles in a package, from grimp's import graph (import-linter's engine).

Every ``import`` statement counts, at module level or inside a function (a lazy import
that gets round a circle is still one), except those under ``if TYPE_CHECKING:``, which
never run. A circle is a strongly connected component of the graph of direct imports
with more than one module (or a module that imports itself).

``python tests/import_graph.py`` (``make lint``) prints the circles of the core
(``barymesh`` without ``barymesh.app`` and ``barymesh.assets``) and exits 1 if it has any.
"""

from __future__ import annotations

import sys

import grimp
import numpy as np
import scipy.sparse as sp
from scipy.sparse.csgraph import connected_components

#: Subpackages of barymesh that are not the core: the window (which may import anything
#: of the core) and the data files.
NOT_CORE = ("barymesh.app", "barymesh.assets")


def import_edges(package: str, leave_out: tuple[str, ...] = ()) -> set[tuple[str, str]]:
    """(importer, imported) pairs of modules of ``package``, run-time imports only.

    Parameters
    ----------
    package : str
        Importable name of the top-level package (found on ``sys.path``).
    leave_out : tuple of str
        Subpackages whose modules (themselves included) are dropped from both ends.
    """
    graph = grimp.build_graph(package, exclude_type_checking_imports=True, cache_dir=None)

    def kept(name: str) -> bool:
        return not any(name == p or name.startswith(p + ".") for p in leave_out)

    modules = {m for m in graph.modules if kept(m)}
    return {
        (m, target)
        for m in modules
        for target in graph.find_modules_directly_imported_by(m)
        if target in modules
    }


def circles(edges: set[tuple[str, str]]) -> list[list[str]]:
    """The import circles among ``edges``: each a sorted list of modules, the lists sorted.

    >>> circles({("p.a", "p.b"), ("p.b", "p.a"), ("p.b", "p.c")})
    [['p.a', 'p.b']]
    >>> circles({("p.a", "p.b"), ("p.b", "p.c")})
    []
    """
    names = sorted({m for edge in edges for m in edge})
    if not names:
        return []
    index = {m: i for i, m in enumerate(names)}
    rows = np.array([index[a] for a, _ in edges], dtype=np.intp)
    cols = np.array([index[b] for _, b in edges], dtype=np.intp)
    graph = sp.coo_matrix((np.ones(len(rows)), (rows, cols)), shape=(len(names), len(names)))
    _, label = connected_components(graph, directed=True, connection="strong")
    sizes = np.bincount(label)
    self_loops = {index[a] for a, b in edges if a == b}
    out = [
        sorted(names[i] for i in np.flatnonzero(label == c))
        for c in range(len(sizes))
        if sizes[c] > 1 or any(label[i] == c for i in self_loops)
    ]
    return sorted(out)


def describe(circle: list[str], edges: set[tuple[str, str]]) -> str:
    """One line per import inside a circle: ``a -> b``."""
    inside = set(circle)
    return "\n".join(f"  {a} -> {b}" for a, b in sorted(edges) if a in inside and b in inside)


def main() -> int:
    edges = import_edges("barymesh", NOT_CORE)
    found = circles(edges)
    for circle in found:
        print(f"import circle of {len(circle)} modules:\n{describe(circle, edges)}")
    if not found:
        print(f"no import circle in the core ({len(edges)} imports)")
    return 1 if found else 0


if __name__ == "__main__":
    sys.exit(main())
