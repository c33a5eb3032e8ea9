"""The result of :func:`barymesh.mom.periodic_sweep`: reflection and transmission of an
infinite array over frequency, its Floquet orders and onsets, and its exports.

Kept apart from the sweep's driver (:mod:`barymesh.mom.periodic_sweep`), which samples,
solves and interpolates; this module only holds and derives what a sweep found.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from functools import cached_property
from typing import TYPE_CHECKING, Any

import numpy as np

from ..constants import SPEED_OF_LIGHT
from ..mesh import TriMesh
from .excitation import PlaneWave
from .floquet import (
    merged_onsets,
    order_onsets,
)
from .periodic import (
    PeriodicSolution,
    periodic_solve,
)
from .periodic_green import reciprocal_vectors
from .stack import Stack

if TYPE_CHECKING:
    from .circuit import EquivalentCircuit


@dataclass(frozen=True, eq=False)
class PeriodicSweep:
    """Reflection and transmission of an infinite array over frequency.

    Attributes
    ----------
    frequencies : (F,) float
        Hz, as asked for.
    incidence : PlaneWave
        The incident wave: its direction is that of every frequency; its polarisation
        is the one :attr:`reflection`, :attr:`transmission` and :meth:`co_polar` report.
    polarizations : (K, 3) float
        The incident fields solved: TE and TM (:func:`te_tm_polarizations`, K = 2), or the
        incidence's own polarisation alone (K = 1).
    incident_te_tm : (2,) complex
        The incidence's TE and TM components.
    orders : (P, 2) int
        Every Floquet order (p, q) that propagates somewhere in the band, (0, 0) first,
        then by onset.
    onsets : (P,) float
        The frequency (Hz) above which each order propagates (0 for (0, 0)).
    order_reflection, order_transmission : (F, P, 2, K) complex
        TE and TM amplitude of each order on the incident side and the far side, per
        incident field solved, in units of the incident amplitude (as in
        :class:`~barymesh.mom.PeriodicSolution`); NaN where the order is evanescent.
    lattice : (2, 2) float
        Rows a1, a2 (m).
    sampled : (S,) float
        The frequencies solved (Hz), increasing: with ``interpolate=False`` the requested
        ones; otherwise the greedy samples, including those next to each onset.
    error_estimate : (F,) float
        Estimated absolute error of the (0, 0) coefficients at each frequency (0 where
        solved).
    interpolated : bool
    sheet_impedance : complex
        Ω per square.
    resonances : (R,) float
        Hz: peaks and dips of |R_co| (total reflection, total transmission).
    resonance_kinds : tuple of str
        "peak" or "dip" per resonance.
    quality_factors : (R,) float
        Q = Re f_p / (2 |Im f_p|) of the rational fit's pole f_p nearest each resonance,
        among the poles whose term reaches the resonance prominence on the real axis (NaN
        when there is none close by).
    mesh : TriMesh
        The cell, for :meth:`solution`.
    lattice_source : object
        The ``lattice=`` given (None: the mesh's own), for :meth:`solution`.
    stack : Stack or None
        The layers around the sheet (None: in vacuum); R and T are referred to its faces
        (:attr:`reference_planes`).
    warnings : tuple of str
        When the curve should not be trusted as it is (see :mod:`barymesh.mom.caveats`).
    """

    frequencies: np.ndarray
    incidence: PlaneWave
    polarizations: np.ndarray
    incident_te_tm: np.ndarray
    orders: np.ndarray
    onsets: np.ndarray
    order_reflection: np.ndarray
    order_transmission: np.ndarray
    lattice: np.ndarray
    sampled: np.ndarray
    error_estimate: np.ndarray
    interpolated: bool
    sheet_impedance: complex
    resonances: np.ndarray
    resonance_kinds: tuple[str, ...]
    quality_factors: np.ndarray
    mesh: TriMesh
    lattice_source: Any = None
    stack: Stack | None = None
    warnings: tuple[str, ...] = ()

    @property
    def reference_planes(self) -> tuple[float, float]:
        """Heights (mm) over the sheet of the planes R and T are referred to (as
        :attr:`barymesh.mom.PeriodicSolution.reference_planes`)."""
        if self.stack is None:
            return (0.0, 0.0)
        top, bottom = self.stack.reference_planes
        return (top, bottom) if np.asarray(self.incidence.direction)[2] < 0 else (bottom, top)

    @cached_property
    def layer_onsets(self) -> tuple[tuple[float, tuple[int, int], int], ...]:
        """Onsets inside the band of orders that propagate in a layer but not in vacuum.

        (frequency in Hz, order (p, q), index of the layer in ``stack.layers``) for each,
        by frequency: above it that order is guided inside the stack (it carries no power
        out; :attr:`grating_lobe_onsets` are the vacuum's). Empty in vacuum.
        """
        if self.stack is None:
            return ()
        direction = np.asarray(self.incidence.direction, dtype=np.float64)
        f0, f1 = float(self.frequencies[0]), float(self.frequencies[-1])
        found = []
        for i, layer in enumerate(self.stack.layers):
            index = math.sqrt(layer.eps_r * layer.mu_r)
            if layer.thickness <= 0 or index <= 1.0:
                continue
            orders, onsets = order_onsets(self.lattice, direction, f1, index)
            for order, onset in zip(orders, onsets, strict=True):
                if f0 < onset < f1 and np.any(order != 0):
                    found.append((float(onset), (int(order[0]), int(order[1])), i))
        return tuple(sorted(found))

    @property
    def n_solves(self) -> int:
        """Frequencies solved (each one impedance matrix, K right-hand sides)."""
        return len(self.sampled)

    @property
    def both_polarizations(self) -> bool:
        """True when TE and TM incidence were both solved (the full 2 × 2 per order)."""
        return self.polarizations.shape[0] == 2

    @cached_property
    def grating_lobe_onsets(self) -> np.ndarray:
        """(G,) float: the onsets (Hz) inside the band, increasing, each once."""
        f = self.frequencies
        inside = self.onsets[(self.onsets > f[0]) & (self.onsets < f[-1])]
        return merged_onsets(inside)

    @property
    def propagating(self) -> np.ndarray:
        """(F, P) bool: which orders propagate at each frequency."""
        return self.frequencies[:, None] > self.onsets[None, :]

    def _respond(self, coefficients: np.ndarray) -> np.ndarray:
        """(F, P, 2, K) → (F, P, 2): the response to the incidence's polarisation."""
        if self.both_polarizations:
            return coefficients @ self.incident_te_tm
        return coefficients[..., 0]

    @cached_property
    def order_response(self) -> tuple[np.ndarray, np.ndarray]:
        """(F, P, 2) complex R and T of every order for the incidence's polarisation."""
        return self._respond(self.order_reflection), self._respond(self.order_transmission)

    @property
    def reflection(self) -> np.ndarray:
        """(F, 2) complex: TE and TM reflection of the (0, 0) order, for the incidence."""
        return self.order_response[0][:, 0]

    @property
    def transmission(self) -> np.ndarray:
        """(F, 2) complex: TE and TM transmission of the (0, 0) order (incident wave
        included), for the incidence."""
        return self.order_response[1][:, 0]

    def co_polar(self) -> tuple[np.ndarray, np.ndarray]:
        """(F,) complex R and T of the (0, 0) order along the incident polarisation."""
        p = np.conj(self.incident_te_tm)
        return self.reflection @ p, self.transmission @ p

    def equivalent_circuit(
        self, kind: str | None = None, band: tuple[float, float] | None = None
    ) -> EquivalentCircuit:
        """The Foster LC circuit of the sheet (:func:`barymesh.mom.circuit.equivalent_circuit`).

        Fitted to the co-polar (0, 0) reflection of this sweep (its rational fit's values
        where it interpolated), below the first grating-lobe or guided-order onset.
        ``kind`` "series" (patches, rings: capacitive at low frequency) or "parallel"
        (grids, apertures: inductive), default the one that fits better; ``band`` (Hz)
        narrows the frequencies fitted. Returns an
        :class:`~barymesh.mom.circuit.EquivalentCircuit`.
        """
        from .circuit import equivalent_circuit

        onsets = [*self.grating_lobe_onsets, *(onset for onset, _, _ in self.layer_onsets)]
        return equivalent_circuit(
            self.frequencies,
            self.co_polar()[0],
            self.stack,
            self.incidence,
            kind=kind,
            band=band,
            onsets=onsets,
        )

    def cross_polar(self) -> tuple[np.ndarray, np.ndarray]:
        """(F,) complex R and T of the (0, 0) order across the incident polarisation."""
        c = self.incident_te_tm
        q = np.array([-np.conj(c[1]), np.conj(c[0])])  # orthogonal to c
        return self.reflection @ np.conj(q), self.transmission @ np.conj(q)

    @cached_property
    def beta(self) -> np.ndarray:
        """(F, P) float: β_pq = sqrt(k² − |κ_pq|²) (rad/m), NaN where evanescent."""
        k = 2.0 * np.pi * self.frequencies / SPEED_OF_LIGHT
        recip = np.array(reciprocal_vectors(self.lattice[0], self.lattice[1]))
        u = np.asarray(self.incidence.direction)[:2]
        kappa = k[:, None, None] * u + (self.orders @ recip)[None]
        b2 = k[:, None] ** 2 - np.einsum("fpc,fpc->fp", kappa, kappa)
        return np.where(self.propagating & (b2 > 0), np.sqrt(np.abs(b2)), np.nan)

    @cached_property
    def power_fractions(self) -> tuple[np.ndarray, np.ndarray]:
        """(F, P) reflected and transmitted power of each order over the incident power
        (0 where evanescent), for the incidence."""
        r, t = self.order_response
        weight = self.beta / self.beta[:, :1]
        rp = np.nan_to_num(weight * (np.abs(r) ** 2).sum(axis=2))
        tp = np.nan_to_num(weight * (np.abs(t) ** 2).sum(axis=2))
        return rp, tp

    @property
    def absorption(self) -> np.ndarray:
        """(F,) float: 1 − reflected − transmitted power, what a sheet impedance and lossy
        layers absorb.

        From the coefficients, so on a perfect conductor over lossless layers it measures
        the power balance error (discretisation, fit).
        """
        r, t = self.power_fractions
        return 1.0 - r.sum(axis=1) - t.sum(axis=1)

    def solution(self, frequency: float) -> PeriodicSolution:
        """The full solve at one frequency (currents included), for the incidence."""
        return periodic_solve(
            self.mesh,
            frequency,
            self.incidence,
            lattice=self.lattice_source,
            sheet_impedance=self.sheet_impedance,
            stack=self.stack,
        )

    def to_touchstone(self, path: Any, from_below: PeriodicSweep | None = None) -> None:
        """Write the (0, 0) order's 4-port S-parameters (TE/TM above, TE/TM below) to
        ``path`` (.s4p), a 2-port (.s2p) over a ground plane; on layers without one the
        lower ports need ``from_below``, the mirrored wave's sweep. See
        :func:`barymesh.io.floquet.write_touchstone`."""
        from ..io.floquet import write_touchstone

        write_touchstone(path, self, from_below)

    def to_csv(self, path: Any) -> None:
        """Write every propagating order at every frequency to ``path`` (CSV); see
        :func:`barymesh.io.floquet.write_orders_csv`."""
        from ..io.floquet import write_orders_csv

        write_orders_csv(path, self)

    def to_network(
        self, name: str = "barymesh periodic sweep", from_below: PeriodicSweep | None = None
    ) -> Any:
        """The (0, 0) order's S-parameters as a ``skrf.Network`` (needs scikit-rf): the
        ports of :meth:`to_touchstone`, at full precision. See
        :func:`barymesh.io.floquet.to_network`."""
        from ..io.floquet import to_network

        return to_network(self, name, from_below)


# -- the sweep --------------------------------------------------------------------------
