"""The grazing condition of a periodic orbit: how near one of its excursions comes to
``theta = 0`` (or to ``theta_over``) without reaching it, and, for a run that crossed, how far
beyond it went. Shared by the one-parameter location of grazings (:mod:`.bifurcations`) and
the grazing curves in the plane (:mod:`.curves`).

Definitions and choices
-----------------------
Depth
    The turning point of ``|theta|`` nearest ``theta = 0`` with no impact on either side of it
    within the grid step (a double impact can leave ``theta``'s sign as it was at the two grid
    points), found on the run's grid and refined by quintic Hermite interpolation from
    ``theta``, ``theta'`` and ``theta''`` (the equations of motion, :func:`rockjit.model.accel`)
    at the two grid points around it: error ``O(h^6)``, ``h = T/N``. For ``|theta|`` near
    ``theta_over``, the largest turning point, ``theta_over - |theta|``. It is smooth on the
    side where the excursion does not reach the threshold; at the grazing it is 0.
Deficit
    Across a grazing the excursion reaches ``theta = 0`` at a speed ``v``, touches down twice
    (or rests, below the Zeno cut-off) and comes back. ``v^2 / 2|theta''|``, with the slowest
    impact's speed, estimates how far the free flight would have gone beyond: proportional to
    the depth's continuation through 0 (the constant does not matter to the secant method of
    :func:`push_onto`, which finds where it extrapolates to 0).
"""

from __future__ import annotations

import math

import numpy as np

from ..model import accel

#: Nothing here is called by users.
__all__: list[str] = []

_TWO_PI = 2.0 * math.pi


def _quintic(h, p0, d0, s0, p1, d1, s1):
    """Coefficients (highest first, in ``u = (t - t0) / h``) of the quintic Hermite
    interpolant with values, first and second derivatives at both ends."""
    # basis polynomials, highest degree first
    H = np.array([[-6, 15, -10, 0, 0, 1], [-3, 8, -6, 0, 1, 0],
                  [-0.5, 1.5, -1.5, 0.5, 0, 0], [0.5, -1, 0.5, 0, 0, 0],
                  [-3, 7, -4, 0, 0, 0], [6, -15, 10, 0, 0, 0]], float)
    w = np.array([p0, h * d0, h * h * s0, h * h * s1, h * d1, p1])
    return w @ H


def _turning(poly):
    """``(u, value)`` at the root in ``[0, 1]`` of the interpolant's derivative (bisection
    refined by Newton), where the derivative changes sign across the interval."""
    dp = np.polyder(poly)
    ddp = np.polyder(dp)
    lo, hi = 0.0, 1.0
    flo = np.polyval(dp, lo)
    for _ in range(30):
        mid = 0.5 * (lo + hi)
        fm = np.polyval(dp, mid)
        if (fm > 0) == (flo > 0):
            lo, flo = mid, fm
        else:
            hi = mid
    u = 0.5 * (lo + hi)
    for _ in range(3):
        d2 = np.polyval(ddp, u)
        if d2 == 0:
            break
        u = min(1.0, max(0.0, u - np.polyval(dp, u) / d2))
    return u, float(np.polyval(poly, u))


class Depth:
    """The grazing condition of a run: the refined depth of its turning point nearest
    ``theta = 0`` (``kind="impact"``) or nearest ``|theta| = theta_over`` (``"overturn"``).

    ``half``: a symmetric orbit, whose condition is read off the half map's stretch, the first
    ``p/2`` periods (the other half is its mirror image at the solution; the smaller of the
    two depths would not be smooth on the way there)."""

    def __init__(self, block, flow, kind, p, half):
        self.kind = kind
        self.thc = block.thc
        self.xi = block.xi
        self.flow = flow
        self.p = p
        self.half = half

    def window(self, r, lam):
        """The run's trajectory and impacts over the stretch the condition is read on."""
        tr, imp = r.trajectory, r.impacts
        if self.half:
            n = self.p * self.flow.N // 2
            tr = tr[:n + 1]
            imp = imp[imp[:, 0] < self.p * self.flow.period(lam) / 2]
        return tr, imp

    def count(self, r, lam):
        """Impacts over the stretch."""
        return int(self.window(r, lam)[1].shape[0])

    def deficit(self, r, lam, j):
        """How far a run that crossed the threshold went beyond it, estimated as the depth
        ``v^2 / 2|theta''|`` of the free flight through the crossing at speed ``v`` (the
        slowest impact, or the speed at overturning), or ``None``."""
        alpha, omega = self.flow.params(lam)
        phi = self.flow.phase + _TWO_PI * j / self.flow.N
        if self.kind == "impact":
            imp = self.window(r, lam)[1]
            if imp.shape[0] == 0:
                return None
            k = int(np.argmin(np.abs(imp[:, 1])))
            t, v = float(imp[k, 0]), float(imp[k, 1])
            theta, side = 0.0, (1 if v < 0 else -1)
        else:
            if r.status != "overturned":
                return None
            t, theta, v = float(r.t), float(r.state[0]), float(r.state[1])
            side = 1 if theta > 0 else -1
        v = max(abs(v), self.flow.rest_speed)
        f = alpha * omega * omega * math.sin(omega * t + phi)
        a = abs(accel(theta, v, f, side, self.thc, self.xi))
        return v * v / (2.0 * a) if a > 0 else None

    def __call__(self, r, lam, j):
        """The depth (``> 0`` on the side solved on), or ``None`` without such a turn."""
        alpha, omega = self.flow.params(lam)
        phi = self.flow.phase + _TWO_PI * j / self.flow.N
        tr, imps = self.window(r, lam)
        t, th, dth = tr[:, 0], tr[:, 1], tr[:, 2]
        s = np.sign(th)
        same = (s[:-1] == s[1:]) & (s[:-1] != 0)
        rate = s * dth  # d|theta|/dt
        if self.kind == "impact":
            k = np.nonzero(same & (rate[:-1] < 0) & (rate[1:] >= 0))[0]
        else:
            k = np.nonzero(same & (rate[:-1] > 0) & (rate[1:] <= 0))[0]
        if k.size == 0:
            return None
        imp = imps[:, 0]
        if imp.size:
            # no impact inside the interval (a double impact can leave theta's sign as it was)
            inside = ((imp[None, :] > t[k, None]) & (imp[None, :] <= t[k + 1, None])).any(1)
            k = k[~inside]
            if k.size == 0:
                return None
        a = np.abs(th)
        # the few candidates nearest the threshold, refined
        key = a[k] if self.kind == "impact" else -a[k]
        order = k[np.argsort(key)[:3]]
        best = None
        aw2 = alpha * omega * omega
        for i in order:
            vals = []
            for m in (i, i + 1):
                f = aw2 * math.sin(omega * t[m] + phi)
                side = 1 if th[m] > 0 else -1
                vals.append((th[m], dth[m], accel(th[m], dth[m], f, side, self.thc, self.xi)))
            (p0, d0, s0), (p1, d1, s1) = vals
            _, v = _turning(_quintic(t[i + 1] - t[i], p0, d0, s0, p1, d1, s1))
            v = abs(v)
            depth = v if self.kind == "impact" else self.flow.theta_over - v
            if best is None or depth < best:
                best = depth
        return best


def slow_pair(r, rel=0.05):
    """Whether a run has at least two impacts slower than ``rel`` times its largest
    ``|theta'|``: an excursion that touched down and came back."""
    if r.impacts.shape[0] < 2:
        return False
    vmax = max(float(np.abs(r.trajectory[:, 2]).max()), 1e-300)
    return int(np.count_nonzero(np.abs(r.impacts[:, 1]) < rel * vmax)) >= 2


def push_onto(evaluate, y, u, deficit, start=1e-11, max_move=1e-2, tries=8):
    """From ``y``, off a grazing condition's side with estimated ``deficit``, along ``u``
    (raising the condition by one per unit): the secant method on the deficit estimated at
    each trial, to just inside. ``evaluate(y)`` returns ``(ok, deficit, payload)``; the first
    valid payload is returned, else ``None``."""
    hist = [(0.0, deficit)]
    un = float(np.abs(u).max())
    for _ in range(tries):
        m2, d2 = hist[-1]
        m1, d1 = hist[-2] if len(hist) > 1 else (None, None)
        if d1 is not None and d2 is not None and d1 > 1.01 * d2:
            root = m2 + d2 * (m2 - m1) / (d1 - d2)  # where the deficit extrapolates to 0
            mu = root + 0.01 * (root - m2) + 1e-12
        elif m2 > 0:
            mu = 10.0 * m2
        else:
            mu = 20.0 * d2 if d2 else start
        if mu * un > max_move:
            return None
        ok, d, payload = evaluate(y + mu * u)
        if ok:
            return payload
        hist.append((mu, d))
    return None


def deficit_gradient(evaluate, y, deficit, n=2):
    """Forward differences of the estimated deficit in the first ``n`` components of ``y``
    (the state): ``(gradient, payload)``, the payload of a trial that was already valid, or
    ``(None, None)``."""
    g = np.zeros(len(y))
    for i in range(n):
        h = 1e-7 * max(1.0, abs(y[i]))
        y2 = np.array(y, float)
        y2[i] += h
        ok, d, payload = evaluate(y2)
        if ok:
            return None, payload
        if d is not None:
            g[i] = (d - deficit) / h
    return (g if np.any(g) else None), None
