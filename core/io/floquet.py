"""Files of an infinite array's sweep: a Touchstone .s4p and a CSV of every Floquet order.

The writers take a :class:`barymesh.mom.PeriodicSweep` (they read its arrays only, and
import nothing of the solver).

- :func:`write_touchstone`: the (0, 0) order as a 4-port, TE and TM above the screen
  (ports 1, 2) and below it (ports 3, 4), or as a 2-port (TE and TM above) over a ground
  plane, Touchstone version 1, real and imaginary parts (``# Hz S RI R 1``), the
  conventions, the reference planes and the stack in its ``!`` comment lines; scikit-rf
  reads it (``skrf.Network(path)``).
- :func:`write_orders_csv`: one row per frequency, propagating order (p, q) and scattered
  polarisation: R and T, their power fractions, whether the frequency was solved.
"""

from __future__ import annotations

import csv
import io
import math
from pathlib import Path
from typing import Any

import numpy as np

from .atomic import atomic_write_text

#: Columns of :func:`write_orders_csv`, in order.
ORDER_COLUMNS = (
    "frequency_hz",
    "p",
    "q",
    "pol",
    "R_re",
    "R_im",
    "R_abs",
    "R_phase_deg",
    "T_re",
    "T_im",
    "T_abs",
    "T_phase_deg",
    "R_power",
    "T_power",
    "solved",
    "error_estimate",
)

__all__ = ["ORDER_COLUMNS", "scattering_matrices", "write_orders_csv", "write_touchstone"]


def scattering_matrices(sweep: Any, from_below: Any = None) -> np.ndarray:
    """(F, 4, 4) complex S of the (0, 0) order: ports TE/TM above (1, 2) and below (3, 4);
    (F, 2, 2) over a ground plane (ports TE/TM above).

    S[:2, :2] is the reflection of a wave from above (rows: scattered TE, TM; columns:
    incident TE, TM), S[2:, :2] its transmission (incident wave included); from below,
    by the mirror symmetry of a zero-thickness screen in free space, the same blocks
    swapped: S = [[R, T], [T, R]]. A sheet on layers is not its own mirror image:
    ``from_below``, the sweep of the mirrored wave from below, gives S[2:, 2:] and S[:2, 2:].

    Raises
    ------
    ValueError
        When the sweep solved one incident polarisation only, or a sweep on layers (no
        ground plane) comes without ``from_below``.
    """
    if not sweep.both_polarizations:
        raise ValueError(
            "the 4-port S-parameters need the TE and the TM incidence: sweep with "
            "polarizations='both'"
        )
    r = sweep.order_reflection[:, 0]  # (F, 2, 2): scattered TE/TM, incident TE/TM
    t = sweep.order_transmission[:, 0]
    stack = getattr(sweep, "stack", None)
    if stack is not None and stack.ground:
        return r.copy()
    r_below, t_below = r, t
    if stack is not None:
        if from_below is None:
            raise ValueError(
                "a sheet on layers is not its own mirror image: the 4-port needs the sweep "
                "of the wave from below too (from_below=)"
            )
        if not from_below.both_polarizations or not np.array_equal(
            from_below.frequencies, sweep.frequencies
        ):
            raise ValueError(
                "from_below must be the sweep from below at the same frequencies, with "
                "polarizations='both'"
            )
        r_below = from_below.order_reflection[:, 0]
        t_below = from_below.order_transmission[:, 0]
    top = np.concatenate([r, t_below], axis=2)  # rows above: [R | T from below]
    bottom = np.concatenate([t, r_below], axis=2)
    return np.concatenate([top, bottom], axis=1)


def _angles(direction: np.ndarray) -> tuple[float, float]:
    """(θ, φ) in degrees of where a wave travelling along ``direction`` comes from."""
    d = -np.asarray(direction, dtype=np.float64)
    if d[2] < 0:
        d = d * np.array([1.0, 1.0, -1.0])  # from below: the angle from −z
    theta = math.degrees(math.acos(max(-1.0, min(1.0, d[2]))))
    phi = math.degrees(math.atan2(d[1], d[0])) if math.hypot(d[0], d[1]) > 1e-12 else 0.0
    return theta, phi


def _number(x: float) -> str:
    return f"{x:.12g}"


def write_touchstone(path: str | Path, sweep: Any, from_below: Any = None) -> None:
    """Write the (0, 0) order's S-parameters of ``sweep`` to a Touchstone v1 file.

    Parameters
    ----------
    path : str or Path
        Usually ending in ``.s4p`` (``.s2p`` over a ground plane); written atomically.
    sweep : PeriodicSweep
        Solved with ``polarizations='both'``.
    from_below : PeriodicSweep, optional
        On layers without a ground plane: the mirrored wave's sweep from below
        (:func:`scattering_matrices`).
    """
    stack = getattr(sweep, "stack", None)
    if stack is not None:
        s = scattering_matrices(sweep, from_below)
        _write_layered(path, sweep, s)
        return
    s = scattering_matrices(sweep)
    d = np.asarray(sweep.incidence.direction, dtype=np.float64)
    theta, phi = _angles(d)
    side = "above" if d[2] < 0 else "below"
    onsets = ", ".join(f"{f / 1e9:.6g} GHz" for f in sweep.grating_lobe_onsets) or "none"
    how = (
        f"interpolated (AAA) from {sweep.n_solves} solved frequencies, largest estimated "
        f"error {float(np.max(sweep.error_estimate)):.2g}"
        if sweep.interpolated
        else f"solved at each of the {len(sweep.frequencies)} frequencies"
    )
    zs = complex(sweep.sheet_impedance)
    lines = [
        "! barymesh periodic_sweep: the (0, 0) Floquet order of an infinite array as a 4-port",
        "! Ports: 1 = TE above the screen, 2 = TM above, 3 = TE below, 4 = TM below.",
        "! Reference planes: the screen, z = 0, for every port. Time convention exp(+j w t).",
        f"! Incidence: from {side}, theta = {theta:.6g} deg, phi = {phi:.6g} deg, travelling along",
        f"!   ({_number(d[0])}, {_number(d[1])}, {_number(d[2])}); the same transverse wavevector "
        "k_t = k (dx, dy) at every",
        "!   port (the mirrored direction on the other side).",
        "! TE = z x kappa/|kappa| (the incidence plane's normal; y at normal incidence),",
        "!   TM = TE x d for a wave travelling down, -TE x d travelling up: the tangential part",
        "!   of TM is the same above and below.",
        "! Reference impedance: each port's mode's wave impedance (TE: eta0 k/beta, TM:",
        "!   eta0 beta/k). S_ij is the ratio of the modes' E amplitudes, which for the (0, 0)",
        "!   order (the same beta on both sides) are power waves: |S_ij|^2 is the power fraction.",
        "!   'R 1' below: the data are normalised to those impedances.",
        "! S_ij with j = 1, 2 from the solver: i = 1, 2 reflection, i = 3, 4 transmission",
        "!   (incident wave included).",
        "! j = 3, 4 by symmetry, not solved: a zero-thickness screen in free space is its own",
        "!   mirror image in z = 0; the mirror maps the wave from above onto the one from below",
        "!   with the same k_t and the same TE/TM components (TE is tangential, TM's tangential",
        "!   part is the same on both sides), and so S(3:4, 3:4) = S(1:2, 1:2), S(1:2, 3:4) =",
        "!   S(3:4, 1:2).",
        f"! Sheet impedance Z_s = {zs.real:.6g} {'+-'[zs.imag < 0]} j{abs(zs.imag):.6g} ohm/sq.",
        f"! Grating-lobe onsets in the band: {onsets}; above one, power also goes into other",
        "!   orders and this 4-port is not unitary (see the CSV of every order).",
        f"! Frequencies: {how}.",
        "# Hz S RI R 1",
    ]
    for f, m in zip(sweep.frequencies, s, strict=True):
        for i in range(4):
            pairs = " ".join(f"{_number(v.real)} {_number(v.imag)}" for v in m[i])
            lines.append(f"{_number(f) if i == 0 else ' ' * 8} {pairs}")
    atomic_write_text(path, "\n".join(lines) + "\n")


def write_orders_csv(path: str | Path, sweep: Any) -> None:
    """Write every propagating Floquet order at every frequency of ``sweep`` to a CSV.

    One row per frequency, order (p, q) and scattered polarisation (``te``, ``tm``), for
    the sweep's incidence (its ``incidence``): R and T (T of (0, 0)
    includes the incident wave), magnitude and phase (degrees), the power fraction of
    that wave (|R|² β_pq / β_00), ``solved`` (1 where the frequency was solved, 0 where
    it was interpolated) and the sweep's error estimate. Columns :data:`ORDER_COLUMNS`.
    """
    r, t = sweep.order_response  # (F, P, 2)
    weight = sweep.beta / sweep.beta[:, :1]  # (F, P), NaN where evanescent
    solved = np.isin(sweep.frequencies, sweep.sampled)
    buf = io.StringIO()
    w = csv.writer(buf, lineterminator="\n")
    w.writerow(ORDER_COLUMNS)
    for i, f in enumerate(sweep.frequencies):
        for j in np.flatnonzero(sweep.propagating[i]):
            p, q = (int(v) for v in sweep.orders[j])
            for c, pol in enumerate(("te", "tm")):
                a, b = complex(r[i, j, c]), complex(t[i, j, c])
                w.writerow(
                    [
                        repr(float(f)),
                        p,
                        q,
                        pol,
                        repr(a.real),
                        repr(a.imag),
                        repr(abs(a)),
                        repr(math.degrees(math.atan2(a.imag, a.real))),
                        repr(b.real),
                        repr(b.imag),
                        repr(abs(b)),
                        repr(math.degrees(math.atan2(b.imag, b.real))),
                        repr(float(weight[i, j] * abs(a) ** 2)),
                        repr(float(weight[i, j] * abs(b) ** 2)),
                        int(solved[i]),
                        repr(float(sweep.error_estimate[i])),
                    ]
                )
    atomic_write_text(path, buf.getvalue())


def _write_layered(path: str | Path, sweep: Any, s: np.ndarray) -> None:
    """:func:`write_touchstone` of a sheet on layers: the reference planes and the stack."""
    stack = sweep.stack
    d = np.asarray(sweep.incidence.direction, dtype=np.float64)
    theta, phi = _angles(d)
    top, bottom = stack.reference_planes
    ports = s.shape[1]
    zs = complex(sweep.sheet_impedance)
    lines = [
        f"! barymesh periodic_sweep: the (0, 0) Floquet order of an infinite array on layers "
        f"as a {ports}-port",
        "! The stack, top first (mm; 'sheet' where the metal lies): "
        + (
            "; ".join([layer.describe() for layer in stack.above] + ["sheet"])
            + ("; " if stack.below or stack.ground else "")
            + "; ".join(
                [layer.describe() for layer in stack.below] + (["ground"] if stack.ground else [])
            )
        ),
        "! Time convention exp(+j w t). Vacuum outside the stack.",
    ]
    if ports == 2:
        lines += [
            "! Ports: 1 = TE above, 2 = TM above. A ground plane closes the stack below:",
            "!   no transmission, and |S|^2 sums to 1 less what the layers and the sheet absorb.",
        ]
    else:
        lines += [
            "! Ports: 1 = TE above, 2 = TM above, 3 = TE below, 4 = TM below; S(:, 3:4) from a",
            "!   second sweep of the mirrored wave from below (the stack is not its own mirror).",
        ]
    lines += [
        f"! Reference planes: ports 1, 2 at the stack's top face, z = {top:.6g} mm over the "
        "sheet" + ("" if ports == 2 else f"; ports 3, 4 at its bottom face, z = {bottom:.6g} mm."),
        "!   A reflection phase means nothing without its reference plane: shift it to the",
        "!   sheet by exp(+2j beta z) (beta = k cos theta in vacuum) only where vacuum is between.",
        f"! Incidence: theta = {theta:.6g} deg, phi = {phi:.6g} deg; the same transverse "
        "wavevector at every port.",
        "! TE = z x kappa/|kappa| (y at normal incidence), TM = TE x d travelling down, -TE x d",
        "!   travelling up. Reference impedance: each port's mode's wave impedance in vacuum;",
        "!   'R 1' below: the data are normalised to them.",
        f"! Sheet impedance Z_s = {zs.real:.6g} {'+-'[zs.imag < 0]} j{abs(zs.imag):.6g} ohm/sq.",
        "# Hz S RI R 1",
    ]
    for f, m in zip(sweep.frequencies, s, strict=True):
        for i in range(ports):
            pairs = " ".join(f"{_number(v.real)} {_number(v.imag)}" for v in m[i])
            lines.append(f"{_number(f) if i == 0 else ' ' * 8} {pairs}")
    atomic_write_text(path, "\n".join(lines) + "\n")
