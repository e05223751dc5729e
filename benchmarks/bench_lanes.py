"""Issue 17: cycles per cell-step with L grid cells per thread in lockstep, L = 1, 2, 4, 8.

Measured side by side in one process, on one thread, the block's free-flight step (closed-form
forcing tabulated per period, no tangent, no events; a lane leaving the polynomial's range is
put back to its start, rarely):

- ``scalar``: today's step (:func:`rockjit.integrate.rk_step`) for each of L independent cells in
  turn, then the step's acceptance; the out-of-order core may overlap neighbouring cells' chains;
- ``lanes``: :func:`rockjit.lanes.block_step_lanes`, the same arithmetic written as one loop over
  lanes (SIMD), then the acceptance in lane arrays;
- ``lanes + bookkeeping``: ``lanes`` plus what a grid kernel does per lane after the step:
  the results copied into the lane's own stage array, event detection
  (:func:`rockjit.integrate.detect`) and acceptance (:func:`rockjit.integrate.accept`).

The lanes' end states are checked equal, bit for bit, to the scalar step's. The arithmetic
bound drawn in the plot is :data:`FLOPS_PER_STEP` floating-point instructions (counted from the
source, below) at :data:`FP_PER_CYCLE` per cycle (two FMA/multiply pipes), scalar and at the
vector width.

    flock /work/timing.lock python benchmarks/bench_lanes.py           # ~1 min after compiling
    flock /work/timing.lock python benchmarks/bench_lanes.py --quick

Writes lanes.{md,json} and lanes.png to benchmarks/results/ (quick/ with --quick, or --out).
"""

from __future__ import annotations

import math

import numba
import numpy as np

import _common as H

import rockjit
from rockjit import integrate as ig
from rockjit import lanes as ln
from rockjit.analysis import GRID_N
from rockjit.kernel import pack

LS = (1, 2, 4, 8)
FULL = dict(steps=2_000_000, reps=7)
QUICK = dict(steps=40_000, reps=3)

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


def cpu_mhz():
    try:
        with open("/proc/cpuinfo") as f:
            for line in f:
                if line.startswith("cpu MHz"):
                    return float(line.split(":")[1])
    except OSError:
        pass
    return math.nan


def kernels():
    """The three measured loops, compiled (numba, not cached: a benchmark's own code)."""
    n_st = ig.N_STAGES
    rk_step, rhs, detect, accept = ig.rk_step, ig.rhs, ig.detect, ig.accept
    Work = ig.Work

    @numba.njit(cache=False, _nrt=False)
    def restart(l, y, K, par, jac, trig):
        y[l, 0] = 0.2 + 0.01 * l
        y[l, 1] = 0.0
        rhs(False, 0.0, y[l], 1, par, K[l], jac[l], trig[l])

    @numba.njit(cache=False, _nrt=False)
    def scalar(n, L, BOOK, y, K, par, ytmp, ynew, tab, ftab, jac, trig, lam, tab_full):
        n_per = ftab.shape[0]
        for l in range(L):
            restart(l, y, K, par, jac, trig)
        j = 0
        for _ in range(n):
            for l in range(L):
                Kl = K[l]
                rk_step(False, False, True, 0.0, 1.0, y[l], Kl, 1, par, ytmp[l], ynew[l], tab,
                        ftab[j], jac[l], trig[l])
                if BOOK:
                    w = Work(Kl, y[l], ytmp[l], ynew[l], ytmp[l], lam, tab_full, tab_full,
                             ftab[j], jac[l], trig[l], ftab)
                    kind, lo, hi = detect(y[l], ynew[l], tab[ig.T_HC, 6], Kl, 1, par)
                    if kind == ig.EV_NONE or kind == ig.EV_IMPACT:
                        accept(2, 2, 1, tab[ig.T_HC, 6], 0.0, w)
                    if y[l, 0] < -0.3:
                        restart(l, y, K, par, jac, trig)
                    continue
                y[l, 0] = ynew[l, 0]
                y[l, 1] = ynew[l, 1]
                Kl[0, 0] = Kl[n_st, 0]
                Kl[0, 1] = Kl[n_st, 1]
                trig[l, 0] = trig[l, 2]
                trig[l, 1] = trig[l, 3]
                if y[l, 0] < -0.3:
                    restart(l, y, K, par, jac, trig)
            j += 1
            if j == n_per:
                j = 0

    W = ln.W

    @numba.njit(cache=False, _nrt=False)
    def lanes(n, L, BOOK, y, K, par, ytmp, ynew, tab, ftab, jac, trig, lin, lout, lam,
              tab_full):
        n_per = ftab.shape[0]
        for l in range(L):
            restart(l, y, K, par, jac, trig)
            lin[ln.I_X * W + l] = y[l, 0]
            lin[ln.I_V * W + l] = y[l, 1]
            lin[ln.I_K * W + l] = K[l, 0, 1]
            lin[ln.I_S * W + l] = trig[l, 0]
            lin[ln.I_C * W + l] = trig[l, 1]
            lin[ln.I_SG * W + l] = 1.0
            lin[ln.I_STHC * W + l] = par[ig.P_STHC]
            lin[ln.I_CTHC * W + l] = par[ig.P_CTHC]
            lin[ln.I_XI * W + l] = par[ig.P_XI]
            ln.lane_tables(tab, lin, l)
        j = 0
        for _ in range(n):
            for l in range(L):
                for i in range(n_st + 1):
                    lin[(ln.I_FR + i) * W + l] = ftab[j, i]
            ln.block_step_lanes(L, lin, lout)
            for l in range(L):
                if BOOK:
                    Kl = K[l]
                    for i in range(1, n_st + 1):
                        Kl[i, 0] = lout[(ln.O_KV + i) * W + l]
                        Kl[i, 1] = lout[(ln.O_KA + i) * W + l]
                    ynew[l, 0] = lout[ln.O_X * W + l]
                    ynew[l, 1] = lout[ln.O_V * W + l]
                    trig[l, 2] = lout[ln.O_S * W + l]
                    trig[l, 3] = lout[ln.O_C * W + l]
                    w = Work(Kl, y[l], ytmp[l], ynew[l], ytmp[l], lam, tab_full, tab_full,
                             ftab[j], jac[l], trig[l], ftab)
                    kind, lo, hi = detect(y[l], ynew[l], tab[ig.T_HC, 6], Kl, 1, par)
                    if kind == ig.EV_NONE or kind == ig.EV_IMPACT:
                        accept(2, 2, 1, tab[ig.T_HC, 6], 0.0, w)
                else:
                    y[l, 0] = lout[ln.O_X * W + l]
                    y[l, 1] = lout[ln.O_V * W + l]
                    K[l, 0, 1] = lout[(ln.O_KA + n_st) * W + l]
                    trig[l, 0] = lout[ln.O_S * W + l]
                    trig[l, 1] = lout[ln.O_C * W + l]
                if y[l, 0] < -0.3:
                    restart(l, y, K, par, jac, trig)
                lin[ln.I_X * W + l] = y[l, 0]
                lin[ln.I_V * W + l] = y[l, 1]
                lin[ln.I_K * W + l] = K[l, 0, 1]
                lin[ln.I_S * W + l] = trig[l, 0]
                lin[ln.I_C * W + l] = trig[l, 1]
            j += 1
            if j == n_per:
                j = 0

    return scalar, lanes


def setup(L):
    """The state and work arrays of L lanes of the reference block (alpha = 0.6)."""
    n_st = ig.N_STAGES
    blk = rockjit.Block(hb=1.0, alpha=0.6, omega=1.3)
    n_per = GRID_N
    p = pack(blk, 0.0, n_per)
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
    z = lambda *s: np.zeros(s)  # noqa: E731
    common = dict(y=z(L, 2), K=z(L, n_st + 1, 2), par=par, ytmp=z(L, 2), ynew=z(L, 2),
                  tab=tab, ftab=ftab, jac=z(L, n_st + 1), trig=z(L, 4))
    book = dict(lam=z(4), tab_full=z(ig.N_TAB, n_st + 1))
    lanes = dict(lin=z(ln.N_LIN * ln.W), lout=z(ln.N_LOUT * ln.W), **book)
    return common, lanes, book


def measure(cfg):
    scalar, lanes = kernels()
    n = cfg["steps"]
    cases = {}
    for L in LS:
        c1, _, b1 = setup(L)
        c2, l2, _ = setup(L)
        c3, l3, _ = setup(L)
        c4, _, b4 = setup(L)
        # compile and check: equal end states after the same number of steps
        m = 1000
        scalar(m, L, False, *c1.values(), *b1.values())
        scalar(m, L, True, *c4.values(), *b4.values())
        lanes(m, L, False, *c2.values(), *l2.values())
        lanes(m, L, True, *c3.values(), *l3.values())
        for c in (c2, c3, c4):
            if not np.array_equal(c1["y"], c["y"]):
                raise SystemExit(f"L={L}: lanes differ from the scalar step: {c1['y']} {c['y']}")
        s = max(1, n // L)
        cases[("scalar", L)] = lambda L=L, c=c1, d=b1, s=s: scalar(s, L, False, *c.values(),
                                                                 *d.values())
        cases[("scalar + bookkeeping", L)] = lambda L=L, c=c4, d=b4, s=s: scalar(
            s, L, True, *c.values(), *d.values())
        cases[("lanes", L)] = lambda L=L, c=c2, d=l2, s=s: lanes(s, L, False, *c.values(),
                                                               *d.values())
        cases[("lanes + bookkeeping", L)] = lambda L=L, c=c3, d=l3, s=s: lanes(
            s, L, True, *c.values(), *d.values())
    t = H.side_by_side(cases, cfg["reps"])
    out = {}
    for (kind, L) in cases:
        cell_steps = max(1, n // L) * L
        out[(kind, L)] = 1e9 * t.median((kind, L)) / cell_steps
    return out, {f"{k[0]}|{k[1]}": v for k, v in t.wall.items()}


def main(argv=None):
    b = H.Bench(__doc__, argv)
    cfg = QUICK if b.quick else FULL
    numba.set_num_threads(1)
    mhz = cpu_mhz()
    ns, raw = measure(cfg)
    kinds = ("scalar", "lanes", "scalar + bookkeeping", "lanes + bookkeeping")
    rows = []
    for L in LS:
        rows.append([L] + [f"{ns[(k, L)]:.1f} / {ns[(k, L)] * mhz / 1e3:.0f}" for k in kinds])
    bound_scalar = FLOPS_PER_STEP / FP_PER_CYCLE
    bound_vec = bound_scalar / VECTOR
    md = ("#### Lanes: cycles per cell-step\n\n"
          f"One thread, the block's free-flight step at N={GRID_N} (hb=1, alpha=0.6, "
          f"omega=1.3), {cfg['steps']} cell-steps per case, medians of {cfg['reps']} "
          f"interleaved runs; ns / cycles per cell-step at {mhz:.0f} MHz. End states equal "
          "bit for bit to the scalar step's.\n\n"
          + H.md_table(["L"] + [f"{k} (ns / cycles)" for k in kinds], rows)
          + f"\n\nArithmetic bound: {FLOPS_PER_STEP} multiplies and FMAs per step at "
          f"{FP_PER_CYCLE} per cycle: {bound_scalar:.0f} cycles scalar, {bound_vec:.0f} at "
          f"{VECTOR} doubles per vector.\n\n" + H.env_line(b.env) + "\n")
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
    ax.set_ylabel("cycles per cell-step")
    ax.legend(fontsize=8)
    ax.set_title("free-flight step, one thread")
    b.report("lanes", markdown=md, data=dict(ns_per_cell_step={f"{k}|{L}": ns[(k, L)]
                                                               for (k, L) in ns},
                                             mhz=mhz, raw=raw, cfg=cfg),
             figures=[("lanes.png", fig, 120)])


if __name__ == "__main__":
    main()
