"""What a solve cannot vouch for: the caveats that go into ``Solution.warnings``.

Each function returns a tuple of sentences (empty when there is nothing to
say), so that :func:`barymesh.mom.solve` and :func:`barymesh.mom.sweep` can collect
them and the command line and the window can show them as they are.

* :func:`junction_warning`: edges shared by three or more triangles get no
  RWG function, so no current crosses them.
* :func:`lattice_warning`: a unit cell's mesh (it has a lattice) is solved
  as one finite scatterer in free space, not as an infinite array.
* :func:`low_frequency_warning`: the EFIE's low-frequency breakdown, from
  k·D and the condition number.
* :func:`overlap_warning`: overlapping paper-mode patches.
* :func:`coarse_mesh_warning`: edges longer than a tenth of the wavelength.

:func:`check_electrical_size` is not a caveat but a refusal: below
:data:`MIN_KD` double precision cannot form the EFIE's matrix at all.
"""

from __future__ import annotations

import numpy as np

from ..constants import SPEED_OF_LIGHT
from ..mesh import TriMesh
from .geometry import METRES_PER_MESH_UNIT

_C_OVER_2PI = SPEED_OF_LIGHT / (2.0 * np.pi)

#: Below this k·D (D the diagonal of the mesh's bounding box) the EFIE's vector
#: potential is (k D)² smaller than its scalar potential and the radiated power a
#: cancellation between them. Measured on Makarov's plates and the 10 mm patch: the
#: energy balance (extinction − scattering) is off by 0.2–0.9 % at k D = 0.003,
#: 9–26 % at 0.0009, and the extinction is negative at 9e-5; at k D = 0.009 0.03–0.4 %.
LOW_FREQUENCY_KD = 0.01
#: Above this 1-norm condition number a double-precision solve keeps fewer than six
#: digits, whatever k D is (e.g. a mesh far finer than the wavelength needs).
CONDITION_LIMIT = 1e10
#: Below this k·D the EFIE's vector potential, (k D)² of its scalar potential, is under
#: double precision's rounding (1e-16) of the same entries: the matrix loses it entirely
#: (and far below, 1/(ω ε0) overflows: 1e-300 Hz gave NaN currents). Refused.
MIN_KD = 1e-8
#: Edges per wavelength below which a mesh is coarse: edges over λ/10 (the sizing's default
#: ``cells_per_wavelength``, and the usual rule for RWG meshes).
CELLS_PER_WAVELENGTH = 10.0


def junction_warning(mesh: TriMesh) -> tuple[str, ...]:
    """A sentence when ``mesh`` has junction edges (three or more triangles on an edge)."""
    count = len(mesh.junction_edges)
    if count == 0:
        return ()
    return (
        f"{count} junction edge{'s' if count != 1 else ''} (shared by three or more "
        f"triangles) carry no RWG unknown: no current crosses them, so the surfaces "
        f"meeting there are solved as if cut apart along them (no junction basis functions)",
    )


def lattice_warning(mesh: TriMesh) -> tuple[str, ...]:
    """A sentence when ``mesh`` is a unit cell's (or a tiled array's): it has a lattice."""
    lattice = getattr(mesh, "lattice", None)
    if lattice is None:
        return ()
    a1, a2 = (tuple(float(x) for x in v) for v in (lattice.a1, lattice.a2))
    return (
        f"the mesh is a cell of a lattice (a1 = ({a1[0]:g}, {a1[1]:g}) mm, a2 = "
        f"({a2[0]:g}, {a2[1]:g}) mm) but is solved as one finite scatterer in free space: "
        f"the lattice is ignored, and the result is for this mesh alone, not for an "
        f"infinite periodic array",
    )


def electrical_size(geometry_vertices: np.ndarray, k: float) -> float:
    """k·D (rad): D is the diagonal (m) of the bounding box of the vertices (m)."""
    span = np.ptp(np.asarray(geometry_vertices, dtype=float), axis=0)
    return float(k * np.linalg.norm(span))


def low_frequency_warning(
    kd: float, condition_number: float, use_condition: bool = True
) -> tuple[str, ...]:
    """A sentence when k·D or the condition number says the EFIE has broken down.

    Parameters
    ----------
    kd : float
        Electrical size k·D (see :func:`electrical_size`).
    condition_number : float
        The solve's 1-norm condition number estimate.
    use_condition : bool
        Also warn on a condition number above :data:`CONDITION_LIMIT` alone.

    Examples
    --------
    >>> low_frequency_warning(8.9, 450.0)
    ()
    >>> low_frequency_warning(8.9e-5, 3.3e12)[0][:40]
    'low-frequency breakdown of the EFIE: k·D'
    """
    small = kd < LOW_FREQUENCY_KD
    ill = use_condition and not condition_number <= CONDITION_LIMIT  # NaN, inf: ill
    if not (small or ill):
        return ()
    if small:
        head = (
            f"low-frequency breakdown of the EFIE: k·D = {kd:.3g} (below {LOW_FREQUENCY_KD:g}; "
            f"D the mesh's bounding-box diagonal), condition number {condition_number:.3g}"
        )
    else:
        head = (
            f"ill-conditioned EFIE: condition number {condition_number:.3g} (above "
            f"{CONDITION_LIMIT:.0e}) at k·D = {kd:.3g}"
        )
    return (
        head + ": the currents may be inaccurate and the extinction, scattering and "
        "absorption cross-sections (small differences of large terms) may be wrong, even "
        "negative; a loop-star or augmented EFIE would be needed (not implemented)",
    )


def overlap_warning(mesh: TriMesh, condition_number: float) -> tuple[str, ...]:
    """A sentence for a paper-mode mesh whose patches overlap."""
    ratio = mesh.overlap_ratio if mesh.mode == "paper" else None
    if not ratio or ratio <= 1e-12:
        return ()
    return (
        f"paper-mode mesh with overlapping patches (overlap ratio {ratio:.3g}): the "
        f"overlaps carry doubled, non-conforming currents and the matrix condition number "
        f"is {condition_number:.3g}; a conforming mesh gives the physical solution",
    )


def check_electrical_size(mesh: TriMesh, frequency: float, name: str = "frequency") -> float:
    """Refuse a frequency at which double precision cannot form the EFIE of ``mesh``.

    Returns k·D (:func:`electrical_size`); raises ValueError naming ``name`` below
    :data:`MIN_KD`, with the lowest frequency the mesh can be solved at.
    """
    vertices = np.asarray(mesh.points, dtype=float) * METRES_PER_MESH_UNIT
    k = 2.0 * np.pi * frequency / SPEED_OF_LIGHT
    kd = electrical_size(vertices, k)
    if not kd >= MIN_KD:
        lowest = MIN_KD * frequency / kd if kd > 0 else float("inf")
        raise ValueError(
            f"{name}={frequency:.6g} Hz is too low for this mesh: k·D = {kd:.3g}, and below "
            f"{MIN_KD:g} double precision cannot form the EFIE (its vector potential is lost "
            f"in rounding); expected {name} >= {lowest:.3g} Hz"
        )
    return kd


def coarse_mesh_warning(mesh: TriMesh, k: float) -> tuple[str, ...]:
    """A sentence when edges of ``mesh`` are longer than λ/10 at wavenumber ``k`` (rad/m)."""
    lengths = mesh.edge_lengths  # mm
    wavelength = 2.0 * np.pi / k / METRES_PER_MESH_UNIT  # mm
    limit = wavelength / CELLS_PER_WAVELENGTH
    over = int(np.count_nonzero(lengths > limit))
    if not over:
        return ()
    longest = float(lengths.max())
    ghz = k * _C_OVER_2PI / 1e9
    return (
        f"mesh too coarse for the wavelength: at {ghz:.6g} GHz (λ = {wavelength:.4g} mm) "
        f"{over:,} of {len(lengths):,} edges are over λ/{CELLS_PER_WAVELENGTH:g}, the longest "
        f"{longest:.4g} mm ({longest / wavelength:.3g} λ); the currents and cross-sections "
        "are unreliable: refine the mesh",
    )


def solve_warnings(mesh: TriMesh, k: float, condition_number: float) -> tuple[str, ...]:
    """All caveats of a solve of ``mesh`` at wavenumber ``k`` (rad/m), in a fixed order.

    The condition-number warning is left out when the overlap warning (which
    names the condition number and its cause) is given.
    """
    vertices = np.asarray(mesh.points, dtype=float) * METRES_PER_MESH_UNIT
    overlap = overlap_warning(mesh, condition_number)
    kd = electrical_size(vertices, k)
    low = low_frequency_warning(kd, condition_number, use_condition=not overlap)
    coarse = coarse_mesh_warning(mesh, k)
    return overlap + junction_warning(mesh) + lattice_warning(mesh) + low + coarse
