"""The study spec: a JSON document read, checked and turned into a list of points.

A spec names a base design, the axes it varies, how the axes are sampled, the solve and
the figures derived per point::

    {
      "base": {"preset": "srr-openmodes"},
      "axes": {"inner_radius": [3.0, 3.5, 4.0], "gap_width": [0.5, 1.0]},
      "sample": "product",
      "solve": {"kind": "free_space", "frequencies": "4GHz:9GHz:51",
                "direction": [0, 0, -1], "polarization": [0, 1, 0]},
      "derive": ["resonance_frequency", "quality_factor"],
      "output": "study.parquet"
    }

A bad spec raises :class:`SpecError` naming the key and the problem. A point whose
parameters the mesher refuses is not a spec error: it becomes an error row of the study.

>>> spec = parse_spec({"base": {"preset": "srr-openmodes"},
...                    "axes": {"inner_radius": [3.0, 3.5], "gap_width": [0.5, 1.0]},
...                    "solve": {"kind": "free_space", "frequencies": "4GHz:9GHz:3"}})
>>> len(spec.points()), spec.points()[1]
(4, {'inner_radius': 3.0, 'gap_width': 1.0})
"""

from __future__ import annotations

import copy
import hashlib
import itertools
import json
import math
import re
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np

from ..frequencies import parse_frequencies, parse_frequency
from ..mom.stack import Stack
from .layers import is_stack_path, layer_field, study_stack

#: Keys of a spec.
SPEC_KEYS = ("base", "axes", "sample", "solve", "stack", "derive", "output")
#: Kinds of solve.
SOLVE_KINDS = ("free_space", "infinite_array")
#: Derived figures named by a string (column names in :data:`FIGURE_COLUMNS`).
FIGURES = ("resonance_frequency", "quality_factor", "bandwidth_3db", "zero_phase_frequency")
#: Derived figures that take a list of frequencies: {"extinction_cross_section_at": [...]}.
FIGURES_AT = ("extinction_cross_section_at", "reflection_at", "reflection_phase_at")
#: Column of each derived figure named by a string.
FIGURE_COLUMNS = {
    "resonance_frequency": "resonance_frequency_hz",
    "quality_factor": "quality_factor",
    "bandwidth_3db": "bandwidth_3db_hz",
    "zero_phase_frequency": "zero_phase_frequency_hz",
}
#: Figures of the infinite array alone.
INFINITE_ARRAY_FIGURES = ("reflection_at", "reflection_phase_at", "zero_phase_frequency")
#: Figures that depend on where R is referred: with any of them the derived table also has
#: :data:`REFERENCE_PLANE_COLUMN`.
PHASE_FIGURES = ("reflection_phase_at", "zero_phase_frequency")
#: The derived table's column of the plane R is referred to: its height over the sheet (mm).
REFERENCE_PLANE_COLUMN = "reflection_reference_plane_mm"
#: Axis paths that vary the incidence rather than the geometry.
INCIDENCE_KEYS = ("theta", "phi", "pol")
#: Most points of a study (the product of its axes, or a Latin-hypercube sample): each is
#: a solve, and the list of points is made up front.
MAX_POINTS = 100_000
#: Most rows of the per-frequency table: points times frequencies.
MAX_ROWS = 10_000_000
_TOKEN = re.compile(r"([A-Za-z_][A-Za-z0-9_]*)|\[(\d+)\]")


class SpecError(ValueError):
    """A bad study spec: the message names the key and says what is wrong."""


def _fail(key: str, message: str) -> SpecError:
    return SpecError(f"study spec: {key}: {message}")


def _kind(value: Any) -> str:
    from ..values import kind

    return kind(value)


def _short(value: Any) -> str:
    """``repr(value)`` cut to 40 characters (a 5,000-digit number, a deep list)."""
    from ..values import echo

    return echo(value)


def _number(key: str, value: Any) -> float:
    if isinstance(value, bool) or not isinstance(value, int | float):
        raise _fail(key, f"{_kind(value)} {_short(value)}; expected a number")
    if isinstance(value, int) and abs(value) > 1e300:  # float() would overflow
        raise _fail(key, f"{_short(value)} is too large; expected a number up to 1e300")
    if not math.isfinite(value):
        raise _fail(key, f"{_short(value)} is not finite; expected a number")
    return float(value)


# -- parameter paths -----------------------------------------------------------------


def parse_path(path: str) -> tuple[str | int, ...]:
    """``'elements[1].gap_width'`` -> ('elements', 1, 'gap_width').

    >>> parse_path("elements[1].gap_width"), parse_path("incidence.theta")
    (('elements', 1, 'gap_width'), ('incidence', 'theta'))
    """
    tokens: list[str | int] = []
    pos = 0
    while pos < len(path):
        if tokens and path[pos] == "." and pos + 1 < len(path) and path[pos + 1] != "[":
            pos += 1
        m = _TOKEN.match(path, pos)
        if m is None or (m.group(1) is not None and tokens and path[pos - 1] != "."):
            raise _fail(
                f"axes.{path}",
                "is not a parameter path; expected names joined by dots with [i] for list "
                "items, e.g. inner_radius, elements[1].gap_width, incidence.theta",
            )
        tokens.append(m.group(1) if m.group(1) is not None else int(m.group(2)))
        pos = m.end()
    if not tokens or not isinstance(tokens[0], str):
        raise _fail(f"axes.{path}", "is not a parameter path; it must start with a name")
    return tuple(tokens)


def set_path(data: Any, path: tuple[str | int, ...], value: Any, where: str) -> None:
    """Set ``value`` at ``path`` inside the nested dicts and lists ``data`` (in place)."""
    node = data
    for depth, token in enumerate(path):
        last = depth == len(path) - 1
        shown = "".join(f"[{t}]" if isinstance(t, int) else f".{t}" for t in path[:depth])
        shown = shown.lstrip(".") or "the base"
        if isinstance(token, int):
            if not isinstance(node, list) or not -len(node) <= token < len(node):
                size = len(node) if isinstance(node, list) else 0
                raise _fail(where, f"{shown} has no item [{token}] ({size} items)")
        elif not isinstance(node, dict) or token not in node:
            names = ", ".join(sorted(node)) if isinstance(node, dict) else ""
            raise _fail(where, f"{shown} has no {_short(token)}; it has: {names}")
        if last:
            node[token] = value
        else:
            node = node[token]


# -- the parts of a spec ---------------------------------------------------------------


@dataclass(frozen=True)
class Base:
    """The base design: ``kind`` "params" (a MeshParams dict) or "cell" (a cell dict)."""

    kind: str
    data: dict[str, Any]

    def design(self, assignments: dict[str, Any]) -> dict[str, Any]:
        """A copy of :attr:`data` with each geometry path set to its value."""
        data = copy.deepcopy(self.data)
        for path, value in assignments.items():
            set_path(data, parse_path(path), value, f"axes.{path}")
        return data

    def build(self, data: dict[str, Any]) -> Any:
        """The design ``data``: a MeshParams or a UnitCell (raising the mesher's errors)."""
        if self.kind == "params":
            from ..params import MeshParams

            return MeshParams.from_dict(data)
        from ..cell import cell_from_dict

        return cell_from_dict(data)


@dataclass(frozen=True)
class Axis:
    """One axis: a parameter path and its values (product) or its [low, high] (sampled)."""

    path: str
    values: tuple[Any, ...]

    @property
    def incidence(self) -> bool:
        """True for ``incidence.theta`` and the like."""
        return self.path.startswith("incidence.")

    @property
    def layer(self) -> bool:
        """True for a value of a layer of the stack, ``stack.below[0].thickness``."""
        return is_stack_path(self.path)


@dataclass(frozen=True)
class Solve:
    """Solve settings.

    ``frequencies`` (F,) Hz; for ``free_space`` either ``direction`` and ``polarization``
    (vectors) or ``incidence`` angles (``theta``, ``phi`` in degrees, ``pol`` "TE", "TM"
    or an angle from θ̂ towards φ̂); for ``infinite_array`` the incidence angles, and
    ``interpolate`` (solve at chosen samples and fit the rest, as
    :func:`barymesh.mom.periodic_sweep` does; False solves every frequency).
    """

    kind: str
    frequencies: tuple[float, ...]
    direction: tuple[float, float, float] | None = None
    polarization: tuple[float, float, float] | None = None
    incidence: dict[str, Any] | None = None
    memory_limit: float | None = None
    interpolate: bool = True


@dataclass(frozen=True)
class Derive:
    """One derived figure: ``name`` and, for the ``..._at`` figures, its frequencies (Hz)."""

    name: str
    at: tuple[float, ...] = ()

    @property
    def columns(self) -> tuple[str, ...]:
        """The derived table's columns of this figure."""
        if self.name in FIGURE_COLUMNS:
            return (FIGURE_COLUMNS[self.name],)
        quantity = {
            "extinction_cross_section_at": "extinction_cross_section_m2",
            "reflection_at": "reflection_co_abs",
            "reflection_phase_at": "reflection_co_phase_deg",
        }[self.name]
        return tuple(f"{quantity}_at_{f / 1e9:.6g}GHz" for f in self.at)


def figure_columns(derive: tuple[Derive, ...]) -> tuple[str, ...]:
    """The derived table's figure columns of ``derive``, in order: each figure's, then
    :data:`REFERENCE_PLANE_COLUMN` when a figure depends on the reference plane."""
    columns = tuple(c for d in derive for c in d.columns)
    if any(d.name in PHASE_FIGURES for d in derive):
        columns += (REFERENCE_PLANE_COLUMN,)
    return columns


@dataclass(frozen=True)
class StudySpec:
    """A checked study spec (see :func:`parse_spec`); ``points()`` lists its points.

    ``stack`` is the spec's :class:`~barymesh.mom.Stack` (None: the sheet in vacuum).
    """

    base: Base
    axes: tuple[Axis, ...]
    sample: str | dict[str, int]
    solve: Solve
    derive: tuple[Derive, ...]
    output: str | None
    document: dict[str, Any] = field(repr=False, compare=False, default_factory=dict)
    stack: Stack | None = None

    @property
    def axis_names(self) -> tuple[str, ...]:
        return tuple(a.path for a in self.axes)

    @property
    def derived_columns(self) -> tuple[str, ...]:
        return figure_columns(self.derive)

    @property
    def latin_hypercube(self) -> bool:
        return isinstance(self.sample, dict)

    def points(self) -> list[dict[str, Any]]:
        """Each point's axis values, in order: the product (last axis fastest) or the sample.

        A Latin-hypercube sample (:class:`scipy.stats.qmc.LatinHypercube`, seeded) puts
        each of its N points in its own of N equal slices of every axis.
        """
        names = self.axis_names
        if not self.latin_hypercube:
            combos = itertools.product(*(a.values for a in self.axes))
            return [dict(zip(names, c, strict=True)) for c in combos]
        from scipy.stats import qmc

        assert isinstance(self.sample, dict)
        n, seed = self.sample["latin_hypercube"], self.sample["seed"]
        unit = qmc.LatinHypercube(d=len(self.axes), seed=seed).random(n)
        low = np.array([a.values[0] for a in self.axes], dtype=float)
        high = np.array([a.values[1] for a in self.axes], dtype=float)
        values = qmc.scale(unit, low, high) if len(self.axes) else unit
        return [{k: float(v) for k, v in zip(names, row, strict=True)} for row in values]

    def canonical(self) -> str:
        """The spec as canonical JSON (sorted keys, no ``output``): what :meth:`digest` hashes."""
        doc = {k: v for k, v in self.document.items() if k != "output"}
        return json.dumps(doc, sort_keys=True, separators=(",", ":"), allow_nan=False)

    def digest(self) -> str:
        """16 hex digits of the SHA-256 of :meth:`canonical`: equal specs, equal digests."""
        return hashlib.sha256(self.canonical().encode()).hexdigest()[:16]


# -- parsing ---------------------------------------------------------------------------


def load_spec(source: str | Path | dict[str, Any]) -> StudySpec:
    """Read a spec from a JSON file (or take a dict) and check it (:func:`parse_spec`)."""
    if isinstance(source, dict):
        return parse_spec(source)
    path = Path(source)
    try:
        text = path.read_text(encoding="utf-8")
    except OSError as exc:
        raise SpecError(f"cannot read the study spec {path}: {exc.strerror or exc}") from None
    except UnicodeDecodeError as exc:
        raise SpecError(
            f"{path} is not a study spec: byte {exc.start:,} (0x{exc.object[exc.start]:02x}) is "
            "not UTF-8 text; expected a JSON file"
        ) from None
    try:
        data = json.loads(text)
    except json.JSONDecodeError as exc:
        raise SpecError(f"{path} is not JSON: {exc.msg} at line {exc.lineno}") from None
    except RecursionError:
        raise SpecError(f"{path}: the JSON is nested too deeply to be a study spec") from None
    except ValueError:  # an integer of more digits than Python converts (4,300)
        raise SpecError(
            f"{path}: a number has more digits than a study spec can hold; expected "
            "ordinary numbers (1e300 at most)"
        ) from None
    return parse_spec(data, base_dir=path.parent)


def parse_spec(data: Any, base_dir: str | Path | None = None) -> StudySpec:
    """Check a spec document and return the :class:`StudySpec`.

    Parameters
    ----------
    data : dict
        The parsed JSON document.
    base_dir : path, optional
        Folder that a relative ``base.cell`` path is read from (the spec file's).

    Raises
    ------
    SpecError
        The first problem found, naming its key.
    """
    try:
        return _parse_spec(data, base_dir)
    except RecursionError:
        raise SpecError(
            "study spec: nested too deeply (lists or objects inside each other)"
        ) from None
    except ValueError as exc:  # an integer too long to convert or show, anywhere in the spec
        if isinstance(exc, SpecError) or "digits" not in str(exc):
            raise
        raise SpecError("study spec: a number has more digits than a spec can hold") from None


def _parse_spec(data: Any, base_dir: str | Path | None) -> StudySpec:
    if not isinstance(data, dict):
        raise SpecError(f"study spec: expected a JSON object, got {_kind(data)}")
    unknown = sorted(set(data) - set(SPEC_KEYS))
    if unknown:
        raise _fail(unknown[0], f"unknown key; expected {', '.join(SPEC_KEYS)}")
    for key in ("base", "axes", "solve"):
        if key not in data:
            raise _fail(key, "missing")
    base = _base(data["base"], base_dir)
    sample = _sample(data.get("sample", "product"))
    axes = _axes(data["axes"], sample)
    solve = _solve(data["solve"], axes)
    _check_size(sample, axes, solve)
    stack = _stack(data["stack"], solve) if data.get("stack") is not None else None
    _stack_axes(axes, stack)
    densest = _densest(stack, axes)
    base = _solver_grade(data["base"], base, max(solve.frequencies), base_dir, densest)
    derive = _derive(data.get("derive", ["resonance_frequency", "quality_factor"]), solve)
    output = data.get("output")
    if output is not None and (not isinstance(output, str) or not output.strip()):
        raise _fail("output", f"{_kind(output)}; expected a file name (.parquet or .csv)")
    if output is not None and Path(output).suffix.lower() not in (".parquet", ".csv"):
        raise _fail("output", f"{_short(output)}: expected a .parquet or .csv file")
    if solve.kind == "infinite_array" and base.kind != "cell":
        raise _fail("solve.kind", "infinite_array needs a unit cell: base cell or cell_preset")
    for axis in axes:  # every geometry path must exist in the base
        if not axis.incidence and not axis.layer:
            base.design({axis.path: axis.values[0]})
    document = {
        "base": {"params" if base.kind == "params" else "cell": base.data},
        "axes": {a.path: list(a.values) for a in axes},
        "sample": sample,
        "solve": _solve_document(solve),
        "derive": [{d.name: list(d.at)} if d.at else d.name for d in derive],
        "output": output,
    }
    if stack is not None:  # only when given: a spec without one keeps its digest
        document["stack"] = stack.to_dict()
    document = json.loads(json.dumps(document))  # tuples to lists: the canonical form
    return StudySpec(base, axes, sample, solve, derive, output, document, stack)


def _check_size(sample: str | dict[str, int], axes: tuple[Axis, ...], solve: Solve) -> None:
    """Refuse a study of more points, or rows, than :data:`MAX_POINTS` and :data:`MAX_ROWS`."""
    if isinstance(sample, dict):
        points, key = sample["latin_hypercube"], "sample.latin_hypercube"
    else:
        points, key = math.prod(len(a.values) for a in axes), "axes"
    if points > MAX_POINTS:
        sizes = " x ".join(f"{len(a.values):,}" for a in axes)
        what = f"{points:,} points" if isinstance(sample, dict) else f"{sizes} = {points:,} points"
        raise _fail(key, f"{what}, more than a study takes ({MAX_POINTS:,}); use fewer")
    rows = points * len(solve.frequencies)
    if rows > MAX_ROWS:
        raise _fail(
            "solve.frequencies",
            f"{len(solve.frequencies):,} frequencies at {points:,} points make {rows:,} rows, "
            f"more than a study's table takes ({MAX_ROWS:,}); use fewer",
        )


def _base(raw: Any, base_dir: str | Path | None) -> Base:
    if not isinstance(raw, dict) or len(raw) != 1:
        raise _fail("base", "expected an object with one key: preset, params, cell or cell_preset")
    ((key, value),) = raw.items()
    where = f"base.{key}"
    if key == "preset":
        from ..presets import load_preset, preset_names

        if value not in preset_names():
            raise _fail(where, f"unknown preset {_short(value)}; expected one of {preset_names()}")
        return Base("params", load_preset(value)[0].to_dict())
    if key == "params":
        from ..params import MeshParams

        if not isinstance(value, dict):
            raise _fail(where, f"{_kind(value)}; expected an object of MeshParams fields")
        try:
            return Base("params", MeshParams.from_dict(value).to_dict())
        except (TypeError, ValueError) as exc:
            raise _fail(where, str(exc)) from None
    if key in ("cell", "cell_preset"):
        from ..cell import cell_preset_names, cell_to_dict, load_cell, load_cell_preset

        if key == "cell" and isinstance(value, dict):  # a cell document inline
            from ..cell import cell_from_dict

            try:
                return Base("cell", cell_to_dict(cell_from_dict(value, where)))
            except (TypeError, ValueError) as exc:
                raise _fail(where, str(exc)) from None
        if not isinstance(value, str):
            raise _fail(where, f"{_kind(value)}; expected a name or a path")
        try:
            if key == "cell_preset":
                if value not in cell_preset_names():
                    raise _fail(
                        where, f"unknown cell preset {_short(value)}: {cell_preset_names()}"
                    )
                cell = load_cell_preset(value)
            else:
                path = Path(value)
                if not path.is_absolute() and base_dir is not None:
                    path = Path(base_dir) / path
                cell = load_cell(path)
        except (OSError, ValueError) as exc:
            if isinstance(exc, SpecError):
                raise
            raise _fail(where, str(exc)) from None
        return Base("cell", cell_to_dict(cell))
    raise _fail(f"base.{key}", "unknown key; expected preset, params, cell or cell_preset")


def _densest(stack: Stack | None, axes: tuple[Axis, ...]) -> float:
    """εr μr of the densest layer any point of the study has (1 without a stack)."""
    if stack is None:
        return 1.0
    stacks = [stack]
    for axis in axes:
        if axis.layer:
            side, index, name = layer_field(parse_path(axis.path), stack)
            if name in ("eps_r", "mu_r"):
                stacks += [stack.replaced(f"{side}[{index}].{name}", v) for v in axis.values]
    return max(s.max_index for s in stacks) ** 2


def _solver_grade(
    raw: dict[str, Any], base: Base, top: float, base_dir: Any, densest: float = 1.0
) -> Base:
    """The base made solver-grade (:mod:`barymesh.solver_grade`) for frequencies up to
    ``top`` Hz in a medium of εr μr ``densest``: the parts that do not say ``grading``
    themselves in ``raw`` (the spec's ``base``). The result says ``grading`` for every
    part, so that the canonical spec reads back to itself."""
    from ..solver_grade import document_grading, solver_cell, solver_params

    ((key, value),) = raw.items()
    where = f"base.{key}"
    try:
        if base.kind == "params":
            from ..params import MeshParams
            from ..presets import given_keys

            said = given_keys(value) if key == "preset" else set(value)
            if "grading" in said:
                return base
            params = MeshParams.from_dict(base.data)
            graded = solver_params(params, frequency=top, relative_permittivity=densest)
            return base if graded is params else Base("params", graded.to_dict())
        from ..cell import cell_from_dict, cell_preset_path, cell_to_dict, read_cell_document

        if isinstance(value, dict):
            document = value
        elif key == "cell_preset":
            document = read_cell_document(cell_preset_path(value))
        else:
            path = Path(value)
            if not path.is_absolute() and base_dir is not None:
                path = Path(base_dir) / path
            document = read_cell_document(path)
        flags, pixels = document_grading(document)
        cell = cell_from_dict(base.data, where)
        if len(flags) != len(cell.elements):
            flags = tuple(True for _ in cell.elements)
        graded_cell = solver_cell(
            cell,
            frequency=top,
            relative_permittivity=densest,
            grade=flags,
            grade_pixels=pixels,
        )
        data = cell_to_dict(graded_cell)
        if graded_cell.pixels is not None:  # said, so that the canonical spec keeps it
            data["pixels"]["grading"] = graded_cell.pixels.grading
        return Base("cell", data)
    except (OSError, TypeError, ValueError) as exc:
        if isinstance(exc, SpecError):
            raise
        raise _fail(where, f"the solver-grade mesh: {exc}") from None


def _sample(raw: Any) -> str | dict[str, int]:
    if raw == "product":
        return "product"
    if isinstance(raw, dict) and "latin_hypercube" in raw:
        extra = sorted(set(raw) - {"latin_hypercube", "seed"})
        if extra:
            raise _fail(f"sample.{extra[0]}", "unknown key; expected latin_hypercube, seed")
        n, seed = raw["latin_hypercube"], raw.get("seed", 0)
        for key, v, low, high in (("latin_hypercube", n, 1, MAX_POINTS), ("seed", seed, 0, None)):
            if isinstance(v, bool) or not isinstance(v, int) or v < low:
                raise _fail(f"sample.{key}", f"{_short(v)}; expected a whole number >= {low}")
            if high is not None and v > high:
                raise _fail(
                    f"sample.{key}", f"{v:,} points, more than a study takes ({high:,}); use fewer"
                )
        return {"latin_hypercube": n, "seed": seed}
    raise _fail("sample", f'{raw!r:.60}; expected "product" or {{"latin_hypercube": N, "seed": S}}')


def _axes(raw: Any, sample: str | dict[str, int]) -> tuple[Axis, ...]:
    if not isinstance(raw, dict):
        raise _fail("axes", f"{_kind(raw)}; expected an object of parameter paths to values")
    axes = []
    for path, values in raw.items():
        key = f"axes.{path}"
        tokens = parse_path(path)
        if tokens[0] == "incidence" and (len(tokens) != 2 or tokens[1] not in INCIDENCE_KEYS):
            raise _fail(key, f"expected incidence.{', incidence.'.join(INCIDENCE_KEYS)}")
        if isinstance(sample, dict):
            if not isinstance(values, list) or len(values) != 2:
                raise _fail(key, "a Latin-hypercube axis is [low, high]")
            low, high = (_number(key, v) for v in values)
            if not low < high:
                raise _fail(key, f"[{low:g}, {high:g}]: expected low < high")
            axes.append(Axis(path, (low, high)))
            continue
        if isinstance(values, dict):
            values = _range(key, values)
        if not isinstance(values, list) or not values:
            raise _fail(key, f"{_kind(values)}; expected a non-empty list of values or a range")
        for v in values:
            if isinstance(v, dict | list) or v is None:
                raise _fail(key, f"{_kind(v)} in the list; expected numbers or strings")
            if isinstance(v, float) and not math.isfinite(v):
                raise _fail(key, f"{_short(v)} in the list is not finite; expected numbers")
            if isinstance(v, int) and not isinstance(v, bool) and abs(v) > 1e300:
                raise _fail(key, f"{_short(v)} in the list is too large; expected numbers")
        if len({json.dumps(v) for v in values}) != len(values):
            raise _fail(key, "a value is listed twice")
        axes.append(Axis(path, tuple(values)))
    return tuple(axes)


def _range(key: str, raw: dict[str, Any]) -> list[float]:
    if set(raw) != {"start", "stop", "num"}:
        raise _fail(key, 'a range is {"start": A, "stop": B, "num": K}')
    a, b = _number(f"{key}.start", raw["start"]), _number(f"{key}.stop", raw["stop"])
    k = raw["num"]
    if isinstance(k, bool) or not isinstance(k, int) or k < 1:
        raise _fail(f"{key}.num", f"{_short(k)}; expected a whole number >= 1")
    if k > MAX_POINTS:
        raise _fail(f"{key}.num", f"{k:,} values, more than a study takes ({MAX_POINTS:,})")
    return [float(v) for v in np.linspace(a, b, k)]


def _vector(key: str, raw: Any) -> tuple[float, float, float]:
    if not isinstance(raw, list) or len(raw) != 3:
        raise _fail(key, f"{raw!r:.40}; expected [x, y, z]")
    return tuple(_number(key, v) for v in raw)  # type: ignore[return-value]


def _solve(raw: Any, axes: tuple[Axis, ...]) -> Solve:
    if not isinstance(raw, dict):
        raise _fail("solve", f"{_kind(raw)}; expected an object with kind and frequencies")
    kind = raw.get("kind")
    if kind not in SOLVE_KINDS:
        raise _fail("solve.kind", f"{_short(kind)}; expected one of {', '.join(SOLVE_KINDS)}")
    known = {"kind", "frequencies", "memory_limit", *INCIDENCE_KEYS}
    if kind == "free_space":
        known |= {"direction", "polarization"}
    else:
        known |= {"interpolate"}
    extra = sorted(set(raw) - known)
    if extra:
        raise _fail(f"solve.{extra[0]}", f"unknown key for {kind}; expected {sorted(known)}")
    if "frequencies" not in raw:
        raise _fail("solve.frequencies", "missing")
    freqs = raw["frequencies"]
    try:
        if isinstance(freqs, str):
            values = parse_frequencies(freqs, "solve.frequencies")
        elif isinstance(freqs, list) and freqs:
            values = [
                parse_frequency(f, "solve.frequencies")
                if isinstance(f, str)
                else _number("solve.frequencies", f)
                for f in freqs
            ]
        else:
            raise _fail("solve.frequencies", f"{freqs!r:.40}; expected 'A:B:K' or a list")
    except SpecError:
        raise
    except ValueError as exc:
        raise _fail("solve.frequencies", str(exc)) from None
    if min(values) <= 0 or any(b <= a for a, b in itertools.pairwise(values)):
        raise _fail("solve.frequencies", "expected positive frequencies in increasing order")
    memory = raw.get("memory_limit")
    if memory is not None and not _number("solve.memory_limit", memory) > 0:
        raise _fail("solve.memory_limit", f"{_short(memory)}; expected bytes > 0")
    interpolate = raw.get("interpolate", True)
    if not isinstance(interpolate, bool):
        raise _fail("solve.interpolate", f"{_short(interpolate)}; expected true or false")
    angles = {k: raw[k] for k in INCIDENCE_KEYS if k in raw}
    vectors = {k: raw[k] for k in ("direction", "polarization") if k in raw}
    varied = [a for a in axes if a.incidence]
    if angles and vectors:
        raise _fail("solve", "give the incidence as direction/polarization or theta/phi/pol")
    if varied and vectors:
        raise _fail(varied[0].path, "an incidence axis needs solve.theta/phi/pol, not vectors")
    incidence = None
    direction = polarization = None
    if vectors:
        direction = _vector("solve.direction", vectors.get("direction", [0, 0, -1]))
        polarization = _vector("solve.polarization", vectors.get("polarization", [1, 0, 0]))
        plane_wave({"direction": direction, "polarization": polarization}, "solve")
    else:
        incidence = {"theta": 0.0, "phi": 0.0, "pol": "TM", **angles}
        for a in varied:  # each value must make a wave
            for v in a.values:
                plane_wave({**incidence, a.path.split(".")[1]: v}, a.path)
        plane_wave(incidence, "solve")
    return Solve(kind, tuple(values), direction, polarization, incidence, memory, interpolate)


def _stack(raw: Any, solve: Solve) -> Stack:
    """The spec's ``stack``: the command line's text or :meth:`Stack.to_dict`'s mapping."""
    if solve.kind != "infinite_array":
        raise _fail("stack", "layers need solve.kind infinite_array (free space has none)")
    try:
        return study_stack(raw)
    except (TypeError, ValueError) as exc:
        raise _fail("stack", str(exc)) from None


def _stack_axes(axes: tuple[Axis, ...], stack: Stack | None) -> None:
    """Check each ``stack.…`` axis: its layer and field exist and each value (a product's
    values, a Latin hypercube's ends) makes a valid stack."""
    for axis in axes:
        if not axis.layer:
            continue
        key = f"axes.{axis.path}"
        try:
            side, index, name = layer_field(parse_path(axis.path), stack)
        except ValueError as exc:
            raise _fail(key, str(exc)) from None
        assert stack is not None  # layer_field refuses a path into no stack
        for value in axis.values:
            if isinstance(value, bool) or not isinstance(value, int | float):
                raise _fail(key, f"{_kind(value)} {value!r:.40}; expected a number")
            try:
                stack.replaced(f"{side}[{index}].{name}", value)
            except (TypeError, ValueError) as exc:
                raise _fail(key, f"{_short(value)} makes the stack invalid: {exc}") from None


def _solve_document(solve: Solve) -> dict[str, Any]:
    """The solve settings as the spec writes them (what ``_solve`` reads back)."""
    doc: dict[str, Any] = {"kind": solve.kind, "frequencies": list(solve.frequencies)}
    if solve.memory_limit is not None:
        doc["memory_limit"] = solve.memory_limit
    if solve.kind == "infinite_array":
        doc["interpolate"] = solve.interpolate
    if solve.direction is not None:
        doc.update(direction=solve.direction, polarization=solve.polarization)
    else:
        doc.update(solve.incidence or {})
    return doc


def incidence_angle(pol: Any, where: str) -> float:
    """``pol`` "TM" (E along θ̂: 0), "TE" (E along φ̂: 90) or an angle in degrees."""
    if isinstance(pol, str) and pol.upper() in ("TE", "TM"):
        return 90.0 if pol.upper() == "TE" else 0.0
    if isinstance(pol, bool) or not isinstance(pol, int | float) or not math.isfinite(pol):
        raise _fail(where, f"pol={_short(pol)}; expected TE, TM or an angle in degrees")
    return float(pol)


def plane_wave(incidence: dict[str, Any], where: str) -> Any:
    """The :class:`~barymesh.mom.PlaneWave` of ``incidence``: ``direction`` and
    ``polarization`` vectors, or ``theta``, ``phi`` and ``pol``; a bad one is a
    :class:`SpecError` naming ``where``."""
    from ..mom.excitation import PlaneWave

    try:
        if "direction" in incidence:
            return PlaneWave(incidence["direction"], incidence["polarization"])
        theta = _number(f"{where}.theta", incidence["theta"])
        phi = _number(f"{where}.phi", incidence["phi"])
        if not 0 <= theta < 90:
            raise _fail(where, f"theta={theta:g}; expected 0 <= theta < 90 degrees")
        return PlaneWave.from_angles(theta, phi, incidence_angle(incidence["pol"], where))
    except SpecError:
        raise
    except (TypeError, ValueError) as exc:
        raise _fail(where, str(exc)) from None


def _derive(raw: Any, solve: Solve) -> tuple[Derive, ...]:
    if not isinstance(raw, list):
        raise _fail("derive", f"{_kind(raw)}; expected a list of figures")
    out = []
    for i, item in enumerate(raw):
        key = f"derive[{i}]"
        if isinstance(item, str):
            if item not in FIGURES:
                raise _fail(key, f"unknown figure {_short(item)}; expected {', '.join(FIGURES)}")
            if item in INFINITE_ARRAY_FIGURES and solve.kind != "infinite_array":
                raise _fail(key, f"{item} needs solve.kind infinite_array")
            out.append(Derive(item))
            continue
        if not isinstance(item, dict) or len(item) != 1 or next(iter(item)) not in FIGURES_AT:
            raise _fail(key, f'expected a figure name or {{"{FIGURES_AT[0]}": [frequencies]}}')
        ((name, freqs),) = item.items()
        if name in INFINITE_ARRAY_FIGURES and solve.kind != "infinite_array":
            raise _fail(key, f"{name} needs solve.kind infinite_array")
        if name == "extinction_cross_section_at" and solve.kind != "free_space":
            raise _fail(key, "extinction_cross_section_at needs solve.kind free_space")
        if not isinstance(freqs, list) or not freqs:
            raise _fail(f"{key}.{name}", "expected a list of frequencies")
        try:
            at = tuple(
                parse_frequency(f, f"{key}.{name}")
                if isinstance(f, str)
                else _number(f"{key}.{name}", f)
                for f in freqs
            )
        except SpecError:
            raise
        except ValueError as exc:
            raise _fail(f"{key}.{name}", str(exc)) from None
        lo, hi = solve.frequencies[0], solve.frequencies[-1]
        outside = [f for f in at if not lo <= f <= hi]
        if outside:
            raise _fail(
                f"{key}.{name}",
                f"{outside[0] / 1e9:g} GHz is outside the solved {lo / 1e9:g}-{hi / 1e9:g} GHz",
            )
        out.append(Derive(name, at))
    columns = [c for d in out for c in d.columns]
    if len(set(columns)) != len(columns):
        raise _fail("derive", "a figure is asked for twice")
    return tuple(out)
