"""Named parameter sets (presets) and user parameter files.

A preset is a JSON file in ``assets/presets/`` (installed as
``barymesh/assets/presets/``): a :class:`MeshParams` dict
plus a one-line ``"description"``. A user's parameter file has the same
layout (the description is optional) and may live anywhere.

>>> params, description = load_preset("paper-fig10")
>>> params.structure, params.patch_size, params.subdivisions
('patch', 10.0, 4)
"""

from __future__ import annotations

import json
from pathlib import Path
from typing import Any

from .params import MeshParams
from .values import InvalidValue, echo, expected_names


def _asset_dir() -> Path:
    """The shipped data: ``barymesh/assets/`` in a wheel, the repository's ``assets/`` in a
    checkout (an editable install maps ``barymesh`` to ``core/``, beside ``assets/``)."""
    here = Path(__file__).resolve().parent
    installed = here / "assets"
    return installed if installed.is_dir() else here.parent / "assets"


#: Folder of the shipped data (presets and cells).
ASSET_DIR = _asset_dir()
#: Folder of the shipped presets.
PRESET_DIR = ASSET_DIR / "presets"


def preset_names() -> list[str]:
    """Names of the shipped presets, sorted."""
    return sorted(p.stem for p in PRESET_DIR.glob("*.json"))


def read_json_file(
    path: Path, kind: str = "parameter file", document: str = "JSON parameters", article: str = ""
) -> Any:
    """The JSON document in ``path``; a ``ValueError`` naming the file for anything wrong.

    ``kind`` names the file in "no such …" (``"parameter file"``, ``"cell file"``),
    ``document`` what it should hold (``"JSON parameters"``, ``"JSON cell"``, with
    ``article`` before it where English wants one).
    """
    expected = f"{article} {document}".strip()
    try:
        text = path.read_text(encoding="utf-8")
    except FileNotFoundError:
        raise ValueError(f"{path}: no such {kind}") from None
    except OSError as exc:
        raise ValueError(f"{path}: cannot read it ({exc.strerror or exc})") from None
    except UnicodeDecodeError:
        raise ValueError(f"{path}: not a UTF-8 text file; expected {expected}") from None
    try:
        return json.loads(text)
    except json.JSONDecodeError as exc:
        raise ValueError(f"{path}: invalid JSON at line {exc.lineno}: {exc.msg}") from None
    except (ValueError, RecursionError) as exc:  # a number of over 4300 digits, deep nesting
        why = "nested too deeply" if isinstance(exc, RecursionError) else "a number is too long"
        raise ValueError(f"{path}: invalid {document} ({why})") from None


def _read_json(path: Path) -> dict[str, Any]:
    data = read_json_file(path)
    if not isinstance(data, dict):
        raise ValueError(
            f"{path}: expected a JSON object of parameter names to values, "
            f"got {type(data).__name__}"
        )
    return data


def _params_from(data: dict[str, Any], source: str) -> MeshParams:
    """Validate ``data`` (without its description) into MeshParams; errors name ``source``."""
    try:
        return MeshParams.from_dict(data)
    except (ValueError, TypeError) as exc:
        raise ValueError(f"{source}: {exc}") from None


def _load(path: Path) -> tuple[MeshParams, str]:
    data = _read_json(path)
    description = data.pop("description", "")
    if not isinstance(description, str):
        raise ValueError(f"{path}: description={description!r} is not a string")
    return _params_from(data, str(path)), description


def load_preset(name: str) -> tuple[MeshParams, str]:
    """The parameters and the one-line description of preset ``name``.

    Raises
    ------
    ValueError
        If there is no such preset (the message lists the known ones) or its
        file is invalid (the message names the file and the key).
    """
    names = preset_names()
    if name not in names:
        raise ValueError(f"unknown preset {name!r}; expected one of {', '.join(names)}")
    return _load(PRESET_DIR / f"{name}.json")


def preset_descriptions() -> dict[str, str]:
    """Preset name -> one-line description, in name order."""
    return {name: load_preset(name)[1] for name in preset_names()}


def load_params_file(path: str | Path) -> MeshParams:
    """Parameters from a JSON file (a MeshParams dict, optionally with a ``"description"``)."""
    return _load(Path(path))[0]


def save_params_file(params: MeshParams, path: str | Path, description: str = "") -> None:
    """Write ``params`` as a JSON parameter file that :func:`load_params_file` reads back."""
    from .io.atomic import atomic_write_text

    data: dict[str, Any] = {}
    if description:
        data["description"] = description
    data.update(params.to_dict())
    atomic_write_text(Path(path), json.dumps(data, indent=2) + "\n")


def parse_assignment(text: str) -> tuple[str, Any]:
    """Split ``name=value``; the value is JSON when it parses, else the plain string.

    >>> parse_assignment("subdivisions=8"), parse_assignment("mode=conforming")
    (('subdivisions', 8), ('mode', 'conforming'))
    >>> parse_assignment("origin=[1,2]")
    ('origin', [1, 2])
    """
    name, sep, raw = text.partition("=")
    name = name.strip()
    if not sep or not name:
        raise ValueError(f"--set {text!r} is invalid; expected name=value, e.g. subdivisions=8")
    raw = raw.strip()
    try:
        value = json.loads(raw)
    except json.JSONDecodeError:
        value = raw
    except (ValueError, RecursionError):  # a number of over 4300 digits, deep nesting
        message = f"--set {text[:60]!r}: the value is nested too deeply or too long"
        raise ValueError(message) from None
    return name, value


def resolve_params(
    preset: str | None = None,
    params_file: str | Path | None = None,
    sets: list[str] | tuple[str, ...] = (),
) -> MeshParams:
    """Combine a preset, a parameter file and ``name=value`` settings; later ones win.

    Starts from ``MeshParams()`` defaults; the preset's fields, then the
    file's, then each setting in order replace earlier values. The result is
    validated once, so intermediate combinations need not be valid.

    >>> resolve_params("paper-fig10", None, ["subdivisions=8"]).subdivisions
    8
    """
    data: dict[str, Any] = {}
    origin: dict[str, str] = {}  # parameter name -> where its value came from
    if preset is not None:
        data.update(load_preset(preset)[0].to_dict())
        origin.update(dict.fromkeys(data, f"preset {preset!r}"))
    if params_file is not None:
        path = Path(params_file)
        file_data = _read_json(path)
        file_data.pop("description", None)
        _check_keys(file_data, str(path))
        data.update(file_data)
        origin.update(dict.fromkeys(file_data, str(path)))
    for text in sets:
        name, value = parse_assignment(text)
        _check_keys({name: value}, f"--set {text!r}")
        data[name] = value
        origin[name] = f"--set {text!r}"
    try:
        return MeshParams.from_dict(data)
    except (ValueError, TypeError) as exc:
        source = origin.get(exc.field) if isinstance(exc, InvalidValue) else None
        if source is None:
            source = ", ".join(dict.fromkeys(origin.values())) or "default parameters"
        raise ValueError(f"{source}: {exc}") from None


def given_keys(
    preset: str | None = None,
    params_file: str | Path | None = None,
    sets: list[str] | tuple[str, ...] = (),
) -> set[str]:
    """The parameter names that the preset's file, the parameter file and the settings
    write themselves (not the defaults :func:`resolve_params` fills in).

    >>> sorted(given_keys("paper-fig11-8mm", None, ["subdivisions=8"]))[:4]
    ['diagonal', 'grading', 'mode', 'patch_size']
    """
    keys: set[str] = set()
    if preset is not None:
        if preset not in preset_names():
            raise ValueError(f"unknown preset {preset!r}; expected one of {preset_names()}")
        keys |= set(_read_json(PRESET_DIR / f"{preset}.json")) - {"description"}
    if params_file is not None:
        keys |= set(_read_json(Path(params_file))) - {"description"}
    keys |= {parse_assignment(text)[0] for text in sets}
    return keys


def _check_keys(data: dict[str, Any], source: str) -> None:
    known = set(MeshParams.__dataclass_fields__)
    unknown = sorted(set(data) - known)
    if unknown:
        raise ValueError(
            f"{source}: unknown parameter {echo(unknown[0])}; {expected_names(unknown[0], known)}"
        )
