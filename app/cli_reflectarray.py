"""``barymesh reflectarray``: a reflectarray laid out from a cell's S-curve, from the command line.

::

    barymesh reflectarray --cell patch.cell.json --parameter elements[0].patch_size \\
        --values 6:11:11 --freq 10GHz --stack "1.575mm eps=2.2; ground" \\
        --aperture 15x15 --feed 0,0,150 --beam 20,0 --bits 1 -o array.dxf

Solves the cell's reflection-phase library as ``barymesh library`` does (the same
options), designs the array with :func:`barymesh.reflectarray.design` and prints its
summary (the S-curve's coverage, the main beam, gain, side lobes, phase error and the
quantisation loss); ``-o`` writes the whole array as one cell (``.cell.json``) or its
metal outline (``.dxf``, ``.gds``). Registered in :mod:`barymesh.app.cli`. Bad usage is
one line and exit 2, bad input exit 1.
"""

from __future__ import annotations

import argparse
import math
import re
from typing import Any

from barymesh.app.cli_library import add_library_arguments, checked_library_inputs, solve_library
from barymesh.app.cli_options import UsageError, check_folder

#: What ``-o`` writes: the array as a cell file, or its outline.
OUTPUTS = (".cell.json", ".dxf", ".gds")


def parse_aperture(text: str) -> tuple[int, int]:
    """``--aperture``: ``N1xN2`` elements, or ``N`` for N x N.

    >>> parse_aperture("15x12"), parse_aperture("9")
    ((15, 12), (9, 9))
    """
    match = re.fullmatch(r"\s*(\d{1,6})\s*(?:[xX×]\s*(\d{1,6}))?\s*", text)
    if not match or int(match[1]) < 1 or (match[2] is not None and int(match[2]) < 1):
        raise UsageError(f"--aperture {text[:40]!r} is invalid; expected N1xN2 (15x15) or N")
    n1 = int(match[1])
    return n1, int(match[2]) if match[2] is not None else n1


def parse_numbers(text: str, option: str, count: int, what: str) -> tuple[float, ...]:
    """``count`` comma-separated finite numbers (``--feed``, ``--beam``)."""
    try:
        numbers = tuple(float(x) for x in text.split(","))
    except ValueError:
        numbers = ()
    if len(numbers) != count or not all(math.isfinite(x) for x in numbers):
        raise UsageError(f"{option} {text[:40]!r} is invalid; expected {what}")
    return numbers


def add_parser(subparsers: Any) -> argparse.ArgumentParser:
    """Add ``reflectarray`` to ``subparsers`` (of :func:`barymesh.app.cli.build_parser`)."""
    p = subparsers.add_parser(
        "reflectarray",
        help="a reflectarray laid out from a cell's reflection-phase library",
        description="Solve a unit cell's reflection-phase library (as `barymesh library`), "
        "give every element of an N1 x N2 aperture the parameter whose phase makes up the "
        "feed's path and tilts the beam (local-periodicity approximation), and print the "
        "predicted main beam, gain, side lobes and phase error; -o writes the array as "
        "one cell (.cell.json) or its metal outline (.dxf, .gds).",
    )
    add_library_arguments(p)
    d = p.add_argument_group("reflectarray")
    d.add_argument("--aperture", required=True, metavar="N1xN2", help="elements per side (15x15)")
    d.add_argument(
        "--feed",
        required=True,
        metavar="X,Y,Z",
        help="the feed's phase centre in mm over the aperture's centre (0,0,150); it "
        "points at the centre",
    )
    d.add_argument(
        "--beam", required=True, metavar="THETA,PHI", help="beam direction in degrees (20,0)"
    )
    d.add_argument(
        "--bits",
        type=int,
        choices=(1, 2, 3),
        help="quantise the phases to 2, 4 or 8 levels (default: continuous)",
    )
    d.add_argument(
        "--design-freq",
        metavar="F",
        help="the design frequency, one of --freq's (default: --freq's only one)",
    )
    d.add_argument(
        "--feed-q",
        type=float,
        default=None,
        metavar="Q",
        help="the feed's pattern cos^Q (default 6.5: about -9 dB at ±30°)",
    )
    d.add_argument(
        "-o",
        "--output",
        metavar="OUT",
        help="write the array as a cell (.cell.json) or its outline (.dxf, .gds)",
    )
    return p


def run(args: argparse.Namespace) -> int:
    """``barymesh reflectarray``: solve the library, design the array, report and write."""
    import numpy as np

    from barymesh.frequencies import parse_frequencies

    if args.output is not None:
        if not args.output.lower().endswith(OUTPUTS):
            raise UsageError(f"-o {args.output}: expected {', '.join(OUTPUTS)}")
        check_folder(args.output)
    aperture = parse_aperture(args.aperture)
    x, y, z = parse_numbers(args.feed, "--feed", 3, "X,Y,Z in mm (0,0,150)")
    theta, phi = parse_numbers(args.beam, "--beam", 2, "THETA,PHI in degrees (20,0)")
    feed, beam = (x, y, z), (theta, phi)
    values, frequencies, stack = checked_library_inputs(args)
    if args.design_freq is not None:
        try:
            (frequency,) = parse_frequencies(args.design_freq, "--design-freq")
        except ValueError as exc:
            raise UsageError(str(exc)) from None
    elif len(frequencies) == 1:
        frequency = frequencies[0]
    else:
        raise UsageError("--freq gives several frequencies: choose one with --design-freq F")
    if not any(abs(frequency - f) <= 1e-9 * f for f in frequencies):
        raise UsageError(
            f"--design-freq {frequency / 1e9:g} GHz is not one of --freq's frequencies"
        )
    from barymesh.reflectarray import DEFAULT_FEED_Q, design

    lib, label = solve_library(args, values, frequencies, stack)
    q = DEFAULT_FEED_Q if args.feed_q is None else args.feed_q
    array = design(lib, aperture, feed, beam, frequency, bits=args.bits, q=q)
    column = int(np.argmin(np.abs(lib.frequencies - frequency)))
    covered = float(np.ptp(lib.phase_deg[:, column]))
    print(
        f"S-curve of {label}: {lib.parameter} from {lib.values[0]:g} to {lib.values[-1]:g} "
        f"covers {min(covered, 360.0):.0f}° of 360° at {frequency / 1e9:g} GHz "
        f"(referred to {lib.reference_plane:g} mm over the sheet)"
    )
    print(array.summary())
    for warning in lib.warnings:
        print(f"warning: {warning}")
    if args.output is not None:
        cell = array.to_cell()
        if args.output.lower().endswith(".cell.json"):
            from barymesh.cell import save_cell

            save_cell(cell, args.output)
        else:
            from barymesh.cell import export_outline

            export_outline(cell, args.output)
        print(f"wrote {args.output} ({len(cell.elements)} elements)")
    return 0
