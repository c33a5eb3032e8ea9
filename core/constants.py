"""Physical constants of free space, in one place, taken from :mod:`scipy.constants`.

SI units (m/s, H/m, F/m, Ω), and the speed of light in mm/s too, since every length of
a mesh is in millimetres. The values are scipy's (CODATA): the speed of light is exact
by the SI definition of the metre; μ0, ε0 and η0 are measured since the 2019 SI.

The measured ones, ``MU0`` (μ0, H/m), ``EPS0`` (ε0, F/m) and ``FREE_SPACE_IMPEDANCE``
(η0 = μ0 c, Ω; also named ``ETA0``, as in the MoM literature), are read from
:mod:`scipy.constants` when first asked for, so that importing this module (the mesher
needs only the speed of light) does not import scipy.

>>> SPEED_OF_LIGHT
299792458.0
>>> round(wavelength(10e9), 6)  # mm in vacuum
29.979246
>>> from barymesh.constants import FREE_SPACE_IMPEDANCE, MU0
>>> abs(FREE_SPACE_IMPEDANCE - MU0 * SPEED_OF_LIGHT) < 1e-9 * FREE_SPACE_IMPEDANCE
True
"""

from __future__ import annotations

import math
from typing import TYPE_CHECKING

#: Speed of light in vacuum (m/s), exact: the SI defines the metre by it (scipy's ``c``).
SPEED_OF_LIGHT: float = 299792458.0
#: Speed of light in vacuum (mm/s), for wavelengths in mm.
SPEED_OF_LIGHT_MM: float = SPEED_OF_LIGHT * 1e3

if TYPE_CHECKING:
    #: Vacuum permeability μ0 (H/m).
    MU0: float
    #: Vacuum permittivity ε0 (F/m).
    EPS0: float
    #: Free-space (characteristic) impedance η0 = μ0 c (Ω).
    FREE_SPACE_IMPEDANCE: float
    #: The MoM literature's name for :data:`FREE_SPACE_IMPEDANCE`.
    ETA0: float

#: The measured constants and their names in :mod:`scipy.constants`' table. They are read
#: from scipy when first asked for (PEP 562): importing scipy.constants costs a tenth of a
#: second, which the mesher, that needs only the speed of light, does not pay.
_MEASURED = {
    "MU0": "vacuum mag. permeability",
    "EPS0": "vacuum electric permittivity",
    "FREE_SPACE_IMPEDANCE": "characteristic impedance of vacuum",
    "ETA0": "characteristic impedance of vacuum",
}


def __getattr__(name: str) -> float:
    if name not in _MEASURED:
        raise AttributeError(f"module {__name__!r} has no attribute {name!r}")
    import scipy.constants

    value = float(scipy.constants.physical_constants[_MEASURED[name]][0])
    globals()[name] = value  # asked once
    return value


def __dir__() -> list[str]:
    return sorted(set(globals()) | set(_MEASURED))


def wavelength(frequency: float, relative_permittivity: float = 1.0) -> float:
    """Wavelength (mm) at ``frequency`` (Hz) in a medium of ``relative_permittivity``.

    λ = c0 / (f √εr), with no check of the arguments (the callers validate them).

    Parameters
    ----------
    frequency : float
        Hz, > 0.
    relative_permittivity : float
        εr >= 1 of the medium.

    Examples
    --------
    >>> round(wavelength(10e9, 4.0), 6)  # in a substrate of εr = 4: half as long
    14.989623
    """
    return SPEED_OF_LIGHT_MM / (frequency * math.sqrt(relative_permittivity))
