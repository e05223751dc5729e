"""What the explorer asks the library for: its parameters, the computations of each view (coarse
to fine for the basin), and the Python call that reproduces each view.

Nothing here imports a web framework: the views' computations are plain functions of a
:class:`Params` and a progress callback, unit-testable without a browser. Every value a control
gives is checked by the library itself (:class:`rockjit.Block`, :class:`rockjit.Harmonic`,
:class:`rockjit.Integration` and the entry points' plans), so the explorer refuses exactly what
the library refuses, with the library's message.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field, fields, replace

import numpy as np

from ..excitation import Harmonic
# LAWS, the restitution laws' names, is the model's own table, exported here too.
from ..model import LAWS, XI_STUDY, Block
from ..settings import Execution, Integration

__all__ = ["BasinView", "CompareView", "LAWS", "MAX_CELL_STEPS", "MAX_PERIODS", "Params",
           "REFINE", "RunView", "SweepView", "basin_stages", "chunk_for", "clean_number",
           "compare_stages", "limits_text", "python_number", "run_stages", "sweep_stages"]

#: The basin's lattices, coarse to fine: a change shows 50² at once, then refines.
REFINE = (50, 100, 200)
#: The lattice of the two laws side by side.
COMPARE_GRID = 100
#: Amplitudes of a bifurcation diagram, whatever range it shows (a zoom recomputes them all).
SWEEP_POINTS = 500
#: At most this many recorded points of a run's trajectory.
RUN_POINTS = 20_000

# The explorer's own limits, narrower than the library's: they keep every view interactive and
# every piece of work that cannot be interrupted (a chunk of a grid's cells, a cell's run, a
# basin's measures) well under a second, so that a change or a closed tab stops the work
# within a second.
#: Most periods a view integrates.
MAX_PERIODS = 4000
#: Most steps of one cell's run: periods times the steps per period N (N as the grids resolve
#: it: raised for slow forcing and strong damping when left to the library).
MAX_CELL_STEPS = 256_000
#: Cells per chunk of a basin and of a bifurcation diagram (whose cells also compute their
#: Lyapunov exponents) at the default settings (500 periods of 64 steps): a few tenths of a
#: second on two cores where every cell runs to the end (a chaotic region). A grid with more
#: work per cell has fewer cells per chunk (:func:`chunk_for`), so that a chunk takes about as
#: long whatever the settings.
CHUNK = 256
SWEEP_CHUNK = 32
_DEFAULT_WORK = 500 * 64
#: The controls that must hold a number (an empty box is refused); ``n_steps`` empty is the
#: library's default.
_NUMBERS = ("hb", "e", "alpha", "omega", "xi", "phase", "periods")


def limits_text():
    """The explorer's limits in words, shown beside the integration's controls."""
    return (f"periods ≤ {MAX_PERIODS:,}; periods × N ≤ {MAX_CELL_STEPS:,} steps per cell "
            f"(the library itself takes more: use it from Python for longer runs)")


def chunk_for(periods, n_steps, base=CHUNK):
    """Cells per chunk of a grid whose cells run ``periods`` of ``n_steps``: ``base`` at the
    default work per cell (500 × 64 steps), fewer as each cell's work grows (at least 2)."""
    work = int(periods) * max(int(n_steps), 64)
    return max(2, min(int(base), int(base) * _DEFAULT_WORK // max(work, 1)))


def clean_number(value):
    """A number from a browser control without its binary noise: ``0.66 + 0.01`` arrives as
    ``0.67000000000000004``; 12 significant digits give back ``0.67`` (what the control shows).
    Anything else is returned as it is, for the library to accept or refuse."""
    if isinstance(value, float) and math.isfinite(value):
        return float(f"{value:.12g}")
    return value


def python_number(value):
    """A number as Python source that reads back as the same float: ``1`` for ``1.0``."""
    if isinstance(value, (bool, np.bool_)):
        return repr(bool(value))
    if isinstance(value, (int, np.integer)):
        return str(int(value))
    text = repr(float(value))
    return text[:-2] if text.endswith(".0") else text


@dataclass(frozen=True)
class Params:
    """The explorer's parameters: the block, the forcing, the integration, and the amplitudes of
    the bifurcation diagram. Not checked here: :meth:`check` asks the library.

    ``e`` is the constant law's coefficient (ignored by the others); ``phase`` is the forcing
    phase of the basin and of the runs from its cells; ``n_steps`` ``None`` is the library's
    default for grids. The bifurcation diagram runs from the study's initial state ``z0`` at the
    study's forcing point (the study's diagrams), over ``alpha_range``.
    """

    hb: float = 1.0
    law: str = "housner"
    e: float = 0.8
    alpha: float = 0.66
    omega: float = 1.3
    xi: float = XI_STUDY
    phase: float = 0.0
    n_steps: int | None = None
    periods: int = 500
    alpha_range: tuple = (0.3, 1.0)

    def with_(self, **changes):
        """A copy with some fields changed; floats cleaned (:func:`clean_number`), unknown names
        refused."""
        names = {f.name for f in fields(self)}
        for k, v in changes.items():
            if k not in names:
                raise ValueError(f"unknown parameter {k!r}")
            if k in _NUMBERS and (v is None or (isinstance(v, str) and not v.strip())):
                raise ValueError(f"{k} must be a number (the box is empty)")
        return replace(self, **{k: clean_number(v) for k, v in changes.items()})

    # the library's objects -------------------------------------------------------------------
    def block(self, law=None):
        law = self.law if law is None else law
        return Block(hb=self.hb, law=law, e=self.e if law == "constant" else None, xi=self.xi)

    def forcing(self):
        return Harmonic(alpha=self.alpha, omega=self.omega, phase=self.phase)

    def sweep_forcing(self):
        return Harmonic(omega=self.omega)

    def integration(self, n_steps=None):
        return Integration(n_steps=self.n_steps if n_steps is None else n_steps,
                           periods=self.periods)

    def alphas(self):
        a0, a1 = self.alpha_range
        return np.linspace(a0, a1, SWEEP_POINTS)

    def check(self):
        """Ask the library whether these parameters make a basin and a bifurcation diagram;
        raises its ``ValueError`` (with its message) if not. Plans only: nothing is run."""
        from .. import basin, sweep
        block, integration = self.block(), self.integration()
        self.check_limits()  # before the plans: their memory checks would speak for it
        basin.plan(block, self.forcing(), REFINE[0], integration=integration)
        a0, a1 = self.alpha_range
        if not a1 > a0:
            raise ValueError(f"alpha_range must run from a smaller to a larger amplitude "
                             f"(got {a0!r}, {a1!r})")
        sweep.plan(block, self.sweep_forcing(), self.alphas(), integration=integration)
        return self

    def grid_n_steps(self):
        """Steps per period of the basin, its cells' runs and the bifurcation diagram: ``n_steps``,
        or the library's default for grids (:func:`run_n_steps`)."""
        return run_n_steps(self)

    def check_limits(self):
        """The explorer's limits (:data:`MAX_PERIODS`, :data:`MAX_CELL_STEPS`); ``ValueError``
        naming ``periods`` or ``n_steps`` beyond them."""
        if self.periods > MAX_PERIODS:
            raise ValueError(f"periods must be in [1, {MAX_PERIODS}] in the explorer (got "
                             f"{self.periods}); rockjit itself, from Python, takes more")
        n = self.grid_n_steps()
        if self.periods * n > MAX_CELL_STEPS:
            why = "; N, left to the library, is raised for slow forcing or strong damping" \
                if self.n_steps is None and n > 64 else ""
            raise ValueError(f"periods × n_steps must be at most {MAX_CELL_STEPS:,} steps per "
                             f"cell in the explorer (got {self.periods} × {n} = "
                             f"{self.periods * n:,}{why}); give fewer periods or a smaller N")
        return self

    # the Python call of each view -------------------------------------------------------------
    def block_source(self, law=None):
        law = self.law if law is None else law
        text = f"Block(hb={python_number(self.hb)}, law={law!r}"
        if law == "constant":
            text += f", e={python_number(self.e)}"
        if self.xi != XI_STUDY:
            text += f", xi={python_number(self.xi)}"
        return text + ")"

    def forcing_source(self):
        text = f"Harmonic(alpha={python_number(self.alpha)}, omega={python_number(self.omega)}"
        if self.phase != 0:
            text += f", phase={python_number(self.phase)}"
        return text + ")"

    def integration_source(self, n_steps=None):
        """``, integration=Integration(...)`` when it differs from the library's default."""
        n_steps = self.n_steps if n_steps is None else n_steps
        parts = []
        if n_steps is not None:
            parts.append(f"n_steps={python_number(n_steps)}")
        if self.periods != Integration().periods:
            parts.append(f"periods={python_number(self.periods)}")
        return f", integration=Integration({', '.join(parts)})" if parts else ""


_HEADER = "import rockjit\nfrom rockjit import Block, Harmonic{extra}\n"


def _header(*extra):
    names = "".join(f", {n}" for n in extra)
    return _HEADER.format(extra=names)


def basin_call(params, grid):
    """Python that reproduces a basin view: ``b = rockjit.basin(...)``."""
    p = params
    extra = ("Integration",) if p.integration_source() else ()
    return (_header(*extra) + f"b = rockjit.basin({p.block_source()}, {p.forcing_source()}, "
            f"grid={grid}{p.integration_source()})\n")


def sweep_call(params):
    """Python that reproduces a bifurcation view: ``sw = rockjit.sweep(...)``."""
    p = params
    a0, a1 = p.alpha_range
    extra = ("Integration",) if p.integration_source() else ()
    return ("import numpy as np\n" + _header(*extra)
            + f"sw = rockjit.sweep({p.block_source()}, Harmonic(omega={python_number(p.omega)}), "
              f"np.linspace({python_number(a0)}, {python_number(a1)}, {SWEEP_POINTS})"
              f"{p.integration_source()})\n")


def run_call(params, state, n_steps, record_stride):
    """Python that reproduces a run view: ``res = rockjit.simulate(...)`` and its behaviour."""
    p = params
    th, dth = state
    return (_header("Integration")
            + f"res = rockjit.simulate({p.block_source()}, {p.forcing_source()}, "
              f"({python_number(th)}, {python_number(dth)})"
              f"{p.integration_source(n_steps)}, lyapunov=True, "
              f"record_stride={record_stride})\n"
            + "behaviour, period = rockjit.classify_result(res)\n")


def compare_call(params, grid):
    """Python that reproduces the two laws side by side and their agreement."""
    p = params
    extra = ("Integration",) if p.integration_source() else ()
    text = _header(*extra) + "from rockjit.grids.identity import agreement\n"
    for name, law in (("housner", "housner"), ("mao", "mao")):
        text += (f"{name} = rockjit.basin({p.block_source(law)}, {p.forcing_source()}, "
                 f"grid={grid}{p.integration_source()})\n")
    return text + "same = housner.label == mao.label  # the point-wise agreement map\n" \
                  "percent = agreement(housner.label, mao.label)\n"


# ---------------------------------------------------------------------------------------------
# the views' computations: lists of stages, each a function of a progress callback
# ---------------------------------------------------------------------------------------------

@dataclass
class BasinView:
    """One stage of the basin: its lattice, result, measures and Python call."""

    params: Params
    grid: int
    result: object
    measures: dict
    call: str
    final: bool = False


@dataclass
class SweepView:
    params: Params
    result: object
    call: str


@dataclass
class RunView:
    """A run from one cell: the result (with its trajectory and exponents), the behaviour the
    library gives it (:func:`rockjit.classify_result`), the cell and the call."""

    params: Params
    state: tuple
    cell: tuple | None
    result: object
    behaviour: str
    period: int
    call: str


@dataclass
class CompareView:
    params: Params
    housner: object
    mao: object
    agree: np.ndarray
    percent: float
    call: str
    grid: int = COMPARE_GRID
    extra: dict = field(default_factory=dict)


def _execution(progress, params, base=CHUNK):
    """The grids' execution: a superseded or closed request stops at its grid's next chunk (a
    200² basin at the default settings in 157 chunks)."""
    if progress is None:
        return Execution()
    return Execution(progress=progress,
                     chunk=chunk_for(params.periods, params.grid_n_steps(), base))


def basin_stages(params, levels=REFINE):
    """The basin coarse to fine: one stage per lattice of ``levels``; each returns a
    :class:`BasinView` (the last one ``final``)."""
    from .. import basin

    def stage(grid, final):
        def compute(progress=None):
            res = basin(params.block(), params.forcing(), grid,
                        integration=params.integration(), execution=_execution(progress, params))
            return BasinView(params, grid, res, res.measures(), basin_call(params, grid),
                             final=final)
        compute.label = f"basin {grid}\u00b2"
        if final and len(levels) > 1:
            compute.rank = 2.5  # the last refinement after the bifurcation diagram
        return compute
    return [stage(g, i == len(levels) - 1) for i, g in enumerate(levels)]


def sweep_stages(params):
    """The bifurcation diagram: one stage, :data:`SWEEP_POINTS` amplitudes over
    ``params.alpha_range``."""
    from .. import sweep

    def compute(progress=None):
        res = sweep(params.block(), params.sweep_forcing(), params.alphas(),
                    integration=params.integration(),
                    execution=_execution(progress, params, SWEEP_CHUNK))
        return SweepView(params, res, sweep_call(params))
    compute.label = f"bifurcation diagram, {SWEEP_POINTS} amplitudes"
    return [compute]


def run_n_steps(params, basin_result=None):
    """Steps per period of a run from a basin's cell: the basin's own, so that the run is the
    computation of that cell carried to the end (the library's grid default otherwise)."""
    if basin_result is not None:
        return int(basin_result.settings["n_steps"])
    if params.n_steps is not None:
        return params.n_steps
    from ..grids.plan import GRID_N
    from ..single import settings_for
    return settings_for(params.block(), params.forcing(), params.integration(), GRID_N)[0]


def run_stages(params, state, cell=None, n_steps=None):
    """A run from ``state = (theta0, theta0')``, with its trajectory and exponents: one stage
    returning a :class:`RunView`."""
    from .. import classify_result, simulate

    def compute(progress=None):
        n = run_n_steps(params) if n_steps is None else n_steps
        stride = max(1, math.ceil(params.periods * n / RUN_POINTS))
        st = (float(state[0]), float(state[1]))
        res = simulate(params.block(), params.forcing(), st,
                       integration=params.integration(n), lyapunov=True, record_stride=stride)
        name, period = classify_result(res)
        return RunView(params, st, cell, res, name, period, run_call(params, st, n, stride))
    compute.label = "run"
    return [compute]


def compare_stages(params, grid=COMPARE_GRID):
    """Housner's and Mao's basins at the same lattice, and where they agree: one stage."""
    from .. import basin

    def compute(progress=None):
        out = {}
        for k, law in enumerate(("housner", "mao")):
            part = None if progress is None else \
                (lambda done, total, k=k: progress(k * total + done, 2 * total))
            out[law] = basin(params.block(law), params.forcing(), grid,
                             integration=params.integration(),
                             execution=_execution(part, params))
        same = np.asarray(out["housner"].label) == np.asarray(out["mao"].label)
        return CompareView(params, out["housner"], out["mao"], same,
                           100.0 * float(same.mean()), compare_call(params, grid), grid)
    compute.label = f"both laws, {grid}\u00b2"
    return [compute]


def nearest_cell(result, theta0, dtheta0):
    """``(i, j)`` of the lattice point of a basin nearest to ``(theta0, theta0')``, or ``None``
    outside the lattice's cells."""
    th, dth = np.asarray(result.theta0), np.asarray(result.dtheta0)

    def index(axis, v):
        n = axis.size
        if n == 1:
            return 0
        step = (axis[-1] - axis[0]) / (n - 1)
        k = int(round((v - axis[0]) / step))
        return k if 0 <= k < n else None
    i, j = index(th, theta0), index(dth, dtheta0)
    return None if i is None or j is None else (i, j)
