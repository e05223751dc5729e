"""Lognormal fragility curves fitted by maximum likelihood, with profile-likelihood intervals.

``P(overturn | IM = x) = Phi(ln(x / theta_m) / beta)`` (docs/theory/ground-motions.md,
"Incremental dynamic analysis and fragility curves"). :func:`fit_lognormal` fits the median
``theta_m`` and the dispersion ``beta`` to counts of overturned runs at fixed intensities by
maximising the binomial likelihood (Shinozuka et al. 2000; Baker 2015), which uses every run,
a survival above a level that overturned included. In ``(a, s) = (ln theta_m / beta,
1 / beta)`` the model is a probit regression, ``z = s ln x - a``, whose log-likelihood is
concave: Newton's method finds its maximum, and the observed information (its Hessian,
analytic) gives standard errors in ``(ln theta_m, beta)`` by the change of variables; the
median's by the delta method, ``se(theta_m) = theta_m se(ln theta_m)``. Confidence intervals
of ``theta_m`` and ``beta`` are profile-likelihood intervals: the values whose profile
log-likelihood lies within ``chi2_1(level) / 2`` of the maximum.

A fit is reported only where the data identify it. Otherwise the status says why and no
median or dispersion is given: no overturning at all (``"all_survive"``: the median lies above
the largest intensity), only overturning (``"all_overturn"``: below the smallest), or
``"unidentified"`` with a ``reason``: a single intensity level (the likelihood is flat along a
line of ``(theta_m, beta)``); complete separation (every level below a cut survives and every
level above overturns: the likelihood grows as ``beta -> 0``, with any median in the gap);
quasi-complete separation (the same, with one level mixed); an overturning fraction that does
not rise with the intensity; or a nearly flat likelihood (a probability that does not change
with the intensity fits about as well: the interval of ``beta`` has no upper end; or the
interval of the median has no end within ``MEDIAN_REACH``). The intervals are still given
where the data bound something.
:func:`fit_capacities` is the closed form from one collapse capacity per record, with exact
intervals (Student's t and chi-square).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from scipy.special import log_ndtr, ndtr, ndtri

__all__ = ["CONFIDENCE", "LognormalFit", "fit_capacities", "fit_lognormal"]

#: Confidence level of the intervals (and of the test that a fit is identified).
CONFIDENCE = 0.95
_NAN2 = (math.nan, math.nan)
_HALF_LN_2PI = 0.5 * math.log(2.0 * math.pi)
#: How far (in ln intensity) the median's interval is followed: beyond, an open end.
MEDIAN_REACH = 64.0


@dataclass(frozen=True)
class LognormalFit:
    """A lognormal fragility curve and how well the data determine it.

    Attributes
    ----------
    median, beta : float
        ``theta_m`` and ``beta``; ``nan`` unless ``status`` is ``"ok"``.
    se_median, se_beta, se_log_median : float
        Standard errors from the observed information (``nan`` unless ``"ok"``).
    status : str
        ``"ok"``, ``"unidentified"`` (see ``reason``), ``"all_survive"``, ``"all_overturn"``
        or ``"no_data"``.
    bound : float
        Where ``status`` bounds the median instead: the largest intensity (all survive), the
        smallest (all overturn); ``nan`` otherwise.
    n_runs, n_overturned : int
        The runs counted and those that overturned (for :func:`fit_capacities`: the records,
        and those whose capacity was used).
    log_likelihood : float
        The binomial log-likelihood at the fit, or its supremum where the fit is unidentified
        (``nan`` for :func:`fit_capacities`).
    reason : str
        Why the data do not identify the fit (empty when ``"ok"``).
    median_ci, beta_ci : tuple of float
        Confidence intervals ``(low, high)`` at ``confidence``: profile likelihood for
        :func:`fit_lognormal`, exact for :func:`fit_capacities`. Also given where the fit is
        unidentified and the data still bound something: ``0`` and ``inf`` are open ends;
        ``nan`` where there is no interval.
    confidence : float
        The intervals' confidence level.

    Examples
    --------
    >>> from rockjit.ground import fit_lognormal
    >>> fit = fit_lognormal([1, 2, 3, 4], [0, 3, 7, 9], [10, 10, 10, 10])
    >>> round(float(fit.probability(fit.median)), 3)      # one half at the median
    0.5
    >>> fit_lognormal([1, 2], [0, 0], [5, 5]).status        # no overturning: a bound only
    'all_survive'
    >>> f = fit_lognormal([3.0], [1], [2])                  # one level: beta is not determined
    >>> f.status, f.median, f.beta_ci
    ('unidentified', nan, (0.0, inf))
    >>> f.reason
    'one intensity level: the likelihood is flat along a line of (median, beta)'
    """

    median: float
    beta: float
    se_median: float
    se_beta: float
    se_log_median: float
    status: str
    bound: float
    n_runs: int
    n_overturned: int
    log_likelihood: float
    reason: str = ""
    median_ci: tuple = _NAN2
    beta_ci: tuple = _NAN2
    confidence: float = CONFIDENCE

    def probability(self, x):
        """The fitted ``P(overturn | IM = x)`` (``nan`` where there is no fit)."""
        x = np.asarray(x, dtype=float)
        if self.status == "ok":
            return ndtr(np.log(x / self.median) / self.beta)
        return np.full(x.shape, np.nan)

    def to_dict(self):
        """JSON-ready."""
        return dict(median=self.median, beta=self.beta, se_median=self.se_median,
                    se_beta=self.se_beta, se_log_median=self.se_log_median,
                    median_ci=list(self.median_ci), beta_ci=list(self.beta_ci),
                    confidence=self.confidence, status=self.status, reason=self.reason,
                    bound=self.bound, n_runs=self.n_runs, n_overturned=self.n_overturned,
                    log_likelihood=self.log_likelihood)


class _Probit:
    """The binomial log-likelihood of ``z_j = s (l_j - m)`` (``l`` the centred log-intensities),
    with its derivatives in ``z``."""

    def __init__(self, l, k, n):
        self.l, self.k, self.f = l, k, n - k

    def at(self, z):
        """``(loglik, dl/dz, d2l/dz2)`` per level (the second derivative is negative)."""
        lp, lm = log_ndtr(z), log_ndtr(-z)
        lphi = -0.5 * z * z - _HALF_LN_2PI
        lam_p, lam_m = np.exp(lphi - lp), np.exp(lphi - lm)     # phi / Phi: at most ~|z|
        ll = np.where(self.k > 0, self.k * lp, 0.0) + np.where(self.f > 0, self.f * lm, 0.0)
        d = self.k * lam_p - self.f * lam_m
        # lam (z + lam) lies in (0, 1); the clip only guards the rounding at extreme |z|
        w = -(self.k * np.minimum(np.maximum(lam_p * (z + lam_p), 0.0), 1.0)
              + self.f * np.minimum(np.maximum(lam_m * (lam_m - z), 0.0), 1.0))
        return float(ll.sum()), d, w

    def hessian(self, w):
        """The Hessian in ``(a, s)`` of the log-likelihood at ``z = s l - a``, from ``w``
        (:meth:`at`'s second derivatives in ``z``)."""
        l = self.l
        return np.array([[w.sum(), -(w * l).sum()], [-(w * l).sum(), (w * l * l).sum()]])

    def fit(self, a, s):
        """Newton's method in ``(a, s)``, ``z = s l - a`` (concave): the maximum."""
        l = self.l
        v, d, w = self.at(s * l - a)
        for _ in range(200):
            g = np.array([-d.sum(), (d * l).sum()])
            H = self.hessian(w)
            try:
                step = np.linalg.solve(-H, g)
            except np.linalg.LinAlgError:
                break
            t = 1.0
            while True:
                a1, s1 = a + t * step[0], s + t * step[1]
                v1, d1, w1 = self.at(s1 * l - a1)
                if v1 >= v - 1e-13 * (1 + abs(v)) or t < 1e-12:
                    break
                t *= 0.5
            done = abs(v1 - v) <= 1e-14 * (1 + abs(v)) and np.all(np.abs(t * step) <=
                                                                   1e-10 * (1 + abs(s)))
            a, s, v, d, w = a1, s1, v1, d1, w1
            if done:
                break
        return a, s, v, d, w

    def profile_s(self, s, a):
        """``max over a`` of the log-likelihood at fixed ``s > 0``, ``z = s l - a`` (concave in
        ``a``; Newton from ``a``): ``(value, a)``."""
        l = self.l
        v, d, w = self.at(s * l - a)
        for _ in range(500):
            g, h = -d.sum(), w.sum()
            da = -g / h if h < 0 else math.copysign(1.0, g)
            da = max(-2.0, min(2.0, da))
            t = 1.0
            for _ in range(30):
                v1, d1, w1 = self.at(s * l - (a + t * da))
                if v1 >= v:
                    break
                t *= 0.5
            if not v1 > v:        # no gain left at the rounding level: the maximum
                break
            a, gain, v, d, w = a + t * da, v1 - v, v1, d1, w1
            if abs(t * da) <= 1e-13 * (1.0 + abs(a)) or gain <= 1e-14 * (1.0 + abs(v)):
                break
        return v, a

    def profile_m(self, m, s, s_max):
        """``max over 0 < s <= s_max`` of the log-likelihood at fixed ``m``, ``z = s (l - m)``
        (concave in ``s``; Newton from ``s``): ``(value, s)``."""
        u = self.l - m
        v, d, w = self.at(s * u)
        for _ in range(500):
            g, h = (d * u).sum(), (w * u * u).sum()
            ds = -g / h if h < 0 else math.copysign(s, g)
            s1 = min(max(s + ds, 0.25 * s), 4.0 * s, s_max)
            t = 1.0
            for _ in range(30):
                st = s + t * (s1 - s)
                v1, d1, w1 = self.at(st * u)
                if v1 >= v:
                    break
                t *= 0.5
            if not v1 > v:        # no gain left at the rounding level: the maximum
                break
            step, gain, s, v, d, w = abs(st - s), v1 - v, st, v1, d1, w1
            if step <= 1e-13 * s or gain <= 1e-14 * (1.0 + abs(v)) or s >= s_max:
                break
        return v, s


def _root(fun, lo, hi):
    """The root of ``fun`` between ``lo`` and ``hi`` (signs differ)."""
    from scipy.optimize import brentq
    return brentq(fun, lo, hi, xtol=1e-10, rtol=1e-10)


def _intervals(pr, ll_sup, ll_flat, m0, s0, s_max, q, beta_to_zero=False):
    """Profile-likelihood intervals of ``m`` (centred ln median) and ``beta = 1/s``: where the
    profile stays above ``ll_sup - q/2``; ``(m0, s0)`` a point inside. ``ll_flat`` is the
    supremum as ``beta -> inf`` (a constant probability). Returns ``((m_lo, m_hi), (b_lo,
    b_hi))`` with ``-inf``/``inf`` and ``0``/``inf`` for open ends (the median's beyond
    ``MEDIAN_REACH`` log units of ``m0``). ``beta_to_zero``: the supremum is reached as
    ``beta -> 0`` (separation, or a flat likelihood), so beta's interval starts at 0."""
    target = ll_sup - 0.5 * q
    step = math.log(2.0)

    def gs(u):                       # u = ln s; each profile from the same start: one function
        return pr.profile_s(math.exp(u), m0 * math.exp(u))[0] - target

    def gm(m):
        return pr.profile_m(m, s0, s_max)[0] - target

    # beta's upper end: s below s0 (the profile falls to ll_flat as s -> 0)
    if ll_flat >= target:
        b_hi = math.inf
    else:
        u0, u = math.log(s0), math.log(s0) - step
        while gs(u) >= 0 and u > math.log(s0) - 200.0:
            u0, u = u, u - step
        b_hi = 1.0 / math.exp(_root(gs, u, u0)) if gs(u) < 0 else math.inf
    # beta's lower end: s above s0
    u0, u, b_lo = math.log(s0), math.log(s0) + step, 0.0
    while u <= math.log(s_max) and not beta_to_zero:
        if gs(u) < 0:
            b_lo = 1.0 / math.exp(_root(gs, u0, u))
            break
        u0, u = u, u + step
    # the median's ends
    ends = []
    for sign in (-1.0, 1.0):
        inner, d, end = m0, 0.05, sign * math.inf
        while d <= MEDIAN_REACH:
            m = m0 + sign * d
            if gm(m) < 0:
                end = _root(gm, *sorted((inner, m)))
                break
            inner, d = m, 2.0 * d
        ends.append(end)
    return (ends[0], ends[1]), (b_lo, b_hi)


def _ll_binomial(k, n):
    """The binomial log-likelihood at the observed fractions (``0 log 0 = 0``)."""
    p = k / n
    with np.errstate(divide="ignore", invalid="ignore"):
        t = np.where(k > 0, k * np.log(np.where(k > 0, p, 1.0)), 0.0) + \
            np.where(k < n, (n - k) * np.log(np.where(k < n, 1 - p, 1.0)), 0.0)
    return float(t.sum())


def fit_lognormal(x, overturned, runs, *, confidence=CONFIDENCE) -> LognormalFit:
    """Fit a lognormal fragility curve to ``overturned[j]`` overturnings among ``runs[j]`` runs
    at intensity ``x[j] > 0``, by maximum likelihood, with profile-likelihood intervals.

    Parameters
    ----------
    x : array_like of float
        The intensities, finite and positive.
    overturned : array_like of int
        How many runs overturned at each intensity, in ``[0, runs[j]]``.
    runs : array_like of int
        How many runs were made at each intensity (levels with none are left out).
    confidence : float
        The intervals' confidence level, in ``(0, 1)`` (default 0.95).

    Returns
    -------
    LognormalFit
        The median and dispersion with their standard errors and intervals (status
        ``"ok"``); or, where the data do not determine them, no estimate and the status that
        says why (``"unidentified"`` with its ``reason``, ``"all_survive"``,
        ``"all_overturn"``, ``"no_data"``).

    Examples
    --------
    >>> from rockjit.ground.fitting import fit_lognormal
    >>> fit = fit_lognormal([1, 2, 3, 4], [0, 3, 7, 9], [10, 10, 10, 10])
    >>> fit.status, round(fit.median, 2), round(fit.beta, 2)
    ('ok', 2.47, 0.36)
    >>> [round(v, 2) for v in fit.median_ci], [round(v, 2) for v in fit.beta_ci]
    ([1.99, 2.98], [0.22, 0.69])
    >>> fit_lognormal([1, 2, 3], [0, 5, 5], [5, 5, 5]).reason       # a clean cut
    'complete separation between 1 and 2: beta -> 0 and any median in between fits'
    """
    x, k, n = _checked_counts(x, overturned, runs, confidence)
    N, K = int(n.sum()), int(k.sum())
    if N == 0:
        return _no_estimate("no_data", N, K, confidence)
    if K == 0:
        return _no_estimate("all_survive", N, K, confidence, bound=float(x.max()))
    if K == N:
        return _no_estimate("all_overturn", N, K, confidence, bound=float(x.min()))
    levels = _Levels(x, k, n, confidence)
    for rule in (_one_level, _separation):
        fit = rule(levels)
        if fit is not None:
            return fit
    return _maximum(levels)


def _checked_counts(x, overturned, runs, confidence):
    """``(x, k, n)`` as float arrays over the levels with runs; a ``ValueError`` where the data
    or ``confidence`` are out of range."""
    x = np.asarray(x, dtype=float).ravel()
    k = np.asarray(overturned, dtype=float).ravel()
    n = np.asarray(runs, dtype=float).ravel()
    if not (x.shape == k.shape == n.shape):
        raise ValueError("x, overturned and runs must have the same length")
    if not 0.0 < confidence < 1.0:
        raise ValueError(f"confidence must be in (0, 1) (got {confidence!r})")
    use = n > 0
    x, k, n = x[use], k[use], n[use]
    if np.any(~np.isfinite(x)) or np.any(x <= 0):
        raise ValueError("the intensities must be finite and positive")
    if np.any(k < 0) or np.any(k > n):
        raise ValueError("overturned counts must lie in [0, runs]")
    return x, k, n


def _no_estimate(status, N, K, confidence, bound=math.nan):
    """A fit without median, dispersion or intervals: ``status``, and the median's ``bound``."""
    nan = math.nan
    return LognormalFit(nan, nan, nan, nan, nan, status, bound, N, K, nan,
                        confidence=confidence)


class _Levels:
    """Counts with both outcomes among them, in log intensity (``c`` their mean), with what the
    rules of :func:`fit_lognormal` share: the probit likelihood, the supremum of a constant
    probability ``ll_flat``, the interval threshold ``q`` and the reach ``s_max`` of ``s``."""

    def __init__(self, x, k, n, confidence):
        self.k, self.n, self.confidence = k, n, confidence
        self.N, self.K = int(n.sum()), int(k.sum())
        self.lx = np.log(x)
        self.c = float(np.sum(n * self.lx) / self.N)
        self.pr = _Probit(self.lx - self.c, k, n)
        self.q = float(_chi2_1(confidence))
        self.ll_flat = _ll_binomial(np.array([self.K], float), np.array([self.N], float))
        spread = float(np.ptp(self.lx))
        self.s_max = 1e8 / max(spread, 1e-3)

    def intervals(self, ll_sup, m0, s0, beta_to_zero=False):
        """The profile-likelihood intervals of the median (in intensity) and ``beta``."""
        (m_lo, m_hi), bci = _intervals(self.pr, ll_sup, self.ll_flat, m0, s0, self.s_max,
                                       self.q, beta_to_zero)
        return (math.exp(m_lo + self.c), math.exp(m_hi + self.c)), bci

    def unidentified(self, reason, ll_sup, m0=None, s0=None, beta_to_zero=False):
        """No estimate, for ``reason``; the intervals where the data bound something (searched
        from ``(m0, s0)`` where given)."""
        mci = bci = _NAN2
        if m0 is not None:
            try:
                mci, bci = self.intervals(ll_sup, m0, s0, beta_to_zero)
            except (ValueError, OverflowError, FloatingPointError):
                mci = bci = _NAN2
        nan = math.nan
        return LognormalFit(nan, nan, nan, nan, nan, "unidentified", nan, self.N, self.K,
                            ll_sup, reason, tuple(map(float, mci)), tuple(map(float, bci)),
                            self.confidence)


def _one_level(d):
    """Unidentified where every run is at one intensity, else ``None``."""
    if np.unique(d.lx).size == 1:
        return d.unidentified("one intensity level: the likelihood is flat along a line of "
                              "(median, beta)", d.ll_flat, 0.0, 1.0 / max(abs(d.c), 1.0), True)
    return None


def _separation(d):
    """Unidentified where a cut separates the outcomes (every run below survives, every run
    above overturns, one level at most mixed), else ``None``."""
    lx, k, n = d.lx, d.k, d.n
    survive_max = lx[k < n].max()   # the highest level with a survival
    over_min = lx[k > 0].min()      # the lowest level with an overturning
    if survive_max > over_min:
        return None
    s0 = d.s_max * 1e-3
    if survive_max < over_min:
        return d.unidentified(
            f"complete separation between {math.exp(survive_max):.6g} and "
            f"{math.exp(over_min):.6g}: beta -> 0 and any median in between fits", 0.0,
            0.5 * (survive_max + over_min) - d.c, s0, True)
    mixed = lx == survive_max
    km, nm = k[mixed].sum(), n[mixed].sum()
    m0 = survive_max - d.c - float(ndtri(km / nm)) / s0
    return d.unidentified(
        f"quasi-complete separation at {math.exp(survive_max):.6g}: every run below "
        f"survives and every run above overturns, the likelihood grows as beta -> 0",
        _ll_binomial(k[mixed], n[mixed]), m0, s0, True)


def _start(d):
    """A start ``(m0, s0)``: the median where the empirical fraction crosses 1/2, ``s0`` from
    the spread of the log intensities."""
    lx = d.lx
    order = np.argsort(lx)
    m0 = float(np.interp(0.5, np.maximum.accumulate((d.k / d.n)[order]), lx[order])) - d.c
    s0 = 1.0 / max(0.1, float(np.sqrt(np.sum(d.n * (lx - d.c) ** 2) / d.N)))
    return m0, s0


def _standard_errors(pr, w, a, s):
    """``(se(ln theta_m), se(beta))`` from the observed information in ``(a, s)`` (``w``: the
    second derivatives in ``z``), by the change of variables."""
    H = pr.hessian(w)
    J = np.array([[1.0 / s, -a / s ** 2], [0.0, -1.0 / s ** 2]])   # d(m, beta)/d(a, s)
    try:
        cov = J @ np.linalg.inv(-H) @ J.T
        return tuple(math.sqrt(v) if v > 0 else math.nan for v in np.diag(cov))
    except np.linalg.LinAlgError:
        return math.nan, math.nan


def _maximum(d):
    """The maximum-likelihood fit with its intervals, or unidentified where the likelihood is
    too flat to bound ``beta`` or the median."""
    m0, s0 = _start(d)
    a, s, ll, _, w = d.pr.fit(s0 * m0, s0)
    a, s = float(a), float(s)
    if not (s > 0 and math.isfinite(s)):
        return d.unidentified("the fraction overturned does not rise with the intensity",
                              d.ll_flat)
    m = a / s
    if 2.0 * (ll - d.ll_flat) < d.q:
        return d.unidentified(
            f"nearly flat likelihood: a probability that does not change with the intensity "
            f"fits about as well (likelihood ratio {2 * (ll - d.ll_flat):.3g} < {d.q:.3g}), "
            f"so the data set no upper end to beta", ll, m, s)
    se_mu, se_beta = _standard_errors(d.pr, w, a, s)
    mci, bci = d.intervals(ll, m, s)
    if not (mci[0] > 0.0 and mci[1] < math.inf):
        # the profile of the median falls too slowly: it is not bounded within reach
        side = "lower" if mci[0] == 0.0 else "upper"
        return d.unidentified(f"nearly flat likelihood: the data set no {side} end to the "
                              f"median", ll, m, s)
    median = math.exp(m + d.c)
    return LognormalFit(median, 1.0 / s, median * se_mu, se_beta, se_mu, "ok", math.nan, d.N,
                        d.K, ll, "", mci, tuple(map(float, bci)), d.confidence)


def _chi2_1(p):
    """The ``p`` quantile of the chi-square distribution with one degree of freedom."""
    return float(ndtri(0.5 + 0.5 * p)) ** 2


def fit_capacities(capacities, *, confidence=CONFIDENCE) -> LognormalFit:
    """The lognormal fit to one collapse capacity per record (docs/theory/ground-motions.md):
    ``ln theta_m`` the mean of ``ln x_i``, ``beta^2`` their variance (divided by ``n``);
    standard errors ``beta / sqrt(n)`` and ``beta / sqrt(2 n)``; exact intervals, from
    Student's t for the median and the chi-square distribution for ``beta`` (normal
    ``ln x_i``). Capacities that are not finite (``inf``: a record that never overturned the
    block; ``nan``: one whose capacity lies below the intensities tried) are left out:
    ``n_runs`` counts every record, ``n_overturned`` those used.

    Parameters
    ----------
    capacities : array_like of float
        Each record's collapse capacity: the intensity at which it first overturned the block.
    confidence : float
        The intervals' confidence level, in ``(0, 1)`` (default 0.95).

    Returns
    -------
    LognormalFit
        Status ``"ok"``; ``"no_data"`` with fewer than two finite capacities;
        ``"unidentified"`` when they are all equal (``beta`` is below the resolution of the
        intensities).

    Examples
    --------
    >>> from rockjit.ground import fit_capacities
    >>> fit = fit_capacities([2.0, 3.0, 4.5, float("inf")])    # the last never overturned
    >>> round(fit.median, 3), round(fit.beta, 3), fit.n_runs, fit.n_overturned
    (3.0, 0.331, 4, 3)
    >>> [round(v, 2) for v in fit.median_ci], [round(v, 2) for v in fit.beta_ci]
    ([1.1, 8.21], [0.21, 2.55])
    """
    from scipy.stats import chi2, t as student

    if not 0.0 < confidence < 1.0:
        raise ValueError(f"confidence must be in (0, 1) (got {confidence!r})")
    c = np.asarray(capacities, dtype=float).ravel()
    fin = c[np.isfinite(c)]
    if np.any(fin <= 0):
        raise ValueError("capacities must be positive")
    n = fin.size
    nan = math.nan
    if n < 2:
        return LognormalFit(nan, nan, nan, nan, nan, "no_data", nan, int(c.size), n, nan,
                            confidence=confidence)
    lc = np.log(fin)
    mu = float(lc.mean())
    ss = float(np.sum((lc - mu) ** 2))
    if ss <= 1e-24 * max(1.0, mu * mu) * n:
        return LognormalFit(nan, nan, nan, nan, nan, "unidentified", nan, int(c.size), n, nan,
                            f"every capacity is {math.exp(mu):.6g}: the dispersion is below "
                            f"the spacing of the intensities", confidence=confidence)
    beta = math.sqrt(ss / n)
    se_mu = beta / math.sqrt(n)
    alpha = 1.0 - confidence
    half = float(student.ppf(1.0 - alpha / 2, n - 1)) * math.sqrt(ss / (n - 1) / n)
    beta_ci = (math.sqrt(ss / float(chi2.ppf(1.0 - alpha / 2, n - 1))),
               math.sqrt(ss / float(chi2.ppf(alpha / 2, n - 1))))
    return LognormalFit(math.exp(mu), beta, math.exp(mu) * se_mu, beta / math.sqrt(2 * n),
                        se_mu, "ok", nan, int(c.size), n, nan, "",
                        (math.exp(mu - half), math.exp(mu + half)), beta_ci, confidence)
