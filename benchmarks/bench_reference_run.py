"""The study's reference run: rockjit against the study's scipy BDF path, speed and error.

The run: hb=1, alpha=0.6, omega=1.3, Housner restitution, z0 = rockjit.Z0_STUDY, 500 periods
(docs/theory/study.md, figure 2). Measured side by side in one process:

* rockjit (compiled fixed-step Dormand–Prince) at N in {32, 64, 128, 256, 512} steps per period,
  with the closed-form forcing (rockjit's default) and with the 4-D oscillator embedding;
  warm wall time = median of repeats, compile time measured apart in fresh processes;
* the study's path: scipy ``solve_ivp`` BDF, rtol 1e-6, atol 1e-9, on the embedding;
* errors of the final state (theta, theta') and of the impact times against a tight reference
  of the same forcing, computed two independent ways (rockjit at N=8192 and scipy DOP853 at
  rtol 1e-13, atol 1e-14) whose mutual difference is reported as the error floor.

The study's z0 has (r0, s0) a little off the unit circle (radius 0.99993), so the embedded and
closed-form runs are different problems at the 1e-5 level: each run is compared with the
reference of its own forcing.

    python benchmarks/bench_reference_run.py           # full measurement (~2 min)
    python benchmarks/bench_reference_run.py --quick   # smoke mode (20 periods)

Writes reference_run.{md,csv,json,png} to benchmarks/results/ (benchmarks/results/quick/ with
--quick, or --out DIR).
"""

from __future__ import annotations

import math
import sys
import time

import numpy as np

import _common as H

import rockjit
from rockjit import Integration, Scipy

NS = (32, 64, 128, 256, 512)
N_REF = 8192
TIGHT = Scipy("DOP853", rtol=1e-13, atol=1e-14)
STUDY = Scipy("BDF", rtol=1e-6, atol=1e-9)  # the study's path
#: The goal: rockjit this many times faster than the study's BDF path, with a smaller error.
TARGET = 2000.0
FORCINGS = ("closed", "embedded")
FULL = dict(periods=500, repeats=31, bdf_repeats=5)
QUICK = dict(periods=20, repeats=3, bdf_repeats=1)


class Runs:
    """The calls measured: rockjit at N with a forcing, the study's BDF path, DOP853."""

    def __init__(self, periods):
        self.block, closed = H.reference_run()  # from the study's initial state
        self.forcing = {"closed": closed, "embedded": closed.replace(embedded=True)}
        self.periods = periods

    def integration(self, n=None):
        return Integration(periods=self.periods, n_steps=n)

    def rockjit(self, n, forcing):
        return rockjit.simulate(self.block, self.forcing[forcing],
                                integration=self.integration(n))

    def bdf(self):
        return rockjit.simulate(self.block, self.forcing["embedded"],
                                integration=self.integration(), method=STUDY)

    def dop853(self, forcing):
        return rockjit.simulate(self.block, self.forcing[forcing],
                                integration=self.integration(), method=TIGHT)

    def description(self):
        """The run's inputs, for the JSON."""
        return H.encode(dict(block=self.block, forcing=self.forcing["closed"], state=None,
                             z0=list(rockjit.Z0_STUDY), periods=self.periods))


def final_error(res, ref) -> float:
    if abs(res.t - ref.t) > 1e-9 * max(1.0, ref.t):
        raise RuntimeError(f"{res.method} stopped at t={res.t}, the reference at t={ref.t}")
    return float(np.max(np.abs(res.state[:2] - ref.state[:2])))


# --------------------------------------------------------------------------- experiments

def first_calls(runs, n_def):
    """The first call of each kernel in this process (compile, or load from numba's cache)."""
    out = {}
    for f in FORCINGS:
        out[f], _ = H.timed(runs.rockjit, n_def, f)
        print(f"first call in process, {f}: {out[f]:.3f} s")
    return out


def references(runs):
    """The tight reference of each forcing, two independent ways, and their difference."""
    refs = {}
    for f in FORCINGS:
        t_rj, r_rj = H.timed(runs.rockjit, N_REF, f)
        t_dop, r_dop = H.timed(runs.dop853, f)
        refs[f] = dict(rockjit=r_rj, dop853=r_dop, wall_rockjit=t_rj, wall_dop853=t_dop,
                       diff_state=final_error(r_rj, r_dop),
                       diff_impacts=H.impact_time_error(r_rj, r_dop))
        print(f"reference {f}: rockjit N={N_REF} vs DOP853: final state "
              f"{refs[f]['diff_state']:.3g}, impact times {refs[f]['diff_impacts']}")
    return refs


def timings(runs, ns, cfg):
    """Every rockjit case and the BDF path, interleaved (BDF in ``bdf_repeats`` rounds)."""
    cases = {("rockjit", n, f): (lambda n=n, f=f: runs.rockjit(n, f))
             for f in FORCINGS for n in ns}
    cases[("bdf",)] = runs.bdf
    t0 = time.perf_counter()
    t = H.side_by_side(cases, cfg["repeats"], counts={("bdf",): cfg["bdf_repeats"]})
    print(f"timing rounds: {time.perf_counter() - t0:.1f} s")
    return t


def compile_cost(runs, n_def, first, t, quick):
    """Compile time of each forcing's kernel: fresh processes (full), in-process first call."""
    out = {}
    for f in FORCINGS:
        inproc = first[f] - t.median(("rockjit", n_def, f))
        if quick:
            out[f] = dict(method="in-process first call minus warm median", cold=None,
                          cached=None, inproc_s=inproc)
        else:
            out[f] = dict(method="fresh process, empty NUMBA_CACHE_DIR (cold) and again with "
                                 "the cache it wrote (cached)",
                          inproc_s=inproc, **H.compile_times(
                              "simulate", (runs.block, runs.forcing[f]),
                              dict(integration=runs.integration(n_def))))
    return out


# --------------------------------------------------------------------------- rows and verdict

HEADERS = ["method", "N / tolerances", "forcing", "wall median (s)", "compile, cold (s)",
           "compile, cached (s)", "final-state error", "max impact-time error", "n_rhs",
           "speed-up vs BDF"]
CSV_HEADERS = ["method", "n_steps_or_tol", "forcing", "wall_median_s", "compile_cold_s",
               "compile_cached_s", "final_state_error", "max_impact_time_error", "n_rhs",
               "speedup_vs_bdf"]


def rows(ns, n_def, t, refs, compile_info):
    """``(table rows, JSON records)``: every rockjit case, then the BDF path."""
    ref_of = {f: refs[f]["rockjit"] for f in FORCINGS}
    floor = {f: refs[f]["diff_state"] for f in FORCINGS}
    t_bdf = t.median(("bdf",))
    out, recs = [], []
    for f in FORCINGS:
        ci = compile_info[f]
        cols = (ci["inproc_s"], None) if ci["cold"] is None else \
            (ci["cold"]["compile_s"], ci["cached"]["compile_s"])
        for n in ns:
            k = ("rockjit", n, f)
            r, med = t.result[k], t.median(k)
            err = final_error(r, ref_of[f])
            ierr = H.impact_time_error(r, ref_of[f])
            cold, cached = cols if n == n_def else ("same kernel", "same kernel")
            out.append(["rockjit", f"N={n}" + (" (default)" if n == n_def else ""), f, med,
                        cold, cached, H.fmt(err) + (" †" if err < floor[f] else ""), ierr,
                        r.n_rhs, t_bdf / med])
            recs.append(dict(method="rockjit", n_steps=n, forcing=f, wall_median_s=med,
                             wall_all_s=t.wall[k], final_state_error=err,
                             impact_time_error=ierr, n_rhs=r.n_rhs, n_impacts=r.n_impacts,
                             max_error_estimate=r.max_error_estimate,
                             speedup_vs_bdf=t_bdf / med))
    rb = t.result[("bdf",)]
    err_bdf = final_error(rb, ref_of["embedded"])
    ierr_bdf = H.impact_time_error(rb, ref_of["embedded"])
    out.append(["scipy BDF (the study's)", "rtol 1e-6, atol 1e-9", "embedded", t_bdf, None, None,
                err_bdf, ierr_bdf, rb.n_rhs, 1.0])
    recs.append(dict(method="scipy:BDF", rtol=1e-6, atol=1e-9, forcing="embedded",
                     wall_median_s=t_bdf, wall_all_s=t.wall[("bdf",)], final_state_error=err_bdf,
                     impact_time_error=ierr_bdf, n_rhs=rb.n_rhs, n_impacts=rb.n_impacts,
                     speedup_vs_bdf=1.0))
    return out, recs


def target(ns, n_def, t, refs):
    """The goal: >= TARGET times faster than BDF with a smaller error, at each N."""
    ref_of = {f: refs[f]["rockjit"] for f in FORCINGS}
    t_bdf = t.median(("bdf",))
    err_bdf = final_error(t.result[("bdf",)], ref_of["embedded"])

    def verdict(n, f):
        k = ("rockjit", n, f)
        s = t_bdf / t.median(k)
        e = final_error(t.result[k], ref_of[f])
        return s, e, (s >= TARGET and e < err_bdf)

    s_def, e_def, ok_def = verdict(n_def, "closed")
    s_emb, e_emb, ok_emb = verdict(n_def, "embedded")
    # the spread of both sides' times: the machine is shared, and the ratio moves with it
    q_def = np.percentile(t.wall[("rockjit", n_def, "closed")], [25, 75])
    bdf_range = (min(t.wall[("bdf",)]), max(t.wall[("bdf",)]))
    return dict(speedup=TARGET,
                default_n_closed=dict(speedup=s_def, error=e_def, met=ok_def,
                                      speedup_range=(bdf_range[0] / q_def[1],
                                                     bdf_range[1] / q_def[0])),
                default_n_embedded=dict(speedup=s_emb, error=e_emb, met=ok_emb),
                bdf_error=err_bdf, met_at_n={f: [n for n in ns if verdict(n, f)[2]]
                                             for f in FORCINGS},
                quartiles_default_s=list(q_def), bdf_range_s=list(bdf_range))


def verdict_text(v, bdf_error):
    """Whether a case reached the goal, and if not, why, in words."""
    if v["met"]:
        return "goal reached"
    why = []
    if v["speedup"] < TARGET:
        why.append(f"{v['speedup']:.0f}x is below {TARGET:.0f}x")
    if not v["error"] < bdf_error:
        why.append(f"its error {H.fmt(v['error'])} is not below BDF's {H.fmt(bdf_error)}")
    return "out of reach: " + " and ".join(why)


def markdown(table, refs, compile_info, tg, n_def, cfg, quick, env):
    ref_rows = [[f, refs[f]["wall_rockjit"], refs[f]["wall_dop853"], refs[f]["diff_state"],
                 refs[f]["diff_impacts"], refs[f]["rockjit"].n_impacts] for f in FORCINGS]
    closed_vs_embedded = final_error(refs["closed"]["rockjit"], refs["embedded"]["rockjit"])
    dc, de = tg["default_n_closed"], tg["default_n_embedded"]
    q, bdf_range, s_range = tg["quartiles_default_s"], tg["bdf_range_s"], dc["speedup_range"]
    md = [f"### Reference run: hb=1, alpha=0.6, omega=1.3, Housner, z0 = Z0_STUDY, "
          f"{cfg['periods']} periods{H.quick_note(quick)}\n",
          H.md_table(HEADERS, table),
          f"\nWall times: medians of {cfg['repeats']} warm runs (BDF: {cfg['bdf_repeats']}), all "
          f"cases interleaved in one process. Errors: max over (theta, theta') at t = "
          f"{cfg['periods']}T, against rockjit N={N_REF} with the same forcing. Compile: first "
          f"call in a fresh process minus the warm median; cold = empty numba cache, cached = "
          f"the cache the cold process wrote"
          + (" (quick mode: in-process first call only)." if quick else ".")
          + " † below the two references' mutual difference (not resolved).\n",
          "\nTight references (two independent ways, same forcing):\n\n",
          H.md_table(["forcing", f"rockjit N={N_REF} wall (s)", "DOP853 1e-13/1e-14 wall (s)",
                      "final-state difference", "max impact-time difference", "impacts"],
                     ref_rows),
          f"\nClosed vs embedded reference (the study's (r0, s0) has radius "
          f"{math.hypot(*rockjit.Z0_STUDY[2:]):.5f}): final states differ by "
          f"{H.fmt(closed_vs_embedded)}.\n",
          f"\n**Goal** (rockjit >= {TARGET:.0f}x faster than the BDF path, with a smaller "
          f"error): at the default N={n_def} (closed forcing) rockjit is "
          f"**{dc['speedup']:.0f}x** faster with error {H.fmt(dc['error'])} vs BDF's "
          f"{H.fmt(tg['bdf_error'])}: **{verdict_text(dc, tg['bdf_error'])}**. Spread: "
          f"rockjit's quartiles {1e3 * q[0]:.2f}–{1e3 * q[1]:.2f} ms, BDF {bdf_range[0]:.1f}–"
          f"{bdf_range[1]:.1f} s: between {s_range[0]:.0f}x and {s_range[1]:.0f}x. Embedded "
          f"forcing at N={n_def} (like for like with BDF): {de['speedup']:.0f}x, error "
          f"{H.fmt(de['error'])}: {verdict_text(de, tg['bdf_error'])}. Reached at N in "
          f"{tg['met_at_n']['closed'] or 'none'} (closed), "
          f"{tg['met_at_n']['embedded'] or 'none'} (embedded).\n",
          f"\n{H.env_line(env)}\n"]
    if not quick:
        cc = compile_info["closed"]
        md.insert(-1, f"\nIn-process first call (with whatever numba cache the installed "
                      f"package already holds): closed {cc['inproc_s']:.2f} s, embedded "
                      f"{compile_info['embedded']['inproc_s']:.2f} s; `import rockjit` "
                      f"{cc['cold']['import_s']:.2f} s.\n")
    return "".join(md)


def plot(ns, t, refs, n_def, periods):
    ref_of = {f: refs[f]["rockjit"] for f in FORCINGS}
    t_bdf = t.median(("bdf",))
    err_bdf = final_error(t.result[("bdf",)], ref_of["embedded"])
    plt = H.pyplot()
    fig, ax = plt.subplots(figsize=(6.4, 4.6), layout="constrained")
    style = {"closed": ("C0", "o"), "embedded": ("C1", "s")}
    for f, (c, m) in style.items():
        x = [t.median(("rockjit", n, f)) for n in ns]
        y = [max(final_error(t.result[("rockjit", n, f)], ref_of[f]), 1e-17) for n in ns]
        ax.loglog(x, y, marker=m, color=c, label=f"rockjit, {f} forcing")
        for n, xi, yi in zip(ns, x, y):
            ax.annotate(f"N={n}" + ("*" if n == n_def else ""), (xi, yi),
                        textcoords="offset points", xytext=(5, 4), fontsize=7, color=c)
        ax.axhline(refs[f]["diff_state"], color=c, ls=":", lw=0.8)
    ax.loglog([t_bdf], [err_bdf], marker="*", ms=14, color="C3", ls="none",
              label="scipy BDF rtol 1e-6 (study), embedded")
    ax.axvline(t_bdf / TARGET, color="0.4", ls="--", lw=0.8)
    ax.text(t_bdf / TARGET, ax.get_ylim()[0], f" {TARGET:.0f}x faster than BDF", va="bottom",
            fontsize=7, color="0.3")
    ax.set_xlabel("warm wall time, median (s)")
    ax.set_ylabel(f"final-state error at t = {periods}T")
    ax.set_title("Reference run (hb=1, alpha=0.6, omega=1.3, Housner)\n"
                 "dotted: the two tight references' mutual difference; * default N",
                 fontsize=9)
    ax.legend(fontsize=7, loc="center right")
    ax.grid(True, which="major", alpha=0.3)
    return fig


# --------------------------------------------------------------------------- main

def main(argv=None):
    b = H.Bench(__doc__, argv)
    cfg = QUICK if b.quick else FULL
    n_def = rockjit.DEFAULT_N
    ns = sorted(set(NS) | {n_def})
    runs = Runs(cfg["periods"])

    first = first_calls(runs, n_def)  # before anything else
    refs = references(runs)
    t = timings(runs, ns, cfg)
    compile_info = compile_cost(runs, n_def, first, t, b.quick)
    table, recs = rows(ns, n_def, t, refs, compile_info)
    tg = target(ns, n_def, t, refs)

    b.report("reference_run",
             markdown=markdown(table, refs, compile_info, tg, n_def, cfg, b.quick, b.env),
             csv=(CSV_HEADERS, [[*r[:6], str(r[6]).rstrip(" †"), *r[7:]] for r in table]),
             data=dict(
                 run=runs.description(), quick=b.quick,
                 repeats=cfg["repeats"], bdf_repeats=cfg["bdf_repeats"], default_n=n_def,
                 environment=b.env, rows=recs,
                 references={f: dict(wall_rockjit_s=refs[f]["wall_rockjit"],
                                     wall_dop853_s=refs[f]["wall_dop853"],
                                     final_state_difference=refs[f]["diff_state"],
                                     impact_time_difference=refs[f]["diff_impacts"],
                                     n_impacts=refs[f]["rockjit"].n_impacts) for f in FORCINGS},
                 closed_vs_embedded_reference=final_error(refs["closed"]["rockjit"],
                                                          refs["embedded"]["rockjit"]),
                 compile=compile_info, first_call_in_process_s=first, target=tg),
             figures=[("reference_run.png", plot(ns, t, refs, n_def, cfg["periods"]), 130)])
    return 0


if __name__ == "__main__":
    sys.exit(main())
