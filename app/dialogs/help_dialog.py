"""Help → About (F1): the method in a paragraph and every shortcut."""

from __future__ import annotations

from collections.abc import Iterable

from PySide6.QtGui import QAction, QGuiApplication, QKeySequence
from PySide6.QtWidgets import QDialog, QDialogButtonBox, QTextBrowser, QVBoxLayout, QWidget

ABOUT = """<h3>barymesh {version}</h3>
<p>A square patch is split along its diagonal into two primary triangles, each subdivided
uniformly into n² sub-triangles, and vertices closer than a tolerance ε are merged into one
(the paper's metric-space constraint), so that neighbouring triangles share edges.
Rings and split rings are assembled from such patches placed at (r cos θ, r sin θ), and
every edge shared by exactly two triangles carries one Rao–Wilton–Glisson basis function
for the Method of Moments.</p>
<p>After <i>Discretization of Continuous Spaces using Barycentric Subdivision Method with
Metric Space Constraints on the Nearest Neighbour Edges</i>.</p>
{shortcuts}"""


def about_html(version: str, actions: Iterable[QAction]) -> str:
    """The About text: the method in a paragraph and the shortcuts of ``actions``."""
    return ABOUT.format(version=version, shortcuts=shortcuts_html(actions))


def shortcuts_html(actions: Iterable[QAction]) -> str:
    """The table of ``actions``' shortcuts and of the view's mouse and keys."""
    rows = []
    for act in actions:
        keys = ", ".join(
            k.toString(QKeySequence.SequenceFormat.NativeText) for k in act.shortcuts()
        )
        if keys:
            rows.append(f"<tr><td>{act.text().replace('&', '')}</td><td><b>{keys}</b></td></tr>")
    rows.append(
        "<tr><td>Rotate / pan / zoom the view</td><td><b>left / middle drag, wheel</b></td></tr>"
    )
    rows.append("<tr><td>Move a slider</td><td><b>←/→, PgUp/PgDn, Home/End</b></td></tr>")
    rows.append(
        "<tr><td>What is under the cursor (strip under the view)</td><td><b>hover</b></td></tr>"
    )
    rows.append("<tr><td>Select a triangle, edge or vertex (then Z)</td><td><b>click</b></td></tr>")
    return "<h4>Keyboard shortcuts</h4><table cellspacing='6'>" + "".join(rows) + "</table>"


class HelpDialog(QDialog):
    """Help → About / F1: the method and every shortcut, scrolling inside the screen."""

    def __init__(self, html: str, parent: QWidget | None = None) -> None:
        super().__init__(parent)
        self.setWindowTitle("About barymesh")
        self.browser = QTextBrowser(self)
        self.browser.setOpenExternalLinks(True)
        self.browser.setHtml(html)
        buttons = QDialogButtonBox(QDialogButtonBox.StandardButton.Close, self)
        buttons.rejected.connect(self.close)
        col = QVBoxLayout(self)
        col.addWidget(self.browser, 1)
        col.addWidget(buttons)
        screen = parent.screen() if parent is not None else QGuiApplication.primaryScreen()
        room = screen.availableGeometry()
        self.resize(min(620, int(0.9 * room.width())), min(560, int(0.8 * room.height())))
