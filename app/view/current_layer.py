"""The "Surface current" layer: |J| per triangle as a colour map, Re(J e^{jωt}) as arrows.

A :class:`CurrentLayer` owns its own actors on the window's plotter (a copy of the
mesh's triangles coloured by |J|, a scalar bar, and arrows at the centroids) and never
touches :class:`barymesh.app.view.scene.MeshScene`. Every change asks for one repaint through the
``request_render`` callable it is given (the window's render path).

The arrows show the instantaneous real current at phase ωt = φ of the e^{jωt} time
convention: Re(J e^{jφ}); a phase slider that steps φ animates them.
"""

from __future__ import annotations

import logging
from collections.abc import Callable
from typing import Any

import numpy as np

from barymesh import TriMesh

log = logging.getLogger(__name__)

#: Cell-data names on the layer's surface: |J| (A/m) and Re(ρ_s e^{jφ}) (C/m²).
MAGNITUDE = "|J| (A/m)"
CHARGE = "Re rho_s (C/m^2)"
#: What the colours show: |J|, or the surface charge density at phase φ.
QUANTITIES = ("current", "charge")
#: Titles of the colour bar (VTK's font draws no "|" nor Greek).
BAR_TITLE = "current density (A/m)"
CHARGE_TITLE = "charge density (C/m2)"
#: Colour map of |J| (pale yellow to dark red) and the arrows' colour, dark on all of it.
COLORMAP = "YlOrRd"
ARROW_COLOR = "#10206b"
#: Scales of the colour map.
SCALES = ("linear", "log")
#: On the log scale the colour map spans this many decades below the largest |J|.
LOG_DECADES = 3.0
#: The longest arrow, as a fraction of the median triangle's room (see :func:`arrow_room`).
ARROW_LENGTH = 1.0
#: The arrow glyph: tip length and radius, shaft radius, as fractions of its length.
ARROW_TIP, ARROW_TIP_RADIUS, ARROW_SHAFT = 0.4, 0.2, 0.07


def arrow_room(points: np.ndarray, triangles: np.ndarray) -> np.ndarray:
    """The longest arrow each triangle holds: centred on its centroid, at any angle, tip
    included, it stays inside the triangle.

    The centroid lies ``h / 3`` from each side (``h`` that side's height), so a disc of
    radius ``r = 2 A / (3 ℓmax)`` about it is inside the triangle. A centred arrow of
    length ``L`` reaches ``L √(1/4 + tip radius²)`` from its centre (the barbs at the
    tip), so it fits in that disc for ``L = r / √(1/4 + tip radius²)``.

    Parameters
    ----------
    points : (n, 3) float
    triangles : (m, 3) int

    Returns
    -------
    (m,) float64
        Lengths in the points' units.

    >>> tri = np.array([[0.0, 0, 0], [1, 0, 0], [0, 1, 0]])
    >>> round(float(arrow_room(tri, np.array([[0, 1, 2]]))[0]), 4)  # r = 1 / (3 √2)
    0.4377
    """
    p = np.asarray(points, dtype=np.float64)[np.asarray(triangles, dtype=np.int64)]
    sides = np.linalg.norm(p[:, [1, 2, 0]] - p, axis=2)  # (m, 3)
    area = 0.5 * np.linalg.norm(np.cross(p[:, 1] - p[:, 0], p[:, 2] - p[:, 0]), axis=1)
    radius = 2.0 * area / (3.0 * np.maximum(sides.max(axis=1), 1e-300))
    return radius / np.sqrt(0.25 + ARROW_TIP_RADIUS**2)


def arrow_vectors(current: np.ndarray, phase_deg: float) -> np.ndarray:
    """Re(J e^{jφ}) at each centroid: the real current at ωt = φ.

    Parameters
    ----------
    current : (T, 3) complex
        Surface current density J at the centroids (A/m).
    phase_deg : float
        φ in degrees.

    Returns
    -------
    (T, 3) float64

    >>> arrow_vectors(np.array([[1j, 0, 0]]), 90.0).round(12)
    array([[-1.,  0.,  0.]])
    """
    return np.real(np.asarray(current) * np.exp(1j * np.deg2rad(phase_deg)))


class CurrentLayer:
    """|J| colour map and phase-animated arrows on ``plotter`` (see module docstring).

    Parameters
    ----------
    plotter : pyvista.Plotter
        The window's plotter; the layer adds and removes only its own actors.
    request_render : callable
        Schedules one repaint (``MainWindow.request_render``).
    shown_changed : callable, optional
        Called with :attr:`shown` whenever a current comes, goes, is hidden or shown
        (the window's scene then lets the arrows stand out: see
        :meth:`barymesh.app.view.scene.MeshScene.set_covered`).
    """

    def __init__(
        self,
        plotter: Any,
        request_render: Callable[[], None],
        shown_changed: Callable[[bool], None] | None = None,
    ) -> None:
        self.plotter = plotter
        self.request_render = request_render
        self.shown_changed = shown_changed
        self.mesh: TriMesh | None = None
        self.current: np.ndarray | None = None  # (T, 3) complex
        self.magnitude: np.ndarray | None = None  # (T,) float
        self.surface: Any = None  # pyvista.PolyData with MAGNITUDE cell data
        self.arrows: Any = None  # pyvista.PolyData of the arrow glyphs
        self.vectors: np.ndarray | None = None  # (T, 3) Re(J e^{jφ}) the arrows show
        self.charge: np.ndarray | None = None  # (T,) complex ρ_s (C/m²)
        self.quantity = "current"
        self.scale = "linear"
        self.phase = 0.0
        self.visible = True
        self._surface_actor: Any = None
        self._arrow_actor: Any = None
        self._bar_title: str | None = None
        self._arrow: Any = None  # the glyph's arrow (pyvista.PolyData), made once
        self._room = np.ones(0)  # (T,) the longest arrow each triangle holds (mm)
        self._arrow_scale = 1.0  # the longest arrow (mm)

    @property
    def shown(self) -> bool:
        """Whether a current is on screen."""
        return self.current is not None and self.visible

    # -- data ------------------------------------------------------------------------

    def set_current(
        self, mesh: TriMesh, current: np.ndarray, charge: np.ndarray | None = None
    ) -> None:
        """Show ``current`` ((T, 3) complex, A/m at the centroids of ``mesh``) and keep
        ``charge`` ((T,) complex ρ_s, C/m²) for the charge colouring.

        A new current updates the layer's arrays in place, on the mesh already shown or
        on a new one (the actors and the colour bar are kept: no actor is added).
        """
        current = np.asarray(current)
        if current.shape != (len(mesh.triangles), 3):
            raise ValueError(
                f"current has shape {current.shape}; expected "
                f"({len(mesh.triangles)}, 3) for this mesh"
            )
        if charge is not None and np.shape(charge) != (len(mesh.triangles),):
            raise ValueError(
                f"charge has shape {np.shape(charge)}; expected "
                f"({len(mesh.triangles)},) for this mesh"
            )
        import pyvista as pv

        drawn = self._surface_actor is not None and self.surface is not None
        new_mesh = mesh is not self.mesh
        self.mesh, self.current = mesh, current
        self.charge = None if charge is None else np.asarray(charge)
        self.magnitude = np.linalg.norm(np.abs(current), axis=1)
        if new_mesh:
            tri = np.asarray(mesh.triangles, dtype=np.int64)
            faces = np.column_stack([np.full(len(tri), 3, dtype=np.int64), tri]).ravel()
            surface = pv.PolyData(np.asarray(mesh.points, dtype=float), faces)
            # the longest arrow: the typical triangle's room; each arrow is kept to its own
            # triangle's (a graded mesh's small triangles), so none leaves its triangle
            self._room = arrow_room(mesh.points, tri) if len(tri) else np.ones(0)
            typical = float(np.median(self._room)) if len(tri) else 1.0
            self._arrow_scale = ARROW_LENGTH * max(typical, 1e-300)
            if drawn:  # the dataset the mapper reads takes the new mesh
                self.surface.copy_from(surface)
            else:
                self.surface = surface
        self._set_arrays()
        if drawn:
            self._refresh()
            return
        self._draw()

    def clear(self) -> None:
        """Remove the layer's actors (the mesh changed, or no result)."""
        self.mesh = self.current = self.magnitude = self.surface = self.arrows = None
        self.vectors = self.charge = None
        self._remove_actors()
        self._announce()
        self.request_render()

    def set_scale(self, scale: str) -> None:
        """``"linear"`` or ``"log"`` colour map of |J|."""
        if scale not in SCALES:
            raise ValueError(f"scale={scale!r}; expected one of {SCALES}")
        if scale != self.scale:
            self.scale = scale
            self._draw()

    def set_quantity(self, quantity: str) -> None:
        """Colour by ``"current"`` (|J|) or ``"charge"`` (Re(ρ_s e^{jφ}), signed)."""
        if quantity not in QUANTITIES:
            raise ValueError(f"quantity={quantity!r}; expected one of {QUANTITIES}")
        if quantity != self.quantity:
            self.quantity = quantity
            self._draw()

    def set_phase(self, phase_deg: float) -> None:
        """Turn the arrows to Re(J e^{jφ}) at φ = ``phase_deg`` (and the charge colours
        to Re(ρ_s e^{jφ})); one repaint."""
        self.phase = float(phase_deg) % 360.0
        if self.current is None or self.arrows is None:
            return
        if self.quantity == "charge":
            self._set_arrays()
        self.arrows.copy_from(self._glyphs())
        self.arrows.Modified()
        self.request_render()

    def _set_arrays(self) -> None:
        """|J| and Re(ρ_s e^{jφ}) on the surface, the shown one active (the mapper
        colours by the active cell scalars)."""
        self.surface.cell_data[MAGNITUDE] = self.magnitude
        self.surface.cell_data[CHARGE] = self._charge_values()
        self.surface.set_active_scalars(
            CHARGE if self.quantity == "charge" else MAGNITUDE, preference="cell"
        )
        self.surface.Modified()

    def _charge_values(self) -> np.ndarray:
        """(T,) Re(ρ_s e^{jφ}) (zeros without a charge density)."""
        assert self.current is not None  # a current is shown
        if self.charge is None:
            return np.zeros(len(self.current))
        return np.real(self.charge * np.exp(1j * np.deg2rad(self.phase)))

    def _colouring(self) -> tuple[str, list[float], bool, str, str]:
        """(array, clim, log scale, colour map, bar title) of the current quantity."""
        assert self.magnitude is not None  # a current is shown
        if self.quantity == "charge":
            peak = float(np.abs(self.charge).max()) if self.charge is not None else 0.0
            peak = peak if peak > 0 else 1.0
            return CHARGE, [-peak, peak], False, "coolwarm", CHARGE_TITLE
        peak = float(self.magnitude.max())
        log_scale = self.scale == "log" and peak > 0
        clim = [peak * 10**-LOG_DECADES, peak] if log_scale else [0.0, peak if peak > 0 else 1.0]
        return (
            MAGNITUDE,
            clim,
            log_scale,
            COLORMAP,
            f"{BAR_TITLE}{', log scale' if log_scale else ''}",
        )

    def _refresh(self) -> None:
        """New values on the same mesh: colour range and arrows updated, actors kept."""
        _name, clim, _log, _cmap, _title = self._colouring()
        self._surface_actor.GetMapper().SetScalarRange(*clim)
        self.arrows.copy_from(self._glyphs())
        self.arrows.Modified()
        self.request_render()

    def set_visible(self, visible: bool) -> None:
        self.visible = bool(visible)
        for actor in (self._surface_actor, self._arrow_actor):
            if actor is not None:
                actor.SetVisibility(self.visible)
        if self._bar_title is not None and self._bar_title in self.plotter.scalar_bars:
            self.plotter.scalar_bars[self._bar_title].SetVisibility(self.visible)
        self._announce()
        self.request_render()

    def reserved_px(self) -> tuple[float, float]:
        """(right, top): pixels of the view the colour bar takes while a current is shown
        (a vertical bar at the right, a horizontal one at the top), for the framing to
        keep free, so that the mesh and its arrows stay clear of the bar."""
        if not self.shown or self._bar_title not in self.plotter.scalar_bars:
            return 0.0, 0.0
        bar = self.plotter.scalar_bars[self._bar_title]
        w, h = self.plotter.window_size
        x, y = bar.GetPosition()
        if bar.GetOrientation() == 1:  # vertical: its numbers and title left of x
            return (1.0 - x) * w + 0.04 * w, 0.0
        return 0.0, (1.0 - y) * h + 14.0  # horizontal: the numbers and title under it

    def _announce(self) -> None:
        if self.shown_changed is not None:
            self.shown_changed(self.shown)

    # -- drawing ---------------------------------------------------------------------

    def _glyphs(self) -> Any:
        """The arrows: ``pyvista.Arrow`` glyphs at the centroids, longest = the scale."""
        import pyvista as pv

        assert self.mesh is not None and self.current is not None and self.magnitude is not None

        vectors = self.vectors = arrow_vectors(self.current, self.phase)
        peak = float(self.magnitude.max()) if self.magnitude.size else 0.0
        drawn = vectors * (self._arrow_scale / peak if peak > 0 else 0.0)
        length = np.linalg.norm(drawn, axis=1)
        over = length > self._room
        drawn[over] *= (self._room[over] / length[over])[:, None]
        # each arrow centred on its centroid (a glyph starts at its point)
        cloud = pv.PolyData(
            np.asarray(self.mesh.centroids, dtype=float)
            - 0.5 * drawn
            + np.array([0.0, 0.0, 1e-3 * self._arrow_scale])
        )
        cloud["J"] = drawn
        if self._arrow is None:  # one arrow shape for every step
            self._arrow = pv.Arrow(
                tip_length=ARROW_TIP, tip_radius=ARROW_TIP_RADIUS, shaft_radius=ARROW_SHAFT
            )
        return cloud.glyph(orient="J", scale="J", factor=1.0, geom=self._arrow)

    def _remove_actors(self) -> None:
        for actor in (self._surface_actor, self._arrow_actor):
            if actor is not None:
                self.plotter.remove_actor(actor, render=False)
        if self._bar_title is not None and self._bar_title in self.plotter.scalar_bars:
            self.plotter.remove_scalar_bar(self._bar_title, render=False)
        self._surface_actor = self._arrow_actor = self._bar_title = None

    def _bar_args(self) -> dict[str, Any]:
        """The colour bar where the framed mesh leaves room: above it in a tall view,
        at its right in a wide one."""
        args = {
            "title": self._bar_title,
            "fmt": "%.2g",
            "color": "black",
            "title_font_size": 12,
            "label_font_size": 11,
            "n_labels": 4,
        }
        w, h = self.plotter.window_size  # the render window's pixels (Qt or not)
        if w > 1.15 * h:
            return args | {
                "vertical": True,
                "position_x": 0.86,
                "position_y": 0.3,
                "width": 0.1,
                "height": 0.4,
            }
        return args | {
            "vertical": False,
            "position_x": 0.3,
            "position_y": 0.905,
            "width": 0.4,
            "height": 0.09,
        }

    def _draw(self) -> None:
        self._remove_actors()
        if self.current is None:
            self.request_render()
            return
        name, clim, log_scale, cmap, self._bar_title = self._colouring()
        self._surface_actor = self.plotter.add_mesh(
            self.surface,
            scalars=name,
            cmap=cmap,
            clim=clim,
            log_scale=log_scale,
            show_edges=False,
            lighting=False,
            reset_camera=False,
            render=False,
            name="surface_current",
            pickable=False,
            scalar_bar_args=self._bar_args(),
        )
        # the mapper reads self.surface through pyvista's producer: Modified() on it makes
        # the next render take new values
        bar = self.plotter.scalar_bars[self._bar_title]
        bar.SetTextPositionToPrecedeScalarBar()  # numbers under (left of) the bar
        # VTK sets the title against the numbers (under them on a horizontal bar, over the
        # top one on a vertical bar): a blank line between them keeps them apart
        vertical = bar.GetOrientation() == 1
        bar.SetTitle(f"{self._bar_title}\n " if vertical else f" \n{self._bar_title}")
        # drawn just in front of the scene's faces, which lie in the same plane
        mapper = self._surface_actor.GetMapper()
        mapper.SetResolveCoincidentTopologyToPolygonOffset()
        mapper.SetRelativeCoincidentTopologyPolygonOffsetParameters(-4.0, -8.0)
        self.arrows = self._glyphs()
        self._arrow_actor = self.plotter.add_mesh(
            self.arrows,
            color=ARROW_COLOR,
            lighting=False,
            reset_camera=False,
            render=False,
            name="surface_current_arrows",
            pickable=False,
            show_scalar_bar=False,
        )
        self.set_visible(self.visible)
