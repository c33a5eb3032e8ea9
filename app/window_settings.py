"""What the window opens on and what it keeps between sessions.

The settings are an INI file in the user's configuration folder (:func:`app_settings`):
the parameters, the view's layers and colouring, and the window's geometry and docks
(:class:`barymesh.app.dock_layout.DockLayout`). With nothing saved, the window opens on
:data:`START_PRESET`, whose triangles, centroids and shared edges read at first sight.
"""

from __future__ import annotations

import json
import logging
from typing import Any

from PySide6.QtCore import QSettings

from barymesh import MeshParams

log = logging.getLogger(__name__)

ORGANIZATION = APPLICATION = "barymesh"
#: The preset the window opens on when no parameters are given or saved: triangles,
#: centroids and shared edges read at first sight. The paper's Fig. 12(a) (the core's
#: defaults: 720 patches, 86 % overlap) reads as a texture at the start size.
START_PRESET = "conforming-double-ring"
#: Said on the status bar at the start, until the parameters change.
START_MESSAGE = (
    "Opened on the conforming double ring (the geometry of the paper's Fig. 12(a), "
    "watertight). The paper's figures: Presets ▸ paper-fig10 … paper-fig12d "
    "(Fig. 12(a): paper-fig12a or Edit ▸ Reset to defaults)"
)


def start_params() -> tuple[MeshParams, str]:
    """The parameters the window opens on (:data:`START_PRESET`) and the note under the
    view; the core's defaults (the paper's Fig. 12(a)) if the preset cannot be read."""
    from barymesh.presets import load_preset

    try:
        params, description = load_preset(START_PRESET)
    except (ValueError, OSError) as exc:
        log.warning("start preset %s unavailable: %s", START_PRESET, exc)
        return MeshParams(), "The paper's Fig. 12(a) (the defaults)"
    return params, f"Preset {START_PRESET}: {description}"


def app_settings() -> QSettings:
    """The window's settings: an INI file in the user's configuration folder.

    Tests point it elsewhere with ``QSettings.setPath(IniFormat, UserScope, folder)``.
    """
    return QSettings(
        QSettings.Format.IniFormat, QSettings.Scope.UserScope, ORGANIZATION, APPLICATION
    )


def saved_json(settings: QSettings, key: str) -> Any:
    """The JSON value saved under ``key`` (``None`` if none, or not JSON)."""
    text = settings.value(key)
    if not isinstance(text, str):
        return None
    try:
        return json.loads(text)
    except json.JSONDecodeError:
        return None


def saved_params(settings: QSettings) -> MeshParams | None:
    """The parameters a past session left (``None`` if none, or no longer valid)."""
    data = saved_json(settings, "params")
    if data is None:
        return None
    try:
        return MeshParams.from_dict(data)
    except (ValueError, TypeError) as exc:
        log.warning("ignoring the saved parameters: %s", exc)
        return None
