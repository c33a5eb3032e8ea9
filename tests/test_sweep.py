"""Sweep animations from the command line, without a display."""

import imageio.v2 as imageio
import numpy as np
import pytest

from app.sweep import frame_caption, render_sweep
from core import MeshParams
from tests.test_cli import assert_one_line_error, run


@pytest.mark.parametrize("suffix", [".gif", ".mp4"])
def test_sweep_command_writes_the_asked_frames(tmp_path, suffix):
    out = tmp_path / f"sweep{suffix}"
    r = run("sweep", "--preset", "paper-fig10", "--param", "subdivisions", "--from", "1",
            "--to", "4", "--frames", "4", "--window-size", "320", "240", "-o", out.name,
            cwd=tmp_path)  # fmt: skip
    assert r.returncode == 0, r.stderr
    assert "wrote" in r.stdout and "4 frames" in r.stdout
    reader = imageio.get_reader(out)
    frames = [np.asarray(f) for f in reader]
    assert len(frames) == 4
    assert frames[0].shape[:2] == (240, 320)
    # the frames differ: n = 1 has 2 triangles, n = 4 has 32
    assert not np.array_equal(frames[0], frames[-1])
    # and none is blank
    assert all(len(np.unique(f.reshape(-1, f.shape[-1]), axis=0)) > 5 for f in frames)


def test_sweep_in_process_reports_progress(tmp_path):
    seen = []
    n = render_sweep(
        MeshParams(angle_step=20), "angle_step", 20, 10, 3, tmp_path / "a.gif",
        window_size=(200, 160), progress=lambda done, total: seen.append((done, total)),
    )  # fmt: skip
    assert n == 3
    assert seen[-1] == (6, 6) and len(seen) == 6


def test_frame_caption():
    assert frame_caption(MeshParams(angle_step=10), "angle_step", 2304) == (
        "angle_step = 10°   (2,304 triangles)"
    )
    assert frame_caption(MeshParams(), "patch_size", 5).startswith("patch_size = 1 mm")


@pytest.mark.parametrize(
    ("args", "code", "fragment"),
    [
        (["--param", "mode", "--from", "1", "--to", "2", "--frames", "3", "-o", "a.gif"], 2,
         "invalid choice: 'mode'"),
        (["--param", "patch_size", "--from", "1", "--to", "2", "--frames", "1", "-o", "a.gif"], 2,
         "--frames 1 is invalid"),
        (["--param", "patch_size", "--from", "1", "--to", "2", "--frames", "3", "-o", "a.avi"], 2,
         "expected a .gif or .mp4 file"),
        (["--param", "patch_size", "--from", "1", "--to", "-1", "--frames", "3", "-o", "a.gif"], 1,
         "sweep frame 2 of 3 (patch_size=0.0)"),
        (["--param", "patch_size", "--from", "1", "--to", "2", "--frames", "3", "-o", "no/a.gif"],
         1, "does not exist"),
    ],
)  # fmt: skip
def test_sweep_errors(tmp_path, args, code, fragment):
    r = run("sweep", *args, cwd=tmp_path)
    assert_one_line_error(r, code, fragment)
    assert not any(tmp_path.iterdir())
