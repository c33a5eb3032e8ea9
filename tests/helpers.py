"""Small shared checks for the core tests."""

import ast
import contextlib
import functools
import os
import re
import subprocess
import sys
import textwrap

import numpy as np
from hypothesis import strategies as st

from barymesh import MeshParams, TriMesh, build_mesh
from barymesh.topology import edge_topology


def with_points(mesh, points):
    """The mesh with other points, same triangles and repetition record (nothing cached)."""
    return TriMesh(
        points,
        mesh.triangles,
        mesh.patch_ids,
        mesh.regions,
        mesh.n_patches,
        mesh.mode,
        mesh.tolerance,
        mesh.patch_rects,
        repetition=mesh.repetition,
    )


def signed_areas(mesh):
    p = mesh.points[mesh.triangles]
    d1, d2 = p[:, 1] - p[:, 0], p[:, 2] - p[:, 0]
    return 0.5 * (d1[:, 0] * d2[:, 1] - d1[:, 1] * d2[:, 0])


def edge_sets(edges, valence):
    """{(v0, v1): valence} of an edge table."""
    return {tuple(e): int(v) for e, v in zip(edges.tolist(), valence.tolist(), strict=True)}


def assert_topology_matches_generic(mesh):
    """The template fast path equals the general half-edge sort on the same triangles."""
    fast = mesh.topology
    slow = edge_topology(mesh.triangles, mesh.n_vertices)
    assert edge_sets(fast.edges, fast.valence) == edge_sets(slow.edges, slow.valence)
    # each triangle side maps to the same vertex pair in both
    assert np.array_equal(fast.edges[fast.triangle_edges], slow.edges[slow.triangle_edges])

    # same triangles on each edge
    def incidence(topo):
        pairs = zip(topo.edges.tolist(), topo.edge_triangles.tolist(), strict=True)
        return {tuple(e): tuple(t) for e, t in pairs}

    assert incidence(fast) == incidence(slow)


def components(mesh):
    """Connected components of the triangles through shared vertices."""
    from scipy.sparse.csgraph import connected_components

    return connected_components(mesh.vertex_adjacency, directed=False)[0]


@functools.cache
def canonical_meshes():
    """Tiny meshes that cover one region, two regions and disjoint paper-mode patches.

    Built on first call (inside a test, never at import: a core bug then fails the tests
    that need the mesh instead of the collection) and shared; the meshes are immutable."""
    return {
        "patch": build_mesh(MeshParams(structure="patch", patch_size=10.0, origin=(-5, -5))),
        "double-ring": build_mesh(
            MeshParams(
                structure="double_ring",
                mode="conforming",
                inner_radius=2.0,
                outer_radius=3.5,
                patch_size=1.0,
                angle_step=60.0,
                subdivisions=2,
            )
        ),
        "paper-ring": build_mesh(
            MeshParams(structure="ring", inner_radius=4.0, angle_step=90.0, subdivisions=2)
        ),
    }


# -- meshes with junctions (the general topology path) -------------------------------------


def reference_edge_triangles(triangles):
    """{(v0, v1): [triangle, ...]} by plain Python: side k joins vertices k and k + 1.

    An outside reference for :func:`barymesh.topology.edge_topology`, independent of its sorting;
    triangles on each edge are listed in ascending order.
    """
    table = {}
    for t, tri in enumerate(np.asarray(triangles).tolist()):
        for k in range(3):
            a, b = tri[k], tri[(k + 1) % 3]
            table.setdefault((min(a, b), max(a, b)), []).append(t)
    return table


def reference_connectivity(triangles):
    """{(s, t), s != t}: ordered pairs of triangles with a common edge (junctions included)."""
    pairs = set()
    for tris in reference_edge_triangles(triangles).values():
        pairs.update((s, t) for s in tris for t in tris if s != t)
    return pairs


@st.composite
def junction_meshes(draw, max_extra=6):
    """(points (V, 3), triangles (T, 3)): a mesh with a junction edge and an interior edge.

    A fan of 3 to 5 triangles on one edge (the junction), one more triangle glued to a fan
    triangle along a second edge that nothing else uses (an interior edge), and up to
    ``max_extra`` triangles on random distinct vertices; then vertices are relabelled and
    triangles shuffled and rotated, so that the junction and the interior edge sit anywhere.
    Coordinates are random in the unit cube (the topology does not look at them).
    """
    fan = draw(st.integers(3, 5))
    # vertices 0, 1: the junction edge; 2 .. fan + 1: the fan's apexes; fan + 2: the glued apex
    tris = [[0, 1, 2 + i] if i % 2 else [1, 0, 2 + i] for i in range(fan)]
    tris.append([2, 1, fan + 2])  # across edge (1, 2) of the first fan triangle
    n_vertices = fan + 3 + draw(st.integers(0, 3))
    # extras may not use the interior edge (1, 2), which must keep exactly two triangles
    triple = st.lists(st.integers(0, n_vertices - 1), min_size=3, max_size=3, unique=True)
    extras = draw(st.lists(triple.filter(lambda t: not {1, 2} <= set(t)), max_size=max_extra))
    tris = np.array(tris + extras, dtype=np.int64)
    relabel = np.array(draw(st.permutations(range(n_vertices))))
    tris = relabel[tris]
    tris = tris[np.array(draw(st.permutations(range(len(tris)))))]
    turns = np.array(draw(st.lists(st.integers(0, 2), min_size=len(tris), max_size=len(tris))))
    tris = np.stack([np.roll(t, r) for t, r in zip(tris, turns, strict=True)])
    seed = draw(st.integers(0, 2**32 - 1))
    points = np.random.default_rng(seed).random((n_vertices, 3))
    return points, tris


#: Python's words for kinds of values, which a user's message must not show.
PYTHON_TYPE_NAMES = re.compile(
    r"<class|NoneType|\b(?:got|not) (?:dict|list|str|int|float|bool|tuple|ndarray)\b"
    r"|'(?:dict|list|str|int|float|bool|tuple)'|\b(?:dict|list|str|int|float|tuple) object"
    r"|unpack|could not convert|invalid literal|object is not"
)
#: Longest message an error may show (a deeply nested value's echo is cut): issue 30 found
#: 178 parameter and 130 cell messages over 300 characters.
MESSAGE_LIMIT = 300


def assert_clear_message(message):
    """A user's error message: short, and in the user's words, not Python's."""
    assert len(message) < MESSAGE_LIMIT, f"{len(message)} characters: {message[:200]}..."
    assert not PYTHON_TYPE_NAMES.search(message), message


#: Address space of a Python process with barymesh, numpy and scipy imported (about
#: 0.35 GiB with one BLAS thread), and room for a small mesh: a cap this much above
#: what a check may allocate catches allocations of a few hundred MB.
BASE_ADDRESS_SPACE = 1 << 30


@contextlib.contextmanager
def address_space_cap(extra=1 << 30):
    """Cap this process's address space at its size now plus ``extra`` bytes, for a while.

    Inside, an allocation past the cap raises MemoryError (a runaway fails the test at
    once instead of eating the shared machine's memory); the soft limit is put back after.
    """
    import resource

    size = 0
    with open("/proc/self/status") as fh:
        for line in fh:
            if line.startswith("VmSize:"):
                size = int(line.split()[1]) * 1024
    soft, hard = resource.getrlimit(resource.RLIMIT_AS)
    cap = size + extra if hard == resource.RLIM_INFINITY else min(size + extra, hard)
    resource.setrlimit(resource.RLIMIT_AS, (cap, hard))
    try:
        yield
    finally:
        resource.setrlimit(resource.RLIMIT_AS, (soft, hard))


def run_capped(code, address_space=BASE_ADDRESS_SPACE, timeout=600):
    """Run ``code`` in a new Python whose address space is capped (``RLIMIT_AS``).

    A check that allocates before it refuses dies with MemoryError (exit 1, its
    traceback in stderr) instead of eating the shared machine's memory. ``timeout`` is a
    guard against a hang, not a measured time. Returns the CompletedProcess.
    """
    preamble = (
        "import resource\n"
        f"resource.setrlimit(resource.RLIMIT_AS, ({address_space}, {address_space}))\n"
    )
    env = {**os.environ, "OPENBLAS_NUM_THREADS": "1", "OMP_NUM_THREADS": "1"}
    return subprocess.run(
        [sys.executable, "-c", preamble + textwrap.dedent(code)],
        capture_output=True,
        text=True,
        timeout=timeout,
        env=env,
    )


def imports_of(tree):
    """(node, imported module names) of every import statement in the AST ``tree``."""
    for node in ast.walk(tree):
        if isinstance(node, ast.Import):
            yield node, [a.name for a in node.names]
        elif isinstance(node, ast.ImportFrom):
            yield node, [node.module or ""]
