"""The main window's docks: made, laid out for the window's width, tabbed with their whole
titles, and saved and restored with the window.

Wide (:data:`NARROW_WIDTH` pixels and more), Parameters is on the left and Statistics over
Layers on the right; narrow, the three are tabs of one column on the left so that the 3D
view keeps most of the width. The layout follows the width until the user moves one of
those docks, and then stays as the user left it (also in the next session). The docks
tabbed with the Statistics (Solve, Quality, the RWG inspector, the matrix) stay so in
either layout. A side area's tab bar keeps its docks wide enough for their whole titles
("Statistics", not "S…" nor "stics") while the 3D view keeps :data:`MIN_VIEW_WIDTH`.
"""

from __future__ import annotations

from collections.abc import Callable, Sequence

from PySide6.QtCore import QByteArray, QObject, QSettings, Qt, QTimer
from PySide6.QtWidgets import QDockWidget, QMainWindow, QScrollArea, QStyle, QTabBar, QWidget

#: Below this window width the Statistics and Layers docks share the Parameters column
#: (as tabs), so the 3D view keeps most of the width.
NARROW_WIDTH = 1200
#: A side dock area is kept wide enough for its whole tab titles only while the 3D view
#: keeps at least this many pixels of width.
MIN_VIEW_WIDTH = 480


class DockLayout(QObject):
    """The docks of ``window``, and their layout.

    Parameters
    ----------
    window
        The main window the docks belong to.
    closed
        Whether the window has closed (nothing is tidied then).
    """

    def __init__(self, window: QMainWindow, closed: Callable[[], bool]) -> None:
        super().__init__(window)
        self.window = window
        self.closed = closed
        #: Whether the layout follows the window's width (until the user moves a dock).
        self.auto = True
        #: Whether the narrow layout is on.
        self.narrow = False
        #: Whether the layout is moving the docks itself (not the user's doing).
        self.arranging = False
        self._tidy_pending = False
        self._shown_once = False
        self._main: tuple[QDockWidget, QDockWidget, QDockWidget] | None = None
        self._tabbed: Callable[[], Sequence[QDockWidget]] = tuple

    def add(
        self,
        title: str,
        widget: QWidget,
        area: Qt.DockWidgetArea,
        scroll: bool = False,
        name: str | None = None,
        tab_with: QDockWidget | None = None,
    ) -> QDockWidget:
        """A dock of ``widget`` (in a scroll area with ``scroll``), saved under ``name``
        (default ``dock_<title>``) and tabbed with ``tab_with`` if given."""
        window = self.window
        dock = QDockWidget(title, window)
        dock.setObjectName(name or f"dock_{title.lower()}")
        if scroll:
            area_widget = QScrollArea(dock)
            area_widget.setWidget(widget)
            area_widget.setWidgetResizable(True)
            area_widget.setFrameShape(QScrollArea.Shape.NoFrame)
            area_widget.setHorizontalScrollBarPolicy(Qt.ScrollBarPolicy.ScrollBarAlwaysOff)
            bar = window.style().pixelMetric(QStyle.PixelMetric.PM_ScrollBarExtent)
            area_widget.setMinimumWidth(widget.minimumSizeHint().width() + bar + 4)
            dock.setWidget(area_widget)
        else:
            dock.setWidget(widget)
        window.addDockWidget(area, dock)
        if tab_with is not None:
            window.tabifyDockWidget(tab_with, dock)
        dock.visibilityChanged.connect(self.tabs_changed)
        return dock

    def follow(
        self,
        parameters: QDockWidget,
        statistics: QDockWidget,
        layers: QDockWidget,
        tabbed: Callable[[], Sequence[QDockWidget]],
    ) -> None:
        """Lay out these three docks by the width, with ``tabbed()`` tabbed with the
        statistics; a move of one of the three by the user ends the automatic layout."""
        self._main = (parameters, statistics, layers)
        self._tabbed = tabbed
        for dock in self._main:
            dock.dockLocationChanged.connect(self._moved)
            dock.topLevelChanged.connect(self._moved)

    # -- settings --------------------------------------------------------------------------

    def restore(self, settings: QSettings) -> None:
        """The window's geometry and docks as a past session left them."""
        window = self.window
        geometry = settings.value("window/geometry")
        if isinstance(geometry, QByteArray):
            window.restoreGeometry(geometry)
        state = settings.value("window/state")
        if isinstance(state, QByteArray):
            self.arranging = True
            window.restoreState(state)
            self.arranging = False
            auto = settings.value("window/auto_docks", "true")
            self.auto = auto in (True, "true")
            if self._main is not None:
                area = window.dockWidgetArea(self._main[1])
                self.narrow = area == Qt.DockWidgetArea.LeftDockWidgetArea

    def save(self, settings: QSettings) -> None:
        settings.setValue("window/geometry", self.window.saveGeometry())
        settings.setValue("window/state", self.window.saveState())
        settings.setValue("window/auto_docks", self.auto)

    # -- the window's events -----------------------------------------------------------------

    def shown(self, saved_state: bool) -> None:
        """The window was shown: tidy the tabs; the first time, the Statistics go on top
        of the docks tabbed with them unless a saved layout (``saved_state``) says
        otherwise."""
        QTimer.singleShot(0, self.tidy_tabs)
        if not self._shown_once:
            self._shown_once = True
            if not saved_state and self._main is not None:
                QTimer.singleShot(0, self._main[1].raise_)

    def resized(self) -> None:
        """The window's width changed: the narrow or wide layout, while it is automatic."""
        if self.auto and not self.arranging:
            narrow = self.window.width() < NARROW_WIDTH
            if narrow != self.narrow:
                self.arrange(narrow)

    def _moved(self, *_args: object) -> None:
        if not self.arranging:
            self.auto = False  # the user arranged the docks: leave them be

    # -- the layout --------------------------------------------------------------------------

    def arrange(self, narrow: bool) -> None:
        """Wide: Parameters left, Statistics over Layers right. Narrow: all three as tabs of
        one column on the left, so the 3D view keeps most of the width. The tabbed docks
        stay tabbed with Statistics; hidden docks stay hidden."""
        if self._main is None:
            return
        window = self.window
        parameters, statistics, layers = self._main
        left, right = Qt.DockWidgetArea.LeftDockWidgetArea, Qt.DockWidgetArea.RightDockWidgetArea
        extra = list(self._tabbed())
        hidden = {d: d.isHidden() for d in (*self._main, *extra)}
        self.arranging = True
        try:
            if narrow:
                window.addDockWidget(left, statistics)
                window.addDockWidget(left, layers)
                window.tabifyDockWidget(parameters, statistics)
                window.tabifyDockWidget(parameters, layers)
            else:
                window.addDockWidget(right, statistics)
                window.addDockWidget(right, layers, Qt.Orientation.Vertical)
            for dock in extra:
                window.tabifyDockWidget(statistics, dock)
            for dock, was_hidden in hidden.items():
                dock.setHidden(was_hidden)
            if not narrow:  # the statistics, not the last dock tabbed with them, on top
                statistics.raise_()
            parameters.raise_()
        finally:
            self.arranging = False
        self.narrow = narrow
        self.tidy_tabs()

    def tabs_changed(self, *_args: object) -> None:
        """A dock came or went: its tab bar is tidied once the layout has settled (one
        call however many docks changed)."""
        if not self.closed() and not self._tidy_pending:
            self._tidy_pending = True
            QTimer.singleShot(0, self.tidy_tabs)

    def tidy_tabs(self) -> None:
        """Tabbed docks keep their whole titles ("Statistics", not "S…" nor "stics").

        A side area's tab bar whose tabs need more than its docks' own minimum width (the
        RWG inspector and the matrix tabbed in with the Statistics) gets that width as the
        docks' minimum, so that neither the layout nor a drag of the separator narrows it
        below its titles, as long as the 3D view keeps :data:`MIN_VIEW_WIDTH` pixels; the
        minimum goes with those tabs. A tab bar still too narrow scrolls instead of
        eliding the titles."""
        self._tidy_pending = False
        window = self.window
        docks = {d.windowTitle(): d for d in window.findChildren(QDockWidget) if not d.isHidden()}
        view = window.centralWidget()
        sides = (Qt.DockWidgetArea.LeftDockWidgetArea, Qt.DockWidgetArea.RightDockWidgetArea)
        wanted: dict[QDockWidget, int] = {}
        grow: list[tuple[QDockWidget, int]] = []
        for bar in window.findChildren(QTabBar):
            if not isinstance(bar.parent(), QMainWindow):  # the dock areas' tab bars only
                continue
            bar.setElideMode(Qt.TextElideMode.ElideNone)
            bar.setUsesScrollButtons(True)
            bar.setExpanding(False)
            group = [docks[t] for t in map(bar.tabText, range(bar.count())) if t in docks]
            top = docks.get(bar.tabText(bar.currentIndex()))  # on top: its width is true
            if not bar.isVisible() or view is None or top is None or self.arranging:
                continue
            if window.dockWidgetArea(top) not in sides or top.isFloating():
                continue
            need = sum(bar.tabSizeHint(i).width() for i in range(bar.count())) + 2
            own = max(d.minimumSizeHint().width() for d in group)
            if need <= own or need > bar.width() + max(view.width() - MIN_VIEW_WIDTH, 0):
                continue  # their own minimum holds the titles, or there is no room for them
            for dock in group:
                wanted[dock] = need
            if bar.width() < need:  # applied now: a minimum alone waits for the next layout
                grow.append((top, need))
        for dock in window.findChildren(QDockWidget):
            width = wanted.get(dock, 0)
            if dock.minimumWidth() != width:
                dock.setMinimumWidth(width)
        for dock, width in grow:
            window.resizeDocks([dock], [width], Qt.Orientation.Horizontal)
