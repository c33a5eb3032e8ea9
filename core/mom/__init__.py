"""Method of Moments on RWG meshes: the EFIE for perfect conductors in free space and,
for infinite arrays, on dielectric layers.

Time convention e^(jωt); meshes in mm, everything else in SI units.

>>> from barymesh import MeshParams, build_mesh
>>> from barymesh.mom import PlaneWave, solve
>>> mesh = build_mesh(MeshParams(structure="patch", patch_size=100.0, subdivisions=2))
>>> s = solve(mesh, 1e9, PlaneWave(direction=(0, 0, -1), polarization=(1, 0, 0)))
>>> bool(abs(s.extinction_cross_section / s.scattering_cross_section - 1) < 0.01)
True

Modules: :mod:`.quadrature` (triangle rules), :mod:`.singular` (closed-form
potential integrals), :mod:`.geometry` (the per-mesh cache),
:mod:`.operator` (the impedance matrix), :mod:`.near_series` (its near pairs' smooth
kernel as a power series in k), :mod:`.excitation`,
:mod:`.solution` (post-processing), :mod:`.solve` (solve and sweep);
for an infinite array, :mod:`.periodic_green` (the Ewald periodic Green's function),
:mod:`.periodic_geometry` (a cell's frequency-independent data, cached per mesh),
:mod:`.periodic_plan` (the fill's per-mesh tables, kept by the geometry),
:mod:`.periodic_fill` (how the matrix is filled at each frequency),
:mod:`.floquet` (the Floquet orders, their onsets and their TE/TM fields),
:mod:`.periodic` (the periodic EFIE, Floquet reflection and transmission),
:mod:`.periodic_sweep` (its frequency sweeps, point by point or interpolating);
:mod:`.stack` (dielectric layers and a ground plane around the sheet, as transmission
lines) and :mod:`.periodic_layered` (the layered kernel the fill integrates);
:mod:`.reflection_library` (a cell's reflection over one parameter: the S-curve of a
reflectarray's elements, and its inverse); :mod:`.circuit` (the sheet impedance of an
array, its Foster LC circuit and Luukkonen et al.'s analytic model of patches).
"""

from .circuit import EquivalentCircuit, equivalent_circuit
from .excitation import PlaneWave, VoltageSource, excitation_vector
from .floquet import grating_lobe_onsets, te_tm_polarizations
from .geometry import MomGeometry, mom_geometry
from .operator import impedance_matrix, wavenumber
from .periodic import (
    PeriodicSolution,
    check_periodic_memory,
    periodic_geometry,
    periodic_solve,
    periodic_solve_many,
)
from .periodic_green import PeriodicGreen
from .periodic_sweep import PeriodicSweep, periodic_sweep
from .reflection_library import ReflectionLibrary, reflection_library
from .solution import Solution
from .solve import (
    ProblemTooLarge,
    SolveCancelled,
    SweepResult,
    check_memory,
    find_peaks,
    lorentzian_peaks,
    solve,
    sweep,
)
from .stack import Layer, Stack, parse_stack

__all__ = [
    "EquivalentCircuit",
    "Layer",
    "MomGeometry",
    "PeriodicGreen",
    "PeriodicSolution",
    "PeriodicSweep",
    "PlaneWave",
    "ProblemTooLarge",
    "ReflectionLibrary",
    "Solution",
    "SolveCancelled",
    "Stack",
    "SweepResult",
    "VoltageSource",
    "check_memory",
    "check_periodic_memory",
    "equivalent_circuit",
    "excitation_vector",
    "find_peaks",
    "grating_lobe_onsets",
    "impedance_matrix",
    "lorentzian_peaks",
    "mom_geometry",
    "parse_stack",
    "periodic_geometry",
    "periodic_solve",
    "periodic_solve_many",
    "periodic_sweep",
    "reflection_library",
    "solve",
    "sweep",
    "te_tm_polarizations",
    "wavenumber",
]
