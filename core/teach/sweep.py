"""Parameter sweeps: the sequence of parameter sets behind a sweep animation."""

from __future__ import annotations

import dataclasses
import math
from typing import Any

import numpy as np

from ..params import MeshParams

#: Parameters a sweep can vary (numbers; integers are rounded).
SWEEPABLE = (
    "inner_radius",
    "outer_radius",
    "patch_size",
    "angle_step",
    "subdivisions",
    "gap_width",
    "gap_angle",
)


#: Most frames a sweep may have.
MAX_FRAMES = 1000
#: Bytes a sweep keeps per pixel of each frame until it is encoded (RGB, plus the
#: encoder's palette or YUV copy).
FRAME_BYTES_PER_PIXEL = 4
#: Sweeps estimated above this are refused before they start.
SWEEP_MEMORY_LIMIT = 2 * 2**30


def check_sweep_size(frames: int, window_size: tuple[int, int]) -> None:
    """Refuse a sweep whose frames would not fit in memory, with a ``ValueError`` saying so.

    >>> check_sweep_size(20, (800, 600))
    >>> check_sweep_size(100_000, (800, 600))
    Traceback (most recent call last):
    ...
    ValueError: frames=100000 is more than the 1000 a sweep may have
    """
    if isinstance(frames, bool) or not isinstance(frames, int) or frames < 2:
        raise ValueError(f"frames={frames!r} is invalid; expected an integer >= 2")
    if frames > MAX_FRAMES:
        raise ValueError(f"frames={frames} is more than the {MAX_FRAMES} a sweep may have")
    width, height = (int(v) for v in window_size)
    need = frames * width * height * FRAME_BYTES_PER_PIXEL
    if need > SWEEP_MEMORY_LIMIT:
        most = SWEEP_MEMORY_LIMIT // (width * height * FRAME_BYTES_PER_PIXEL)
        raise ValueError(
            f"{frames} frames of {width} x {height} pixels need about {need / 2**30:.1f} GiB; "
            f"at most {most} frames of that size fit in {SWEEP_MEMORY_LIMIT / 2**30:.0f} GiB"
        )


def sweep_params(
    base: MeshParams, name: str, start: float, stop: float, frames: int
) -> list[MeshParams]:
    """``frames`` parameter sets with ``name`` going from ``start`` to ``stop``.

    Integer parameters (``subdivisions``) take rounded values, so a sweep
    1 → 8 over 8 frames visits every n once. Every frame is validated: an
    invalid one raises ``ValueError`` naming the frame and the value.

    Examples
    --------
    >>> ps = sweep_params(MeshParams(), "subdivisions", 1, 4, 4)
    >>> [p.subdivisions for p in ps]
    [1, 2, 3, 4]
    """
    if name not in SWEEPABLE:
        raise ValueError(f"cannot sweep {name!r}; expected one of {', '.join(SWEEPABLE)}")
    if isinstance(frames, bool) or not isinstance(frames, int) or frames < 2:
        raise ValueError(f"frames={frames!r} is invalid; expected an integer >= 2")
    if frames > MAX_FRAMES:
        raise ValueError(f"frames={frames} is more than the {MAX_FRAMES} a sweep may have")
    for label, value in (("start", start), ("stop", stop)):
        try:
            number = float(value)
        except (TypeError, ValueError, OverflowError):
            raise ValueError(f"{label}={value!r} is not a number") from None
        if not math.isfinite(number):
            raise ValueError(f"{label}={value!r} is not a finite number")
    values = np.linspace(float(start), float(stop), frames)
    is_int = isinstance(getattr(base, name), int) and not isinstance(getattr(base, name), bool)
    out = []
    for k, v in enumerate(values):
        value = int(round(v)) if is_int else float(v)
        try:
            change: dict[str, Any] = {name: value}  # checked by MeshParams, named in the error
            out.append(dataclasses.replace(base, **change))
        except ValueError as err:
            raise ValueError(f"sweep frame {k + 1} of {frames} ({name}={value!r}): {err}") from None
    return out
