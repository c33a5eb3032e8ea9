"""Start-up times of the ``barymesh`` command and of the core's import, in fresh processes.

Each case runs ``--repeats`` times (7 by default) in a new Python process and its wall time
from start to exit is recorded, and its CPU time (user + system, which a loaded machine
stretches less); the JSON keeps every run, the medians, and the load average beside each
figure (the machine may be shared: a loaded machine stretches start-up several times over).
The cases:

* ``import numpy``: the reference, the least any numpy program pays;
* ``import barymesh``: the package itself (its names are imported when first asked for);
* ``from barymesh import build_mesh, MeshParams, TriMesh``: the core's meshing API;
* ``barymesh --help``;
* ``barymesh mesh --preset paper-fig10 --stats-json -``: a small mesh, its statistics;
* ``barymesh window: first frame``: the window (``barymesh`` with no verb, as it opens on
  the default structure), timed from launch to the first paint of its 3D view that shows
  the mesh (``benchmarks/first_frame.py`` prints the moment; the process then closes).
  Without a ``DISPLAY`` a virtual X server is started first, outside the timing; its CPU
  column is the whole process's, closing included. ``--no-window`` leaves this case out.

One untimed run of each case first warms the file cache and writes the bytecode caches
(``__pycache__``), as an installed package has them: ``PYTHONDONTWRITEBYTECODE`` is dropped
from the children's environment, since compiling barymesh's sources on every start would
double its import time. ``--importtime`` also writes the
``python -X importtime`` report of each Python case beside the JSON (for finding what is
slow; the report's own numbers are inflated by its bookkeeping).

``--baseline REV`` also times the same cases on the sources of git revision ``REV`` (its
``core/``, ``app/`` and ``assets/`` laid out as the package ``barymesh`` in a temporary
folder put first on ``PYTHONPATH``), each run of it right after the same run of this tree,
so that a before/after comparison sees the same load.

Usage::

    python benchmarks/startup.py
    python benchmarks/startup.py --repeats 3 --json out.json
    python benchmarks/startup.py --baseline main --json /tmp/compare.json
"""

from __future__ import annotations

import argparse
import contextlib
import json
import os
import statistics
import subprocess
import sys
import tempfile
import time
from collections.abc import Iterator
from pathlib import Path

from machine import machine

ROOT = Path(__file__).resolve().parents[1]
RESULTS = ROOT / "benchmarks" / "results"

#: The barymesh console script beside this Python (a virtual environment's bin/).
BARYMESH = str(Path(sys.executable).with_name("barymesh"))

#: The window case: timed to its first frame, not to its exit.
WINDOW = "barymesh window: first frame"

#: Name, command line, target in seconds (the issue's; None: a reference).
CASES: list[tuple[str, list[str], float | None]] = [
    ("import numpy", [sys.executable, "-c", "import numpy"], None),
    ("import barymesh", [sys.executable, "-c", "import barymesh"], 0.15),
    (
        "from barymesh import build_mesh",
        [sys.executable, "-c", "from barymesh import MeshParams, TriMesh, build_mesh"],
        0.15,
    ),
    ("barymesh --help", [BARYMESH, "--help"], 0.3),
    (
        "barymesh mesh --preset paper-fig10 --stats-json -",
        [BARYMESH, "mesh", "--preset", "paper-fig10", "--stats-json", "-"],
        0.4,
    ),
    (WINDOW, [sys.executable, str(Path(__file__).with_name("first_frame.py"))], 2.0),
]


#: The children's environment: bytecode caches written and used, as after an install.
ENV = {k: v for k, v in os.environ.items() if k != "PYTHONDONTWRITEBYTECODE"}


def run_once(cmd: list[str], env: dict[str, str] = ENV) -> tuple[float, float]:
    """Wall and CPU time (s) of one run of ``cmd`` in a new process; its output is discarded.

    The wall time runs to the process's exit, or to the moment it prints as
    ``first-frame T`` (its ``time.monotonic()``) when it does (the window)."""
    before = os.times()
    launch = time.monotonic()
    start = time.perf_counter()
    proc = subprocess.run(cmd, capture_output=True, check=False, env=env)
    seconds = time.perf_counter() - start
    after = os.times()
    if proc.returncode != 0:
        raise SystemExit(f"{' '.join(cmd)} failed ({proc.returncode}): {proc.stderr.decode()}")
    for line in proc.stdout.decode(errors="replace").splitlines():
        if line.startswith("first-frame "):
            seconds = float(line.split()[1]) - launch
    cpu = (after.children_user - before.children_user) + (
        after.children_system - before.children_system
    )
    return seconds, cpu


def summary(runs: list[tuple[float, float]], load: list[float]) -> dict[str, object]:
    """The JSON row of ``runs`` (wall, CPU) seen at load averages ``load`` (before, after)."""
    times = [wall for wall, _ in runs]
    cpu = [c for _, c in runs]
    return {
        "times": times,
        "median": statistics.median(times),
        "min": min(times),
        "cpu_times": cpu,
        "cpu_median": statistics.median(cpu),
        "loadavg": load,
    }


def measure(
    cmd: list[str], repeats: int, baseline: dict[str, str] | None
) -> tuple[dict[str, object], dict[str, object] | None]:
    """``repeats`` timed runs after one untimed, with the load average before and after;
    with a ``baseline`` environment, each run is followed by one in it."""
    run_once(cmd)
    if baseline is not None:
        run_once(cmd, baseline)
    load_before = os.getloadavg()[0]
    ours, theirs = [], []
    for _ in range(repeats):
        ours.append(run_once(cmd))
        if baseline is not None:
            theirs.append(run_once(cmd, baseline))
    load = [load_before, os.getloadavg()[0]]
    return summary(ours, load), (summary(theirs, load) if baseline is not None else None)


def baseline_env(rev: str, folder: Path) -> dict[str, str]:
    """The children's environment that imports ``barymesh`` from git revision ``rev``."""
    src = folder / "src"
    src.mkdir()
    archive = subprocess.run(
        ["git", "-C", str(ROOT), "archive", rev, "core", "app", "assets"],
        capture_output=True,
        check=True,
    ).stdout
    subprocess.run(["tar", "-x", "-C", str(src)], input=archive, check=True)
    (src / "core" / "app").symlink_to(src / "app")
    (src / "core" / "assets").symlink_to(src / "assets")
    (folder / "barymesh").symlink_to(src / "core")
    return dict(ENV, PYTHONPATH=str(folder))


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--repeats", type=int, default=7)
    ap.add_argument("--json", type=Path, default=RESULTS / "startup-2026-12-05.json")
    ap.add_argument("--importtime", action="store_true", help="also write -X importtime reports")
    ap.add_argument("--baseline", metavar="REV", help="also time git revision REV, interleaved")
    ap.add_argument("--no-window", action="store_true", help="leave out the window's case")
    args = ap.parse_args()
    with tempfile.TemporaryDirectory() as folder, display(not args.no_window):
        baseline = baseline_env(args.baseline, Path(folder)) if args.baseline else None
        run(args, baseline)


@contextlib.contextmanager
def display(needed: bool) -> Iterator[None]:
    """A virtual X server (Xvfb) for the window's case when there is no ``DISPLAY``; the
    children find it through ``DISPLAY`` in :data:`ENV`."""
    if not needed or os.environ.get("DISPLAY"):
        yield
        return
    from pyvirtualdisplay import Display

    with Display(size=(1920, 1080), color_depth=24) as virtual:
        ENV["DISPLAY"] = virtual.new_display_var
        try:
            yield
        finally:
            del ENV["DISPLAY"]


def run(args: argparse.Namespace, baseline: dict[str, str] | None) -> None:
    """Time every case (and the baseline's), print a table and write the JSON."""
    cases = {}
    print(f"{'case':52s} {'median':>8s} {'min':>8s} {'cpu':>8s} {'target':>7s}  load")
    for name, cmd, target in CASES:
        if name == WINDOW and args.no_window:
            continue
        row, before = measure(cmd, args.repeats, baseline)
        row["command"] = [Path(c).name if c in (sys.executable, BARYMESH) else c for c in cmd]
        row["target"] = target
        cases[name] = row
        aim = f"{target:.2f}" if target else "-"
        print(
            f"{name:52s} {row['median']:8.3f} {row['min']:8.3f} {row['cpu_median']:8.3f} "
            f"{aim:>7s}  "
            f"{row['loadavg'][0]:.2f}-{row['loadavg'][1]:.2f}"
        )
        if before is not None:
            row["baseline"] = before
            print(
                f"{'  ' + args.baseline:52s} {before['median']:8.3f} {before['min']:8.3f} "
                f"{before['cpu_median']:8.3f}"
            )
        if args.importtime and cmd[0] != BARYMESH and name != WINDOW:
            report = subprocess.run(
                [cmd[0], "-X", "importtime", *cmd[1:]],
                capture_output=True,
                text=True,
                check=True,
                env=ENV,
            ).stderr
            slug = name.replace(" ", "-").replace(",", "")
            args.json.with_name(f"{args.json.stem}-{slug}.importtime.txt").write_text(report)

    doc = {"repeats": args.repeats, "machine": machine(), "cases": cases}
    if args.baseline:
        doc["baseline"] = {
            "revision": args.baseline,
            "commit": subprocess.run(
                ["git", "-C", str(ROOT), "rev-parse", args.baseline],
                capture_output=True,
                text=True,
                check=True,
            ).stdout.strip(),
        }
    args.json.parent.mkdir(parents=True, exist_ok=True)
    args.json.write_text(json.dumps(doc, indent=2) + "\n")
    print(f"wrote {args.json}")


if __name__ == "__main__":
    main()
