"""``barymesh solve``, run as users run it (subprocesses)."""

import csv
import os
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

from barymesh import build_mesh
from barymesh.mom import PlaneWave, solve
from barymesh.presets import resolve_params

ROOT = Path(__file__).resolve().parents[1]


def run(*args, cwd):
    env = dict(os.environ, PYTHONPATH=str(ROOT))
    env.pop("DISPLAY", None)
    return subprocess.run(
        [sys.executable, "-m", "barymesh.app.cli", "solve", *map(str, args)],
        cwd=cwd,
        env=env,
        capture_output=True,
        text=True,
        timeout=300,
    )


def one_line_error(result, code, *fragments):
    assert result.returncode == code, result.stderr
    assert "Traceback" not in result.stderr
    lines = result.stderr.strip().splitlines()
    assert len(lines) == 1, result.stderr
    for fragment in fragments:
        assert fragment in lines[0]


SMALL = ("--preset", "srr-openmodes", "--set", "subdivisions=1")


def test_single_frequency_writes_the_currents_for_paraview(tmp_path, monkeypatch, capsys):
    from barymesh.app import cli

    monkeypatch.chdir(tmp_path)  # in-process (fast); the sweep below runs as a subprocess
    code = cli.main(
        [
            "solve",
            *SMALL,
            "--freq",
            "6.19GHz",
            "--dir",
            "-z",
            "--pol",
            "y",
            "-o",
            "j.vtu",
            "-o",
            "j.npz",
            "-o",
            "one.csv",
        ]
    )
    out = capsys.readouterr()
    assert code == 0, out.err
    assert "139 RWG unknowns" in out.out and "extinction" in out.out
    mesh = build_mesh(resolve_params("srr-openmodes", None, ["subdivisions=1"]))
    want = solve(mesh, 6.19e9, PlaneWave(polarization=(0, 1, 0))).current_density
    # VTK reads the file as ParaView does (meshio 5.3 knows no VTK string arrays, which
    # hold the recorded excitation and units)
    pv = pytest.importorskip("pyvista")
    vtu = pv.read(tmp_path / "j.vtu")
    j_abs = np.asarray(vtu.cell_data["J_abs"])
    j_re, j_im = np.asarray(vtu.cell_data["J_real"]), np.asarray(vtu.cell_data["J_imag"])
    assert j_re.shape == (mesh.n_triangles, 3)
    fields = vtu.field_data
    assert fields["frequency_hz"].tolist() == [6.19e9]
    assert fields["direction"].tolist() == [[0.0, 0.0, -1.0]]
    assert fields["polarization"].tolist() == [[0.0, 1.0, 0.0]]
    assert fields["amplitude_v_per_m"].tolist() == [1.0]
    assert fields["excitation"].tolist() == [
        "plane wave travelling along (0, 0, -1), E along (0, 1, 0), amplitude 1 V/m"
    ]
    assert list(fields["units"]) == [
        "points: mm",
        "J_abs: A/m",
        "J_real: A/m",
        "J_imag: A/m",
        "charge_abs: C/m^2",
        "frequency_hz: Hz",
    ]
    assert list(fields["time_convention"]) == ["exp(+j w t)"]
    np.testing.assert_allclose(j_re + 1j * j_im, want, rtol=1e-9, atol=1e-12)
    np.testing.assert_allclose(j_abs, np.linalg.norm(want, axis=1), rtol=1e-9)
    npz = np.load(tmp_path / "j.npz")
    np.testing.assert_allclose(npz["current_density"], want, rtol=1e-9, atol=1e-12)
    rows = list(csv.DictReader(open(tmp_path / "one.csv")))
    assert float(rows[0]["frequency_hz"]) == 6.19e9
    ext = float(rows[0]["extinction_cross_section_m2"])
    assert float(rows[0]["scattering_cross_section_m2"]) == pytest.approx(ext, rel=0.01)


def test_sweep_writes_csv_and_plot_and_finds_the_resonance(tmp_path):
    r = run(
        *SMALL,
        "--freq",
        "5GHz:7.5GHz:11",
        "--pol",
        "0,1,0",
        "-o",
        "sweep.csv",
        "--plot",
        "sweep.png",
        cwd=tmp_path,
    )
    assert r.returncode == 0, r.stderr
    with open(tmp_path / "sweep.csv") as fh:
        reader = csv.reader(fh)
        header = next(reader)
        rows = [list(map(float, row)) for row in reader]
    assert header[:3] == [
        "frequency_hz",
        "extinction_cross_section_m2",
        "scattering_cross_section_m2",
    ]
    data = np.array(rows)
    np.testing.assert_allclose(data[:, 0], np.linspace(5e9, 7.5e9, 11))
    np.testing.assert_allclose(data[:, 2], data[:, 1], rtol=0.01)
    # the printed resonance is the peak of the written extinction
    line = next(x for x in r.stdout.splitlines() if "resonances" in x)
    f0 = float(line.split(":")[1].split()[0]) * 1e9
    assert abs(f0 - data[np.argmax(data[:, 1]), 0]) <= 0.25e9
    png = (tmp_path / "sweep.png").read_bytes()
    assert png[:8] == b"\x89PNG\r\n\x1a\n" and len(png) > 10_000


def test_feed_prints_the_input_impedance(capsys):
    from barymesh.app import cli

    # Makarov's plate fed across its middle line x = 0 (a vertical mesh line)
    code = cli.main(
        ["solve", "--preset", "makarov-plate", "--freq", "100MHz", "--feed", "0,-500:0,500"]
    )
    out = capsys.readouterr()
    assert code == 0, out.err
    line = next(x for x in out.out.splitlines() if "input impedance" in x)
    assert line.strip().endswith("ohm")
    real = float(line.split()[2])
    assert real > 0  # a passive antenna radiates: positive input resistance


def test_screenshot_renders_the_current_headless(tmp_path):
    import imageio.v3 as iio

    # without a display (run() drops DISPLAY), as `barymesh mesh --screenshot` renders
    r = run(
        "--preset",
        "makarov-platefine",
        "--freq",
        "300MHz",
        "--screenshot",
        "j.png",
        "--window-size",
        "640",
        "480",
        cwd=tmp_path,
    )
    assert r.returncode == 0, r.stderr
    assert "wrote j.png (640x480 px)" in r.stdout
    image = iio.imread(tmp_path / "j.png")[..., :3].astype(int)
    assert image.shape == (480, 640, 3)
    # the plate (left of the colour bar, which sits at 86 % of a wide view's width) is
    # painted with the YlOrRd map: warm pixels, from dark red (|J| peaks at the plate's
    # edges along E) to pale yellow (its corners), not one colour
    plate = image[:, : int(0.8 * 640)]
    warm = plate[..., 0] - plate[..., 2] > 60
    assert warm.sum() > 0.1 * warm.size
    green = plate[..., 1][warm]
    assert np.percentile(green, 1) < 80 and np.percentile(green, 95) > 200
    rows = np.nonzero((plate[..., 1] < 80) & warm)[0]  # the darkest reds
    ys = np.nonzero(warm)[0]
    middle = (ys.min() + ys.max()) / 2
    # |J| of an x-polarised wave peaks at the edges y = ±500 mm, not in the middle
    assert np.abs(rows - middle).min() > 0.3 * (ys.max() - ys.min()) / 2


@pytest.mark.parametrize(
    ("args", "fragment"),
    [
        (("--freq", "6 parsecs"), "--freq '6 parsecs' is invalid"),
        (("--freq", "6GHz:5GHz:3"), "expected A < B"),
        (("--freq", "6GHz", "--pol", "z"), "not perpendicular"),
        (("--freq", "6GHz", "--dir", "up"), "--dir 'up' is invalid"),
        (("--freq", "6GHz", "-o", "a.vtk"), "expected .csv, .npz, .vtu"),
        (("--freq", "3GHz:6GHz:4", "-o", "a.vtu"), "a .vtu holds one frequency"),
        (("--freq", "6GHz", "--plot", "p.png"), "--plot needs a sweep"),
        (("--freq", "6GHz", "--feed", "0,0:0,0"), "zero length"),
        (("--freq", "3GHz:6GHz:4", "--screenshot", "j.png"), "--screenshot shows one"),
        (("--freq", "6GHz", "--screenshot", "j.jpg"), "expected a .png file"),
    ],
)
def test_usage_errors_are_one_line_exit_2(tmp_path, monkeypatch, capsys, args, fragment):
    monkeypatch.chdir(tmp_path)
    in_process(capsys, 2, *SMALL, *args, fragments=(fragment,))


def in_process(capsys, code, *args, fragments=()):
    """Run ``barymesh solve ARGS`` in this process (fast); check the one-line error."""
    from barymesh.app import cli

    assert cli.main(["solve", *map(str, args)]) == code
    err = capsys.readouterr().err
    assert "Traceback" not in err and len(err.strip().splitlines()) == 1, err
    for fragment in fragments:
        assert fragment in err


def test_too_large_a_problem_is_refused_naming_n_and_memory(capsys):
    in_process(
        capsys,
        1,
        *SMALL,
        "--freq",
        "6GHz",
        "--max-memory",
        "100kB",
        fragments=("N = 139 unknowns need", "MiB", "memory_limit of 0.1 MiB"),
    )


def test_feed_off_the_mesh_edges_is_bad_input(capsys):
    in_process(
        capsys,
        1,
        *SMALL,
        "--freq",
        "6GHz",
        "--feed",
        "100,100:100,101",
        fragments=("no interior edge lies on the feed segment",),
    )


def test_solution_warnings_are_printed(tmp_path, monkeypatch, capsys):
    from barymesh.app import cli

    monkeypatch.chdir(tmp_path)
    # the 3 kHz plate of the issue: k·D = 8.9e-5, negative extinction, cond 3e12
    code = cli.main(["solve", "--preset", "makarov-plate", "--freq", "3kHz"])
    out = capsys.readouterr()
    assert code == 0, out.err
    assert "  warning: low-frequency breakdown of the EFIE: k·D = 8.89e-05" in out.out
    # a sweep prints the warning once, from its lowest frequency
    code = cli.main(["solve", "--preset", "makarov-plate", "--freq", "3kHz:300MHz:3"])
    out = capsys.readouterr()
    assert code == 0, out.err
    assert out.out.count("warning: low-frequency breakdown of the EFIE: k·D = 8.89e-05") == 1
    # and a well-posed solve prints none: the fine plate's edges (88.4 mm) are under λ/10
    # at 300 MHz; the coarse plate's (up to 176.8 mm) are not (issue 30)
    code = cli.main(["solve", "--preset", "makarov-platefine", "--freq", "300MHz"])
    out = capsys.readouterr()
    assert code == 0, out.err
    assert "warning" not in out.out
    code = cli.main(["solve", "--preset", "makarov-plate", "--freq", "300MHz"])
    out = capsys.readouterr()
    assert code == 0, out.err
    assert out.out.count("warning: ") == 1
    assert (
        "  warning: mesh too coarse for the wavelength: at 0.3 GHz (λ = 999.3 mm) 208 of 208 "
        "edges are over λ/10, the longest 176.8 mm (0.177 λ)"
    ) in out.out


def test_a_frequency_double_precision_cannot_solve_is_refused_not_nan(capsys):
    # issue 30: 1e-300 Hz printed extinction nan, |J| nan, residual nan and exited 0
    in_process(
        capsys,
        1,
        "--preset",
        "makarov-plate",
        "--freq",
        "1e-300",
        fragments=(
            "frequency=1e-300 Hz is too low for this mesh: k·D = 2.96e-308",
            "expected frequency >= 0.337 Hz",
        ),
    )


def test_cross_sections_at_1_thz_are_printed_with_the_coarse_mesh_warning(capsys):
    # issue 30: `barymesh solve --preset makarov-plate --freq 1THz` hung after printing the
    # frequency (a sphere rule of 29,652 degrees for the scattered power)
    from barymesh.app import cli

    code = cli.main(["solve", "--preset", "makarov-plate", "--freq", "1THz"])
    out = capsys.readouterr()
    assert code == 0, out.err
    assert "nan" not in out.out
    assert (
        "warning: mesh too coarse for the wavelength: at 1000 GHz (λ = 0.2998 mm) 208 of 208"
        in (out.out)
    )
