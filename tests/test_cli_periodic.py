"""``barymesh solve --periodic``: the infinite array from the command line, in-process.

The numbers are checked against physics, not against what the code printed before: the
power balance of a lossless screen, the grating-lobe onsets of a 10 mm square lattice
(c/P at normal incidence, c/(P (1 + sin θ)) at 30°), the Touchstone file read back with
scikit-rf, the CSV's power per frequency.
"""

from __future__ import annotations

import csv
import json
import re

import numpy as np
import pytest

from barymesh.app import cli
from barymesh.cell import Lattice, PixelGrid, UnitCell, save_cell
from barymesh.constants import SPEED_OF_LIGHT

P = 10.0  # mm


@pytest.fixture(scope="module")
def cell_file(tmp_path_factory):
    """7.5 × 2.5 mm strips along y on a 10 mm square lattice (24 triangles)."""
    mask = np.zeros((8, 8), dtype=bool)
    mask[1:7, 3:5] = True
    pixels = PixelGrid(mask, pixel_size=P / 8, origin=(-P / 2, -P / 2), subdivisions=1)
    cell = UnitCell(Lattice.rectangular(P), pixels=pixels, mode="conforming", name="dipoles")
    path = tmp_path_factory.mktemp("cells") / "dipoles.cell.json"
    save_cell(cell, path)
    # the pixels say "grading": solved as given (24 triangles), not made solver-grade
    doc = json.loads(path.read_text())
    doc["pixels"]["grading"] = False
    path.write_text(json.dumps(doc))
    return str(path)


def run(capsys, *args):
    code = cli.main(["solve", *map(str, args)])
    out, err = capsys.readouterr()
    return code, out, err


def test_one_frequency_prints_every_propagating_order(cell_file, capsys):
    code, out, err = run(capsys, "--cell", cell_file, "--periodic", "--freq", "35GHz")
    assert code == 0, err
    rows = re.findall(r"^\s+\(\s*(-?\d+),\s*(-?\d+)\)\s+(.*)$", out, re.M)
    # above c/P = 29.98 GHz at normal incidence: (0, 0) and the four first orders
    assert {(int(p), int(q)) for p, q, _ in rows} == {(0, 0), (1, 0), (-1, 0), (0, 1), (0, -1)}
    power = sum(sum(float(v) for v in rest.split()[-2:]) for _, _, rest in rows)
    assert power == pytest.approx(1.0, abs=2e-3)  # a lossless screen
    balance = float(re.search(r"reflected \+ transmitted = ([0-9.]+)", out)[1])
    assert balance == pytest.approx(1.0, abs=2e-3)
    # the next onset, (1, 1) at sqrt(2) c/P
    onset = float(re.search(r"next grating-lobe onset: ([0-9.]+) GHz", out)[1])
    assert onset == pytest.approx(np.sqrt(2) * SPEED_OF_LIGHT / (P * 1e-3) / 1e9, rel=1e-5)


def test_a_sweep_writes_touchstone_csv_vtu_and_plot(cell_file, capsys, tmp_path):
    import skrf

    s4p, orders, vtu, png = (tmp_path / n for n in ("rt.s4p", "orders.csv", "j.vtu", "rt.png"))
    code, out, err = run(
        capsys,
        "--cell", cell_file, "--periodic", "--freq", "10GHz:35GHz:4", "--no-interpolate",
        "--theta", "30", "--phi", "0", "--pol", "tm",
        "-o", s4p, "-o", orders, "-o", vtu, "--current-at", "20GHz", "--plot", png,
    )  # fmt: skip
    assert code == 0, err
    # onsets of a 10 mm square lattice at 30° in the xz plane, by hand
    c, theta = SPEED_OF_LIGHT, np.radians(30)
    first = c / (P * 1e-3 * (1 + np.sin(theta))) / 1e9  # (1, 0): 19.986 GHz
    g = 2 * np.pi / (P * 1e-3)
    k11 = (-0.5 * g + np.sqrt(0.25 * g * g + 0.75 * 2 * g * g)) / 0.75  # (1, ±1)
    expected = [first, k11 * c / (2 * np.pi) / 1e9, c / (P * 1e-3 * np.cos(theta)) / 1e9]
    printed = re.search(r"grating-lobe onsets: (.*)$", out, re.M)[1]
    onsets = [float(v) for v in re.findall(r"([0-9.]+) GHz", printed)]
    assert onsets == pytest.approx(expected, rel=1e-5)
    # the 4-port: power is conserved below the first onset, lost to other orders above it
    network = skrf.Network(str(s4p))
    assert np.allclose(network.f, [10e9, 10e9 + 25e9 / 3, 10e9 + 50e9 / 3, 35e9])
    column = (np.abs(network.s) ** 2).sum(axis=1)  # (F, 4): power out per incident port
    below = network.f < first * 1e9
    assert np.abs(column[below] - 1).max() < 2e-3
    assert np.all(column[~below] < 0.99)
    # the CSV: every propagating order; with them the power balances everywhere
    with open(orders, newline="") as fh:
        rows = list(csv.DictReader(fh))
    for f in network.f:
        group = [r for r in rows if float(r["frequency_hz"]) == pytest.approx(f)]
        assert sum(float(r["R_power"]) + float(r["T_power"]) for r in group) == pytest.approx(
            1.0, abs=2e-3
        )
    # at 35 GHz: (0, 0), (1, 0), (1, ±1) and (0, ±1)
    assert len({(r["p"], r["q"]) for r in rows if float(r["frequency_hz"]) == 35e9}) == 6
    # the TM incidence's co-polar R in the CSV is the file's S22 (R TM <- TM)
    tm = [r for r in rows if r["p"] == r["q"] == "0" and r["pol"] == "tm"]
    r22 = np.array([complex(float(r["R_re"]), float(r["R_im"])) for r in tm])
    assert np.abs(r22 - network.s[:, 1, 1]).max() < 1e-9
    grid = pytest.importorskip("pyvista").read(vtu)  # VTK, as ParaView reads it
    j = np.asarray(grid.cell_data["J_abs"])
    assert len(j) == 24 and j.max() > 0
    assert grid.field_data["frequency_hz"].tolist() == [20e9]
    (text,) = grid.field_data["excitation"]
    assert text.startswith("infinite array of this cell (lattice a1 = (10, 0) mm, a2 = (0, 10) mm)")
    assert "from above, theta = 30 deg, phi = 0 deg" in text
    direction = grid.field_data["direction"][0]
    np.testing.assert_allclose(direction, [-np.sin(theta), 0.0, -np.cos(theta)], atol=1e-15)
    assert png.stat().st_size > 10_000


def test_the_sweep_interpolates_by_default(cell_file, capsys):
    code, out, err = run(capsys, "--cell", cell_file, "--periodic", "--freq", "8GHz:16GHz:81")
    assert code == 0, err
    solved = int(re.search(r"interpolating sweep: (\d+) frequencies solved", out)[1])
    assert 3 <= solved <= 12
    assert "grating-lobe onsets: none in the band" in out


def test_a_structure_with_a_period_and_a_sheet_impedance(capsys):
    code, out, err = run(
        capsys,
        "--preset", "paper-fig11-8mm", "--set", "subdivisions=8", "--period", "10,12",
        "--periodic", "--freq", "12GHz", "--sheet-impedance", "30-10j",
    )  # fmt: skip
    assert code == 0, err
    assert "on a 10 x 12 mm lattice" in out
    parts = re.search(r"reflected ([0-9.]+) \+ transmitted ([0-9.]+) \+ absorbed ([0-9.]+)", out)
    reflected, transmitted, absorbed = (float(v) for v in parts.groups())
    assert absorbed > 0.05  # a lossy sheet really absorbs
    assert reflected + transmitted + absorbed == pytest.approx(1.0, abs=1e-5)


def test_free_space_takes_the_sheet_impedance(capsys):
    code, out, err = run(
        capsys,
        "--preset", "srr-openmodes", "--set", "subdivisions=1", "--freq", "6.19GHz",
        "--pol", "y", "--sheet-impedance", "20",
    )  # fmt: skip
    assert code == 0, err
    absorbed = float(re.search(r"absorption cross-section ([0-9.eE+-]+) m\^2", out)[1])
    assert absorbed > 0


@pytest.mark.parametrize(
    ("args", "code", "fragment"),
    [
        (["--preset", "paper-fig11-8mm", "--periodic"], 2, "--periodic needs a unit cell"),
        (["CELL", "--periodic", "--theta", "90"], 2, "0 <= theta < 90"),
        (["CELL", "--periodic", "--dir", "-z"], 2, "--theta and --phi"),
        (["CELL", "--periodic", "--feed", "0,0:0,1"], 2, "drop --feed"),
        (["CELL", "--periodic", "--array", "2x2"], 2, "--array makes a finite array"),
        (["CELL", "--periodic", "--period", "10"], 2, "has its own lattice"),
        (["CELL", "--periodic", "-o", "x.npz"], 2, "with --periodic expected .s4p"),
        (["CELL", "--periodic", "-o", "x.vtu", "--freq2"], 2, "--current-at"),
        (["CELL", "--periodic", "--current-at", "5GHz"], 2, "-o FILE.vtu"),
        (["CELL", "--periodic", "--plot", "rt.png"], 2, "--plot needs a sweep"),
        (["CELL", "--periodic", "--sheet-impedance", "abc"], 2, "--sheet-impedance"),
        (["CELL", "--periodic", "--pol", "0,0,1"], 2, "perpendicular"),
        (["CELL", "--periodic", "--tolerance", "2"], 2, "--tolerance"),
        (["CELL", "--theta", "30"], 2, "--theta applies to --periodic"),
        (["CELL", "-o", "x.s4p"], 2, "needs --periodic"),
        (["--preset", "paper-fig11-8mm", "--period", "10"], 2, "add --periodic"),
        (["--preset", "paper-fig11-8mm", "--period", "5", "--periodic"], 1, "larger than"),
        (["CELL", "--periodic", "--sheet-impedance", "-5"], 1, "sheet_impedance"),
        (["--cell-preset", "nope", "--periodic"], 2, "unknown cell preset"),
        (["CELL", "--periodic", "--max-memory", "100MB"], 1, "use a coarser mesh"),
        (["CELL", "--periodic", "--order", "3"], 2, "--order applies to the free-space"),
    ],
)
def test_bad_combinations_are_one_line_errors(cell_file, capsys, tmp_path, args, code, fragment):
    args = [cell_file if a == "CELL" else a for a in args]
    args = [a.replace("x.", str(tmp_path / "x.")) if a.startswith("x.") else a for a in args]
    freq = ["--freq", "5GHz:6GHz:3"] if "--freq2" in args else ["--freq", "12GHz"]
    args = [a for a in args if a != "--freq2"]
    if args[0].endswith(".cell.json"):
        args = ["--cell", *args]
    got, out, err = run(capsys, *args, *freq)
    assert got == code, err
    assert "Traceback" not in err
    lines = err.strip().splitlines()
    assert len(lines) == 1, err
    assert fragment in lines[0]


def test_a_mesh_file_with_a_period(capsys, tmp_path):
    from barymesh import MeshParams, build_mesh
    from barymesh.io import write_mesh

    path = write_mesh(
        build_mesh(MeshParams(structure="patch", patch_size=6.0, subdivisions=6)),
        tmp_path / "patch.msh",
    )
    code, out, err = run(capsys, "--mesh", path, "--period", "10", "--periodic", "--freq", "15GHz")
    assert code == 0, err
    balance = float(re.search(r"reflected \+ transmitted = ([0-9.]+)", out)[1])
    assert balance == pytest.approx(1.0, abs=1e-3)
    onset = float(re.search(r"next grating-lobe onset: ([0-9.]+) GHz", out)[1])
    assert onset == pytest.approx(SPEED_OF_LIGHT / (P * 1e-3) / 1e9, rel=1e-5)
    code, out, err = run(capsys, "--mesh", path, "--period", "5", "--periodic", "--freq", "15GHz")
    assert code == 1 and "larger than the period" in err


def test_a_finite_array_of_the_cell_in_free_space(cell_file, capsys):
    code, out, err = run(capsys, "--cell", cell_file, "--array", "2x1", "--freq", "15GHz")
    assert code == 0, err
    assert "2 x 1 copies: 48 triangles" in out
    assert "extinction" in out


# -- a long solve says so first -----------------------------------------------------------


def test_the_time_model_is_the_fit_of_the_measured_benchmark():
    import json
    from pathlib import Path

    from barymesh.mom import timing

    root = Path(__file__).resolve().parents[1]
    rows = json.loads((root / timing.MEASURED_IN).read_text())["rows"]
    t = np.array([r["triangles"] for r in rows], dtype=float)
    n = np.array([r["unknowns"] for r in rows], dtype=float)
    for key, x, coefficient in (
        ("periodic_geometry_s", t**2, timing.GEOMETRY_S_PER_PAIR),
        ("periodic_fill_s", t**2, timing.FILL_S_PER_PAIR),
        ("periodic_lu_s", n**3, timing.LU_S_PER_N3),
    ):
        y = np.array([r[key] for r in rows])
        fit = np.linalg.lstsq(x[:, None], y, rcond=None)[0][0]
        assert coefficient == pytest.approx(fit, rel=0.05), key
    # the split-ring-pair over 5-15 GHz in 21 points (one onset, 12.49 GHz, inside):
    # 10 to 23 solves of half a minute; the issue saw 15 minutes on a loaded machine
    sweep = timing.periodic_sweep_time(6_976, 8_720, 21, onsets=1)
    assert (sweep.fewest_solves, sweep.most_solves) == (10, 23)
    assert sweep.per_solve_s == pytest.approx(30.0, rel=0.01)
    assert 4 * 60 < sweep.fewest_s < 6 * 60 and 11 * 60 < sweep.most_s < 13 * 60
    assert timing.periodic_sweep_time(6_976, 8_720, 21, interpolate=False).fewest_solves == 21


def test_a_long_periodic_solve_says_its_size_and_time_before_it_starts(capsys):
    # split-ring-pair with a memory cap it cannot meet: the size and the expected time are
    # printed before the solve (here refused before anything large is allocated)
    code, out, err = run(
        capsys,
        "--cell-preset", "split-ring-pair", "--periodic", "--freq", "5GHz:15GHz:21",
        "--max-memory", "1MB",
    )  # fmt: skip
    assert code == 1 and "more than the memory_limit of 1.0 MiB" in err
    line = next(x for x in out.splitlines() if "a long solve" in x)
    assert line.startswith(
        "  a long solve: 6,976 triangles, 8,720 unknowns, 21 frequencies (10 to 23 solved, "
        "about 30 s each, and 12 s for the cell's tables): expected 5 min to 12 min"
    )


def test_a_short_periodic_solve_says_nothing_of_time(cell_file, capsys):
    code, out, _ = run(capsys, "--cell", cell_file, "--periodic", "--freq", "10GHz:12GHz:3")
    assert code == 0 and "a long solve" not in out
