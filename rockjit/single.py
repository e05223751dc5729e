"""``rockjit.single``: one run of the forced rocking block, compiled or through scipy.

:func:`plan` validates every input of a run (ranges, the grid's stability, the memory the run
would allocate) and returns a :class:`RunPlan`; :func:`run` executes it on the compiled path
(:mod:`rockjit._engine.kernel`) or the scipy reference path (:mod:`rockjit.reference`). The command
line builds the same plan, so the API and the CLI accept and refuse exactly the same inputs.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from ._engine import kernel
from .model import Block
from .result import Result
from .validate import choice, integer, memory, real

__all__ = ["DAMPING_STEP", "DEFAULT_N", "IVP_METHODS", "MAX_STEP", "RunPlan", "STABLE_DAMPING",
           "STEP_LIMIT", "Z0_STUDY", "check_step", "default_max_impacts", "forcing_phase",
           "plan", "run", "simulate", "steps_per_period"]

#: The study's initial state ``(theta, theta', r, s)`` of its single runs and sweeps (SPEC.md
#: §7), which :func:`simulate` starts from when no initial state is given. (Every other constant
#: of the study is in :mod:`rockjit.study.paper`, which lists this one too.)
Z0_STUDY = (-0.2254, -0.1597, -0.7778, 0.6284)

#: Default number of steps per forcing period of single runs. Impact times over 20 periods are
#: within 1e-10 of a converged solution (N = 2048) on the study's orbits from N = 160 on; the
#: most demanding of them, the asymmetric orbit (hb=1, alpha=0.8), needs it: 2.1e-10 at N = 128,
#: 6.5e-11 at N = 160 (benchmarks/README.md, "Work against precision").
DEFAULT_N = 160

#: Largest step (in units of 1/Omega0) a default N may give: at slow forcing, N steps per period
#: would be coarse against the block's own time scale, so N is raised until h <= MAX_STEP.
MAX_STEP = 0.1

#: Coarsest step accepted at all: the block's own time scale is ~1, so a longer step is no
#: integration of it (and a stress case: omega = 0.05 with N = 8 gave h = 16).
STEP_LIMIT = 1.0

#: Damping: the velocity's own rate is ``c = 3/4 xi``. The Dormand–Prince step is stable on it
#: for ``h c < 3.307`` (its stability polynomial's real boundary); an explicit N is refused
#: beyond ``h c = STABLE_DAMPING``, and a default N is raised until ``h c <= DAMPING_STEP``,
#: where the step also follows the damped mode accurately. (Found by the stress suite: xi = 200
#: at N = 160, h c = 3.6, overturned at t = 2.2 with an error estimate of 1e2.)
STABLE_DAMPING = 3.0
DAMPING_STEP = 1.0

#: ``solve_ivp`` methods of the reference path.
IVP_METHODS = ("RK23", "RK45", "DOP853", "Radau", "BDF", "LSODA")

#: Largest number of periods, and of steps per period, a run may ask for: bounds that keep the
#: kernels' step counter in 64 bits. The memory check refuses most large requests first, with
#: the memory they would need.
MAX_PERIODS = 10**15
MAX_N = 10**12


def default_max_impacts(periods):
    """The default impact bound: 10,000 impacts per period, at least 100,000. A Zeno cascade
    from ``|theta'| ~ 1`` to the cut-off ``1e-6`` has ``ln(1e-6) / ln(e)`` impacts: ~10 for
    ``e = 0.25``, ~75 for ``e = 0.83``, ~1,400 for ``e = 0.99``, at most two a period."""
    return max(100_000, 10_000 * int(periods))


def check_step(period, n_steps, forcing="closed", radius=1.0, xi=0.0):
    """Reject a grid too coarse to integrate: ``ValueError`` naming ``n_steps`` and the N needed.

    Any forcing: ``h = T/N <= STEP_LIMIT``; damping: ``h 3/4 xi <= STABLE_DAMPING``. The
    embedding also integrates the oscillator's radial contraction, of rate ``3 rho^2 - 1``
    from radius ``rho``, which an explicit step only follows stably for
    ``h (3 rho^2 + 1) <= 1.5`` (found by the stress suite: beyond it r, s overflow).
    """
    h_max = STEP_LIMIT
    why = f"the step T/N must be <= {STEP_LIMIT}"
    if xi > 0 and STABLE_DAMPING / (0.75 * xi) < h_max:
        h_max = STABLE_DAMPING / (0.75 * xi)
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
    """``default``, or the smallest even N with ``period / N <= MAX_STEP`` and
    ``period / N * 3/4 xi <= DAMPING_STEP`` if that is larger."""
    n = int(default)
    h_max = MAX_STEP
    if xi > 0:
        h_max = min(h_max, DAMPING_STEP / (0.75 * xi))
    if period / n > h_max:
        n = 2 * math.ceil(period / (2 * h_max))
    return n


def forcing_phase(phase=None, r0=None, s0=None, forcing="closed", *, embedded_hint=True):
    """Resolve the forcing's initial condition into ``(phi, r0, s0)``.

    Give either ``phase`` (``r = sin(omega t + phase)``) or ``(r0, s0)``; the default is
    ``(r0, s0) = (0, 1)``. With the closed form, ``(r0, s0)`` must lie on the unit circle (to
    1e-3): off it only the embedding is meaningful (SPEC.md §1); ``embedded_hint`` says so in
    the message (callers without an embedding turn it off).
    """
    choice("forcing", forcing, ("closed", "embedded"))
    if phase is not None:
        if r0 is not None or s0 is not None:
            raise ValueError("give either phase or (r0, s0), not both")
        phi = real("phase", phase)
        return phi, math.sin(phi), math.cos(phi)
    if (r0 is None) != (s0 is None):
        raise ValueError("r0 and s0 go together: give both or neither")
    if r0 is None:
        r0, s0 = 0.0, 1.0
    r0 = real("r0", r0, -1e3, 1e3)
    s0 = real("s0", s0, -1e3, 1e3)
    rad = math.hypot(r0, s0)
    if rad == 0.0:
        raise ValueError("(r0, s0) must not be (0, 0): the forcing oscillator has no phase there")
    if forcing == "closed" and abs(rad - 1.0) > 1e-3:
        hint = "; use forcing='embedded' for a start off the circle" if embedded_hint else \
            "; give a point on the circle, or a phase"
        raise ValueError(f"(r0, s0) must lie on the unit circle for the closed-form forcing "
                         f"(|(r0, s0)| = {rad:.6g}){hint}")
    return math.atan2(r0, s0), r0, s0


def initial_state(theta0=None, dtheta0=None, z0=None, r0=None, s0=None, phase=None):
    """``(theta0, dtheta0, r0, s0)`` from the ways a user may give them: ``z0`` at once, or
    separately (missing angles are 0), or nothing at all (the study's ``Z0_STUDY``).
    ``r0, s0`` may be ``None`` (resolved by :func:`forcing_phase`)."""
    if z0 is not None:
        if theta0 is not None or dtheta0 is not None or r0 is not None or s0 is not None:
            raise ValueError("give z0 or (theta0, dtheta0, r0, s0), not both")
        try:
            z = np.asarray(z0, dtype=float).ravel()
        except (TypeError, ValueError):
            raise ValueError(f"z0 must be 4 numbers (theta, theta', r, s) (got {z0!r})") \
                from None
        if z.shape != (4,):
            raise ValueError(f"z0 must have 4 entries (theta, theta', r, s) (got {z.size})")
        theta0, dtheta0, r0, s0 = (float(v) for v in z)
    elif theta0 is None and dtheta0 is None and r0 is None and s0 is None and phase is None:
        theta0, dtheta0, r0, s0 = Z0_STUDY
    return (0.0 if theta0 is None else theta0), (0.0 if dtheta0 is None else dtheta0), r0, s0


def closed_form_z0(theta0=None, dtheta0=None, r0=None, s0=None, phase=None):
    """A whole initial state ``(theta0, dtheta0, r0, s0)`` for the closed-form forcing, by
    :func:`simulate`'s rule: the study's ``z0`` when nothing is given, else the angles given (0
    where not) and the forcing at its phase (default ``(r0, s0) = (0, 1)``)."""
    th, dth, r0, s0 = initial_state(theta0, dtheta0, None, r0, s0, phase)
    return (th, dth) + forcing_phase(phase, r0, s0, "closed", embedded_hint=False)[1:]


def check_theta0(theta0, block, name="theta0"):
    """An initial angle inside the bounded region ``|theta0| < theta_over``."""
    theta0 = real(name, theta0)
    if abs(theta0) >= block.theta_over:
        raise ValueError(f"{name} must satisfy |{name}| < theta_over = {block.theta_over:.6g} "
                         f"(got {theta0:g}): the block would start overturned")
    return theta0


#: Blocks made from plain numbers, by their arguments: a Block is immutable and validated once
#: (its checks were a sixth of a short run's fixed cost, issue 16).
_BLOCKS = {}
_PLAIN = (float, int, str, type(None))


def make_block(hb, alpha, omega, law=None, e=None, xi=None, theta_over=0.5 * math.pi,
               rest_speed=1e-6):
    """A :class:`Block` from the API's keyword arguments (``xi=None``: the study's value)."""
    key = (hb, alpha, omega, law, e, xi, theta_over, rest_speed)
    plain = all(type(v) in _PLAIN for v in key)
    if plain:
        block = _BLOCKS.get(key)
        if block is not None:
            return block
    kw = dict(hb=hb, alpha=alpha, omega=omega, law=law, e=e, theta_over=theta_over,
              rest_speed=rest_speed)
    if xi is not None:
        kw["xi"] = xi
    block = Block(**kw)
    if plain:
        if len(_BLOCKS) >= 1024:
            _BLOCKS.clear()
        _BLOCKS[key] = block
    return block


@dataclass(frozen=True)
class RunPlan:
    """A validated single run: everything :func:`run` needs, nothing left to check."""

    block: Block
    y0: tuple            # (theta0, dtheta0, r0, s0)
    phi: float
    forcing: str
    method: str          # "rockjit" or "scipy:<METHOD>"
    rtol: float
    atol: float
    periods: int
    n_steps: int
    window: int
    max_impacts: int
    record_stride: int | None
    lyapunov: bool
    qr_every: int | None
    memory_bytes: float
    stop_at_overturn: bool = True


def _method(method):
    if method == "rockjit":
        return method
    if isinstance(method, str) and (method == "scipy" or method.startswith("scipy:")):
        name = method.split(":", 1)[1] if ":" in method else "BDF"
        if name not in IVP_METHODS:
            raise ValueError(f"method must be 'rockjit', 'scipy' or 'scipy:<one of "
                             f"{', '.join(IVP_METHODS)}>' (got {method!r})")
        return f"scipy:{name}"
    raise ValueError(f"method must be 'rockjit', 'scipy' or 'scipy:<one of "
                     f"{', '.join(IVP_METHODS)}>' (got {method!r})")


def run_settings(block, periods, n_steps, default_n, max_impacts, window):
    """The settings every run and grid shares, validated: ``(periods, n_steps, max_impacts,
    window)``. ``n_steps=None`` gives ``default_n``, raised for slow forcing and strong
    damping; an explicit one must be even, at least 8, and stable (:func:`check_step`)."""
    periods = integer("periods", periods, 1, MAX_PERIODS)
    if n_steps is None:
        n_steps = steps_per_period(block.period, default_n, block.xi)
    else:
        n_steps = integer("n_steps", n_steps, 8, MAX_N)
        if n_steps % 2:
            raise ValueError(f"n_steps must be even, so that t = kT + T/2 is on the grid "
                             f"(got {n_steps})")
    max_impacts = default_max_impacts(periods) if max_impacts is None else \
        integer("max_impacts", max_impacts, 1, 2**62)
    w0 = int(round(0.8 * periods)) if window is None else \
        integer("window", window, 0, periods - 1)
    return periods, n_steps, max_impacts, w0


def plan(hb, alpha, omega, law=None, *, e=None, xi=None, theta0=None, dtheta0=None, z0=None,
         phase=None, r0=None, s0=None, periods=500, n_steps=None, forcing="closed",
         method="rockjit", rtol=1e-6, atol=1e-9, lyapunov=False, window=None,
         record_stride=None, max_impacts=None, theta_over=0.5 * math.pi, rest_speed=1e-6,
         qr_every=None, stop_at_overturn=True) -> RunPlan:
    """Validate the inputs of :func:`simulate` (same parameters) into a :class:`RunPlan`.

    Raises ``ValueError`` naming the parameter for anything out of range, for a grid too coarse
    to integrate stably, and for a run whose arrays would not fit in memory.
    """
    theta0, dtheta0, r0, s0 = initial_state(theta0, dtheta0, z0, r0, s0, phase)
    dtheta0 = real("dtheta0", dtheta0, -1e6, 1e6)
    block = make_block(hb, alpha, omega, law, e, xi, theta_over, rest_speed)
    theta0 = check_theta0(theta0, block)
    phi, r0, s0 = forcing_phase(phase, r0, s0, forcing)
    method = _method(method)
    periods, n_steps, max_impacts, w0 = run_settings(block, periods, n_steps, DEFAULT_N,
                                                     max_impacts, window)
    check_step(block.period, n_steps, forcing, math.hypot(r0, s0), block.xi)
    if record_stride is not None:
        record_stride = integer("record_stride", record_stride, 1, 2**62)
    if qr_every is not None:
        qr_every = integer("qr_every", qr_every, 0, 2**62)
    lyapunov = bool(lyapunov)
    if method != "rockjit":
        if lyapunov:
            raise ValueError("lyapunov=True is only available with method='rockjit'")
        rtol = real("rtol", rtol, 0.0, 1.0, lo_open=True, hi_open=True)
        atol = real("atol", atol, 0.0, None, lo_open=True)
    n_traj = periods * n_steps // record_stride + 1 if record_stride else 1
    nbytes = kernel.run_bytes(periods, n_steps, max_impacts, n_traj, lyapunov)
    memory(f"periods = {periods} at n_steps = {n_steps}", nbytes)
    if periods * n_steps > 2**62:
        raise ValueError(f"periods * n_steps must be <= 2**62 (got {periods} * {n_steps})")
    return RunPlan(block=block, y0=(theta0, dtheta0, r0, s0), phi=phi, forcing=forcing,
                   method=method, rtol=float(rtol), atol=float(atol), periods=periods,
                   n_steps=n_steps, window=w0, max_impacts=max_impacts,
                   record_stride=record_stride, lyapunov=lyapunov, qr_every=qr_every,
                   memory_bytes=nbytes, stop_at_overturn=bool(stop_at_overturn))


def run(p: RunPlan) -> Result:
    """Execute a :class:`RunPlan` on its path (compiled or scipy)."""
    theta0, dtheta0, r0, s0 = p.y0
    if p.method != "rockjit":
        from .reference import simulate_scipy  # scipy.integrate only when asked for
        return simulate_scipy(p.block, theta0, dtheta0, p.phi, r0, s0, periods=p.periods,
                              n_steps=p.n_steps, forcing=p.forcing,
                              ivp_method=p.method.split(":", 1)[1], rtol=p.rtol, atol=p.atol,
                              record_stride=p.record_stride, max_impacts=p.max_impacts,
                              stop_at_overturn=p.stop_at_overturn)
    return kernel.run_single(p.block, (theta0, dtheta0, r0, s0), p.phi, n_steps=p.n_steps,
                             periods=p.periods, window=p.window, max_impacts=p.max_impacts,
                             record_stride=p.record_stride, embed4=p.forcing == "embedded",
                             lyapunov=p.lyapunov, qr_every=p.qr_every,
                             stop_at_overturn=p.stop_at_overturn)


def simulate(hb, alpha, omega, law=None, *, e=None, xi=None, theta0=None, dtheta0=None,
             z0=None, phase=None, r0=None, s0=None, periods=500, n_steps=None,
             forcing="closed", method="rockjit", rtol=1e-6, atol=1e-9, lyapunov=False,
             window=None, record_stride=None, max_impacts=None,
             theta_over=0.5 * math.pi, rest_speed=1e-6, qr_every=None,
             stop_at_overturn=True) -> Result:
    """Simulate the harmonically forced rocking block.

    Parameters
    ----------
    hb, alpha, omega : float
        Slenderness, forcing amplitude and frequency (SPEC.md §1); see :class:`Block`.
    law : {"housner", "mao", "constant"}, optional
        Restitution law; ``e`` alone implies ``"constant"``.
    e : float, optional
        Constant coefficient of restitution in ``[0, 1]``.
    xi : float, optional
        Damping in ``[0, 1e4]``; default the study's ``2.208e-4``.
    theta0, dtheta0 : float, optional
        Initial angle (``|theta0| < theta_over``) and angular velocity. Default: the study's
        ``z0`` (SPEC.md §7).
    z0 : sequence of 4 floats, optional
        ``(theta0, dtheta0, r0, s0)`` at once, instead of the four separately.
    phase : float, optional
        Forcing phase ``phi`` in ``r = sin(omega t + phi)``; or give ``(r0, s0)``.
    r0, s0 : float, optional
        Initial point of the forcing oscillator; default ``(0, 1)``.
    periods : int
        Number of forcing periods to integrate (``>= 1``), default 500.
    n_steps : int, optional
        Steps per period ``N`` (even, ``>= 8``); default :data:`DEFAULT_N`, raised for slow
        forcing so that the step ``T/N`` stays below :data:`MAX_STEP`, and for strong damping
        so that ``3/4 xi T/N <= DAMPING_STEP``. An explicit N beyond the step's stability
        (:func:`check_step`) is refused, naming the N needed.
    forcing : {"closed", "embedded"}
        Closed-form forcing, or the 4-D oscillator embedding integrated with the block.
    method : str
        ``"rockjit"`` (compiled, fixed step) or ``"scipy"`` / ``"scipy:<METHOD>"`` for the
        reference path through ``scipy.integrate.solve_ivp`` (default BDF, the study's).
    rtol, atol : float
        Tolerances of the scipy path (ignored by the compiled one); ``0 < rtol < 1``,
        ``atol > 0``.
    lyapunov : bool
        Compute the block's Lyapunov exponents (SPEC.md §5); compiled path only.
    window : int, optional
        First period of the averaging window ``[window T, periods T]``; default 80 % of the run
        (the study's ``[400T, 500T]`` for 500 periods).
    record_stride : int, optional
        Record ``(t, theta, theta', r, s)`` every this many grid steps.
    max_impacts : int, optional
        Bound on the number of impacts; reaching it ends the run with status ``max_impacts``.
        Default :func:`default_max_impacts` (10,000 per period, at least 100,000).
    theta_over : float
        Overturning threshold on ``|theta|``, default ``pi/2``.
    rest_speed : float
        Zeno cut-off in ``(0, 0.1]``: an impact leaving with ``|theta'| < rest_speed`` puts the
        block at rest.
    qr_every : int, optional
        Grid steps between Gram–Schmidt renormalisations of the tangent vectors; default
        twice a period, or more often under strong damping (:func:`rockjit._engine.kernel.
        default_qr_every`); 0 never renormalises, so that ``result.extra["tangent"]`` is the
        Jacobian of the whole flow (zero across a rest phase; short runs, tests).
    stop_at_overturn : bool
        Stop when ``|theta|`` reaches ``theta_over`` (the physical rule, default). ``False``
        integrates on through the threshold with the same equations, as the study's own code
        did; ``result.t_overturn`` records the first crossing and the run counts as overturned
        (:func:`rockjit.grids.grids.classify_result`).

    Returns
    -------
    Result

    See Also
    --------
    rockjit.basins.fate.fate : ``K`` runs from nearby initial states, the same keywords: each
        outcome's probability and the predictability horizon.

    Raises
    ------
    ValueError
        For any parameter out of its range; the message names the parameter, the allowed range
        and the value given. Also for a run whose arrays would not fit in memory.
    """
    return run(plan(hb, alpha, omega, law, e=e, xi=xi, theta0=theta0, dtheta0=dtheta0, z0=z0,
                    phase=phase, r0=r0, s0=s0, periods=periods, n_steps=n_steps,
                    forcing=forcing, method=method, rtol=rtol, atol=atol, lyapunov=lyapunov,
                    window=window, record_stride=record_stride, max_impacts=max_impacts,
                    theta_over=theta_over, rest_speed=rest_speed, qr_every=qr_every,
                    stop_at_overturn=stop_at_overturn))
