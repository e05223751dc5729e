"""Periodic orbits of the stroboscopic map: shooting, continuation, located bifurcations.

A period-``p`` orbit of the forced block is a fixed point of ``P^p``, ``P`` the stroboscopic map
``(theta, theta')(kT) -> (theta, theta')((k+1)T)`` at a fixed forcing phase (SPEC.md §8). This
module finds such orbits by Newton's method (shooting), follows them as a forcing parameter
(``alpha`` or ``omega``) varies by pseudo-arclength continuation, and locates where they
bifurcate. It is built on the public :func:`rockjit.simulate` only: a run with ``lyapunov=True,
qr_every=0`` returns in ``result.extra["tangent"]`` the Jacobian of the flow over the run, the
saltation matrix applied at every impact, which over ``p`` periods is the monodromy matrix ``M``
whose eigenvalues are the orbit's Floquet multipliers. Every integration goes through one method,
:meth:`_Flow.run`, so that a lower-level entry point can replace it.

Definitions and choices
-----------------------
Shooting
    Newton on ``F(x) = P^p(x) - x`` with the exact Jacobian ``M - I``, damped by halving the step
    until ``|F|`` decreases (and the trial run neither overturns nor rests), each step at most half
    the orbit's size. Unstable orbits converge like stable ones. Converged when
    ``max|F| <= tol max(1, |M|)`` (``tol`` default ``1e-12``, in the units of ``theta,
    theta'``; ``|M|`` the monodromy's infinity norm, since the round-off of ``P^p(x)`` grows
    with it), or when ``|F|`` stops decreasing within ten times that. :func:`periodic_orbit`
    then takes up to two more steps while they halve ``|F|`` (down to round-off), at the
    requested phase.
Section
    An impact at a sampling instant makes the stroboscopic point jump (``theta' -> e theta'``):
    the map is discontinuous there although the orbit is not. Newton and continuation therefore
    work on a *computational* section, the forcing phase shifted by a whole number ``j`` of grid
    steps so that it lies in the middle of the largest gap between impacts, and moved again when
    an impact comes within 30 % of the best achievable margin. States are reported at the
    requested phase (read off the recorded trajectory, which has every grid point, and for
    :func:`periodic_orbit` polished there by Newton: carried along an expanding orbit, a
    residual at round-off at one section grows at another); multipliers do not depend on the
    section.
Symmetry
    The equations are odd under ``theta -> -theta`` with the forcing shifted by ``T/2``. A cycle
    is *symmetric* when ``x(t + pT/2) = -x(t)``; this needs ``p`` odd (for ``p = 1``:
    ``x(T/2) = -x(0)``, the SPEC's definition; for even ``p`` no orbit is symmetric), checked at
    every cycle point to ``sym_tol`` times the orbit's size. A symmetric branch is solved on the
    half map, ``x + Phi_{pT/2}(x) = 0`` (Jacobian by forward differences), on which the
    symmetry-breaking pitchfork is a regular point, not a branch point. The mirror image of a
    non-symmetric cycle, ``-x(kT + T/2)``, is another orbit with the same multipliers; it is
    reported with each branch (:attr:`Branch.mirror_cycle`), not continued separately.
Refusals
    :func:`periodic_orbit` raises :class:`OrbitRefused` (a ``RuntimeError`` with a ``reason``)
    when a run overturns (``"overturn"``), comes to rest for good (``"rest"``), passes through a
    rest phase (``"passes_through_rest"``: every perturbation dies there, the monodromy is
    zero and the orbit is not a smooth fixed point), hits the impact bound (``"max_impacts"``),
    when Newton fails (``"no_convergence"``), or when the orbit grazes (``"grazing"``): an impact
    with ``|theta'-|`` below ``graze_tol`` times the orbit's largest ``|theta'|``, a turning point
    of ``|theta|`` closer to 0 than ``graze_tol`` times its largest ``|theta|`` without impact, a
    largest ``|theta|`` within a fraction ``over_tol`` of ``theta_over``, or an impact count that
    changes between Newton iterates near the solution.
Continuation
    Pseudo-arclength (Keller 1977; Seydel 2010 ch. 4; Doedel et al. 1991): unknowns
    ``y = (theta, theta', lambda)``, secant predictor, Newton corrector on the bordered system
    ``[F_x F_lambda; t^T]`` with ``F_lambda`` by a forward difference, step grown by 1.3 after a
    corrector of at most 3 iterations and halved after a failure. A step whose orbit has a
    different number of impacts per cycle brackets a grazing, which is then located by bisection
    (to ``param_tol``) and ends the branch. Near a grazing from the side without the extra
    impact the map's derivative blows up (di Bernardo et al. 2008, ch. 6) and the corrector
    fails before the count changes: when the step has shrunk to ``ds_min`` and the last orbit
    turns back within ``1e-3`` of its size from ``theta = 0`` (or hits it at a speed that
    small), the orbit is followed by damped Newton at fixed parameter values to where it stops
    existing, by bisection (measured on the hb=1 Housner case: within ``3e-10`` of where the
    turning point's depth, from dense plain runs, extrapolates to zero). Overturning and rest
    end a branch likewise, located the same way and reported as a grazing (of ``theta_over``,
    of rest). A branch also ends at the
    range's end, at a branch point (a doubled or asymmetric branch folding back onto the orbit
    it was born from, which is then seeded too), on joining a branch already computed (or its
    mirror image), or on closing a loop.
Bifurcations
    Test functions on consecutive branch points (Kuznetsov 2004 ch. 10; Seydel 2010 ch. 5):
    ``det(M - I)`` (a real multiplier through +1), ``det(M + I)`` (through -1),
    ``det(M) - 1`` with a complex pair (Neimark–Sacker). A sign change is located by Brent's
    method along the chord between the two points, each trial a corrected point on the branch
    (the hyperplane through it normal to the chord), to ``1e-8`` or better in the parameter.
    On a symmetric orbit a multiplier +1 of ``M = A^2`` (``A`` the half map's Jacobian) is a
    symmetry-breaking pitchfork when ``A``'s eigenvalue crosses -1 and a fold when it crosses +1
    (then ``det(I - A)`` changes sign too); on other orbits it is a fold. Period doubling and
    symmetry breaking are followed onto the new branch (``2p``, resp. ``p`` without symmetry)
    from the located point along the critical eigenvector. Neimark–Sacker cannot occur in this
    model unless ``e = 1`` and ``xi = 0``: ``det M = e^(2n) exp(-3 xi pT / 4)`` with ``n``
    impacts per cycle (the trace of the variational equation is ``-3 xi / 4`` and each
    saltation matrix has determinant ``e^2``, SPEC.md §5), so a complex pair always has
    ``|mu| < 1``; the test is kept for completeness.

Notes
-----
Saltation and grazing: di Bernardo, Budd, Champneys, Kowalczyk (2008), *Piecewise-smooth
Dynamical Systems*, Springer, ch. 2 and 6 (grazing of impacting orbits). Continuation and test
functions: Seydel (2010), *Practical Bifurcation and Stability Analysis*, 3rd ed., Springer;
Kuznetsov (2004), *Elements of Applied Bifurcation Theory*, 3rd ed., Springer; Doedel, Keller,
Kernévez (1991), "Numerical analysis and control of bifurcation problems", Int. J. Bifurcation
and Chaos 1(3), 493–520 and 1(4), 745–772; Keller (1977), "Numerical solution of bifurcation
and nonlinear eigenvalue problems", in *Applications of Bifurcation Theory*, Academic Press.
"""

from __future__ import annotations

import math
import time
from dataclasses import dataclass, field

import numpy as np

from ..model import Block
from ..single import simulate
from ..validate import integer, pair, real

__all__ = ["BIFURCATION_TYPES", "N_ORBIT", "Bifurcation", "Branch", "Continuation",
           "OrbitRefused", "PeriodicOrbit", "continuation", "continue_branches",
           "periodic_orbit"]

#: Steps per forcing period of the shooting runs. On orbits sampled along every branch of the
#: hb=1 Housner case over alpha in [0.5, 1.0] (periods 1 to 8, ``|mu|`` up to 50), the fixed
#: points found at N = 384 have residuals of at most 2.4e-11 in a converged plain run
#: (N = 8192), against 2.2e-10 at N = 256 and 2.4e-9 at N = 160 (benchmarks/bench_orbits.py);
#: a step costs little beside the fixed cost of a call (+13 % for the continuation over 256).
N_ORBIT = 384

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
}

_TWO_PI = 2.0 * math.pi


class OrbitRefused(RuntimeError):
    """No periodic orbit is returned; ``reason`` says why (one of the keys of ``REASONS``)."""

    def __init__(self, reason, detail=""):
        self.reason = reason
        self.detail = detail
        msg = REASONS.get(reason, reason)
        super().__init__(f"{reason}: {msg}" + (f" ({detail})" if detail else ""))


# ---------------------------------------------------------------------------------------------
# input checks
# ---------------------------------------------------------------------------------------------

def _as_block(block_or_params):
    if isinstance(block_or_params, Block):
        return block_or_params
    if isinstance(block_or_params, dict):
        return Block(**block_or_params)
    raise ValueError("block_or_params must be a rockjit.Block or a dict of its parameters "
                     f"(got {type(block_or_params).__name__})")


def _state(name, x0, p):
    x = np.asarray(x0, dtype=float)
    if x.shape == (p, 2):
        x = x[0]
    if x.shape != (2,):
        raise ValueError(f"{name} must be (theta, theta') or a cycle of shape (p, 2) "
                         f"(got shape {x.shape})")
    if not np.all(np.isfinite(x)):
        raise ValueError(f"{name} must be finite (got {x.tolist()})")
    return x.copy()


def _range(name, rng, lo):
    a, b = pair(name, rng, lo)
    if b <= a:
        raise ValueError(f"{name} must satisfy start < end (got {a:g}, {b:g})")
    return a, b


# ---------------------------------------------------------------------------------------------
# results
# ---------------------------------------------------------------------------------------------

def _sorted_mult(M):
    mu = np.linalg.eigvals(M)
    return mu[np.argsort(-np.abs(mu), kind="stable")].astype(complex)


@dataclass
class PeriodicOrbit:
    """A periodic orbit found by :func:`periodic_orbit`.

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
        close to it that Newton worked on a shifted section only (module docstring).
    multipliers : ndarray of complex, shape (2,)
        Floquet multipliers, largest modulus first.
    stable : bool
        Both multipliers inside the unit circle.
    impacts : int
        Impacts over one cycle (``p`` periods).
    symmetric : bool
        ``x(t + pT/2) = -x(t)`` at every cycle point (module docstring).
    cycle, cycle_half : ndarray, shape (p, 2)
        The cycle's points at ``kT`` and at ``kT + T/2``.
    iterations : int
        Newton iterations.
    monodromy : ndarray, shape (2, 2)
        ``M`` at the phase ``section_phase``.
    max_theta : float
        Largest ``|theta|`` on the grid along the cycle.
    min_impact_speed : float
        Smallest ``|theta'-|`` over the cycle's impacts divided by the largest ``|theta'|``.
    n_simulate : int
        Calls of :func:`rockjit.simulate` spent.
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

    @property
    def impacts_per_period(self) -> float:
        return self.impacts / self.period

    @property
    def forcing_period(self) -> float:
        return _TWO_PI / self.omega

    @property
    def lyapunov(self) -> np.ndarray:
        """``ln|mu| / (pT)``, largest first: the orbit's Lyapunov exponents (SPEC.md §8)."""
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

    def to_dict(self):
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
    """Branches and bifurcations from :func:`continuation` or :func:`continue_branches`.

    ``to_summary()`` gives ``(summary, arrays)``: JSON-ready dicts (write them with
    :func:`rockjit.storage.files.write_json`, which handles non-finite floats) and arrays for
    :func:`rockjit.storage.files.write_npz`.
    """

    parameter: str
    bounds: tuple
    block: Block
    phase: float
    n_steps: int
    branches: list
    bifurcations: list
    n_simulate: int
    wall_s: float
    seeds_tried: int = 0
    settings: dict = field(default_factory=dict)

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
        summary = dict(
            parameter=self.parameter, range=list(self.bounds), hb=b.hb, law=b.law,
            restitution=b.restitution, xi=b.xi,
            **({"omega": b.omega} if self.parameter == "alpha" else {"alpha": b.alpha}),
            phase=self.phase, n_steps=self.n_steps, branches=branches, bifurcations=bifs,
            n_simulate=self.n_simulate, continuation_wall_s=self.wall_s,
            seeds_tried=self.seeds_tried,
            settings=self.settings)
        return summary, arrays


# ---------------------------------------------------------------------------------------------
# the flow: every integration of this module
# ---------------------------------------------------------------------------------------------

class _Flow:
    """Runs of :func:`rockjit.simulate` for one block with a varying parameter ``lambda``."""

    def __init__(self, block, parameter, n_steps, phase, impacts_per_period=1000):
        self.block = block
        self.parameter = parameter
        self.kw = dict(hb=block.hb, law=block.law, xi=block.xi, theta_over=block.theta_over,
                       rest_speed=block.rest_speed)
        if block.law == "constant":
            self.kw["e"] = block.e
        self.N = n_steps
        self.phase = phase  # the output phase; the computational one is phase + 2 pi j / N
        self.imp = impacts_per_period
        self.calls = 0

    def params(self, lam):
        if self.parameter == "alpha":
            return lam, self.block.omega
        return self.block.alpha, lam

    def valid(self, lam):
        return lam > 0 if self.parameter == "omega" else lam >= 0

    def period(self, lam):
        return _TWO_PI / self.params(lam)[1]

    def run(self, x, lam, periods, j, tangent):
        """``periods`` periods from ``x`` at phase ``phase + 2 pi j / N``, trajectory recorded."""
        alpha, omega = self.params(lam)
        self.calls += 1
        return simulate(**self.kw, alpha=alpha, omega=omega, theta0=float(x[0]),
                        dtheta0=float(x[1]), phase=self.phase + _TWO_PI * j / self.N,
                        periods=periods, n_steps=self.N, lyapunov=tangent,
                        qr_every=0 if tangent else None, record_stride=1,
                        max_impacts=self.imp * periods)


def _failure(r):
    """The refusal reason of a run, or ``None``."""
    if r.status == "overturned":
        return "overturn"
    if r.status == "rest":
        return "rest"
    if r.status == "max_impacts":
        return "max_impacts"
    if r.status != "done" or not np.all(np.isfinite(r.state)):
        return "nonfinite"
    if r.n_rest > 0:
        return "passes_through_rest"
    return None


class _Eval:
    """One evaluation of the shooting residual at ``(x, lambda)``."""

    __slots__ = ("ok", "reason", "F", "M", "r", "x", "lam", "nimp")

    def __init__(self, ok, reason=None, F=None, M=None, r=None, x=None, lam=None):
        self.ok = ok
        self.reason = reason
        self.F = F
        self.M = M
        self.r = r
        self.x = x
        self.lam = lam
        self.nimp = r.n_impacts if r is not None else -1


class _Info:
    """What is known about a converged orbit (from its tangent run over one cycle)."""

    __slots__ = ("M", "mu", "stable", "nimp", "cycle", "half", "scale", "sym_defect",
                 "symmetric", "max_theta", "min_speed", "near_miss", "t_next", "t_next_half",
                 "traj", "imp_o", "T", "psi", "run")


# ---------------------------------------------------------------------------------------------
# the solver: residuals, Newton, analysis of an orbit
# ---------------------------------------------------------------------------------------------

class _Solver:
    """Shooting residuals (full and half map), Newton's method, and what a converged run says
    about its orbit."""

    def __init__(self, flow, *, tol=1e-12, sym_tol=1e-6, fd_rel=1e-7):
        self.flow = flow
        self.N = flow.N
        self.tol = tol
        self.sym_tol = sym_tol
        self.fd = fd_rel

    def tol_for(self, ev):
        """Newton's tolerance at an evaluation: ``tol`` times ``max(1, |M|)`` (the round-off
        in ``P^p(x)`` grows with the orbit's expansion)."""
        if ev.M is None:
            return self.tol
        return self.tol * max(1.0, float(np.abs(ev.M).sum(axis=1).max()))

    # -- residuals ----------------------------------------------------------------------------
    def full(self, x, lam, p, j):
        """``F = P^p(x) - x`` with the exact ``M`` (tangent run over ``p`` periods)."""
        r = self.flow.run(x, lam, p, j, True)
        why = _failure(r)
        if why:
            return _Eval(False, why, r=r)
        return _Eval(True, F=r.strobe[p, :2] - x, M=r.extra["tangent"], r=r, x=x, lam=lam)

    def sym(self, x, lam, p, j):
        """``F = x + Phi_{pT/2}(x)``, the half map's residual (``p`` odd)."""
        m = (p - 1) // 2
        r = self.flow.run(x, lam, m + 1, j, False)
        why = _failure(r)
        if why:
            return _Eval(False, why, r=r)
        return _Eval(True, F=x + r.strobe_half[m, :2], r=r, x=x, lam=lam)

    def residual(self, form, x, lam, p, j):
        return self.full(x, lam, p, j) if form == "full" else self.sym(x, lam, p, j)

    def jac_x(self, form, ev, p, j):
        """``dF/dx``: exact for the full form, forward differences for the half map."""
        if form == "full":
            return ev.M - np.eye(2)
        J = np.empty((2, 2))
        for i in range(2):
            h = self.fd * max(1.0, abs(ev.x[i]))
            xe = ev.x.copy()
            xe[i] += h
            e2 = self.sym(xe, ev.lam, p, j)
            if not e2.ok:
                return None
            J[:, i] = (e2.F - ev.F) / h
        return J

    def jac_lam(self, form, ev, p, j):
        h = self.fd * max(1.0, abs(ev.lam))
        e2 = self.residual(form, ev.x, ev.lam + h, p, j)
        if not e2.ok:
            return None
        return (e2.F - ev.F) / h

    # -- the corrector: Newton on [F(y); n.(y - y0)] ------------------------------------------
    def correct(self, y0, n, form, p, j, max_iter=8):
        """Newton from ``y0`` on ``F(y) = 0`` and ``n . (y - y0) = 0``.

        Returns ``(ok, y, eval, iterations, reason)``; ``eval`` is the full-form evaluation at
        the returned point when ``form == "full"``.
        """
        y = np.array(y0, float)
        c = float(n @ y0)
        Jl = None
        reason = "no_convergence"
        prev = math.inf
        for it in range(max_iter):
            if not self.flow.valid(y[2]) or not np.all(np.isfinite(y)):
                return False, y, None, it, "no_convergence"
            ev = self.residual(form, y[:2], y[2], p, j)
            if not ev.ok:
                return False, y, ev, it, ev.reason
            g = float(n @ y) - c
            res = max(float(np.abs(ev.F).max()), abs(g))
            tol = self.tol_for(ev)
            if res <= tol:
                return True, y, ev, it, None
            if it >= 3 and res > 0.5 * prev:
                if res <= 10 * tol:  # round-off floor
                    return True, y, ev, it, None
                break
            prev = res
            Jx = self.jac_x(form, ev, p, j)
            if Jl is None:
                Jl = self.jac_lam(form, ev, p, j)
            if Jx is None or Jl is None:
                return False, y, ev, it, "grazing"
            A = np.empty((3, 3))
            A[:2, :2] = Jx
            A[:2, 2] = Jl
            A[2] = n
            try:
                dy = np.linalg.solve(A, -np.r_[ev.F, g])
            except np.linalg.LinAlgError:
                return False, y, ev, it, "singular"
            if not np.all(np.isfinite(dy)):
                return False, y, ev, it, "singular"
            y = y + dy
        return False, y, None, max_iter, reason

    # -- natural-parameter Newton (shooting) --------------------------------------------------
    def newton(self, x, lam, p, j, scale, max_iter=40, near=1e-6):
        """Damped Newton on ``P^p(x) = x`` at fixed ``lambda``; returns ``(ev, iterations)``.

        Raises :class:`OrbitRefused`.
        """
        ev = self.full(x, lam, p, j)
        if not ev.ok:
            raise OrbitRefused(ev.reason, "at the seed")
        res = float(np.abs(ev.F).max())
        I2 = np.eye(2)
        for it in range(max_iter):
            if res <= self.tol_for(ev):
                return ev, it
            try:
                dx = -np.linalg.solve(ev.M - I2, ev.F)
            except np.linalg.LinAlgError:
                raise OrbitRefused("singular", f"M - I at residual {res:.3g}") from None
            big = float(np.abs(dx).max())
            cap = 0.5 * scale
            if big > cap:
                dx *= cap / big
            step = 1.0
            for _ in range(12):
                et = self.full(ev.x + step * dx, lam, p, j)
                if et.ok:
                    rt = float(np.abs(et.F).max())
                    if rt < (1.0 - 1e-4 * step) * res:
                        break
                step *= 0.5
            else:
                if res <= 10 * self.tol_for(ev):  # round-off floor
                    return ev, it
                raise OrbitRefused("no_convergence",
                                   f"no decrease of |F| = {res:.3g} after {it} iterations")
            if rt < near * scale and et.nimp != ev.nimp:
                raise OrbitRefused("grazing", "the impact count changes between Newton "
                                              f"iterates near the solution ({ev.nimp} -> "
                                              f"{et.nimp})")
            ev, res = et, rt
        if res <= self.tol_for(ev):
            return ev, max_iter
        raise OrbitRefused("no_convergence", f"|F| = {res:.3g} after {max_iter} iterations")

    def polish(self, ev, lam, p, j, steps=2):
        """Newton steps beyond the tolerance while they reduce ``|F|`` (down to round-off)."""
        res = float(np.abs(ev.F).max())
        for _ in range(steps):
            if res == 0.0:
                break
            try:
                dx = -np.linalg.solve(ev.M - np.eye(2), ev.F)
            except np.linalg.LinAlgError:
                break
            et = self.full(ev.x + dx, lam, p, j)
            if not et.ok or et.nimp != ev.nimp:
                break
            rt = float(np.abs(et.F).max())
            if rt >= 0.5 * res:
                if rt < res:
                    ev = et
                break
            ev, res = et, rt
        return ev

    # -- analysis of a converged orbit --------------------------------------------------------
    def analyse(self, r, lam, p, j):
        """Multipliers, the cycle at the output phase, symmetry and grazing margins."""
        N = self.N
        pN = p * N
        T = self.flow.period(lam)
        info = _Info()
        info.run = r
        info.T = T
        traj = r.trajectory[:, 1:3]
        # output-phase samples: output time kT is step kN - j of the computational run
        ks = (N * np.arange(p) - j) % pN
        info.cycle = traj[ks].copy()
        info.half = traj[(ks + N // 2) % pN].copy()
        info.scale = max(float(np.abs(info.cycle).max()), float(np.abs(info.half).max()),
                         1e-12)
        M = r.extra["tangent"].copy()
        info.M = M
        info.mu = _sorted_mult(M)
        info.stable = bool(np.abs(info.mu).max() < 1.0)
        info.nimp = int(r.n_impacts)
        det = float(np.linalg.det(M))
        tr = float(np.trace(M))
        info.psi = (det - tr + 1.0, det + tr + 1.0, det - 1.0, tr * tr - 4.0 * det)
        if p % 2:
            m = (p - 1) // 2
            dd = info.cycle + info.half[(np.arange(p) + m) % p]
            info.sym_defect = float(np.abs(dd).max()) / info.scale
        else:
            info.sym_defect = math.inf
        info.symmetric = info.sym_defect <= self.sym_tol
        th = traj[:, 0]
        info.max_theta = float(np.abs(th).max())
        vmax = max(float(np.abs(traj[:, 1]).max()), 1e-300)
        imp = r.impacts
        info.min_speed = float(np.abs(imp[:, 1]).min()) / vmax if imp.shape[0] else math.inf
        # turning points of |theta| without an impact (a near miss of theta = 0)
        a = np.abs(th)
        mid = a[1:-1]
        lo = (mid <= a[:-2]) & (mid <= a[2:]) & (th[:-2] * th[1:-1] > 0) & \
             (th[1:-1] * th[2:] > 0)
        nm = math.inf
        if lo.any():
            k = np.nonzero(lo)[0] + 1
            den = a[k + 1] - 2 * a[k] + a[k - 1]
            fit = np.where(den > 0, a[k] - (a[k + 1] - a[k - 1]) ** 2 / (8 * np.where(
                den > 0, den, 1.0)), a[k])
            nm = float(max(fit.min(), 0.0)) / max(info.max_theta, 1e-300)
        info.near_miss = nm
        h = T / N
        imp_o = (imp[:, 0] + j * h) % (p * T) if imp.shape[0] else np.zeros(0)
        info.imp_o = imp_o
        if imp_o.size:
            kt = T * np.arange(p)
            info.t_next = ((imp_o[None, :] - kt[:, None]) % (p * T)).min(axis=1)
            info.t_next_half = ((imp_o[None, :] - kt[:, None] - 0.5 * T) % (p * T)).min(axis=1)
        else:
            info.t_next = np.full(p, math.nan)
            info.t_next_half = np.full(p, math.nan)
        info.traj = traj
        return info

    # -- sections -----------------------------------------------------------------------------
    def margins(self, info, j):
        """``(margin at section j, best section, its margin)``, margins in units of T."""
        return self.margins_of(info.imp_o, info.T, j)

    def margins_of(self, imp_o, T, j):
        """As :meth:`margins`, from impact times after the output section."""
        if imp_o.size == 0:
            return 0.5, j, 0.5
        ph = np.sort(imp_o % T) / T
        gaps = np.diff(np.r_[ph, ph[0] + 1.0])
        i = int(np.argmax(gaps))
        best = int(round((ph[i] + 0.5 * gaps[i]) * self.N)) % self.N

        def margin(jj):
            s = jj / self.N
            return float(np.abs((ph - s + 0.5) % 1.0 - 0.5).min())

        return margin(j), best, margin(best)

    @staticmethod
    def shifted(info, delta):
        """The state ``delta`` grid steps after the section (from the recorded trajectory)."""
        return info.traj[delta].copy()

    def defect(self, info, p, delta=0):
        """The vector that vanishes at a branch point: ``x(0) -+ x(pT/2)`` at section + delta."""
        pN = p * self.N
        a = info.traj[delta % pN]
        b = info.traj[(delta + pN // 2) % pN]
        return a - b if p % 2 == 0 else a + b


def _orbit_from(info, solver, x, lam, p, j, ev_res, iters, phase, block):
    flow = solver.flow
    alpha, omega = flow.params(lam)
    return PeriodicOrbit(
        state=info.cycle[0].copy(), period=p, alpha=alpha, omega=omega, phase=phase,
        residual=ev_res, multipliers=info.mu, stable=info.stable, impacts=info.nimp,
        symmetric=info.symmetric, cycle=info.cycle, cycle_half=info.half, iterations=iters,
        monodromy=info.M, section_phase=phase + _TWO_PI * j / solver.N, n_steps=solver.N,
        max_theta=info.max_theta, min_impact_speed=info.min_speed, n_simulate=flow.calls,
        block=Block(**{**_block_kw(block), "alpha": alpha, "omega": omega}))


def _block_kw(block):
    kw = dict(hb=block.hb, alpha=block.alpha, omega=block.omega, law=block.law, xi=block.xi,
              theta_over=block.theta_over, rest_speed=block.rest_speed)
    if block.law == "constant":
        kw["e"] = block.e
    return kw


def _shoot(solver, x0, lam, p, refuse_grazing=True, graze_tol=1e-4, over_tol=1e-3,
           max_iter=40):
    """Shooting from ``x0`` at the output phase; returns ``(info, x, j, residual, iters)``."""
    flow = solver.flow
    ev = solver.full(x0, lam, p, 0)
    if not ev.ok:
        raise OrbitRefused(ev.reason, "at the seed")
    j = 0
    traj = ev.r.trajectory[:, 1:3]
    scale = max(float(np.abs(traj).max()), 1e-12)
    cur, best, mbest = solver.margins_of(ev.r.impacts[:, 0], flow.period(lam), 0)
    x = x0
    if cur < 0.3 * mbest:
        j = best
        x = traj[best].copy()
    ev, iters = solver.newton(x, lam, p, j, scale, max_iter=max_iter)
    done = False
    if j != 0:
        # the point at the requested phase, polished there: carried from the computational
        # section along an expanding orbit the residual grows; Newton steps this small cannot
        # cross an impact unless one sits at that very instant
        x_o = ev.r.trajectory[(-j) % (p * solver.N), 1:3].copy()
        eo = solver.full(x_o, lam, p, 0)
        if eo.ok and eo.nimp == ev.nimp:
            eo = solver.polish(eo, lam, p, 0)
            if float(np.abs(eo.F).max()) <= max(10 * float(np.abs(ev.F).max()),
                                                solver.tol_for(eo)):
                ev, j, done = eo, 0, True
    if not done:
        ev = solver.polish(ev, lam, p, j)
    info = solver.analyse(ev.r, lam, p, j)
    res = float(np.abs(ev.F).max())
    if refuse_grazing:
        blk = flow.block
        if info.min_speed < graze_tol:
            raise OrbitRefused("grazing", f"an impact with |theta'-| = {info.min_speed:.3g} "
                                          "of the orbit's largest |theta'|")
        if info.near_miss < graze_tol:
            raise OrbitRefused("grazing", f"|theta| turns at {info.near_miss:.3g} of its "
                                          "largest value without impact")
        if info.max_theta >= blk.theta_over * (1.0 - over_tol):
            raise OrbitRefused("grazing", f"max |theta| = {info.max_theta:.6g} touches "
                                          f"theta_over = {blk.theta_over:.6g}")
    return info, ev.x.copy(), j, res, iters


def periodic_orbit(block_or_params, x0, p=1, *, phase=0.0, n_steps=N_ORBIT, tol=1e-12,
                   max_iter=40, graze_tol=1e-4, over_tol=1e-3, sym_tol=1e-6,
                   max_impacts_per_period=1000) -> PeriodicOrbit:
    """A period-``p`` orbit of the stroboscopic map by Newton's method (shooting).

    Parameters
    ----------
    block_or_params : Block or dict
        The block (``alpha`` and ``omega`` included), or the keyword arguments of
        :class:`rockjit.Block`.
    x0 : array_like, shape (2,) or (p, 2)
        Seed ``(theta, theta')`` at ``t = 0`` (a settled sweep cell, or any guess); of a cycle
        the first point is used.
    p : int
        Period in forcing periods, ``>= 1``.
    phase : float
        Forcing phase of the section, ``r = sin(omega t + phase)``; default 0, i.e.
        ``(r0, s0) = (0, 1)``.
    n_steps : int
        Steps per period (even, ``>= 8``), default :data:`N_ORBIT`.
    tol : float
        Convergence: ``max|P^p(x) - x| <= tol``.
    max_iter : int
        Newton iterations allowed.
    graze_tol, over_tol : float
        Grazing thresholds (module docstring, "Refusals").
    sym_tol : float
        Symmetry test, relative to the orbit's size.
    max_impacts_per_period : int
        Impact bound of each run, per period.

    Returns
    -------
    PeriodicOrbit

    Raises
    ------
    OrbitRefused
        With ``reason`` in ``overturn, rest, passes_through_rest, max_impacts, grazing,
        no_convergence, singular, nonfinite``.
    ValueError
        For bad input, naming the parameter.

    Notes
    -----
    The Jacobian ``M - I`` is exact: ``M`` is the tangent matrix of the run, with the saltation
    matrix (Müller 1995; di Bernardo et al. 2008, §2.5) at every impact. Newton's method for
    periodic orbits by shooting: Seydel (2010), §7.3.
    """
    block = _as_block(block_or_params)
    p = integer("p", p, 1, 256)
    x0 = _state("x0", x0, p)
    phase = real("phase", phase)
    n_steps = integer("n_steps", n_steps, 8)
    if n_steps % 2:
        raise ValueError(f"n_steps must be even (got {n_steps})")
    tol = real("tol", tol, 0.0, None, lo_open=True)
    max_iter = integer("max_iter", max_iter, 1)
    graze_tol = real("graze_tol", graze_tol)
    over_tol = real("over_tol", over_tol)
    if not 0 <= graze_tol < 1:
        raise ValueError(f"graze_tol must be in [0, 1) (got {graze_tol})")
    if not 0 <= over_tol < 1:
        raise ValueError(f"over_tol must be in [0, 1) (got {over_tol})")
    sym_tol = real("sym_tol", sym_tol, 0.0, None, lo_open=True)
    imp = integer("max_impacts_per_period", max_impacts_per_period, 1)
    flow = _Flow(block, "alpha", n_steps, phase, imp)
    solver = _Solver(flow, tol=tol, sym_tol=sym_tol)
    info, x, j, res, iters = _shoot(solver, x0, block.alpha, p, True, graze_tol, over_tol,
                                    max_iter)
    return _orbit_from(info, solver, x, block.alpha, p, j, res, iters, phase, block)


# ---------------------------------------------------------------------------------------------
# continuation
# ---------------------------------------------------------------------------------------------

def _cycle_distance(a, b):
    """``min over cyclic shifts s of max|a - roll(b, s)|`` for cycles of shape (p, 2)."""
    best = math.inf
    for s in range(b.shape[0]):
        best = min(best, float(np.abs(a - np.roll(b, s, axis=0)).max()))
    return best


class _LocateFailed(Exception):
    pass


def _unit(v):
    n = float(np.linalg.norm(v))
    return v / n if n > 0 else v


@dataclass
class _CPoint:
    y: np.ndarray     # (theta, theta', lambda) at section j
    j: int            # the section the continuation works on at this point
    jt: int           # the section its recorded trajectory starts from
    info: _Info
    iters: int = 0


class _Continuer:
    """Follows branches from seeds, locates bifurcations, switches branches."""

    def __init__(self, solver, bounds, *, ds0, ds_min, ds_max, max_points, max_period, switch,
                 join_tol, max_calls, graze_tol, param_tol):
        self.s = solver
        self.flow = solver.flow
        self.N = solver.N
        self.lo, self.hi = bounds
        self.ds0, self.ds_min, self.ds_max = ds0, ds_min, ds_max
        self.max_points = max_points
        self.max_period = max_period
        self.switching = switch
        self.join_tol = join_tol
        self.max_calls = max_calls
        self.graze_tol = graze_tol
        self.param_tol = param_tol
        self.end_graze = 1e-3
        self.branches = []
        self.bifs = []
        self.seeds_tried = 0

    # -- points -------------------------------------------------------------------------------
    def point(self, y, j, form, p, ev):
        """A branch point from a converged corrector (one more tangent run for the half map)."""
        if form == "full":
            r = ev.r
        else:
            r = self.flow.run(y[:2], y[2], p, j, True)
            if _failure(r):
                return None
        return _CPoint(np.array(y, float), j, j, self.s.analyse(r, y[2], p, j))

    def defect(self, P, p, j):
        return self.s.defect(P.info, p, (j - P.jt) % self.N)

    def tangent(self, P, form, p):
        """The branch's unit tangent at ``P`` (null vector of ``[F_x F_lambda]``)."""
        ev = self.s.residual(form, P.y[:2], P.y[2], p, P.j)
        if not ev.ok:
            return None
        Jx = self.s.jac_x(form, ev, p, P.j)
        Jl = self.s.jac_lam(form, ev, p, P.j)
        if Jx is None or Jl is None:
            return None
        t = np.cross(np.r_[Jx[0], Jl[0]], np.r_[Jx[1], Jl[1]])
        if not np.all(np.isfinite(t)) or np.linalg.norm(t) == 0:
            return None
        t = _unit(t)
        return t if t[2] >= 0 else -t

    # -- known branches -----------------------------------------------------------------------
    def known(self, info, lam, p, symmetric, tol=None):
        """Index of a finished branch (or its mirror) through this orbit, else ``None``."""
        return self.known_cycle(info.cycle, info.scale, lam, p, symmetric,
                                self.join_tol if tol is None else tol)

    def known_cycle(self, cycle, scale, lam, p, symmetric, tol):
        """As :meth:`known` for a bare cycle; ``symmetric=None`` matches either kind."""
        tol = tol * scale
        for bi, br in enumerate(self.branches):
            if br.period != p or (symmetric is not None and br.symmetric != symmetric):
                continue
            v = br.value
            ks = np.nonzero((v[:-1] - lam) * (v[1:] - lam) <= 0)[0]
            cycles = (br.cycle,) if br.symmetric else (br.cycle, br.mirror_cycle)
            n = v.shape[0]
            for k in ks:
                # interpolation within the segment, and extrapolation from the segments on
                # either side (the sampled point jumps where an impact crosses t = 0)
                for i0, i1 in ((k, k + 1), (k - 1, k), (k + 1, k + 2)):
                    if i0 < 0 or i1 >= n:
                        continue
                    dv = v[i1] - v[i0]
                    w = (lam - v[i0]) / dv if dv != 0 else 0.5
                    for cyc in cycles:
                        ci = (1 - w) * cyc[i0] + w * cyc[i1]
                        if _cycle_distance(ci, cycle) <= tol:
                            return bi
        return None

    # -- one direction ------------------------------------------------------------------------
    def march(self, start, t, form, p, bifs, requests):
        """Follow the branch from ``start`` along ``t``; returns ``(points, end reason)``."""
        s = self.s
        pts = []
        a = _CPoint(start.y.copy(), start.j, start.jt, start.info)
        ds = self.ds0
        t = _unit(np.asarray(t, float))
        e_lam = np.array([0.0, 0.0, 1.0])
        fail_ds = None
        why = None
        while True:
            if len(pts) >= self.max_points:
                return pts, "max_points"
            if self.flow.calls > self.max_calls:
                return pts, "budget"
            y_pred = a.y + ds * t
            n = t
            at_end = False
            if not self.lo <= y_pred[2] <= self.hi and abs(t[2]) > 1e-12:
                bound = self.hi if y_pred[2] > self.hi else self.lo
                sb = (bound - a.y[2]) / t[2]
                if 0 <= sb <= ds:
                    y_pred = a.y + sb * t
                    y_pred[2] = bound
                    n = e_lam
                    at_end = True
            ok, y, ev, iters, why = s.correct(y_pred, n, form, p, a.j)
            b = self.point(y, a.j, form, p, ev) if ok else None
            if b is None:
                why = why or "passes_through_rest"
                fail_ds = ds
                ds *= 0.5
                if ds < self.ds_min:
                    if why in ("overturn", "rest", "passes_through_rest", "max_impacts"):
                        last = self.locate_end(a, t, fail_ds, form, p, why, bifs)
                        if last is not None:
                            pts.append(last)
                    elif min(a.info.near_miss, a.info.min_speed) < self.end_graze:
                        # the corrector fails next to a grazing (the map's derivative is
                        # singular there): follow the orbit to where it ends
                        last = self.graze_at(a, t, p, bifs)
                        if last is not None:
                            pts.append(last)
                        return pts, "grazing"
                    return pts, why
                continue
            b.iters = iters
            if b.info.nimp != a.info.nimp:
                last = self.locate_grazing(a, b, form, p, bifs)
                if last is not None:
                    pts.append(last)
                return pts, "grazing"
            if form == "full":
                # a doubled (or asymmetric) branch folding back onto its parent orbit
                da = self.defect(a, p, a.j)
                db = self.defect(b, p, a.j)
                if float(da @ db) < 0 or float(np.abs(db).max()) <= \
                        10 * s.sym_tol * b.info.scale:
                    return pts, "branch_point"
            joined = self.known(b.info, b.y[2], p, form == "sym")
            self.detect(a, b, form, p, bifs, requests)
            pts.append(b)
            if joined is not None:
                return pts, "joins"
            if at_end:
                return pts, "range"
            if len(pts) > 10 and abs(b.y[2] - start.y[2]) < ds and _cycle_distance(
                    b.info.cycle, start.info.cycle) <= self.join_tol * b.info.scale:
                return pts, "closed"
            if iters <= 3:
                ds = min(1.3 * ds, self.ds_max)
            # the section: move it when an impact comes near the sampling instant
            cur, best, mbest = s.margins(b.info, b.j)
            if cur < 0.3 * mbest:
                for P in (a, b):
                    P.y[:2] = s.shifted(P.info, (best - P.jt) % self.N)
                    P.j = best
            sec = b.y - a.y
            if np.linalg.norm(sec) > 0:
                t = _unit(sec)
            if a.info is not start.info:
                a.info.traj = None  # keep memory bounded: only the last two are needed
                a.info.run = None
            a = b

    # -- bifurcations between two branch points -----------------------------------------------
    def detect(self, a, b, form, p, bifs, requests):
        pa, pb = a.info.psi, b.info.psi
        if pa[0] * pb[0] < 0:
            self.locate(a, b, 0, form, p, bifs, requests)
        if pa[1] * pb[1] < 0:
            self.locate(a, b, 1, form, p, bifs, requests)
        if pa[2] * pb[2] < 0 and (pa[3] < 0 or pb[3] < 0):
            self.locate(a, b, 2, form, p, bifs, requests)

    def _chord_point(self, a, c, n, sv, form, p):
        ok, y, ev, _, why = self.s.correct(a.y + sv * c, n, form, p, a.j)
        P = self.point(y, a.j, form, p, ev) if ok else None
        if P is None:
            raise _LocateFailed(why or "passes_through_rest")
        return P

    def locate(self, a, b, idx, form, p, bifs, requests):
        """Brent's method on test function ``psi[idx]`` along the chord from a to b."""
        from scipy.optimize import brentq
        calls0 = self.flow.calls
        c = b.y - a.y
        n = _unit(c)
        cache = {0.0: a, 1.0: b}

        def P(sv):
            if sv not in cache:
                cache[sv] = self._chord_point(a, c, n, sv, form, p)
            return cache[sv]

        located = True
        xtol = min(1e-6, max(1e-13, 0.1 * self.param_tol / max(abs(c[2]), 1e-300)))
        try:
            sv = brentq(lambda u: P(u).info.psi[idx], 0.0, 1.0, xtol=xtol, maxiter=100)
            Q = P(sv)
            detail = ""
        except (_LocateFailed, RuntimeError, ValueError) as exc:
            located = False
            fa, fb = a.info.psi[idx], b.info.psi[idx]
            sv = fa / (fa - fb)
            try:
                Q = P(sv)
            except _LocateFailed:
                Q = a if abs(fa) < abs(fb) else b
            detail = f"bracketing solve failed ({exc}); interpolated"
        if idx == 0:
            kind = "fold"
            if form == "sym":
                # M = A^2 with A the half map's Jacobian: A's eigenvalue -1 breaks the symmetry,
                # +1 is a fold of symmetric orbits, where det(I - A) = det(dF_half/dx) changes
                # sign too
                ja = self._half_det(a, p)
                jb = self._half_det(b, p)
                kind = "fold" if (ja is not None and jb is not None and ja * jb < 0) \
                    else "symmetry_breaking"
        elif idx == 1:
            kind = "period_doubling"
        else:
            if Q.info.psi[3] >= 0:
                return  # a neutral saddle (real mu1 mu2 = 1), no bifurcation
            kind = "neimark_sacker"
        lam = float(Q.y[2])
        alpha, omega = self.flow.params(lam)
        bif = Bifurcation(
            type=kind, parameter=self.flow.parameter, value=lam, alpha=alpha, omega=omega,
            period=p, multipliers=Q.info.mu.copy(), state=Q.info.cycle[0].copy(),
            cycle=Q.info.cycle.copy(), cycle_half=Q.info.half.copy(), branch=-1,
            neighbours=(float(a.y[2]), float(b.y[2])),
            neighbour_multipliers=np.array([a.info.mu, b.info.mu]), located=located,
            n_simulate=0, detail=detail, has_mirror=not Q.info.symmetric)
        bif.n_simulate = self.flow.calls - calls0
        bifs.append(bif)
        if self.switching and kind in ("period_doubling", "symmetry_breaking"):
            requests.append((bif, Q, p))

    def _half_det(self, P, p):
        ev = self.s.sym(P.y[:2], P.y[2], p, P.j)
        if not ev.ok:
            return None
        J = self.s.jac_x("sym", ev, p, P.j)
        return None if J is None else float(np.linalg.det(J))

    def _graze_bif(self, P, a_lam, b_lam, mu_a, mu_b, p, detail, calls0):
        lam = float(P.y[2])
        alpha, omega = self.flow.params(lam)
        return Bifurcation(
            type="grazing", parameter=self.flow.parameter, value=lam, alpha=alpha, omega=omega,
            period=p, multipliers=P.info.mu.copy(), state=P.info.cycle[0].copy(),
            cycle=P.info.cycle.copy(), cycle_half=P.info.half.copy(), branch=-1,
            neighbours=(float(a_lam), float(b_lam)),
            neighbour_multipliers=np.array([mu_a, mu_b]), located=True,
            n_simulate=self.flow.calls - calls0, detail=detail,
            has_mirror=not P.info.symmetric)

    def _bisect(self, a, c, form, p, same_side):
        """Bisection along ``a.y + s c``, s in [0, 1], ``same_side(point or None)``."""
        n = _unit(c)
        lo, hi, Plo = 0.0, 1.0, a
        Phi = None
        for _ in range(60):
            if (hi - lo) * abs(c[2]) <= 0.1 * self.param_tol and hi - lo < 1e-3:
                break
            sv = 0.5 * (lo + hi)
            try:
                Q = self._chord_point(a, c, n, sv, form, p)
            except _LocateFailed:
                Q = None
            if Q is not None and same_side(Q):
                lo, Plo = sv, Q
            else:
                hi, Phi = sv, Q
        return Plo, Phi, (hi - lo) * abs(c[2])

    def refine_edge(self, P, direction, p):
        """Where the orbit through ``P`` (with its impact count) stops existing, towards
        ``direction`` (+-1) in the parameter: damped Newton at fixed parameter values, doubling
        the distance from ``P`` until it fails, then bisection to ``param_tol / 10``.

        Near a grazing the corrector's undamped steps fail some ``1e-8`` short of it; the
        damped Newton with the impact-count guard gets within ``1e-9`` (measured on the hb=1
        Housner case). Returns ``(point, bracket width)``; ``(P, inf)`` if no end is found
        within ``1e-3``.
        """
        s = self.s
        if direction == 0:
            return P, math.inf

        def trial(lam, x):
            if not self.flow.valid(lam):
                return None
            try:
                ev, _ = s.newton(x, lam, p, P.j, P.info.scale, max_iter=20)
            except OrbitRefused:
                return None
            return ev if ev.nimp == P.info.nimp else None

        lo, ev_lo, hi = float(P.y[2]), None, None
        d = self.param_tol
        while d <= 1e-3:
            lam = lo + direction * d
            ev = trial(lam, P.y[:2] if ev_lo is None else ev_lo.x)
            if ev is None:
                hi = lam
                break
            lo, ev_lo = lam, ev
            d *= 2.0
        if hi is None:
            return P, math.inf
        while abs(hi - lo) > 0.1 * self.param_tol:
            mid = 0.5 * (lo + hi)
            ev = trial(mid, P.y[:2] if ev_lo is None else ev_lo.x)
            if ev is None:
                hi = mid
            else:
                lo, ev_lo = mid, ev
        if ev_lo is None:
            return P, abs(hi - lo)
        info = s.analyse(ev_lo.r, lo, p, P.j)
        return _CPoint(np.r_[ev_lo.x, lo], P.j, P.j, info), abs(hi - lo)

    def locate_grazing(self, a, b, form, p, bifs):
        """The impact count changes between a and b: bisection on the count."""
        calls0 = self.flow.calls
        Plo, Phi, width = self._bisect(a, b.y - a.y, form, p,
                                       lambda Q: Q.info.nimp == a.info.nimp)
        Q, w2 = self.refine_edge(Plo, np.sign(b.y[2] - a.y[2]), p)
        if w2 < math.inf:
            Plo, width = Q, w2
        if Plo is a:
            Plo = None
        P = Plo if Plo is not None else a
        ms = P.info.min_speed
        kind = (f"an impact with |theta'-| -> 0 (now {ms:.2g} of max |theta'|)"
                if a.info.nimp > b.info.nimp else
                f"|theta| touches 0 without impact (now {P.info.near_miss:.2g} of max |theta|)")
        detail = (f"impacts per cycle {a.info.nimp} -> {b.info.nimp}: {kind}; bracket "
                  f"{width:.1g} wide")
        bifs.append(self._graze_bif(P, a.y[2], b.y[2], a.info.mu, b.info.mu, p, detail,
                                    calls0))
        return Plo

    def graze_at(self, a, t, p, bifs):
        """The corrector fails next to a grazing: the orbit is followed to where it ends."""
        calls0 = self.flow.calls
        nm, ms = a.info.near_miss, a.info.min_speed
        what = (f"|theta| turns back short of 0 without impact (by {nm:.2g} of its largest "
                "value at the last point continued)" if nm <= ms else
                f"an impact with |theta'-| -> 0 ({ms:.2g} of the largest |theta'| at the last "
                "point continued)")
        Q, width = self.refine_edge(a, np.sign(t[2]), p)
        detail = f"{what}; located to a bracket {width:.1g} wide"
        mu_b = np.full(2, np.nan, complex)
        bifs.append(self._graze_bif(Q, a.y[2], Q.y[2] + np.sign(t[2]) * width, a.info.mu,
                                    mu_b, p, detail, calls0))
        return None if Q is a else Q

    def locate_end(self, a, t, ds_fail, form, p, why, bifs):
        """The branch ends by overturning or rest: bisection on where it stops existing."""
        calls0 = self.flow.calls
        Plo, Phi, width = self._bisect(a, ds_fail * t, form, p, lambda Q: True)
        Q, w2 = self.refine_edge(Plo, np.sign(t[2]), p)
        if w2 < math.inf:
            Plo, width = Q, w2
        P = a if Plo is a else Plo
        what = {"overturn": "max |theta| reaches theta_over (the orbit overturns)",
                "rest": "the orbit comes to rest",
                "passes_through_rest": "the orbit enters a rest phase (impact speeds -> 0)",
                "max_impacts": "impacts accumulate (impact bound)"}[why]
        detail = f"{what}; bracket {width:.1g} wide"
        mu_b = np.full(2, np.nan, complex)
        bifs.append(self._graze_bif(P, a.y[2], a.y[2] + ds_fail * t[2], a.info.mu, mu_b, p,
                                    detail, calls0))
        return None if Plo is a else Plo

    # -- branches -----------------------------------------------------------------------------
    def finish(self, pts, ends, form, p, origin, parent, bifs):
        v = np.array([P.y[2] for P in pts])
        al, om = np.array([self.flow.params(x) for x in v]).T.reshape(2, -1)
        br = Branch(
            parameter=self.flow.parameter, period=p, symmetric=form == "sym", value=v,
            alpha=al, omega=om, cycle=np.array([P.info.cycle for P in pts]),
            cycle_half=np.array([P.info.half for P in pts]),
            multipliers=np.array([P.info.mu for P in pts]),
            stable=np.array([P.info.stable for P in pts]),
            impacts=np.array([P.info.nimp for P in pts], np.int64),
            symmetric_points=np.array([P.info.symmetric for P in pts]),
            t_next_impact=np.array([P.info.t_next for P in pts]),
            t_next_impact_half=np.array([P.info.t_next_half for P in pts]), ends=tuple(ends),
            origin=origin, parent=parent)
        idx = len(self.branches)
        self.branches.append(br)
        for bf in bifs:
            bf.branch = idx
            self.bifs.append(bf)
        return idx

    def follow_seed(self, lam, x, p, origin):
        """Solve a seed; if it is new, follow its branch both ways. Returns the branch index."""
        self.seeds_tried += 1
        if not self.lo <= lam <= self.hi:
            return None
        x = np.asarray(x, float)
        if x.ndim == 2:
            # a sweep's cycle: a cheap look first, at a tolerance loose enough for its grid
            if self.known_cycle(x, max(float(np.abs(x).max()), 1e-12), lam, p, None,
                                10 * self.join_tol) is not None:
                return None
            x = x[0]
        try:
            info, xc, j, _, _ = _shoot(self.s, x, lam, p, refuse_grazing=True,
                                       graze_tol=self.graze_tol)
        except OrbitRefused:
            return None
        if p % 2 == 0 and float(np.abs(self.s.defect(info, p, 0)).max()) <= \
                10 * self.s.sym_tol * info.scale:
            return self.follow_seed(lam, info.cycle[0], p // 2, origin)
        sym = bool(info.symmetric)
        if self.known(info, lam, p, sym) is not None:
            return None
        form = "sym" if sym else "full"
        start = _CPoint(np.r_[xc, lam], j, j, info)
        t = self.tangent(start, form, p)
        if t is None:
            return None
        bifs, requests = [], []
        plus, end_p = self.march(start, t, form, p, bifs, requests)
        if end_p == "closed":
            minus, end_m = [], "closed"
        else:
            minus, end_m = self.march(start, -t, form, p, bifs, requests)
        pts = minus[::-1] + [start] + plus
        idx = self.finish(pts, (end_m, end_p), form, p, origin, None, bifs)
        self.run_requests(requests, idx)
        # a seeded branch that folds back onto the orbit it was born from: follow that one too
        for end, P in ((end_m, pts[0]), (end_p, pts[-1])):
            if end == "branch_point":
                self.parent_seed(P, p, idx)
        return idx

    def parent_seed(self, P, p, idx):
        """Seed the orbit a branch point leads to: the symmetric one (odd ``p``) or the one of
        half the period (even ``p``), from the symmetrised (averaged) end point."""
        c, h = P.info.cycle, P.info.half
        if p % 2:
            x, pp = 0.5 * (c[0] - h[(p - 1) // 2]), p
        else:
            x, pp = 0.5 * (c[0] + c[p // 2]), p // 2
        lam = float(P.y[2])
        self.follow_seed(lam, x, pp, f"parent of branch {idx} (branch point at "
                                     f"{self.flow.parameter} = {lam:.6g})")

    def run_requests(self, requests, parent):
        for bif, Q, p in requests:
            new = self.switch(bif, Q, p, parent)
            bif.new_branch = new

    def switch(self, bif, Q, p, parent):
        """Onto the branch born at a period doubling (``2p``) or symmetry breaking (``p``)."""
        pd = bif.type == "period_doubling"
        pn = 2 * p if pd else p
        if pn > self.max_period or self.flow.calls > self.max_calls:
            return None
        w, V = np.linalg.eig(Q.info.M)
        i = int(np.argmin(np.abs(w - (-1.0 if pd else 1.0))))
        v = _unit(np.real(V[:, i]))
        ystar = Q.y.copy()
        n = np.r_[v, 0.0]
        got = None
        for hrel in (1e-3, 1e-4, 3e-3, 1e-2):
            h = hrel * Q.info.scale
            ok, y, ev, _, _ = self.s.correct(np.r_[ystar[:2] + h * v, ystar[2]], n, "full",
                                             pn, Q.j, max_iter=12)
            R = self.point(y, Q.j, "full", pn, ev) if ok else None
            if R is None or not self.lo <= R.y[2] <= self.hi:
                continue
            d = self.s.defect(R.info, pn, 0)
            if float(np.abs(d).max()) <= 100 * self.s.sym_tol * R.info.scale:
                continue  # fell back onto the orbit it bifurcates from
            got = R
            break
        if got is None:
            bif.detail = (bif.detail + "; " if bif.detail else "") + "branch switching failed"
            return None
        known = self.known(got.info, got.y[2], pn, False)
        if known is not None:
            return known
        bifs, requests = [], []
        pts, end = self.march(got, got.y - ystar, "full", pn, bifs, requests)
        origin = f"{bif.type} of branch {parent} at {bif.parameter} = {bif.value:.10g}"
        idx = self.finish([got] + pts, ("branch_point", end), "full", pn, origin, parent,
                          bifs)
        self.run_requests(requests, idx)
        return idx


_DEFAULTS = dict(ds0=0.01, ds_min=1e-8, ds_max=0.025, max_points=2000, max_period=8,
                 join_tol=1e-3, max_calls=2_000_000, graze_tol=1e-4, param_tol=1e-8,
                 switch=True)


def _seed_list(seeds, name):
    out = []
    for i, sd in enumerate(seeds):
        if isinstance(sd, PeriodicOrbit):
            out.append((None, sd.cycle, sd.period, sd))
            continue
        try:
            val, x, p = sd
        except (TypeError, ValueError):
            raise ValueError(f"{name}[{i}] must be (parameter value, state or cycle, p) or a "
                             f"PeriodicOrbit (got {sd!r})") from None
        p = integer(f"{name}[{i}] period", p, 1, 256)
        out.append((real(f"{name}[{i}] value", val), _state(f"{name}[{i}] state", x, p), p,
                    None))
    return out


def _run(block, parameter, bounds, phase, seeds, n_steps, settings, origin_fmt):
    t0 = time.perf_counter()
    flow = _Flow(block, parameter, n_steps, phase)
    solver = _Solver(flow, tol=settings.pop("tol"), sym_tol=settings.pop("sym_tol"))
    cont = _Continuer(solver, bounds, **settings)
    for val, x, p, orb in seeds:
        if orb is not None:
            if not math.isclose(orb.phase, phase, abs_tol=1e-12):
                raise ValueError(f"a PeriodicOrbit seed must be at the continuation's phase "
                                 f"{phase!r} (got {orb.phase!r})")
            val = orb.alpha if parameter == "alpha" else orb.omega
            x = orb.cycle[0]
        cont.follow_seed(val, x, p, origin_fmt(val, p))
    branches, bifs = _within(cont.branches, cont.bifs, bounds)
    return Continuation(parameter=parameter, bounds=tuple(bounds), block=block, phase=phase,
                        n_steps=n_steps, branches=branches, bifurcations=bifs,
                        n_simulate=flow.calls, wall_s=time.perf_counter() - t0,
                        seeds_tried=cont.seeds_tried, settings=dict(settings))


def _within(branches, bifs, bounds):
    """The branches' points and the bifurcations inside ``bounds`` (a branch switched onto at a
    bifurcation may be followed past the range before its march ends; what lies outside was
    not asked for)."""
    lo, hi = bounds
    tol = 1e-9 * max(1.0, abs(hi))
    kept = []
    for br in branches:
        m = (br.value >= lo - tol) & (br.value <= hi + tol)
        if not m.all():
            arrays = {f: getattr(br, f)[m] for f in ("value", "alpha", "omega", "cycle",
                                                     "cycle_half", "multipliers", "stable",
                                                     "impacts", "symmetric_points",
                                                     "t_next_impact", "t_next_impact_half")}
            ends = tuple("range" if not (lo - tol <= v <= hi + tol) else e
                         for v, e in zip((br.value[0], br.value[-1]), br.ends))
            br = Branch(parameter=br.parameter, period=br.period, symmetric=br.symmetric,
                        ends=ends, origin=br.origin, parent=br.parent, **arrays)
        kept.append(br)
    return kept, [b for b in bifs if lo - tol <= b.value <= hi + tol]


def _settings(kw):
    st = dict(_DEFAULTS)
    for k, v in kw.items():
        if k not in st and k not in ("tol", "sym_tol"):
            raise TypeError(f"unexpected keyword argument {k!r}")
        st[k] = v
    st.setdefault("tol", 1e-12)
    st.setdefault("sym_tol", 1e-6)
    for k in ("ds0", "ds_min", "ds_max", "join_tol", "graze_tol", "param_tol", "tol",
              "sym_tol"):
        st[k] = real(k, st[k], 0.0, None, lo_open=True)
    if not st["ds_min"] <= st["ds0"] <= st["ds_max"]:
        raise ValueError(f"need ds_min <= ds0 <= ds_max (got {st['ds_min']}, {st['ds0']}, "
                         f"{st['ds_max']})")
    st["max_points"] = integer("max_points", st["max_points"], 2)
    st["max_period"] = integer("max_period", st["max_period"], 1, 256)
    st["max_calls"] = integer("max_calls", st["max_calls"], 1)
    st["switch"] = bool(st.get("switch", True))
    return st


def continuation(block_or_params, seeds, *, parameter="alpha", bounds, phase=0.0,
                 n_steps=N_ORBIT, switch=True, **options) -> Continuation:
    """Follow the periodic orbits through given seeds as ``alpha`` or ``omega`` varies.

    Parameters
    ----------
    block_or_params : Block or dict
        The block; its ``alpha`` (or ``omega``) is the fixed one of the pair.
    seeds : sequence
        Each ``(value, state, p)``: the continuation parameter's value, ``(theta, theta')`` (or
        a ``(p, 2)`` cycle) at ``t = 0`` and the period; or a :class:`PeriodicOrbit` (at the same
        phase).
    parameter : {"alpha", "omega"}
    bounds : (float, float)
        The parameter range; branches stop at its ends.
    phase : float
        Forcing phase of the stroboscopic section (default 0: ``(r0, s0) = (0, 1)``).
    n_steps : int
        Steps per forcing period, default :data:`N_ORBIT`.
    switch : bool
        Continue the branches born at period doublings (as ``2p``, up to ``max_period``) and
        symmetry-breaking pitchforks.
    **options
        ``ds0`` (first step, 0.01), ``ds_min`` (1e-8), ``ds_max`` (0.025): pseudo-arclength steps
        in ``(theta, theta', lambda)``; ``max_points`` (per direction, 2000); ``max_period``
        (8); ``join_tol`` (1e-3: two cycles are the same orbit within this fraction of the
        orbit's size); ``max_calls`` (a bound on simulate calls); ``graze_tol`` (1e-4, seeds);
        ``param_tol`` (1e-8: bifurcations are located to this in the parameter); ``tol``
        (1e-12, Newton); ``sym_tol`` (1e-6, symmetry and branch points).

    Returns
    -------
    Continuation
    """
    block = _as_block(block_or_params)
    if parameter not in ("alpha", "omega"):
        raise ValueError(f"parameter must be 'alpha' or 'omega' (got {parameter!r})")
    bounds = _range("bounds", bounds, 0.0)
    if parameter == "omega" and bounds[0] <= 0:
        raise ValueError(f"bounds must be > 0 for omega (got {bounds})")
    phase = real("phase", phase)
    n_steps = integer("n_steps", n_steps, 8)
    if n_steps % 2:
        raise ValueError(f"n_steps must be even (got {n_steps})")
    st = _settings(dict(options, switch=switch))
    sl = _seed_list(seeds, "seeds")
    return _run(block, parameter, bounds, phase, sl, n_steps, st,
                lambda v, p: f"seed p={p} at {parameter} = {v:.6g}")


def _sweep_seeds(sw, max_period):
    """One seed per periodic cell of a sweep: ``(alpha, cycle (p, 2), p)``, by period."""
    names = [str(n) for n in sw.names]
    periodic = {names.index(n) for n in ("symmetric", "asymmetric", "multiperiodic")}
    out = []
    for i, a in enumerate(np.asarray(sw.alpha)):
        p = int(sw.period[i])
        if int(sw.label[i]) not in periodic or not 1 <= p <= max_period:
            continue
        pts = np.asarray(sw.strobe[i])
        pts = pts[np.all(np.isfinite(pts), axis=1)]
        if pts.shape[0] < p:
            continue
        out.append((float(a), pts[-p:].copy(), p, None))
    out.sort(key=lambda s: (s[2], s[0]))
    return out


def continue_branches(hb, law, omega, alpha_range, seeds=None, sweep=None, *, e=None,
                      xi=None, phase=None, n_steps=N_ORBIT, switch=True, sweep_step=0.002,
                      **options) -> Continuation:
    """Every periodic branch of a sweep's attractors over ``alpha_range``, with bifurcations.

    Parameters
    ----------
    hb, law, omega : float, str, float
        The block (as :func:`rockjit.simulate`).
    alpha_range : (float, float)
    seeds : sequence, optional
        ``(alpha, state or cycle, p)`` at the forcing ``phase`` (see :func:`continuation`).
    sweep : SweepResult, optional
        Seeds from every periodic cell (period up to ``max_period``) of this sweep, at its
        forcing phase (that of its ``z0``). A cell whose orbit lies on a branch already
        followed (or its mirror image), within ``join_tol`` of the orbit's size and any cyclic
        shift, is skipped: each distinct attractor seeds one branch.
    e, xi : float, optional
        As in :func:`rockjit.simulate`.
    phase : float, optional
        Forcing phase of the section: the sweep's if a sweep is given, else 0.
    sweep_step : float
        With neither seeds nor a sweep, a sweep of this step over ``alpha_range`` from the
        study's ``z0`` is run first (:func:`rockjit.grids.grids.sweep`).
    n_steps, switch, **options
        As in :func:`continuation`.

    Returns
    -------
    Continuation
        Branches in the order found (seeds by period, then alpha; switched branches right
        after their parent) and every located bifurcation.
    """
    from ..grids import grids as analysis

    a0, a1 = _range("alpha_range", alpha_range, 0.0)
    kw = dict(hb=hb, alpha=a0, omega=omega, law=law, e=e)
    if xi is not None:
        kw["xi"] = xi
    block = Block(**kw)
    st = _settings(dict(options, switch=switch))
    if seeds is None and sweep is None:
        sweep = analysis.sweep(hb, omega, law=law, e=e, xi=xi, alpha_range=(a0, a1),
                               alpha_step=real("sweep_step", sweep_step, 0.0, None, lo_open=True))
    sl = []
    if sweep is not None:
        sb = sweep.block
        if not (math.isclose(sb.hb, block.hb) and math.isclose(sb.omega, block.omega)
                and sb.law == block.law and math.isclose(sb.restitution, block.restitution)
                and math.isclose(sb.xi, block.xi)):
            raise ValueError(f"sweep must be of the same block (hb={block.hb}, "
                             f"omega={block.omega}, law={block.law}, xi={block.xi}); got "
                             f"hb={sb.hb}, omega={sb.omega}, law={sb.law}, xi={sb.xi}")
        z = sweep.settings.get("z0")
        sphase = math.atan2(z[2], z[3]) if z is not None else 0.0
        if phase is not None and not math.isclose(real("phase", phase), sphase,
                                                  abs_tol=1e-12):
            raise ValueError(f"phase must be the sweep's forcing phase {sphase!r} (got "
                             f"{phase!r})")
        phase = sphase
        sl += _sweep_seeds(sweep, st["max_period"])
    phase = 0.0 if phase is None else real("phase", phase)
    if seeds is not None:
        sl = _seed_list(seeds, "seeds") + sl
    n_steps = integer("n_steps", n_steps, 8)
    if n_steps % 2:
        raise ValueError(f"n_steps must be even (got {n_steps})")
    return _run(block, "alpha", (a0, a1), phase, sl, n_steps, st,
                lambda v, p: f"seed p={p} at alpha = {v:.6g}")


# ---------------------------------------------------------------------------------------------
# the command line's entry: a plan (validation only), then the sweep and the continuation
# ---------------------------------------------------------------------------------------------

@dataclass(frozen=True)
class OrbitsPlan:
    """A validated ``rockjit orbits``: the seeding sweep's plan and the continuation's
    settings."""

    sweep_plan: object
    alpha_range: tuple
    n_steps: int
    settings: dict


def plan_orbits(hb, law, omega, alpha_range, *, e=None, xi=None, sweep_step=0.001,
                n_steps=N_ORBIT, periods=500, threads=None, **options) -> OrbitsPlan:
    """Validate :func:`continue_branches` seeded by a sweep of step ``sweep_step`` from the
    study's ``z0`` (same parameters); nothing is run."""
    from ..grids import grids as analysis
    a0, a1 = _range("alpha_range", alpha_range, 0.0)
    sp = analysis.plan_sweep(hb, omega, law=law, e=e, xi=xi, alpha_range=(a0, a1),
                             alpha_step=sweep_step, periods=periods, threads=threads)
    n_steps = integer("n_steps", n_steps, 8, 10**6)
    if n_steps % 2:
        raise ValueError(f"n_steps must be even (got {n_steps})")
    return OrbitsPlan(sweep_plan=sp, alpha_range=(a0, a1), n_steps=n_steps,
                      settings=_settings(options))


def run(plan: OrbitsPlan, *, progress=False, client=None, store=None, message=None):
    """Execute an :class:`OrbitsPlan`: the sweep, then the branches from its periodic
    attractors. Returns ``(Continuation, SweepResult)``."""
    from ..grids import grids as analysis
    sw = analysis.run(plan.sweep_plan, progress=progress, client=client, store=store,
                      message=message)
    b = sw.block
    st = dict(plan.settings)
    switch = st.pop("switch")
    cont = continue_branches(b.hb, b.law, b.omega, plan.alpha_range, sweep=sw, e=b.e,
                             xi=b.xi, n_steps=plan.n_steps, switch=switch, **st)
    return cont, sw
