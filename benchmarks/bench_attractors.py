"""What attractor identity, basin measures and erosion profiles cost.

1. the study's four 100x100 basins (500 periods, early stop) with and without attractor
   identification (``Classification(attractors=True/False)``), side by side: the overhead
   (goal: at most 15 % of a basin's time), and the cost of ``BasinResult.measures()``
   (entropy, uncertainty exponent, integrity) apart;
2. an erosion profile of 71 amplitudes x 100x100 cells, both laws (hb=1, omega=1.3, alpha in
   [0.3, 1.0] every 0.01; goal: at most 90 s warm on this 2-core machine), with the share of
   its time in the compiled grid kernel.

    python benchmarks/bench_attractors.py            # full measurement (several minutes)
    python benchmarks/bench_attractors.py --quick    # smoke mode (small grids)

Writes attractors.{md,csv,json,png} to benchmarks/results/ (benchmarks/results/quick/ with
--quick, or --out DIR).
"""

from __future__ import annotations

import sys
import time
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parent))
import _common as H  # noqa: E402

import rockjit  # noqa: E402
from rockjit import Block, Classification, Harmonic  # noqa: E402
from rockjit._engine import kernel  # noqa: E402

#: (hb, alpha, omega) of the study's basins, each with both laws; every cell at the forcing
#: phase (r0, s0) = (0, 1), a basin's default
BASINS = ((1.0, 0.66, 1.3), (2.0, 0.2, 1.6))
FULL = dict(grid=100, repeats=5, erosion=dict(hb=1.0, omega=1.3, alpha_range=(0.3, 1.0),
                                              alpha_step=0.01, grid=100))
QUICK = dict(grid=24, repeats=3, erosion=dict(hb=1.0, omega=1.3, alpha_range=(0.6, 0.8),
                                              alpha_step=0.05, grid=16))
#: Goals: attractor identification's overhead on a basin, the erosion profile's wall time
TARGET_OVERHEAD = 0.15
TARGET_EROSION_S = 90.0


def identification_cost(grid, repeats):
    """Each basin with and without attractors, side by side; the measures apart."""
    cases = {}
    for hb, alpha, omega in BASINS:
        for law in ("housner", "mao"):
            for att in (False, True):
                cases[(hb, law, att)] = (
                    lambda hb=hb, alpha=alpha, omega=omega, law=law, att=att: rockjit.basin(
                        Block(hb=hb, law=law), Harmonic(alpha=alpha, omega=omega), grid,
                        classification=Classification(attractors=att)))
    for f in cases.values():  # first calls: compile or load the kernels
        f()
    t = H.side_by_side(cases, repeats)
    rows = []
    for hb, alpha, omega in BASINS:
        for law in ("housner", "mao"):
            off, on = t.median((hb, law, False)), t.median((hb, law, True))
            b = t.result[(hb, law, True)]
            t_m, _ = H.timed(b.measures)
            same = bool(np.array_equal(b.label, t.result[(hb, law, False)].label))
            rows.append([hb, alpha, omega, law, grid, off, on, on / off - 1.0, t_m,
                         len(b.attractors), same])
    return rows, t


def erosion(cfg, law, alphas=None):
    """The erosion profile of ``cfg`` for ``law`` (over ``alphas``, default the profile's)."""
    if alphas is None:
        alphas = rockjit.alpha_grid(cfg["alpha_range"], cfg["alpha_step"])
    return rockjit.erosion(Block(hb=cfg["hb"], law=law), Harmonic(omega=cfg["omega"]), alphas,
                           cfg["grid"])


def erosion_cost(cfg):
    """The profile of both laws, warm, and the time spent in the grid kernel."""
    spent = {"kernel": 0.0}
    real = kernel.run_chunk

    def counted(*a, **kw):
        t0 = time.perf_counter()
        try:
            return real(*a, **kw)
        finally:
            spent["kernel"] += time.perf_counter() - t0

    erosion(cfg, "housner", cfg["alpha_range"][:1])  # one amplitude: load the kernels
    kernel.run_chunk = counted
    try:
        t0 = time.perf_counter()
        prof = {law: erosion(cfg, law) for law in ("housner", "mao")}
        wall = time.perf_counter() - t0
    finally:
        kernel.run_chunk = real
    n_alpha = prof["housner"].alpha.size
    return dict(wall_s=wall, kernel_s=spent["kernel"], n_alpha=n_alpha,
                cells=2 * n_alpha * cfg["grid"] ** 2,
                GIM={law: r.GIM.tolist() for law, r in prof.items()}), prof


def plot(rows, ero):
    plt = H.pyplot()
    fig, (ax, ax2) = plt.subplots(1, 2, figsize=(11, 4), layout="constrained")
    labels = [f"hb={r[0]:g}\n{r[3]}" for r in rows]
    x = np.arange(len(rows))
    ax.bar(x - 0.2, [r[5] for r in rows], 0.4, label="behaviours only")
    ax.bar(x + 0.2, [r[6] for r in rows], 0.4, label="with attractor identity")
    ax.set_xticks(x, labels)
    ax.set_ylabel("basin wall time, median (s)")
    ax.set_title("attractor identification: overhead "
                 + ", ".join(f"{100 * r[7]:+.0f} %" for r in rows), fontsize=9)
    ax.legend(fontsize=8)
    ax2.bar(["erosion profile,\nboth laws", "of which in\nthe grid kernel"],
            [ero["wall_s"], ero["kernel_s"]], color=["#2ca02c", "#98df8a"])
    ax2.axhline(TARGET_EROSION_S, color="r", lw=0.8, label=f"goal {TARGET_EROSION_S:g} s")
    ax2.set_ylabel("s")
    ax2.set_title(f"{ero['n_alpha']} amplitudes x 2 laws, {ero['cells']:,} cells", fontsize=9)
    ax2.legend(fontsize=8)
    return fig


def goal_overhead(rows):
    """Whether every basin's identification overhead is within the goal, in words."""
    over = [f"hb={r[0]:g} {r[3]} {100 * r[7]:+.0f} %" for r in rows if r[7] > TARGET_OVERHEAD]
    return "reached on every basin" if not over else "out of reach on " + ", ".join(over)


def main(argv=None):
    b = H.Bench(__doc__, argv)
    cfg = QUICK if b.quick else FULL
    rows, _ = identification_cost(cfg["grid"], cfg["repeats"])
    ero, _ = erosion_cost(cfg["erosion"])
    cols = ["hb", "alpha", "omega", "law", "grid", "without_s", "with_s", "overhead",
            "measures_s", "n_attractors", "labels_equal"]
    md = [f"# Attractors, measures, erosion ({'quick' if b.quick else 'full'})", "",
          H.env_line(b.env), "", H.quick_note(b.quick),
          f"Medians of {cfg['repeats']} side-by-side rounds; goal: an overhead of at most "
          f"{100 * TARGET_OVERHEAD:.0f} % "
          f"({goal_overhead(rows)}).", "",
          H.md_table(cols, [[H.fmt(v) if isinstance(v, float) else v for v in r]
                            for r in rows]), "",
          f"Erosion profile, both laws, {ero['n_alpha']} amplitudes, {ero['cells']:,} cells: "
          f"**{ero['wall_s']:.1f} s** warm (goal {TARGET_EROSION_S:g} s: "
          f"{'reached' if ero['wall_s'] <= TARGET_EROSION_S else 'out of reach here'}), "
          f"of which "
          f"{ero['kernel_s']:.1f} s in the compiled grid kernel "
          f"({100 * ero['kernel_s'] / ero['wall_s']:.0f} %)."]
    b.report("attractors", markdown="\n".join(md), csv=(cols, rows),
             data=dict(quick=b.quick, environment=b.env, basins=[dict(zip(cols, r))
                                                                 for r in rows],
                       erosion=dict(ero, config={k: list(v) if isinstance(v, tuple) else v
                                                 for k, v in cfg["erosion"].items()})),
             figures=[("attractors.png", plot(rows, ero), 130)])
    return 0


if __name__ == "__main__":
    sys.exit(main())
