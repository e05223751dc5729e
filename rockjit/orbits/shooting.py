"""Shooting: periodic orbits of the stroboscopic map as fixed points found by Newton's method.

A period-``p`` orbit of the forced block is a fixed point of ``P^p``, ``P`` the stroboscopic map
``(theta, theta')(kT) -> (theta, theta')((k+1)T)`` at a fixed forcing phase (docs/theory/global-dynamics.md). Every
integration goes through one method, :meth:`Flow.run`, a call of the public
:func:`rockjit.simulate`: a run with ``lyapunov=True`` and ``qr_every=0`` returns in
``result.extra["tangent"]`` the Jacobian of the flow over the run, the saltation matrix applied
at every impact, which over ``p`` periods is the monodromy matrix ``M`` whose eigenvalues are the
orbit's Floquet multipliers. The continuation (:mod:`.arclength`) and the location of
bifurcations (:mod:`.bifurcations`) are built on the same flow and solver.

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
    ``x(T/2) = -x(0)``, the documented definition; for even ``p`` no orbit is symmetric), checked at
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
    changes between Newton iterates near the solution (tolerances: :class:`Shooting`).
"""

from __future__ import annotations

import math

import numpy as np

from ..excitation import Harmonic
from ..grids import plan as gp
from ..model import Block
from ..settings import Integration
from ..single import simulate
from ..validate import integer
from .types import OrbitRefused, PeriodicOrbit, Shooting

__all__ = ["N_ORBIT", "periodic_orbit"]

#: Steps per forcing period of the shooting runs. On orbits sampled along every branch of the
#: hb=1 Housner case over alpha in [0.5, 1.0] (periods 1 to 8, |mu| up to 50), the fixed
#: points found at N = 384 have residuals of at most 2.4e-11 in a converged plain run
#: (N = 8192), against 2.2e-10 at N = 256 and 2.4e-9 at N = 160 (benchmarks/bench_orbits.py);
#: a step costs little beside the fixed cost of a call (+13 % for the continuation over 256).
N_ORBIT = 384

_TWO_PI = 2.0 * math.pi


# ---------------------------------------------------------------------------------------------
# input checks, shared with the continuation
# ---------------------------------------------------------------------------------------------

def check_block(block):
    """``block``, if it is a :class:`rockjit.Block`."""
    if not isinstance(block, Block):
        raise ValueError(f"block must be a rockjit.Block (got {type(block).__name__})")
    return block


def check_forcing(forcing, *names, why):
    """The closed-form :class:`rockjit.Harmonic` with ``names`` given (``-name``: left out)
    and its phase: ``forcing.phase``, or that of its ``(r0, s0)``, else 0."""
    forcing = gp.harmonic(forcing, *names, why=why)
    return forcing, forcing.start()[0]


def check_n_steps(n_steps, hi=None):
    """Steps per period: even, ``>= 8``."""
    n_steps = integer("n_steps", n_steps, 8, hi)
    if n_steps % 2:
        raise ValueError(f"n_steps must be even (got {n_steps})")
    return n_steps


def check_shooting(shooting):
    """``shooting``, or the default :class:`Shooting`."""
    shooting = Shooting() if shooting is None else shooting
    if not isinstance(shooting, Shooting):
        raise ValueError(f"shooting must be a rockjit.orbits.Shooting "
                         f"(got {type(shooting).__name__})")
    return shooting


def check_state(name, x0, p):
    """A seed ``(theta, theta')``, or the first point of a ``(p, 2)`` cycle."""
    x = np.asarray(x0, dtype=float)
    if x.shape == (p, 2):
        x = x[0]
    if x.shape != (2,):
        raise ValueError(f"{name} must be (theta, theta') or a cycle of shape (p, 2) "
                         f"(got shape {x.shape})")
    if not np.all(np.isfinite(x)):
        raise ValueError(f"{name} must be finite (got {x.tolist()})")
    return x.copy()


def _sorted_mult(M):
    mu = np.linalg.eigvals(M)
    return mu[np.argsort(-np.abs(mu), kind="stable")].astype(complex)


# ---------------------------------------------------------------------------------------------
# the flow: every integration of the package
# ---------------------------------------------------------------------------------------------

class Flow:
    """Runs of :func:`rockjit.simulate` for one block with a varying parameter ``lambda``.

    ``forcing`` holds the fixed forcing parameter (``omega`` when ``lambda`` is ``alpha``, and
    ``alpha`` when it is ``omega``); ``shooting`` the runs' impact bound per period, overturning
    threshold and Zeno cut-off."""

    def __init__(self, block, forcing, parameter, n_steps, phase, shooting):
        self.block = block
        self.forcing = forcing
        self.parameter = parameter
        self.N = n_steps
        self.phase = phase  # the output phase; the computational one is phase + 2 pi j / N
        self.imp = shooting.max_impacts_per_period
        self.theta_over = shooting.theta_over
        self.rest_speed = shooting.rest_speed
        self.calls = 0
        self._integrations = {}

    def params(self, lam):
        if self.parameter == "alpha":
            return lam, self.forcing.omega
        return self.forcing.alpha, lam

    def valid(self, lam):
        return lam > 0 if self.parameter == "omega" else lam >= 0

    def period(self, lam):
        return _TWO_PI / self.params(lam)[1]

    def integration(self, periods, tangent):
        """The :class:`rockjit.Integration` of a run (made once per length and kind)."""
        key = (periods, tangent)
        if key not in self._integrations:
            self._integrations[key] = Integration(
                periods=periods, n_steps=self.N, qr_every=0 if tangent else None,
                max_impacts=self.imp * periods, theta_over=self.theta_over,
                rest_speed=self.rest_speed)
        return self._integrations[key]

    def run(self, x, lam, periods, j, tangent):
        """``periods`` periods from ``x`` at phase ``phase + 2 pi j / N``, trajectory recorded."""
        alpha, omega = self.params(lam)
        self.calls += 1
        return simulate(self.block, Harmonic(alpha=alpha, omega=omega,
                                             phase=self.phase + _TWO_PI * j / self.N),
                        (float(x[0]), float(x[1])),
                        integration=self.integration(periods, tangent), lyapunov=tangent,
                        record_stride=1)


def failure(r):
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


class Eval:
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


class Info:
    """What is known about a converged orbit (from its tangent run over one cycle)."""

    __slots__ = ("M", "mu", "stable", "nimp", "cycle", "half", "scale", "sym_defect",
                 "symmetric", "max_theta", "min_speed", "near_miss", "t_next", "t_next_half",
                 "traj", "imp_o", "T", "psi", "run")


# ---------------------------------------------------------------------------------------------
# the solver: residuals, Newton, analysis of an orbit
# ---------------------------------------------------------------------------------------------

class Solver:
    """Shooting residuals (full and half map), Newton's method, and what a converged run says
    about its orbit."""

    def __init__(self, flow, shooting, *, fd_rel=1e-7):
        self.flow = flow
        self.shooting = shooting
        self.N = flow.N
        self.tol = shooting.tol
        self.sym_tol = shooting.sym_tol
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
        why = failure(r)
        if why:
            return Eval(False, why, r=r)
        return Eval(True, F=r.strobe[p, :2] - x, M=r.extra["tangent"], r=r, x=x, lam=lam)

    def sym(self, x, lam, p, j):
        """``F = x + Phi_{pT/2}(x)``, the half map's residual (``p`` odd)."""
        m = (p - 1) // 2
        r = self.flow.run(x, lam, m + 1, j, False)
        why = failure(r)
        if why:
            return Eval(False, why, r=r)
        return Eval(True, F=x + r.strobe_half[m, :2], r=r, x=x, lam=lam)

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
    def newton(self, x, lam, p, j, scale, max_iter=40, near=1e-6, count=None):
        """Damped Newton on ``P^p(x) = x`` at fixed ``lambda``; returns ``(ev, iterations)``.

        ``count``: the orbit with this many impacts per cycle only (followed up to a
        grazing): the seed must have it, and a trial step with another count is halved like
        one that does not decrease ``|F|``. Raises :class:`OrbitRefused`.
        """
        ev = self.full(x, lam, p, j)
        if not ev.ok:
            raise OrbitRefused(ev.reason, "at the seed")
        if count is not None and ev.nimp != count:
            raise OrbitRefused("grazing", f"the seed has {ev.nimp} impacts per cycle, not "
                                          f"{count}")
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
                if et.ok and (count is None or et.nimp == count):
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
            x = ev.x + dx
            # near a fold M - I is nearly singular and the step can leave the bounded region,
            # where no run starts: the orbit stays as converged
            if not (np.all(np.isfinite(x)) and abs(x[0]) < self.flow.theta_over):
                break
            et = self.full(x, lam, p, j)
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
        info = Info()
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
        if lo.any() and imp.shape[0]:
            # not where an excursion touched down twice and came back between grid points
            tt = r.trajectory[:, 0]
            k = np.nonzero(lo)[0] + 1
            hit = ((imp[None, :, 0] > tt[k - 1, None]) &
                   (imp[None, :, 0] <= tt[k + 1, None])).any(1)
            lo[k[hit] - 1] = False
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
        block=block, forcing=Harmonic(alpha=alpha, omega=omega, phase=phase))


def shoot(solver, x0, lam, p, refuse_grazing=True):
    """Shooting from ``x0`` at the output phase, with the solver's :class:`Shooting` settings;
    returns ``(info, x, j, residual, iters)``."""
    flow = solver.flow
    st = solver.shooting
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
    ev, iters = solver.newton(x, lam, p, j, scale, max_iter=st.max_iter)
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
        if info.min_speed < st.graze_tol:
            raise OrbitRefused("grazing", f"an impact with |theta'-| = {info.min_speed:.3g} "
                                          "of the orbit's largest |theta'|")
        if info.near_miss < st.graze_tol:
            raise OrbitRefused("grazing", f"|theta| turns at {info.near_miss:.3g} of its "
                                          "largest value without impact")
        if info.max_theta >= flow.theta_over * (1.0 - st.over_tol):
            raise OrbitRefused("grazing", f"max |theta| = {info.max_theta:.6g} touches "
                                          f"theta_over = {flow.theta_over:.6g}")
    return info, ev.x.copy(), j, res, iters


def periodic_orbit(block, forcing, x0, p=1, *, n_steps=N_ORBIT,
                   shooting=None) -> PeriodicOrbit:
    """A period-``p`` orbit of the stroboscopic map by Newton's method (shooting).

    Parameters
    ----------
    block : Block
        The block: slenderness, restitution law, damping.
    forcing : Harmonic
        The excitation with its ``alpha`` and ``omega`` (closed form). Its phase is the
        section's, ``r = sin(omega t + phase)``: ``forcing.phase``, or that of its
        ``(r0, s0)``; neither: 0, i.e. ``(r0, s0) = (0, 1)``.
    x0 : array_like, shape (2,) or (p, 2)
        Seed ``(theta, theta')`` at ``t = 0`` (a settled sweep cell, or any guess); of a cycle
        the first point is used.
    p : int
        Period in forcing periods, in ``[1, 256]``.
    n_steps : int
        Steps per period (even, ``>= 8``), default :data:`N_ORBIT`.
    shooting : Shooting, optional
        Newton's tolerance and iterations, the symmetry and grazing tolerances, the runs'
        impact bound, overturning threshold and Zeno cut-off (:class:`Shooting`, its defaults
        when not given).

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

    Examples
    --------
    The study's asymmetric orbit (``h/b = 1``, ``alpha = 0.8``), stable, from a rough seed;
    and from another seed the symmetric orbit, unstable beyond its pitchfork:

    >>> from rockjit import Block, Harmonic
    >>> from rockjit.orbits import periodic_orbit
    >>> block, forcing = Block(hb=1), Harmonic(alpha=0.8, omega=1.3)
    >>> o = periodic_orbit(block, forcing, (-0.44, -0.36))
    >>> o.stable, o.symmetric, o.impacts, o.state.round(4).tolist()
    (True, False, 2, [-0.4421, -0.3643])
    >>> [round(float(abs(m)), 4) for m in o.multipliers]
    [0.7492, 0.0052]
    >>> s = periodic_orbit(block, forcing, (-0.3, -0.3))
    >>> s.stable, s.symmetric, round(float(abs(s.multipliers[0])), 4)
    (False, True, 1.1218)
    """
    block = check_block(block)
    forcing, phase = check_forcing(forcing, "alpha", "omega", why="a periodic orbit")
    p = integer("p", p, 1, 256)
    x0 = check_state("x0", x0, p)
    n_steps = check_n_steps(n_steps)
    shooting = check_shooting(shooting)
    flow = Flow(block, forcing, "alpha", n_steps, phase, shooting)
    solver = Solver(flow, shooting)
    info, x, j, res, iters = shoot(solver, x0, forcing.alpha, p)
    return _orbit_from(info, solver, x, forcing.alpha, p, j, res, iters, phase, block)
