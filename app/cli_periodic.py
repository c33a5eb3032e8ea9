"""``barymesh solve --periodic``: the infinite array of a unit cell from the command line.

::

    barymesh solve --cell-preset coding-16x16 --periodic --freq 5GHz:40GHz:651 \\
        --theta 30 --phi 0 --pol te -o rt.s4p -o orders.csv --plot rt.png
    barymesh solve --preset paper-fig11-8mm --set subdivisions=8 --period 10 --periodic \\
        --freq 20GHz

One frequency prints R and T of every propagating Floquet order; a range runs
:func:`barymesh.mom.periodic_sweep` (interpolating unless ``--no-interpolate``) and prints
the grating-lobe onsets and the resonances. Called by :mod:`barymesh.app.cli_solve`, which
parses the options; usage errors are :class:`PeriodicUsageError` (exit 2), bad input
``ValueError`` (exit 1), one line each.

Also the unit cells of ``barymesh solve`` in free space: :func:`cell_mesh`.
"""

from __future__ import annotations

import argparse
import dataclasses
import math
from pathlib import Path
from typing import Any

import numpy as np

from barymesh.app.cli_options import load_cell_source, solver_grade_cell, solver_grade_structure

#: Outputs of --periodic: the 4-port (a 2-port over a ground plane), every Floquet order,
#: the cell's current.
PERIODIC_OUTPUTS = (".s4p", ".s2p", ".csv", ".vtu")

__all__ = [
    "PERIODIC_OUTPUTS",
    "PeriodicUsageError",
    "cell_mesh",
    "check_periodic_usage",
    "incidence",
    "parse_impedance",
    "parse_stack_option",
    "run_periodic",
]


class PeriodicUsageError(ValueError):
    """Bad usage of ``barymesh solve --periodic`` (exit 2, through the solve parser)."""


def parse_impedance(text: str | None) -> complex:
    """``--sheet-impedance``: ohm per square, complex allowed.

    >>> parse_impedance("377"), parse_impedance("10-5j"), parse_impedance(None)
    ((377+0j), (10-5j), 0j)
    """
    if text is None:
        return 0j
    try:
        value = complex(text.strip().replace(" ", "").replace("i", "j"))
    except ValueError:
        raise PeriodicUsageError(
            f"--sheet-impedance {text!r} is invalid; expected ohm per square, e.g. 377 or 10-5j"
        ) from None
    if not (math.isfinite(value.real) and math.isfinite(value.imag)):
        raise PeriodicUsageError(f"--sheet-impedance {text!r} is not finite")
    return value


def parse_stack_option(text: str | None) -> Any:
    """``--stack``: the layers' syntax (:func:`barymesh.mom.parse_stack`) or a JSON file.

    >>> parse_stack_option("30mil eps=2.2; ground").describe()
    '0.762mm eps=2.2; ground'
    """
    from barymesh.mom import Stack, parse_stack

    if text is None:
        return None
    if text.strip().lower().endswith(".json"):
        import json

        try:
            data = json.loads(Path(text).read_text(encoding="utf-8"))
            return Stack.from_dict(data)
        except OSError as exc:
            raise PeriodicUsageError(f"--stack {text}: cannot read it ({exc.strerror})") from None
        except (ValueError, TypeError) as exc:
            raise PeriodicUsageError(f"--stack {text}: {exc}") from None
    try:
        return parse_stack(text)
    except (ValueError, TypeError) as exc:
        raise PeriodicUsageError(f"--stack: {exc}") from None


def _has_cell(args: argparse.Namespace) -> bool:
    return args.cell is not None or args.cell_preset is not None


def check_periodic_usage(args: argparse.Namespace, n_frequencies: int) -> None:
    """Every bad combination of options with ``--periodic``, or of its options without it."""
    periodic_only = [
        ("--theta", args.theta is not None),
        ("--phi", args.phi is not None),
        ("--no-interpolate", args.no_interpolate),
        ("--tolerance", args.tolerance is not None),
        ("--current-at", args.current_at is not None),
        ("--stack", getattr(args, "stack", None) is not None),
        ("--circuit", getattr(args, "circuit", False)),
    ]
    s4p = [out for out in args.outputs if Path(out).suffix.lower() in (".s4p", ".s2p")]
    if not args.periodic:
        for option, given in periodic_only:
            if given:
                hint = " (free space: --dir, --pol)" if option in ("--theta", "--phi") else ""
                raise PeriodicUsageError(f"{option} applies to --periodic{hint}")
        if s4p:
            raise PeriodicUsageError(f"-o {s4p[0]}: a Touchstone 4-port needs --periodic")
        if args.period is not None and args.array is None:
            raise PeriodicUsageError(
                "--period makes the structure a unit cell: add --periodic (the infinite "
                "array) or --array N1xN2 (a finite one)"
            )
        return
    if args.feed:
        raise PeriodicUsageError("--periodic solves a plane wave on the array; drop --feed")
    if args.dir is not None:
        raise PeriodicUsageError(
            "--periodic takes the incidence as --theta and --phi (degrees), not --dir"
        )
    if args.array is not None:
        raise PeriodicUsageError(
            "--array makes a finite array; --periodic solves the infinite one: drop one"
        )
    if args.order is not None:
        raise PeriodicUsageError("--order applies to the free-space solver, not --periodic")
    if args.screenshot:
        raise PeriodicUsageError(
            "--screenshot is not available with --periodic: write the cell's current with "
            "-o current.vtu"
        )
    if not _has_cell(args) and args.period is None:
        what = f"the mesh {args.mesh}" if args.mesh else "a structure"
        raise PeriodicUsageError(
            f"--periodic needs a unit cell: --cell FILE, --cell-preset NAME, or {what} "
            "with --period PX[,PY] (mm)"
        )
    theta = 0.0 if args.theta is None else args.theta
    if not (math.isfinite(theta) and 0.0 <= theta < 90.0):
        raise PeriodicUsageError(
            f"--theta {args.theta:g} is invalid; expected 0 <= theta < 90 degrees (the wave "
            "comes from above)"
        )
    if args.phi is not None and not math.isfinite(args.phi):
        raise PeriodicUsageError(f"--phi {args.phi!r} is not a finite angle in degrees")
    if args.tolerance is not None and not (
        math.isfinite(args.tolerance) and 0 < args.tolerance < 1
    ):
        raise PeriodicUsageError(f"--tolerance {args.tolerance:g} is invalid; expected 0 < TOL < 1")
    for out in args.outputs:
        if Path(out).suffix.lower() not in PERIODIC_OUTPUTS:
            raise PeriodicUsageError(
                f"-o {out}: with --periodic expected {', '.join(PERIODIC_OUTPUTS)}"
            )
    vtu = [out for out in args.outputs if Path(out).suffix.lower() == ".vtu"]
    if vtu and n_frequencies > 1 and args.current_at is None:
        raise PeriodicUsageError(
            f"-o {vtu[0]}: a sweep writes the current at one frequency: add --current-at F"
        )
    if args.current_at is not None and not vtu:
        raise PeriodicUsageError("--current-at sets the frequency of -o FILE.vtu: add one")
    if getattr(args, "circuit", False) and n_frequencies < 3:
        raise PeriodicUsageError(
            "--circuit fits the sheet's LC circuit to a sweep: give --freq A:B:K with K >= 3"
        )
    stack = parse_stack_option(getattr(args, "stack", None))
    grounded = stack is not None and stack.ground
    for out in args.outputs:
        suffix = Path(out).suffix.lower()
        if suffix == ".s4p" and grounded:
            raise PeriodicUsageError(
                f"-o {out}: over a ground plane the array has one side: write a 2-port, .s2p"
            )
        if suffix == ".s2p" and not grounded:
            raise PeriodicUsageError(
                f"-o {out}: a 2-port is for a sheet over a ground plane (--stack '...; "
                "ground'); without one write the 4-port, .s4p"
            )


def incidence(args: argparse.Namespace, vector: tuple[float, float, float] | None = None) -> Any:
    """The plane wave of --theta, --phi and --pol in periodic mode: TE, TM, or ``vector``
    (the parsed --pol vector, when it is not te or tm)."""
    from barymesh.mom import PlaneWave, te_tm_polarizations

    theta = 0.0 if args.theta is None else args.theta
    phi = 0.0 if args.phi is None else args.phi
    direction = PlaneWave.from_angles(theta, phi).direction
    pol = (args.pol or "te").strip().lower()
    if vector is None:
        polarization = te_tm_polarizations(direction)[1 if pol == "tm" else 0]
    else:
        polarization = np.array(vector, dtype=float)
    try:
        return PlaneWave(direction, polarization, args.amplitude)
    except ValueError as exc:
        raise PeriodicUsageError(
            f"--theta {theta:g} --phi {phi:g} --pol {args.pol}: {exc}"
        ) from None


# -- what is solved: a unit cell ------------------------------------------------------


def cell_mesh(
    args: argparse.Namespace,
    structure_mesh: Any = None,
    top_frequency: float | None = None,
    relative_permittivity: float = 1.0,
) -> tuple[Any, str, Any, str]:
    """The mesh of --cell, --cell-preset, or of a structure with --period, and its title.

    Returns ``(mesh, title, lattice, note)``: ``lattice`` is None when the mesh carries its
    own (a cell's), or the --period lattice of a mesh file (``structure_mesh`` read from
    --mesh), which the periodic solver takes as ``lattice=``. The cell or structure is
    meshed solver-grade (:mod:`barymesh.solver_grade`, edges within λ/10 at
    ``top_frequency`` in a medium of ``relative_permittivity``, εr μr of the densest
    layer) unless ``--mesh-as-given``; ``note`` says what that changed ("": nothing).
    """
    from barymesh.cell import Element, Lattice, UnitCell, build_cell, tile

    if args.cell is not None and args.cell_preset is not None:
        raise PeriodicUsageError("--cell and --cell-preset both name a cell; give one")
    if _has_cell(args):
        given = [o for o, v in (("--preset", args.preset), ("--params", args.params)) if v]
        given += ["--set"] if args.sets else []
        given += ["--mesh"] if args.mesh else []
        if given:
            raise PeriodicUsageError(
                f"{given[0]} names one structure; a cell (--cell, --cell-preset) holds its "
                "own elements"
            )
        if args.period is not None:
            raise PeriodicUsageError("--period: a cell (--cell, --cell-preset) has its own lattice")
        cell, label = _load_cell(args)
        cell, note = solver_grade_cell(args, cell, top_frequency, relative_permittivity)
    else:
        if structure_mesh is not None:
            px, py = args.period
            _check_fits(structure_mesh, px, py, args.mesh)
            return structure_mesh, args.mesh, Lattice.rectangular(px, py), ""
        from barymesh import build_mesh
        from barymesh.presets import resolve_params

        params = resolve_params(args.preset, args.params, args.sets)
        params, note = solver_grade_structure(args, params, top_frequency, relative_permittivity)
        mesh = build_mesh(params)
        label = args.preset or params.structure
        lo, hi = mesh.points[:, :2].min(axis=0), mesh.points[:, :2].max(axis=0)
        # without --period (a finite --array), the bounding box: neighbouring copies touch
        px, py = args.period or (float(hi[0] - lo[0]), float(hi[1] - lo[1]))
        _check_fits(mesh, px, py, label)
        centre = (lo + hi) / 2
        element = Element(params, position=(-centre[0], -centre[1]), name=label)
        cell = UnitCell(
            Lattice.rectangular(px, py),
            (element,),
            mode=params.mode,
            tolerance=params.tolerance,
            name=label,
        )
        label = f"{label} on a {px:g} x {py:g} mm lattice"
    built = build_cell(cell)
    if args.array is not None:
        built = tile(built, *args.array)
        label = f"{label}, {args.array[0]} x {args.array[1]} copies"
    return built.mesh, label, None, note


def _load_cell(args: argparse.Namespace) -> tuple[Any, str]:
    from barymesh.cell import cell_preset_names

    if args.cell_preset is not None and args.cell_preset not in cell_preset_names():
        raise PeriodicUsageError(
            f"unknown cell preset {args.cell_preset!r}; expected one of "
            f"{', '.join(cell_preset_names())}"
        )
    return load_cell_source(args)


def _check_fits(mesh: Any, px: float, py: float, label: str) -> None:
    lo, hi = mesh.points[:, :2].min(axis=0), mesh.points[:, :2].max(axis=0)
    w, h = (float(v) for v in hi - lo)
    slack = 1e-9 * max(px, py)
    if w > px + slack or h > py + slack:
        raise ValueError(
            f"{label} is {w:.6g} x {h:.6g} mm, larger than the period {px:g} x {py:g} mm "
            "(--period): neighbouring copies would overlap"
        )


# -- running --------------------------------------------------------------------------


def run_periodic(
    args: argparse.Namespace,
    frequencies: list[float],
    sheet_impedance: complex,
    current_at: float | None,
    progress: Any,
    vector: tuple[float, float, float] | None = None,
    memory_limit: float | None = None,
) -> int:
    """Solve, report and write; ``progress`` is the command line's spinner, ``vector`` the
    parsed --pol vector (None for te and tm), ``memory_limit`` the parsed --max-memory."""
    from barymesh.mom import periodic_sweep

    wave = incidence(args, vector)
    stack = parse_stack_option(getattr(args, "stack", None))
    structure = None
    if args.mesh:
        from barymesh.io import read_mesh

        with progress(f"reading {args.mesh}"):
            structure = read_mesh(args.mesh, unit=args.unit)
    with progress("building the unit cell"):
        # solver-grade: edges within λ/10 in the densest layer of the stack
        densest = 1.0 if stack is None else stack.max_index**2
        mesh, title, lattice, note = cell_mesh(args, structure, max(frequencies), densest)
    print(f"{title}: {mesh.n_triangles:,} triangles, {len(mesh.rwg):,} interior RWG unknowns")
    if note:
        print(f"  {note}")
    both = any(Path(out).suffix.lower() in (".s4p", ".s2p") for out in args.outputs)
    below_too = both and stack is not None and not stack.ground
    _say_expected_time(
        mesh, lattice, frequencies, wave, not args.no_interpolate, 2 if below_too else 1
    )
    options: dict[str, Any] = {
        "interpolate": not args.no_interpolate,
        "polarizations": "both" if both else "incident",
        "lattice": lattice,
        "sheet_impedance": sheet_impedance,
        "memory_limit": memory_limit,
        "stack": stack,
    }
    if args.tolerance is not None:
        options["tolerance"] = args.tolerance
    n = len(frequencies)
    what = f"solving the infinite array at {n} frequenc{'ies' if n > 1 else 'y'}"
    with progress(what) as report:
        sweep = periodic_sweep(mesh, frequencies, wave, progress=report, **options)
    below = None
    if below_too:
        # the stack is not its own mirror image: the lower ports need the wave from below
        what = f"solving the wave from below at {n} frequenc{'ies' if n > 1 else 'y'}"
        with progress(what) as report:
            below = periodic_sweep(mesh, frequencies, _mirrored(wave), progress=report, **options)
    _describe_incidence(args, sweep)
    if n == 1:
        _report_orders(sweep)
        _report_next_onset(sweep, lattice if lattice is not None else mesh.lattice, wave)
    else:
        _report_sweep(sweep)
    for text in sweep.warnings:
        print(f"  warning: {text}")
    if getattr(args, "circuit", False):
        _report_circuit(sweep)
    for out in args.outputs:
        suffix = Path(out).suffix.lower()
        if suffix in (".s4p", ".s2p"):
            sweep.to_touchstone(out, from_below=below)
        elif suffix == ".csv":
            sweep.to_csv(out)
        else:
            from barymesh.io.current_vtu import describe_excitation, write_current_vtu

            f = frequencies[0] if current_at is None else current_at
            with progress(f"solving at {f / 1e9:.6g} GHz for the current"):
                solution = sweep.solution(f)
            a1, a2 = (np.asarray(a, dtype=float) * 1e3 for a in sweep.lattice)  # m -> mm
            theta = 0.0 if args.theta is None else args.theta
            phi = 0.0 if args.phi is None else args.phi
            text = (
                f"infinite array of this cell (lattice a1 = ({a1[0]:.6g}, {a1[1]:.6g}) mm, "
                f"a2 = ({a2[0]:.6g}, {a2[1]:.6g}) mm), {describe_excitation(wave)}: from above, "
                f"theta = {theta:g} deg, phi = {phi:g} deg; J of the cell at the origin (the "
                "others differ by the Floquet phase)"
            )
            if sweep.stack is not None:
                text += f"; the sheet on the stack {sweep.stack.describe()}"
            write_current_vtu(
                out, mesh, solution.current_density, frequency=f, excitation=wave, description=text
            )
        print(f"wrote {out}")
    if args.plot:
        plot_sweep(sweep, args.plot)
        print(f"wrote {args.plot}")
    return 0


#: A periodic solve expected to take longer than this (seconds) says so before it starts.
LONG_SOLVE_S = 30.0


def _say_expected_time(
    mesh: Any,
    lattice: Any,
    frequencies: list[float],
    wave: Any,
    interpolate: bool,
    sweeps: int = 1,
) -> None:
    """Before a long solve: its size and the time the measured model expects
    (:func:`barymesh.mom.timing.periodic_sweep_time`); ``sweeps`` is 2 when the wave from
    below is solved too (a stack that is not its own mirror image)."""
    from barymesh.cell.periodic import periodic_pairs
    from barymesh.mom import grating_lobe_onsets
    from barymesh.mom.timing import periodic_sweep_time

    lat = lattice if lattice is not None else mesh.lattice
    pairs = mesh.periodic_pairs if lattice is None else periodic_pairs(mesh, lat, mesh.tolerance)
    unknowns = len(mesh.rwg) + (len(pairs.edges) if pairs is not None else 0)
    n = len(frequencies)
    onsets = 0
    if n > 1:
        onsets = len(grating_lobe_onsets(lat, wave, f_max=frequencies[-1], f_min=frequencies[0]))
    t = periodic_sweep_time(mesh.n_triangles, unknowns, n, interpolate and n > 1, onsets)
    if sweeps > 1:
        t = dataclasses.replace(
            t, fewest_solves=sweeps * t.fewest_solves, most_solves=sweeps * t.most_solves
        )
    if t.most_s < LONG_SOLVE_S:
        return
    solves = (
        f"{t.most_solves}"
        if t.fewest_solves == t.most_solves
        else f"{t.fewest_solves} to {t.most_solves}"
    )
    span = (
        _minutes(t.most_s)
        if t.fewest_solves == t.most_solves
        else f"{_minutes(t.fewest_s)} to {_minutes(t.most_s)}"
    )
    print(
        f"  a long solve: {mesh.n_triangles:,} triangles, {unknowns:,} unknowns, {n} "
        f"frequenc{'ies' if n > 1 else 'y'} ({solves} solved, about {t.per_solve_s:.0f} s "
        f"each, and {t.geometry_s:.0f} s for the cell's tables): expected {span} on the "
        "2-core benchmark machine, longer on a loaded one",
        flush=True,
    )


def _minutes(seconds: float) -> str:
    """``"40 s"``, ``"12 min"``, ``"2.5 h"``: a rough duration."""
    if seconds < 90:
        return f"{seconds:.0f} s"
    if seconds < 5400:
        return f"{seconds / 60:.0f} min"
    return f"{seconds / 3600:.1f} h"


def _mirrored(wave: Any) -> Any:
    """The wave from below with the same transverse wavevector and TE/TM components."""
    from barymesh.mom import PlaneWave, te_tm_polarizations

    d = np.asarray(wave.direction, dtype=float)
    up = np.array([d[0], d[1], -d[2]])
    te, tm = te_tm_polarizations(d)
    te_up, tm_up = te_tm_polarizations(up)
    pol = np.asarray(wave.polarization)
    return PlaneWave(up, (pol @ te) * te_up + (pol @ tm) * tm_up, wave.amplitude)


def _describe_incidence(args: argparse.Namespace, sweep: Any) -> None:
    theta = 0.0 if args.theta is None else args.theta
    phi = 0.0 if args.phi is None else args.phi
    pol = (args.pol or "te").lower()
    name = pol.upper() if pol in ("te", "tm") else f"E along {args.pol}"
    zs = sweep.sheet_impedance
    sheet = (
        ""
        if zs == 0
        else f", sheet impedance {zs.real:.6g} {'+-'[zs.imag < 0]} j{abs(zs.imag):.6g} ohm/sq"
    )
    print(f"  incidence from above: theta = {theta:g} deg, phi = {phi:g} deg, {name}{sheet}")
    if sweep.stack is not None:
        top, bottom = sweep.reference_planes
        print(f"  stack: {sweep.stack.describe()}")
        far = (
            "T = 0 (ground plane)"
            if sweep.stack.ground
            else f"T at its bottom face, z = {bottom:g} mm"
        )
        print(
            f"  reference planes: R at the stack's top face, z = {top:g} mm over the sheet; {far}"
        )


def _polar(z: complex) -> str:
    return f"{abs(z):8.5f} {math.degrees(math.atan2(z.imag, z.real)):7.2f}"


def _report_orders(sweep: Any) -> None:
    """One frequency: R and T of every propagating order, the power balance."""
    f = float(sweep.frequencies[0])
    r, t = (x[0] for x in sweep.order_response)  # (P, 2)
    rp, tp = (x[0] for x in sweep.power_fractions)
    print(f"  f = {f / 1e9:.6g} GHz")
    print(
        "  order (p, q)   |R_TE|   ∠R_TE   |R_TM|   ∠R_TM   |T_TE|   ∠T_TE   |T_TM|   "
        "∠T_TM   P_refl   P_trans"
    )
    for j in np.flatnonzero(sweep.propagating[0]):
        p, q = (int(v) for v in sweep.orders[j])
        cells = "  ".join(_polar(complex(z)) for z in (*r[j], *t[j]))
        print(f"  ({p:3d}, {q:3d})    {cells}  {rp[j]:7.5f}  {tp[j]:7.5f}")
    rc, tc = (complex(x[0]) for x in sweep.co_polar())
    print(f"  co-polar (0, 0): R = {_polar(rc).strip()} deg, T = {_polar(tc).strip()} deg")
    absorbed = float(sweep.absorption[0])
    lossless = sweep.stack is None or not sweep.stack.lossy
    if sweep.sheet_impedance == 0 and lossless:
        print(f"  power balance: reflected + transmitted = {rp.sum() + tp.sum():.6f} (lossless: 1)")
    else:
        print(
            f"  reflected {rp.sum():.6f} + transmitted {tp.sum():.6f} + absorbed {absorbed:.6f} = 1"
        )


def _report_next_onset(sweep: Any, lattice: Any, wave: Any) -> None:
    from barymesh.mom import grating_lobe_onsets

    f = float(sweep.frequencies[0])
    above = grating_lobe_onsets(lattice, wave, f_max=100.0 * f, f_min=f)
    if len(above):
        print(f"  next grating-lobe onset: {above[0] / 1e9:.6g} GHz")


def _report_sweep(sweep: Any) -> None:
    f = sweep.frequencies
    print(f"  {len(f)} frequencies, {f[0] / 1e9:.6g} to {f[-1] / 1e9:.6g} GHz")
    if sweep.interpolated:
        print(
            f"  interpolating sweep: {sweep.n_solves} frequencies solved, largest estimated "
            f"error {float(np.max(sweep.error_estimate)):.2g}"
        )
    onsets = sweep.grating_lobe_onsets
    text = ", ".join(f"{o / 1e9:.6g} GHz" for o in onsets) if len(onsets) else "none in the band"
    print(f"  grating-lobe onsets: {text}")
    if len(sweep.resonances):
        parts = []
        for fr, kind, q in zip(
            sweep.resonances, sweep.resonance_kinds, sweep.quality_factors, strict=True
        ):
            extra = f", Q {q:.3g}" if np.isfinite(q) else ""
            parts.append(f"{fr / 1e9:.6g} GHz (|R| {kind}{extra})")
        print("  resonances: " + ", ".join(parts))
    else:
        print("  no resonance (peak or dip of |R|) inside the sweep")
    r, t = (np.abs(x) for x in sweep.co_polar())
    i, k = int(np.argmax(r)), int(np.argmin(t))
    print(
        f"  largest |R_co| {r[i]:.6g} at {f[i] / 1e9:.6g} GHz; smallest |T_co| {t[k]:.6g} "
        f"at {f[k] / 1e9:.6g} GHz"
    )
    a = sweep.absorption
    if sweep.sheet_impedance == 0 and (sweep.stack is None or not sweep.stack.lossy):
        print(f"  largest power-balance error {float(np.max(np.abs(a))):.2g}")
    else:
        j = int(np.argmax(a))
        print(f"  largest absorption {a[j]:.6g} at {f[j] / 1e9:.6g} GHz")


def _report_circuit(sweep: Any) -> None:
    """The sheet's Foster LC (``PeriodicSweep.equivalent_circuit``), or why there is none."""
    try:
        circuit = sweep.equivalent_circuit()
    except ValueError as exc:
        print(f"  equivalent circuit: none ({exc})")
        return
    print(f"  equivalent circuit: {circuit.describe()}")


def plot_sweep(sweep: Any, path: str) -> None:
    """|R| and |T| (dB) of the (0, 0) order against frequency, onsets and resonances marked."""
    try:
        import matplotlib

        matplotlib.use("Agg")
        import matplotlib.pyplot as plt
    except ImportError as exc:
        raise ValueError(f"--plot needs matplotlib: pip install 'barymesh[app]' ({exc})") from None
    from barymesh.io import atomic_path

    def db(x: np.ndarray) -> np.ndarray:
        return 20.0 * np.log10(np.maximum(np.abs(x), 1e-6))

    f = sweep.frequencies / 1e9
    r, t = sweep.co_polar()
    rx, tx = sweep.cross_polar()
    fig, ax = plt.subplots(figsize=(7, 4), dpi=120)
    ax.plot(f, db(r), label="|R| co-polar")
    ax.plot(f, db(t), label="|T| co-polar")
    if max(np.abs(rx).max(), np.abs(tx).max()) > 1e-2:
        ax.plot(f, db(rx), ":", label="|R| cross-polar")
        ax.plot(f, db(tx), ":", label="|T| cross-polar")
    ax.set_ylim(max(-60.0, float(min(db(r).min(), db(t).min())) - 3.0), 3.0)
    top = ax.get_ylim()[1]
    for onset in sweep.grating_lobe_onsets:
        ax.axvline(onset / 1e9, color="0.4", ls="--", lw=0.8)
        ax.annotate(
            f"grating lobe {onset / 1e9:.4g} GHz",
            (onset / 1e9, top),
            rotation=90,
            ha="right",
            va="top",
            fontsize=7,
            color="0.3",
        )
    bottom = ax.get_ylim()[0]
    for fr in sweep.resonances:
        ax.axvline(fr / 1e9, color="tab:red", ls=":", lw=0.8)
        ax.annotate(
            f"{fr / 1e9:.4g} GHz",
            (fr / 1e9, bottom),
            rotation=90,
            ha="right",
            va="bottom",
            fontsize=7,
            color="tab:red",
        )
    if sweep.interpolated:
        solved = np.isin(sweep.frequencies, sweep.sampled)
        ax.plot(f[solved], db(r[solved]), "k.", ms=3, label="solved")
    ax.set_xlabel("frequency (GHz)")
    ax.set_ylabel("magnitude (dB)")
    ax.set_title("infinite array, (0, 0) order", fontsize=9)
    ax.grid(alpha=0.3)
    ax.legend(fontsize=7, loc="lower right")
    fig.tight_layout()
    with atomic_path(path) as tmp:
        fig.savefig(str(tmp), format="png")
    plt.close(fig)
