"""Design studies: parameter × frequency sweeps of a cell, one Dask task per point.

A spec (JSON, :mod:`.spec`) names a base design, axes of parameter paths and their values
(a product or a Latin-hypercube sample), the solve and the figures to derive;
:func:`run` runs it on a Dask cluster (:mod:`.run`), writing each finished point as it
comes so that a rerun goes on where the last one stopped, and returns a
:class:`StudyResult` (:mod:`.results`): a per-frequency table and a derived table
(pandas), Parquet or CSV files, and an xarray Dataset.

Needs the ``study`` extra (``pip install 'barymesh[study]'``: dask, distributed, pandas,
pyarrow, xarray, and bokeh for the Dask dashboard); nothing else in barymesh imports Dask.

>>> from barymesh.study import parse_spec, run_serial
>>> spec = parse_spec({"base": {"params": {"structure": "patch", "patch_size": 15.0,
...                                        "subdivisions": 2}},
...                    "axes": {"patch_size": [14.0, 15.0]},
...                    "solve": {"kind": "free_space", "frequencies": "6GHz:11GHz:11"}})
>>> result = run_serial(spec)
>>> list(result.derived.columns)
['patch_size', 'status', 'resonance_frequency_hz', 'quality_factor', 'warnings']
>>> bool(result.derived.resonance_frequency_hz.is_monotonic_decreasing)
True
"""

from __future__ import annotations

import sys
from importlib import import_module
from types import ModuleType
from typing import TYPE_CHECKING, Any

if TYPE_CHECKING:
    from .point import PointResult, StudyContext
    from .results import StudyResult, read_result
    from .run import Progress, run, run_serial
    from .spec import SpecError, StudySpec, load_spec, parse_spec

#: Each public name and the module it comes from. They are imported when first asked for:
#: the results and the runs import pandas, which :mod:`.spec` and :mod:`.point` (what
#: :func:`barymesh.mom.reflection_library` solves its points with) do without.
_NAMES = {
    "PointResult": "point",
    "StudyContext": "point",
    "StudyResult": "results",
    "read_result": "results",
    "Progress": "run",
    "run": "run",
    "run_serial": "run",
    "SpecError": "spec",
    "StudySpec": "spec",
    "load_spec": "spec",
    "parse_spec": "spec",
}


def __getattr__(name: str) -> Any:
    if name not in _NAMES:
        raise AttributeError(f"module {__name__!r} has no attribute {name!r}")
    value = getattr(import_module(f".{_NAMES[name]}", __name__), name)
    globals()[name] = value
    return value


class _Package(ModuleType):
    """This package, whose ``run`` stays the function :func:`.run.run`: importing the
    submodule ``barymesh.study.run`` (a Dask worker unpickling a task, ``from
    barymesh.study.run import ...``) binds the package's attribute of that name to the
    module, which an eager import of the function used to overwrite at once."""

    def __setattr__(self, name: str, value: Any) -> None:
        if name in _NAMES and isinstance(value, ModuleType):
            value = getattr(value, name)
        super().__setattr__(name, value)


sys.modules[__name__].__class__ = _Package


__all__ = [
    "PointResult",
    "Progress",
    "SpecError",
    "StudyContext",
    "StudyResult",
    "StudySpec",
    "load_spec",
    "parse_spec",
    "read_result",
    "run",
    "run_serial",
]
