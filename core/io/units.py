"""Length units of mesh files. Meshes are in mm; files may be in m, mm or um."""

from __future__ import annotations

#: Unit name -> how many of that unit make one millimetre.
PER_MM = {"m": 1e-3, "mm": 1.0, "um": 1e3}
UNITS = tuple(PER_MM)


def per_mm(unit: str) -> float:
    """The factor from mm to ``unit`` (multiply mm coordinates by it).

    >>> per_mm("m"), per_mm("um")
    (0.001, 1000.0)
    """
    try:
        return PER_MM[unit]
    except (KeyError, TypeError):
        raise ValueError(f"unit={unit!r} is unknown; expected one of {', '.join(UNITS)}") from None
