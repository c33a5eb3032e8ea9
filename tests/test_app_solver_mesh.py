"""The mesh the window solves (barymesh.app.model.solver_mesh), without Qt: which builds
are graded, the same mesh object again from the cache, a published preset and an
imported file as they are, the λ/10 refusal in the window's words."""

import pytest

from barymesh import MeshParams, build_mesh
from barymesh.app.model.build import compute, compute_cell
from barymesh.app.model.solver_mesh import (
    SolverGradeRefused,
    gradable,
    published_params,
    solver_mesh,
)
from barymesh.cell import Element, Lattice, UnitCell, build_cell
from barymesh.presets import load_preset
from barymesh.solver_grade import solver_cell, solver_params

PATCH = MeshParams(structure="patch", patch_size=100.0, subdivisions=4)


def test_a_uniform_patch_is_solved_on_its_graded_mesh_built_once():
    result = compute(PATCH)
    solved = solver_mesh(result, 1e9)
    expected = build_mesh(solver_params(PATCH, frequency=1e9))
    assert solved.graded and solved.shown is result.mesh
    assert solved.mesh.n_triangles == expected.n_triangles and len(solved.mesh.rwg) == 736
    assert solver_mesh(result, 1e9).mesh is solved.mesh  # the cache: not built again
    assert solved.describe(736, 40) == (
        "solved on the solver-grade mesh: 736 unknowns (the view shows the mesh as drawn, "
        "40 unknowns)"
    )


def test_a_cell_is_graded_for_the_densest_layer():
    cell = UnitCell(Lattice.rectangular(12.0), (Element(PATCH.replace(patch_size=8.0)),))
    result = compute_cell(cell)
    vacuum = solver_mesh(result, 20e9)
    slab = solver_mesh(result, 20e9, 10.2)  # λ/10 in εr 10.2: finer
    for solved, eps in ((vacuum, 1.0), (slab, 10.2)):
        expected = build_cell(solver_cell(cell, frequency=20e9, relative_permittivity=eps))
        assert solved.mesh.n_triangles == expected.mesh.n_triangles
        assert solved.mesh.lattice == cell.lattice
    assert slab.mesh.n_triangles > vacuum.mesh.n_triangles


def test_a_mesh_already_solver_grade_is_the_one_drawn():
    graded = solver_params(PATCH, frequency=1e9)
    result = compute(graded)
    solved = solver_mesh(result, 1e9)
    assert solved.mesh is result.mesh and not solved.graded
    assert solved.describe(736) == "solved on the mesh as drawn: 736 unknowns"


def test_published_presets_and_imported_files_are_solved_as_they_are():
    makarov = load_preset("makarov-platefine")[0]
    assert makarov in published_params()
    result = compute(makarov)
    assert not gradable(result) and solver_mesh(result, 300e6).mesh is result.mesh
    assert gradable(compute(makarov.replace(subdivisions=4)))  # no longer the published one
    imported = compute(PATCH)
    imported.source = "plate.msh"
    assert not gradable(imported) and solver_mesh(imported, 1e9).mesh is imported.mesh


def test_the_lambda_over_10_refusal_speaks_of_the_window():
    with pytest.raises(SolverGradeRefused) as info:
        solver_mesh(compute(PATCH), 1e12)
    message = str(info.value)
    assert message.startswith("the solver-grade mesh of the patch, with edges within λ/10")
    assert message.endswith("or the mesh as drawn (untick “Solver-grade mesh”)")
    assert "--mesh-as-given" not in message and isinstance(info.value, ValueError)
