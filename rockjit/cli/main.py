"""The ``rockjit`` command line: argparse and file output over the library's plans and runs.

Every command parses its options into the library's own plan (``rockjit.simulate.plan``,
``rockjit.sweep.plan`` and the others: :mod:`rockjit.entry`), which validates everything before
any work: a bad value ends the command with one line ``rockjit: error: ...`` on stderr and exit
status 2, having written nothing. Then it computes and writes its data, its figure(s) and
``summary.json`` into a hidden staging directory, published into ``--out`` as one unit at the
end (:class:`rockjit.storage.output_dir.OutputDir`). Every problem with ``--out`` itself (a
file, a dangling or looping link, a name too long, a directory named like an output file, a
place that cannot be written, a file rockjit did not write where it would write one, another
rockjit run writing into it) is found before any work, with the rest of the input; ``--out``
stays this run's until it is published (:mod:`rockjit.storage.ownership`). A figure that cannot
be drawn does not lose the data: they are published without it, a line says so, exit status 3.

One outcome per run: the exit status says whether ``--out`` was published. A command
interrupted before that (SIGINT, Ctrl-C: exit status 130; SIGTERM: 143) leaves ``--out`` as it
was; the finished chunks of its grids wait in ``<out>.chunks`` so that running the same command
again resumes. A signal once ``--out`` is published changes nothing: exit status 0, and a line
says so. An error while running (a full disk, a file system that refuses a write, a bug) is one
line ``rockjit: error: ...`` or ``rockjit: internal error: ...`` on stderr with its traceback in a
report file, exit status 1, ``--out`` as it was.

JSON files write non-finite numbers as the strings ``"nan"``, ``"inf"``, ``"-inf"``
(:mod:`rockjit.storage.atomic`).
"""

from __future__ import annotations

import argparse
import contextlib
import functools
import importlib
import math
import os
import re
import signal
import sys
import time
import warnings
from pathlib import Path

import numpy as np

from .. import __version__

__all__ = ["build_parser", "main"]

PROG = "rockjit"


class UsageError(Exception):
    """Bad command-line input: reported in one line, exit status 2."""


class _Parser(argparse.ArgumentParser):
    """argparse with one-line errors; the options declared ``type=float`` and ``type=int``
    parsed by :func:`_real` and :func:`_int` (exactly ASCII decimal numbers); and anything that
    starts like a negative number taken as a value (``--theta0 -1e-3``, ``--dtheta0 -inf``, and
    ``-1_0`` too, for the number parser to refuse), not as an option."""

    def __init__(self, *a, **kw):
        super().__init__(*a, **kw)
        self.register("type", float, _real)
        self.register("type", int, _int)
        self._negative_number_matcher = re.compile(r"^-(\.?\d|(inf|infinity|nan)$)",
                                                   re.IGNORECASE)

    def error(self, message):
        raise UsageError(message)


# ---------------------------------------------------------------------------------------------
# the values of options: exactly ASCII decimal numbers, a Dask scheduler's address
# ---------------------------------------------------------------------------------------------

_DECIMAL = re.compile(r"[+-]?([0-9]+(\.[0-9]*)?|\.[0-9]+)([eE][+-]?[0-9]+)?")
_NONFINITE = re.compile(r"[+-]?(inf|infinity|nan)", re.IGNORECASE)
_INTEGER = re.compile(r"[+-]?[0-9]+")


def _real(text):
    """A real number option: ``[+-]digits[.digits][e[+-]digits]`` in ASCII, or ``inf``, ``nan``
    (the range checks refuse those, naming the option); no ``_``, no other digits or spaces."""
    if _DECIMAL.fullmatch(text) or _NONFINITE.fullmatch(text):
        return float(text)
    raise argparse.ArgumentTypeError(f"must be a number such as 0.5, -2 or 1e-3 (got {text!r})")


def _int(text):
    """An integer option: ``[+-]digits`` in ASCII."""
    if _INTEGER.fullmatch(text):
        try:
            return int(text)
        except ValueError:  # more digits than Python converts
            raise argparse.ArgumentTypeError(f"is too large ({len(text)} digits)") from None
    raise argparse.ArgumentTypeError(f"must be an integer such as 100 (got {text!r})")


_ADDRESS = re.compile(r"(?:(?P<scheme>[A-Za-z][A-Za-z0-9+.-]*)://)?"
                      r"(?P<host>\[[0-9A-Fa-f:.]+\]|[A-Za-z0-9_.-]+)(?::(?P<port>[0-9]+))?")


def _scheduler(text):
    """``--scheduler``: a Dask scheduler's address, ``tcp://HOST:PORT`` (or ``tls://``, or
    ``HOST:PORT``) with 1 <= PORT <= 65535, or the path of an existing scheduler file (written by
    ``dask scheduler --scheduler-file``). Checked before connecting."""
    if not text.strip():
        raise argparse.ArgumentTypeError("must be a Dask scheduler's address, tcp://HOST:PORT, "
                                         "or a scheduler file (got an empty string)")
    if "://" not in text and os.path.isfile(text):
        return text
    m = _ADDRESS.fullmatch(text)
    scheme = (m.group("scheme") or "tcp").lower() if m else None
    if m is None or scheme not in ("tcp", "tls") or ("://" not in text and not m.group("port")):
        hint = (" (no such scheduler file)" if "://" not in text and ":" not in text else "")
        raise argparse.ArgumentTypeError(f"must be a Dask scheduler's address, tcp://HOST:PORT, "
                                         f"or an existing scheduler file (got {text!r}){hint}")
    port = m.group("port")
    if port is not None and not 1 <= int(port) <= 65535:
        raise argparse.ArgumentTypeError(f"port must be in [1, 65535] (got {int(port)} in "
                                         f"{text!r})")
    return text


def _say(args, msg):  # progress and notes: silenced by --quiet
    if not args.quiet:
        print(f"{PROG}: {msg}", file=sys.stderr, flush=True)


def _warn(msg):
    print(f"{PROG}: warning: {' '.join(str(msg).split())}", file=sys.stderr, flush=True)


# ---------------------------------------------------------------------------------------------
# checks of the command line's own options (the library checks the rest)
# ---------------------------------------------------------------------------------------------

#: The files each command writes into --out besides summary.json (names or fnmatch patterns):
#: a directory of one of these names inside --out is refused before any work.
OUTPUTS = {
    "trajectory": ("trajectory.npz", "trajectory.*"),
    "sweep": ("sweep.npz", "bifurcation.*"),
    "basin": ("basin.npz", "basin.*", "attractors.*"),
    "plane": ("plane.npz", "plane.*"),
    "erosion": ("erosion.npz", "erosion.*"),
    "safety": ("safety.npz", "safety_*"),
    "orbits": ("orbits.npz", "orbits.*"),
    "fate": ("fate.npz", "fate.*"),
    "cor": ("restitution.*", "e_table.csv", "e_table.md"),
    "paper": ("fig*", "*_table.csv", "*_table.md", "index.html"),
    "chart": ("chart.npz", "chart.*"),
    "spectrum": ("spectrum.npz", "spectrum.*"),
    "fragility": ("fragility.npz", "fragility.*", "rotation.*"),
}
#: The commands whose grids keep their finished chunks in <out>.chunks.
CHUNKED = ("sweep", "basin", "plane", "erosion", "safety", "orbits", "chart", "paper",
           "spectrum", "fragility")


#: Commands whose cells run on the CPU only (the pulses' and records' kernel), by what they run.
CPU_ONLY = {"spectrum": "spectra", "fragility": "fragility curves"}


def _check_device(args):
    """``--device cuda`` is refused in one line, before any work, where it cannot run: for the
    commands whose cells run on the CPU only, and on a machine without a usable GPU."""
    if getattr(args, "device", "cpu") == "cuda":
        from ..settings import cuda_refusal, cuda_unsupported
        if args.command in CPU_ONLY:
            raise UsageError(cuda_unsupported(CPU_ONLY[args.command], "--device cuda",
                                              "--device cpu"))
        refusal = cuda_refusal("--device cuda", "--device cpu")
        if refusal is not None:
            raise UsageError(refusal)


def _check_run(args):
    """``--threads`` fits numba's; the scipy path's tolerances are valid numbers whatever the
    method; ``--scheduler`` needs dask and ``--scheduler-timeout`` is a positive time; ``--out``
    can be written (:func:`rockjit.storage.output_dir.check_out`)."""
    from ..validate import integer, real
    if getattr(args, "threads", None) is not None:
        import numba
        integer("threads", args.threads, 1, numba.config.NUMBA_NUM_THREADS)
    if getattr(args, "rtol", None) is not None:  # as rockjit.simulate.plan checks them for scipy
        real("rtol", args.rtol, 0.0, 1.0, lo_open=True, hi_open=True)
        real("atol", args.atol, 0.0, None, lo_open=True)
    if getattr(args, "scheduler_timeout", None) is not None:
        real("--scheduler-timeout", args.scheduler_timeout, 0.0, 1e6, lo_open=True)
    if getattr(args, "scheduler", None):
        try:
            import dask.distributed  # noqa: F401
        except ImportError:
            raise UsageError("--scheduler needs dask: pip install 'rockjit[dask]'") from None
    from ..storage.output_dir import check_out
    check_out(args.out, name="--out", files=OUTPUTS.get(args.command, ()),
              chunks=args.command in CHUNKED)


def _chunk_root(args):
    from ..storage.output_dir import chunk_root
    return chunk_root(args.out)


#: Seconds to wait for a Dask scheduler to answer (at most; --scheduler-timeout if shorter).
CONNECT_TIMEOUT = 15.0


def _client(args):  # a Dask client for --scheduler, or None
    if not getattr(args, "scheduler", None):
        return None
    from dask.distributed import Client
    _say(args, f"{args.command}: connecting to the Dask scheduler at {args.scheduler}")
    timeout = min(CONNECT_TIMEOUT, args.scheduler_timeout)
    file = "://" not in args.scheduler and os.path.isfile(args.scheduler)
    try:
        if file:
            return Client(scheduler_file=args.scheduler, timeout=f"{timeout}s")
        return Client(args.scheduler, timeout=f"{timeout}s")
    except Exception as exc:  # OSError, TimeoutError, a bad scheduler file, ...
        raise UsageError(f"--scheduler {args.scheduler}: cannot reach the Dask scheduler "
                         f"({type(exc).__name__}: {exc})") from None


def _block(args, law=None):
    """The block of ``--hb --law --e --xi`` (``law``: one of ``--law both``'s)."""
    from ..model import XI_STUDY, Block
    return Block(hb=args.hb, law=law or args.law, e=args.e,
                 xi=XI_STUDY if args.xi is None else args.xi)


def _laws(args):
    """The laws a command runs: ``--law both`` is Housner's and Mao's."""
    if args.law == "both":
        if args.e is not None:
            raise UsageError("--e goes with --law constant, not --law both")
        return ("housner", "mao")
    if args.law is None:  # as the library: --e alone selects the constant law
        return ("housner" if args.e is None else "constant",)
    return (args.law,)


def _forcing(args, alpha=True, omega=True):
    """The harmonic forcing of ``--alpha --omega --phase/--r0 --s0 --forcing``."""
    from ..excitation import Harmonic
    try:
        return Harmonic(alpha=args.alpha if alpha else None,
                        omega=args.omega if omega else None, phase=getattr(args, "phase", None),
                        r0=getattr(args, "r0", None), s0=getattr(args, "s0", None),
                        embedded=getattr(args, "forcing", "closed") == "embedded")
    except ValueError as exc:  # the library's hint, in the options this command has
        text = str(exc)
        hint = "; use Harmonic(..., embedded=True) for a start off the circle"
        if hint in text:
            text = text.replace(hint, "; use --forcing embedded for a start off the circle"
                                if hasattr(args, "forcing") else
                                "; give a point on the circle, or --phase")
        raise ValueError(text) from None


def _state(args):
    """``(--theta0, --dtheta0)`` (0 where one is left out), or ``None`` for the study's."""
    if args.theta0 is None and args.dtheta0 is None:
        return None
    return (args.theta0 or 0.0, args.dtheta0 or 0.0)


def _integration(args):
    from ..settings import Integration
    kw = dict(periods=args.periods, n_steps=getattr(args, "n_steps", None),
              max_impacts=getattr(args, "max_impacts", None),
              stop_at_overturn=not getattr(args, "continue_past_overturn", False))
    if getattr(args, "rest_speed", None) is not None:
        kw["rest_speed"] = args.rest_speed
    return Integration(**kw)


def _classification(args):
    from ..settings import Classification
    return Classification(early_stop=not getattr(args, "full_length", False),
                          uncertainty=getattr(args, "uncertainty", None))


def _execution(args, client=None, name=None):
    """Threads, progress, the chunk store ``<out>.chunks[/name]`` and the Dask client."""
    from ..settings import Execution
    root = _chunk_root(args)
    return Execution(threads=getattr(args, "threads", None), progress=not args.quiet,
                     device=getattr(args, "device", "cpu"),
                     client=client, store=root / name if name else root,
                     message=lambda m: _say(args, m))


def _alphas(args):
    """The amplitudes of ``--alpha-range --alpha-step``, their number checked first."""
    from .._engine import kernel
    from ..grids.plan import alpha_count, alpha_grid
    from ..validate import memory
    *_, n = alpha_count(args.alpha_range, args.alpha_step)
    memory(f"--alpha-step {args.alpha_step:g} over --alpha-range ({n:.3g} amplitudes)",
           kernel.grid_bytes(n, 1, 8, 101, 400, True, 1, 1))
    return alpha_grid(args.alpha_range, args.alpha_step)


# ---------------------------------------------------------------------------------------------
# the commands: plan (validation only) and run (compute, write into the staging directory)
# ---------------------------------------------------------------------------------------------

def _trajectory_plan(args):
    from ..single import simulate
    from ..validate import integer
    integer("max-points", args.max_points, 2)
    from ..single import Scipy, _method
    method = _method(args.method)  # the tolerances are checked whatever the method
    tolerances = Scipy("BDF" if method == "rockjit" else method.method, rtol=args.rtol,
                       atol=args.atol)
    method = method if method == "rockjit" else tolerances
    kw = dict(integration=_integration(args), lyapunov=args.lyapunov, method=method)
    block, forcing, state = _block(args), _forcing(args), _state(args)
    p = simulate.plan(block, forcing, state, **kw)  # settles N; then the recording's stride
    stride = max(1, math.ceil(p.periods * p.n_steps / args.max_points))
    return simulate.plan(block, forcing, state, record_stride=stride, **kw)


def _trajectory_run(args, p, out):
    from .. import outputs
    from ..single import run
    name = p.method if p.method == "rockjit" else p.method.name
    _say(args, f"trajectory: {p.periods} periods, {name}")
    t0 = time.perf_counter()
    res, wall = run(p), time.perf_counter() - t0
    for note in res.caveats():
        _warn(_cli_words(note))
    return wall, dict(outputs.trajectory(out, res), record_stride=p.record_stride)


def _cli_words(text):
    """A library's sentence with its parameters named as the command line spells them."""
    return text.replace("Integration.max_impacts", "--max-impacts").replace(
        "rockjit.fate", "`rockjit fate`")


def _sweep_plan(args):
    from ..grids import sweep
    return sweep.plan(_block(args), _forcing(args, alpha=False), _alphas(args), _state(args),
                      integration=_integration(args), classification=_classification(args),
                      lyapunov=not args.no_lyapunov, execution=_execution(args))


def _basin_plan(args):
    from ..grids import basin
    from ..settings import Lattice
    from ..validate import memory
    lattice = Lattice(args.grid, tuple(args.theta_range), tuple(args.dtheta_range))
    plans = {law: basin.plan(_block(args, law), _forcing(args), lattice,
                             integration=_integration(args),
                             classification=_classification(args), lyapunov=args.lyapunov,
                             execution=_execution(args))
             for law in _laws(args)}
    memory(f"--grid {args.grid} for {len(plans)} laws", sum(p.memory_bytes for p in plans.values()))
    return plans


def _plane_plan(args):
    from ..grids import plane
    phase = _forcing(args, alpha=False, omega=False)
    return plane.plan(_block(args), args.alpha_range, args.omega_range, grid=args.grid,
                      state=_state(args), forcing=phase, integration=_integration(args),
                      classification=_classification(args), lyapunov=not args.no_lyapunov,
                      execution=_execution(args))


def _erosion_plan(args):
    from ..basins.erosion import erosion
    from ..grids.plan import alpha_count, grid_memory
    from ..single import settings_for
    # the whole profile's memory before the amplitudes' array is made
    *_, n = alpha_count(args.alpha_range, args.alpha_step)
    integration, execution = _integration(args), _execution(args)
    probe = _forcing(args, alpha=False).replace(alpha=args.alpha_range[0])
    n_steps, _, _ = settings_for(_block(args, _laws(args)[0]), probe, integration, 64)
    grid_memory(f"--alpha-range and --alpha-step ({n} amplitudes) at --grid {args.grid}",
                float(args.grid) ** 2 * n, dict(periods=args.periods, n_steps=n_steps),
                execution, 16)
    alphas = _alphas(args)
    if len(_laws(args)) > 1:
        grid_memory(f"--grid {args.grid} at {n} amplitudes for {len(_laws(args))} laws",
                    float(args.grid) ** 2 * n * len(_laws(args)),
                    dict(periods=args.periods, n_steps=n_steps), execution, 16)
    return {law: erosion.plan(_block(args, law), _forcing(args, alpha=False), alphas, args.grid,
                              integration=integration, classification=_classification(args),
                              execution=execution)
            for law in _laws(args)}


def _safety_plan(args):
    """``rockjit safety``: one :func:`rockjit.safety` plan per law, the contour levels
    checked."""
    from ..integrity.chart import safety
    from ..validate import real
    for v in args.levels:
        real("--levels", v, 0.0, 1.0)
    phase = _forcing(args, alpha=False, omega=False)
    return {law: safety.plan(_block(args, law), tuple(args.alpha_range),
                             tuple(args.omega_range), grid=tuple(args.grid),
                             lattice=args.lattice, forcing=phase,
                             integration=_integration(args),
                             classification=_classification(args), execution=_execution(args))
            for law in _laws(args)}


def _write_safety(out, res, args):
    from ..integrity.figure import write
    return write(out, res, tuple(args.levels))


#: The module whose ``run`` computes a grid command's plans (``rockjit.grids.plan`` where the
#: command is not listed); looked up when the command runs.
_GRID_RUNS = {"erosion": "rockjit.basins.erosion", "orbits": "rockjit.orbits.arclength",
              "safety": "rockjit.integrity.chart", "spectrum": "rockjit.ground.spectrum"}


def _grid_run(writer, name, store=None, write=None):
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
            res = {law: _grid(args, run, p, store(law) if store else law)
                   for law, p in plans.items()}
        else:
            res = _grid(args, run, plans, name)
        wall = time.perf_counter() - t0
        _say(args, f"{args.command}: computed in {wall:.1f} s")
        if write is not None:
            return wall, write(out, res, args)
        return wall, getattr(outputs, writer)(out, res)
    return run_it


def _orbits_plan(args):
    from ..orbits import ContinuationSettings, orbits_of_sweep
    from ..settings import Integration
    return orbits_of_sweep.plan(_block(args), _forcing(args, alpha=False),
                                tuple(args.alpha_range), alpha_step=args.alpha_step,
                                integration=Integration(periods=args.periods),
                                settings=ContinuationSettings(max_period=args.max_period),
                                execution=_execution(args))


def _chart_plan(args):
    """``rockjit chart``: one :func:`rockjit.chart` plan per law (``--law both``: two)."""
    from ..orbits.plane_chart import ChartCurves, chart
    from ..validate import memory
    curves = ChartCurves(seed_omegas=args.seed_omegas, max_period=args.max_period)
    plans = {law: chart.plan(_block(args, law), tuple(args.alpha_range),
                             tuple(args.omega_range), grid=tuple(args.grid), curves=curves,
                             integration=_integration(args), lyapunov=args.lyapunov,
                             execution=_execution(args))
             for law in _laws(args)}
    memory(f"--grid {args.grid[0]} {args.grid[1]} for {len(plans)} laws",
           sum(p.plane_plan.memory_bytes for p in plans.values()))
    return plans


def _chart_run(args, plans, out):
    from .. import outputs
    from ..orbits.plane_chart import run
    t0 = time.perf_counter()
    res = {}
    for law, p in plans.items():
        _say(args, f"chart: {law}, {p.plane_plan.shape[1]} x {p.plane_plan.shape[2]} cells, "
                   f"then the curves from {len(p.seed_omegas)} omega lines")
        res[law] = _grid(args, run, p, f"chart_{law}")
        _say(args, f"chart: {law}: {len(res[law].curves)} curves "
                   f"({', '.join(f'{k} {v:.1f} s' for k, v in res[law].timing.items())})")
    results = outputs.chart(out, res)
    results.pop("figure")
    return time.perf_counter() - t0, results


def _fate_plan(args):
    from ..basins.fate import fate
    from ..settings import Execution
    return fate.plan(_block(args), _forcing(args), _state(args),
                     integration=_integration(args), ensemble=args.ensemble,
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
    _say(args, "fate: " + ", ".join(f"{k} {v:.3f}" for k, v in fr.probabilities.items()))
    return wall, outputs.fate(out, fr)


def _cor_plan(args):
    from ..model import Block
    from ..validate import real
    [Block(hb=hb, law="housner") for hb in args.hb_values]
    real("hb_max", args.hb_max, 1 / math.sqrt(2), 100.0, lo_open=True)


def _cor_run(args, _, out):
    from ..study.paper import write_e_table
    t0 = time.perf_counter()
    table = write_e_table(out, args.hb_values, args.hb_max, "restitution.png", "e_table")
    return time.perf_counter() - t0, dict(table=table)


def _paper_plan(args):
    from ..study.paper import plan_paper
    return plan_paper(grid=args.grid, periods=args.periods, n_steps=args.n_steps,
                      alpha_step=args.alpha_step, zoom=args.zoom, zoom_step=args.zoom_step,
                      erosion_step=args.erosion_step, erosion_grid=args.erosion_grid,
                      as_published=args.as_published, execution=_execution(args))


def _paper_run(args, p, out):
    from ..study.paper import paper
    t0 = time.perf_counter()
    results = _grid(args, lambda plan, ex: paper(out, plan, execution=ex,
                                                 say=lambda m: _say(args, m)), p, None)
    return time.perf_counter() - t0, results


def _explore_plan(args):
    """``rockjit explore``: the explorer's server (:mod:`rockjit.explorer`), served until Ctrl-C.
    It writes no ``--out``: the command ends here, with exit status 0, instead of going on to
    the file-writing run of the other commands; a bad ``--port`` or ``--address`` is a usage
    error (exit status 2) like any other."""
    from ..explorer import explore
    try:
        explore(port=args.port, address=args.address, browser=not args.no_browser, block=True,
                allow_hosts=args.allow_host or ())
    except ImportError as exc:  # the explore extra is not installed
        raise UsageError(str(exc)) from None
    except KeyboardInterrupt:
        print(f"\n{PROG}: explore: stopped", file=sys.stderr, flush=True)
    raise SystemExit(0)


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
    from ..ground.pulses import RATIO_RANGE, Pulse
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
    return {law: spectrum.plan(_block(args, law), Pulse(args.pulse), ratios, amplitudes,
                               integration=integration, method=method, tol=args.tol,
                               execution=_execution(args))
            for law in _laws(args)}


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
    laws = _laws(args)
    block = _block(args, laws[0])
    return fragility.plan(block, _records_of(args), args.size, x, measure=args.measure,
                          laws=laws, integration=_transient(args),
                          method=_transient_method(args), execution=_execution(args))


def _fragility_run(args, p, out):
    from .. import outputs
    from ..ground.fragility import run
    path = "compiled path" if p.method == "rockjit" else f"scipy path ({p.method.method})"
    _say(args, f"fragility: {p.runs} runs ({len(p.records)} records x "
               f"{p.intensities.size} intensities x {p.sizes.size} sizes x "
               f"{len(p.blocks)} laws) on the {path}")
    t0 = time.perf_counter()
    res = _grid(args, run, p, "fragility")
    wall = time.perf_counter() - t0
    _say(args, f"fragility: computed in {wall:.1f} s")
    return wall, outputs.fragility(out, res)


def _grid(args, run, plan, name):
    """``run(plan, execution)`` with the command line's progress, Dask client
    (``--scheduler``) and chunk store (``<out>.chunks/name``), the store's notes on stderr
    unless ``--quiet``."""
    client = _client(args)
    try:
        return run(plan, _execution(args, client, name))
    finally:
        if client is not None:
            client.close()


# ---------------------------------------------------------------------------------------------
# the parser
# ---------------------------------------------------------------------------------------------

def _law_names(both):
    """The ``--law`` values in words: the registered laws' names (rockjit.laws), and ``both``
    (Housner's and Mao's) where a command compares two laws."""
    from ..laws import names
    options = list(names()) + (["both"] if both else [])
    return ", ".join(options[:-1]) + " or " + options[-1]


def _add_block(p, alpha=True, omega=True, both=False):
    p.add_argument("--hb", type=float, required=True, help="slenderness h/b")
    p.add_argument("--law", default=None,
                   help=f"restitution law: {_law_names(both)} (default housner, or constant "
                        f"with --e)")
    p.add_argument("--e", type=float, default=None,
                   help="constant coefficient of restitution in [0, 1] (with --law constant)")
    p.add_argument("--xi", type=float, default=None,
                   help="viscous damping (default the study's 2.208e-4)")
    if alpha:
        p.add_argument("--alpha", type=float, required=True, help="forcing amplitude A/R")
    if omega:
        p.add_argument("--omega", type=float, required=True,
                       help="forcing frequency Omega/Omega0")


def _add_run(p, periods=500, grid=False):
    from ..grids.plan import GRID_N
    from ..single import DEFAULT_N, MAX_STEP
    p.add_argument("--periods", type=int, default=periods,
                   help=f"forcing periods to integrate (default {periods})")
    p.add_argument("--n-steps", type=int, default=None,
                   help=f"steps per forcing period, even (default {GRID_N if grid else DEFAULT_N}"
                        f", raised if T/N > {MAX_STEP} or for strong damping)")
    p.add_argument("--max-impacts", type=int, default=None,
                   help="impact bound (default 10,000 per period, at least 100,000)")
    p.add_argument("--continue-past-overturn", action="store_true",
                   help="integrate on past |theta| = pi/2 as the study did (such runs still "
                        "count as overturned)")


def _add_state(p, default_note):
    p.add_argument("--theta0", type=float, default=None, help="initial angle")
    p.add_argument("--dtheta0", type=float, default=None, help="initial angular velocity")
    _add_phase(p, default_note)


def _add_phase(p, default_note):
    g = p.add_mutually_exclusive_group()
    g.add_argument("--phase", type=float, default=None,
                   help="forcing phase phi in r = sin(omega t + phi)")
    g.add_argument("--r0", type=float, default=None, help="forcing oscillator r(0) (with --s0)")
    p.add_argument("--s0", type=float, default=None,
                   help=f"forcing oscillator s(0) (with --r0); {default_note}")


def _add_forcing(p):
    p.add_argument("--forcing", default="closed", choices=("closed", "embedded"),
                   help="closed-form forcing or the 4-D oscillator embedding")


def _add_common(p, threads=True, device=True):
    p.add_argument("--out", required=True, help="output directory (created if missing)")
    p.add_argument("--style", default="default", choices=("default", "paper"),
                   help="figures with titles (default, 200 dpi) or for a journal's captions "
                        "(paper: no figure titles, 300 dpi); both 3.5 or 7.2 inches wide with "
                        "7-9 point type")
    p.add_argument("--format", default="png", choices=("png", "pdf", "svg"),
                   help="format of the figures (default png)")
    if threads:
        p.add_argument("--threads", type=int, default=None,
                       help="numba threads (default all); results do not depend on it")
    if device:
        p.add_argument("--device", default="cpu", choices=("cpu", "cuda"),
                       help="where the cells run: the CPU's cores (default) or an NVIDIA GPU "
                            "(needs its driver and numba-cuda: pip install 'rockjit[cuda]')")
    p.add_argument("--quiet", action="store_true", help="no progress on stderr")


def _add_grid_run(p, lyapunov_default):
    """Options of the grid commands (sweep, basin, plane)."""
    _add_run(p, grid=True)
    if lyapunov_default:
        p.add_argument("--no-lyapunov", action="store_true",
                       help="skip the exponents (chaotic is then reported as aperiodic)")
    else:
        p.add_argument("--lyapunov", action="store_true",
                       help="compute exponents (tells chaotic from aperiodic)")
    p.add_argument("--full-length", action="store_true", help="disable early stopping")
    p.add_argument("--uncertainty", type=float, default=None, metavar="EPS",
                   help="flag the cells whose outcome changes when their initial state moves "
                        "by EPS (relative); runs the grid twice")
    _add_common(p)
    _add_scheduler(p)


def _add_scheduler(p):
    p.add_argument("--scheduler", default=None, metavar="ADDRESS", type=_scheduler,
                   help="run the chunks of cells on this Dask scheduler (tcp://host:8786, or "
                        "a scheduler file); default in this process")
    p.add_argument("--scheduler-timeout", type=float, default=60.0, metavar="SECONDS",
                   help="give up when the scheduler has had no worker for this long "
                        "(default 60)")


def _add_transient(p):
    """Options of the commands on pulses and records (spectrum, fragility)."""
    p.add_argument("--free-time", type=float, default=100.0,
                   help="model time units of free rocking after the excitation (default 100; "
                        "each run stops earlier once its outcome is decided)")
    p.add_argument("--method", default="rockjit",
                   help="rockjit (the compiled path, default), scipy (DOP853) or "
                        "scipy:<solve_ivp method>")
    p.add_argument("--rtol", type=float, default=1e-10,
                   help="scipy path tolerance (default 1e-10)")
    p.add_argument("--atol", type=float, default=1e-12,
                   help="scipy path tolerance (default 1e-12)")


def _add_alphas(p, step):
    p.add_argument("--alpha-range", type=float, nargs=2, required=True,
                   metavar=("START", "END"), help="amplitudes from START to END (included)")
    if step is not None:
        p.add_argument("--alpha-step", type=float, default=step, help=f"step (default {step})")


def _command(sub, name, plan, run, help, description):
    p = sub.add_parser(name, help=help, description=description)
    p.set_defaults(plan=plan, run=run)
    return p


def build_parser():
    """The argument parser (its ``error`` raises :class:`UsageError`)."""
    from ..study.paper import E_FIGURE_HB_MAX, E_TABLE_HB, ZOOM
    parser = _Parser(prog=PROG, description="The harmonically forced rigid rocking block "
                     "(Housner's model): single runs, bifurcation sweeps, basins, figures.")
    parser.add_argument("--version", action="version", version=f"%(prog)s {__version__}")
    sub = parser.add_subparsers(dest="command", required=True, metavar="COMMAND",
                                parser_class=_Parser)

    p = _command(sub, "trajectory", _trajectory_plan, _trajectory_run, "one run",
                 "Simulate one run; write trajectory.npz (t, theta, dtheta, r, s, strobe, "
                 "strobe_half, impacts, lyapunov_running), trajectory.png and summary.json.")
    _add_block(p)
    _add_state(p, "default: the study's z0 = (-0.2254, -0.1597, -0.7778, 0.6284)")
    _add_run(p)
    p.add_argument("--method", default="rockjit",
                   help="rockjit (compiled), scipy or scipy:<solve_ivp method> (default rockjit)")
    _add_forcing(p)
    p.add_argument("--rtol", type=float, default=1e-6, help="scipy path tolerance")
    p.add_argument("--atol", type=float, default=1e-9, help="scipy path tolerance")
    p.add_argument("--rest-speed", type=float, default=1e-6,
                   help="Zeno cut-off: impact speed below which the block rests (default 1e-6)")
    p.add_argument("--lyapunov", action="store_true", help="compute Lyapunov exponents")
    p.add_argument("--max-points", type=int, default=50_000,
                   help="at most this many recorded points (default 50000)")
    _add_common(p, device=False)

    p = _command(sub, "sweep", _sweep_plan, _grid_run("sweep", "sweep"), "sweep over alpha",
                 "Sweep the forcing amplitude; write sweep.npz, bifurcation.png and "
                 "summary.json (fractions of each behaviour).")
    _add_block(p, alpha=False)
    _add_alphas(p, 0.001)
    _add_state(p, "default: the study's z0")
    _add_grid_run(p, lyapunov_default=True)

    p = _command(sub, "basin", _basin_plan, _grid_run("basins", "basin"), "basin of attraction",
                 "Classify a grid of initial states (theta0, dtheta0); write basin.npz "
                 "(label[i, j] belongs to theta0[i], dtheta0[j]), basin.png and summary.json "
                 "(percentages; with --law both, per law and the agreement).")
    _add_block(p, both=True)
    p.add_argument("--grid", type=int, default=100, help="cells per side (default 100)")
    p.add_argument("--theta-range", type=float, nargs=2, default=(-1.0, 1.0),
                   metavar=("LO", "HI"), help="theta0 range (default -1 1)")
    p.add_argument("--dtheta-range", type=float, nargs=2, default=(-1.0, 1.0),
                   metavar=("LO", "HI"), help="dtheta0 range (default -1 1)")
    _add_phase(p, "default (r0, s0) = (0, 1)")
    _add_grid_run(p, lyapunov_default=False)

    p = _command(sub, "plane", _plane_plan, _grid_run("plane", "plane"), "the (alpha, omega) plane",
                 "Classify a grid over the forcing plane (alpha, omega) from one initial state; "
                 "write plane.npz (label[i, j] belongs to alpha[i], omega[j]), plane.png and "
                 "summary.json. Runs in-process or, with --scheduler, on a Dask cluster; an "
                 "interrupted run resumes.")
    _add_block(p, alpha=False, omega=False)
    _add_alphas(p, None)
    p.add_argument("--omega-range", type=float, nargs=2, required=True,
                   metavar=("START", "END"), help="frequencies (ends included)")
    p.add_argument("--grid", type=int, nargs=2, default=(50, 50), metavar=("NA", "NW"),
                   help="points along alpha and omega (default 50 50)")
    _add_state(p, "default: the study's z0")
    _add_grid_run(p, lyapunov_default=True)

    p = _command(sub, "erosion", _erosion_plan, _grid_run("erosion", "erosion"),
                 "erosion profile: integrity and attractors of the basin along alpha",
                 "A basin at each amplitude; its attractors continued from one amplitude to the "
                 "next; write erosion.npz, erosion.png (GIM and IF against alpha, and each "
                 "attractor's basin fraction, stacked) and summary.json.")
    _add_block(p, alpha=False, both=True)
    _add_alphas(p, 0.01)
    p.add_argument("--grid", type=int, default=100, help="cells per side (default 100)")
    _add_phase(p, "default (r0, s0) = (0, 1)")
    _add_run(p, grid=True)
    p.add_argument("--full-length", action="store_true", help="disable early stopping")
    _add_common(p)
    _add_scheduler(p)

    p = _command(sub, "safety", _safety_plan,
                 _grid_run("safety", "safety", "safety_{}".format, _write_safety),
                 "integrity charts: the safe basin over the (alpha, omega) plane",
                 "A basin at every forcing of an (alpha, omega) grid, each reduced to its safe "
                 "fraction, GIM, IF, LIM and attractors; write safety.npz, safety_<law>.png "
                 "(the safe fraction with contours at --levels; with --law both also "
                 "safety_difference.png) and summary.json. Column by column, resumable, on "
                 "Dask with --scheduler.")
    _add_block(p, alpha=False, omega=False, both=True)
    _add_alphas(p, None)
    p.add_argument("--omega-range", type=float, nargs=2, required=True,
                   metavar=("START", "END"), help="frequencies (ends included)")
    p.add_argument("--grid", type=int, nargs=2, default=(20, 20), metavar=("NA", "NW"),
                   help="forcings along alpha and omega (default 20 20)")
    p.add_argument("--lattice", type=int, default=50,
                   help="initial states per side of every basin, over [-1, 1]^2 (default 50)")
    p.add_argument("--levels", type=float, nargs="+", default=[0.5, 0.9], metavar="FRACTION",
                   help="safe fractions drawn as contours (default 0.5 0.9)")
    _add_phase(p, "default (r0, s0) = (0, 1)")
    _add_run(p, grid=True)
    p.add_argument("--full-length", action="store_true", help="disable early stopping")
    _add_common(p)
    _add_scheduler(p)

    p = _command(sub, "orbits", _orbits_plan, _grid_run("orbits", "sweep"),
                 "periodic orbits continued in alpha, bifurcations located",
                 "Seed from every periodic attractor of a sweep, follow each orbit both ways "
                 "in alpha (stable and unstable), locate its bifurcations; write orbits.npz, "
                 "orbits.png (branches over the sweep) and summary.json (\"bifurcations\").")
    _add_block(p, alpha=False)
    _add_alphas(p, 0.001)
    p.add_argument("--periods", type=int, default=500, help="periods of the seeding sweep")
    p.add_argument("--max-period", type=int, default=8, help="longest period followed")
    _add_common(p)
    _add_scheduler(p)

    p = _command(sub, "chart", _chart_plan, _chart_run,
                 "the (alpha, omega) plane with its bifurcation curves",
                 "The brute-force chart of behaviours from the study's z0 over the forcing "
                 "plane and the fold, "
                 "symmetry-breaking, period-doubling and grazing curves across it, followed by "
                 "continuation from the bifurcations located along alpha on a few omega lines; "
                 "write chart.npz, chart.png (with --law both: both laws side by side and "
                 "their curves on one chart) and summary.json (\"curves\": type, period, law, "
                 "points).")
    _add_block(p, alpha=False, omega=False, both=True)
    _add_alphas(p, None)
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
    _add_common(p)
    _add_scheduler(p)

    p = _command(sub, "fate", _fate_plan, _fate_run, "outcome probabilities of nearby runs",
                 "Run an ensemble from initial states perturbed by a few ulps to 1e-10 "
                 "(relative): each outcome's probability, the transient's exponent and the "
                 "predictability horizon; write fate.npz, fate.png and summary.json.")
    _add_block(p)
    _add_state(p, "default: the study's z0")
    _add_run(p)
    _add_forcing(p)
    p.add_argument("--ensemble", type=int, default=64, help="members (default 64)")
    p.add_argument("--spread", type=float, nargs=2, default=None, metavar=("LO", "HI"),
                   help="relative perturbations, log-uniform (default 8.9e-16 1e-10)")
    p.add_argument("--seed", type=int, default=0, help="seed of the perturbations")
    _add_common(p)

    p = _command(sub, "spectrum", _spectrum_plan,
                 _grid_run("spectrum", "spectrum", "spectrum-{}".format),
                 "overturning spectrum of a pulse",
                 "Run the block from rest under a pulse at every (omega_p/p, a_p/(g cot "
                 "theta_c)) of a grid: each cell's outcome (safe, overturned after an impact, "
                 "overturned without one) and max|theta|/(pi/2 - theta_c); at every ratio "
                 "the minimum overturning amplitude and the boundary of overturning without "
                 "impact, "
                 "located by bisection to --tol. Writes spectrum.npz, spectrum.png and "
                 "summary.json (\"min_overturn\", per law with --law both). Compiled path; "
                 "--method scipy for the reference path.")
    _add_block(p, alpha=False, omega=False, both=True)
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
    _add_transient(p)
    _add_common(p, threads=False)
    _add_scheduler(p)

    p = _command(sub, "fragility", _fragility_plan, _fragility_run,
                 "fragility curves by incremental dynamic analysis",
                 "Scale every record to each intensity, run the block from rest for each "
                 "size and law, and fit lognormal fragility curves (median and dispersion by "
                 "maximum likelihood) to overturning and to max|theta|/(pi/2 - theta_c) >= "
                 "0.5, 1. Writes fragility.npz, fragility.png, rotation.png and summary.json.")
    _add_block(p, alpha=False, omega=False, both=True)
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
    _add_transient(p)
    _add_common(p, threads=False)
    _add_scheduler(p)

    p = sub.add_parser("compile", help="compile every kernel into numba's cache", description=
                       "Compile the kernel variants the commands use into numba's cache, in "
                       "parallel processes: later runs only load them (images, CI, Dask).")
    p.add_argument("--quiet", action="store_true", help="no progress on stderr")

    p = _command(sub, "cor", _cor_plan, _cor_run, "restitution laws: figure 1 and the e-table",
                 "Figure 1 (e_H, e_M against thc, with delta e %) and a table of e_H, e_M, "
                 "delta e % (CSV and Markdown).")
    p.add_argument("--hb-values", type=float, nargs="+", default=list(E_TABLE_HB),
                   help="rows of the table")
    p.add_argument("--hb-max", type=float, default=E_FIGURE_HB_MAX,
                   help="largest h/b in the figure")
    _add_common(p, threads=False, device=False)

    p = _command(sub, "paper", _paper_plan, _paper_run,
                 "every figure and table of the study, with the data of each",
                 "Regenerate figures 1-6 and the tables of the study, the attractor maps "
                 "(7) and the erosion profiles (8). Smaller --grid, "
                 "--periods, --alpha-step give a quick version. An interrupted paper resumes; "
                 "--scheduler runs its grids on Dask.")
    p.add_argument("--grid", type=int, default=None,
                   help="cells per side of every basin, the erosion profiles' too (default "
                        "100 for the study's basins, 40 for the erosion profiles' survey)")
    p.add_argument("--periods", type=int, default=500, help="forcing periods (default 500)")
    p.add_argument("--n-steps", type=int, default=None,
                   help="steps per period (default 160 for single runs, 64 for grids)")
    p.add_argument("--alpha-step", type=float, default=0.001, help="sweep step (default 0.001)")
    p.add_argument("--zoom", type=float, nargs=2, default=ZOOM, metavar=("START", "END"),
                   help=f"alpha range of the zoomed Housner hb=1 diagram (default {ZOOM[0]} "
                        f"{ZOOM[1]})")
    p.add_argument("--zoom-step", type=float, default=None,
                   help="step of the zoom sweep (default alpha-step / 4)")
    p.add_argument("--erosion-step", type=float, default=0.02,
                   help="amplitude step of the erosion profiles (default 0.02)")
    p.add_argument("--erosion-grid", type=int, default=None,
                   help="cells per side of the erosion profiles' basins (default --grid, or "
                        "40 without it)")
    p.add_argument("--as-published", action="store_true",
                   help="also draw figure 5 as the study computed it: integrated past overturning")
    _add_common(p)
    _add_scheduler(p)

    p = _command(sub, "explore", _explore_plan, None,
                 "explore the dynamics live in a browser",
                 "Serve a local web app: the basin of the current parameters (recomputed as "
                 "they change, 50² then 100² then 200²), a cell's run, the bifurcation diagram "
                 "along alpha (a box zoom recomputes it), both laws side by side; every view "
                 "as a PNG and as the Python call that reproduces it. Needs the explore extra: "
                 "pip install 'rockjit[explore]'. Serves until Ctrl-C.")
    p.add_argument("--port", type=int, default=0,
                   help="port to listen on (default 0: a free one; the address is printed)")
    p.add_argument("--address", default="127.0.0.1",
                   help="address to bind (default 127.0.0.1: only this machine can connect; "
                        "::1 for IPv6's loopback; 0.0.0.0 lets other machines connect, with a "
                        "warning)")
    p.add_argument("--allow-host", action="append", metavar="NAME",
                   help="also accept requests that name this host (repeatable; by default "
                        "only the bound address, localhost for a loopback one, and this "
                        "machine's host name for another)")
    p.add_argument("--no-browser", action="store_true",
                   help="do not open the system's web browser")
    return parser


def _error(msg):
    msg = " ".join(str(msg).split())  # always one line
    print(f"{PROG}: error: {msg}", file=sys.stderr, flush=True)
    return 2


def _internal_error(exc, prefix=""):
    """An error while running (a full disk, a file system refusing a write, a lost Dask
    scheduler, a bug): one line on stderr (after ``prefix``), the traceback in a report file
    (``rockjit-error-*.txt`` in the temporary directory), exit status 1. Never raises: if the
    report cannot be written either, the line says why."""
    import tempfile
    import traceback
    path = None
    try:
        fd, path = tempfile.mkstemp(prefix=f"{PROG}-error-", suffix=".txt")
        with os.fdopen(fd, "w", encoding="utf-8") as f:
            traceback.print_exception(type(exc), exc, exc.__traceback__, file=f)
        report = f"the traceback is in {path}"
    except Exception as e:  # its disk may be full too
        if path is not None:
            with contextlib.suppress(OSError):
                os.unlink(path)
        report = f"no report could be written ({type(e).__name__}: {' '.join(str(e).split())})"
    if prefix:
        line = (f"{PROG}: error: {prefix}{type(exc).__name__}: {' '.join(str(exc).split())}; "
                f"--out is as it was; {report}")
    elif isinstance(exc, OSError) and exc.strerror:
        where = f": {exc.filename}" if exc.filename else ""
        line = f"{PROG}: error: {exc.strerror}{where}; --out is as it was; {report}"
    else:
        line = (f"{PROG}: internal error: {type(exc).__name__}: {' '.join(str(exc).split())}; "
                f"--out is as it was; {report} (please report it)")
    with contextlib.suppress(Exception):
        print(" ".join(line.split()), file=sys.stderr, flush=True)
    return 1


def _from_dask(exc):
    """Whether ``exc`` is a connection's failure (``OSError``, ``TimeoutError``) raised inside
    dask.distributed."""
    if not isinstance(exc, (OSError, TimeoutError)):
        return False
    tb = exc.__traceback__
    while tb is not None:
        if f"{os.sep}distributed{os.sep}" in tb.tb_frame.f_code.co_filename:
            return True
        tb = tb.tb_next
    return False


def _compile(args):
    """``rockjit compile``: every kernel variant into numba's cache, in parallel processes."""
    from .._engine.kernel import COMMON as names, VARIANTS, compile_kernels
    t0 = time.perf_counter()
    _say(args, f"compile: {len(names)} kernel variants (a minute or two cold on two cores)")
    try:
        compile_kernels(names, progress=lambda i, n, name, s: _say(
            args, f"compile: [{i}/{n}] {name} ({VARIANTS[name][0]}): {s:.1f} s"))
    except KeyboardInterrupt as exc:
        print(f"\n{PROG}: interrupted; the variants compiled so far are cached", file=sys.stderr)
        return 128 + getattr(exc, "signum", 2)
    _say(args, f"compile: done in {time.perf_counter() - t0:.1f} s")
    return 0


def main(argv=None):
    """Run the command line; returns the exit status: 0 done (``--out`` published, also when a
    signal arrives after that: the line says so), 1 an error while running (one line, the
    traceback in a report file), 2 bad input (or an ``--out`` rockjit may not write: a file it
    did not write in the way, another run writing it), 3 published but a figure could not be
    drawn (one line says which; its data are written), 130 / 143 interrupted by SIGINT /
    SIGTERM before ``--out`` was published (``--out`` as it was)."""
    from .signals import command_interrupts
    with command_interrupts() as sig:
        try:
            return _main(argv, sig)
        except BaseException as exc:
            sig.final = True
            # a signal: KeyboardInterrupt, or what it became on its way out (an ImportError
            # when it interrupted the import of an extension module)
            if isinstance(exc, KeyboardInterrupt) or (sig.received and
                                                      not isinstance(exc, SystemExit)):
                return _interrupted(exc, sig)
            raise
        finally:
            sig.final = True  # from here on a signal changes nothing


def _interrupted(exc, sig):
    """A SIGINT or SIGTERM (``exc.signum``) that interrupted the run: 128 + the signal, unless
    ``--out`` was published already (0)."""
    from ..storage.output_dir import chunk_root
    from .signals import signal_name
    signum = getattr(exc, "signum", None) or (sig.received[-1] if sig.received else 2)
    out = sig.out
    if out is not None and out.published:
        print(f"{PROG}: {signal_name(signum)} arrived after {out.path} was written; the command "
              f"has completed (exit status 0)", file=sys.stderr, flush=True)
        return 0
    where = ""
    if out is not None:
        out.discard()
        chunks = chunk_root(out.path)
        if os.path.isdir(chunks):
            where = f" (finished chunks wait in {chunks} for a rerun)"
    print(f"\n{PROG}: interrupted ({signal_name(signum)}); --out is as it was{where}",
          file=sys.stderr, flush=True)
    return 128 + signum


def _main(argv, sig):
    from .. import outputs
    from ..storage.output_dir import OutputDir
    from .signals import interrupted, signal_name
    try:
        args = build_parser().parse_args(argv)
    except UsageError as exc:
        return _error(exc)
    except SystemExit as exc:  # --help, --version
        return exc.code if isinstance(exc.code, int) else 0
    if args.command == "compile":
        return _compile(args)
    try:
        _check_device(args)
        plan = args.plan(args)
        _check_run(args)
        # --out taken for this run (its lock), refused if it holds files rockjit did not write
        out = sig.out = OutputDir(args.out, command=args.command)
        out.claim(files=OUTPUTS.get(args.command, ()),
                  figure_format=getattr(args, "format", None), name="--out")
    except (UsageError, ValueError) as exc:
        return _error(exc)
    from .._jit import cached_kernels
    # spectra and fragility run the pulses' and records' kernel, the others the harmonic ones
    engine = ("transient",) if args.command in ("spectrum", "fragility") else \
        ("integrate", "kernel")
    if args.command != "cor" and not cached_kernels(modules=engine):
        _say(args, "first run here: numba compiles rockjit's kernels into its cache, about "
                   "10-20 s per kernel variant on two cores, once (`rockjit compile` does it "
                   "ahead of time)")
        if args.command == "paper":  # every variant, side by side
            rc = _compile(args)
            if rc:
                out.discard()
                return rc
    import matplotlib
    matplotlib.use("Agg")
    interrupted(sig)  # a signal whose KeyboardInterrupt something swallowed: no work
    from ..grids.runner import NoWorkers, worker_timeout
    from ..plotting import style
    timeout = getattr(args, "scheduler_timeout", None)
    out.figure_format = getattr(args, "format", None)
    out.dpi = style.STYLES[getattr(args, "style", "default")].rc["savefig.dpi"]
    n = n0 = len(sig.received)
    try:
        with warnings.catch_warnings(), style.use(getattr(args, "style", "default")), \
                (worker_timeout(timeout) if timeout else contextlib.nullcontext()):
            if args.quiet:
                warnings.simplefilter("ignore")
            wall, results = args.run(args, plan, out)
            inputs = {k: v for k, v in vars(args).items() if not callable(v)}
            out.json("summary.json", outputs.summary(out, args.command, inputs, wall, **results))
            interrupted(sig)  # likewise: before publication, a signal always interrupts
            n = len(sig.received)
            note = out.publish()
    except KeyboardInterrupt:
        if not out.published:
            raise  # main: --out as it was, 130 or 143
        note = out.warning
    except NoWorkers as exc:
        out.discard()
        return _error(f"--scheduler {args.scheduler}: {exc} (--scheduler-timeout)")
    except (UsageError, ValueError) as exc:  # a check made only once running
        out.discard()
        return _error(exc)
    except Exception as exc:  # a full disk, a refused write, a bug: one line and a report
        out.discard()
        if len(sig.received) > n0:
            raise  # what a signal became (see main)
        lost = getattr(args, "scheduler", None) and _from_dask(exc)
        return _internal_error(exc, f"--scheduler {args.scheduler}: the connection to the Dask "
                                    f"scheduler failed: " if lost else "")
    except BaseException:
        out.discard()
        raise
    sig.final = True  # published: from here on a signal changes nothing
    try:
        if note:
            _warn(note)
        for f in out.figure_errors:
            _warn(f"{f['name']} could not be drawn ({f['error']}); the data were written "
                  f"without it (exit status 3)")
        if args.command in CHUNKED:
            from ..storage.chunkstore import remove_stores
            remove_stores(_chunk_root(args), message=lambda m: _say(args, m))
        _say(args, f"{args.command}: wrote {args.out}")
    except Exception as exc:  # the outputs are published: the command has succeeded
        _warn(f"{args.out} was written; cleaning up after it failed ({type(exc).__name__}: "
              f"{exc})")
    status = 3 if out.figure_errors else 0  # published, a figure missing
    late = ([out.interrupted] if out.interrupted else []) + sig.received[n:]
    if late:
        print(f"{PROG}: {signal_name(late[0])} arrived after {args.out} was written; the "
              f"command has completed (exit status {status})", file=sys.stderr, flush=True)
    return status
