"""``rockjit.simulate``: one run of the forced rocking block, compiled or through scipy."""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np

from . import integrate as ig
from .model import Block
from .model import _finite as _real

__all__ = ["Result", "simulate", "Z0_STUDY", "DEFAULT_N", "MAX_STEP", "STATUS_MESSAGES",
           "STEP_LIMIT", "check_step", "steps_per_period"]

#: Initial state ``(theta, theta', r, s)`` of the study's single runs and sweeps (SPEC.md §7).
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


def check_step(period, n_steps, forcing="closed", radius=1.0):
    """Reject a grid too coarse to integrate: ``ValueError`` naming ``n_steps``.

    Any forcing: ``h = T/N <= STEP_LIMIT``. The embedding also integrates the oscillator's
    radial contraction, of rate ``3 rho^2 - 1`` from radius ``rho``, which an explicit step
    only follows stably for ``h (3 rho^2 + 1) <= 1.5`` (found by the stress suite: beyond it
    r, s overflow).
    """
    h_max = STEP_LIMIT
    why = f"the step T/N must be <= {STEP_LIMIT}"
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


def steps_per_period(period, default):
    """``default``, or the smallest even N with ``period / N <= MAX_STEP`` if that is larger."""
    n = int(default)
    if period / n > MAX_STEP:
        n = 2 * math.ceil(period / (2 * MAX_STEP))
    return n

STATUS_MESSAGES = {
    "done": "reached the requested number of periods",
    "overturned": "the block overturned (|theta| reached theta_over)",
    "rest": "the block came to rest and the forcing can never lift it again "
            "(alpha * omega**2 <= cot(thc))",
    "max_impacts": "stopped at the impact bound max_impacts before the requested end",
    "nonfinite": "a non-finite number appeared; this is a bug, please report the inputs",
    "settled": "stopped early: the stroboscopic orbit settled on a periodic one",
}


@dataclass
class Result:
    """What one run produced. Arrays are views of exactly what was computed.

    Attributes
    ----------
    block : Block
        The validated parameters.
    method : str
        ``"rockjit"`` or ``"scipy:<solve_ivp method>"``.
    status : str
        One of ``done, overturned, rest, max_impacts, nonfinite, settled``; ``message`` says it
        in words.
    t : float
        Time reached (the overturning or rest instant for runs that stopped there).
    state : ndarray, shape (4,)
        ``(theta, theta', r, s)`` at ``t``.
    period : float
        Forcing period ``T``.
    n_steps : int
        Steps per period ``N`` (the compiled path's grid; also the scipy path's sampling grid).
    strobe : ndarray, shape (k, 4)
        ``(theta, theta', r, s)`` at ``t = 0, T, 2T, ...`` as far as the run went.
    strobe_half : ndarray, shape (k, 4)
        The same at ``t = T/2, 3T/2, ...``.
    impacts : ndarray, shape (m, 3)
        ``(t, theta'-, theta'+)`` of each impact, in order.
    n_impacts, n_grid_steps, n_rhs : int
        Counts of impacts, grid steps completed, right-hand-side evaluations.
    max_error_estimate : float
        Largest embedded 4th-order error estimate of ``theta, theta'`` over the run's steps
        (``nan`` on the scipy path).
    trajectory : ndarray, shape (p, 5) or None
        ``(t, theta, theta', r, s)`` every ``record_stride`` grid steps, when asked.
    lyapunov : ndarray, shape (2,) or None
        ``(lambda1, lambda2)`` averaged over ``window``, when asked.
    lyapunov_running : ndarray, shape (k, 2) or None
        The running estimate ``lambda(t)`` at ``t = 0, T, 2T, ...``.
    window : tuple of float or None
        ``(t0, t1)`` over which ``lyapunov`` was averaged.
    n_rest, n_rest_window : int
        Rest phases entered (Zeno cut-offs), overall and within ``window``.
    n_impacts_window : int
        Impacts within the window (for the exact identity of SPEC.md §5).
    """

    block: Block
    method: str
    status: str
    t: float
    state: np.ndarray
    period: float
    n_steps: int
    periods: int
    strobe: np.ndarray
    strobe_half: np.ndarray
    impacts: np.ndarray
    n_impacts: int
    n_grid_steps: int
    n_rhs: int
    max_error_estimate: float
    trajectory: np.ndarray | None = None
    lyapunov: np.ndarray | None = None
    lyapunov_running: np.ndarray | None = None
    window: tuple | None = None
    n_rest: int = 0
    n_rest_window: int = 0
    n_impacts_window: int = 0
    extra: dict = field(default_factory=dict)

    @property
    def message(self) -> str:
        return STATUS_MESSAGES[self.status]

    @property
    def lambda_max(self) -> float:
        """``lambda1`` over the window (``nan`` when exponents were not asked for)."""
        return math.nan if self.lyapunov is None else float(self.lyapunov[0])

    def __repr__(self) -> str:
        b = self.block
        return (f"Result({self.method}, hb={b.hb}, alpha={b.alpha}, omega={b.omega}, "
                f"law={b.law}, status={self.status!r}, t={self.t:.6g}, "
                f"impacts={self.n_impacts})")


def _int(name, value, lo, hi=None):
    try:
        ok = float(value) == int(value)
    except (TypeError, ValueError, OverflowError):
        ok = False
    if not ok or isinstance(value, bool):
        raise ValueError(f"{name} must be an integer (got {value!r})")
    value = int(value)
    if value < lo or (hi is not None and value > hi):
        rng = f">= {lo}" if hi is None else f"in [{lo}, {hi}]"
        raise ValueError(f"{name} must be {rng} (got {value})")
    return value


def forcing_phase(phase=None, r0=None, s0=None, forcing="closed"):
    """Resolve the forcing's initial condition into ``(phi, r0, s0)``.

    Give either ``phase`` (``r = sin(omega t + phase)``) or ``(r0, s0)``; the default is
    ``(r0, s0) = (0, 1)``. With the closed form, ``(r0, s0)`` must lie on the unit circle (to
    1e-3): off it only the embedding is meaningful (SPEC.md §1).
    """
    if forcing not in ("closed", "embedded"):
        raise ValueError(f"forcing must be 'closed' or 'embedded' (got {forcing!r})")
    if phase is not None:
        if r0 is not None or s0 is not None:
            raise ValueError("give either phase or (r0, s0), not both")
        phi = _real("phase", phase)
        return phi, math.sin(phi), math.cos(phi)
    if (r0 is None) != (s0 is None):
        raise ValueError("r0 and s0 go together: give both or neither")
    if r0 is None:
        r0, s0 = 0.0, 1.0
    r0 = _real("r0", r0)
    s0 = _real("s0", s0)
    rad = math.hypot(r0, s0)
    if rad == 0.0:
        raise ValueError("(r0, s0) must not be (0, 0): the forcing oscillator has no phase there")
    if forcing == "closed" and abs(rad - 1.0) > 1e-3:
        raise ValueError(
            f"(r0, s0) must lie on the unit circle for forcing='closed' (|(r0, s0)| = {rad:.6g});"
            " use forcing='embedded' for a start off the circle")
    return math.atan2(r0, s0), r0, s0


def initial_side(theta0, dtheta0):
    """The corner a run starts on: sign of theta0, else of theta0', else 0 (rest)."""
    if theta0 > 0.0 or (theta0 == 0.0 and dtheta0 > 0.0):
        return 1
    if theta0 < 0.0 or (theta0 == 0.0 and dtheta0 < 0.0):
        return -1
    return 0


def check_settings(periods, n_steps, max_impacts, window, record_stride):
    periods = _int("periods", periods, 1)
    n_steps = _int("n_steps", n_steps, 8)
    if n_steps % 2:
        raise ValueError(f"n_steps must be even, so that t = kT + T/2 is on the grid "
                         f"(got {n_steps})")
    max_impacts = _int("max_impacts", max_impacts, 1)
    if window is None:
        w0 = int(round(0.8 * periods))
    else:
        w0 = _int("window", window, 0, periods - 1)
    if record_stride is not None:
        record_stride = _int("record_stride", record_stride, 1)
    return periods, n_steps, max_impacts, w0, record_stride


def pack(block: Block, phi: float, n_steps: int):
    """The float parameter vector the compiled kernels read (layout in :mod:`integrate`)."""
    par = np.zeros(ig.N_PAR)
    par[ig.P_THC] = block.thc
    par[ig.P_XI] = block.xi
    par[ig.P_E] = block.restitution
    par[ig.P_AW2] = block.alpha * block.omega**2
    par[ig.P_OMEGA] = block.omega
    par[ig.P_PHI] = phi
    par[ig.P_COT] = block.cot
    par[ig.P_THOVER] = block.theta_over
    par[ig.P_REST] = block.rest_speed
    par[ig.P_H] = block.period / n_steps
    return par


def simulate(hb, alpha, omega, law=None, *, e=None, xi=None, theta0=None, dtheta0=None,
             z0=None, phase=None, r0=None, s0=None, periods=500, n_steps=None,
             forcing="closed", method="rockjit", rtol=1e-6, atol=1e-9, lyapunov=False,
             window=None, record_stride=None, max_impacts=100_000,
             theta_over=0.5 * math.pi, rest_speed=1e-6, qr_every=None) -> Result:
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
        Damping; default the study's ``2.208e-4``.
    theta0, dtheta0 : float, optional
        Initial angle and angular velocity. Default: the study's ``z0`` (SPEC.md §7).
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
        forcing so that the step ``T/N`` stays below :data:`MAX_STEP`.
    forcing : {"closed", "embedded"}
        Closed-form forcing, or the 4-D oscillator embedding integrated with the block.
    method : str
        ``"rockjit"`` (compiled, fixed step) or ``"scipy"`` / ``"scipy:<METHOD>"`` for the
        reference path through ``scipy.integrate.solve_ivp`` (default BDF, the study's).
    rtol, atol : float
        Tolerances of the scipy path (ignored by the compiled one).
    lyapunov : bool
        Compute the block's Lyapunov exponents (SPEC.md §5); compiled path only.
    window : int, optional
        First period of the averaging window ``[window T, periods T]``; default 80 % of the run
        (the study's ``[400T, 500T]`` for 500 periods).
    record_stride : int, optional
        Record ``(t, theta, theta', r, s)`` every this many grid steps.
    max_impacts : int
        Bound on the number of impacts; reaching it ends the run with status ``max_impacts``.
    theta_over : float
        Overturning threshold on ``|theta|``, default ``pi/2``.
    rest_speed : float
        Zeno cut-off: an impact leaving with ``|theta'| < rest_speed`` puts the block at rest.
    qr_every : int, optional
        Grid steps between Gram–Schmidt renormalisations of the tangent vectors; default
        ``n_steps // 2``; 0 renormalises only on entering rest, so that for a run without rest
        phases ``result.extra["tangent"]`` is the Jacobian of the whole flow (short runs, tests).

    Returns
    -------
    Result

    Raises
    ------
    ValueError
        For any parameter out of its range; the message names the parameter, the allowed range
        and the value given.
    """
    if z0 is not None:
        if theta0 is not None or dtheta0 is not None or r0 is not None or s0 is not None:
            raise ValueError("give z0 or (theta0, dtheta0, r0, s0), not both")
        z = np.asarray(z0, dtype=float).ravel()
        if z.shape != (4,):
            raise ValueError(f"z0 must have 4 entries (theta, theta', r, s) (got {z.size})")
        theta0, dtheta0, r0, s0 = (float(v) for v in z)
    elif theta0 is None and dtheta0 is None and r0 is None and s0 is None and phase is None:
        theta0, dtheta0, r0, s0 = Z0_STUDY
    theta0 = _real("theta0", 0.0 if theta0 is None else theta0)
    dtheta0 = _real("dtheta0", 0.0 if dtheta0 is None else dtheta0)
    kw = dict(hb=hb, alpha=alpha, omega=omega, law=law, e=e, theta_over=theta_over,
              rest_speed=rest_speed)
    if xi is not None:
        kw["xi"] = xi
    block = Block(**kw)
    phi, r0, s0 = forcing_phase(phase, r0, s0, forcing)
    if n_steps is None:
        n_steps = steps_per_period(block.period, DEFAULT_N)
    periods, n_steps, max_impacts, w0, record_stride = check_settings(
        periods, n_steps, max_impacts, window, record_stride)
    check_step(block.period, n_steps, forcing, math.hypot(r0, s0))

    if isinstance(method, str) and (method == "scipy" or method.startswith("scipy:")):
        if lyapunov:
            raise ValueError("lyapunov=True is only available with method='rockjit'")
        from .reference import simulate_scipy
        ivp_method = method.split(":", 1)[1] if ":" in method else "BDF"
        return simulate_scipy(block, theta0, dtheta0, phi, r0, s0, periods=periods,
                              n_steps=n_steps, forcing=forcing, ivp_method=ivp_method,
                              rtol=_real("rtol", rtol), atol=_real("atol", atol),
                              record_stride=record_stride, max_impacts=max_impacts)
    if method != "rockjit":
        raise ValueError(f"method must be 'rockjit', 'scipy' or 'scipy:<solve_ivp method>' "
                         f"(got {method!r})")

    embed4 = forcing == "embedded"
    run = ig.build(embed4=embed4, tangent=bool(lyapunov), record=record_stride is not None)
    par = pack(block, phi, n_steps)
    ipar = np.zeros(ig.N_IPAR, dtype=np.int64)
    ipar[ig.I_N] = n_steps
    ipar[ig.I_PERIODS] = periods
    ipar[ig.I_MAXIMP] = max_impacts
    ipar[ig.I_STRIDE] = record_stride or 1
    ipar[ig.I_WINDOW] = w0
    ipar[ig.I_QR] = n_steps // 2 if qr_every is None else _int("qr_every", qr_every, 0)
    y0 = np.array([theta0, dtheta0, r0, s0])
    strobe = np.zeros((periods + 1, 4))
    half = np.zeros((periods, 4))
    impacts = np.empty((max_impacts, 3))  # only the rows filled are exposed: no need to zero
    n_traj = periods * n_steps // record_stride + 1 if record_stride else 1
    traj = np.zeros((n_traj, 5))
    lam_run = np.zeros((periods + 1 if lyapunov else 1, 2))
    per_imp = np.zeros(periods + 1, dtype=np.int64)
    iout = np.zeros(ig.N_IOUT, dtype=np.int64)
    fout = np.zeros(ig.N_FOUT)
    code = run(y0, initial_side(theta0, dtheta0), par, ipar, strobe, half, impacts, traj,
               lam_run, per_imp, iout, fout)
    status = ig.STATUS_NAMES[int(code)]
    n_imp = int(iout[ig.O_IMPACTS])
    ns = int(iout[ig.O_NSTROBE])
    res = Result(
        block=block, method="rockjit", status=status, t=float(fout[ig.F_T]),
        state=fout[ig.F_TH:ig.F_S + 1].copy(), period=block.period, n_steps=n_steps,
        periods=periods, strobe=strobe[:ns], strobe_half=half[:int(iout[ig.O_NHALF])],
        impacts=impacts[:min(n_imp, max_impacts)], n_impacts=n_imp,
        n_grid_steps=int(iout[ig.O_STEPS]), n_rhs=int(iout[ig.O_RHS]),
        max_error_estimate=float(fout[ig.F_MAXERR]),
        trajectory=traj[:int(iout[ig.O_NTRAJ])] if record_stride else None,
        n_rest=int(iout[ig.O_NREST]), n_rest_window=int(iout[ig.O_NREST_WIN]),
        n_impacts_window=int(iout[ig.O_NIMP_WIN]),
    )
    if lyapunov:
        # the tangent matrix at the end: the flow's Jacobian since the last renormalisation
        res.extra["tangent"] = fout[ig.F_V:ig.F_V + 4].reshape(2, 2, order="F").copy()
        res.window = (w0 * block.period, res.t)
        res.lyapunov_running = lam_run[:ns]
        if status == "rest":
            # at rest for good every perturbation dies out in finite time
            res.lyapunov = np.array([-math.inf, -math.inf])
        else:
            # Gram-Schmidt's first column carries the largest growth only asymptotically; over
            # a finite window a (near-)degenerate pair may come out in either order
            res.lyapunov = np.sort(fout[ig.F_LAM1:ig.F_LAM2 + 1])[::-1].copy()
        res.lyapunov_running = -np.sort(-res.lyapunov_running, axis=1)
    return res
