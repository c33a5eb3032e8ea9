"""Parameter sweeps: the sequence of parameter sets behind a sweep animation."""

from __future__ import annotations

import dataclasses

import numpy as np

from .params import MeshParams

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
    values = np.linspace(float(start), float(stop), frames)
    is_int = isinstance(getattr(base, name), int) and not isinstance(getattr(base, name), bool)
    out = []
    for k, v in enumerate(values):
        value = int(round(v)) if is_int else float(v)
        try:
            out.append(dataclasses.replace(base, **{name: value}))
        except ValueError as err:
            raise ValueError(f"sweep frame {k + 1} of {frames} ({name}={value!r}): {err}") from None
    return out
