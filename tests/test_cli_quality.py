"""The quality report on the command line: `mesh` and `info` print it and write it as JSON
(strict: no NaN or Infinity), equal to barymesh.quality.quality_report."""

import json

import numpy as np
import pytest
from test_cli import assert_one_line_error, run

from barymesh import MeshParams, build_mesh
from barymesh.cell import cell_preset_names
from barymesh.io import read_mesh
from barymesh.presets import load_preset
from barymesh.quality import quality_report


def strict_json(text):
    def refuse(name):
        raise ValueError(f"not JSON: {name}")

    return json.loads(text, parse_constant=refuse)


#: A 10 mm x 2 mm patch, n = 4: every triangle has legs 2.5 and 0.5 mm, so its smallest
#: angle is atan(0.2) = 11.31° and its aspect ratio c (a + b + c) / (4√3 ab/2) = 3.2675
#: (c = √6.5 mm): all 32 under 30° and above 3.
THIN = ("--set", "structure=patch", "--set", "patch_size=10", "--set", "patch_width=2")


def test_mesh_prints_and_writes_the_report(tmp_path):
    r = run("mesh", *THIN, "--quality-json", "q.json", cwd=tmp_path)
    assert r.returncode == 0, r.stderr
    assert "smallest angle 11.3 deg" in r.stdout
    assert "below 30 deg: 32 (100%)" in r.stdout
    assert "aspect ratio max 3.267, median 3.267; above 3: 32 (100%)" in r.stdout
    written = strict_json((tmp_path / "q.json").read_text())
    assert written["min_angle_deg"]["min"] == pytest.approx(np.degrees(np.arctan(0.2)))
    expected = quality_report(
        build_mesh(MeshParams(structure="patch", patch_size=10.0, patch_width=2.0))
    )
    assert written == json.loads(json.dumps(expected))
    assert len(written["worst"]) == 20 and written["edge_wavelength"] is None


def test_report_alone_on_stdout(tmp_path):
    r = run("mesh", "--preset", "srr-openmodes", "--quality-json", "-", cwd=tmp_path)
    assert r.returncode == 0, r.stderr
    report = strict_json(r.stdout)  # nothing else on stdout
    assert report == json.loads(
        json.dumps(quality_report(build_mesh(load_preset("srr-openmodes")[0])))
    )
    # issue 12: the conforming preset's sectors are nearly square, no triangle under 30°
    assert report["min_angle_deg"]["min"] >= 30.0
    below = sum(report["min_angle_deg"]["histogram"]["counts"][:15])  # bins 0..30°
    assert report["min_angle_deg"]["below"] == below == 0
    smallest = f"{report['min_angle_deg']['min']:.3g}"
    assert "quality:" in r.stderr and f"smallest angle {smallest} deg" in r.stderr


def test_info_with_frequency_adds_edge_over_wavelength(tmp_path):
    """Fig. 10 written and read back: every longest side 2.5√2 mm; at 10 GHz λ = 29.98 mm."""
    r = run("mesh", "--preset", "paper-fig10", "-o", "p.msh", cwd=tmp_path)
    assert r.returncode == 0, r.stderr
    r = run("info", "p.msh", "--frequency", "10e9", "--quality-json", "-", cwd=tmp_path)
    assert r.returncode == 0, r.stderr
    report = strict_json(r.stdout)
    over = report["edge_wavelength"]
    assert over["wavelength_mm"] == pytest.approx(29.9792458, rel=1e-12)
    assert over["max"] == pytest.approx(2.5 * np.sqrt(2) / 29.9792458, rel=1e-9)
    assert over["above"] == 32  # 0.118 > 1/10 on all 32 triangles
    assert "above 1/10: 32 (100%)" in r.stderr
    assert report == json.loads(
        json.dumps(quality_report(read_mesh(tmp_path / "p.msh"), wavelength=29.9792458))
    )


def test_degenerate_triangle_gives_null_not_nan(tmp_path):
    """A zero-area triangle has no aspect ratio: null in both JSON outputs."""
    (tmp_path / "flat.obj").write_text("v 0 0 0\nv 1 0 0\nv 2 0 0\nv 0 1 0\nf 1 2 3\nf 1 2 4\n")
    r = run("info", "flat.obj", "--quality-json", "q.json", "--stats-json", "-", cwd=tmp_path)
    assert r.returncode == 0, r.stderr
    stats = strict_json(r.stdout)
    assert stats["max_aspect_ratio"] is None
    report = strict_json((tmp_path / "q.json").read_text())
    assert report["aspect_ratio"]["max"] is None and report["aspect_ratio"]["degenerate"] == 1
    assert report["worst"][0]["triangle"] == 0 and report["worst"][0]["min_angle_deg"] == 0.0
    assert "degenerate (zero-area) triangles: 1" in r.stderr


@pytest.mark.parametrize(
    ("faces", "flat"),
    # two proper triangles and one collinear, or one on a single point
    [("f 1 2 4\nf 2 3 4\nf 1 2 3\n", 2), ("f 1 2 4\nf 2 3 4\nf 4 4 4\n", 2)],
)
def test_info_names_the_zero_area_triangle_instead_of_nan(tmp_path, faces, flat):
    # issue 30: "max aspect ratio nan" for a degenerate triangle (0/0 when its corners
    # coincide, inf when they are collinear)
    (tmp_path / "flat.obj").write_text("v 0 0 0\nv 1 0 0\nv 2 0 0\nv 0 1 0\n" + faces)
    r = run("info", "flat.obj", cwd=tmp_path)
    assert r.returncode == 0, r.stderr
    assert f"max aspect ratio inf (triangle {flat} has zero area)" in r.stdout
    assert "aspect ratio max inf, median " in r.stdout
    assert "nan" not in r.stdout and "undefined" not in r.stdout


def test_usage_errors(tmp_path):
    r = run(
        "mesh", "--preset", "paper-fig10", "--stats-json", "-", "--quality-json", "-", cwd=tmp_path
    )
    assert_one_line_error(r, 2, "--quality-json", "stdout")
    r = run("info", "x.msh", "--frequency", "0", cwd=tmp_path)
    assert_one_line_error(r, 2, "--frequency")
    r = run("mesh", "--preset", "paper-fig10", "--quality-json", "no/such/q.json", cwd=tmp_path)
    assert_one_line_error(r, 1, "no/such")


def test_cell_info_reports_the_whole_cell(tmp_path):
    name = cell_preset_names()[0]
    r = run(
        "info", "--cell-preset", name, "--quality-json", "-", "--stats-json", "s.json", cwd=tmp_path
    )
    assert r.returncode == 0, r.stderr
    report = strict_json(r.stdout)
    stats = strict_json((tmp_path / "s.json").read_text())
    assert report["triangles"] == stats["cell"]["triangles"]
    smallest = stats["cell"]["min_angle_deg"]
    assert report["min_angle_deg"]["min"] == pytest.approx(smallest, rel=1e-12)
    assert "quality:" in r.stderr
