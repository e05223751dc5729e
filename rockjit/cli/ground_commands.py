"""The commands on pulses and ground-motion records: ``rockjit spectrum`` (a pulse's
overturning spectrum) and ``rockjit fragility`` (fragility curves by incremental dynamic
analysis), each with its options, plan and run."""

from __future__ import annotations

import os
import time

import numpy as np

from .arguments import add_block, add_command, add_common, add_scheduler, add_transient
from .grid_commands import grid_run
from .messages import say
from .options import block_of, execution_of, laws_of, run_grid


def _transient_method(args):
    """The method of ``--method --rtol --atol`` for pulses and records: ``"rockjit"`` (the
    compiled path), or the scipy path at the tolerances given."""
    from ..ground.batch import check_method
    from ..single import Scipy
    method = check_method(args.method)
    name = "DOP853" if method == "rockjit" or args.method == "scipy" else method.method
    scipy = Scipy(name, rtol=args.rtol, atol=args.atol)  # the tolerances checked either way
    return method if method == "rockjit" else scipy


def _transient(args):
    from ..ground.settings import Transient
    return Transient(free_time=args.free_time)


def _spectrum_plan(args):
    from ..plugs.pulse import RATIO_RANGE, Pulse
    from ..ground.spectrum import spectrum
    from ..validate import integer, pair
    nr, nk = (integer("grid", v, 1, 10**4) for v in args.grid)
    r0, r1 = pair("ratio-range", args.ratio_range, *RATIO_RANGE)
    k0, k1 = pair("amplitude-range", args.amplitude_range, 0.0, 1e6)
    for name, (a, b), n in (("ratio-range", (r0, r1), nr), ("amplitude-range", (k0, k1), nk)):
        if n > 1 and not a < b:
            raise ValueError(f"{name} must satisfy start < end for {n} grid points "
                             f"(got {a:g}, {b:g})")
    ratios, amplitudes = np.linspace(r0, r1, nr), np.linspace(k0, k1, nk)
    method, integration = _transient_method(args), _transient(args)
    return {law: spectrum.plan(block_of(args, law), Pulse(args.pulse), ratios, amplitudes,
                               integration=integration, method=method, tol=args.tol,
                               execution=execution_of(args))
            for law in laws_of(args)}


def _records_of(args):
    """The records of ``--records``: FEMA P695 set names and files, in order."""
    from ..ground.fema import SETS, fema_set
    from ..ground.records import read_record
    recs = []
    for item in args.records:
        if item in SETS:
            recs.extend(fema_set(item))
        elif os.path.exists(item):
            recs.append(read_record(item))
        else:
            raise ValueError(f"--records: {item!r} is neither a record set "
                             f"({', '.join(SETS)}) nor a file")
    return recs


#: Default intensities of `rockjit fragility` by measure.
_INTENSITIES = {"pga": np.round(np.arange(1.25, 6.001, 0.25), 10).tolist(),
                "pgv": np.round(np.arange(0.05, 1.0001, 0.05), 10).tolist()}


def _fragility_plan(args):
    from ..ground.fragility import fragility
    from ..validate import choice
    choice("measure", args.measure, ("pga", "pgv"))
    x = args.intensities if args.intensities is not None else _INTENSITIES[args.measure]
    laws = laws_of(args)
    block = block_of(args, laws[0])
    return fragility.plan(block, _records_of(args), args.size, x, measure=args.measure,
                          laws=laws, integration=_transient(args),
                          method=_transient_method(args), execution=execution_of(args))


def _fragility_run(args, p, out):
    from .. import outputs
    from ..ground.fragility import run
    path = "compiled path" if p.method == "rockjit" else f"scipy path ({p.method.method})"
    say(args, f"fragility: {p.runs} runs ({len(p.records)} records x "
               f"{p.intensities.size} intensities x {p.sizes.size} sizes x "
               f"{len(p.blocks)} laws) on the {path}")
    t0 = time.perf_counter()
    res = run_grid(args, run, p, "fragility")
    wall = time.perf_counter() - t0
    say(args, f"fragility: computed in {wall:.1f} s")
    return wall, outputs.fragility(out, res)


def add_spectrum_command(sub):
    """``rockjit spectrum``: the overturning spectrum of a pulse."""
    p = add_command(sub, "spectrum", _spectrum_plan,
                    grid_run("spectrum", "spectrum", "spectrum-{}".format),
                    "overturning spectrum of a pulse",
                    "Run the block from rest under a pulse at every (omega_p/p, a_p/(g cot "
                    "theta_c)) of a grid: each cell's outcome (safe, overturned after an impact, "
                    "overturned without one) and max|theta|/(pi/2 - theta_c); at every ratio "
                    "the minimum overturning amplitude and the boundary of overturning without "
                    "impact, "
                    "located by bisection to --tol. Writes spectrum.npz, spectrum.png and "
                    "summary.json (\"min_overturn\", per law with --law both). Compiled path; "
                    "--method scipy for the reference path.")
    add_block(p, alpha=False, omega=False, both=True)
    p.add_argument("--pulse", default="sine", choices=("sine", "cosine", "ricker"),
                   help="the pulse (default sine)")
    p.add_argument("--ratio-range", type=float, nargs=2, required=True,
                   metavar=("START", "END"), help="frequency ratios omega_p/p (ends included)")
    p.add_argument("--amplitude-range", type=float, nargs=2, required=True,
                   metavar=("START", "END"),
                   help="amplitude ratios a_p/(g cot theta_c) (ends included; 1 is uplift)")
    p.add_argument("--grid", type=int, nargs=2, default=(100, 100), metavar=("NR", "NK"),
                   help="points along the ratios and the amplitudes (default 100 100)")
    p.add_argument("--tol", type=float, default=1e-6,
                   help="relative width of the located boundaries (default 1e-6)")
    add_transient(p)
    add_common(p, threads=False)
    add_scheduler(p)


def add_fragility_command(sub):
    """``rockjit fragility``: fragility curves from records."""
    p = add_command(sub, "fragility", _fragility_plan, _fragility_run,
                    "fragility curves by incremental dynamic analysis",
                    "Scale every record to each intensity, run the block from rest for each "
                    "size and law, and fit lognormal fragility curves (median and dispersion by "
                    "maximum likelihood) to overturning and to max|theta|/(pi/2 - theta_c) >= "
                    "0.5, 1. Writes fragility.npz, fragility.png, rotation.png and summary.json.")
    add_block(p, alpha=False, omega=False, both=True)
    p.add_argument("--size", type=float, nargs="+", required=True, metavar="R",
                   help="the block's half-diagonal R in metres (several: the size effect)")
    p.add_argument("--records", nargs="+", required=True, metavar="SET|FILE",
                   help="farfield, nearfield, nearfield-pulse, nearfield-no-pulse (FEMA P695: "
                        "pip install 'rockjit[records]') or .AT2 / two-column (s, g) files")
    p.add_argument("--measure", default="pga", choices=("pga", "pgv"),
                   help="intensity measure: PGA/(g cot theta_c) (default) or PGV in m/s")
    p.add_argument("--intensities", type=float, nargs="+", default=None, metavar="X",
                   help="the intensities every record is scaled to (default 1.25 to 6 by "
                        "0.25 for pga, 0.05 to 1 m/s by 0.05 for pgv)")
    add_transient(p)
    add_common(p, threads=False)
    add_scheduler(p)
