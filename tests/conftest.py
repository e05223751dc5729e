"""Shared helpers of the test suite: independent references that never import rockjit.model.

``spec_run`` integrates the rocking block from the equations of docs/theory/model.md and impacts.md, written out here a
second time, with ``scipy.integrate.solve_ivp`` (DOP853, tight tolerances), a terminal event on
``theta = 0`` and on ``|theta| = theta_over``, and a restart after each impact. It knows nothing of
rest or uplift (the runs it is used on have none before the horizon), so it is short enough to
read in one sitting: that is the point of it.
"""

from __future__ import annotations

import math
from types import SimpleNamespace

import numpy as np
import pytest
from scipy.integrate import solve_ivp

#: The study's initial state (docs/theory/study.md), typed in from the study, not imported from rockjit.
Z0_SPEC = (-0.2254, -0.1597, -0.7778, 0.6284)
PHI_SPEC = math.atan2(Z0_SPEC[2], Z0_SPEC[3])


def e_housner_spec(hb):
    """docs/theory/impacts.md: ``1 - 1.5 cos^2(thc)``."""
    return 1.0 - 1.5 * math.cos(math.atan(hb)) ** 2


def e_mao_spec(hb):
    """docs/theory/impacts.md: ``sqrt(N / D)``."""
    thc = math.atan(hb)
    t = math.tan(thc)
    n = t * (t**2 - 3.0) + 3.0 * t**4 * (math.pi / 2 - thc) + 3.0 * thc
    d = 4.0 * t / math.cos(thc) ** 2
    return math.sqrt(n / d)


def theta_ddot_spec(t, theta, dtheta, side, hb, aw2, omega, phi, xi):
    """docs/theory/model.md, the two corners written separately."""
    thc = math.atan(hb)
    f = aw2 * math.sin(omega * t + phi)
    if side > 0:
        return 0.75 * (f * math.sin(thc + theta) - math.cos(thc + theta) - xi * dtheta)
    return 0.75 * (f * math.sin(thc - theta) + math.cos(thc - theta) - xi * dtheta)


def spec_run(hb, alpha, omega, e, *, theta0, dtheta0, phi, t_end, xi=0.0, t0=0.0, side=None,
             theta_over=0.5 * math.pi, rtol=1e-12, atol=1e-13, dense=False,
             max_impacts=None, max_step=0.01):
    """Event-driven reference integration of docs/theory/model.md, impacts.md (no rest, no uplift).

    Stops at ``t_end``, on overturning, or after ``max_impacts`` impacts (status "impacts").
    ``max_step`` bounds the solver's steps: solve_ivp looks for events only as sign changes
    between step ends, so a dip through ``theta = 0`` shorter than a step would go unseen.
    Returns a dict with ``status``, ``t``, ``y`` (theta, theta'),
    ``impacts`` (rows ``t, theta'-, theta'+``) and, with ``dense``, the list of
    ``(t_start, t_stop, sol)`` flight segments.
    """
    aw2 = alpha * omega**2
    if side is None:
        side = int(np.sign(theta0) or np.sign(dtheta0))
    assert side != 0, "spec_run does not start at rest"

    def rhs(t, y, s):
        return [y[1], theta_ddot_spec(t, y[0], y[1], s, hb, aw2, omega, phi, xi)]

    t = float(t0)
    y = np.array([theta0, dtheta0], dtype=float)
    impacts = []
    segments = []
    status = "done"
    while t < t_end:
        def hit(tt, yy, s):
            return s * yy[0]
        hit.terminal, hit.direction = True, -1

        def over(tt, yy, s):
            return theta_over - s * yy[0]
        over.terminal, over.direction = True, -1

        sol = solve_ivp(rhs, (t, t_end), y, method="DOP853", rtol=rtol, atol=atol,
                        events=(hit, over), args=(side,), dense_output=dense,
                        max_step=max_step)
        assert sol.status >= 0, sol.message
        if dense:
            segments.append((t, float(sol.t[-1]), sol.sol))
        if sol.status == 0:
            t, y = t_end, sol.y[:, -1]
            break
        if len(sol.t_events[1]):
            t, y = float(sol.t_events[1][0]), sol.y_events[1][0]
            status = "overturned"
            break
        t = float(sol.t_events[0][0])
        dm = float(sol.y_events[0][0][1])
        dp = e * dm
        impacts.append((t, dm, dp))
        y = np.array([0.0, dp])
        side = -side
        if max_impacts is not None and len(impacts) >= max_impacts:
            status = "impacts"
            break
        assert abs(dp) > 1e-6, "spec_run reached a Zeno cascade; choose another run"
    return dict(status=status, t=t, y=np.asarray(y, dtype=float),
                impacts=np.array(impacts).reshape(-1, 3), segments=segments)


def first_uplift(t0, aw2, cot, omega, phi):
    """First ``t >= t0`` with ``|aw2 sin(omega t + phi)| > cot``, and the sign of f there.

    Written from scratch: the uplift instants are ``psi = asin(cot/aw2) + k pi``.
    """
    a = math.asin(cot / aw2)
    psi0 = omega * t0 + phi
    if abs(aw2 * math.sin(psi0)) > cot:
        return t0, int(np.sign(math.sin(psi0)))
    k = math.ceil((psi0 - a) / math.pi)
    return (a + k * math.pi - phi) / omega, (-1) ** (k % 2)


@pytest.fixture(scope="session")
def spec():
    """The independent references, as one namespace."""
    return SimpleNamespace(run=spec_run, e_housner=e_housner_spec, e_mao=e_mao_spec,
                           theta_ddot=theta_ddot_spec, first_uplift=first_uplift,
                           z0=Z0_SPEC, phi=PHI_SPEC)
