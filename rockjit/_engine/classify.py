"""The behaviour rules (docs/theory/behaviours.md), compiled: the period test, the classes, the exponents over
a stretch of periods.

Everything here reads a run's stroboscopic samples ``x_k = (theta, theta')`` at ``kT``
(``strobe[k]``) and at ``kT + T/2`` (``half[k]``), and ``per_imp[k]``, the number of impacts
before ``kT``. The integrator's early stop (:func:`rockjit._engine.integrate.settled_period`) and the
classification of a finished run (:func:`find_period`) apply the same test,
:func:`repeats`, to different stretches.

- ``overturn``: the run stopped by overturning; ``rest``: it came to rest for good
  (``alpha omega^2 <= cot(thc)`` once at rest);
- period ``p``: the smallest ``p <= pmax`` with ``|x_{k+p} - x_k| <= tol * S`` for every sample
  of the stretch (both components, both sampling instants) and the same number of impacts in
  periods ``p`` apart, where ``S`` is the largest ``|theta|, |theta'|`` of the stretch's samples
  (so the tolerance is relative to the orbit's size); at least two repetitions are required;
- ``symmetric``: period 1 and ``x(kT + T/2) = -x(kT)`` to the same tolerance; ``asymmetric``:
  period 1 otherwise; ``multiperiodic``: period ``p >= 2``;
- ``chaotic``: no period and ``lambda1 > lam_tol``; ``aperiodic``: no period, and ``lambda1``
  not computed or ``<= lam_tol``;
- ``unresolved``: the run hit the impact bound (never silently relabelled).
"""

from __future__ import annotations

import math

from .._jit import jit
from ..result import APERIODIC, ASYMMETRIC, CHAOTIC, MULTIPERIODIC, SYMMETRIC

__all__ = ["classify", "find_period", "lam_between", "orbit_scale", "repeats"]


@jit(nrt=False)
def orbit_scale(strobe, half, k0, k1):
    """Largest ``|theta|, |theta'|`` of the samples ``strobe[k0..k1]`` and ``half[k0..k1-1]``."""
    scale = 0.0
    for j in range(k0, k1 + 1):
        for c in range(2):
            scale = max(scale, abs(strobe[j, c]))
            if j < k1:
                scale = max(scale, abs(half[j, c]))
    return scale


@jit(nrt=False)
def repeats(strobe, half, per_imp, j0, j1, p, half_from, lim):
    """The period test: does the run repeat itself ``p`` periods apart over periods ``j0..j1``?

    For each ``j`` in ``j0..j1``: ``strobe[j]`` against ``strobe[j - p]``, the half-period
    sample of the period ending at ``jT`` (``half[j - 1]``) against ``half[j - 1 - p]`` where
    ``j - 1 - p >= half_from``, both components within ``lim``, and the number of impacts in
    that period against the one ``p`` periods earlier (where both are known).
    """
    for j in range(j0, j1 + 1):
        if j - p - 1 >= 0 and \
                per_imp[j] - per_imp[j - 1] != per_imp[j - p] - per_imp[j - p - 1]:
            return False
        for c in range(2):
            if abs(strobe[j, c] - strobe[j - p, c]) > lim:
                return False
            if j - 1 - p >= half_from and abs(half[j - 1, c] - half[j - 1 - p, c]) > lim:
                return False
    return True


@jit(nrt=False)
def find_period(strobe, half, per_imp, k0, k1, tol, pmax):
    """Smallest period ``p <= pmax`` of the samples ``k0..k1``, at least two repetitions.

    Returns ``(p, lim)``: ``p = 0`` when there is none, and the absolute tolerance used.
    """
    lim = tol * orbit_scale(strobe, half, k0, k1) + 1e-300
    for p in range(1, pmax + 1):
        if k1 - k0 < 2 * p:
            return 0, lim
        if repeats(strobe, half, per_imp, k0 + p, k1, p, k0, lim):
            return p, lim
    return 0, lim


@jit(nrt=False)
def classify(strobe, half, per_imp, k0, k1, lam1, have_lam, tol, pmax, lam_tol):
    """Behaviour code and period of a bounded run from its samples ``k0..k1``."""
    p, lim = find_period(strobe, half, per_imp, k0, k1, tol, pmax)
    if p == 1:
        for j in range(k0, k1):
            for c in range(2):
                if abs(half[j, c] + strobe[j, c]) > lim:
                    return ASYMMETRIC, 1
        return SYMMETRIC, 1
    if p >= 2:
        return MULTIPERIODIC, p
    if have_lam and lam1 > lam_tol:
        return CHAOTIC, 0
    return APERIODIC, 0


@jit(nrt=False)
def lam_between(lam_run, k0, k1):
    """Exponents averaged over ``[k0 T, k1 T]`` from the running sums at ``kT``.

    ``lam_run[k, :2] = S(kT) / (kT)`` with ``S`` the accumulated log-stretch, so
    ``(lam_run[k1] k1 - lam_run[k0] k0) / (k1 - k0)`` is the growth rate per unit time;
    ``lam_run[k, 2]`` counts the collapses of the tangent vectors before ``kT`` (a rest phase,
    an impact with ``e = 0``): with one inside the stretch every perturbation died there, and
    the exponents are ``-inf``.
    """
    if k1 <= k0:
        return math.nan, math.nan
    if lam_run[k1, 2] > lam_run[k0, 2]:
        return -math.inf, -math.inf
    l1 = (lam_run[k1, 0] * k1 - lam_run[k0, 0] * k0) / (k1 - k0)
    l2 = (lam_run[k1, 1] * k1 - lam_run[k0, 1] * k0) / (k1 - k0)
    return l1, l2
