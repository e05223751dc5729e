"""The groups of options the commands share (the block, the run, the initial state and the
forcing's phase, the output, a Dask scheduler, the runs on pulses and records), and the
declaration of a command with its plan and run."""

from __future__ import annotations

from .usage import scheduler_address


def _law_names(both):
    """The ``--law`` values in words: the registered laws' names (rockjit.laws), and ``both``
    (Housner's and Mao's) where a command compares two laws."""
    from ..laws import names
    options = list(names()) + (["both"] if both else [])
    return ", ".join(options[:-1]) + " or " + options[-1]


def add_block(p, alpha=True, omega=True, both=False):
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


def add_run(p, periods=500, grid=False):
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


def add_state(p, default_note):
    p.add_argument("--theta0", type=float, default=None, help="initial angle")
    p.add_argument("--dtheta0", type=float, default=None, help="initial angular velocity")
    add_phase(p, default_note)


def add_phase(p, default_note):
    g = p.add_mutually_exclusive_group()
    g.add_argument("--phase", type=float, default=None,
                   help="forcing phase phi in r = sin(omega t + phi)")
    g.add_argument("--r0", type=float, default=None, help="forcing oscillator r(0) (with --s0)")
    p.add_argument("--s0", type=float, default=None,
                   help=f"forcing oscillator s(0) (with --r0); {default_note}")


def add_forcing(p):
    p.add_argument("--forcing", default="closed", choices=("closed", "embedded"),
                   help="closed-form forcing or the 4-D oscillator embedding")


def add_common(p, threads=True, device=True):
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


def add_grid_run(p, lyapunov_default):
    """Options of the grid commands (sweep, basin, plane)."""
    add_run(p, grid=True)
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
    add_common(p)
    add_scheduler(p)


def add_scheduler(p):
    p.add_argument("--scheduler", default=None, metavar="ADDRESS", type=scheduler_address,
                   help="run the chunks of cells on this Dask scheduler (tcp://host:8786, or "
                        "a scheduler file); default in this process")
    p.add_argument("--scheduler-timeout", type=float, default=60.0, metavar="SECONDS",
                   help="give up when the scheduler has had no worker for this long "
                        "(default 60)")


def add_transient(p):
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


def add_alphas(p, step):
    p.add_argument("--alpha-range", type=float, nargs=2, required=True,
                   metavar=("START", "END"), help="amplitudes from START to END (included)")
    if step is not None:
        p.add_argument("--alpha-step", type=float, default=step, help=f"step (default {step})")


def add_command(sub, name, plan, run, help, description):
    p = sub.add_parser(name, help=help, description=description)
    p.set_defaults(plan=plan, run=run)
    return p
