"""Editors of a unit cell: the pixel painter (:mod:`app.edit.painter`) and its pure edits
(:mod:`app.edit.pixels`)."""
