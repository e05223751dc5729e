"""The edge state: the saddle orbit on the boundary between the safe basin and overturning.

Edge tracking (Skufca, Yorke and Eckhardt 2006): two initial states at the forcing's phase, one
safe and one fatal, are bisected along their segment until they are ``bisect_tol`` apart; both
are then carried along by the stroboscopic map, and whenever they drift more than
``separation`` apart they are bisected again between their images (an image of a safe state is
safe, of a fatal one fatal), until the tracked points recur with a period. The pair stays on
the boundary and is drawn to the attracting set *within* it, the edge state. Its period is read
off the tracked points (the smallest ``p`` whose points recur), and the orbit is handed to
rockjit's shooting (:func:`rockjit.orbits.periodic_orbit`), which converges it and gives its
Floquet multipliers: one outside the unit circle (the direction across the boundary), the rest
inside.

The tracking runs the compiled path at ``n_steps`` steps per period, both the map's periods
and the fates of the bisection (:class:`.outcome.Outcomes`, ``periods`` long).

Reference: J. D. Skufca, J. A. Yorke, B. Eckhardt, "Edge of chaos in a parallel shear flow",
Phys. Rev. Lett. 96, 174101 (2006).
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np

from ..settings import Integration
from ..single import DEFAULT_N, simulate
from ..validate import integer, real
from .outcome import Outcomes
from .shock import _Search

__all__ = ["EdgeState", "edge_state"]

#: Periods tracked at least before the tracked points are looked at for a period.
MIN_TRACK = 20


@dataclass
class EdgeState:
    """An edge state found by edge tracking and converged by shooting.

    Attributes
    ----------
    state : ndarray, shape (2,)
        A point of the orbit at the forcing's phase (the shooting's).
    period : int
    multipliers : ndarray of complex
        Floquet multipliers, largest modulus first.
    residual : float
        The shooting's ``max|P^p(x) - x|``.
    orbit : PeriodicOrbit
        The shooting's result (its cycle, impacts, symmetry).
    tracked : ndarray, shape (n, 2)
        The midpoints of the tracked pair, one per period.
    rebisections : int
        Times the pair was bisected again along the way.

    Examples
    --------
    What :func:`rockjit.edge_state` returns:

    >>> import rockjit
    >>> from rockjit import Block, Harmonic
    >>> e = rockjit.edge_state(Block(hb=1), Harmonic(alpha=0.66, omega=1.3), (-0.2825, -0.164),
    ...                        (0.0709, 0.2243), track=30)
    >>> e.state.shape, e.orbit.period == e.period
    ((2,), True)
    """

    state: np.ndarray
    period: int
    multipliers: np.ndarray
    residual: float
    orbit: object
    tracked: np.ndarray
    rebisections: int
    settings: dict = field(default_factory=dict)

    def __repr__(self):
        mu = ", ".join(f"{abs(m):.4g}" for m in self.multipliers)
        return (f"<rockjit.EdgeState: period {self.period} at ({self.state[0]:.6g}, "
                f"{self.state[1]:.6g}), |multipliers| {mu}, residual {self.residual:.1e}, "
                f"{len(self.tracked)} periods tracked, {self.rebisections} rebisections>")


def _bisect(oc, a, b, tol):
    """``(a, b)`` closer than ``tol`` on the segment from safe ``a`` to fatal ``b``: the
    multisection of the fatal shock's rays (:class:`.shock._Search`), on the ray from ``a``
    through ``b``."""
    d = b - a
    length = float(np.linalg.norm(d))
    if length <= tol:
        return a, b
    angle = np.array([math.atan2(d[1], d[0])])
    lo, hi = _Search(oc, a).narrow(angle, np.zeros(1), np.array([length]), 0.0, atol=tol)
    u = np.array([math.cos(angle[0]), math.sin(angle[0])])
    return a + lo[0] * u, a + hi[0] * u


def _step(block, forcing, integration, z):
    """The stroboscopic map: ``z`` one period on (``None`` where the run overturns)."""
    r = simulate(block, forcing, (float(z[0]), float(z[1])), integration=integration)
    if len(r.strobe) < 2:
        return None
    return np.asarray(r.strobe[1, :2], dtype=float)


def _period(points, max_period, tol):
    """The smallest ``p`` whose last points recur within ``tol``, or ``None``."""
    n = len(points)
    for p in range(1, max_period + 1):
        if n < 3 * p + 1:
            break
        last = points[-2 * p:]
        prev = points[-3 * p:-p]
        if np.max(np.abs(last - prev)) <= tol:
            return p
    return None


@dataclass(frozen=True)
class _Tracking:
    """The edge tracking's settings (see :func:`edge_state`), checked."""

    periods: int
    track: int
    separation: float
    bisect_tol: float
    max_period: int
    n_steps: int

    @classmethod
    def checked(cls, periods, track, separation, bisect_tol, max_period, n_steps):
        """The settings, or a ValueError naming the first one out of its range."""
        periods = integer("periods", periods, 10, 10**6)
        track = integer("track", track, 10, 10**6)
        bisect_tol = real("bisect_tol", bisect_tol, 1e-14, 1e-3)
        separation = real("separation", separation, bisect_tol, 0.1, lo_open=True)
        max_period = integer("max_period", max_period, 1, 64)
        n_steps = integer("n_steps", n_steps, 8, 100_000)
        return cls(periods, track, separation, bisect_tol, max_period, n_steps)

    @property
    def recur_tol(self):
        """Distance within which tracked points count as recurring."""
        return 10 * self.separation


def _sides(oc, safe, fatal, periods):
    """``safe`` and ``fatal`` as states, checked to be finite and to be what they say."""
    a = np.asarray(safe, dtype=float).reshape(-1)
    b = np.asarray(fatal, dtype=float).reshape(-1)
    if a.shape != (2,) or b.shape != (2,) or not (np.isfinite(a).all() and
                                                   np.isfinite(b).all()):
        raise ValueError("safe and fatal must each be two finite numbers (theta0, theta0')")
    f = oc.fatal(np.stack([a, b]))
    if f[0] or not f[1]:
        raise ValueError(f"safe must not overturn and fatal must overturn within periods = "
                         f"{periods} (safe overturns: {bool(f[0])}, fatal overturns: "
                         f"{bool(f[1])})")
    return a, b


class _Pair:
    """The tracked pair: a safe state ``a`` and a fatal one ``b`` on either side of the edge,
    carried by the stroboscopic map and bisected again whenever they drift apart."""

    def __init__(self, block, oc, settings, a, b):
        self.block, self.oc, self.s = block, oc, settings
        self.one = Integration(periods=1, n_steps=settings.n_steps)
        self.a, self.b = _bisect(oc, a, b, settings.bisect_tol)
        self.rebisections = 0

    def advance(self):
        """The pair one period on; ``False`` when the fatal state overturned at once (the pair
        is then bisected again nearer the safe one, and has no new point)."""
        a1 = _step(self.block, self.oc.forcing, self.one, self.a)
        b1 = _step(self.block, self.oc.forcing, self.one, self.b)
        if a1 is None:
            raise ValueError("the safe state of the pair overturned within one period: give a "
                             "longer horizon (periods)")
        if b1 is None:
            self._rebisect(0.01 * self.s.bisect_tol + 0.5 * np.linalg.norm(self.b - self.a))
            return False
        self.a, self.b = a1, b1
        if np.linalg.norm(self.b - self.a) > self.s.separation:
            ends = self.oc.fatal(np.stack([self.a, self.b]))
            if ends[0] or not ends[1]:
                raise ValueError("the tracked pair lost its sides (a fate changed within "
                                 "the horizon): give a longer horizon (periods)")
            self._rebisect(self.s.bisect_tol)
        return True

    def _rebisect(self, tol):
        """Bisect the pair again, to ``tol``."""
        self.a, self.b = _bisect(self.oc, self.a, self.b, tol)
        self.rebisections += 1

    def track(self):
        """The pair's midpoints, one per period, until they recur with a period (looked at
        every five periods from :data:`MIN_TRACK` on) or ``track`` periods are done."""
        tracked = []
        for _ in range(self.s.track):
            if not self.advance():
                continue
            tracked.append(0.5 * (self.a + self.b))
            if len(tracked) >= MIN_TRACK and len(tracked) % 5 == 0 and \
                    _period(np.asarray(tracked), self.s.max_period, self.s.recur_tol) is not None:
                break
        return np.asarray(tracked)


def edge_state(block, forcing, safe, fatal, *, periods=500, track=300, separation=1e-4,
               bisect_tol=1e-9, max_period=8, n_steps=DEFAULT_N, shooting=None,
               threads=None) -> EdgeState:
    """The edge state between the safe basin and overturning, by edge tracking and shooting.

    Parameters
    ----------
    block : Block
    forcing : Harmonic
        With ``alpha`` and ``omega``; its phase is the states' (default ``(r0, s0) = (0, 1)``).
    safe, fatal : array_like, shape (2,)
        Initial states ``(theta0, theta0')``: one from which the block does not overturn within
        ``periods``, one from which it does (e.g. an attractor's point and that point plus its
        :func:`rockjit.fatal_shock`).
    periods : int
        Horizon of a run deciding a state's fate, ``>= 10``.
    track : int
        Periods the pair is tracked at most, ``>= 10``; the tracking stops earlier, after at
        least 20 periods, once its last points recur with a period up to ``max_period``
        (within ten times ``separation``).
    separation : float
        Distance at which the pair is bisected again, in ``(bisect_tol, 0.1]``.
    bisect_tol : float
        Distance of the pair after a bisection, in ``[1e-14, 1e-3]``.
    max_period : int
        Largest period looked for in the tracked points, in ``[1, 64]``.
    n_steps : int
        Steps per period of the tracking's runs.
    shooting : Shooting, optional
        The shooting's tolerances (:class:`rockjit.orbits.Shooting`).
    threads : int, optional
        Threads of the bisection's runs.

    Returns
    -------
    EdgeState

    Raises
    ------
    ValueError
        For bad input, or when ``safe`` overturns or ``fatal`` does not, or when the tracked
        points show no period up to ``max_period`` (an edge state that is not periodic).
    rockjit.orbits.OrbitRefused
        When shooting does not converge from the tracked point.

    Examples
    --------
    Between the symmetric cycle of ``h/b = 1`` at ``alpha = 0.66`` and a state its minimal
    fatal shock away, a period-1 saddle:

    >>> import rockjit
    >>> from rockjit import Block, Harmonic
    >>> e = rockjit.edge_state(Block(hb=1), Harmonic(alpha=0.66, omega=1.3), (-0.2825, -0.164),
    ...                        (0.0709, 0.2243), track=30)
    >>> e.period, e.residual <= 1e-10, bool(abs(e.multipliers[0]) > 1)
    (1, True, True)
    """
    from ..orbits import periodic_orbit
    s = _Tracking.checked(periods, track, separation, bisect_tol, max_period, n_steps)
    oc = Outcomes(block, forcing, Integration(periods=s.periods, n_steps=s.n_steps),
                  threads=threads)
    pair = _Pair(block, oc, s, *_sides(oc, safe, fatal, s.periods))
    tracked = pair.track()
    p = _period(tracked, s.max_period, s.recur_tol)
    if p is None:
        raise ValueError(f"the tracked edge shows no period up to max_period = {s.max_period}: "
                         f"an edge state that is not periodic, or too few periods tracked")
    orbit = periodic_orbit(block, oc.forcing, tracked[-1], p, shooting=shooting)
    return EdgeState(state=np.asarray(orbit.state, dtype=float), period=int(orbit.period),
                     multipliers=np.asarray(orbit.multipliers), residual=float(orbit.residual),
                     orbit=orbit, tracked=tracked, rebisections=pair.rebisections,
                     settings=dict(periods=s.periods, track=s.track, separation=s.separation,
                                   bisect_tol=s.bisect_tol, n_steps=s.n_steps, runs=oc.runs))
