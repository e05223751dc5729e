"""What one run under a pulse or a record produced, and the outcome codes of the grids.

The outcome of a transient run is one of :data:`OUTCOMES`: the block survived (``safe``),
overturned after at least one impact (mode 1 of Zhang & Makris 2001), overturned without ever
returning to ``theta = 0`` (mode 2), or the run could not say (it stopped at its impact bound,
at a time limit that fell inside the excitation, or on a non-finite number). Its demand is
``max |theta| / alpha_s``, the largest rotation over the slenderness angle
``alpha_s = pi/2 - thc = arctan(b/h)``: the literature's ``theta / alpha`` (1 is the static
tipping angle; docs/theory/ground-motions.md).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

__all__ = ["MODE_NAMES", "OUTCOMES", "SAFE", "OVERTURN_IMPACT", "OVERTURN_NO_IMPACT",
           "OUTPUTS", "STATUSES", "STATUS_CODES", "TransientResult", "UNRESOLVED", "alpha_s",
           "empty_outputs", "outcome_of"]

#: Outcome codes of a transient run, in order.
OUTCOMES = ("safe", "overturn after impact", "overturn without impact", "unresolved")
SAFE, OVERTURN_IMPACT, OVERTURN_NO_IMPACT, UNRESOLVED = range(4)
#: The overturning modes as summary.json writes them.
MODE_NAMES = {OVERTURN_IMPACT: "with impact", OVERTURN_NO_IMPACT: "without impact"}

#: Statuses of a transient run and what each means.
STATUSES = {
    "overturned": "the block overturned (|theta| reached theta_over)",
    "rest": "the block came to rest and the excitation can no longer lift it",
    "decided": "stopped after the excitation: the block's energy is below the tipping energy "
               "and no more than the potential energy at the largest |theta| so far, so free "
               "rocking can neither overturn it nor swing it wider",
    "time_limit": "still rocking at the time limit",
    "max_impacts": "stopped at the impact bound max_impacts",
    "nonfinite": "a non-finite number appeared; this is a bug, please report the inputs",
}

#: The statuses a kernel reports, in the order of their codes.
STATUS_CODES = tuple(STATUSES)
#: A kernel's outputs for a chunk of cells (:mod:`rockjit.ground.batch`): name -> dtype.
OUTPUTS = {"outcome": np.int8, "max_rotation": np.float64, "t_overturn": np.float64,
           "t_end": np.float64, "n_impacts": np.int64, "status": np.int8}


def empty_outputs(n):
    """The output arrays of ``n`` cells, filled as a kernel fills them for no run."""
    return {k: (np.full(n, np.nan) if np.dtype(t).kind == "f" else np.zeros(n, dtype=t))
            for k, t in OUTPUTS.items()}


def alpha_s(hb):
    """The slenderness angle ``arctan(b/h) = pi/2 - thc``."""
    return math.atan2(1.0, hb)


def outcome_of(status, n_impacts, t, end):
    """The outcome code of a run that stopped with ``status`` at time ``t`` after
    ``n_impacts`` impacts, under an excitation that ends at ``end``."""
    if status == "overturned":
        return OVERTURN_IMPACT if n_impacts > 0 else OVERTURN_NO_IMPACT
    if status in ("rest", "decided") or (status == "time_limit" and t >= end):
        return SAFE
    return UNRESOLVED


@dataclass
class TransientResult:
    """One run under a pulse or a record.

    Attributes
    ----------
    block : Block
    excitation : Pulse or Record
        The excitation, bound to the block (the pulse's ``hb``, the record's size).
    settings : Transient
    method : str
        ``"rockjit"`` (the compiled path) or ``"scipy:<solve_ivp method>"``.
    status : str
        One of :data:`rockjit.ground.response.STATUSES`.
    t : float
        Model time reached.
    state : ndarray, shape (2,)
        ``(theta, theta')`` at ``t``.
    t_uplift : float
        The first instant the block left rest (``nan``: it never did, or never rested).
    max_theta : float
        ``max |theta|`` over the run (``theta_over`` for an overturned run).
    impacts : ndarray, shape (m, 3)
        ``(t, theta'-, theta'+)`` of every impact, in order.
    t_overturn : float
        When ``|theta|`` reached ``theta_over`` (``nan``: it did not).
    trajectory : ndarray, shape (p, 3) or None
        ``(t, theta, theta')`` at the solver's points (the compiled path: its grid's), the
        events and the ends of rest.
    n_rhs : int
        Right-hand-side evaluations (the compiled path: six per step, the events' steps
        included).
    n_rest : int
        Rest phases entered after an impact (Zeno cut-offs).

    Examples
    --------
    >>> import rockjit
    >>> from rockjit import Block, Pulse
    >>> res = rockjit.simulate(Block(hb=4), Pulse("sine", ratio=2.0, amplitude=1.5),
    ...                        method="scipy")
    >>> res.status, res.mode, res.n_impacts
    ('overturned', 'with impact', 1)
    >>> rockjit.ground.OUTCOMES[res.outcome]
    'overturn after impact'
    """

    block: object
    excitation: object
    settings: object
    method: str
    status: str
    t: float
    state: np.ndarray
    t_uplift: float
    max_theta: float
    impacts: np.ndarray
    t_overturn: float = math.nan
    trajectory: np.ndarray | None = None
    n_rhs: int = 0
    n_rest: int = 0

    @property
    def message(self) -> str:
        """What ``status`` means, in words (:data:`rockjit.ground.response.STATUSES`)."""
        return STATUSES[self.status]

    @property
    def n_impacts(self) -> int:
        """The number of impacts."""
        return int(self.impacts.shape[0])

    @property
    def alpha_s(self) -> float:
        """The block's slenderness angle ``arctan(b/h)``."""
        return alpha_s(self.block.hb)

    @property
    def max_rotation(self) -> float:
        """``max |theta| / alpha_s``."""
        return self.max_theta / self.alpha_s

    @property
    def overturned(self) -> bool:
        """Whether the block overturned."""
        return self.status == "overturned"

    @property
    def outcome(self) -> int:
        """The outcome code (:data:`OUTCOMES`)."""
        return outcome_of(self.status, self.n_impacts, self.t, self.excitation.end)

    @property
    def mode(self):
        """``"with impact"`` or ``"without impact"`` for an overturned run, else ``None``."""
        return MODE_NAMES.get(self.outcome)

    @property
    def seconds(self) -> float:
        """Seconds per model time unit: ``sqrt(R/g)`` for a record, ``nan`` for a pulse
        (whose ratios hold for any size)."""
        tf = getattr(self.excitation, "time_factor", None)
        return 1.0 / tf if tf else math.nan

    def arrays(self):
        """The run's arrays by name, for an ``.npz``."""
        out = {"impacts": self.impacts}
        if self.trajectory is not None:
            out.update(t=self.trajectory[:, 0], theta=self.trajectory[:, 1],
                       dtheta=self.trajectory[:, 2])
        return out

    def summary(self):
        """JSON-ready scalars of the run."""
        return dict(status=self.status, message=self.message, outcome=OUTCOMES[self.outcome],
                    mode=self.mode, t_end=self.t, t_uplift=self.t_uplift,
                    t_overturn=self.t_overturn, max_theta=self.max_theta,
                    max_rotation=self.max_rotation, n_impacts=self.n_impacts,
                    n_rest=self.n_rest, restitution=self.block.restitution,
                    method=self.method, seconds_per_unit=self.seconds)

    def caveats(self):
        """What a reader must be told: a run that ended without an outcome."""
        if self.outcome != UNRESOLVED:
            return []
        return [f"the run stopped at t = {self.t:.6g} without an outcome: {self.message}"]

    def __repr__(self):
        return (f"TransientResult({self.method}, hb={self.block.hb}, law={self.block.law}, "
                f"{self.excitation!r}, status={self.status!r}, t={self.t:.6g}, "
                f"impacts={self.n_impacts}, max|theta|/alpha_s={self.max_rotation:.4g})")
