"""Measures of a basin map: basin entropy, uncertainty exponent and dynamical integrity.

Every function here works on a map of integer *outcomes* (docs/theory/global-dynamics.md):
attractor ids ``>= 0``,
``-1`` for overturn, ``-2`` for unresolved. It is pure NumPy/SciPy and knows nothing of the
integrator; the grid-free uncertainty estimate :func:`uncertain_fraction_sampled` takes any
callable ``outcome(points) -> ids`` (the compiled kernels, in rockjit).

- :func:`basin_entropy`: ``Sb`` and ``Sbb`` of Daza et al. (2016) on non-overlapping boxes.
- :func:`uncertain_fraction` (on a grid map) and :func:`uncertain_fraction_sampled` (on random
  points): the fraction ``f(eps)`` of initial conditions whose outcome changes under a
  perturbation of size ``eps`` (Grebogi, McDonald, Ott & Yorke 1983);
  :func:`uncertainty_exponent` fits ``f ~ eps^alpha`` and gives the boundary's dimension
  ``D - alpha``.
- :func:`integrity`: the global integrity measure GIM, the integrity factor IF and the local
  integrity measure LIM of each attractor on the safe (non-overturning) basin (Soliman &
  Thompson 1989; Rega & Lenci 2005; Lenci & Rega 2019).

References
----------
- A. Daza, A. Wagemakers, B. Georgeot, D. Guéry-Odelin, M. A. F. Sanjuán, "Basin entropy: a
  new tool to analyze uncertainty in dynamical systems", Sci. Rep. 6, 31416 (2016).
- C. Grebogi, S. W. McDonald, E. Ott, J. A. Yorke, "Final state sensitivity: an obstruction
  to predictability", Phys. Lett. A 99, 415-418 (1983).
- S. W. McDonald, C. Grebogi, E. Ott, J. A. Yorke, "Fractal basin boundaries", Physica D 17,
  125-153 (1985).
- M. S. Soliman, J. M. T. Thompson, "Integrity measures quantifying the erosion of smooth
  and fractal basins of attraction", J. Sound Vib. 135, 453-475 (1989).
- G. Rega, S. Lenci, "Identifying, evaluating, and controlling dynamical integrity measures
  in non-linear mechanical oscillators", Nonlinear Anal. 63, 902-914 (2005).
- S. Lenci, G. Rega (eds.), "Global Nonlinear Dynamics for Engineering Design and System
  Safety", CISM Courses and Lectures 588, Springer (2019).
- G. Datseris, A. Wagemakers, "Effortless estimation of basins of attraction", Chaos 32,
  023104 (2022) (Attractors.jl).
"""

from __future__ import annotations

import math
import numbers
import operator
from dataclasses import dataclass, field

import numpy as np
from scipy import ndimage
from scipy.spatial import cKDTree

__all__ = [
    "OVERTURN", "UNRESOLVED", "BasinEntropy", "Integrity", "SampledUncertainty",
    "UncertaintyExponent", "basin_entropy", "integrity", "uncertain_fraction",
    "uncertain_fraction_sampled", "uncertainty_exponent",
]

#: Outcome id of a cell that overturns.
OVERTURN = -1
#: Outcome id of a cell that could not be resolved (the impact bound was reached).
UNRESOLVED = -2


# --------------------------------------------------------------------------- input checks

def _ids_2d(ids, name="ids"):
    """``ids`` as a non-empty 2-D integer array, or a ValueError naming it."""
    a = np.asarray(ids)
    if a.ndim != 2 or a.size == 0:
        raise ValueError(f"{name} must be a non-empty 2-D array of outcome ids "
                         f"(got shape {a.shape})")
    if a.dtype.kind not in "iu":
        raise ValueError(f"{name} must be an integer array of outcome ids (got dtype {a.dtype})")
    return a


def _int(value, name, lo, hi=None):
    """``value`` as a Python int in ``[lo, hi]``, or a ValueError naming it."""
    try:
        if isinstance(value, (bool, np.bool_)):
            raise TypeError
        v = operator.index(value)
    except TypeError:
        raise ValueError(f"{name} must be an integer (got {value!r})") from None
    if v < lo or (hi is not None and v > hi):
        rng = f">= {lo}" if hi is None else f"in [{lo}, {hi}]"
        raise ValueError(f"{name} must be {rng} (got {v})")
    return v


def _axis(values, name, size):
    """A uniformly spaced, increasing grid axis of ``size`` points; returns (array, spacing)."""
    a = np.asarray(values, dtype=float)
    if a.ndim != 1 or a.size != size:
        raise ValueError(f"{name} must be a 1-D array of {size} values, one per grid line "
                         f"(got shape {a.shape})")
    if size < 2 or not np.all(np.isfinite(a)):
        raise ValueError(f"{name} must hold at least 2 finite values (got {a.size})")
    d = np.diff(a)
    h = (a[-1] - a[0]) / (size - 1)
    if not np.all(d > 0):
        raise ValueError(f"{name} must be strictly increasing")
    if np.max(np.abs(d - h)) > 1e-6 * h:
        raise ValueError(f"{name} must be uniformly spaced (spacings from {d.min():g} to "
                         f"{d.max():g})")
    return a, h


# --------------------------------------------------------------------------- basin entropy

@dataclass(frozen=True)
class BasinEntropy:
    """Basin entropy of a map; unpacks as ``Sb, Sbb`` (like scipy.stats' result objects).

    Attributes
    ----------
    Sb : float
        Basin entropy: mean box entropy over all ``n_boxes`` boxes (nats).
    Sbb : float
        Boundary basin entropy: mean over the ``n_boundary`` boxes holding more than one outcome;
        ``nan`` when there are none (a map without a boundary has no boundary entropy).
    n_boxes : int
        Number of full ``box x box`` boxes used.
    n_boundary : int
        Number of those holding more than one outcome.
    box : int
        Side of the boxes, in cells.

    Examples
    --------
    >>> import numpy as np
    >>> from rockjit.measures import basin_entropy
    >>> ids = np.zeros((10, 10), dtype=int)
    >>> ids[:, 4:] = 1
    >>> Sb, Sbb = basin_entropy(ids)
    >>> round(Sb, 4), round(Sbb, 4), basin_entropy(ids).n_boundary
    (0.2502, 0.5004, 2)
    """

    Sb: float
    Sbb: float
    n_boxes: int
    n_boundary: int
    box: int

    def __iter__(self):
        yield self.Sb
        yield self.Sbb

    def to_dict(self):
        """The values under the names ``summary.json`` uses (``Sbb`` may be ``nan``)."""
        return {"basin_entropy": self.Sb, "boundary_basin_entropy": self.Sbb,
                "n_boxes": self.n_boxes, "n_boundary_boxes": self.n_boundary, "box": self.box}


def basin_entropy(ids, box=5):
    """Basin entropy ``Sb`` and boundary basin entropy ``Sbb`` of a map of outcomes.

    Parameters
    ----------
    ids : array_like of int, shape (n, m)
        Outcome of each cell. Every distinct value is an outcome: attractor ids, overturn
        (``-1``) and unresolved (``-2``) alike.
    box : int, optional
        Side of the square boxes, in cells (``>= 2`` and at most ``min(n, m)``). Default 5, the
        value of Daza et al.

    Returns
    -------
    BasinEntropy
        ``Sb``, ``Sbb`` (unpacks as that pair), the number of boxes and of boundary boxes.

    Notes
    -----
    Daza et al. (2016): the map is covered with non-overlapping boxes of ``box x box`` cells; in
    box ``i``, ``p_ij`` is the fraction of its cells with outcome ``j`` and ``S_i = -sum_j p_ij
    ln p_ij`` (natural logarithm). ``Sb`` is the mean of ``S_i`` over all boxes, ``Sbb`` the
    mean over the boxes with more than one outcome. ``Sbb > ln 2`` is a sufficient condition for
    a fractal boundary (Daza et al. 2016).

    Boxes start at cell ``(0, 0)``. When a side is not a multiple of ``box``, the last
    ``n % box`` rows and ``m % box`` columns, which would only fill partial boxes, are left out:
    every box then holds the same number of cells, so every ``S_i`` has the same resolution.
    Attractors.jl (Datseris & Wagemakers 2022) does the same in its box-counting dimension, but
    its ``basin_entropy`` refuses such a map instead; rockjit's grids are the user's choice (101
    x 101 is common), so the remainder is dropped and the boxes used are reported.

    ``Sbb`` is ``nan`` when no box holds two outcomes (a constant map, or boundaries that all
    lie on box edges): the mean over an empty set is undefined, and ``0`` would claim a boundary
    of zero entropy, which no boundary box can have (its ``S_i >= ln(box^2) / box^2 > 0``).
    Attractors.jl returns ``0/0`` (NaN) there too. ``Sb`` is then ``0``.

    Examples
    --------
    Two outcomes split by a straight boundary inside the first column of boxes:

    >>> import numpy as np
    >>> from rockjit.measures import basin_entropy
    >>> ids = np.zeros((10, 10), dtype=int)
    >>> ids[:, 4:] = 1
    >>> e = basin_entropy(ids, box=5)
    >>> round(e.Sb, 4), round(e.Sbb, 4), e.n_boxes, e.n_boundary
    (0.2502, 0.5004, 4, 2)
    """
    a = _ids_2d(ids)
    n, m = a.shape
    b = _int(box, "box", 2, min(n, m))
    nb, mb = n // b, m // b
    crop = a[:nb * b, :mb * b]
    values, inv = np.unique(crop, return_inverse=True)
    inv = inv.reshape(crop.shape).astype(np.int64)
    k = values.size
    # box number of each cell, row-major over the boxes
    box_of = (np.arange(nb * b) // b)[:, None] * mb + (np.arange(mb * b) // b)[None, :]
    # (box, outcome) pairs present and their cell counts; memory O(cells), any number of outcomes
    pair, count = np.unique(box_of.astype(np.int64) * k + inv, return_counts=True)
    owner = pair // k
    p = count / float(b * b)
    entropy = np.bincount(owner, weights=-p * np.log(p), minlength=nb * mb)
    n_outcomes = np.bincount(owner, minlength=nb * mb)
    boundary = n_outcomes > 1
    n_boundary = int(np.count_nonzero(boundary))
    sb = float(entropy.mean())
    sbb = float(entropy[boundary].mean()) if n_boundary else math.nan
    return BasinEntropy(Sb=sb, Sbb=sbb, n_boxes=nb * mb, n_boundary=n_boundary, box=b)


# --------------------------------------------------------------------------- uncertainty exponent

def _eps_list(eps, name, kind):
    """``eps`` as a 1-D array (int cells or positive floats) and whether it was a scalar."""
    scalar = np.ndim(eps) == 0
    arr = np.atleast_1d(np.asarray(eps))
    if arr.ndim != 1 or arr.size == 0:
        raise ValueError(f"{name} must be a number or a non-empty 1-D sequence "
                         f"(got shape {np.shape(eps)})")
    if kind == "int":
        if arr.dtype.kind not in "iu" or np.any(arr < 1):
            raise ValueError(f"{name} must be integers >= 1, in cells (got {eps!r})")
        return arr.astype(int), scalar
    try:
        arr = arr.astype(float)
    except (TypeError, ValueError):
        raise ValueError(f"{name} must be numbers (got {eps!r})") from None
    return arr, scalar


def uncertain_fraction(ids, eps_cells, margin=None):
    """Fraction of grid cells whose outcome changes under a perturbation of ``eps_cells`` cells.

    Parameters
    ----------
    ids : array_like of int, shape (n, m)
        Outcome of each cell (every distinct value is an outcome).
    eps_cells : int or sequence of int
        Perturbation size(s) in cells (index units), each ``>= 1``.
    margin : int, optional
        Cells left out along each edge; the fraction is taken over the interior
        ``ids[margin:n-margin, margin:m-margin]``. At least ``max(eps_cells)`` (so every
        perturbed cell lies on the map); default ``max(eps_cells)``, so that with a sequence of
        ``eps_cells`` every fraction is counted over the same cells.

    Returns
    -------
    f : float or ndarray, shape (k,)
        The uncertain fraction for each ``eps_cells`` (a float for a scalar ``eps_cells``).

    Notes
    -----
    The grid form of the perturbation method of Grebogi et al. (1983; McDonald et al. 1985): a
    cell ``(i, j)`` is
    *uncertain at eps* when its outcome differs from that of at least one of its four
    neighbours at distance ``eps`` along the axes, ``(i +- eps, j)`` and ``(i, j +- eps)`` (GMOY
    perturb an initial condition by ``+-eps`` along one coordinate; both coordinates are used
    here so that a boundary of any orientation is seen). Distances are in cells, so on a grid
    with unequal spacings the perturbation is a cross in normalised, not state, units; the
    exponent fitted from ``f(eps)`` does not depend on that scaling. Every interior cell is
    counted (a census rather than GMOY's random sample); for a smooth boundary ``f`` is
    proportional to ``eps`` exactly, up to the lattice.

    Attractors.jl's ``uncertainty_exponent`` is not this method: it counts, for box sides
    ``eps``, the non-overlapping boxes holding more than one outcome (partial boxes dropped),
    fits the box-counting dimension ``d`` of the boundary from ``log N`` against ``log(1/eps)``,
    and returns ``D - d``. Both estimate the same exponent when the boundary is self-similar.

    Examples
    --------
    >>> import numpy as np
    >>> from rockjit.measures import uncertain_fraction
    >>> ids = np.zeros((10, 10), dtype=int)
    >>> ids[:, 4:] = 1
    >>> uncertain_fraction(ids, [1, 2])
    array([0.33333333, 0.66666667])
    """
    a = _ids_2d(ids)
    eps, scalar = _eps_list(eps_cells, "eps_cells", "int")
    n, m = a.shape
    emax = int(eps.max())
    if margin is None:
        mg = emax
    else:
        mg = _int(margin, "margin", emax)
    if 2 * mg >= min(n, m):
        raise ValueError(f"margin must leave an interior: 2 * margin < min(ids.shape) = "
                         f"{min(n, m)} (got margin {mg}; margin defaults to max(eps_cells))")
    core = a[mg:n - mg, mg:m - mg]
    out = np.empty(eps.size)
    for k, e in enumerate(eps):
        e = int(e)
        changed = ((a[mg - e:n - mg - e, mg:m - mg] != core)
                   | (a[mg + e:n - mg + e, mg:m - mg] != core)
                   | (a[mg:n - mg, mg - e:m - mg - e] != core)
                   | (a[mg:n - mg, mg + e:m - mg + e] != core))
        out[k] = np.count_nonzero(changed) / core.size
    return float(out[0]) if scalar else out


@dataclass(frozen=True)
class UncertaintyExponent:
    """Fit of ``f ~ eps^alpha``; unpacks as ``alpha, stderr, dimension``.

    Attributes
    ----------
    alpha : float
        The uncertainty exponent (slope of ``ln f`` against ``ln eps``).
    stderr : float
        Its standard error from the least-squares residuals.
    dimension : float
        The boundary's dimension ``D - alpha``.
    intercept : float
        ``ln f`` at ``eps = 1`` on the fitted line.

    Examples
    --------
    >>> from rockjit.measures import uncertainty_exponent
    >>> alpha, stderr, dimension = uncertainty_exponent([1, 2, 4], [0.1, 0.2, 0.4])
    >>> round(alpha, 12), round(dimension, 12)
    (1.0, 1.0)
    """

    alpha: float
    stderr: float
    dimension: float
    intercept: float

    def __iter__(self):
        yield self.alpha
        yield self.stderr
        yield self.dimension

    def to_dict(self):
        """``{"alpha", "alpha_stderr", "boundary_dimension"}`` for ``summary.json``."""
        return {"alpha": self.alpha, "alpha_stderr": self.stderr,
                "boundary_dimension": self.dimension}


def uncertainty_exponent(eps, f, dim=2):
    """Fit the uncertainty exponent ``alpha`` of ``f(eps) ~ eps^alpha`` by least squares.

    Parameters
    ----------
    eps : array_like, shape (k,)
        Perturbation sizes, ``> 0`` (any unit: the slope does not depend on it), with at least
        two distinct values.
    f : array_like, shape (k,)
        Uncertain fractions at ``eps``, in ``(0, 1]``.
    dim : int, optional
        Dimension ``D`` of the sampled state space (default 2, the ``(theta, theta')`` plane).

    Returns
    -------
    UncertaintyExponent
        ``alpha``, its standard error and the boundary dimension ``D - alpha`` (unpacks as that
        triple), and the fit's intercept.

    Notes
    -----
    Grebogi et al. (1983; McDonald et al. 1985): the fraction of uncertain initial conditions
    scales as ``f ~ eps^alpha`` and the box-counting dimension of the basin boundary is ``D -
    alpha`` (``alpha = 1`` for a smooth boundary in the plane, ``alpha -> 0`` for a riddled
    one). The fit is ordinary least squares of ``ln f`` on ``ln eps`` with equal weights; the
    standard error is ``sqrt(SSR / (k - 2) / Sxx)``, the usual one of a fitted slope (as in
    ``scipy.stats.linregress``), so at least three points are needed.

    Examples
    --------
    A smooth boundary (the fraction grows like ``eps``) has ``alpha = 1``, dimension 1:

    >>> from rockjit.measures import uncertainty_exponent
    >>> u = uncertainty_exponent([1, 2, 4], [0.1, 0.2, 0.4])
    >>> round(u.alpha, 12), round(u.stderr, 12), round(u.dimension, 12)
    (1.0, 0.0, 1.0)
    """
    x = np.asarray(eps, dtype=float)
    y = np.asarray(f, dtype=float)
    if x.ndim != 1 or x.size < 3:
        raise ValueError(f"eps must be a 1-D sequence of at least 3 values, so that the slope "
                         f"has a standard error (got shape {x.shape})")
    if y.shape != x.shape:
        raise ValueError(f"f must have the shape of eps {x.shape} (got {y.shape})")
    if not np.all(np.isfinite(x)) or np.any(x <= 0):
        raise ValueError(f"eps must be finite and > 0 (got {x.tolist()})")
    if not np.all(np.isfinite(y)) or np.any(y <= 0) or np.any(y > 1):
        raise ValueError(f"f must be fractions in (0, 1]; a zero fraction has no logarithm, "
                         f"sample more points or use larger eps (got {y.tolist()})")
    d = _int(dim, "dim", 1)
    lx, ly = np.log(x), np.log(y)
    xm, ym = lx.mean(), ly.mean()
    sxx = float(np.sum((lx - xm) ** 2))
    if sxx <= 0.0:
        raise ValueError(f"eps must hold at least two distinct values (got {x.tolist()})")
    alpha = float(np.sum((lx - xm) * (ly - ym)) / sxx)
    resid = ly - (ym + alpha * (lx - xm))
    stderr = math.sqrt(float(np.sum(resid**2)) / (x.size - 2) / sxx)
    return UncertaintyExponent(alpha=alpha, stderr=stderr, dimension=d - alpha,
                               intercept=float(ym - alpha * xm))


@dataclass(frozen=True)
class SampledUncertainty:
    """Uncertain fractions from random points (:func:`uncertain_fraction_sampled`).

    Attributes
    ----------
    eps : ndarray, shape (k,)
        Perturbation sizes, as fractions of the box's sides.
    f : ndarray, shape (k,)
        Uncertain fraction at each ``eps``.
    stderr : ndarray, shape (k,)
        Binomial standard error of each fraction, ``sqrt(f (1 - f) / n)``.
    uncertain : ndarray of int, shape (k,)
        Number of uncertain points at each ``eps``.
    n : int
        Number of base points.

    Examples
    --------
    >>> from rockjit.measures import uncertain_fraction_sampled
    >>> half_plane = lambda points: (points[:, 0] > 0).astype(int)
    >>> s = uncertain_fraction_sampled(half_plane, (-1, -1), (1, 1), [0.01, 0.02, 0.04],
    ...                                n=2000)
    >>> s.f.tolist(), round(s.exponent().alpha, 2)
    ([0.0135, 0.023, 0.054], 1.0)
    """

    eps: np.ndarray
    f: np.ndarray
    stderr: np.ndarray
    uncertain: np.ndarray
    n: int

    def exponent(self, dim=2):
        """:func:`uncertainty_exponent` of these fractions."""
        return uncertainty_exponent(self.eps, self.f, dim=dim)


def uncertain_fraction_sampled(outcome, lo, hi, eps, n=10_000, seed=0):
    """Uncertain fractions from seeded random points, for any ``outcome(points) -> ids``.

    Parameters
    ----------
    outcome : callable
        ``outcome(points)`` with ``points`` an ndarray of shape ``(N, 2)`` (state units, rows
        ``(theta, theta')``) returns the outcome ids, integer array of shape ``(N,)``. It is
        called once, on all the points at once.
    lo, hi : array_like, shape (2,)
        Corners of the sampled box, ``lo < hi`` componentwise.
    eps : float or sequence of float
        Perturbation sizes as fractions of the box's sides, each in ``(0, 0.5)``.
    n : int, optional
        Number of random base points (default 10 000).
    seed : int, optional
        Seed of ``numpy.random.default_rng`` (default 0): equal seeds give equal results.

    Returns
    -------
    SampledUncertainty
        Fractions, their binomial standard errors and counts; ``.exponent()`` fits ``alpha``.

    Notes
    -----
    Grebogi et al. (1983; McDonald et al. 1985): a random initial condition ``x`` is *uncertain
    at eps* when the outcome of ``x + delta`` or of ``x - delta`` differs from that of ``x``,
    ``|delta| = eps``. Here the direction of ``delta`` is drawn at random (uniform angle) for
    each point, in the coordinates normalised by the box's sides: ``delta = eps (hi - lo) (cos
    phi, sin phi)``, so
    ``eps`` is dimensionless like the grid form's ``eps_cells / (n - 1)`` (``theta`` and
    ``theta'`` have different units; GMOY perturbed along one coordinate). For a smooth boundary
    crossing the box, ``f = (4 / pi) eps L / A`` to first order (``L`` the boundary's length, ``A``
    the base points' area, in normalised units).

    The base points are uniform in the box shrunk by ``max(eps)`` on every side, so every
    perturbed point stays in the sampled box; the same base points and directions serve every
    ``eps`` (common random numbers: the fitted slope is less noisy than with independent
    samples).

    Examples
    --------
    The outcome of a half-plane: its boundary is a straight line, its exponent 1:

    >>> from rockjit.measures import uncertain_fraction_sampled
    >>> half_plane = lambda points: (points[:, 0] > 0).astype(int)
    >>> s = uncertain_fraction_sampled(half_plane, (-1, -1), (1, 1), [0.01, 0.02, 0.04],
    ...                                n=2000, seed=0)
    >>> s.uncertain.tolist(), round(s.exponent().alpha, 2)
    ([27, 46, 108], 1.0)
    """
    if not callable(outcome):
        raise ValueError(f"outcome must be a callable outcome(points) -> ids "
                         f"(got {type(outcome).__name__})")
    lo_a, hi_a = _box(lo, hi)
    e = _sampled_eps(eps)
    npts = _int(n, "n", 1)
    if not isinstance(seed, numbers.Integral) or isinstance(seed, bool):
        raise ValueError(f"seed must be an integer (got {seed!r})")
    unit = _perturbed_unit_points(np.random.default_rng(seed), e, npts)
    points = lo_a + unit * (hi_a - lo_a)
    got = _outcomes_of(outcome, points)
    counts = _uncertain_counts(got, npts, e.size)
    frac = counts / npts
    return SampledUncertainty(eps=e, f=frac, stderr=np.sqrt(frac * (1.0 - frac) / npts),
                              uncertain=counts, n=npts)


def _box(lo, hi):
    """The corners ``lo < hi`` of a sampled box as float arrays, or a ValueError naming them."""
    lo_a = np.asarray(lo, dtype=float)
    hi_a = np.asarray(hi, dtype=float)
    for name, v in (("lo", lo_a), ("hi", hi_a)):
        if v.shape != (2,) or not np.all(np.isfinite(v)):
            raise ValueError(f"{name} must be 2 finite numbers (theta, theta') "
                             f"(got {np.asarray(v).tolist()})")
    if not np.all(hi_a > lo_a):
        raise ValueError(f"hi must exceed lo componentwise (got lo {lo_a.tolist()}, "
                         f"hi {hi_a.tolist()})")
    return lo_a, hi_a


def _sampled_eps(eps):
    """``eps`` as fractions of the box's sides in ``(0, 0.5)``, or a ValueError naming it."""
    e, _ = _eps_list(eps, "eps", "float")
    if not np.all(np.isfinite(e)) or np.any(e <= 0) or np.any(e >= 0.5):
        raise ValueError(f"eps must be in (0, 0.5), fractions of the box's sides "
                         f"(got {e.tolist()})")
    return e


def _perturbed_unit_points(rng, e, npts):
    """The base points and, for each ``eps``, their ``+`` and ``-`` perturbations, in the unit
    box: ``npts`` rows per block, blocks ``[base, +e[0], -e[0], +e[1], ...]``."""
    margin = float(e.max())
    u = margin + (1.0 - 2.0 * margin) * rng.random((npts, 2))
    phi = 2.0 * np.pi * rng.random(npts)
    direction = np.column_stack([np.cos(phi), np.sin(phi)])
    blocks = [u]
    for ek in e:
        blocks.append(u + ek * direction)
        blocks.append(u - ek * direction)
    return np.clip(np.concatenate(blocks), 0.0, 1.0)  # clip only rounding at the box's edge


def _outcomes_of(outcome, points):
    """``outcome(points)``, checked to be one integer id per point."""
    got = np.asarray(outcome(points))
    if got.shape != (points.shape[0],) or got.dtype.kind not in "iu":
        raise ValueError(f"outcome must return an integer array of shape ({points.shape[0]},) "
                         f"for points of shape {points.shape} (got dtype {got.dtype}, "
                         f"shape {got.shape})")
    return got


def _uncertain_counts(got, npts, k_eps):
    """For each ``eps``, the number of base points whose ``+`` or ``-`` perturbation changes
    the outcome (``got`` in the blocks of :func:`_perturbed_unit_points`)."""
    base = got[:npts]
    counts = np.empty(k_eps, dtype=np.int64)
    for k in range(k_eps):
        plus = got[npts * (1 + 2 * k):npts * (2 + 2 * k)]
        minus = got[npts * (2 + 2 * k):npts * (3 + 2 * k)]
        counts[k] = np.count_nonzero((plus != base) | (minus != base))
    return counts


# --------------------------------------------------------------------------- dynamical integrity

@dataclass(frozen=True)
class Integrity:
    """Dynamical integrity of a map (:func:`integrity`).

    Attributes
    ----------
    GIM : float
        Global integrity measure: safe fraction of the sampled cells, 0-1.
    IF : float
        Integrity factor: ``radius / half_width``, 0-1.
    LIM : dict of int to float
        Local integrity measure of each attractor given, same normalisation (``nan`` when a
        cycle point lies outside the sampled region).
    radius : float
        Radius of the largest safe disc, state units.
    centre : tuple of float or None
        Its centre ``(theta, theta')`` (a grid node), ``None`` when nothing is safe.
    half_width : float
        The normalisation: half the shorter side of the sampled region, state units.

    Notes
    -----
    Definitions of Soliman & Thompson (1989) and Rega & Lenci (2005; Lenci & Rega 2019), on
    the safe basin of docs/theory/global-dynamics.md:

    - **Safe cells** are those with an attractor id ``>= 0``. Unresolved cells (``-2``) are
      *not* safe: nothing shows they stay bounded, and an integrity measure must not claim
      safety it has not seen (the conservative choice).
    - **GIM** is the number of safe cells over the number of cells: the safe basin's area as a
      fraction of the sampled region's.
    - **IF** is the radius of the largest disc, in state units (``theta`` and ``theta'`` as
      they are), lying inside the safe basin, over the region's half-width. The sampled region is
      the rectangle ``[theta[0], theta[-1]] x [dtheta[0], dtheta[-1]]``; what lies outside it is
      unknown, so the disc must also stay inside the region (as in Lenci & Rega's usage, where the
      hypersphere lies in the safe basin, itself a subset of the region of interest). The
      half-width is half the shorter side, ``min(theta[-1] - theta[0], dtheta[-1] -
      dtheta[0]) / 2``, the radius of the largest disc the region holds, so that ``0 <= IF <= 1``
      and an all-safe region has ``IF = 1`` (exactly when the grid has a node at the region's
      centre, within one spacing otherwise).
    - The disc radius at a safe node is the smaller of its distance to the nearest *unsafe node*
      (``scipy.ndimage.distance_transform_edt`` with ``sampling=`` the two spacings, so the
      distance is Euclidean in state units) and its distance to the region's edge; the largest
      over the safe nodes is IF's radius. The map does not show where between a safe and an
      unsafe node the boundary lies, so the radius can exceed the continuous one by up to one
      grid spacing, and a centre off the nodes could gain up to half a diagonal.
    - **LIM** of an attractor is the radius of the largest disc centred on the attractor that
      stays in the basin, same normalisation. For a cycle of ``p`` points this is the *minimum*
      over its points: the LIM is the distance from the attractor, a set, to the basin's
      boundary (Soliman & Thompson 1989; Rega & Lenci 2005), which is the smallest distance of
      its points; a disturbance at the most exposed point is the one that loses the orbit. A
      point's radius is its distance to the nearest node outside the basin and to the region's
      edge, measured from the point itself (not its node); it is ``0`` when the point's nearest
      node is outside the basin, and ``nan`` when the point lies outside the sampled region (the
      map says nothing there).

    Examples
    --------
    >>> import numpy as np
    >>> from rockjit.measures import integrity
    >>> axis = np.linspace(-1, 1, 21)
    >>> ids = np.zeros((21, 21), dtype=int)
    >>> ids[:5] = -1
    >>> m = integrity(ids, axis, axis)
    >>> round(m.radius, 6), m.half_width, m.to_dict()["LIM"]
    (0.8, 1.0, {})
    """

    GIM: float
    IF: float
    LIM: dict = field(default_factory=dict)
    radius: float = 0.0
    centre: tuple | None = None
    half_width: float = 1.0

    def to_dict(self):
        """``{"GIM": .., "IF": .., "LIM": {id: ..}}`` (plain floats; ``nan`` kept as such)."""
        return {"GIM": self.GIM, "IF": self.IF,
                "LIM": {int(k): float(v) for k, v in self.LIM.items()}}


def _points(points):
    """``points`` as ``{id: ndarray (p, 2)}``, or a ValueError naming it."""
    if points is None:
        return {}
    if not hasattr(points, "items"):
        raise ValueError(f"points must be a mapping {{attractor id: array (p, 2)}} "
                         f"(got {type(points).__name__})")
    out = {}
    for key, val in points.items():
        if isinstance(key, (bool, np.bool_)) or not isinstance(key, numbers.Integral) or key < 0:
            raise ValueError(f"points' keys must be attractor ids, integers >= 0 (got {key!r})")
        arr = np.asarray(val, dtype=float)
        if arr.ndim != 2 or arr.shape[1] != 2 or arr.shape[0] < 1:
            raise ValueError(f"points[{key}] must have shape (p, 2), p >= 1, rows (theta, "
                             f"theta') (got shape {arr.shape})")
        if not np.all(np.isfinite(arr)):
            raise ValueError(f"points[{key}] must be finite")
        out[int(key)] = arr
    return out


def _border_distance(x, a):
    """Distance from ``x`` to the nearer end of the axis ``a`` (negative outside)."""
    return np.minimum(x - a[0], a[-1] - x)


def integrity(ids, theta, dtheta, points=None, lim_basin="safe"):
    """Global integrity measure, integrity factor and local integrity measures of a map.

    Parameters
    ----------
    ids : array_like of int, shape (n, m)
        Outcome of each cell: attractor ids ``>= 0``, ``-1`` overturn, ``-2`` unresolved.
        ``ids[i, j]`` is the outcome of the initial state ``(theta[i], dtheta[j])``.
    theta : array_like, shape (n,)
        The ``theta`` grid line of each row, increasing and uniformly spaced.
    dtheta : array_like, shape (m,)
        The ``theta'`` grid line of each column, increasing and uniformly spaced (its spacing
        may differ from ``theta``'s).
    points : mapping of int to array_like, shape (p, 2), optional
        Cycle points ``(theta, theta')`` of each attractor whose LIM is wanted, keyed by id.
    lim_basin : {"safe", "own"}, optional
        The basin the LIM disc must stay in: ``"safe"`` (default), the whole safe
        basin; ``"own"``, the attractor's own basin (cells with its id), as in Soliman &
        Thompson's original LIM (1989).

    Returns
    -------
    Integrity
        ``GIM``, ``IF``, ``LIM`` (``.to_dict()`` gives ``{"GIM", "IF", "LIM"}``), and the radius,
        centre and normalisation of the IF disc.

    Notes
    -----
    Soliman & Thompson (1989) and Rega & Lenci (2005; Lenci & Rega 2019), on the safe basin of
    docs/theory/global-dynamics.md (the cells with an attractor id ``>= 0``; unresolved cells
    are *not* safe). :class:`Integrity`'s notes define each measure and rockjit's choices.

    Examples
    --------
    A 21 x 21 map over ``[-1, 1]^2`` whose first five rows of ``theta`` overturn, and one
    attractor at ``(0.5, 0)``:

    >>> import numpy as np
    >>> from rockjit.measures import integrity
    >>> axis = np.linspace(-1, 1, 21)
    >>> ids = np.zeros((21, 21), dtype=int)
    >>> ids[:5] = -1
    >>> m = integrity(ids, axis, axis, {0: [[0.5, 0.0]]})
    >>> round(m.GIM, 4), round(m.IF, 6), m.LIM
    (0.7619, 0.8, {0: 0.5})
    """
    a, th, h0, dth, h1 = _outcome_map(ids, theta, dtheta)
    if lim_basin not in ("safe", "own"):
        raise ValueError(f"lim_basin must be 'safe' or 'own' (got {lim_basin!r})")
    pts = _points(points)
    safe = a >= 0
    half = 0.5 * float(min(th[-1] - th[0], dth[-1] - dth[0]))
    radius, centre = _largest_safe_disc(safe, th, dth, h0, h1)
    lim = {}
    for key, cyc in pts.items():
        basin = safe if lim_basin == "safe" else (a == key)
        lim[key] = float(_lim(cyc, basin, th, dth, h0, h1) / half)
    return Integrity(GIM=float(np.count_nonzero(safe)) / safe.size, IF=float(radius / half),
                     LIM=lim, radius=radius, centre=centre, half_width=float(half))


def _outcome_map(ids, theta, dtheta):
    """The checked map and its axes: ``(ids, theta, theta's spacing, dtheta, its spacing)``."""
    a = _ids_2d(ids)
    n, m = a.shape
    if a.min() < UNRESOLVED:
        raise ValueError(f"ids must hold attractor ids >= 0, -1 (overturn) or -2 (unresolved) "
                         f"(got {int(a.min())})")
    th, h0 = _axis(theta, "theta", n)
    dth, h1 = _axis(dtheta, "dtheta", m)
    return a, th, h0, dth, h1


def _largest_safe_disc(safe, th, dth, h0, h1):
    """IF's disc: the largest radius over the safe nodes of a disc in the safe basin and the
    region, and its centre node (``None`` when nothing is safe)."""
    border = np.minimum(_border_distance(th, th)[:, None], _border_distance(dth, dth)[None, :])
    radius_at = np.where(safe, np.minimum(_edt(safe, (h0, h1)), border), 0.0)
    k = int(np.argmax(radius_at))
    radius = float(radius_at.flat[k])
    centre = None
    if safe.any():
        i, j = divmod(k, safe.shape[1])
        centre = (float(th[i]), float(dth[j]))
    return radius, centre


def _edt(mask, sampling):
    """Distance from each node of ``mask`` to the nearest node outside it (``inf`` if none)."""
    if mask.all():
        return np.full(mask.shape, np.inf)
    return ndimage.distance_transform_edt(mask, sampling=sampling)


def _lim(cycle, basin, th, dth, h0, h1):
    """Smallest, over the cycle's points, radius of a disc in ``basin`` and the region."""
    outside_tol = 1e-9 * max(h0, h1)
    edge = np.minimum(_border_distance(cycle[:, 0], th), _border_distance(cycle[:, 1], dth))
    if np.any(edge < -outside_tol):
        return math.nan
    i = np.clip(np.rint((cycle[:, 0] - th[0]) / h0).astype(int), 0, th.size - 1)
    j = np.clip(np.rint((cycle[:, 1] - dth[0]) / h1).astype(int), 0, dth.size - 1)
    if not np.all(basin[i, j]):
        return 0.0
    if basin.all():
        to_out = np.full(cycle.shape[0], np.inf)
    else:
        oi, oj = np.nonzero(~basin)
        to_out, _ = cKDTree(np.column_stack([th[oi], dth[oj]])).query(cycle)
    return float(np.min(np.minimum(to_out, np.maximum(edge, 0.0))))
