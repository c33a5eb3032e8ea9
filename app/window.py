"""The desktop window: controls, a live 3D view of the mesh, statistics and layers.

The state lives in :class:`barymesh.app.model.AppModel` (no Qt); this module wires the panels,
the pyvistaqt view (:class:`barymesh.app.view.scene.MeshScene`), the meshing controller
(:class:`barymesh.app.worker.MeshController`), menus and settings around it. What a mesh
result becomes in the view is the scene presenter's
(:class:`barymesh.app.view.scene_presenter.ScenePresenter`); open, save and export are the
File actions' (:class:`barymesh.app.file_actions.FileActions`).

Run ``barymesh`` or ``python -m barymesh.app``; :func:`barymesh.app.window_main.main` reads the
options and opens it.
"""

from __future__ import annotations

import json
import logging
import os
from collections.abc import Callable
from pathlib import Path
from typing import Any

import numpy as np
from PySide6.QtCore import (
    QByteArray,
    QSettings,
    Qt,
)
from PySide6.QtGui import (
    QAction,
    QActionGroup,
    QCloseEvent,
    QKeySequence,
)
from PySide6.QtWidgets import (
    QDockWidget,
    QLabel,
    QMainWindow,
    QMessageBox,
    QToolBar,
    QWidget,
)

import barymesh
from barymesh import MeshParams, TriMesh
from barymesh.app.actions import make_action
from barymesh.app.build_progress import BuildProgress
from barymesh.app.dialogs.export_dialog import ExportDialog
from barymesh.app.dialogs.help_dialog import HelpDialog, about_html
from barymesh.app.dock_layout import DockLayout
from barymesh.app.edit.cell_tools import CellTools
from barymesh.app.file_actions import ExportJob, FileActions
from barymesh.app.model import (
    AppModel,
    ClickTools,
    MeshResult,
    ParamError,
    file_error_sentence,
)
from barymesh.app.model.layers import COLOR_BY_TITLES, LAYER_TITLES, LAYERS
from barymesh.app.panels.controls import ControlsPanel
from barymesh.app.panels.infinite_array_panel import InfiniteArrayPanel
from barymesh.app.panels.layers_panel import LayersPanel
from barymesh.app.panels.quality_panel import QualityPanel
from barymesh.app.panels.reflection_phase_panel import ReflectionPhasePanel
from barymesh.app.panels.solve_panel import SolvePanel
from barymesh.app.panels.stats_panel import StatsPanel
from barymesh.app.teach.teaching_tools import TeachingTools
from barymesh.app.teach.teaching_windows import TeachingWindows
from barymesh.app.view.framing import (
    FramedCamera,
    frame_from_above,
    look_from_above,
    pixels_per_mm,
)
from barymesh.app.view.gl_info import multi_samples
from barymesh.app.view.scene import MeshScene
from barymesh.app.view.scene_presenter import ScenePresenter
from barymesh.app.view.view_tools import ViewTools
from barymesh.app.window_settings import (
    START_MESSAGE,
    app_settings,
    saved_json,
    saved_params,
    start_params,
)
from barymesh.app.worker import MeshController

log = logging.getLogger(__name__)

#: The window icon (shipped in the wheel as package data).
ICON = Path(__file__).resolve().parent / "icons" / "barymesh.svg"
SCRIPTED_SIZE = (1400, 860)
#: Keys that work from every window of the program (the teaching windows too).
APPLICATION_KEYS = ("F1", "F7", "F8")


class MainWindow(QMainWindow):
    """The barymesh window.

    Parameters
    ----------
    params : MeshParams, optional
        Start from these (else the last session's, else the defaults).
    settings : QSettings, optional
    scripted : bool
        A ``--screenshot``/``--quit`` run: fixed size and layout, settings not saved.
    cell : barymesh.cell.UnitCell, optional
        Open this unit cell (its first element's parameters in the Parameters panel).
    """

    # the window's own docks, set by add_dock as "<title>_dock"
    parameters_dock: QDockWidget
    statistics_dock: QDockWidget
    layers_dock: QDockWidget
    solve_dock: QDockWidget
    quality_dock: QDockWidget
    scripted_run: Any  # a --screenshot/--quit run's driver (barymesh.app.window_main), kept

    #: (ExportJob, exception or None) from an export's worker thread.

    def __init__(
        self,
        params: MeshParams | None = None,
        settings: QSettings | None = None,
        scripted: bool = False,
        cell: Any = None,
    ) -> None:
        super().__init__()
        from barymesh.app.gui_gc import collect_in_gui_thread
        from barymesh.app.view.interactor import ViewInteractor, disable_view_keys

        collect_in_gui_thread()  # no cyclic collection in a worker thread (a VTK deadlock)

        self.settings = settings if settings is not None else app_settings()
        self.scripted = scripted
        self.setObjectName("barymesh")
        self.setWindowTitle("barymesh")
        if params is None and not scripted:
            params = saved_params(self.settings)
        self._start_preset: tuple[MeshParams, str] | None = None  # (params, note) at start
        if params is None and cell is None:
            self._start_preset = start_params()
            params = self._start_preset[0]
        self.model = AppModel(params, cell)
        if not scripted:
            self.model.restore_view_state(saved_json(self.settings, "view"))

        # auto_update=False: no 5 Hz re-render timer; we render once per change ourselves.
        # (one render a frame: VTK's interaction renders only ask for the next paint)
        self.plotter = ViewInteractor(self, auto_update=False, multi_samples=multi_samples())
        self.plotter.setMinimumSize(320, 240)
        disable_view_keys(self.plotter)
        self.scene = MeshScene(
            self.plotter, visible=self.model.layers, color_by=self.model.color_by
        )
        self.scene.top_view()
        # File: open, save, export and screenshots (barymesh.app.file_actions)
        self.files = FileActions(self, self.settings, self.model, self.plotter, self.scene)
        self.framing = FramedCamera(self.plotter)  # the camera a mesh was last framed with
        # the mouse moved the camera (a drag ended, a wheel step: VTK's style ends each
        # step's interaction too); the rulers and the note follow when it rests
        for event in ("EndInteractionEvent", "MouseWheelForwardEvent", "MouseWheelBackwardEvent"):
            self.plotter.iren.add_observer(event, self._camera_moved)
        # the scene data, its requests and the view's paints (barymesh.app.view.scene_presenter)
        self.presenter = ScenePresenter(
            self.plotter,
            self.scene,
            self.model,
            mesh_changed=self._mesh_changed,
            frame=self.frame_mesh,
            parent=self,
        )
        self.paint_counter = self.presenter.paint_counter  # one paint per new mesh
        self._closed = False
        # the docks, their narrow or wide layout and their tabs (barymesh.app.dock_layout)
        self.dock_layout = DockLayout(self, closed=lambda: self._closed)

        self.controls = ControlsPanel(self.model, self)
        self.stats = StatsPanel(self.model, self)
        self.layers = LayersPanel(self.model, self)
        self.add_dock(
            "Parameters", self.controls, Qt.DockWidgetArea.LeftDockWidgetArea, scroll=True
        )
        # in a scroll area, like the other tall docks: the statistics' full height (426 px)
        # must not set the window's minimum height (it did: 733 px, 823 with a cell)
        self.add_dock("Statistics", self.stats, Qt.DockWidgetArea.RightDockWidgetArea, scroll=True)
        self.add_dock("Layers", self.layers, Qt.DockWidgetArea.RightDockWidgetArea)
        # Solve: an RWG MoM solve of the mesh on screen and its "Surface current" layer
        self.solve_panel = SolvePanel(self, self.model, self.plotter, self._current_shown)
        # the side columns keep the window's height: the bottom area (the Infinite array's
        # curve) lies under the 3D view only
        self.setCorner(Qt.Corner.BottomLeftCorner, Qt.DockWidgetArea.LeftDockWidgetArea)
        self.setCorner(Qt.Corner.BottomRightCorner, Qt.DockWidgetArea.RightDockWidgetArea)
        self.array_panel = InfiniteArrayPanel(
            self.model, self.solve_panel.show_array_current, self.solve_panel, host=self
        )
        # short labels: the dock's four tabs fit its default width (no scroll arrows hiding
        # the last); the tooltips say their full names
        self.solve_panel.add_page(
            self.array_panel,
            "&Array",
            "Infinite array: the cell's periodic array, its reflection and transmission "
            "over frequency",
        )
        self.phase_panel = ReflectionPhasePanel(
            self.model,
            self.solve_panel,
            host=self,
            stack_twin=self.array_panel.stack_editor,
            tab_with=self.array_panel.curve_dock,
            open_cell=lambda cell, message: self.cell_tools.open_cell(cell, message),
        )
        self.solve_panel.add_page(
            self.phase_panel,
            "P&hase",
            "Reflection phase: the S-curve of the cell's infinite array over one of its "
            "parameters, and the reflectarray designer",
        )
        self.add_dock("Solve", self.solve_panel, Qt.DockWidgetArea.RightDockWidgetArea, scroll=True)
        self.tabifyDockWidget(self.statistics_dock, self.solve_dock)
        # Quality: the quality report, its histograms and worst triangles (red layer)
        self.quality_panel = QualityPanel(
            self,
            self.model,
            self.plotter,
            view_bounds=lambda: self.scene.bounds,
            zoom_to_points=lambda points: self.view_tools.zoom_to_points(points),
        )
        self.add_dock(
            "Quality", self.quality_panel, Qt.DockWidgetArea.RightDockWidgetArea, scroll=True
        )
        self.tabifyDockWidget(self.statistics_dock, self.quality_dock)
        self.quality_dock.visibilityChanged.connect(self.quality_panel.set_seen)
        self.statistics_dock.raise_()

        self.controller = MeshController(self.model, self)
        self.controller.view_size = lambda: tuple(self.plotter.renderer.GetSize())
        self.presenter.attach_controller(self.controller)
        self.model.result_changed.connect(self._show_result)
        self.model.error_changed.connect(self._show_error)
        self.model.build_failed.connect(self._build_failed)
        self.model.layer_changed.connect(self._layer_changed)
        self.model.color_by_changed.connect(self._color_by_changed)
        self.model.detail_changed.connect(self.presenter.set_detail)
        self.model.history_changed.connect(self._history_changed)
        self._make_actions()
        # a build's progress and its Cancel on the status bar (barymesh.app.build_progress)
        self.progress = BuildProgress(
            self.statusBar(),
            self.model,
            self.controller,
            self.act_cancel,
            self._show_error,
            parent=self,
        )
        self.busy, self.cancel_button = self.progress.bar, self.progress.cancel_button
        self.summary = QLabel(self)
        self.statusBar().addPermanentWidget(self.summary)
        self._make_menus()
        self._history_changed()
        self.model.result_changed.connect(self._source_changed)
        # the 3D view with the readout strip under it
        self.setCentralWidget(self.view_tools.container())
        self.statusBar().messageChanged.connect(self._status_message_changed)
        self._note_params: MeshParams | None = None
        self.model.params_changed.connect(self._params_changed_note)

        self.dock_layout.follow(
            self.parameters_dock,
            self.statistics_dock,
            self.layers_dock,
            tabbed=lambda: [
                self.teaching.inspector_dock,
                self.teaching.matrix_dock,
                self.solve_dock,
                self.quality_dock,
            ],
        )
        if scripted:
            self.resize(*SCRIPTED_SIZE)
        else:
            self.resize(1400, 860)
            self.dock_layout.restore(self.settings)
            if self.model.cell_state is None:  # a saved layout had a cell open: not now
                self.cell_tools.dock.hide()
            self.teaching.sync_with_docks()
        if self._start_preset is not None:  # gone with the first change, as a preset's note
            self._note_params = self._start_preset[0]
            self.view_tools.set_note(self._start_preset[1])
        self.controller.request()

    # -- construction ------------------------------------------------------------------

    # -- the tools' host (barymesh.app.tool_host.ToolHost) ---------------------------------

    @property
    def widget(self) -> QMainWindow:
        return self

    @property
    def closed(self) -> bool:
        return self._closed

    @property
    def arranging_docks(self) -> bool:
        return self.dock_layout.arranging

    def show_status(self, message: str, timeout_ms: int = 0) -> None:
        self.statusBar().showMessage(message, timeout_ms)

    def status_message(self) -> str:
        return self.statusBar().currentMessage()

    def setting(self, key: str, default: Any = None) -> Any:
        return self.settings.value(key, default)

    def set_setting(self, key: str, value: Any) -> None:
        self.settings.setValue(key, value)

    def add_dock(
        self,
        title: str,
        widget: QWidget,
        area: Qt.DockWidgetArea,
        scroll: bool = False,
        name: str | None = None,
        tab_with: QDockWidget | None = None,
    ) -> QDockWidget:
        """A dock of ``widget``; the window's own (no ``name``) is also ``<title>_dock``."""
        dock = self.dock_layout.add(title, widget, area, scroll, name, tab_with)
        if name is None:
            setattr(self, f"{title.lower()}_dock", dock)
        return dock

    def add_action(
        self, text: str, slot: Any, shortcut: Any = None, tip: str = "", checkable: bool = False
    ) -> QAction:
        return make_action(
            self, text, slot, shortcut, tip, checkable, application_keys=APPLICATION_KEYS
        )

    def _make_actions(self) -> None:
        # File: open, load and save parameters, export, screenshot, copy (FileActions')
        (
            self.act_open,
            self.act_load,
            self.act_save,
            self.act_export,
            self.act_shot,
            self.act_copy,
        ) = self.files.make_actions()
        a = self.add_action
        self.act_quit = a("&Quit", self.close, QKeySequence.StandardKey.Quit, "Close barymesh")
        self.act_cancel = a(
            "&Cancel meshing",
            self.cancel_build,
            "Esc",
            "Abandon the running build; the mesh on screen stays",
        )
        self.act_cancel.setEnabled(False)
        self.act_undo = a("&Undo", self.model.undo, ["Ctrl+Z"], "Undo the last parameter change")
        self.act_redo = a(
            "&Redo", self.model.redo, ["Ctrl+Shift+Z", "Ctrl+Y"], "Redo the parameter change"
        )
        self.act_reset = a(
            "Reset to &defaults",
            self.model.reset,
            "Ctrl+Shift+R",
            "The paper's Fig. 12(a) parameters (undoable)",
        )
        self.act_camera = a(
            "&Reset camera",
            self.reset_camera,
            "R",
            "Frame the whole mesh from above (undoes tilt, pan and zoom)",
        )
        self.act_top = a(
            "&Top view", self.top_view, "T", "Look straight down the z axis, keeping the zoom"
        )
        self.layer_actions: dict[str, QAction] = {}
        for i, name in enumerate(LAYERS):
            act = a(
                LAYER_TITLES[name],
                lambda on, n=name: self.model.set_layer_visible(n, on),
                f"Ctrl+{i + 1}",
                f"Show or hide {LAYER_TITLES[name].lower()}",
                checkable=True,
            )
            act.setChecked(self.model.layers[name])
            self.layer_actions[name] = act
        self.color_group = QActionGroup(self)
        self.color_actions: dict[str, QAction] = {}
        for key, title in COLOR_BY_TITLES.items():
            act = QAction(title, self.color_group)
            act.setCheckable(True)
            act.setChecked(key == self.model.color_by)
            act.triggered.connect(lambda _=False, k=key: self.model.set_color_by(k))
            self.color_actions[key] = act
        self.act_help = a("&Keyboard shortcuts…", self.show_about, "F1", "Shortcuts and the method")
        self.act_about = a("&About barymesh", self.show_about)
        self._make_tools()

    def _make_tools(self) -> None:
        """The tools, each given the host interface (:class:`barymesh.app.tool_host.ToolHost`)
        and, explicitly, what it needs of the others, so this is the order they need:

        0. the click tools' state (:class:`barymesh.app.model.ClickTools`, no Qt), shared
           by the Teach tools, the View tools and the drag tool;
        1. the Teach tools make the click picker and the triangle highlight of the view;
        2. the Teach windows (construction, compare, sweep) need only the model;
        3. the View tools (readout, measure, zoom) use the picker, the highlight and the
           Teach tools' selection; the Teach tools' zoom requests are connected to them;
        4. the Cell tools (and their drag tool) use the View tools' ``world_at`` and the
           picker.
        """
        self.clicks = ClickTools()
        # Teach: RWG basis inspector, connectivity matrix, presentation mode (issue 5)
        self.teaching = TeachingTools(
            self,
            self.plotter,
            self.scene,
            self.clicks,
            beside=self.statistics_dock,
            refit=self.refit_if_framed,
        )
        # Teach: construction, paper vs conforming; File: sweep animation (issue 5)
        self.teaching_windows = TeachingWindows(self, self.model)
        # View: hover readout, measure distance, zoom to selection
        self.view_tools = ViewTools(
            self,
            self.plotter,
            self.scene,
            self.clicks,
            picker=self.teaching.picker,
            highlight=self.teaching.highlight,
            selected_triangles=self.teaching.selected_triangles,
            refit=self.refit_if_framed,
        )
        self.solve_panel.attach_inspector(self.teaching.inspector)  # I_n of its edge
        self.teaching.zoom_to_selection_requested.connect(self.view_tools.zoom_to_selection)
        self.teaching.zoom_to_points_requested.connect(self.view_tools.zoom_to_points)
        # Cell: unit-cell files and presets, the Elements dock, the array preview (issue 13)
        self.cell_tools = CellTools(
            self,
            self.model,
            self.plotter,
            self.scene,
            self.framing,
            self.clicks,
            controls=self.controls,
            parameters_dock=self.parameters_dock,
            run_export=self.files.run_export,
            world_at=self.view_tools.world_at,
            picker=self.teaching.picker,
        )

    def _study_action(self) -> QAction:
        """File → Design study (:mod:`barymesh.app.dialogs.study_dialog`), made on first use."""

        def open_study() -> None:
            from barymesh.app.dialogs.study_dialog import StudyDialog

            if getattr(self, "study_dialog", None) is None:
                solve = self.solve_panel  # the dialog starts from the Solve dock's wave
                self.study_dialog = StudyDialog(
                    lambda: self.model.params,
                    self.model.set_params,
                    parent=self,
                    incidence=(solve.direction.currentText(), solve.polarization.currentText()),
                )
            self.study_dialog.show()
            self.study_dialog.raise_()

        self.act_study = self.add_action(
            "Design stud&y…", open_study, tip="Vary two parameters over a frequency range on Dask"
        )
        return self.act_study

    def _make_menus(self) -> None:
        bar = self.menuBar()
        file = bar.addMenu("&File")
        file.addActions([self.act_open])
        file.addSeparator()
        file.addActions([self.act_load, self.act_save])
        file.addSeparator()
        file.addActions([self.act_export, self.act_shot, self.act_copy])
        file.addAction(self.teaching_windows.act_sweep)
        file.addAction(self._study_action())
        file.addSeparator()
        file.addAction(self.act_quit)

        presets = bar.addMenu("&Presets")
        try:
            from barymesh.presets import preset_descriptions

            descriptions = preset_descriptions()
        except Exception as exc:  # noqa: BLE001 - a broken preset file must not stop the window
            log.warning("presets unavailable: %s", exc)
            descriptions = {}
        for name, description in descriptions.items():
            act = presets.addAction(name)
            act.setStatusTip(description)
            act.setToolTip(description)
            act.triggered.connect(lambda _=False, n=name: self.load_preset(n))
        presets.setToolTipsVisible(True)
        if not descriptions:
            presets.addAction("(no presets found)").setEnabled(False)
        from barymesh.app.edit.painter_opener import PainterOpener, cell_menu

        self.cell_menu = cell_menu(self)  # the one "&Cell" menu every tool adds to
        self.cell_tools.add_to_menus(file, self.cell_menu, after=self.act_save)

        edit = bar.addMenu("&Edit")
        edit.addActions([self.act_undo, self.act_redo])
        edit.addSeparator()
        edit.addAction(self.act_reset)
        edit.addAction(self.act_cancel)

        view = bar.addMenu("&View")
        layers = view.addMenu("&Layers")
        layers.addActions(list(self.layer_actions.values()))
        colours = view.addMenu("&Colour faces by")
        colours.addActions(list(self.color_actions.values()))
        view.addSeparator()
        view.addActions([self.act_camera, self.act_top, self.view_tools.act_zoom])
        view.addAction(self.view_tools.act_measure)
        view.addSeparator()
        for dock in (
            self.parameters_dock,
            self.statistics_dock,
            self.layers_dock,
            self.solve_dock,
            self.quality_dock,
        ):
            view.addAction(dock.toggleViewAction())
        layers.addAction(self.quality_panel.act_layer)

        self.teach_menu = getattr(self, "teach_menu", None) or bar.addMenu("&Teach")
        self.teaching.add_to_menu(self.teach_menu)
        self.teaching_windows.add_to_menu(self.teach_menu)

        self.painter_opener = PainterOpener(self, self.cell_menu)  # Cell → Paint pixels…

        help_ = bar.addMenu("&Help")
        help_.addActions([self.act_help, self.act_about])

        tools = QToolBar("Toolbar", self)
        tools.setObjectName("toolbar")
        tools.addActions([self.act_undo, self.act_redo])
        tools.addSeparator()
        tools.addActions([self.act_camera, self.act_top])
        tools.addAction(self.view_tools.act_measure)
        tools.addSeparator()
        tools.addAction(self.act_shot)
        self.addToolBar(tools)
        view.addAction(tools.toggleViewAction())

    # -- model -> view -------------------------------------------------------------------

    def _show_result(self, result: MeshResult) -> None:
        if self._closed:
            return
        self.presenter.show(result)
        p = result.params
        s = result.stats
        title = (
            Path(result.source).name
            if result.source != "parameters"
            else (
                f"cell {result.cell.name}" if result.cell is not None else p.structure if p else ""
            )
        )
        self.setWindowTitle(f"barymesh – {title}")
        self.summary.setText(f"{s['triangles']:,} triangles · {s['interior_edges']:,} RWG unknowns")
        if self.model.error is None:
            preset = self._start_preset
            if (
                preset is not None
                and self._note_params is not None
                and self._note_params == preset[0]
            ):
                self.statusBar().showMessage(START_MESSAGE)  # until the first change
            else:
                self.statusBar().clearMessage()

    def _mesh_changed(self, mesh: TriMesh) -> None:
        """A new mesh is in the scene: the tools that pick and highlight in it follow."""
        self.teaching.mesh_changed(mesh)
        self.view_tools.mesh_changed(mesh)

    @property
    def paint_pending(self) -> bool:
        """Whether the mesh on screen still waits for its first paint
        (:attr:`.ScenePresenter.paint_pending`)."""
        return self.presenter.paint_pending

    def _show_error(self, error: ParamError | None) -> None:
        if error is None:
            self.statusBar().clearMessage()
        else:
            self.statusBar().showMessage(f"{error.name}: {error.message}")

    def _build_failed(self, message: str) -> None:
        self.statusBar().showMessage(f"{message} (the last good mesh stays on screen)")

    def cancel_build(self) -> None:
        """Abandon the running build; the parameters go back to the mesh on screen."""
        self.progress.cancel()

    def _layer_changed(self, name: str, visible: bool) -> None:
        if self._closed:
            return
        self.scene.set_visible(name, visible)
        act = self.layer_actions[name]
        if act.isChecked() != visible:
            act.setChecked(visible)
        self.request_render()

    def _color_by_changed(self, key: str) -> None:
        if self._closed:
            return
        self.presenter.set_color_by(key)
        self.color_actions[key].setChecked(True)
        self.refit_if_framed(render=False)  # a legend came or went: room for it
        self.request_render()

    def _status_message_changed(self, message: str) -> None:
        """A message gets the whole status bar: the triangle count steps aside meanwhile."""
        self.summary.setVisible(not message)
        self.statusBar().setToolTip(message)

    def _params_changed_note(self, params: MeshParams) -> None:
        if self._note_params is not None and params != self._note_params:
            self._note_params = None
            self.view_tools.set_note("")
            if self.statusBar().currentMessage() == START_MESSAGE:
                self.statusBar().clearMessage()

    def _history_changed(self) -> None:
        self.act_undo.setEnabled(self.model.can_undo)
        self.act_redo.setEnabled(self.model.can_redo)

    def _source_changed(self, _result: MeshResult) -> None:
        """A mesh file on screen has no parameters to save: say so on the action."""
        in_file = self.model.file_source is not None
        self.act_save.setEnabled(not in_file)
        self.act_save.setStatusTip(
            "The view holds a mesh file: go back to the parametric mesh to save parameters"
            if in_file
            else "Save the parameters as a JSON file"
        )

    def _camera_moved(self, *_args: Any) -> None:
        """The mouse moved the camera: line widths, dot sizes and what is drawn follow at
        once, the rulers and the note when it rests
        (:meth:`.ScenePresenter.camera_rested`)."""
        self.scene.fit_marker_sizes(settled=False)
        self.teaching.highlight.fit(pixels_per_mm(self.plotter))
        self.presenter.camera_moved()

    # -- view ----------------------------------------------------------------------------

    def request_render(self) -> None:
        """Schedule one repaint of the 3D view.

        pyvistaqt's widget renders the scene in its paintGL anyway; calling
        ``plotter.render()`` as well would draw every frame twice.
        """
        self.presenter.request_render()

    def reset_camera(self) -> None:
        """R: the whole mesh and its rulers from straight above, fitted to the view."""
        self.frame_mesh()
        self.request_render()

    def top_view(self) -> None:
        """T: straight down the z axis again (a tilt or roll undone), the zoom kept."""
        look_from_above(self.plotter)
        self.scene.fit_marker_sizes()
        self.request_render()

    def frame_mesh(self) -> None:
        """Frame the mesh and its rulers from above, fitted to the view's width and height;
        the view keeps it framed through resizes until the camera is moved."""
        if self.scene.bounds is None:
            self.scene.top_view()
        else:
            current_right, current_top = self.solve_panel.layer.reserved_px()
            frame_from_above(
                self.plotter,
                self.scene.bounds,
                right_px=max(self.scene.legend_px(), current_right),
                bottom_px=self.scene.note_px(),
                top_px=max(self.teaching.inspector.overlay.top_px(), current_top),
            )
        self.scene.fit_marker_sizes()
        self.teaching.highlight.fit(pixels_per_mm(self.plotter))
        self.framing.remember()

    def _current_shown(self, shown: bool) -> None:
        """The Surface current's colour bar came or went: the mesh is fitted beside it
        (the current layer renders next)."""
        self.scene.set_covered(shown)
        self.refit_if_framed(render=False)

    def refit_if_framed(self, render: bool = True) -> None:
        """After the view changed size: keep a framed mesh framed (not a moved camera).

        From the view's resize event pass ``render=False``: a resized widget is repainted
        anyway, and that one paint then shows the refitted camera."""
        if self._closed:
            return
        if self.framing.holds():
            self.frame_mesh()
            if render:
                self.request_render()

    # -- files: barymesh.app.file_actions.FileActions, under their old names ----------------

    @property
    def export_job(self) -> ExportJob | None:
        """The mesh export being written, if any (one at a time)."""
        return self.files.export_job

    @property
    def export_dialog(self) -> ExportDialog | None:
        """The last File → Export mesh dialog (None before the first)."""
        return self.files.export_dialog

    def view_image(self, scale: int = 1, transparent: bool = False) -> np.ndarray | None:
        """The 3D view as an image (:meth:`.FileActions.view_image`)."""
        return self.files.view_image(scale, transparent)

    def save_view_png(self, path: str | Path, scale: int = 1, transparent: bool = False) -> bool:
        """Write the 3D view to a PNG (:meth:`.FileActions.save_view_png`)."""
        return self.files.save_view_png(path, scale, transparent)

    def copy_view_to_clipboard(self, scale: int = 1, transparent: bool = False) -> None:
        """Copy the 3D view (:meth:`.FileActions.copy_view_to_clipboard`)."""
        self.files.copy_view_to_clipboard(scale, transparent)

    def open_mesh_file(self, path: str | Path) -> bool:
        """Show a mesh file (:meth:`.FileActions.open_mesh_file`)."""
        return self.files.open_mesh_file(path)

    def load_params_file(self, path: str | Path) -> bool:
        """Load parameters (:meth:`.FileActions.load_params_file`)."""
        return self.files.load_params_file(path)

    def save_params_file(self, path: str | Path) -> bool:
        """Save the parameters on screen (:meth:`.FileActions.save_params_file`)."""
        return self.files.save_params_file(path)

    def export_mesh(self, path: str | Path, unit: str | None = None) -> bool:
        """Write the mesh on screen now (:meth:`.FileActions.export_mesh`)."""
        return self.files.export_mesh(path, unit)

    def start_export(
        self,
        path: str | Path,
        unit: str | None = None,
        done: Callable[[bool], None] | None = None,
    ) -> bool:
        """Write the mesh on screen in a worker thread (:meth:`.FileActions.start_export`)."""
        return self.files.start_export(path, unit, done)

    def load_preset(self, name: str) -> bool:
        from barymesh.presets import load_preset

        try:
            params, description = load_preset(name)
        except (ValueError, OSError) as exc:
            self.file_error(f"Could not load preset {name}", exc)
            return False
        self._note_params = None
        self.model.set_params(params)
        # the description stays under the view until the parameters change
        self._note_params = params
        self.view_tools.set_note(f"Preset {name}: {description}")
        self.statusBar().showMessage(f"Preset {name}: {description}", 8000)
        return True

    def file_error(
        self, title: str, exc: BaseException, path: str | os.PathLike[str] | None = None
    ) -> None:
        """One sentence in the status bar (and a warning box): the file once, the reason
        in the file's terms."""
        sentence = file_error_sentence(title, exc, path)
        log.info("%s", sentence, exc_info=exc)
        self.statusBar().showMessage(sentence)
        if not self.scripted:
            box = QMessageBox(
                QMessageBox.Icon.Warning, "barymesh", sentence, QMessageBox.StandardButton.Ok, self
            )
            if path is not None:
                box.setInformativeText(f"File: {path}")
            box.exec()

    # -- help ----------------------------------------------------------------------------

    def show_about(self) -> HelpDialog:
        """About and the keyboard shortcuts (F1): a scrolling dialog that fits the screen."""
        dialog = getattr(self, "help_dialog", None)
        if dialog is None:
            dialog = self.help_dialog = HelpDialog(
                about_html(barymesh.__version__, self.findChildren(QAction)), self
            )
        dialog.show()
        dialog.raise_()
        dialog.activateWindow()
        return dialog

    # -- dock layout ---------------------------------------------------------------------

    def showEvent(self, event: Any) -> None:  # noqa: N802 - Qt's name
        super().showEvent(event)
        self.dock_layout.shown(isinstance(self.settings.value("window/state"), QByteArray))

    def resizeEvent(self, event: Any) -> None:  # noqa: N802 - Qt's name
        super().resizeEvent(event)
        self.dock_layout.resized()

    def save_settings(self) -> None:
        s = self.settings
        self.dock_layout.save(s)
        s.setValue("params", json.dumps(self.model.params.to_dict()))
        s.setValue("view", json.dumps(self.model.view_state()))
        s.sync()

    def closeEvent(self, event: QCloseEvent) -> None:  # noqa: N802 - Qt's name
        from barymesh.app.view.interactor import close_view

        if not hasattr(self, "controller"):
            # A constructor that raised left this window half made: free only its view.
            if (plotter := getattr(self, "plotter", None)) is not None:
                close_view(plotter)
        elif not self._closed:
            self._closed = True
            if not self.scripted:
                self.save_settings()
            self.controller.stop()  # returns at once; a running build is abandoned
            self.presenter.close()
            self.progress.stop()
            # Release VTK's render window and GL context while the widget still exists.
            close_view(self.plotter)
        super().closeEvent(event)
