"""Incremental dynamic analysis of a block over a record set, and its fragility curves.

:func:`fragility` scales every record of a set to each of a list of intensities, runs the
block from rest under each scaled record (for each block size and each restitution law), and
fits lognormal curves by maximum likelihood (:mod:`rockjit.ground.fitting`; a curve the runs
do not identify is reported as such, without an estimate) to:

- the probability of overturning against the intensity (the fragility curve);
- the probability that ``max |theta| / alpha_s`` reaches 0.5 and 1 (rotation exceedance; an
  overturned run exceeds every level).

The intensity measure is ``PGA / (g cot theta_c)`` (``measure="pga"``, the default: the
record's peak ground acceleration over the uplift threshold, dimensionless, 1 at uplift) or
the peak ground velocity in m/s (``measure="pgv"``). Both are measured on the record itself,
independent of the block's size, so the curves of blocks of several sizes (``sizes``) are
directly comparable: Housner's scale effect makes the larger block the safer one
(docs/theory/ground-motions.md).

All runs (laws x sizes x records x intensities) form one batch
(:mod:`rockjit.ground.batch`): the compiled kernel by default, in this process
or on a Dask cluster.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np

from ..entry import entry_point
from ..model import LAWS, Block
from ..validate import choice, memory, real, real_array
from .batch import Batch, grid_method, run_batch
from .fitting import fit_capacities, fit_lognormal
from .plan import grid_settings
from .records import SIZE_RANGE, Record
from .response import OVERTURN_IMPACT, OVERTURN_NO_IMPACT, UNRESOLVED

__all__ = ["EXCEEDANCE", "FragilityPlan", "FragilityResult", "MEASURES", "fragility", "run"]

#: Intensity measures: name -> what it is.
MEASURES = {"pga": "PGA / (g cot theta_c)", "pgv": "PGV (m/s)"}
#: The rotation levels ``max |theta| / alpha_s`` whose exceedance is fitted.
EXCEEDANCE = (0.5, 1.0)
#: Most runs one analysis may ask for.
MAX_RUNS = 10**8


def measure_of(record, measure, hb):
    """The record's own intensity (its scale included): ``PGA hb`` or ``PGV``."""
    return record.pga * hb if measure == "pga" else record.pgv


@dataclass(frozen=True, eq=False)
class FragilityPlan:
    """A validated incremental dynamic analysis."""

    blocks: tuple        # one per law
    records: tuple       # Records (sizes not bound)
    sizes: np.ndarray
    intensities: np.ndarray
    measure: str
    integration: object
    method: object

    @property
    def runs(self):
        return len(self.blocks) * self.sizes.size * len(self.records) * self.intensities.size


@dataclass
class FragilityResult:
    """An incremental dynamic analysis: every run's outcome and its fitted curves.

    ``outcome[l, s, r, j]`` belongs to law ``laws[l]``, size ``sizes[s]``, record
    ``records[r]`` and intensity ``intensity[j]`` (codes of
    :data:`rockjit.ground.OUTCOMES`); ``max_rotation`` and ``t_overturn`` likewise;
    ``scale[r, j]`` is the factor record ``r`` was scaled by. ``fits[law][size]`` holds the
    :class:`~rockjit.ground.LognormalFit` of ``"overturn"``, of each rotation
    exceedance ``"exceed_0.5"``, ``"exceed_1"``, and ``"capacity"``: the closed-form fit to each
    record's first overturning intensity.

    Attributes
    ----------
    block : Block
        The block (its law is the first of ``laws``).
    laws : tuple of str
        The restitution laws run.
    sizes : ndarray, shape (n_sizes,)
        The block's half-diagonals in metres.
    records : tuple of Record
        The records, unscaled.
    intensity : ndarray, shape (n_intensities,)
        The intensities every record was scaled to.
    measure : str
        ``"pga"`` or ``"pgv"``.
    outcome : ndarray of int8, shape (n_laws, n_sizes, n_records, n_intensities)
        Each run's outcome code (:data:`rockjit.ground.OUTCOMES`).
    max_rotation, t_overturn : ndarray, same shape
        Each run's ``max |theta| / alpha_s`` and overturning time (``nan``: it did not).
    scale : ndarray, shape (n_records, n_intensities)
        The factor each record was scaled by.
    fits : dict
        ``fits[law][size][name]``: the :class:`~rockjit.ground.LognormalFit` of ``"overturn"``,
        ``"exceed_0.5"``, ``"exceed_1"`` and ``"capacity"``.
    settings : dict
        The integration's settings, for the summary.
    method : str
        The path that ran, e.g. ``"scipy:DOP853"``.

    Examples
    --------
    >>> import numpy as np, rockjit
    >>> from rockjit import Block, Record, Transient
    >>> t = np.arange(0.0, 2.0, 0.01)
    >>> rec = Record(0.3 * np.sin(2 * np.pi * t) * np.sin(np.pi * t / 2), 0.01, name="1 Hz")
    >>> fr = rockjit.fragility(Block(hb=3), [rec], sizes=[0.5, 2.0], intensities=[2.0, 4.0],
    ...                        laws=("housner", "mao"), integration=Transient(free_time=20.0))
    >>> fr.outcome.shape                              # laws, sizes, records, intensities
    (2, 2, 1, 2)
    >>> fr.capacities("housner", 0.5).tolist()        # the record's first overturning intensity
    [4.0]
    """

    block: Block
    laws: tuple
    sizes: np.ndarray
    records: tuple
    intensity: np.ndarray
    measure: str
    outcome: np.ndarray
    max_rotation: np.ndarray
    t_overturn: np.ndarray
    scale: np.ndarray
    fits: dict = field(default_factory=dict)
    settings: dict = field(default_factory=dict)
    method: str = ""

    def __repr__(self):
        from ..reprs import text
        return text(self)

    @property
    def overturned(self):
        """Runs that overturned (either mode), as a boolean array shaped like ``outcome``."""
        return np.isin(self.outcome, (OVERTURN_IMPACT, OVERTURN_NO_IMPACT))

    @property
    def resolved(self):
        """Runs with an outcome (not ``"unresolved"``), as a boolean array."""
        return self.outcome != UNRESOLVED

    def exceeded(self, level):
        """Runs whose ``max |theta| / alpha_s`` reached ``level`` (overturned ones included)."""
        return self.overturned | (self.max_rotation >= level)

    def fraction(self, what="overturn"):
        """The fraction of resolved runs, per law, size and intensity, that overturned
        (``"overturn"``) or exceeded a level (``"exceed_0.5"``): shape ``(laws, sizes,
        intensities)``."""
        hit = self.overturned if what == "overturn" else \
            self.exceeded(float(what.split("_", 1)[1]))
        n = self.resolved.sum(axis=2)
        with np.errstate(invalid="ignore", divide="ignore"):
            return np.where(n > 0, (hit & self.resolved).sum(axis=2) / n, np.nan)

    def capacities(self, law, size):
        """Each record's collapse capacity: the smallest intensity of the list at which it
        overturned the block; ``inf`` where it never did, ``nan`` where it did already at the
        smallest (the capacity lies below the list). Resolved to the list's spacing."""
        l, s = self.laws.index(law), int(np.flatnonzero(self.sizes == size)[0])
        over = self.overturned[l, s]
        return np.array([(self.intensity[np.argmax(o)] if np.argmax(o) > 0 else np.nan)
                         if o.any() else np.inf for o in over])

    def median_ratio(self, a="mao", b="housner"):
        """``median(a) / median(b)`` of the overturning fits at each size (``nan`` where
        either has no fitted median)."""
        if a not in self.laws or b not in self.laws:
            return {}
        out = {}
        for size in self.sizes:
            ma = self.fits[a][float(size)]["overturn"].median
            mb = self.fits[b][float(size)]["overturn"].median
            out[float(size)] = ma / mb if math.isfinite(ma) and math.isfinite(mb) and mb \
                else math.nan
        return out

    def summary(self):
        """JSON-ready: per law and size, the fitted curves and the empirical fractions; the
        ratio of Mao's to Housner's median when both laws ran."""
        laws = {}
        for li, law in enumerate(self.laws):
            per = {}
            for si, size in enumerate(self.sizes):
                f = self.fits[law][float(size)]
                per[f"{float(size):g}"] = dict(
                    {k: v.to_dict() for k, v in f.items()},
                    fraction_overturned=self.fraction("overturn")[li, si].tolist(),
                    **{f"fraction_exceed_{lv:g}": self.fraction(f"exceed_{lv:g}")[li, si]
                       .tolist() for lv in EXCEEDANCE},
                    unresolved=int(np.count_nonzero(~self.resolved[li, si])))
            b = self.block.replace(law=law)
            laws[law] = dict(restitution=b.restitution, sizes=per)
        out = dict(measure=self.measure, measure_is=MEASURES[self.measure],
                   intensity=self.intensity.tolist(), hb=self.block.hb, xi=self.block.xi,
                   sizes=[float(s) for s in self.sizes],
                   records=[r.name for r in self.records], laws=laws,
                   method=self.method, settings=self.settings)
        if "mao" in self.laws and "housner" in self.laws:
            out["mao_over_housner_median"] = {f"{k:g}": v for k, v in
                                              self.median_ratio().items()}
        if self.sizes.size > 1:
            out["size_effect"] = {law: {f"{float(s):g}": self.fits[law][float(s)]["overturn"]
                                        .median for s in self.sizes} for law in self.laws}
        return out

    def arrays(self):
        """The analysis's arrays by name, for an ``.npz``."""
        return dict(outcome=self.outcome, max_rotation=self.max_rotation,
                    t_overturn=self.t_overturn, scale=self.scale, intensity=self.intensity,
                    sizes=self.sizes, laws=np.asarray(self.laws, dtype=str),
                    records=np.asarray([r.name for r in self.records], dtype=str))


def run(p: FragilityPlan, execution=None) -> FragilityResult:
    """Compute a :class:`FragilityPlan`: one batch of every run, then the fits."""
    nl, ns, nr, nx = len(p.blocks), p.sizes.size, len(p.records), p.intensities.size
    hb = p.blocks[0].hb
    own = np.array([measure_of(r, p.measure, hb) for r in p.records])
    scale = p.intensities[None, :] / own[:, None]                       # (nr, nx)
    sources = tuple(r.bind(size=float(s)) for s in p.sizes for r in p.records)
    L, S, R, J = np.meshgrid(np.arange(nl), np.arange(ns), np.arange(nr), np.arange(nx),
                             indexing="ij")
    batch = Batch(p.blocks, sources, L.ravel(), (S * nr + R).ravel(), scale[R, J].ravel())
    out = run_batch(batch, p.integration, p.method, execution, label="fragility")
    shape = (nl, ns, nr, nx)
    res = FragilityResult(
        block=p.blocks[0], laws=tuple(b.law for b in p.blocks), sizes=p.sizes.copy(),
        records=p.records, intensity=p.intensities.copy(), measure=p.measure,
        outcome=out["outcome"].reshape(shape), max_rotation=out["max_rotation"].reshape(shape),
        t_overturn=out["t_overturn"].reshape(shape), scale=scale,
        settings=dict(free_time=p.integration.free_time, theta_over=p.integration.theta_over,
                      rest_speed=p.integration.rest_speed,
                      rtol=getattr(p.method, "rtol", None), atol=getattr(p.method, "atol", None)),
        method=p.method if p.method == "rockjit" else p.method.name)
    ok = res.resolved
    for li, law in enumerate(res.laws):
        res.fits[law] = {}
        for si, size in enumerate(res.sizes):
            n = ok[li, si].sum(axis=0)
            fits = {"overturn": fit_lognormal(res.intensity, (res.overturned & ok)[li, si]
                                              .sum(axis=0), n)}
            for lv in EXCEEDANCE:
                fits[f"exceed_{lv:g}"] = fit_lognormal(
                    res.intensity, (res.exceeded(lv) & ok)[li, si].sum(axis=0), n)
            fits["capacity"] = fit_capacities(res.capacities(law, size))
            res.fits[law][float(size)] = fits
    return res


def _records(records):
    """The records, checked: a record set's name or a sequence of records, each with some
    motion to scale."""
    if isinstance(records, str):
        from .fema import fema_set
        return fema_set(records)
    try:
        recs = tuple(records)
    except TypeError:
        raise ValueError(f"records must be a record set's name or a sequence of "
                         f"rockjit.Record (got {type(records).__name__})") from None
    if not recs:
        raise ValueError("records must hold at least one record")
    for r in recs:
        if not isinstance(r, Record):
            raise ValueError(f"records must be rockjit.Record objects (got "
                             f"{type(r).__name__})")
    for r in recs:
        if r.pga == 0.0:
            raise ValueError(f"record {r.name!r} has no motion (PGA 0): it cannot be scaled")
    return recs


def _sizes(sizes):
    """The block's sizes, checked: one or more distinct half-diagonals in metres."""
    sz = np.atleast_1d(real_array("sizes", sizes, "one or more sizes in metres")).astype(float)
    if sz.ndim != 1 or sz.size == 0:
        raise ValueError(f"sizes must be one or more numbers (got {sizes!r})")
    for s in sz:
        real("size", float(s), *SIZE_RANGE)
    if np.unique(sz).size != sz.size:
        raise ValueError(f"sizes must be distinct (got {sz.tolist()})")
    return sz


def _intensities(intensities):
    """The intensities, checked: one or more, positive and increasing."""
    x = np.atleast_1d(real_array("intensities", intensities, "increasing positive numbers"))
    x = x.astype(float)
    if x.ndim != 1 or x.size == 0:
        raise ValueError(f"intensities must be one or more numbers (got {intensities!r})")
    for v in x:
        real("intensity", float(v), 0.0, 1e6, lo_open=True)
    if x.size > 1 and not np.all(np.diff(x) > 0):
        raise ValueError(f"intensities must be increasing (got {x.tolist()})")
    return x


def _blocks(block, laws):
    """One block per restitution law of ``laws`` (distinct names), or ``block`` alone."""
    if laws is None:
        return (block,)
    names = (laws,) if isinstance(laws, str) else tuple(laws)
    if not names:
        raise ValueError("laws must name at least one restitution law")
    for name in names:
        choice("law", name, LAWS)
    if len(set(names)) != len(names):
        raise ValueError(f"laws must be distinct (got {names})")
    return tuple(block if name == block.law else block.replace(law=name) for name in names)


@entry_point(run)
def fragility(block, records, sizes, intensities, *, measure="pga", laws=None,
              integration=None, method=None, execution=None) -> FragilityResult:
    """Incremental dynamic analysis: overturning and rotation fragility curves of a block over
    a record set.

    Parameters
    ----------
    block : Block
        The block's slenderness and damping (and its law, unless ``laws`` is given).
    records : str or sequence of Record
        A FEMA P695 set (``"farfield"``, ``"nearfield"``, ``"nearfield-pulse"``,
        ``"nearfield-no-pulse"``; the ``records`` extra) or records read with
        :func:`rockjit.ground.read_record` and friends (their sizes are ignored).
    sizes : sequence of float
        The block's half-diagonal ``R`` in metres, one or more, in ``[1e-3, 1e4]``.
    intensities : sequence of float
        The intensities every record is scaled to, increasing and positive.
    measure : {"pga", "pgv"}
        ``PGA / (g cot theta_c)`` (default) or PGV in m/s.
    laws : sequence of str, optional
        Restitution laws to run, e.g. ``("housner", "mao")``; default the block's.
    integration : Transient, optional
        Free rocking time after each record, Zeno cut-off, overturning threshold; every run
        stops once its outcome is decided.
    method : {"rockjit"} or Scipy, optional
        ``"rockjit"``, the compiled path (the default), or a :class:`rockjit.Scipy` for the
        scipy reference path (the checks use DOP853 at ``rtol = 1e-10, atol = 1e-12``).
    execution : Execution, optional
        Where the batch runs (this process, or a Dask cluster) and progress.

    Returns
    -------
    FragilityResult
        Every run's outcome and demand, and the fitted curves per law and size.

    Examples
    --------
    Two short synthetic records, scaled to three intensities:

    >>> import numpy as np, rockjit
    >>> from rockjit import Block, Record, Transient
    >>> t = np.arange(0.0, 2.0, 0.01)
    >>> records = [Record(0.3 * np.sin(2 * np.pi * f * t) * np.sin(np.pi * t / 2), 0.01,
    ...                   name=f"{f:g} Hz") for f in (1.0, 2.0)]
    >>> fr = rockjit.fragility(Block(hb=3), records, sizes=[0.5], intensities=[0.9, 2.0, 4.0],
    ...                        integration=Transient(free_time=20.0))
    >>> fr.fraction("overturn")[0, 0].tolist()      # per intensity
    [0.0, 0.0, 1.0]
    >>> fit = fr.fits["housner"][0.5]["overturn"]    # a clean cut between 2 and 4: no estimate
    >>> fit.status, fit.median, [round(v, 2) for v in fit.median_ci]
    ('unidentified', nan, [1.82, 4.52])
    >>> fit.reason
    'complete separation between 2 and 4: beta -> 0 and any median in between fits'
    """
    if not isinstance(block, Block):
        raise ValueError(f"block must be a rockjit.Block (got {type(block).__name__})")
    recs = _records(records)
    sz, x = _sizes(sizes), _intensities(intensities)
    choice("measure", measure, tuple(MEASURES))
    blocks = _blocks(block, laws)
    n = float(len(blocks)) * sz.size * len(recs) * x.size
    if n > MAX_RUNS:
        raise ValueError(f"an analysis may have at most {MAX_RUNS:.0e} runs (got {n:.3g})")
    memory(f"{n:.3g} runs", n * 64.0)
    method = grid_method(method)
    return FragilityPlan(blocks=blocks, records=recs, sizes=sz, intensities=x,
                         measure=measure, integration=grid_settings(integration),
                         method=method)
