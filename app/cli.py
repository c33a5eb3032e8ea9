"""The ``barymesh`` command line.

::

    barymesh                       open the desktop window (same options as below)
    barymesh mesh [options]        build a mesh, write files, render a screenshot
    barymesh info FILE             import a mesh file and print its statistics
    barymesh presets               list the presets

Exit codes: 0 success, 1 bad input (parameter values, files), 2 bad usage.
Errors are one line on stderr, never a traceback.
"""

from __future__ import annotations

import argparse
import contextlib
import json
import os
import sys
import threading
import time
from collections.abc import Iterator
from pathlib import Path
from typing import Any, NoReturn, TextIO

from app import cli_solve

PROG = "barymesh"
#: Options that belong to the desktop window when given without a verb.
WINDOW_OPTIONS = ("--preset", "--params", "--set", "--screenshot", "--quit")
#: Work longer than this (seconds) shows a spinner when stderr is a terminal.
PROGRESS_DELAY = 1.0


class UsageError(Exception):
    """Bad command-line usage (exit code 2)."""


class InputError(Exception):
    """Bad input: parameter values, files (exit code 1)."""


# -- argument parsing ------------------------------------------------------


class _Parser(argparse.ArgumentParser):
    """argparse with usage errors raised as :class:`UsageError`, not printed mid-way."""

    def error(self, message: str) -> NoReturn:
        raise UsageError(f"{self.prog}: {message}")


def _window_size(text: str) -> int:
    try:
        value = int(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f"{text!r} is not a whole number of pixels") from None
    if not 16 <= value <= 16384:
        raise argparse.ArgumentTypeError(f"{value} pixels is outside 16..16384")
    return value


def _add_params_options(p: argparse.ArgumentParser) -> None:
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


def _add_stats_option(p: argparse.ArgumentParser) -> None:
    p.add_argument(
        "--stats-json",
        metavar="PATH|-",
        help="write the statistics as JSON to PATH, or to stdout with '-' (then nothing "
        "else goes to stdout)",
    )


def build_parser() -> argparse.ArgumentParser:
    """The parser of the subcommands (``mesh``, ``info``, ``sweep``, ``presets``)."""
    from core.io import EXPORT_EXTENSIONS, IMPORT_EXTENSIONS, UNITS

    parser = _Parser(
        prog=PROG,
        description="RWG-ready triangle meshes of metasurface unit cells. "
        "Without a command, opens the desktop window "
        "(options: --preset, --params, --set, --screenshot, --quit).",
    )
    from core import __version__

    parser.add_argument("--version", action="version", version=f"{PROG} {__version__}")
    verbs = parser.add_subparsers(dest="verb", metavar="COMMAND", parser_class=_Parser)

    mesh = verbs.add_parser(
        "mesh",
        help="build a mesh; write files, a screenshot, statistics",
        description="Build a mesh from a preset, a parameter file and/or single parameters, "
        "write each -o file (format from its extension), optionally render a screenshot "
        "without a display, and print a short summary.",
    )
    _add_params_options(mesh)
    out = mesh.add_argument_group("output")
    out.add_argument(
        "-o",
        "--output",
        dest="outputs",
        metavar="OUT",
        action="append",
        default=[],
        help=f"write the mesh; the extension picks the format: {', '.join(EXPORT_EXTENSIONS)} "
        "(repeatable)",
    )
    out.add_argument(
        "--unit",
        choices=UNITS,
        help="length unit of the written files (default mm; .mat: m)",
    )
    out.add_argument("--screenshot", metavar="PNG", help="render the mesh off-screen to PNG")
    out.add_argument(
        "--window-size",
        nargs=2,
        type=_window_size,
        metavar=("W", "H"),
        default=(1024, 768),
        help="screenshot size in pixels (default 1024 768)",
    )
    out.add_argument(
        "--transparent", action="store_true", help="screenshot with a transparent background"
    )
    _add_stats_option(out)

    info = verbs.add_parser(
        "info",
        help="import a mesh file and print its statistics",
        description="Import a mesh file and print the same statistics as `barymesh mesh`. "
        f"Reads {', '.join(IMPORT_EXTENSIONS)}; only triangles count, other cells are "
        "reported as ignored.",
    )
    info.add_argument("file", metavar="FILE", help="the mesh file")
    info.add_argument(
        "--unit",
        choices=UNITS,
        help="length unit of the file's coordinates (default mm; .mat: m)",
    )
    _add_stats_option(info)

    from core.sweep import SWEEPABLE

    sweep = verbs.add_parser(
        "sweep",
        help="animate a sweep of one parameter to GIF or MP4",
        description="Mesh and render K frames with one parameter going from A to B "
        "(integers rounded), without a display, and save them as an animation.",
    )
    _add_params_options(sweep)
    anim = sweep.add_argument_group("sweep")
    anim.add_argument("--param", required=True, choices=SWEEPABLE, help="the parameter to vary")
    anim.add_argument("--from", dest="start", required=True, type=float, metavar="A")
    anim.add_argument("--to", dest="stop", required=True, type=float, metavar="B")
    anim.add_argument("--frames", required=True, type=int, metavar="K", help="frames, >= 2")
    anim.add_argument("--fps", type=float, default=4.0, help="frames per second (default 4)")
    anim.add_argument(
        "-o", "--output", required=True, metavar="OUT", help="the animation: .gif or .mp4"
    )
    anim.add_argument(
        "--window-size",
        nargs=2,
        type=_window_size,
        metavar=("W", "H"),
        default=(800, 600),
        help="frame size in pixels (default 800 600)",
    )

    cli_solve.add_parser(verbs)
    verbs.add_parser(
        "presets",
        help="list the presets, one per line",
        description="List the presets with a one-line description each.",
    )
    return parser


# -- progress --------------------------------------------------------------


@contextlib.contextmanager
def progress(what: str, stream: TextIO | None = None) -> Iterator[None]:
    """Show ``what`` with a spinner and the elapsed time on ``stream`` (stderr).

    Only when the stream is a terminal and the work takes longer than
    ``PROGRESS_DELAY`` seconds; the line is cleared when the work ends.
    """
    stream = sys.stderr if stream is None else stream
    try:
        tty = stream.isatty()
    except (AttributeError, ValueError):
        tty = False
    if not tty:
        yield
        return
    done = threading.Event()
    shown = threading.Event()
    start = time.monotonic()

    def spin() -> None:
        if done.wait(PROGRESS_DELAY):
            return
        frames = "|/-\\"
        k = 0
        while not done.is_set():
            shown.set()
            stream.write(f"\r{frames[k % 4]} {what} … {time.monotonic() - start:5.1f} s")
            stream.flush()
            k += 1
            done.wait(0.1)

    thread = threading.Thread(target=spin, daemon=True)
    thread.start()
    try:
        yield
    finally:
        done.set()
        thread.join()
        if shown.is_set():
            stream.write("\r\033[K")
            stream.flush()


# -- output ----------------------------------------------------------------


def _summary(stats: dict[str, Any], title: str) -> str:
    lines = [
        f"{title}",
        f"  {stats['triangles']:,} triangles, {stats['vertices']:,} vertices, "
        f"{stats['patches']:,} patches, {stats['regions']} region(s)",
        f"  {stats['edges']:,} edges: {stats['interior_edges']:,} interior (RWG unknowns), "
        f"{stats['boundary_edges']:,} boundary, {stats['junction_edges']:,} junction",
        f"  edge length {stats['min_edge']:.6g} .. {stats['max_edge']:.6g} mm, "
        f"min angle {stats['min_angle_deg']:.3g} deg, "
        f"max aspect ratio {stats['max_aspect_ratio']:.4g}",
        f"  area {stats['area']:.6g} mm^2, V - E + F = {stats['euler_characteristic']}",
    ]
    if stats.get("overlap_ratio") is not None:
        lines.append(f"  overlap ratio {stats['overlap_ratio']:.4g} (paper mode)")
    if stats.get("ignored_cells"):
        cells = ", ".join(f"{n:,} {kind}" for kind, n in sorted(stats["ignored_cells"].items()))
        lines.append(f"  ignored non-triangle cells: {cells}")
    return "\n".join(lines)


def _emit_stats(stats: dict[str, Any], target: str | None) -> None:
    if target is None:
        return
    text = json.dumps(stats, indent=2) + "\n"
    if target == "-":
        sys.stdout.write(text)
        return
    from core.io import atomic_write_text

    atomic_write_text(Path(target), text)


# -- verbs -----------------------------------------------------------------


def _cmd_mesh(args: argparse.Namespace) -> int:
    from core import build_mesh
    from core.io import describe_export, export_format
    from core.presets import preset_names, resolve_params

    if args.preset is not None and args.preset not in preset_names():
        raise UsageError(
            f"mesh: unknown preset {args.preset!r}; expected one of {', '.join(preset_names())}"
        )
    for out in args.outputs:
        try:
            export_format(out)
        except ValueError as exc:
            raise UsageError(f"mesh: -o {exc}") from None
    if args.transparent and not args.screenshot:
        raise UsageError("mesh: --transparent needs --screenshot")
    for text in args.sets:
        if "=" not in text or not text.partition("=")[0].strip():
            raise UsageError(f"mesh: --set {text!r} is invalid; expected name=value")
    targets = [*args.outputs, args.screenshot, None if args.stats_json == "-" else args.stats_json]
    for target in filter(None, targets):
        _check_folder(target)  # before minutes of meshing, not after
    stats_to_stdout = args.stats_json == "-"
    say = sys.stderr if stats_to_stdout else sys.stdout

    params = resolve_params(args.preset, args.params, args.sets)
    with progress(f"building {params.predicted_triangles():,} triangles"):
        mesh = build_mesh(params)
        stats = mesh.stats()
    title = f"{args.preset or 'mesh'}: {params.structure}, {params.mode} mode"
    print(_summary(stats, title), file=say)

    from core.io import write_mesh

    for out in args.outputs:
        with progress(f"writing {out}"):
            written = write_mesh(mesh, out, unit=args.unit)
        print(f"wrote {describe_export(written, args.unit)}", file=say)
    if args.screenshot:
        _screenshot(mesh, args.screenshot, tuple(args.window_size), args.transparent)
        print(f"wrote {args.screenshot} ({args.window_size[0]}x{args.window_size[1]} px)", file=say)
    _emit_stats(stats, args.stats_json)
    return 0


def _check_folder(target: str) -> None:
    folder = Path(target).parent
    if not folder.is_dir():
        what = "is not a folder" if folder.exists() else "does not exist"
        raise InputError(f"cannot write {target}: the folder {folder} {what}")


def _screenshot(mesh: Any, path: str, size: tuple[int, int], transparent: bool) -> None:
    try:
        from app.scene import render_screenshot
    except ImportError as exc:
        raise InputError(
            f"screenshots need the desktop extras (pyvista): pip install 'barymesh[app]' ({exc})"
        ) from None
    from core.io import atomic_path

    with progress(f"rendering {path}"), atomic_path(path) as tmp:
        render_screenshot(mesh, str(tmp), window_size=size, transparent=transparent)
        if not tmp.exists() or tmp.stat().st_size == 0:
            raise InputError(f"cannot write {path}: the renderer produced no image")


def _cmd_info(args: argparse.Namespace) -> int:
    from core.io import read_mesh

    stats_to_stdout = args.stats_json == "-"
    say = sys.stderr if stats_to_stdout else sys.stdout
    with progress(f"reading {args.file}"):
        mesh = read_mesh(args.file, unit=args.unit)
        stats = mesh.stats()
    print(_summary(stats, f"{args.file}: imported mesh"), file=say)
    _emit_stats(stats, args.stats_json)
    return 0


def _cmd_presets(args: argparse.Namespace) -> int:
    from core.presets import preset_descriptions

    described = preset_descriptions()
    width = max(map(len, described), default=0)
    for name, description in described.items():
        print(f"{name:<{width}}  {description}")
    return 0


def _cmd_sweep(args: argparse.Namespace) -> int:
    from core.presets import preset_names, resolve_params

    if args.preset is not None and args.preset not in preset_names():
        raise UsageError(
            f"sweep: unknown preset {args.preset!r}; expected one of {', '.join(preset_names())}"
        )
    if args.frames < 2:
        raise UsageError(f"sweep: --frames {args.frames} is invalid; expected 2 or more")
    if Path(args.output).suffix.lower() not in (".gif", ".mp4"):
        raise UsageError(f"sweep: -o {args.output}: expected a .gif or .mp4 file")
    if not args.fps > 0:
        raise UsageError(f"sweep: --fps {args.fps} is invalid; expected a positive number")
    _check_folder(args.output)
    base = resolve_params(args.preset, args.params, args.sets)
    try:
        from app.sweep import render_sweep
    except ImportError as exc:
        raise InputError(
            f"sweeps need the desktop extras (pyvista): pip install 'barymesh[app]' ({exc})"
        ) from None
    with progress(f"rendering {args.frames} frames of {args.param}"):
        written = render_sweep(
            base, args.param, args.start, args.stop, args.frames, args.output,
            window_size=tuple(args.window_size), fps=args.fps,
        )  # fmt: skip
    print(f"wrote {args.output} ({written} frames, {args.window_size[0]}x{args.window_size[1]} px)")
    return 0


VERBS = {"mesh": _cmd_mesh, "info": _cmd_info, "presets": _cmd_presets, "sweep": _cmd_sweep}
VERBS["solve"] = cli_solve.run


# -- entry point -----------------------------------------------------------


def _open_window(argv: list[str]) -> int:
    try:
        from app.window import main as window_main
    except ModuleNotFoundError as exc:
        if exc.name not in ("app.window", "app"):
            raise InputError(
                f"the desktop window needs the app extras: pip install 'barymesh[app]' "
                f"(missing module {exc.name})"
            ) from None
        print(build_parser().format_help())
        print("The desktop window is not available yet; use the commands above.")
        return 0
    return int(window_main(argv) or 0)


def _fail(message: str, code: int) -> int:
    message = " ".join(str(message).split())  # one line
    print(f"{PROG}: error: {message}", file=sys.stderr)
    return code


def main(argv: list[str] | None = None) -> int:
    """Run the command line; returns the exit code (0, 1 input, 2 usage)."""
    argv = list(sys.argv[1:] if argv is None else argv)
    try:
        if not argv or (argv[0].startswith("-") and argv[0] not in ("-h", "--help", "--version")):
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
    except (InputError, ValueError, TypeError, OSError) as exc:
        return _fail(str(exc) or type(exc).__name__, 1)
    except KeyboardInterrupt:
        return _fail("interrupted", 130)
    except Exception as exc:  # noqa: BLE001 - the promise is: never a traceback
        return _fail(f"unexpected {type(exc).__name__}: {exc}", 1)


if __name__ == "__main__":
    sys.exit(main())
