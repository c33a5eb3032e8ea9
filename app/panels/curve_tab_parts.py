"""Widgets the Solve dock's curve tabs share (Infinite array, Reflection phase).

Both tabs put, under their inputs, the same three messages (a bad input in red, the
status, the solver's warnings in an orange box), a group with the layers' editor, a note
and a button that opens their curve's dock again; and both draw their curve in an area
with one grey line over it. These functions make those pieces, so that the two tabs look
and read alike; what each tab connects them to stays in the tab.
"""

from __future__ import annotations

from dataclasses import dataclass

from PySide6.QtCore import Qt
from PySide6.QtWidgets import (
    QGroupBox,
    QLabel,
    QPushButton,
    QSizePolicy,
    QVBoxLayout,
    QWidget,
)

from barymesh.app.panels.stack_editor import StackEditor

#: The style of the warnings' box: visible, not modal.
WARNINGS_STYLE = "QLabel { background: #fff4e0; border: 1px solid #e0a040; padding: 4px; }"
#: The grey of secondary lines (the line over a curve, a note about a shared stack).
GREY = "color: #555555;"


@dataclass
class Messages:
    """The three lines under a tab's inputs."""

    error: QLabel
    status: QLabel
    warnings: QLabel


def add_messages(owner: QWidget, col: QVBoxLayout) -> Messages:
    """A red error line, a status line and the (hidden) warnings' box, added to ``col``."""
    error = QLabel(owner)
    error.setStyleSheet("color: #d0021b;")
    error.setWordWrap(True)
    col.addWidget(error)
    status = QLabel(owner)
    status.setWordWrap(True)
    col.addWidget(status)
    warnings = QLabel(owner)
    warnings.setWordWrap(True)
    warnings.setTextFormat(Qt.TextFormat.RichText)
    warnings.setTextInteractionFlags(Qt.TextInteractionFlag.TextSelectableByMouse)
    warnings.setStyleSheet(WARNINGS_STYLE)
    warnings.hide()
    col.addWidget(warnings)
    return Messages(error, status, warnings)


def stack_group(owner: QWidget, tooltip: str) -> tuple[QGroupBox, QVBoxLayout, StackEditor]:
    """The "Layers and ground plane" group with its editor (not yet in the group's layout,
    so that a tab can put a line above it)."""
    group = QGroupBox("Layers and ground plane", owner)
    group.setToolTip(tooltip)
    box = QVBoxLayout(group)
    box.setContentsMargins(4, 4, 4, 4)
    return group, box, StackEditor(group)


def add_note_and_show_button(
    owner: QWidget, col: QVBoxLayout, dock_title: str
) -> tuple[QLabel, QPushButton]:
    """ "No curve yet." and the button that opens the curve's dock again, added to ``col``."""
    note = QLabel("No curve yet.", owner)
    note.setWordWrap(True)
    col.addWidget(note)
    button = QPushButton("Show the &curve", owner)
    button.setToolTip(f"Open the {dock_title} dock again")
    col.addWidget(button)
    return note, button


def curve_area(placeholder: str) -> tuple[QWidget, QVBoxLayout, QLabel]:
    """The widget a curve is drawn in, with its one grey line on top (always there, so that
    the curve does not move when a warning comes or goes)."""
    area = QWidget()
    layout = QVBoxLayout(area)
    layout.setContentsMargins(2, 2, 2, 2)
    line = QLabel(placeholder, area)
    line.setSizePolicy(QSizePolicy.Policy.Ignored, QSizePolicy.Policy.Fixed)
    line.setStyleSheet(GREY)
    layout.addWidget(line)
    return area, layout, line
