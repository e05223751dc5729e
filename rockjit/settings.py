"""The settings a computation is made with, as small validated objects.

Four concepts, each one frozen dataclass validated once, in its constructor, with messages that
name the field, the allowed range and the value given:

- :class:`Integration`: how a run is integrated (steps per period, length, averaging window,
  impact bound, the Zeno cut-off, the overturning threshold);
- :class:`Classification`: how a grid's cells are classified (the period test's tolerances,
  early stopping, attractor identity, the uncertain-cell test);
- :class:`Lattice`: the initial states of a basin, ``grid x grid`` over ``(theta0, theta0')``;
- :class:`Execution`: where and how a grid runs (the device, threads, chunks, lanes, a Dask
  cluster, a chunk store, progress). It never changes a result.

The block (:class:`rockjit.Block`) and the excitation (:class:`rockjit.Harmonic`) are the other
two; every entry point takes these objects plus what is its own alone.
"""

from __future__ import annotations

import math
import os
from dataclasses import dataclass, replace
from typing import Any, Callable

from .validate import boolean, integer, pair, real

__all__ = ["DEVICES", "Classification", "Execution", "Integration", "Lattice", "MAX_IMPACTS",
           "MAX_N", "MAX_PERIODS", "REST_SPEED_RANGE", "cuda_missing", "cuda_refusal",
           "default_max_impacts", "scipy_on_cuda"]

#: Largest number of periods, and of steps per period, a run may ask for: bounds that keep the
#: kernels' step counter in 64 bits. The memory check refuses most large requests first, with
#: the memory they would need.
MAX_PERIODS = 10**15
MAX_N = 10**12

#: The Zeno cut-off's range. Below ~1e-17 an impact speed is rounding of ``theta'`` near 0 and
#: the cut-off behaves as 0, at which a Zeno cascade piles impacts at one instant until the
#: impact bound; 1e-12 leaves four decades of margin (docs/theory/impacts.md).
REST_SPEED_RANGE = (1e-12, 0.1)


#: Largest impact bound, explicit or default: the kernels count impacts in 64-bit integers.
MAX_IMPACTS = 2**62


def default_max_impacts(periods):
    """The default impact bound: 10,000 impacts per period, at least 100,000, at most
    ``MAX_IMPACTS`` (``2**62``: the bound of ``MAX_PERIODS`` periods would not fit the kernels'
    64-bit counter). A Zeno cascade from ``|theta'| ~ 1`` to the cut-off ``1e-6`` has
    ``ln(1e-6) / ln(e)`` impacts: ~10 for ``e = 0.25``, ~75 for ``e = 0.83``, ~1,400 for
    ``e = 0.99``, at most two a period."""
    return min(MAX_IMPACTS, max(100_000, 10_000 * int(periods)))


def _set(obj, **values):
    for name, value in values.items():
        object.__setattr__(obj, name, value)


class _Replace:
    def replace(self, **changes):
        """A copy with some fields changed (validated again)."""
        return replace(self, **changes)


@dataclass(frozen=True)
class Integration(_Replace):
    """How a run is integrated.

    Parameters
    ----------
    n_steps : int, optional
        Steps per forcing period ``N`` (even, ``>= 8``). Default: the entry point's own (160 for
        single runs, 64 for grids), raised for slow forcing and strong damping so that the step
        stays accurate; an explicit ``N`` too coarse to be stable is refused, naming the ``N``
        needed.
    periods : int
        Forcing periods to integrate, default 500 (the study's).
    window : int, optional
        First period of the averaging window ``[window T, periods T]`` of the exponents and of
        a full-length classification; default 80 % of the run (the study's ``[400T, 500T]``).
    max_impacts : int, optional
        Bound on the number of impacts; reaching it ends a run with status ``max_impacts``.
        Default 10,000 impacts per period, at least 100,000
        (``rockjit.settings.default_max_impacts``).
    rest_speed : float
        The Zeno cut-off in ``[1e-12, 0.1]``: an impact leaving with ``|theta'| < rest_speed``
        puts the block at rest. Default ``1e-6``.
    theta_over : float
        Overturning threshold on ``|theta|`` in ``(0, pi/2]``, default ``pi/2``.
    stop_at_overturn : bool
        Stop when ``|theta|`` reaches ``theta_over`` (the physical rule, default); ``False``
        integrates on through the threshold with the same equations, as the study's own code
        did (the run still counts as overturned; ``t_overturn`` is the first crossing).
    qr_every : int, optional
        Grid steps between Gram–Schmidt renormalisations of the tangent vectors; default twice
        a period, more often under strong damping; 0 never renormalises (the tangent matrix is
        then the Jacobian of the whole flow).

    Examples
    --------
    >>> from rockjit import Integration
    >>> Integration(periods=200).window_start()
    160
    """

    n_steps: int | None = None
    periods: int = 500
    window: int | None = None
    max_impacts: int | None = None
    rest_speed: float = 1e-6
    theta_over: float = 0.5 * math.pi
    stop_at_overturn: bool = True
    qr_every: int | None = None

    def __post_init__(self):
        periods = integer("periods", self.periods, 1, MAX_PERIODS)
        n_steps = self.n_steps
        if n_steps is not None:
            n_steps = integer("n_steps", n_steps, 8, MAX_N)
            if n_steps % 2:
                raise ValueError(f"n_steps must be even, so that t = kT + T/2 is on the grid "
                                 f"(got {n_steps})")
        window = None if self.window is None else integer("window", self.window, 0,
                                                          periods - 1)
        max_impacts = None if self.max_impacts is None else \
            integer("max_impacts", self.max_impacts, 1, MAX_IMPACTS)
        if isinstance(self.rest_speed, (int, float)) and self.rest_speed == 0:
            raise ValueError(
                "rest_speed must be > 0 (got 0): with e < 1 the impacts of a Zeno cascade "
                "accumulate in finite time, and without a cut-off a run would pile impacts at "
                "one instant until max_impacts")
        rest_speed = real("rest_speed", self.rest_speed, *REST_SPEED_RANGE)
        theta_over = real("theta_over", self.theta_over, 0.0, 0.5 * math.pi, lo_open=True)
        qr_every = None if self.qr_every is None else integer("qr_every", self.qr_every, 0,
                                                              2**62)
        _set(self, periods=periods, n_steps=n_steps, window=window, max_impacts=max_impacts,
             rest_speed=rest_speed, theta_over=theta_over,
             stop_at_overturn=boolean("stop_at_overturn", self.stop_at_overturn),
             qr_every=qr_every)

    def window_start(self):
        """The first period of the window: ``window``, or 80 % of the run."""
        return int(round(0.8 * self.periods)) if self.window is None else self.window

    def impact_bound(self):
        """``max_impacts``, or the default bound of the run's length
        (``rockjit.settings.default_max_impacts``)."""
        return default_max_impacts(self.periods) if self.max_impacts is None else \
            self.max_impacts


@dataclass(frozen=True)
class Classification(_Replace):
    """How the cells of a grid are classified (docs/theory/behaviours.md).

    Parameters
    ----------
    tol : float
        Period test: two stroboscopic samples ``p`` periods apart agree within ``tol`` times the
        orbit's size, in ``(0, 1)``; default ``1e-6``.
    pmax : int
        Largest period looked for, in ``[1, 1000]``; default 16.
    lam_tol : float
        ``lambda_max > lam_tol`` makes an unperiodic cell chaotic, else aperiodic; default
        ``1e-2``.
    settle_tol : float
        Early stopping: a run stops once its last ``settle_reps * p`` periods repeat within
        ``settle_tol`` (``0 < settle_tol <= tol``); default ``1e-9``.
    settle_reps : int
        Repetitions that count as settled, ``>= 2``; default 10.
    early_stop : bool
        Stop each run once it settled (default); ``False`` integrates every cell to the end.
    attractors : bool
        Identify the attractors (docs/theory/global-dynamics.md): ids per cell and what each
        attractor is, with its Floquet multipliers. Default ``True``.
    uncertainty : float, optional
        Flag the cells whose outcome changes when their initial state moves by this relative
        amount, in ``[1e-15, 0.5]`` (costs a second run of the grid).

    Examples
    --------
    >>> from rockjit import Classification
    >>> Classification(early_stop=False).tol
    1e-06
    """

    tol: float = 1e-6
    pmax: int = 16
    lam_tol: float = 1e-2
    settle_tol: float = 1e-9
    settle_reps: int = 10
    early_stop: bool = True
    attractors: bool = True
    uncertainty: float | None = None

    def __post_init__(self):
        tol = real("tol", self.tol, 0.0, 1.0, lo_open=True, hi_open=True)
        _set(self, tol=tol,
             settle_tol=real("settle_tol", self.settle_tol, 0.0, tol, lo_open=True),
             pmax=integer("pmax", self.pmax, 1, 1000),
             settle_reps=integer("settle_reps", self.settle_reps, 2, 10**6),
             lam_tol=real("lam_tol", self.lam_tol),
             early_stop=boolean("early_stop", self.early_stop),
             attractors=boolean("attractors", self.attractors),
             uncertainty=None if self.uncertainty is None else
             real("uncertainty", self.uncertainty, 1e-15, 0.5))


@dataclass(frozen=True)
class Lattice(_Replace):
    """The initial states of a basin: ``grid x grid`` points over ``(theta0, theta0')``, ends
    included.

    Parameters
    ----------
    grid : int
        Points per side, ``>= 1``; default 100 (the study's).
    theta_range, dtheta_range : pair of float
        The ranges of ``theta0`` and ``theta0'``; default ``(-1, 1)`` each. ``theta_range`` must
        lie inside ``(-theta_over, theta_over)``, checked by the entry point.

    Examples
    --------
    >>> from rockjit import Lattice
    >>> Lattice(3).axes()[0]
    array([-1.,  0.,  1.])
    """

    grid: int = 100
    theta_range: tuple = (-1.0, 1.0)
    dtheta_range: tuple = (-1.0, 1.0)

    def __post_init__(self):
        _set(self, grid=integer("grid", self.grid, 1, 10**9),
             theta_range=pair("theta_range", self.theta_range),
             dtheta_range=pair("dtheta_range", self.dtheta_range, -1e6, 1e6))

    @property
    def cells(self):
        """Number of cells, ``grid**2``."""
        return self.grid * self.grid

    def axes(self):
        """``(theta0, dtheta0)``: the two axes as arrays."""
        import numpy as np
        return (np.linspace(*self.theta_range, self.grid),
                np.linspace(*self.dtheta_range, self.grid))


#: Where a grid's cells may run (:class:`Execution`'s ``device``).
DEVICES = ("cpu", "cuda")


def cuda_missing():
    """What this machine lacks for ``device="cuda"``, as a phrase, or ``None`` where numba's
    CUDA target sees a GPU (``numba.cuda.is_available()``; imported only when asked)."""
    import importlib
    try:
        cuda = importlib.import_module("numba.cuda")
    except Exception:  # numba-cuda absent or broken: any failure to import means no device
        return "numba-cuda is not installed"
    try:
        if cuda.is_available():
            return None
    except Exception:  # a driver that fails to load is no driver
        pass
    return "no CUDA-capable GPU with a working driver was found"


def cuda_refusal(what='device="cuda"', instead='device="cpu"'):
    """The one line that refuses ``what`` (the CUDA device, as the caller names it) where this
    machine cannot run it: what it needs, what is missing here, and ``instead``; ``None``
    where nothing is missing."""
    missing = cuda_missing()
    if missing is None:
        return None
    return (f'{what} needs a CUDA-capable NVIDIA GPU with its driver and numba-cuda '
            f'(pip install "rockjit[cuda]"); {missing}: use {instead}')


def scipy_on_cuda(name='device="cuda"', instead='device="cpu"', compiled='method="rockjit"'):
    """The one line that refuses ``name`` for the scipy reference path, which runs on the CPU
    only."""
    return (f"{name} runs the compiled path ({compiled}); the scipy reference path runs on the "
            f"CPU only: use {instead}")


@dataclass(frozen=True)
class Execution(_Replace):
    """Where and how a grid runs. Nothing here changes a result: every cell is computed the
    same way whatever the threads, chunks, lanes or cluster.

    Parameters
    ----------
    device : {"cpu", "cuda"}
        Where the cells run: the CPU's cores (default), or an NVIDIA GPU through numba's CUDA
        target, which needs a CUDA-capable GPU with its driver and ``numba-cuda``
        (``pip install "rockjit[cuda]"``): the cells of sweeps, basins, planes, erosion
        profiles, fates, the safety and chart grids, spectra and fragility curves run one
        per GPU thread (docs/guide/gpu.md; the scipy reference path stays on the CPU). Where
        this machine lacks the GPU, its driver or ``numba-cuda``, ``device="cuda"`` is refused
        with a ``ValueError`` saying what is missing.
    threads : int, optional
        numba threads (default: all).
    chunk : int, optional
        Cells per chunk: the unit of progress, of Dask tasks and of resumption; default about
        a twentieth of the grid, at least 64 (a rerun on a chunk store keeps the chunks it
        began with). In this process the cells run as pieces of a chunk on one thread each,
        as many at once as ``threads``, each thread taking the next piece when its last is
        done, so that no thread waits at a chunk's end whatever the chunk's size
        (``rockjit.grids.runner``).
    lanes : int, optional
        Cells per thread in lockstep, 1 to 8 (grids without tangent vectors); default 8.
    client : dask.distributed.Client, optional
        Run the chunks on this Dask cluster.
    scheduler : str, optional
        Or the address of a Dask scheduler (``tcp://host:port``) or a scheduler file: a client
        is opened for the computation and closed after it.
    store : path, optional
        Directory for finished chunks: a rerun with the same inputs computes only what is
        missing.
    progress : bool or callable
        Show progress on stderr, described by what it counts (the grid, the block's
        slenderness and law, the fixed forcing: ``basin hb=1 housner alpha=0.66 omega=1.3``):
        a tqdm bar on a terminal; elsewhere (a log file, a pipe) plain lines, at most one
        every 5 s plus the last, so that a log stays readable. Or a callable
        ``progress(done, total)``, called with the cells finished so far once the chunks
        already stored are counted and after each chunk, instead of the output on stderr. An exception it raises stops the grid between
        two chunks and propagates (the chunks finished so far stay in the store, if any): an
        interactive caller cancels a computation this way.
    message : callable, optional
        ``message(text)`` hears the chunk store's notes (a lock taken over, a damaged chunk
        recomputed) and the wait for Dask workers; default a line on stderr.
    worker_timeout : float, optional
        Seconds a computation on Dask waits for the scheduler to have a worker before it
        gives up with an error; default 60 (:data:`rockjit.grids.runner.WORKER_TIMEOUT`).

    Examples
    --------
    >>> from rockjit import Execution
    >>> Execution(threads=1, progress=False).lanes is None
    True
    """

    threads: int | None = None
    chunk: int | None = None
    lanes: int | None = None
    client: Any = None
    device: str = "cpu"
    scheduler: str | None = None
    store: Any = None
    progress: bool | Callable = False
    message: Callable | None = None
    worker_timeout: float | None = None

    def __post_init__(self):
        if not isinstance(self.device, str) or self.device not in DEVICES:
            raise ValueError(f"device must be one of {', '.join(map(repr, DEVICES))} "
                             f"(got {self.device!r})")
        refusal = cuda_refusal() if self.device == "cuda" else None
        if refusal is not None:
            raise ValueError(refusal)
        if self.threads is not None:
            import numba
            _set(self, threads=integer("threads", self.threads, 1,
                                       numba.config.NUMBA_NUM_THREADS))
        if self.chunk is not None:
            _set(self, chunk=integer("chunk", self.chunk, 1, 10**18))
        if self.lanes is not None:
            _set(self, lanes=integer("lanes", self.lanes, 1, 8))
        if self.client is not None and self.scheduler is not None:
            raise ValueError("give client or scheduler, not both")
        if self.scheduler is not None and (not isinstance(self.scheduler, str)
                                           or not self.scheduler.strip()):
            raise ValueError(f"scheduler must be a Dask scheduler's address or file "
                             f"(got {self.scheduler!r})")
        if self.store is not None and not isinstance(self.store, (str, os.PathLike)):
            raise ValueError(f"store must be a path (got {type(self.store).__name__})")
        if self.message is not None and not callable(self.message):
            raise ValueError("message must be a callable taking one string")
        if not callable(self.progress):
            try:
                _set(self, progress=boolean("progress", self.progress))
            except ValueError:
                raise ValueError(f"progress must be True, False or a callable "
                                 f"progress(done, total) (got {self.progress!r})") from None
        if self.worker_timeout is not None:
            _set(self, worker_timeout=real("worker_timeout", self.worker_timeout, 0.0, None,
                                           lo_open=True))
