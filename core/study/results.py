"""A study's results: two tidy tables, their files, and an xarray Dataset for plotting.

The per-frequency table has one row per point and frequency: one column per axis, then
``frequency_hz``, then the solve's columns as ``barymesh solve -o x.csv`` names them.
The derived table has one row per point: the axes, ``status`` (``ok`` or the one-line
error), one column per derived figure and ``warnings`` (the point's warnings, one
"kind: text" sentence a line; "" when there are none). Both are indexed by ``point`` (the point's
number in :meth:`barymesh.study.spec.StudySpec.points`), which the files keep.

Files: ``study.parquet`` (or ``.csv``) and ``study.derived.parquet`` beside it, and
``study.meta.json`` with the spec, the package versions and the machine. While a study
runs, each finished point is one Parquet file in ``study.parquet.parts/<digest>/``
(:func:`write_part`), which a rerun of the same spec reads back instead of solving again.
"""

from __future__ import annotations

import json
import os
import platform
import re
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np
import pandas as pd

from .point import PointResult, solve_columns
from .spec import StudySpec

#: Schema metadata key of a part file that holds the point's derived row (JSON).
PART_KEY = b"barymesh.study.point"
#: The derived table's column of each point's warnings: one sentence a line.
WARNINGS_COLUMN = "warnings"

#: Units of the table columns by the suffix of their name (the CF conventions' UDUNITS
#: spelling, which xarray's unit-aware libraries read); a column without one is a ratio.
COLUMN_UNITS = {"_hz": "Hz", "_m2": "m2", "_ohm": "ohm"}
#: Units of the parameters an axis may vary (the last name of its path): MeshParams and
#: cell fields are in mm and degrees, the incidence's angles in degrees.
AXIS_UNITS = {
    **dict.fromkeys(
        (
            "inner_radius",
            "outer_radius",
            "patch_size",
            "patch_width",
            "gap_width",
            "origin",
            "tolerance",
            "max_edge",
            "min_edge",
            "position",
            "pixel_size",
            "a1",
            "a2",
        ),
        "mm",
    ),
    **dict.fromkeys(("angle_step", "gap_angle", "rotation", "theta", "phi"), "degree"),
    "frequency": "Hz",
}


def column_units(name: str) -> str:
    """The unit of a table column (``"Hz"``, ``"m2"``, ``"ohm"``), ``"1"`` for a ratio.

    >>> column_units("resonance_frequency_hz"), column_units("extinction_cross_section_m2_at_9GHz")
    ('Hz', 'm2')
    >>> column_units("quality_factor")
    '1'
    """
    base = name.split("_at_", 1)[0]
    return next((u for suffix, u in COLUMN_UNITS.items() if base.endswith(suffix)), "1")


def axis_units(path: str) -> str | None:
    """The unit of an axis (``"elements[1].gap_width"`` -> ``"mm"``); None where it has none.

    >>> axis_units("elements[1].gap_width"), axis_units("incidence.theta"), axis_units("mode")
    ('mm', 'degree', None)
    """
    name = re.sub(r"\[\d+\]", "", path).rsplit(".", 1)[-1]
    return AXIS_UNITS.get(name)


@dataclass(frozen=True, eq=False)
class StudyResult:
    """The tables of a study (pandas DataFrames indexed by ``point``).

    Attributes
    ----------
    spec : StudySpec
    table : DataFrame
        One row per point and frequency (ok points only).
    derived : DataFrame
        One row per point: axes, ``status``, figures, ``warnings``.
    meta : dict
        Spec, digest, package versions, machine, and the run's counts: ``computed``
        (points solved by this run), ``resumed`` (read back from the parts of an earlier
        run), ``refused`` (error rows found before submission); the workers:
        ``workers`` (how many solved points in this run, from the scheduler's task
        stream), ``worker_points`` (each one's address and the points it solved),
        ``workers_at_start`` and ``workers_at_end`` (connected to the scheduler then).
    """

    spec: StudySpec
    table: pd.DataFrame
    derived: pd.DataFrame
    meta: dict[str, Any] = field(default_factory=dict)

    @property
    def computed(self) -> int:
        """Points this run solved (not read back from an earlier run's parts)."""
        return int(self.meta.get("computed", 0))

    @property
    def failed(self) -> pd.DataFrame:
        """The error rows of :attr:`derived`."""
        return self.derived[self.derived["status"] != "ok"]

    def warning_kinds(self) -> dict[str, list[int]]:
        """The points of each kind of warning ("near an onset", "coarse mesh", "zero
        phase", …: the text before the first colon), kinds in order of first appearance."""
        out: dict[str, list[int]] = {}
        for point, text in self.derived[WARNINGS_COLUMN].items():
            for kind in dict.fromkeys(w.split(":", 1)[0] for w in str(text).splitlines()):
                out.setdefault(kind, []).append(int(point))
        return out

    def to_xarray(self) -> Any:
        """An xarray Dataset: the per-frequency columns and the derived figures.

        A product sample has the axes and ``frequency_hz`` as dimensions, with the axis
        values as coordinates; a Latin-hypercube sample has the dimensions ``point`` and
        ``frequency_hz``, with each axis a coordinate along ``point``. Error points are
        NaN; ``status`` is a string variable over the points. Every number carries its
        ``units`` attribute (:func:`column_units`, :func:`axis_units`: ``"Hz"``,
        ``"m2"``, ``"ohm"``, ``"mm"``, ``"degree"``, ``"1"`` for a ratio), as the CF
        conventions spell them, so plots label their axes and pint-xarray can read them.
        """
        import xarray as xr

        axes = list(self.spec.axis_names)
        freqs = np.asarray(self.spec.solve.frequencies)
        table = self.table.drop(columns=axes)
        derived = self.derived.drop(columns=axes)
        points = self.spec.points()
        index = pd.RangeIndex(len(points), name="point")
        per_point = derived.reindex(index)
        per_point["status"] = per_point["status"].fillna("not run")
        per_point[WARNINGS_COLUMN] = per_point[WARNINGS_COLUMN].fillna("")
        full = pd.MultiIndex.from_product([index, freqs], names=["point", "frequency_hz"])
        per_freq = table.set_index("frequency_hz", append=True).reindex(full)
        ds = xr.Dataset(
            {
                **{
                    c: (("point", "frequency_hz"), per_freq[c].to_numpy().reshape(len(index), -1))
                    for c in per_freq.columns
                },
                **{c: (("point",), per_point[c].to_numpy()) for c in per_point.columns},
            },
            coords={
                "point": index.to_numpy(),
                "frequency_hz": freqs,
                **{a: ("point", [p[a] for p in points]) for a in axes},
            },
            attrs={"spec": self.spec.canonical(), "digest": self.spec.digest()},
        )
        if self.spec.latin_hypercube or not axes:
            return _with_units(ds)
        shape = [len(a.values) for a in self.spec.axes]
        out = xr.Dataset(
            {
                name: (
                    (*axes, *var.dims[1:]),
                    var.to_numpy().reshape(*shape, *var.shape[1:]),
                )
                for name, var in ds.data_vars.items()
            },
            coords={
                "frequency_hz": freqs,
                **{a.path: list(a.values) for a in self.spec.axes},
            },
            attrs=ds.attrs,
        )
        return _with_units(out)

    def write(self, output: str | Path) -> list[Path]:
        """Write the tables (Parquet or CSV by ``output``'s extension) and the meta JSON.

        Returns the files written: ``output``, ``<stem>.derived<ext>``, ``<stem>.meta.json``.
        """
        from ..io import atomic_path, atomic_write_text

        out = Path(output)
        paths = output_paths(out)
        for frame, path in ((self.table, paths[0]), (self.derived, paths[1])):
            with atomic_path(path) as tmp:
                if out.suffix.lower() == ".csv":
                    frame.to_csv(tmp, float_format="%.17g")
                else:
                    frame.to_parquet(tmp, engine="pyarrow")
        atomic_write_text(paths[2], json.dumps(self.meta, indent=2, default=str) + "\n")
        return paths


def _with_units(ds: Any) -> Any:
    """``ds`` with a ``units`` attribute on every numeric variable and coordinate."""
    for name in [*ds.data_vars, *ds.coords]:
        var = ds[name]
        if var.dtype.kind not in "fiuc":
            continue
        if name in ds.data_vars or name == "frequency_hz":
            unit: str | None = column_units(str(name))
        else:
            unit = axis_units(str(name)) if name != "point" else None
        if unit is not None:
            var.attrs["units"] = unit
    return ds


def library_dataset(lib: Any) -> Any:
    """A :class:`~barymesh.mom.ReflectionLibrary` as an xarray Dataset
    (:meth:`~barymesh.mom.ReflectionLibrary.to_xarray`; here, with the study's other
    Datasets, so that xarray is imported by the study package alone)."""
    try:
        import xarray as xr
    except ImportError:
        raise ImportError(
            "ReflectionLibrary.to_xarray needs xarray: pip install 'barymesh[study]'"
        ) from None
    dims = ("value", "frequency")
    return xr.Dataset(
        {
            "reflection": ((*dims, "out", "in"), lib.reflection),
            "phase_deg": (dims, lib.phase_deg, {"units": "degree"}),
            "magnitude": (dims, lib.magnitude),
        },
        coords={
            "value": ("value", lib.values, {"long_name": lib.parameter}),
            "frequency": ("frequency", lib.frequencies, {"units": "Hz"}),
            "out": ["TE", "TM"],  # the order of the 2 × 2 (barymesh.mom.reflection_library)
            "in": ["TE", "TM"],
        },
        attrs={
            "parameter": lib.parameter,
            "polarization": lib.polarization,
            "reference_plane_mm": lib.reference_plane,
            "stack": lib.stack.describe() if lib.stack is not None else "",
        },
    )


def output_paths(output: str | Path) -> list[Path]:
    """``study.parquet`` -> [study.parquet, study.derived.parquet, study.meta.json]."""
    out = Path(output)
    return [out, out.with_name(f"{out.stem}.derived{out.suffix}"), out.with_suffix(".meta.json")]


def read_result(output: str | Path) -> StudyResult:
    """Read the files :meth:`StudyResult.write` wrote back into a :class:`StudyResult`."""
    from .spec import parse_spec

    paths = output_paths(output)
    meta = json.loads(paths[2].read_text(encoding="utf-8"))
    spec = parse_spec(meta["spec"])
    if Path(output).suffix.lower() == ".csv":
        table = pd.read_csv(paths[0], index_col="point")
        table = table.astype(dict.fromkeys(solve_columns(spec.solve.kind), float))
        derived = pd.read_csv(paths[1], index_col="point", keep_default_na=False)
        for c in spec.derived_columns:
            derived[c] = pd.to_numeric(derived[c]).astype(float)
        for axis in spec.axes:  # CSV writes 14.0 as 14: the spec's values give the type
            if any(isinstance(v, float) for v in axis.values):
                for frame in (table, derived):
                    frame[axis.path] = frame[axis.path].astype(float)
    else:
        table = pd.read_parquet(paths[0], engine="pyarrow")
        derived = pd.read_parquet(paths[1], engine="pyarrow")
    return StudyResult(spec, table, derived, meta)


# -- assembling ------------------------------------------------------------------------


def tables(spec: StudySpec, points: list[PointResult]) -> tuple[pd.DataFrame, pd.DataFrame]:
    """The per-frequency and derived tables of finished points, in point order."""
    axes = list(spec.axis_names)
    figures = list(spec.derived_columns)
    points = sorted(points, key=lambda p: p.index)
    frames = []
    columns = list(solve_columns(spec.solve.kind))
    for p in points:
        if p.status != "ok":
            continue
        n = len(p.table["frequency_hz"])
        frame = pd.DataFrame(
            {
                **{a: np.repeat(np.asarray([p.values[a]]), n) for a in axes},
                **{c: p.table[c] for c in columns},
            },
            index=pd.Index(np.full(n, p.index, dtype=np.int64), name="point"),
        )
        frames.append(frame)
    if frames:
        table = pd.concat(frames)
    else:
        table = pd.DataFrame(
            columns=axes + columns, index=pd.Index([], name="point", dtype="int64")
        )
        table = table.astype(dict.fromkeys(columns, float))
    derived = pd.DataFrame(
        [
            [p.values[a] for a in axes]
            + [p.status]
            + [float(p.derived[c]) for c in figures]
            + ["\n".join(p.warnings)]
            for p in points
        ],
        columns=axes + ["status"] + figures + [WARNINGS_COLUMN],
        index=pd.Index([p.index for p in points], name="point", dtype="int64"),
    )
    derived = derived.astype({"status": str, **dict.fromkeys(figures, float), WARNINGS_COLUMN: str})
    return table, derived


def machine() -> dict[str, Any]:
    """The machine a study ran from: host, platform, Python, cores, memory."""
    from ..mom.solve import available_memory

    return {
        "host": platform.node(),
        "platform": platform.platform(),
        "python": platform.python_version(),
        "cpu_count": os.cpu_count(),
        "memory_available_bytes": available_memory(),
    }


def versions() -> dict[str, str]:
    """Versions of barymesh and the packages a study runs on (missing ones left out)."""
    from importlib import metadata

    out = {}
    for name in (
        "barymesh",
        "numpy",
        "scipy",
        "pandas",
        "pyarrow",
        "xarray",
        "dask",
        "distributed",
    ):
        try:
            out[name] = metadata.version(name)
        except metadata.PackageNotFoundError:
            pass
    return out


# -- part files ------------------------------------------------------------------------


def parts_folder(spec: StudySpec, output: str | Path) -> Path:
    """``<output>.parts/<digest>/``: the part files of this spec (another spec, another folder)."""
    return Path(f"{output}.parts") / spec.digest()


def write_part(folder: Path, point: PointResult) -> Path:
    """Write one finished point as ``point-<index>.parquet`` (atomically: whole or absent).

    Its rows are the per-frequency columns; the point's values, status, derived figures
    and unknowns are JSON in the schema metadata.
    """
    import pyarrow as pa
    import pyarrow.parquet as pq

    folder.mkdir(parents=True, exist_ok=True)
    table = pa.table({k: np.asarray(v, dtype=float) for k, v in point.table.items()})
    record = {
        "index": point.index,
        "values": point.values,
        "status": point.status,
        "derived": point.derived,
        "unknowns": point.unknowns,
        "warnings": list(point.warnings),
    }
    table = table.replace_schema_metadata({PART_KEY: json.dumps(record).encode()})
    path = folder / f"point-{point.index:07d}.parquet"
    tmp = path.with_name(f".{path.name}.{os.getpid()}.tmp")
    pq.write_table(table, tmp)
    os.replace(tmp, path)
    return path


def read_parts(folder: Path, columns: tuple[str, ...] = ()) -> dict[int, PointResult]:
    """The finished points in ``folder`` by index.

    Unreadable files are ignored (redone), and so are solved points that lack one of the
    per-frequency ``columns`` (written by an older barymesh: solving them again gives
    the column). A part written before points kept their warnings has none.
    """
    import pyarrow.parquet as pq

    out: dict[int, PointResult] = {}
    if not folder.is_dir():
        return out
    for path in sorted(folder.glob("point-*.parquet")):
        try:
            table = pq.read_table(path)
            record = json.loads(table.schema.metadata[PART_KEY])
        except (OSError, KeyError, ValueError, TypeError):
            continue
        if record["status"] == "ok" and not set(columns) <= set(table.column_names):
            continue
        out[int(record["index"])] = PointResult(
            int(record["index"]),
            record["values"],
            record["status"],
            {name: table.column(name).to_numpy() for name in table.column_names},
            {k: float("nan") if v is None else float(v) for k, v in record["derived"].items()},
            int(record["unknowns"]),
            tuple(record.get("warnings", ())),
        )
    return out
