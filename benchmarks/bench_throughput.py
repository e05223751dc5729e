"""Issue 5: throughput and scaling of rockjit.

Measured here, each as a table:

- nanoseconds per grid step and per right-hand side, on the study's reference run (hb=1,
  alpha=0.6, omega=1.3, Housner, 500 periods) at N = 64 ... 1024, and the fixed cost of one
  ``simulate`` call; where the time goes (microbenchmarks of the step's pieces);
- trajectories per second: single runs, basin cells (early stop on and off), sweep alphas;
- basin time against grid size n = 25 ... 400 (the study's basin hb=1, alpha=0.66, omega=1.3,
  defaults: N = GRID_N, 500 periods, early stop), against periods, against threads (1 and 2);
- the cost of the Lyapunov exponents (on and off) for a single run, a basin and a sweep;
- compile time, cold (fresh NUMBA_CACHE_DIR) and cached, of each kernel, in fresh processes;
- peak memory of a 400 x 400 basin (ru_maxrss of a fresh process, and tracemalloc's peak of the
  NumPy allocations made around the kernel).

    python benchmarks/bench_throughput.py           # full (~10 min)
    python benchmarks/bench_throughput.py --quick   # smoke (~40 s; no compile probes)

Writes throughput.{md,csv,json,png} to benchmarks/results/ (benchmarks/results/quick/ with
--quick, or --out DIR).
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

import numba
import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parent))
import _common as C  # noqa: E402

import rockjit  # noqa: E402
from rockjit import analysis as an  # noqa: E402
from rockjit import integrate as ig  # noqa: E402
from rockjit.model import sincos_poly  # noqa: E402
from rockjit.simulate import pack  # noqa: E402

REF = dict(C.REFERENCE_RUN, z0=rockjit.Z0_STUDY)
BASIN = dict(hb=1.0, alpha=0.66, omega=1.3, law="housner")  # the study's hb=1 basin
SWEEP = dict(hb=1.0, omega=1.3, law="housner")


# --------------------------------------------------------------------------- helpers

def cpu_mhz():
    try:
        with open("/proc/cpuinfo") as f:
            for line in f:
                if line.startswith("cpu MHz"):
                    return float(line.split(":")[1])
    except OSError:
        pass
    return math.nan


def loadavg():
    try:
        return os.getloadavg()[0]
    except OSError:
        return math.nan


def timed_cpu(fn):
    """``(wall, cpu, result)``: wall time and this process's CPU time (all threads)."""
    c0 = os.times()
    t0 = time.perf_counter()
    out = fn()
    wall = time.perf_counter() - t0
    c1 = os.times()
    return wall, (c1.user - c0.user) + (c1.system - c0.system), out


# --------------------------------------------------------------------------- microbenchmarks

@numba.njit(cache=False)
def _sincos_chain(n, x):
    """n dependent sincos_poly calls (latency)."""
    for _ in range(n):
        s, c = sincos_poly(x)
        x = 0.3 + 0.5 * s + 0.1 * c
    return x


@numba.njit(cache=False)
def _sincos_free(n, x0):
    """n independent sincos_poly calls (throughput)."""
    acc = 0.0
    for i in range(n):
        s, c = sincos_poly(x0 + 1e-9 * i)
        acc += s + c
    return acc


@numba.njit(cache=False, _nrt=False)  # as the kernel's loop: no reference counting
def _dp_steps(n, y, K, par, ytmp, ynew, tab, fr, jac, trig):
    """n bare Dormand-Prince steps chained through the state (no event detection)."""
    ig.rhs(False, 0.0, y, 1, par, K, jac, trig)
    for _ in range(n):
        ig.rk_step(False, False, False, 0.0, 1.0, y, K, 1, par, ytmp, ynew, tab, fr, jac,
                   trig)
        y[0] = ynew[0]
        y[1] = ynew[1]
        K[0, 0] = K[ig.N_STAGES, 0]
        K[0, 1] = K[ig.N_STAGES, 1]
        jac[0] = jac[ig.N_STAGES]
        trig[0] = trig[2]
        trig[1] = trig[3]
        if y[0] < -0.3:  # keep the free fall within range (rare)
            y[0] = 0.2
            y[1] = 0.0
            ig.rhs(False, 0.0, y, 1, par, K, jac, trig)
    return y[0]


def microbench(n_steps, repeats):
    """ns per call of: sincos (chained, independent), a bare DP5 step (chained)."""
    blk = rockjit.Block(hb=1.0, alpha=0.0, omega=1.3)
    p = pack(blk, 0.0, rockjit.DEFAULT_N)
    par = np.zeros(ig.N_PARW)  # with the derived constants, as the kernel makes it
    par[:ig.N_PAR] = p
    par[ig.P_STHC] = math.sin(p[ig.P_THC])
    par[ig.P_CTHC] = math.cos(p[ig.P_THC])
    K = np.zeros((ig.N_STAGES + 1, 2))
    y = np.array([0.2, 0.0])
    ytmp, ynew = np.zeros(2), np.zeros(2)
    tab = np.zeros((ig.N_TAB, ig.N_STAGES + 1))
    ig.step_table(par[ig.P_OMEGA], par[ig.P_H], tab)
    fr, jac = np.zeros(ig.N_STAGES + 1), np.zeros(ig.N_STAGES + 1)
    trig = np.zeros(4)
    _sincos_chain(10, 0.3)
    _sincos_free(10, 0.3)
    _dp_steps(10, y, K, par, ytmp, ynew, tab, fr, jac, trig)
    n = n_steps
    cases = {
        "sincos, chained": lambda: _sincos_chain(6 * n, 0.3),
        "sincos, independent": lambda: _sincos_free(6 * n, 0.3),
        "bare DP5 step": lambda: _dp_steps(n, y, K, par, ytmp, ynew, tab, fr, jac, trig),
    }
    times = C.interleaved(cases, repeats)
    per = {"sincos, chained": 6 * n, "sincos, independent": 6 * n, "bare DP5 step": n}
    return {k: 1e9 * C.median(v) / per[k] for k, v in times.items()}


@numba.njit(parallel=True, cache=False)
def _burn(n, out):
    for i in numba.prange(out.size):
        x = 1.0 + i
        for _ in range(n):
            x = x * 0.9999999 + 1e-7
        out[i] = x


def machine_parallelism(repeats):
    """Speed-up of a trivially parallel arithmetic kernel with 2 threads over 1, right now."""
    out = np.zeros(64)
    _burn(10, out)
    n = 2_000_000
    res = {}
    old = numba.get_num_threads()
    try:
        for th in (1, 2):
            numba.set_num_threads(th)
            res[th] = []
        for _ in range(repeats):
            for th in (1, 2):
                numba.set_num_threads(th)
                res[th].append(C.timed(_burn, n, out)[0])
    finally:
        numba.set_num_threads(old)
    return C.median(res[1]) / C.median(res[2])


# --------------------------------------------------------------------------- fresh processes

_PROBE = textwrap.dedent("""
    import json, statistics, sys, time
    spec = json.loads(sys.argv[1])
    t0 = time.perf_counter()
    import rockjit
    from rockjit import analysis
    t1 = time.perf_counter()
    fn = dict(simulate=rockjit.simulate, basin=analysis.basin, sweep=analysis.sweep)[spec["kind"]]
    fn(**spec["kw"])
    t2 = time.perf_counter()
    warm = []
    for _ in range(spec["repeats"]):
        a = time.perf_counter()
        fn(**spec["kw"])
        warm.append(time.perf_counter() - a)
    print(json.dumps(dict(import_s=t1 - t0, first_s=t2 - t1, warm_s=statistics.median(warm))))
""")


def _probe(spec, cache_dir):
    env = dict(os.environ, NUMBA_CACHE_DIR=cache_dir)
    p = subprocess.run([sys.executable, "-c", _PROBE, json.dumps(spec)], env=env,
                       capture_output=True, text=True, check=True, cwd=cache_dir)
    d = json.loads(p.stdout.strip().splitlines()[-1])
    d["compile_s"] = d["first_s"] - d["warm_s"]
    return d


def compile_times(spec):
    """Compile time of one call in three fresh processes sharing one new NUMBA_CACHE_DIR:
    ``cold`` (empty cache), ``second`` and ``third`` (with what the earlier ones wrote)."""
    with tempfile.TemporaryDirectory(prefix="rockjit-numba-cache-") as d:
        return dict(cold=_probe(spec, d), second=_probe(spec, d), third=_probe(spec, d))


_MEM = textwrap.dedent("""
    import json, resource, sys, time, tracemalloc
    spec = json.loads(sys.argv[1])
    import numpy as np
    from rockjit import analysis
    kw = spec["kw"]
    analysis.basin(kw["hb"], kw["alpha"], kw["omega"], grid=2, periods=5)  # load the kernel
    base_kib = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss

    def status(key):
        with open("/proc/self/status") as f:
            for line in f:
                if line.startswith(key):
                    return int(line.split()[1])
        return -1
    try:  # reset the RSS high-water mark (Linux), so that the basin's own peak shows
        with open("/proc/self/clear_refs", "w") as f:
            f.write("5")
        hwm_reset = True
    except OSError:
        hwm_reset = False
    rss0_kib = status("VmRSS:")
    tracemalloc.start()
    t = time.perf_counter()
    b = analysis.basin(**kw)
    wall = time.perf_counter() - t
    _, tm_peak = tracemalloc.get_traced_memory()
    tracemalloc.stop()
    hwm_kib = status("VmHWM:")
    peak_kib = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss
    out_bytes = sum(a.nbytes for a in (b.label, b.period, b.t_end, b.theta0, b.dtheta0))
    print(json.dumps(dict(base_kib=base_kib, peak_kib=peak_kib, tracemalloc_peak_b=tm_peak,
                          rss0_kib=rss0_kib, hwm_kib=hwm_kib, hwm_reset=hwm_reset,
                          wall_s=wall, result_bytes=out_bytes,
                          mean_periods=float(np.mean(b.t_end) / b.block.period),
                          fractions=b.fractions())))
""")


def peak_memory(kw):
    p = subprocess.run([sys.executable, "-c", _MEM, json.dumps(dict(kw=kw))],
                       capture_output=True, text=True, check=True, cwd=tempfile.gettempdir())
    return json.loads(p.stdout.strip().splitlines()[-1])


# --------------------------------------------------------------------------- main

def main(argv=None):
    args = C.parser(__doc__.splitlines()[0]).parse_args(argv)
    out = C.out_dir(args)
    quick = args.quick
    env = C.environment()
    env["cpu_mhz"] = cpu_mhz()
    print(C.env_line(env))
    rec = dict(quick=quick, environment=env)
    periods = 50 if quick else 500
    reps = 3 if quick else 11

    # load every kernel used below
    rockjit.simulate(**REF, periods=2)
    rockjit.simulate(**REF, periods=2, lyapunov=True)
    an.basin(**BASIN, grid=2, periods=2)
    an.basin(**BASIN, grid=2, periods=2, lyapunov=True)

    # ---- ns per step ---------------------------------------------------------------------
    ns_list = tuple(sorted({64, 256, rockjit.DEFAULT_N} if quick
                           else {64, 128, 256, 1024, rockjit.DEFAULT_N}))
    results = {}

    def keep(n):
        def call():
            results[n] = rockjit.simulate(**REF, periods=periods, n_steps=n)
        return call

    cases = {n: keep(n) for n in ns_list}
    cases["call"] = lambda: rockjit.simulate(**REF, periods=1, n_steps=8)
    times = C.interleaved(cases, reps * 3)
    med = {k: C.median(v) for k, v in times.items()}
    call_cold_s = med["call"]  # right after a large run: caches cold
    # the fixed cost of a call, warm: many 1-period N=8 calls in a row
    call_s = C.median([C.timed(rockjit.simulate, **REF, periods=1, n_steps=8)[0]
                       for _ in range(300)])
    call_small_s = C.median([C.timed(rockjit.simulate, **REF, periods=1, n_steps=8,
                                     max_impacts=100)[0] for _ in range(300)])
    step_rows = []
    for n in ns_list:
        r = results[n]
        kern = med[n] - call_s
        step_rows.append([n, med[n], r.n_grid_steps, r.n_rhs, 1e9 * kern / r.n_grid_steps,
                          1e9 * kern / r.n_rhs, 1e9 * kern / r.n_grid_steps * env["cpu_mhz"] / 1e3,
                          r.n_impacts])
    micro = microbench(200_000 if quick else 2_000_000, reps)
    rec["ns_per_step"] = dict(rows=step_rows, call_overhead_s=call_s,
                              call_overhead_after_large_run_s=call_cold_s,
                              call_overhead_max_impacts_100_s=call_small_s, micro_ns=micro,
                              raw={str(k): v for k, v in times.items()})
    print("ns/step", step_rows, micro, call_s)

    # ---- trajectories per second -----------------------------------------------------------
    g_es = 30 if quick else 100
    g_full = 8 if quick else 20
    sweep_alphas = np.round(np.arange(0.5, 1.0 + 1e-9, 0.02 if quick else 0.005), 6)
    traj = {}
    traj["single run"] = (C.median(times[rockjit.DEFAULT_N]) if rockjit.DEFAULT_N in times
                          else math.nan, 1, f"reference run, N={rockjit.DEFAULT_N}, "
                                            f"{periods} periods")
    w = [C.timed(an.basin, **BASIN, grid=g_es)[0] for _ in range(3)]
    traj["basin, early stop"] = (C.median(w), g_es**2,
                                 f"{g_es}x{g_es} study basin, N={an.GRID_N}, 500 periods")
    w = [C.timed(an.basin, **BASIN, grid=g_full, early_stop=False)[0]
         for _ in range(1 if not quick else 2)]
    traj["basin, full length"] = (C.median(w), g_full**2,
                                  f"{g_full}x{g_full} study basin, N={an.GRID_N}, all 500 "
                                  "periods")
    w = [C.timed(an.sweep, **SWEEP, alphas=sweep_alphas)[0] for _ in range(1 if not quick
                                                                            else 2)]
    traj["sweep with exponents"] = (C.median(w), sweep_alphas.size,
                                    f"study's hb=1 Housner sweep, alpha 0.5..1.0 "
                                    f"({sweep_alphas.size} values), lyapunov, early stop")
    traj_rows = [[k, v[2], v[1], v[0], v[1] / v[0]] for k, v in traj.items()]
    rec["trajectories"] = traj_rows
    print(traj_rows)

    # ---- basin time against grid size -------------------------------------------------------
    sizes = (10, 20, 40) if quick else (25, 50, 100, 200, 400)
    size_rows = []
    for n in sizes:
        k = 3 if n <= 100 else 1
        ws = []
        for _ in range(k):
            wall, cpu, b = timed_cpu(lambda: an.basin(**BASIN, grid=n))
            ws.append((wall, cpu))
        wall = C.median([x[0] for x in ws])
        cpu = C.median([x[1] for x in ws])
        size_rows.append([n, n * n, k, wall, n * n / wall, cpu / wall,
                          float(np.mean(b.t_end) / b.block.period)])
        print("size", size_rows[-1])
    rec["basin_size"] = size_rows

    # ---- basin time against periods ---------------------------------------------------------
    g_p = 12 if quick else 24
    plist = (20, 50) if quick else (50, 100, 200, 500, 1000)
    per_rows = []
    for p in plist:
        w_es = C.median([C.timed(an.basin, **BASIN, grid=g_p, periods=p)[0] for _ in range(3)])
        w_full = C.timed(an.basin, **BASIN, grid=g_p, periods=p, early_stop=False)[0]
        per_rows.append([p, w_es, w_full, 1e9 * w_full / (g_p**2 * p * an.GRID_N),
                         1e9 * w_full * numba.get_num_threads() / (g_p**2 * p * an.GRID_N)])
        print("periods", per_rows[-1])
    rec["basin_periods"] = dict(grid=g_p, rows=per_rows)

    # ---- threads -----------------------------------------------------------------------------
    load0 = loadavg()
    par_before = machine_parallelism(5)
    thr_rows = []
    for label, kw, k in (("early stop", dict(grid=g_es), 5 if not quick else 2),
                         ("full length", dict(grid=g_full, early_stop=False),
                          3 if not quick else 2)):
        res_t = {1: [], 2: []}
        for rep in range(k):
            for th in ((1, 2) if rep % 2 == 0 else (2, 1)):
                res_t[th].append(timed_cpu(lambda: an.basin(**BASIN, threads=th, **kw))[:2])
        w1 = C.median([x[0] for x in res_t[1]])
        w2 = C.median([x[0] for x in res_t[2]])
        c2 = C.median([x[1] for x in res_t[2]])
        thr_rows.append([label, kw["grid"] ** 2, w1, w2, w1 / w2, c2 / w2])
    par_after = machine_parallelism(5)
    load1 = loadavg()
    rec["threads"] = dict(rows=thr_rows, machine_speedup_before=par_before,
                          machine_speedup_after=par_after, loadavg=(load0, load1))
    print("threads", thr_rows, par_before, par_after, load0, load1)

    # ---- exponents on and off ---------------------------------------------------------------
    g_l = 20 if quick else 50
    lyap_alphas = sweep_alphas[::2]
    cases = {
        ("single run", False): lambda: rockjit.simulate(**REF, periods=periods),
        ("single run", True): lambda: rockjit.simulate(**REF, periods=periods, lyapunov=True),
        ("basin", False): lambda: an.basin(**BASIN, grid=g_l),
        ("basin", True): lambda: an.basin(**BASIN, grid=g_l, lyapunov=True),
        ("sweep", False): lambda: an.sweep(**SWEEP, alphas=lyap_alphas, lyapunov=False),
        ("sweep", True): lambda: an.sweep(**SWEEP, alphas=lyap_alphas, lyapunov=True),
    }
    lt = C.interleaved(cases, 3 if quick else 7)
    lm = {k: C.median(v) for k, v in lt.items()}
    what = {"single run": f"reference run, N={rockjit.DEFAULT_N}, {periods} periods",
            "basin": f"{g_l}x{g_l} study basin, early stop",
            "sweep": f"{lyap_alphas.size} alphas of the hb=1 sweep, early stop"}
    lyap_rows = [[k, what[k], lm[(k, False)], lm[(k, True)], lm[(k, True)] / lm[(k, False)]]
                 for k in what]
    # with lyapunov=False a sweep cannot tell chaotic from aperiodic: same labels otherwise
    rec["lyapunov"] = dict(rows=lyap_rows, raw={f"{k[0]}/{k[1]}": v for k, v in lt.items()})
    print("lyap", lyap_rows)

    # ---- compile times ----------------------------------------------------------------------
    comp_rows = []
    if not quick:
        specs = [
            ("simulate (closed forcing)", dict(kind="simulate", kw=dict(REF, periods=50))),
            ("simulate, lyapunov=True", dict(kind="simulate",
                                             kw=dict(REF, periods=50, lyapunov=True))),
            ("simulate, embedded forcing", dict(kind="simulate",
                                                kw=dict(REF, periods=50, forcing="embedded"))),
            ("basin (grid kernel)", dict(kind="basin", kw=dict(BASIN, grid=4, periods=50))),
            ("sweep, lyapunov (tangent grid kernel)",
             dict(kind="sweep", kw=dict(SWEEP, alphas=[0.6, 0.7], periods=50))),
        ]
        for label, spec in specs:
            spec["repeats"] = 3
            ct = compile_times(spec)
            comp_rows.append([label, ct["cold"]["compile_s"], ct["second"]["compile_s"],
                              ct["third"]["compile_s"], ct["third"]["import_s"]])
            print("compile", comp_rows[-1])
    rec["compile"] = comp_rows

    # ---- peak memory of a 400 x 400 basin ---------------------------------------------------
    g_m = 40 if quick else 400
    mem = peak_memory(dict(BASIN, grid=g_m))
    rec["memory"] = mem
    print("memory", mem)
    C.check_unchanged(env)

    # ---- tables ------------------------------------------------------------------------------
    mhz = env["cpu_mhz"]
    q = " (QUICK MODE)" if quick else ""
    md = [f"#### Throughput and scaling: results{q}\n"]
    md.append(f"\n**Nanoseconds per step**: the reference run (hb=1, alpha=0.6, omega=1.3, "
              f"Housner, z0), {periods} periods, medians of {3 * reps} interleaved runs; the "
              f"fixed cost of a `simulate` call is subtracted: {1e6 * call_s:.0f} µs, the "
              f"median of 300 1-period N=8 calls in a row ({1e6 * call_small_s:.0f} µs with "
              f"`max_impacts=100` instead of the default 100 000, the rows of the impact "
              f"buffer; {1e6 * call_cold_s:.0f} µs right after a 500-period run, caches "
              f"cold). Cycles at the nominal {mhz:.0f} MHz.\n\n")
    md.append(C.md_table(["N", "wall (s)", "grid steps", "rhs evaluations", "ns / step",
                          "ns / rhs", "cycles / step", "impacts"], step_rows))
    md.append("\nWhere the time goes (microbenchmarks, ns per call, medians of "
              f"{reps}):\n\n")
    md.append(C.md_table(["piece", "ns", "cycles"],
                         [[k, v, v * mhz / 1e3] for k, v in micro.items()]
                         + [["6 x sincos chained (a step's sines, were none overlapped)",
                             6 * micro["sincos, chained"],
                             6 * micro["sincos, chained"] * mhz / 1e3]]))
    md.append("\n**Trajectories per second** (one basin cell or sweep value is one trajectory; "
              "default threads):\n\n")
    md.append(C.md_table(["what", "setting", "trajectories", "wall (s)", "trajectories / s"],
                         traj_rows))
    md.append(f"\n**Basin time against grid size**: the study's basin (hb=1, alpha=0.66, "
              f"omega=1.3, Housner), defaults (N={an.GRID_N}, 500 periods, early stop, "
              "default threads); median of 3 up to n=100, one run above. CPU/wall: the process's "
              "CPU time over wall time (2 would be both threads busy).\n\n")
    md.append(C.md_table(["n", "cells", "runs", "wall (s)", "cells / s", "CPU / wall",
                          "mean periods run per cell"], size_rows))
    md.append(f"\n**Basin time against periods**: the same basin on a {g_p}x{g_p} grid, early "
              "stop (median of 3) and full length (one run).\n\n")
    md.append(C.md_table(["periods", "early stop (s)", "full length (s)",
                          "full length: wall ns / step", "x threads"], per_rows))
    md.append(f"\n**Threads**: the same basin with 1 and 2 numba threads, alternating order; "
              f"CPU/wall of the 2-thread runs. A trivially parallel arithmetic kernel ran "
              f"{par_before:.2f}x (before) and {par_after:.2f}x (after) faster on 2 threads than "
              f"on 1 at the time: the speed-up this shared machine allowed. Load average "
              f"{load0:.2f} before, {load1:.2f} after.\n\n")
    md.append(C.md_table(["basin", "cells", "1 thread (s)", "2 threads (s)", "speed-up",
                          "CPU / wall (2 threads)"], thr_rows))
    md.append("\n**Exponents on and off** (medians of interleaved runs):\n\n")
    md.append(C.md_table(["what", "setting", "lyapunov=False (s)", "lyapunov=True (s)",
                          "ratio"], lyap_rows))
    if comp_rows:
        md.append("\n**Compile time**: first call in a fresh process minus the warm median, in "
                  "three fresh processes one after the other sharing one new NUMBA_CACHE_DIR: "
                  "cold = empty cache, then the 2nd and 3rd sessions with what the earlier ones "
                  "wrote; each kernel in its own new cache, so a cold figure includes the shared "
                  "model and stepper functions.\n\n")
        md.append(C.md_table(["kernel", "cold (s)", "2nd session (s)", "3rd session (s)",
                              "import rockjit (s)"], comp_rows))
    md.append(f"\n**Peak memory of a {g_m}x{g_m} basin** (defaults, early stop; fresh process, "
              f"kernel loaded from cache first; {mem['wall_s']:.1f} s, "
              f"{mem['mean_periods']:.1f} periods run per cell on average):\n\n")
    hwm = [["RSS high-water mark during the basin (VmHWM, reset just before it)",
            mem["hwm_kib"] / 1024],
           ["its increase over the RSS before the basin", (mem["hwm_kib"] - mem["rss0_kib"]) / 1024]
           ] if mem.get("hwm_reset") else []
    md.append(C.md_table(
        ["measure", "MiB"],
        [["process peak, ru_maxrss (Python, numba, LLVM, the loaded kernel, the basin)",
          mem["peak_kib"] / 1024],
         ["ru_maxrss after loading the kernel, before the basin", mem["base_kib"] / 1024],
         *hwm,
         ["tracemalloc peak (NumPy arrays made in Python around the kernel)",
          mem["tracemalloc_peak_b"] / 2**20],
         ["the returned arrays (label, period, t_end, axes)", mem["result_bytes"] / 2**20]]))
    md.append(f"\n{C.env_line(env)}\n")
    md = "".join(md)
    C.write_text(out / "throughput.md", md)
    C.update_readme(args, "throughput", md)
    C.write_csv(out / "throughput.csv", ["table", "key", "value"], _flat(rec))
    C.write_json(out / "throughput.json", rec)
    plot(out / "throughput.png", size_rows, per_rows, g_p)
    print(md)
    return 0


def _flat(rec):
    rows = []
    for r in rec["ns_per_step"]["rows"]:
        rows.append(["ns_per_step", f"N={r[0]}", r[4]])
    for k, v in rec["ns_per_step"]["micro_ns"].items():
        rows.append(["micro_ns", k, v])
    for r in rec["trajectories"]:
        rows.append(["trajectories_per_s", r[0], r[4]])
    for r in rec["basin_size"]:
        rows.append(["basin_size_wall_s", f"n={r[0]}", r[3]])
    for r in rec["basin_periods"]["rows"]:
        rows.append(["basin_periods_wall_s", f"periods={r[0]},early_stop", r[1]])
        rows.append(["basin_periods_wall_s", f"periods={r[0]},full", r[2]])
    for r in rec["threads"]["rows"]:
        rows.append(["threads_speedup", r[0], r[4]])
    for r in rec["lyapunov"]["rows"]:
        rows.append(["lyapunov_ratio", r[0], r[4]])
    for r in rec["compile"]:
        rows.append(["compile_cold_s", r[0], r[1]])
        rows.append(["compile_cached_s", r[0], r[2]])
    rows.append(["memory_peak_mib", "basin", rec["memory"]["peak_kib"] / 1024])
    return rows


def plot(path, size_rows, per_rows, g_p):
    plt = C.pyplot()
    fig, axes = plt.subplots(1, 2, figsize=(10, 4), layout="constrained")
    ax = axes[0]
    cells = [r[1] for r in size_rows]
    ax.loglog(cells, [r[3] for r in size_rows], "o-", label="measured")
    c0, w0 = cells[-1], size_rows[-1][3]
    ax.loglog(cells, [w0 * c / c0 for c in cells], "k:", lw=0.8, label="linear in cells")
    for r in size_rows:
        ax.annotate(f"{r[0]}²", (r[1], r[3]), fontsize=7, xytext=(3, -9),
                    textcoords="offset points")
    ax.set_xlabel("cells")
    ax.set_ylabel("wall time (s)")
    ax.set_title("basin time against grid size (early stop)", fontsize=9)
    ax.legend(fontsize=7)
    ax.grid(True, which="both", alpha=0.25)
    ax = axes[1]
    ps = [r[0] for r in per_rows]
    ax.loglog(ps, [r[1] for r in per_rows], "o-", label="early stop")
    ax.loglog(ps, [r[2] for r in per_rows], "s-", label="full length")
    ax.set_xlabel("periods")
    ax.set_ylabel("wall time (s)")
    ax.set_title(f"basin time against periods ({g_p}x{g_p})", fontsize=9)
    ax.legend(fontsize=7)
    ax.grid(True, which="both", alpha=0.25)
    C.save_figure(fig, path, dpi=120)
    plt.close(fig)


if __name__ == "__main__":
    sys.exit(main())
