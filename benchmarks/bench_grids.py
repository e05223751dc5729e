"""Sweeps and basins: wall time, threads, early stopping and grid resolution.

Everything at the study's settings (docs/theory/study.md), measured side by side in one process
(the numbers 1, 2, 4 and 5 name the parts in the tables and the CSV's ``item`` column):

1. the hb=1 Housner basin (100x100 cells over (theta0, theta0') in [-1, 1]^2, (r0, s0) = (0, 1),
   alpha=0.66, omega=1.3, 500 periods): 2 threads (all) vs 1 thread with early stopping (the
   default), and full length (``Classification(early_stop=False)``); fractions per behaviour;
   goal <= 2 s;
2. the hb=1 Housner alpha sweep (alpha 0.5...1.0 step 0.001 = 501 values, lambda_max on, 500
   periods, z0 = rockjit.Z0_STUDY, omega=1.3): early stopping on 2 and 1 threads, and full
   length; goal <= 3 s;
4. early stopping against full length on the study's four basins (hb=1 alpha=0.66 omega=1.3,
   hb=2 alpha=0.2 omega=1.6, Housner and Mao): percentage of cells with the same label
   (required: >= 99.9 % on each), and every differing cell;
5. grid resolution: the four basins and the sweep at n_steps = 64, 128 and 256 (GRID_N, the
   default of sweeps and basins, is one of them): label agreement of 64 and 128 with 256, wall
   time of each, and for the sweep the largest |lambda_max difference|.

(The ``rockjit paper`` command end to end is benchmarks/bench_paper.py.) Compile time of the
two grid kernels (basin: no tangent; sweep: tangent) is measured apart, in fresh processes with
an empty and then a filled numba cache.

    python benchmarks/bench_grids.py           # full measurement (~20 min on 2 loaded cores)
    python benchmarks/bench_grids.py --quick   # smoke mode (small grids, few periods)

Writes grids.{md,csv,json} and grids_{timing,agreement,sweep_resolution}.png to
benchmarks/results/ (benchmarks/results/quick/ with --quick, or --out DIR), and refreshes the
``grids`` block of benchmarks/results/grids_section.md and of benchmarks/README.md.
"""

from __future__ import annotations

import sys
import time

import numba
import numpy as np

import _common as H

import rockjit
from rockjit import BEHAVIOURS, Block, Classification, Execution, Harmonic, Integration
from rockjit.grids.plan import GRID_N
from rockjit.grids.identity import agreement

#: The study's four basins (docs/theory/study.md, figure 6): (block, forcing), every cell at
#: the forcing phase (r0, s0) = (0, 1) (a basin's default)
BASINS = (
    (Block(hb=1.0, law="housner"), Harmonic(alpha=0.66, omega=1.3)),
    (Block(hb=1.0, law="mao"), Harmonic(alpha=0.66, omega=1.3)),
    (Block(hb=2.0, law="housner"), Harmonic(alpha=0.2, omega=1.6)),
    (Block(hb=2.0, law="mao"), Harmonic(alpha=0.2, omega=1.6)),
)
#: The study's hb=1 Housner sweep over alpha at omega=1.3, from its initial state
SWEEP = (Block(hb=1.0, law="housner"), Harmonic(omega=1.3))
NS = (64, 128, 256)
N_REF = 256
#: Goals: the basin's and the sweep's wall time (early stop, all threads; the basin's was 2 s
#: when the grids were first written, 0.15 s since events are located on the interpolant), and
#: the agreement of early stopping with full length required on every basin
TARGET_BASIN_S = 0.15
TARGET_SWEEP_S = 3.0
TARGET_AGREEMENT = 99.9
SECTION = H.RESULTS / "grids_section.md"
MAX_LISTED = 12  # differing cells listed in the Markdown (all of them go to the JSON)
#: reps: items 1 and 2; reps_full: the full-length basin in item 1; reps_n: item 5
FULL = dict(grid=100, periods=500, alpha_step=0.001, reps=7, reps_full=3, reps_n=3)
QUICK = dict(grid=24, periods=60, alpha_step=0.01, reps=2, reps_full=1, reps_n=1)
THREADS_CASES = ("early, all threads", "early, 1 thread", "full length, all threads")


def basin_name(b):
    block, forcing = b
    return f"hb={block.hb:g} alpha={forcing.alpha:g} omega={forcing.omega:g} {block.law}"


def basin_tag(b):
    return f"hb{b[0].hb:g}_{b[0].law}"


class Grids:
    """The basins and the sweep of a configuration, called with the settings varied here."""

    def __init__(self, cfg):
        self.grid = cfg["grid"]
        self.periods = cfg["periods"]
        self.alpha_step = cfg["alpha_step"]
        self.alphas = rockjit.alpha_grid((0.5, 1.0), self.alpha_step)

    def integration(self, n_steps=None):
        return Integration(periods=self.periods, n_steps=n_steps)

    @staticmethod
    def options(threads, early_stop):
        return dict(classification=Classification(early_stop=early_stop),
                    execution=Execution(threads=threads))

    def basin(self, b, *, n_steps=None, threads=None, early_stop=True):
        return rockjit.basin(*b, self.grid, integration=self.integration(n_steps),
                             **self.options(threads, early_stop))

    def sweep(self, *, n_steps=None, threads=None, early_stop=True):
        return rockjit.sweep(*SWEEP, self.alphas, integration=self.integration(n_steps),
                             lyapunov=True, **self.options(threads, early_stop))

    def description(self):
        """The inputs, for the JSON: ``(basin settings, sweep settings)``."""
        return (H.encode(dict(grid=self.grid, integration=self.integration(),
                              basins=BASINS)),
                H.encode(dict(block=SWEEP[0], forcing=SWEEP[1], alpha_range=(0.5, 1.0),
                              alpha_step=self.alpha_step,
                              n_alphas=self.alphas.size, state=None,
                              z0=list(rockjit.Z0_STUDY), integration=self.integration(),
                              lyapunov=True)))


# --------------------------------------------------------------------------- comparisons

def differing_cells(a, b):
    """Every cell where the label arrays of two basins differ, as dicts."""
    out = []
    T = a.forcing.period
    for i, j in zip(*np.nonzero(a.label != b.label)):
        out.append(dict(i=int(i), j=int(j), theta0=float(a.theta0[i]),
                        dtheta0=float(a.dtheta0[j]), label_a=BEHAVIOURS[a.label[i, j]],
                        period_a=int(a.period[i, j]), t_end_a_periods=float(a.t_end[i, j] / T),
                        label_b=BEHAVIOURS[b.label[i, j]], period_b=int(b.period[i, j]),
                        t_end_b_periods=float(b.t_end[i, j] / T)))
    return out


def differing_alphas(s, ref):
    """Every alpha where two sweeps' labels differ, as dicts."""
    return [dict(alpha=float(s.alpha[k]), label=BEHAVIOURS[s.label[k]], period=int(s.period[k]),
                 label_ref=BEHAVIOURS[ref.label[k]], period_ref=int(ref.period[k]),
                 lambda_max=float(s.lambda_max[k]), lambda_max_ref=float(ref.lambda_max[k]))
            for k in np.nonzero(s.label != ref.label)[0]]


def lam_diff(sa, sb):
    """Largest |lambda_max difference| between two sweeps: over all alphas where both are
    finite, and over those where both are the same periodic behaviour."""
    la, lb = sa.lambda_max, sb.lambda_max
    fin = np.isfinite(la) & np.isfinite(lb)
    periodic = np.isin(sa.label, [BEHAVIOURS.index(n) for n in
                                  ("symmetric", "asymmetric", "multiperiodic")])
    same_per = fin & periodic & (sa.label == sb.label) & (sa.period == sb.period)
    d = np.full(la.shape, np.nan)
    d[fin] = np.abs(la[fin] - lb[fin])
    return dict(max_all=float(d[fin].max()) if fin.any() else None,
                alpha_max_all=float(sa.alpha[fin][np.argmax(d[fin])]) if fin.any() else None,
                max_same_periodic=float(d[same_per].max()) if same_per.any() else None,
                n_finite=int(fin.sum()), n_same_periodic=int(same_per.sum()))


# --------------------------------------------------------------------------- experiments

def first_calls(g):
    """The first call of each grid kernel in this process (from the package's cache)."""
    first = {}
    first["basin"], _ = H.timed(g.basin, BASINS[0])
    first["sweep"], _ = H.timed(g.sweep)
    print(f"first calls in process: basin {first['basin']:.2f} s, sweep {first['sweep']:.2f} s",
          flush=True)
    return first


def item1_basin(g, cfg):
    """Part 1: the hb=1 Housner basin, all threads vs 1 thread, early stop vs full length."""
    b0 = BASINS[0]
    t = H.side_by_side(dict(zip(THREADS_CASES, (
        lambda: g.basin(b0),
        lambda: g.basin(b0, threads=1),
        lambda: g.basin(b0, early_stop=False)))), cfg["reps"],
        counts={"full length, all threads": cfg["reps_full"]})
    a, one = t.result["early, all threads"], t.result["early, 1 thread"]
    identical = bool(np.array_equal(a.label, one.label) and np.array_equal(a.t_end, one.t_end))
    print("item 1:", {k: round(v, 3) for k, v in t.medians().items()}, flush=True)
    return t, identical


def item2_sweep(g, cfg):
    """Part 2: the hb=1 Housner sweep, all threads vs 1 thread, early stop vs full length."""
    t = H.side_by_side(dict(zip(THREADS_CASES, (
        lambda: g.sweep(),
        lambda: g.sweep(threads=1),
        lambda: g.sweep(early_stop=False)))), cfg["reps"])
    a, one = t.result["early, all threads"], t.result["early, 1 thread"]
    identical = bool(np.array_equal(a.label, one.label)
                     and np.array_equal(a.lambda_max, one.lambda_max, equal_nan=True))
    full = t.result["full length, all threads"]
    early_vs_full = dict(agreement=agreement(a.label, full.label),
                         differing=[dict(alpha=float(a.alpha[k]), early=BEHAVIOURS[a.label[k]],
                                         full=BEHAVIOURS[full.label[k]],
                                         period_early=int(a.period[k]),
                                         period_full=int(full.period[k]))
                                    for k in np.nonzero(a.label != full.label)[0]],
                         lam=lam_diff(a, full))
    print("item 2:", {k: round(v, 3) for k, v in t.medians().items()}, flush=True)
    return t, identical, early_vs_full


def item5_resolution(g, cfg):
    """Part 5 (and the early-stop half of part 4): the four basins and the sweep at each N.

    Returns ``{tag or "sweep": Timings keyed by N}``.
    """
    out = {}
    for b in BASINS:
        out[basin_tag(b)] = t = H.side_by_side(
            {n: (lambda n=n: g.basin(b, n_steps=n)) for n in NS}, cfg["reps_n"])
        print(f"item 5 {basin_name(b)}:", {n: round(t.median(n), 3) for n in NS}, flush=True)
    out["sweep"] = t = H.side_by_side({n: (lambda n=n: g.sweep(n_steps=n)) for n in NS},
                                      cfg["reps_n"])
    print("item 5 sweep:", {n: round(t.median(n), 3) for n in NS}, flush=True)
    return out


def item4_full_length(g, t1):
    """Part 4's full-length basins: ``{tag: (wall s, CPU s, result)}`` (hb=1 Housner's is
    part 1's)."""
    k = "full length, all threads"
    out = {basin_tag(BASINS[0]): (t1.median(k), t1.cpu_median(k), t1.result[k])}
    for b in BASINS[1:]:
        out[basin_tag(b)] = H.timed_cpu(g.basin, b, early_stop=False)
        print(f"item 4 full length {basin_name(b)}: {out[basin_tag(b)][0]:.1f} s", flush=True)
    return out


def compile_cost(g):
    """Compile time of the two grid kernels, apart, in three fresh processes each.

    Three, not two: before commit 4e61b69 rockjit's cache check found the folder the first
    process wrote without its source stamp and emptied it, so the second process compiled
    again. The second process shows that it no longer does; the third is what every later
    process sees.
    """
    processes = ("cold", "second", "cached")
    kw = dict(integration=g.integration())
    return dict(basin=H.compile_times("basin", (*BASINS[0], g.grid), kw, processes=processes,
                                      warm_repeats=2),
                sweep=H.compile_times("sweep", (*SWEEP, g.alphas), dict(kw, lyapunov=True),
                                      processes=processes, warm_repeats=2))


# --------------------------------------------------------------------------- summaries

def item4_rows(t5, full):
    out = []
    for b in BASINS:
        tag = basin_tag(b)
        e, (wall_full, cpu_full, f) = t5[tag].result[GRID_N], full[tag]
        diff = differing_cells(e, f)
        out.append(dict(basin=basin_name(b), tag=tag, agreement=agreement(e.label, f.label),
                        n_differ=len(diff), differing=diff,
                        wall_early_s=t5[tag].median(GRID_N), wall_full_s=wall_full,
                        cpu_early_s=t5[tag].cpu_median(GRID_N), cpu_full_s=cpu_full,
                        fractions_early=e.fractions(), fractions_full=f.fractions(),
                        mean_t_end_early_periods=float(np.mean(e.t_end)
                                                       / b[1].period)))
    return out


def item5_rows(t5):
    out = []
    for b in BASINS:
        tag = basin_tag(b)
        t = t5[tag]
        ref = t.result[N_REF]
        row = dict(basin=basin_name(b), tag=tag, wall_s={n: t.median(n) for n in NS},
                   cpu_s={n: t.cpu_median(n) for n in NS}, wall_all_s=dict(t.wall),
                   fractions={n: t.result[n].fractions() for n in NS})
        for n in NS:
            if n != N_REF:
                row[f"agreement_{n}"] = agreement(t.result[n].label, ref.label)
                row[f"differing_{n}"] = differing_cells(t.result[n], ref)
        out.append(row)
    t = t5["sweep"]
    sw = t.result
    sweep5 = dict(wall_s={n: t.median(n) for n in NS}, cpu_s={n: t.cpu_median(n) for n in NS},
                  wall_all_s=dict(t.wall))
    for n in NS:
        if n != N_REF:
            sweep5[f"agreement_{n}"] = agreement(sw[n].label, sw[N_REF].label)
            sweep5[f"lam_{n}"] = lam_diff(sw[n], sw[N_REF])
            sweep5[f"differing_{n}"] = differing_alphas(sw[n], sw[N_REF])
    return out, sweep5


# --------------------------------------------------------------------------- the report

def _threads_table(t):
    """Items 1 and 2: each case's wall and CPU time, against early stopping on all threads."""
    base = t.median("early, all threads")
    return H.md_table(["case", "wall median (s)", "runs", "time / early all threads",
                       "CPU median (s)", "CPU / wall"],
                      [[k, t.median(k), len(t.wall[k]), t.median(k) / base, t.cpu_median(k),
                        t.cpu_median(k) / t.median(k)] for k in THREADS_CASES])


def _fractions_table(t):
    """Items 1 and 2: the percentage of each behaviour, early stop and full length."""
    return H.md_table(["run"] + [f"{n} %" for n in BEHAVIOURS],
                      [[run, *[t.result[k].fractions()[n] for n in BEHAVIOURS]]
                       for run, k in (("early stop", "early, all threads"),
                                      ("full length", "full length, all threads"))])


def _with_period(label, period):
    return label + (f" p={period}" if period else "")


def goal(wall, limit, n_threads):
    """Whether a wall time reached its goal, in words."""
    if wall <= limit:
        return f"Goal of {limit:g} s **reached** ({wall:.2f} s)"
    return (f"Goal of {limit:g} s **out of reach** here: {wall:.2f} s on {n_threads} threads "
            f"of a shared machine")


def markdown(m):
    """The report's Markdown from the measurements ``m`` (a dict: see :func:`main`)."""
    cfg, t1, t2 = m["cfg"], m["t1"], m["t2"]
    item4, item5, sweep5 = m["item4"], m["item5"], m["sweep5"]
    s_early = t2.result["early, all threads"]
    n_threads = m["n_threads"]
    md = [f"### Sweeps and basins: wall time, threads, early stopping, grid resolution"
          f"{H.quick_note(m['quick'], 'small grid, few periods')}\n",
          f"Grids at the default n_steps = GRID_N = {GRID_N} unless said. Basin: "
          f"{cfg['grid']}x{cfg['grid']} cells over (theta0, theta0') in [-1, 1]^2, (r0, s0) = "
          f"(0, 1), {cfg['periods']} periods. Sweep: hb=1, omega=1.3, Housner, alpha 0.5...1.0 "
          f"step {cfg['alpha_step']:g} ({s_early.alpha.size} values), lambda_max on, z0 = "
          f"Z0_STUDY, {cfg['periods']} periods. 'all threads' = {n_threads}.\n\n"]

    md.append(f"**1. Basin hb=1, alpha=0.66, omega=1.3, Housner** (goal <= "
              f"{TARGET_BASIN_S:g} s)\n\n")
    base = t1.median("early, all threads")
    md.append(_threads_table(t1))
    md.append(f"\nThread speed-up (early stop): {t1.median('early, 1 thread') / base:.2f}x on "
              f"{n_threads} threads; early stopping saves "
              f"{t1.median('full length, all threads') / base:.0f}x over full length. Labels "
              f"and t_end identical on 1 and {n_threads} threads: {m['threads_identical']}. "
              f"{goal(base, TARGET_BASIN_S, n_threads)}.\n\n")
    md.append(_fractions_table(t1))

    md.append(f"\n**2. Sweep hb=1, Housner, {s_early.alpha.size} alphas, lambda_max on** "
              f"(goal <= {TARGET_SWEEP_S:g} s)\n\n")
    base2 = t2.median("early, all threads")
    md.append(_threads_table(t2))
    es = m["sweep_es"]
    md.append(f"\nThread speed-up: {t2.median('early, 1 thread') / base2:.2f}x; early stopping "
              f"saves {t2.median('full length, all threads') / base2:.1f}x. Results identical "
              f"on 1 and {n_threads} threads: {m['s_threads_identical']}. Early vs full length: "
              f"{es['agreement']:.2f} % of alphas with the same label "
              f"({len(es['differing'])} differ). "
              f"{goal(base2, TARGET_SWEEP_S, n_threads)}.\n\n")
    md.append(_fractions_table(t2))

    md.append(f"\n**4. Early stopping vs full length, the study's four basins** (N = {GRID_N}; "
              f"requirement >= {TARGET_AGREEMENT:g} % on each)\n\n")
    md.append(H.md_table(["basin", "same label (%)", "cells differing", "early stop (s)",
                          "full length (s)", "saving", "mean stop time (periods)",
                          f">= {TARGET_AGREEMENT:g} %"],
                         [[r["basin"], r["agreement"], r["n_differ"], r["wall_early_s"],
                           r["wall_full_s"], r["wall_full_s"] / r["wall_early_s"],
                           r["mean_t_end_early_periods"],
                           "yes" if r["agreement"] >= TARGET_AGREEMENT else "**no**"]
                          for r in item4]))
    listed = [(r["basin"], d) for r in item4 for d in r["differing"]]
    if listed:
        md.append("\nDiffering cells (early stop vs full length)"
                  + (f", first {MAX_LISTED} of {len(listed)}" if len(listed) > MAX_LISTED
                     else "") + ":\n\n")
        md.append(H.md_table(["basin", "theta0", "theta0'", "early stop", "stopped at (T)",
                              "full length", "full ended at (T)"],
                             [[bn, f"{d['theta0']:.4f}", f"{d['dtheta0']:.4f}",
                               _with_period(d["label_a"], d["period_a"]), d["t_end_a_periods"],
                               _with_period(d["label_b"], d["period_b"]), d["t_end_b_periods"]]
                              for bn, d in listed[:MAX_LISTED]]))

    md.append(f"\n**5. Grid resolution** (n_steps; agreement of labels with N = {N_REF}; "
              f"early stopping on; wall = median of {cfg['reps_n']})\n\n")
    others = [n for n in NS if n != N_REF]
    rows = [[r["basin"], *[r["wall_s"][n] for n in NS],
             *[r[f"agreement_{n}"] for n in others],
             *[len(r[f"differing_{n}"]) for n in others]] for r in item5]
    rows.append(["sweep hb=1 Housner", *[sweep5["wall_s"][n] for n in NS],
                 *[sweep5[f"agreement_{n}"] for n in others],
                 *[len(sweep5[f"differing_{n}"]) for n in others]])
    md.append(H.md_table(["grid", *[f"N={n} (s)" for n in NS],
                          *[f"N={n} agrees (%)" for n in others],
                          *[f"N={n} cells differing" for n in others]], rows))
    md.append("\nSweep lambda_max against N = 256:\n\n")
    md.append(H.md_table(["N", "max abs diff, all finite", "at alpha",
                          "max abs diff, same periodic label", "alphas same periodic"],
                         [[f"N={n}", sweep5[f"lam_{n}"]["max_all"],
                           sweep5[f"lam_{n}"]["alpha_max_all"],
                           sweep5[f"lam_{n}"]["max_same_periodic"],
                           sweep5[f"lam_{n}"]["n_same_periodic"]] for n in others]))
    for n in others:
        diff = sweep5[f"differing_{n}"]
        if diff:
            md.append(f"\nSweep alphas whose label differs, N={n} vs {N_REF}: " + ", ".join(
                f"{d['alpha']:.3f} ({_with_period(d['label'], d['period'])} vs "
                f"{_with_period(d['label_ref'], d['period_ref'])})" for d in diff[:MAX_LISTED])
                + (" ..." if len(diff) > MAX_LISTED else "") + ".\n")

    ci = m["compile"]
    if ci:
        md.append("\nCompile time, apart (first call in a fresh process minus its warm median; "
                  "three processes in turn on one new NUMBA_CACHE_DIR: cold = empty; second = "
                  "after the cold one; cached = after both):\n\n")
        md.append(H.md_table(["kernel", "compile, cold (s)", "compile, second process (s)",
                              "compile, cached (s)", "import rockjit (s)"],
                             [[f"{k} ({'tangent' if k == 'sweep' else 'no tangent'})",
                               v["cold"]["compile_s"], v["second"]["compile_s"],
                               v["cached"]["compile_s"], v["cached"]["import_s"]]
                              for k, v in ci.items()]))
        again = [k for k, v in ci.items()
                 if v["second"]["compile_s"] > 0.5 * v["cold"]["compile_s"]]
        if again:
            md.append(f"\nThe second process compiles again ({', '.join(again)}): rockjit's "
                      "cache check empties a NUMBA_CACHE_DIR folder it finds without its source "
                      "stamp, which is the case of the folder the first process created (a bug;"
                      " the package's own `__pycache__`, the default, is not affected).\n")
        else:
            md.append("\nThe second process loads what the first compiled (with a fresh "
                      "NUMBA_CACHE_DIR it used to compile again, before commit 4e61b69).\n")
    first = m["first"]
    md.append(f"\nFirst calls in this process (package cache): basin {first['basin']:.2f} s, "
              f"sweep {first['sweep']:.2f} s. Medians of {cfg['reps']} interleaved runs (the "
              f"full-length basin: {cfg['reps_full']}) unless said; CPU = process CPU time of "
              f"all threads, so CPU / wall is the parallelism obtained. The 2-CPU machine is "
              f"shared with other benchmarks, so wall times are inflated by its load; 1-minute "
              f"load average before / after each item: "
              + ", ".join(f"{k} {v[0].split(' /')[0]} / {v[1].split(' /')[0]}"
                          for k, v in m["loads"].items())
              + f" ({m['total'] / 60:.1f} min in all).\n")
    md.append(f"\n{H.env_line(m['env'])}\n")
    return "".join(md)


CSV_HEADERS = ["item", "case", "n_steps", "wall_median_s", "runs", "target_s",
               "agreement_percent"]


def csv_rows(m):
    cfg, t1, t2 = m["cfg"], m["t1"], m["t2"]
    rows = [["1 basin hb=1 housner", k, GRID_N, t1.median(k), len(t1.wall[k]), TARGET_BASIN_S,
             None] for k in THREADS_CASES]
    rows += [["2 sweep hb=1 housner", k, GRID_N, t2.median(k), len(t2.wall[k]), TARGET_SWEEP_S,
              m["sweep_es"]["agreement"] if k.startswith("full") else None]
             for k in THREADS_CASES]
    for r in m["item4"]:
        rows.append(["4 early vs full", r["basin"] + " early", GRID_N, r["wall_early_s"],
                     cfg["reps_n"], None, r["agreement"]])
        rows.append(["4 early vs full", r["basin"] + " full length", GRID_N, r["wall_full_s"],
                     1, None, r["agreement"]])
    for r in m["item5"]:
        for n in NS:
            rows.append(["5 resolution", r["basin"], n, r["wall_s"][n], cfg["reps_n"], None,
                         r.get(f"agreement_{n}", 100.0)])
    for n in NS:
        rows.append(["5 resolution", "sweep hb=1 housner", n, m["sweep5"]["wall_s"][n],
                     cfg["reps_n"], None, m["sweep5"].get(f"agreement_{n}", 100.0)])
    return rows


def json_data(m, g):
    t1, t2, t5 = m["t1"], m["t2"], m["t5"]
    sw = t5["sweep"].result
    basin_settings, sweep_settings = g.description()
    return dict(
        quick=m["quick"], environment=m["env"], total_s=m["total"],
        basin_settings=basin_settings, sweep_settings=sweep_settings, grid_n=GRID_N,
        n_threads=m["n_threads"], first_call_in_process_s=m["first"], load_average=m["loads"],
        cpu_s=dict(item1=dict(t1.cpu), item2=dict(t2.cpu),
                   item5={tag: dict(t.cpu) for tag, t in t5.items()}),
        item1=dict(wall_s=t1.wall, median_s=t1.medians(),
                   threads_identical=m["threads_identical"],
                   fractions_early=t1.result["early, all threads"].fractions(),
                   fractions_full=t1.result["full length, all threads"].fractions(),
                   target_s=TARGET_BASIN_S),
        item2=dict(wall_s=t2.wall, median_s=t2.medians(),
                   threads_identical=m["s_threads_identical"], early_vs_full=m["sweep_es"],
                   fractions_early=t2.result["early, all threads"].fractions(),
                   fractions_full=t2.result["full length, all threads"].fractions(),
                   target_s=TARGET_SWEEP_S),
        item4=m["item4"],
        item5=dict(basins=m["item5"], sweep=m["sweep5"],
                   sweep_lambda_max={str(n): sw[n].lambda_max for n in NS},
                   sweep_label={str(n): sw[n].label for n in NS}),
        compile=m["compile"])


# --------------------------------------------------------------------------- plots

def plot_timing(m):
    t1, t2, item5, sweep5, cfg = m["t1"], m["t2"], m["item5"], m["sweep5"], m["cfg"]
    titles = (f"basin hb=1 Housner, {cfg['grid']}x{cfg['grid']}, {cfg['periods']} periods",
              f"sweep hb=1 Housner, {t2.result['early, all threads'].alpha.size} alphas, "
              "lambda on")
    plt = H.pyplot()
    fig, axes = plt.subplots(1, 3, figsize=(13.5, 4.2), layout="constrained")
    for ax, t, target, title in ((axes[0], t1, TARGET_BASIN_S, titles[0]),
                                 (axes[1], t2, TARGET_SWEEP_S, titles[1])):
        keys = list(THREADS_CASES)
        x = np.arange(len(keys))
        ax.bar(x, [t.median(k) for k in keys], color=["C0", "C1", "C3"][:len(keys)], alpha=0.8)
        for xi, k in zip(x, keys):
            ax.plot([xi] * len(t.wall[k]), t.wall[k], "k.", ms=4)
            ax.annotate(f"{t.median(k):.2f} s", (xi, t.median(k)), ha="center", va="bottom",
                        fontsize=8, xytext=(0, 3), textcoords="offset points")
        ax.axhline(target, color="k", ls="--", lw=1, label=f"goal {target:g} s")
        ax.set_xticks(x, [k.replace(", ", "\n").replace("all threads",
                                                           f"{m['n_threads']} threads")
                          for k in keys], fontsize=8)
        ax.set_yscale("log")
        ax.set_ylabel("wall time (s), median; dots = runs")
        ax.set_title(title, fontsize=9)
        ax.legend(fontsize=8, loc="upper left")
        ax.grid(True, axis="y", alpha=0.3, which="both")
    ax = axes[2]
    for r in item5:
        ax.plot(NS, [r["wall_s"][n] for n in NS], "o-", label=r["basin"])
    ax.plot(NS, [sweep5["wall_s"][n] for n in NS], "s--k", label="sweep hb=1 Housner")
    ax.axvline(GRID_N, color="0.6", lw=0.8)
    ax.set_xscale("log", base=2)
    ax.set_xticks(NS, [str(n) for n in NS])
    ax.set_yscale("log")
    ax.set_xlabel("n_steps per period (grey: GRID_N)")
    ax.set_ylabel("wall time (s), early stop, all threads")
    ax.set_title("cost against grid resolution", fontsize=9)
    ax.legend(fontsize=7)
    ax.grid(True, alpha=0.3, which="both")
    return fig


def _label_image(ax, b, label):
    from matplotlib.colors import BoundaryNorm, ListedColormap

    from rockjit.plotting.figures import BEHAVIOUR_COLOURS
    cmap = ListedColormap([BEHAVIOUR_COLOURS[n] for n in BEHAVIOURS])
    norm = BoundaryNorm(np.arange(len(BEHAVIOURS) + 1) - 0.5, cmap.N)
    th, dth = b.theta0, b.dtheta0
    dx = (th[-1] - th[0]) / max(len(th) - 1, 1) / 2
    dy = (dth[-1] - dth[0]) / max(len(dth) - 1, 1) / 2
    ax.imshow(np.asarray(label).T, origin="lower", cmap=cmap, norm=norm, alpha=0.45,
              interpolation="nearest", aspect="auto",
              extent=(th[0] - dx, th[-1] + dx, dth[0] - dy, dth[-1] + dy))


def plot_agreement(m):
    from matplotlib.lines import Line2D
    from matplotlib.patches import Patch

    from rockjit.plotting.figures import BEHAVIOUR_COLOURS
    t5, full, item4, item5 = m["t5"], m["full"], m["item4"], m["item5"]
    plt = H.pyplot()
    fig, axes = plt.subplots(2, len(BASINS), figsize=(4.0 * len(BASINS), 8.4),
                             layout="constrained", sharex=True, sharey=True)
    present = set()
    for c, b in enumerate(BASINS):
        tag = basin_tag(b)
        f, e = full[tag][2], t5[tag].result[GRID_N]
        r4 = item4[c]
        ax = axes[0, c]
        _label_image(ax, f, f.label)
        present |= set(np.unique(f.label).tolist())
        d = np.nonzero(e.label != f.label)
        ax.plot(f.theta0[d[0]], f.dtheta0[d[1]], "o", mfc="none", mec="red", ms=7, mew=1.5)
        ax.set_title(f"{r4['basin']}\nearly stop vs full length (N={GRID_N}): "
                     f"{r4['agreement']:.2f} % ({r4['n_differ']} cells)", fontsize=8)
        ax = axes[1, c]
        ref = t5[tag].result[N_REF]
        _label_image(ax, ref, ref.label)
        present |= set(np.unique(ref.label).tolist())
        r5 = item5[c]
        for n, mk, col in ((64, "x", "red"), (128, "o", "blue")):
            d = np.nonzero(t5[tag].result[n].label != ref.label)
            kw = dict(mfc="none") if mk == "o" else {}
            ax.plot(ref.theta0[d[0]], ref.dtheta0[d[1]], mk, color=col, mec=col, ms=6,
                    mew=1.2, **kw)
        ax.set_title(f"N=64: {r5['agreement_64']:.2f} %, N=128: "
                     f"{r5['agreement_128']:.2f} % same as N={N_REF}", fontsize=8)
        ax.set_xlabel("theta0")
    axes[0, 0].set_ylabel("theta0'  (background: full-length labels)")
    axes[1, 0].set_ylabel(f"theta0'  (background: N={N_REF} labels)")
    handles = [Patch(color=BEHAVIOUR_COLOURS[BEHAVIOURS[k]], alpha=0.45, label=BEHAVIOURS[k])
               for k in sorted(present)]
    handles += [Line2D([], [], ls="", marker="o", mfc="none", mec="red", mew=1.5,
                       label="early stop differs from full length"),
                Line2D([], [], ls="", marker="x", color="red",
                       label=f"N=64 differs from N={N_REF}"),
                Line2D([], [], ls="", marker="o", mfc="none", mec="blue",
                       label=f"N=128 differs from N={N_REF}")]
    fig.legend(handles=handles, loc="outside lower center", ncols=min(len(handles), 6),
               fontsize=8, frameon=False)
    fig.suptitle("Basins: cells whose label changes with early stopping (top) and with the "
                 "grid resolution (bottom)", fontsize=10)
    return fig


def plot_sweep(m):
    sw = m["t5"]["sweep"].result
    s_early = m["t2"].result["early, all threads"]
    s_full = m["t2"].result["full length, all threads"]
    plt = H.pyplot()
    fig, axes = plt.subplots(2, 1, figsize=(8.0, 6.0), layout="constrained", sharex=True)
    ax = axes[0]
    ref = sw[N_REF]
    for n, st in ((N_REF, dict(color="k", lw=1.4)), (128, dict(color="C0", lw=0.8)),
                  (64, dict(color="C1", lw=0.6, ls=":"))):
        lam = np.where(np.isfinite(sw[n].lambda_max), sw[n].lambda_max, np.nan)
        ax.plot(sw[n].alpha, lam, label=f"N={n}", **st)
    ax.set_ylabel("lambda_max (rest = -inf and overturn not drawn)")
    ax.axhline(0, color="0.5", lw=0.6)
    ax.legend(fontsize=8)
    ax.set_title("Sweep hb=1, Housner, omega=1.3: lambda_max against the grid resolution",
                 fontsize=9)
    ax.grid(True, alpha=0.3)
    ax = axes[1]
    for n, col in ((128, "C0"), (64, "C1")):
        ok = np.isfinite(sw[n].lambda_max) & np.isfinite(ref.lambda_max)
        d = np.full(ok.shape, np.nan)
        d[ok] = np.abs(sw[n].lambda_max[ok] - ref.lambda_max[ok])
        same = sw[n].label == ref.label
        ax.semilogy(sw[n].alpha[ok & same], np.maximum(d[ok & same], 1e-17), ".", color=col,
                    ms=3, label=f"N={n} vs {N_REF}, same label")
        ax.semilogy(sw[n].alpha[ok & ~same], np.maximum(d[ok & ~same], 1e-17), "x",
                    color=col, ms=6, label=f"N={n} vs {N_REF}, label differs")
    diff_es = s_early.label != s_full.label
    for a in s_early.alpha[diff_es]:
        ax.axvline(a, color="red", lw=0.6, alpha=0.6)
    ax.set_xlabel("alpha")
    ax.set_ylabel("|lambda_max difference|")
    ax.set_title("red lines: alphas where early stopping changes the label (N = "
                 f"{GRID_N})" if diff_es.any() else
                 "early stopping changes no label of this sweep", fontsize=8)
    ax.legend(fontsize=7, ncols=2)
    ax.grid(True, alpha=0.3, which="both")
    return fig


# --------------------------------------------------------------------------- main

def main(argv=None):
    b = H.Bench(__doc__, argv)
    cfg = QUICK if b.quick else FULL
    g = Grids(cfg)
    b.env["load_start"] = H.load_text()
    t_start = time.perf_counter()
    loads = {}

    def loaded(key, experiment, *args):
        """Run an experiment, noting the load average before and after it."""
        loads[key] = [H.load_text()]
        out = experiment(*args)
        loads[key].append(H.load_text())
        return out

    first = first_calls(g)
    t1, threads_identical = loaded("item1", item1_basin, g, cfg)
    t2, s_threads_identical, sweep_es = loaded("item2", item2_sweep, g, cfg)
    t5 = loaded("item5", item5_resolution, g, cfg)
    full = loaded("item4", item4_full_length, g, t1)
    compile_info = None if b.quick else compile_cost(g)
    b.env["load_end"] = H.load_text()
    item5, sweep5 = item5_rows(t5)
    m = dict(cfg=cfg, quick=b.quick, env=b.env, first=first, loads=loads,
             n_threads=numba.config.NUMBA_NUM_THREADS, t1=t1, t2=t2, t5=t5, full=full,
             threads_identical=threads_identical, s_threads_identical=s_threads_identical,
             sweep_es=sweep_es, item4=item4_rows(t5, full), item5=item5, sweep5=sweep5,
             compile=compile_info, total=time.perf_counter() - t_start)

    b.report("grids", markdown=markdown(m), csv=(CSV_HEADERS, csv_rows(m)),
             data=json_data(m, g),
             figures=[("grids_timing.png", plot_timing(m), 120),
                      ("grids_agreement.png", plot_agreement(m), 110),
                      ("grids_sweep_resolution.png", plot_sweep(m), 120)],
             also=[SECTION])
    return 0


if __name__ == "__main__":
    sys.exit(main())
