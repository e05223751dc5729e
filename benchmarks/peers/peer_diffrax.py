"""diffrax (JAX) peer: an event on theta = 0, a jump and a restart inside ``jax.lax.while_loop``,
``jax.jit`` over the whole run, ``jax.vmap`` over the basin's cells.

What a user competent in diffrax writes: the rocking block's vector field on ``y = (theta,
theta')`` with the block's constants and the corner ``side`` in ``args``; a ``diffrax.Event`` with
two continuous conditions, ``side theta`` (impact) and ``theta_over - side theta`` (overturning),
both on down-crossings, located by ``optimistix.Newton`` on the solver's dense output (diffrax's
documented event location); each ``diffeqsolve`` runs from the current time to the next output time
``j T/2`` (``SaveAt(t1=True)``) or to the first event, whichever comes first, with an adaptive
``PIDController``; an outer ``lax.while_loop`` records the output sample, or applies the jump
``theta'(+) = e theta'(-)`` and restarts on the other corner (a new ``diffeqsolve`` from the
impact: the solver's FSAL derivative is fresh), or handles rest and uplift (docs/theory/impacts.md,
the closed-form uplift instant written in ``jax.numpy``). The whole run is one ``jax.jit``-compiled
function of traced block constants and tolerances (one compilation per solver and number of
periods); the basin is the same function under ``jax.vmap`` over ``(theta0, theta0')``, in chunks.
Float64 throughout (``jax_enable_x64``), CPU.
"""

from __future__ import annotations

import math
import os

os.environ.setdefault("XLA_PYTHON_CLIENT_PREALLOCATE", "false")

import jax  # noqa: E402

jax.config.update("jax_enable_x64", True)
jax.config.update("jax_platforms", "cpu")

import diffrax as dfx  # noqa: E402
import jax.numpy as jnp  # noqa: E402
import numpy as np  # noqa: E402
import optimistix as optx  # noqa: E402

import common as C  # noqa: E402

NAME = "diffrax"
METHODS = ("Tsit5", "Dopri5", "Dopri8")
ST_RUN, ST_DONE, ST_OVER, ST_REST, ST_MAXIMP, ST_FAIL = range(6)
_STATUS = {ST_DONE: C.DONE, ST_OVER: C.OVERTURNED, ST_REST: C.RESTED,
           ST_MAXIMP: C.MAX_IMPACTS, ST_FAIL: C.FAILED}
MAX_STEPS = 100_000   # steps of one diffeqsolve (one half period at most)
_TINY = float(np.finfo(np.float64).tiny)


def vector_field(t, y, args):
    """The equation of motion (docs/theory/model.md) on corner ``side``: ``theta'' = 3/4
    (f sin(thc + s theta) - s cos(thc + s theta) - xi theta')``,
    ``f = alpha omega^2 sin(omega t + phi)``."""
    aw2, omega, phi, thc, xi, side = args
    a = thc + side * y[0]
    f = aw2 * jnp.sin(omega * t + phi)
    return jnp.stack([y[1], 0.75 * (f * jnp.sin(a) - side * jnp.cos(a) - xi * y[1])])


def _impact(t, y, args, **kwargs):
    return args[5] * y[0]


def _make_over(thover):
    def over(t, y, args, **kwargs):
        return thover - args[5] * y[0]
    return over


def uplift_time(t, aw2, cot, omega, phi):
    """First ``t' >= t`` with ``|aw2 sin(omega t' + phi)| > cot`` (``inf`` if never)."""
    a = jnp.arcsin(jnp.minimum(cot / aw2, 1.0))
    psi = omega * t + phi
    u = psi - jnp.pi * jnp.floor(psi / jnp.pi)
    up = jnp.where((a < u) & (u < jnp.pi - a), t,
                   jnp.where(u <= a, t + (a - u) / omega, t + (jnp.pi - u + a) / omega))
    return jnp.where(aw2 <= cot, jnp.inf, up)


def _solver(method):
    return {"Tsit5": dfx.Tsit5, "Dopri5": dfx.Dopri5, "Dopri8": dfx.Dopri8}[method]()


def make_run(method, periods, n_record, thover=0.5 * math.pi):
    """``run(par, theta0, dtheta0, rtol, atol)`` for ``periods`` periods, jit-compiled.

    ``par = (aw2, omega, phi, thc, xi, e, cot, rest_speed, T)``. Returns ``(status, t, y,
    samples (2 periods + 1, 2), n_samples, per_imp (periods + 1,), impact times (n_record,),
    n_impacts, n_steps)``.
    """
    solver = _solver(method)
    term = dfx.ODETerm(vector_field)
    n_samp = 2 * periods + 1
    max_imp = max(100_000, 10_000 * periods)
    # Newton stops when the time step is below atol + rtol t and |side theta| below atol:
    # atol = 1e-14 cannot be met once the time's own rounding times theta' exceeds it
    # (t ~ 140: ulp(t) theta' ~ 2e-14; the root find then fails after its 256 steps).
    root = optx.Newton(rtol=1e-14, atol=1e-12)
    event = dfx.Event([_impact, _make_over(thover)], root_finder=root,
                      direction=[False, False])

    def run(par, theta0, dtheta0, rtol, atol):
        aw2, omega, phi, thc, xi, e, cot, rest_speed, T = par
        half = 0.5 * T
        controller = dfx.PIDController(rtol=rtol, atol=atol)
        side0 = jnp.where((theta0 > 0) | ((theta0 == 0) & (dtheta0 > 0)), 1.0,
                          jnp.where((theta0 < 0) | (dtheta0 < 0), -1.0, 0.0))
        y0 = jnp.stack([theta0, dtheta0]).astype(jnp.float64)
        carry = dict(t=jnp.float64(0.0), y=y0, side=side0, j=jnp.int64(0), n_imp=jnp.int64(0),
                     status=jnp.int64(ST_RUN), samples=jnp.zeros((n_samp, 2)),
                     per_imp=jnp.zeros(periods + 1, jnp.int64),
                     imp_t=jnp.zeros(max(n_record, 1)), n_steps=jnp.int64(0))

        def record(c, y, t):
            j = c["j"]
            samples = c["samples"].at[j].set(y)
            per_imp = jnp.where(j % 2 == 0, c["per_imp"].at[j // 2].set(c["n_imp"]),
                                c["per_imp"])
            status = jnp.where(j + 1 >= n_samp, ST_DONE, c["status"])
            return dict(c, t=t, y=y, j=j + 1, samples=samples, per_imp=per_imp, status=status)

        def flight(c):
            t1 = jnp.maximum(c["j"] * half, c["t"])
            args = (aw2, omega, phi, thc, xi, c["side"])
            sol = dfx.diffeqsolve(term, solver, c["t"], t1, None, c["y"], args=args,
                                  stepsize_controller=controller, event=event,
                                  saveat=dfx.SaveAt(t1=True), max_steps=MAX_STEPS,
                                  throw=False)
            t_new = sol.ts[-1]
            y_new = sol.ys[-1]
            hit, over = sol.event_mask
            failed = ~(dfx.is_successful(sol.result) | (sol.result == dfx.RESULTS.event_occurred))
            n_steps = c["n_steps"] + sol.stats["num_steps"]
            # no event: the output sample at t1
            c_sample = record(dict(c, n_steps=n_steps), y_new, t_new)
            # overturning
            c_over = dict(c, t=t_new, y=y_new, status=jnp.int64(ST_OVER), n_steps=n_steps)
            # impact: jump, other corner, rest if slow
            dth = e * y_new[1]
            n_imp = c["n_imp"] + 1
            imp_t = c["imp_t"].at[jnp.minimum(c["n_imp"], n_record - 1)].set(t_new) \
                if n_record > 0 else c["imp_t"]
            slow = jnp.abs(dth) < rest_speed
            side = jnp.where(slow, 0.0, -c["side"])
            # start a hair off theta = 0 on the new corner: an event is a down-crossing from
            # a positive value, and a start on 0 would miss an impact inside the first step
            # (the short flights of a Zeno cascade)
            y_imp = jnp.stack([side * _TINY, jnp.where(slow, 0.0, dth)])
            status = jnp.where(n_imp >= max_imp, ST_MAXIMP, c["status"])
            c_imp = dict(c, t=t_new, y=y_imp, side=side, n_imp=n_imp, imp_t=imp_t,
                         status=status, n_steps=n_steps)
            out = jax.tree.map(lambda a, b: jnp.where(hit, a, b), c_imp, c_sample)
            out = jax.tree.map(lambda a, b: jnp.where(over, a, b), c_over, out)
            return dict(out, status=jnp.where(failed, ST_FAIL, out["status"]))

        def rest(c):
            t_up = uplift_time(c["t"], aw2, cot, omega, phi)
            t_s = c["j"] * half
            c_sample = record(c, jnp.zeros(2), jnp.maximum(c["t"], t_s))
            side = jnp.where(jnp.sin(omega * t_up + phi) > 0, 1.0, -1.0)
            c_lift = dict(c, t=t_up, y=jnp.stack([side * _TINY, 0.0]), side=side)
            out = jax.tree.map(lambda a, b: jnp.where(t_up > t_s, a, b), c_sample, c_lift)
            never = jnp.isinf(t_up) & (t_up > t_s)
            # a block that can never lift again: rest for good (samples to the end are 0)
            return dict(out, status=jnp.where(never & (c["j"] == 0), ST_REST,
                                              jnp.where(never, ST_REST, out["status"])))

        def body(c):
            return jax.lax.cond(c["side"] == 0.0, rest, flight, c)

        c = jax.lax.while_loop(lambda c: c["status"] == ST_RUN, body, carry)
        return (c["status"], c["t"], c["y"], c["samples"], c["j"], c["per_imp"], c["imp_t"],
                c["n_imp"], c["n_steps"])

    return run


_RUNS = {}
_BASINS = {}


def _par(p: C.Params):
    return jnp.array([p.aw2, p.omega, p.phi, p.thc, p.xi, p.e, p.cot, p.rest_speed, p.T])


def compiled_run(method, periods, n_record):
    key = (method, periods, n_record)
    if key not in _RUNS:
        _RUNS[key] = jax.jit(make_run(method, periods, n_record))
    return _RUNS[key]


def run(p: C.Params, theta0, dtheta0, periods, rtol, atol, method="Tsit5", n_record=None):
    """One run; returns a :class:`common.PeerRun`."""
    n_record = 4 * periods + 64 if n_record is None else n_record
    f = compiled_run(method, int(periods), int(n_record))
    out = jax.block_until_ready(f(_par(p), jnp.float64(theta0), jnp.float64(dtheta0),
                                  jnp.float64(rtol), jnp.float64(atol)))
    st, t, y, samples, n_s, per_imp, imp_t, n_imp, n_steps = (np.asarray(v) for v in out)
    strobe, half = C.samples_from(2 * periods + 1, samples, int(n_s))
    n_imp = int(n_imp)
    return C.PeerRun(status=_STATUS[int(st)], t=float(t), state=y.copy(),
                     impacts=imp_t[:min(n_imp, n_record)].copy(), n_impacts=n_imp,
                     strobe=strobe, half=half, per_imp=per_imp[:strobe.shape[0]].copy(),
                     extra=dict(n_steps=int(n_steps)))


def compiled_basin(method, periods):
    key = (method, periods)
    if key not in _BASINS:
        _BASINS[key] = jax.jit(jax.vmap(make_run(method, periods, 0),
                                        in_axes=(None, 0, 0, None, None)))
    return _BASINS[key]


def basin(p: C.Params, theta0s, dtheta0s, periods, rtol, atol, method="Tsit5", chunk=2500):
    """Labels ``(len(theta0s), len(dtheta0s))``: the run under ``jax.vmap``, ``chunk`` cells
    at a time; each cell classified by ``rockjit._engine.classify`` (:func:`common.label_code`)."""
    TH, DTH = np.meshgrid(theta0s, dtheta0s, indexing="ij")
    th, dth = TH.ravel(), DTH.ravel()
    f = compiled_basin(method, int(periods))
    chunk = min(chunk, th.size)   # a batch size is a compilation: keep one per grid size
    labels = np.empty(th.size, dtype=np.int64)
    par = _par(p)
    for a in range(0, th.size, chunk):
        sl = slice(a, min(a + chunk, th.size))
        n = sl.stop - sl.start
        # pad the last chunk to the compiled batch size
        tt = np.zeros(chunk)
        dd = np.zeros(chunk)
        tt[:n], dd[:n] = th[sl], dth[sl]
        dd[n:] = 0.1
        out = jax.block_until_ready(f(par, jnp.asarray(tt), jnp.asarray(dd), jnp.float64(rtol),
                                      jnp.float64(atol)))
        st, _, _, samples, n_s, per_imp, _, _, _ = (np.asarray(v) for v in out)
        for i in range(n):
            # a failed cell (diffeqsolve's max_steps, or its root find) is labelled
            # unresolved, so the benchmark's label check lists it
            strobe, half = C.samples_from(2 * periods + 1, samples[i], int(n_s[i]))
            labels[a + i] = C.label_code(_STATUS[int(st[i])], strobe, half,
                                         per_imp[i][:strobe.shape[0]], periods)
    return labels.reshape(TH.shape)
