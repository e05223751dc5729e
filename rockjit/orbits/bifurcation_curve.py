"""A codimension-one curve in the forcing plane as followed (:class:`BifurcationCurve`): its
points, orbits and multipliers along its arclength, where it crosses a given ``omega``
(interpolated, or solved again there), and its summary and arrays for the output files.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from ..excitation import ALPHA_MAX, OMEGA_RANGE
from ..validate import real
from .curve_types import CurveSettings
from .tracer import _section, _system
from .types import OrbitRefused

__all__ = ["BifurcationCurve"]


@dataclass
class BifurcationCurve:
    """A codimension-one curve in the forcing plane, ordered along its arclength.

    Attributes
    ----------
    type : str
        One of :data:`CURVE_TYPES`.
    period : int
        Period of the orbit that bifurcates (or grazes).
    law : str
        The block's restitution law.
    symmetric : bool
        Solved on the half map (a symmetric orbit).
    grazing : str or None
        For a grazing curve, ``"impact"`` (an excursion touches ``theta = 0`` at zero speed)
        or ``"overturn"`` (``max|theta|`` touches ``theta_over``).
    alpha, omega : ndarray, shape (n,)
        The curve.
    state : ndarray, shape (n, 2)
        The orbit's first cycle point at each curve point, at the section ``phase``.
    cycle, cycle_half : ndarray, shape (n, p, 2)
        The cycle at ``kT`` and ``kT + T/2`` (the mirror orbit of a non-symmetric one is
        ``-cycle_half``).
    multipliers : ndarray of complex, shape (n, 2)
    impacts : ndarray of int, shape (n,)
        Impacts per cycle.
    condition : ndarray, shape (n,)
        The defining condition's residual at each point (``det(M -+ I)``, or the grazing
        depth in radians).
    residual : ndarray, shape (n,)
        ``max|fixed-point equations|`` at each point.
    critical : ndarray, shape (n,)
        ``min |mu - c|`` over the multipliers, ``c = +1`` (fold, symmetry breaking) or ``-1``
        (period doubling); ``nan`` for grazing.
    ends : tuple of str
        Why the curve ends at its first and last point (:data:`CURVE_ENDS`).
    codim2 : list of Codim2Point
    phase : float
        The forcing phase of the section.
    seed : dict
        The bifurcation it was followed from (:meth:`Bifurcation.to_dict`'s fields that
        place it).
    n_simulate : int
        Runs spent.
    wall_s : float
    n_steps : int

    Examples
    --------
    >>> from rockjit import Block, Harmonic
    >>> from rockjit.orbits import (ContinuationSettings, CurveSettings, continuation,
    ...                             continue_curve)
    >>> c = continuation(Block(hb=1), Harmonic(omega=1.3), [(0.8, (-0.44, -0.36), 1)],
    ...                  bounds=(0.77, 0.8), settings=ContinuationSettings(switch=False))
    >>> sb = c.bifurcations[0]
    >>> curve = continue_curve(Block(hb=1), sb, phase=c.phase, alpha_range=(0.7, 0.85),
    ...                        omega_range=(1.25, 1.35))
    >>> curve.type, curve.ends
    ('symmetry_breaking', ('range', 'range'))
    >>> bool(abs(curve.critical).max() < 1e-9)
    True
    """

    type: str
    period: int
    law: str
    symmetric: bool
    grazing: str | None
    alpha: np.ndarray
    omega: np.ndarray
    state: np.ndarray
    cycle: np.ndarray
    cycle_half: np.ndarray
    multipliers: np.ndarray
    impacts: np.ndarray
    condition: np.ndarray
    residual: np.ndarray
    critical: np.ndarray
    ends: tuple
    codim2: list
    phase: float
    seed: dict
    n_simulate: int
    wall_s: float
    n_steps: int
    block: object = None
    shooting: object = None
    count: int = 0  # the impacts the extended system keeps (over the half map's stretch)

    @property
    def points(self) -> np.ndarray:
        """``(n, 2)``: ``(alpha, omega)`` along the curve."""
        return np.stack([self.alpha, self.omega], 1)

    def __len__(self):
        return self.alpha.shape[0]

    def alpha_at(self, omega):
        """The curve's ``alpha`` values where it crosses ``omega`` (linear interpolation
        between its points; several where it turns in ``omega``)."""
        w = self.omega - omega
        out = []
        for k in np.nonzero(w[:-1] * w[1:] <= 0)[0]:
            dw = self.omega[k + 1] - self.omega[k]
            s = 0.5 if dw == 0 else (omega - self.omega[k]) / dw
            a = float(self.alpha[k] + s * (self.alpha[k + 1] - self.alpha[k]))
            if not out or abs(a - out[-1]) > 1e-12:  # a point on omega is in two segments
                out.append(a)
        return out

    def solve_at(self, omega):
        """The curve's ``alpha`` where it crosses ``omega``, solved there (not interpolated):
        the extended system corrected at fixed ``omega`` from each crossing of the curve's
        points, one value per crossing (``nan`` where the corrector fails).

        Examples
        --------
        >>> from rockjit import Block, Harmonic
        >>> from rockjit.orbits import ContinuationSettings, continuation, continue_curve
        >>> c = continuation(Block(hb=1), Harmonic(omega=1.3), [(0.8, (-0.44, -0.36), 1)],
        ...                  bounds=(0.77, 0.8), settings=ContinuationSettings(switch=False))
        >>> curve = continue_curve(Block(hb=1), c.bifurcations[0], phase=c.phase,
        ...                        alpha_range=(0.7, 0.85), omega_range=(1.2, 1.4))
        >>> [round(a, 9) for a in curve.solve_at(1.25)]
        [0.806781978]
        """
        omega = real("omega", omega, *OMEGA_RANGE)
        box = (0.0, ALPHA_MAX, OMEGA_RANGE[0], OMEGA_RANGE[1])
        flow, solver, ext, tracer = _system(self.block, self.type, self.period, self.symmetric,
                                            self.grazing, self.count, self.phase, self.n_steps,
                                            self.shooting, box, CurveSettings())
        w = self.omega - omega
        out = []
        for k in np.nonzero(w[:-1] * w[1:] <= 0)[0]:
            dw = self.omega[k + 1] - self.omega[k]
            s = 0.5 if dw == 0 else (omega - self.omega[k]) / dw
            a = float(self.alpha[k] + s * (self.alpha[k + 1] - self.alpha[k]))
            if out and abs(a - out[-1][0]) < 1e-12:
                continue
            x = self.state[k] + s * (self.state[k + 1] - self.state[k])
            lam = (a, omega)
            try:
                j, xj = _section(solver, x, lam, self.period)
            except OrbitRefused:
                out.append((a, math.nan))
                continue
            y0 = np.r_[xj, lam]
            ev0 = ext(y0, j)
            if not ev0.ok and ext.depth is not None:
                ev0 = tracer.enter_side(y0, j, ev0)
                y0 = y0 if ev0 is None or not ev0.ok else ev0.y
            ok, y, _, _, _ = tracer.correct(y0, np.array([0.0, 0.0, 0.0, 1.0]), j,
                                            max_iter=40, max_jac=40)
            out.append((a, float(y[2]) if ok else math.nan))
        return [v for _, v in out]

    def through(self, omega, alpha, cycle, tol=1e-3):
        """Whether the curve crosses ``omega`` within ``tol`` (relative) of ``alpha``, with an
        orbit there within 5 % of its size of ``cycle`` (or of its mirror image): the same
        curve, found again."""
        from ..grids.cycles import cycle_distance
        w = self.omega - omega
        for k in np.nonzero(w[:-1] * w[1:] <= 0)[0]:
            dw = self.omega[k + 1] - self.omega[k]
            s = 0.5 if dw == 0 else (omega - self.omega[k]) / dw
            a = self.alpha[k] + s * (self.alpha[k + 1] - self.alpha[k])
            if abs(a - alpha) > tol * max(1.0, abs(alpha)):
                continue
            scale = max(float(np.abs(cycle).max()), 1e-12)
            for cyc in (self.cycle, -self.cycle_half):
                ci = (1 - s) * cyc[k] + s * cyc[k + 1]
                if cycle_distance(ci, np.asarray(cycle)) <= 0.05 * scale:
                    return True
        return False

    def to_dict(self, points=True):
        """JSON-ready: type, period, law, ``points`` ``[[alpha, omega], ...]``, ends,
        codimension-two points, the largest residuals."""
        d = dict(type=self.type, period=int(self.period), law=self.law,
                 symmetric=bool(self.symmetric), grazing=self.grazing, n_points=len(self),
                 ends=list(self.ends), codim2=[c.to_dict() for c in self.codim2],
                 max_condition=float(np.max(np.abs(self.condition))) if len(self) else 0.0,
                 max_residual=float(np.max(self.residual)) if len(self) else 0.0,
                 max_critical=float(np.nanmax(self.critical)) if len(self) and
                 np.isfinite(self.critical).any() else None,
                 alpha_range=[float(self.alpha.min()), float(self.alpha.max())],
                 omega_range=[float(self.omega.min()), float(self.omega.max())],
                 phase=self.phase, seed=self.seed, n_simulate=self.n_simulate,
                 wall_s=self.wall_s)
        if points:
            d["points"] = self.points.tolist()
        return d

    def arrays(self, prefix):
        """The curve's arrays for an ``.npz``, each name prefixed."""
        mu = np.asarray(self.multipliers, complex)
        return {prefix + "alpha": self.alpha, prefix + "omega": self.omega,
                prefix + "state": self.state, prefix + "cycle": self.cycle,
                prefix + "multipliers": np.stack([mu.real, mu.imag], -1),
                prefix + "impacts": self.impacts, prefix + "condition": self.condition,
                prefix + "residual": self.residual, prefix + "critical": self.critical}
