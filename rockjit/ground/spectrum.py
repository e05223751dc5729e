"""Overturning spectra of pulses: outcome and demand over the plane of the two ratios.

:func:`spectrum` runs a block, from rest, under a pulse at every ``(omega_p / p,
a_p / (g cot theta_c))`` of a grid and records each cell's outcome (safe, overturned after an
impact, overturned without one: Zhang & Makris 2001's two modes) and ``max |theta| / alpha_s``.
At every frequency ratio it then locates, by bisection to a relative ``tol`` (default
``1e-6``), two boundaries:

- the **minimum overturning amplitude**: between the last grid amplitude that does not
  overturn the block below the first one that does (or the uplift threshold 1, which never
  does, when the grid's first amplitude overturns it), the smallest amplitude found to
  overturn it, with the mode of that overturning;
- the **boundary of overturning without impact**, located the same way on "overturns without
  impact".

Overturning is not monotonic in the amplitude (the safe island between the two modes), so a
bisection finds *a* boundary inside its bracket: the lowest the grid can see. An overturning
sliver narrower than the grid's spacing below the first overturning grid amplitude is missed.

The cells and every bisection step are batches (:mod:`rockjit.ground.batch`): the compiled
kernel runs them by default, the scipy reference path on request.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np

from ..entry import entry_point
from ..model import Block
from ..validate import memory, real, real_array
from .batch import Batch, grid_method, run_batch
from .plan import grid_settings
from ..plugs.pulse import AMPLITUDE_MAX, RATIO_RANGE, Pulse
from .response import (MODE_NAMES, OUTCOMES, OVERTURN_IMPACT, OVERTURN_NO_IMPACT, SAFE,
                       UNRESOLVED)

__all__ = ["SpectrumPlan", "SpectrumResult", "compare", "run", "spectrum"]

#: Most cells a spectrum may have.
MAX_CELLS = 10**8


def axis(name, values, lo, hi):
    """A grid axis: one or more increasing finite numbers in ``[lo, hi]``."""
    a = real_array(name, values, "numbers")
    a = np.atleast_1d(a).astype(float)
    if a.ndim != 1 or a.size == 0:
        raise ValueError(f"{name} must be one or more numbers (got {values!r})")
    for v in a:
        real(name, float(v), lo, hi)
    if a.size > 1 and not np.all(np.diff(a) > 0):
        raise ValueError(f"{name} must be increasing (got {a.tolist()})")
    return a


@dataclass(frozen=True, eq=False)
class SpectrumPlan:
    """A validated spectrum: everything :func:`run` needs."""

    block: Block
    pulse: Pulse
    ratios: np.ndarray
    amplitudes: np.ndarray
    integration: object
    method: object
    tol: float
    locate: bool

    @property
    def cells(self):
        return self.ratios.size * self.amplitudes.size


@dataclass
class SpectrumResult:
    """A pulse's overturning spectrum for one block.

    ``outcome[i, j]`` belongs to ``ratio[i]``, ``amplitude[j]`` (codes of
    :data:`rockjit.ground.OUTCOMES`); ``max_rotation``, ``t_overturn``,
    ``n_impacts`` likewise. ``min_overturn[i]`` is the located minimum overturning amplitude at
    ``ratio[i]`` (``nan``: no grid amplitude overturns the block), ``min_mode[i]`` its mode's
    outcome code; ``min_no_impact[i]`` the located boundary of overturning without impact.

    Attributes
    ----------
    block : Block
        The block.
    pulse : Pulse
        The pulse's kind (its ratio and amplitude are the grid's).
    ratio : ndarray, shape (nr,)
        The frequency ratios ``omega_p / p``.
    amplitude : ndarray, shape (nk,)
        The amplitude ratios ``a_p / (g cot theta_c)``.
    outcome : ndarray of int8, shape (nr, nk)
        Each cell's outcome code (:data:`rockjit.ground.OUTCOMES`).
    max_rotation, t_overturn : ndarray, shape (nr, nk)
        Each cell's ``max |theta| / alpha_s`` and overturning time (``nan``: it did not).
    n_impacts : ndarray of int, shape (nr, nk)
        Each cell's impacts.
    min_overturn, min_no_impact : ndarray, shape (nr,)
        The located boundaries at each ratio (``nan`` where the grid has none).
    min_mode : ndarray of int8, shape (nr,)
        The outcome code at ``min_overturn``: the mode of overturning.
    settings : dict
        The bisections' tolerance and the integration's settings.
    method : str
        The path that ran, e.g. ``"scipy:DOP853"``.
    n_runs : int
        Runs made, the bisections' included.

    Examples
    --------
    >>> import rockjit
    >>> from rockjit import Block, Pulse
    >>> sp = rockjit.spectrum(Block(hb=4, xi=0.0), Pulse("cosine"), [2.0], [4.0, 6.0],
    ...                       tol=1e-4)
    >>> sp.outcome.tolist()            # at amplitude 4: after an impact; at 6: without one
    [[1, 2]]
    >>> sp.min_overturn_list()[0]["mode"], round(float(sp.min_overturn[0]), 3)
    ('with impact', 1.407)
    """

    block: Block
    pulse: Pulse
    ratio: np.ndarray
    amplitude: np.ndarray
    outcome: np.ndarray
    max_rotation: np.ndarray
    t_overturn: np.ndarray
    n_impacts: np.ndarray
    min_overturn: np.ndarray
    min_mode: np.ndarray
    min_no_impact: np.ndarray
    settings: dict = field(default_factory=dict)
    method: str = ""
    n_runs: int = 0

    def __repr__(self):
        from ..reprs import text
        return text(self)

    def min_overturn_list(self):
        """``[{"ratio", "amplitude", "mode"}, ...]``: the minimum overturning amplitude at every
        ratio (``amplitude`` and ``mode`` ``None`` where the grid never overturns the block)."""
        out = []
        for r, k, m in zip(self.ratio, self.min_overturn, self.min_mode):
            ok = math.isfinite(k)
            out.append({"ratio": float(r), "amplitude": float(k) if ok else None,
                        "mode": MODE_NAMES.get(int(m)) if ok else None})
        return out

    def no_impact_list(self):
        """``[{"ratio", "amplitude"}, ...]``: the boundary of overturning without impact."""
        return [{"ratio": float(r), "amplitude": float(k) if math.isfinite(k) else None}
                for r, k in zip(self.ratio, self.min_no_impact)]

    def safe_island(self):
        """Cells that survive although a smaller amplitude at the same ratio overturns the
        block (the region between the two modes), as a boolean array."""
        over = np.isin(self.outcome, (OVERTURN_IMPACT, OVERTURN_NO_IMPACT))
        below = np.maximum.accumulate(over, axis=1)
        return (self.outcome == SAFE) & below

    def fractions(self):
        """Percentage of cells per outcome."""
        n = self.outcome.size
        return {name: 100.0 * float(np.count_nonzero(self.outcome == c)) / n
                for c, name in enumerate(OUTCOMES)}

    def summary(self):
        """JSON-ready: the law, the fractions, the located boundaries, the safe island."""
        return dict(law=self.block.law, restitution=self.block.restitution, hb=self.block.hb,
                    pulse=self.pulse.kind, fractions=self.fractions(),
                    min_overturn=self.min_overturn_list(),
                    min_overturn_without_impact=self.no_impact_list(),
                    safe_island_cells=int(np.count_nonzero(self.safe_island())),
                    unresolved_cells=int(np.count_nonzero(self.outcome == UNRESOLVED)),
                    runs=self.n_runs, method=self.method, settings=self.settings)

    def arrays(self, suffix=""):
        """The spectrum's arrays by name, for an ``.npz``."""
        a = dict(outcome=self.outcome, max_rotation=self.max_rotation,
                 t_overturn=self.t_overturn, n_impacts=self.n_impacts,
                 min_overturn=self.min_overturn, min_mode=self.min_mode,
                 min_no_impact=self.min_no_impact)
        return {k + suffix: v for k, v in a.items()}


def run(p: SpectrumPlan, execution=None) -> SpectrumResult:
    """Compute a :class:`SpectrumPlan`: the grid, then the bisections."""
    block, kind = p.block, p.pulse.kind
    sources = tuple(Pulse(kind, ratio=float(r), amplitude=1.0, hb=block.hb)
                    for r in p.ratios)
    nr, nk = p.ratios.size, p.amplitudes.size
    batch = Batch((block,), sources, np.zeros(nr * nk, dtype=np.int64),
                  np.repeat(np.arange(nr), nk), np.tile(p.amplitudes, nr))
    out = run_batch(batch, p.integration, p.method, execution, label="spectrum")
    shape = (nr, nk)
    outcome = out["outcome"].reshape(shape)
    runs = nr * nk
    min_k = np.full(nr, np.nan)
    min_mode = np.full(nr, UNRESOLVED, dtype=np.int8)
    min_ni = np.full(nr, np.nan)
    if p.locate:
        # the bisections' batches are small and many: one line for all of them; no store (the
        # bisections are computed again on a rerun, from the grid's stored outcomes)
        quiet = None if execution is None else execution.replace(progress=False, store=None)
        over = np.isin(outcome, (OVERTURN_IMPACT, OVERTURN_NO_IMPACT))
        min_k, min_mode, n1 = _bisect(p, sources, over, outcome,
                                      lambda o: (o == OVERTURN_IMPACT) | (o == OVERTURN_NO_IMPACT),
                                      quiet)
        min_ni, _, n2 = _bisect(p, sources, outcome == OVERTURN_NO_IMPACT, outcome,
                                lambda o: o == OVERTURN_NO_IMPACT, quiet)
        runs += n1 + n2
        if execution is not None and execution.progress and execution.message is not None:
            found = int(np.isfinite(min_k).sum() + np.isfinite(min_ni).sum())
            execution.message(f"spectrum: {found} boundaries located to {p.tol:g} "
                              f"(relative) in {n1 + n2} more runs")
    return SpectrumResult(
        block=block, pulse=p.pulse, ratio=p.ratios.copy(), amplitude=p.amplitudes.copy(),
        outcome=outcome, max_rotation=out["max_rotation"].reshape(shape),
        t_overturn=out["t_overturn"].reshape(shape), n_impacts=out["n_impacts"].reshape(shape),
        min_overturn=min_k, min_mode=min_mode, min_no_impact=min_ni,
        settings=dict(tol=p.tol, free_time=p.integration.free_time,
                      theta_over=p.integration.theta_over,
                      rest_speed=p.integration.rest_speed, xi=block.xi,
                      rtol=getattr(p.method, "rtol", None),
                      atol=getattr(p.method, "atol", None)),
        method=p.method if p.method == "rockjit" else p.method.name, n_runs=runs)


def _bisect(p, sources, hit, outcome, test, execution):
    """Per ratio, the smallest amplitude found with ``test(outcome)`` true, located between the
    last grid amplitude without it below the first with it (or 1, the uplift threshold), to the
    relative ``p.tol``: ``(amplitude, outcome code there, runs)``; ``nan`` where no grid
    amplitude has it."""
    nr = p.ratios.size
    amp = p.amplitudes
    lo = np.full(nr, np.nan)
    hi = np.full(nr, np.nan)
    code = np.full(nr, UNRESOLVED, dtype=np.int8)
    for i in range(nr):
        js = np.flatnonzero(hit[i])
        if js.size == 0:
            continue
        j = js[0]
        hi[i] = amp[j]
        code[i] = outcome[i, j]
        lo[i] = amp[j - 1] if j > 0 else min(1.0, amp[j])
    runs = 0
    while True:
        active = np.flatnonzero(np.isfinite(hi) & (hi - lo > p.tol * hi))
        if active.size == 0:
            break
        mid = 0.5 * (lo[active] + hi[active])
        batch = Batch((p.block,), sources, np.zeros(active.size, dtype=np.int64), active, mid)
        o = run_batch(batch, p.integration, p.method, execution, label="bisection")["outcome"]
        runs += active.size
        yes = test(o)
        hi[active[yes]] = mid[yes]
        code[active[yes]] = o[yes]
        lo[active[~yes]] = mid[~yes]
    return hi, code, runs


@entry_point(run)
def spectrum(block, pulse, ratios, amplitudes, *, integration=None, method=None, tol=1e-6,
             locate=True, execution=None) -> SpectrumResult:
    """The overturning spectrum of a pulse: outcome and demand over a grid of ratios.

    Parameters
    ----------
    block : Block
        The block (slenderness, restitution law, damping).
    pulse : Pulse
        The pulse's kind, without ``ratio`` and ``amplitude`` (the grid sweeps them):
        ``Pulse("sine")``, ``Pulse("cosine")`` or ``Pulse("ricker")``.
    ratios : array of float
        Frequency ratios ``omega_p / p``, increasing, in ``[1e-3, 1e3]``.
    amplitudes : array of float
        Amplitude ratios ``a_p / (g cot theta_c)``, increasing, in ``[0, 1e6]``.
    integration : Transient, optional
        Free rocking time, Zeno cut-off, overturning threshold; every run stops once its
        outcome is decided (``stop_when_decided``) and keeps no trajectory.
    method : {"rockjit"} or Scipy, optional
        ``"rockjit"``, the compiled path (the default: ``rockjit.ground.compiled``), or a
        :class:`rockjit.Scipy` for the scipy reference path (the checks use DOP853 at
        ``rtol = 1e-10, atol = 1e-12``).
    tol : float
        Relative width, in ``[1e-12, 0.1]``, to which the bisections locate each boundary;
        default ``1e-6``.
    locate : bool
        Locate the boundaries by bisection (default); ``False`` computes the grid alone.
    execution : Execution, optional
        Where the batches run (this process, or a Dask cluster), progress, and a chunk store
        (``store``) that keeps the grid's finished chunks: run again with the same store, an
        interrupted spectrum computes only the chunks missing, with the same result bit for
        bit.

    Returns
    -------
    SpectrumResult

    Examples
    --------
    >>> import numpy as np, rockjit
    >>> from rockjit import Block, Pulse
    >>> sp = rockjit.spectrum(Block(hb=4, xi=0.0), Pulse("cosine"), [2.0], [4.0, 6.0],
    ...                       tol=1e-4)
    >>> [round(float(k), 2) for k in sp.min_no_impact]
    [5.19]
    """
    if not isinstance(block, Block):
        raise ValueError(f"block must be a rockjit.Block (got {type(block).__name__})")
    if not isinstance(pulse, Pulse):
        raise ValueError(f"pulse must be a rockjit.Pulse (got {type(pulse).__name__})")
    pulse.require("-ratio", "-amplitude", why="a spectrum")
    if pulse.hb is not None and pulse.hb != block.hb:
        pulse.bind(block)
    ratios = axis("ratios", ratios, *RATIO_RANGE)
    amplitudes = axis("amplitudes", amplitudes, 0.0, AMPLITUDE_MAX)
    cells = float(ratios.size) * float(amplitudes.size)
    if cells > MAX_CELLS:
        raise ValueError(f"a spectrum may have at most {MAX_CELLS:.0e} cells "
                         f"(got {ratios.size} x {amplitudes.size})")
    memory(f"a spectrum of {ratios.size} x {amplitudes.size} cells", cells * 64.0)
    tol = real("tol", tol, 1e-12, 0.1)
    from ..validate import boolean
    locate = boolean("locate", locate)
    method = grid_method(method)
    return SpectrumPlan(block=block, pulse=Pulse(pulse.kind), ratios=ratios,
                        amplitudes=amplitudes, integration=grid_settings(integration),
                        method=method, tol=tol, locate=locate)


def compare(a: SpectrumResult, b: SpectrumResult):
    """Where two spectra on the same grid (two restitution laws) differ: the cells whose
    outcome differs, and the ratio of their minimum overturning amplitudes at each ratio
    (``b`` over ``a``). JSON-ready.

    Parameters
    ----------
    a, b : SpectrumResult
        Two spectra on the same ratios and amplitudes, of blocks with different laws.

    Returns
    -------
    dict
        ``cells_differ`` and ``percent_differ``, the cells whose outcome differs;
        ``min_overturn_ratio``, ``[{"ratio", "<law b>_over_<law a>"}, ...]`` (``None`` where
        either has no minimum overturning amplitude); ``differ_at``, each differing cell's
        ratio, amplitude and both outcomes.

    Examples
    --------
    >>> import sys, rockjit
    >>> from rockjit import Block, Pulse
    >>> compare = sys.modules["rockjit.ground.spectrum"].compare
    >>> a, b = (rockjit.spectrum(Block(hb=4, xi=0.0, law=law), Pulse("cosine"), [2.0],
    ...                          [4.0, 6.0], tol=1e-4) for law in ("housner", "mao"))
    >>> c = compare(a, b)
    >>> c["cells_differ"], round(float(c["min_overturn_ratio"][0]["mao_over_housner"]), 3)
    (0, 0.994)
    """
    if a.outcome.shape != b.outcome.shape or not np.allclose(a.ratio, b.ratio):
        raise ValueError("the two spectra are not on the same grid")
    diff = a.outcome != b.outcome
    rows = []
    for r, ka, kb in zip(a.ratio, a.min_overturn, b.min_overturn):
        q = kb / ka if math.isfinite(ka) and math.isfinite(kb) else None
        rows.append({"ratio": float(r), f"{b.block.law}_over_{a.block.law}": q})
    where = [{"ratio": float(a.ratio[i]), "amplitude": float(a.amplitude[j]),
              a.block.law: OUTCOMES[a.outcome[i, j]], b.block.law: OUTCOMES[b.outcome[i, j]]}
             for i, j in zip(*np.nonzero(diff))]
    return dict(cells_differ=int(np.count_nonzero(diff)),
                percent_differ=100.0 * float(np.mean(diff)), min_overturn_ratio=rows,
                differ_at=where)
