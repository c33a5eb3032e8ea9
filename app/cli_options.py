"""The command line's options and their checks, shared by :mod:`barymesh.app.cli`,
:mod:`barymesh.app.cli_solve` and the window
(:func:`~barymesh.app.cli_options.build_window_parser` is the one parser of ``barymesh``
without a command, for :func:`barymesh.app.cli.main` and :func:`barymesh.app.window_main.main`
alike).

Qt-free: the command line works without the app extras.
"""

from __future__ import annotations

import argparse
import math
import re
from pathlib import Path
from typing import Any, NoReturn


class UsageError(Exception):
    """Bad command-line usage (exit code 2)."""


class InputError(Exception):
    """Bad input: parameter values, files (exit code 1)."""


# -- argument types and groups ------------------------------------------------


#: A value that starts with "-" and is not an option: an axis (``-z``) or a number or
#: vector (``-1,0,0``, ``-.5``).
_DASH_VALUE = re.compile(r"^-([xyzXYZ]$|\d|\.\d)")


class Parser(argparse.ArgumentParser):
    """argparse with usage errors raised as :class:`UsageError`, not printed mid-way.

    ``dash_value_options``: options whose value may start with "-" (``--dir -z``,
    ``--pol -1,0,0``); argparse takes such a value only when joined (``--dir=-z``), so
    they are joined before parsing.
    """

    dash_value_options: tuple[str, ...] = ()

    def error(self, message: str) -> NoReturn:
        """Raise :class:`UsageError` with the program's name and ``message``."""
        raise UsageError(f"{self.prog}: {message}")

    def parse_known_args(self, args=None, namespace=None):
        if args is not None and self.dash_value_options:
            args = join_dash_values(list(args), self.dash_value_options)
        return super().parse_known_args(args, namespace)


def join_dash_values(argv: list[str], options: tuple[str, ...]) -> list[str]:
    """``--dir -z`` as ``--dir=-z`` for each option of ``options`` followed by a value
    that starts with "-" (an axis letter, a digit or ".digit").

    >>> join_dash_values(["x.json", "--dir", "-z", "--pol", "-1,0,0", "--theta", "-5"],
    ...                  ("--dir", "--pol"))
    ['x.json', '--dir=-z', '--pol=-1,0,0', '--theta', '-5']
    """
    out: list[str] = []
    i = 0
    while i < len(argv):
        arg = argv[i]
        if arg in options and i + 1 < len(argv) and _DASH_VALUE.match(argv[i + 1]):
            out.append(f"{arg}={argv[i + 1]}")
            i += 2
            continue
        out.append(arg)
        i += 1
    return out


def window_size(text: str) -> int:
    """``--window-size`` W or H: a whole number of pixels, 16 to 16384."""
    try:
        value = int(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f"{text!r} is not a whole number of pixels") from None
    if not 16 <= value <= 16384:
        raise argparse.ArgumentTypeError(f"{value} pixels is outside 16..16384")
    return value


def finite(text: str) -> float:
    """A finite number (``--fps``, ``--from``, ``--chord-error``…)."""
    try:
        value = float(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f"{text[:40]!r} is not a number") from None
    if not math.isfinite(value):
        raise argparse.ArgumentTypeError(f"{text[:40]!r} is not a finite number")
    return value


def whole(text: str) -> int:
    """A whole number (``--frames``)."""
    try:
        return int(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f"{text[:40]!r} is not a whole number") from None


def array_size(text: str) -> tuple[int, int]:
    """``--array N1xN2``: at least one copy each way, e.g. ``3x2`` -> (3, 2)."""
    match = re.fullmatch(r"\s*(\d{1,12})\s*[xX×]\s*(\d{1,12})\s*", text)
    if not match:
        raise argparse.ArgumentTypeError(
            f"{text[:40]!r} is invalid; expected N1xN2 copies, e.g. 3x2"
        )
    n1, n2 = int(match[1]), int(match[2])
    if n1 < 1 or n2 < 1:
        raise argparse.ArgumentTypeError(f"{text[:40]!r} is invalid; expected at least 1x1")
    return n1, n2


def period(text: str) -> tuple[float, float]:
    """``--period PX[,PY]`` in mm, both > 0 (one value: a square lattice)."""
    parts = text.split(",")
    if len(parts) > 2:
        raise argparse.ArgumentTypeError(f"{text[:40]!r} is invalid; expected PX or PX,PY in mm")
    values = [finite(part) for part in parts]
    if min(values) <= 0:
        raise argparse.ArgumentTypeError(f"{text[:40]!r} is invalid; expected periods > 0 mm")
    return values[0], values[-1]


def add_cell_options(p: argparse.ArgumentParser, structure: bool = True) -> None:
    """``--cell``, ``--cell-preset``, ``--array`` and, with ``structure``, ``--period``."""
    if structure:
        title = "unit cell (instead of --preset/--params/--set, except --array and --period)"
        array = (
            "an N1 x N2 array of the cell, or of the structure on a rectangular lattice whose "
            "periods are its bounding box (copies touch), as one welded mesh"
        )
    else:
        title = "unit cell (instead of a mesh FILE)"
        array = "an N1 x N2 array of the cell, as one welded mesh"
    g = p.add_argument_group(title)
    g.add_argument("--cell", metavar="FILE.cell.json", help="a unit-cell file")
    g.add_argument(
        "--cell-preset", metavar="NAME", help="a shipped unit cell (see `barymesh presets`)"
    )
    g.add_argument("--array", type=array_size, metavar="N1xN2", help=array)
    if structure:
        g.add_argument(
            "--period",
            type=period,
            metavar="PX[,PY]",
            help="lattice periods (mm) of a structure made into a cell, instead of its "
            "bounding box",
        )


def load_cell_source(args: argparse.Namespace) -> tuple[Any, str]:
    """The cell of ``--cell`` or ``--cell-preset`` and its label; errors name the file."""
    from barymesh.cell import load_cell, load_cell_preset
    from barymesh.io.import_ import file_problem

    if args.cell_preset is not None:
        return load_cell_preset(args.cell_preset), f"cell preset {args.cell_preset!r}"
    path = Path(args.cell)
    problem = file_problem(path)  # a pipe or a device is never opened
    if problem:
        raise InputError(f"{path}: {problem}")
    return load_cell(path), str(path)  # CellFileError names the file and the place


def add_mesh_grade_option(p: argparse.ArgumentParser) -> None:
    """``--mesh-as-given``: solve the mesh as the parts describe it, not solver-grade."""
    p.add_argument(
        "--mesh-as-given",
        action="store_true",
        help="solve the mesh exactly as the preset, parameters or cell give it; by default "
        "a part that does not say 'grading' is meshed solver-grade: a patch, strip or "
        "triangle graded toward its edges (n >= 16), pixels toward the painted outline, "
        "every part's edges within lambda/10 at the highest frequency",
    )


def solver_grade_structure(
    args: argparse.Namespace,
    params: Any,
    top_frequency: float | None,
    relative_permittivity: float = 1.0,
) -> tuple[Any, str]:
    """The solver-grade parameters of the structure of --preset/--params/--set, and a note
    ("" when nothing changed or ``--mesh-as-given``)."""
    if getattr(args, "mesh_as_given", False):
        return params, ""
    from barymesh.presets import given_keys
    from barymesh.solver_grade import solver_params

    if "grading" in given_keys(args.preset, args.params, args.sets):
        return params, ""  # it says how it is to be meshed
    out = solver_params(
        params, frequency=top_frequency, relative_permittivity=relative_permittivity
    )
    return out, _grade_note([("the structure", params, out)])


def solver_grade_cell(
    args: argparse.Namespace,
    cell: Any,
    top_frequency: float | None,
    relative_permittivity: float = 1.0,
) -> tuple[Any, str]:
    """The solver-grade cell of --cell/--cell-preset (parts that say 'grading' are taken
    as given), and a note ("" when nothing changed or ``--mesh-as-given``)."""
    if getattr(args, "mesh_as_given", False):
        return cell, ""
    from barymesh.cell import cell_preset_path, read_cell_document
    from barymesh.solver_grade import document_grading, solver_cell

    path = cell_preset_path(args.cell_preset) if args.cell_preset is not None else args.cell
    flags, pixels = document_grading(read_cell_document(path))
    if len(flags) != len(cell.elements):  # not the document's elements: grade them all
        flags = tuple(True for _ in cell.elements)
    out = solver_cell(
        cell,
        frequency=top_frequency,
        relative_permittivity=relative_permittivity,
        grade=flags,
        grade_pixels=pixels,
    )
    parts: list[tuple[str, Any, Any]] = [
        (repr(a.name), a.params, b.params) for a, b in zip(cell.elements, out.elements, strict=True)
    ]
    if cell.pixels is not None and out.pixels is not None:
        parts.append(("the pixels", cell.pixels, out.pixels))
    return out, _grade_note(parts)


def _grade_note(parts: list[tuple[str, Any, Any]]) -> str:
    """'solver-grade mesh: 'patch' graded toward its edges, n = 16; ...' or ''."""
    said = []
    for name, before, after in parts:
        if after is before:
            continue
        what = []
        if after.grading and not before.grading:
            what.append("graded toward its edges" if name != "the pixels" else "graded")
        if after.subdivisions != before.subdivisions:
            what.append(f"n = {after.subdivisions} (was {before.subdivisions})")
        elif what:
            what.append(f"n = {after.subdivisions}")
        if what:
            said.append(f"{name} {', '.join(what)}")
    if not said:
        return ""
    return "solver-grade mesh: " + "; ".join(said) + " (--mesh-as-given: as given)"


def add_params_options(p: argparse.ArgumentParser) -> None:
    """``--preset``, ``--params`` and the repeatable ``--set name=value``."""
    g = p.add_argument_group("parameters (later sources win: preset, then file, then --set)")
    g.add_argument("--preset", metavar="NAME", help="start from a preset (see `barymesh presets`)")
    g.add_argument("--params", metavar="FILE.json", help="a JSON parameter file")
    g.add_argument(
        "--set",
        dest="sets",
        metavar="name=value",
        action="append",
        default=[],
        help="one parameter, value as JSON when it parses: subdivisions=8, origin=[1,2], "
        "mode=conforming (repeatable)",
    )


def add_stats_option(p: argparse._ActionsContainer) -> None:
    """``--stats-json PATH|-``."""
    p.add_argument(
        "--stats-json",
        metavar="PATH|-",
        help="write the statistics as JSON to PATH, or to stdout with '-' (then nothing "
        "else goes to stdout)",
    )


def add_quality_option(p: argparse._ActionsContainer) -> None:
    """``--quality-json PATH|-``."""
    p.add_argument(
        "--quality-json",
        metavar="PATH|-",
        help="write the quality report (smallest angle, aspect ratio, edge/wavelength: "
        "figures, histograms, the 20 worst triangles) as JSON to PATH, or to stdout with '-'",
    )


def parse_copies(text: str) -> tuple[int, int]:
    """``"3x2"`` -> (3, 2): the window's array preview copies as typed on the command line.

    >>> parse_copies("3x2"), parse_copies(" 4 × 1 ")
    ((3, 2), (4, 1))
    """
    # the cell document imports the unit cells' code: not for ``barymesh --help``
    from barymesh.app.model.cell_document import MAX_COPIES

    match = re.fullmatch(r"\s*(\d{1,6})\s*[xX×]\s*(\d{1,6})\s*", text)
    if not match or not all(1 <= int(g) <= MAX_COPIES for g in match.groups()):
        raise argparse.ArgumentTypeError(
            f"{text[:40]!r} is invalid; expected N1xN2 copies, each 1 to {MAX_COPIES}, e.g. 3x2"
        )
    return int(match[1]), int(match[2])


# -- the window's options ------------------------------------------------------


def build_window_parser() -> argparse.ArgumentParser:
    """The parser of ``barymesh`` without a command: the window's options.

    Errors print the usage and exit 2 (:func:`barymesh.app.window_main.main`);
    :func:`barymesh.app.cli.main` makes them one line first.
    """
    parser = argparse.ArgumentParser(
        prog="barymesh",
        description="Open the barymesh window: sliders drive the mesher, the 3D view follows.",
    )
    parser.add_argument("--preset", metavar="NAME", help="start from a preset (see Presets menu)")
    parser.add_argument("--params", metavar="FILE", help="start from a JSON parameter file")
    parser.add_argument(
        "--set",
        metavar="NAME=VALUE",
        nargs="+",
        action="extend",
        default=[],
        dest="sets",
        help="override parameters, e.g. --set subdivisions=8",
    )
    parser.add_argument(
        "--cell",
        metavar="FILE.cell.json",
        help="open a unit cell file (instead of --preset/--params/--set)",
    )
    parser.add_argument(
        "--cell-preset", metavar="NAME", help="open a shipped unit cell (see the Cell menu)"
    )
    parser.add_argument(
        "--array",
        metavar="N1xN2",
        type=parse_copies,
        help="with a cell: preview N1 x N2 copies of it (drawn, not meshed)",
    )
    parser.add_argument(
        "--screenshot", metavar="PNG", help="save a grab of the whole window once the mesh is shown"
    )
    parser.add_argument(
        "--quit", action="store_true", help="exit once the mesh is shown (and the screenshot saved)"
    )
    return parser


# -- checks --------------------------------------------------------------------


#: Bytes an off-screen render needs per pixel (colour, depth and VTK's copies; measured:
#: 9.1 GB for 16384 x 16384 with llvmpipe).
RENDER_BYTES_PER_PIXEL = 36
#: Renders estimated above this are refused before they start.
RENDER_MEMORY_LIMIT = 2 * 2**30


def check_render_size(verb: str, width: int, height: int) -> None:
    """Refuse (:class:`UsageError`) an off-screen render that would need more memory than
    :data:`RENDER_MEMORY_LIMIT`, before it starts."""
    need = width * height * RENDER_BYTES_PER_PIXEL
    if need > RENDER_MEMORY_LIMIT:
        raise UsageError(
            f"{verb}: --window-size {width} {height} would need about {need / 2**30:.1f} GiB "
            f"to render; at most {RENDER_MEMORY_LIMIT / 2**30:.0f} GiB "
            f"({RENDER_MEMORY_LIMIT // RENDER_BYTES_PER_PIXEL:,} pixels)"
        )


def check_folder(target: str) -> None:
    """Refuse (:class:`InputError`) an output whose folder does not exist, before the work
    that would write it."""
    folder = Path(target).parent
    if not folder.is_dir():
        what = "is not a folder" if folder.exists() else "does not exist"
        raise InputError(f"cannot write {target}: the folder {folder} {what}")


def check_preset(args: argparse.Namespace, verb: str | None) -> None:
    """``--preset`` names a shipped structure preset (a cell preset gets a hint);
    UsageError (exit code 2) if not. ``verb`` starts the message (None: the window)."""
    from barymesh.cell import cell_preset_names
    from barymesh.presets import preset_names

    lead = f"{verb}: " if verb else ""
    if args.preset is not None and args.preset not in preset_names():
        if args.preset in cell_preset_names():
            raise UsageError(
                f"{lead}{args.preset!r} is a unit-cell preset; use --cell-preset {args.preset}"
            )
        raise UsageError(
            f"{lead}unknown preset {args.preset!r}; expected one of {', '.join(preset_names())}"
        )


def check_cell_usage(args: argparse.Namespace, verb: str | None) -> None:
    """A cell replaces the structure options; its preset must exist. UsageError (exit
    code 2) if not; ``verb`` starts the message (None: the window)."""
    from barymesh.cell import cell_preset_names
    from barymesh.presets import preset_names

    lead = f"{verb}: " if verb else ""
    cell_option = "--cell" if args.cell is not None else "--cell-preset"
    if args.cell is not None and args.cell_preset is not None:
        raise UsageError(f"{lead}--cell and --cell-preset both name a cell; give one")
    if args.cell is not None or args.cell_preset is not None:
        given = [
            option
            for option, value in (
                ("--preset", getattr(args, "preset", None)),
                ("--params", getattr(args, "params", None)),
                ("--set", getattr(args, "sets", None)),
            )
            if value
        ]
        if given:
            raise UsageError(
                f"{lead}{given[0]} sets the parameters of one structure; a cell "
                f"({cell_option}) holds its own elements: edit its file instead"
            )
        if getattr(args, "period", None) is not None:
            raise UsageError(
                f"{lead}--period makes a structure into a cell; a cell ({cell_option}) "
                "has its own lattice"
            )
    name = args.cell_preset
    if name is not None and name not in cell_preset_names():
        hint = ""
        if name in preset_names():
            hint = f"; {name!r} is a structure preset: use --preset {name}"
        raise UsageError(
            f"{lead}unknown cell preset {name!r}; expected one of "
            f"{', '.join(cell_preset_names())}{hint}"
        )
