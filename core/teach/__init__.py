"""Helpers of the teaching windows (the window's Teach menu), kept apart from the mesher.

``construction``
    The paper's construction of a patch mesh, step by step (Section II.D).
``rwg_basis``
    One RWG basis function sampled on its two triangles, and the status of an edge.
``sweep``
    The parameter sets behind a sweep animation.

Their old names, ``barymesh.construction``, ``barymesh.rwg_basis`` and ``barymesh.sweep``,
are the same modules (scripts written before the move keep working).
"""
