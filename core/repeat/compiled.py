"""When the repeated paths run their compiled loops (:mod:`barymesh.repeat.kernels`).

The numpy functions of :mod:`barymesh.repeat` are the reference and the default. The
compiled loops give the same arrays bit for bit and save about a third of a large build
(1M triangles: about 26 ms against 38 ms), but the first of them in a process imports
numba and loads the loops from their cache: about 0.5 s and 130 MB, once. That pays in a
process that builds many large meshes (a benchmark, a long batch script), not in a
``barymesh mesh`` of one 1M mesh (1.0 s against 0.35 s, 250 MB against 125 MB) nor in
the window (its first large mesh late by 0.35 s, its memory above its budget), so they
are opt-in: set the environment variable :data:`BACKEND_VARIABLE` to ``numba`` and meshes
of at least :data:`MIN_TRIANGLES` triangles take them. Smaller meshes never import numba,
nor does ``import barymesh``.
"""

from __future__ import annotations

import importlib.util
import os
import time
from types import ModuleType

import numpy as np

#: Set to "numba" for the compiled loops from :data:`MIN_TRIANGLES` triangles on; unset
#: (or "numpy"), the numpy paths at every size.
BACKEND_VARIABLE = "BARYMESH_MESH_KERNELS"
#: The value of :data:`BACKEND_VARIABLE` that asks for the compiled loops.
COMPILED = "numba"
#: Triangles from which the compiled loops are used.
MIN_TRIANGLES = 1 << 17

_KERNELS: ModuleType | None = None
_AVAILABLE: bool | None = None


def _numba_available() -> bool:
    global _AVAILABLE
    if _AVAILABLE is None:
        try:
            _AVAILABLE = importlib.util.find_spec("numba") is not None
        except (ImportError, ValueError):  # a module set to None in sys.modules: blocked
            _AVAILABLE = False
    return _AVAILABLE


def kernels(size: int) -> ModuleType | None:
    """The compiled kernels' module for a pass over ``size`` triangles (or edges), or None.

    None unless :data:`BACKEND_VARIABLE` says ``numba``, below :data:`MIN_TRIANGLES`, or
    without numba: then the caller runs its numpy path.
    """
    global _KERNELS
    if size < MIN_TRIANGLES or os.environ.get(BACKEND_VARIABLE) != COMPILED:
        return None
    if _KERNELS is None:
        if not _numba_available():
            return None
        _KERNELS = importlib.import_module(f"{__package__}.kernels")
    return _KERNELS


def axes_of(columns: list[np.ndarray]) -> tuple[list[np.ndarray], np.ndarray]:
    """Three coordinate columns and which of them the numpy paths add (not all zero).

    A missing column (z of a planar mesh) is an empty array, never read.
    """
    empty = np.zeros(0)
    padded = [*columns, *[empty] * (3 - len(columns))]
    return padded, np.array([len(c) > 0 and bool(c.any()) for c in padded])


def warm_up() -> float:
    """Compile (or load from the cache) the kernels on a tiny mesh; the seconds it took.

    Every type a build passes: columns read-only (a layout's) or not (a mesh's own), two
    of them (planar) or three, the vertex map read-only (a record's) or not.
    """
    start = time.perf_counter()
    if not _numba_available():
        return 0.0
    compiled = importlib.import_module(f"{__package__}.kernels")
    tri = np.array([[0, 1, 2]], dtype=np.intp)
    ends = np.array([0, 1], dtype=np.intp), np.array([1, 2], dtype=np.intp)
    for frozen in (False, True):
        for n_columns in (2, 3):
            made = [np.arange(6.0) + a for a in range(n_columns)]
            for c in made:
                c.flags.writeable = not frozen
            columns, axes = axes_of(made)
            compiled.copies_lengths(*columns, axes, 2, 3, *ends, np.empty(4))
            compiled.copy_slack(*columns, n_columns, 3)
            for vmap_frozen in (False, True):
                vmap = np.arange(6, dtype=np.int32).reshape(2, 3)
                vmap.flags.writeable = not vmap_frozen
                for unwelded in (True, False):
                    compiled.centroids(*columns, axes, vmap, unwelded, 3, tri, np.empty((2, 3)))
    uv = np.array([0.0, 1.0])
    compiled.rect_points(uv, uv, np.ones((1, 4)), np.empty((2, 3)), np.empty(2), np.empty(2))
    return time.perf_counter() - start
