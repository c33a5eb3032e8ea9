"""Editing unit cells in the window: the Elements and Lattice panels, the array preview
and the Cell menu's actions, and the pixel painter (:mod:`barymesh.app.edit.painter`).
Their Qt-free models (the cell document, the painter's pure edits) are in
:mod:`barymesh.app.model`."""
