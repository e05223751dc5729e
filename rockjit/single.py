"""One run of the forced rocking block: validated, then integrated compiled or through scipy.

:func:`simulate` is the entry point. Its inputs are the block (:class:`rockjit.Block`), the
excitation (:class:`rockjit.Harmonic`), the initial state and the integration settings
(:class:`rockjit.Integration`); :func:`plan` checks what depends on them together (the step's
stability, the memory the run would allocate) into a :class:`RunPlan`, and :func:`run` executes
it on the compiled path (:mod:`rockjit._engine.kernel`) or the scipy reference path
(:mod:`rockjit.reference`). The command line builds the same plan, so the API and the CLI accept
and refuse exactly the same inputs.
"""

from __future__ import annotations

import functools
import math
from dataclasses import dataclass

import numpy as np

from ._engine import kernel
from .excitation import STUDY_PHASE, Harmonic
from .model import Block, damping_rate, initial_side
from .result import Result
from ._engine.classify import classify
from .result import BEHAVIOURS
from .settings import Classification, Integration
from .validate import boolean, choice, integer, memory, real, real_array

__all__ = ["DAMPING_ONSET", "DAMPING_STEP", "DEFAULT_N", "IVP_METHODS", "MAX_STEP", "RunPlan", "STABLE_DAMPING",
           "STEP_LIMIT", "Scipy", "Z0_STUDY", "check_step", "classify_result", "run", "simulate",
           "steps_per_period"]

#: The study's initial state ``(theta, theta', r, s)`` of its single runs and sweeps
#: (docs/theory/study.md): a run from the default state starts here, at the study's forcing
#: phase unless the excitation gives another.
Z0_STUDY = (-0.2254, -0.1597) + STUDY_PHASE

#: Default number of steps per forcing period of single runs: the least that keeps impact times
#: over 20 periods within 1e-10 of a converged solution on every orbit of the study
#: (benchmarks/results/work_precision.md).
DEFAULT_N = 160

#: Largest step (in units of 1/Omega0) a default N may give: at slow forcing, N steps per period
#: would be coarse against the block's own time scale, so N is raised until h <= MAX_STEP.
MAX_STEP = 0.1

#: Coarsest step accepted at all: the block's own time scale is ~1, so a longer step is no
#: integration of it.
STEP_LIMIT = 1.0

#: Damping: the velocity's own rate is ``c = 3/4 xi``. The Dormand–Prince step is stable on it
#: for ``h c < 3.307`` (its stability polynomial's real boundary); an explicit N is refused
#: beyond ``h c = STABLE_DAMPING``, and a default N is raised until ``h c <= DAMPING_STEP``,
#: and for accuracy (below).
STABLE_DAMPING = 3.0
DAMPING_STEP = 1.0
#: Accuracy under damping. At a fixed step the stroboscopic error of a damped run grows about
#: as ``xi^2 h^5``, so a cap on ``h c`` alone would let it grow with xi below the cap. Once
#: ``c`` exceeds ``DAMPING_ONSET`` a default N is also raised to ``default *
#: (c / DAMPING_ONSET)^(2/5)``, which keeps ``xi^2 h^5``, and with it the error, near the
#: undamped default's (benchmarks/results/event_accuracy.md, "Strong damping").
DAMPING_ONSET = 1.0

#: ``solve_ivp`` methods of the reference path.
IVP_METHODS = ("RK23", "RK45", "DOP853", "Radau", "BDF", "LSODA")


@dataclass(frozen=True)
class Scipy:
    """The scipy reference path: ``scipy.integrate.solve_ivp`` with this method and these
    tolerances, restarted at every impact (docs/theory/integrator.md). The study's was BDF at
    ``rtol=1e-6, atol=1e-9``.

    Parameters
    ----------
    method : {"BDF", "RK23", "RK45", "DOP853", "Radau", "LSODA"}
        The ``solve_ivp`` method; default ``"BDF"`` (the study's).
    rtol, atol : float
        Relative tolerance in ``(0, 1)`` and absolute tolerance ``> 0``; default the study's
        ``1e-6`` and ``1e-9``.

    Examples
    --------
    >>> from rockjit import Scipy
    >>> Scipy("DOP853", rtol=1e-12, atol=1e-12).name
    'scipy:DOP853'
    """

    method: str = "BDF"
    rtol: float = 1e-6
    atol: float = 1e-9

    def __post_init__(self):
        choice("method", self.method, IVP_METHODS)
        object.__setattr__(self, "rtol", real("rtol", self.rtol, 0.0, 1.0, lo_open=True,
                                              hi_open=True))
        object.__setattr__(self, "atol", real("atol", self.atol, 0.0, None, lo_open=True))

    @property
    def name(self):
        """``"scipy:<METHOD>"``, as results record it."""
        return f"scipy:{self.method}"


def _method(method):
    """``"rockjit"`` or a :class:`Scipy`, from what :func:`simulate` was given."""
    if method == "rockjit" or isinstance(method, Scipy):
        return method
    if isinstance(method, str) and (method == "scipy" or method.startswith("scipy:")):
        name = method.split(":", 1)[1] if ":" in method else "BDF"
        if name in IVP_METHODS:
            return Scipy(name)
    raise ValueError(f"method must be 'rockjit', 'scipy', 'scipy:<one of "
                     f"{', '.join(IVP_METHODS)}>' or a rockjit.Scipy (got {method!r})")


def check_step(period, n_steps, forcing="closed", radius=1.0, xi=0.0):
    """Reject a grid too coarse to integrate: ``ValueError`` naming ``n_steps`` and the N needed.

    Any forcing: ``h = T/N <= STEP_LIMIT``; damping: ``h 3/4 xi <= STABLE_DAMPING``. The
    embedding also integrates the oscillator's radial contraction, of rate ``3 rho^2 - 1``
    from radius ``rho``, which an explicit step only follows stably for
    ``h (3 rho^2 + 1) <= 1.5`` (found by the stress suite: beyond it r, s overflow).
    """
    h_max = STEP_LIMIT
    why = f"the step T/N must be <= {STEP_LIMIT}"
    if xi > 0 and STABLE_DAMPING / damping_rate(xi) < h_max:
        h_max = STABLE_DAMPING / damping_rate(xi)
        why = (f"the damping xi = {xi:g} needs a step T/N <= {h_max:.3g} to stay stable "
               f"(3/4 xi T/N <= {STABLE_DAMPING})")
    if forcing == "embedded":
        h_emb = 1.5 / (3.0 * max(radius, 1.0) ** 2 + 1.0)
        if h_emb < h_max:
            h_max = h_emb
            why = (f"the embedded oscillator from |(r0, s0)| = {radius:.3g} needs a step "
                   f"<= {h_emb:.3g}")
    if period / n_steps > h_max:
        need = 2 * math.ceil(period / (2 * h_max))
        raise ValueError(f"n_steps must be >= {need} here: {why} (got n_steps = {n_steps}, "
                         f"T/N = {period / n_steps:.3g})")


def steps_per_period(period, default, xi=0.0):
    """``default``, raised for damping to ``default * (c / DAMPING_ONSET)^(2/5)`` when
    ``c = 3/4 xi`` exceeds ``DAMPING_ONSET``, and then to the smallest even N with
    ``h = period / N <= MAX_STEP`` and ``h c <= DAMPING_STEP`` if that is larger."""
    n = int(default)
    h_max = MAX_STEP
    if xi > 0:
        c = damping_rate(xi)
        h_max = min(h_max, DAMPING_STEP / c)
        if c > DAMPING_ONSET:
            n = max(n, 2 * math.ceil(n * (c / DAMPING_ONSET) ** 0.4 / 2))
    if period / n > h_max:
        n = 2 * math.ceil(period / (2 * h_max))
    return n


def settings_for(block, forcing, integration, default_n):
    """The integration settings resolved for this block and forcing: ``(n_steps, window,
    max_impacts)``. ``n_steps`` defaults to ``default_n``, raised for slow forcing and strong
    damping; an explicit one is checked for stability (:func:`check_step`)."""
    period = forcing.period
    if integration.n_steps is None:
        n_steps = steps_per_period(period, default_n, block.xi)
    else:
        n_steps = integration.n_steps
    return n_steps, integration.window_start(), integration.impact_bound()


def check_theta0(theta0, integration, name="theta0"):
    """An initial angle inside the bounded region ``|theta0| < theta_over``."""
    theta0 = real(name, theta0)
    if abs(theta0) >= integration.theta_over:
        raise ValueError(f"{name} must satisfy |{name}| < theta_over = "
                         f"{integration.theta_over:.6g} (got {theta0:g}): the block would start "
                         f"overturned")
    return theta0


def state_pair(state, integration):
    """``(theta0, theta0')`` from a run's ``state``, checked: two finite numbers, the angle
    inside ``|theta0| < theta_over``."""
    if type(state) is tuple and len(state) == 2 and type(state[0]) is float \
            and type(state[1]) is float:  # the common case, without an array (a run's cost)
        th, dth = state
    else:
        z = real_array("state", state, "two numbers (theta0, theta0')")
        if z.shape != (2,):
            raise ValueError(f"state must be two numbers (theta0, theta0') (got {state!r})")
        th, dth = float(z[0]), float(z[1])
    th = check_theta0(th, integration, "state[0] (theta0)")
    dth = real("state[1] (dtheta0)", dth, -1e6, 1e6)
    return th, dth


def initial_state(state, forcing, integration):
    """``(theta0, theta0', phi, r0, s0)`` from a run's ``state`` (``(theta0, theta0')``, or
    ``None``: the study's) and its excitation's phase (not given: the study's forcing point
    for the study's state, ``(0, 1)`` otherwise)."""
    if state is None:
        th, dth = Z0_STUDY[:2]
        return (th, dth) + forcing.start(STUDY_PHASE)
    return state_pair(state, integration) + forcing.start((0.0, 1.0))


@dataclass(frozen=True)
class RunPlan:
    """A validated single run: everything :func:`run` needs, nothing left to check."""

    block: Block
    forcing: Harmonic
    integration: Integration
    y0: tuple            # (theta0, dtheta0, r0, s0)
    phi: float
    method: object       # "rockjit" or a Scipy
    n_steps: int
    window: int
    max_impacts: int
    record_stride: int | None
    lyapunov: bool
    memory_bytes: float

    @property
    def periods(self):
        return self.integration.periods


def run(p: RunPlan, execution=None) -> Result:
    """Execute a :class:`RunPlan` on its path (compiled or scipy); a plan under a pulse or a
    record (:class:`rockjit.ground.plan.TransientPlan`) runs itself on the transient path."""
    if not isinstance(p, RunPlan):
        return p.run()
    if p.method != "rockjit":
        from .reference import simulate_scipy  # scipy.integrate only when asked for
        return simulate_scipy(p)
    return kernel.run_single(p)


def plan_simulate(block, forcing, state=None, *, integration=None, lyapunov=False,
                  record_stride=None, method="rockjit"):
    """The plan of :func:`simulate` (``rockjit.simulate.plan``): its parameters checked
    together, before any work; a :class:`RunPlan`, or for a transient excitation its own plan.
    ``run(plan)`` executes it."""
    if not isinstance(block, Block):
        raise ValueError(f"block must be a rockjit.Block (got {type(block).__name__})")
    if getattr(forcing, "transient", False) and not isinstance(forcing, Harmonic):
        return forcing.plan_run(block, state, integration, lyapunov, record_stride,
                                _method(method))
    if not isinstance(forcing, Harmonic):
        raise ValueError(f"forcing must be a rockjit excitation: Harmonic, Pulse, Record or a "
                         f"plug of rockjit.plugs "
                         f"(got {type(forcing).__name__})")
    forcing.require("alpha", "omega", why="a single run")
    integration = Integration() if integration is None else integration
    if not isinstance(integration, Integration):
        raise ValueError(f"integration must be a rockjit.Integration "
                         f"(got {type(integration).__name__})")
    theta0, dtheta0, phi, r0, s0 = initial_state(state, forcing, integration)
    method = _method(method)
    n_steps, window, max_impacts = settings_for(block, forcing, integration, DEFAULT_N)
    check_step(forcing.period, n_steps, "embedded" if forcing.embedded else "closed",
               math.hypot(r0, s0), block.xi)
    if record_stride is not None:
        record_stride = integer("record_stride", record_stride, 1, 2**62)
    lyapunov = boolean("lyapunov", lyapunov)
    if method != "rockjit" and lyapunov:
        raise ValueError("lyapunov=True is only available with method='rockjit'")
    periods = integration.periods
    if periods * n_steps > 2**62:
        raise ValueError(f"periods * n_steps must be <= 2**62 (got {periods} * {n_steps})")
    n_traj = periods * n_steps // record_stride + 1 if record_stride else 1
    nbytes = kernel.run_bytes(periods, n_steps, max_impacts, n_traj, lyapunov)
    memory(f"periods = {periods} at n_steps = {n_steps}", nbytes)
    return RunPlan(block=block, forcing=forcing, integration=integration,
                   y0=(theta0, dtheta0, r0, s0), phi=phi, method=method, n_steps=n_steps,
                   window=window, max_impacts=max_impacts, record_stride=record_stride,
                   lyapunov=lyapunov, memory_bytes=nbytes)


class Prepared:
    """A single run made ready to repeat: its validated plan, packed parameters and compiled
    kernel are kept, so that a call with a new initial state or amplitude costs the
    integration and little else (the plan's checks, the packing and the kernel's look-up are
    not made again).

    Made by ``rockjit.simulate.prepare(...)`` (the parameters of :func:`rockjit.simulate`);
    :func:`rockjit.simulate` keeps one per block, excitation and settings it is called with
    again.
    Calling it with ``state`` (a new ``(theta0, theta0')``) and ``alpha`` (a new amplitude)
    returns the :class:`rockjit.Result` of that run; the forcing phase stays the prepared
    run's (give it in the excitation, ``phase`` or ``r0, s0``, to fix it yourself).

    Parameters
    ----------
    plan : RunPlan
        A validated single run of the compiled path (``rockjit.simulate.plan(...)``);
        ``method`` must be ``"rockjit"``.

    Examples
    --------
    >>> import rockjit
    >>> from rockjit import Block, Harmonic, Integration
    >>> run = rockjit.simulate.prepare(Block(hb=1), Harmonic(alpha=0.6, omega=1.3),
    ...                                integration=Integration(periods=20))
    >>> [run(state=(th, 0.0)).status for th in (0.1, 0.2)]
    ['done', 'done']
    >>> run(alpha=0.7).forcing.alpha
    0.7
    """

    __slots__ = ("plan", "_kernel", "_par", "_ipar", "_entry")

    def __init__(self, plan):
        if not isinstance(plan, RunPlan):
            raise ValueError("a run under a pulse or a record cannot be prepared: call "
                             "rockjit.simulate for each run")
        if plan.method != "rockjit":
            raise ValueError("only runs of the compiled path can be prepared "
                             "(method='rockjit')")
        self.plan = plan
        self._kernel, self._par, self._ipar = kernel.prepare_single(plan)
        self._entry = None

    def __getstate__(self):
        # the compiled code's entry cannot be pickled: a copy finds it again at its first call
        return self.plan, self._kernel, self._par, self._ipar

    def __setstate__(self, state):
        self.plan, self._kernel, self._par, self._ipar = state
        self._entry = None

    def __call__(self, state=None, *, alpha=None):
        """Run from ``state`` (``(theta0, theta0')``; default the plan's) at amplitude
        ``alpha`` (default the plan's): a :class:`Result`."""
        p = self.plan
        par, forcing = self._par, None
        if alpha is not None:
            forcing = p.forcing.replace(alpha=alpha)
            par = kernel.vary(par.copy()[None, :], alpha=forcing.alpha)[0]
        y0 = np.array(p.y0)
        if state is not None:
            # a new block state; the forcing's, (r0, s0), stays the plan's (its phase)
            y0[0], y0[1] = state_pair(state, p.integration)
        out = kernel.single_outputs(p)
        args = (y0, initial_side(y0[0], y0[1]), par, self._ipar, out)
        if self._entry is None:
            code = self._kernel(*args)
            # the arguments' types never change (the plan's y0 and outputs, the packed
            # parameters, an int side): later calls go straight to the compiled code, without
            # numba's dispatch (a microsecond a call), which also skips its check of the types
            self._entry = self._kernel.get_overload(tuple(map(self._kernel.typeof_pyval,
                                                              args)))
        else:
            code = self._entry(*args)
        return kernel.single_result(p, code, out, forcing)


def _prepare(*args, **kwargs):
    return Prepared(simulate.plan(*args, **kwargs))


_prepare.__doc__ = """A :class:`Prepared` run: the parameters of :func:`simulate`, validated once
and packed for the compiled kernel; call it with a new ``state`` or ``alpha`` to run again
without the checks, the packing and the kernel's look-up."""

#: Prepared runs :func:`simulate` reuses, by its arguments but the state (a few at most).
_PREPARED = {}
_PREPARED_MAX = 64


def simulate(block, forcing, state=None, *, integration=None, lyapunov=False,
             record_stride=None, method="rockjit") -> Result:
    """Simulate the rocking block under an excitation.

    Parameters
    ----------
    block : Block
        The block: slenderness, restitution law, damping.
    forcing : Harmonic, Pulse, Record or an excitation plug
        The excitation: harmonic, with its amplitude ``alpha`` and frequency ``omega`` (and
        phase, or the study's); or a transient one, a :class:`rockjit.Pulse` (with its
        ``ratio`` and ``amplitude``), a :class:`rockjit.Record` (with the block's ``size``)
        or an excitation plug such as :class:`rockjit.HarmonicSum`, which runs on the compiled
        transient kernel (or the scipy path) and returns a
        :class:`rockjit.ground.TransientResult` (docs/guide/earthquakes.md,
        docs/guide/extending.md).
    state : pair of float, optional
        The initial ``(theta0, theta0')``, ``|theta0| < theta_over``. Default: the study's
        ``z0`` (docs/theory/study.md), at the study's forcing phase unless ``forcing`` gives
        one; at rest, ``(0, 0)``, under a pulse or a record.
    integration : Integration or Transient, optional
        Steps per period, periods, window, impact bound, Zeno cut-off, overturning threshold
        (:class:`rockjit.Integration`; default N here is :data:`rockjit.DEFAULT_N`); for a pulse or a
        record, a :class:`rockjit.Transient` (free rocking time or a duration, in model
        units).
    lyapunov : bool
        Compute the block's Lyapunov exponents (docs/theory/exponents.md); compiled path only.
    record_stride : int, optional
        Record ``(t, theta, theta', r, s)`` every this many grid steps.
    method : {"rockjit", "scipy", "scipy:<METHOD>"} or Scipy
        The compiled path (default), or the reference path through
        ``scipy.integrate.solve_ivp`` (default BDF at the study's tolerances; a
        :class:`rockjit.Scipy` chooses the method and tolerances).

    Returns
    -------
    Result
        The run's samples, impacts, exponents and status.

    Raises
    ------
    ValueError
        For any parameter out of its range (the message names it, the allowed range and the
        value given), a step too coarse to be stable, or a run whose arrays would not fit in
        memory.

    See Also
    --------
    rockjit.fate : runs from nearby initial states: each outcome's probability and the
        predictability horizon.

    Examples
    --------
    >>> import rockjit
    >>> from rockjit import Block, Harmonic
    >>> res = rockjit.simulate(Block(hb=1), Harmonic(alpha=0.6, omega=1.3), lyapunov=True)
    >>> res.status, rockjit.classify_result(res)
    ('done', ('symmetric', 1))
    """
    # a run from the study's state starts at the study's forcing phase, one from a given state
    # at phase 0 (unless the excitation gives one): the two never share a prepared run
    key = (block, forcing, integration, lyapunov, record_stride, method, state is None)
    try:
        prepared = _PREPARED.get(key)
    except TypeError:  # an argument that cannot be hashed: no reuse (and no error here)
        return run(plan_simulate(block, forcing, state, integration=integration,
                                 lyapunov=lyapunov, record_stride=record_stride, method=method))
    if prepared is not None:
        return prepared(state)
    p = plan_simulate(block, forcing, state, integration=integration, lyapunov=lyapunov,
                      record_stride=record_stride, method=method)
    if p.method == "rockjit" and type(lyapunov) is bool and not getattr(forcing, "transient",
                                                                         False):
        if len(_PREPARED) >= _PREPARED_MAX:
            _PREPARED.clear()
        prepared = _PREPARED[key] = Prepared(p)
        return prepared()  # the plan's own state: run(p), packed once
    return run(p)


simulate.plan = plan_simulate
simulate.prepare = _prepare


def classify_result(result, classification=None):
    """Behaviour name and period of a :class:`rockjit.Result` (the run's window).

    Uses the same compiled classifier as the sweeps and basins on the result's stroboscopic
    samples from ``window`` on (docs/theory/behaviours.md).

    Parameters
    ----------
    result : Result
        A run of :func:`rockjit.simulate`.
    classification : Classification, optional
        The period test's tolerances (``tol``, ``pmax``, ``lam_tol``); default
        ``Classification()``.

    Returns
    -------
    name : str
        One of :data:`rockjit.BEHAVIOURS`.
    period : int
        The period in forcing periods (0 for overturn, rest, chaotic, aperiodic, unresolved).

    Examples
    --------
    >>> import rockjit
    >>> from rockjit import Block, Harmonic
    >>> rockjit.classify_result(rockjit.simulate(Block(hb=1), Harmonic(alpha=0.8, omega=1.3)))
    ('asymmetric', 1)
    """
    cl = Classification() if classification is None else classification
    if result.status == "overturned" or math.isfinite(result.t_overturn):
        return "overturn", 0
    if result.status == "rest":
        return "rest", 0
    if result.status not in ("done", "settled"):
        return "unresolved", 0
    k1 = result.strobe.shape[0] - 1
    k0 = int(round(result.window[0] / result.period)) if result.window else \
        int(round(0.8 * result.periods))
    k0 = min(k0, k1)
    per_imp = np.zeros(k1 + 1, dtype=np.int64)
    t_imp = result.impacts[:, 0]
    for k in range(k1 + 1):
        per_imp[k] = np.count_nonzero(t_imp <= k * result.period * (1 + 1e-12))
    half = np.zeros((k1 + 1, 4))
    half[:result.strobe_half.shape[0]] = result.strobe_half[:k1 + 1]
    lam = result.lambda_max
    code, p = classify(result.strobe, half, per_imp, k0, k1, lam, not math.isnan(lam),
                       float(cl.tol), int(cl.pmax), float(cl.lam_tol))
    return BEHAVIOURS[code], int(p)
