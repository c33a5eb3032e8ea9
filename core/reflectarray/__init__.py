"""The reflectarray designer: a reflection-phase library laid out over an aperture.

From a cell's S-curve (:class:`barymesh.mom.ReflectionLibrary`), an aperture of N1 × N2
cells, a feed and a beam direction, :func:`design` gives each element the phase that
points the beam (the feed's spatial delay made up, plus the progressive phase of the
beam) and the cell parameter that reflects it, continuous or quantised to 1, 2 or 3
bits; the :class:`Reflectarray` it returns predicts the pattern (element pattern × array
factor, each cell as in an infinite array of itself: the local-periodicity
approximation), the main beam, the side lobes and the quantisation loss, and becomes one
unit cell of the whole array (:meth:`Reflectarray.to_cell`) for cell files, DXF and GDSII.

>>> from barymesh import reflectarray
>>> round(reflectarray.textbook_quantization_loss(1), 1)
-3.9
"""

from .designer import (
    BITS,
    DEFAULT_ELEMENT_Q,
    DEFAULT_FEED_Q,
    Reflectarray,
    closest_on_curve,
    design,
    textbook_quantization_loss,
    wrapped,
)

__all__ = [
    "BITS",
    "DEFAULT_ELEMENT_Q",
    "DEFAULT_FEED_Q",
    "Reflectarray",
    "closest_on_curve",
    "design",
    "textbook_quantization_loss",
    "wrapped",
]
