"""Where a cold start's time goes (numba compilation), per kernel variant, per compiler stage
and per command, each cold and warm side by side.

Every measurement runs in fresh Python processes. **Cold**: a new, empty ``NUMBA_CACHE_DIR``
(every kernel compiles); **warm**: a second fresh process on the cache the cold one wrote (the
kernels load from it). Cold and warm of one item run back to back; items (and package roots, see
below) are rotated from repeat to repeat. Wall time is the whole process's, seen from outside;
CPU time is the process's user + system time (all threads), which a loaded machine inflates much
less than wall time.

What is measured

- **kernel variants** (:data:`rockjit._engine.kernel.VARIANTS`): the first call of each, through
  :func:`rockjit._engine.kernel.compile_variant` (what ``rockjit compile`` runs), each alone on an
  empty cache; and two sequences in one process, ``run`` then ``grid`` and ``run+tangent`` then
  ``grid+tangent``, which show what a grid kernel costs once the single-run kernel it calls is
  compiled (the grid kernels call the same ``integrate._run`` specialisation).
- **the compile time by stage**, in the cold process (exclusive CPU seconds, nested work counted
  once), through numba's event API (``numba.core.event``: the ``numba:compile`` and
  ``numba:run_pass`` events) and wrappers of numba's code library (``numba.core.codegen``):
  typing (``nopython_type_inference``), numba's IR inlining (``inline_inlinables``: the pieces
  declared ``inline="always"``), the other front-end passes, lowering to LLVM IR
  (``native_lowering``, less the LLVM work nested in it), LLVM (parsing and linking the IR, the
  per-function and the module optimisation passes, machine-code generation) and numba's on-disk
  cache. Also per compiled function (its qualified name; an inlined piece's typing and lowering
  are charged to its host), and per inlined piece, how many copies of its IR numba inlined and
  how many IR statements they hold. (numba 0.68 has no ``NUMBA_DEBUG_TIMING``; it offers these
  events, ``NUMBA_LLVM_PASS_TIMINGS`` and ``NUMBA_CHROME_TRACE``.)
- **commands**, as a user runs them first, in-process (``rockjit.cli.main``, same breakdown):
  ``rockjit trajectory --hb 1 --alpha 0.6 --omega 1.3`` with and without ``--lyapunov``, a tiny
  basin, a tiny sweep, ``rockjit compile`` (its worker processes compile; the parent's
  breakdown is empty) and ``rockjit paper``, the README's first command;
- **the install** (part ``install``): ``python -m venv`` and ``pip install -e ROOT`` into a
  fresh folder, per root, with whatever index and wheel cache pip is configured to use;
- **the cold-start goals**, from the above: a cold ``rockjit trajectory`` at most 4x its warm
  time, and the README's first command (install + cold ``rockjit paper``) under 45 s. (The third,
  the test suite cold under 100 s, is what ``.ci/run`` on a fresh clone measures.)
- **warm speed**, the guard of any change made to cut compile time: the per-step time of the
  reference run (hb 1, alpha 0.6, omega 1.3, 5000 periods, over its ``n_grid_steps``), with and
  without exponents, a basin of the study (hb 1, alpha 0.66, omega 1.3, ``r0, s0 = 0, 1``) and
  a sweep of the study (hb 1, omega 1.3, alpha 0.5..1, exponents on), every package root in one
  process, interleaved; and whether every root's results are bit-identical to the first's. Each
  root is called in its own API (``_common.call_in``: the settings objects, or the flat keywords
  of the versions before them), so a root of an earlier commit can be measured beside this one.

Several package roots can be measured side by side (``--root NAME=DIR``, a folder holding a
``rockjit`` package; default: this checkout), e.g. the code as it is and a patched copy: that is
how the levers against compile time are compared (benchmarks/README.md).

    python benchmarks/bench_compile.py          # full (~15 min)
    python benchmarks/bench_compile.py --quick    # smoke (seconds): one small function
    python benchmarks/bench_compile.py --root base=. --root new=/tmp/patched --parts speed
    python benchmarks/bench_compile.py --parts commands --commands trajectory --repeats 3 \
        --root default=. --root opt1=. --env opt1:NUMBA_OPT=1 --root opt0=. \
        --env opt0:NUMBA_OPT=0 --root novec=. --env novec:NUMBA_LOOP_VECTORIZE=0 \
        --env novec:NUMBA_SLP_VECTORIZE=0 --name compile_levers   # the switches as levers

Writes compile.{md,csv,json,png} through the shared harness (benchmarks/_common.py).
"""

from __future__ import annotations

import collections
import hashlib
import json
import math
import os
import shutil
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import _common as H

#: The commands a user runs first (argv after ``rockjit``; ``OUT`` is replaced by a fresh
#: folder).
COMMANDS = {
    "trajectory": ["trajectory", "--hb", "1", "--alpha", "0.6", "--omega", "1.3", "--out", "OUT",
                   "--quiet"],
    "trajectory --lyapunov": ["trajectory", "--hb", "1", "--alpha", "0.6", "--omega", "1.3",
                              "--lyapunov", "--out", "OUT", "--quiet"],
    "basin (6 x 6, 40 periods)": ["basin", "--hb", "1", "--alpha", "0.66", "--omega", "1.3",
                                  "--grid", "6", "--periods", "40", "--out", "OUT", "--quiet"],
    "sweep (3 alphas, 40 periods)": ["sweep", "--hb", "1", "--omega", "1.3", "--alpha-range",
                                     "0.6", "0.62", "--alpha-step", "0.01", "--periods", "40",
                                     "--out", "OUT", "--quiet"],
    "compile": ["compile", "--quiet"],
    "paper": ["paper", "--out", "OUT", "--quiet"],
}
#: Kernel sequences compiled in one process: what the second costs after the first.
SEQUENCES = (("run", "grid"), ("run+tangent", "grid+tangent"))
#: The variant whose compiled functions are listed one by one (``rockjit trajectory``'s).
DETAIL = "run+record"

#: Breakdown columns (exclusive CPU seconds) and the instrumentation's categories in each.
PARTS = {
    "typing": ("pass:nopython_type_inference", "pass:partial_type_inference"),
    "ir_inlining": ("pass:inline_inlinables", "pass:inline_closure_likes",
                    "pass:inline_overloads"),
    "front_end_other": None,  # every other numba pass
    "lowering": ("pass:native_lowering", "pass:native_parfor_lowering"),
    "llvm_parse_link": ("llvm:parse", "llvm:link"),
    "llvm_opt": ("llvm:function-opt", "llvm:module-opt"),
    "llvm_codegen": ("llvm:codegen",),
    "cache": ("cache:save", "cache:load"),
}
PART_NAMES = list(PARTS) + ["other"]
CSV_COLUMNS = ["root", "group", "item", "mode", "n", "wall_s", "wall_min_s", "wall_max_s",
               "cpu_s", "first_call_s", "compile_cpu_s", "compiles"] + PART_NAMES

#: Speed cases: settings (full, quick).
SPEED = dict(run_periods=5000, periods=500, grid=100, alpha_step=0.001, repeats=11)


# =========================================================================== the child process

def _instrument():
    """Install the timers; returns ``report()``, which gives the breakdown collected so far.

    Every timed region (a numba compiler pass, an LLVM step, a cache access) is pushed on one
    stack; on exit its wall and CPU time less that of the regions nested in it is charged to
    ``(category, function being compiled)``, so nothing is counted twice.
    """
    from numba.core import caching
    from numba.core import codegen as cg
    from numba.core import event as ev
    from numba.core import inline_closurecall as icc

    acc = collections.defaultdict(lambda: [0.0, 0.0])
    stack = []
    compiling = []
    n_compiles = collections.Counter()
    n_vars = collections.Counter()
    inlined = collections.defaultdict(lambda: [0, 0])  # (piece, host) -> [copies, statements]

    def now():
        return time.perf_counter(), time.process_time()

    def push(cat, fn):
        stack.append([cat, fn, now(), [0.0, 0.0]])

    def pop():
        cat, fn, (w0, c0), (wc, cc) = stack.pop()
        w1, c1 = now()
        a = acc[(cat, fn)]
        a[0] += (w1 - w0) - wc
        a[1] += (c1 - c0) - cc
        if stack:
            stack[-1][3][0] += w1 - w0
            stack[-1][3][1] += c1 - c0

    class Listener(ev.Listener):
        def on_start(self, event):
            d = event.data
            if event.kind == "numba:run_pass":
                push("pass:" + d["name"].split(" [")[0], d["qualname"])
            else:
                compiling.append(d["dispatcher"].py_func.__qualname__)
                push("compile, other", compiling[-1])

        def on_end(self, event):
            pop()
            if event.kind == "numba:compile":
                fn = compiling.pop()
                n_compiles[fn] += 1
                try:
                    n_vars[fn] = sum(len(c.fndesc.typemap)
                                     for c in event.data["dispatcher"].overloads.values())
                except Exception:  # pragma: no cover - numba's internals moved
                    pass

    def wrap(cls, name, cat):
        f = getattr(cls, name)

        def timed(self, *a, **k):
            push(cat, compiling[-1] if compiling else "(top level)")
            try:
                return f(self, *a, **k)
            finally:
                pop()
        setattr(cls, name, timed)

    wrap(cg.CPUCodeLibrary, "add_ir_module", "llvm:parse")
    wrap(cg.CPUCodeLibrary, "_optimize_functions", "llvm:function-opt")
    wrap(cg.CPUCodeLibrary, "_optimize_final_module", "llvm:module-opt")
    wrap(cg.JITCodeLibrary, "_finalize_specific", "llvm:codegen")
    wrap(cg.CPUCodeLibrary, "finalize", "llvm:link")
    wrap(caching.Cache, "save_overload", "cache:save")
    wrap(caching.Cache, "load_overload", "cache:load")

    inline_ir = icc.InlineWorker.inline_ir

    def counted(self, caller_ir, block, i, callee_ir, *a, **k):
        key = (callee_ir.func_id.func_qualname, caller_ir.func_id.func_qualname)
        inlined[key][0] += 1
        inlined[key][1] += sum(len(b.body) for b in callee_ir.blocks.values())
        return inline_ir(self, caller_ir, block, i, callee_ir, *a, **k)
    icc.InlineWorker.inline_ir = counted

    listener = Listener()
    ev.register("numba:run_pass", listener)
    ev.register("numba:compile", listener)

    def report():
        return dict(
            by=[[c, f, w, u] for (c, f), (w, u) in acc.items()],
            compiles=dict(n_compiles), vars=dict(n_vars),
            inlined=[[p, h, n, s] for (p, h), (n, s) in inlined.items()])
    return report




def _piece():
    """The quick mode's item: one small compiled function of the package, called once."""
    import numpy as np

    from rockjit._engine import integrate as ig
    s = np.zeros((5, 4))
    ig.settled_period(s, s, np.zeros(5, dtype=np.int64), 3, 1, 1, 1e-9)


def _child(spec):
    """Run one measurement (``spec`` from the parent); print its JSON on the last line."""
    import resource
    kind = spec["kind"]
    if kind == "speed":
        print("\n" + json.dumps(_speed_child(spec)))
        return
    report = _instrument()
    out = {}
    t0 = time.perf_counter()
    import rockjit  # noqa: F401
    out["import_s"] = time.perf_counter() - t0
    if kind in ("kernel", "piece"):
        from rockjit._engine import kernel as kernel
        steps = []
        for name in spec["names"]:
            before = report()
            t1, c1 = time.perf_counter(), time.process_time()
            if kind == "piece":
                _piece()
            else:
                kernel.compile_variant(name)
            first, first_cpu = time.perf_counter() - t1, time.process_time() - c1
            t2 = time.perf_counter()
            if kind == "piece":
                _piece()
            else:
                kernel.compile_variant(name)
            again = time.perf_counter() - t2
            steps.append(dict(name=name, first_s=first, first_cpu_s=first_cpu, again_s=again,
                              parts=_diff_parts(before, report())))
        out["steps"] = steps
        out["first_s"] = sum(s["first_s"] for s in steps)
        out["rc"] = 0
    else:
        from rockjit.cli.main import main as cli
        argv = [a if a != "OUT" else spec["out"] for a in spec["argv"]]
        t1 = time.perf_counter()
        out["rc"] = int(cli(argv) or 0)
        out["first_s"] = time.perf_counter() - t1
    ru = resource.getrusage(resource.RUSAGE_SELF)
    out["cpu_s"] = ru.ru_utime + ru.ru_stime
    out["inside_s"] = time.perf_counter() - t0
    out.update(report())
    sys.stdout.flush()
    print("\n" + json.dumps(out))


def _diff_parts(before, after):
    """Compile CPU seconds by part between two snapshots of the instrumentation."""
    a, b = _parts(after), _parts(before)
    return {k: a[k] - b[k] for k in a}


def _speed_cases(rj, spec, alphas, warm_up=False):
    """The speed cases of one root (the rockjit package ``rj``): zero-argument calls in its own
    API (:func:`_common.call_in`); ``warm_up``: the same calls, tiny."""
    periods, grid, threads = spec["periods"], spec["grid"], spec["threads"]
    run_periods = spec["run_periods"]
    if warm_up:
        run_periods, periods, grid, alphas = 5, 5, 2, alphas[:2]
    run = dict(hb=1.0, alpha=0.6, omega=1.3, periods=run_periods)
    basin = dict(hb=1.0, alpha=0.66, omega=1.3, grid=grid, r0=0.0, s0=1.0, periods=periods,
                 threads=threads)
    sweep = dict(hb=1.0, omega=1.3, alphas=alphas, periods=periods, z0=rj.Z0_STUDY,
                 threads=threads)
    return {"run_ns_per_step": H.call_in(rj, "simulate", run),
            "run_lyapunov_ns_per_step": H.call_in(rj, "simulate", dict(run, lyapunov=True)),
            "basin_s": H.call_in(rj, "basin", basin),
            "sweep_s": H.call_in(rj, "sweep", sweep)}


def _speed_child(spec):
    """Warm speed of every root, interleaved in this one process (roots imported as aliases),
    and whether every root's results equal the first root's bit for bit."""
    import importlib

    import numpy as np
    sys.path.insert(0, spec["alias_dir"])
    names = spec["aliases"]
    mods = {n: importlib.import_module(n) for n in names}
    alphas = np.round(np.arange(0.5, 1.0 + 1e-9, spec["alpha_step"]), 12)
    loaded = {}
    for n in names:  # compile or load everything first, outside the timing
        t0 = time.perf_counter()
        for call in _speed_cases(mods[n], spec, alphas, warm_up=True).values():
            call()
        loaded[n] = time.perf_counter() - t0

    def per_step(res):
        return res.n_grid_steps

    cases, last = {}, {}
    for n in names:
        for m, call in _speed_cases(mods[n], spec, alphas).items():
            cases[(n, m)] = call
    keys = list(cases)
    times = {f"{n}|{m}": [] for n, m in keys}
    for rep in range(spec["repeats"]):
        i = rep % len(keys)
        order = keys[i:] + keys[:i]
        if rep % 2:
            order = order[::-1]
        for k in order:
            t0 = time.perf_counter()
            r = cases[k]()
            dt = time.perf_counter() - t0
            last[k] = r
            times[f"{k[0]}|{k[1]}"].append(dt / per_step(r) * 1e9 if "per_step" in k[1] else dt)

    def arrays(r):
        d = {}
        for a in ("state", "strobe", "strobe_half", "impacts", "lyapunov", "label", "period",
                  "t_end", "lambda_max", "impact_section", "theta0", "dtheta0", "alpha"):
            v = getattr(r, a, None)
            if isinstance(v, np.ndarray):
                d[a] = v
        return d

    identical = {}
    first = names[0]
    for n in names[1:]:
        for m in ("run_ns_per_step", "run_lyapunov_ns_per_step", "basin_s", "sweep_s"):
            a, b = arrays(last[(first, m)]), arrays(last[(n, m)])
            identical[f"{n}|{m}"] = bool(a.keys() == b.keys() and all(
                np.array_equal(a[x], b[x], equal_nan=True) for x in a))
    return dict(times=times, identical=identical, loaded_s=loaded, load=os.getloadavg(),
                api={n: H.api_of(mods[n]) for n in names})


# =========================================================================== the parent

def _run_child(spec, root, cache_dir, workdir, timeout, extra_env=None):
    """One fresh process (with ``extra_env`` set in its environment); returns the child's JSON
    plus the wall time seen from outside."""
    env = H.child_env(NUMBA_CACHE_DIR=str(cache_dir), PYTHONDONTWRITEBYTECODE="1")
    env.update(extra_env or {})
    env["PYTHONPATH"] = str(root) + os.pathsep + str(H.HERE)
    env.pop("NUMBA_DISABLE_JIT", None)
    cmd = [sys.executable, str(Path(__file__).resolve()), "--child", json.dumps(spec)]
    load0 = os.getloadavg()[0]
    t0 = time.perf_counter()
    proc = subprocess.run(cmd, env=env, cwd=workdir, capture_output=True, text=True,
                          timeout=timeout)
    wall = time.perf_counter() - t0
    try:
        d = json.loads(proc.stdout.strip().splitlines()[-1])
    except (IndexError, json.JSONDecodeError):
        raise RuntimeError(f"child failed ({proc.returncode}) for {spec}:\n"
                           f"{proc.stdout[-3000:]}\n{proc.stderr[-3000:]}") from None
    if d.get("rc", 0) != 0:
        raise RuntimeError(f"command failed (exit {d['rc']}) for {spec}:\n"
                           f"{proc.stdout[-3000:]}\n{proc.stderr[-3000:]}")
    d["wall_s"] = wall
    d["load"] = [load0, os.getloadavg()[0]]
    return d


def _items(args, quick):
    """The (group, name, spec) of everything to measure."""
    if quick:
        return [("kernel", "piece: integrate.settled_period",
                 dict(kind="piece", names=["settled_period"]))]
    from rockjit._engine.kernel import COMMON, VARIANTS
    items = []
    if "kernels" in args.parts:
        names = (args.variants.split(",") if args.variants else VARIANTS if args.all
                 else COMMON)
        for name in names:
            items.append(("kernel", name, dict(kind="kernel", names=[name])))
        for seq in () if args.variants else SEQUENCES:
            items.append(("kernel", " then ".join(seq), dict(kind="kernel", names=list(seq))))
    if "commands" in args.parts:
        for n in args.commands.split(",") if args.commands else COMMANDS:
            argv = COMMANDS[n]
            items.append(("command", f"rockjit {n}", dict(kind="command", argv=argv)))
    return items


def _measure_pair(item, root_name, root, rep, args, tmp):
    """A cold process on a fresh cache, then a warm one on the cache it wrote."""
    group, name, spec = item
    cache = Path(tempfile.mkdtemp(prefix="numba-cache-", dir=tmp))
    work = Path(tempfile.mkdtemp(prefix="work-", dir=tmp))
    rows = []
    try:
        for mode in ("cold", "warm"):
            s = dict(spec, out=str(work / f"out-{mode}"))
            d = _run_child(s, root, cache, work, args.timeout, args.root_env.get(root_name))
            d.update(root=root_name, item=name, group=group, mode=mode, rep=rep)
            rows.append(d)
            print(f"  {root_name:>10} {mode:4} {name:36} wall {d['wall_s']:7.2f} s  "
                  f"cpu {d['cpu_s']:7.2f} s  load {d['load'][0]:.1f}", flush=True)
    finally:
        shutil.rmtree(cache, ignore_errors=True)
        shutil.rmtree(work, ignore_errors=True)
    return rows


def measure(args, roots, tmp, quick):
    """Every item x root x repeat, cold then warm; rotated so that none always runs first."""
    items = _items(args, quick)
    rows = []
    for rep in range(args.repeats):
        k = rep % max(len(items), 1)
        order = items[k:] + items[:k]
        rnames = list(roots)
        rnames = rnames[rep % len(rnames):] + rnames[:rep % len(rnames)]
        for item in order:
            for rn in rnames:
                rows += _measure_pair(item, rn, roots[rn], rep, args, tmp)
    return rows


def speed(args, roots, tmp):
    """Warm speed of every root, in one process (see :func:`_speed_child`)."""
    # numba keys its cache on the path a module was imported from: with --speed-cache the
    # aliases live beside it, named after their root, so that a rerun loads what one compiled
    alias_dir = (Path(args.speed_cache) / "aliases" if args.speed_cache
                 else Path(tempfile.mkdtemp(prefix="aliases-", dir=tmp)))
    alias_dir.mkdir(parents=True, exist_ok=True)
    aliases = []
    for root in roots.values():
        pkg = Path(root).resolve() / "rockjit"
        a = "rockjit_bench_" + hashlib.sha1(str(pkg).encode()).hexdigest()[:10]
        if not (alias_dir / a).is_symlink():
            os.symlink(pkg, alias_dir / a)
        aliases.append(a)
    st = dict(SPEED)
    for k in ("run_periods", "periods", "grid", "alpha_step"):
        if getattr(args, f"speed_{k}") is not None:
            st[k] = getattr(args, f"speed_{k}")
    st["repeats"] = args.speed_repeats or st["repeats"]
    st["threads"] = args.threads
    spec = dict(kind="speed", alias_dir=str(alias_dir), aliases=aliases, **st)
    cache = args.speed_cache or Path(tempfile.mkdtemp(prefix="numba-cache-", dir=tmp))
    d = _run_child(spec, H.ROOT, cache, tmp, args.timeout * 4)
    names = dict(zip(aliases, roots))
    times = {}
    for key, ts in d["times"].items():
        a, m = key.split("|")
        times.setdefault(names[a], {})[m] = ts
    identical = {}
    for key, v in d["identical"].items():
        a, m = key.split("|")
        identical.setdefault(names[a], {})[m] = v
    return dict(times=times, identical=identical, load=d["load"], settings=st,
                loaded_s={names[a]: s for a, s in d["loaded_s"].items()},
                api={names[a]: v for a, v in d["api"].items()})


# =========================================================================== summaries

def _part_of(cat):
    for part, cats in PARTS.items():
        if cats and cat in cats:
            return part
    if cat.startswith("pass:"):
        return "front_end_other"
    return "other"


def _parts(row):
    """Breakdown of one child's compile CPU time by :data:`PARTS`."""
    p = dict.fromkeys(PART_NAMES, 0.0)
    for cat, _fn, _w, u in row["by"]:
        p[_part_of(cat)] += u
    return p


def _med(xs):
    xs = [x for x in xs if x is not None]
    return statistics.median(xs) if xs else math.nan


def summarise(rows):
    """Medians and spreads per (root, item, mode)."""
    groups = collections.defaultdict(list)
    for r in rows:
        groups[(r["root"], r["group"], r["item"], r["mode"])].append(r)
    out = []
    for (root, group, item, mode), rs in groups.items():
        walls = [r["wall_s"] for r in rs]
        parts = [_parts(r) for r in rs]
        s = dict(root=root, group=group, item=item, mode=mode, n=len(rs),
                 wall_s=_med(walls), wall_min_s=min(walls), wall_max_s=max(walls),
                 cpu_s=_med([r["cpu_s"] for r in rs]),
                 first_call_s=_med([r.get("first_s") for r in rs]),
                 compiles=_med([sum(r["compiles"].values()) for r in rs]),
                 compile_cpu_s=_med([sum(p.values()) for p in parts]))
        for k in PART_NAMES:
            s[k] = _med([p[k] for p in parts])
        if rs[0].get("steps"):
            s["steps"] = [dict(name=st["name"],
                               first_s=_med([r["steps"][i]["first_s"] for r in rs]),
                               **{k: _med([r["steps"][i]["parts"][k] for r in rs])
                                  for k in PART_NAMES})
                          for i, st in enumerate(rs[0]["steps"])]
        out.append(s)
    return out


def per_function(rows, root, item):
    """Per compiled function of the first cold run of ``item``: CPU by part, compiles, size."""
    cold = [r for r in rows if r["root"] == root and r["item"] == item and r["mode"] == "cold"]
    if not cold:
        return []
    r = cold[0]
    fn = collections.defaultdict(lambda: collections.defaultdict(float))
    for cat, f, _w, u in r["by"]:
        fn[f][_part_of(cat)] += u
    out = []
    for f, parts in fn.items():
        out.append(dict(function=f, cpu_s=sum(parts.values()),
                        compiles=r["compiles"].get(f, 0), typed_vars=r["vars"].get(f, 0),
                        **{k: parts.get(k, 0.0) for k in PART_NAMES}))
    out.sort(key=lambda x: -x["cpu_s"])
    return out


def inlined_pieces(rows, root, item):
    cold = [r for r in rows if r["root"] == root and r["item"] == item and r["mode"] == "cold"]
    if not cold:
        return []
    return sorted(cold[0]["inlined"], key=lambda x: (-x[3], x[0]))


# =========================================================================== the report

def _span(s):
    return f"{s['wall_s']:.2f} [{s['wall_min_s']:.2f}-{s['wall_max_s']:.2f}]"


def markdown(b, args, rows, summary, spd, quick):
    roots = list(dict.fromkeys(s["root"] for s in summary)) or list(spd["times"] if spd else [])
    md = [f"### Cold start: compile time per kernel variant, stage and command"
          f"{H.quick_note(quick, 'one small function, no commands, no speed')}\n",
          H.env_line(b.env) + f" Load average at the start {b.env['load_start']}, at the end "
          f"{b.env['load_end']}.\n",
          "Cold = a fresh process on an empty `NUMBA_CACHE_DIR`; warm = a fresh process on the "
          f"cache the cold one wrote. Medians of {args.repeats} repeat(s) [min-max], wall time "
          "of the whole process; CPU = its user + system time. The stage columns split the "
          "cold process's compile CPU time (exclusive seconds: numba's event API and wrappers "
          "of its code library).\n"]
    if args.root_env:
        md.append("Roots run with an environment of their own (levers that are switches): "
                  + "; ".join(f"{rn}: " + " ".join(f"`{k}={v}`" for k, v in e.items())
                              for rn, e in args.root_env.items()) + ".\n")
    by = {(s["root"], s["item"], s["mode"]): s for s in summary}
    items = list(dict.fromkeys(s["item"] for s in summary))
    for group, title in (("kernel", "Kernel variants (first call of `kernel.compile_variant`, "
                                    "each on an empty cache)"),
                         ("command", "Commands, whole process")):
        its = [i for i in items if any(s["group"] == group and s["item"] == i for s in summary)]
        if not its:
            continue
        md.append(f"\n#### {title}\n")
        head = ["root", "item", "cold wall (s)", "warm wall (s)", "cold/warm", "cold CPU (s)",
                "warm CPU (s)", "functions compiled"] + PART_NAMES
        body = []
        for i in its:
            for rn in roots:
                c, w = by.get((rn, i, "cold")), by.get((rn, i, "warm"))
                if c is None or w is None:
                    continue
                body.append([rn, i, _span(c), _span(w), f"{c['wall_s'] / w['wall_s']:.1f}x",
                             f"{c['cpu_s']:.1f}", f"{w['cpu_s']:.1f}", f"{c['compiles']:.0f}"]
                            + [f"{c[k]:.2f}" for k in PART_NAMES])
        md.append(H.md_table(head, body))
    seqs = [s for s in summary if s["mode"] == "cold" and len(s.get("steps", ())) > 1]
    if seqs:
        md.append("\n#### Sequences in one process: the second kernel's first call after the "
                  "first's (cold)\n")
        md.append(H.md_table(["root", "sequence", "kernel", "first call (s)", "compile CPU (s)"]
                             + PART_NAMES,
                             [[s["root"], s["item"], st["name"], f"{st['first_s']:.2f}",
                               f"{sum(st[k] for k in PART_NAMES):.2f}"]
                              + [f"{st[k]:.2f}" for k in PART_NAMES]
                              for s in seqs for st in s["steps"]]))
    detail = DETAIL if DETAIL in items else (items[0] if items else None)
    if detail:
        for rn in roots:
            fr = per_function(rows, rn, detail)
            if not fr:
                continue
            md.append(f"\n#### Per compiled function: `{detail}`, root {rn} (first cold run, "
                      "CPU s, the top 15)\n")
            head = ["function", "CPU (s)", "signatures", "typed variables"] + PART_NAMES
            md.append(H.md_table(head, [[f["function"], f"{f['cpu_s']:.2f}", f["compiles"],
                                         f["typed_vars"]] + [f"{f[k]:.2f}" for k in PART_NAMES]
                                        for f in fr[:15]]))
            ip = inlined_pieces(rows, rn, detail)
            if ip:
                md.append(f"\nPieces inlined by numba (`inline=\"always\"`), root {rn}: copies "
                          "of the piece's IR and the IR statements they hold, per host (a piece "
                          "inlined into another piece is counted in both).\n")
                md.append(H.md_table(["piece", "into", "copies", "IR statements"], ip))
    if spd:
        st = spd["settings"]
        md.append("\n#### Warm speed (one process, roots interleaved)\n")
        md.append(f"Reference run hb=1, alpha=0.6, omega=1.3, {st['run_periods']} periods (ns "
                  f"per grid step, without and with exponents); basin hb=1, alpha=0.66, omega=1.3, "
                  f"{st['grid']} x {st['grid']}, and sweep hb=1, omega=1.3, alpha 0.5..1 step "
                  f"{st['alpha_step']:g} (s, {st['periods']} periods, threads="
                  f"{st['threads'] or 'all'}); medians of {st['repeats']} [min-max], ratio to "
                  "the first root; identical: every output array equal to the first root's "
                  "bit for bit.\n")
        first = next(iter(spd["times"]))
        head = ["root", "case", "median", "min-max", "ratio", "identical"]
        body = []
        for rn, t in spd["times"].items():
            for m, v in t.items():
                ref = statistics.median(spd["times"][first][m])
                same = "—" if rn == first else str(spd["identical"][rn][m])
                body.append([rn, m, f"{statistics.median(v):.4g}",
                             f"{min(v):.4g}-{max(v):.4g}", f"{statistics.median(v) / ref:.3f}",
                             same])
        md.append(H.md_table(head, body))
    return "\n".join(md) + "\n"


def install(roots, tmp):
    """Seconds to make a virtual environment and ``pip install -e`` each root into it."""
    out = {}
    for name, root in roots.items():
        venv = Path(tempfile.mkdtemp(prefix="venv-", dir=tmp))
        t0 = time.perf_counter()
        subprocess.run([sys.executable, "-m", "venv", str(venv)], check=True)
        subprocess.run([str(venv / "bin" / "python"), "-m", "pip", "install", "--quiet", "-e",
                        str(root)], check=True, capture_output=True)
        out[name] = time.perf_counter() - t0
        print(f"  {name:>10} install {out[name]:7.2f} s", flush=True)
        shutil.rmtree(venv, ignore_errors=True)
    return out


def goals(summary, inst):
    """The cold start's two goals for commands, per root, from the commands measured
    (Markdown): a cold ``rockjit trajectory`` at most 4x its warm time, and install plus a
    cold ``rockjit paper`` under 45 s."""
    by = {(s["root"], s["item"], s["mode"]): s["wall_s"] for s in summary}
    lines = []
    roots = list(dict.fromkeys(s["root"] for s in summary))
    warm0 = by.get((roots[0], "rockjit trajectory", "warm")) if roots else None
    for root in roots:
        cold, warm = by.get((root, "rockjit trajectory", "cold")), by.get(
            (root, "rockjit trajectory", "warm"))
        if cold and warm:
            ok = "reached" if cold <= 4 * warm else \
                f"out of reach: the cold run compiles for ~{cold - warm:.0f} s"
            if warm0 and warm > 1.25 * warm0:
                # a slower kernel shrinks the ratio without shortening the wait
                ok = (f"no gain: the ratio falls because the warm run takes "
                      f"{warm / warm0:.1f}x {roots[0]}'s")
            lines.append(f"| {root} | cold `rockjit trajectory` / warm | {cold:.1f} s / "
                         f"{warm:.2f} s = {cold / warm:.1f}x | <= 4x | {ok} |")
        paper = by.get((root, "rockjit paper", "cold"))
        if paper and root in inst:
            total = paper + inst[root]
            warm_paper = by.get((root, "rockjit paper", "warm"))
            ok = "reached" if total <= 45.0 else "out of reach" + (
                "" if warm_paper is None else
                f": the cold run compiles for ~{paper - warm_paper:.0f} s")
            lines.append(f"| {root} | install + cold `rockjit paper` | {inst[root]:.1f} s + "
                         f"{paper:.1f} s = {total:.1f} s | <= 45 s | {ok} |")
    if not lines:
        return ""
    return ("\n#### Cold-start goals\n\n| root | what | measured | goal | |\n"
            "|---|---|---|---|---|\n" + "\n".join(lines) + "\n")


def csv_rows(summary, spd):
    rows = [[s.get(c) for c in CSV_COLUMNS] for s in summary]
    if spd:
        for rn, t in spd["times"].items():
            for m, v in t.items():
                rows.append([rn, "speed", m, "warm", len(v), statistics.median(v), min(v),
                             max(v)] + [None] * (len(CSV_COLUMNS) - 8))
    return rows


def plot(summary):
    plt = H.pyplot()
    roots = list(dict.fromkeys(s["root"] for s in summary))
    by = {(s["root"], s["item"], s["mode"]): s for s in summary}
    items = list(dict.fromkeys(s["item"] for s in summary))
    its = [i for i in items if all((r, i, m) in by for r in roots for m in ("cold", "warm"))]
    fig, (ax, bx) = plt.subplots(1, 2, figsize=(14, 0.45 * max(len(its) * len(roots), 1) + 2.5))
    y = 0
    yt, yl = [], []
    colors = plt.rcParams["axes.prop_cycle"].by_key()["color"]
    for i in its:
        for k, rn in enumerate(roots):
            c, w = by[(rn, i, "cold")], by[(rn, i, "warm")]
            ax.barh(y, c["wall_s"], color=colors[k % len(colors)], alpha=0.45,
                    xerr=[[c["wall_s"] - c["wall_min_s"]], [c["wall_max_s"] - c["wall_s"]]])
            ax.barh(y, w["wall_s"], color=colors[k % len(colors)])
            left = 0.0
            for j, part in enumerate(PART_NAMES):
                bx.barh(y, c[part], left=left, color=plt.cm.tab10(j),
                        label=part if y == 0 else None)
                left += c[part]
            yt.append(y)
            yl.append(f"{i} [{rn}]" if len(roots) > 1 else i)
            y += 1
        y += 0.5
    for a in (ax, bx):
        a.set_yticks(yt)
        a.set_yticklabels(yl, fontsize=7)
        a.invert_yaxis()
    bx.set_yticklabels([])
    ax.set_xlabel("wall time (s): cold (light, min-max) and warm (dark)")
    bx.set_xlabel("cold: compile CPU time by stage (s)")
    if its:
        # beside the bars, never over them
        bx.legend(fontsize=7, loc="upper left", bbox_to_anchor=(1.01, 1.0), frameon=False)
    fig.suptitle("rockjit cold start: numba compilation per kernel variant and command")
    fig.tight_layout()
    return fig


def options(p):
    p.add_argument("--root", action="append", default=[], metavar="NAME=DIR",
                   help="a folder holding a rockjit package to measure (repeatable; default "
                        "this checkout)")
    p.add_argument("--env", action="append", default=[], metavar="NAME:VAR=VALUE",
                   help="an environment variable for the cold and warm processes of root NAME "
                        "(repeatable): a lever that is a switch, e.g. --root opt1=. --env "
                        "opt1:NUMBA_OPT=1 (the speed part ignores it)")
    p.add_argument("--parts", default="kernels,commands,install,speed",
                   help="comma-separated: kernels, commands, install, speed (default all; "
                        "--quick: one small function only)")
    p.add_argument("--all", action="store_true", help="every kernel variant, not only the "
                   "common ones (rockjit._engine.kernel.COMMON)")
    p.add_argument("--variants", default=None,
                   help="comma-separated kernel variants to measure (then no sequences)")
    p.add_argument("--commands", default=None,
                   help="comma-separated commands to measure (keys of COMMANDS, e.g. "
                        "'trajectory,compile')")
    p.add_argument("--repeats", type=int, default=1, help="cold/warm pairs per item and root")
    p.add_argument("--speed-repeats", type=int, default=None)
    p.add_argument("--speed-run-periods", type=int, default=None,
                   help="periods of the reference run timed per step (default 5000)")
    p.add_argument("--speed-periods", type=int, default=None,
                   help="periods of the basin and sweep (default 500)")
    p.add_argument("--speed-grid", type=int, default=None)
    p.add_argument("--speed-alpha-step", type=float, default=None)
    p.add_argument("--speed-cache", type=Path, default=None,
                   help="NUMBA_CACHE_DIR of the speed process (default a fresh one: it "
                        "compiles first, outside the timing)")
    p.add_argument("--threads", type=int, default=None,
                   help="numba threads of the basin and sweep speed cases (default all)")
    p.add_argument("--timeout", type=float, default=1800.0, help="seconds per process")
    p.add_argument("--name", default="compile",
                   help="the report's name: NAME.{md,csv,json,png} (default compile; the levers "
                        "page is compile_levers)")


def main(argv=None):
    argv = sys.argv[1:] if argv is None else argv
    if argv[:1] == ["--child"]:
        _child(json.loads(argv[1]))
        return 0
    b = H.Bench(__doc__, argv, options=options)
    args = b.args
    quick = b.quick
    args.parts = set(args.parts.split(","))
    roots = {}
    for r in args.root or [f"this={H.ROOT}"]:
        name, _, d = r.partition("=")
        d = Path(d).resolve()
        if not (d / "rockjit" / "__init__.py").is_file():
            raise SystemExit(f"--root {r}: no rockjit package in {d}")
        roots[name] = d
    args.root_env = {}
    for e in args.env:
        name, _, kv = e.partition(":")
        var, eq, value = kv.partition("=")
        if name not in roots or not var or not eq:
            raise SystemExit(f"--env {e}: NAME:VAR=VALUE with NAME one of the roots "
                             f"({', '.join(roots)})")
        args.root_env.setdefault(name, {})[var] = value
    b.env["load_start"] = H.load_text()
    with tempfile.TemporaryDirectory(prefix="bench-compile-") as tmp:
        rows = measure(args, roots, tmp, quick) if quick or args.parts & {"kernels",
                                                                          "commands"} else []
        spd = speed(args, roots, tmp) if "speed" in args.parts and not quick else None
        inst = install(roots, tmp) if "install" in args.parts and not quick else {}
    b.env["load_end"] = H.load_text()
    summary = summarise(rows)
    md = markdown(b, args, rows, summary, spd, quick) + goals(summary, inst)
    settings = {k: sorted(v) if isinstance(v, set) else v for k, v in vars(args).items()}
    b.report(args.name, markdown=md, csv=(CSV_COLUMNS, csv_rows(summary, spd)),
             data=dict(environment=b.env, settings=settings, roots=roots, summary=summary,
                       runs=rows, speed=spd, install_s=inst),
             figures=[(f"{args.name}.png", plot(summary), 120)])
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
