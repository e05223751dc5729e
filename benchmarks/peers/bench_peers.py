"""rockjit side by side with the compiled peers a user would pick instead.

Peers (``benchmarks/peers/peer_*.py``, described in benchmarks/README.md): diffrax (JAX),
SUNDIALS CVODE through scikit-sundae, numbakit-ode (nbkode) inside a numba impact loop; and the
best scipy method of ``bench_work_precision.py`` (DOP853) through rockjit's scipy path.

1. **Checked before timed.** The study's reference run (hb=1, Housner, alpha=0.6, omega=1.3,
   z0 = Z0_STUDY, 500 periods): each peer at tight tolerances against rockjit at N = 8192
   (impact count, impact times, final state, label). The hb=1 Housner basin (alpha=0.66,
   omega=1.3, (r0, s0) = (0, 1), 500 periods, rockjit's classification): labels against
   ``rockjit.basin(...).label`` on a ``--basin-sub`` x ``--basin-sub`` subgrid of the
   100 x 100 lattice (every peer), and on the whole lattice for peers whose estimated time is
   under ``--full-basin-cap`` seconds.
2. **Work–precision** on bench_work_precision.py's periodic and chaotic scenes (same
   parameters, same error: the final (theta, theta') against rockjit at N = 8192; a run with
   another status or impact count is flagged, not counted): rockjit at N = 16..1024, each peer
   method at rtol = 1e-3..1e-12 (atol = 1e-3 rtol), scipy DOP853 likewise. Warm wall times are
   medians of interleaved repeats (every case of a scene in each round, the order rotated; a
   case under 10 ms after two untimed calls of its own, so that it is not timed with the caches
   the case before emptied);
   compile times (first call in this process minus the warm median) are reported apart.
3. **Basin at equal label accuracy**: for each peer the loosest rtol in a ladder whose labels
   agree with rockjit's in >= 99.5 % of the subgrid's cells, and its time; the time for the
   100 x 100 grid measured (full grid run) or estimated (subgrid time x cells ratio, marked).

    python benchmarks/peers/bench_peers.py            # full (~30 min on a quiet 2-core machine)
    python benchmarks/peers/bench_peers.py --quick    # smoke (~4 min: fewer tolerances, 10 x 10
                                                      # subgrid, 100-period basin)

Writes peers.{md,csv,json}, peers_wp_periodic.png, peers_wp_chaotic.png and peers_basin.png to
benchmarks/results/ (benchmarks/results/quick/ with --quick, or --out DIR). Needs the optional
extra: ``pip install -e ".[peers]"``; a peer that does not import is reported and skipped.
"""

from __future__ import annotations

import importlib
import math
import os
import statistics
import sys
import time
import warnings
from pathlib import Path

import numpy as np

HERE = Path(__file__).resolve().parent
sys.path.insert(0, str(HERE))
warnings.filterwarnings("ignore", category=Warning, module="numba")
warnings.filterwarnings("ignore", message=".*First-class function type.*")

import common as C  # noqa: E402

sys.path.insert(0, str(HERE.parent))
import _common as H  # noqa: E402

import rockjit  # noqa: E402
from rockjit import (BEHAVIOURS, Block, Classification, Harmonic, Integration,  # noqa: E402
                     Scipy)

N_REF = 8192
NS = (16, 32, 64, 128, 256, 512, 1024)
RTOLS = tuple(10.0 ** -k for k in range(3, 13))
ATOL_RATIO = 1e-3
TARGETS = tuple(10.0 ** -k for k in range(4, 11))
AGREE = 99.5
#: Methods timed per peer in the work–precision diagram; the first is the peer's basin method.
PEER_METHODS = {"nbkode": ("RK45", "DOP853"), "diffrax": ("Tsit5", "Dopri8"),
                "cvode": ("Adams",)}
#: Tight settings of the reference-run check, per peer: (method, rtol, atol).
TIGHT = {"nbkode": ("DOP853", 1e-12, 1e-15), "diffrax": ("Dopri8", 1e-12, 1e-15),
         "cvode": ("Adams", 1e-12, 1e-15)}
BASIN_LADDER = (1e-3, 1e-4, 1e-5, 1e-6, 1e-8)
#: Peers whose basin ladder runs on the coarser subgrid ``--basin-sub-slow`` (CVODE calls a
#: Python right-hand side: ~0.6 s per settled cell over 500 periods).
SLOW_BASIN = ("cvode",)


# ----------------------------------------------------------------------------- helpers

timed = H.timed
fmt = H.fmt
md_table = H.md_table


def rj_call(kw, periods, n_steps=None, method="rockjit"):
    """A call of rockjit's run of ``kw`` (``hb``, ``alpha``, ``omega``): Housner restitution,
    from the study's initial state, over ``periods``, at ``n_steps`` or through ``method``.
    The block, excitation and settings are made once, as each peer's problem is: the call is
    what a user repeats."""
    block = Block(hb=kw["hb"], law="housner")
    forcing = Harmonic(alpha=kw["alpha"], omega=kw["omega"])
    integration = Integration(periods=periods, n_steps=n_steps)
    return lambda: rockjit.simulate(block, forcing, integration=integration, method=method)


def rj_run(kw, periods, n_steps=None, method="rockjit"):
    """rockjit's run (:func:`rj_call`), once."""
    return rj_call(kw, periods, n_steps, method)()


#: A case faster than this is timed after untimed calls of its own (:data:`WARMUPS`): a
#: run of microseconds right after another library's (JAX, SUNDIALS) would be timed with the
#: caches that library emptied, two to three times its time in a loop of such runs (measured
#: for rockjit's and nbkode's); every method, rockjit's and the peers', is treated alike.
FAST_CASE_S = 0.01
WARMUPS = 2


def interleaved(cases, repeats, counts=None, probe=None):
    """``{key: [seconds]}``: the harness's :func:`_common.side_by_side` wall times, the cases
    faster than :data:`FAST_CASE_S` in ``probe`` (seconds by key) timed after warm-up calls."""
    warm = {k: WARMUPS for k, t in (probe or {}).items() if t < FAST_CASE_S}
    return H.side_by_side(cases, repeats, counts=counts, warmups=warm).wall


def peer_versions():
    """``{distribution: version or None}`` of the peers' packages."""
    from importlib.metadata import PackageNotFoundError, version
    vers = {}
    for dist in ("jax", "diffrax", "scikit-sundae", "numbakit-ode"):
        try:
            vers[dist] = version(dist)
        except PackageNotFoundError:
            vers[dist] = None
    return vers


def env_line(env):
    peers = ", ".join(f"{k} {v}" for k, v in env["peers"].items() if v)
    return H.env_line(env).rstrip(".") + f"; peers: {peers}."


def load_peers(names):
    """Import each peer module; ``{name: module}`` and ``{name: why not}``."""
    got, missing = {}, {}
    for name in names:
        try:
            got[name] = importlib.import_module(f"peer_{name}")
        except Exception as exc:  # noqa: BLE001 - reported in the results
            missing[name] = f"{type(exc).__name__}: {exc}"
    return got, missing


# ----------------------------------------------------------------------------- checks

def reference_check(peers, periods):
    """Each peer at tight settings against rockjit N = 8192 on the study's reference run."""
    z = rockjit.Z0_STUDY
    kw = dict(hb=C.REFERENCE["hb"], alpha=C.REFERENCE["alpha"], omega=C.REFERENCE["omega"])
    ref = rj_run(kw, periods, N_REF)
    p = C.params(**kw)
    rows = []
    for name, mod in peers.items():
        method, rtol, atol = TIGHT[name]
        first, _ = timed(lambda: mod.run(p, z[0], z[1], periods, rtol, atol, method=method))
        wall, r = timed(lambda: mod.run(p, z[0], z[1], periods, rtol, atol, method=method))
        same = r.n_impacts == ref.n_impacts and r.status == ref.status
        dt = float(np.max(np.abs(r.impacts - ref.impacts[:, 0]))) if same else math.nan
        err = float(np.max(np.abs(r.state - ref.state[:2]))) if r.status == ref.status \
            else math.nan
        rows.append(dict(peer=name, method=method, rtol=rtol, atol=atol, status=r.status,
                         n_impacts=r.n_impacts, ref_n_impacts=ref.n_impacts,
                         ref_status=ref.status,
                         impact_time_error=dt, final_state_error=err, label=C.label(r, periods),
                         ref_label=rockjit.classify_result(ref)[0], wall_s=wall,
                         first_call_s=first))
        print(f"[reference] {name} {method} rtol={rtol:g}: {r.status}, {r.n_impacts} impacts "
              f"(rockjit {ref.n_impacts}), impact times {fmt(dt)}, final state {fmt(err)}, "
              f"{rows[-1]['label']}", flush=True)
    return rows, dict(status=ref.status, n_impacts=ref.n_impacts, t=ref.t)


def scene_runs(peers, name, scene, quick, repeats):
    """Work–precision of one scene: rows of (method, setting, wall, error, flag)."""
    kw = dict(hb=scene["hb"], alpha=scene["alpha"], omega=scene["omega"])
    periods = scene["periods"]
    z = rockjit.Z0_STUDY
    ref = rj_run(kw, periods, N_REF)
    half = rj_run(kw, periods, N_REF // 2)
    floor = float(np.max(np.abs(half.state[:2] - ref.state[:2])))
    if not quick:
        d = rj_run(kw, periods, method=Scipy("DOP853", rtol=1e-13, atol=1e-15))
        floor = max(floor, float(np.max(np.abs(d.state[:2] - ref.state[:2]))))
    p = C.params(**kw)
    ns = (16, 64, 256) if quick else NS
    rtols = (1e-4, 1e-7, 1e-10) if quick else RTOLS
    cases, meta, results, compile_s = {}, {}, {}, {}

    def keep(key, fn):
        def call():
            results[key] = fn()
        return call

    for n in ns:
        key = ("rockjit", "", f"N={n}")
        cases[key] = keep(key, rj_call(kw, periods, n))
        meta[key] = dict(method="rockjit", setting=f"N={n}", n=n, rtol=None)
    for pname, mod in peers.items():
        for m in PEER_METHODS[pname]:
            first = None
            for rtol in rtols:
                key = (pname, m, f"rtol={rtol:.0e}")
                fn = (lambda mod=mod, m=m, rtol=rtol:
                      mod.run(p, z[0], z[1], periods, rtol, ATOL_RATIO * rtol, method=m))
                if first is None:   # compile (or load) apart
                    first = timed(fn)[0]
                    compile_s[(pname, m)] = first
                cases[key] = keep(key, fn)
                meta[key] = dict(method=f"{pname} {m}", setting=f"rtol={rtol:.0e}", n=None,
                                 rtol=rtol)
    for rtol in rtols:
        key = ("scipy", "DOP853", f"rtol={rtol:.0e}")
        cases[key] = keep(key, rj_call(kw, periods, method=Scipy("DOP853", rtol=rtol,
                                                                   atol=ATOL_RATIO * rtol)))
        meta[key] = dict(method="scipy DOP853", setting=f"rtol={rtol:.0e}", n=None, rtol=rtol)
    # one untimed call of each case; slow ones (> 50 ms) run in fewer rounds
    probe = {k: timed(fn)[0] for k, fn in cases.items()}
    slow = {k: max(2, repeats // 3) for k, t in probe.items() if t > 0.05}
    times = interleaved(cases, repeats, counts=slow, probe=probe)
    rows = []
    for key in cases:
        r = results[key]
        status, n_imp = r.status, r.n_impacts
        flag = ""
        if status != ref.status:
            flag = f"status {status}"
        elif n_imp != ref.n_impacts:
            flag = f"{n_imp} impacts (ref {ref.n_impacts})"
        state = np.asarray(r.state[:2], dtype=float)
        err = float(np.max(np.abs(state - ref.state[:2]))) if status == ref.status \
            else math.nan
        rows.append(dict(scene=name, **meta[key], wall_s=statistics.median(times[key]),
                         wall_all_s=times[key], error=err, flag=flag, status=status,
                         n_impacts=n_imp))
    for (pname, m), first in compile_s.items():
        warm = min(r["wall_s"] for r in rows if r["method"] == f"{pname} {m}")
        compile_s[(pname, m)] = max(first - warm, 0.0)
    print(f"[{name}] {len(rows)} cases, {repeats} rounds; floor {fmt(floor)}", flush=True)
    return dict(name=name, title=scene["title"], rows=rows, floor=floor,
                compile={f"{a} {b}": v for (a, b), v in compile_s.items()},
                ref=dict(status=ref.status, n_impacts=ref.n_impacts, t=ref.t))


def call_floor(peers, n=41):
    """The fixed cost of one call: a one-period run of the chaotic scene's block at the
    loosest settings, median of ``n``; for rockjit also its parts: validating the inputs
    (``rockjit.simulate.plan``), running a plan from scratch (``rockjit.single.run``: packing,
    the kernel's look-up, the run) and calling a prepared run (``rockjit.simulate.prepare``,
    which ``rockjit.simulate`` calls underneath when a block and its settings come again)."""
    sim = importlib.import_module("rockjit.single")
    sc = C.SCENES["chaotic"]
    kw = dict(hb=sc["hb"], alpha=sc["alpha"], omega=sc["omega"])
    z = rockjit.Z0_STUDY
    p = C.params(**kw)
    block, forcing = Block(hb=kw["hb"], law="housner"), Harmonic(alpha=kw["alpha"],
                                                                 omega=kw["omega"])
    one = Integration(periods=1, n_steps=8)
    plan = rockjit.simulate.plan(block, forcing, integration=one)
    cases = {"rockjit simulate": lambda: rockjit.simulate(block, forcing, integration=one),
             "rockjit plan (validation)": lambda: rockjit.simulate.plan(block, forcing,
                                                                        integration=one),
             "rockjit run(plan)": lambda: sim.run(plan),
             "rockjit prepared run": rockjit.simulate.prepare(block, forcing, integration=one)}
    for name, mod in peers.items():
        m = PEER_METHODS[name][0]
        cases[f"{name} {m}"] = (lambda mod=mod, m=m:
                                mod.run(p, z[0], z[1], 1, 1e-3, 1e-6, method=m))
    for fn in cases.values():   # a first call compiles (nbkode) or traces (JAX): apart
        fn()
    probe = {k: timed(fn)[0] for k, fn in cases.items()}
    times = interleaved(cases, n, probe=probe)
    return {k: statistics.median(v) for k, v in times.items()}


def cheapest(rows, target):
    ok = [r for r in rows if not r["flag"] and r["error"] <= target]
    return min(ok, key=lambda r: r["wall_s"]) if ok else None


# ----------------------------------------------------------------------------- basin

def subgrid_index(sub, grid=100):
    return np.unique(np.round(np.linspace(0, grid - 1, sub)).astype(int))


def basin_part(peers, quick, sub, sub_slow, full_cap, repeats):
    """Labels at equal accuracy: ladder on the subgrid, then the whole grid if affordable."""
    b = C.BASIN
    periods = 100 if quick else b["periods"]
    block = Block(hb=b["hb"], law="housner")
    forcing = Harmonic(alpha=b["alpha"], omega=b["omega"], r0=b["r0"], s0=b["s0"])
    length = Integration(periods=periods)

    def rj_basin(integration=length, early_stop=True):
        return rockjit.basin(block, forcing, b["grid"], integration=integration,
                             classification=Classification(early_stop=early_stop))

    first, ref = timed(rj_basin)
    t_rj = interleaved({"early": rj_basin}, repeats)["early"]
    full_n = 1 if quick else 3
    t_rj_full = [timed(lambda: rj_basin(early_stop=False))[0] for _ in range(full_n)]
    ref_full = rj_basin(early_stop=False)
    ref256 = rj_basin(integration=length.replace(n_steps=256))
    rj = dict(wall_s=statistics.median(t_rj), wall_all_s=t_rj, first_call_s=first,
              full_length_wall_s=statistics.median(t_rj_full),
              agree_full_length=100.0 * float(np.mean(ref_full.label == ref.label)),
              agree_n256=100.0 * float(np.mean(ref256.label == ref.label)),
              fractions=ref.fractions(), periods=periods)
    print(f"[basin] rockjit {fmt(rj['wall_s'])} s (full length {fmt(rj['full_length_wall_s'])}"
          f" s); fractions {ref.fractions()}", flush=True)
    th, dth = C.basin_axes(b["grid"])
    p = C.params(b["hb"], b["alpha"], b["omega"], r0=b["r0"], s0=b["s0"])
    out = {}

    def warm(mod, m, n):
        # compile (or load) on an n x n lattice of cells that overturn at once, so that the
        # timed runs are warm (JAX compiles once per batch size)
        return timed(lambda: mod.basin(p, np.full(n, 1.4), np.full(n, 1.0), periods, 1e-3,
                                       1e-6, method=m))[0]

    for name, mod in peers.items():
        m = PEER_METHODS[name][0]
        idx = subgrid_index(sub_slow if name in SLOW_BASIN else sub, b["grid"])
        ref_sub = ref.label[np.ix_(idx, idx)]
        ladder = []
        tc = warm(mod, m, len(idx))
        chosen = None
        for rtol in BASIN_LADDER:
            w, lab = timed(lambda: mod.basin(p, th[idx], dth[idx], periods, rtol,
                                             ATOL_RATIO * rtol, method=m))
            agree = 100.0 * float(np.mean(lab == ref_sub))
            diff = [(float(th[idx[i]]), float(dth[idx[j]]), BEHAVIOURS[lab[i, j]],
                     BEHAVIOURS[ref_sub[i, j]]) for i, j in np.argwhere(lab != ref_sub)]
            ladder.append(dict(rtol=rtol, wall_s=w, agree=agree, n_diff=len(diff),
                               differing=diff[:20]))
            print(f"[basin] {name} {m} rtol={rtol:g} on {len(idx)}^2: {fmt(w)} s, agree "
                  f"{agree:.2f} %", flush=True)
            if agree >= AGREE:
                chosen = ladder[-1]
                break
        rec = dict(method=m, sub=len(idx), ladder=ladder, first_call_s=tc,
                   chosen=None if chosen is None else chosen["rtol"])
        if chosen is not None:
            est = chosen["wall_s"] * (b["grid"] ** 2) / (len(idx) ** 2)
            rec["estimate_full_s"] = est
            if est <= full_cap and len(idx) < b["grid"]:
                warm(mod, m, b["grid"])
                w, lab = timed(lambda: mod.basin(p, th, dth, periods, chosen["rtol"],
                                                 ATOL_RATIO * chosen["rtol"], method=m))
                rec["full"] = dict(wall_s=w, agree=100.0 * float(np.mean(lab == ref.label)),
                                   n_diff=int(np.count_nonzero(lab != ref.label)))
                print(f"[basin] {name} full grid: {fmt(w)} s, agree {rec['full']['agree']:.2f}"
                      " %", flush=True)
            elif len(idx) == b["grid"]:
                rec["full"] = dict(wall_s=chosen["wall_s"], agree=chosen["agree"],
                                   n_diff=chosen["n_diff"])
        out[name] = rec
    return rj, out, periods


# ----------------------------------------------------------------------------- output

#: A peer reproduces the reference run when it ends with rockjit's status and impact count and
#: every impact time is within this of rockjit's at N = 8192 (the peers run it at rtol 1e-12).
IMPACT_TIME_TOL = 1e-8


def correctness(ref_rows, basin):
    """``{peer: dict(reference=bool, basin=bool or None, why=str)}``: the checks made before
    any time is read (the model of docs/theory reproduced: the reference run's impact times, the
    basin's labels at >= 99.5 % agreement), with the reason where one fails."""
    out = {}
    for r in ref_rows:
        ok = (r["status"] == r["ref_status"] and r["n_impacts"] == r["ref_n_impacts"]
              and r["impact_time_error"] <= IMPACT_TIME_TOL)
        why = "" if ok else (
            f"reference run: {r['status']} with {r['n_impacts']} impacts against rockjit's "
            f"{r['ref_status']} with {r['ref_n_impacts']}; max impact-time error "
            f"{fmt(r['impact_time_error'])}")
        out[r["peer"]] = dict(reference=bool(ok), basin=None, why=why)
    if basin is not None:
        for name, rec in basin[1].items():
            best = max(rec["ladder"], key=lambda st: st["agree"])
            ok = best["agree"] >= AGREE
            full = rec.get("full")
            if full is not None:
                ok = ok and full["agree"] >= AGREE
            out.setdefault(name, dict(reference=None, why=""))["basin"] = bool(ok)
            if not ok:
                cells = "; ".join(f"({a:.3f}, {b_:.3f}) {got} vs rockjit {want}"
                                  for a, b_, got, want in best["differing"][:5])
                out[name]["why"] += (" " if out[name]["why"] else "") + (
                    f"basin: best agreement {best['agree']:.2f} % (rtol {best['rtol']:.0e}) on "
                    f"the {rec['sub']}x{rec['sub']} subgrid; differing cells "
                    f"(theta0, theta0') peer vs rockjit: {cells}")
    return out



def plot_wp(s):
    """The work–precision figure of one scene."""
    plt = H.pyplot()
    fig, ax = plt.subplots(figsize=(8.4, 4.8), layout="constrained")
    methods = list(dict.fromkeys(r["method"] for r in s["rows"]))
    marks = "osD^vP*Xh"
    for i, m in enumerate(methods):
        rows = [r for r in s["rows"] if r["method"] == m and math.isfinite(r["error"])]
        good = [r for r in rows if not r["flag"]]
        bad = [r for r in rows if r["flag"]]
        col = f"C{i}"
        if good:
            ax.plot([r["wall_s"] for r in good], [max(r["error"], 1e-17) for r in good],
                    marker=marks[i % len(marks)], color=col, ms=4,
                    lw=1.6 if m == "rockjit" else 0.9, label=m)
        if bad:
            ax.plot([r["wall_s"] for r in bad], [max(r["error"], 1e-17) for r in bad],
                    ls="none", marker="x", color=col, ms=7)
    ax.axhline(s["floor"], color="0.5", ls="--", lw=0.8, label="reference floor")
    ax.axhspan(1e-10, 1e-4, color="0.9", zorder=-1)
    ax.plot([], [], "kx", ls="none", label="other status / impact count")
    ax.set_xscale("log")
    ax.set_yscale("log")
    ax.set_xlabel("warm wall time per run, median (s)")
    ax.set_ylabel("final-state error max|d(theta, theta')|")
    ax.set_title(s["title"] + " (shaded: the goal's 1e-4..1e-10)", fontsize=8)
    ax.grid(True, which="both", alpha=0.25)
    ax.legend(fontsize=7, loc="upper left", bbox_to_anchor=(1.01, 1.0))  # off the curves
    return fig


def plot_basin(rj, basins):
    """Bars: the 100 x 100 basin's time at equal label accuracy, rockjit and each peer."""
    plt = H.pyplot()
    names = ["rockjit", "rockjit full length"]
    vals = [rj["wall_s"], rj["full_length_wall_s"]]
    hatch = ["", ""]
    for name, rec in basins.items():
        if rec.get("chosen") is None:
            continue
        names.append(f"{name} {rec['method']}\nrtol {rec['chosen']:.0e}")
        if "full" in rec:
            vals.append(rec["full"]["wall_s"])
            hatch.append("")
        else:
            vals.append(rec["estimate_full_s"])
            hatch.append("//")
    fig, ax = plt.subplots(figsize=(6.4, 3.8), layout="constrained")
    bars = ax.bar(range(len(vals)), vals, color=[f"C{i}" for i in range(len(vals))])
    for bar, h in zip(bars, hatch):
        bar.set_hatch(h)
    ax.set_yscale("log")
    ax.set_xticks(range(len(vals)), names, fontsize=7)
    ax.set_ylabel("wall time, 100 x 100 basin (s)")
    ax.set_title("hb=1 Housner basin at >= 99.5 % label agreement with rockjit\n"
                 "(hatched: estimated from the subgrid)", fontsize=8)
    for i, v in enumerate(vals):
        ax.text(i, v, fmt(v), ha="center", va="bottom", fontsize=7)
    return fig


def options(ap):
    """The script's own options, after the harness's ``--quick`` and ``--out``."""
    ap.add_argument("--peers", nargs="*", default=list(PEER_METHODS),
                    help="peers to run (default all)")
    ap.add_argument("--repeats", type=int, default=None,
                    help="interleaved rounds of the work–precision timings (default 21; 3 quick)")
    ap.add_argument("--basin-sub", type=int, default=None,
                    help="side of the basin subgrid every peer runs (default 30; 10 quick; "
                         "100 = the whole lattice)")
    ap.add_argument("--basin-sub-slow", type=int, default=None,
                    help="subgrid side for the slow peers (CVODE; default 15; 6 quick)")
    ap.add_argument("--full-basin-cap", type=float, default=None,
                    help="run a peer's whole 100 x 100 basin when its subgrid estimate is "
                         "below this many seconds (default 600; 0 quick)")
    ap.add_argument("--skip-basin", action="store_true", help="leave the basin part out")


def main(argv=None):
    b = H.Bench(__doc__, argv, options=options)
    args, quick = b.args, b.quick
    repeats = args.repeats or (3 if quick else 21)
    sub = args.basin_sub or (10 if quick else 30)
    sub_slow = args.basin_sub_slow or (6 if quick else 15)
    cap = args.full_basin_cap if args.full_basin_cap is not None else (0.0 if quick else 600.0)
    env = dict(b.env, peers=peer_versions())
    load0 = H.loadavg()
    print("peers: " + ", ".join(f"{k} {v}" for k, v in env["peers"].items()), flush=True)
    t_start = time.perf_counter()
    peers, missing = load_peers(args.peers)
    for k, v in missing.items():
        print(f"peer {k} not available: {v}", flush=True)
    t_first_rj, _ = timed(lambda: rj_run(dict(hb=1.0, alpha=0.6, omega=1.3), 2))

    floor_calls = call_floor(peers)
    ref_rows, ref_info = reference_check(peers, 100 if quick else C.REFERENCE["periods"])
    scenes = {name: scene_runs(peers, name, sc, quick, repeats)
              for name, sc in C.SCENES.items()}
    basin = None
    if not args.skip_basin:
        basin = basin_part(peers, quick, sub, sub_slow, cap, 3 if quick else 7)
    checks = correctness(ref_rows, basin)
    load1 = H.loadavg()
    total = time.perf_counter() - t_start

    # ---- tables
    md = [f"### rockjit and its peers{' (QUICK MODE)' if quick else ''}\n\n"]
    if missing:
        md.append("Not available here: " + "; ".join(f"{k} ({v})" for k, v in missing.items())
                  + "\n\n")
    md.append(f"**Checked: the study's reference run** ({ref_info['n_impacts']} impacts over "
              f"{100 if quick else 500} periods, rockjit N = {N_REF} as the reference):\n\n")
    md.append(md_table(["peer", "method", "rtol / atol", "status", "impacts (rockjit)",
                        "max impact-time error", "final-state error", "label (rockjit)",
                        "first call (s)", "warm (s)"],
                       [[r["peer"], r["method"], f"{r['rtol']:.0e} / {r['atol']:.0e}",
                         r["status"], f"{r['n_impacts']} ({r['ref_n_impacts']})",
                         r["impact_time_error"], r["final_state_error"],
                         f"{r['label']} ({r['ref_label']})", r["first_call_s"], r["wall_s"]]
                        for r in ref_rows]))
    md.append("\n**Checks before timing** (reference run: rockjit's status and impact count, "
              f"impact times within {IMPACT_TIME_TOL:.0e}; basin: >= {AGREE} % of cells "
              "labelled as rockjit labels them):\n\n")
    md.append(md_table(["peer", "reference run", "basin labels", "where and why not"],
                       [[name, "—" if c["reference"] is None else
                         ("pass" if c["reference"] else "**FAIL**"),
                         "—" if c["basin"] is None else ("pass" if c["basin"] else "**FAIL**"),
                         c["why"] or "—"] for name, c in checks.items()]))
    wp_rows = []
    for target in TARGETS:
        for s in scenes.values():
            fam = list(dict.fromkeys(r["method"] for r in s["rows"]))
            best = {m: cheapest([r for r in s["rows"] if r["method"] == m], target)
                    for m in fam}
            rj = best.get("rockjit")
            peer_best = [(m, b) for m, b in best.items()
                         if m != "rockjit" and not m.startswith("scipy") and b is not None]
            fastest = min(peer_best, key=lambda mb: mb[1]["wall_s"]) if peer_best else None
            sp = best.get("scipy DOP853")
            wp_rows.append(dict(
                target=target, scene=s["name"], below_floor=target < s["floor"],
                rockjit=None if rj is None else (rj["wall_s"], rj["setting"]),
                fastest_peer=None if fastest is None else (fastest[0], fastest[1]["wall_s"],
                                                           fastest[1]["setting"]),
                scipy=None if sp is None else (sp["wall_s"], sp["setting"]),
                ratio=(fastest[1]["wall_s"] / rj["wall_s"]) if (rj and fastest) else math.nan,
                ratio_scipy=(sp["wall_s"] / rj["wall_s"]) if (rj and sp) else math.nan,
                per_method={m: None if b is None else (b["wall_s"], b["setting"])
                            for m, b in best.items()}))
    md.append("\n**Work–precision**: the cheapest run reaching each error (median warm wall "
              "time, its setting) and the fastest peer's time over rockjit's:\n\n")
    rows = []
    for w in wp_rows:
        rows.append([f"{w['target']:.0e}", w["scene"],
                     "—" if w["rockjit"] is None else f"{fmt(w['rockjit'][0])} s "
                     f"({w['rockjit'][1]})",
                     "—" if w["fastest_peer"] is None else f"{w['fastest_peer'][0]}: "
                     f"{fmt(w['fastest_peer'][1])} s ({w['fastest_peer'][2]})",
                     w["ratio"],
                     "—" if w["scipy"] is None else f"{fmt(w['scipy'][0])} s ({w['scipy'][1]})",
                     w["ratio_scipy"],
                     "—" if math.isnan(w["ratio"]) else
                     ("yes" if w["ratio"] >= 10 else "**no**")])
    md.append(md_table(["target", "scene", "rockjit", "fastest peer", "peer / rockjit",
                        "scipy DOP853", "DOP853 / rockjit", ">= 10x"], rows))
    md.append("\nEvery method's cheapest run per target (wall s, setting):\n\n")
    fams = list(dict.fromkeys(r["method"] for s in scenes.values() for r in s["rows"]))
    rows = []
    for w in wp_rows:
        rows.append([f"{w['target']:.0e}", w["scene"]] +
                    ["—" if w["per_method"].get(m) is None else
                     f"{fmt(w['per_method'][m][0])} ({w['per_method'][m][1]})" for m in fams])
    md.append(md_table(["target", "scene", *fams], rows))
    md.append("\nCompile time (first call in this process minus the warm median; per scene, "
              "since nbkode freezes the block's constants into its right-hand side and JAX "
              "compiles per number of periods):\n\n")
    crow = [[s["name"], *[s["compile"].get(f"{p} {m}") for p in peers for m in PEER_METHODS[p]]]
            for s in scenes.values()]
    md.append(md_table(["scene", *[f"{p} {m}" for p in peers for m in PEER_METHODS[p]]], crow))
    md.append(f"\nrockjit: first call in this process {fmt(t_first_rj)} s (its kernels load "
              "from numba's cache).\n")
    md.append("\nFixed cost of a call (one period of the chaotic scene's block at the loosest "
              f"settings, median of 41 interleaved calls, each after {WARMUPS} untimed ones): "
              + "; ".join(f"{k} {fmt(1e6 * v)} µs" for k, v in floor_calls.items()) + ".\n")
    md.append("\nEvery run (error, median wall s; flags in brackets):\n")
    for s in scenes.values():
        md.append(f"\n*{s['title']}* (reference: rockjit N = {N_REF}, {s['ref']['n_impacts']} "
                  f"impacts; floor {fmt(s['floor'])})\n\n")
        md.append(md_table(["method", "setting", "error", "wall (s)", "runs", "flag"],
                           [[r["method"], r["setting"], r["error"], r["wall_s"],
                             len(r["wall_all_s"]), r["flag"]] for r in s["rows"]]))
    if basin is not None:
        rj, basins, bper = basin
        md.append(f"\n**Basin**: hb=1 Housner, alpha=0.66, omega=1.3, (r0, s0) = (0, 1), "
                  f"100 x 100 over [-1, 1]^2, {bper} periods. rockjit (early stop, all "
                  f"threads): {fmt(rj['wall_s'])} s (median of {len(rj['wall_all_s'])}); "
                  f"full length {fmt(rj['full_length_wall_s'])} s; labels equal to full "
                  f"length in {rj['agree_full_length']:.2f} %, to N = 256 in "
                  f"{rj['agree_n256']:.2f} % of cells. Peers: the ladder rtol = "
                  f"{', '.join(f'{r:.0e}' for r in BASIN_LADDER)} (atol = 1e-3 rtol) on the "
                  "subgrid, stopping at the first with >= 99.5 % agreement:\n\n")
        rows = []
        for name, rec in basins.items():
            for step in rec["ladder"]:
                rows.append([name, rec["method"], f"{step['rtol']:.0e}",
                             f"{rec['sub']}x{rec['sub']}", step["wall_s"], step["agree"],
                             step["n_diff"]])
        md.append(md_table(["peer", "method", "rtol", "cells", "wall (s)", "agree (%)",
                            "cells differing"], rows))
        md.append("\nAt equal label accuracy (>= 99.5 %), the 100 x 100 basin:\n\n")
        rows = [["rockjit", "N = 64, early stop", rj["wall_s"], "measured", 100.0, 1.0],
                ["rockjit", "N = 64, full length", rj["full_length_wall_s"], "measured",
                 rj["agree_full_length"], rj["full_length_wall_s"] / rj["wall_s"]]]
        for name, rec in basins.items():
            if rec["chosen"] is None:
                rows.append([name, rec["method"], None, "no rtol of the ladder reached 99.5 %",
                             None, None])
                continue
            if "full" in rec:
                w, how, ag = rec["full"]["wall_s"], "measured", rec["full"]["agree"]
            else:
                w, how = rec["estimate_full_s"], f"estimated ({rec['sub']}^2 subgrid x " \
                    f"{100 ** 2 / rec['sub'] ** 2:.3g})"
                ag = rec["ladder"][-1]["agree"]
            rows.append([name, f"{rec['method']} rtol {rec['chosen']:.0e}", w, how, ag,
                         w / rj["wall_s"]])
        md.append(md_table(["", "setting", "wall (s)", "how", "agree (%)",
                            "time / rockjit"], rows))
        md.append("\nFirst calls (compile or load): " + "; ".join(
            f"{n} {fmt(r['first_call_s'])} s" for n, r in basins.items()) +
            f"; rockjit {fmt(rj['first_call_s'])} s.\n")
    md.append(f"\nAll threads everywhere: rockjit and nbkode use numba's {os.cpu_count()} "
              "threads, CVODE a pool of as many processes for the basin, JAX its own CPU "
              "threads. Work–precision: medians of "
              f"{repeats} interleaved rounds (cases slower than 50 ms in a third of them, at "
              f"least 2; cases faster than {FAST_CASE_S * 1e3:.0f} ms timed after {WARMUPS} "
              "untimed calls of their own, as in a loop of them: right after a run of another "
              "library they take two to three times as long, whichever the method). The "
              "machine is shared: 1/5/15-min load average "
              f"{' / '.join(f'{x:.2f}' for x in load0)} at the start, "
              f"{' / '.join(f'{x:.2f}' for x in load1)} at the end; {total / 60:.1f} min in "
              "all.\n")
    md.append(f"\n{env_line(env)}\n")
    md = "".join(md)
    csv_rows = [[s["name"], r["method"], r["setting"], r["wall_s"], r["error"], r["status"],
                 r["n_impacts"], r["flag"]] for s in scenes.values() for r in s["rows"]]
    if basin is not None:
        for name, rec in basin[1].items():
            for step in rec["ladder"]:
                csv_rows.append(["basin", f"{name} {rec['method']}", f"rtol={step['rtol']:.0e}",
                                 step["wall_s"], 100.0 - step["agree"], "", "",
                                 f"{rec['sub']}x{rec['sub']} subgrid; error column = % cells "
                                 "differing"])
    figures = [(f"peers_wp_{s['name']}.png", plot_wp(s), 120) for s in scenes.values()]
    if basin is not None:
        figures.append(("peers_basin.png", plot_basin(basin[0], basin[1]), 120))
    b.report("peers", markdown=md,
             csv=(["scene", "method", "setting", "wall_median_s", "error", "status",
                   "n_impacts", "flag"], csv_rows),
             data=dict(quick=quick, repeats=repeats, environment=env, missing=missing,
                       checks=checks, reference_check=ref_rows, reference=ref_info,
                       call_floor_s=floor_calls, scenes=scenes, summary=wp_rows,
                       basin=None if basin is None else dict(rockjit=basin[0], peers=basin[1],
                                                             periods=basin[2]),
                       load_average=dict(start=load0, end=load1), total_s=total),
             figures=figures)
    return 0


if __name__ == "__main__":
    sys.exit(main())
