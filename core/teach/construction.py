"""The paper's construction of a patch mesh, step by step, for teaching.

Each step lists what to draw: labelled points, line segments, filled
triangles, centroids and shared edges, in mm. The steps follow Section II.D of
the paper: the square ABCD, the diagonal BC and the two primary triangles, the
edge midpoints m1, m2, m3, the quarter points m11, m12, m21, m22 (further
halvings when n is a larger power of two, or the n-division points otherwise),
the connecting lines, the finished sub-triangles, their centroids and finally
the shared edges.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from ..build import build_mesh
from ..params import MeshParams


@dataclass(frozen=True)
class ConstructionStep:
    """What one step of the construction shows (everything accumulated so far).

    Attributes
    ----------
    title : str
    description : str
    points : (k, 2) float64
    labels : list of str
        One label per point ("" for an unlabelled point).
    segments : (m, 2, 2) float64
        Line segments.
    triangles : (t, 3, 2) float64
        Filled sub-triangles.
    centroids : (c, 2) float64
    shared_edges : (s, 2, 2) float64
    highlight : (h, 2, 2) float64
        Segments new in this step, drawn emphasised.
    """

    title: str
    description: str
    points: np.ndarray
    labels: list[str]
    segments: np.ndarray
    triangles: np.ndarray = field(default_factory=lambda: np.empty((0, 3, 2)))
    centroids: np.ndarray = field(default_factory=lambda: np.empty((0, 2)))
    shared_edges: np.ndarray = field(default_factory=lambda: np.empty((0, 2, 2)))
    highlight: np.ndarray = field(default_factory=lambda: np.empty((0, 2, 2)))


def _bisection_labels(n: int) -> list[tuple[str, str, float]] | None:
    """Paper labels of the halving points on AB and AC, if n is a power of two.

    Returns (label, edge, fraction along the edge from A) for every level:
    level 1: m1 (AB), m2 (AC); level 2: m11 = mid A–m1, m12 = mid B–m1,
    m22 = mid A–m2, m21 = mid C–m2; deeper levels append digits likewise.
    """
    if n < 2 or n & (n - 1):
        return None
    out: list[tuple[str, str, float]] = []
    levels = n.bit_length() - 1
    # intervals (label of the point at their middle, start, end) per edge
    for edge, name in (("AB", "m1"), ("AC", "m2")):
        frontier = [(name, 0.0, 1.0)]
        for _ in range(levels):
            nxt = []
            for label, a, b in frontier:
                mid = (a + b) / 2
                out.append((label, edge, mid))
                towards_a, towards_far = (label + "1", label + "2")
                if edge == "AC" and len(label) == 2:
                    towards_a, towards_far = label + "2", label + "1"  # the paper's m22 / m21
                nxt += [(towards_a, a, mid), (towards_far, mid, b)]
            frontier = nxt
    return out


def construction_steps(params: MeshParams) -> list[ConstructionStep]:
    """The steps of the paper's construction for one patch or one triangle.

    Parameters
    ----------
    params : MeshParams
        ``structure`` "patch" or "triangle" (other structures use their
        patch size: one patch at ``origin``), uniform scheme.

    Returns
    -------
    list of ConstructionStep

    Examples
    --------
    >>> steps = construction_steps(MeshParams(structure="patch", patch_size=10.0))
    >>> [s.title for s in steps][:3]
    ['Square patch ABCD', 'Diagonal BC: primary triangles ABC and BCD', 'Edge midpoints m1, m2, m3']
    >>> len(steps[-3].triangles), len(steps[-1].shared_edges)
    (32, 40)
    """
    if params.scheme != "uniform":
        raise ValueError(
            f"scheme={params.scheme!r}: the step-by-step construction follows the uniform scheme"
        )
    n = params.subdivisions
    if params.structure == "triangle":
        mesh = build_mesh(params)
        a, b, c = mesh.points[[0, n, len(mesh.points) - 1], :2]
        primaries = [(a, b, c)]
        names: tuple[str, ...] = ("A", "B", "C")
    else:
        patch = MeshParams(
            structure="patch",
            patch_size=params.patch_size,
            patch_width=params.patch_width,
            subdivisions=n,
            diagonal=params.diagonal,
            origin=params.origin,
        )
        mesh = build_mesh(patch)
        x0, y0 = params.origin
        h, w = params.patch_size, params.patch_height
        a, b, c, d = np.array([[x0, y0], [x0 + h, y0], [x0, y0 + w], [x0 + h, y0 + w]])
        primaries = [(a, b, c), (d, c, b)] if params.diagonal == "BC" else [(a, b, d), (a, d, c)]
        names = ("A", "B", "C", "D")
    corners = [a, b, c] if len(names) == 3 else [a, b, c, d]
    steps: list[ConstructionStep] = []
    points = np.array(corners, dtype=float)
    labels = list(names)
    outline = [(a, b), (b, c), (c, a)] if len(names) == 3 else [(a, b), (b, d), (d, c), (c, a)]
    segments = np.array(outline, dtype=float)

    def add(title, description, new_segments=None, **extra):
        nonlocal segments
        highlight = np.empty((0, 2, 2))
        if new_segments is not None and len(new_segments):
            highlight = np.asarray(new_segments, dtype=float).reshape(-1, 2, 2)
            segments = np.concatenate([segments, highlight])
        steps.append(
            ConstructionStep(
                title,
                description,
                points.copy(),
                list(labels),
                segments.copy(),
                highlight=highlight,
                **extra,
            )
        )

    if len(names) == 4:
        add(
            "Square patch ABCD",
            "The patch with corners A = (x0, y0), B = (x0 + h, y0), C = (x0, y0 + w), "
            "D = (x0 + h, y0 + w).",
        )
        diag = "BC" if params.diagonal == "BC" else "AD"
        p, q = (b, c) if diag == "BC" else (a, d)
        tri_names = "ABC and BCD" if diag == "BC" else "ABD and ACD"
        add(
            f"Diagonal {diag}: primary triangles {tri_names}",
            f"The line |{diag}| splits the square into two primary triangles.",
            [(p, q)],
        )
    else:
        add("Primary triangle ABC", "The primary triangle to be subdivided.")

    first = primaries[0]
    p0, p1, p2 = first
    on_edge = {"AB": (p0, p1), "AC": (p0, p2)}
    # the first primary is ABC, or ABD with Makarov's diagonal AD: name its third corner
    third = "D" if len(names) == 4 and params.diagonal == "AD" else "C"
    halvings = _bisection_labels(n)
    if halvings is not None:
        m3 = (p1 + p2) / 2
        level_of: dict[int, list[tuple[str, str, float]]] = {}
        for label, edge, frac in halvings:
            level_of.setdefault(len(label) - 1, []).append((label, edge, frac))
        for level in sorted(level_of):
            for label, edge, frac in level_of[level]:
                s, e = on_edge[edge]
                points = np.vstack([points, s + frac * (e - s)])
                labels.append(label)
            if level == 1:
                points = np.vstack([points, m3])
                labels.append("m3")
                add(
                    "Edge midpoints m1, m2, m3",
                    f"Eq. 24: halving AB, A{third} and B{third} of the primary triangle "
                    f"AB{third} gives m1, m2 and m3.",
                )
            elif level == 2:
                add(
                    "Quarter points m11, m12, m21, m22",
                    f"Halving |Am1|, |Bm1|, |Am2| and |{third}m2| gives m11, m12, m22 and m21: "
                    f"AB and A{third} are cut into four.",
                )
            else:
                add(f"Points dividing the edges into {2**level}", "Halving every segment again.")
    else:
        ts = np.arange(1, n) / n
        for edge, (s, e) in on_edge.items():
            for k, t in enumerate(ts, start=1):
                points = np.vstack([points, s + t * (e - s)])
                labels.append(f"{edge.lower()}{k}")
        for t in ts:
            points = np.vstack([points, p1 + t * (p2 - p1)])
            labels.append("")
        if n > 1:
            add(
                f"Points dividing the edges into {n}",
                f"Each edge of the primary triangle is cut into {n} equal segments.",
            )

    # connecting lines: through the division points, parallel to the primary's edges
    lines = []
    for q0, q1, q2 in primaries:
        for k in range(1, n):
            t = k / n
            lines += [
                (q0 + t * (q1 - q0), q0 + t * (q2 - q0)),  # parallel to q1 q2
                (q1 + t * (q0 - q1), q1 + t * (q2 - q1)),  # parallel to q0 q2
                (q2 + t * (q0 - q2), q2 + t * (q1 - q2)),  # parallel to q0 q1
            ]
    # the division points of the other primary, unlabelled
    for q0, q1, q2 in primaries[1:]:
        for k in range(1, n):
            t = k / n
            extra = np.array([q0 + t * (q1 - q0), q0 + t * (q2 - q0)])
            points = np.vstack([points, extra])
            labels += ["", ""]
    if lines:
        add(
            "Connecting lines",
            "Lines through the division points, parallel to the triangle's edges, "
            "intersect to form the sub-triangles.",
            lines,
        )

    tris = mesh.points[mesh.triangles][:, :, :2]
    per = "16" if n == 4 else f"{n * n}"
    add(
        f"{len(tris)} sub-triangles",
        f"Each primary triangle holds {per} sub-triangles (row k holds 2k − 1).",
        triangles=tris,
    )
    add(
        "Centroids",
        "Eqs. 25–26: the centroid of every sub-triangle, the quadrature points of RWG codes.",
        triangles=tris,
        centroids=mesh.centroids[:, :2].copy(),
    )
    shared = mesh.points[mesh.edges[mesh.interior_edges]][:, :, :2]
    add(
        "Shared edges",
        f"{len(shared)} edges are shared by two triangles: each is one RWG unknown.",
        triangles=tris,
        centroids=mesh.centroids[:, :2].copy(),
        shared_edges=shared,
    )
    return steps
