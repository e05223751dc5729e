"""SUNDIALS CVODE peer, through scikit-sundae (``sksundae``): a root function on theta and a
restart at each impact.

What a user competent in CVODE writes: the rocking block's right-hand side on the state
``(theta, theta')`` as a Python callback filling ``yp`` (CVODE calls it through sksundae's
Cython wrapper), the corner ``side`` in the solver's ``userdata``; CVODE's Adams–Moulton method
(variable order 1–12, variable step: the choice for a non-stiff problem) with its default Newton
iteration and dense linear solver, fed an analytic 2x2 Jacobian; two root functions,
``side theta`` (impact, downwards) and ``theta_over - side theta`` (overturning, downwards),
located by CVODE's own root finder (Illinois). The driver steps from one output time
``j T/2`` to the next in CVODE's ``normal`` mode (CVODE steps past the output time and
interpolates, its usual mode); at a root CVODE returns the root's time and state, the driver
applies the jump and re-initialises the solver there (``CVodeReInit``: CVODE's documented way to
restart after a discontinuity). Rest and uplift as in docs/theory/impacts.md (``common``'s
docstring).
The basin runs the cells in a process pool, one process per core.
"""

from __future__ import annotations

import math
import os
from concurrent.futures import ProcessPoolExecutor

import numpy as np
import sksundae as sun

import common as C

NAME = "CVODE"
METHODS = ("Adams", "BDF")
_TINY = np.finfo(float).tiny


class _Block:
    """userdata: the block's constants and the current corner."""

    __slots__ = ("aw2", "omega", "phi", "thc", "xi", "thover", "side")

    def __init__(self, p: C.Params):
        self.aw2, self.omega, self.phi, self.thc, self.xi = p.aw2, p.omega, p.phi, p.thc, p.xi
        self.thover = p.theta_over
        self.side = 1.0


def _rhs(t, y, yp, b):
    th = y[0]
    s = b.side
    a = b.thc + s * th
    yp[0] = y[1]
    yp[1] = 0.75 * (b.aw2 * math.sin(b.omega * t + b.phi) * math.sin(a) - s * math.cos(a)
                    - b.xi * y[1])


def _jac(t, y, yp, JJ, b):
    s = b.side
    a = b.thc + s * y[0]
    f = b.aw2 * math.sin(b.omega * t + b.phi)
    JJ[0, 0] = 0.0
    JJ[0, 1] = 1.0
    JJ[1, 0] = 0.75 * s * (f * math.cos(a) + s * math.sin(a))
    JJ[1, 1] = -0.75 * b.xi


def _make_events():
    """The root functions, a fresh function object per run: sksundae keeps the events it
    found in lists on this object for the solver's whole life (through every re-init) and
    turns them into arrays at every ``step`` call, so they are cleared at each restart."""
    def events(t, y, ev, b):
        ev[0] = b.side * y[0]
        ev[1] = b.thover - b.side * y[0]

    events.terminal = [True, True]
    events.direction = [-1, -1]
    return events


def _clear(events):
    events._i.clear()
    events._t.clear()
    events._y.clear()
    events._i_cnt[:] = 0


#: The uplift instant (docs/theory/impacts.md) (plain Python: CVODE's driver is Python).
uplift_time = C.uplift_time


def run(p: C.Params, theta0, dtheta0, periods, rtol, atol, method="Adams"):
    """One run; returns a :class:`common.PeerRun`."""
    b = _Block(p)
    events = _make_events()
    solver = sun.cvode.CVODE(_rhs, userdata=b, method=method, rtol=rtol, atol=atol,
                             jacfn=_jac, eventsfn=events, num_events=2,
                             max_num_steps=100_000)
    T, half = p.T, 0.5 * p.T
    n_samp = 2 * periods + 1
    t_end = periods * T
    samples = np.zeros((n_samp, 2))
    per_imp = np.zeros(periods + 1, dtype=np.int64)
    impacts = []
    max_imp = max(100_000, 10_000 * periods)
    side = 1.0 if (theta0 > 0 or (theta0 == 0 and dtheta0 > 0)) else (
        -1.0 if (theta0 < 0 or dtheta0 < 0) else 0.0)
    t = 0.0
    y = np.array([theta0, dtheta0], dtype=float)
    j = 0
    status = C.DONE
    nfev = 0
    seg_nfev = 0
    if side != 0.0:
        b.side = side
        solver.init_step(t, y)
    while j < n_samp:
        if side == 0.0:
            t_up = uplift_time(t, p.aw2, p.cot, p.omega, p.phi)
            while j < n_samp and j * half <= min(t_up, t_end):
                samples[j] = 0.0
                if j % 2 == 0:
                    per_imp[j // 2] = len(impacts)
                j += 1
            if t_up == math.inf:
                status = C.RESTED
                break
            if t_up >= t_end:
                t = t_end
                y = np.zeros(2)
                break
            t = t_up
            side = 1.0 if math.sin(p.omega * t + p.phi) > 0 else -1.0
            b.side = side
            y = np.array([side * _TINY, 0.0])
            solver.init_step(t, y)
            continue
        tout = j * half
        if tout <= t:   # a sample at the restart instant itself
            samples[j] = y
            if j % 2 == 0:
                per_imp[j // 2] = len(impacts)
            j += 1
            continue
        res = solver.step(tout)
        if res.status < 0:
            raise RuntimeError(f"CVODE failed at t={t}: {res.message}")
        seg_nfev = res.nfev   # since the last (re-)initialisation
        if res.status == 2:   # CV_ROOT_RETURN
            nfev += seg_nfev
            seg_nfev = 0
            t = float(res.t)
            y = np.array(res.y, dtype=float)
            # the last row of i_events flags the roots found there: (impact, overturn)
            over = res.i_events[-1][1] != 0
            _clear(events)
            if over:
                status = C.OVERTURNED
                break
            dth = p.e * y[1]
            impacts.append(t)
            if len(impacts) >= max_imp:
                status = C.MAX_IMPACTS
                break
            side = -side
            if abs(dth) < p.rest_speed:
                side = 0.0
                y = np.zeros(2)
                continue
            b.side = side
            y = np.array([side * _TINY, dth])
            solver.init_step(t, y)
        else:
            t = tout
            y = np.array(res.y, dtype=float)
            samples[j] = y
            if j % 2 == 0:
                per_imp[j // 2] = len(impacts)
            j += 1
    nfev += seg_nfev
    strobe, half_s = C.samples_from(n_samp, samples, j)
    return C.PeerRun(status=status, t=t, state=np.array(y[:2], dtype=float),
                     impacts=np.array(impacts), n_impacts=len(impacts), strobe=strobe,
                     half=half_s, per_imp=per_imp[:strobe.shape[0]].copy(), n_rhs=nfev)


def _cells(args):
    p, cells, periods, rtol, atol, method = args
    return [C.label_code(*_status_samples(run(p, th, dth, periods, rtol, atol, method)),
                         periods) for th, dth in cells]


def _status_samples(r):
    return r.status, r.strobe, r.half, r.per_imp


def basin(p: C.Params, theta0s, dtheta0s, periods, rtol, atol, method="Adams", workers=None):
    """Labels ``(len(theta0s), len(dtheta0s))``; cells spread over a process pool."""
    TH, DTH = np.meshgrid(theta0s, dtheta0s, indexing="ij")
    cells = list(zip(TH.ravel(), DTH.ravel()))
    workers = workers or os.cpu_count() or 1
    # interleaved chunks: neighbouring cells cost alike, so each worker gets a fair share
    chunks = [cells[i::4 * workers] for i in range(4 * workers)]
    labels = np.empty(len(cells), dtype=np.int64)
    with ProcessPoolExecutor(workers) as ex:
        for i, codes in enumerate(ex.map(_cells, [(p, c, periods, rtol, atol, method)
                                                  for c in chunks])):
            labels[i::4 * workers] = codes
    return labels.reshape(TH.shape)
