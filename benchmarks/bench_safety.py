"""What global safety costs: integrity charts, the minimal fatal shock, the edge state.

1. an integrity chart of h/b = 1 per law: ``--chart NA NW`` forcings over alpha in [0.2, 1.0],
   omega in [1.0, 2.0], each a 50x50 basin (500 periods, early stop), on ``--threads`` threads
   (default 2); the goal is the 60x60 chart per law in at most 10 min. A smaller chart than
   60x60 is measured when the machine is shared, and the 60x60 time extrapolated from its time
   per basin (said so in the table);
2. the minimal fatal shock of the symmetric cycle of h/b = 1 at alpha = 0.66, omega = 1.3
   (500 periods; goal at most 10 s), against a 101x101 lattice scan of the same square;
3. the edge state found from that shock (edge tracking, then shooting).

    python benchmarks/bench_safety.py                 # 12x12 charts, extrapolated to 60x60
    python benchmarks/bench_safety.py --chart 60 60   # the full charts (about 2 x 10 min)
    python benchmarks/bench_safety.py --quick         # smoke mode (tiny chart)

Writes safety.{md,csv,json,png} to benchmarks/results/ (benchmarks/results/quick/ with
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
from rockjit import Block, Execution, Harmonic, Integration, Lattice  # noqa: E402
from rockjit.plotting.style import LAW_NAMES  # noqa: E402

ALPHA_RANGE, OMEGA_RANGE = (0.2, 1.0), (1.0, 2.0)
TARGET_GRID = (60, 60)
TARGET_CHART_S = 600.0
TARGET_SHOCK_S = 10.0
#: The edge state's shooting residual it should reach.
TARGET_EDGE_RESIDUAL = 1e-10
FORCING = Harmonic(alpha=0.66, omega=1.3)
POINT = (-0.2825, -0.164)


def options(p):
    p.add_argument("--chart", type=int, nargs=2, default=(12, 12), metavar=("NA", "NW"),
                   help="forcings of the measured chart per law (default 12 12)")
    p.add_argument("--threads", type=int, default=2, help="threads (default 2)")


def chart_cost(grid, lattice, periods, threads):
    """One chart per law: wall time, time per basin, the 60x60 time it implies."""
    rows, charts = [], {}
    ex = Execution(threads=threads, progress=False)
    # first call: compile or load the kernels
    rockjit.safety(Block(hb=1), ALPHA_RANGE, OMEGA_RANGE, grid=(2, 2), lattice=4,
                   integration=Integration(periods=10), execution=ex)
    for law in ("housner", "mao"):
        t0 = time.perf_counter()
        ch = rockjit.safety(Block(hb=1, law=law), ALPHA_RANGE, OMEGA_RANGE, grid=grid,
                            lattice=lattice, integration=Integration(periods=periods),
                            execution=ex)
        wall = time.perf_counter() - t0
        per_basin = wall / (grid[0] * grid[1])
        full = per_basin * TARGET_GRID[0] * TARGET_GRID[1]
        measured = tuple(grid) == TARGET_GRID
        rows.append([law, f"{grid[0]}x{grid[1]}", lattice, periods, threads, wall, per_basin,
                     full, "measured" if measured else "extrapolated",
                     float(np.mean(ch.safe))])
        charts[law] = ch
    return rows, charts


def shock_cost(threads, periods):
    block, integ = Block(hb=1), Integration(periods=periods)
    t0 = time.perf_counter()
    s = rockjit.fatal_shock(block, FORCING, POINT, integration=integ, threads=threads)
    wall = time.perf_counter() - t0
    x = np.array(POINT)
    half = 0.8
    t1 = time.perf_counter()
    b = rockjit.basin(block, FORCING, Lattice(101, (x[0] - half, x[0] + half),
                                              (x[1] - half, x[1] + half)),
                      integration=integ, execution=Execution(threads=threads, progress=False))
    lattice_s = time.perf_counter() - t1
    TH, DTH = np.meshgrid(b.theta0, b.dtheta0, indexing="ij")
    nearest = float(np.min(np.hypot(TH - x[0], DTH - x[1])[b.label == 0]))
    return dict(wall_s=wall, norm=s.norm, accuracy=s.accuracy, runs=s.runs,
                delta=s.delta.tolist(), lattice_nearest=nearest, lattice_s=lattice_s), s


def edge_cost(shock, threads, periods):
    t0 = time.perf_counter()
    e = rockjit.edge_state(Block(hb=1), FORCING, shock.point, shock.point + shock.delta,
                           periods=periods, track=60, threads=threads)
    wall = time.perf_counter() - t0
    return dict(wall_s=wall, state=e.state.tolist(), period=e.period,
                multipliers=[abs(complex(m)) for m in e.multipliers], residual=e.residual,
                rebisections=e.rebisections)


def plot(charts, rows):
    plt = H.pyplot()
    fig, axes = plt.subplots(1, len(charts), figsize=(10, 4), layout="constrained")
    for ax, (law, ch) in zip(np.atleast_1d(axes), charts.items()):
        m = ax.pcolormesh(ch.omega, ch.alpha, ch.safe, vmin=0, vmax=1, shading="nearest")
        if ch.alpha.size > 1 and ch.omega.size > 1:
            cs = ax.contour(ch.omega, ch.alpha, ch.safe, levels=[0.5, 0.9], colors="white",
                            linestyles=["solid", "dashed"])
            ax.clabel(cs, fmt=lambda v: f"{v:.0%} safe", fontsize=7)
        wall = next(r[5] for r in rows if r[0] == law)
        ax.set_title(f"{LAW_NAMES[law]}: safe fraction ({wall:.0f} s)", fontsize=9)
        ax.set_xlabel(r"$\omega$")
        ax.set_ylabel(r"$\alpha$")
    fig.colorbar(m, ax=axes, label="safe fraction (initial states that never overturn)")
    return fig


def main(argv=None):
    b = H.Bench(__doc__, argv, options=options)
    threads = b.args.threads
    grid = (3, 3) if b.quick else tuple(b.args.chart)
    lattice, periods = (10, 100) if b.quick else (50, 500)
    rows, charts = chart_cost(grid, lattice, periods, threads)
    shock, s = shock_cost(threads, periods)
    edge = edge_cost(s, threads, periods)
    cols = ["law", "chart", "lattice", "periods", "threads", "wall_s", "s_per_basin",
            "60x60_s", "60x60", "mean_safe"]
    reach = all(r[7] <= TARGET_CHART_S for r in rows)
    md = [f"# Global safety ({'quick' if b.quick else 'full'})", "", H.env_line(b.env), "",
          H.quick_note(b.quick), f"Load average {H.load_text()}.", "",
          f"Integrity charts of h/b = 1, alpha in {ALPHA_RANGE}, omega in {OMEGA_RANGE}, each "
          f"forcing a {lattice}x{lattice} basin ({periods} periods, early stop), on {threads} "
          f"threads, warm. The 60x60 column is the measured chart's time per basin times 3600 "
          f"where the chart measured is smaller (marked extrapolated). Goal: 60x60 per law in "
          f"{TARGET_CHART_S:g} s ({'reached' if reach else 'out of reach here'}).", "",
          H.md_table(cols, [[H.fmt(v) if isinstance(v, float) else v for v in r]
                            for r in rows]), "",
          f"Minimal fatal shock (h/b = 1, alpha = 0.66, omega = 1.3, the cycle at {POINT}): "
          f"**{shock['wall_s']:.2f} s**, {shock['runs']:,} runs, norm {shock['norm']:.6f} "
          f"(relative accuracy {shock['accuracy']:.1e}; goal {TARGET_SHOCK_S:g} s: "
          f"{'reached' if shock['wall_s'] <= TARGET_SHOCK_S else 'out of reach here'}); the "
          f"nearest fatal node of a 101x101 lattice over the square of half-width 0.8 around "
          f"it is {shock['lattice_nearest']:.6f} away ({shock['lattice_s']:.2f} s).", "",
          f"Edge state from that shock: period {edge['period']} at "
          f"({edge['state'][0]:.6f}, {edge['state'][1]:.6f}), |multipliers| "
          f"{', '.join(f'{m:.4g}' for m in edge['multipliers'])}, shooting residual "
          f"{edge['residual']:.1e} (goal {TARGET_EDGE_RESIDUAL:g}: "
          f"{'reached' if edge['residual'] <= TARGET_EDGE_RESIDUAL else 'not reached'}), "
          f"{edge['rebisections']} rebisections, "
          f"**{edge['wall_s']:.2f} s**."]
    b.report("safety", markdown="\n".join(md), csv=(cols, rows),
             data=dict(quick=b.quick, environment=b.env, charts=[dict(zip(cols, r))
                                                                 for r in rows],
                       shock=shock, edge=edge),
             figures=[("safety.png", plot(charts, rows), 110)])
    return 0


if __name__ == "__main__":
    sys.exit(main())
