"""Editing unit cells in the window: the Elements and Lattice panels, the array preview
and the Cell menu's actions, and the pixel painter (:mod:`barymesh.app.edit.painter`) with
its worker's preview (``painter_preview``, no VTK), its VTK scene (``painter_scene``), its
toolbars (``painter_toolbars``) and its Cell menu entry (``painter_opener``). Their Qt-free
models (the cell document, the painter's pure edits) are in :mod:`barymesh.app.model`."""
