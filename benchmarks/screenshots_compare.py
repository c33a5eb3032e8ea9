"""Whether two revisions of the program draw the presets alike: window screenshots of every
mesh preset and unit-cell preset, made by each revision, compared pixel by pixel.

A refactoring of the window must leave its pictures as they were (issue 31's contract).
Each revision is taken from git (``git archive``: ``core/``, ``app/`` and ``assets/``), laid
out as the ``barymesh`` package in a temporary folder and run by this checkout's Python with
the editable install switched off, so both run on the same libraries. Every screenshot is
``barymesh --preset NAME --screenshot PNG --quit`` (or ``--cell-preset``) in a fresh
settings folder, at the window's scripted size.

The one value that differs from run to run is the Statistics panel's "Mesh time"; the
differing pixels are reported with their bounding box and the Statistics dock's row under
it, so that a difference there is told from a difference in the picture.

Usage::

    python benchmarks/screenshots_compare.py 135d60d HEAD --json out.json

Without ``DISPLAY`` the script re-runs itself under ``xvfb-run``.
"""

from __future__ import annotations

import argparse
import json
import os
import platform
import shutil
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[1]
PRESETS = (
    "conforming-double-ring",
    "paper-fig10",
    "paper-fig12a",
    "paper-fig12c",
    "paper-fig12d",
    "paper-fig8-dsdr",
    "srr-openmodes",
)
CELL_PRESETS = ("coding-16x16", "double-ring-patch", "hexagonal-rings", "split-ring-pair")
#: Runs ``barymesh.app.cli.main`` from the package folder given first, not the editable
#: install of this checkout.
RUNNER = """
import sys
sys.meta_path[:] = [f for f in sys.meta_path if "editable" not in repr(f).lower()]
sys.path.insert(0, sys.argv[1])
from barymesh.app.cli import main
sys.exit(main(sys.argv[2:]))
"""


def package(revision: str, folder: Path) -> Path:
    """``revision``'s core, app and assets laid out as the ``barymesh`` package."""
    tree = folder / "tree"
    tree.mkdir(parents=True)
    archive = subprocess.run(
        ["git", "-C", str(ROOT), "archive", revision, "core", "app", "assets"],
        check=True,
        capture_output=True,
    ).stdout
    subprocess.run(["tar", "-x", "-C", str(tree)], input=archive, check=True)
    pkg = folder / "pkg" / "barymesh"
    shutil.copytree(tree / "core", pkg)
    shutil.copytree(tree / "app", pkg / "app")
    shutil.copytree(tree / "assets", pkg / "assets")
    return pkg.parent


def screenshots(pkg: Path, out: Path) -> dict[str, str]:
    """Every preset's screenshot by the package in ``pkg``; returns name -> error (if any)."""
    out.mkdir(parents=True)
    errors = {}
    cases = [(p, ["--preset", p]) for p in PRESETS]
    cases += [(f"cell-{c}", ["--cell-preset", c]) for c in CELL_PRESETS]
    for name, args in cases:
        with tempfile.TemporaryDirectory() as config:
            env = dict(os.environ, XDG_CONFIG_HOME=config)
            run = subprocess.run(
                [sys.executable, "-c", RUNNER, str(pkg), *args]
                + ["--screenshot", str(out / f"{name}.png"), "--quit"],
                env=env,
                capture_output=True,
                text=True,
                timeout=300,
            )
        if run.returncode != 0:
            errors[name] = run.stderr.strip().splitlines()[-1] if run.stderr else "no output"
    return errors


def compare(a: Path, b: Path) -> dict:
    import imageio.v3 as iio

    x, y = iio.imread(a), iio.imread(b)
    if x.shape != y.shape:
        return {"same_size": False, "sizes": [list(x.shape), list(y.shape)]}
    d = np.any(x != y, axis=-1)
    result: dict = {"same_size": True, "pixels": int(x.shape[0] * x.shape[1])}
    result["differing"] = int(d.sum())
    if d.any():
        rows, cols = np.nonzero(d)
        result["box"] = [int(rows.min()), int(rows.max()), int(cols.min()), int(cols.max())]
    return result


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("before", help="the revision before (a commit, tag or branch)")
    parser.add_argument("after", nargs="?", default="HEAD", help="the revision after")
    parser.add_argument("--json", metavar="FILE", help="write the comparison here")
    parser.add_argument("--keep", metavar="DIR", help="keep the screenshots in DIR")
    args = parser.parse_args(argv)
    if not os.environ.get("DISPLAY") and shutil.which("xvfb-run"):
        return subprocess.call(
            ["xvfb-run", "-a", "-s", "-screen 0 1920x1080x24", sys.executable, __file__]
            + (argv if argv is not None else sys.argv[1:])
        )
    work = Path(args.keep) if args.keep else Path(tempfile.mkdtemp(prefix="shots-"))
    started = time.time()
    sides = {}
    for side, revision in (("before", args.before), ("after", args.after)):
        commit = subprocess.run(
            ["git", "-C", str(ROOT), "rev-parse", "--short", revision],
            check=True,
            capture_output=True,
            text=True,
        ).stdout.strip()
        pkg = package(revision, work / side)
        sides[side] = {"revision": revision, "commit": commit}
        sides[side]["errors"] = screenshots(pkg, work / side / "png")
    cases = {}
    for png in sorted((work / "before" / "png").glob("*.png")):
        other = work / "after" / "png" / png.name
        if other.exists():
            cases[png.stem] = compare(png, other)
    report = {
        "benchmark": "screenshots_compare",
        "date": time.strftime("%Y-%m-%d"),
        "machine": platform.node(),
        "load_average": list(os.getloadavg()),
        "seconds": round(time.time() - started, 1),
        "before": sides["before"],
        "after": sides["after"],
        "cases": cases,
        "note": (
            "Differing pixels only inside the Statistics dock's 'Mesh time' row are the "
            "build's measured time, which differs from run to run."
        ),
    }
    for name, case in cases.items():
        print(f"{name:28s} differing pixels {case.get('differing', 'size differs')!s:>8}", end="")
        print(f"  box (rows, cols) {case['box']}" if case.get("box") else "")
    for side in ("before", "after"):
        for name, error in sides[side]["errors"].items():
            print(f"{side} {name}: {error}")
    if args.json:
        Path(args.json).write_text(json.dumps(report, indent=2) + "\n")
    if not args.keep:
        shutil.rmtree(work, ignore_errors=True)
    return 0


if __name__ == "__main__":
    sys.exit(main())
