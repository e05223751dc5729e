"""The commands on periodic orbits and their bifurcations: ``rockjit orbits`` (orbits
continued in alpha) and ``rockjit chart`` (the (alpha, omega) plane with its bifurcation
curves), each with its options, plan and run."""

from __future__ import annotations

import time

from .arguments import add_alphas, add_block, add_command, add_common, add_scheduler
from .grid_commands import grid_run
from .messages import say
from .options import block_of, execution_of, forcing_of, integration_of, laws_of, run_grid


def _orbits_plan(args):
    from ..orbits import ContinuationSettings, orbits_of_sweep
    from ..settings import Integration
    return orbits_of_sweep.plan(block_of(args), forcing_of(args, alpha=False),
                                tuple(args.alpha_range), alpha_step=args.alpha_step,
                                integration=Integration(periods=args.periods),
                                settings=ContinuationSettings(max_period=args.max_period),
                                execution=execution_of(args))


def _chart_plan(args):
    """``rockjit chart``: one :func:`rockjit.chart` plan per law (``--law both``: two)."""
    from ..orbits.plane_chart import ChartCurves, chart
    from ..validate import memory
    curves = ChartCurves(seed_omegas=args.seed_omegas, max_period=args.max_period)
    plans = {law: chart.plan(block_of(args, law), tuple(args.alpha_range),
                             tuple(args.omega_range), grid=tuple(args.grid), curves=curves,
                             integration=integration_of(args), lyapunov=args.lyapunov,
                             execution=execution_of(args))
             for law in laws_of(args)}
    memory(f"--grid {args.grid[0]} {args.grid[1]} for {len(plans)} laws",
           sum(p.plane_plan.memory_bytes for p in plans.values()))
    return plans


def _chart_run(args, plans, out):
    from .. import outputs
    from ..orbits.plane_chart import run
    t0 = time.perf_counter()
    res = {}
    for law, p in plans.items():
        say(args, f"chart: {law}, {p.plane_plan.shape[1]} x {p.plane_plan.shape[2]} cells, "
                   f"then the curves from {len(p.seed_omegas)} omega lines")
        res[law] = run_grid(args, run, p, f"chart_{law}")
        say(args, f"chart: {law}: {len(res[law].curves)} curves "
                   f"({', '.join(f'{k} {v:.1f} s' for k, v in res[law].timing.items())})")
    results = outputs.chart(out, res)
    results.pop("figure")
    return time.perf_counter() - t0, results


def add_orbits_command(sub):
    """``rockjit orbits``: periodic orbits continued in alpha."""
    p = add_command(sub, "orbits", _orbits_plan, grid_run("orbits", "sweep"),
                    "periodic orbits continued in alpha, bifurcations located",
                    "Seed from every periodic attractor of a sweep, follow each orbit both ways "
                    "in alpha (stable and unstable), locate its bifurcations; write orbits.npz, "
                    "orbits.png (branches over the sweep) and summary.json (\"bifurcations\").")
    add_block(p, alpha=False)
    add_alphas(p, 0.001)
    p.add_argument("--periods", type=int, default=500, help="periods of the seeding sweep")
    p.add_argument("--max-period", type=int, default=8, help="longest period followed")
    add_common(p)
    add_scheduler(p)


def add_chart_command(sub):
    """``rockjit chart``: the (alpha, omega) plane with its bifurcation curves."""
    p = add_command(sub, "chart", _chart_plan, _chart_run,
                    "the (alpha, omega) plane with its bifurcation curves",
                    "The brute-force chart of behaviours from the study's z0 over the forcing "
                    "plane and the fold, "
                    "symmetry-breaking, period-doubling and grazing curves across it, followed by "
                    "continuation from the bifurcations located along alpha on a few omega lines; "
                    "write chart.npz, chart.png (with --law both: both laws side by side and "
                    "their curves on one chart) and summary.json (\"curves\": type, period, law, "
                    "points).")
    add_block(p, alpha=False, omega=False, both=True)
    add_alphas(p, None)
    p.add_argument("--omega-range", type=float, nargs=2, required=True,
                   metavar=("START", "END"), help="frequencies (ends included)")
    p.add_argument("--grid", type=int, nargs=2, default=(200, 200), metavar=("NA", "NW"),
                   help="chart points along alpha and omega (default 200 200)")
    p.add_argument("--seed-omegas", type=float, nargs="+", default=None, metavar="OMEGA",
                   help="the omega lines whose bifurcations seed the curves (default five, "
                        "evenly spaced inside --omega-range)")
    p.add_argument("--max-period", type=int, default=2,
                   help="longest period of the bifurcations followed (default 2)")
    p.add_argument("--lyapunov", action="store_true",
                   help="the chart's exponents (tell chaotic from aperiodic; 3x its cost)")
    p.add_argument("--periods", type=int, default=500,
                   help="forcing periods of the chart's runs (default 500)")
    p.add_argument("--n-steps", type=int, default=None,
                   help="steps per forcing period of the chart's runs (default 64)")
    add_common(p)
    add_scheduler(p)
