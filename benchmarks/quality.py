"""Mesh quality: smallest angle, largest aspect ratio, triangles and RWG unknowns.

Measured for every shipped preset and for the mesher benchmark's conforming
split ring at about 10k, 100k and 1M triangles (``gmsh_peer.SPLIT``), with
barymesh's own figures (``TriMesh.stats()``):

- smallest angle (degrees) over all triangles;
- largest aspect ratio, ``barymesh.quality``'s l_max (l_0 + l_1 + l_2) / (4 √3 A),
  which is l_max / (2 √3 r_in) with r_in the inradius: 1 for an equilateral
  triangle, unbounded as a triangle flattens;
- triangles, and RWG unknowns: the interior edges (edges on exactly two
  triangles), checked against the length of the mesh's RWG table.

``--baseline PATH`` measures the same cases again with the ``core`` of another
checkout of barymesh (a subprocess with that checkout first on the path) and
prints its figures beside this checkout's ("today" and "new"). The split ring
is given by the same parameters in both; presets are read from each checkout.

gmsh's 2D mesher (Frontal-Delaunay, gmsh's default; ``--gmsh-algorithm``) is
run on the same geometry as every conforming ring preset and the split ring,
at about this checkout's triangle count, and its mesh is measured with the same
``core`` functions (as an imported mesh), so the definitions match. Each gmsh
run is a subprocess killed after ``--gmsh-timeout`` seconds.

Usage::

    python benchmarks/quality.py                               # table on stdout
    python benchmarks/quality.py --baseline ../baseline --markdown --json quality.json
    python benchmarks/quality.py --sizes 10k --no-gmsh         # quick look
"""

from __future__ import annotations

import argparse
import importlib.util
import json
import os
import subprocess
import sys
import time
from pathlib import Path
from typing import Any

ROOT = Path(__file__).resolve().parents[1]
HERE = Path(__file__).resolve().parent
sys.path.insert(0, str(HERE))

from gmsh_peer import ALGORITHMS, GMSH_STRUCTURES, SPLIT, Gmsh, split_ring_fields  # noqa: E402

SIZES = tuple(SPLIT)
DEFAULT_SIZES = ("10k", "100k", "1M")
ASPECT_RATIO = "l_max (l0 + l1 + l2) / (4 sqrt(3) A) = l_max / (2 sqrt(3) r_in)"


def use_core(root: Path) -> Path:
    """Import the ``core/`` folder of the checkout ``root`` as ``barymesh`` (what its wheel
    installs under that name); its folder."""
    init = root.resolve() / "core" / "__init__.py"
    spec = importlib.util.spec_from_file_location(
        "barymesh", init, submodule_search_locations=[str(init.parent)]
    )
    module = importlib.util.module_from_spec(spec)
    sys.modules["barymesh"] = module
    spec.loader.exec_module(module)
    return init.parent


def measure(sizes: list[str], presets: bool = True) -> list[dict[str, Any]]:
    """Figures of the split ring at ``sizes`` and of every preset, with the imported ``core``."""
    from barymesh import MeshParams, build_mesh
    from barymesh.presets import load_preset, preset_names

    cases = [(f"split ring {s}", "split ring", MeshParams(**split_ring_fields(s))) for s in sizes]
    if presets:
        cases += [(name, "preset", load_preset(name)[0]) for name in preset_names()]
    rows = []
    for name, kind, params in cases:
        print(f"measuring {name} ...", file=sys.stderr, flush=True)
        mesh = build_mesh(params)
        s = mesh.stats()
        if s["interior_edges"] != len(mesh.rwg):
            raise AssertionError(
                f"{name}: stats() counts {s['interior_edges']} interior edges, "
                f"the RWG table has {len(mesh.rwg)} rows"
            )
        rows.append(
            {
                "name": name,
                "kind": kind,
                "mode": params.mode,
                "structure": params.structure,
                "params": params.to_dict(),
                "triangles": s["triangles"],
                "unknowns": s["interior_edges"],
                "min_angle_deg": s["min_angle_deg"],
                "max_aspect_ratio": s["max_aspect_ratio"],
                "area_mm2": s["area"],
            }
        )
        del mesh
    return rows


def measure_gmsh(params: dict[str, Any], target: int, algorithm: int) -> dict[str, Any]:
    """gmsh's mesh of the geometry of ``params`` at about ``target`` triangles, measured by core."""
    import numpy as np

    from barymesh import MeshParams, TriMesh

    t0 = time.perf_counter()
    g = Gmsh(MeshParams.from_dict(params), target, algorithm)
    nodes, triangles = g.run()
    seconds = time.perf_counter() - t0
    n = len(triangles)
    mesh = TriMesh(
        nodes,
        triangles,
        np.zeros(n, dtype=np.int64),
        np.ones(n, dtype=np.int64),
        n_patches=1,
        mode="imported",
    )
    s = mesh.stats()
    return {
        "triangles": s["triangles"],
        "unknowns": s["interior_edges"],
        "min_angle_deg": s["min_angle_deg"],
        "max_aspect_ratio": s["max_aspect_ratio"],
        "junction_edges": s["junction_edges"],
        "area_mm2": s["area"],
        "mesh_size_mm": g.size,
        "seconds": seconds,
    }


def _run_worker(args: list[str], timeout: float, core_root: Path) -> Any:
    """Run this script as a worker with ``core_root``'s core; its JSON answer."""
    cmd = [sys.executable, str(Path(__file__).resolve()), "--core", str(core_root), *args]
    proc = subprocess.run(
        cmd,
        capture_output=True,
        text=True,
        timeout=timeout,
        check=False,
        env=_env_with_path(core_root),
    )
    if proc.returncode != 0:
        raise RuntimeError(f"{' '.join(cmd)} failed:\n{proc.stderr.strip()}")
    return json.loads(proc.stdout)


def _env_with_path(root: Path) -> dict[str, str]:
    """The environment with ``root`` first on ``PYTHONPATH``."""
    env = dict(os.environ)
    env["PYTHONPATH"] = os.pathsep.join(p for p in (str(root), env.get("PYTHONPATH")) if p)
    return env


def _commit(root: Path) -> str | None:
    proc = subprocess.run(
        ["git", "-C", str(root), "describe", "--always", "--dirty"],
        capture_output=True,
        text=True,
        check=False,
    )
    return proc.stdout.strip() or None


def gmsh_rows(rows: list[dict[str, Any]], algorithm: int, timeout: float) -> None:
    """Add gmsh's figures to the conforming rows it can mesh (or why not), in place."""
    for row in rows:
        if row["mode"] != "conforming" or row["structure"] not in GMSH_STRUCTURES:
            continue
        print(f"gmsh on {row['name']} ...", file=sys.stderr, flush=True)
        args = [
            "--worker",
            "gmsh",
            "--case",
            json.dumps(row["params"]),
            "--target",
            str(row["triangles"]),
            "--gmsh-algorithm",
            str(algorithm),
        ]
        try:
            row["gmsh"] = _run_worker(args, timeout, ROOT)
        except subprocess.TimeoutExpired:
            row["gmsh"] = {"error": f"timed out after {timeout:g} s"}


# -- output -------------------------------------------------------------------------


def _cells(value: Any, kind: str) -> str:
    if value is None:
        return "–"
    if kind == "int":
        return f"{value:,}"
    if kind == "angle":
        return f"{value:.1f}"
    return f"{value:.2f}"


FIGURES = (
    ("triangles", "triangles", "int"),
    ("unknowns", "unknowns", "int"),
    ("min_angle_deg", "min angle °", "angle"),
    ("max_aspect_ratio", "max aspect", "ratio"),
)


def _ordered(rows: list[dict[str, Any]]) -> list[dict[str, Any]]:
    def key(row: dict[str, Any]) -> tuple:
        split = row["kind"] == "split ring"
        size = SIZES.index(row["name"].rsplit(" ", 1)[1]) if split else 0
        return (not split, row["mode"] != "conforming", size, row["name"])

    return sorted(rows, key=key)


def table(
    rows: list[dict[str, Any]], baseline: dict[str, dict[str, Any]] | None, markdown: bool
) -> str:
    """The figures as a Markdown or a plain table; ``baseline`` maps names to rows."""
    head = ["mesh", "mode"]
    for _, label, _ in FIGURES:
        head += [f"{label} today", f"{label} new"] if baseline is not None else [label]
    head += [f"gmsh {label}" for _, label, _ in FIGURES]
    body = []
    for row in _ordered(rows):
        cells = [row["name"], row["mode"]]
        old = None if baseline is None else baseline.get(row["name"], {})
        for key, _, kind in FIGURES:
            if old is not None:
                cells.append(_cells(old.get(key), kind))
            cells.append(_cells(row[key], kind))
        g = row.get("gmsh")
        if g is not None and "error" in g:
            cells += [g["error"]] + ["–"] * (len(FIGURES) - 1)
        else:
            cells += [_cells(None if g is None else g[key], kind) for key, _, kind in FIGURES]
        body.append(cells)
    if markdown:
        align = ["---", "---"] + ["---:"] * (len(head) - 2)
        return "\n".join("| " + " | ".join(r) + " |" for r in [head, align, *body])
    widths = [max(len(r[i]) for r in [head, *body]) for i in range(len(head))]
    lines = [
        "  ".join(
            c.ljust(w) if i < 2 else c.rjust(w)
            for i, (c, w) in enumerate(zip(r, widths, strict=True))
        )
        for r in [head, *body]
    ]
    lines.insert(1, "-" * len(lines[0]))
    return "\n".join(lines)


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument(
        "--sizes",
        default=",".join(DEFAULT_SIZES),
        help=f"split ring sizes, a comma list from {', '.join(SIZES)} "
        f"(default {','.join(DEFAULT_SIZES)}; empty for presets only)",
    )
    ap.add_argument("--no-presets", action="store_true", help="only the split ring")
    ap.add_argument(
        "--baseline",
        type=Path,
        help="another barymesh checkout: its figures go in the 'today' columns",
    )
    ap.add_argument("--no-gmsh", action="store_true", help="skip gmsh")
    ap.add_argument(
        "--gmsh-algorithm",
        default="frontal-delaunay",
        help=f"gmsh's 2D algorithm: {', '.join(ALGORITHMS)} or its number "
        "(default frontal-delaunay, gmsh's own default)",
    )
    ap.add_argument(
        "--gmsh-timeout",
        type=float,
        default=150.0,
        help="seconds allowed to each gmsh run, calibration included (default 150)",
    )
    ap.add_argument("--markdown", action="store_true", help="print a Markdown table")
    ap.add_argument("--json", type=Path, help="also write the figures here")
    ap.add_argument("--worker", choices=("measure", "gmsh"), help=argparse.SUPPRESS)
    ap.add_argument("--core", type=Path, default=ROOT, help=argparse.SUPPRESS)
    ap.add_argument("--case", help=argparse.SUPPRESS)
    ap.add_argument("--target", type=int, help=argparse.SUPPRESS)
    args = ap.parse_args(argv)

    sizes = [s.strip() for s in args.sizes.split(",") if s.strip()]
    unknown = [s for s in sizes if s not in SIZES]
    if unknown:
        ap.error(f"--sizes: unknown {unknown}; expected some of {', '.join(SIZES)}")
    algorithm = ALGORITHMS.get(args.gmsh_algorithm.lower())
    if algorithm is None:
        try:
            algorithm = int(args.gmsh_algorithm)
        except ValueError:
            ap.error(
                f"--gmsh-algorithm={args.gmsh_algorithm!r}: expected one of "
                f"{', '.join(ALGORITHMS)} or gmsh's number"
            )
    if args.gmsh_timeout <= 0:
        ap.error(f"--gmsh-timeout={args.gmsh_timeout}: expected a positive number of seconds")
    if args.baseline is not None and not (args.baseline / "core" / "__init__.py").is_file():
        ap.error(f"--baseline {args.baseline}: no barymesh checkout there (no core/__init__.py)")

    use_core(args.core)
    if args.worker == "measure":
        print(json.dumps(measure(sizes, not args.no_presets)))
        return 0
    if args.worker == "gmsh":
        print(json.dumps(measure_gmsh(json.loads(args.case), args.target, algorithm)))
        return 0

    rows = measure(sizes, not args.no_presets)
    baseline = None
    if args.baseline is not None:
        print(f"measuring the baseline {args.baseline} in a subprocess ...", file=sys.stderr)
        worker = ["--worker", "measure", "--sizes", ",".join(sizes)]
        worker += ["--no-presets"] if args.no_presets else []
        old = _run_worker(worker, 600, args.baseline.resolve())
        baseline = {row["name"]: row for row in old}
    with_gmsh = not args.no_gmsh
    if with_gmsh and importlib.util.find_spec("gmsh") is None:
        print("gmsh is not installed: no gmsh columns", file=sys.stderr)
        with_gmsh = False
    if with_gmsh:
        gmsh_rows(rows, algorithm, args.gmsh_timeout)

    print(table(rows, baseline, args.markdown))
    if args.json:
        doc = {
            "aspect_ratio": ASPECT_RATIO,
            "unknowns": "interior edges (on exactly two triangles) = rows of the RWG table",
            "new": {"checkout": str(ROOT), "commit": _commit(ROOT)},
            "baseline": None
            if args.baseline is None
            else {"checkout": str(args.baseline.resolve()), "commit": _commit(args.baseline)},
            "gmsh_algorithm": algorithm if with_gmsh else None,
            "rows": [
                {**row, "baseline": None if baseline is None else baseline.get(row["name"])}
                for row in _ordered(rows)
            ],
        }
        args.json.write_text(json.dumps(doc, indent=2))
    return 0


if __name__ == "__main__":
    sys.exit(main())
