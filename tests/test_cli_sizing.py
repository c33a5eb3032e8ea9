"""``barymesh mesh --set frequency=...`` as users run it (a subprocess, no display)."""

import json
import math

from test_cli import assert_one_line_error, run

#: λ at 10 GHz (mm), c0 = 299,792,458 m/s.
LAMBDA_10GHZ = 29.9792458


def test_mesh_sized_by_frequency_reports_n_and_edge_per_lambda(tmp_path):
    """Fig. 10's 10 mm patch: longest edge 10 √2 / n ≤ λ/10 = 2.998 mm first at n = 5."""
    r = run(
        "mesh",
        "--preset",
        "paper-fig10",
        "--set",
        "frequency=10e9",
        "--stats-json",
        "-",
        cwd=tmp_path,
    )
    assert r.returncode == 0, r.stderr
    stats = json.loads(r.stdout)
    assert stats["subdivisions_chosen"] == 5 and stats["triangles"] == 2 * 5**2
    assert math.isclose(stats["wavelength"], LAMBDA_10GHZ, rel_tol=1e-15)
    assert math.isclose(
        stats["max_edge_wavelengths"], 10 * math.sqrt(2) / 5 / LAMBDA_10GHZ, rel_tol=1e-14
    )
    assert stats["lambda_10_rule"] is True
    assert "sized: subdivisions 5 chosen for edges <= 2.99792 mm" in r.stderr
    assert "lambda/10 rule met" in r.stderr


def test_frequency_in_a_substrate_and_a_parameter_file(tmp_path):
    """εr = 4 halves λ: λ/10 = 1.499 mm, so n = ceil(10 √2 / 1.499) = 10."""
    path = tmp_path / "sized.json"
    path.write_text(
        json.dumps(
            {
                "structure": "patch",
                "patch_size": 10.0,
                "frequency": 10e9,
                "relative_permittivity": 4.0,
            }
        )
    )
    r = run("mesh", "--params", path, "--stats-json", "-", cwd=tmp_path)
    assert r.returncode == 0, r.stderr
    assert json.loads(r.stdout)["subdivisions_chosen"] == 10


def test_bad_frequency_is_one_line_naming_it(tmp_path):
    r = run("mesh", "--preset", "paper-fig10", "--set", "frequency=-1", cwd=tmp_path)
    assert_one_line_error(r, 1, "--set 'frequency=-1'", "frequency=-1 Hz", "> 0 Hz")


def test_unreachable_frequency_names_the_triangles_needed(tmp_path):
    """1 THz: λ/10 = 0.02998 mm; n = 64 leaves 10 √2 / 64 = 0.221 mm; about n = 472,
    2 × 472² = 445,568 triangles."""
    r = run("mesh", "--preset", "paper-fig10", "--set", "frequency=1e12", cwd=tmp_path)
    assert_one_line_error(r, 1, "frequency=1e+12 Hz", "445,568 triangles")
