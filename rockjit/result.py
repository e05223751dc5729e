"""The result types every backend builds: one run, an α sweep, a basin, a parameter plane.

They sit below every backend (the compiled kernels, the scipy path, the grid runners), so that
any of them can build a result without importing another; they hold labelled arrays and the
validated parameters, and know nothing of how they were computed.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np

from .excitation import Excitation
from .reprs import text as _text
from .model import Block
from .settings import Integration

__all__ = ["BEHAVIOURS", "HORIZON_TOL", "ROUNDING", "BasinResult", "GridResult",
           "PlaneResult", "Result", "STATUSES", "STATUS_MESSAGES", "SweepResult", "fractions",
           "horizon"]

#: Behaviour names; a label array holds their indices (docs/theory/behaviours.md).
BEHAVIOURS = ("overturn", "rest", "symmetric", "asymmetric", "multiperiodic", "chaotic",
              "aperiodic", "unresolved")
OVERTURN, REST, SYMMETRIC, ASYMMETRIC, MULTIPERIODIC, CHAOTIC, APERIODIC, UNRESOLVED = range(8)

#: Statuses of a run, in the order of the kernels' status codes (rockjit._engine.integrate).
STATUSES = ("done", "overturned", "rest", "max_impacts", "nonfinite", "settled")

#: Each status in words (:attr:`rockjit.Result.message`).
STATUS_MESSAGES = {
    "done": "reached the requested number of periods",
    "overturned": "the block overturned (|theta| reached theta_over)",
    "rest": "the block came to rest and the forcing can never lift it again "
            "(alpha * omega**2 <= cot(thc))",
    "max_impacts": "stopped at the impact bound max_impacts before the requested end",
    "nonfinite": "a non-finite number appeared; this is a bug, please report the inputs",
    "settled": "stopped early: the stroboscopic orbit settled on a periodic one",
}


#: Separation, relative to the orbit's size, at which two runs count as different (the
#: predictability horizon's tolerance, rockjit.basins.fate).
HORIZON_TOL = 1e-2
#: Rounding, relative: the perturbation every run carries.
ROUNDING = float(np.finfo(float).eps)


def horizon(lam1, eps, tol=HORIZON_TOL):
    """Predictability horizon ``ln(tol / eps) / lam1``: the time two runs ``eps`` apart stay
    within ``tol`` of each other when they separate at the rate ``lam1`` (``inf`` unless
    ``lam1 > 0``)."""
    if not lam1 > 0:
        return math.inf
    return math.log(tol / eps) / lam1


def fractions(label):
    """Percentage of cells per behaviour name (every name present, zeros included)."""
    label = np.asarray(label)
    n = label.size
    return {name: (100.0 * np.count_nonzero(label == code) / n if n else 0.0)
            for code, name in enumerate(BEHAVIOURS)}


@dataclass
class Result:
    """What one run produced. Arrays are views of exactly what was computed.

    Attributes
    ----------
    block : Block
        The block.
    forcing : Harmonic
        The excitation.
    integration : Integration
        The integration settings as given (``n_steps`` is the one used).
    method : str
        ``"rockjit"`` or ``"scipy:<solve_ivp method>"``.
    status : str
        One of :data:`rockjit.result.STATUSES`; ``message`` says it in words.
    t : float
        Time reached (the overturning or rest instant for runs that stopped there).
    state : ndarray, shape (4,)
        ``(theta, theta', r, s)`` at ``t``.
    period : float
        Forcing period ``T``.
    n_steps : int
        Steps per period ``N`` (the compiled path's grid; also the scipy path's sampling grid).
    periods : int
        Periods asked for.
    strobe : ndarray, shape (k, 4)
        ``(theta, theta', r, s)`` at ``t = 0, T, 2T, ...`` as far as the run went.
    strobe_half : ndarray, shape (k, 4)
        The same at ``t = T/2, 3T/2, ...``.
    impacts : ndarray, shape (m, 3)
        ``(t, theta'-, theta'+)`` of the impacts, in order: all of them, or the latest million
        (``rockjit._engine.kernel.IMPACT_RECORD``) when there were more (``n_impacts`` counts
        all).
    n_impacts, n_grid_steps, n_rhs : int
        Counts of impacts, grid steps completed, right-hand-side evaluations.
    max_error_estimate : float
        Largest embedded 4th-order error estimate of ``theta, theta'`` over the run's steps
        (``nan`` on the scipy path).
    trajectory : ndarray, shape (p, 5) or None
        ``(t, theta, theta', r, s)`` every ``record_stride`` grid steps, when asked.
    lyapunov : ndarray, shape (2,) or None
        ``(lambda1, lambda2)`` averaged over ``window``, when asked; ``-inf`` when every
        perturbation dies in the window (a rest phase, or an impact with ``e = 0``).
    lyapunov_running : ndarray, shape (k, 2) or None
        The running estimate ``lambda(t)`` at ``t = 0, T, 2T, ...``.
    window : tuple of float or None
        ``(t0, t1)`` over which ``lyapunov`` was averaged.
    n_rest, n_rest_window : int
        Rest phases entered (Zeno cut-offs), overall and within ``window``.
    n_impacts_window : int
        Impacts within the window (for the exact identity of docs/theory/exponents.md).
    n_locate_unconverged : int
        Events whose time the Newton polish could not bring within its tolerance (taken at the
        best bracketed estimate; expected 0, counted so that tests can require it).
    t_overturn : float
        A run that went on past the overturning threshold (``stop_at_overturn=False``, the
        study's way): the first instant ``|theta|`` reached it; ``nan`` otherwise.
    extra : dict
        Further arrays of some runs (``"tangent"``: the tangent matrix of a run with
        ``lyapunov=True`` and ``qr_every=0``).

    Examples
    --------
    >>> import rockjit
    >>> from rockjit import Block, Harmonic, Integration
    >>> res = rockjit.simulate(Block(hb=1), Harmonic(alpha=0.6, omega=1.3),
    ...                        integration=Integration(periods=20))
    >>> res.status, res.n_impacts, round(res.t, 4)
    ('done', 40, 96.6644)
    >>> res.message
    'reached the requested number of periods'
    >>> res.strobe.shape, res.impacts.shape
    ((21, 4), (40, 3))
    """

    block: Block
    forcing: Excitation
    integration: Integration
    method: str
    status: str
    t: float
    state: np.ndarray
    period: float
    n_steps: int
    periods: int
    strobe: np.ndarray
    strobe_half: np.ndarray
    impacts: np.ndarray
    n_impacts: int
    n_grid_steps: int
    n_rhs: int
    max_error_estimate: float
    trajectory: np.ndarray | None = None
    lyapunov: np.ndarray | None = None
    lyapunov_running: np.ndarray | None = None
    window: tuple | None = None
    n_rest: int = 0
    n_rest_window: int = 0
    n_impacts_window: int = 0
    n_locate_unconverged: int = 0
    t_overturn: float = math.nan
    extra: dict = field(default_factory=dict)

    @property
    def message(self) -> str:
        """The status in words (:data:`rockjit.result.STATUS_MESSAGES`)."""
        return STATUS_MESSAGES[self.status]

    @property
    def lambda_max(self) -> float:
        """``lambda1`` over the window (``nan`` when exponents were not asked for)."""
        return math.nan if self.lyapunov is None else float(self.lyapunov[0])

    def arrays(self):
        """The run's arrays by name, for an ``.npz``: the recorded trajectory (``t, theta,
        dtheta, r, s``) when there is one, the samples, the impacts, the running exponents."""
        out = {}
        if self.trajectory is not None:
            tr = self.trajectory
            out.update(t=tr[:, 0], theta=tr[:, 1], dtheta=tr[:, 2], r=tr[:, 3], s=tr[:, 4])
        out.update(strobe=self.strobe, strobe_half=self.strobe_half, impacts=self.impacts)
        if self.lyapunov_running is not None:
            out["lyapunov_running"] = self.lyapunov_running
        return out

    def summary(self):
        """JSON-ready scalars of the run (its exponents when computed)."""
        # the first instant |theta| reached theta_over: where a run stopped there, its end
        t_over = self.t if self.status == "overturned" and math.isnan(self.t_overturn) \
            else self.t_overturn
        out = dict(status=self.status, message=self.message, t_end=self.t,
                   final_state=self.state, n_impacts=self.n_impacts, n_rest=self.n_rest,
                   restitution=self.block.restitution, n_steps=self.n_steps,
                   max_error_estimate=self.max_error_estimate, method=self.method,
                   n_locate_unconverged=self.n_locate_unconverged, t_overturn=t_over)
        if self.lyapunov is not None:
            # the averaging window as planned, forwards; a run that ended before it began has
            # no exponent over it (nan), which window_reached says
            reached = self.window is not None and self.t > self.window[0]
            window = self.window if self.window is None or reached else \
                (float(self.window[0]), float(self.periods * self.period))
            out.update(lambda_max=self.lyapunov[0], lyapunov=self.lyapunov, window=window,
                       window_reached=bool(reached),
                       horizon=self.horizon, beyond_horizon=bool(self.beyond_horizon))
        return out

    @property
    def horizon(self) -> float:
        """The run's own predictability horizon: how long rounding (``eps = 2.2e-16``) takes to
        grow to :data:`rockjit.result.HORIZON_TOL` at the finite-time exponent of the whole run,
        ``lambda1`` over ``[0, t]`` (``inf`` when it is not positive, ``nan`` without
        exponents)."""
        if self.lyapunov_running is None or len(self.lyapunov_running) < 2:
            return math.nan
        return horizon(float(self.lyapunov_running[-1, 0]), ROUNDING)

    @property
    def beyond_horizon(self) -> bool:
        """True when the run ended beyond its own horizon: its outcome is one sample of what
        rounding can make of it, not a result (rockjit.basins.fate gives the probabilities)."""
        return self.t > self.horizon

    @property
    def stopped_early(self) -> bool:
        """True when the run ended before the requested time for a reason other than its
        physics (the impact bound, a non-finite number)."""
        return self.status in ("max_impacts", "nonfinite")

    def caveats(self):
        """What a reader of this run must be told, as sentences: a stop before the requested
        end, exponents with no averaging window, an outcome beyond the predictability horizon."""
        out = []
        if self.stopped_early:
            raise_ = "; raise Integration.max_impacts"
            out.append(f"the run stopped at t = {self.t:.6g} of {self.periods * self.period:.6g}: "
                       f"{self.message}"
                       + (raise_ if self.status == "max_impacts" else ""))
        if self.lyapunov is not None and self.window and self.t <= self.window[0]:
            out.append("the run ended before the averaging window began: lambda is nan")
        if self.lyapunov is not None and self.beyond_horizon:
            out.append(f"the run ended at t = {self.t:.4g}, beyond its predictability horizon "
                       f"t* = {self.horizon:.4g} (rounding grown to 1 % at lambda1 = "
                       f"{self.lyapunov_running[-1, 0]:.3g}): its outcome is one sample; "
                       "rockjit.fate gives the probabilities")
        return out

    def __repr__(self) -> str:
        b, f = self.block, self.forcing
        return (f"Result({self.method}, hb={b.hb}, law={b.law}, alpha={f.alpha}, "
                f"omega={f.omega}, status={self.status!r}, t={self.t:.6g}, "
                f"impacts={self.n_impacts})")


def _names_array():
    return np.array(BEHAVIOURS)


@dataclass(kw_only=True)
class GridResult:
    """What every grid result has: the block, the excitation (without what the grid sweeps), the
    settings it was computed with, and the behaviour names that its ``label`` codes index."""

    block: Block
    forcing: Excitation | None = None
    settings: dict = field(default_factory=dict)
    names: np.ndarray = field(default_factory=_names_array)
    #: Outcome id of each cell (same shape as ``label``): ``>= 0`` the attractor it reaches,
    #: ``-1`` overturn, ``-2`` unresolved (rockjit.grids.identity); None when not identified.
    attractor: np.ndarray | None = None
    #: The attractors, by id: each one's behaviour, period, cycle points, basin fraction and
    #: Floquet multipliers (``rockjit.grids.identity.Attractor``).
    attractors: list = field(default_factory=list)
    #: Cells whose outcome changes when their initial state moves by ``settings["uncertainty"]``
    #: (``Classification(uncertainty=...)``); None when not asked for.
    uncertain: np.ndarray | None = None
    #: ``lambda1`` of each cell as the finite-window QR average over its classified stretch
    #: (docs/theory/exponents.md, "Benettin's method"), the study's estimate, shaped like
    #: ``label``; ``lambda_max`` replaces it by the exact Floquet exponent where the cell
    #: settled on a periodic orbit. None when no exponents were computed.
    lambda_window: np.ndarray | None = None

    def fractions(self):
        """Percentage of cells per behaviour name."""
        return fractions(self.label)

    def attractor_summary(self):
        """The attractors as JSON-ready dicts."""
        return [a.to_dict() for a in self.attractors]


@dataclass(kw_only=True)
class SweepResult(GridResult):
    """An α sweep: one run per forcing amplitude, all from the same initial state.

    Attributes
    ----------
    alpha : ndarray, shape (n,)
    label : ndarray of int, shape (n,)
        Behaviour codes; ``names[label]`` gives the names (:data:`rockjit.BEHAVIOURS`).
    period : ndarray of int, shape (n,)
        Period in forcing periods (0 when none).
    lambda_max : ndarray, shape (n,)
        The largest Lyapunov exponent: where the run settled on a periodic orbit (symmetric,
        asymmetric, multiperiodic), its Floquet exponent ``ln|mu1| / (pT)`` from the exact
        monodromy (``-inf`` through rest); elsewhere ``lambda_window`` (``nan`` when not
        computed or overturned, ``-inf`` when every perturbation dies: rest).
    lambda_window : ndarray, shape (n,)
        ``lambda1`` as the finite-window QR average over the classified stretch, every cell
        (the study's estimate).
    strobe : ndarray, shape (n, w, 2)
        ``(theta, theta')`` at ``t = kT`` over the classified stretch (``nan``-padded).
    impact_section : ndarray, shape (n, m, 2)
        ``(t mod T, theta'-)`` of the impacts over the classified stretch (``nan``-padded).
    t_end : ndarray, shape (n,)
        Time each run stopped (early stop, overturn, rest or the end).

    Examples
    --------
    >>> import rockjit
    >>> from rockjit import Block, Harmonic, Integration
    >>> sw = rockjit.sweep(Block(hb=1), Harmonic(omega=1.3), [0.6, 0.8],
    ...                    integration=Integration(periods=100))
    >>> [str(n) for n in sw.names[sw.label]], sw.period.tolist()
    (['symmetric', 'asymmetric'], [1, 1])
    >>> sw.strobe.shape
    (2, 21, 2)
    """

    alpha: np.ndarray
    label: np.ndarray
    period: np.ndarray
    lambda_max: np.ndarray
    strobe: np.ndarray
    impact_section: np.ndarray
    t_end: np.ndarray
    #: The first overturning instant of each run that went on past it (nan: never, or
    #: stopped there), and the behaviour code of the motion each run settled on (the label
    #: before the study's rule made a fallen cell "overturn").
    t_overturn: np.ndarray | None = None
    motion: np.ndarray | None = None

    def __repr__(self):
        return _text(self)

    def arrays(self):
        """The sweep's arrays by name, for an ``.npz``."""
        out = dict(alpha=self.alpha, label=self.label, period=self.period,
                   lambda_max=self.lambda_max, strobe=self.strobe,
                   impact_section=self.impact_section, t_end=self.t_end,
                   names=np.asarray(self.names, dtype=str))
        if self.lambda_window is not None:
            out["lambda_window"] = self.lambda_window
        if self.attractor is not None:
            out["attractor"] = self.attractor
        if self.settings.get("stop_at_overturn") is False:
            out.update(t_overturn=self.t_overturn, motion=self.motion)
        return out

    def to_xarray(self):
        """The sweep as a labelled ``xarray.Dataset`` (needs ``pip install rockjit[xarray]``).

        Returns
        -------
        xarray.Dataset
            Coordinate ``alpha`` (with ``units`` and ``long_name``); variables ``label``
            (the behaviour names as CF ``flag_values``/``flag_meanings``), ``period``,
            ``lambda_max``, ``t_end``, ``strobe`` (``alpha, strobe_sample, strobe_var``),
            ``impact_section`` (``alpha, impact, impact_var``) and, where computed,
            ``lambda_window``, ``attractor``, ``uncertain``, ``t_overturn``, ``motion``;
            attributes: the block, the excitation and the settings as numbers and strings
            (booleans as 0/1), so that ``ds.to_netcdf(path)`` writes it.

        Raises
        ------
        ImportError
            Without xarray.

        Examples
        --------
        >>> import rockjit
        >>> from rockjit import Block, Harmonic, Integration
        >>> sw = rockjit.sweep(Block(hb=1), Harmonic(omega=1.3), [0.6, 0.8],
        ...                    integration=Integration(periods=100))
        >>> ds = sw.to_xarray()
        >>> bool(ds.label.sel(alpha=0.8) == sw.label[1]), ds.attrs["law"]
        (True, 'housner')
        >>> ds.label.attrs["flag_meanings"].split()[:3]
        ['overturn', 'rest', 'symmetric']
        """
        from .storage.labelled import sweep_dataset
        return sweep_dataset(self)


@dataclass(kw_only=True)
class BasinResult(GridResult):
    """A basin of attraction over ``(theta0, theta0')`` at a fixed forcing phase.

    ``label[i, j]`` belongs to ``theta0[i]``, ``dtheta0[j]``. ``lambda_max`` (when computed)
    is, as in :class:`SweepResult`, the Floquet exponent of a cell that settled on a periodic
    orbit and ``lambda_window`` elsewhere.

    Attributes
    ----------
    theta0, dtheta0 : ndarray, shape (n,)
        The lattice's axes.
    label, period : ndarray of int, shape (n, n)
        Behaviour code (``names[label]``) and period of each cell.
    lambda_max : ndarray, shape (n, n) or None
        The Floquet exponent of a periodic cell, ``lambda_window`` elsewhere (when
        asked for).
    t_end : ndarray, shape (n, n)
        Time each run stopped.
    block, forcing, settings :
        The block, the excitation and the settings it was computed with; ``attractor``,
        ``attractors`` and ``uncertain`` are below.

    Examples
    --------
    >>> import rockjit
    >>> from rockjit import Block, Harmonic, Integration
    >>> b = rockjit.basin(Block(hb=1), Harmonic(alpha=0.66, omega=1.3), grid=10,
    ...                   integration=Integration(periods=100))
    >>> b.label.shape, str(b.names[b.label[5, 5]]), len(b.attractors)
    ((10, 10), 'symmetric', 2)
    >>> {k: round(float(v), 1) for k, v in b.fractions().items() if v}
    {'overturn': 48.0, 'symmetric': 52.0}
    """

    theta0: np.ndarray
    dtheta0: np.ndarray
    label: np.ndarray
    period: np.ndarray
    lambda_max: np.ndarray | None
    t_end: np.ndarray

    def __repr__(self):
        return _text(self)

    def summary(self):
        """JSON-ready: behaviours (percent and counts), settings, attractors and, when they
        were identified, the attractor map's measures (:meth:`measures`)."""
        lab = np.asarray(self.label)
        counts = {str(n): int(np.count_nonzero(lab == c)) for c, n in enumerate(self.names)}
        out = dict(law=self.block.law, restitution=self.block.restitution,
                   fractions=self.fractions(), counts=counts, settings=self.settings,
                   attractors=self.attractor_summary())
        if self.attractor is not None:
            out.update(self.measures())
        return out

    def to_xarray(self):
        """The basin as a labelled ``xarray.Dataset`` (needs ``pip install rockjit[xarray]``).

        Returns
        -------
        xarray.Dataset
            Coordinates ``theta0``, ``dtheta0`` (with ``units`` and ``long_name``);
            variables ``label`` (the behaviour names as CF ``flag_values``/
            ``flag_meanings``), ``period``, ``t_end`` and, where computed, ``attractor``
            (each attractor named in its flags), ``uncertain``, ``lambda_max``,
            ``lambda_window``; attributes: the block, the excitation (``alpha``, ``omega``,
            the phase) and the settings as numbers and strings (booleans as 0/1), so that
            ``ds.to_netcdf(path)`` writes it.

        Raises
        ------
        ImportError
            Without xarray.

        Examples
        --------
        >>> import rockjit
        >>> from rockjit import Block, Harmonic, Integration
        >>> b = rockjit.basin(Block(hb=1), Harmonic(alpha=0.66, omega=1.3), grid=10,
        ...                   integration=Integration(periods=100))
        >>> ds = b.to_xarray()
        >>> ds.label.dims, ds.attrs["alpha"], ds.attrs["law"]
        (('theta0', 'dtheta0'), 0.66, 'housner')
        >>> cell = ds.label.sel(theta0=0.1, dtheta0=0.1, method="nearest")
        >>> bool(cell == b.label[5, 5]), str(b.names[cell.item()])
        (True, 'symmetric')
        """
        from .storage.labelled import basin_dataset
        return basin_dataset(self)

    def measures(self, box=5, eps_cells=(1, 2, 3, 4, 6, 8)):
        """Measures of the attractor map (rockjit.measures): basin entropy ``Sb`` and
        boundary basin entropy ``Sbb`` on ``box x box`` boxes, the uncertainty exponent of the
        boundary from the fraction of cells whose outcome differs ``eps`` cells away, and the
        dynamical integrity (GIM, IF, and LIM of each bounded attractor). JSON-ready."""
        from . import measures as M
        ids = self.attractor
        if min(ids.shape) >= 2:
            out = M.basin_entropy(ids, box=min(box, *ids.shape)).to_dict()
        else:  # no box of two cells fits
            out = dict(basin_entropy=math.nan, boundary_basin_entropy=math.nan, n_boxes=0,
                       n_boundary_boxes=0, box=box)
        eps = [e for e in eps_cells if 2 * e < min(ids.shape)]
        f = M.uncertain_fraction(ids, eps) if eps else []
        if len(eps) >= 3 and np.all(np.asarray(f) > 0):
            u = M.uncertainty_exponent(eps, f)
            out["uncertainty_exponent"] = dict(alpha=u.alpha, stderr=u.stderr,
                                               dimension=u.dimension, eps_cells=eps,
                                               fraction=list(map(float, f)))
        else:  # no boundary the perturbations can find
            out["uncertainty_exponent"] = dict(alpha=math.nan, stderr=math.nan,
                                               dimension=math.nan, eps_cells=eps,
                                               fraction=list(map(float, f)))
        points = {a.id: a.points for a in self.attractors}
        th, dth = np.asarray(self.theta0), np.asarray(self.dtheta0)
        if th.size > 1 and dth.size > 1 and th[-1] > th[0] and dth[-1] > dth[0]:
            out["integrity"] = M.integrity(ids, th, dth, points).to_dict()
        else:  # a line or a point of initial states holds no disc
            out["integrity"] = {"GIM": float(np.mean(ids >= 0)), "IF": math.nan,
                                "LIM": {a.id: math.nan for a in self.attractors}}
        return out


@dataclass(kw_only=True)
class PlaneResult(GridResult):
    """Behaviours over the forcing plane ``(alpha, omega)`` from one or more initial states.

    ``label[m, i, j]`` belongs to initial state ``z0[m]``, ``alpha[i]``, ``omega[j]``.

    ``lambda_max`` is, as in :class:`SweepResult`, the Floquet exponent of each cell that
    settled on a periodic orbit (each cell its own system) and ``lambda_window`` elsewhere.

    Attributes
    ----------
    alpha : ndarray, shape (na,)
    omega : ndarray, shape (nw,)
    z0 : ndarray, shape (m, 4)
        The initial states ``(theta0, theta0', r0, s0)``.
    label, period : ndarray of int, shape (m, na, nw)
        Behaviour code (``names[label]``) and period of each cell.
    lambda_max, t_end : ndarray, shape (m, na, nw)
    block, forcing, settings :
        As in :class:`rockjit.BasinResult`; the attractors are continued across the plane.

    Examples
    --------
    >>> import rockjit
    >>> from rockjit import Block
    >>> pl = rockjit.plane(Block(hb=1), (0.5, 0.6), (1.2, 1.3), grid=(2, 2))
    >>> pl.names[pl.label[0]].tolist()
    [['rest', 'rest'], ['rest', 'symmetric']]
    """

    alpha: np.ndarray
    omega: np.ndarray
    z0: np.ndarray
    label: np.ndarray
    period: np.ndarray
    lambda_max: np.ndarray
    t_end: np.ndarray

    def __repr__(self):
        return _text(self)

    def to_xarray(self):
        """The plane as a labelled ``xarray.Dataset`` (needs ``pip install rockjit[xarray]``).

        Returns
        -------
        xarray.Dataset
            Dimensions ``state, alpha, omega``: coordinates ``alpha``, ``omega`` (with
            ``units`` and ``long_name``) and, along ``state``, the initial states ``z0`` as
            ``theta0, dtheta0, r0, s0``; variables ``label`` (the behaviour names as CF
            ``flag_values``/``flag_meanings``), ``period``, ``lambda_max``, ``t_end`` and,
            where computed, ``lambda_window``, ``attractor``, ``uncertain``; attributes: the
            block and the settings as numbers and strings, so that ``ds.to_netcdf(path)``
            writes it.

        Raises
        ------
        ImportError
            Without xarray.

        Examples
        --------
        >>> import rockjit
        >>> from rockjit import Block
        >>> pl = rockjit.plane(Block(hb=1), (0.5, 0.6), (1.2, 1.3), grid=(2, 2))
        >>> ds = pl.to_xarray()
        >>> ds.label.dims
        ('state', 'alpha', 'omega')
        >>> str(pl.names[ds.label.sel(state=0, alpha=0.6, omega=1.3).item()])
        'symmetric'
        """
        from .storage.labelled import plane_dataset
        return plane_dataset(self)
