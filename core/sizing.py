"""Sizing from frequency: the smallest subdivision whose edges meet a target length.

Solvers want edges short against the wavelength (the common guidance is λ/10; Feko's
standard is λ/12) and triangles small against λ² (λ²/30). With ``frequency`` (Hz, and
optionally the substrate's ``relative_permittivity``) or ``max_edge`` (mm) set in
:class:`barymesh.params.MeshParams`, :func:`barymesh.build.build_mesh` asks :func:`sized_mesh`
for the smallest ``subdivisions`` whose mesh has every edge within the target.

The search does not rely on a closed form of the construction (conforming sectors, for
one, may subdivide along the arc differently from across the track): it estimates n from
the longest edge of the coarsest mesh, then builds, measures the longest edge of the
mesh it built (vectorised over the triangles) and steps until the n found meets the
target and n − 1, built and measured too, does not (or n is the scheme's smallest).

>>> round(wavelength(10e9), 6)          # mm in vacuum
29.979246
>>> round(wavelength(10e9, 4.0), 6)     # in a substrate of εr = 4: half as long
14.989623
"""

from __future__ import annotations

import math
from collections.abc import Callable, Iterator
from typing import TYPE_CHECKING, Any

import numpy as np

from .constants import wavelength
from .params import (
    MAX_BARYCENTRIC_LEVELS,
    MAX_PATCH_COUNT,
    MAX_UNIFORM_SUBDIVISIONS,
    SINGLE_STRUCTURES,
    MeshParams,
    default_subdivisions,
)
from .topology import BLOCK

if TYPE_CHECKING:
    from .mesh import TriMesh

#: The rule of thumb the statistics check: every edge at most a tenth of the wavelength.
RULE_CELLS_PER_WAVELENGTH = 10
#: A refusal is shorter than this (a user's one line; the suite's ``assert_clear_message``).
MESSAGE_LIMIT = 300


def params_wavelength(params: MeshParams) -> float | None:
    """λ (mm) of ``params`` (``frequency`` in the medium of ``relative_permittivity``), or None."""
    if params.frequency is None:
        return None
    return wavelength(params.frequency, params.relative_permittivity)


def target_edge(params: MeshParams) -> tuple[float, str] | None:
    """(longest edge allowed in mm, the parameter that sets it), or None without sizing.

    The target is λ / ``cells_per_wavelength`` with a ``frequency``, ``max_edge`` with a
    largest edge; with both, the smaller (stricter) one, named ``"frequency"`` on a tie.
    """
    candidates = []
    lam = params_wavelength(params)
    if lam is not None:
        candidates.append((lam / params.cells_per_wavelength, "frequency"))
    if params.max_edge is not None:
        candidates.append((params.max_edge, "max_edge"))
    if not candidates:
        return None
    return min(candidates, key=lambda c: c[0])


def _columns(points: np.ndarray) -> list[np.ndarray]:
    columns = [np.ascontiguousarray(points[:, k]) for k in range(points.shape[1])]
    if len(columns) == 3 and not columns[2].any():
        columns = columns[:2]
    return columns


def _corner_blocks(
    points: np.ndarray, triangles: np.ndarray, columns: list[np.ndarray] | None
) -> Iterator[list[list[np.ndarray]]]:
    """The triangles' corners block by block (cache-sized): ``c[i][k]`` is coordinate k
    of corner i of each triangle in the block."""
    triangles = np.asarray(triangles)
    if columns is None:
        columns = _columns(np.asarray(points, dtype=np.float64))
    for lo in range(0, len(triangles), BLOCK):
        tri = triangles[lo : lo + BLOCK]
        yield [[col.take(tri[:, i]) for col in columns] for i in range(3)]


def longest_edge(
    points: np.ndarray, triangles: np.ndarray, columns: list[np.ndarray] | None = None
) -> float:
    """Length (mm) of the longest side of any triangle: the mesh's longest edge.

    Every edge is a side of a triangle, so no edge table is needed; the squared sides are
    reduced block by block (cache-sized, no (T, 3, 3) temporary) and the root taken once.

    Parameters
    ----------
    points : (V, 2) or (V, 3) float64
    triangles : (T, 3) int
    columns : list of (V,) float64, optional
        Contiguous coordinate columns of ``points`` (x, y, and z unless it is all zero).

    Examples
    --------
    >>> longest_edge(np.array([[0.0, 0, 0], [3, 0, 0], [0, 4, 0]]), np.array([[0, 1, 2]]))
    5.0
    """
    best = [0.0]
    for corners in _corner_blocks(points, triangles, columns):
        for a, b in ((0, 1), (1, 2), (2, 0)):
            square = sum((p - q) * (p - q) for p, q in zip(corners[b], corners[a], strict=True))
            best.append(square.max())
    return float(np.sqrt(np.max(best)))


def largest_area(
    points: np.ndarray, triangles: np.ndarray, columns: list[np.ndarray] | None = None
) -> float:
    """Area (mm²) of the largest triangle, block by block (as :func:`longest_edge`).

    >>> largest_area(np.array([[0.0, 0, 0], [3, 0, 0], [0, 4, 0]]), np.array([[0, 1, 2]]))
    6.0
    """
    best = [0.0]
    for c in _corner_blocks(points, triangles, columns):
        u = [c[1][k] - c[0][k] for k in range(len(c[0]))]
        v = [c[2][k] - c[0][k] for k in range(len(c[0]))]
        if len(c[0]) == 2:
            cross2 = (u[0] * v[1] - u[1] * v[0]) ** 2
        else:
            cross2 = (
                (u[1] * v[2] - u[2] * v[1]) ** 2
                + (u[2] * v[0] - u[0] * v[2]) ** 2
                + (u[0] * v[1] - u[1] * v[0]) ** 2
            )
        best.append(cross2.max())
    return float(0.5 * np.sqrt(np.max(best)))


def sizing_stats(mesh: TriMesh, longest: float) -> dict[str, Any]:
    """The statistics of sizing, for :meth:`barymesh.mesh.TriMesh.stats`.

    Empty unless the mesh was built from parameters with a ``frequency`` or ``max_edge``.
    With either: ``subdivisions_chosen`` (the n the mesher picked) and ``target_edge``
    (mm). With a frequency: ``wavelength`` (mm, in the medium), ``max_edge_wavelengths``
    (longest edge / λ), ``max_area_wavelengths2`` (largest triangle area / λ²) and
    ``lambda_10_rule`` (True when every edge is at most λ/10).
    """
    params = getattr(mesh, "params", None)
    if params is None:
        return {}
    target = target_edge(params)
    if target is None:  # not sized
        return {}
    out: dict[str, Any] = {
        "subdivisions_chosen": int(params.subdivisions),
        "target_edge": float(target[0]),
    }
    lam = params_wavelength(params)
    if lam is not None:
        area = largest_area(mesh.points, mesh.triangles, mesh.columns)
        out["wavelength"] = lam
        out["max_edge_wavelengths"] = longest / lam
        out["max_area_wavelengths2"] = area / (lam * lam)
        out["lambda_10_rule"] = bool(longest <= lam / RULE_CELLS_PER_WAVELENGTH)
    return out


def sizing_summary(stats: dict[str, Any]) -> str:
    """One plain-text line on the sizing of a mesh (the command line's summary).

    >>> sizing_summary({"subdivisions_chosen": 5, "target_edge": 2.5, "max_edge": 2.4})
    '  sized: subdivisions 5 chosen for edges <= 2.5 mm; longest edge 2.4 mm'
    """
    line = (
        f"  sized: subdivisions {stats['subdivisions_chosen']} chosen for edges <= "
        f"{stats['target_edge']:.6g} mm; longest edge {stats['max_edge']:.6g} mm"
    )
    if "wavelength" in stats:
        rule = "met" if stats["lambda_10_rule"] else "NOT met"
        line += (
            f" = {stats['max_edge_wavelengths']:.4g} lambda (lambda = "
            f"{stats['wavelength']:.6g} mm), largest area "
            f"{stats['max_area_wavelengths2']:.4g} lambda^2, lambda/10 rule {rule}"
        )
    return line


def accuracy_floor(params: MeshParams) -> int:
    """The smallest subdivisions sizing may choose: a graded patch's, triangle's or cross's
    accuracy default (:func:`barymesh.params.default_subdivisions`), else 1.

    >>> accuracy_floor(MeshParams(structure="patch", grading=True, frequency=1e9))
    16
    """
    if params.grading and params.structure in (*SINGLE_STRUCTURES, "cross"):
        return default_subdivisions(params.structure, True)
    return 1


def _limit(scheme: str) -> int:
    return MAX_UNIFORM_SUBDIVISIONS if scheme == "uniform" else MAX_BARYCENTRIC_LEVELS


def _estimate(scheme: str, n: int, edge: float, target: float) -> int:
    """The n at which an edge of ``edge`` mm at ``n`` would shrink to ``target`` mm.

    A guess only (edges about 1/n for the uniform scheme, about halved per barycentric
    level); the search measures what it proposes.
    """
    ratio = edge / target
    if scheme == "uniform":
        return math.ceil(n * ratio * (1 - 1e-12))
    return n + max(1, math.ceil(math.log2(ratio) - 1e-12))


def _what(params: MeshParams, name: str, target: float) -> str:
    """``frequency=… Hz asks for edges ≤ … mm (λ/… of … mm)`` or the max_edge equivalent."""
    if name == "frequency":
        lam = params_wavelength(params)
        medium = (
            ""
            if params.relative_permittivity == 1
            else (f" in εr = {params.relative_permittivity:g}")
        )
        return (
            f"frequency={params.frequency:.6g} Hz asks for edges <= {target:.6g} mm "
            f"(λ/{params.cells_per_wavelength:g} of {lam:.6g} mm{medium})"
        )
    return f"max_edge={params.max_edge!r} mm asks for edges <= {target:.6g} mm"


def _needs(params: MeshParams, name: str, target: float, n: int, refusal: str) -> str:
    """Why the target's subdivisions ``n`` is refused: the target, then the refusal.

    Two messages in one can pass :data:`MESSAGE_LIMIT` (issue 30's seventh fuzz run: a
    wavelength of 2.7e111 mm made it 300 characters), so the target is said ever shorter
    (without its wavelength, then not at all); the refusal itself names its parameter.
    """
    for what in (
        f"{_what(params, name, target)}, which needs subdivisions={n}; there: ",
        f"{name} asks for edges <= {target:.6g} mm, which needs subdivisions={n}: ",
        "",
    ):
        if len(what) + len(refusal) < MESSAGE_LIMIT:
            break
    return what + refusal


def sized_mesh(
    params: MeshParams,
    build: Callable[[MeshParams], TriMesh],
    check: Callable[[TriMesh], None],
) -> TriMesh:
    """The mesh of the smallest ``subdivisions`` whose every edge is at most the target.

    Parameters
    ----------
    params : MeshParams
        With ``frequency`` or ``max_edge`` set (``params.sized``); its ``subdivisions`` is
        not used.
    build : callable
        ``build(candidate)`` meshes ``candidate`` (``params`` with one ``subdivisions``)
        without the invariant check; ``mesh.params`` is ``candidate``.
    check : callable
        ``check(mesh)`` runs the invariant check on the mesh chosen, before it is returned.

    Returns
    -------
    TriMesh
        Built from ``params`` with ``subdivisions`` = the chosen n (``mesh.params``):
        every edge at most the target, and the mesh of n − 1 built and measured to exceed
        it, unless n is 1.

    Raises
    ------
    ValueError
        Naming ``frequency`` or ``max_edge`` (whichever sets the target) when the finest
        subdivision of the scheme, or the triangle budget ``max_triangles``, cannot meet
        it, with the triangles it would take.
    """
    found = target_edge(params)
    if found is None:
        raise ValueError(
            "sized_mesh needs parameters with a frequency or a max_edge; both are none"
        )
    target, name = found
    scheme = params.scheme
    top = _limit(scheme)
    edges: dict[int, float] = {}  # n -> longest edge of its mesh, for every n measured
    chosen: TriMesh | None = None  # the mesh of ``good``

    def candidate(n: int) -> MeshParams:
        try:
            return params.replace(subdivisions=n)
        except ValueError as exc:
            raise ValueError(_needs(params, name, target, n, str(exc))) from None

    # a graded patch or triangle never goes below its accuracy default (params.py)
    floor = accuracy_floor(params)
    bad, good = floor - 1, None  # largest n known to miss (or not allowed), smallest to meet
    n = floor
    while good is None or good - bad > 1:
        trial = candidate(n)
        if trial.predicted_triangles() > params.max_triangles:
            if good is None:  # every finer n is over the budget too
                _refuse(params, name, target, bad, edges, budget=True)
            bad = n  # cannot be chosen (an n below ``good`` with more triangles)
        else:
            mesh = build(trial)
            edges[n] = longest_edge(mesh.points, mesh.triangles, mesh.columns)
            if edges[n] <= target:
                good, chosen = n, mesh
            else:
                bad = n
            del mesh
        if good is None:
            if bad >= top:
                _refuse(params, name, target, bad, edges, budget=False)
            n = min(top, max(bad + 1, _estimate(scheme, bad, edges[bad], target)))
        elif good - bad > 1:
            # from above: the estimate from ``good``'s own edge, at most n - 1 (usually n - 1
            # exactly: the first estimate is usually right, and n - 1 proves it minimal)
            n = max(bad + 1, min(good - 1, _estimate(scheme, good, edges[good], target)))
    assert chosen is not None  # the mesh of ``good``, which the loop found
    check(chosen)
    return chosen


def _refuse(
    params: MeshParams,
    name: str,
    target: float,
    bad: int,
    edges: dict[int, float],
    budget: bool,
) -> None:
    """Raise the ValueError for a target the scheme or the budget cannot meet."""
    scheme = params.scheme
    top = _limit(scheme)
    what = _what(params, name, target)
    if bad not in edges:  # not even the smallest n allowed (1, or a graded patch's 16) fits
        count: int | None = params.replace(subdivisions=bad + 1).predicted_triangles()
        raise ValueError(
            f"{what}, but the coarsest mesh already has {count:,} triangles, above the "
            f"budget max_triangles={params.max_triangles:,}"
        )
    edge = edges[bad]
    need = max(bad + 1, _estimate(scheme, bad, edge, target))
    unit = "n" if scheme == "uniform" else "levels"
    if need <= top:
        count = params.replace(subdivisions=need).predicted_triangles()
        about = ""
    else:
        base = params.replace(subdivisions=top).predicted_triangles()
        # in logarithms: (need / top)**2 or 6**(need - top) overflows float64 for far targets
        growth = 2 * math.log(need / top) if scheme == "uniform" else (need - top) * math.log(6)
        about = "about "
        count = (
            None
            if math.log(base) + growth > math.log(MAX_PATCH_COUNT)
            else (round(base * math.exp(growth)))
        )
    shown = f"{about}{count:,}" if count is not None else f"more than {MAX_PATCH_COUNT:.0e}"
    level = f"{need}" if need < 10**6 else f"{need:.3g}"
    needed = f"it would take {about}{unit} = {level}, {shown} triangles"
    if budget:
        raise ValueError(
            f"{what}; {needed}, above the budget max_triangles={params.max_triangles:,} "
            f"({unit} = {bad} leaves edges of {edge:.6g} mm): raise max_triangles, or ask "
            "for longer edges"
        )
    raise ValueError(
        f"{what}; the {scheme} scheme's finest {unit} = {top} leaves edges of {edge:.6g} mm: "
        f"{needed}; ask for longer edges or use larger patches"
    )
