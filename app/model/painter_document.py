"""The pixel painter's document, without Qt: a coding cell's pixel grid and lattice with
their undo history, the rest of the cell, the symmetry every edit keeps, and the edits.

:class:`barymesh.app.edit.painter.PixelPainterWindow` draws this document and turns the
mouse and its fields into the calls below; everything it decides (what an edit makes, which
symmetry holds on a grid that stopped being square, where a resized grid lies and whether
the lattice follows it, what is saved) is decided here and tested without a window
(``tests/test_app_painter_document.py``). The pixel operations themselves are
:mod:`barymesh.app.model.pixels`.
"""

from __future__ import annotations

import dataclasses
import logging
from pathlib import Path

import numpy as np

from barymesh.app.model import pixels
from barymesh.app.model.undo_history import UndoHistory
from barymesh.cell import Lattice, PixelGrid, UnitCell, load_cell, load_cell_preset, save_cell

log = logging.getLogger(__name__)

#: The cell the painter opens on.
START_PRESET = "coding-16x16"
#: The name a saved cell's file ends with.
SUFFIX = ".cell.json"
#: Said while a 4- or 8-fold symmetry waits for the grid to be square again.
NOT_SQUARE = (
    "The grid is not square: symmetry none until it is square again (4- and "
    "8-fold need a square grid)"
)


@dataclasses.dataclass(frozen=True)
class PainterState:
    """One undo step: the pixel grid and the lattice (the lattice follows a resize)."""

    grid: PixelGrid
    lattice: Lattice


class NothingToSave(ValueError):
    """The cell has no metal (no element, no pixel): there is no cell to write."""


class PainterDocument:
    """The edited cell: its grid and lattice under undo, its other parts, the symmetry.

    Parameters
    ----------
    cell : UnitCell, optional
        The cell to edit (:meth:`open`). Default: the 16 x 16 coding cell preset.
    """

    def __init__(self, cell: UnitCell | None = None) -> None:
        #: The symmetry every edit keeps (a key of :data:`barymesh.cell.SYMMETRIES`).
        self.symmetry = "none"
        #: A 4- or 8-fold symmetry put aside while the grid is not square.
        self.square_symmetry: str | None = None
        #: The file the cell was last opened from or saved to.
        self.path: Path | None = None
        self.open(cell if cell is not None else start_cell())

    # -- the state -------------------------------------------------------------------------

    @property
    def state(self) -> PainterState:
        return self.history.current

    @property
    def grid(self) -> PixelGrid:
        """The pixel grid being painted."""
        return self.state.grid

    @property
    def mask(self) -> np.ndarray:
        """(R, C) bool: the grid's mask (row 0 at the bottom)."""
        return self.state.grid.mask

    @property
    def lattice(self) -> Lattice:
        return self.state.lattice

    @property
    def has_elements(self) -> bool:
        """Whether the cell has elements beside its pixels."""
        return bool(self._cell.elements)

    @property
    def name(self) -> str:
        return self._cell.name

    def cell(self) -> UnitCell | None:
        """The edited cell (None when it would have no metal: no element, no pixel)."""
        state = self.state
        if not self._cell.elements and not state.grid.mask.any():
            return None
        return dataclasses.replace(self._cell, lattice=state.lattice, pixels=state.grid)

    def open(self, cell: UnitCell) -> None:
        """Edit ``cell`` (a new history). A cell without a grid gets an empty one over it
        (:func:`blank_grid`); a painted one starts in the largest symmetry it has."""
        grid = cell.pixels if cell.pixels is not None else blank_grid(cell.lattice)
        self._cell = cell
        self.history: UndoHistory[PainterState] = UndoHistory(PainterState(grid, cell.lattice))
        if grid.mask.any():
            fits = [
                m
                for m in ("8-fold", "4-fold", "mirror_x", "mirror_y")
                if square_or_mirror(m, grid.shape) and pixels.is_invariant(grid.mask, m)
            ]
            self.symmetry = fits[0] if fits else "none"
            self.square_symmetry = None

    def open_file(self, path: str | Path) -> None:
        """Edit the cell of a ``*.cell.json`` file (raises ``OSError``/``ValueError``, and
        then nothing changes)."""
        cell = load_cell(path)
        self.path = Path(path)
        self.open(cell)

    def save(self, path: str | Path) -> Path:
        """Write the cell to ``path`` (given the ``.cell.json`` suffix); returns the path
        written. Raises :class:`NothingToSave`, or ``OSError``/``ValueError`` of the write."""
        path = Path(path)
        if not path.name.endswith(SUFFIX):
            path = path.with_name(path.name.removesuffix(".json") + SUFFIX)
        cell = self.cell()
        if cell is None:
            raise NothingToSave("Nothing to save: the cell has no metal")
        save_cell(cell, path)
        self.path = path
        return path

    # -- undo --------------------------------------------------------------------------------

    def push(self, grid: PixelGrid, lattice: Lattice | None = None) -> bool:
        """Make (grid, lattice) the current state, one undo step (False when unchanged)."""
        state = PainterState(grid, lattice or self.lattice)
        if state.grid == self.grid and state.lattice == self.lattice:
            return False
        self.history.push(state)
        return True

    def undo(self) -> bool:
        return self.history.undo() is not None

    def redo(self) -> bool:
        return self.history.redo() is not None

    # -- edits (each one undo step; ValueError: nothing changed) -------------------------------

    def invert(self) -> bool:
        """The Babinet complement of the grid."""
        return self.set_mask(pixels.inverted(self.mask))

    def clear(self) -> bool:
        return self.set_mask(np.zeros_like(self.mask))

    def random_fill(self, seed: int, density: float) -> bool:
        """A random mask under the symmetry with a share ``density`` of metal."""
        return self.set_mask(pixels.random_mask(self.mask.shape, seed, self.symmetry, density))

    def fill_at(self, row: int, col: int, value: bool) -> bool:
        """Flood fill the 4-connected region of (row, col) (and its images) with ``value``."""
        return self.set_mask(pixels.flood_filled(self.mask, row, col, self.symmetry, value))

    def painted(self, start: np.ndarray, cells: list[tuple[int, int]], value: bool) -> np.ndarray:
        """``start`` with ``cells`` and their images under the symmetry set to ``value``
        (a stroke under way; :meth:`set_mask` makes it one undo step)."""
        return pixels.painted(start, cells, self.symmetry, value)

    def set_mask(self, mask: np.ndarray) -> bool:
        return self.push(self.grid.replaced(mask=mask))

    def set_grid_size(self, rows: int, cols: int, pixel_size: float) -> bool:
        """Resize the grid (centred) and/or change the pixel size; the grid keeps its centre,
        and a lattice that was the grid's extent follows it."""
        grid, lattice = self.grid, self.lattice
        mask = pixels.resized(grid.mask, rows, cols)
        centre = np.asarray(grid.origin) + 0.5 * grid.pixel_size * np.array(
            [grid.shape[1], grid.shape[0]]
        )
        origin = centre - 0.5 * pixel_size * np.array([cols, rows])
        new = grid.replaced(mask=mask, pixel_size=pixel_size, origin=tuple(origin))
        if fits_grid(grid, lattice):
            lattice = Lattice.rectangular(cols * pixel_size, rows * pixel_size)
        return self.push(new, lattice)

    # -- symmetry ------------------------------------------------------------------------------

    def choose_symmetry(self, mode: str) -> str:
        """Keep ``mode`` from now on; returns what to say of it (a grid not yet symmetric
        gets the images of the next stroke). Raises ``ValueError`` for a mode the grid's
        shape cannot keep (4- or 8-fold on a grid not square); the symmetry stays then."""
        pixels.check_symmetry(mode, self.mask.shape)
        self.symmetry = mode
        self.square_symmetry = None
        title = pixels.SYMMETRY_TITLES[mode]
        if not pixels.is_invariant(self.mask, mode):
            return (
                f"The grid is not {title} symmetric: the next stroke or fill adds the images "
                "of its metal"
            )
        return f"Symmetry: {title}"

    def follow_shape(self) -> str | None:
        """After the grid's shape changed: a 4- or 8-fold symmetry is put aside while the
        grid is not square (:data:`NOT_SQUARE`) and comes back when it is; returns what to
        say of that (None: nothing changed)."""
        rows, cols = self.grid.shape
        if rows != cols and self.symmetry in ("4-fold", "8-fold"):
            self.square_symmetry, self.symmetry = self.symmetry, "none"
            return NOT_SQUARE
        if rows == cols and self.square_symmetry:
            back, self.square_symmetry = self.square_symmetry, None
            if self.symmetry == "none":
                self.symmetry = back
                return f"The grid is square again: symmetry {pixels.SYMMETRY_TITLES[back]} is back"
        return None

    def orbit(self, pixel: tuple[int, int]) -> np.ndarray:
        """(K, 2) the pixel and its images under the symmetry (the pixel alone where the
        grid's shape cannot keep it)."""
        try:
            ids = pixels.orbit_ids(self.mask.shape, self.symmetry)
        except ValueError:
            return np.array([pixel])
        return np.argwhere(ids == ids[pixel])


def reframes(old: PixelGrid, new: PixelGrid) -> bool:
    """Whether going from ``old`` to ``new`` moves the grid's extent (the view frames it)."""
    return old.shape != new.shape or old.pixel_size != new.pixel_size


def fits_grid(grid: PixelGrid, lattice: Lattice) -> bool:
    """Whether the lattice is rectangular and exactly the grid's extent."""
    if lattice.kind != "rectangular":
        return False
    w, h = grid.shape[1] * grid.pixel_size, grid.shape[0] * grid.pixel_size
    tol = 1e-9 * max(w, h)
    return abs(lattice.a1[0] - w) <= tol and abs(lattice.a2[1] - h) <= tol


def blank_grid(lattice: Lattice, columns: int = 16) -> PixelGrid:
    """An empty grid of ``columns`` square pixels across the cell's bounding box, centred.

    Examples
    --------
    >>> g = blank_grid(Lattice.rectangular(8.0, 4.0))
    >>> g.shape, g.pixel_size, g.origin
    ((8, 16), 0.5, (-4.0, -2.0))
    """
    corners = lattice.corners()
    w, h = np.ptp(corners, axis=0)
    size = float(w) / columns
    rows = max(1, int(round(float(h) / size)))
    return PixelGrid(
        np.zeros((rows, columns), bool), size, (-0.5 * columns * size, -0.5 * rows * size)
    )


def square_or_mirror(mode: str, shape: tuple[int, int]) -> bool:
    """Whether a grid of ``shape`` can keep ``mode`` (4- and 8-fold need a square)."""
    return mode.startswith("mirror") or shape[0] == shape[1]


def start_cell() -> UnitCell:
    """The cell the painter opens on (:data:`START_PRESET`; a diagonal if it is damaged)."""
    try:
        return load_cell_preset(START_PRESET)
    except (OSError, ValueError) as exc:  # a damaged preset: start blank
        log.warning("cell preset %s unavailable: %s", START_PRESET, exc)
        grid = PixelGrid(np.zeros((16, 16), bool), 0.5, (-4.0, -4.0))
        return UnitCell(
            Lattice.rectangular(8.0),
            pixels=grid.replaced(mask=np.eye(16, dtype=bool)),
            name="pixels",
        )
