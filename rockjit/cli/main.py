"""The ``rockjit`` command line: argparse and file output over the library's plans and runs.

This module runs a command (:func:`main`: parse, plan, check, compute, publish, and the exit
status). The parser is :func:`~.parser.build_parser`; each command's options, its plan
(validation only) and its run (compute, write into the staging directory) are in the module of
its group (:mod:`.single_commands`, :mod:`.grid_commands`,
:mod:`.orbit_commands`, :mod:`.ground_commands`, :mod:`.study_commands`), made of the option
groups they share (:mod:`.arguments`) and of the library objects those options make
(:mod:`.options`); :mod:`.checks` holds the checks of the command line's own options,
:mod:`.usage` the parser's class and the values of options, :mod:`.messages` the lines on
stderr.

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

import contextlib
import os
import sys
import warnings

from .checks import CHUNKED, OUTPUTS, check_device, check_run
from .messages import PROG, error, from_dask, internal_error, say, warn
from .options import chunks_of
from .parser import build_parser
from .study_commands import run_compile
from .usage import UsageError

__all__ = ["build_parser", "main"]


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
    """Run one command (see :func:`main`): parse, plan and claim ``--out``, compute, publish."""
    from .. import outputs
    from .signals import interrupted
    try:
        args = build_parser().parse_args(argv)
    except UsageError as exc:
        return error(exc)
    except SystemExit as exc:  # --help, --version
        return exc.code if isinstance(exc.code, int) else 0
    if args.command == "compile":
        return run_compile(args)
    try:
        plan, out = _plan(args, sig)
    except (UsageError, ValueError) as exc:
        return error(exc)
    rc = _first_run(args)
    if rc:
        out.discard()
        return rc
    import matplotlib
    matplotlib.use("Agg")
    interrupted(sig)  # a signal whose KeyboardInterrupt something swallowed: no work
    from ..grids.runner import worker_timeout
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
    except BaseException as exc:
        out.discard()
        status = _failed(exc, args, sig, n0)
        if status is None:
            raise  # what a signal became (see main), or not an error of the run's
        return status
    sig.final = True  # published: from here on a signal changes nothing
    _after_publication(args, out, note)
    return _completed(args, out, sig, n)


def _plan(args, sig):
    """The command's plan and ``--out`` claimed for this run, before any work (a UsageError or
    ValueError for bad input)."""
    from ..storage.output_dir import OutputDir
    check_device(args)
    plan = args.plan(args)
    check_run(args)
    # --out taken for this run (its lock), refused if it holds files rockjit did not write
    out = sig.out = OutputDir(args.out, command=args.command)
    out.claim(files=OUTPUTS.get(args.command, ()),
              figure_format=getattr(args, "format", None), name="--out")
    return plan, out


def _first_run(args):
    """Say so when numba's cache lacks the command's kernels (``paper`` then compiles every
    variant, side by side); returns that compilation's exit status, else 0."""
    from .._jit import cached_kernels
    # spectra and fragility run the pulses' and records' kernel, the others the harmonic ones
    engine = ("transient",) if args.command in ("spectrum", "fragility") else \
        ("integrate", "kernel")
    if args.command != "cor" and not cached_kernels(modules=engine):
        say(args, "first run here: numba compiles rockjit's kernels into its cache, about "
                   "10-20 s per kernel variant on two cores, once (`rockjit compile` does it "
                   "ahead of time)")
        if args.command == "paper":
            return run_compile(args)
    return 0


def _failed(exc, args, sig, n0):
    """The exit status of a run that failed before publication, its one line said; ``None``
    when ``exc`` goes on up: what a signal became (``n0`` signals were seen before the run),
    or no ``Exception``."""
    from ..grids.runner import NoWorkers
    if isinstance(exc, NoWorkers):
        return error(f"--scheduler {args.scheduler}: {exc} (--scheduler-timeout)")
    if isinstance(exc, (UsageError, ValueError)):  # a check made only once running
        return error(exc)
    if not isinstance(exc, Exception) or len(sig.received) > n0:
        return None
    # a full disk, a refused write, a bug: one line and a report
    lost = getattr(args, "scheduler", None) and from_dask(exc)
    return internal_error(exc, f"--scheduler {args.scheduler}: the connection to the Dask "
                               f"scheduler failed: " if lost else "")


def _after_publication(args, out, note):
    """The lines after publication (the note, each figure not drawn, where the outputs are) and
    the finished chunks removed; a failure here is a warning (the command has succeeded)."""
    try:
        if note:
            warn(note)
        for f in out.figure_errors:
            warn(f"{f['name']} could not be drawn ({f['error']}); the data were written "
                 f"without it (exit status 3)")
        if args.command in CHUNKED:
            from ..storage.chunkstore import remove_stores
            remove_stores(chunks_of(args), message=lambda m: say(args, m))
        say(args, f"{args.command}: wrote {args.out}")
    except Exception as exc:  # the outputs are published: the command has succeeded
        warn(f"{args.out} was written; cleaning up after it failed ({type(exc).__name__}: "
             f"{exc})")


def _completed(args, out, sig, n):
    """The exit status of a published command, 3 when a figure is missing, else 0; a line for a
    signal that arrived after the first ``n`` (which came before publication)."""
    from .signals import signal_name
    status = 3 if out.figure_errors else 0
    late = ([out.interrupted] if out.interrupted else []) + sig.received[n:]
    if late:
        print(f"{PROG}: {signal_name(late[0])} arrived after {args.out} was written; the "
              f"command has completed (exit status {status})", file=sys.stderr, flush=True)
    return status
