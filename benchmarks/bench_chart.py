"""The forcing plane with exact boundaries: the time of ``rockjit.chart`` and the two laws'
period-1 boundaries across the plane.

1. **Speed.** The h/b = 1 Housner chart: 200 x 200 cells over alpha in [0.2, 1.2], omega in
   [0.8, 3] (``rockjit.plane``'s brute force from the study's z0, without exponents, the chart's
   default) and every period-1 and period-2 bifurcation curve seeded from the five default omega
   lines and followed across it; warm (a small chart first loads numba's cache), medians of
   ``repeats`` runs, the time split between the chart, the seed lines (their sweeps and
   continuations along alpha) and the curves. Goal: at most 60 s.
2. **The laws across the plane.** For h/b = 1 and h/b = 2 and both laws: the symmetry breaking
   and the first period doubling solved on their curves (``BifurcationCurve.solve_at``, not
   interpolated) and the overturn of the study's z0 (the smallest alpha that overturns, from a
   sweep at step 0.001), every 0.1 in omega over [0.8, 3]; Mao's shift against Housner's.

    python benchmarks/bench_chart.py            # full measurement (a few minutes)
    python benchmarks/bench_chart.py --quick    # smoke mode (coarse chart, few omegas)

Writes chart.{md,csv,json,png} (the timing) and chart_laws.{md,csv,png} (the boundaries) to
benchmarks/results/ (benchmarks/results/quick/ with --quick, or --out DIR).
"""

from __future__ import annotations

import math
import sys
import time
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parent))
import _common as H  # noqa: E402

import rockjit  # noqa: E402
from rockjit import Block, ChartCurves, Classification, Harmonic  # noqa: E402

TARGET_S = 60.0
ALPHA, OMEGA = (0.2, 1.2), (0.8, 3.0)
FULL = dict(grid=(200, 200), max_period=2, repeats=3, laws_grid=(60, 60),
            omegas=np.round(np.arange(0.8, 3.0 + 1e-9, 0.1), 10), over_step=0.001)
QUICK = dict(grid=(30, 30), max_period=1, repeats=1, laws_grid=(20, 20),
             omegas=np.array([1.0, 1.6, 2.4]), over_step=0.01)
BOUNDARIES = ("symmetry_breaking", "period_doubling", "overturn")


# --------------------------------------------------------------------------- speed

def timing_runs(cfg):
    block = Block(hb=1)
    rockjit.chart(block, ALPHA, OMEGA, grid=(12, 12), curves=ChartCurves(max_period=1))  # warm
    runs = []
    for i in range(cfg["repeats"]):
        load = H.loadavg()[0]
        t0 = time.perf_counter()
        c0 = time.process_time()
        res = rockjit.chart(block, ALPHA, OMEGA, grid=cfg["grid"],
                            curves=ChartCurves(max_period=cfg["max_period"]))
        wall, cpu = time.perf_counter() - t0, time.process_time() - c0
        runs.append(dict(run=i, total_s=wall, cpu_s=cpu, load1=load, **res.timing,
                         curves=len(res.curves),
                         curve_points=int(sum(len(c) for c in res.curves)),
                         kinds=sorted(f"{c.type}/{c.period}" for c in res.curves),
                         calls=int(sum(c.n_simulate for c in res.curves))))
        print(f"run {i}: {wall:.1f} s {res.timing}", flush=True)
    return runs, res


def timing_markdown(runs, cfg, quick, env):
    keys = ("chart_s", "seeds_s", "curves_s", "total_s")
    med = {k: H.median([r[k] for r in runs]) for k in keys}
    met = med["total_s"] <= TARGET_S
    na, nw = cfg["grid"]
    rows = [[k.replace("_s", ""), med[k], ", ".join(f"{r[k]:.1f}" for r in runs)] for k in keys]
    last = runs[-1]
    q = H.quick_note(quick, f"{na} x {nw} cells, period 1 only")
    return "".join([
        f"### The h/b = 1 Housner chart with its bifurcation curves{q}\n",
        f"`rockjit.chart(Block(hb=1), {ALPHA}, {OMEGA}, grid={cfg['grid']}, "
        f"curves=ChartCurves(max_period={cfg['max_period']}))`: {na * nw} cells from the study's z0 (no exponents, "
        f"the chart's default), five seed lines, {last['curves']} curves "
        f"({', '.join(last['kinds'])}; {last['curve_points']} points, "
        f"{last['calls']} runs of the orbits' shooting). Warm; median of {len(runs)}.\n\n",
        H.md_table(["part", "median (s)", "runs (s)"], rows),
        f"\n**Goal** (at most {TARGET_S:g} s warm): {med['total_s']:.1f} s, "
        + ("**goal reached**.\n" if met else
           "**out of reach** on this shared machine (see the load below).\n"),
        "\nchart: the brute-force plane (rockjit.plane); seeds: the five omega lines' sweeps "
        "(step 0.005, no exponents) and their continuation along alpha with every bifurcation "
        "located; curves: the continuation of each bifurcation in the plane. The process CPU "
        f"time of a run was {H.median([r['cpu_s'] for r in runs]):.1f} s (both cores).\n",
        f"\nThe machine is shared (load average 1/5/15 min {env['load_start']} at the start, "
        f"{env['load_end']} at the end).\n",
        f"\n{H.env_line(env)}\n"]), med, met


# --------------------------------------------------------------------------- the two laws

def overturn_onset(block, omega, step):
    """The smallest alpha in ``ALPHA`` at which the study's z0 overturns (``nan``: none)."""
    sw = rockjit.sweep(block, Harmonic(omega=float(omega)), rockjit.alpha_grid(ALPHA, step),
                       lyapunov=False, classification=Classification(attractors=False))
    over = np.asarray(sw.label) == rockjit.BEHAVIOURS.index("overturn")
    return float(np.asarray(sw.alpha)[np.argmax(over)]) if over.any() else math.nan


def boundary(res, kind, omega):
    """The period-1 boundary's alpha at ``omega``: the lowest crossing of its curves."""
    if kind == "overturn":
        return math.nan
    vals = [a for c in res.curves if c.type == kind and c.period == 1
            for a in c.solve_at(float(omega)) if math.isfinite(a)]
    return min(vals) if vals else math.nan


def laws_rows(cfg):
    rows = []
    for hb in (1, 2):
        res = {law: rockjit.chart(Block(hb=hb, law=law), ALPHA, OMEGA, grid=cfg["laws_grid"],
                                  curves=ChartCurves(max_period=1))
               for law in ("housner", "mao")}
        for w in cfg["omegas"]:
            for kind in BOUNDARIES:
                a = {}
                for law, r in res.items():
                    a[law] = overturn_onset(r.block, w, cfg["over_step"]) \
                        if kind == "overturn" else boundary(r, kind, w)
                shift = a["mao"] - a["housner"]
                rows.append([hb, kind, float(w), a["housner"], a["mao"], shift])
        print(f"h/b = {hb}: done", flush=True)
    return rows


def laws_markdown(rows, cfg, quick, env):
    out = [f"### Where Mao's law moves the period-1 boundaries{H.quick_note(quick)}\n",
           f"alpha of each boundary every {'0.1' if not quick else 'few'} in omega over "
           f"[0.8, 3]: the symmetry breaking and the first period doubling solved on their "
           f"curves (to 1e-10), the overturn of the study's z0 from a sweep at step "
           f"{cfg['over_step']:g} (the smallest alpha that overturns). Shift: Mao minus "
           "Housner; — where a boundary does not lie in alpha in [0.2, 1.2].\n"]
    for hb in (1, 2):
        for kind in BOUNDARIES:
            digits = 3 if kind == "overturn" else 6
            sel = [r for r in rows if r[0] == hb and r[1] == kind]
            sh = np.array([r[5] for r in sel], float)
            ok = np.isfinite(sh)
            rng = (f"{sh[ok].min():+.4f} to {sh[ok].max():+.4f} (mean {sh[ok].mean():+.4f}, "
                   f"over {ok.sum()} of {len(sel)} omegas)" if ok.any() else "—")
            out.append(f"\n**h/b = {hb}, {kind.replace('_', ' ')}**: shift {rng}.\n\n")
            out.append(H.md_table(["omega", "Housner", "Mao", "shift"],
                                  [[f"{r[2]:g}", *(_num(v, digits) for v in r[3:6])]
                                   for r in sel]))
    out.append(f"\n{H.env_line(env)}\n")
    return "".join(out)


def _num(v, digits):
    return "—" if not math.isfinite(v) else f"{v:.{digits}f}"


def laws_figure(rows):
    plt = H.pyplot()
    fig, axes = plt.subplots(1, 2, figsize=(11, 4.4), layout="constrained", sharey=True)
    styles = {"symmetry_breaking": "--", "period_doubling": "-.", "overturn": "-"}
    for ax, hb in zip(axes, (1, 2)):
        for kind, ls in styles.items():
            for law, col in (("housner", 3), ("mao", 4)):
                sel = [r for r in rows if r[0] == hb and r[1] == kind]
                ax.plot([r[2] for r in sel], [r[col] for r in sel], ls=ls,
                        color="C0" if law == "housner" else "C3", marker=".",
                        label=f"{law}: {kind.replace('_', ' ')}")
        ax.set_title(f"h/b = {hb}")
        ax.set_xlabel("\u03c9")
    axes[0].set_ylabel("\u03b1 of the boundary")
    axes[1].legend(fontsize=7, loc="upper right")
    return fig


def timing_figure(runs, res):
    from rockjit.plotting.chart import fig_chart
    return fig_chart(res, title=f"h/b = 1, Housner: {res.plane.alpha.size} x "
                                f"{res.plane.omega.size} cells and {len(res.curves)} curves in "
                                f"{runs[-1]['total_s']:.0f} s")


# --------------------------------------------------------------------------- main

def main(argv=None):
    b = H.Bench(__doc__, argv)
    cfg = QUICK if b.quick else FULL
    b.env["load_start"] = H.load_text()
    runs, res = timing_runs(cfg)
    b.env["load_end"] = H.load_text()
    md, med, met = timing_markdown(runs, cfg, b.quick, b.env)
    cols = ["run", "chart_s", "seeds_s", "curves_s", "total_s", "cpu_s", "cells", "curves",
            "curve_points", "load1"]
    cells = cfg["grid"][0] * cfg["grid"][1]
    b.report("chart", markdown=md,
             csv=(cols, [[r["run"], r["chart_s"], r["seeds_s"], r["curves_s"], r["total_s"],
                          r["cpu_s"], cells, r["curves"], r["curve_points"], r["load1"]]
                         for r in runs]),
             data=dict(quick=b.quick, environment=b.env, grid=list(cfg["grid"]),
                       max_period=cfg["max_period"], runs=runs, medians=med, target_s=TARGET_S,
                       target_met=met,
                       curves=[c.to_dict(points=False) for c in res.curves]),
             figures=[("chart.png", timing_figure(runs, res), 90)])
    rows = laws_rows(cfg)
    b.report("chart_laws", markdown=laws_markdown(rows, cfg, b.quick, b.env),
             csv=(["hb", "boundary", "omega", "alpha_housner", "alpha_mao", "shift"], rows),
             figures=[("chart_laws.png", laws_figure(rows), 110)])
    return 0


if __name__ == "__main__":
    sys.exit(main())
