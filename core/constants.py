"""Physical constants of free space, in one place, taken from :mod:`scipy.constants`.

SI units (m/s, H/m, F/m, Ω), and the speed of light in mm/s too, since every length of
a mesh is in millimetres. The values are scipy's (CODATA): the speed of light is exact
by the SI definition of the metre; μ0, ε0 and η0 are measured since the 2019 SI.

>>> SPEED_OF_LIGHT
299792458.0
>>> round(wavelength(10e9), 6)  # mm in vacuum
29.979246
>>> abs(FREE_SPACE_IMPEDANCE - MU0 * SPEED_OF_LIGHT) < 1e-9 * FREE_SPACE_IMPEDANCE
True
"""

from __future__ import annotations

import math

import scipy.constants as _si

#: Speed of light in vacuum (m/s), exact.
SPEED_OF_LIGHT: float = float(_si.c)
#: Speed of light in vacuum (mm/s), for wavelengths in mm.
SPEED_OF_LIGHT_MM: float = SPEED_OF_LIGHT * 1e3
#: Vacuum permeability μ0 (H/m).
MU0: float = float(_si.mu_0)
#: Vacuum permittivity ε0 (F/m).
EPS0: float = float(_si.epsilon_0)
#: Free-space (characteristic) impedance η0 = μ0 c (Ω).
FREE_SPACE_IMPEDANCE: float = float(_si.physical_constants["characteristic impedance of vacuum"][0])
#: The MoM literature's name for :data:`FREE_SPACE_IMPEDANCE`.
ETA0: float = FREE_SPACE_IMPEDANCE


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
