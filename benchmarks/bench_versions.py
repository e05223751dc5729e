"""Two versions of rockjit side by side: step time, basin and sweep time, and identical results.

A change that reshapes the kernels (their inputs and outputs, the loop, compile time, lanes)
must keep warm speed within a few percent of an earlier commit and the results the same. This
script measures exactly that: it checks the earlier commit out into a temporary git worktree,
starts one worker process per version (each imports its own rockjit and warms its kernels), and
times the same calls in both, interleaved round by round in rotating order, so the ratio of the
medians is taken side by side on one noisy machine:

- ``run``: the study's reference run (hb=1, alpha=0.6, omega=1.3, Housner, z0, 500 periods),
  nanoseconds per step; ``run+lyapunov``: the same with the exponents;
- ``basin``: the study's 100x100 hb=1 Housner basin (alpha=0.66, omega=1.3, (r0, s0) = (0, 1),
  early stopping, no exponents; attractor identification off where the version has it);
- ``basin-full``: the same basin at full length (``early_stop=False``, 500 periods);
- ``rk4-basin``: the same basin computed by the plain RK4 reference of
  ``benchmarks/reference_rk4.py`` (this checkout's, in both workers: its two timings are one
  program measured twice) at full length over 100 periods (500 would take a minute a call),
  the yardstick of the full-length basin: the report compares their throughputs in
  cell-periods per second, each version's own in the same run;
- ``sweep``: hb=1 Housner over alpha in [0.5, 1.0] every 0.005 with exponents;
- ``spectrum-sine``, ``spectrum-ricker``: the transient kernel on an 80 x 80 overturning
  spectrum of a pulse (h/b = 4, no bisection); ``ida``: on an incremental dynamic analysis of
  six synthetic 20 s records at 30 intensities under both laws (``_common.call_in``).

Each case also reports whether both versions returned the same numbers, bit for bit (the final
state and impact count of a run; the labels, periods, exponents and strobe points of a grid;
the outcomes and largest rotations of a transient grid).

Each version is called in its own API. A case is written once, in flat keywords (the API of the
versions before rockjit's settings objects); each worker looks at the rockjit it imported
(``_common.api_of``: does it have ``rockjit.Harmonic``?) and makes the call that version takes
(``_common.call_in``): the flat keywords as they are (those its functions know), or the block,
the excitation and the settings objects built from them. So ``--base f12ce1e`` (flat keywords)
and ``--base HEAD`` (settings objects) both compare the same runs.

    python benchmarks/bench_versions.py --base 4b22de6           # this checkout against 4b22de6
    python benchmarks/bench_versions.py --quick   # smoke: this checkout against itself, small
    python benchmarks/bench_versions.py --base e16710d --cases run,run+lyapunov --out /tmp/b

Without ``--base`` both workers import this checkout (a self-comparison: every case must come
out identical, and the ratios near 1 show the method's noise).

Writes versions.{md,csv,json,png} to benchmarks/results/ (and its block of
benchmarks/README.md), or to benchmarks/results/quick/ with ``--quick``.
"""

from __future__ import annotations

import json
import os
import subprocess
import sys
import tempfile
import textwrap
from pathlib import Path

import _common as H

#: The study's reference run, from its initial state, in flat keywords.
REFERENCE_RUN = dict(hb=1.0, alpha=0.6, omega=1.3, law="housner")
#: The cases: name -> (function, flat keyword arguments, see ``_common.call_in``); ``quick``
#: shrinks them.
CASES = {
    "run": ("simulate", dict(REFERENCE_RUN, periods=500)),
    "run+lyapunov": ("simulate", dict(REFERENCE_RUN, periods=500, lyapunov=True)),
    "basin": ("basin", dict(hb=1.0, alpha=0.66, omega=1.3, law="housner", grid=100, r0=0.0,
                            s0=1.0, attractors=False)),
    "basin-full": ("basin", dict(hb=1.0, alpha=0.66, omega=1.3, law="housner", grid=100,
                                 r0=0.0, s0=1.0, attractors=False, early_stop=False)),
    "rk4-basin": ("rk4basin", dict(hb=1.0, alpha=0.66, omega=1.3, law="housner", grid=100,
                                   r0=0.0, s0=1.0, periods=100)),
    "sweep": ("sweep", dict(hb=1.0, omega=1.3, law="housner", alpha_range=(0.5, 1.0),
                            alpha_step=0.005, lyapunov=True, attractors=False)),
    "spectrum-sine": ("spectrum", dict(hb=4.0, pulse="sine", grid=80)),
    "spectrum-ricker": ("spectrum", dict(hb=4.0, pulse="ricker", grid=80)),
    "ida": ("fragility", dict(hb=4.0, records=6, levels=30)),
}
QUICK = {"run": dict(periods=50), "run+lyapunov": dict(periods=50), "basin": dict(grid=20,
         periods=50), "basin-full": dict(grid=12, periods=50),
         "rk4-basin": dict(grid=12, periods=20), "sweep": dict(alpha_step=0.05, periods=50),
         "spectrum-sine": dict(grid=12), "spectrum-ricker": dict(grid=12),
         "ida": dict(records=2, levels=4)}
#: The cases a plain run measures (``--cases`` names others): the two long ones are asked for.
DEFAULT_CASES = ("run", "run+lyapunov", "basin", "sweep")

#: The worker: reads one JSON request per line, answers one JSON line (seconds, a digest, and
#: which API it called); it imports the rockjit of its version and this folder's _common.
_WORKER = textwrap.dedent("""
    import hashlib, json, sys, time
    import numpy as np
    import rockjit
    import _common as H

    def rk4basin(kw):
        # the plain RK4 reference basin of this checkout (benchmarks/reference_rk4.py) on the
        # packed inputs of the version's own basin plan, at full length
        import reference_rk4  # compiled once per worker
        kw = dict(kw, early_stop=False)
        plan = H.plan_in(rockjit, "basin", kw)
        class Labels:
            label = reference_rk4.basin_rk4(plan.y0s, plan.pars, plan.ipar, plan.cpar)
        return lambda: Labels

    def digest(res):
        h = hashlib.sha256()
        names = ("state", "n_impacts") if hasattr(res, "state") else (
            "label", "period", "lambda_max", "strobe", "outcome", "max_rotation")
        for name in names:
            v = getattr(res, name, None)
            if v is not None:
                h.update(np.ascontiguousarray(np.asarray(v, dtype=float)).tobytes())
        return h.hexdigest()

    for line in sys.stdin:
        fn_name, kw = json.loads(line)
        call = rk4basin(kw) if fn_name == "rk4basin" else H.call_in(rockjit, fn_name, kw)
        c0, t0 = time.process_time(), time.perf_counter()
        res = call()
        wall, cpu = time.perf_counter() - t0, time.process_time() - c0
        steps = getattr(res, "n_steps", 0) * kw.get("periods", 0) if fn_name == "simulate" else 0
        print(json.dumps(dict(wall=wall, cpu=cpu, digest=digest(res), steps=steps,
                              file=rockjit.__file__, api=H.api_of(rockjit))), flush=True)
""")


class Worker:
    """One Python process importing the rockjit under ``src``."""

    def __init__(self, src):
        env = dict(os.environ, PYTHONPATH=os.pathsep.join([str(src), str(H.HERE)]))
        self.proc = subprocess.Popen([sys.executable, "-c", _WORKER], env=env, cwd=str(src),
                                     stdin=subprocess.PIPE, stdout=subprocess.PIPE, text=True)

    def __call__(self, fn, kw):
        self.proc.stdin.write(json.dumps([fn, kw]) + "\n")
        self.proc.stdin.flush()
        line = self.proc.stdout.readline()
        if not line:
            raise RuntimeError(f"a worker died running {fn}({kw})")
        return json.loads(line)

    def close(self):
        self.proc.stdin.close()
        self.proc.wait(timeout=60)


def options(p):
    p.add_argument("--base", default=None,
                   help="the earlier commit (any git revision); default: this checkout itself")
    p.add_argument("--repeats", type=int, default=None, help="rounds (default 15; quick 3)")
    p.add_argument("--processes", type=int, default=None,
                   help="fresh worker pairs the rounds are shared out over (default 3; quick 1)")
    p.add_argument("--cases", default=",".join(DEFAULT_CASES),
                   help=f"comma-separated subset of {', '.join(CASES)} (default: "
                        f"{', '.join(DEFAULT_CASES)}), e.g. to bisect one case's change quickly")


def measure(bench, base_src, cases, repeats, processes=1):
    """Every case in both versions, interleaved; rows, the raw times and the API each version
    was called in (``{"base": [...], "this": [...]}``).

    The rounds are shared out over ``processes`` fresh pairs of workers, one pair after the
    other: a process's own layout (where its arrays and code land, which core it gets) moves
    one version's time by 10-20 % for the life of that process on this machine, so one pair
    alone can show a difference that is not the code's. Each pair's own ratio (of its medians)
    is kept too: their spread is the measurement's noise."""
    here = H.ROOT
    raw = {(c, v): [] for c in cases for v in ("base", "this")}
    cpu = {(c, v): [] for c in cases for v in ("base", "this")}
    last = {}
    pair = {c: [] for c in cases}  # each pair's ratio of medians
    per = [repeats // processes + (k < repeats % processes) for k in range(processes)]
    for k, rounds in enumerate(per):
        workers = {"base": Worker(base_src), "this": Worker(here)}
        try:
            for name, (fn, kw) in cases.items():  # warm: compile or load every variant once
                for w in workers.values():
                    w(fn, kw)
            order = list(workers) if k % 2 else list(workers)[::-1]
            for rep in range(rounds):
                for c, (fn, kw) in cases.items():
                    for v in (order if rep % 2 else order[::-1]):
                        r = workers[v](fn, kw)
                        raw[c, v].append(r["wall"])
                        cpu[c, v].append(r["cpu"])
                        last[c, v] = r
            for c in cases:
                pair[c].append(H.median(raw[c, "this"][-rounds:]) /
                               H.median(raw[c, "base"][-rounds:]))
        finally:
            for w in workers.values():
                w.close()
    rows = []
    for c in cases:
        b, t = H.median(raw[c, "base"]), H.median(raw[c, "this"])
        steps = last[c, "this"]["steps"]
        cb, ct = H.median(cpu[c, "base"]), H.median(cpu[c, "this"])
        rows.append(dict(case=c, base_s=b, this_s=t, ratio=t / b, cpu_ratio=ct / cb,
                         pair_min=min(pair[c]), pair_max=max(pair[c]),
                         base_ns_step=b / steps * 1e9 if steps else None,
                         this_ns_step=t / steps * 1e9 if steps else None,
                         identical=last[c, "base"]["digest"] == last[c, "this"]["digest"]))
    api = {v: sorted({last[c, v]["api"] for c in cases}) for v in ("base", "this")}
    return rows, {f"{c}/{v}/{k}": ts for k, d in (("wall", raw), ("cpu", cpu))
                  for (c, v), ts in d.items()}, api


def _api_words(names):
    words = {"objects": "rockjit's settings objects", "flat": "flat keywords"}
    return " and ".join(words.get(n, n) for n in names)


def yardstick(rows, cases):
    """Lines comparing the full-length basin with the plain RK4 reference, when both ran: each
    version's throughput (cell-periods per second) over the reference's in the same run, and
    the full-length basin's speed-up of this over base."""
    by = {r["case"]: r for r in rows}
    if "basin-full" not in by or "rk4-basin" not in by:
        return []
    full, rk4 = by["basin-full"], by["rk4-basin"]
    cells = cases["basin-full"][1]["grid"] ** 2
    assert cases["rk4-basin"][1]["grid"] ** 2 == cells
    p_full = cases["basin-full"][1].get("periods", 500)
    p_rk4 = cases["rk4-basin"][1]["periods"]
    out = ["", "Full-length basin against the plain RK4 reference (`reference_rk4.py`), "
           "throughput in cell-periods per second, each version against the reference's own "
           "timing in its worker:", "",
           "| version | rockjit full length | RK4 reference | rockjit / RK4 |",
           "|---|---|---|---|"]
    for v in ("base", "this"):
        a = cells * p_full / full[f"{v}_s"]
        b = cells * p_rk4 / rk4[f"{v}_s"]
        out.append(f"| {v} | {a:.4g} | {b:.4g} | {a / b:.2f} |")
    out += ["", f"Full-length basin, this over base: {1.0 / full['ratio']:.2f}x the cells per "
                f"second (pairs of processes: {1.0 / full['pair_max']:.2f}-"
                f"{1.0 / full['pair_min']:.2f}x)."]
    return out


def main(argv=None):
    bench = H.Bench(__doc__, argv, options=options)
    a = bench.args
    repeats = a.repeats or (3 if bench.quick else 15)
    processes = a.processes or (1 if bench.quick else 3)
    if not 1 <= processes <= repeats:
        bench.parser.error(f"--processes must be in [1, --repeats = {repeats}] "
                           f"(got {processes})")
    chosen = [c.strip() for c in a.cases.split(",") if c.strip()]
    unknown = sorted(set(chosen) - set(CASES))
    if unknown or not chosen:
        bench.parser.error(f"--cases: unknown {unknown}; choose from {', '.join(CASES)}")
    cases = {c: (fn, dict(kw, **(QUICK[c] if bench.quick else {})))
             for c, (fn, kw) in CASES.items() if c in chosen}
    if a.base is None:
        rev = "this checkout"
        rows, raw, api = measure(bench, H.ROOT, cases, repeats, processes)
    else:
        rev = subprocess.run(["git", "-C", str(H.ROOT), "rev-parse", "--short", a.base],
                             capture_output=True, text=True, check=True).stdout.strip()
        with tempfile.TemporaryDirectory(prefix="rockjit-base-") as tmp:
            src = Path(tmp) / "src"
            subprocess.run(["git", "-C", str(H.ROOT), "worktree", "add", "--detach", "--quiet",
                            str(src), rev], check=True)
            try:
                rows, raw, api = measure(bench, src, cases, repeats, processes)
            finally:
                subprocess.run(["git", "-C", str(H.ROOT), "worktree", "remove", "--force",
                                str(src)], check=False)
    this = bench.env.get("commit", "this checkout")
    lines = [f"#### Two versions side by side: {rev} (base) and {this} (this)", "",
             f"Medians of {repeats} rounds over {processes} fresh pairs of worker processes, each "
             f"case run in both versions back to back (order alternating), after one warm-up "
             f"call per process; `this/base` compares wall times (`pairs`: the lowest and highest "
             f"ratio of one pair of processes alone, the measurement's noise), `CPU "
             f"this/base` the process CPU times (all threads; less sensitive to other work on a "
             f"shared machine); `identical`: both returned the same numbers bit for bit. "
             f"Each version was called in its own API: base {_api_words(api['base'])}, this "
             f"{_api_words(api['this'])}.", "",
             "| case | base | this | this/base | pairs | CPU this/base | ns/step base "
             "| ns/step this | identical |", "|---|---|---|---|---|---|---|---|---|"]
    for r in rows:
        ns = ("", "") if r["base_ns_step"] is None else (f"{r['base_ns_step']:.0f}",
                                                        f"{r['this_ns_step']:.0f}")
        lines.append(f"| {r['case']} | {r['base_s']:.4g} s | {r['this_s']:.4g} s | "
                     f"{r['ratio']:.3f} | {r['pair_min']:.2f}-{r['pair_max']:.2f} | "
                     f"{r['cpu_ratio']:.3f} | {ns[0]} | {ns[1]} | "
                     f"{'yes' if r['identical'] else 'no'} |")
    lines += yardstick(rows, cases)
    markdown = "\n".join(lines) + "\n"
    plt = H.pyplot()
    fig, ax = plt.subplots(figsize=(6, 3.2))
    ax.barh([r["case"] for r in rows], [r["ratio"] for r in rows], color="tab:blue",
            xerr=[[max(r["ratio"] - r["pair_min"], 0.0) for r in rows],
                  [max(r["pair_max"] - r["ratio"], 0.0) for r in rows]], capsize=3)
    ax.axvline(1.0, color="k", lw=0.8)
    ax.set_xlabel(f"wall time, this / base ({rev}); bars: single pairs of processes")
    ax.invert_yaxis()
    fig.tight_layout()
    keys = list(rows[0])
    bench.report("versions", markdown=markdown, csv=(keys, [[r[k] for k in keys] for r in rows]),
                 data=dict(base=rev, rows=rows, raw=raw, api=api, env=bench.env),
                 figures=[("versions.png", fig, 120)])
    return 0


if __name__ == "__main__":
    sys.exit(main())
