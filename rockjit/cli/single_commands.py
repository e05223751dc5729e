"""The commands of single runs: ``rockjit trajectory`` (one run) and ``rockjit fate`` (the
outcomes of an ensemble of nearby runs), each with its options, plan and run."""

from __future__ import annotations

import math
import time

from .arguments import add_block, add_command, add_common, add_forcing, add_run, add_state
from .messages import say, warn
from .options import block_of, forcing_of, integration_of, state_of


def _trajectory_plan(args):
    from ..single import simulate
    from ..validate import integer
    integer("max-points", args.max_points, 2)
    from ..single import Scipy, _method
    method = _method(args.method)  # the tolerances are checked whatever the method
    tolerances = Scipy("BDF" if method == "rockjit" else method.method, rtol=args.rtol,
                       atol=args.atol)
    method = method if method == "rockjit" else tolerances
    kw = dict(integration=integration_of(args), lyapunov=args.lyapunov, method=method)
    block, forcing, state = block_of(args), forcing_of(args), state_of(args)
    p = simulate.plan(block, forcing, state, **kw)  # settles N; then the recording's stride
    stride = max(1, math.ceil(p.periods * p.n_steps / args.max_points))
    return simulate.plan(block, forcing, state, record_stride=stride, **kw)


def _trajectory_run(args, p, out):
    from .. import outputs
    from ..single import run
    name = p.method if p.method == "rockjit" else p.method.name
    say(args, f"trajectory: {p.periods} periods, {name}")
    t0 = time.perf_counter()
    res, wall = run(p), time.perf_counter() - t0
    for note in res.caveats():
        warn(_cli_words(note))
    return wall, dict(outputs.trajectory(out, res), record_stride=p.record_stride)


def _cli_words(text):
    """A library's sentence with its parameters named as the command line spells them."""
    return text.replace("Integration.max_impacts", "--max-impacts").replace(
        "rockjit.fate", "`rockjit fate`")


def _fate_plan(args):
    from ..basins.fate import fate
    from ..settings import Execution
    return fate.plan(block_of(args), forcing_of(args), state_of(args),
                     integration=integration_of(args), ensemble=args.ensemble,
                     spread=args.spread, seed=args.seed,
                     execution=Execution(threads=args.threads, device=args.device,
                                         progress=not args.quiet))


def _fate_run(args, p, out):
    from .. import outputs
    from ..basins.fate import run
    from ..settings import Execution
    t0 = time.perf_counter()
    fr = run(p, Execution(threads=args.threads, device=args.device, progress=not args.quiet))
    wall = time.perf_counter() - t0
    say(args, "fate: " + ", ".join(f"{k} {v:.3f}" for k, v in fr.probabilities.items()))
    return wall, outputs.fate(out, fr)


def add_trajectory_command(sub):
    """``rockjit trajectory``: one run."""
    p = add_command(sub, "trajectory", _trajectory_plan, _trajectory_run, "one run",
                    "Simulate one run; write trajectory.npz (t, theta, dtheta, r, s, strobe, "
                    "strobe_half, impacts, lyapunov_running), trajectory.png and summary.json.")
    add_block(p)
    add_state(p, "default: the study's z0 = (-0.2254, -0.1597, -0.7778, 0.6284)")
    add_run(p)
    p.add_argument("--method", default="rockjit",
                   help="rockjit (compiled), scipy or scipy:<solve_ivp method> (default rockjit)")
    add_forcing(p)
    p.add_argument("--rtol", type=float, default=1e-6, help="scipy path tolerance")
    p.add_argument("--atol", type=float, default=1e-9, help="scipy path tolerance")
    p.add_argument("--rest-speed", type=float, default=1e-6,
                   help="Zeno cut-off: impact speed below which the block rests (default 1e-6)")
    p.add_argument("--lyapunov", action="store_true", help="compute Lyapunov exponents")
    p.add_argument("--max-points", type=int, default=50_000,
                   help="at most this many recorded points (default 50000)")
    add_common(p, device=False)


def add_fate_command(sub):
    """``rockjit fate``: the outcome probabilities of nearby runs."""
    p = add_command(sub, "fate", _fate_plan, _fate_run, "outcome probabilities of nearby runs",
                    "Run an ensemble from initial states perturbed by a few ulps to 1e-10 "
                    "(relative): each outcome's probability, the transient's exponent and the "
                    "predictability horizon; write fate.npz, fate.png and summary.json.")
    add_block(p)
    add_state(p, "default: the study's z0")
    add_run(p)
    add_forcing(p)
    p.add_argument("--ensemble", type=int, default=64, help="members (default 64)")
    p.add_argument("--spread", type=float, nargs=2, default=None, metavar=("LO", "HI"),
                   help="relative perturbations, log-uniform (default 8.9e-16 1e-10)")
    p.add_argument("--seed", type=int, default=0, help="seed of the perturbations")
    add_common(p)
