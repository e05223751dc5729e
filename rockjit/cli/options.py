"""From a command's options to the library's objects its plan is made of: the block, the
laws, the forcing, the initial state, the integration and classification settings, and the
execution (threads, progress, chunk store, Dask client) its grids run with."""

from __future__ import annotations

import os

from .messages import say
from .usage import UsageError


def chunks_of(args):
    from ..storage.output_dir import chunk_root
    return chunk_root(args.out)


#: Seconds to wait for a Dask scheduler to answer (at most; --scheduler-timeout if shorter).
CONNECT_TIMEOUT = 15.0


def client_of(args):  # a Dask client for --scheduler, or None
    if not getattr(args, "scheduler", None):
        return None
    from dask.distributed import Client
    say(args, f"{args.command}: connecting to the Dask scheduler at {args.scheduler}")
    timeout = min(CONNECT_TIMEOUT, args.scheduler_timeout)
    file = "://" not in args.scheduler and os.path.isfile(args.scheduler)
    try:
        if file:
            return Client(scheduler_file=args.scheduler, timeout=f"{timeout}s")
        return Client(args.scheduler, timeout=f"{timeout}s")
    except Exception as exc:  # OSError, TimeoutError, a bad scheduler file, ...
        raise UsageError(f"--scheduler {args.scheduler}: cannot reach the Dask scheduler "
                         f"({type(exc).__name__}: {exc})") from None


def block_of(args, law=None):
    """The block of ``--hb --law --e --xi`` (``law``: one of ``--law both``'s)."""
    from ..model import XI_STUDY, Block
    return Block(hb=args.hb, law=law or args.law, e=args.e,
                 xi=XI_STUDY if args.xi is None else args.xi)


def laws_of(args):
    """The laws a command runs: ``--law both`` is Housner's and Mao's."""
    if args.law == "both":
        if args.e is not None:
            raise UsageError("--e goes with --law constant, not --law both")
        return ("housner", "mao")
    if args.law is None:  # as the library: --e alone selects the constant law
        return ("housner" if args.e is None else "constant",)
    return (args.law,)


def forcing_of(args, alpha=True, omega=True):
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


def state_of(args):
    """``(--theta0, --dtheta0)`` (0 where one is left out), or ``None`` for the study's."""
    if args.theta0 is None and args.dtheta0 is None:
        return None
    return (args.theta0 or 0.0, args.dtheta0 or 0.0)


def integration_of(args):
    from ..settings import Integration
    kw = dict(periods=args.periods, n_steps=getattr(args, "n_steps", None),
              max_impacts=getattr(args, "max_impacts", None),
              stop_at_overturn=not getattr(args, "continue_past_overturn", False))
    if getattr(args, "rest_speed", None) is not None:
        kw["rest_speed"] = args.rest_speed
    return Integration(**kw)


def classification_of(args):
    from ..settings import Classification
    return Classification(early_stop=not getattr(args, "full_length", False),
                          uncertainty=getattr(args, "uncertainty", None))


def execution_of(args, client=None, name=None):
    """Threads, progress, the chunk store ``<out>.chunks[/name]`` and the Dask client."""
    from ..settings import Execution
    root = chunks_of(args)
    return Execution(threads=getattr(args, "threads", None), progress=not args.quiet,
                     device=getattr(args, "device", "cpu"),
                     client=client, store=root / name if name else root,
                     message=lambda m: say(args, m))


def alphas_of(args):
    """The amplitudes of ``--alpha-range --alpha-step``, their number checked first."""
    from .._engine import kernel
    from ..grids.plan import alpha_count, alpha_grid
    from ..validate import memory
    *_, n = alpha_count(args.alpha_range, args.alpha_step)
    memory(f"--alpha-step {args.alpha_step:g} over --alpha-range ({n:.3g} amplitudes)",
           kernel.grid_bytes(n, 1, 8, 101, 400, True, 1, 1))
    return alpha_grid(args.alpha_range, args.alpha_step)


def run_grid(args, run, plan, name):
    """``run(plan, execution)`` with the command line's progress, Dask client
    (``--scheduler``) and chunk store (``<out>.chunks/name``), the store's notes on stderr
    unless ``--quiet``."""
    client = client_of(args)
    try:
        return run(plan, execution_of(args, client, name))
    finally:
        if client is not None:
            client.close()
