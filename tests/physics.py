"""A second, slow statement of the rocking block's physics, for the tests only.

Nothing here imports rockjit: every formula is written again from its paper, in the plainest
Python and NumPy that states it, so that a mistake in ``rockjit.model`` (which both of rockjit's
integration paths share) cannot cancel out of a comparison. Speed is no concern.

Model (Housner 1963, "The behavior of inverted pendulum structures during earthquakes", Bull.
Seismol. Soc. Am. 53(2), 403-417; in dimensionless form, time in units of ``1/sqrt(g/R)``). A
rigid block of half-diagonal ``R`` whose diagonal makes the angle ``thc = arctan(h/b)`` with the
ground rocks on a base moving as ``A sin(Omega t)``; ``f(t) = alpha omega^2 sin(omega t + phi)``
is the base's acceleration in units of ``g``. With ``theta > 0`` on one corner and
``theta < 0`` on the other:

    theta > 0:  theta'' = 3/4 ( f sin(thc + theta) - cos(thc + theta) - xi theta' )
    theta < 0:  theta'' = 3/4 ( f sin(thc - theta) + cos(thc - theta) - xi theta' )

At ``theta = 0`` the pivot changes: ``theta'(+) = e theta'(-)`` (Housner 1963), with
``e = 1 - 3/2 cos^2(thc)`` (Housner 1963, conservation of angular momentum about the new corner)
or ``e = sqrt(N / D)`` (Mao et al. 2024, kinetic-energy redistribution at the impact). A block at
rest leaves it only when ``|f| > cot(thc) = b/h`` (Housner 1963), on the side of the sign of f.

Impacts in the tangent dynamics: the saltation matrix of an impact on the surface ``theta = 0``
(Müller 1995, "Calculation of Lyapunov exponents for dynamic systems with discontinuities",
Chaos, Solitons & Fractals 5(9), 1671-1681; di Bernardo, Budd, Champneys, Kowalczyk 2008,
*Piecewise-smooth Dynamical Systems*, §2.5) is ``S = G + (F+ - G F-) n^T / (n^T F-)`` with
``G = diag(1, e)`` the jump's Jacobian, ``n = (1, 0)`` the surface's normal and ``F-``, ``F+`` the
vector fields before and after; written out, ``S = [[e, 0], [(A+ - e A-) / theta'-, e]]`` with
``A-``, ``A+`` the angular accelerations on the old corner before the jump and on the new one
after it.

The stroboscopic map ``P`` takes ``(theta, theta')`` at ``t = kT`` to ``t = (k + 1)T``
(``T = 2 pi / omega``); the Floquet multipliers of a period-``p`` orbit are the eigenvalues of the
Jacobian of ``P^p`` at a cycle point (di Bernardo et al. 2008; Seydel 2010, *Practical
Bifurcation and Stability Analysis*). Here that
Jacobian comes from central finite differences of the slow integrator, never from a tangent
integration.
"""

from __future__ import annotations

import math

import numpy as np
from scipy.integrate import solve_ivp


# ---------------------------------------------------------------------------------------------
# restitution
# ---------------------------------------------------------------------------------------------

def e_housner(thc):
    """Housner (1963): ``e = 1 - 1.5 cos^2(thc)``."""
    return 1.0 - 1.5 * math.cos(thc) ** 2


def e_mao(thc):
    """Mao et al. (2024): ``e = sqrt(N / D)``,
    ``N = tan(thc)(tan^2(thc) - 3) + 3 tan^4(thc)(pi/2 - thc) + 3 thc``,
    ``D = 4 tan(thc) sec^2(thc)``."""
    t = math.tan(thc)
    sec = 1.0 / math.cos(thc)
    num = t * (t**2 - 3.0) + 3.0 * t**4 * (math.pi / 2.0 - thc) + 3.0 * thc
    den = 4.0 * t * sec**2
    return math.sqrt(num / den)


def delta_e_percent(e1, e2):
    """Symmetric percentage difference of two coefficients: ``|e1 - e2| / mean * 100``."""
    return abs(e1 - e2) / ((e1 + e2) / 2.0) * 100.0


#: The speed-softened Housner law's ``v_half`` as rockjit registers it under ``"speed"``.
V_HALF = 1.0


def restitution(law, thc, e=None):
    """The coefficient of the named law (``"housner"``, ``"mao"``, or ``"constant"`` with ``e``;
    ``"speed"``: Housner's, the coefficient of a slow impact)."""
    if law in ("housner", "speed"):
        return e_housner(thc)
    if law == "mao":
        return e_mao(thc)
    assert law == "constant" and e is not None
    return float(e)


# ---------------------------------------------------------------------------------------------
# equations of motion, jump, saltation, uplift
# ---------------------------------------------------------------------------------------------

def theta_ddot(theta, dtheta, f, side, thc, xi):
    """Housner (1963): the angular acceleration on corner ``side`` (+1: the corner of
    ``theta > 0``, -1: of ``theta < 0``), forcing acceleration ``f`` (in g)."""
    if side > 0:
        return 0.75 * (f * math.sin(thc + theta) - math.cos(thc + theta) - xi * dtheta)
    if side < 0:
        return 0.75 * (f * math.sin(thc - theta) + math.cos(thc - theta) - xi * dtheta)
    return 0.0  # at rest


def theta_ddot_partials(theta, dtheta, f, side, thc, xi):
    """The derivatives of :func:`theta_ddot` by ``theta``, ``theta'`` and ``f``, by hand."""
    if side > 0:
        return (0.75 * (f * math.cos(thc + theta) + math.sin(thc + theta)),
                -0.75 * xi,
                0.75 * math.sin(thc + theta))
    return (0.75 * (-f * math.cos(thc - theta) + math.sin(thc - theta)),
            -0.75 * xi,
            0.75 * math.sin(thc - theta))


def jump(dtheta_minus, e):
    """The impact on ``theta = 0`` (Housner 1963): ``theta'(+) = e theta'(-)``."""
    return e * dtheta_minus


def at_impact(law, e, dtheta_minus):
    """The coefficient of an impact at ``theta'(-)``: the block's ``e``, or for the speed law
    ``e / (1 + |theta'(-)| / V_HALF)``."""
    if law == "speed":
        return e / (1.0 + abs(dtheta_minus) / V_HALF)
    return e


def saltation_matrix(dtheta_minus, f, side_old, thc, xi, e):
    """Müller (1995) for the impact surface ``theta = 0``:
    ``S = [[e, 0], [(A+ - e A-) / theta'-, e]]``."""
    a_minus = theta_ddot(0.0, dtheta_minus, f, side_old, thc, xi)
    a_plus = theta_ddot(0.0, jump(dtheta_minus, e), f, -side_old, thc, xi)
    return np.array([[e, 0.0], [(a_plus - e * a_minus) / dtheta_minus, e]])


def forcing(t, alpha, omega, phi):
    """The base's acceleration in g, ``alpha omega^2 sin(omega t + phi)``."""
    return alpha * omega**2 * math.sin(omega * t + phi)


def lifts(f, cot):
    """Housner (1963): the block at rest is lifted when ``|f| > cot(thc) = b/h``."""
    return abs(f) > cot


def first_uplift(t0, aw2, omega, phi, cot, scan=400):
    """First ``t >= t0`` at which the forcing ``aw2 sin(omega t + phi)`` lifts a block at rest
    (threshold ``cot = cot(thc) = b/h``), by brute force.

    Scans the forcing over two periods in ``scan`` steps a period for the first sample with
    ``|f| > cot``, then bisects the bracket down to rounding. Returns ``t0`` when it already
    holds there, ``inf`` when ``aw2 <= cot`` (the largest ``|f|`` never exceeds the threshold).
    The returned time is the bracket's right end: ``|f| > cot`` holds there. The scan sees
    every window of uplift wider than ``T / scan`` (``aw2 > 1.0002 cot`` with the default).
    """
    def f(t):
        return aw2 * math.sin(omega * t + phi)

    if lifts(f(t0), cot):
        return t0
    if not aw2 > cot:
        return math.inf
    T = 2.0 * math.pi / omega
    dt = T / scan
    a = t0
    for k in range(1, 2 * scan + 1):
        b = t0 + k * dt
        if lifts(f(b), cot):
            break
        a = b
    else:
        raise AssertionError("no uplift within two periods although alpha omega^2 > cot")
    for _ in range(200):
        m = 0.5 * (a + b)
        if m <= a or m >= b:
            break
        if lifts(f(m), cot):
            b = m
        else:
            a = m
    return b


# ---------------------------------------------------------------------------------------------
# the slow reference integrator
# ---------------------------------------------------------------------------------------------

class Run:
    """What :func:`reference_run` found: ``status`` ("done", "rest", "overturned"), the time
    ``t`` reached, the final ``state``, ``strobe`` (rows ``theta, theta'`` at ``t = kT`` as far as
    the run went), ``impacts`` (rows ``t, theta'-, theta'+``), ``rests`` (the instants the block
    was put to rest) and ``uplifts`` (the instants it was lifted)."""

    def __init__(self, **kw):
        self.__dict__.update(kw)

    def __repr__(self):
        return (f"Run(status={self.status!r}, t={self.t:.6g}, impacts={len(self.impacts)}, "
                f"rests={len(self.rests)}, uplifts={len(self.uplifts)})")


def reference_run(hb, alpha, omega, *, law="housner", e=None, xi, theta0, dtheta0, phi=0.0,
                  periods, rest_speed=1e-6, theta_over=0.5 * math.pi, rtol=1e-12, atol=1e-12,
                  max_step=0.01, max_impacts=10_000):
    """Integrate the block over ``periods`` forcing periods from ``(theta0, theta0')`` at
    ``t = 0``, event by event, with ``scipy.integrate.solve_ivp`` (DOP853).

    Each flight is integrated on its corner until ``theta`` reaches 0 from that corner's side
    (an impact) or ``|theta|`` reaches ``theta_over`` (overturning); after an impact the jump is
    applied and the next flight starts on the other corner. An impact leaving with
    ``|theta'+| < rest_speed`` puts the block at rest (``theta = theta' = 0``): it stays there
    until ``|f| > cot(thc)`` and leaves on the side of the sign of ``f``, or for good when the
    forcing can never lift it. ``max_step`` bounds the solver's steps: ``solve_ivp`` sees an
    event only as a sign change between two step ends, so a dip through 0 and back shorter than
    a step would be missed. The start: the side is the sign of ``theta0``, else of ``theta0'``,
    else the block is at rest.
    """
    thc = math.atan(hb)
    e = restitution(law, thc, e)
    T = 2.0 * math.pi / omega
    t_end = periods * T
    t_strobe = T * np.arange(periods + 1)

    def rhs(t, y, side):
        return [y[1], theta_ddot(y[0], y[1], forcing(t, alpha, omega, phi), side, thc, xi)]

    def impact(t, y, side):
        return side * y[0]
    impact.terminal = True
    impact.direction = -1

    def overturn(t, y, side):
        return theta_over - side * y[0]
    overturn.terminal = True
    overturn.direction = -1

    t = 0.0
    y = np.array([theta0, dtheta0], dtype=float)
    side = int(np.sign(theta0)) or int(np.sign(dtheta0))
    strobe = {0: y.copy()}
    impacts, rests, uplifts = [], [], []
    status = "done"
    while t < t_end:
        if side == 0:
            t_up = first_uplift(t, alpha * omega**2, omega, phi, 1.0 / hb)
            if t_up == math.inf:
                status = "rest"  # for good: the run ends here
                break
            for k in np.flatnonzero((t_strobe > t) & (t_strobe <= min(t_up, t_end))):
                strobe[int(k)] = np.zeros(2)
            if t_up >= t_end:
                t = t_end
                break
            t = t_up
            side = 1 if forcing(t, alpha, omega, phi) > 0 else -1
            y = np.zeros(2)
            uplifts.append(t)
            continue
        ks = np.flatnonzero(t_strobe > t)
        sol = solve_ivp(rhs, (t, t_end), y, method="DOP853", rtol=rtol, atol=atol,
                        events=(impact, overturn), t_eval=t_strobe[ks], args=(side,),
                        max_step=max_step)
        assert sol.status >= 0, sol.message
        ys = np.asarray(sol.y, dtype=float).reshape(2, -1)  # at the strobe instants reached
        for k, yk in zip(ks, ys.T):
            strobe[int(k)] = yk.copy()
        if sol.status == 0:
            t, y = t_end, ys[:, -1].copy()
            break
        if len(sol.t_events[1]):
            t, y = float(sol.t_events[1][0]), sol.y_events[1][0].copy()
            status = "overturned"
            break
        t = float(sol.t_events[0][0])
        dm = float(sol.y_events[0][0][1])
        dp = jump(dm, at_impact(law, e, dm))
        impacts.append((t, dm, dp))
        side = -side
        y = np.array([0.0, dp])
        if abs(dp) < rest_speed:
            side = 0
            y = np.zeros(2)
            rests.append(t)
        if len(impacts) >= max_impacts:
            status = "max_impacts"
            break
    n = len(strobe)
    assert sorted(strobe) == list(range(n))
    return Run(status=status, t=t, state=np.asarray(y, dtype=float),
               strobe=np.array([strobe[k] for k in range(n)]).reshape(-1, 2),
               impacts=np.array(impacts, dtype=float).reshape(-1, 3),
               rests=np.array(rests), uplifts=np.array(uplifts), e=e, thc=thc)


# ---------------------------------------------------------------------------------------------
# the stroboscopic map and an independent monodromy
# ---------------------------------------------------------------------------------------------

def strobe_map(x, p, **params):
    """``P^p(x)``: ``(theta, theta')`` after ``p`` periods from ``x`` at ``t = 0``, and the
    number of impacts on the way."""
    r = reference_run(**params, theta0=float(x[0]), dtheta0=float(x[1]), periods=int(p))
    assert r.status == "done" and len(r.rests) == 0, r
    return r.state, len(r.impacts)


def monodromy_fd(x, p, rel=3e-6, **params):
    """The Jacobian of ``P^p`` at ``x`` by central differences of :func:`reference_run`.

    The step in both coordinates is ``rel`` times the size of ``x`` (its largest component).
    Its error is the truncation, ``~ h^2``, plus the reference's round-off (~1e-14 a run)
    over ``2h``: against a converged tangent integration, over 17 cycles of periods 1 to 3,
    the largest error of an entry was 2.6e-8 at ``rel = 1e-6``, 9e-9 at ``3e-6`` (the default)
    and 3.2e-8 at ``1e-5``. Every perturbed run must have as many impacts as the others (a
    perturbation that adds or removes an impact would straddle a grazing, where ``P^p`` is
    not differentiable). Returns ``(M, P^p(x))``.
    """
    x = np.asarray(x, dtype=float)
    h = rel * max(float(np.abs(x).max()), 1e-3)
    M = np.empty((2, 2))
    counts = set()
    for j in range(2):
        d = np.zeros(2)
        d[j] = h
        yp, n_p = strobe_map(x + d, p, **params)
        ym, n_m = strobe_map(x - d, p, **params)
        counts.update((n_p, n_m))
        M[:, j] = (yp - ym) / (2.0 * h)
    y0, n0 = strobe_map(x, p, **params)
    counts.add(n0)
    assert len(counts) == 1, f"the impact count changes under the perturbation: {counts}"
    return M, y0


def floquet_fd(x, p, rel=3e-6, **params):
    """Eigenvalues of :func:`monodromy_fd`: the Floquet multipliers of the cycle through
    ``x``."""
    M, _ = monodromy_fd(x, p, rel=rel, **params)
    return np.linalg.eigvals(M).astype(complex)


def match_pairs(a, b):
    """The largest difference between two pairs of complex numbers, matched to each other in
    the better of the two orders (not by sorting their moduli)."""
    a = np.asarray(a, dtype=complex)
    b = np.asarray(b, dtype=complex)
    return min(float(np.abs(a - b).max()), float(np.abs(a - b[::-1]).max()))
