"""Lognormal fragility curves fitted by maximum likelihood.

``P(overturn | IM = x) = Phi(ln(x / theta_m) / beta)`` (docs/theory/ground-motions.md,
"Incremental dynamic analysis and fragility curves"). :func:`fit_lognormal` fits the median
``theta_m`` and the dispersion ``beta`` to counts of overturned runs at fixed intensities by
maximising the binomial likelihood (Shinozuka et al. 2000; Baker 2015), which uses every run,
a survival above a level that overturned included. Standard errors come from the observed
information matrix: the Hessian of the negative log-likelihood at its maximum, in
``(ln theta_m, beta)``, inverted; the median's by the delta method,
``se(theta_m) = theta_m se(ln theta_m)``.

Data the likelihood has no interior maximum for are reported as such rather than fitted:
no overturning at all (``"all_survive"``: the median lies above the largest intensity), only
overturning (``"all_overturn"``: below the smallest), or a clean cut between the levels
(``"separated"``: ``beta -> 0`` and any median between the two levels; the geometric mean is
given). :func:`fit_capacities` is the closed form from one collapse capacity per record.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from scipy.special import log_ndtr, ndtr

__all__ = ["LognormalFit", "fit_capacities", "fit_lognormal"]

#: Smallest dispersion the fit reports as a finite maximum; below it the data are a clean cut.
BETA_MIN = 1e-3


@dataclass(frozen=True)
class LognormalFit:
    """A lognormal fragility curve and how well the data determine it.

    Attributes
    ----------
    median, beta : float
        ``theta_m`` and ``beta`` (``nan`` where the data have no maximum; see ``status``).
    se_median, se_beta, se_log_median : float
        Standard errors from the observed information (``nan`` without an interior maximum).
    status : str
        ``"ok"``, ``"all_survive"``, ``"all_overturn"``, ``"separated"`` or ``"no_data"``.
    bound : float
        Where ``status`` bounds the median instead: the largest intensity (all survive), the
        smallest (all overturn); ``nan`` otherwise.
    n_runs, n_overturned : int
        The runs counted and those that overturned (for :func:`fit_capacities`: the records,
        and those whose capacity was used).
    log_likelihood : float
        The binomial log-likelihood at the fit (``nan`` for :func:`fit_capacities`).

    Examples
    --------
    >>> from rockjit.ground import fit_lognormal
    >>> fit = fit_lognormal([1, 2, 3, 4], [0, 3, 7, 9], [10, 10, 10, 10])
    >>> round(float(fit.probability(fit.median)), 3)      # one half at the median
    0.5
    >>> fit_lognormal([1, 2], [0, 0], [5, 5]).status        # no overturning: a bound only
    'all_survive'
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

    def probability(self, x):
        """The fitted ``P(overturn | IM = x)`` (``nan`` where there is no fit; a step for a
        separated fit)."""
        x = np.asarray(x, dtype=float)
        if self.status == "ok":
            return ndtr(np.log(x / self.median) / self.beta)
        if self.status == "separated":
            return (x >= self.median).astype(float)
        return np.full(x.shape, np.nan)

    def to_dict(self):
        """JSON-ready."""
        return dict(median=self.median, beta=self.beta, se_median=self.se_median,
                    se_beta=self.se_beta, se_log_median=self.se_log_median,
                    status=self.status, bound=self.bound, n_runs=self.n_runs,
                    n_overturned=self.n_overturned, log_likelihood=self.log_likelihood)


def _nll(mu, beta, lx, k, n):
    """Negative binomial log-likelihood (without the binomial coefficients)."""
    z = (lx - mu) / beta
    return -float(np.sum(k * log_ndtr(z) + (n - k) * log_ndtr(-z)))


def _hessian(fun, x, h):
    """Central-difference Hessian of ``fun`` at ``x`` with steps ``h``."""
    m = len(x)
    H = np.empty((m, m))
    f0 = fun(x)
    for i in range(m):
        ei = np.zeros(m)
        ei[i] = h[i]
        H[i, i] = (fun(x + ei) - 2.0 * f0 + fun(x - ei)) / h[i] ** 2
        for j in range(i + 1, m):
            ej = np.zeros(m)
            ej[j] = h[j]
            H[i, j] = H[j, i] = (fun(x + ei + ej) - fun(x + ei - ej) - fun(x - ei + ej)
                                 + fun(x - ei - ej)) / (4.0 * h[i] * h[j])
    return H


def fit_lognormal(x, overturned, runs) -> LognormalFit:
    """Fit a lognormal fragility curve to ``overturned[j]`` overturnings among ``runs[j]`` runs
    at intensity ``x[j] > 0``, by maximum likelihood.

    Parameters
    ----------
    x : array_like of float
        The intensities, finite and positive.
    overturned : array_like of int
        How many runs overturned at each intensity, in ``[0, runs[j]]``.
    runs : array_like of int
        How many runs were made at each intensity (levels with none are left out).

    Returns
    -------
    LognormalFit
        The median and dispersion with their standard errors, or, where the likelihood has
        no interior maximum, the status that says why (``"all_survive"``,
        ``"all_overturn"``, ``"separated"``, ``"no_data"``).

    Examples
    --------
    >>> from rockjit.ground.fitting import fit_lognormal
    >>> fit = fit_lognormal([1, 2, 3, 4], [0, 3, 7, 9], [10, 10, 10, 10])
    >>> fit.status, round(fit.median, 2), round(fit.beta, 2)
    ('ok', 2.47, 0.36)
    """
    x = np.asarray(x, dtype=float).ravel()
    k = np.asarray(overturned, dtype=float).ravel()
    n = np.asarray(runs, dtype=float).ravel()
    if not (x.shape == k.shape == n.shape):
        raise ValueError("x, overturned and runs must have the same length")
    use = n > 0
    x, k, n = x[use], k[use], n[use]
    if np.any(~np.isfinite(x)) or np.any(x <= 0):
        raise ValueError("the intensities must be finite and positive")
    if np.any(k < 0) or np.any(k > n):
        raise ValueError("overturned counts must lie in [0, runs]")
    N, K = int(n.sum()), int(k.sum())
    nan = math.nan

    def bare(status, median=nan, bound=nan, beta=nan):
        return LognormalFit(median, beta, nan, nan, nan, status, bound, N, K, nan)

    if N == 0:
        return bare("no_data")
    if K == 0:
        return bare("all_survive", bound=float(x.max()))
    if K == N:
        return bare("all_overturn", bound=float(x.min()))
    lx = np.log(x)
    # a clean cut: every level below some intensity survives, every level above overturns
    survive_max = lx[k < n].max()   # the highest level with a survival
    over_min = lx[k > 0].min()      # the lowest level with an overturning
    if survive_max < over_min and np.all(k[lx <= survive_max] == 0) and \
            np.all(k[lx >= over_min] == n[lx >= over_min]):
        return LognormalFit(float(np.exp(0.5 * (survive_max + over_min))), 0.0, nan, nan, nan,
                            "separated", nan, N, K, 0.0)
    # a start: the median where the empirical fraction crosses 1/2, beta from its spread
    frac = k / n
    order = np.argsort(lx)
    mu0 = float(np.interp(0.5, np.maximum.accumulate(frac[order]), lx[order]))
    beta0 = max(0.1, float(np.std(lx)) if lx.size > 1 else 0.3)

    from scipy.optimize import minimize

    def f(q):  # q = (mu, ln beta)
        return _nll(q[0], math.exp(q[1]), lx, k, n)

    best = None
    for start in ((mu0, math.log(beta0)), (float(np.mean(lx)), math.log(0.4))):
        r = minimize(f, np.array(start), method="Nelder-Mead",
                     options=dict(xatol=1e-10, fatol=1e-12, maxiter=4000))
        if best is None or r.fun < best.fun:
            best = r
    mu, beta = float(best.x[0]), float(math.exp(best.x[1]))
    if beta < BETA_MIN:
        return LognormalFit(float(math.exp(mu)), beta, nan, nan, nan, "separated", nan, N, K,
                            -float(best.fun))
    H = _hessian(lambda q: _nll(q[0], q[1], lx, k, n), np.array([mu, beta]),
                 np.array([1e-4 * max(1.0, abs(mu)), 1e-4 * beta]))
    try:
        cov = np.linalg.inv(H)
        se_mu, se_beta = (math.sqrt(v) if v > 0 else nan for v in np.diag(cov))
    except np.linalg.LinAlgError:
        se_mu = se_beta = nan
    median = math.exp(mu)
    return LognormalFit(median, beta, median * se_mu, se_beta, se_mu, "ok", nan, N, K,
                        -float(best.fun))


def fit_capacities(capacities) -> LognormalFit:
    """The lognormal fit to one collapse capacity per record (docs/theory/ground-motions.md):
    ``ln theta_m`` the mean of ``ln x_i``, ``beta^2`` their variance (divided by ``n``);
    standard errors ``beta / sqrt(n)`` and ``beta / sqrt(2 n)``. Capacities that are not finite
    (``inf``: a record that never overturned the block; ``nan``: one whose capacity lies below
    the intensities tried) are left out: ``n_runs`` counts every record, ``n_overturned`` those
    used.

    Parameters
    ----------
    capacities : array_like of float
        Each record's collapse capacity: the intensity at which it first overturned the block.

    Returns
    -------
    LognormalFit
        Status ``"ok"``, or ``"no_data"`` with fewer than two finite capacities.

    Examples
    --------
    >>> from rockjit.ground import fit_capacities
    >>> fit = fit_capacities([2.0, 3.0, 4.5, float("inf")])    # the last never overturned
    >>> round(fit.median, 3), round(fit.beta, 3), fit.n_runs, fit.n_overturned
    (3.0, 0.331, 4, 3)
    """
    c = np.asarray(capacities, dtype=float).ravel()
    fin = c[np.isfinite(c)]
    if np.any(fin <= 0):
        raise ValueError("capacities must be positive")
    n = fin.size
    if n < 2:
        return LognormalFit(math.nan, math.nan, math.nan, math.nan, math.nan,
                            "no_data", math.nan, int(c.size), n, math.nan)
    lc = np.log(fin)
    mu = float(lc.mean())
    beta = float(math.sqrt(np.mean((lc - mu) ** 2)))
    se_mu = beta / math.sqrt(n)
    return LognormalFit(math.exp(mu), beta, math.exp(mu) * se_mu, beta / math.sqrt(2 * n),
                        se_mu, "ok", math.nan, int(c.size), n, math.nan)
