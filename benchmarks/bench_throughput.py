"""Throughput and scaling of rockjit: single runs, basins, sweeps, threads, compile, memory.

Measured here, each as a table:

- nanoseconds per grid step and per right-hand side, on the study's reference run (hb=1,
  alpha=0.6, omega=1.3, Housner, 500 periods) at N = 64 ... 1024, and the fixed cost of one
  ``simulate`` call; where the time goes (microbenchmarks of the step's pieces);
- the fixed cost of a call by path (a prepared run, ``simulate``, a plan then its run) against
  the compiled run alone, on the chaotic scene of the peers' benchmark;
- trajectories per second: single runs, basin cells (early stop on and off), sweep alphas;
- basin time against grid size n = 25 ... 400 (the study's basin hb=1, alpha=0.66, omega=1.3,
  defaults: N = GRID_N, 500 periods, early stop), against periods, against threads (1 and 2);
- the cost of the Lyapunov exponents (on and off) for a single run, a basin and a sweep;
- compile time, cold (fresh NUMBA_CACHE_DIR) and cached, of each kernel, in fresh processes;
- peak memory of a 400 x 400 basin (ru_maxrss of a fresh process, and tracemalloc's peak of the
  NumPy allocations made around the kernel).

The microbenchmarks of a step's pieces and the compiled run alone are the places where a
benchmark reaches into rockjit's private code: :func:`step_internals` and :func:`kernel_alone`
(see their docstrings for the names).

    python benchmarks/bench_throughput.py           # full (~10 min)
    python benchmarks/bench_throughput.py --quick   # smoke (~40 s; no compile probes)

Writes throughput.{md,csv,json,png} to benchmarks/results/ (benchmarks/results/quick/ with
--quick, or --out DIR).
"""

from __future__ import annotations

import json
import math
import subprocess
import sys
import tempfile
import textwrap

import numba
import numpy as np

import _common as H

import rockjit
from rockjit import (Block, Classification, Execution, Harmonic, Integration, basin, simulate,
                     sweep)
from rockjit.grids.plan import GRID_N

#: The reference run (from the study's initial state), the study's hb=1 basin and sweep
REF = H.reference_run()
BASIN = (Block(hb=1.0, law="housner"), Harmonic(alpha=0.66, omega=1.3))
SWEEP = (Block(hb=1.0, law="housner"), Harmonic(omega=1.3))
FULL_LENGTH = Classification(early_stop=False)
FULL = dict(periods=500, reps=11, ns=(64, 128, 256, 1024), micro_steps=2_000_000,
            g_es=100, g_full=20, sweep_step=0.005, full_reps=1, sizes=(25, 50, 100, 200, 400),
            g_p=24, plist=(50, 100, 200, 500, 1000), thread_reps=(5, 3), g_l=50, lyap_reps=7,
            g_m=400, call_reps=3001)
QUICK = dict(periods=50, reps=3, ns=(64, 256), micro_steps=200_000,
             g_es=30, g_full=8, sweep_step=0.02, full_reps=2, sizes=(10, 20, 40),
             g_p=12, plist=(20, 50), thread_reps=(2, 2), g_l=20, lyap_reps=3, g_m=40,
             call_reps=301)


def cpu_mhz():
    try:
        with open("/proc/cpuinfo") as f:
            for line in f:
                if line.startswith("cpu MHz"):
                    return float(line.split(":")[1])
    except OSError:
        pass
    return math.nan


# --------------------------------------------------------------------------- PRIVATE API
# The one function of the benchmarks that uses rockjit's private integrator code. When the
# integrator's internals change, this is what to update (and nothing else in benchmarks/).

def kernel_alone(prepared):
    """A call of the compiled run under a prepared run (``rockjit.single.Prepared``) from the
    plan's own state, on outputs made once: the integration and nothing else, the floor a call
    of any path pays; the call returns the final state. Uses the private ``Prepared._entry``
    (the compiled code, set by its first call), ``Prepared._par`` and ``_ipar``,
    ``rockjit.single.initial_side``, ``rockjit._engine.kernel.single_outputs`` and the output
    layout ``rockjit._engine.integrate.F_TH``, ``F_S``."""
    from rockjit import single
    from rockjit._engine import kernel

    from rockjit._engine import integrate

    prepared()
    y0 = np.array(prepared.plan.y0)
    out = kernel.single_outputs(prepared.plan)
    args = (y0, single.initial_side(y0[0], y0[1]), prepared._par, prepared._ipar, out)
    entry = prepared._entry
    final = slice(integrate.F_TH, integrate.F_S + 1)  # theta, theta', r, s at the end
    return lambda: (entry(*args), out.fout[final])[1]


def step_internals():
    """Microbenchmark callables built on rockjit's private integrator code.

    Uses exactly these private names (today's layout):

    - ``rockjit._engine.integrate``: ``rk_step``, ``rhs``, ``step_table``; the constants
      ``N_STAGES``, ``N_TAB``, ``N_PAR``, ``N_PARW`` and the parameter-vector indices
      ``P_THC``, ``P_OMEGA``, ``P_H``, ``P_STHC``, ``P_CTHC``;
    - ``rockjit._engine.kernel.pack`` (the float parameter vector, from a block, an excitation
      and integration settings);
    - ``rockjit.model.sincos_poly`` (the stepper's sine and cosine).

    Returns
    -------
    dict
        ``{piece: (call(n), calls of the piece per call)}`` for ``"sincos, chained"`` (n
        dependent ``sincos_poly`` calls: latency), ``"sincos, independent"`` (throughput) and
        ``"bare DP5 step"`` (n Dormand–Prince steps chained through the state, no event
        detection), each compiled and called once already.
    """
    from rockjit._engine import integrate as ig
    from rockjit.model import sincos_poly
    from rockjit._engine.kernel import pack

    rk_step, rhs, n_stages = ig.rk_step, ig.rhs, ig.N_STAGES

    @numba.njit(cache=False)
    def sincos_chain(n, x):
        for _ in range(n):
            s, c = sincos_poly(x)
            x = 0.3 + 0.5 * s + 0.1 * c
        return x

    @numba.njit(cache=False)
    def sincos_free(n, x0):
        acc = 0.0
        for i in range(n):
            s, c = sincos_poly(x0 + 1e-9 * i)
            acc += s + c
        return acc

    @numba.njit(cache=False, _nrt=False)  # as the kernel's loop: no reference counting
    def dp_steps(n, y, K, par, ytmp, ynew, tab, fr, jac, trig):
        rhs(None, 0.0, y, 1, par, K, jac, trig)
        for _ in range(n):
            rk_step(None, None, False, 0.0, 1.0, y, K, 1, par, ytmp, ynew, tab, fr, jac, trig)
            y[0] = ynew[0]
            y[1] = ynew[1]
            K[0, 0] = K[n_stages, 0]
            K[0, 1] = K[n_stages, 1]
            jac[0] = jac[n_stages]
            trig[0] = trig[2]
            trig[1] = trig[3]
            if y[0] < -0.3:  # keep the free fall within range (rare)
                y[0] = 0.2
                y[1] = 0.0
                rhs(None, 0.0, y, 1, par, K, jac, trig)
        return y[0]

    p = pack(Block(hb=1.0), Harmonic(alpha=0.0, omega=1.3), 0.0, Integration(),
             rockjit.DEFAULT_N)
    par = np.zeros(ig.N_PARW)  # with the derived constants, as the kernel makes it
    par[:ig.N_PAR] = p
    par[ig.P_STHC] = math.sin(p[ig.P_THC])
    par[ig.P_CTHC] = math.cos(p[ig.P_THC])
    K = np.zeros((n_stages + 1, 2))
    y = np.array([0.2, 0.0])
    ytmp, ynew = np.zeros(2), np.zeros(2)
    tab = np.zeros((ig.N_TAB, n_stages + 1))
    ig.step_table(par[ig.P_OMEGA], par[ig.P_H], tab)
    fr, jac = np.zeros(n_stages + 1), np.zeros(n_stages + 1)
    trig = np.zeros(4)
    sincos_chain(10, 0.3)
    sincos_free(10, 0.3)
    dp_steps(10, y, K, par, ytmp, ynew, tab, fr, jac, trig)
    return {"sincos, chained": (lambda n: sincos_chain(6 * n, 0.3), 6),
            "sincos, independent": (lambda n: sincos_free(6 * n, 0.3), 6),
            "bare DP5 step": (lambda n: dp_steps(n, y, K, par, ytmp, ynew, tab, fr, jac, trig),
                              1)}


# --------------------------------------------------------------------------- experiments

def run(periods, **integration):
    """The reference run over ``periods`` (more integration settings as keywords)."""
    return simulate(*REF, integration=Integration(periods=periods, **integration))


def ns_per_step(cfg, mhz):
    """Nanoseconds per grid step and per rhs of the reference run at each N, side by side,
    less the fixed cost of a call (many 1-period N=8 calls in a row)."""
    ns_list = tuple(sorted(set(cfg["ns"]) | {rockjit.DEFAULT_N}))
    cases = {n: (lambda n=n: run(cfg["periods"], n_steps=n)) for n in ns_list}
    cases["call"] = lambda: run(1, n_steps=8)
    t = H.side_by_side(cases, cfg["reps"] * 3)
    call_cold_s = t.median("call")  # right after a large run: caches cold
    call_s = H.median([H.timed(run, 1, n_steps=8)[0] for _ in range(300)])
    call_small_s = H.median([H.timed(run, 1, n_steps=8, max_impacts=100)[0]
                             for _ in range(300)])
    rows = []
    for n in ns_list:
        r = t.result[n]
        kern = t.median(n) - call_s
        rows.append([n, t.median(n), r.n_grid_steps, r.n_rhs, 1e9 * kern / r.n_grid_steps,
                     1e9 * kern / r.n_rhs, 1e9 * kern / r.n_grid_steps * mhz / 1e3, r.n_impacts])
    print("ns/step", rows, call_s)
    return dict(rows=rows, call_overhead_s=call_s, call_overhead_after_large_run_s=call_cold_s,
                call_overhead_max_impacts_100_s=call_small_s,
                raw={str(k): v for k, v in t.wall.items()},
                single_run_s=t.median(rockjit.DEFAULT_N))


#: The fixed cost of a call, on the chaotic scene of bench_work_precision.py and the peers'
#: benchmark (hb=1, alpha=0.955, omega=1.3, from the study's state): at the loosest settings,
#: and as that scene runs at 1e-6.
CALL_SCENES = {"1 period, N=8": (1, 8), "5 periods, N=64": (5, 64)}


def calls(cfg):
    """The cost of one call by path, side by side, and its overhead: the median less the
    compiled run's own (:func:`kernel_alone`). Every path runs the same integration (checked)."""
    rows = []
    for label, (periods, n) in CALL_SCENES.items():
        def objects(periods=periods, n=n):
            return (Block(hb=1.0, law="housner"), Harmonic(alpha=0.955, omega=1.3),
                    Integration(periods=periods, n_steps=n))
        block, forcing, integration = objects()
        prepared = simulate.prepare(block, forcing, integration=integration)
        theta0, dtheta0 = (float(x) for x in prepared.plan.y0[:2])
        cases = {
            "the compiled run alone": kernel_alone(prepared),
            "prepared run": prepared,
            "prepared run, new state": lambda: prepared(state=(theta0, dtheta0)),
            "prepared run, new amplitude": lambda: prepared(alpha=0.955),
            "simulate (its prepared run reused)": lambda: simulate(block, forcing,
                                                                   integration=integration),
            "simulate, objects made per call": lambda: (
                lambda b, f, i: simulate(b, f, integration=i))(*objects()),
            "plan, then run (nothing reused)": lambda: rockjit.single.run(
                simulate.plan(block, forcing, integration=integration)),
        }
        for fn in cases.values():
            fn()
        t = H.side_by_side(cases, cfg["call_reps"])
        final = t.result["the compiled run alone"]
        for path, r in t.result.items():
            if path != "the compiled run alone" and not np.array_equal(r.state, final):
                raise RuntimeError(f"{path} ran another integration ({label})")
        base = t.median("the compiled run alone")
        for path in cases:
            rows.append([label, path, 1e6 * t.median(path), 1e6 * (t.median(path) - base)])
    print("calls", rows)
    return rows


def where_time_goes(cfg):
    """ns per call of a step's pieces (microbenchmarks, interleaved)."""
    pieces = step_internals()
    n = cfg["micro_steps"]
    t = H.side_by_side({k: (lambda f=f: f(n)) for k, (f, _) in pieces.items()}, cfg["reps"])
    micro = {k: 1e9 * t.median(k) / (per * n) for k, (_, per) in pieces.items()}
    print("micro", micro)
    return micro


def trajectories(cfg, single_run_s):
    """Trajectories per second: a single run, basin cells (early stop on, off), sweep values."""
    g_es, g_full = cfg["g_es"], cfg["g_full"]
    alphas = sweep_alphas(cfg)
    traj = {"single run": (single_run_s, 1, f"reference run, N={rockjit.DEFAULT_N}, "
                                            f"{cfg['periods']} periods")}
    w = [H.timed(basin, *BASIN, g_es)[0] for _ in range(3)]
    traj["basin, early stop"] = (H.median(w), g_es**2,
                                 f"{g_es}x{g_es} study basin, N={GRID_N}, 500 periods")
    w = [H.timed(basin, *BASIN, g_full, classification=FULL_LENGTH)[0]
         for _ in range(cfg["full_reps"])]
    traj["basin, full length"] = (H.median(w), g_full**2,
                                  f"{g_full}x{g_full} study basin, N={GRID_N}, all 500 "
                                  "periods")
    w = [H.timed(sweep, *SWEEP, alphas)[0] for _ in range(cfg["full_reps"])]
    traj["sweep with exponents"] = (H.median(w), alphas.size,
                                    f"study's hb=1 Housner sweep, alpha 0.5..1.0 "
                                    f"({alphas.size} values), lyapunov, early stop")
    rows = [[k, v[2], v[1], v[0], v[1] / v[0]] for k, v in traj.items()]
    print(rows)
    return rows


def sweep_alphas(cfg):
    return np.round(np.arange(0.5, 1.0 + 1e-9, cfg["sweep_step"]), 6)


def basin_sizes(cfg):
    """Basin time against grid size (median of 3 up to n = 100, one run above)."""
    rows = []
    for n in cfg["sizes"]:
        k = 3 if n <= 100 else 1
        ws = [H.timed_cpu(basin, *BASIN, n) for _ in range(k)]
        wall = H.median([x[0] for x in ws])
        cpu = H.median([x[1] for x in ws])
        b = ws[-1][2]
        rows.append([n, n * n, k, wall, n * n / wall, cpu / wall,
                     float(np.mean(b.t_end) / b.forcing.period)])
        print("size", rows[-1])
    return rows


def basin_periods(cfg):
    """Basin time against periods: early stop (median of 3) and full length (one run)."""
    g_p = cfg["g_p"]
    rows = []
    for p in cfg["plist"]:
        periods = Integration(periods=p)
        w_es = H.median([H.timed(basin, *BASIN, g_p, integration=periods)[0]
                         for _ in range(3)])
        w_full = H.timed(basin, *BASIN, g_p, integration=periods,
                         classification=FULL_LENGTH)[0]
        rows.append([p, w_es, w_full, 1e9 * w_full / (g_p**2 * p * GRID_N),
                     1e9 * w_full * numba.get_num_threads() / (g_p**2 * p * GRID_N)])
        print("periods", rows[-1])
    return rows


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
    res = {1: [], 2: []}
    old = numba.get_num_threads()
    try:
        for _ in range(repeats):
            for th in (1, 2):
                numba.set_num_threads(th)
                res[th].append(H.timed(_burn, 2_000_000, out)[0])
    finally:
        numba.set_num_threads(old)
    return H.median(res[1]) / H.median(res[2])


def threads(cfg):
    """The basin with 1 and 2 numba threads, alternating order, between two measures of what
    the machine allows."""
    load0 = H.loadavg()[0]
    par_before = machine_parallelism(5)
    rows = []
    for label, grid, cl, k in (("early stop", cfg["g_es"], Classification(),
                                cfg["thread_reps"][0]),
                               ("full length", cfg["g_full"], FULL_LENGTH,
                                cfg["thread_reps"][1])):
        res = {1: [], 2: []}
        for rep in range(k):
            for th in ((1, 2) if rep % 2 == 0 else (2, 1)):
                res[th].append(H.timed_cpu(basin, *BASIN, grid, classification=cl,
                                           execution=Execution(threads=th))[:2])
        w1 = H.median([x[0] for x in res[1]])
        w2 = H.median([x[0] for x in res[2]])
        c2 = H.median([x[1] for x in res[2]])
        rows.append([label, grid ** 2, w1, w2, w1 / w2, c2 / w2])
    par_after = machine_parallelism(5)
    load1 = H.loadavg()[0]
    print("threads", rows, par_before, par_after, load0, load1)
    return dict(rows=rows, machine_speedup_before=par_before, machine_speedup_after=par_after,
                loadavg=(load0, load1))


def exponents(cfg):
    """The exponents on and off: a single run, a basin and a sweep, interleaved."""
    g_l, periods = cfg["g_l"], cfg["periods"]
    alphas = sweep_alphas(cfg)[::2]
    length = Integration(periods=periods)
    t = H.side_by_side({
        ("single run", False): lambda: simulate(*REF, integration=length),
        ("single run", True): lambda: simulate(*REF, integration=length, lyapunov=True),
        ("basin", False): lambda: basin(*BASIN, g_l),
        ("basin", True): lambda: basin(*BASIN, g_l, lyapunov=True),
        ("sweep", False): lambda: sweep(*SWEEP, alphas, lyapunov=False),
        ("sweep", True): lambda: sweep(*SWEEP, alphas, lyapunov=True),
    }, cfg["lyap_reps"])
    what = {"single run": f"reference run, N={rockjit.DEFAULT_N}, {periods} periods",
            "basin": f"{g_l}x{g_l} study basin, early stop",
            "sweep": f"{alphas.size} alphas of the hb=1 sweep, early stop"}
    # with lyapunov=False a sweep cannot tell chaotic from aperiodic: same labels otherwise
    rows = [[k, what[k], t.median((k, False)), t.median((k, True)),
             t.median((k, True)) / t.median((k, False))] for k in what]
    print("lyap", rows)
    return dict(rows=rows, raw={f"{k[0]}/{k[1]}": v for k, v in t.wall.items()})


#: The kernels whose compile time is measured: (label, entry point, arguments, keywords).
_P50 = dict(integration=Integration(periods=50))
COMPILE_SPECS = (
    ("simulate (closed forcing)", "simulate", REF, _P50),
    ("simulate, lyapunov=True", "simulate", REF, dict(_P50, lyapunov=True)),
    ("simulate, embedded forcing", "simulate", (REF[0], REF[1].replace(embedded=True)), _P50),
    ("basin (grid kernel)", "basin", (*BASIN, 4), _P50),
    ("sweep, lyapunov (tangent grid kernel)", "sweep", (*SWEEP, [0.6, 0.7]), _P50),
)


def compile_cost():
    """Compile time of each kernel in three fresh processes sharing one new cache."""
    rows = []
    for label, kind, args, kw in COMPILE_SPECS:
        ct = H.compile_times(kind, args, kw, processes=("cold", "second", "third"),
                             warm_repeats=3)
        rows.append([label, ct["cold"]["compile_s"], ct["second"]["compile_s"],
                     ct["third"]["compile_s"], ct["third"]["import_s"]])
    return rows


_MEM = H.DECODE + textwrap.dedent("""
    import json, resource, sys, time, tracemalloc
    spec = json.loads(sys.argv[1])
    import numpy as np
    import rockjit
    args = decode(spec["args"])
    rockjit.basin(args[0], args[1], 2, integration=rockjit.Integration(periods=5))  # load
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
    b = rockjit.basin(*args)
    wall = time.perf_counter() - t
    _, tm_peak = tracemalloc.get_traced_memory()
    tracemalloc.stop()
    hwm_kib = status("VmHWM:")
    peak_kib = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss
    out_bytes = sum(a.nbytes for a in (b.label, b.period, b.t_end, b.theta0, b.dtheta0))
    print(json.dumps(dict(base_kib=base_kib, peak_kib=peak_kib, tracemalloc_peak_b=tm_peak,
                          rss0_kib=rss0_kib, hwm_kib=hwm_kib, hwm_reset=hwm_reset,
                          wall_s=wall, result_bytes=out_bytes,
                          mean_periods=float(np.mean(b.t_end) / b.forcing.period),
                          fractions=b.fractions())))
""")


def peak_memory(cfg):
    """Peak memory of a basin, in a fresh process (kernel loaded from the cache first)."""
    p = subprocess.run([sys.executable, "-c", _MEM, json.dumps(dict(
        args=H.encode([*BASIN, cfg["g_m"]])))], env=H.child_env(), capture_output=True,
        text=True, check=True, cwd=tempfile.gettempdir())
    mem = json.loads(p.stdout.strip().splitlines()[-1])
    print("memory", mem)
    return mem


# --------------------------------------------------------------------------- the report

def markdown(rec, cfg, quick, env):
    mhz = env["cpu_mhz"]
    st, micro, thr, mem = rec["ns_per_step"], rec["ns_per_step"]["micro_ns"], rec["threads"], \
        rec["memory"]
    g_m = cfg["g_m"]
    md = [f"#### Throughput and scaling: results{H.quick_note(quick)}\n"]
    md.append(f"\n**Nanoseconds per step**: the reference run (hb=1, alpha=0.6, omega=1.3, "
              f"Housner, z0), {cfg['periods']} periods, medians of {3 * cfg['reps']} interleaved "
              f"runs; the fixed cost of a `simulate` call is subtracted: "
              f"{1e6 * st['call_overhead_s']:.0f} µs, the median of 300 1-period N=8 calls in a "
              f"row ({1e6 * st['call_overhead_max_impacts_100_s']:.0f} µs with "
              f"`max_impacts=100` instead of the default 100 000, the rows of the impact "
              f"buffer; {1e6 * st['call_overhead_after_large_run_s']:.0f} µs right after a "
              f"500-period run, caches cold). Cycles at the nominal {mhz:.0f} MHz.\n\n")
    md.append(H.md_table(["N", "wall (s)", "grid steps", "rhs evaluations", "ns / step",
                          "ns / rhs", "cycles / step", "impacts"], st["rows"]))
    md.append(f"\nWhere the time goes (microbenchmarks, ns per call, medians of "
              f"{cfg['reps']}):\n\n")
    md.append(H.md_table(["piece", "ns", "cycles"],
                         [[k, v, v * mhz / 1e3] for k, v in micro.items()]
                         + [["6 x sincos chained (a step's sines, were none overlapped)",
                             6 * micro["sincos, chained"],
                             6 * micro["sincos, chained"] * mhz / 1e3]]))
    md.append(f"\n**The fixed cost of a call**: the chaotic scene (hb=1, alpha=0.955, "
              f"omega=1.3, Housner, from the study's state), each path medians of "
              f"{cfg['call_reps']} interleaved calls; overhead = the median less the compiled "
              "run's own (called straight, on outputs made once). Every path runs the same "
              "integration (its final state checked). A prepared run "
              "(`rockjit.simulate.prepare`) skips the checks, the packing and numba's "
              "dispatch; what it still pays is the result: its arrays made, the scalars read "
              "back, the `Result` built.\n\n")
    md.append(H.md_table(["scene", "path", "µs per call", "overhead (µs)"], rec["calls"]))
    md.append("\n**Trajectories per second** (one basin cell or sweep value is one trajectory; "
              "default threads):\n\n")
    md.append(H.md_table(["what", "setting", "trajectories", "wall (s)", "trajectories / s"],
                         rec["trajectories"]))
    md.append(f"\n**Basin time against grid size**: the study's basin (hb=1, alpha=0.66, "
              f"omega=1.3, Housner), defaults (N={GRID_N}, 500 periods, early stop, "
              "default threads); median of 3 up to n=100, one run above. CPU/wall: the process's "
              "CPU time over wall time (2 would be both threads busy).\n\n")
    md.append(H.md_table(["n", "cells", "runs", "wall (s)", "cells / s", "CPU / wall",
                          "mean periods run per cell"], rec["basin_size"]))
    g_p = rec["basin_periods"]["grid"]
    md.append(f"\n**Basin time against periods**: the same basin on a {g_p}x{g_p} grid, early "
              "stop (median of 3) and full length (one run).\n\n")
    md.append(H.md_table(["periods", "early stop (s)", "full length (s)",
                          "full length: wall ns / step", "x threads"],
                         rec["basin_periods"]["rows"]))
    load0, load1 = thr["loadavg"]
    md.append(f"\n**Threads**: the same basin with 1 and 2 numba threads, alternating order; "
              f"CPU/wall of the 2-thread runs. A trivially parallel arithmetic kernel ran "
              f"{thr['machine_speedup_before']:.2f}x (before) and "
              f"{thr['machine_speedup_after']:.2f}x (after) faster on 2 threads than on 1 at the "
              f"time: the speed-up this shared machine allowed. Load average {load0:.2f} "
              f"before, {load1:.2f} after.\n\n")
    md.append(H.md_table(["basin", "cells", "1 thread (s)", "2 threads (s)", "speed-up",
                          "CPU / wall (2 threads)"], thr["rows"]))
    md.append("\n**Exponents on and off** (medians of interleaved runs):\n\n")
    md.append(H.md_table(["what", "setting", "lyapunov=False (s)", "lyapunov=True (s)",
                          "ratio"], rec["lyapunov"]["rows"]))
    if rec["compile"]:
        md.append("\n**Compile time**: first call in a fresh process minus the warm median, in "
                  "three fresh processes one after the other sharing one new NUMBA_CACHE_DIR: "
                  "cold = empty cache, then the 2nd and 3rd processes with what the earlier ones "
                  "wrote; each kernel in its own new cache, so a cold figure includes the shared "
                  "model and stepper functions.\n\n")
        md.append(H.md_table(["kernel", "cold (s)", "2nd process (s)", "3rd process (s)",
                              "import rockjit (s)"], rec["compile"]))
    md.append(f"\n**Peak memory of a {g_m}x{g_m} basin** (defaults, early stop; fresh process, "
              f"kernel loaded from cache first; {mem['wall_s']:.1f} s, "
              f"{mem['mean_periods']:.1f} periods run per cell on average):\n\n")
    hwm = [["RSS high-water mark during the basin (VmHWM, reset just before it)",
            mem["hwm_kib"] / 1024],
           ["its increase over the RSS before the basin",
            (mem["hwm_kib"] - mem["rss0_kib"]) / 1024]] if mem.get("hwm_reset") else []
    md.append(H.md_table(
        ["measure", "MiB"],
        [["process peak, ru_maxrss (Python, numba, LLVM, the loaded kernel, the basin)",
          mem["peak_kib"] / 1024],
         ["ru_maxrss after loading the kernel, before the basin", mem["base_kib"] / 1024],
         *hwm,
         ["tracemalloc peak (NumPy arrays made in Python around the kernel)",
          mem["tracemalloc_peak_b"] / 2**20],
         ["the returned arrays (label, period, t_end, axes)", mem["result_bytes"] / 2**20]]))
    md.append(f"\n{H.env_line(env)}\n")
    return "".join(md)


def csv_rows(rec):
    rows = [["ns_per_step", f"N={r[0]}", r[4]] for r in rec["ns_per_step"]["rows"]]
    rows += [["micro_ns", k, v] for k, v in rec["ns_per_step"]["micro_ns"].items()]
    rows += [["call_us", f"{r[0]}|{r[1]}", r[2]] for r in rec["calls"]]
    rows += [["call_overhead_us", f"{r[0]}|{r[1]}", r[3]] for r in rec["calls"]
             if r[1] != "the compiled run alone"]
    rows += [["trajectories_per_s", r[0], r[4]] for r in rec["trajectories"]]
    rows += [["basin_size_wall_s", f"n={r[0]}", r[3]] for r in rec["basin_size"]]
    for r in rec["basin_periods"]["rows"]:
        rows.append(["basin_periods_wall_s", f"periods={r[0]},early_stop", r[1]])
        rows.append(["basin_periods_wall_s", f"periods={r[0]},full", r[2]])
    rows += [["threads_speedup", r[0], r[4]] for r in rec["threads"]["rows"]]
    rows += [["lyapunov_ratio", r[0], r[4]] for r in rec["lyapunov"]["rows"]]
    for r in rec["compile"]:
        rows.append(["compile_cold_s", r[0], r[1]])
        rows.append(["compile_cached_s", r[0], r[2]])
    rows.append(["memory_peak_mib", "basin", rec["memory"]["peak_kib"] / 1024])
    return rows


def plot(size_rows, per_rows, g_p):
    plt = H.pyplot()
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
    return fig


# --------------------------------------------------------------------------- main

def main(argv=None):
    b = H.Bench(__doc__, argv)
    cfg = QUICK if b.quick else FULL
    b.env["cpu_mhz"] = cpu_mhz()
    # load every kernel used below
    two = Integration(periods=2)
    simulate(*REF, integration=two)
    simulate(*REF, integration=two, lyapunov=True)
    basin(*BASIN, 2, integration=two)
    basin(*BASIN, 2, integration=two, lyapunov=True)

    rec = dict(quick=b.quick, environment=b.env)
    rec["ns_per_step"] = ns_per_step(cfg, b.env["cpu_mhz"])
    rec["ns_per_step"]["micro_ns"] = where_time_goes(cfg)
    rec["calls"] = calls(cfg)
    rec["trajectories"] = trajectories(cfg, rec["ns_per_step"].pop("single_run_s"))
    rec["basin_size"] = basin_sizes(cfg)
    rec["basin_periods"] = dict(grid=cfg["g_p"], rows=basin_periods(cfg))
    rec["threads"] = threads(cfg)
    rec["lyapunov"] = exponents(cfg)
    rec["compile"] = [] if b.quick else compile_cost()
    rec["memory"] = peak_memory(cfg)

    b.report("throughput", markdown=markdown(rec, cfg, b.quick, b.env),
             csv=(["table", "key", "value"], csv_rows(rec)), data=rec,
             figures=[("throughput.png", plot(rec["basin_size"], rec["basin_periods"]["rows"],
                                              cfg["g_p"]), 120)])
    return 0


if __name__ == "__main__":
    sys.exit(main())
