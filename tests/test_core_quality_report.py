"""barymesh.quality.quality_report: closed forms on hand-made triangles, the issue's measured
presets, the λ/10 rule, the worst list and JSON without NaN."""

import json
from types import SimpleNamespace

import numpy as np
import pytest

from barymesh import MeshParams, TriMesh, build_mesh
from barymesh.presets import load_preset
from barymesh.quality import (
    ASPECT_RATIO_THRESHOLD,
    HISTOGRAM_BINS,
    longest_sides,
    params_wavelength,
    quality_lines,
    quality_report,
    triangle_quality,
    wavelength_mm,
)

SQRT3 = np.sqrt(3.0)


def mesh_of(corners):
    """Separate triangles from a (T, 3, 2) array of corners."""
    corners = np.asarray(corners, dtype=np.float64)
    n = len(corners)
    return TriMesh(
        corners.reshape(-1, 2),
        np.arange(3 * n).reshape(n, 3),
        np.arange(n),
        np.ones(n, dtype=int),
        n,
    )


def isosceles(apex_deg, base_at=(0.0, 0.0)):
    """Two unit legs around an apex angle, apex at ``base_at``."""
    a = np.radians(apex_deg)
    x, y = base_at
    return [(x, y), (x + 1.0, y), (x + np.cos(a), y + np.sin(a))]


# equilateral (60°, 1); 30-30-120 (30°, (2+√3)/√3); 90-45-45 (45°, (2+√2)/(2√3)·√2);
# 20-20-140 (20°): a flat cap, ratio 2cos20 (2 + 2cos20)/(4√3 · ½ sin140)
FOUR = [isosceles(60), isosceles(120, (3, 0)), isosceles(90, (6, 0)), isosceles(140, (9, 0))]
CAP20 = (
    2
    * np.cos(np.radians(20))
    * (2 + 2 * np.cos(np.radians(20)))
    / (4 * SQRT3 * 0.5 * np.sin(np.radians(140)))
)


def test_closed_forms_of_four_triangles():
    r = quality_report(mesh_of(FOUR), worst=4)
    a, ar = r["min_angle_deg"], r["aspect_ratio"]
    assert r["triangles"] == 4
    assert a["min"] == pytest.approx(20.0, abs=1e-12)
    assert a["below"] == 1  # 30-30-120 sits on the threshold: not below it
    assert ar["max"] == pytest.approx(CAP20, rel=1e-12)
    assert CAP20 > ASPECT_RATIO_THRESHOLD and ar["above"] == 1
    assert ar["degenerate"] == 0
    # worst first: 20°, 30°, 45°, 60°, with the closed-form ratios
    assert [w["triangle"] for w in r["worst"]] == [3, 1, 2, 0]
    assert [w["min_angle_deg"] for w in r["worst"]] == pytest.approx([20, 30, 45, 60], abs=1e-12)
    assert [w["aspect_ratio"] for w in r["worst"]] == pytest.approx(
        [CAP20, (2 + SQRT3) / SQRT3, np.sqrt(2) * (2 + np.sqrt(2)) / (2 * SQRT3), 1.0], rel=1e-12
    )
    apex = np.radians(140)
    assert r["worst"][0]["centroid"] == pytest.approx(
        [(9 + 10 + 9 + np.cos(apex)) / 3, np.sin(apex) / 3, 0.0], abs=1e-12
    )
    assert r["edge_wavelength"] is None


def test_histograms_count_every_triangle_once():
    mesh = build_mesh(
        MeshParams(structure="split_ring", mode="conforming", angle_step=10.0, subdivisions=3)
    )
    r = quality_report(mesh, wavelength=20.0)
    for key in ("min_angle_deg", "aspect_ratio", "edge_wavelength"):
        h = r[key]["histogram"]
        assert len(h["edges"]) == HISTOGRAM_BINS + 1 and len(h["counts"]) == HISTOGRAM_BINS
        assert np.all(np.diff(h["edges"]) > 0)
        assert sum(h["counts"]) + h["below_range"] + h["above_range"] == mesh.n_triangles
    # the bins agree with the per-triangle angles: the count below 30° is the first 15 bins
    assert r["min_angle_deg"]["histogram"]["edges"][15] == 30.0
    assert sum(r["min_angle_deg"]["histogram"]["counts"][:15]) == r["min_angle_deg"]["below"]
    assert r["min_angle_deg"]["percentiles"]["50"] == pytest.approx(np.median(mesh.min_angles))


def test_thirty_degrees_bounds_the_aspect_ratio_below_the_threshold():
    """Every triangle of smallest angle ≥ 30° has aspect ratio ≤ (2+√3)/√3 < 3 (the
    justification of the threshold), over a fine grid of angle pairs."""
    b, c = np.meshgrid(np.linspace(30, 120, 361), np.linspace(30, 120, 361))
    keep = (180 - b - c) >= 30 - 1e-9
    b, c = np.radians(b[keep]), np.radians(c[keep])
    corners = np.stack([np.zeros_like(b), np.ones_like(b)], axis=1)  # side from A to B
    # the third vertex where the angles at A (b) and B (c) meet
    t = np.sin(c) / np.sin(b + c)
    third = np.stack([t * np.cos(b), t * np.sin(b)], axis=1)
    pts = np.concatenate(
        [
            np.column_stack([corners[:, 0], corners[:, 0]]),
            np.column_stack([corners[:, 1], np.zeros_like(b)]),
            third,
        ]
    )
    n = len(b)
    tri = np.column_stack([np.arange(n), n + np.arange(n), 2 * n + np.arange(n)])
    q = triangle_quality(np.column_stack([pts, np.zeros(len(pts))]), tri)
    assert q.min_angles_deg.min() >= 30 - 1e-6
    assert q.aspect_ratios.max() == pytest.approx((2 + SQRT3) / SQRT3, rel=1e-9)
    assert q.aspect_ratios.max() < ASPECT_RATIO_THRESHOLD


def test_thin_rectangle_closed_form():
    """A 10 mm x 2 mm patch, n = 4: every triangle has legs a = 2.5 and b = 0.5 mm: the
    smallest angle atan(b/a), the aspect ratio c (a + b + c) / (4√3 ab/2), c = √(a² + b²);
    all 32 under 30° and above 3, ties listed by index."""
    mesh = build_mesh(MeshParams(structure="patch", patch_size=10.0, patch_width=2.0))
    r = quality_report(mesh, worst=5)
    a, b = 2.5, 0.5
    c = np.hypot(a, b)
    assert r["triangles"] == 32
    assert r["min_angle_deg"]["min"] == pytest.approx(np.degrees(np.arctan(b / a)), rel=1e-12)
    assert r["aspect_ratio"]["max"] == pytest.approx(
        c * (a + b + c) / (4 * SQRT3 * a * b / 2), rel=1e-12
    )
    assert r["min_angle_deg"]["below"] == 32 and r["aspect_ratio"]["above"] == 32
    assert [w["triangle"] for w in r["worst"]] == [0, 1, 2, 3, 4]


def test_conforming_presets_meet_the_30_degree_floor():
    """Issue 12: the conforming presets whose geometry allows it have no triangle under
    30° (paper-fig8-dsdr's 2° sector bound does not: its floor is reported instead)."""
    for name in ("conforming-double-ring", "srr-openmodes"):
        mesh = build_mesh(load_preset(name)[0])
        r = quality_report(mesh, worst=0)
        assert r["min_angle_deg"]["min"] >= 30.0 and r["min_angle_deg"]["below"] == 0
        assert r["worst"] == []
    dsdr = build_mesh(load_preset("paper-fig8-dsdr")[0])
    floor = dsdr.stats()["min_angle_floor_deg"]
    assert floor < 30.0
    assert quality_report(dsdr)["min_angle_deg"]["min"] == pytest.approx(floor, abs=0.5)


def test_edge_over_wavelength_on_the_papers_patch():
    """Fig. 10: a 10 mm patch, n = 4: legs 2.5 mm, hypotenuse 2.5√2 mm on every triangle."""
    mesh = build_mesh(MeshParams(structure="patch", patch_size=10.0, subdivisions=4))
    assert np.allclose(longest_sides(mesh.points, mesh.triangles), 2.5 * np.sqrt(2))
    over = quality_report(mesh, wavelength=30.0)["edge_wavelength"]
    assert over["max"] == pytest.approx(2.5 * np.sqrt(2) / 30.0, rel=1e-12)
    assert over["above"] == 32 and over["threshold"] == 0.1
    under = quality_report(mesh, wavelength=40.0)["edge_wavelength"]  # 3.54 mm < 4 mm
    assert under["above"] == 0 and under["wavelength_mm"] == 40.0
    for r in (over, under):
        assert sum(r["histogram"]["counts"]) == 32


def test_wavelength_from_frequency_and_permittivity():
    assert wavelength_mm(10e9) == pytest.approx(29.9792458, rel=1e-12)
    assert wavelength_mm(10e9, 4.0) == pytest.approx(29.9792458 / 2, rel=1e-12)
    assert params_wavelength(SimpleNamespace(frequency=1e9)) == pytest.approx(299.792458)
    assert params_wavelength(
        SimpleNamespace(frequency=5e9, relative_permittivity=2.25)
    ) == pytest.approx(299.792458 / 5 / 1.5)
    assert params_wavelength(MeshParams()) is None  # no frequency: no wavelength
    assert params_wavelength(None) is None
    with pytest.raises(ValueError, match="frequency"):
        wavelength_mm(-1.0)
    with pytest.raises(ValueError, match="relative_permittivity"):
        wavelength_mm(1e9, 0.5)


def test_worst_list_is_the_smallest_angles_ties_by_index():
    mesh = build_mesh(load_preset("conforming-double-ring")[0])
    r = quality_report(mesh, worst=25)
    order = np.lexsort((np.arange(mesh.n_triangles), mesh.min_angles))[:25]
    assert [w["triangle"] for w in r["worst"]] == order.tolist()
    assert [w["min_angle_deg"] for w in r["worst"]] == mesh.min_angles[order].tolist()
    assert np.allclose([w["centroid"] for w in r["worst"]], mesh.centroids[order])
    assert len(quality_report(mesh, worst=10_000)["worst"]) == mesh.n_triangles


def test_degenerate_triangles_give_json_without_nan():
    flat = [[(0, 0), (1, 0), (2, 0)], [(0, 1), (0, 1), (0, 1)], isosceles(60, (5, 5))]
    r = quality_report(mesh_of(flat), wavelength=10.0)
    text = json.dumps(r, allow_nan=False)  # raises on NaN or inf
    back = json.loads(text)
    assert back["aspect_ratio"]["max"] is None and back["aspect_ratio"]["degenerate"] == 2
    assert back["aspect_ratio"]["above"] == 2
    assert back["min_angle_deg"]["min"] == 0.0 and back["min_angle_deg"]["below"] == 2
    assert back["worst"][0]["aspect_ratio"] is None
    assert any("degenerate" in line for line in quality_lines(r))


def test_empty_mesh_and_bad_arguments():
    empty = TriMesh(np.zeros((0, 3)), np.zeros((0, 3), dtype=int), [], [], 0)
    r = quality_report(empty)
    assert r["triangles"] == 0 and r["min_angle_deg"]["min"] is None and r["worst"] == []
    json.dumps(r, allow_nan=False)
    mesh = mesh_of(FOUR)
    for bad in (-1, 2.5, True):
        with pytest.raises(ValueError, match="worst"):
            quality_report(mesh, worst=bad)
    for bad in (0.0, -3.0, float("nan"), float("inf")):
        with pytest.raises(ValueError, match="wavelength"):
            quality_report(mesh, wavelength=bad)


def test_summary_lines():
    mesh = build_mesh(MeshParams(structure="patch", patch_size=10.0, subdivisions=4))
    lines = quality_lines(quality_report(mesh, wavelength=30.0))
    assert lines[0].startswith("  smallest angle 45 deg")
    assert "below 30 deg: 0 (0%)" in lines[0]
    assert "above 1/10: 32 (100%)" in lines[2]
