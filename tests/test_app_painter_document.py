"""app/model/painter_document.py: the pixel painter's document, without Qt (the window's
own tests, tests/test_app_painter.py, drive the same document through the mouse)."""

import subprocess
import sys

import numpy as np
import pytest

from barymesh.app.model.painter_document import (
    NOT_SQUARE,
    NothingToSave,
    PainterDocument,
    blank_grid,
    fits_grid,
    reframes,
)
from barymesh.app.model.pixels import SYMMETRY_TITLES
from barymesh.cell import Lattice, PixelGrid, UnitCell, load_cell, load_cell_preset


def cell_of(mask, pixel_size=0.5, lattice=None, **kw) -> UnitCell:
    rows, cols = mask.shape
    grid = PixelGrid(
        np.asarray(mask, bool), pixel_size, (-0.5 * cols * pixel_size, -0.5 * rows * pixel_size)
    )
    if lattice is None:
        lattice = Lattice.rectangular(cols * pixel_size, rows * pixel_size)
    return UnitCell(lattice, pixels=grid, **kw)


def eight_fold(n=8) -> np.ndarray:
    """A ring of width 1 at distance 2 from the border: invariant under the whole group."""
    m = np.zeros((n, n), bool)
    m[2, 2:-2] = m[-3, 2:-2] = m[2:-2, 2] = m[2:-2, -3] = True
    return m


def test_importing_the_document_loads_no_qt():
    code = (
        "import sys, barymesh.app.model.painter_document as d; d.PainterDocument(); "
        "bad = [m for m in sys.modules if m.split('.')[0] in ('PySide6', 'vtkmodules', "
        "'pyvista', 'pyvistaqt')]; assert not bad, bad"
    )
    subprocess.run([sys.executable, "-c", code], check=True, timeout=120)


def test_a_cell_opens_in_the_largest_symmetry_it_has():
    assert PainterDocument(cell_of(eight_fold())).symmetry == "8-fold"
    mirror = np.zeros((6, 6), bool)
    mirror[1, 0] = mirror[1, 5] = True  # mirror_x maps column c to 5 - c; nothing else holds
    assert PainterDocument(cell_of(mirror)).symmetry == "mirror_x"
    lone = np.zeros((6, 6), bool)
    lone[1, 0] = True
    assert PainterDocument(cell_of(lone)).symmetry == "none"


def test_each_edit_is_one_undo_step_and_undo_redo_walk_them():
    doc = PainterDocument(cell_of(eight_fold()))
    first = doc.mask.copy()
    assert doc.invert()
    assert np.array_equal(doc.mask, ~first)  # the Babinet complement
    assert doc.clear()
    assert not doc.mask.any()
    assert not doc.clear()  # nothing changes: no undo step
    assert len(doc.history.states) == 3 and doc.history.position == 2
    assert doc.undo() and np.array_equal(doc.mask, ~first)
    assert doc.undo() and np.array_equal(doc.mask, first)
    assert not doc.undo()  # the start of the history
    assert doc.redo() and doc.redo() and not doc.mask.any()
    assert not doc.redo()


def test_a_stroke_and_a_fill_keep_the_symmetry():
    one = np.zeros((8, 8), bool)
    one[3, 3] = True  # a cell needs metal to open
    doc = PainterDocument(cell_of(one))
    assert doc.clear()
    doc.choose_symmetry("8-fold")
    stroke = doc.painted(doc.mask, [(0, 1)], True)
    # (0, 1) has 8 images in an 8 x 8 grid: (0,1) (0,6) (7,1) (7,6) (1,0) (6,0) (1,7) (6,7)
    assert stroke.sum() == 8
    assert doc.set_mask(stroke)
    assert len(doc.orbit((0, 1))) == 8 and len(doc.orbit((0, 0))) == 4  # a corner: 4 images
    doc.choose_symmetry("none")
    assert doc.fill_at(3, 3, True)  # the empty region around the centre, 4-connected
    # the 4 corners are walled in by the stroke's pixels beside them: all else is metal
    assert doc.mask.sum() == 64 - 4
    assert not doc.mask[[0, 0, 7, 7], [0, 7, 0, 7]].any()
    doc.undo()
    assert doc.mask.sum() == 8


def test_a_resize_keeps_the_centre_and_the_lattice_that_was_its_extent_follows():
    doc = PainterDocument(cell_of(eight_fold(8), pixel_size=0.5))  # 4 x 4 mm, centred
    assert fits_grid(doc.grid, doc.lattice)
    assert doc.set_grid_size(12, 12, 0.5)
    assert doc.grid.shape == (12, 12) and doc.grid.origin == (-3.0, -3.0)
    assert doc.lattice.a1[0] == pytest.approx(6.0) and doc.lattice.a2[1] == pytest.approx(6.0)
    assert doc.mask.sum() == eight_fold(8).sum()  # added rows and columns are empty
    assert doc.set_grid_size(12, 12, 0.25)  # a smaller pixel: the grid shrinks about its centre
    assert doc.grid.origin == (-1.5, -1.5) and doc.lattice.a1[0] == pytest.approx(3.0)
    # a lattice larger than the grid stays as it is
    other = PainterDocument(cell_of(eight_fold(8), lattice=Lattice.rectangular(10.0)))
    assert not fits_grid(other.grid, other.lattice)
    other.set_grid_size(10, 10, 0.5)
    assert other.lattice == Lattice.rectangular(10.0)
    with pytest.raises(ValueError, match="rows=0"):
        other.set_grid_size(0, 10, 0.5)
    assert other.grid.shape == (10, 10)  # a refused size changes nothing
    assert reframes(doc.history.states[0].grid, doc.grid)
    assert not reframes(doc.grid, doc.grid.replaced(mask=~doc.mask))


def test_a_symmetry_a_grid_cannot_keep_waits_until_it_is_square_again():
    doc = PainterDocument(cell_of(eight_fold(8)))
    assert doc.symmetry == "8-fold"
    doc.set_grid_size(8, 10, 0.5)
    assert doc.follow_shape() == NOT_SQUARE and doc.symmetry == "none"
    with pytest.raises(ValueError, match="needs a square grid"):
        doc.choose_symmetry("4-fold")
    assert doc.symmetry == "none"
    doc.undo()  # square again
    note = doc.follow_shape()
    assert note is not None and "square again" in note and doc.symmetry == "8-fold"
    assert doc.follow_shape() is None  # said once
    assert doc.choose_symmetry("mirror_y") == f"Symmetry: {SYMMETRY_TITLES['mirror_y']}"
    assert doc.symmetry == "mirror_y"
    doc.fill_at(0, 0, True)
    note = doc.choose_symmetry("none")
    assert note.startswith("Symmetry:")
    lone = PainterDocument(cell_of(np.eye(8, dtype=bool)[::-1] & np.tri(8, dtype=bool)[::-1]))
    note = lone.choose_symmetry("mirror_x")
    assert "is not" in note and "next stroke" in note  # not symmetric yet: the next edit adds


def test_a_cell_without_metal_is_not_saved_and_a_saved_one_reads_back(tmp_path):
    one = np.zeros((4, 4), bool)
    one[0, 0] = True
    doc = PainterDocument(cell_of(one, name="blank"))
    assert doc.clear() and doc.cell() is None
    with pytest.raises(NothingToSave):
        doc.save(tmp_path / "blank")
    assert not list(tmp_path.iterdir())
    doc.fill_at(0, 0, True)
    written = doc.save(tmp_path / "full.json")
    assert written.name == "full.cell.json" and doc.path == written
    back = load_cell(written)
    assert np.array_equal(back.pixels.mask, doc.mask) and back.lattice == doc.lattice
    assert back.name == "blank"
    other = PainterDocument()
    other.open_file(written)
    assert np.array_equal(other.mask, doc.mask) and other.path == written
    with pytest.raises((OSError, ValueError)):
        other.open_file(tmp_path / "missing.cell.json")
    assert np.array_equal(other.mask, doc.mask)  # a file that cannot be read changes nothing


def test_a_cell_without_a_grid_gets_a_blank_one_over_it():
    rings = load_cell_preset("double-ring-patch")  # two elements, no pixels
    assert rings.pixels is None
    doc = PainterDocument(rings)
    assert doc.grid == blank_grid(rings.lattice) and not doc.mask.any()
    assert doc.has_elements and doc.cell().elements == rings.elements  # metal: the elements
    grid = blank_grid(Lattice.rectangular(8.0, 4.0))
    assert grid.shape == (8, 16) and grid.pixel_size == 0.5
