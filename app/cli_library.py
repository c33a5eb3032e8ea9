"""``barymesh library``: a cell's reflection-phase library (S-curve) from the command line.

::

    barymesh library --cell-preset NAME --parameter elements[0].patch_size \\
        --values 5:9.5:19 --freq 10GHz --stack "1.575mm eps=2.2; ground" -o lib.csv

Solves :func:`barymesh.mom.reflection_library` in this process and prints a short table
(value, frequency, co-polar phase and |R|, and the reference plane), or writes its CSV
(:meth:`barymesh.mom.ReflectionLibrary.to_csv`) with ``-o``. Registered in
:mod:`barymesh.app.cli`. Bad usage is one line and exit 2, bad input exit 1.
"""

from __future__ import annotations

import argparse
import re
from typing import Any

from barymesh.app.cli_options import UsageError, check_folder, load_cell_source

#: Most values of ``--values`` (each is two solves).
MAX_VALUES = 10_000


def parse_values(text: str) -> list[float]:
    """``--values``: ``A:B:K`` (K values from A to B inclusive) or a comma list.

    >>> parse_values("5:9.5:4"), parse_values("1, 2.5,4")
    ([5.0, 6.5, 8.0, 9.5], [1.0, 2.5, 4.0])
    """
    parts = text.split(":")
    try:
        if len(parts) == 1:
            values = [float(x) for x in text.split(",")]
        elif len(parts) == 3:
            a, b = float(parts[0]), float(parts[1])
            if not re.fullmatch(r"\s*\d{1,30}\s*", parts[2]):
                raise ValueError
            k = int(parts[2])
            if not 2 <= k <= MAX_VALUES or not b != a:
                raise UsageError(
                    f"--values {text[:40]!r}: expected A != B and K from 2 to {MAX_VALUES:,}"
                )
            step = (b - a) / (k - 1)
            values = [a + i * step for i in range(k - 1)] + [b]
        else:
            raise ValueError
    except ValueError:
        raise UsageError(
            f"--values {text[:40]!r} is invalid; expected A:B:K (5:9.5:19) or a list (5,6,7.5)"
        ) from None
    return values


def add_parser(subparsers: Any) -> argparse.ArgumentParser:
    """Add ``library`` to ``subparsers`` (of :func:`barymesh.app.cli.build_parser`)."""
    p = subparsers.add_parser(
        "library",
        help="the reflection phase of a cell's infinite array over one parameter (S-curve)",
        description="Solve the infinite array of a unit cell for each value of one "
        "parameter and print the co-polar reflection's phase and magnitude (the S-curve "
        "of a reflectarray's elements), referred to the stack's top face; -o writes the "
        "whole library as CSV (the 2 x 2 TE/TM reflection too).",
    )
    s = add_library_arguments(p)
    s.add_argument("-o", "--output", metavar="OUT", help="write the library as CSV (.csv)")
    return p


def add_library_arguments(p: argparse.ArgumentParser) -> argparse._ArgumentGroup:
    """The cell and the library's options (``library`` and ``reflectarray`` share them);
    returns the library's group."""
    g = p.add_argument_group("unit cell")
    g.add_argument("--cell", metavar="FILE.cell.json", help="a unit-cell file")
    g.add_argument(
        "--cell-preset", metavar="NAME", help="a shipped unit cell (see `barymesh presets`)"
    )
    s = p.add_argument_group("library")
    s.add_argument(
        "--parameter",
        required=True,
        metavar="PARAM",
        help="the value to vary, as a study's axis names it: elements[0].patch_size, "
        "stack.below[0].thickness, incidence.theta",
    )
    s.add_argument(
        "--values",
        required=True,
        metavar="A:B:K | V1,V2,...",
        help="K values from A to B (5:9.5:19), or a list",
    )
    s.add_argument(
        "--freq",
        required=True,
        metavar="F | A:B:K",
        help="a frequency (10GHz) or K frequencies from A to B (8GHz:12GHz:5): one curve each",
    )
    s.add_argument(
        "--stack",
        metavar="LAYERS | FILE.json",
        help='dielectric layers and a ground plane, e.g. "1.575mm eps=2.2 tand=0.0009; '
        'ground" (default: the sheet in vacuum)',
    )
    s.add_argument("--theta", type=float, default=0.0, help="incidence angle in degrees (0)")
    s.add_argument("--phi", type=float, default=0.0, help="azimuth in degrees (0)")
    s.add_argument(
        "--pol",
        choices=("te", "tm", "TE", "TM"),
        default="tm",
        help="incident polarisation whose reflection is the co-polar phase (default tm: "
        "E along x at normal incidence)",
    )
    return s


def checked_library_inputs(args: argparse.Namespace) -> tuple[list[float], list[float], Any]:
    """(values, frequencies, stack) of the library's options; bad ones are usage errors."""
    from barymesh.app.cli_periodic import PeriodicUsageError, parse_stack_option
    from barymesh.frequencies import parse_frequencies

    if (args.cell is None) == (args.cell_preset is None):
        raise UsageError(f"{args.verb} needs one unit cell: --cell FILE or --cell-preset NAME")
    values = parse_values(args.values)
    try:
        frequencies = parse_frequencies(args.freq, "--freq")
        stack = parse_stack_option(args.stack)
    except (PeriodicUsageError, ValueError) as exc:
        raise UsageError(str(exc)) from None
    return values, frequencies, stack


def solve_library(
    args: argparse.Namespace, values: list[float], frequencies: list[float], stack: Any
) -> tuple[Any, str]:
    """The library the options describe, and its cell's label."""
    from barymesh.mom import reflection_library

    cell, label = load_cell_source(args)
    incidence = {"theta": args.theta, "phi": args.phi, "pol": args.pol.upper()}
    lib = reflection_library(
        cell, args.parameter, values, frequencies, incidence=incidence, stack=stack
    )
    return lib, label


def run(args: argparse.Namespace) -> int:
    """``barymesh library``: solve the library and print or write it."""
    if args.output is not None:
        if not args.output.lower().endswith(".csv"):
            raise UsageError(f"-o {args.output}: expected a .csv file")
        check_folder(args.output)
    values, frequencies, stack = checked_library_inputs(args)
    lib, label = solve_library(args, values, frequencies, stack)
    if args.output is not None:
        lib.to_csv(args.output)
        print(
            f"wrote {args.output} ({len(lib.values)} values x {len(lib.frequencies)} "
            f"frequencies of {label})"
        )
    else:
        print(table(lib))
    for warning in lib.warnings:
        print(f"warning: {warning}")
    return 0


def table(lib: Any) -> str:
    """The library as a short text table: value, frequency, ∠R and |R|, then the plane."""
    name = lib.parameter
    width = max(len(name), 8)
    lines = [f"{name:>{width}}  {'f (GHz)':>9}  {'phase (deg)':>11}  {'|R|':>8}"]
    for i, value in enumerate(lib.values):
        for j, f in enumerate(lib.frequencies):
            lines.append(
                f"{value:>{width}.6g}  {f / 1e9:>9.6g}  {lib.phase_deg[i, j]:>11.2f}  "
                f"{lib.magnitude[i, j]:>8.5f}"
            )
    where = "the stack's top face" if lib.stack is not None else "the sheet"
    lines.append(
        f"co-polar R ({lib.polarization} in, {lib.polarization} out), referred to {where}: "
        f"{lib.reference_plane:g} mm over the sheet"
    )
    return "\n".join(lines)
