"""The commands over grids of the harmonic forcing's runs: ``rockjit sweep``, ``basin``,
``plane``, ``erosion`` and ``safety``, each with its options and plan, and the run of a grid
command (:func:`grid_run`, which ``orbits`` and ``spectrum`` run with too)."""

from __future__ import annotations

import importlib
import time

from .arguments import (add_alphas, add_block, add_command, add_common, add_grid_run,
                        add_phase, add_run, add_scheduler, add_state)
from .messages import say
from .options import (alphas_of, block_of, classification_of, execution_of, forcing_of,
                      integration_of, laws_of, run_grid, state_of)


def _sweep_plan(args):
    from ..grids import sweep
    return sweep.plan(block_of(args), forcing_of(args, alpha=False), alphas_of(args),
                      state_of(args),
                      integration=integration_of(args), classification=classification_of(args),
                      lyapunov=not args.no_lyapunov, execution=execution_of(args))


def _basin_plan(args):
    from ..grids import basin
    from ..settings import Lattice
    from ..validate import memory
    lattice = Lattice(args.grid, tuple(args.theta_range), tuple(args.dtheta_range))
    plans = {law: basin.plan(block_of(args, law), forcing_of(args), lattice,
                             integration=integration_of(args),
                             classification=classification_of(args), lyapunov=args.lyapunov,
                             execution=execution_of(args))
             for law in laws_of(args)}
    memory(f"--grid {args.grid} for {len(plans)} laws", sum(p.memory_bytes for p in plans.values()))
    return plans


def _plane_plan(args):
    from ..grids import plane
    phase = forcing_of(args, alpha=False, omega=False)
    return plane.plan(block_of(args), args.alpha_range, args.omega_range, grid=args.grid,
                      state=state_of(args), forcing=phase, integration=integration_of(args),
                      classification=classification_of(args), lyapunov=not args.no_lyapunov,
                      execution=execution_of(args))


def _erosion_plan(args):
    from ..basins.erosion import erosion
    from ..grids.plan import alpha_count, grid_memory
    from ..single import settings_for
    # the whole profile's memory before the amplitudes' array is made
    *_, n = alpha_count(args.alpha_range, args.alpha_step)
    integration, execution = integration_of(args), execution_of(args)
    probe = forcing_of(args, alpha=False).replace(alpha=args.alpha_range[0])
    n_steps, _, _ = settings_for(block_of(args, laws_of(args)[0]), probe, integration, 64)
    grid_memory(f"--alpha-range and --alpha-step ({n} amplitudes) at --grid {args.grid}",
                float(args.grid) ** 2 * n, dict(periods=args.periods, n_steps=n_steps),
                execution, 16)
    alphas = alphas_of(args)
    if len(laws_of(args)) > 1:
        grid_memory(f"--grid {args.grid} at {n} amplitudes for {len(laws_of(args))} laws",
                    float(args.grid) ** 2 * n * len(laws_of(args)),
                    dict(periods=args.periods, n_steps=n_steps), execution, 16)
    return {law: erosion.plan(block_of(args, law), forcing_of(args, alpha=False), alphas, args.grid,
                              integration=integration, classification=classification_of(args),
                              execution=execution)
            for law in laws_of(args)}


def _safety_plan(args):
    """``rockjit safety``: one :func:`rockjit.safety` plan per law, the contour levels
    checked."""
    from ..integrity.chart import safety
    from ..validate import real
    for v in args.levels:
        real("--levels", v, 0.0, 1.0)
    phase = forcing_of(args, alpha=False, omega=False)
    return {law: safety.plan(block_of(args, law), tuple(args.alpha_range),
                             tuple(args.omega_range), grid=tuple(args.grid),
                             lattice=args.lattice, forcing=phase,
                             integration=integration_of(args),
                             classification=classification_of(args), execution=execution_of(args))
            for law in laws_of(args)}


def _write_safety(out, res, args):
    from ..integrity.figure import write
    return write(out, res, tuple(args.levels))


#: The module whose ``run`` computes a grid command's plans (``rockjit.grids.plan`` where the
#: command is not listed); looked up when the command runs.
_GRID_RUNS = {"erosion": "rockjit.basins.erosion", "orbits": "rockjit.orbits.arclength",
              "safety": "rockjit.integrity.chart", "spectrum": "rockjit.ground.spectrum"}


def grid_run(writer, name, store=None, write=None):
    """The run of a grid command: its plan (or one plan per law) computed with the command
    line's progress, Dask client and chunk store, then written.

    ``writer``: the name of the writer in :mod:`rockjit.outputs`, called ``(out, results)``;
    ``write``, where given, is called ``(out, results, args)`` instead. ``name``: the chunk
    store of a single plan; ``store(law)``: that of each law's plan (default the law)."""
    def run_it(args, plans, out):
        from .. import outputs
        run = importlib.import_module(_GRID_RUNS.get(args.command, "rockjit.grids.plan")).run
        t0 = time.perf_counter()
        if isinstance(plans, dict):
            res = {law: run_grid(args, run, p, store(law) if store else law)
                   for law, p in plans.items()}
        else:
            res = run_grid(args, run, plans, name)
        wall = time.perf_counter() - t0
        say(args, f"{args.command}: computed in {wall:.1f} s")
        if write is not None:
            return wall, write(out, res, args)
        return wall, getattr(outputs, writer)(out, res)
    return run_it


def add_sweep_command(sub):
    """``rockjit sweep``: a sweep over alpha."""
    p = add_command(sub, "sweep", _sweep_plan, grid_run("sweep", "sweep"), "sweep over alpha",
                    "Sweep the forcing amplitude; write sweep.npz, bifurcation.png and "
                    "summary.json (fractions of each behaviour).")
    add_block(p, alpha=False)
    add_alphas(p, 0.001)
    add_state(p, "default: the study's z0")
    add_grid_run(p, lyapunov_default=True)


def add_basin_command(sub):
    """``rockjit basin``: a basin of attraction."""
    p = add_command(sub, "basin", _basin_plan, grid_run("basins", "basin"), "basin of attraction",
                    "Classify a grid of initial states (theta0, dtheta0); write basin.npz "
                    "(label[i, j] belongs to theta0[i], dtheta0[j]), basin.png and summary.json "
                    "(percentages; with --law both, per law and the agreement).")
    add_block(p, both=True)
    p.add_argument("--grid", type=int, default=100, help="cells per side (default 100)")
    p.add_argument("--theta-range", type=float, nargs=2, default=(-1.0, 1.0),
                   metavar=("LO", "HI"), help="theta0 range (default -1 1)")
    p.add_argument("--dtheta-range", type=float, nargs=2, default=(-1.0, 1.0),
                   metavar=("LO", "HI"), help="dtheta0 range (default -1 1)")
    add_phase(p, "default (r0, s0) = (0, 1)")
    add_grid_run(p, lyapunov_default=False)


def add_plane_command(sub):
    """``rockjit plane``: the (alpha, omega) plane."""
    p = add_command(sub, "plane", _plane_plan, grid_run("plane", "plane"),
                    "the (alpha, omega) plane",
                    "Classify a grid over the forcing plane (alpha, omega) from one initial state; "
                    "write plane.npz (label[i, j] belongs to alpha[i], omega[j]), plane.png and "
                    "summary.json. Runs in-process or, with --scheduler, on a Dask cluster; an "
                    "interrupted run resumes.")
    add_block(p, alpha=False, omega=False)
    add_alphas(p, None)
    p.add_argument("--omega-range", type=float, nargs=2, required=True,
                   metavar=("START", "END"), help="frequencies (ends included)")
    p.add_argument("--grid", type=int, nargs=2, default=(50, 50), metavar=("NA", "NW"),
                   help="points along alpha and omega (default 50 50)")
    add_state(p, "default: the study's z0")
    add_grid_run(p, lyapunov_default=True)


def add_erosion_command(sub):
    """``rockjit erosion``: the erosion profile along alpha."""
    p = add_command(sub, "erosion", _erosion_plan, grid_run("erosion", "erosion"),
                    "erosion profile: integrity and attractors of the basin along alpha",
                    "A basin at each amplitude; its attractors continued from one amplitude to the "
                    "next; write erosion.npz, erosion.png (GIM and IF against alpha, and each "
                    "attractor's basin fraction, stacked) and summary.json.")
    add_block(p, alpha=False, both=True)
    add_alphas(p, 0.01)
    p.add_argument("--grid", type=int, default=100, help="cells per side (default 100)")
    add_phase(p, "default (r0, s0) = (0, 1)")
    add_run(p, grid=True)
    p.add_argument("--full-length", action="store_true", help="disable early stopping")
    add_common(p)
    add_scheduler(p)


def add_safety_command(sub):
    """``rockjit safety``: the integrity charts."""
    p = add_command(sub, "safety", _safety_plan,
                    grid_run("safety", "safety", "safety_{}".format, _write_safety),
                    "integrity charts: the safe basin over the (alpha, omega) plane",
                    "A basin at every forcing of an (alpha, omega) grid, each reduced to its safe "
                    "fraction, GIM, IF, LIM and attractors; write safety.npz, safety_<law>.png "
                    "(the safe fraction with contours at --levels; with --law both also "
                    "safety_difference.png) and summary.json. Column by column, resumable, on "
                    "Dask with --scheduler.")
    add_block(p, alpha=False, omega=False, both=True)
    add_alphas(p, None)
    p.add_argument("--omega-range", type=float, nargs=2, required=True,
                   metavar=("START", "END"), help="frequencies (ends included)")
    p.add_argument("--grid", type=int, nargs=2, default=(20, 20), metavar=("NA", "NW"),
                   help="forcings along alpha and omega (default 20 20)")
    p.add_argument("--lattice", type=int, default=50,
                   help="initial states per side of every basin, over [-1, 1]^2 (default 50)")
    p.add_argument("--levels", type=float, nargs="+", default=[0.5, 0.9], metavar="FRACTION",
                   help="safe fractions drawn as contours (default 0.5 0.9)")
    add_phase(p, "default (r0, s0) = (0, 1)")
    add_run(p, grid=True)
    p.add_argument("--full-length", action="store_true", help="disable early stopping")
    add_common(p)
    add_scheduler(p)
