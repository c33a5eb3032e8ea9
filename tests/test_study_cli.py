"""``barymesh study SPEC.json``, run as users run it (a subprocess for the real clusters)."""

from __future__ import annotations

import io
import json
import os
import signal
import subprocess
import sys
import time
from pathlib import Path

import pandas as pd
import pytest

from barymesh.app import cli
from barymesh.app.cli_study import ProgressBar, progress_line
from barymesh.study import Progress, read_result

pytest.importorskip("distributed")

ROOT = Path(__file__).resolve().parents[1]
PATCH = {"structure": "patch", "patch_size": 15.0, "subdivisions": 2}


def write_spec(folder: Path, name="s.json", **changes) -> Path:
    doc = {
        "base": {"params": PATCH},
        "axes": {"patch_size": [13.0, 14.0, -1.0]},
        "solve": {"kind": "free_space", "frequencies": "6GHz:12GHz:11"},
        "derive": ["resonance_frequency", "quality_factor"],
        "output": "s.parquet",
    }
    doc.update(changes)
    path = folder / name
    path.write_text(json.dumps(doc))
    return path


def study(*args, cwd, **kw):
    env = dict(os.environ, PYTHONPATH=str(ROOT))
    env.pop("DISPLAY", None)
    return subprocess.Popen(
        [sys.executable, "-m", "barymesh.app.cli", "study", *map(str, args)],
        cwd=cwd,
        env=env,
        stdout=subprocess.PIPE,
        stderr=subprocess.PIPE,
        text=True,
        **kw,
    )


def one_line_error(code, err, expected_code, *fragments):
    assert code == expected_code, err
    assert "Traceback" not in err
    lines = err.strip().splitlines()
    assert len(lines) == 1, err
    for fragment in fragments:
        assert fragment in lines[0]


@pytest.mark.parametrize(
    ("args", "code", "fragment"),
    [
        (["missing.json"], 1, "cannot read the study spec missing.json"),
        (["s.json", "--workers", "0"], 2, "--workers 0 is invalid"),
        (["s.json", "--scheduler", "tcp://127.0.0.1:1", "--workers", "2"], 2, "drop --scheduler"),
        (["s.json", "-o", "x.h5"], 2, "-o x.h5: expected a .parquet or .csv"),
        (["s.json", "-o", "nowhere/x.csv"], 1, "the folder nowhere does not exist"),
        (["bad.json"], 1, "study spec: axes.radius: the base has no 'radius'"),
    ],
)
def test_bad_usage_and_bad_specs_are_one_line(tmp_path, monkeypatch, capsys, args, code, fragment):
    monkeypatch.chdir(tmp_path)
    write_spec(tmp_path)
    write_spec(
        tmp_path, "bad.json", axes={"radius": [1.0]}, base={"params": {"structure": "patch"}}
    )
    result = cli.main(["study", *args])
    one_line_error(result, capsys.readouterr().err, code, fragment)


def test_an_output_that_cannot_be_written_is_one_line_before_any_worker_starts(
    tmp_path, monkeypatch, capsys
):
    # issue 30: output "/proc/x.parquet" printed a multi-line Dask log ending in a raw
    # [Errno 2]; the parts folder is made before the cluster starts
    monkeypatch.chdir(tmp_path)
    write_spec(tmp_path, output="/proc/x.parquet")
    result = cli.main(["study", "s.json"])
    one_line_error(
        result,
        capsys.readouterr().err,
        1,
        "cannot write the study to /proc/x.parquet: its parts folder /proc/x.parquet.parts/",
    )


def test_a_study_runs_on_a_local_cluster_and_a_rerun_solves_nothing(tmp_path):
    spec = write_spec(tmp_path)
    p = study(spec, "--workers", "2", "-o", "out.csv", cwd=tmp_path)
    out, err = p.communicate(timeout=300)
    assert p.returncode == 0, err
    assert "Traceback" not in err
    assert "3 points: 2 ok, 1 failed; 2 solved now, 0 from an earlier run" in out
    assert "point 2: patch_size=-1.0 is invalid" in out
    for name in ("out.csv", "out.derived.csv", "out.meta.json"):
        assert f"wrote {name}" in out and (tmp_path / name).exists()
    first = read_result(tmp_path / "out.csv")
    assert list(first.derived.status[:2]) == ["ok", "ok"]
    p = study(spec, "--workers", "1", "--threads", "-o", "out.csv", cwd=tmp_path)
    out, err = p.communicate(timeout=300)
    assert p.returncode == 0, err
    assert "0 solved now, 3 from an earlier run" in out
    pd.testing.assert_frame_equal(read_result(tmp_path / "out.csv").derived, first.derived)


def test_ctrl_c_keeps_the_finished_points_and_exits_130(tmp_path):
    spec = write_spec(
        tmp_path,
        base={"params": {**PATCH, "subdivisions": 6}},
        axes={"patch_size": [float(v) for v in range(10, 22)]},
        solve={"kind": "free_space", "frequencies": "6GHz:12GHz:31"},
    )
    p = study(spec, "--workers", "1", cwd=tmp_path)
    parts = tmp_path / "s.parquet.parts"
    deadline = time.monotonic() + 240
    while not list(parts.glob("*/point-*.parquet")) and time.monotonic() < deadline:
        time.sleep(0.2)
    assert p.poll() is None, p.communicate()
    p.send_signal(signal.SIGINT)
    out, err = p.communicate(timeout=120)
    assert p.returncode == 130, err
    assert "Traceback" not in err
    assert "interrupted:" in err and "run the same command again to go on" in err
    kept = list(parts.glob("*/point-*.parquet"))
    assert 1 <= len(kept) < 12 and not (tmp_path / "s.parquet").exists()


def test_the_progress_bar_shows_points_failures_and_time_left():
    assert progress_line(Progress(0, 0, 10, 0.0, float("nan")), width=10) == (
        "[..........] 0/10 points, 0 failed, ? left"
    )
    line = progress_line(Progress(5, 2, 10, 50.0, 3725.0), width=10)
    assert line == "[#####.....] 5/10 points, 2 failed, 1h02m left"

    class Tty(io.StringIO):
        def isatty(self):
            return True

    stream = Tty()
    bar = ProgressBar(stream)
    bar(Progress(1, 0, 4, 1.0, 3.0, "http://127.0.0.1:8787/status"))
    bar(Progress(2, 0, 4, 2.0, 2.0, "http://127.0.0.1:8787/status"))
    text = stream.getvalue()
    assert text.count("dashboard: http://127.0.0.1:8787/status") == 1
    assert text.endswith("2/4 points, 0 failed, 2s left")
    # not a terminal (a log, a pipe): whole lines, at the start, each tenth of the points
    # (here each point) and the end, never a carriage return or an escape sequence
    log = io.StringIO()
    bar = ProgressBar(log)
    bar(Progress(0, 0, 4, 0.0, float("nan"), "http://127.0.0.1:8787/status"))
    bar(Progress(1, 0, 4, 61.0, 183.0, "http://127.0.0.1:8787/status"))
    bar(Progress(4, 1, 4, 250.0, 0.0, "http://127.0.0.1:8787/status"))
    bar.close()
    assert log.getvalue().splitlines() == [
        "dashboard: http://127.0.0.1:8787/status",
        "study: 0/4 points, 0 failed, time left unknown (0s so far)",
        "study: 1/4 points, 0 failed, 3m03s left (1m01s so far)",
        "study: 4/4 points, 1 failed, 0s left (4m10s so far)",
    ]
    # many points: a line per tenth, not per point
    many = io.StringIO()
    bar = ProgressBar(many)
    for done in range(101):
        bar(Progress(done, 0, 100, float(done), float(100 - done)))
    assert len(many.getvalue().splitlines()) == 11
