"""Edits of a pixel mask under a symmetry: paint, erase, flood fill, invert, random fill, resize.

Pure numpy, no Qt: every function takes a boolean ``(R, C)`` mask and returns a new one
(the input is never changed), so the painter's undo history is a list of masks.

Symmetry modes act on the grid about its centre, as in :func:`barymesh.cell.symmetrized`
(``mask[i, j]`` is row i from the bottom, column j from the left)::

    none      the identity only
    mirror_x  x -> -x: column j <-> column C - 1 - j            (group of 2)
    mirror_y  y -> -y: row i <-> row R - 1 - i                  (group of 2)
    4-fold    C4: the quarter turns about the centre             (group of 4, square grids)
    8-fold    D4: the quarter turns and the four mirrors
              (x, y, both diagonals), the square's full group    (group of 8, square grids)

"4-fold" is the rotation group, the usual meaning for coding metasurfaces whose
response must not depend on a 90° turn of the incident polarisation; it does not
imply mirror symmetry (the shipped 16 x 16 coding cell is C4 but not mirror
symmetric). "8-fold" adds the mirrors.

An edit under a mode returns a mask invariant under the mode's group: the mask is
first closed under the group (the images of its metal are added,
:func:`barymesh.cell.symmetrized`), then the edit is applied to whole orbits (a pixel
and all its images). On a mask that is already invariant the closure changes
nothing, so painting and then erasing a pixel restores the mask.
"""

from __future__ import annotations

import numpy as np
import numpy.typing as npt

from barymesh.cell import SYMMETRIES, symmetrized

#: What the painter shows for each symmetry mode.
SYMMETRY_TITLES = {
    "none": "none",
    "mirror_x": "mirror x (x → −x)",
    "mirror_y": "mirror y (y → −y)",
    "4-fold": "4-fold (quarter turns, C4)",
    "8-fold": "8-fold (turns + mirrors, D4)",
}
#: Largest rows or columns of a grid the editor accepts (256 x 256 pixels: 2,097,152
#: triangles when all are set, within the mesher's 5,000,000 budget).
MAX_SIDE = 256


def _mask(mask: np.ndarray) -> np.ndarray:
    m = np.asarray(mask)
    if m.ndim != 2 or m.size == 0:
        raise ValueError(f"mask has shape {m.shape}; expected a non-empty rows x columns array")
    if m.dtype != bool:
        raise ValueError(f"mask has dtype {m.dtype}; expected booleans")
    return m


def check_symmetry(symmetry: str, shape: tuple[int, int]) -> None:
    """Raise ``ValueError`` unless ``symmetry`` is a known mode that fits a grid of ``shape``."""
    if symmetry not in SYMMETRIES:
        raise ValueError(
            f"symmetry={symmetry!r} is unknown; expected one of {', '.join(SYMMETRIES)}"
        )
    if symmetry in ("4-fold", "8-fold") and shape[0] != shape[1]:
        raise ValueError(
            f"symmetry={symmetry!r} needs a square grid; this one has {shape[0]} rows and "
            f"{shape[1]} columns"
        )


def group_images(array: np.ndarray, symmetry: str) -> list[np.ndarray]:
    """The images of a 2D ``array`` under every element of the mode's group (identity first).

    Parameters
    ----------
    array : (R, C)
    symmetry : str
        One of :data:`barymesh.cell.SYMMETRIES`.

    Returns
    -------
    list of (R, C) arrays
        1, 2, 2, 4 or 8 views of ``array``.
    """
    a = np.asarray(array)
    check_symmetry(symmetry, a.shape)
    if symmetry == "none":
        return [a]
    if symmetry == "mirror_x":
        return [a, a[:, ::-1]]
    if symmetry == "mirror_y":
        return [a, a[::-1, :]]
    turns = [np.rot90(a, k) for k in range(4)]
    return turns if symmetry == "4-fold" else turns + [t.T for t in turns]


def orbit_ids(shape: tuple[int, int], symmetry: str) -> np.ndarray:
    """(R, C) int64: for every pixel the smallest flat index of its orbit.

    Two pixels have the same id exactly when a group element maps one onto the
    other (the group is closed under inverses, so the images of the index
    array at a pixel are its whole orbit).

    Examples
    --------
    >>> orbit_ids((2, 2), "4-fold").tolist()
    [[0, 0], [0, 0]]
    >>> orbit_ids((1, 3), "mirror_x").tolist()
    [[0, 1, 0]]
    """
    index = np.arange(shape[0] * shape[1], dtype=np.int64).reshape(shape)
    return np.minimum.reduce(group_images(index, symmetry))


def is_invariant(mask: np.ndarray, symmetry: str) -> bool:
    """Whether ``mask`` equals its image under every element of the mode's group."""
    m = _mask(mask)
    return all(np.array_equal(m, g) for g in group_images(m, symmetry))


def _index(mask: np.ndarray, row: int, col: int) -> tuple[int, int]:
    rows, cols = mask.shape
    for name, value, n in (("row", row, rows), ("col", col, cols)):
        if isinstance(value, bool) or not isinstance(value, int | np.integer):
            raise ValueError(f"{name}={value!r} is invalid; expected an integer")
        if not 0 <= value < n:
            raise ValueError(f"{name}={value} is outside the grid; expected 0 … {n - 1}")
    return int(row), int(col)


def painted(
    mask: np.ndarray, pixels: npt.ArrayLike, symmetry: str = "none", value: bool = True
) -> np.ndarray:
    """Set (``value`` True) or clear every pixel of ``pixels`` and all their images.

    Parameters
    ----------
    mask : (R, C) bool
    pixels : (K, 2) int
        (row, column) of the pixels of one stroke.
    symmetry : str
    value : bool
        True paints metal, False erases.

    Returns
    -------
    (R, C) bool
        Invariant under the mode's group.

    Examples
    --------
    >>> m = painted(np.zeros((4, 4), bool), [[0, 1]], "4-fold")
    >>> np.argwhere(m).tolist()
    [[0, 1], [1, 3], [2, 0], [3, 2]]
    """
    m = _mask(mask)
    check_symmetry(symmetry, m.shape)
    pix = np.asarray(pixels, dtype=np.int64).reshape(-1, 2)
    for r, c in pix.tolist():
        _index(m, r, c)
    out = symmetrized(m, symmetry)
    if len(pix):
        ids = orbit_ids(m.shape, symmetry)
        out[np.isin(ids, ids[pix[:, 0], pix[:, 1]])] = bool(value)
    return out


def paint(mask: np.ndarray, row: int, col: int, symmetry: str = "none") -> np.ndarray:
    """Metal on pixel (row, col) and its images; see :func:`painted`."""
    return painted(mask, [_index(_mask(mask), row, col)], symmetry, True)


def erase(mask: np.ndarray, row: int, col: int, symmetry: str = "none") -> np.ndarray:
    """No metal on pixel (row, col) and its images; see :func:`painted`."""
    return painted(mask, [_index(_mask(mask), row, col)], symmetry, False)


def flood_filled(
    mask: np.ndarray, row: int, col: int, symmetry: str = "none", value: bool = True
) -> np.ndarray:
    """Set the connected region of pixel (row, col) (and of its images) to ``value``.

    The region is every pixel equal to the clicked one and joined to it through
    pixels sharing a side (4-neighbours; diagonal neighbours are not joined, as
    corner-only contacts are not joined in the mesh).

    Examples
    --------
    >>> m = np.array([[1, 0, 0], [0, 0, 1], [1, 0, 0]], bool)
    >>> flood_filled(m, 0, 1).astype(int).tolist()
    [[1, 1, 1], [1, 1, 1], [1, 1, 1]]
    >>> flood_filled(m, 0, 0, value=False).astype(int).tolist()
    [[0, 0, 0], [0, 0, 1], [1, 0, 0]]
    """
    m = _mask(mask)
    r, c = _index(m, row, col)
    check_symmetry(symmetry, m.shape)
    closed = symmetrized(m, symmetry)
    ids = orbit_ids(m.shape, symmetry)
    seeds = ids == ids[r, c]
    same = closed == closed[r, c]  # an invariant mask: equal on the whole orbit
    from scipy import ndimage  # here: scipy.ndimage (and scipy.special) off the start-up

    labels, _ = ndimage.label(same)  # default structure: 4-neighbours
    region = np.isin(labels, np.unique(labels[seeds]))
    out = closed.copy()
    out[region] = bool(value)
    return out


def inverted(mask: np.ndarray) -> np.ndarray:
    """The Babinet complement: metal where there was none and none where there was.

    It commutes with every symmetry, so an invariant mask stays invariant.
    """
    return ~_mask(mask)


def random_mask(
    shape: tuple[int, int], seed: int, symmetry: str = "none", density: float = 0.5
) -> np.ndarray:
    """A random mask invariant under the mode's group, reproducible from ``seed``.

    Every orbit is metal with probability ``density``: one draw of
    ``numpy.random.default_rng(seed).random(shape)`` per pixel, each orbit
    taking the draw of its first pixel.

    Parameters
    ----------
    shape : (R, C)
    seed : int >= 0
    symmetry : str
    density : float in [0, 1]

    Returns
    -------
    (R, C) bool
    """
    try:
        rows, cols = (int(v) for v in shape)
    except (TypeError, ValueError):
        raise ValueError(f"shape={shape!r} is invalid; expected (rows, columns)") from None
    if not (1 <= rows <= MAX_SIDE and 1 <= cols <= MAX_SIDE):
        raise ValueError(f"shape={shape!r} is invalid; expected 1 … {MAX_SIDE} rows and columns")
    if isinstance(seed, bool) or not isinstance(seed, int | np.integer) or seed < 0:
        raise ValueError(f"seed={seed!r} is invalid; expected an integer >= 0")
    if not 0.0 <= float(density) <= 1.0:
        raise ValueError(f"density={density!r} is invalid; expected a fraction in [0, 1]")
    ids = orbit_ids((rows, cols), symmetry)
    draws = np.random.default_rng(int(seed)).random((rows, cols))
    return (draws.ravel()[ids] < float(density)).reshape(rows, cols)


def resized(mask: np.ndarray, rows: int, cols: int) -> np.ndarray:
    """The mask on a grid of ``rows`` x ``cols``, centred: rows and columns are added
    (empty) or removed evenly on both sides, an odd one at the top or the right.

    Centring keeps every symmetry about the grid's centre when the change is even.

    Examples
    --------
    >>> resized(np.ones((1, 1), bool), 3, 2).astype(int).tolist()
    [[0, 0], [1, 0], [0, 0]]
    """
    m = _mask(mask)
    for name, n in (("rows", rows), ("cols", cols)):
        if isinstance(n, bool) or not isinstance(n, int | np.integer) or not 1 <= n <= MAX_SIDE:
            raise ValueError(f"{name}={n!r} is invalid; expected an integer 1 … {MAX_SIDE}")
    out = np.zeros((int(rows), int(cols)), dtype=bool)
    src, dst = [], []
    for old, new in zip(m.shape, (int(rows), int(cols)), strict=True):
        shift = int((new - old) / 2)  # towards zero: an odd change at the top / right
        lo = max(0, -shift)
        n = min(old - lo, new - max(0, shift))
        src.append(slice(lo, lo + n))
        dst.append(slice(max(0, shift), max(0, shift) + n))
    out[tuple(dst)] = m[tuple(src)]
    return out


def pixel_at(
    shape: tuple[int, int], origin: tuple[float, float], pixel_size: float, xy: tuple[float, float]
) -> tuple[int, int] | None:
    """(row, column) of the pixel containing the point ``xy`` (mm), None outside the grid.

    A point on a side between two pixels belongs to the upper / right one.

    Examples
    --------
    >>> pixel_at((16, 16), (-4.0, -4.0), 0.5, (0.1, -3.9))
    (0, 8)
    >>> pixel_at((16, 16), (-4.0, -4.0), 0.5, (4.2, 0.0)) is None
    True
    """
    col = int(np.floor((float(xy[0]) - origin[0]) / pixel_size))
    row = int(np.floor((float(xy[1]) - origin[1]) / pixel_size))
    if 0 <= row < shape[0] and 0 <= col < shape[1]:
        return row, col
    return None


def pixel_line(start: tuple[int, int], end: tuple[int, int]) -> np.ndarray:
    """(K, 2) int64 pixels from ``start`` to ``end`` with no gap (a fast drag skips pixels
    between two mouse events; the stroke fills them in, sharing a side or a corner).

    Examples
    --------
    >>> pixel_line((0, 0), (2, 4)).tolist()
    [[0, 0], [1, 1], [1, 2], [2, 3], [2, 4]]
    """
    a, b = np.asarray(start, dtype=np.float64), np.asarray(end, dtype=np.float64)
    n = int(np.abs(b - a).max())
    t = np.linspace(0.0, 1.0, n + 1)[:, None]
    return np.floor(a + t * (b - a) + 0.5).astype(np.int64)
