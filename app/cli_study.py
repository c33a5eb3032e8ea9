"""``barymesh study``: a parameter × frequency design study on Dask (barymesh.study).

::

    barymesh study srr.json                       # a LocalCluster over all cores
    barymesh study srr.json --workers 2 -o srr.csv
    barymesh study srr.json --scheduler tcp://head:8786

Registered in :mod:`barymesh.app.cli`. A bad spec is one line and exit 1, bad usage exit
2; Ctrl-C keeps every finished point (exit 130) and the same command goes on from there.
"""

from __future__ import annotations

import argparse
import logging
import math
import sys
from pathlib import Path
from typing import Any, TextIO

from barymesh.app.cli_options import UsageError, check_folder, whole

#: Width of the progress bar in characters.
BAR = 30


def add_parser(subparsers: Any) -> argparse.ArgumentParser:
    """Add the ``study`` subcommand to ``subparsers`` (of :func:`barymesh.app.cli.build_parser`)."""
    p = subparsers.add_parser(
        "study",
        help="run a parameter x frequency design study on Dask (SPEC.json)",
        description="Run the study that SPEC.json describes (base design, axes, sample, "
        "solve, derived figures; see the Studies page of the documentation): one Dask task "
        "per point, on a local cluster over all cores, or on the cluster at --scheduler or "
        "in the Dask configuration. Finished points are kept as they come; running the "
        "same spec again solves only the missing ones.",
    )
    p.add_argument("spec", metavar="SPEC.json", help="the study spec")
    p.add_argument(
        "--scheduler", metavar="ADDR", help="a running Dask scheduler, e.g. tcp://host:8786"
    )
    p.add_argument(
        "--workers", type=whole, metavar="N", help="local cluster workers (default: one per core)"
    )
    p.add_argument(
        "--threads",
        action="store_true",
        help="local cluster workers as threads of this process instead of processes",
    )
    p.add_argument(
        "-o",
        "--output",
        metavar="PATH",
        help="the per-frequency table, .parquet or .csv (default: the spec's output, else "
        "SPEC.parquet); the derived table and the .meta.json are written beside it",
    )
    p.add_argument(
        "--restart", action="store_true", help="solve every point again, ignoring finished ones"
    )
    return p


def run(args: argparse.Namespace) -> int:
    """Execute ``barymesh study``; returns the exit code."""
    if args.workers is not None and args.workers < 1:
        raise UsageError(f"study: --workers {args.workers} is invalid; expected 1 or more")
    if args.scheduler is not None and (args.workers is not None or args.threads):
        raise UsageError("study: --workers and --threads size a local cluster; drop --scheduler")
    if args.output is not None and Path(args.output).suffix.lower() not in (".parquet", ".csv"):
        raise UsageError(f"study: -o {args.output}: expected a .parquet or .csv file")
    try:
        from barymesh.study import load_spec
        from barymesh.study import run as run_study
    except ImportError as exc:
        raise ValueError(
            f"study needs the study extra: pip install 'barymesh[study]' (missing {exc.name})"
        ) from None
    spec = load_spec(args.spec)
    output = args.output or spec.output or str(Path(args.spec).with_suffix(".parquet").name)
    check_folder(output)
    logging.getLogger("distributed").setLevel(logging.ERROR)
    bar = ProgressBar(sys.stderr)
    print(f"study {Path(args.spec).name}: {len(spec.points())} points, digest {spec.digest()}")
    if spec.stack is not None:
        print(f"  on the stack {spec.stack.describe() or '(no layers)'}")
    try:
        result = run_study(
            spec,
            scheduler=args.scheduler,
            workers=args.workers,
            processes=not args.threads,
            output=output,
            progress=bar,
            resume=not args.restart,
        )
    except KeyboardInterrupt:
        bar.close()
        from barymesh.study.results import parts_folder

        print(
            f"interrupted: {bar.done} of {bar.total} points kept in {parts_folder(spec, output)}"
            "; run the same command again to go on",
            file=sys.stderr,
        )
        return 130
    bar.close()
    meta = result.meta
    failed = len(result.failed)
    print(
        f"  {meta['finished']} points: {meta['finished'] - failed} ok, {failed} failed; "
        f"{meta['computed']} solved now, {meta['resumed']} from an earlier run, "
        f"in {meta['seconds']:.1f} s"
    )
    for index, row in result.failed.head(3).iterrows():
        print(f"  point {index}: {row['status']}")
    for line in warning_lines(result):
        print(line)
    from barymesh.study.results import output_paths

    for path in output_paths(output):
        print(f"wrote {path}")
    return 0


def warning_lines(result: Any, shown: int = 8) -> list[str]:
    """The CLI's summary of the points' warnings: one line per kind, with the points that
    have it and the first one's sentence.

    ::

          warnings on 3 of 6 points (the derived table's warnings column):
            coarse mesh (points 1, 3, 5): edges up to 1.89 mm, over a tenth of … (point 1)
    """
    kinds = result.warning_kinds()
    if not kinds:
        return []
    column = result.derived["warnings"]
    flagged = int((column.str.len() > 0).sum())
    lines = [
        f"  warnings on {flagged} of {len(column)} points (the derived table's warnings column):"
    ]
    for kind, points in kinds.items():
        listed = ", ".join(str(p) for p in points[:shown])
        if len(points) > shown:
            listed += f", … ({len(points) - shown} more)"
        first = next(w for w in str(column[points[0]]).splitlines() if w.split(":", 1)[0] == kind)
        text = first.split(":", 1)[1].strip() if ":" in first else first
        lines.append(
            f"    {kind} (point{'s' * (len(points) > 1)} {listed}): {text} (point {points[0]})"
        )
    return lines


class ProgressBar:
    """A one-line bar on a terminal: points done and failed, estimated time left, and the
    Dask dashboard's address once. Prints nothing where ``stream`` is not a terminal."""

    def __init__(self, stream: TextIO) -> None:
        self.stream = stream
        try:
            self.tty = stream.isatty()
        except (AttributeError, ValueError):
            self.tty = False
        self.done = self.total = 0
        self.shown = False
        self.dashboard = ""

    def __call__(self, p: Any) -> None:
        self.done, self.total = p.done, p.total
        if not self.tty:
            return
        if p.dashboard and p.dashboard != self.dashboard:
            self.dashboard = p.dashboard
            self.stream.write(f"\r\033[Kdashboard: {p.dashboard}\n")
        self.stream.write("\r\033[K" + progress_line(p))
        self.stream.flush()
        self.shown = True

    def close(self) -> None:
        if self.shown:
            self.stream.write("\r\033[K")
            self.stream.flush()


def progress_line(p: Any, width: int = BAR) -> str:
    """``[#####.....] 12/64 points, 1 failed, 3m20s left``.

    >>> from barymesh.study import Progress
    >>> progress_line(Progress(16, 1, 64, 30.0, 90.0), width=8)
    '[##......] 16/64 points, 1 failed, 1m30s left'
    """
    filled = int(width * p.done / p.total) if p.total else width
    left = "?" if not math.isfinite(p.eta) else _duration(p.eta)
    bar = "#" * filled + "." * (width - filled)
    return f"[{bar}] {p.done}/{p.total} points, {p.failed} failed, {left} left"


def _duration(seconds: float) -> str:
    s = int(round(seconds))
    if s >= 3600:
        return f"{s // 3600}h{s % 3600 // 60:02d}m"
    if s >= 60:
        return f"{s // 60}m{s % 60:02d}s"
    return f"{s}s"
