"""Issue 2: the study's reference run, rockjit against the study's scipy BDF path.

The run: hb=1, alpha=0.6, omega=1.3, Housner restitution, z0 = rockjit.Z0_STUDY, 500 periods
(SPEC.md §7, figure 2). Measured side by side in one process:

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
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parent))
import _common as C  # noqa: E402

import rockjit  # noqa: E402

NS = (32, 64, 128, 256, 512)
N_REF = 8192
TIGHT = dict(rtol=1e-13, atol=1e-14)
STUDY_TOL = dict(rtol=1e-6, atol=1e-9)
TARGET = 2000.0


def final_error(res, ref) -> float:
    if abs(res.t - ref.t) > 1e-9 * max(1.0, ref.t):
        raise RuntimeError(f"{res.method} stopped at t={res.t}, the reference at t={ref.t}")
    return float(np.max(np.abs(res.state[:2] - ref.state[:2])))


def impact_error(res, ref):
    """Largest impact-time difference, or a string saying the counts differ."""
    if res.n_impacts != ref.n_impacts:
        return f"counts differ ({res.n_impacts} vs {ref.n_impacts})"
    if res.n_impacts == 0:
        return None
    return float(np.max(np.abs(res.impacts[:, 0] - ref.impacts[:, 0])))


def main(argv=None):
    args = C.parser(__doc__.splitlines()[0]).parse_args(argv)
    out = C.out_dir(args)
    quick = args.quick
    periods = 20 if quick else 500
    repeats = 3 if quick else 31
    bdf_repeats = 1 if quick else 5
    n_def = rockjit.DEFAULT_N
    ns = sorted(set(NS) | {n_def})
    base = dict(C.REFERENCE_RUN, z0=rockjit.Z0_STUDY, periods=periods)
    forcings = ("closed", "embedded")

    def run_rj(n, forcing):
        return rockjit.simulate(**base, n_steps=n, forcing=forcing)

    def run_bdf():
        return rockjit.simulate(**base, forcing="embedded", method="scipy", **STUDY_TOL)

    env = C.environment()
    print(C.env_line(env))

    # ---- first calls in this process (compile, or load from numba's cache), before anything else
    first_inproc = {}
    for f in forcings:
        first_inproc[f], _ = C.timed(run_rj, n_def, f)
        print(f"first call in process, {f}: {first_inproc[f]:.3f} s")

    # ---- the tight references, two independent ways per forcing
    refs = {}
    for f in forcings:
        t_rj, r_rj = C.timed(run_rj, N_REF, f)
        t_dop, r_dop = C.timed(rockjit.simulate, **base, forcing=f, method="scipy:DOP853",
                               **TIGHT)
        refs[f] = dict(rockjit=r_rj, dop853=r_dop, wall_rockjit=t_rj, wall_dop853=t_dop,
                       diff_state=final_error(r_rj, r_dop), diff_impacts=impact_error(r_rj, r_dop))
        print(f"reference {f}: rockjit N={N_REF} vs DOP853: final state "
              f"{refs[f]['diff_state']:.3g}, impact times {refs[f]['diff_impacts']}")
    ref_of = {f: refs[f]["rockjit"] for f in forcings}
    closed_vs_embedded = final_error(ref_of["closed"], ref_of["embedded"])

    # ---- timings, side by side
    results = {}

    def keep(key, fn):
        def call():
            results[key] = fn()
        return call

    cases = {("rockjit", n, f): keep(("rockjit", n, f), lambda n=n, f=f: run_rj(n, f))
             for f in forcings for n in ns}
    cases[("bdf",)] = keep(("bdf",), run_bdf)
    t0 = time.perf_counter()
    times = C.interleaved(cases, repeats, counts={("bdf",): bdf_repeats})
    print(f"timing rounds: {time.perf_counter() - t0:.1f} s")
    med = {k: C.median(v) for k, v in times.items()}
    t_bdf = med[("bdf",)]

    # ---- compile time, apart from run time
    if quick:
        compile_info = {f: dict(method="in-process first call minus warm median",
                                cold=None, cached=None,
                                inproc_s=first_inproc[f] - med[("rockjit", n_def, f)])
                        for f in forcings}
    else:
        compile_info = {}
        for f in forcings:
            ct = C.compile_times(dict(base, n_steps=n_def, forcing=f))
            compile_info[f] = dict(method="fresh process, empty NUMBA_CACHE_DIR (cold) and "
                                          "again with the cache it wrote (cached)",
                                   inproc_s=first_inproc[f] - med[("rockjit", n_def, f)], **ct)
            print(f"compile {f}: cold {ct['cold']['compile_s']:.2f} s, "
                  f"cached {ct['cached']['compile_s']:.2f} s")

    def compile_cols(f):
        ci = compile_info[f]
        if ci["cold"] is None:
            return ci["inproc_s"], None
        return ci["cold"]["compile_s"], ci["cached"]["compile_s"]

    # ---- rows
    floor = {f: refs[f]["diff_state"] for f in forcings}
    headers = ["method", "N / tolerances", "forcing", "wall median (s)", "compile, cold (s)",
               "compile, cached (s)", "final-state error", "max impact-time error", "n_rhs",
               "speed-up vs BDF"]
    rows, records = [], []
    for f in forcings:
        for n in ns:
            k = ("rockjit", n, f)
            r = results[k]
            err = final_error(r, ref_of[f])
            ierr = impact_error(r, ref_of[f])
            cold, cached = compile_cols(f) if n == n_def else ("same kernel", "same kernel")
            label = f"N={n}" + (" (default)" if n == n_def else "")
            rows.append(["rockjit", label, f, med[k], cold, cached,
                         C.fmt(err) + (" †" if err < floor[f] else ""), ierr, r.n_rhs,
                         t_bdf / med[k]])
            records.append(dict(method="rockjit", n_steps=n, forcing=f, wall_median_s=med[k],
                                wall_all_s=times[k], final_state_error=err,
                                impact_time_error=ierr, n_rhs=r.n_rhs, n_impacts=r.n_impacts,
                                max_error_estimate=r.max_error_estimate,
                                speedup_vs_bdf=t_bdf / med[k]))
    rb = results[("bdf",)]
    err_bdf = final_error(rb, ref_of["embedded"])
    ierr_bdf = impact_error(rb, ref_of["embedded"])
    rows.append(["scipy BDF (the study's)", "rtol 1e-6, atol 1e-9", "embedded", t_bdf, None,
                 None, err_bdf, ierr_bdf, rb.n_rhs, 1.0])
    records.append(dict(method="scipy:BDF", rtol=1e-6, atol=1e-9, forcing="embedded",
                        wall_median_s=t_bdf, wall_all_s=times[("bdf",)],
                        final_state_error=err_bdf, impact_time_error=ierr_bdf, n_rhs=rb.n_rhs,
                        n_impacts=rb.n_impacts, speedup_vs_bdf=1.0))

    # ---- the target
    def verdict(n, f):
        k = ("rockjit", n, f)
        s = t_bdf / med[k]
        e = final_error(results[k], ref_of[f])
        return s, e, (s >= TARGET and e < err_bdf)

    met = {f: [n for n in ns if verdict(n, f)[2]] for f in forcings}
    s_def, e_def, ok_def = verdict(n_def, "closed")
    s_emb, e_emb, ok_emb = verdict(n_def, "embedded")
    # the spread of both sides' times: the machine is shared, and the ratio moves with it
    q_def = np.percentile(times[("rockjit", n_def, "closed")], [25, 75])
    bdf_range = (min(times[("bdf",)]), max(times[("bdf",)]))
    s_range = (bdf_range[0] / q_def[1], bdf_range[1] / q_def[0])

    # ---- outputs
    ref_headers = ["forcing", f"rockjit N={N_REF} wall (s)", "DOP853 1e-13/1e-14 wall (s)",
                   "final-state difference", "max impact-time difference", "impacts"]
    ref_rows = [[f, refs[f]["wall_rockjit"], refs[f]["wall_dop853"], refs[f]["diff_state"],
                 refs[f]["diff_impacts"], refs[f]["rockjit"].n_impacts] for f in forcings]
    ccold = compile_info["closed"]
    md = [f"### Reference run: hb=1, alpha=0.6, omega=1.3, Housner, z0 = Z0_STUDY, "
          f"{periods} periods{' (QUICK MODE)' if quick else ''}\n",
          C.md_table(headers, rows),
          f"\nWall times: medians of {repeats} warm runs (BDF: {bdf_repeats}), all cases "
          f"interleaved in one process. Errors: max over (theta, theta') at t = {periods}T, "
          f"against rockjit N={N_REF} with the same forcing. Compile: first call in a fresh "
          f"process minus the warm median; cold = empty numba cache, cached = the cache the "
          f"cold process wrote" + (" (quick mode: in-process first call only)." if quick
                                   else ".") +
          " † below the two references' mutual difference (not resolved).\n",
          "\nTight references (two independent ways, same forcing):\n\n",
          C.md_table(ref_headers, ref_rows),
          f"\nClosed vs embedded reference (the study's (r0, s0) has radius "
          f"{math.hypot(*rockjit.Z0_STUDY[2:]):.5f}): final states differ by "
          f"{C.fmt(closed_vs_embedded)}.\n",
          f"\n**Target** (rockjit >= {TARGET:.0f}x faster than the BDF path, with a smaller "
          f"error): at the default N={n_def} (closed forcing) rockjit is **{s_def:.0f}x** faster "
          f"with error {C.fmt(e_def)} vs BDF's {C.fmt(err_bdf)}: "
          f"**{'met' if ok_def else 'not met'}**. Spread: rockjit's quartiles "
          f"{1e3 * q_def[0]:.2f}–{1e3 * q_def[1]:.2f} ms, BDF {bdf_range[0]:.1f}–"
          f"{bdf_range[1]:.1f} s: between {s_range[0]:.0f}x and {s_range[1]:.0f}x. Embedded forcing at N={n_def} (like for like "
          f"with BDF): {s_emb:.0f}x, error {C.fmt(e_emb)}: {'met' if ok_emb else 'not met'}. "
          f"Met at N in {met['closed'] or 'none'} (closed), {met['embedded'] or 'none'} "
          f"(embedded).\n",
          f"\n{C.env_line(env)}\n"]
    if not quick:
        md.insert(-1, f"\nIn-process first call (with whatever numba cache the installed "
                      f"package already holds): closed {ccold['inproc_s']:.2f} s, embedded "
                      f"{compile_info['embedded']['inproc_s']:.2f} s; `import rockjit` "
                      f"{ccold['cold']['import_s']:.2f} s.\n")
    md_text = "".join(md)
    C.write_text(out / "reference_run.md", md_text)
    C.update_readme(args, "reference_run", md_text)
    C.write_csv(out / "reference_run.csv",
                ["method", "n_steps_or_tol", "forcing", "wall_median_s", "compile_cold_s",
                 "compile_cached_s", "final_state_error", "max_impact_time_error", "n_rhs",
                 "speedup_vs_bdf"],
                [[r[0], r[1], r[2], r[3], r[4], r[5], str(r[6]).rstrip(" †"), r[7], r[8], r[9]]
                 for r in rows])
    C.write_json(out / "reference_run.json", dict(
        run=dict(base, z0=list(rockjit.Z0_STUDY)), quick=quick, repeats=repeats,
        bdf_repeats=bdf_repeats, default_n=n_def, environment=env, rows=records,
        references={f: dict(wall_rockjit_s=refs[f]["wall_rockjit"],
                            wall_dop853_s=refs[f]["wall_dop853"],
                            final_state_difference=refs[f]["diff_state"],
                            impact_time_difference=refs[f]["diff_impacts"],
                            n_impacts=refs[f]["rockjit"].n_impacts) for f in forcings},
        closed_vs_embedded_reference=closed_vs_embedded, compile=compile_info,
        first_call_in_process_s=first_inproc,
        target=dict(speedup=TARGET, default_n_closed=dict(speedup=s_def, error=e_def, met=ok_def,
                                                          speedup_range=s_range),
                    default_n_embedded=dict(speedup=s_emb, error=e_emb, met=ok_emb),
                    bdf_error=err_bdf, met_at_n=met)))
    C.check_unchanged(env)
    plot(out / "reference_run.png", ns, med, results, ref_of, floor, t_bdf, err_bdf, n_def,
         periods)
    print(md_text)
    return 0


def plot(path, ns, med, results, ref_of, floor, t_bdf, err_bdf, n_def, periods):
    plt = C.pyplot()
    fig, ax = plt.subplots(figsize=(6.4, 4.6), layout="constrained")
    style = {"closed": ("C0", "o"), "embedded": ("C1", "s")}
    for f, (c, m) in style.items():
        x = [med[("rockjit", n, f)] for n in ns]
        y = [max(final_error(results[("rockjit", n, f)], ref_of[f]), 1e-17) for n in ns]
        ax.loglog(x, y, marker=m, color=c, label=f"rockjit, {f} forcing")
        for n, xi, yi in zip(ns, x, y):
            ax.annotate(f"N={n}" + ("*" if n == n_def else ""), (xi, yi), textcoords="offset points",
                        xytext=(5, 4), fontsize=7, color=c)
        ax.axhline(floor[f], color=c, ls=":", lw=0.8)
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
    C.save_figure(fig, path, dpi=130)
    plt.close(fig)


if __name__ == "__main__":
    sys.exit(main())
