"""``barymesh solve``: the MoM solver (barymesh.mom) from the command line.

::

    barymesh solve --preset srr-openmodes --freq 6.19GHz --pol y -o current.vtu
    barymesh solve --preset srr-openmodes --freq 3GHz:12GHz:91 --pol y -o sweep.csv \\
        --plot sweep.png
    barymesh solve --mesh strip.msh --freq 150MHz --feed 0,-10:0,10
    barymesh solve --preset makarov-platefine --freq 300MHz --screenshot current.png
    barymesh solve --cell-preset coding-16x16 --periodic --freq 5GHz:40GHz:651 \\
        --theta 30 --phi 0 --pol te -o rt.s4p -o orders.csv --plot rt.png
    barymesh solve --preset paper-fig11-8mm --set subdivisions=8 --period 10 --periodic \\
        --freq 20GHz

Registered in :mod:`barymesh.app.cli` (``add_parser`` builds the subcommand, ``run``
executes it); the options and checks it shares with :mod:`barymesh.app.cli` come from
:mod:`barymesh.app.cli_options`. Errors are raised as the command line's exceptions (one
line, exit 1 or 2, never a traceback).
"""

from __future__ import annotations

import argparse
import re
from pathlib import Path
from typing import Any

from barymesh import frequencies
from barymesh.app.cli_options import (
    add_cell_options,
    add_mesh_grade_option,
    add_params_options,
    check_folder,
    check_render_size,
    solver_grade_structure,
    window_size,
)
from barymesh.app.cli_periodic import (
    PeriodicUsageError,
    cell_mesh,
    check_periodic_usage,
    parse_impedance,
    run_periodic,
)
from barymesh.app.cli_progress import progress
from barymesh.io import cross_sections

#: Frequency units understood by --freq.
FREQUENCY_UNITS = frequencies.FREQUENCY_UNITS
#: Named directions for --dir and --pol.
AXES = {
    "x": (1.0, 0.0, 0.0),
    "y": (0.0, 1.0, 0.0),
    "z": (0.0, 0.0, 1.0),
}
SWEEP_OUTPUTS = (".csv", ".npz")
SINGLE_OUTPUTS = (".csv", ".npz", ".vtu")
#: Columns of the sweep CSV, in order (:data:`barymesh.io.cross_sections.CSV_COLUMNS`).
CSV_COLUMNS = cross_sections.CSV_COLUMNS


class SolveUsageError(ValueError):
    """Bad usage of ``barymesh solve``; :func:`run` reports it through the parser (exit 2)."""


def add_parser(subparsers: Any) -> argparse.ArgumentParser:
    """Add the ``solve`` subcommand to ``subparsers`` (of :func:`barymesh.app.cli.build_parser`)."""
    p = subparsers.add_parser(
        "solve",
        help="solve for the currents (RWG Method of Moments) at one frequency or a sweep",
        description="Build a mesh (or read one with --mesh) and solve the EFIE for a perfect "
        "conductor in free space: a plane wave (--dir, --pol) or a delta-gap voltage source "
        "(--feed). One --freq prints the cross-sections; a range sweeps them and finds the "
        "resonances. With --periodic, solve the infinite array of a unit cell (--cell, "
        "--cell-preset, or a structure with --period): one --freq prints R and T of every "
        "propagating Floquet order; a range sweeps them (interpolating) and finds the "
        "grating-lobe onsets and the resonances. Time convention exp(jwt); mesh lengths in mm.",
    )
    add_params_options(p)
    add_cell_options(p)
    p.add_argument("--mesh", metavar="FILE", help="solve a mesh file instead of building one")
    add_mesh_grade_option(p)
    from barymesh.io import UNITS

    p.add_argument(
        "--unit", choices=UNITS, help="length unit of --mesh's coordinates (default mm; .mat: m)"
    )
    s = p.add_argument_group("solve")
    s.add_argument(
        "--freq",
        required=True,
        metavar="F | A:B:K",
        help="a frequency (6.19GHz, 300MHz, 1e9) or a sweep of K frequencies from A to B "
        "(3GHz:12GHz:91)",
    )
    s.add_argument(
        "--dir",
        metavar="AXIS | X,Y,Z",
        help="direction of travel of the plane wave: -z (default), +x, ... or a vector",
    )
    s.add_argument(
        "--pol",
        metavar="AXIS | X,Y,Z | te | tm",
        help="polarisation of E: x (default), y, ... or a vector, perpendicular to --dir; "
        "with --periodic also te (default: E across the plane of incidence; y at normal "
        "incidence) or tm",
    )
    s.add_argument("--amplitude", type=float, default=1.0, help="|E| in V/m (default 1)")
    s.add_argument(
        "--feed",
        metavar="X0,Y0:X1,Y1",
        help="a delta-gap voltage source on the mesh edges along this segment (mm) instead "
        "of a plane wave; prints the input impedance",
    )
    s.add_argument("--volts", type=float, default=1.0, help="feed voltage (default 1 V)")
    s.add_argument(
        "--sheet-impedance",
        metavar="Z",
        help="surface impedance of the metal in ohm per square, complex allowed (377, "
        "10-5j): a resistive or lossy sheet instead of a perfect conductor",
    )
    s.add_argument("--order", type=int, default=None, help="near quadrature degree (1-8)")
    s.add_argument(
        "--max-memory",
        metavar="SIZE",
        help="refuse problems needing more memory than this (e.g. 2GB, 500MB)",
    )
    per = p.add_argument_group("infinite array (--periodic)")
    per.add_argument(
        "--periodic",
        action="store_true",
        help="solve the infinite array of the unit cell (--cell, --cell-preset, or the "
        "structure with --period): reflection and transmission of its Floquet orders",
    )
    per.add_argument(
        "--theta",
        type=float,
        default=None,
        metavar="DEG",
        help="angle of incidence from the normal, 0 (default) to below 90 degrees; the wave "
        "comes from above",
    )
    per.add_argument(
        "--phi", type=float, default=None, metavar="DEG", help="azimuth of incidence (degrees)"
    )
    per.add_argument(
        "--stack",
        metavar="LAYERS | FILE.json",
        help="dielectric layers around the sheet, top first, separated by ';': a thickness "
        "with its unit and eps=, tand=, mu= (e.g. '1.575mm eps=2.2 tand=0.0009; ground'); "
        "'sheet' marks where the sheet lies (default: on top), 'ground' puts a ground "
        "plane under the last layer; or a JSON file of barymesh.mom.Stack.to_dict. R is "
        "then referred to the stack's top face, T to its bottom face",
    )
    per.add_argument(
        "--no-interpolate",
        action="store_true",
        help="solve at every frequency of the sweep instead of fitting the curve (AAA) "
        "through a few solved ones",
    )
    per.add_argument(
        "--tolerance",
        type=float,
        default=None,
        metavar="TOL",
        help="target error of the interpolating sweep's R and T (default 1e-3)",
    )
    per.add_argument(
        "--circuit",
        action="store_true",
        help="with a sweep: fit the sheet's equivalent circuit (a series or parallel LC "
        "whose reflection follows the cell's) and print its L, C, resonance and where it "
        "stops following the cell",
    )
    per.add_argument(
        "--current-at",
        metavar="F",
        help="frequency of the current a sweep writes to -o FILE.vtu (e.g. 18.5GHz)",
    )
    out = p.add_argument_group("output")
    out.add_argument(
        "-o",
        "--output",
        dest="outputs",
        metavar="OUT",
        action="append",
        default=[],
        help="results: .csv (cross-sections per frequency), .npz (arrays), .vtu (one "
        "frequency: J_abs, J_real, J_imag per triangle for ParaView); with --periodic: "
        ".s4p (the (0, 0) order as a Touchstone 4-port, TE/TM above and below; .s2p, TE/TM "
        "above, with a grounded --stack), .csv (R "
        "and T of every propagating order per frequency), .vtu (the cell's current) "
        "(repeatable)",
    )
    out.add_argument(
        "--plot",
        metavar="PNG",
        help="plot the sweep's cross-sections (with --periodic: the magnitudes of R and T "
        "in dB, the grating-lobe onsets marked) to PNG",
    )
    out.add_argument(
        "--screenshot",
        metavar="PNG",
        help="render |J| on the mesh off-screen to PNG (one frequency), as the window's "
        "Surface current layer shows it",
    )
    out.add_argument(
        "--window-size",
        nargs=2,
        type=window_size,
        metavar=("W", "H"),
        default=(1024, 768),
        help="screenshot size in pixels (default 1024 768)",
    )
    p.dash_value_options = ("--dir", "--pol")  # `--dir -z`, `--pol -1,0,0`
    # usage errors go through this parser, which raises the running cli's UsageError
    p.set_defaults(solve_parser=p)
    return p


# -- parsing ---------------------------------------------------------------------------


def parse_frequency(text: str) -> float:
    """``'6.19GHz'`` -> 6.19e9 (Hz); a bare number is in Hz (:mod:`barymesh.frequencies`).

    >>> parse_frequency("6.19GHz"), parse_frequency("300 MHz"), parse_frequency("1e9")
    (6190000000.0, 300000000.0, 1000000000.0)
    """
    try:
        return frequencies.parse_frequency(text, "--freq")
    except ValueError as exc:
        raise SolveUsageError(str(exc)) from None


def parse_frequencies(text: str) -> list[float]:
    """One frequency, or ``A:B:K`` -> K frequencies from A to B inclusive.

    >>> parse_frequencies("3GHz:12GHz:4")
    [3000000000.0, 6000000000.0, 9000000000.0, 12000000000.0]
    """
    try:
        return frequencies.parse_frequencies(text, "--freq")
    except ValueError as exc:
        raise SolveUsageError(str(exc)) from None


def parse_vector(text: str, option: str) -> tuple[float, float, float]:
    """``'-z'`` -> (0, 0, -1); ``'0,1,0'`` -> (0, 1, 0).

    >>> parse_vector("-z", "--dir"), parse_vector("1,1,0", "--pol")
    ((0.0, 0.0, -1.0), (1.0, 1.0, 0.0))
    """
    t = text.strip().lower()
    sign = -1.0 if t.startswith("-") else 1.0
    name = t.lstrip("+-")
    if name in AXES:
        return tuple(sign * c + 0.0 for c in AXES[name])  # type: ignore[return-value]
    try:
        values = tuple(float(v) for v in t.split(","))
    except ValueError:
        values = ()
    if len(values) != 3:
        raise SolveUsageError(
            f"{option} {text!r} is invalid; expected an axis (x, -z, ...) or X,Y,Z"
        )
    return values


def parse_feed(text: str) -> tuple[tuple[float, ...], tuple[float, ...]]:
    """``'0,-10:0,10'`` -> ((0, -10), (0, 10)) in mm."""
    try:
        a, b = text.split(":")
        start = tuple(float(v) for v in a.split(","))
        end = tuple(float(v) for v in b.split(","))
    except ValueError:
        start = end = ()
    if len(start) not in (2, 3) or len(end) != len(start):
        raise SolveUsageError(
            f"--feed {text!r} is invalid; expected X0,Y0:X1,Y1 (mm), e.g. 0,-10:0,10"
        )
    return start, end


def parse_memory(text: str | None) -> float | None:
    """``'2GB'`` -> 2 GiB in bytes; None stays None.

    >>> parse_memory("500MB")
    524288000.0
    """
    if text is None:
        return None
    m = re.fullmatch(r"\s*([0-9.]+)\s*([kKmMgGtT]?)i?[bB]?\s*", text)
    if not m:
        raise SolveUsageError(f"--max-memory {text!r} is invalid; expected e.g. 2GB or 500MB")
    scale = {"": 1, "k": 2**10, "m": 2**20, "g": 2**30, "t": 2**40}[m.group(2).lower()]
    return float(m.group(1)) * scale


# -- running ---------------------------------------------------------------------------


def run(args: argparse.Namespace) -> int:
    """Execute ``barymesh solve``; returns the exit code.

    Usage errors are raised through the subcommand's parser (the command
    line's ``UsageError``, exit 2); bad input as ``ValueError`` (exit 1).
    """
    try:
        return _run(args)
    except (SolveUsageError, PeriodicUsageError) as exc:
        args.solve_parser.error(str(exc))
        raise  # error() raises; this line is never reached


def _run(args: argparse.Namespace) -> int:
    freqs = parse_frequencies(args.freq)
    is_sweep = len(freqs) > 1
    check_periodic_usage(args, len(freqs))
    zs = parse_impedance(args.sheet_impedance)
    if args.periodic:
        return _run_periodic(args, freqs, zs)
    allowed = SWEEP_OUTPUTS if is_sweep else SINGLE_OUTPUTS
    for out in args.outputs:
        if Path(out).suffix.lower() not in allowed:
            what = "a sweep" if is_sweep else "one frequency"
            hint = (
                " (a .vtu holds one frequency's currents)" if out.lower().endswith(".vtu") else ""
            )
            raise SolveUsageError(f"-o {out}: for {what} expected {', '.join(allowed)}{hint}")
    if args.plot and not is_sweep:
        raise SolveUsageError("--plot needs a sweep: --freq A:B:K")
    if args.plot and Path(args.plot).suffix.lower() != ".png":
        raise SolveUsageError(f"--plot {args.plot}: expected a .png file")
    if args.screenshot and is_sweep:
        raise SolveUsageError("--screenshot shows one frequency's current: --freq F")
    if args.screenshot and Path(args.screenshot).suffix.lower() != ".png":
        raise SolveUsageError(f"--screenshot {args.screenshot}: expected a .png file")
    if args.screenshot:
        check_render_size("solve", *args.window_size)
    if args.mesh and (args.preset or args.params or args.sets):
        raise SolveUsageError("--mesh cannot be combined with --preset, --params or --set")
    if args.mesh and (args.cell or args.cell_preset or args.array):
        raise SolveUsageError("--mesh cannot be combined with --cell, --cell-preset or --array")
    for target in [*args.outputs, args.plot, args.screenshot]:
        if target:
            check_folder(target)
    memory = parse_memory(args.max_memory)
    excitation = _excitation(args)
    if zs != 0 and not isinstance(excitation, _plane_wave()):
        raise SolveUsageError("--sheet-impedance takes a plane wave, not --feed")

    from barymesh.mom import solve, sweep

    mesh, title, note = _mesh(args, progress, max(freqs))
    n = len(mesh.rwg)
    print(f"{title}: {mesh.n_triangles:,} triangles, {n:,} RWG unknowns")
    if note:
        print(f"  {note}")
    options: dict[str, Any] = {"memory_limit": memory, "sheet_impedance": zs}
    if args.order is not None:
        options["order"] = args.order
    try:
        if is_sweep:
            with progress(f"solving {len(freqs)} frequencies, N = {n:,}") as report:
                result = sweep(mesh, freqs, excitation, progress=report, **options)
            _report_sweep(result, excitation)
            for out in args.outputs:
                _write_sweep(result, out)
                print(f"wrote {out}")
            if args.plot:
                _plot_sweep(result, args.plot)
                print(f"wrote {args.plot}")
        else:
            with progress(f"solving N = {n:,}"):
                solution = solve(mesh, freqs[0], excitation, **options)
            _report_single(solution)
            for out in args.outputs:
                _write_single(solution, mesh, out)
                print(f"wrote {out}")
            if args.screenshot:
                with progress(f"rendering {args.screenshot}"):
                    render_current(
                        mesh, solution.current_density, args.screenshot, tuple(args.window_size)
                    )
                print(f"wrote {args.screenshot} ({args.window_size[0]}x{args.window_size[1]} px)")
    except MemoryError as exc:
        raise ValueError(f"not enough memory for N = {n:,} unknowns ({exc})") from None
    return 0


def _plane_wave() -> type:
    from barymesh.mom import PlaneWave

    return PlaneWave


def _run_periodic(args: argparse.Namespace, freqs: list[float], zs: complex) -> int:
    if args.plot and len(freqs) == 1:
        raise SolveUsageError("--plot needs a sweep: --freq A:B:K")
    if args.plot and Path(args.plot).suffix.lower() != ".png":
        raise SolveUsageError(f"--plot {args.plot}: expected a .png file")
    if args.mesh and (args.preset or args.params or args.sets):
        raise SolveUsageError("--mesh cannot be combined with --preset, --params or --set")
    if args.unit and not args.mesh:
        raise SolveUsageError("--unit applies to --mesh files only")
    if args.preset is not None:
        from barymesh.presets import preset_names

        if args.preset not in preset_names():
            raise SolveUsageError(
                f"unknown preset {args.preset!r}; expected one of {', '.join(preset_names())}"
            )
    current_at = parse_frequency(args.current_at) if args.current_at is not None else None
    pol = (args.pol or "te").strip().lower()
    vector = None if pol in ("te", "tm") else parse_vector(args.pol, "--pol")
    for target in [*args.outputs, args.plot]:
        if target:
            check_folder(target)
    memory = parse_memory(args.max_memory)
    return run_periodic(args, freqs, zs, current_at, progress, vector, memory)


def _excitation(args: argparse.Namespace) -> Any:
    from barymesh.mom import PlaneWave, VoltageSource

    if args.feed:
        if args.dir is not None or args.pol is not None:
            raise SolveUsageError("--feed replaces the plane wave; drop --dir and --pol")
        start, end = parse_feed(args.feed)
        try:
            return VoltageSource(start, end, voltage=args.volts)  # type: ignore[arg-type]  # numbers in, an array kept
        except ValueError as exc:
            raise SolveUsageError(f"--feed {args.feed!r}: {exc}") from None
    direction = parse_vector(args.dir or "-z", "--dir")
    polarization = parse_vector(args.pol or "x", "--pol")
    try:
        return PlaneWave(direction, polarization, args.amplitude)  # type: ignore[arg-type]  # numbers in, an array kept
    except ValueError as exc:
        raise SolveUsageError(f"--dir {args.dir} --pol {args.pol}: {exc}") from None


def _mesh(args: argparse.Namespace, progress: Any, top_frequency: float) -> tuple[Any, str, str]:
    """The mesh to solve, its title and what the solver grade changed ("": nothing): a
    file as read, a structure or cell solver-grade (:mod:`barymesh.solver_grade`) unless
    ``--mesh-as-given``."""
    from barymesh import build_mesh
    from barymesh.presets import preset_names, resolve_params

    if args.mesh:
        from barymesh.io import read_mesh

        with progress(f"reading {args.mesh}"):
            return read_mesh(args.mesh, unit=args.unit), args.mesh, ""
    if args.unit:
        raise SolveUsageError("--unit applies to --mesh files only")
    if args.cell is not None or args.cell_preset is not None or args.array is not None:
        with progress("building the cell"):
            mesh, title, _, note = cell_mesh(args, top_frequency=top_frequency)
        return mesh, title, note
    if args.preset is not None and args.preset not in preset_names():
        raise SolveUsageError(
            f"unknown preset {args.preset!r}; expected one of {', '.join(preset_names())}"
        )
    params = resolve_params(args.preset, args.params, args.sets)
    with progress("choosing the solver-grade mesh"):
        params, note = solver_grade_structure(args, params, top_frequency)
    with progress(f"building {params.predicted_triangles():,} triangles"):
        mesh = build_mesh(params)
    return mesh, f"{args.preset or 'mesh'}: {params.structure}, {params.mode} mode", note


def _finite(values: dict[str, Any]) -> None:
    """Refuse to report a result that is not a finite number (NaN is never a result)."""
    import numpy as np

    bad = [name for name, value in values.items() if not np.all(np.isfinite(value))]
    if bad:
        raise ArithmeticError(
            f"the solve gave no finite {', '.join(bad)} (the matrix overflowed or is "
            "singular); nothing is reported or written"
        )


def _report_single(s: Any) -> None:
    from barymesh.mom import PlaneWave

    plane = isinstance(s.excitation, PlaneWave)
    j = abs(s.current_density).max(axis=0)
    values: dict[str, Any] = {"current": j, "residual": s.residual}
    if plane:
        values["extinction"] = s.extinction_cross_section
        values["scattering"] = s.scattering_cross_section
    else:
        values["input impedance"] = s.input_impedance
    _finite(values)
    print(f"  f = {s.frequency / 1e9:.6g} GHz")
    if plane:
        print(
            f"  extinction {s.extinction_cross_section:.6g} m^2, scattering "
            f"{s.scattering_cross_section:.6g} m^2 (PEC: equal within the quadrature error)"
        )
        if s.sheet_impedance != 0:
            print(f"  absorption cross-section {s.absorption_cross_section:.6g} m^2 (the sheet)")
    else:
        z = s.input_impedance
        print(f"  input impedance {z.real:.6g} {'+-'[z.imag < 0]} j{abs(z.imag):.6g} ohm")
    print(f"  largest |J| component {j.max():.6g} A/m")
    print(f"  condition number ~{s.condition_number:.3g}, residual {s.residual:.2g}")
    for text in s.warnings:
        print(f"  warning: {text}")


def _report_sweep(r: Any, excitation: Any) -> None:
    from barymesh.mom import PlaneWave

    f = r.frequencies
    plane = isinstance(excitation, PlaneWave)
    _finite({"coefficients": r.coefficients, "residuals": r.residuals})
    if plane:
        _finite({"extinction": r.extinction_cross_section})
    print(f"  {len(f)} frequencies, {f[0] / 1e9:.6g} to {f[-1] / 1e9:.6g} GHz")
    if plane:
        peaks = r.resonances
        if len(peaks):
            print(
                "  resonances (extinction peaks): " + ", ".join(f"{p / 1e9:.6g} GHz" for p in peaks)
            )
        else:
            print("  no extinction peak inside the sweep")
        i = int(abs(r.extinction_cross_section).argmax())
        print(
            f"  largest extinction {r.extinction_cross_section[i]:.6g} m^2 at {f[i] / 1e9:.6g} GHz"
        )
    print(f"  largest condition number ~{r.condition_numbers.max():.3g}")
    for text in r.warnings:
        print(f"  warning: {text}")


def _write_sweep(r: Any, out: str) -> None:
    import numpy as np

    from barymesh.io import atomic_path

    if out.lower().endswith(".csv"):
        r.to_csv(out)
        return
    with atomic_path(out) as tmp, open(tmp, "wb") as fh:
        np.savez_compressed(
            fh,
            frequency_hz=r.frequencies,
            extinction_cross_section_m2=r.extinction_cross_section,
            scattering_cross_section_m2=r.scattering_cross_section,
            input_impedance_ohm=r.input_impedance,
            coefficients=r.coefficients,
            resonances_hz=r.resonances,
            condition_number=r.condition_numbers,
            residual=r.residuals,
        )


def _write_single(s: Any, mesh: Any, out: str) -> None:
    import numpy as np

    from barymesh.io import atomic_path, atomic_write_text
    from barymesh.mom import PlaneWave

    plane = isinstance(s.excitation, PlaneWave)
    nan = float("nan")
    ext = s.extinction_cross_section if plane else nan
    sca = s.scattering_cross_section if plane else nan
    zin = complex(nan, nan) if plane else s.input_impedance
    suffix = Path(out).suffix.lower()
    j = s.current_density
    if suffix == ".csv":
        rows = cross_sections.cross_section_rows(
            s.frequency, ext, sca, zin, s.condition_number, s.residual
        )
        atomic_write_text(out, cross_sections.csv_text(rows))
    elif suffix == ".npz":
        with atomic_path(out) as tmp, open(tmp, "wb") as fh:
            np.savez_compressed(
                fh,
                frequency_hz=s.frequency,
                coefficients=s.coefficients,
                current_density=j,
                charge_density=s.charge_density,
                centroids_mm=mesh.centroids,
                points_mm=mesh.points,
                triangles=mesh.triangles,
                extinction_cross_section_m2=ext,
                scattering_cross_section_m2=sca,
                input_impedance_ohm=zin,
            )
    else:
        from barymesh.io.current_vtu import write_current_vtu

        write_current_vtu(
            out,
            mesh,
            j,
            frequency=s.frequency,
            excitation=s.excitation,
            charge_abs=np.abs(s.charge_density),
        )


def _plot_sweep(r: Any, path: str) -> None:
    try:
        import matplotlib

        matplotlib.use("Agg")
        import matplotlib.pyplot as plt
    except ImportError as exc:
        raise ValueError(f"--plot needs matplotlib: pip install 'barymesh[app]' ({exc})") from None
    from barymesh.io import atomic_path

    fig, ax = plt.subplots(figsize=(7, 4), dpi=120)
    f = r.frequencies / 1e9
    plotted = False
    if not all(v != v for v in r.extinction_cross_section):  # not all NaN: a plane wave
        ax.plot(f, r.extinction_cross_section * 1e6, label="extinction")
        ax.plot(f, r.scattering_cross_section * 1e6, "--", label="scattering")
        ax.set_ylabel("cross-section (mm²)")
        for p in r.resonances:
            ax.axvline(p / 1e9, color="0.5", lw=0.8)
            ax.annotate(
                f"{p / 1e9:.4g} GHz", (p / 1e9, ax.get_ylim()[1]), ha="left", va="top", fontsize=8
            )
        plotted = True
    else:
        ax.plot(f, r.input_impedance.real, label="R_in")
        ax.plot(f, r.input_impedance.imag, "--", label="X_in")
        ax.set_ylabel("input impedance (ohm)")
        plotted = True
    if plotted:
        ax.legend()
    ax.set_xlabel("frequency (GHz)")
    ax.grid(alpha=0.3)
    fig.tight_layout()
    with atomic_path(path) as tmp:
        fig.savefig(str(tmp), format="png")
    plt.close(fig)


#: Scene layers drawn under the current in a --screenshot (the orange shared edges and
#: the centroids would be lost in the colour map).
SCREENSHOT_LAYERS = {
    "faces": True,
    "triangle_edges": True,
    "patch_outlines": False,
    "shared_edges": False,
    "boundary_edges": True,
    "junction_edges": True,
    "centroids": False,
    "labels": False,
}


def render_current(mesh: Any, current: Any, path: str, window_size: tuple[int, int]) -> None:
    """Render |J| of ``current`` ((T, 3) complex, A/m) on ``mesh`` off-screen to a PNG of
    exactly ``window_size`` pixels: the mesh as
    :func:`barymesh.app.view.scaled_shot.render_screenshot` draws it, under the window's Surface
    current layer (:class:`barymesh.app.view.current_layer.CurrentLayer`:
    colour map, scale bar, arrows of Re J). Works without an X display."""
    try:
        import imageio.v3 as iio
        import numpy as np
        import pyvista as pv

        from barymesh.app.view.current_layer import CurrentLayer
        from barymesh.app.view.scene import MeshScene, prepare_headless, resized_image
        from barymesh.app.view.scene_data import scene_data
    except ImportError as exc:
        raise ValueError(
            f"--screenshot needs the desktop extras (pyvista): pip install 'barymesh[app]' ({exc})"
        ) from None
    from barymesh.io import atomic_path

    width, height = (int(v) for v in window_size)
    prepare_headless()
    plotter = pv.Plotter(off_screen=True, window_size=(width, height))
    try:
        scene = MeshScene(plotter, visible=SCREENSHOT_LAYERS)
        scene.update(scene_data(mesh))
        scene.top_view()
        CurrentLayer(plotter, lambda: None).set_current(mesh, current)
        image = np.asarray(plotter.screenshot(None, return_img=True))
    finally:
        plotter.close()
    if image.shape[:2] != (height, width):
        image = resized_image(image, width, height)
    with atomic_path(path) as tmp:
        iio.imwrite(tmp, image, extension=".png")
        if not tmp.exists() or tmp.stat().st_size == 0:
            raise ValueError(f"cannot write {path}: the renderer produced no image")
