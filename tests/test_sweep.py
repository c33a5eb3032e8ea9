"""Sweep animations from the command line, without a display."""

import imageio.v2 as imageio
import numpy as np
import pytest
from test_cli import assert_one_line_error, run

from barymesh import MeshParams
from barymesh.app.teach.sweep import frame_caption, render_sweep


@pytest.mark.parametrize("suffix", [".gif", ".mp4"])
def test_sweep_command_writes_the_asked_frames(tmp_path, suffix):
    out = tmp_path / f"sweep{suffix}"
    r = run(
        "sweep",
        "--preset",
        "paper-fig10",
        "--param",
        "subdivisions",
        "--from",
        "1",
        "--to",
        "4",
        "--frames",
        "4",
        "--window-size",
        "320",
        "240",
        "-o",
        out.name,
        cwd=tmp_path,
    )
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
        MeshParams(angle_step=20),
        "angle_step",
        20,
        10,
        3,
        tmp_path / "a.gif",
        window_size=(200, 160),
        progress=lambda done, total: seen.append((done, total)),
    )
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
        (
            ["--param", "mode", "--from", "1", "--to", "2", "--frames", "3", "-o", "a.gif"],
            2,
            "invalid choice: 'mode'",
        ),
        (
            ["--param", "patch_size", "--from", "1", "--to", "2", "--frames", "1", "-o", "a.gif"],
            2,
            "--frames 1 is invalid",
        ),
        (
            ["--param", "patch_size", "--from", "1", "--to", "2", "--frames", "3", "-o", "a.avi"],
            2,
            "expected a .gif or .mp4 file",
        ),
        (
            ["--param", "patch_size", "--from", "1", "--to", "-1", "--frames", "3", "-o", "a.gif"],
            1,
            "sweep frame 2 of 3 (patch_size=0.0)",
        ),
        (
            [
                "--param",
                "patch_size",
                "--from",
                "1",
                "--to",
                "2",
                "--frames",
                "3",
                "-o",
                "no/a.gif",
            ],
            1,
            "does not exist",
        ),
    ],
)
def test_sweep_errors(tmp_path, args, code, fragment):
    r = run("sweep", *args, cwd=tmp_path)
    assert_one_line_error(r, code, fragment)
    assert not any(tmp_path.iterdir())


def test_each_frame_carries_its_own_caption(tmp_path):
    """Issue 9 #7: captions were one frame late. Frame 0 of 20 → 1 must equal frame 2 of 1 → 20.

    Both sweeps visit the same three meshes with the same camera (fixed on the union of all
    extents), so with the right caption on each frame the mirrored frames are identical.
    """
    base = MeshParams(angle_step=20, subdivisions=1)
    down, up = tmp_path / "down.gif", tmp_path / "up.gif"
    render_sweep(base, "angle_step", 20, 10, 3, down, window_size=(240, 180))
    render_sweep(base, "angle_step", 10, 20, 3, up, window_size=(240, 180))
    a, b = imageio.mimread(down), imageio.mimread(up)
    assert np.array_equal(a[0], b[2]) and np.array_equal(a[2], b[0])
    assert np.array_equal(a[1], b[1])
    assert not np.array_equal(a[0], a[2])


@pytest.mark.parametrize("fps", [2.0, 4.0, 10.0])
def test_gif_frame_delay_follows_fps(tmp_path, fps):
    from PIL import Image

    out = tmp_path / "a.gif"
    render_sweep(MeshParams(), "patch_size", 1, 2, 3, out, window_size=(64, 48), fps=fps)
    with Image.open(out) as gif:
        delays = []
        for k in range(gif.n_frames):
            gif.seek(k)
            delays.append(gif.info["duration"])
    assert delays == [1000 / fps] * 3


@pytest.mark.parametrize(
    ("args", "fragment"),
    [
        (["--from", "inf"], "argument --from: 'inf' is not a finite number"),
        (["--from", "nan"], "argument --from: 'nan' is not a finite number"),
        (["--to", "Infinity"], "argument --to: 'Infinity' is not a finite number"),
        (["--frames", "100000"], "frames=100000 is more than the 1000 a sweep may have"),
        (["--frames", "1e3"], "'1e3' is not a whole number"),
        (["--frames", "900", "--window-size", "1280", "720"], "at most 582 frames"),
        (["--fps", "0"], "--fps 0 is invalid"),
        (["--fps", "1000"], "--fps 1000 is invalid"),
        (["--window-size", "16384", "16384"], "--window-size 16384 16384 would need about 9.0"),
    ],
)
def test_sweep_limits_are_one_line(tmp_path, args, fragment):
    base = {"--param": "angle_step", "--from": "20", "--to": "1", "--frames": "3", "-o": "a.gif"}
    given = dict(zip(args[::2], args[1::2], strict=False))
    argv = [x for k, v in {**base, **given}.items() if k != "--window-size" for x in (k, v)]
    if "--window-size" in args:
        argv += args[args.index("--window-size") :]
    r = run("sweep", *argv, cwd=tmp_path)
    assert_one_line_error(r, 2, fragment)
    assert not any(tmp_path.iterdir())


def test_render_sweep_refuses_before_rendering(tmp_path):
    with pytest.raises(ValueError, match="more than the 1000"):
        render_sweep(MeshParams(), "patch_size", 1, 2, 100_000, tmp_path / "a.gif")
    with pytest.raises(ValueError, match="is not a finite number"):
        render_sweep(MeshParams(), "patch_size", float("inf"), 2, 3, tmp_path / "a.gif")
    assert not any(tmp_path.iterdir())


def test_sweep_frames_draw_triangle_edges_and_centroids(tmp_path):
    # paper-fig12c from n = 2 to 4 at 800 x 600: triangles of 8 px and more on every
    # frame, drawn the way the window draws them (shared edges orange, centroids magenta)
    pytest.importorskip("pyvista")
    from gui_helpers import colour_pixels

    from barymesh.app.view.scene_data import COLORS
    from barymesh.presets import load_preset

    base, _ = load_preset("paper-fig12c")
    out = tmp_path / "sweep.gif"
    assert render_sweep(base, "subdivisions", 2, 4, 3, out, window_size=(800, 600)) == 3
    for i, frame in enumerate(imageio.mimread(out)):
        shared = colour_pixels(frame, COLORS["shared_edges"])
        centroids = colour_pixels(frame, COLORS["centroids"])
        assert shared > 2_000 and centroids > 300, (i, shared, centroids)
