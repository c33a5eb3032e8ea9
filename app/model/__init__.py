"""The window's state and what it shows, without Qt (napari's ``components``).

One topic per module; every name is re-exported here, where the panels and the tests
import it from:

- :mod:`~barymesh.app.model.events`: :class:`Event`, the model's only signal type;
- :mod:`~barymesh.app.model.specs`: how each parameter is shown as a control
  (:class:`ParamSpec`, :data:`SPECS`, titles, :func:`applies`, the subdivisions carried
  over a scheme change);
- :mod:`~barymesh.app.model.typed_text`: typed text read exactly (:func:`read_number`,
  :func:`read_points`);
- :mod:`~barymesh.app.model.build`: :func:`compute` of a structure or a unit cell, one
  path, into a :class:`MeshResult`;
- :mod:`~barymesh.app.model.formatting`: text for values, bytes, seconds, statistics,
  file errors;
- :mod:`~barymesh.app.model.app_model`: :class:`AppModel`, parameters with undo/redo,
  refusals, the unit cell, the mesh on screen, layers;
- :mod:`~barymesh.app.model.click_tools`: :class:`ClickTools`, which of the 3D view's
  click tools are on and where a click goes;
- :mod:`~barymesh.app.model.selection`: :class:`ViewSelection`, what a click selected
  and what Zoom to selection frames;
- :mod:`~barymesh.app.model.undo_history`: :class:`UndoHistory`, a linear history of
  states (the pixel painter's).
"""

from barymesh.app.model.app_model import AppModel, ParamError
from barymesh.app.model.build import MeshResult, compute, compute_cell
from barymesh.app.model.click_tools import CLICK_TOOLS, ClickTools
from barymesh.app.model.events import Event
from barymesh.app.model.formatting import (
    STAT_LABELS,
    file_error_sentence,
    format_bytes,
    format_seconds,
    format_value,
    mom_matrix_bytes,
    stats_texts,
)
from barymesh.app.model.selection import ViewSelection
from barymesh.app.model.specs import (
    ADVANCED_SPECS,
    CHOICE_STRUCTURES,
    CHOICES,
    MODE_TITLES,
    NOT_TRIANGLE,
    PARAM_SPECS,
    POINT_PARAMS,
    RING_STRUCTURES,
    SLIDER_DECADES,
    SPECS,
    STRUCTURE_TITLES,
    ParamSpec,
    applies,
    carried_subdivisions,
    carry_note,
    named_parameter,
    subdivisions_limit,
)
from barymesh.app.model.typed_text import Reading, read_number, read_points
from barymesh.app.model.undo_history import UndoHistory

__all__ = [
    "ADVANCED_SPECS",
    "CLICK_TOOLS",
    "CHOICES",
    "CHOICE_STRUCTURES",
    "MODE_TITLES",
    "NOT_TRIANGLE",
    "PARAM_SPECS",
    "POINT_PARAMS",
    "RING_STRUCTURES",
    "SLIDER_DECADES",
    "SPECS",
    "STAT_LABELS",
    "STRUCTURE_TITLES",
    "AppModel",
    "ClickTools",
    "Event",
    "MeshResult",
    "ParamError",
    "ParamSpec",
    "Reading",
    "UndoHistory",
    "ViewSelection",
    "applies",
    "carried_subdivisions",
    "carry_note",
    "compute",
    "compute_cell",
    "file_error_sentence",
    "format_bytes",
    "format_seconds",
    "format_value",
    "mom_matrix_bytes",
    "named_parameter",
    "read_number",
    "read_points",
    "stats_texts",
    "subdivisions_limit",
]
