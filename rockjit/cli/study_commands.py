"""The commands of the study and its tools: ``rockjit compile`` (the kernels into numba's
cache), ``rockjit cor`` (the restitution laws' figure and table), ``rockjit paper`` (every
figure and table of the study) and ``rockjit explore`` (the explorer's server), each with its
options, plan and run."""

from __future__ import annotations

import math
import sys
import time

from .arguments import add_command, add_common, add_scheduler
from .messages import PROG, say
from .options import execution_of, run_grid
from .usage import UsageError


def run_compile(args):
    """``rockjit compile``: every kernel variant into numba's cache, in parallel processes."""
    from .._engine.kernel import COMMON as names, VARIANTS, compile_kernels
    t0 = time.perf_counter()
    say(args, f"compile: {len(names)} kernel variants (a minute or two cold on two cores)")
    try:
        compile_kernels(names, progress=lambda i, n, name, s: say(
            args, f"compile: [{i}/{n}] {name} ({VARIANTS[name][0]}): {s:.1f} s"))
    except KeyboardInterrupt as exc:
        print(f"\n{PROG}: interrupted; the variants compiled so far are cached", file=sys.stderr)
        return 128 + getattr(exc, "signum", 2)
    say(args, f"compile: done in {time.perf_counter() - t0:.1f} s")
    return 0


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
                      as_published=args.as_published, execution=execution_of(args))


def _paper_run(args, p, out):
    from ..study.paper import paper
    t0 = time.perf_counter()
    results = run_grid(args, lambda plan, ex: paper(out, plan, execution=ex,
                                                    say=lambda m: say(args, m)), p, None)
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


def add_compile_command(sub):
    """``rockjit compile``: every kernel into numba's cache (no plan: :func:`rockjit.cli.main.main`
    runs it)."""
    p = sub.add_parser("compile", help="compile every kernel into numba's cache", description=
                       "Compile the kernel variants the commands use into numba's cache, in "
                       "parallel processes: later runs only load them (images, CI, Dask).")
    p.add_argument("--quiet", action="store_true", help="no progress on stderr")


def add_cor_command(sub):
    """``rockjit cor``: the restitution laws' figure and table."""
    from ..study.paper import E_FIGURE_HB_MAX, E_TABLE_HB
    p = add_command(sub, "cor", _cor_plan, _cor_run, "restitution laws: figure 1 and the e-table",
                    "Figure 1 (e_H, e_M against thc, with delta e %) and a table of e_H, e_M, "
                    "delta e % (CSV and Markdown).")
    p.add_argument("--hb-values", type=float, nargs="+", default=list(E_TABLE_HB),
                   help="rows of the table")
    p.add_argument("--hb-max", type=float, default=E_FIGURE_HB_MAX,
                   help="largest h/b in the figure")
    add_common(p, threads=False, device=False)


def add_paper_command(sub):
    """``rockjit paper``: every figure and table of the study."""
    from ..study.paper import ZOOM
    p = add_command(sub, "paper", _paper_plan, _paper_run,
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
    add_common(p)
    add_scheduler(p)


def add_explore_command(sub):
    """``rockjit explore``: the explorer, live in a browser."""
    p = add_command(sub, "explore", _explore_plan, None,
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
