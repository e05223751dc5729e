"""Issue 4: sweeps and basins — wall time, threads, early stopping and grid resolution.

Everything at the study's settings (SPEC.md §6–7), measured side by side in one process:

1. the hb=1 Housner basin (100x100 cells over (theta0, theta0') in [-1, 1]^2, (r0, s0) = (0, 1),
   alpha=0.66, omega=1.3, 500 periods): 2 threads (all) vs 1 thread with early stopping (the
   default), and full length (``early_stop=False``); fractions per behaviour; target <= 2 s;
2. the hb=1 Housner alpha sweep (alpha 0.5...1.0 step 0.001 = 501 values, lambda_max on, 500
   periods, z0 = rockjit.Z0_STUDY, omega=1.3): early stopping on 2 and 1 threads, and full
   length; target <= 3 s;
4. early stopping against full length on the study's four basins (hb=1 alpha=0.66 omega=1.3,
   hb=2 alpha=0.2 omega=1.6, Housner and Mao): percentage of cells with the same label
   (issue 4 requires >= 99.9 % on each), and every differing cell;
5. grid resolution: the four basins and the sweep at n_steps = 64, 128 and 256 (GRID_N, the
   default of sweeps and basins, is one of them): label agreement of 64 and 128 with 256, wall
   time of each, and for the sweep the largest |lambda_max difference|.

(Item 3, the ``rockjit paper`` command end to end, is benchmarks/bench_paper.py.) Compile time
of the two grid kernels (basin: no tangent; sweep: tangent) is measured apart, in fresh
processes with an empty and then a filled numba cache.

    python benchmarks/bench_grids.py           # full measurement (~20 min on 2 loaded cores)
    python benchmarks/bench_grids.py --quick   # smoke mode (small grids, 60 periods; ~1 min)

Writes grids.{md,csv,json} and grids_{timing,agreement,sweep_resolution}.png to
benchmarks/results/ (benchmarks/results/quick/ with --quick, or --out DIR), and refreshes the
``grids`` block of benchmarks/results/grids_section.md (and of README.md once it has one).
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
from rockjit.analysis import BEHAVIOURS, GRID_N, basin, sweep  # noqa: E402

#: The study's four basins (SPEC.md §7, figure 6).
BASINS = (
    dict(hb=1.0, alpha=0.66, omega=1.3, law="housner"),
    dict(hb=1.0, alpha=0.66, omega=1.3, law="mao"),
    dict(hb=2.0, alpha=0.2, omega=1.6, law="housner"),
    dict(hb=2.0, alpha=0.2, omega=1.6, law="mao"),
)
NS = (64, 128, 256)
N_REF = 256
TARGET_BASIN_S = 2.0
TARGET_SWEEP_S = 3.0
TARGET_AGREEMENT = 99.9
SECTION = C.RESULTS / "grids_section.md"
MAX_LISTED = 12  # differing cells listed in the Markdown (all of them go to the JSON)


def basin_name(b):
    return f"hb={b['hb']:g} alpha={b['alpha']:g} omega={b['omega']:g} {b['law']}"


def basin_tag(b):
    return f"hb{b['hb']:g}_{b['law']}"


# --------------------------------------------------------------------------- helpers

def update_block(path: Path, key: str, text: str):
    """Replace the block between ``<!-- key:begin -->`` and ``<!-- key:end -->`` in ``path``
    (atomically); a file without the markers is left alone."""
    path = Path(path)
    if not path.exists():
        return False
    old = path.read_text()
    begin, end = f"<!-- {key}:begin -->", f"<!-- {key}:end -->"
    i, j = old.find(begin), old.find(end)
    if i < 0 or j < i:
        print(f"note: no {begin} ... {end} block in {path}; not updated", file=sys.stderr)
        return False
    C.write_text(path, old[:i + len(begin)] + "\n" + text.rstrip("\n") + "\n" + old[j:])
    return True


def publish(args, key: str, text: str):
    """A full run in the default folder refreshes its block in grids_section.md and, once the
    section has been pasted there, in README.md."""
    if args.quick or (args.out is not None and Path(args.out).resolve() != C.RESULTS.resolve()):
        return
    update_block(SECTION, key, text)
    C.update_readme(args, key, text)


def load() -> str:
    """The 1-, 5- and 15-minute load averages (the machine is shared)."""
    try:
        return " / ".join(f"{x:.2f}" for x in os.getloadavg())
    except OSError:
        return "?"


def pct_row(fr):
    return [fr[n] for n in BEHAVIOURS]


def differing_cells(a, b, period_a=None, period_b=None, t_a=None, t_b=None):
    """Every cell where the label arrays of two basins differ, as dicts."""
    out = []
    T = 2 * math.pi / a.block.omega
    for i, j in zip(*np.nonzero(a.label != b.label)):
        d = dict(i=int(i), j=int(j), theta0=float(a.theta0[i]), dtheta0=float(a.dtheta0[j]),
                 label_a=BEHAVIOURS[a.label[i, j]], period_a=int(a.period[i, j]),
                 t_end_a_periods=float(a.t_end[i, j] / T),
                 label_b=BEHAVIOURS[b.label[i, j]], period_b=int(b.period[i, j]),
                 t_end_b_periods=float(b.t_end[i, j] / T))
        out.append(d)
    return out


def agreement(a, b) -> float:
    a, b = np.asarray(a), np.asarray(b)
    return 100.0 * np.count_nonzero(a == b) / a.size


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
    out = dict(max_all=float(d[fin].max()) if fin.any() else None,
               alpha_max_all=float(sa.alpha[fin][np.argmax(d[fin])]) if fin.any() else None,
               max_same_periodic=float(d[same_per].max()) if same_per.any() else None,
               n_finite=int(fin.sum()), n_same_periodic=int(same_per.sum()))
    return out


# --------------------------------------------------------------------------- compile probes

_PROBE = textwrap.dedent("""
    import json, statistics, sys, time
    t0 = time.perf_counter()
    import rockjit
    from rockjit.analysis import basin, sweep
    t1 = time.perf_counter()
    fn = basin if sys.argv[1] == "basin" else sweep
    kw = json.loads(sys.argv[2])
    fn(**kw)
    t2 = time.perf_counter()
    warm = []
    for _ in range(int(sys.argv[3])):
        a = time.perf_counter()
        fn(**kw)
        warm.append(time.perf_counter() - a)
    print(json.dumps(dict(import_s=t1 - t0, first_s=t2 - t1, warm_s=statistics.median(warm))))
""")


def grid_compile_times(kind, kwargs, warm_repeats=2):
    """Like ``_common.compile_times`` but for ``basin``/``sweep``: fresh processes sharing one
    new ``NUMBA_CACHE_DIR``, first with it empty (``cold``), then twice more with what the
    earlier ones wrote (``second``, ``cached``).

    Three, not two: before commit 4e61b69 rockjit's cache check found the folder the first
    process wrote without its source stamp and emptied it, so the second process compiled
    again. The second process shows whether that is fixed; the third is what every later
    session sees.
    """
    out = {}
    with tempfile.TemporaryDirectory(prefix="rockjit-numba-cache-") as d:
        env = dict(os.environ, NUMBA_CACHE_DIR=d)
        for which in ("cold", "second", "cached"):
            proc = subprocess.run([sys.executable, "-c", _PROBE, kind, json.dumps(kwargs),
                                   str(warm_repeats)], env=env, capture_output=True, text=True,
                                  check=True, cwd=d)
            r = json.loads(proc.stdout.strip().splitlines()[-1])
            r["compile_s"] = r["first_s"] - r["warm_s"]
            out[which] = r
            print(f"compile {kind} {which}: {r['compile_s']:.1f} s (first call {r['first_s']:.1f}"
                  f" s, warm {r['warm_s']:.2f} s)", flush=True)
    return out


# --------------------------------------------------------------------------- main

def main(argv=None):
    args = C.parser(__doc__.splitlines()[0]).parse_args(argv)
    out = C.out_dir(args)
    quick = args.quick
    grid = 24 if quick else 100
    periods = 60 if quick else 500
    alpha_step = 0.01 if quick else 0.001
    reps = 2 if quick else 7          # items 1 and 2
    reps_full = 1 if quick else 3     # the full-length basin in item 1
    reps_n = 1 if quick else 3        # item 5
    bkw = dict(grid=grid, r0=0.0, s0=1.0, periods=periods)
    skw = dict(hb=1.0, omega=1.3, law="housner", alpha_range=(0.5, 1.0), alpha_step=alpha_step,
               z0=rockjit.Z0_STUDY, periods=periods, lyapunov=True)
    b0 = BASINS[0]
    n_threads = __import__("numba").config.NUMBA_NUM_THREADS

    env = C.environment()
    env["load_start"] = load()
    print(C.env_line(env), f"load {env['load_start']}", flush=True)
    t_start = time.perf_counter()

    # ---- first calls in this process (from whatever cache the package holds)
    first = {}
    first["basin"], _ = C.timed(basin, **b0, **bkw)
    first["sweep"], _ = C.timed(sweep, **skw)
    print(f"first calls in process: basin {first['basin']:.2f} s, sweep {first['sweep']:.2f} s",
          flush=True)

    results = {}
    cpu = {}  # process CPU seconds of each run (all threads), by result key
    loads = {}

    def keep(key, fn, **kw):
        def call():
            c0 = time.process_time()
            results[key] = fn(**kw)
            cpu.setdefault(key, []).append(time.process_time() - c0)
        return call

    # ---- item 1: the hb=1 Housner basin
    cases1 = {
        "early, all threads": keep("b_early_all", basin, **b0, **bkw),
        "early, 1 thread": keep("b_early_1", basin, **b0, **bkw, threads=1),
        "full length, all threads": keep("b_full_all", basin, **b0, **bkw, early_stop=False),
    }
    keys1 = dict(zip(cases1, ("b_early_all", "b_early_1", "b_full_all")))
    loads["item1"] = [load()]
    t1 = C.interleaved(cases1, reps, counts={"full length, all threads": reps_full})
    loads["item1"].append(load())
    m1 = {k: C.median(v) for k, v in t1.items()}
    c1 = {k: C.median(cpu[keys1[k]]) for k in cases1}
    print("item 1:", {k: round(v, 3) for k, v in m1.items()}, flush=True)
    threads_identical = bool(
        np.array_equal(results["b_early_all"].label, results["b_early_1"].label)
        and np.array_equal(results["b_early_all"].t_end, results["b_early_1"].t_end))

    # ---- item 2: the hb=1 Housner sweep
    cases2 = {
        "early, all threads": keep("s_early_all", sweep, **skw),
        "early, 1 thread": keep("s_early_1", sweep, **skw, threads=1),
        "full length, all threads": keep("s_full_all", sweep, **skw, early_stop=False),
    }
    keys2 = dict(zip(cases2, ("s_early_all", "s_early_1", "s_full_all")))
    loads["item2"] = [load()]
    t2 = C.interleaved(cases2, reps)
    loads["item2"].append(load())
    m2 = {k: C.median(v) for k, v in t2.items()}
    c2 = {k: C.median(cpu[keys2[k]]) for k in cases2}
    print("item 2:", {k: round(v, 3) for k, v in m2.items()}, flush=True)
    s_threads_identical = bool(
        np.array_equal(results["s_early_all"].label, results["s_early_1"].label)
        and np.array_equal(results["s_early_all"].lambda_max, results["s_early_1"].lambda_max,
                           equal_nan=True))
    s_es = results["s_early_all"], results["s_full_all"]
    sweep_es = dict(agreement=agreement(s_es[0].label, s_es[1].label),
                    differing=[dict(alpha=float(s_es[0].alpha[k]),
                                    early=BEHAVIOURS[s_es[0].label[k]],
                                    full=BEHAVIOURS[s_es[1].label[k]],
                                    period_early=int(s_es[0].period[k]),
                                    period_full=int(s_es[1].period[k]))
                               for k in np.nonzero(s_es[0].label != s_es[1].label)[0]],
                    lam=lam_diff(*s_es))

    # ---- item 5 (and the early-stop half of item 4): four basins at N = 64, 128, 256
    bres = {}
    t5 = {}
    loads["item5"] = [load()]
    for b in BASINS:
        cases = {n: keep(("basin", basin_tag(b), n), basin, **b, **bkw, n_steps=n) for n in NS}
        tt = C.interleaved(cases, reps_n)
        for n in NS:
            t5[(basin_tag(b), n)] = tt[n]
            bres[(basin_tag(b), n)] = results[("basin", basin_tag(b), n)]
        print(f"item 5 {basin_name(b)}:", {n: round(C.median(tt[n]), 3) for n in NS},
              flush=True)
    cases = {n: keep(("sweep", n), sweep, **skw, n_steps=n) for n in NS}
    tt = C.interleaved(cases, reps_n)
    for n in NS:
        t5[("sweep", n)] = tt[n]
    print("item 5 sweep:", {n: round(C.median(tt[n]), 3) for n in NS}, flush=True)
    loads["item5"].append(load())

    # ---- item 4: full-length basins (the hb=1 Housner one is item 1's)
    full = {basin_tag(b0): results["b_full_all"]}
    t4_full = {basin_tag(b0): m1["full length, all threads"]}
    c4_full = {basin_tag(b0): c1["full length, all threads"]}
    loads["item4"] = [load()]
    for b in BASINS[1:]:
        c0 = time.process_time()
        dt, full[basin_tag(b)] = C.timed(basin, **b, **bkw, early_stop=False)
        c4_full[basin_tag(b)] = time.process_time() - c0
        t4_full[basin_tag(b)] = dt
        print(f"item 4 full length {basin_name(b)}: {dt:.1f} s", flush=True)
    loads["item4"].append(load())
    item4 = []
    for b in BASINS:
        tag = basin_tag(b)
        e, f = bres[(tag, GRID_N)], full[tag]
        diff = differing_cells(e, f)
        item4.append(dict(basin=basin_name(b), tag=tag, agreement=agreement(e.label, f.label),
                          n_differ=len(diff), differing=diff,
                          wall_early_s=C.median(t5[(tag, GRID_N)]), wall_full_s=t4_full[tag],
                          cpu_early_s=C.median(cpu[("basin", tag, GRID_N)]),
                          cpu_full_s=c4_full[tag],
                          fractions_early=e.fractions(), fractions_full=f.fractions(),
                          mean_t_end_early_periods=float(np.mean(e.t_end) * b["omega"]
                                                         / (2 * math.pi))))

    # ---- item 5 summaries
    item5 = []
    for b in BASINS:
        tag = basin_tag(b)
        ref = bres[(tag, N_REF)]
        row = dict(basin=basin_name(b), tag=tag,
                   wall_s={n: C.median(t5[(tag, n)]) for n in NS},
                   cpu_s={n: C.median(cpu[("basin", tag, n)]) for n in NS},
                   wall_all_s={n: t5[(tag, n)] for n in NS},
                   fractions={n: bres[(tag, n)].fractions() for n in NS})
        for n in NS:
            if n != N_REF:
                row[f"agreement_{n}"] = agreement(bres[(tag, n)].label, ref.label)
                row[f"differing_{n}"] = differing_cells(bres[(tag, n)], ref)
        item5.append(row)
    sw = {n: results[("sweep", n)] for n in NS}
    sweep5 = dict(wall_s={n: C.median(t5[("sweep", n)]) for n in NS},
                  cpu_s={n: C.median(cpu[("sweep", n)]) for n in NS},
                  wall_all_s={n: t5[("sweep", n)] for n in NS})
    for n in NS:
        if n != N_REF:
            sweep5[f"agreement_{n}"] = agreement(sw[n].label, sw[N_REF].label)
            sweep5[f"lam_{n}"] = lam_diff(sw[n], sw[N_REF])
            sweep5[f"differing_{n}"] = [
                dict(alpha=float(sw[n].alpha[k]), label=BEHAVIOURS[sw[n].label[k]],
                     period=int(sw[n].period[k]), label_ref=BEHAVIOURS[sw[N_REF].label[k]],
                     period_ref=int(sw[N_REF].period[k]),
                     lambda_max=float(sw[n].lambda_max[k]),
                     lambda_max_ref=float(sw[N_REF].lambda_max[k]))
                for k in np.nonzero(sw[n].label != sw[N_REF].label)[0]]

    # ---- compile time, apart
    compile_info = None
    if not quick:
        compile_info = dict(basin=grid_compile_times("basin", dict(b0, **bkw)),
                            sweep=grid_compile_times("sweep", dict(skw, z0=list(skw["z0"]))))

    env["load_end"] = load()
    total = time.perf_counter() - t_start
    C.check_unchanged(env)

    # ================================================================== tables
    q = " (QUICK MODE: small grid, few periods)" if quick else ""
    md = []
    md.append(f"### Sweeps and basins: wall time, threads, early stopping, grid resolution{q}\n")
    md.append(f"Grids at the default n_steps = GRID_N = {GRID_N} unless said. "
              f"Basin: {grid}x{grid} cells over (theta0, theta0') in [-1, 1]^2, (r0, s0) = (0, 1),"
              f" {periods} periods. Sweep: hb=1, omega=1.3, Housner, alpha 0.5...1.0 step "
              f"{alpha_step:g} ({s_es[0].alpha.size} values), lambda_max on, z0 = Z0_STUDY, "
              f"{periods} periods. 'all threads' = {n_threads}.\n\n")

    md.append(f"**1. Basin hb=1, alpha=0.66, omega=1.3, Housner** (target <= {TARGET_BASIN_S:g} s)"
              "\n\n")
    base = m1["early, all threads"]
    rows = [[k, m1[k], len(t1[k]), m1[k] / base, c1[k], c1[k] / m1[k]] for k in cases1]
    md.append(C.md_table(["case", "wall median (s)", "runs", "time / early all threads",
                          "CPU median (s)", "CPU / wall"], rows))
    md.append(f"\nThread speed-up (early stop): {m1['early, 1 thread'] / base:.2f}x on "
              f"{n_threads} threads; early stopping saves "
              f"{m1['full length, all threads'] / base:.0f}x over full length. Labels and t_end "
              f"identical on 1 and {n_threads} threads: {threads_identical}. Target "
              f"{'**met**' if base <= TARGET_BASIN_S else '**not met**'} "
              f"({base:.2f} s).\n\n")
    rows = [["early stop", *pct_row(results["b_early_all"].fractions())],
            ["full length", *pct_row(results["b_full_all"].fractions())]]
    md.append(C.md_table(["run"] + [f"{n} %" for n in BEHAVIOURS], rows))

    md.append(f"\n**2. Sweep hb=1, Housner, {s_es[0].alpha.size} alphas, lambda_max on** "
              f"(target <= {TARGET_SWEEP_S:g} s)\n\n")
    base2 = m2["early, all threads"]
    rows = [[k, m2[k], len(t2[k]), m2[k] / base2, c2[k], c2[k] / m2[k]] for k in cases2]
    md.append(C.md_table(["case", "wall median (s)", "runs", "time / early all threads",
                          "CPU median (s)", "CPU / wall"], rows))
    md.append(f"\nThread speed-up: {m2['early, 1 thread'] / base2:.2f}x; early stopping saves "
              f"{m2['full length, all threads'] / base2:.1f}x. Results identical on 1 and "
              f"{n_threads} threads: {s_threads_identical}. Early vs full length: "
              f"{sweep_es['agreement']:.2f} % of alphas with the same label "
              f"({len(sweep_es['differing'])} differ). Target "
              f"{'**met**' if base2 <= TARGET_SWEEP_S else '**not met**'} ({base2:.2f} s).\n\n")
    rows = [["early stop", *pct_row(s_es[0].fractions())],
            ["full length", *pct_row(s_es[1].fractions())]]
    md.append(C.md_table(["run"] + [f"{n} %" for n in BEHAVIOURS], rows))

    md.append(f"\n**4. Early stopping vs full length, the study's four basins** (N = {GRID_N}; "
              f"requirement >= {TARGET_AGREEMENT:g} % on each)\n\n")
    rows = [[r["basin"], r["agreement"], r["n_differ"], r["wall_early_s"], r["wall_full_s"],
             r["wall_full_s"] / r["wall_early_s"], r["mean_t_end_early_periods"],
             "yes" if r["agreement"] >= TARGET_AGREEMENT else "**no**"] for r in item4]
    md.append(C.md_table(["basin", "same label (%)", "cells differing", "early stop (s)",
                          "full length (s)", "saving", "mean stop time (periods)",
                          f">= {TARGET_AGREEMENT:g} %"], rows))
    listed = [(r["basin"], d) for r in item4 for d in r["differing"]]
    if listed:
        md.append("\nDiffering cells (early stop vs full length)"
                  + (f", first {MAX_LISTED} of {len(listed)}" if len(listed) > MAX_LISTED
                     else "") + ":\n\n")
        md.append(C.md_table(["basin", "theta0", "theta0'", "early stop", "stopped at (T)",
                              "full length", "full ended at (T)"],
                             [[bn, f"{d['theta0']:.4f}", f"{d['dtheta0']:.4f}",
                               d["label_a"] + (f" p={d['period_a']}" if d["period_a"] else ""),
                               d["t_end_a_periods"],
                               d["label_b"] + (f" p={d['period_b']}" if d["period_b"] else ""),
                               d["t_end_b_periods"]] for bn, d in listed[:MAX_LISTED]]))

    md.append(f"\n**5. Grid resolution** (n_steps; agreement of labels with N = {N_REF}; "
              f"early stopping on; wall = median of {reps_n})\n\n")
    rows = []
    for r in item5:
        rows.append([r["basin"], *[r["wall_s"][n] for n in NS],
                     *[r[f"agreement_{n}"] for n in NS if n != N_REF],
                     *[len(r[f"differing_{n}"]) for n in NS if n != N_REF]])
    rows.append(["sweep hb=1 Housner", *[sweep5["wall_s"][n] for n in NS],
                 *[sweep5[f"agreement_{n}"] for n in NS if n != N_REF],
                 *[len(sweep5[f"differing_{n}"]) for n in NS if n != N_REF]])
    md.append(C.md_table(["grid", *[f"N={n} (s)" for n in NS],
                          *[f"N={n} agrees (%)" for n in NS if n != N_REF],
                          *[f"N={n} cells differing" for n in NS if n != N_REF]], rows))
    md.append("\nSweep lambda_max against N = 256:\n\n")
    rows = [[f"N={n}", sweep5[f"lam_{n}"]["max_all"], sweep5[f"lam_{n}"]["alpha_max_all"],
             sweep5[f"lam_{n}"]["max_same_periodic"], sweep5[f"lam_{n}"]["n_same_periodic"]]
            for n in NS if n != N_REF]
    md.append(C.md_table(["N", "max abs diff, all finite", "at alpha",
                          "max abs diff, same periodic label", "alphas same periodic"], rows))
    for n in NS:
        if n != N_REF and sweep5[f"differing_{n}"]:
            md.append(f"\nSweep alphas whose label differs, N={n} vs {N_REF}: " + ", ".join(
                f"{d['alpha']:.3f} ({d['label']}"
                + (f" p={d['period']}" if d['period'] else "") + f" vs {d['label_ref']}"
                + (f" p={d['period_ref']}" if d['period_ref'] else "") + ")"
                for d in sweep5[f"differing_{n}"][:MAX_LISTED])
                + (" ..." if len(sweep5[f"differing_{n}"]) > MAX_LISTED else "") + ".\n")

    if compile_info:
        md.append("\nCompile time, apart (first call in a fresh process minus its warm median; "
                  "three processes in turn on one new NUMBA_CACHE_DIR: cold = empty; second = "
                  "after the cold one; cached = after both):\n\n")
        md.append(C.md_table(["kernel", "compile, cold (s)", "compile, second process (s)",
                              "compile, cached (s)", "import rockjit (s)"],
                             [[f"{k} ({'tangent' if k == 'sweep' else 'no tangent'})",
                               v["cold"]["compile_s"], v["second"]["compile_s"],
                               v["cached"]["compile_s"], v["cached"]["import_s"]]
                              for k, v in compile_info.items()]))
        again = [k for k, v in compile_info.items()
                 if v["second"]["compile_s"] > 0.5 * v["cold"]["compile_s"]]
        if again:
            md.append(f"\nThe second process compiles again ({', '.join(again)}): rockjit's "
                      "cache check empties a NUMBA_CACHE_DIR folder it finds without its source "
                      "stamp, which is the case of the folder the first process created (a bug;"
                      " the package's own `__pycache__`, the default, is not affected).\n")
        else:
            md.append("\nThe second process loads what the first compiled (with a fresh "
                      "NUMBA_CACHE_DIR it used to compile again, before commit 4e61b69).\n")
    md.append(f"\nFirst calls in this process (package cache): basin {first['basin']:.2f} s, "
              f"sweep {first['sweep']:.2f} s. Medians of {reps} interleaved runs (the "
              f"full-length basin: {reps_full}) unless said; CPU = process CPU time of all "
              f"threads, so CPU / wall is the parallelism obtained. The 2-CPU machine is shared "
              f"with other benchmarks, so wall times are inflated by its load; 1-minute load "
              f"average before / after each item: "
              + ", ".join(f"{k} {v[0].split(' /')[0]} / {v[1].split(' /')[0]}"
                          for k, v in loads.items())
              + f" ({total / 60:.1f} min in all).\n")
    md.append(f"\n{C.env_line(env)}\n")
    md_text = "".join(md)
    C.write_text(out / "grids.md", md_text)

    # ================================================================== csv, json
    csv_rows = []
    for k in cases1:
        csv_rows.append(["1 basin hb=1 housner", k, GRID_N, m1[k], len(t1[k]), TARGET_BASIN_S,
                         None])
    for k in cases2:
        csv_rows.append(["2 sweep hb=1 housner", k, GRID_N, m2[k], len(t2[k]), TARGET_SWEEP_S,
                         sweep_es["agreement"] if k.startswith("full") else None])
    for r in item4:
        csv_rows.append(["4 early vs full", r["basin"] + " early", GRID_N, r["wall_early_s"],
                         reps_n, None, r["agreement"]])
        csv_rows.append(["4 early vs full", r["basin"] + " full length", GRID_N,
                         r["wall_full_s"], 1, None, r["agreement"]])
    for r in item5:
        for n in NS:
            csv_rows.append(["5 resolution", r["basin"], n, r["wall_s"][n], reps_n, None,
                             r.get(f"agreement_{n}", 100.0)])
    for n in NS:
        csv_rows.append(["5 resolution", "sweep hb=1 housner", n, sweep5["wall_s"][n], reps_n,
                         None, sweep5.get(f"agreement_{n}", 100.0)])
    C.write_csv(out / "grids.csv", ["item", "case", "n_steps", "wall_median_s", "runs",
                                    "target_s", "agreement_percent"], csv_rows)
    C.write_json(out / "grids.json", dict(
        quick=quick, environment=env, total_s=total, basin_settings=bkw,
        sweep_settings=dict(skw, z0=list(skw["z0"])), grid_n=GRID_N, n_threads=n_threads,
        first_call_in_process_s=first, load_average=loads,
        cpu_s={" ".join(map(str, k)) if isinstance(k, tuple) else k: v for k, v in cpu.items()},
        item1=dict(wall_s=t1, median_s=m1, threads_identical=threads_identical,
                   fractions_early=results["b_early_all"].fractions(),
                   fractions_full=results["b_full_all"].fractions(),
                   target_s=TARGET_BASIN_S),
        item2=dict(wall_s=t2, median_s=m2, threads_identical=s_threads_identical,
                   early_vs_full=sweep_es, fractions_early=s_es[0].fractions(),
                   fractions_full=s_es[1].fractions(), target_s=TARGET_SWEEP_S),
        item4=item4,
        item5=dict(basins=[{k: ({str(kk): vv for kk, vv in v.items()} if isinstance(v, dict)
                                else v) for k, v in r.items()} for r in item5],
                   sweep={k: ({str(kk): vv for kk, vv in v.items()} if isinstance(v, dict)
                              and k.startswith("wall") else v) for k, v in sweep5.items()},
                   sweep_lambda_max={str(n): sw[n].lambda_max for n in NS},
                   sweep_label={str(n): sw[n].label for n in NS}),
        compile=compile_info))

    # ================================================================== plots
    plot_timing(out / "grids_timing.png", m1, t1, m2, t2, item5, sweep5, n_threads,
                (f"basin hb=1 Housner, {grid}x{grid}, {periods} periods",
                 f"sweep hb=1 Housner, {s_es[0].alpha.size} alphas, lambda on"))
    plot_agreement(out / "grids_agreement.png", bres, full, item4, item5)
    plot_sweep(out / "grids_sweep_resolution.png", sw, s_es)
    publish(args, "grids", md_text)
    print(md_text)
    return 0


# --------------------------------------------------------------------------- plots

def plot_timing(path, m1, t1, m2, t2, item5, sweep5, n_threads, titles):
    plt = C.pyplot()
    fig, axes = plt.subplots(1, 3, figsize=(13.5, 4.2), layout="constrained")
    for ax, m, t, target, title in (
            (axes[0], m1, t1, TARGET_BASIN_S, titles[0]),
            (axes[1], m2, t2, TARGET_SWEEP_S, titles[1])):
        keys = list(m)
        x = np.arange(len(keys))
        colours = ["C0", "C1", "C3"]
        ax.bar(x, [m[k] for k in keys], color=colours[:len(keys)], alpha=0.8)
        for xi, k in zip(x, keys):
            ax.plot([xi] * len(t[k]), t[k], "k.", ms=4)
            ax.annotate(f"{m[k]:.2f} s", (xi, m[k]), ha="center", va="bottom", fontsize=8,
                        xytext=(0, 3), textcoords="offset points")
        ax.axhline(target, color="k", ls="--", lw=1, label=f"target {target:g} s")
        ax.set_xticks(x, [k.replace(", ", "\n").replace("all threads",
                                                           f"{n_threads} threads")
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
    C.save_figure(fig, path, dpi=120)
    plt.close(fig)


def _label_image(ax, b, label):
    from matplotlib.colors import BoundaryNorm, ListedColormap

    from rockjit.plotting import BEHAVIOUR_COLOURS
    cmap = ListedColormap([BEHAVIOUR_COLOURS[n] for n in BEHAVIOURS])
    norm = BoundaryNorm(np.arange(len(BEHAVIOURS) + 1) - 0.5, cmap.N)
    th, dth = b.theta0, b.dtheta0
    dx = (th[-1] - th[0]) / max(len(th) - 1, 1) / 2
    dy = (dth[-1] - dth[0]) / max(len(dth) - 1, 1) / 2
    ax.imshow(np.asarray(label).T, origin="lower", cmap=cmap, norm=norm, alpha=0.45,
              interpolation="nearest", aspect="auto",
              extent=(th[0] - dx, th[-1] + dx, dth[0] - dy, dth[-1] + dy))


def plot_agreement(path, bres, full, item4, item5):
    from matplotlib.lines import Line2D
    from matplotlib.patches import Patch

    from rockjit.plotting import BEHAVIOUR_COLOURS
    plt = C.pyplot()
    fig, axes = plt.subplots(2, len(BASINS), figsize=(4.0 * len(BASINS), 8.4),
                             layout="constrained", sharex=True, sharey=True)
    present = set()
    for c, b in enumerate(BASINS):
        tag = basin_tag(b)
        f, e = full[tag], bres[(tag, GRID_N)]
        r4 = item4[c]
        ax = axes[0, c]
        _label_image(ax, f, f.label)
        present |= set(np.unique(f.label).tolist())
        d = np.nonzero(e.label != f.label)
        ax.plot(f.theta0[d[0]], f.dtheta0[d[1]], "o", mfc="none", mec="red", ms=7, mew=1.5)
        ax.set_title(f"{r4['basin']}\nearly stop vs full length (N={GRID_N}): "
                     f"{r4['agreement']:.2f} % "
                     f"({r4['n_differ']} cells)", fontsize=8)
        ax = axes[1, c]
        ref = bres[(tag, N_REF)]
        _label_image(ax, ref, ref.label)
        present |= set(np.unique(ref.label).tolist())
        r5 = item5[c]
        for n, mk, col in ((64, "x", "red"), (128, "o", "blue")):
            lab = bres[(tag, n)].label
            d = np.nonzero(lab != ref.label)
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
    C.save_figure(fig, path, dpi=110)
    plt.close(fig)


def plot_sweep(path, sw, s_es):
    plt = C.pyplot()
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
    diff_es = s_es[0].label != s_es[1].label
    for a in s_es[0].alpha[diff_es]:
        ax.axvline(a, color="red", lw=0.6, alpha=0.6)
    ax.set_xlabel("alpha")
    ax.set_ylabel("|lambda_max difference|")
    ax.set_title("red lines: alphas where early stopping changes the label (N = "
                 f"{GRID_N})" if diff_es.any() else
                 "early stopping changes no label of this sweep", fontsize=8)
    ax.legend(fontsize=7, ncols=2)
    ax.grid(True, alpha=0.3, which="both")
    C.save_figure(fig, path, dpi=120)
    plt.close(fig)


if __name__ == "__main__":
    sys.exit(main())
