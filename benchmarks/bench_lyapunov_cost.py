"""What the Lyapunov exponents cost, on the study's reference run.

The run: hb=1, alpha=0.6, omega=1.3, Housner restitution, z0 = rockjit.Z0_STUDY, 500 periods,
exponents averaged over the last 100 (docs/theory/exponents.md, docs/theory/study.md). Measured
side by side in one process, in alternating order: ``lyapunov=False`` against ``lyapunov=True``
(tangent dynamics and saltation matrices compiled in) at the default N and at N=64; compile time of
each kernel measured apart in fresh processes. Also reported: lambda1, lambda2, and the exact
identity ``lambda1 + lambda2 = -3/4 xi + 2 nu ln(e)`` with ``nu = n_impacts_window / window
length``.

There is no scipy variational path: exponents exist only on the compiled path, so there is no
reference timing to compare with.

    python benchmarks/bench_lyapunov_cost.py           # full measurement (~1 min)
    python benchmarks/bench_lyapunov_cost.py --quick   # smoke mode (20 periods)

Writes lyapunov_cost.{md,csv,json,png} to benchmarks/results/ (benchmarks/results/quick/ with
--quick, or --out DIR).
"""

from __future__ import annotations

import math
import sys

import numpy as np

import _common as H

import rockjit
from rockjit import Integration

FULL = dict(periods=500, repeats=21)
QUICK = dict(periods=20, repeats=3)


# --------------------------------------------------------------------------- experiments

def first_calls(run, n_def):
    """The first call of each kernel in this process (compile, or load from numba's cache)."""
    out = {}
    for lyap in (False, True):
        out[lyap], _ = H.timed(run, n_def, lyap)
        print(f"first call in process, lyapunov={lyap}: {out[lyap]:.3f} s")
    return out


def cost(run, ns, repeats):
    """``lyapunov=False`` against ``True`` at each N, the four cases interleaved.

    (N, False) and (N, True) are adjacent: the rotation of the rounds alternates which goes first.
    """
    return H.side_by_side({(n, lyap): (lambda n=n, lyap=lyap: run(n, lyap))
                           for n in ns for lyap in (False, True)}, repeats)


def compile_cost(block, forcing, periods, n_def, warm, first, quick):
    """Compile time of each kernel: fresh processes (full), or the in-process first call."""
    out = {}
    for lyap in (False, True):
        inproc = first[lyap] - warm[(n_def, lyap)]
        if quick:
            out[lyap] = dict(cold=None, cached=None, inproc_s=inproc)
        else:
            out[lyap] = dict(inproc_s=inproc, **H.compile_times(
                "simulate", (block, forcing),
                dict(integration=Integration(periods=periods, n_steps=n_def), lyapunov=lyap)))
    return out


def identity(res):
    """``(lambda1 + lambda2, -3/4 xi + 2 nu ln e, nu)`` over the run's window
    (docs/theory/exponents.md)."""
    b = res.block
    t0, t1 = res.window
    nu = res.n_impacts_window / (t1 - t0)
    return float(np.sum(res.lyapunov)), -0.75 * b.xi + 2.0 * nu * math.log(b.restitution), nu


def records(ns, n_def, t):
    """One record per N: the cost and the exponents with their identity."""
    out = []
    for n in ns:
        r0, r1 = t.result[(n, False)], t.result[(n, True)]
        m0, m1 = t.median((n, False)), t.median((n, True))
        # the tangent kernel is a separate compilation: its trajectory may round differently
        same_path = dict(n_rhs_equal=r0.n_rhs == r1.n_rhs,
                         state_difference=float(np.max(np.abs(r0.state - r1.state))))
        s, rhs, nu = identity(r1)
        out.append(dict(n_steps=n, wall_median_off_s=m0, wall_median_on_s=m1, cost_ratio=m1 / m0,
                        wall_all_off_s=t.wall[(n, False)], wall_all_on_s=t.wall[(n, True)],
                        n_rhs=r1.n_rhs, n_impacts=r1.n_impacts,
                        lambda1=float(r1.lyapunov[0]), lambda2=float(r1.lyapunov[1]),
                        lambda_sum=s, identity_rhs=rhs, identity_error=abs(s - rhs), nu=nu,
                        n_impacts_window=r1.n_impacts_window, n_rest_window=r1.n_rest_window,
                        window=list(r1.window), status=r1.status, on_vs_off=same_path))
    return out


# --------------------------------------------------------------------------- the report

CSV_COLUMNS = ("n_steps", "wall_median_off_s", "wall_median_on_s", "cost_ratio", "n_rhs",
               "lambda1", "lambda2", "lambda_sum", "identity_rhs", "identity_error")


def markdown(recs, compile_info, r_def, n_def, cfg, quick, env):
    cost_rows = [[f"{r['n_steps']}" + (" (default)" if r["n_steps"] == n_def else ""),
                  r["wall_median_off_s"], r["wall_median_on_s"], r["cost_ratio"], r["n_rhs"],
                  r["n_impacts"]] for r in recs]
    lam_rows = [[r["n_steps"], r["lambda1"], r["lambda2"], r["lambda_sum"], r["identity_rhs"],
                 r["identity_error"], r["nu"], r["n_rest_window"]] for r in recs]
    comp_rows = []
    for lyap in (False, True):
        ci = compile_info[lyap]
        name = "lyapunov=True (tangent)" if lyap else "lyapunov=False"
        if ci["cold"] is None:
            comp_rows.append([name + " [in-process first call]", ci["inproc_s"], None])
        else:
            comp_rows.append([name, ci["cold"]["compile_s"], ci["cached"]["compile_s"]])
    w0, w1 = r_def.window
    return "".join([
        f"### Lyapunov cost: reference run, {cfg['periods']} periods, window "
        f"[{w0 / r_def.period:.0f}T, {w1 / r_def.period:.0f}T]{H.quick_note(quick)}\n",
        H.md_table(["N", "lyapunov=False (s)", "lyapunov=True (s)", "cost ratio", "n_rhs",
                    "impacts"], cost_rows),
        f"\nMedians of {cfg['repeats']} warm runs each, the four cases interleaved in one "
        f"process in rotating order. Ratio = with / without exponents. There is no scipy "
        f"variational path (exponents are computed only by the compiled integrator), so no "
        f"reference timing.\n\n",
        H.md_table(["N", "lambda1", "lambda2", "lambda1 + lambda2", "-3/4 xi + 2 nu ln e",
                    "identity error", "nu (impacts / unit time)", "rest phases in window"],
                   lam_rows),
        "\nIdentity (docs/theory/exponents.md): lambda1 + lambda2 = -3/4 xi + 2 nu ln e over "
        "the window, "
        f"xi = {r_def.block.xi:.6g}, e = {r_def.block.restitution:.6g}.\n\n",
        H.md_table(["kernel", "compile, cold (s)", "compile, cached (s)"], comp_rows),
        "\nCompile: first call in a fresh process minus the warm median; cold = empty numba "
        "cache, cached = the cache the cold process wrote.\n",
        f"\n{H.env_line(env)}\n"])


def plot(ns, results, n_def):
    plt = H.pyplot()
    fig, ax = plt.subplots(figsize=(6.4, 4.2), layout="constrained")
    r = results[(n_def, True)]
    k = np.arange(r.lyapunov_running.shape[0])
    for j, c in ((0, "C0"), (1, "C1")):
        ax.plot(k[1:], r.lyapunov_running[1:, j], color=c, lw=1.2,
                label=f"lambda{j + 1}(t), N={n_def}")
        ax.axhline(r.lyapunov[j], color=c, ls="--", lw=0.8,
                   label=f"lambda{j + 1} over window = {r.lyapunov[j]:.4f}")
    for n in ns:
        if n != n_def:
            rr = results[(n, True)]
            ax.plot(k[1:], rr.lyapunov_running[1:, 0], color="k", lw=0.6, ls=":",
                    label=f"lambda1(t), N={n}")
    ax.axvspan(r.window[0] / r.period, r.window[1] / r.period, color="0.9", zorder=0,
               label="averaging window")
    ax.set_xscale("log")
    ax.set_xlabel("t / T (periods)")
    ax.set_ylabel("running estimate lambda(t)")
    ax.set_title("Reference run (hb=1, alpha=0.6, omega=1.3, Housner): running exponents",
                 fontsize=9)
    ax.legend(fontsize=7)
    ax.grid(True, alpha=0.3)
    return fig


# --------------------------------------------------------------------------- main

def main(argv=None):
    b = H.Bench(__doc__, argv)
    cfg = QUICK if b.quick else FULL
    n_def = rockjit.DEFAULT_N
    ns = [n_def] + [n for n in (64,) if n != n_def]
    block, forcing = H.reference_run()  # from the study's initial state
    periods = cfg["periods"]

    def run(n, lyap):
        return rockjit.simulate(block, forcing,
                                integration=Integration(periods=periods, n_steps=n),
                                lyapunov=lyap)

    first = first_calls(run, n_def)
    t = cost(run, ns, cfg["repeats"])
    compile_info = compile_cost(block, forcing, periods, n_def, t.medians(), first, b.quick)
    recs = records(ns, n_def, t)

    b.report("lyapunov_cost",
             markdown=markdown(recs, compile_info, t.result[(n_def, True)], n_def, cfg, b.quick,
                               b.env),
             csv=(CSV_COLUMNS, [[r[k] for k in CSV_COLUMNS] for r in recs]),
             data=dict(run=H.encode(dict(block=block, forcing=forcing, state=None,
                                         z0=list(rockjit.Z0_STUDY), periods=periods)),
                       quick=b.quick,
                       repeats=cfg["repeats"], default_n=n_def, environment=b.env, rows=recs,
                       compile={str(k): v for k, v in compile_info.items()},
                       first_call_in_process_s={str(k): v for k, v in first.items()},
                       lyapunov_running={str(n): t.result[(n, True)].lyapunov_running
                                         for n in ns}),
             figures=[("lyapunov_cost.png", plot(ns, t.result, n_def), 130)])
    return 0


if __name__ == "__main__":
    sys.exit(main())
