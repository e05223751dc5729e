"""Fates decided by round-off: ensembles of nearby runs, outcome probabilities, horizons.

A chaotic transient amplifies any difference at a rate ``lambda1``: two runs ``eps`` apart
(rounding is ``eps ~ 1e-16``) become unrelated after about the *predictability horizon*
``t* = ln(tol / eps) / lambda1`` (``tol`` the separation at which they count as different, here
:data:`HORIZON_TOL` of the orbit's size). Past ``t*`` a single run's outcome is one sample of a
distribution, not a result. :func:`fate` runs ``K`` copies from initial states perturbed at
relative sizes spread log-uniformly over ``spread`` (default: from a few units in the last place
to ``1e-10``) and reports each outcome's probability, the finite-time exponent of the transient,
and the horizon. The ensemble is one grid of the compiled kernels (closed-form forcing) or
``K`` single runs (the embedding), so it is independent of the number of threads.

Grids can flag their *uncertain* cells (:func:`rockjit.grids.plan.uncertain_cells`, the
``uncertainty`` setting of the grids): those whose outcome changes when the initial state is
perturbed by ``eps``; the fraction of uncertain cells against ``eps`` gives the boundary's
uncertainty exponent (Grebogi, McDonald, Ott & Yorke 1983,
:func:`rockjit.measures.uncertainty_exponent`).
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np

from ..grids import plan as gp
from ..entry import entry_point
from ..grids import runner

from .._engine import kernel
from ..grids.identity import identify
from ..result import BEHAVIOURS, HORIZON_TOL, ROUNDING, horizon
from ..settings import Classification, Execution
from ..single import classify_result
from ..single import simulate
from ..single import run as run_one
from ..validate import integer, memory, pair

__all__ = ["DEFAULT_SPREAD", "HORIZON_TOL", "FateResult", "fate", "horizon", "outcome_keys",
           "perturb"]

#: Relative perturbations of the ensemble's initial states: four units in the last place to
#: 1e-10 (log-uniform).
DEFAULT_SPREAD = (4 * np.finfo(float).eps, 1e-10)


def perturb(x, k, spread, seed):
    """``k`` copies of the state ``x`` (theta, theta'), each component moved by a relative
    amount ``+-10^u`` with ``u`` uniform over ``log10(spread)`` (absolute where the component is
    0); seeded, so an ensemble is the same on every machine. Copy 0 is ``x`` itself."""
    rng = np.random.default_rng(seed)
    lo, hi = np.log10(spread[0]), np.log10(spread[1])
    mag = 10.0 ** rng.uniform(lo, hi, size=(k, 2))
    sign = rng.choice([-1.0, 1.0], size=(k, 2))
    x = np.asarray(x, dtype=float)
    scale = np.where(x != 0.0, np.abs(x), 1.0)
    out = x[None, :] + sign * mag * scale[None, :]
    out[0] = x
    return out


def outcome_keys(attractors):
    """Readable, stable names of an ensemble's outcomes: ``{outcome id: key}``.

    ``-1`` is ``"overturn"``, ``-2`` ``"unresolved"``; an attractor is named by its behaviour
    and, when periodic, its period (``"asymmetric p=1"``; rest for good is ``"rest"``, a
    chaotic or aperiodic cloud ``"chaotic"`` or ``"aperiodic"``). Attractors that would share
    a name are told apart by ``" (a)"``, ``" (b)"``, ... in the order of their position in the
    state plane: the smallest ``(theta, theta')`` of their points, compared as a pair. The ids
    themselves (by decreasing basin) never appear, so that the same attractor has the same key
    in ensembles of any size or seed.

    Parameters
    ----------
    attractors : list of Attractor
        As :func:`rockjit.grids.identity.identify` returns them.

    Returns
    -------
    dict of int to str

    Examples
    --------
    >>> import numpy as np
    >>> from rockjit.grids.identity import Attractor
    >>> a = [Attractor(id=k, behaviour="asymmetric", period=1, points=np.array([[x, 0.0]]),
    ...                fraction=50.0, n_cells=1, lam=np.zeros(2)) for k, x in enumerate((0.1, -0.1))]
    >>> outcome_keys(a)
    {-1: 'overturn', -2: 'unresolved', 1: 'asymmetric p=1 (a)', 0: 'asymmetric p=1 (b)'}
    """
    names = {-1: "overturn", -2: "unresolved"}
    base = {a.id: a.name for a in attractors}

    def position(a):
        pts = np.asarray(a.points, dtype=float).reshape(-1, 2)
        pts = pts[np.isfinite(pts).all(axis=1)]
        return tuple(pts[np.lexsort((pts[:, 1], pts[:, 0]))[0]]) if len(pts) else (0.0, 0.0)

    for name in dict.fromkeys(base.values()):
        same = sorted((a for a in attractors if base[a.id] == name),
                      key=lambda a: (position(a), a.id))
        for k, a in enumerate(same):
            names[a.id] = name if len(same) == 1 else f"{name} ({_letters(k)})"
    return names


def _letters(k):
    """0 -> 'a', 25 -> 'z', 26 -> 'aa', ..."""
    out = ""
    k += 1
    while k:
        k, r = divmod(k - 1, 26)
        out = chr(ord("a") + r) + out
    return out


@dataclass
class FateResult:
    """The outcomes of an ensemble of nearby runs.

    Attributes
    ----------
    probabilities : dict of str to float
        Each outcome's share of the members (sums to 1), most frequent first. The keys
        (``rockjit.basins.fate.outcome_keys``): ``"overturn"``, ``"rest"``, ``"unresolved"``,
        a periodic attractor ``"<behaviour> p=<period>"`` (``"symmetric p=1"``,
        ``"multiperiodic p=7"``),
        a chaotic or aperiodic one by its behaviour (``"chaotic"``); attractors that would
        share a key get ``" (a)"``, ``" (b)"``, ... in the order of their position in the
        state plane, so that a key names the same attractor whatever the ensemble's size or
        seed.
    ids : dict of str to int
        Each key's outcome id in ``outcome``.
    outcome : ndarray of int, shape (K,)
        Each member's outcome id (``>= 0`` attractors, ``-1`` overturn, ``-2`` unresolved).
    t_end : ndarray, shape (K,)
        When each member stopped (overturned, came to rest for good, or the end).
    initial : ndarray, shape (K, 2)
        The members' initial ``(theta, theta')``; member 0 is the nominal run.
    lambda1 : float
        The nominal run's finite-time largest exponent over the transient ``[0, t_end]``.
    horizon : float
        ``ln(HORIZON_TOL / spread[1]) / lambda1``: beyond it the members are unrelated.
    horizon_rounding : float
        The same for rounding alone (``eps = 2.2e-16``): the horizon of a single run.
    nominal : Result
        The unperturbed run (with exponents).
    block, forcing, settings :
        The run's block, excitation and the ensemble's settings.

    Examples
    --------
    >>> import rockjit
    >>> from rockjit import Block, Harmonic, Integration
    >>> f = rockjit.fate(Block(hb=1), Harmonic(alpha=0.969, omega=1.3), ensemble=8,
    ...                  integration=Integration(periods=200))
    >>> f.outcome.shape, sorted(f.probabilities)
    ((8,), ['overturn'])
    >>> round(f.lambda1, 2), round(f.horizon, 1)
    (0.21, 87.0)
    """

    probabilities: dict
    ids: dict
    outcome: np.ndarray
    t_end: np.ndarray
    initial: np.ndarray
    lambda1: float
    horizon: float
    horizon_rounding: float
    nominal: object
    block: object
    forcing: object = None
    settings: dict = field(default_factory=dict)

    def __repr__(self):
        from ..reprs import text
        return text(self)

    def to_summary(self):
        """JSON-ready."""
        return dict(probabilities=self.probabilities, lambda1=self.lambda1,
                    horizon=self.horizon, horizon_rounding=self.horizon_rounding,
                    t_end_median=float(np.median(self.t_end)),
                    nominal=self.nominal.summary(), settings=self.settings)


@dataclass(frozen=True)
class FatePlan:
    """A validated ensemble: the nominal run's plan, the members' initial states."""

    run_plan: object
    starts: np.ndarray
    ensemble: int
    spread: tuple
    seed: int


def run(plan: FatePlan, execution=None) -> FateResult:
    """Execute a :class:`FatePlan`."""
    execution = Execution() if execution is None else execution
    p, starts = plan.run_plan, plan.starts
    nominal = run_one(p)
    if not p.forcing.embedded:
        label, period, pts, n_got, t_end = _members_on_a_grid(p, starts, execution)
    else:  # the embedding: one compiled run per member (the grid kernels use the closed form)
        label, period, pts, n_got, t_end = _members_one_by_one(p, starts)
    ids, found = identify(label, period, pts, n_got)
    names = outcome_keys(found)
    order = sorted(np.unique(ids), key=lambda v: (-np.count_nonzero(ids == v), names[int(v)]))
    probs = {names[int(v)]: float(np.mean(ids == v)) for v in order}
    lam_run = nominal.lyapunov_running
    lam1 = float(lam_run[-1, 0]) if lam_run is not None and len(lam_run) > 1 else math.nan
    return FateResult(probabilities=probs, outcome=ids, t_end=t_end, initial=starts,
                      ids={names[int(v)]: int(v) for v in order},
                      lambda1=lam1, horizon=horizon(lam1, plan.spread[1]),
                      horizon_rounding=horizon(lam1, ROUNDING), nominal=nominal,
                      block=p.block, forcing=p.forcing,
                      settings=dict(ensemble=plan.ensemble, spread=list(plan.spread),
                                    seed=plan.seed, embedded=p.forcing.embedded,
                                    periods=p.periods, n_steps=p.n_steps,
                                    horizon_tol=HORIZON_TOL))


@entry_point(run)
def fate(block, forcing, state=None, *, integration=None, ensemble=64, spread=None, seed=0,
         execution=None) -> FateResult:
    """Outcome probabilities of ``ensemble`` runs from initial states perturbed at relative
    sizes over ``spread`` (see the module docstring).

    Parameters
    ----------
    block, forcing, state, integration :
        The run, as in :func:`rockjit.simulate` (its exponents are always computed for the
        nominal run).
    ensemble : int
        Members, at least 2 (member 0 is the unperturbed run).
    spread : pair of float, optional
        Smallest and largest relative perturbation, ``0 < lo <= hi <= 1e-2``; default
        :data:`rockjit.basins.fate.DEFAULT_SPREAD`.
    seed : int
        Seed of the perturbations.
    execution : Execution, optional
        Threads and progress of the ensemble's grid (closed-form forcing).

    Returns
    -------
    FateResult
        Each outcome's probability, the nominal run, its finite-time exponent and the
        predictability horizon.

    Examples
    --------
    >>> import rockjit
    >>> from rockjit import Block, Harmonic
    >>> f = rockjit.fate(Block(hb=1), Harmonic(alpha=0.6, omega=1.3), ensemble=4)
    >>> f.probabilities
    {'symmetric p=1': 1.0}
    """
    execution = Execution() if execution is None else execution
    ensemble = integer("ensemble", ensemble, 2, 10**6)
    spread = DEFAULT_SPREAD if spread is None else pair("spread", spread, 0.0, 1e-2,
                                                          lo_open=True)
    seed = integer("seed", seed, 0, 2**63 - 1)
    p = simulate.plan(block, forcing, state, integration=integration, lyapunov=True)
    memory(f"ensemble = {ensemble}", kernel.grid_bytes(ensemble, p.periods, p.n_steps,
                                                       Classification().pmax, 0, False,
                                                       ensemble, 1))
    starts = perturb(p.y0[:2], ensemble, spread, seed)
    if np.abs(starts[:, 0]).max() >= p.integration.theta_over:
        raise ValueError(f"spread = {spread} moves theta0 past theta_over; give a smaller "
                         f"spread")
    return FatePlan(run_plan=p, starts=starts, ensemble=ensemble, spread=tuple(spread),
                    seed=seed)


def _members_on_a_grid(p, starts, execution):
    """The members as the cells of one grid (closed-form forcing): full length, no early stop,
    so that each member's fate is its own run's, as far as the nominal run went."""
    n = starts.shape[0]
    cl = Classification()
    par = kernel.pack(p.block, p.forcing, p.phi, p.integration, p.n_steps, cl.settle_tol)
    ipar = kernel.settings(p.n_steps, p.periods, p.max_impacts, p.window, pmax=cl.pmax,
                           stop_at_overturn=p.integration.stop_at_overturn)
    cpar = kernel.classification_vector(cl)
    y0s = np.column_stack([starts, np.full(n, p.y0[2]), np.full(n, p.y0[3])])
    out = runner.run_grid(y0s, np.tile(par, (n, 1)), ipar, cpar, tangent=False, n_pts=cl.pmax,
                          n_imp_pts=0, label=gp.progress_label("fate", p.block, p.forcing),
                          execution=execution)
    r = kernel.grid_results(out)
    return r["label"], r["period"], out["pts"], out["n_got"], r["t_end"]


def _members_one_by_one(p, starts):
    from dataclasses import replace

    n = starts.shape[0]
    m = Classification().pmax
    label = np.zeros(n, dtype=np.int64)
    period = np.zeros(n, dtype=np.int64)
    pts = np.full((n, m, 2), np.nan)
    n_got = np.zeros(n, dtype=np.int64)
    t_end = np.zeros(n)
    for i, (th, dth) in enumerate(starts):
        r = run_one(replace(p, y0=(float(th), float(dth)) + tuple(p.y0[2:]), lyapunov=False))
        name, per = classify_result(r)
        label[i], period[i], t_end[i] = BEHAVIOURS.index(name), per, r.t
        if name not in ("overturn", "rest", "unresolved"):
            s = r.strobe[-m:, :2]
            pts[i, :len(s)] = s
            n_got[i] = len(s)
    return label, period, pts, n_got, t_end
