"""The barymesh command line, run as users run it (subprocesses), and its helpers in-process."""

import io
import json
import os
import re
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

from barymesh.app import cli, cli_progress
from barymesh.cell import cell_preset_names
from barymesh.io import read_mesh
from barymesh.presets import preset_names

ROOT = Path(__file__).resolve().parents[1]


def run(*args, cwd, stdin=None):
    env = dict(os.environ, PYTHONPATH=str(ROOT))
    env.pop("DISPLAY", None)  # everything here must work without a display
    return subprocess.run(
        [sys.executable, "-m", "barymesh.app.cli", *map(str, args)],
        cwd=cwd,
        env=env,
        capture_output=True,
        text=True,
        timeout=300,
    )


def assert_one_line_error(result, code, *fragments):
    assert result.returncode == code, result.stderr
    assert "Traceback" not in result.stderr
    lines = result.stderr.strip().splitlines()
    assert len(lines) == 1, result.stderr
    assert lines[0].startswith("barymesh") and "error:" in lines[0]
    for fragment in fragments:
        assert fragment in lines[0]
    assert result.stdout == ""


def test_presets_lists_one_line_each(tmp_path):
    r = run("presets", cwd=tmp_path)
    assert r.returncode == 0 and r.stderr == ""
    lines = r.stdout.strip().splitlines()
    assert [line.split()[0] for line in lines] == preset_names() + cell_preset_names()
    assert all(len(line.split(None, 1)) == 2 for line in lines)


#: Paper Fig. 12(d): 2 rings x 18 sectors (20 deg) of one patch, 2 n^2 = 32 triangles each.
FIG12D_TRIANGLES = 2 * 18 * 2 * 4**2


def test_mesh_writes_every_output_and_summary(tmp_path):
    outs = ["d.msh", "d.vtu", "d.vtp", "d.stl", "d.obj", "d.mat", "d.npz", "d.csv"]
    args = [a for o in outs for a in ("-o", o)]
    r = run("mesh", "--preset", "paper-fig12d", *args, cwd=tmp_path)
    assert r.returncode == 0, r.stderr
    assert FIG12D_TRIANGLES == 1152
    assert "1,152 triangles" in r.stdout
    for out in outs:
        assert (tmp_path / out).exists()
        assert f"wrote {out}" in r.stdout
        if out.endswith((".npz", ".csv")):
            continue
        back = read_mesh(tmp_path / out)
        assert back.n_triangles == FIG12D_TRIANGLES
    assert "(MATLAB p/t (Makarov), m)" in r.stdout  # .mat defaults to metres


def test_unit_flag(tmp_path):
    r = run("mesh", "--preset", "paper-fig10", "-o", "p.msh", "--unit", "m", cwd=tmp_path)
    assert r.returncode == 0, r.stderr
    mesh = read_mesh(tmp_path / "p.msh", unit="m")
    assert mesh.stats()["area"] == pytest.approx(100.0)
    assert read_mesh(tmp_path / "p.msh").stats()["area"] == pytest.approx(1e-4)


def test_stats_json_stdout_is_only_json(tmp_path):
    r = run(
        "mesh",
        "--preset",
        "paper-fig10",
        "--set",
        "subdivisions=2",
        "-o",
        "a.stl",
        "--stats-json",
        "-",
        cwd=tmp_path,
    )
    assert r.returncode == 0, r.stderr
    stats = json.loads(r.stdout)
    n = 2  # a 10 mm square patch in n x n cells, two triangles each
    closed_forms = {
        "triangles": 2 * n**2,
        "vertices": (n + 1) ** 2,
        "edges": 3 * n**2 + 2 * n,
        "interior_edges": 3 * n**2 - 2 * n,
        "boundary_edges": 4 * n,
        "junction_edges": 0,
        "euler_characteristic": 1,
        "patches": 1,
    }
    assert {key: stats[key] for key in closed_forms} == closed_forms
    assert stats["area"] == pytest.approx(100.0)
    assert stats["min_edge"] == pytest.approx(5.0) and stats["max_edge"] == pytest.approx(
        5.0 * 2**0.5
    )
    assert "8 triangles" in r.stderr  # the human summary moved to stderr


def test_stats_json_file(tmp_path):
    r = run("mesh", "--preset", "paper-fig12d", "--stats-json", "s.json", cwd=tmp_path)
    assert r.returncode == 0, r.stderr
    assert json.loads((tmp_path / "s.json").read_text())["triangles"] == 1152
    assert "1,152 triangles" in r.stdout


def test_params_file_and_sets(tmp_path):
    (tmp_path / "mine.json").write_text('{"structure": "patch", "patch_size": 2.0}')
    r = run(
        "mesh",
        "--params",
        "mine.json",
        "--set",
        "subdivisions=3",
        "--set",
        "origin=[1,2]",
        "--stats-json",
        "-",
        cwd=tmp_path,
    )
    assert r.returncode == 0, r.stderr
    stats = json.loads(r.stdout)
    assert stats["triangles"] == 2 * 9 and stats["area"] == pytest.approx(4.0)


def test_info(tmp_path):
    assert run("mesh", "--preset", "makarov-plate", "-o", "plate.mat", cwd=tmp_path).returncode == 0
    r = run("info", "plate.mat", cwd=tmp_path)
    assert r.returncode == 0, r.stderr
    assert "128 triangles" in r.stdout and "176 interior" in r.stdout
    r = run("info", "plate.mat", "--stats-json", "-", cwd=tmp_path)
    stats = json.loads(r.stdout)
    assert stats["interior_edges"] == 176 and stats["area"] == pytest.approx(1e6)
    r = run("info", "plate.mat", "--unit", "mm", "--stats-json", "-", cwd=tmp_path)
    assert json.loads(r.stdout)["area"] == pytest.approx(1.0)


def test_info_reports_ignored_cells(tmp_path):
    from test_io_import import MSH41

    (tmp_path / "g.msh").write_text(MSH41)
    r = run("info", "g.msh", cwd=tmp_path)
    assert r.returncode == 0, r.stderr
    assert "ignored non-triangle cells: 3 line, 1 vertex" in r.stdout
    r = run("info", "g.msh", "--stats-json", "-", cwd=tmp_path)
    assert json.loads(r.stdout)["ignored_cells"] == {"line": 3, "vertex": 1}


@pytest.mark.parametrize(
    ("args", "fragments"),
    [
        (["frobnicate"], ["invalid choice: 'frobnicate'"]),
        (["mesh", "--preset", "nope"], ["unknown preset 'nope'"]),
        (["mesh", "--set", "subdivisions"], ["--set 'subdivisions' is invalid"]),
        (["mesh", "-o", "mesh.xyz"], ["mesh.xyz", "cannot write .xyz"]),
        (["mesh", "--unit", "km"], ["invalid choice: 'km'"]),
        (["mesh", "--window-size", "0", "10"], ["0 pixels is outside"]),
        (["mesh", "--window-size", "a", "10"], ["'a' is not a whole number"]),
        (["mesh", "--transparent"], ["--transparent needs --screenshot"]),
        (["mesh", "--bogus"], ["unrecognized arguments: --bogus"]),
        (["info"], ["the following arguments are required: FILE"]),
    ],
)
def test_usage_errors_exit_2(tmp_path, args, fragments):
    assert_one_line_error(run(*args, cwd=tmp_path), 2, *fragments)


@pytest.mark.parametrize(
    ("args", "fragments"),
    [
        (["mesh", "--set", "subdivisions=0"], ["subdivisions=0 is outside 1..64"]),
        (["mesh", "--set", "colour=red"], ["unknown parameter 'colour'"]),
        (["mesh", "--set", "structure=hexagon"], ["structure='hexagon' is unknown"]),
        (["mesh", "--params", "missing.json"], ["missing.json", "no such parameter file"]),
        (["mesh", "--params", "bad.json"], ["bad.json", "invalid JSON"]),
        (["mesh", "--set", "max_triangles=10"], ["above the budget"]),
        (
            ["mesh", "--preset", "paper-fig10", "-o", "nowhere/x.msh"],
            ["nowhere/x.msh", "does not exist"],
        ),
        (
            ["mesh", "--preset", "paper-fig10", "-o", "blocker/x.msh"],
            ["blocker/x.msh", "is not a folder"],
        ),
        (["mesh", "--preset", "paper-fig10", "--stats-json", "nowhere/s.json"], ["nowhere/s.json"]),
        (["info", "missing.msh"], ["missing.msh", "does not exist"]),
        (["info", "garbage.msh"], ["garbage.msh", "not a readable Gmsh"]),
        (["info", "empty.stl"], ["empty.stl", "empty"]),
        (["info", "bad.json"], ["bad.json", "cannot read .json"]),
    ],
)
def test_input_errors_exit_1(tmp_path, args, fragments):
    (tmp_path / "bad.json").write_text("{nope")
    (tmp_path / "blocker").write_text("a file, not a folder")
    (tmp_path / "garbage.msh").write_bytes(b"$MeshFormat\n9.9 7\n\x00\xff")
    (tmp_path / "empty.stl").write_bytes(b"")
    r = run(*args, cwd=tmp_path)
    if "--stats-json" in args:  # the summary came before the failed stats file
        r = subprocess.CompletedProcess(r.args, r.returncode, "", r.stderr)
    assert_one_line_error(r, 1, *fragments)


def test_help_and_version(tmp_path):
    r = run("--help", cwd=tmp_path)
    assert r.returncode == 0 and "mesh" in r.stdout and "presets" in r.stdout
    r = run("mesh", "--help", cwd=tmp_path)
    assert r.returncode == 0 and "--stats-json" in r.stdout and "--window-size" in r.stdout
    r = run("--version", cwd=tmp_path)
    assert r.returncode == 0 and r.stdout.startswith("barymesh ")


def test_installed_console_script():
    script = Path(sys.executable).with_name("barymesh")
    if not script.exists():
        pytest.skip("barymesh is not installed in this environment")
    r = subprocess.run([script, "presets"], capture_output=True, text=True, timeout=60)
    assert r.returncode == 0 and "paper-fig10" in r.stdout


# -- no verb: the desktop window ------------------------------------------


def test_no_verb_opens_window(monkeypatch):
    import types

    calls = []
    fake = types.ModuleType("barymesh.app.window_main")
    fake.main = lambda argv: calls.append(argv) or 0
    monkeypatch.setitem(sys.modules, "barymesh.app.window_main", fake)
    assert cli.main([]) == 0
    assert cli.main(["--preset", "paper-fig10", "--set", "subdivisions=2", "--quit"]) == 0
    assert calls == [[], ["--preset", "paper-fig10", "--set", "subdivisions=2", "--quit"]]


def test_no_verb_without_window_prints_usage(monkeypatch, capsys):
    monkeypatch.setitem(sys.modules, "barymesh.app.window_main", None)  # import fails as if absent
    assert cli.main([]) == 0
    out = capsys.readouterr().out
    assert "mesh" in out and "info" in out and "presets" in out


def test_window_failure_is_one_line(monkeypatch, capsys):
    import types

    fake = types.ModuleType("barymesh.app.window_main")

    def boom(argv):
        raise RuntimeError("no OpenGL")

    fake.main = boom
    monkeypatch.setitem(sys.modules, "barymesh.app.window_main", fake)
    assert cli.main(["--quit"]) == 1
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and "no OpenGL" in err


# -- progress --------------------------------------------------------------


class FakeTTY(io.StringIO):
    def isatty(self):
        return True


def test_progress_only_on_a_terminal_and_after_the_delay(monkeypatch):
    import time

    monkeypatch.setattr(cli_progress, "PROGRESS_DELAY", 0.05)
    tty = FakeTTY()
    with cli.progress("building", tty):
        time.sleep(0.4)
    text = tty.getvalue()
    assert "building" in text and " s" in text and text.endswith("\r\033[K")

    quick = FakeTTY()
    monkeypatch.setattr(cli_progress, "PROGRESS_DELAY", 5.0)
    with cli.progress("building", quick):
        pass
    assert quick.getvalue() == ""

    pipe = io.StringIO()
    monkeypatch.setattr(cli_progress, "PROGRESS_DELAY", 0.0)
    with cli.progress("building", pipe):
        time.sleep(0.2)
    assert pipe.getvalue() == ""


def test_progress_off_a_terminal_writes_log_lines_with_the_steps(monkeypatch):
    """A pipe or a log gets whole lines: after LOG_DELAY, every LOG_EVERY, and at the end."""
    import time

    monkeypatch.setattr(cli_progress, "LOG_DELAY", 0.05)
    monkeypatch.setattr(cli_progress, "LOG_EVERY", 0.2)
    log = io.StringIO()
    with cli.progress("solving 4 frequencies", log) as report:
        report(1, 4)
        time.sleep(0.15)  # the first line: 1/4 and the time left at that rate
        report(3, 4)
        time.sleep(0.25)  # another line: 3/4
        report(4, 4)
    lines = log.getvalue().splitlines()
    assert "\r" not in log.getvalue() and "\033" not in log.getvalue()
    assert re.fullmatch(r"solving 4 frequencies: 1/4 after 0s, about 0s left", lines[0])
    assert "solving 4 frequencies: 3/4 after 0s, about 0s left" in lines[1:-1]
    assert lines[-1] == "solving 4 frequencies: done, 4/4 in 0s"

    failed = io.StringIO()
    with pytest.raises(RuntimeError), cli.progress("building", failed):
        time.sleep(0.1)
        raise RuntimeError("no room")
    assert failed.getvalue().splitlines() == [
        "building: running for 0s",
        "building: stopped after 0s",
    ]

    monkeypatch.setattr(cli_progress, "LOG_DELAY", 5.0)
    quick = io.StringIO()
    with cli.progress("building", quick):
        time.sleep(0.1)
    assert quick.getvalue() == ""  # quick work: nothing in the log


# -- screenshots -----------------------------------------------------------


@pytest.mark.parametrize("transparent", [False, True])
def test_screenshot_without_display(tmp_path, transparent):
    pytest.importorskip("pyvista")
    pytest.importorskip("barymesh.app.view.scaled_shot")
    iio = pytest.importorskip("imageio.v3")
    args = [
        "mesh",
        "--preset",
        "paper-fig12d",
        "--screenshot",
        "shot.png",
        "--window-size",
        "320",
        "240",
    ]
    if transparent:
        args.append("--transparent")
    r = run(*args, cwd=tmp_path)
    assert r.returncode == 0, r.stderr
    assert "wrote shot.png (320x240 px)" in r.stdout
    image = iio.imread(tmp_path / "shot.png")
    assert image.shape[:2] == (240, 320)
    rgb = image[..., :3].reshape(-1, 3).astype(int)
    corner = image[0, 0]
    if transparent:
        assert image.shape[2] == 4 and corner[3] == 0  # see-through background
        assert (image[..., 3] > 0).mean() > 0.02  # and opaque mesh
    background = np.all(rgb == rgb[0], axis=1)
    assert 0.05 < background.mean() < 0.98  # both background and mesh pixels
    assert len(np.unique(rgb[~background], axis=0)) > 3  # faces, edges, centroids
    assert [p.name for p in tmp_path.iterdir() if ".tmp" in p.name] == []


# -- hostile input: one line on stderr naming the input (issue 10 #12, #7, #11) ----------


def _write_inputs(folder):
    (folder / "digits.json").write_text('{"subdivisions": ' + "9" * 5000 + "}")
    (folder / "deep.json").write_text('{"origin": ' + "[" * 100_000 + "]" * 100_000 + "}")
    import scipy.io

    p = np.array([[0.0, 1, 0], [0, 0, 1], [0, 0, 0]])
    scipy.io.savemat(folder / "complex.mat", {"p": p + 1j, "t": np.array([[1], [2], [3], [1]])})
    (folder / "truncated.msh").write_text("$MeshFormat\n2.2 0 8\n$EndMeshFormat\n$Nodes\n423\n")
    os.mkfifo(folder / "pipe.msh")
    (folder / "zero.stl").symlink_to("/dev/zero")
    (folder / "loop.obj").symlink_to(folder / "loop.obj")


@pytest.mark.parametrize(
    ("args", "code", "fragments"),
    [
        (["--frobnicate"], 2, ["unrecognized arguments: --frobnicate"]),
        (["--preset", "paper-fig10", "--bogus", "1"], 2, ["unrecognized arguments: --bogus 1"]),
        (["mesh", "--params", "digits.json"], 1, ["digits.json", "a number is too long"]),
        (["mesh", "--params", "deep.json"], 1, ["deep.json", "nested too deeply"]),
        (["mesh", "--set", "subdivisions=" + "9" * 5000], 1, ["--set 'subdivisions=9", "too long"]),
        (["mesh", "--set", "origin=" + "[" * 100_000], 1, ["--set 'origin=[[", "too deeply"]),
        (
            ["mesh", "--screenshot", "a.png", "--window-size", "16384", "16384"],
            2,
            ["--window-size 16384 16384 would need about 9.0 GiB"],
        ),
        (["info", "complex.mat"], 1, ["complex.mat: its p holds complex numbers"]),
        (["info", "truncated.msh"], 1, ["truncated.msh: its $Nodes section has no $EndNodes"]),
        (["info", "pipe.msh"], 1, ["pipe.msh: the path is a named pipe (FIFO), not a file"]),
        (["info", "zero.stl"], 1, ["zero.stl: the path is a symbolic link to /dev/zero, which is"]),
        (["info", "loop.obj"], 1, ["loop.obj: the path is a symbolic link loop"]),
    ],
)
def test_hostile_input_is_one_line_naming_it(tmp_path, args, code, fragments):
    _write_inputs(tmp_path)
    before = set(tmp_path.iterdir())
    r = run(*args, cwd=tmp_path)
    assert_one_line_error(r, code, *fragments)
    assert "Warning" not in r.stderr and "Traceback" not in r.stderr
    assert r.stderr.count(args[-1]) <= 1 or args[0] != "info"  # the path is said once
    after = {p for p in tmp_path.iterdir() if p.name != "matplotlib"}  # XDG_CONFIG_HOME here
    assert after == before  # nothing written, no temp file


def test_messages_shorten_huge_numbers(capsys):
    assert cli._fail("inner_radius=" + "1" * 500 + " is too large", 1) == 1
    err = capsys.readouterr().err
    assert len(err) < 80 and "inner_radius=11111111…" in err


def test_screenshot_removes_what_a_killed_render_left(tmp_path):
    """A killed render (VTK aborting, SIGKILL) leaves its temp file; the next write removes it."""
    from barymesh.io.atomic import TEMP_MARK

    dead = subprocess.Popen([sys.executable, "-c", "pass"])
    dead.wait()
    stale = tmp_path / f".shot.png{TEMP_MARK}{dead.pid}-x.tmp.png"
    stale.write_bytes(b"")
    os.utime(stale, (1e9, 1e9))
    r = run(
        "mesh",
        "--preset",
        "paper-fig10",
        "--screenshot",
        "shot.png",
        "--window-size",
        "64",
        "48",
        cwd=tmp_path,
    )
    assert r.returncode == 0, r.stderr
    assert sorted(p.name for p in tmp_path.iterdir() if p.name != "matplotlib") == ["shot.png"]


#: Runs the ``barymesh`` entry point that pyproject.toml declares, as the console script
#: does, with Ctrl-C arriving while the command line imports numpy.
INTERRUPTED_WHILE_IMPORTING = """
import importlib, importlib.abc, os, signal, sys, tomllib

# as a terminal starts it: a run started in the background (nohup, CI) has SIGINT ignored,
# which a child inherits, and Python then raises no KeyboardInterrupt for it
signal.signal(signal.SIGINT, signal.default_int_handler)

class CtrlC(importlib.abc.MetaPathFinder):
    def find_spec(self, name, path=None, target=None):
        if name == "numpy":
            os.kill(os.getpid(), signal.SIGINT)
        return None

with open(sys.argv[1], "rb") as fh:
    target = tomllib.load(fh)["project"]["scripts"]["barymesh"]
module, function = target.split(":")
sys.meta_path.insert(0, CtrlC())
sys.argv = ["barymesh", "mesh", "--preset", "paper-fig10"]
sys.exit(getattr(importlib.import_module(module), function)())
"""


def test_ctrl_c_while_the_command_starts_is_one_line_and_exit_130(tmp_path):
    # issue 30: a SIGINT while `barymesh mesh` was still importing printed a
    # KeyboardInterrupt traceback and the process died by the signal (exit -2)
    r = subprocess.run(
        [sys.executable, "-c", INTERRUPTED_WHILE_IMPORTING, str(ROOT / "pyproject.toml")],
        cwd=tmp_path,
        capture_output=True,
        text=True,
        timeout=300,
    )
    assert r.returncode == 130, r.stderr
    assert r.stderr == "barymesh: interrupted\n"
    assert r.stdout == ""
