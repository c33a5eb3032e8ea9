"""Teaching helpers of the core: RWG basis sampling and the step-by-step construction."""

import numpy as np
import pytest

from barymesh import MeshParams, build_mesh
from barymesh.teach.construction import construction_steps
from barymesh.teach.rwg_basis import edge_status, quadrature_points, sample_rwg


@pytest.fixture(scope="module")
def ring():
    return build_mesh(MeshParams(structure="ring", mode="conforming", angle_step=30))


def test_rwg_normal_component_is_one_across_the_edge(ring):
    """f_n · n̂ = 1 on edge n from both sides: the current is continuous across it."""
    for edge in ring.interior_edges[::7]:
        b = sample_rwg(ring, int(edge))
        v0, v1 = ring.points[b.vertices]
        mid = (v0 + v1) / 2
        tangent = (v1 - v0) / np.linalg.norm(v1 - v0)
        normal = np.array([tangent[1], -tangent[0], 0.0])
        if np.dot(normal, b.centroid_minus - b.centroid_plus) < 0:
            normal = -normal  # from T+ into T-
        f_plus = b.length / (2 * b.area_plus) * (mid - ring.points[b.free_plus])
        f_minus = b.length / (2 * b.area_minus) * (ring.points[b.free_minus] - mid)
        assert np.dot(f_plus, normal) == pytest.approx(1.0)
        assert np.dot(f_minus, normal) == pytest.approx(1.0)
        # divergence: l/A+ on T+, -l/A- on T-, integrating to zero
        assert b.divergence_plus * b.area_plus + b.divergence_minus * b.area_minus == pytest.approx(
            0.0, abs=1e-12
        )


def test_rwg_samples_at_subtriangle_centroids(ring):
    edge = int(ring.interior_edges[0])
    b = sample_rwg(ring, edge, quadrature=4)
    assert b.points_plus.shape == (16, 3) and b.values_minus.shape == (16, 3)
    # the mean of the quadrature points is the triangle's centroid
    assert np.allclose(b.points_plus.mean(0), b.centroid_plus)
    assert np.allclose(b.values_plus.mean(0), b.length / (2 * b.area_plus) * b.rho_plus)
    assert (b.t_plus, b.t_minus) == (int(ring.rwg.t_plus[b.row]), int(ring.rwg.t_minus[b.row]))
    assert ring.rwg.edge[b.row] == edge


def test_quadrature_points_by_hand():
    corners = np.array([[0.0, 0, 0], [3, 0, 0], [0, 3, 0]])
    q = quadrature_points(corners, 1)
    assert np.allclose(q, [[1, 1, 0]])
    assert len(quadrature_points(corners, 3)) == 9


def test_edges_without_rwg_say_why(ring):
    edge = int(ring.boundary_edges[0])
    assert edge_status(ring, edge).startswith("boundary edge: on one triangle only")
    with pytest.raises(ValueError, match=f"edge {edge} has no RWG function: boundary edge"):
        sample_rwg(ring, edge)
    with pytest.raises(ValueError, match="out of range"):
        edge_status(ring, 10**6)


def test_construction_of_the_paper_patch():
    steps = construction_steps(MeshParams(structure="patch", patch_size=10.0))
    assert [s.title for s in steps] == [
        "Square patch ABCD",
        "Diagonal BC: primary triangles ABC and BCD",
        "Edge midpoints m1, m2, m3",
        "Quarter points m11, m12, m21, m22",
        "Connecting lines",
        "32 sub-triangles",
        "Centroids",
        "Shared edges",
    ]
    last = steps[-1]
    where = {
        label: tuple(p) for label, p in zip(last.labels, last.points.tolist(), strict=True) if label
    }
    assert where == {
        "A": (0, 0),
        "B": (10, 0),
        "C": (0, 10),
        "D": (10, 10),
        "m1": (5, 0),
        "m2": (0, 5),
        "m3": (5, 5),
        "m11": (2.5, 0),
        "m12": (7.5, 0),
        "m22": (0, 2.5),
        "m21": (0, 7.5),
    }
    assert len(steps[5].triangles) == 32 and len(steps[5].centroids) == 0
    assert len(steps[6].centroids) == 32
    assert len(last.shared_edges) == 40
    assert np.allclose(steps[1].highlight, [[[10, 0], [0, 10]]])


@pytest.mark.parametrize(("n", "titles"), [(1, 5), (3, 7), (8, 9)])
def test_construction_for_any_n(n, titles):
    steps = construction_steps(MeshParams(structure="patch", subdivisions=n))
    assert len(steps) == titles
    assert len(steps[-1].triangles) == 2 * n * n
    assert len(steps[-1].shared_edges) == 3 * n * n - 2 * n


def test_construction_of_one_triangle():
    steps = construction_steps(MeshParams(structure="triangle", subdivisions=4, patch_size=2))
    assert steps[0].title == "Primary triangle ABC"
    assert len(steps[-1].triangles) == 16
    assert "m11" in steps[-1].labels


def test_sweep_of_angle_step_and_subdivisions():
    from barymesh.teach.sweep import sweep_params

    angles = [p.angle_step for p in sweep_params(MeshParams(), "angle_step", 20, 1, 20)]
    assert angles[0] == 20 and angles[-1] == 1 and len(angles) == 20
    ns = [p.subdivisions for p in sweep_params(MeshParams(), "subdivisions", 1, 8, 8)]
    assert ns == list(range(1, 9))


def test_sweep_errors_name_the_frame():
    from barymesh.teach.sweep import sweep_params

    with pytest.raises(ValueError, match=r"sweep frame 2 of 3 \(patch_size=0.0\): patch_size=0"):
        sweep_params(MeshParams(), "patch_size", 1, -1, 3)
    with pytest.raises(ValueError, match="cannot sweep 'mode'"):
        sweep_params(MeshParams(), "mode", 1, 2, 3)
    with pytest.raises(ValueError, match="frames=1 is invalid"):
        sweep_params(MeshParams(), "patch_size", 1, 2, 1)


def test_the_teaching_helpers_keep_their_old_names():
    # moved into barymesh.teach (issue 31); scripts importing the old names get the same
    # modules, not copies
    import importlib

    for name in ("construction", "rwg_basis", "sweep"):
        old = importlib.import_module(f"barymesh.{name}")
        assert old is importlib.import_module(f"barymesh.teach.{name}")
    from barymesh.sweep import sweep_params as old_sweep_params

    assert old_sweep_params is sweep_params_of_teach()


def sweep_params_of_teach():
    from barymesh.teach.sweep import sweep_params

    return sweep_params
