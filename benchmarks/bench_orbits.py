"""The speed of shooting and continuation, and the accuracy of the located bifurcations.

On the study's case (hb=1, Housner, omega=1.3, alpha in [0.5, 1.0]):

1. one Newton solve of a period-1 orbit (``rockjit.orbits.periodic_orbit``, alpha = 0.8, the
   asymmetric orbit, seeded from the sweep cell's stroboscopic point): median of repeats, warm
   (target 5 ms);
2. ``continue_branches`` over [0.5, 1.0] from the study's sweep (step 0.001), every branch of
   its periodic attractors followed, every bifurcation located: median of repeats, warm
   (target 5 s); the sweep's own time is reported apart;
3. calls of ``rockjit.simulate``: in all, and per located bifurcation (the calls its bracketing
   solve spent);
4. where the time goes: the time inside ``simulate`` (the compiled run and its Python wrapper),
   the per-call cost against the per-period cost (a fit over runs of 1 to 16 periods), and the
   rest (orbits' own Python);
5. accuracy: the residual of orbits found at N = 160, 256, 384 (the default) and 512 steps per
   period in a converged plain run (N = 8192), over orbits sampled along every branch with
   |mu| < 50; each bifurcation's alpha at the default N against twice it (the discretisation's
   shift);
6. compile time, apart: the first solve in a fresh process, with the kernels in numba's cache
   and (full runs only) from an empty cache.

    python benchmarks/bench_orbits.py            # full measurement (a few minutes, compiles)
    python benchmarks/bench_orbits.py --quick    # smoke mode (coarser sweep, fewer repeats)

Writes orbits.{md,csv,json,png} and orbits_branches.png to benchmarks/results/
(benchmarks/results/quick/ with --quick, or --out DIR), through rockjit.storage.atomic's writers.
"""

from __future__ import annotations

import json
import math
import os
import subprocess
import sys
import tempfile
import textwrap
import time
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parent))
import _common as C  # noqa: E402

import rockjit  # noqa: E402
from rockjit import Block, Harmonic, Integration, orbits  # noqa: E402
from rockjit.orbits import shooting  # noqa: E402
from rockjit.plotting import figures as plotting  # noqa: E402

CASE = dict(hb=1.0, law="housner", omega=1.3)
BLOCK = Block(hb=CASE["hb"], law=CASE["law"])
SWEEP_FORCING = Harmonic(omega=CASE["omega"])
RANGE = (0.5, 1.0)
NEWTON_ALPHA = 0.8
TARGET_NEWTON_S = 5e-3
TARGET_CONT_S = 5.0


_PROBE = textwrap.dedent("""
    import json, statistics, sys, time
    t0 = time.perf_counter()
    import numpy as np
    from rockjit import Block, Harmonic
    from rockjit import orbits
    t1 = time.perf_counter()
    a = json.loads(sys.argv[1])
    b = Block(hb=a["hb"], law=a["law"])
    f = Harmonic(alpha=a["alpha"], omega=a["omega"], phase=a["phase"])
    orbits.periodic_orbit(b, f, a["seed"], 1)
    t2 = time.perf_counter()
    warm = []
    for _ in range(20):
        s = time.perf_counter()
        orbits.periodic_orbit(b, f, a["seed"], 1)
        warm.append(time.perf_counter() - s)
    w = statistics.median(warm)
    print(json.dumps(dict(import_s=t1 - t0, first_s=t2 - t1, warm_s=w, compile_s=t2 - t1 - w)))
""")


def probe(args: dict, cache_dir: str | None) -> dict:
    """The first and warm solves in a fresh process (``cache_dir``: an empty numba cache)."""
    env = dict(os.environ)
    if cache_dir is not None:
        env["NUMBA_CACHE_DIR"] = cache_dir
    root = str(Path(rockjit.__file__).resolve().parent.parent)
    env["PYTHONPATH"] = root + os.pathsep + env.get("PYTHONPATH", "")
    with tempfile.TemporaryDirectory() as cwd:
        proc = subprocess.run([sys.executable, "-c", _PROBE, json.dumps(args)], env=env,
                              capture_output=True, text=True, check=True, cwd=cwd)
    return json.loads(proc.stdout.strip().splitlines()[-1])


class Timer:
    """Wraps ``rockjit.orbits.shooting.simulate`` (every run of the orbits) to count its calls
    and the time spent in them."""

    def __init__(self):
        self.calls = 0
        self.seconds = 0.0
        self.inner = shooting.simulate

    def __call__(self, *a, **k):
        t = time.perf_counter()
        try:
            return self.inner(*a, **k)
        finally:
            self.seconds += time.perf_counter() - t
            self.calls += 1

    def __enter__(self):
        shooting.simulate = self
        return self

    def __exit__(self, *exc):
        shooting.simulate = self.inner


def sweep_seed(sw, alpha):
    i = int(np.argmin(np.abs(sw.alpha - alpha)))
    pts = sw.strobe[i][np.all(np.isfinite(sw.strobe[i]), axis=1)]
    return float(sw.alpha[i]), pts[-1].copy()


def call_cost(phase, seed, repeats):
    """Median time of one tangent run (default N) over 1, 2, 4, 8, 16 periods, linear fit."""
    P = np.array([1, 2, 4, 8, 16])
    med = []
    forcing = Harmonic(alpha=NEWTON_ALPHA, omega=CASE["omega"], phase=phase)
    for p in P:
        args = (BLOCK, forcing, (seed[0], seed[1]))
        kw = dict(integration=Integration(periods=int(p), n_steps=orbits.N_ORBIT, qr_every=0),
                  lyapunov=True, record_stride=1)
        rockjit.simulate(*args, **kw)
        ts = [C.timed(rockjit.simulate, *args, **kw)[0] for _ in range(repeats)]
        med.append(C.median(ts))
    slope, icpt = np.polyfit(P, med, 1)
    return dict(periods=P.tolist(), median_s=med, per_call_s=float(icpt),
                per_period_s=float(slope))


def residual_study(cont, ns, n_ref, per_branch):
    """Largest plain-run residual (at ``n_ref``) of orbits shot at each N in ``ns``."""
    out = {n: [] for n in ns}
    samples = []
    for br in cont.branches:
        ok = np.nonzero(np.abs(br.multipliers[:, 0]) < 50)[0]
        for k in ok[np.linspace(0, ok.size - 1, min(per_branch, ok.size)).astype(int)] \
                if ok.size else []:
            samples.append((float(br.value[k]), br.cycle[k].copy(), br.period))
    for a, cyc, p in samples:
        f = Harmonic(alpha=a, omega=CASE["omega"], phase=cont.phase)
        for n in ns:
            try:
                o = orbits.periodic_orbit(BLOCK, f, cyc, p, n_steps=n,
                                          shooting=orbits.Shooting(graze_tol=0))
            except orbits.OrbitRefused:
                continue
            r = rockjit.simulate(BLOCK, f, (o.state[0], o.state[1]),
                                 integration=Integration(periods=p, n_steps=n_ref))
            out[n].append(float(np.abs(r.strobe[p, :2] - o.state).max()))
    return {n: dict(max=max(v) if v else math.nan, median=C.median(v) if v else math.nan,
                    count=len(v)) for n, v in out.items()}, len(samples)


def match_shift(a, b):
    """|alpha_b - alpha_a| for each bifurcation of ``a`` (same type and period, nearest)."""
    out = []
    for x in a.bifurcations:
        cand = [y.alpha for y in b.bifurcations if y.type == x.type and y.period == x.period]
        out.append(min((abs(y - x.alpha) for y in cand), default=math.nan))
    return out


def fmt_mu(mu):
    return ", ".join(f"{m.real:.6g}" if abs(m.imag) < 1e-12 else f"{m.real:.4g}{m.imag:+.4g}i"
                     for m in mu)


def main(argv=None):
    b = C.Bench(__doc__, argv)
    quick = b.quick
    step = 0.005 if quick else 0.001
    rep_newton = 5 if quick else 41
    rep_cont = 1 if quick else 5
    env = b.env
    print(C.env_line(env))

    # -- the sweep (seeds), first calls (compile or load from cache) --------------------------
    alphas = rockjit.alpha_grid(RANGE, step)
    t_sweep0, sw = C.timed(rockjit.sweep, BLOCK, SWEEP_FORCING, alphas)
    t_sweep, sw = C.timed(rockjit.sweep, BLOCK, SWEEP_FORCING, alphas)
    z = sw.settings["z0"]
    phase = math.atan2(z[2], z[3])
    a_seed, seed = sweep_seed(sw, NEWTON_ALPHA)
    frc = Harmonic(alpha=a_seed, omega=CASE["omega"], phase=phase)
    t_first_newton, orb = C.timed(orbits.periodic_orbit, BLOCK, frc, seed, 1)
    t_first_cont, _ = C.timed(orbits.continue_branches, BLOCK, SWEEP_FORCING, RANGE, sweep=sw)
    print(f"sweep {t_sweep:.3f} s (first {t_sweep0:.3f} s); first solve {t_first_newton:.3f} s;"
          f" first continuation {t_first_cont:.3f} s")

    # -- 1, 2: warm timings, side by side -------------------------------------------------------
    res = {}

    rough = seed + np.array([0.02, -0.02])

    def newton():
        res["newton"] = orbits.periodic_orbit(BLOCK, frc, seed, 1)

    def newton_rough():
        res["rough"] = orbits.periodic_orbit(BLOCK, frc, rough, 1)

    def cont():
        res["cont"] = orbits.continue_branches(BLOCK, SWEEP_FORCING, RANGE, sweep=sw)

    times = C.side_by_side({"newton": newton, "rough": newton_rough, "cont": cont}, rep_newton,
                           counts={"cont": rep_cont}).wall
    t_newton = C.median(times["newton"])
    t_rough = C.median(times["rough"])
    t_cont = C.median(times["cont"])
    orb = res["newton"]
    c = res["cont"]
    print(f"Newton solve: {t_newton * 1e3:.3f} ms median of {len(times['newton'])} "
          f"({orb.iterations} iterations, {orb.n_simulate} simulate calls, residual "
          f"{orb.residual:.2g})")
    print(f"Newton solve from a seed 0.02 off: {t_rough * 1e3:.3f} ms "
          f"({res['rough'].iterations} iterations, {res['rough'].n_simulate} simulate calls)")
    print(f"continuation: {t_cont:.3f} s median of {len(times['cont'])}; {len(c.branches)} "
          f"branches, {len(c.bifurcations)} bifurcations, {c.n_simulate} simulate calls")

    # -- 3, 4: calls and where the time goes ----------------------------------------------------
    with Timer() as tm:
        t_prof, c2 = C.timed(orbits.continue_branches, BLOCK, SWEEP_FORCING, RANGE, sweep=sw)
    cost = call_cost(phase, orb.state, 5 if quick else 41)
    located = [b for b in c.bifurcations if b.type != "grazing"]
    calls_per_bif = [b.n_simulate for b in located]
    print(f"time in simulate: {tm.seconds:.3f} of {t_prof:.3f} s ({tm.calls} calls); "
          f"per call {cost['per_call_s'] * 1e6:.1f} us + {cost['per_period_s'] * 1e6:.1f} us "
          f"per period")

    # -- 5: accuracy ------------------------------------------------------------------------
    ns = (160, 256, orbits.N_ORBIT, 512) if orbits.N_ORBIT not in (160, 256, 512) else \
        (160, 256, 512)
    resid, n_samples = residual_study(c, ns, 8192, 3 if quick else 8)
    for n in ns:
        print(f"N = {n}: largest residual in a converged run {resid[n]['max']:.2g} "
              f"({resid[n]['count']} orbits)")
    n2 = 2 * orbits.N_ORBIT
    c2n = orbits.continue_branches(BLOCK, SWEEP_FORCING, RANGE, sweep=sw, n_steps=n2)
    shift = match_shift(c, c2n)

    # -- 6: compile time --------------------------------------------------------------------
    pargs = dict(**CASE, alpha=a_seed, seed=seed.tolist(), phase=phase)
    compile_info = dict(cached=probe(pargs, None), cold=None)
    if not quick:
        with tempfile.TemporaryDirectory(prefix="rockjit-numba-cache-") as d:
            compile_info["cold"] = probe(pargs, d)
    for k, v in compile_info.items():
        if v:
            print(f"first solve in a fresh process ({k} kernels): {v['first_s']:.2f} s "
                  f"(compile/load {v['compile_s']:.2f} s, import {v['import_s']:.2f} s)")
    # -- tables -----------------------------------------------------------------------------
    rows = [
        ("one Newton solve, period 1 (alpha = 0.8), warm", t_newton * 1e3, "ms",
         TARGET_NEWTON_S * 1e3),
        ("one Newton solve from a seed 0.02 off in theta and theta', warm", t_rough * 1e3, "ms",
         TARGET_NEWTON_S * 1e3),
        ("the same, fastest of the repeats (least disturbed by other load)",
         min(times["rough"]) * 1e3, "ms", None),
        ("continuation over alpha in [0.5, 1.0], all bifurcations located, warm", t_cont, "s",
         TARGET_CONT_S),
        ("the sweep that seeds it (not included above)", t_sweep, "s", None),
        ("simulate calls of the continuation", c.n_simulate, "", None),
        ("simulate calls per located bifurcation (median)", C.median(calls_per_bif), "", None),
        ("simulate calls per located bifurcation (max)", max(calls_per_bif), "", None),
        ("time inside simulate, share of the continuation", tm.seconds / t_prof, "", None),
        ("one tangent run: cost per call (fit)", cost["per_call_s"] * 1e6, "us", None),
        (f"one tangent run: cost per period (fit, N = {orbits.N_ORBIT})",
         cost["per_period_s"] * 1e6, "us", None),
    ] + [(f"largest residual in a converged run, orbits shot at N = {n}", resid[n]["max"],
          "", 1e-10) for n in ns] + [
        (f"largest bifurcation shift N = {orbits.N_ORBIT} -> {n2} (alpha)",
         max((s for s in shift if math.isfinite(s)), default=math.nan), "", 1e-8),
        ("first solve in a fresh process, kernels cached", compile_info["cached"]["first_s"],
         "s", None),
        ("first solve in a fresh process, empty cache",
         compile_info["cold"]["first_s"] if compile_info["cold"] else math.nan, "s", None),
    ]
    bif_rows = [(b.type, f"{b.alpha:.10f}", b.period, fmt_mu(b.multipliers), b.n_simulate, s,
                 "" if b.located else "not located")
                for b, s in sorted(zip(c.bifurcations, shift), key=lambda t: t[0].alpha)]
    md = [f"# Periodic orbits: shooting and continuation ({'quick' if quick else 'full'})", "",
          C.env_line(env), "",
          f"hb = {CASE['hb']:g}, {CASE['law']}, omega = {CASE['omega']:g}, alpha in "
          f"{list(RANGE)}, sweep step {step:g}, N = {orbits.N_ORBIT}, phase {phase:.6g} (the "
          f"sweep's). Medians: Newton of {len(times['newton'])}, continuation of "
          f"{len(times['cont'])}; residuals over {n_samples} orbits sampled on the branches.",
          "", C.md_table(["measurement", "value", "unit", "target"], rows), "",
          "## Located bifurcations", "",
          C.md_table(["type", "alpha", "p", "multipliers", "simulate calls",
                      f"shift at N = {n2}", "note"], bif_rows), "",
          "## Branches", "",
          C.md_table(["#", "p", "symmetric", "points", "alpha from", "to", "ends", "origin"],
                     [(i, br.period, str(br.symmetric), len(br), f"{br.value.min():.6f}",
                       f"{br.value.max():.6f}", " / ".join(br.ends), br.origin)
                      for i, br in enumerate(c.branches)])]
    # -- figures ----------------------------------------------------------------------------
    summary, _ = c.to_summary()
    data = dict(
        environment=env, quick=quick, case=dict(**CASE, alpha_range=list(RANGE),
                                                sweep_step=step, phase=phase),
        newton=dict(median_s=t_newton, repeats=len(times["newton"]), iterations=orb.iterations,
                    simulate_calls=orb.n_simulate, residual=orb.residual, all_s=times["newton"],
                    seed=seed.tolist(), seed_alpha=a_seed),
        newton_rough=dict(median_s=t_rough, iterations=res["rough"].iterations,
                          simulate_calls=res["rough"].n_simulate, all_s=times["rough"],
                          seed=rough.tolist()),
        continuation=dict(median_s=t_cont, repeats=len(times["cont"]), all_s=times["cont"],
                          simulate_calls=c.n_simulate, calls_per_bifurcation=calls_per_bif,
                          seconds_in_simulate=tm.seconds, seconds_profiled=t_prof),
        sweep_s=t_sweep, first_calls=dict(newton_s=t_first_newton, continuation_s=t_first_cont),
        call_cost=cost, residuals={str(k): v for k, v in resid.items()},
        shift_2n=dict(n_steps=n2, shift=shift), compile=compile_info, result=summary)
    from matplotlib.figure import Figure
    fig = Figure(figsize=(11, 4), layout="constrained")
    ax1, ax2, ax3 = fig.subplots(1, 3)
    ax1.semilogy(ns, [resid[n]["max"] for n in ns], "o-", label="largest")
    ax1.semilogy(ns, [resid[n]["median"] for n in ns], "s--", label="median")
    ax1.axhline(1e-10, color="r", lw=0.8, label="1e-10")
    ax1.set_xlabel("steps per period N")
    ax1.set_ylabel("|P^p(x) - x| at N = 8192")
    ax1.set_title("residual of shot orbits", fontsize=10)
    ax1.legend(fontsize=8)
    ax2.bar(["Newton\n(ms)", "Newton, seed\n0.02 off (ms)", "continuation\n(s)"],
            [t_newton * 1e3, t_rough * 1e3, t_cont], color=["#1f77b4", "#6baed6", "#2ca02c"])
    ax2.plot([-0.4, 1.4], [TARGET_NEWTON_S * 1e3] * 2, "r-")
    ax2.plot([1.6, 2.4], [TARGET_CONT_S] * 2, "r-", label="targets")
    ax2.set_title("warm medians", fontsize=10)
    ax2.legend(fontsize=8)
    ax3.plot(cost["periods"], np.array(cost["median_s"]) * 1e6, "o-")
    ax3.set_xlabel("periods per simulate call")
    ax3.set_ylabel(f"\u00b5s per call (tangent, N = {orbits.N_ORBIT})")
    ax3.set_title(f"{cost['per_call_s'] * 1e6:.0f} \u00b5s per call + "
                  f"{cost['per_period_s'] * 1e6:.0f} \u00b5s per period", fontsize=10)
    b.report("orbits", markdown="\n".join(md),
             csv=(["measurement", "value", "unit", "target"], rows), data=data,
             figures=[("orbits.png", fig, 150),
                      ("orbits_branches.png", plotting.fig_branches(c, sw), 150)])
    return 0


if __name__ == "__main__":
    sys.exit(main())
