"""The ``barymesh`` command line.

::

    barymesh                       open the desktop window (same options as below)
    barymesh mesh [options]        build a mesh, write files, render a screenshot
    barymesh info FILE             import a mesh file and print its statistics
    barymesh presets               list the presets (structures, then unit cells)
    barymesh study SPEC.json       a design study on Dask (barymesh.app.cli_study)
    barymesh library [options]     a cell's reflection-phase library (barymesh.app.cli_library)
    barymesh reflectarray [options]  a reflectarray from that library (.cli_reflectarray)
    barymesh --print-completion bash   the shell completion script (barymesh.app.cli_completion)

A unit cell (``--cell FILE.cell.json`` or ``--cell-preset NAME``) or an array
(``--array N1xN2``, of a cell or of one structure) is meshed by
:mod:`barymesh.cell`; ``-o`` then also takes ``.dxf`` and ``.gds`` (the metal
outline) and a ``.msh`` carries ``$Periodic`` when the mesh is periodic.

Exit codes: 0 success, 1 bad input (parameter values, files), 2 bad usage.
Errors are one line on stderr, never a traceback.
"""

from __future__ import annotations

import argparse
import json
import math
import os
import re
import sys
from dataclasses import dataclass
from pathlib import Path
from typing import Any, NoReturn

from barymesh.app import cli_library, cli_reflectarray, cli_solve, cli_study
from barymesh.app.cli_options import (
    InputError,
    Parser,
    UsageError,
    add_cell_options,
    add_params_options,
    add_quality_option,
    add_stats_option,
    build_window_parser,
    check_cell_usage,
    check_folder,
    check_preset,
    check_render_size,
    finite,
    load_cell_source,
    whole,
    window_size,
)
from barymesh.app.cli_progress import progress

__all__ = ["InputError", "UsageError", "build_parser", "main", "progress"]

PROG = "barymesh"


# -- argument parsing ------------------------------------------------------


def build_parser() -> argparse.ArgumentParser:
    """The parser of the subcommands (``mesh``, ``info``, ``sweep``, ``presets``)."""
    from barymesh.cell.outline import DEFAULT_CHORD_ERROR
    from barymesh.io import EXPORT_EXTENSIONS, IMPORT_EXTENSIONS, MSH_VERSIONS, UNITS

    parser = Parser(
        prog=PROG,
        description="RWG-ready triangle meshes of metasurface unit cells. "
        "Without a command, opens the desktop window "
        "(options: --preset, --params, --set, --screenshot, --quit).",
    )
    from barymesh import __version__

    parser.add_argument("--version", action="version", version=f"{PROG} {__version__}")
    verbs = parser.add_subparsers(dest="verb", metavar="COMMAND", parser_class=Parser)

    mesh = verbs.add_parser(
        "mesh",
        help="build a mesh; write files, a screenshot, statistics",
        description="Build a mesh from a preset, a parameter file and/or single parameters, "
        "or of a unit cell or an array, write each -o file (format from its extension), "
        "optionally render a screenshot without a display, and print a short summary.",
    )
    add_params_options(mesh)
    add_cell_options(mesh)
    out = mesh.add_argument_group("output")
    out.add_argument(
        "-o",
        "--output",
        dest="outputs",
        metavar="OUT",
        action="append",
        default=[],
        help=f"write the mesh; the extension picks the format: {', '.join(EXPORT_EXTENSIONS)}; "
        "or the metal outline: .dxf, .gds (repeatable)",
    )
    out.add_argument(
        "--chord-error",
        type=finite,
        metavar="MM",
        help=f"outlines: largest distance between an arc and its chords (default "
        f"{DEFAULT_CHORD_ERROR:g} mm)",
    )
    out.add_argument(
        "--unit",
        choices=UNITS,
        help="length unit of the written files (default mm; .mat: m)",
    )
    out.add_argument(
        "--msh-version",
        choices=MSH_VERSIONS,
        help=f"Gmsh format of a .msh: {MSH_VERSIONS[0]} (default; the solvers of Makarov's era "
        "read it) or 4.1 (Gmsh 4's own; each patch one entity); a cell's $Periodic in both",
    )
    out.add_argument("--screenshot", metavar="PNG", help="render the mesh off-screen to PNG")
    out.add_argument(
        "--window-size",
        nargs=2,
        type=window_size,
        metavar=("W", "H"),
        default=(1024, 768),
        help="screenshot size in pixels (default 1024 768)",
    )
    out.add_argument(
        "--transparent", action="store_true", help="screenshot with a transparent background"
    )
    add_stats_option(out)
    add_quality_option(out)

    info = verbs.add_parser(
        "info",
        help="import a mesh file and print its statistics",
        description="Import a mesh file and print the same statistics as `barymesh mesh`. "
        f"Reads {', '.join(IMPORT_EXTENSIONS)}; only triangles count, other cells are "
        "reported as ignored. A unit cell (FILE.cell.json, --cell or --cell-preset) is "
        "meshed instead and its statistics printed per part, with the periodic check.",
    )
    info.add_argument("file", metavar="FILE", nargs="?", help="the mesh file (or a cell file)")
    add_cell_options(info, structure=False)
    info.add_argument(
        "--unit",
        choices=UNITS,
        help="length unit of the file's coordinates (default mm; .mat: m)",
    )
    info.add_argument(
        "--frequency",
        type=finite,
        metavar="HZ",
        help="the quality report adds each triangle's longest edge over the free-space "
        "wavelength at this frequency (the lambda/10 rule)",
    )
    add_stats_option(info)
    add_quality_option(info)

    from barymesh.teach.sweep import MAX_FRAMES, SWEEPABLE

    sweep = verbs.add_parser(
        "sweep",
        help="animate a sweep of one parameter to GIF or MP4",
        description="Mesh and render K frames with one parameter going from A to B "
        "(integers rounded), without a display, and save them as an animation.",
    )
    add_params_options(sweep)
    for option in ("--cell", "--cell-preset", "--array", "--period"):  # refused in one line
        dest = "refused_" + option[2:].replace("-", "_")
        sweep.add_argument(option, dest=dest, help=argparse.SUPPRESS)
    anim = sweep.add_argument_group("sweep")
    anim.add_argument("--param", required=True, choices=SWEEPABLE, help="the parameter to vary")
    anim.add_argument("--from", dest="start", required=True, type=finite, metavar="A")
    anim.add_argument("--to", dest="stop", required=True, type=finite, metavar="B")
    anim.add_argument(
        "--frames", required=True, type=whole, metavar="K", help=f"frames, 2..{MAX_FRAMES}"
    )
    anim.add_argument(
        "--fps", type=finite, default=4.0, help="frames per second, up to 100 (default 4)"
    )
    anim.add_argument(
        "-o", "--output", required=True, metavar="OUT", help="the animation: .gif or .mp4"
    )
    anim.add_argument(
        "--window-size",
        nargs=2,
        type=window_size,
        metavar=("W", "H"),
        default=(800, 600),
        help="frame size in pixels (default 800 600)",
    )

    cli_solve.add_parser(verbs)
    cli_study.add_parser(verbs)
    cli_library.add_parser(verbs)
    cli_reflectarray.add_parser(verbs)
    verbs.add_parser(
        "presets",
        help="list the presets, one per line",
        description="List the structure presets (--preset NAME), then the unit-cell presets "
        "(--cell-preset NAME, described as 'cell: ...'), one line each.",
    )
    from barymesh.app.cli_completion import add_completion

    return add_completion(parser)


# -- output ----------------------------------------------------------------


def _aspect_text(largest: float, degenerate: int | None = None) -> str:
    """The largest aspect ratio for a person: ``inf (triangle 7 has zero area)``, not nan.

    The ratio is l_max × perimeter / (4√3 area): infinite for a flat triangle and 0/0 (NaN)
    for one whose corners coincide; both are triangles of zero area.
    """
    if math.isfinite(largest):
        return f"{largest:.4g}"
    which = "a triangle has" if degenerate is None else f"triangle {degenerate:,} has"
    return f"inf ({which} zero area)"


def _summary(stats: dict[str, Any], title: str, degenerate: int | None = None) -> str:
    lines = [
        f"{title}",
        f"  {stats['triangles']:,} triangles, {stats['vertices']:,} vertices, "
        f"{stats['patches']:,} patches, {stats['regions']} region(s)",
        f"  {stats['edges']:,} edges: {stats['interior_edges']:,} interior (RWG unknowns), "
        f"{stats['boundary_edges']:,} boundary, {stats['junction_edges']:,} junction",
        f"  edge length {stats['min_edge']:.6g} .. {stats['max_edge']:.6g} mm, "
        f"min angle {stats['min_angle_deg']:.3g} deg, "
        f"max aspect ratio {_aspect_text(stats['max_aspect_ratio'], degenerate)}",
        f"  area {stats['area']:.6g} mm^2, V - E + F = {stats['euler_characteristic']}",
    ]
    if stats.get("overlap_ratio") is not None:
        lines.append(f"  overlap ratio {stats['overlap_ratio']:.4g} (paper mode)")
    if stats.get("ignored_cells"):
        cells = ", ".join(f"{n:,} {kind}" for kind, n in sorted(stats["ignored_cells"].items()))
        lines.append(f"  ignored non-triangle cells: {cells}")
    if "subdivisions_chosen" in stats:
        from barymesh.sizing import sizing_summary

        lines.append(sizing_summary(stats))
    return "\n".join(lines)


def _quality(mesh: Any, wavelength: float | None) -> dict[str, Any]:
    from barymesh.quality import quality_report

    with progress("measuring the quality"):
        return quality_report(mesh, wavelength=wavelength)


def _quality_text(report: dict[str, Any]) -> str:
    from barymesh.quality import quality_lines

    return "\n".join(["  quality:", *("  " + line for line in quality_lines(report))])


def _to_stdout(args: argparse.Namespace) -> bool:
    """Whether a JSON output goes to stdout (then the summary goes to stderr)."""
    return "-" in (args.stats_json, args.quality_json)


def _check_json_targets(args: argparse.Namespace, verb: str) -> None:
    if args.stats_json == "-" and args.quality_json == "-":
        raise UsageError(
            f"{verb}: --stats-json - and --quality-json - both want stdout; write one to a file"
        )


def _json_ready(value: Any) -> Any:
    """``value`` with every float that is not finite (NaN, ±inf) replaced by None."""
    if isinstance(value, float):
        return value if math.isfinite(value) else None
    if isinstance(value, dict):
        return {k: _json_ready(v) for k, v in value.items()}
    if isinstance(value, (list, tuple)):
        return [_json_ready(v) for v in value]
    return value


def _emit_stats(stats: dict[str, Any], target: str | None) -> None:
    if target is None:
        return
    # no NaN or Infinity: strict JSON parsers refuse them (null instead)
    text = json.dumps(_json_ready(stats), indent=2, allow_nan=False) + "\n"
    if target == "-":
        sys.stdout.write(text)
        return
    from barymesh.io import atomic_write_text

    atomic_write_text(Path(target), text)


# -- verbs -----------------------------------------------------------------


def _cmd_mesh(args: argparse.Namespace) -> int:
    _check_mesh_usage(args)
    say = sys.stderr if _to_stdout(args) else sys.stdout
    outlines = [out for out in args.outputs if Path(out).suffix.lower() in OUTLINE_EXTENSIONS]
    built = _build(args)
    polygons = _outline_polygons(built, args, outlines[0]) if outlines else []
    print(built.summary, file=say)
    from barymesh.quality import params_wavelength

    wavelength = params_wavelength(built.params)
    report = _quality(built.mesh, wavelength)
    print(_quality_text(report), file=say)

    from barymesh.io import describe_export

    for out in args.outputs:
        with progress(f"writing {out}"):
            if out in outlines:
                _write_outline(polygons, out, built.name)
                print(f"wrote {_describe_outline(out, polygons, args.chord_error)}", file=say)
            else:
                extra = _write_mesh_file(built, out, args.unit, wavelength, args.msh_version)
                described = describe_export(out, args.unit, args.msh_version)
                print(f"wrote {described}{extra}", file=say)
    if args.screenshot:
        _screenshot(built.mesh, args.screenshot, tuple(args.window_size), args.transparent)
        print(f"wrote {args.screenshot} ({args.window_size[0]}x{args.window_size[1]} px)", file=say)
    _emit_stats(built.stats, args.stats_json)
    _emit_stats(report, args.quality_json)
    return 0


def _check_mesh_usage(args: argparse.Namespace) -> None:
    """Checks of ``mesh`` before any work: usage (exit code 2), then folders and writers (1)."""
    from barymesh.io import export_format

    check_preset(args, "mesh")
    check_cell_usage(args, "mesh")
    for out in args.outputs:
        if Path(out).suffix.lower() in OUTLINE_EXTENSIONS:
            continue
        try:
            export_format(out)
        except ValueError as exc:
            raise UsageError(f"mesh: -o {exc}; or .dxf, .gds for the outline") from None
    outlines = [out for out in args.outputs if Path(out).suffix.lower() in OUTLINE_EXTENSIONS]
    if args.chord_error is not None and not outlines:
        raise UsageError("mesh: --chord-error needs an outline output (-o FILE.dxf or .gds)")
    if args.chord_error is not None and args.chord_error <= 0:
        raise UsageError(f"mesh: --chord-error {args.chord_error:g} is invalid; expected > 0 mm")
    if outlines and args.unit not in (None, "mm"):
        raise UsageError(
            f"mesh: -o {outlines[0]}: outlines are written in mm; --unit {args.unit} is for "
            "mesh files (write them in a separate run)"
        )
    if args.transparent and not args.screenshot:
        raise UsageError("mesh: --transparent needs --screenshot")
    if args.msh_version is not None and not any(
        Path(out).suffix.lower() == ".msh" for out in args.outputs
    ):
        raise UsageError(
            f"mesh: --msh-version {args.msh_version} sets the format of a .msh output; add "
            "-o FILE.msh"
        )
    if args.screenshot:
        check_render_size("mesh", *args.window_size)
    for text in args.sets:
        if "=" not in text or not text.partition("=")[0].strip():
            raise UsageError(f"mesh: --set {text!r} is invalid; expected name=value")
    _check_json_targets(args, "mesh")
    targets = [*args.outputs, args.screenshot]
    targets += [t for t in (args.stats_json, args.quality_json) if t != "-"]
    for target in filter(None, targets):
        check_folder(target)  # before minutes of meshing, not after
    for out in outlines:
        _check_outline_writer(out)


# -- what a command meshes: one structure, or a unit cell / an array ----------

#: Outline extensions of -o: (format name, the module that writes it).
OUTLINE_EXTENSIONS = {".dxf": ("DXF", "ezdxf"), ".gds": ("GDSII", "gdstk")}


@dataclass(frozen=True)
class _Built:
    """A finished mesh and what the outputs need of it."""

    mesh: Any  # TriMesh
    stats: dict[str, Any]  # TriMesh.stats(), or CellMesh.stats() for a cell
    summary: str
    name: str  # the structure's or the cell's name (GDSII cell name)
    label: str  # where it came from, for messages
    params: Any = None  # MeshParams of a plain structure
    cell: Any = None  # UnitCell, or None for a plain structure
    cell_mesh: Any = None  # CellMesh
    copies: tuple[int, int] = (1, 1)


def _build(args: argparse.Namespace) -> _Built:
    """Mesh what the options name: a structure, or a cell or array (with progress)."""
    from barymesh import build_mesh

    array, period = args.array, getattr(args, "period", None)
    if args.cell is not None or args.cell_preset is not None:
        cell, label = load_cell_source(args)
        budget = None
    else:
        params = _resolve(args)
        name = args.preset or params.structure
        label = _structure_label(args)
        what = (
            "choosing the subdivisions"
            if params.sized
            else f"building {params.predicted_triangles():,} triangles"
        )
        with progress(what):
            mesh = build_mesh(params)
        if array is None and period is None:
            stats = mesh.stats()
            title = f"{args.preset or 'mesh'}: {params.structure}, {params.mode} mode"
            return _Built(mesh, stats, _summary(stats, title), name, label, params=params)
        cell = _structure_cell(params, mesh, name, period)
        budget = params.max_triangles
    copies = array or (1, 1)
    total = _check_cell_budget(cell, copies, label, budget)
    from barymesh.cell import build_cell, tile
    from barymesh.params import DEFAULT_MAX_TRIANGLES

    limit = DEFAULT_MAX_TRIANGLES if budget is None else budget
    with progress(f"building {total:,} triangles"):
        try:
            cell_mesh = build_cell(cell, max_triangles=limit)
            if copies != (1, 1):
                cell_mesh = tile(cell_mesh, *copies, max_triangles=limit)
        except ValueError as exc:
            raise InputError(f"{label}: {exc}") from None
        stats = cell_mesh.stats()
    return _Built(
        cell_mesh.mesh,
        stats,
        _cell_summary(cell_mesh, stats, label),
        cell.name,
        label,
        cell=cell,
        cell_mesh=cell_mesh,
        copies=copies,
    )


def _structure_label(args: argparse.Namespace) -> str:
    given = [f"preset {args.preset!r}" if args.preset else "", args.params or ""]
    given += [f"--set {text!r}" for text in args.sets]
    return ", ".join(filter(None, given)) or "the default structure"


def _structure_cell(params: Any, mesh: Any, name: str, period: tuple[float, float] | None) -> Any:
    """One structure as a cell: centred on its bounding box, whose size is the period.

    Without ``period`` the lattice is rectangular with the bounding box's width and
    height as periods, so neighbouring copies touch.
    """
    from barymesh.cell import Element, Lattice, UnitCell

    lo, hi = mesh.points[:, :2].min(axis=0), mesh.points[:, :2].max(axis=0)
    px, py = period if period is not None else (float(hi[0] - lo[0]), float(hi[1] - lo[1]))
    centre = (lo + hi) / 2
    element = Element(params, position=(-centre[0], -centre[1]), name=name)
    return UnitCell(
        Lattice.rectangular(px, py),
        (element,),
        mode=params.mode,
        tolerance=params.tolerance,
        name=name,
    )


def _check_cell_budget(cell: Any, copies: tuple[int, int], label: str, budget: int | None) -> int:
    """The predicted triangles of ``copies`` of ``cell``; refused above the budget."""
    from barymesh.params import DEFAULT_MAX_TRIANGLES

    budget = DEFAULT_MAX_TRIANGLES if budget is None else budget
    per = cell.predicted_triangles()
    total = per * copies[0] * copies[1]
    if total > budget:
        raise InputError(
            f"{label}: {copies[0]} x {copies[1]} copies of {per:,} triangles make {total:,} "
            f"triangles, above the budget of max_triangles={budget:,}; use fewer copies"
        )
    return total


def _cell_summary(cell_mesh: Any, stats: dict[str, Any], label: str) -> str:
    cell = cell_mesh.cell
    parts = f"{len(cell.elements)} element(s)"
    if cell.pixels is not None:
        parts += f" and {int(cell.pixels.mask.sum()):,} pixel(s)"
    n1, n2 = cell_mesh.copies
    whole = "cell" if (n1, n2) == (1, 1) else "array"
    title = f"{label}: unit cell {cell.name!r}, {parts}, {cell.mode} mode"
    if whole == "array":
        title += f", an array of {n1} x {n2} cells"
    lat = cell.lattice
    lines = [
        _summary(stats["cell"], title),
        f"  lattice {lat.kind}: a1 = ({lat.a1[0]:.6g}, {lat.a1[1]:.6g}) mm, "
        f"a2 = ({lat.a2[0]:.6g}, {lat.a2[1]:.6g}) mm",
        "  parts: "
        + ", ".join(f"{part['name']!r} {part['triangles']:,} triangles" for part in stats["parts"]),
    ]
    pairs, unmatched = stats["periodic_edge_pairs"], stats["unmatched_periodic_edges"]
    if unmatched:
        lines.append(f"  periodic: no, {unmatched:,} edge(s) on the {whole}'s sides lack a partner")
    elif pairs:
        lines.append(f"  periodic: yes, {pairs:,} edge pairs across the {whole}'s sides")
    else:
        lines.append(f"  periodic: no mesh edge on the {whole}'s sides")
    lines += [f"  note: {note}" for note in stats["notes"]]
    return "\n".join(lines)


def _write_mesh_file(
    built: _Built,
    out: str,
    unit: str | None,
    wavelength: float | None = None,
    msh_version: str | None = None,
) -> str:
    """Write a mesh file; a cell's .msh gets ``$Periodic`` when periodic. Returns a remark.

    With ``wavelength`` (mm) VTK files also carry each triangle's edge/wavelength;
    ``msh_version`` is the Gmsh format of a .msh."""
    from barymesh.io import export_unit, per_mm, write_mesh, write_periodic_msh

    cell_mesh = built.cell_mesh
    if cell_mesh is None or Path(out).suffix.lower() != ".msh":
        write_mesh(built.mesh, out, unit=unit, wavelength=wavelength, msh_version=msh_version)
        return ""
    pairs = cell_mesh.periodic_pairs
    if pairs.matched and len(pairs.edges):
        write_periodic_msh(cell_mesh, out, per_mm(export_unit(out, unit)), msh_version)
        return f" with $Periodic: {len(pairs.edges):,} edge pairs"
    write_mesh(built.mesh, out, unit=unit, msh_version=msh_version)
    why = "not periodic" if not pairs.matched else "no mesh edge on its sides"
    return f" without $Periodic ({why})"


def _check_outline_writer(out: str) -> None:
    import importlib

    kind, module = OUTLINE_EXTENSIONS[Path(out).suffix.lower()]
    try:
        importlib.import_module(module)
    except ImportError:
        raise InputError(
            f"cannot write {out}: {kind} outlines need {module}: pip install 'barymesh[cell]'"
        ) from None


def _outline_polygons(built: _Built, args: argparse.Namespace, first: str) -> list[Any]:
    """The metal outline of what was built (a structure alone keeps its coordinates)."""
    from barymesh.cell import Element, Lattice, UnitCell, outline_polygons
    from barymesh.cell.outline import DEFAULT_CHORD_ERROR

    cell = built.cell
    if cell is None:
        params, xy = built.params, built.mesh.points[:, :2]
        size = xy.max(axis=0) - xy.min(axis=0)
        cell = UnitCell(
            Lattice.rectangular(*size),
            (Element(params, name=built.name),),
            mode=params.mode,
            tolerance=params.tolerance,
            name=built.name,
        )
    error = DEFAULT_CHORD_ERROR if args.chord_error is None else args.chord_error
    with progress(f"outlining for {first}"):
        try:
            return outline_polygons(cell, error, built.copies)
        except ValueError as exc:
            raise InputError(f"{built.label}: cannot write {first}: {exc}") from None


def _write_outline(polygons: list[Any], out: str, name: str) -> None:
    from barymesh.cell import write_outline_dxf, write_outline_gds

    if Path(out).suffix.lower() == ".dxf":
        write_outline_dxf(polygons, out)
    else:
        gds_name = re.sub(r"[^A-Za-z0-9_$-]", "_", name)[:32] or "CELL"
        write_outline_gds(polygons, out, cell_name=gds_name)


def _describe_outline(out: str, polygons: list[Any], chord_error: float | None) -> str:
    from barymesh.cell.outline import DEFAULT_CHORD_ERROR

    kind = OUTLINE_EXTENSIONS[Path(out).suffix.lower()][0]
    holes = sum(len(p.holes) for p in polygons)
    area = sum(p.area for p in polygons)
    error = DEFAULT_CHORD_ERROR if chord_error is None else chord_error
    return (
        f"{out} ({kind} outline, mm: {len(polygons)} polygon(s), {holes} hole(s), "
        f"metal area {area:.6g} mm^2, chord error {error:g} mm)"
    )


def _resolve(args: argparse.Namespace) -> Any:
    """The parameters of ``args``; every error names its source (preset, file, --set)."""
    from barymesh.presets import resolve_params

    try:
        return resolve_params(args.preset, args.params, args.sets)
    except (ArithmeticError, RecursionError) as exc:  # ValueError already names the source
        given = [f"preset {args.preset!r}" if args.preset else "", args.params or ""]
        given += [f"--set {text!r}" for text in args.sets]
        sources = ", ".join(filter(None, given)) or "default parameters"
        why = "nested too deeply" if isinstance(exc, RecursionError) else str(exc)
        raise InputError(f"{sources}: {why}") from None


def _screenshot(mesh: Any, path: str, size: tuple[int, int], transparent: bool) -> None:
    try:
        from barymesh.app.view.scaled_shot import render_screenshot
    except ImportError as exc:
        raise InputError(
            f"screenshots need the desktop extras (pyvista): pip install 'barymesh[app]' ({exc})"
        ) from None
    from barymesh.io import atomic_path

    with progress(f"rendering {path}"), atomic_path(path) as tmp:
        render_screenshot(mesh, str(tmp), window_size=size, transparent=transparent)
        if not tmp.exists() or tmp.stat().st_size == 0:
            raise InputError(f"cannot write {path}: the renderer produced no image")


def _cmd_info(args: argparse.Namespace) -> int:
    from barymesh.io import read_mesh

    cell_given = args.cell is not None or args.cell_preset is not None
    if args.file is not None and args.file.lower().endswith(".cell.json") and not cell_given:
        args.cell, args.file, cell_given = args.file, None, True
    if args.file is None and not cell_given:
        raise UsageError(
            "info: the following arguments are required: FILE "
            "(or --cell FILE.cell.json, --cell-preset NAME)"
        )
    if args.file is not None and cell_given:
        raise UsageError(f"info: give a mesh FILE or a cell, not both ({args.file})")
    if args.array is not None and not cell_given:
        raise UsageError("info: --array needs a cell (--cell or --cell-preset)")
    if args.unit is not None and cell_given:
        raise UsageError("info: --unit is for mesh files; a cell is in mm")
    check_cell_usage(args, "info")
    _check_json_targets(args, "info")
    from barymesh.quality import wavelength_mm

    try:
        wavelength = wavelength_mm(args.frequency)
    except ValueError:
        raise UsageError(
            f"info: --frequency {args.frequency:g} is invalid; expected a positive number of Hz"
        ) from None
    for target in (args.stats_json, args.quality_json):
        if target is not None and target != "-":
            check_folder(target)
    say = sys.stderr if _to_stdout(args) else sys.stdout
    if cell_given:
        built = _build(args)
        mesh, stats, summary = built.mesh, built.stats, built.summary
    else:
        with progress(f"reading {args.file}"):
            mesh = read_mesh(args.file, unit=args.unit)
            stats = mesh.stats()
        import numpy as np

        flat = np.flatnonzero(~np.isfinite(mesh.aspect_ratios))
        degenerate = int(flat[0]) if len(flat) else None
        summary = _summary(stats, f"{args.file}: imported mesh", degenerate)
    print(summary, file=say)
    report = _quality(mesh, wavelength)
    print(_quality_text(report), file=say)
    _emit_stats(stats, args.stats_json)
    _emit_stats(report, args.quality_json)
    return 0


def _cmd_presets(args: argparse.Namespace) -> int:
    from barymesh.cell import cell_preset_names, load_cell_preset
    from barymesh.presets import preset_descriptions

    described = preset_descriptions()
    for name in cell_preset_names():
        described[name] = f"cell: {load_cell_preset(name).description}"
    width = max(map(len, described), default=0)
    for name, description in described.items():
        print(f"{name:<{width}}  {description}")
    return 0


def _cmd_sweep(args: argparse.Namespace) -> int:
    for option in ("cell", "cell_preset", "array", "period"):
        if getattr(args, f"refused_{option}") is not None:
            raise UsageError(
                f"sweep: --{option.replace('_', '-')} is not supported: a sweep varies one "
                "parameter of one structure, and a cell's elements each have their own; "
                "sweep the structure (--preset, --params, --set)"
            )
    check_preset(args, "sweep")
    from barymesh.teach.sweep import check_sweep_size

    if args.frames < 2:
        raise UsageError(f"sweep: --frames {args.frames} is invalid; expected 2 or more")
    if Path(args.output).suffix.lower() not in (".gif", ".mp4"):
        raise UsageError(f"sweep: -o {args.output}: expected a .gif or .mp4 file")
    if not 0 < args.fps <= 100:
        raise UsageError(f"sweep: --fps {args.fps:g} is invalid; expected more than 0, up to 100")
    check_render_size("sweep", *args.window_size)
    try:
        check_sweep_size(args.frames, tuple(args.window_size))
    except ValueError as exc:
        raise UsageError(f"sweep: {exc}") from None
    check_folder(args.output)
    base = _resolve(args)
    try:
        from barymesh.app.teach.sweep import render_sweep
    except ImportError as exc:
        raise InputError(
            f"sweeps need the desktop extras (pyvista): pip install 'barymesh[app]' ({exc})"
        ) from None
    with progress(f"rendering {args.frames} frames of {args.param}"):
        written = render_sweep(
            base,
            args.param,
            args.start,
            args.stop,
            args.frames,
            args.output,
            window_size=tuple(args.window_size),
            fps=args.fps,
        )
    print(f"wrote {args.output} ({written} frames, {args.window_size[0]}x{args.window_size[1]} px)")
    return 0


#: Subcommand -> its function. A new subcommand adds its parser in ``build_parser`` (or a
#: ``register(verbs)`` call there) and one entry here.
VERBS = {"mesh": _cmd_mesh, "info": _cmd_info, "presets": _cmd_presets, "sweep": _cmd_sweep}
VERBS["solve"] = cli_solve.run
VERBS["study"] = cli_study.run
VERBS["library"] = cli_library.run
VERBS["reflectarray"] = cli_reflectarray.run


# -- entry point -----------------------------------------------------------


def _open_window(argv: list[str]) -> int:
    try:
        from barymesh.app.window_main import main as window_main
    except ModuleNotFoundError as exc:
        if exc.name not in ("barymesh.app.window", "barymesh.app.window_main", "barymesh.app"):
            raise InputError(
                f"the desktop window needs the app extras: pip install 'barymesh[app]' "
                f"(missing module {exc.name})"
            ) from None
        print(build_parser().format_help())
        print("The desktop window is not available yet; use the commands above.")
        return 0
    parser = build_window_parser()  # bad options: one line and exit 2, before any window

    def one_line(message: str) -> NoReturn:
        raise UsageError(f"{message} (see barymesh --help)")

    parser.error = one_line  # type: ignore[method-assign]  # this parser's errors: one line
    try:
        parser.parse_args(argv)
    except SystemExit as exc:  # --help
        return int(exc.code or 0)
    return int(window_main(argv) or 0)


def _fail(message: str, code: int) -> int:
    message = " ".join(str(message).split())  # one line
    message = re.sub(r"\d{40,}", lambda m: f"{m[0][:8]}…({len(m[0]):,} digits)", message)
    print(f"{PROG}: error: {message}", file=sys.stderr)
    return code


def main(argv: list[str] | None = None) -> int:
    """Run the command line; returns the exit code (0, 1 input, 2 usage)."""
    argv = list(sys.argv[1:] if argv is None else argv)
    try:
        own = ("-h", "--help", "--version", "--print-completion")
        if not argv or (argv[0].startswith("-") and argv[0].split("=")[0] not in own):
            return _open_window(argv)
        parser = build_parser()
        try:
            args = parser.parse_args(argv)
        except SystemExit as exc:  # --help and --version
            return int(exc.code or 0)
        if args.verb is None:
            parser.print_help()
            return 0
        return VERBS[args.verb](args)
    except UsageError as exc:
        return _fail(str(exc), 2)
    except BrokenPipeError:  # e.g. `barymesh presets | head -1`: stop quietly
        devnull = os.open(os.devnull, os.O_WRONLY)
        os.dup2(devnull, sys.stdout.fileno())
        return 1
    except (InputError, ValueError, TypeError, OSError, ArithmeticError) as exc:
        return _fail(str(exc) or type(exc).__name__, 1)
    except RecursionError:
        return _fail("the input is nested too deeply", 1)
    except KeyboardInterrupt:
        return _fail("interrupted", 130)
    except Exception as exc:  # noqa: BLE001 - the promise is: never a traceback
        return _fail(f"unexpected {type(exc).__name__}: {exc}", 1)


if __name__ == "__main__":
    sys.exit(main())
