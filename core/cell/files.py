"""Unit cells as JSON files (``*.cell.json``) and the shipped cell presets.

A cell file is one JSON object::

    {
      "format": "barymesh-cell", "version": 1,
      "name": "double-ring-patch", "description": "...",
      "mode": "paper", "tolerance": null,
      "lattice": {"rectangular": [20, 20]},      (or {"hexagonal": 12} or {"a1": [..], "a2": [..]})
      "elements": [
        {"name": "rings", "position": [0, 0], "rotation": 0,
         "structure": "double_ring", "inner_radius": 5, ...},   (any MeshParams field)
        ...
      ],
      "pixels": {"pixel_size": 0.5, "origin": [-4, -4], "subdivisions": 4,
                 "rows": ["0110", "1001", ...]}                  (top row first, as drawn)
    }

Errors name the place in the document, e.g. ``elements[2].inner_radius``.
"""

from __future__ import annotations

import json
from pathlib import Path
from typing import Any

import numpy as np

from ..params import MODES, MeshParams
from ..presets import ASSET_DIR, read_json_file
from ..values import InvalidValue, echo, expected_names, kind
from .model import Element, Lattice, PixelGrid, UnitCell

FORMAT = "barymesh-cell"
VERSION = 1
SUFFIX = ".cell.json"
#: Folder of the shipped cell presets.
CELL_PRESET_DIR = ASSET_DIR / "cells"

_ELEMENT_KEYS = ("name", "position", "rotation")
_PIXEL_KEYS = ("rows", "pixel_size", "origin", "subdivisions", "scheme", "diagonal", "grading")
_TOP_KEYS = (
    "format",
    "version",
    "name",
    "description",
    "mode",
    "tolerance",
    "lattice",
    "elements",
    "pixels",
)


class CellFileError(ValueError):
    """A cell document is invalid; the message names the file and the path in it."""


def _fail(where: str, message: str) -> CellFileError:
    return CellFileError(f"{where}: {message}")


def _unknown(data: dict[str, Any], known: tuple[str, ...] | set[str], where: str) -> None:
    extra = sorted(set(data) - set(known))
    if extra:
        prefix = f"{where}." if where else ""
        raise _fail(
            f"{prefix}{extra[0] if len(extra[0]) <= 40 else echo(extra[0])}",
            f"unknown key; {expected_names(extra[0], known)}",
        )


def _field_error(exc: Exception, where: str, fields: set[str]) -> CellFileError:
    """Prefix a validation error with the document path of the field it names."""
    field = exc.field if isinstance(exc, InvalidValue) else None
    path = f"{where}.{field}" if field in fields else where
    return _fail(path, str(exc))


# -- dict <-> cell ------------------------------------------------------------


def cell_to_dict(cell: UnitCell) -> dict[str, Any]:
    """The JSON-ready document of ``cell`` (see the module docstring)."""
    lat = cell.lattice
    if lat.kind == "rectangular":
        lattice: dict[str, Any] = {"rectangular": [lat.a1[0], lat.a2[1]]}
    elif lat.kind == "hexagonal":
        lattice = {"hexagonal": lat.a1[0]}
    else:
        lattice = {"a1": list(lat.a1), "a2": list(lat.a2)}
    elements = []
    for el in cell.elements:
        params = el.params.to_dict()
        params.pop("mode")  # the cell's
        elements.append(
            {"name": el.name, "position": list(el.position), "rotation": el.rotation, **params}
        )
    pixels = None
    if cell.pixels is not None:
        g = cell.pixels
        pixels = {
            "pixel_size": g.pixel_size,
            "origin": list(g.origin),
            "subdivisions": g.subdivisions,
            "scheme": g.scheme,
            "diagonal": g.diagonal,
            "rows": ["".join("1" if v else "0" for v in row) for row in g.mask[::-1]],
        }
        if g.grading:  # written only when set: files of ungraded grids stay as they were
            pixels["grading"] = True
    return {
        "format": FORMAT,
        "version": VERSION,
        "name": cell.name,
        "description": cell.description,
        "mode": cell.mode,
        "tolerance": cell.tolerance,
        "lattice": lattice,
        "elements": elements,
        "pixels": pixels,
    }


def cell_from_dict(data: Any, source: str = "cell") -> UnitCell:
    """Validate a document into a :class:`UnitCell`; errors name ``source`` and the path."""
    try:
        return _cell_from_dict(data)
    except CellFileError as exc:
        raise CellFileError(f"{source}: {exc}") from None


def _cell_from_dict(data: Any) -> UnitCell:
    if not isinstance(data, dict):
        raise _fail("document", f"expected a JSON object, got {kind(data)}")
    _unknown(data, _TOP_KEYS, "")
    if data.get("format", FORMAT) != FORMAT:
        raise _fail("format", f"{echo(data['format'])} is not a cell file; expected {FORMAT!r}")
    version = data.get("version")
    if version != VERSION:
        raise _fail("version", f"{echo(version)} is not supported; expected {VERSION}")
    mode = data.get("mode", "paper")
    if not isinstance(mode, str) or mode not in MODES:
        raise _fail("mode", f"{echo(mode)} is unknown; expected one of {', '.join(MODES)}")
    lattice = _lattice(data.get("lattice"))
    raw_elements = data.get("elements", [])
    if not isinstance(raw_elements, list):
        raise _fail("elements", f"expected a list of elements, got {kind(raw_elements)}")
    elements = tuple(_element(e, f"elements[{k}]", mode) for k, e in enumerate(raw_elements))
    pixels = None if data.get("pixels") is None else _pixels(data["pixels"])
    for key in ("name", "description"):
        if not isinstance(data.get(key, ""), str):
            raise _fail(key, f"{echo(data[key])} is not a string")
    try:
        return UnitCell(
            lattice=lattice,
            elements=elements,
            pixels=pixels,
            mode=mode,
            tolerance=data.get("tolerance"),
            name=data.get("name", "cell"),
            description=data.get("description", ""),
        )
    except (ValueError, TypeError) as exc:
        # the field named, a parameter or a path such as elements[2].position
        field = exc.field if isinstance(exc, InvalidValue) else "document"
        raise _fail(field, str(exc)) from None


def _lattice(raw: Any) -> Lattice:
    if not isinstance(raw, dict):
        raise _fail(
            "lattice",
            f"expected an object such as {{'rectangular': [px, py]}}, got {kind(raw)} {echo(raw)}",
        )
    try:
        if set(raw) == {"rectangular"}:
            value = raw["rectangular"]
            if isinstance(value, list) and len(value) in (1, 2):
                return Lattice.rectangular(*value)
            if isinstance(value, list | dict | str) or value is None:
                raise _fail(
                    "lattice.rectangular",
                    f"{echo(value)} is invalid; expected a period in mm or two periods [px, py]",
                )
            return Lattice.rectangular(value)
        if set(raw) == {"hexagonal"}:
            return Lattice.hexagonal(raw["hexagonal"])
        if set(raw) == {"a1", "a2"}:
            return Lattice(raw["a1"], raw["a2"])
    except CellFileError:
        raise
    except (ValueError, TypeError) as exc:
        field = exc.field if isinstance(exc, InvalidValue) else ""
        key = {"px": "rectangular", "py": "rectangular", "a": "hexagonal"}.get(field, field)
        raise _fail(f"lattice.{key}" if key else "lattice", str(exc)) from None
    raise _fail(
        "lattice",
        f"keys {echo(sorted(raw))} are invalid; expected 'rectangular', 'hexagonal', or 'a1' "
        "and 'a2'",
    )


def _element(raw: Any, where: str, mode: str) -> Element:
    if not isinstance(raw, dict):
        raise _fail(where, f"expected an object of element fields, got {kind(raw)}")
    fields = set(MeshParams.__dataclass_fields__)
    _unknown(raw, fields | set(_ELEMENT_KEYS), where)
    params = {k: v for k, v in raw.items() if k not in _ELEMENT_KEYS}
    if "mode" in params and params["mode"] != mode:
        raise _fail(
            f"{where}.mode",
            f"mode={echo(params['mode'])} differs from the cell's mode={mode!r}; "
            "an element takes the cell's mode (leave it out)",
        )
    params["mode"] = mode
    try:
        mp = MeshParams.from_dict(params)
    except (ValueError, TypeError) as exc:
        raise _field_error(exc, where, fields) from None
    try:
        return Element(
            mp,
            position=raw.get("position", (0.0, 0.0)),
            rotation=raw.get("rotation", 0.0),
            name=raw.get("name", where),
        )
    except (ValueError, TypeError) as exc:
        raise _field_error(exc, where, set(_ELEMENT_KEYS)) from None


def _pixels(raw: Any) -> PixelGrid:
    where = "pixels"
    if not isinstance(raw, dict):
        raise _fail(where, f"expected an object with 'rows', got {kind(raw)}")
    _unknown(raw, _PIXEL_KEYS, where)
    rows = raw.get("rows")
    if not isinstance(rows, list) or not rows or not all(isinstance(r, str) for r in rows):
        raise _fail(f"{where}.rows", "expected a non-empty list of strings of 0 and 1")
    width = len(rows[0])
    for k, row in enumerate(rows):
        if len(row) != width or set(row) - {"0", "1"}:
            raise _fail(
                f"{where}.rows[{k}]",
                f"{echo(row)} is invalid; expected {width} characters, each 0 or 1",
            )
    mask = np.array([[c == "1" for c in row] for row in rows[::-1]], dtype=bool)
    kwargs = {k: raw[k] for k in _PIXEL_KEYS[1:] if k in raw}
    try:
        return PixelGrid(mask, **kwargs)
    except (ValueError, TypeError) as exc:
        raise _field_error(exc, where, set(_PIXEL_KEYS)) from None


# -- files --------------------------------------------------------------------


def save_cell(cell: UnitCell, path: str | Path) -> None:
    """Write ``cell`` as a cell file (written atomically) that :func:`load_cell` reads back."""
    from ..io.atomic import atomic_write_text

    atomic_write_text(Path(path), json.dumps(cell_to_dict(cell), indent=2) + "\n")


def read_cell_document(path: str | Path) -> Any:
    """The JSON document of a cell file as written (not yet validated).

    What a part says itself (for example ``grading``, which solving reads:
    :func:`barymesh.solver_grade.document_grading`) is only there, not in the
    :class:`UnitCell` made of it.
    """
    path = Path(path)
    try:
        return read_json_file(path, "cell file", "JSON cell", article="a")
    except ValueError as exc:
        raise CellFileError(str(exc)) from None


def load_cell(path: str | Path) -> UnitCell:
    """Read and validate a cell file; errors name the file and the path in the document."""
    return cell_from_dict(read_cell_document(path), str(Path(path)))


def cell_preset_names() -> list[str]:
    """Names of the shipped cell presets, sorted."""
    return sorted(p.name[: -len(SUFFIX)] for p in CELL_PRESET_DIR.glob(f"*{SUFFIX}"))


def cell_preset_path(name: str) -> Path:
    """The file of the shipped cell preset ``name`` (see :func:`cell_preset_names`)."""
    names = cell_preset_names()
    if name not in names:
        raise ValueError(f"unknown cell preset {name!r}; expected one of {', '.join(names)}")
    return CELL_PRESET_DIR / f"{name}{SUFFIX}"


def load_cell_preset(name: str) -> UnitCell:
    """The shipped cell preset ``name`` (see :func:`cell_preset_names`)."""
    return load_cell(cell_preset_path(name))
