"""What the periodic-orbit functions take and give back: their settings (:class:`Shooting`,
:class:`ContinuationSettings`), their results (:class:`PeriodicOrbit`, :class:`Branch`,
:class:`Bifurcation`, :class:`Continuation`) and their refusal (:class:`OrbitRefused`).

The settings are frozen dataclasses validated once, in their constructors, with messages that
name the field, the allowed range and the value given (as :mod:`rockjit.settings`).
"""

from __future__ import annotations

import math
from dataclasses import asdict, dataclass, field, replace

import numpy as np

from ..excitation import Harmonic
from ..model import Block
from ..reprs import text as _text
from ..settings import Integration
from ..validate import boolean, integer, real

__all__ = ["BIFURCATION_TYPES", "REASONS", "Bifurcation", "Branch", "Continuation",
           "ContinuationSettings", "OrbitRefused", "PeriodicOrbit", "Shooting"]

BIFURCATION_TYPES = ("fold", "symmetry_breaking", "period_doubling", "neimark_sacker",
                     "grazing")

REASONS = {
    "overturn": "the block overturns (|theta| reaches theta_over)",
    "rest": "the block comes to rest for good",
    "passes_through_rest": "the orbit passes through a rest phase (its monodromy is zero)",
    "max_impacts": "the run hit the impact bound",
    "nonfinite": "a non-finite number appeared",
    "no_convergence": "Newton's method did not converge",
    "grazing": "the orbit grazes",
    "singular": "the Jacobian is singular",
    "unstable": "the orbit is too unstable to be followed",
}

_TWO_PI = 2.0 * math.pi


class OrbitRefused(RuntimeError):
    """No periodic orbit is returned; ``reason`` says why (one of the keys of :data:`REASONS`).

    Examples
    --------
    >>> from rockjit.orbits import OrbitRefused
    >>> err = OrbitRefused("grazing", "an impact with |theta'-| = 1e-05")
    >>> err.reason, str(err)
    ('grazing', "grazing: the orbit grazes (an impact with |theta'-| = 1e-05)")
    """

    def __init__(self, reason, detail=""):
        self.reason = reason
        self.detail = detail
        msg = REASONS.get(reason, reason)
        super().__init__(f"{reason}: {msg}" + (f" ({detail})" if detail else ""))


# ---------------------------------------------------------------------------------------------
# settings
# ---------------------------------------------------------------------------------------------

def _set(obj, **values):
    for name, value in values.items():
        object.__setattr__(obj, name, value)


def _fraction(name, value):
    value = real(name, value)
    if not 0 <= value < 1:
        raise ValueError(f"{name} must be in [0, 1) (got {value})")
    return value


@dataclass(frozen=True)
class Shooting:
    """How a periodic orbit is solved for, and when it is refused
    (:mod:`rockjit.orbits.shooting`, "Shooting" and "Refusals").

    Parameters
    ----------
    tol : float
        Newton's convergence: ``max|P^p(x) - x| <= tol max(1, |M|)``, ``> 0``; default
        ``1e-12``.
    max_iter : int
        Newton iterations allowed, ``>= 1``; default 40.
    sym_tol : float
        The symmetry test (and, in a continuation, the branch-point test), relative to the
        orbit's size, ``> 0``; default ``1e-6``.
    graze_tol, over_tol : float
        Grazing thresholds in ``[0, 1)``: an impact slower than ``graze_tol`` times the orbit's
        largest ``|theta'|`` (or a turn of ``|theta|`` that close to 0), a largest ``|theta|``
        within ``over_tol`` of ``theta_over``; defaults ``1e-4`` and ``1e-3``. ``graze_tol = 0``
        accepts orbits arbitrarily close to a grazing.
    max_impacts_per_period : int
        Impact bound of each run, per period, ``>= 1``; default 1000.
    theta_over, rest_speed : float
        The runs' overturning threshold and Zeno cut-off, as in :class:`rockjit.Integration`
        (defaults ``pi/2`` and ``1e-6``).

    Examples
    --------
    >>> from rockjit.orbits import Shooting
    >>> Shooting(graze_tol=0).tol
    1e-12
    >>> Shooting(over_tol=1)
    Traceback (most recent call last):
    ...
    ValueError: over_tol must be in [0, 1) (got 1.0)
    """

    tol: float = 1e-12
    max_iter: int = 40
    sym_tol: float = 1e-6
    graze_tol: float = 1e-4
    over_tol: float = 1e-3
    max_impacts_per_period: int = 1000
    theta_over: float = 0.5 * math.pi
    rest_speed: float = 1e-6

    def __post_init__(self):
        run = Integration(theta_over=self.theta_over, rest_speed=self.rest_speed)
        _set(self, tol=real("tol", self.tol, 0.0, None, lo_open=True),
             max_iter=integer("max_iter", self.max_iter, 1),
             sym_tol=real("sym_tol", self.sym_tol, 0.0, None, lo_open=True),
             graze_tol=_fraction("graze_tol", self.graze_tol),
             over_tol=_fraction("over_tol", self.over_tol),
             max_impacts_per_period=integer("max_impacts_per_period",
                                            self.max_impacts_per_period, 1),
             theta_over=run.theta_over, rest_speed=run.rest_speed)

    def replace(self, **changes):
        """A copy with some fields changed (validated again)."""
        return replace(self, **changes)


@dataclass(frozen=True)
class ContinuationSettings:
    """How branches are followed (:mod:`rockjit.orbits.arclength`, "Continuation").

    Parameters
    ----------
    ds0, ds_min, ds_max : float
        First, smallest and largest pseudo-arclength step in ``(theta, theta', lambda)``,
        ``0 < ds_min <= ds0 <= ds_max``; defaults 0.01, ``1e-8``, 0.025.
    max_points : int
        Points per direction of a branch, ``>= 2``; default 2000.
    max_period : int
        Longest period followed (seeds, and branches switched onto at period doublings), in
        ``[1, 256]``; default 8.
    join_tol : float
        Two cycles are one orbit within this fraction of the orbit's size (any cyclic shift),
        ``> 0``; default ``1e-3``.
    max_calls : int
        A bound on the runs spent, ``>= 1``; default 2,000,000.
    param_tol : float
        Bifurcations and branch ends are located to this in the parameter, ``> 0``; default
        ``1e-8``.
    switch : bool
        Follow the branches born at period doublings (as ``2p``, up to ``max_period``) and
        symmetry-breaking pitchforks; default ``True``.

    Examples
    --------
    >>> from rockjit.orbits import ContinuationSettings
    >>> ContinuationSettings(switch=False).ds_max
    0.025
    >>> ContinuationSettings(ds0=0.1)
    Traceback (most recent call last):
    ...
    ValueError: need ds_min <= ds0 <= ds_max (got 1e-08, 0.1, 0.025)
    """

    ds0: float = 0.01
    ds_min: float = 1e-8
    ds_max: float = 0.025
    max_points: int = 2000
    max_period: int = 8
    join_tol: float = 1e-3
    max_calls: int = 2_000_000
    param_tol: float = 1e-8
    switch: bool = True

    def __post_init__(self):
        for name in ("ds0", "ds_min", "ds_max", "join_tol", "param_tol"):
            _set(self, **{name: real(name, getattr(self, name), 0.0, None, lo_open=True)})
        if not self.ds_min <= self.ds0 <= self.ds_max:
            raise ValueError(f"need ds_min <= ds0 <= ds_max (got {self.ds_min}, {self.ds0}, "
                             f"{self.ds_max})")
        _set(self, max_points=integer("max_points", self.max_points, 2),
             max_period=integer("max_period", self.max_period, 1, 256),
             max_calls=integer("max_calls", self.max_calls, 1),
             switch=boolean("switch", self.switch))

    def replace(self, **changes):
        """A copy with some fields changed (validated again)."""
        return replace(self, **changes)


def settings_record(settings, shooting):
    """The settings a continuation was made with, as one flat JSON-ready dict."""
    return {**asdict(settings), **asdict(shooting)}


# ---------------------------------------------------------------------------------------------
# results
# ---------------------------------------------------------------------------------------------

@dataclass
class PeriodicOrbit:
    """A periodic orbit found by :func:`rockjit.orbits.periodic_orbit`.

    Attributes
    ----------
    state : ndarray, shape (2,)
        ``(theta, theta')`` at ``t = 0`` at the requested forcing ``phase``: a fixed point of
        ``P^p``.
    period : int
        ``p``, in forcing periods.
    alpha, omega, phase : float
        Forcing amplitude, frequency and phase.
    residual : float
        ``max|P^p(x) - x|`` at ``section_phase``: the requested phase, unless an impact sits so
        close to it that Newton worked on a shifted section only
        (:mod:`rockjit.orbits.shooting`, "Section").
    multipliers : ndarray of complex, shape (2,)
        Floquet multipliers, largest modulus first.
    stable : bool
        Both multipliers inside the unit circle.
    impacts : int
        Impacts over one cycle (``p`` periods).
    symmetric : bool
        ``x(t + pT/2) = -x(t)`` at every cycle point (:mod:`rockjit.orbits.shooting`,
        "Symmetry").
    cycle, cycle_half : ndarray, shape (p, 2)
        The cycle's points at ``kT`` and at ``kT + T/2``.
    iterations : int
        Newton iterations.
    monodromy : ndarray, shape (2, 2)
        ``M`` at the phase ``section_phase``.
    section_phase : float
        The forcing phase of the section Newton worked on.
    n_steps : int
        Steps per forcing period of the runs.
    max_theta : float
        Largest ``|theta|`` on the grid along the cycle.
    min_impact_speed : float
        Smallest ``|theta'-|`` over the cycle's impacts divided by the largest ``|theta'|``.
    n_simulate : int
        Calls of :func:`rockjit.simulate` spent.
    block : Block
        The block.
    forcing : Harmonic
        The excitation at the orbit's ``alpha``, ``omega`` and ``phase``.

    Examples
    --------
    >>> from rockjit import Block, Harmonic
    >>> from rockjit.orbits import periodic_orbit
    >>> o = periodic_orbit(Block(hb=1), Harmonic(alpha=0.8, omega=1.3), (-0.44, -0.36))
    >>> o.period, o.impacts, o.stable, o.symmetric
    (1, 2, True, False)
    >>> bool(o.residual < 1e-12), o.forcing.alpha
    (True, 0.8)
    """

    state: np.ndarray
    period: int
    alpha: float
    omega: float
    phase: float
    residual: float
    multipliers: np.ndarray
    stable: bool
    impacts: int
    symmetric: bool
    cycle: np.ndarray
    cycle_half: np.ndarray
    iterations: int
    monodromy: np.ndarray
    section_phase: float
    n_steps: int
    max_theta: float
    min_impact_speed: float
    n_simulate: int
    block: Block | None = None
    forcing: Harmonic | None = None

    def __repr__(self):
        return _text(self)

    @property
    def impacts_per_period(self) -> float:
        """Impacts per forcing period (``impacts / p``)."""
        return self.impacts / self.period

    @property
    def forcing_period(self) -> float:
        """The forcing period ``T = 2 pi / omega``."""
        return _TWO_PI / self.omega

    @property
    def lyapunov(self) -> np.ndarray:
        """``ln|mu| / (pT)``, largest first: the orbit's Lyapunov exponents (docs/theory/global-dynamics.md)."""
        with np.errstate(divide="ignore"):
            return np.log(np.abs(self.multipliers)) / (self.period * self.forcing_period)


@dataclass
class Branch:
    """A continued branch of period-``p`` orbits, ordered along its arclength.

    Attributes
    ----------
    parameter : str
        ``"alpha"`` or ``"omega"``.
    period : int
    symmetric : bool
        Solved as a symmetric branch (half map).
    value, alpha, omega : ndarray, shape (n,)
        The continuation parameter, and both forcing parameters, at each point.
    cycle, cycle_half : ndarray, shape (n, p, 2)
        The cycle at ``kT`` and ``kT + T/2`` at the continuation's phase.
    multipliers : ndarray of complex, shape (n, 2)
    stable : ndarray of bool, shape (n,)
    impacts : ndarray of int, shape (n,)
        Impacts per cycle.
    symmetric_points : ndarray of bool, shape (n,)
    t_next_impact, t_next_impact_half : ndarray, shape (n, p)
        Time from each cycle point at ``kT`` (resp. ``kT + T/2``) to the next impact. It jumps
        (by the gap between two impacts) where an impact crosses the sampling instant, and the
        sampled ``theta'`` jumps there by the factor ``e``: plots break the line there.
    ends : tuple of str
        Why the branch ends at its first and last point (``range``, ``grazing``, ``overturn``,
        ``rest``, ``passes_through_rest``, ``branch_point``, ``joins``, ``closed``,
        ``no_convergence``, ``max_points``, ``max_impacts``, ``budget``).
    origin : str
        How it was found (a seed, or a bifurcation of another branch).
    parent : int or None
        Index of the branch it was switched from.

    Examples
    --------
    >>> from rockjit import Block, Harmonic
    >>> from rockjit.orbits import ContinuationSettings, continuation
    >>> c = continuation(Block(hb=1), Harmonic(omega=1.3), [(0.8, (-0.44, -0.36), 1)],
    ...                  bounds=(0.79, 0.81), settings=ContinuationSettings(switch=False))
    >>> br = c.branches[0]
    >>> br.period, br.symmetric, br.ends, bool(br.stable.all())
    (1, False, ('range', 'range'), True)
    >>> br.mirror_cycle.shape == br.cycle.shape
    True
    """

    parameter: str
    period: int
    symmetric: bool
    value: np.ndarray
    alpha: np.ndarray
    omega: np.ndarray
    cycle: np.ndarray
    cycle_half: np.ndarray
    multipliers: np.ndarray
    stable: np.ndarray
    impacts: np.ndarray
    symmetric_points: np.ndarray
    t_next_impact: np.ndarray
    t_next_impact_half: np.ndarray
    ends: tuple
    origin: str
    parent: int | None = None

    def __repr__(self):
        return _text(self)

    @property
    def state(self) -> np.ndarray:
        """``(n, 2)``: the first cycle point at each branch point."""
        return self.cycle[:, 0, :]

    @property
    def impacts_per_period(self) -> np.ndarray:
        """``(n,)``: impacts per forcing period (``impacts / p``)."""
        return self.impacts / self.period

    @property
    def mirror_cycle(self) -> np.ndarray | None:
        """``(n, p, 2)``: the mirror-image orbit ``-x(kT + T/2)``; ``None`` if symmetric."""
        return None if self.symmetric else -self.cycle_half

    def __len__(self):
        return self.value.shape[0]


@dataclass
class Bifurcation:
    """A located bifurcation.

    Attributes
    ----------
    type : str
        One of :data:`BIFURCATION_TYPES`.
    parameter : str
    value, alpha, omega : float
        Where it is (``value`` is the continuation parameter).
    period : int
        Period of the orbit that bifurcates.
    multipliers : ndarray of complex, shape (2,)
        At the located point.
    state : ndarray, shape (2,)
        The orbit's first cycle point there (at the continuation's phase).
    cycle, cycle_half : ndarray, shape (p, 2)
        Its cycle at ``kT`` and ``kT + T/2``.
    branch : int
        Index of the branch it was found on.
    neighbours : tuple of float
        Parameter values of the two branch points that bracket it.
    neighbour_multipliers : ndarray of complex, shape (2, 2)
        Their multipliers.
    located : bool
        False if the bracketing solve failed (``value`` is then interpolated).
    n_simulate : int
        Calls of :func:`rockjit.simulate` spent locating it.
    detail : str
    has_mirror : bool
        The orbit is not symmetric: its mirror image bifurcates at the same parameter.
    new_branch : int or None
        The branch switched onto from here (period doubling, symmetry breaking).

    Examples
    --------
    >>> from rockjit import Block, Harmonic
    >>> from rockjit.orbits import ContinuationSettings, continuation
    >>> c = continuation(Block(hb=1), Harmonic(omega=1.3), [(0.8, (-0.44, -0.36), 1)],
    ...                  bounds=(0.77, 0.8), settings=ContinuationSettings(switch=False))
    >>> bif = c.bifurcations[0]
    >>> bif.type, bif.period, round(bif.alpha, 4), bif.located
    ('symmetry_breaking', 1, 0.7798, True)
    >>> sorted(bif.to_dict())[:3]
    ['alpha', 'branch', 'cycle']
    """

    type: str
    parameter: str
    value: float
    alpha: float
    omega: float
    period: int
    multipliers: np.ndarray
    state: np.ndarray
    cycle: np.ndarray
    cycle_half: np.ndarray
    branch: int
    neighbours: tuple
    neighbour_multipliers: np.ndarray
    located: bool
    n_simulate: int
    detail: str = ""
    has_mirror: bool = False
    new_branch: int | None = None

    def __repr__(self):
        return _text(self)

    def to_dict(self):
        """JSON-ready (complex multipliers as ``[re, im]`` pairs)."""
        mu = [[float(m.real), float(m.imag)] for m in self.multipliers]
        nmu = [[[float(m.real), float(m.imag)] for m in row] for row in
               self.neighbour_multipliers]
        return dict(type=self.type, parameter=self.parameter, value=self.value,
                    alpha=self.alpha, omega=self.omega, period=self.period, multipliers=mu,
                    multipliers_abs=[float(abs(m)) for m in self.multipliers],
                    state=self.state.tolist(), cycle=self.cycle.tolist(),
                    cycle_half=self.cycle_half.tolist(), branch=self.branch,
                    neighbours=list(self.neighbours), neighbour_multipliers=nmu,
                    located=self.located, n_simulate=self.n_simulate, detail=self.detail,
                    has_mirror=self.has_mirror, new_branch=self.new_branch)


@dataclass
class Continuation:
    """Branches and bifurcations from :func:`rockjit.orbits.continuation` or
    :func:`rockjit.orbits.continue_branches`.

    ``to_summary()`` gives ``(summary, arrays)``: JSON-ready dicts (write them with
    :func:`rockjit.storage.atomic.write_json`, which handles non-finite floats) and arrays for
    :func:`rockjit.storage.atomic.write_npz`.

    Attributes
    ----------
    parameter : str
        ``"alpha"`` or ``"omega"``.
    bounds : tuple of float
        The parameter range.
    block : Block
    forcing : Harmonic
        The excitation without the continued parameter, at the continuation's phase.
    phase : float
        The forcing phase of the stroboscopic section.
    n_steps : int
        Steps per forcing period of the runs.
    branches : list of Branch
    bifurcations : list of Bifurcation
    n_simulate : int
        Calls of :func:`rockjit.simulate` spent.
    wall_s : float
    seeds_tried : int
    settings : dict
        The :class:`ContinuationSettings` and :class:`Shooting` fields.

    Examples
    --------
    >>> from rockjit import Block, Harmonic
    >>> from rockjit.orbits import ContinuationSettings, continuation
    >>> c = continuation(Block(hb=1), Harmonic(omega=1.3), [(0.8, (-0.44, -0.36), 1)],
    ...                  bounds=(0.79, 0.81), settings=ContinuationSettings(switch=False))
    >>> len(c.branches), c.forcing.omega, c.phase
    (1, 1.3, 0.0)
    >>> summary, arrays = c.to_summary()
    >>> summary["omega"], arrays["branch0_cycle"].shape[1:]
    (1.3, (1, 2))
    """

    parameter: str
    bounds: tuple
    block: Block
    forcing: Harmonic
    phase: float
    n_steps: int
    branches: list
    bifurcations: list
    n_simulate: int
    wall_s: float
    seeds_tried: int = 0
    settings: dict = field(default_factory=dict)

    def __repr__(self):
        return _text(self)

    def to_summary(self):
        """``(summary, arrays)``; multipliers are written as ``[re, im]`` pairs.

        ``arrays`` holds, for branch ``i``: ``branch{i}_value``, ``_alpha``, ``_omega`` (n,),
        ``_cycle``, ``_cycle_half`` (n, p, 2), ``_multipliers`` (n, 2, 2: re, im),
        ``_stable``, ``_impacts``, ``_symmetric`` (n,), ``_t_next_impact``,
        ``_t_next_impact_half`` (n, p); and
        ``bif_type`` (k,), ``bif_value``, ``bif_alpha``, ``bif_omega``, ``bif_period``,
        ``bif_branch`` (k,), ``bif_multipliers`` (k, 2, 2), ``bif_state`` (k, 2).
        """
        b = self.block
        branches = []
        arrays = {}
        for i, br in enumerate(self.branches):
            branches.append(dict(
                index=i, period=br.period, symmetric=br.symmetric, n_points=len(br),
                value_range=[float(br.value.min()), float(br.value.max())],
                ends=list(br.ends), origin=br.origin, parent=br.parent,
                stable_points=int(np.count_nonzero(br.stable)),
                impacts=sorted({int(v) for v in br.impacts})))
            pre = f"branch{i}_"
            arrays[pre + "value"] = br.value
            arrays[pre + "alpha"] = br.alpha
            arrays[pre + "omega"] = br.omega
            arrays[pre + "cycle"] = br.cycle
            arrays[pre + "cycle_half"] = br.cycle_half
            arrays[pre + "multipliers"] = np.stack([br.multipliers.real,
                                                    br.multipliers.imag], -1)
            arrays[pre + "stable"] = br.stable
            arrays[pre + "impacts"] = br.impacts
            arrays[pre + "symmetric"] = br.symmetric_points
            arrays[pre + "t_next_impact"] = br.t_next_impact
            arrays[pre + "t_next_impact_half"] = br.t_next_impact_half
        bifs = [bf.to_dict() for bf in self.bifurcations]
        k = len(self.bifurcations)
        arrays["bif_type"] = np.array([bf.type for bf in self.bifurcations], dtype="U24")
        arrays["bif_value"] = np.array([bf.value for bf in self.bifurcations], float)
        arrays["bif_alpha"] = np.array([bf.alpha for bf in self.bifurcations], float)
        arrays["bif_omega"] = np.array([bf.omega for bf in self.bifurcations], float)
        arrays["bif_period"] = np.array([bf.period for bf in self.bifurcations], np.int64)
        arrays["bif_branch"] = np.array([bf.branch for bf in self.bifurcations], np.int64)
        mu = np.array([bf.multipliers for bf in self.bifurcations], complex).reshape(k, 2)
        arrays["bif_multipliers"] = np.stack([mu.real, mu.imag], -1)
        arrays["bif_state"] = np.array([bf.state for bf in self.bifurcations],
                                       float).reshape(k, 2)
        fixed = "omega" if self.parameter == "alpha" else "alpha"
        summary = dict(
            parameter=self.parameter, range=list(self.bounds), hb=b.hb, law=b.law,
            restitution=b.restitution, xi=b.xi, **{fixed: getattr(self.forcing, fixed)},
            phase=self.phase, n_steps=self.n_steps, branches=branches, bifurcations=bifs,
            n_simulate=self.n_simulate, continuation_wall_s=self.wall_s,
            seeds_tried=self.seeds_tried,
            settings=self.settings)
        return summary, arrays
