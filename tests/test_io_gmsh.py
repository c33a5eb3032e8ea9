"""Gmsh MSH 2.2 and 4.1 files read back by Gmsh itself (its Python API), meshio and our reader.

Gmsh (the ``test`` extra; its wheel needs the X11/OpenGL libraries of ``GMSH_DEPS`` in the
Makefile, which ``make test`` installs) is the reference reader: its physical groups,
entities, nodes, elements and, for MSH 4.1, the ``$Periodic`` links it builds from the
file. Gmsh 4 keeps the ``$Periodic`` section of an MSH 2.2 file only as a model attribute
(it does so with its own 2.2 files too), so there meshio reads the links and the section
is compared with the layout Gmsh writes.
"""

from __future__ import annotations

import meshio
import numpy as np
import pytest
from helpers import canonical_meshes

from barymesh import TriMesh, build_mesh
from barymesh.app.cli import main
from barymesh.cell import build_cell, load_cell_preset
from barymesh.io import MSH_VERSIONS, describe_export, read_mesh, write_mesh, write_periodic_msh
from barymesh.presets import load_preset


@pytest.fixture
def gmsh():
    """Gmsh's Python API, initialised for one test (skipped where its wheel cannot load)."""
    try:
        import gmsh as api
    except (ImportError, OSError) as exc:  # OSError: libGLU & co. missing (GMSH_DEPS)
        pytest.skip(f"gmsh cannot be imported here: {exc}")
    api.initialize(interruptible=False)
    api.option.setNumber("General.Terminal", 0)
    try:
        yield api
    finally:
        api.finalize()


def gmsh_contents(gmsh, path):
    """What Gmsh reads: {physical (dim, tag): (name, triangles)}, nodes, triangles, entities."""
    gmsh.open(str(path))
    groups = {}
    for dim, tag in gmsh.model.getPhysicalGroups():
        count = 0
        for entity in gmsh.model.getEntitiesForPhysicalGroup(dim, tag):
            types, elements, _ = gmsh.model.mesh.getElements(dim, int(entity))
            count += sum(len(e) for e in elements)
        groups[(dim, tag)] = (gmsh.model.getPhysicalName(dim, tag), count)
    node_tags, coords, _ = gmsh.model.mesh.getNodes()
    tri_types, tri_tags, tri_nodes = gmsh.model.mesh.getElements(2)
    assert list(tri_types) == [2]  # 3-node triangles only
    points = dict(zip(node_tags.tolist(), coords.reshape(-1, 3).tolist(), strict=True))
    triangles = [
        tuple(sorted(tuple(points[n]) for n in tri)) for tri in tri_nodes[0].reshape(-1, 3).tolist()
    ]
    return groups, len(node_tags), sorted(triangles), gmsh.model.getEntities(2)


def triangle_corners(mesh, scale=1.0):
    p = (mesh.points * scale).tolist()
    return sorted(tuple(sorted(tuple(p[v]) for v in tri)) for tri in mesh.triangles.tolist())


@pytest.fixture(scope="module")
def rings():
    """paper-fig8-dsdr: a conforming double ring, regions 1 and 2, 2,752 triangles."""
    return build_mesh(load_preset("paper-fig8-dsdr")[0])


@pytest.mark.parametrize("version", MSH_VERSIONS)
def test_gmsh_reads_the_regions_patches_and_triangles(tmp_path, gmsh, rings, version):
    path = write_mesh(rings, tmp_path / "rings.msh", msh_version=version)
    assert path.read_text().startswith(f"$MeshFormat\n{version} 0 8\n")
    groups, n_nodes, triangles, entities = gmsh_contents(gmsh, path)
    inner, outer = (int(np.count_nonzero(rings.regions == r)) for r in (1, 2))
    assert inner + outer == rings.n_triangles == 2_752 and inner > 0 and outer > 0
    assert groups == {(2, 1): ("inner_ring", inner), (2, 2): ("outer_ring", outer)}
    assert n_nodes == rings.n_vertices
    assert triangles == triangle_corners(rings)  # the coordinates exactly (17 digits)
    if version == "4.1":  # every patch (sector) is one surface entity
        assert sorted(tag for _, tag in entities) == list(range(1, rings.n_patches + 1))


def test_msh41_round_trips_through_meshio_and_our_reader(tmp_path, rings):
    path = write_mesh(rings, tmp_path / "rings.msh", msh_version="4.1")
    m = meshio.read(path)
    assert sum(len(c.data) for c in m.cells if c.type == "triangle") == rings.n_triangles
    assert {k: v.tolist() for k, v in m.field_data.items()} == {
        "inner_ring": [1, 2],
        "outer_ring": [2, 2],
    }
    back = read_mesh(path)
    assert back.n_patches == rings.n_patches and back.n_triangles == rings.n_triangles

    # every triangle keeps its region and its patch (grouped by patch in the file)
    def labelled(mesh):
        p = mesh.points.tolist()
        return sorted(
            (tuple(sorted(tuple(p[v]) for v in tri)), r, q)
            for tri, r, q in zip(
                mesh.triangles.tolist(), mesh.regions.tolist(), mesh.patch_ids.tolist(), strict=True
            )
        )

    assert labelled(back) == labelled(rings)


def test_msh41_in_metres(tmp_path, gmsh):
    mesh = canonical_meshes()["patch"]
    path = write_mesh(mesh, tmp_path / "p.msh", unit="m", msh_version="4.1")
    groups, _, triangles, _ = gmsh_contents(gmsh, path)
    assert groups == {(2, 1): ("patch", mesh.n_triangles)}
    np.testing.assert_allclose(np.array(triangles), np.array(triangle_corners(mesh, 1e-3)))


def test_msh41_gives_a_patch_whose_vertices_all_lie_on_others_a_node_of_its_own(tmp_path, gmsh):
    # patch 0 holds every vertex first; without the matching patch 1 would name no node,
    # and Gmsh and meshio would not know its entity (nor its physical group)
    mesh = TriMesh(
        points=[[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [1.0, 1.0, 0.0], [0.0, 1.0, 0.0]],
        triangles=[[0, 1, 2], [0, 2, 3], [0, 1, 3]],
        patch_ids=[0, 0, 1],
        regions=[1, 1, 2],
        n_patches=2,
    )
    path = write_mesh(mesh, tmp_path / "two.msh", msh_version="4.1")
    groups, n_nodes, _, entities = gmsh_contents(gmsh, path)
    assert sorted(tag for _, tag in entities) == [1, 2]
    assert groups == {(2, 1): ("inner_ring", 2), (2, 2): ("outer_ring", 1)}
    assert n_nodes == 4
    back = read_mesh(path)
    assert sorted(back.regions.tolist()) == [1, 1, 2] and back.n_patches == 2


def test_msh_version_is_checked():
    mesh = canonical_meshes()["patch"]
    with pytest.raises(ValueError, match=r"msh_version='3' is not a Gmsh version we write"):
        write_mesh(mesh, "never.msh", msh_version="3")
    assert describe_export("a.msh", "m", "4.1") == "a.msh (Gmsh MSH 4.1 ASCII, m)"
    assert describe_export("a.msh") == "a.msh (Gmsh MSH 2.2 ASCII, mm)"


# -- a unit cell's $Periodic --------------------------------------------------------


@pytest.fixture(scope="module")
def coding():
    """coding-16x16: an 8 mm square cell of pixels, periodic along both lattice vectors."""
    return build_cell(load_cell_preset("coding-16x16"))


def test_gmsh_reads_the_periodic_links_of_msh41(tmp_path, gmsh, coding):
    path = tmp_path / "coding.msh"
    write_periodic_msh(coding, path, msh_version="4.1")
    groups, n_nodes, triangles, _ = gmsh_contents(gmsh, path)
    pairs = coding.periodic_pairs
    assert n_nodes == coding.mesh.n_vertices and len(triangles) == 3_968
    sides = {tag: count for (dim, tag), (_, count) in groups.items() if dim == 1}
    names = {tag: name for (dim, tag), (name, _) in groups.items()}
    assert names == {
        1: "pixels",
        1001: "a1_minus",
        1002: "a1_plus",
        1003: "a2_minus",
        1004: "a2_plus",
    }
    per_shift = [int(np.count_nonzero(pairs.edge_shift == k)) for k in (0, 1)]
    assert sides == {1001: per_shift[0], 1002: per_shift[0], 1003: per_shift[1], 1004: per_shift[1]}
    assert sum(per_shift) == len(pairs.edges) == 64
    for slave, master, shift, k in ((2, 1, (8.0, 0.0), 0), (4, 3, (0.0, 8.0), 1)):
        tag, slaves, masters, affine = gmsh.model.mesh.getPeriodicNodes(1, slave)
        assert tag == master
        t = np.asarray(affine).reshape(4, 4)
        np.testing.assert_array_equal(t[:3, :3], np.eye(3))
        np.testing.assert_array_equal(t[:2, 3], shift)
        assert len(slaves) == int(np.count_nonzero(pairs.vertex_shift == k)) > 0
        xyz = {}
        for node in set(slaves.tolist()) | set(masters.tolist()):
            xyz[node] = np.asarray(gmsh.model.mesh.getNode(node)[0])
        moved = np.array(
            [xyz[s] - xyz[m] for s, m in zip(slaves.tolist(), masters.tolist(), strict=True)]
        )
        np.testing.assert_allclose(moved[:, :2], np.tile(shift, (len(moved), 1)), atol=1e-12)


def test_msh22_periodic_section_has_gmshs_layout(tmp_path, gmsh, coding):
    path = tmp_path / "coding.msh"
    write_periodic_msh(coding, path)  # 2.2, the default
    groups, n_nodes, triangles, _ = gmsh_contents(gmsh, path)
    assert groups[(2, 1)] == ("pixels", 3_968) and n_nodes == coding.mesh.n_vertices
    text = path.read_text()
    section = text[text.index("$Periodic\n") : text.index("$EndPeriodic")].splitlines()
    assert section[1] == "2"  # two links: a1's and a2's
    assert section[2] == "1 2 1"  # dimension, slave curve, master curve
    affine = section[3].split()
    assert affine[0] == "Affine" and [float(v) for v in affine[1:]] == [
        1,
        0,
        0,
        8,
        0,
        1,
        0,
        0,
        0,
        0,
        1,
        0,
        0,
        0,
        0,
        1,
    ]
    count = int(section[4])
    assert count == int(np.count_nonzero(coding.periodic_pairs.vertex_shift == 0))
    assert section[5 + count] == "1 4 3"


def test_command_line_writes_msh41(tmp_path, capsys, gmsh):
    out = tmp_path / "c.msh"
    code = main(["mesh", "--cell-preset", "coding-16x16", "-o", str(out), "--msh-version", "4.1"])
    printed = capsys.readouterr().out
    assert code == 0
    assert f"wrote {out} (Gmsh MSH 4.1 ASCII, mm) with $Periodic: 64 edge pairs" in printed
    gmsh.open(str(out))
    assert gmsh.model.mesh.getPeriodicNodes(1, 2)[0] == 1


def test_command_line_refuses_msh_version_without_msh(capsys):
    assert main(["mesh", "--preset", "paper-fig10", "--msh-version", "4.1"]) == 2
    err = capsys.readouterr().err
    assert "--msh-version 4.1 sets the format of a .msh output; add -o FILE.msh" in err
    assert main(["mesh", "--preset", "paper-fig10", "-o", "x.msh", "--msh-version", "3"]) == 2
    assert "invalid choice: '3'" in capsys.readouterr().err
