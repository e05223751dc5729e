"""Cycles per cell-step with L grid cells per thread in lockstep, L = 1, 2, 4, 8.

Measured side by side in one process, on one thread, the block's free-flight step (closed-form
forcing tabulated per period, no tangent, no events; a lane leaving the polynomial's range is
put back to its start, rarely):

- ``scalar``: today's step (:func:`rockjit._engine.integrate.rk_step`) for each of L independent
  cells in turn, then the step's acceptance; the out-of-order core may overlap neighbouring
  cells' chains;
- ``lanes``: :func:`rockjit._engine.lanes.block_step_lanes`, the same arithmetic written as one
  loop over lanes, vectorised (it always computes all ``W`` = 8 lanes, one AVX-512 vector; L of them
  count), which also accepts the step.

(That the vector step equals the scalar one bit for bit is tests/_engine/test_lanes.py's.) The arithmetic
bound drawn in the plot is :data:`FLOPS_PER_STEP` floating-point instructions (counted from the
source, below) at :data:`FP_PER_CYCLE` per cycle (two FMA/multiply pipes), scalar and at the
vector width.

Then the grid kernel itself (:func:`rockjit._engine.kernel.run_chunk_counted`, ``lanes`` = 1, 2,
4, 8, side by side, outputs checked equal to ``lanes=1``'s): cells per second and wall ns per
cell-step on the study's hb=1 Housner basin, full length and early-stopped, on the same threads,
and from the lanes' own cycle counters (one more run per L with ``profile=True``, not timed) the
share of the time in the vector steps and in the steps taken by the single-lane code (events,
rest phases), with the speed-up that remains possible if those keep their cost (Amdahl: the L=1
time over the time of the scalar steps).

    python benchmarks/bench_lanes.py           # ~10 min
    python benchmarks/bench_lanes.py --quick
    python benchmarks/bench_lanes.py --grid-full 40 --periods-full 200

Writes lanes.{md,json} and lanes.png to benchmarks/results/ (quick/ with --quick, or --out).
"""

from __future__ import annotations

import math
import time

import numba
import numpy as np

import _common as H
from bench_throughput import cpu_mhz

import rockjit
from rockjit import Block, Classification, Execution, Harmonic, Integration
from rockjit._engine import integrate as ig
from rockjit._engine import kernel as kn
from rockjit._engine import lanes as ln
from rockjit._engine.kernel import pack
from rockjit.grids import plan as gp
from rockjit.grids.plan import GRID_N

LS = (1, 2, 4, 8)
FULL = dict(grid_big=1000, steps=2_000_000, reps=7, grid_full=100, periods_full=500,
            reps_full=1, grid_es=100, reps_es=3)
QUICK = dict(grid_big=20, steps=40_000, reps=3, grid_full=12, periods_full=40, reps_full=2,
             grid_es=20, reps_es=2)
#: The study's hb=1 basin (every cell at the forcing phase (r0, s0) = (0, 1))
BASIN = (Block(hb=1.0, law="housner"), Harmonic(alpha=0.66, omega=1.3))

#: Multiplies and FMAs of one block step (fast path, no slopes), from the source: per stage
#: corner 2 FMA, rotate 2 FMA + 2 mul, near_poly 3 mul + 9 FMA, accel_near 2 mul + 2 FMA (22);
#: six stages 132; the stage sums 6 mul + 34 FMA; the end's sincos_poly 6 mul + 14 FMA; the
#: constants of corner and accel_near 4 mul (hoisted). Adds, abs and max (the range check, 12)
#: go to the other two pipes and are not counted.
FLOPS_PER_STEP = 132 + 40 + 20 + 4
#: FMA/multiply instructions issued per cycle (two pipes, AMD Zen and Intel since Skylake).
FP_PER_CYCLE = 2
#: Doubles per vector (AVX2: 4; the 512-bit instructions of this CPU run as two halves on Zen 4).
VECTOR = 4


def _options(p):
    p.add_argument("--grid-full", type=int, default=None,
                   help="cells per side of the full-length basin (default 100)")
    p.add_argument("--periods-full", type=int, default=None,
                   help="periods of the full-length basin (default 500)")


def kernels():
    """The two measured loops, compiled (numba, not cached: a benchmark's own code). A lane is
    put back to its start when its step would cross theta = 0 (an impact) or leave the
    polynomials' range, the same rule in both."""
    n_st = ig.N_STAGES
    rk_step, rhs = ig.rk_step, ig.rhs
    W = ln.W

    @numba.njit(cache=False, _nrt=False)
    def restart(l, y, K, par, jac, trig):
        y[l, 0] = 0.2 + 0.01 * l
        y[l, 1] = 0.0
        rhs(None, 0.0, y[l], 1, par, K[l], jac[l], trig[l])

    @numba.njit(cache=False, _nrt=False)
    def scalar(n, L, y, K, par, ytmp, ynew, tab, ftab, jac, trig, lin, lout, ftl, nv):
        n_per = ftab.shape[0]
        for l in range(L):
            restart(l, y, K, par, jac, trig)
        j = 0
        for _ in range(n):
            for l in range(L):
                Kl = K[l]
                rk_step(None, None, True, 0.0, 1.0, y[l], Kl, 1, par, ytmp[l], ynew[l], tab,
                        ftab[j], jac[l], trig[l])
                if ynew[l, 0] < 0.0:
                    restart(l, y, K, par, jac, trig)
                    continue
                y[l, 0] = ynew[l, 0]
                y[l, 1] = ynew[l, 1]
                Kl[0, 0] = Kl[n_st, 0]
                Kl[0, 1] = Kl[n_st, 1]
                trig[l, 0] = trig[l, 2]
                trig[l, 1] = trig[l, 3]
            j += 1
            if j == n_per:
                j = 0

    @numba.njit(cache=False, _nrt=False)
    def load(l, y, K, par, jac, trig, lin, tab):
        restart(l, y, K, par, jac, trig)
        lin[ln.LI_X * W + l] = y[l, 0]
        lin[ln.LI_V * W + l] = y[l, 1]
        lin[ln.LI_K * W + l] = K[l, 0, 1]
        lin[ln.LI_S * W + l] = trig[l, 0]
        lin[ln.LI_C * W + l] = trig[l, 1]
        lin[ln.LI_SG * W + l] = 1.0
        lin[ln.LI_STHC * W + l] = par[ig.P_STHC]
        lin[ln.LI_CTHC * W + l] = par[ig.P_CTHC]
        lin[ln.LI_XI * W + l] = par[ig.P_XI]
        lin[ln.LI_THOVER * W + l] = par[ig.P_THOVER]
        ln.lane_tables(tab, lin, l)

    @numba.njit(cache=False, _nrt=False)
    def lanes(n, L, y, K, par, ytmp, ynew, tab, ftab, jac, trig, lin, lout, ftl, nv):
        n_per = ftab.shape[0]
        for l in range(W):
            load(l, y, K, par, jac, trig, lin, tab)
            for jj in range(n_per):
                for i in range(n_st + 1):
                    ftl[(jj * (n_st + 1) + i) * W + l] = ftab[jj, i]
        j = 0
        for _ in range(n):
            ln.block_step_lanes(nv.shape[0], j, lin, lout, ftl)  # all W lanes, one vector
            for l in range(L):
                if lout[ln.LO_FAST * W + l] == 0.0:
                    load(l, y, K, par, jac, trig, lin, tab)
            j += 1
            if j == n_per:
                j = 0

    return scalar, lanes


def setup(L):
    """The state and work arrays of L lanes of the reference block (alpha = 0.6)."""
    n_st = ig.N_STAGES
    n_per = GRID_N
    p = pack(Block(hb=1.0), Harmonic(alpha=0.6, omega=1.3), 0.0, Integration(), n_per)
    par = np.zeros(ig.N_PARW)
    par[:ig.N_PAR] = p
    par[ig.P_STHC] = math.sin(p[ig.P_THC])
    par[ig.P_CTHC] = math.cos(p[ig.P_THC])
    tab = np.zeros((ig.N_TAB, n_st + 1))
    ig.step_table(par[ig.P_OMEGA], par[ig.P_H], tab)
    ftab = np.zeros((n_per, n_st + 1))
    for j in range(n_per):
        for i in range(n_st + 1):
            c = ig.C[i] if i < n_st else 1.0
            ftab[j, i] = par[ig.P_AW2] * math.sin(par[ig.P_PHI] + 2 * math.pi * (j + c) / n_per)
    W = ln.W
    z = lambda *s: np.zeros(s)  # noqa: E731
    return dict(y=z(W, 2), K=z(W, n_st + 1, 2), par=par, ytmp=z(W, 2), ynew=z(W, 2), tab=tab,
                ftab=ftab, jac=z(W, n_st + 1), trig=z(W, 4), lin=z(ln.N_LIN * W),
                lout=z(ln.N_LOUT * W), ftl=z(n_per * (n_st + 1) * W), nv=z(W))


def measure(cfg):
    """ns per cell-step of the two loops for each L (the vector step always computes W lanes;
    L of them are counted)."""
    scalar, lanes = kernels()
    n = cfg["steps"]
    cases = {}
    for L in LS:
        c1, c2 = setup(L), setup(L)
        scalar(100, L, *c1.values())
        lanes(100, L, *c2.values())
        s = max(1, n // L)
        cases[("scalar", L)] = lambda L=L, c=c1, s=s: scalar(s, L, *c.values())
        cases[("lanes", L)] = lambda L=L, c=c2, s=s: lanes(s, L, *c.values())
    t = H.side_by_side(cases, cfg["reps"])
    out = {}
    for (kind, L) in cases:
        out[(kind, L)] = 1e9 * t.median((kind, L)) / (max(1, n // L) * L)
    return out, {f"{k[0]}|{k[1]}": v for k, v in t.wall.items()}


def grids(cfg, threads):
    """The grid kernel with L = 1, 2, 4, 8 lanes side by side on the study's basin, full length
    and early-stopped; outputs checked equal to L=1's."""
    rows, data, parts = [], {}, {}
    for name, grid, periods, early, reps in (
            ("full length", cfg["grid_full"], cfg["periods_full"], False, cfg["reps_full"]),
            ("early stop", cfg["grid_es"], 500, True, cfg["reps_es"])):
        plan = rockjit.basin.plan(*BASIN, grid, integration=Integration(periods=periods),
                                  classification=Classification(early_stop=early))
        args = (plan.tangent, plan.y0s, plan.pars, plan.ipar, plan.cpar, plan.n_pts,
                plan.n_imp_pts, threads)
        for L in LS:
            kn.run_chunk_counted(*args[:1], plan.y0s[:4], plan.pars[:4], *args[3:], L)
        t = H.side_by_side({L: (lambda L=L: kn.run_chunk_counted(*args, L)) for L in LS}, reps)
        ref = t.result[1][0]
        for L in LS:
            out = t.result[L][0]
            for k in ("res", "pts", "imp", "n_got", "n_imp_got"):
                if not np.array_equal(ref[k], out[k], equal_nan=True):
                    raise SystemExit(f"{name}, L={L}: {k} differs from L=1")
        steps = float(np.sum(ref["res"][:, kn.R_T] / plan.pars[:, ig.P_H]))
        n = plan.y0s.shape[0]
        w1 = t.median(1)
        for L in LS:
            w = t.median(L)
            # the cycle accounting, from one more run with the counter read (it costs time)
            c = None if L == 1 else kn.run_chunk_counted(*args, L, profile=True)[1]
            row = [name, f"{grid}x{grid}, {periods} periods", L, n / w, 1e9 * w / steps,
                   w1 / w]
            if c is None:
                row += ["", "", "", ""]
            else:
                c = c.sum(axis=0).astype(float)
                scalar_frac = c[1] / (c[0] + c[1])
                # the cycle counter ticks at the TSC's rate: seconds per thread
                scalar_s = c[4] / (H_TSC_HZ * threads)
                row += [scalar_frac, c[3] / c[5], c[4] / c[5], w1 / scalar_s]
                parts[(name, L)] = dict(zip(("rest", "after event", "locate", "impact",
                                             "detect", "first step again", "grid point"),
                                            (c[6:13] / c[4]).tolist()))
            rows.append(row)
        data[name] = dict(raw={str(k): v for k, v in t.wall.items()}, steps=steps, cells=n,
                          scalar_parts={str(L): parts.get((name, L)) for L in LS})
        print(name, rows[-len(LS):], parts.get((name, 8)), flush=True)
    return rows, data, parts


#: The rate of the cycle counter (``rdtsc``: the nominal clock, here the one /proc/cpuinfo
#: reports; set in main).
H_TSC_HZ = math.nan


def big_basin(grid):
    """The study's hb=1 basin at ``grid`` x ``grid`` (500 periods, early stop, attractors
    identified), once with one lane and once with eight; wall seconds (the goal: 1000 x 1000
    in under a minute)."""
    plan = rockjit.basin.plan(*BASIN, grid)
    out = {}
    for L in (1, 8):
        t0 = time.perf_counter()
        gp.run(plan, Execution(lanes=L))
        out[L] = time.perf_counter() - t0
    return out


def main(argv=None):
    global H_TSC_HZ
    b = H.Bench(__doc__, argv, options=_options)
    cfg = dict(QUICK if b.quick else FULL)
    if b.args.grid_full:
        cfg["grid_full"] = b.args.grid_full
    if b.args.periods_full:
        cfg["periods_full"] = b.args.periods_full
    threads = numba.get_num_threads()
    mhz = cpu_mhz()
    H_TSC_HZ = mhz * 1e6
    grid_rows, grid_data, parts = grids(cfg, threads)
    big = big_basin(cfg["grid_big"])
    numba.set_num_threads(1)
    ns, raw = measure(cfg)
    kinds = ("scalar", "lanes")
    rows = []
    for L in LS:
        rows.append([L] + [f"{ns[(k, L)]:.1f} / {ns[(k, L)] * mhz / 1e3:.0f}" for k in kinds])
    bound_scalar = FLOPS_PER_STEP / FP_PER_CYCLE
    bound_vec = bound_scalar / VECTOR
    md = ("#### Lanes: cycles per cell-step\n\n"
          f"One thread, the block's free-flight step at N={GRID_N} (hb=1, alpha=0.6, "
          f"omega=1.3), {cfg['steps']} cell-steps per case, medians of {cfg['reps']} "
          f"interleaved runs; ns / cycles per cell-step at {mhz:.0f} MHz, the nominal clock "
          "(a core that runs faster spends more cycles than these).\n\n"
          + H.md_table(["L"] + [f"{k} (ns / cycles)" for k in kinds], rows)
          + f"\n\nArithmetic bound: {FLOPS_PER_STEP} multiplies and FMAs per step at "
          f"{FP_PER_CYCLE} per cycle: {bound_scalar:.0f} cycles scalar, {bound_vec:.0f} at "
          f"{VECTOR} doubles per vector.\n\n"
          f"#### Lanes in the grid kernel\n\n"
          f"The study's hb=1 Housner basin (alpha=0.66, omega=1.3, N={GRID_N}), "
          f"{threads} threads, medians of interleaved runs; outputs equal to L=1's bit for "
          "bit. Scalar steps: the steps the single-lane code takes (events, rest phases); "
          "time shares from the lanes' cycle counters; bound: the speed-up left if the "
          "scalar steps keep their cost (L=1 wall over their time).\n\n"
          + H.md_table(["basin", "grid", "L", "cells / s", "wall ns / cell-step",
                        "speed-up vs L=1", "scalar steps", "time in vector steps",
                        "time in scalar steps", "bound"],
                       [[r[0], r[1], r[2], H.fmt(r[3]), H.fmt(r[4]), H.fmt(r[5])]
                        + [H.fmt(x) if x != "" else "" for x in r[6:]] for r in grid_rows])
          + "\n\nWhere the scalar steps' time goes (L=8, share of their cycles): "
          + "; ".join(f"{name}: " + ", ".join(f"{k} {v:.2f}" for k, v in p.items())
                      for (name, L), p in parts.items() if L == 8)
          + " (the rest: the lanes' bookkeeping and the cycle counter's own reads).\n\n"
          + f"The study's hb=1 basin at {cfg['grid_big']}x{cfg['grid_big']} (500 periods, early "
          f"stop, attractors identified; goal: 1000x1000 in under 60 s), one run "
          f"each: {big[1]:.1f} s with one lane, {big[8]:.1f} s with eight"
          + (f": goal {'reached' if big[8] < 60.0 else 'out of reach here'}"
             if cfg["grid_big"] == 1000 else "") + ".\n\n"
          + H.env_line(b.env) + "\n")
    plt = H.pyplot()
    fig, ax = plt.subplots(figsize=(6, 4))
    for k in kinds:
        ax.plot(LS, [ns[(k, L)] * mhz / 1e3 for L in LS], "o-", label=k)
    ax.axhline(bound_scalar, color="k", ls="--", lw=1, label="arithmetic bound, scalar")
    ax.axhline(bound_vec, color="k", ls=":", lw=1, label=f"arithmetic bound, {VECTOR}-wide")
    ax.set_xscale("log", base=2)
    ax.set_xticks(LS, [str(L) for L in LS])
    ax.set_ylim(bottom=0)
    ax.set_xlabel("lanes L (cells per thread in lockstep)")
    ax.set_ylabel(f"cycles per cell-step (at the nominal {mhz:.0f} MHz)")
    ax.legend(fontsize=8)
    ax.set_title("free-flight step, one thread")
    csv_cols = ["basin", "grid", "lanes", "cells_per_s", "ns_per_cell_step", "speedup_vs_1",
                "scalar_steps", "time_vector", "time_scalar", "bound"]
    b.report("lanes", markdown=md, csv=(csv_cols, [list(r[:10]) for r in grid_rows]),
             data=dict(ns_per_cell_step={f"{k}|{L}": ns[(k, L)] for (k, L) in ns}, mhz=mhz,
                       raw=raw, cfg=cfg, grid_rows=grid_rows, grids=grid_data, threads=threads,
                       big_basin_s={str(k): v for k, v in big.items()}),
             figures=[("lanes.png", fig, 120)])


if __name__ == "__main__":
    main()
