"""The window's File menu: open a mesh file, load and save parameters, export the mesh
(in a worker thread, with progress and Cancel) and the 3D view as a PNG (1× to 4×).

These actions read and write files; they need the model, the 3D view and the window's
status bar, settings and error reports, not the window's panels or its menus. So
:class:`FileActions` gets the window's :class:`barymesh.app.tool_host.ToolHost` and what it
draws from, and the window keeps only thin methods of the same names
(``window.open_mesh_file``, ``window.start_export``, ``window.export_job``…) for scripts and
tests written against the window.
"""

from __future__ import annotations

import logging
from collections.abc import Callable
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np
from PySide6.QtCore import QSettings, Qt, QTimer
from PySide6.QtGui import QAction, QGuiApplication, QImage, QKeySequence
from PySide6.QtWidgets import QFileDialog, QProgressDialog

from barymesh import TriMesh
from barymesh.app.dialogs.export_dialog import ExportDialog
from barymesh.app.dialogs.screenshot_dialog import ScreenshotDialog, png_steps, write_png
from barymesh.app.dialogs.step_progress import run_in_steps
from barymesh.app.jobs import Jobs
from barymesh.app.model import AppModel, file_error_sentence
from barymesh.app.tool_host import ToolHost

log = logging.getLogger(__name__)

#: An export still writing after this many ms shows its progress dialog (with Cancel).
EXPORT_PROGRESS_MS = 300


@dataclass(eq=False)
class ExportJob:
    """One mesh export in a worker thread (:meth:`FileActions.run_export`)."""

    path: str
    what: str  # "out.msh (Gmsh MSH 2.2 ASCII, mm)"
    done: Callable[[bool], None] | None = None
    cancelled: bool = False
    progress: QProgressDialog | None = None
    wrote: Callable[[TriMesh, str], str] | None = None  # the status line once written
    mesh: TriMesh | None = None  # what was (or is being) written


class FileActions:
    """Open, save and export of one window.

    Parameters
    ----------
    host : ToolHost
        The window: the parent of the dialogs, the status bar, the remembered folders
        (``paths/…`` settings), file errors and render requests.
    settings : QSettings
        The window's settings, which the export and screenshot dialogs read and write
        themselves (unit, scale, transparency).
    model : AppModel
        Whose mesh on screen is exported, whose parameters are saved.
    plotter : pyvistaqt.QtInteractor
        The 3D view a screenshot is taken of.
    scene : barymesh.app.view.scene.MeshScene
        Its actors: a 2× to 4× screenshot draws them again off screen.
    """

    def __init__(
        self,
        host: ToolHost,
        settings: QSettings,
        model: AppModel,
        plotter: Any,
        scene: Any,
    ) -> None:
        self.host = host
        self.settings = settings
        self.model = model
        self.plotter, self.scene = plotter, scene
        self.export_job: ExportJob | None = None  # the export being written, if any
        self.export_dialog: ExportDialog | None = None  # the last File → Export mesh dialog
        self.jobs = Jobs(host.widget, name="barymesh-export")  # one export at a time

    def make_actions(self) -> tuple[QAction, ...]:
        """The File menu's actions, made through the host (its shortcuts work with the
        menu bar hidden): open, load and save parameters, export, screenshot, copy. Without
        :mod:`barymesh.io` (never in a full install) open and export are disabled and
        say why."""
        a = self.host.add_action
        actions = (
            a(
                "&Open mesh file…",
                self.open_mesh_dialog,
                QKeySequence.StandardKey.Open,
                "Import a mesh file (msh, vtk, stl, obj, mat…) to inspect it",
            ),
            a("&Load parameters…", self.load_params_dialog, "Ctrl+L", "Load a JSON parameter file"),
            a(
                "&Save parameters…",
                self.save_params_dialog,
                QKeySequence.StandardKey.Save,
                "Save the parameters as a JSON file",
            ),
            a(
                "&Export mesh…",
                self.export_mesh_dialog,
                "Ctrl+E",
                "Write the mesh in a solver's format",
            ),
            a(
                "Export &screenshot…",
                self.screenshot_dialog,
                "Ctrl+Shift+E",
                "Save a PNG of the 3D view (1–4×, optionally transparent)",
            ),
            a(
                "&Copy screenshot",
                lambda: self.copy_view_to_clipboard(),
                "Ctrl+Shift+C",
                "Copy the 3D view to the clipboard",
            ),
        )
        try:
            from barymesh.io import EXPORT_FORMATS, IMPORT_FORMATS  # noqa: F401
        except ImportError as exc:  # pragma: no cover - barymesh.io ships with core
            for act in (actions[0], actions[3]):
                act.setEnabled(False)
                act.setToolTip(f"mesh files need barymesh.io ({exc})")
        return actions

    # -- the 3D view as an image -----------------------------------------------------------

    def view_image(self, scale: int = 1, transparent: bool = False) -> np.ndarray | None:
        """The 3D view as an (h·scale, w·scale, 3 or 4) uint8 array that looks like the view.

        At 2× to 4× the scene is drawn again off screen at that size, fonts, ruler offsets,
        lines and dots scaled along (:mod:`barymesh.app.view.scaled_shot`), one render at a
        time under a progress dialog with Cancel (the window answers between them); None
        when cancelled."""
        from barymesh.app.view.scaled_shot import MAX_SCALE, ScaledShot

        if not 1 <= int(scale) <= MAX_SCALE:
            raise ValueError(f"scale={scale!r} is outside 1..{MAX_SCALE}")
        self._settle_for_export()
        if int(scale) > 1:
            shot = ScaledShot(self.scene, int(scale), transparent)
            w, h = shot.size
            if not run_in_steps(
                self.host.widget, "Export screenshot", f"Drawing {w} × {h} px", shot.steps()
            ):
                return None
            return shot.image
        self.plotter.ren_win.Render()  # the scene as it is now, not the last frame shown
        image = self.plotter.screenshot(None, transparent_background=transparent, return_img=True)
        self.plotter.render()
        return np.ascontiguousarray(image)

    def save_view_png(self, path: str | Path, scale: int = 1, transparent: bool = False) -> bool:
        """Write the 3D view to a PNG; errors go to the status bar. Returns success.

        At 2× to 4× it is drawn in steps and written in a worker thread, under a progress
        dialog whose Cancel leaves no file (:meth:`view_image`)."""
        from barymesh.app.view.scaled_shot import ScaledShot

        name = Path(path).name
        try:
            self._settle_for_export()
            if int(scale) > 1:
                shot = ScaledShot(self.scene, int(scale), transparent)
                w, h = shot.size
                if not run_in_steps(
                    self.host.widget,
                    "Export screenshot",
                    f"Saving {name} ({w} × {h} px)",
                    png_steps(shot, path, self.host.widget),
                ):
                    self.host.show_status(f"Screenshot {name} cancelled: no file written", 5000)
                    return False
            else:
                image = self.view_image(1, transparent)
                assert image is not None  # only a drawing in steps (2× to 4×) is cancelled
                write_png(path, image)
        except Exception as exc:  # noqa: BLE001 - shown, never raised to the user
            log.exception("screenshot failed")
            self.host.show_status(file_error_sentence(f"Could not save {name}", exc, path))
            return False
        self.host.show_status(f"Saved {path}", 5000)
        return True

    def _settle_for_export(self) -> None:
        """An export shows the view as it is at rest: rulers and note laid out for the
        camera now (they wait for the rest while the camera moves)."""
        if self.scene.settle():
            self.host.request_render()

    def copy_view_to_clipboard(self, scale: int = 1, transparent: bool = False) -> None:
        image = self.view_image(scale, transparent)
        if image is None:
            self.host.show_status("Copy of the view cancelled", 5000)
            return
        h, w, c = image.shape
        fmt = QImage.Format.Format_RGBA8888 if c == 4 else QImage.Format.Format_RGB888
        qimage = QImage(image.data, w, h, c * w, fmt).copy()
        QGuiApplication.clipboard().setImage(qimage)
        self.host.show_status(f"Copied a {w} × {h} px image of the view", 5000)

    def screenshot_dialog(self) -> None:
        ScreenshotDialog(
            self.host.widget,
            self.settings,
            (self.plotter.width(), self.plotter.height()),
            self.save_view_png,
            self.copy_view_to_clipboard,
        ).exec()

    # -- mesh and parameter files ------------------------------------------------------------

    def _path_setting(self, key: str, default: str) -> str:
        return str(self.host.setting(f"paths/{key}", default))

    def open_mesh_dialog(self) -> None:
        from barymesh.io import IMPORT_EXTENSIONS

        patterns = " ".join(f"*{e}" for e in IMPORT_EXTENSIONS)
        path, _ = QFileDialog.getOpenFileName(
            self.host.widget,
            "Open mesh file",
            self._path_setting("mesh", ""),
            f"Mesh files ({patterns});;All files (*)",
        )
        if path:
            self.host.set_setting("paths/mesh", path)
            self.open_mesh_file(path)

    def open_mesh_file(self, path: str | Path) -> bool:
        """Show a mesh read from ``path`` until the next parameter change."""
        from barymesh.io import read_mesh

        try:
            mesh: TriMesh = read_mesh(path)
        except (ValueError, OSError) as exc:
            self.host.file_error(f"Could not open {Path(path).name}", exc, path)
            return False
        result = self.model.show_imported(mesh, str(path))
        if not self.model.set_result(result):
            return False
        self.host.show_status(
            f"Opened {Path(path).name}: {mesh.n_triangles:,} triangles. The parameters apply "
            "again with Back to the parametric mesh (Parameters panel).",
            8000,
        )
        return True

    def load_params_dialog(self) -> None:
        path, _ = QFileDialog.getOpenFileName(
            self.host.widget,
            "Load parameters",
            self._path_setting("params", ""),
            "Parameter files (*.json);;All files (*)",
        )
        if path:
            self.host.set_setting("paths/params", path)
            self.load_params_file(path)

    def load_params_file(self, path: str | Path) -> bool:
        from barymesh.presets import load_params_file

        try:
            params = load_params_file(path)
        except (ValueError, OSError) as exc:
            self.host.file_error(f"Could not load {Path(path).name}", exc, path)
            return False
        self.model.set_params(params)
        return True

    def save_params_dialog(self) -> None:
        path, _ = QFileDialog.getSaveFileName(
            self.host.widget,
            "Save parameters",
            self._path_setting("params", "barymesh-params.json"),
            "Parameter files (*.json)",
        )
        if path:
            if not path.lower().endswith(".json"):
                path += ".json"
            self.host.set_setting("paths/params", path)
            self.save_params_file(path)

    def save_params_file(self, path: str | Path) -> bool:
        from barymesh.presets import save_params_file

        if self.model.file_source is not None:
            self.host.show_status(
                f"Not saved: the view holds {Path(self.model.file_source).name}, which has no "
                "parameters; go back to the parametric mesh first"
            )
            return False
        result = self.model.result  # the parameters of the mesh on screen, as exported
        params = result.params if result is not None and result.params else self.model.params
        try:
            save_params_file(params, path)
        except (ValueError, OSError) as exc:
            self.host.file_error(f"Could not save {Path(path).name}", exc, path)
            return False
        newer = " (those of the mesh on screen; newer ones are being meshed)"
        self.host.show_status(f"Saved {path}{newer if params != self.model.params else ''}", 5000)
        return True

    # -- mesh export -------------------------------------------------------------------------

    def export_mesh_dialog(self) -> ExportDialog:
        """File → Export mesh: a file, its format and the length unit (window-modal)."""
        dialog = ExportDialog(
            self.host.widget, self.settings, self.start_export, self.host.status_message
        )
        dialog.open()
        self.export_dialog = dialog
        return dialog

    def export_mesh(self, path: str | Path, unit: str | None = None) -> bool:
        """Write the mesh on screen to ``path`` now, on the GUI thread (scripts' way; the
        menu's goes through :meth:`start_export`). Returns success."""
        from barymesh.io import describe_export, write_mesh
        from barymesh.quality import params_wavelength

        result = self.model.result
        if result is None or result.mesh is None:
            self.host.show_status("No mesh to export yet")
            return False
        try:
            params = result.params if result.source == "parameters" else None
            write_mesh(result.mesh, path, unit=unit, wavelength=params_wavelength(params))
            what = describe_export(path, unit)
        except (ValueError, OSError) as exc:
            self.host.file_error(f"Could not export {Path(path).name}", exc, path)
            return False
        self.host.show_status(f"Wrote {what}", 5000)
        return True

    def start_export(
        self,
        path: str | Path,
        unit: str | None = None,
        done: Callable[[bool], None] | None = None,
    ) -> bool:
        """Write the mesh on screen to ``path`` in a worker thread; the window answers.

        A progress dialog (after a moment) shows what is written and has Cancel: a
        cancelled export leaves no file and no temporary file. ``done(ok)`` follows on
        the GUI thread. Returns whether the export started (False: nothing to export, an
        export still running or an unknown extension or unit, said in the status bar).
        """
        from barymesh.quality import params_wavelength

        result = self.model.result
        if result is None or result.mesh is None:
            self.host.show_status("No mesh to export yet")
            return False
        mesh = result.mesh
        params = result.params if result.source == "parameters" else None
        return self.run_export(
            path,
            unit,
            lambda: mesh,
            f"{mesh.n_triangles:,} triangles",
            done,
            wavelength=params_wavelength(params),
        )

    def run_export(
        self,
        path: str | Path,
        unit: str | None,
        make_mesh: Callable[[], TriMesh],
        what: str,
        done: Callable[[bool], None] | None = None,
        *,
        wavelength: float | None = None,
        wrote: Callable[[TriMesh, str], str] | None = None,
    ) -> bool:
        """Make a mesh and write it to ``path`` in a worker thread (see :meth:`start_export`).

        ``make_mesh()`` runs in the thread too (numpy only, no VTK); ``what`` says what is
        written in the progress dialog; ``wrote(mesh, described_path)`` the status line.
        One export at a time: a second one is refused while ``export_job`` is set.
        """
        from barymesh.io import describe_export, write_mesh

        if self.export_job is not None:
            self.host.show_status(
                f"Still writing {Path(self.export_job.path).name}; wait or cancel it first"
            )
            return False
        try:
            described = describe_export(path, unit)
        except ValueError as exc:
            self.host.file_error(f"Could not export {Path(path).name}", exc, path)
            return False
        job = ExportJob(str(path), described, done, wrote=wrote)
        progress = QProgressDialog(
            f"Writing {Path(path).name}: {what}…", "Cancel", 0, 0, self.host.widget
        )
        progress.setWindowTitle("Export mesh")
        progress.setWindowModality(Qt.WindowModality.WindowModal)
        progress.setAutoClose(False)
        progress.setAutoReset(False)
        progress.canceled.connect(lambda: self._cancel_export(job))
        progress.hide()
        job.progress = progress
        self.export_job = job

        # a quick write shows no dialog at all; a longer one shows it after a moment
        def show_progress() -> None:
            if job.progress is not None:
                job.progress.show()

        QTimer.singleShot(EXPORT_PROGRESS_MS, show_progress)

        def work() -> BaseException | None:  # worker thread: numpy and files only
            try:
                job.mesh = make_mesh()
                write_mesh(
                    job.mesh,
                    path,
                    unit=unit,
                    wavelength=wavelength,
                    cancelled=lambda: job.cancelled,
                )
            except Exception as exc:  # noqa: BLE001 - reported on the GUI thread
                return exc
            return None

        self.jobs.submit(work, self._export_finished, job)
        return True

    def _cancel_export(self, job: ExportJob) -> None:
        job.cancelled = True
        if job.progress is not None:
            job.progress.setLabelText(f"Cancelling {Path(job.path).name}…")

    def _export_finished(self, job: ExportJob, error: BaseException | None) -> None:
        from barymesh.io import ExportCancelled

        if job.progress is not None:
            job.progress.canceled.disconnect()  # closing a progress dialog emits canceled
            job.progress.close()
            job.progress.deleteLater()
            job.progress = None
        if self.export_job is job:
            self.export_job = None
        ok = error is None
        if isinstance(error, ExportCancelled):
            self.host.show_status(
                f"Export of {Path(job.path).name} cancelled: no file written", 5000
            )
        elif error is not None:
            if not isinstance(error, ValueError | OSError):
                log.error("export failed", exc_info=error)
            self.host.file_error(f"Could not export {Path(job.path).name}", error, job.path)
        else:
            assert job.mesh is not None  # the write succeeded: the work made the mesh
            wrote = job.wrote(job.mesh, job.what) if job.wrote is not None else f"Wrote {job.what}"
            if job.cancelled:  # Cancel came after the file was complete and in place
                wrote += " (complete before Cancel)"
            self.host.show_status(wrote, 8000)
        if job.done is not None:
            job.done(ok)
