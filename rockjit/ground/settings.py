"""How a run under a transient excitation (a pulse, a record) is integrated.

A harmonic run is measured in forcing periods (:class:`rockjit.Integration`); a pulse or a
record has no period. A transient run instead lasts until the excitation has ended and then
for ``free_time`` more model time units of free rocking (or until ``duration``, if given), and
ends earlier when the block overturns, comes to rest for good, or, with ``stop_when_decided``,
as soon as free rocking can no longer change the outcome (docs/guide/earthquakes.md, "When a
run stops"). Time is in model units, ``1/sqrt(g/R)``: for a record on a block of
half-diagonal ``R`` one unit is ``sqrt(R/g)`` seconds (``Record.time_factor``).
"""

from __future__ import annotations

import math
from dataclasses import dataclass, replace

from ..settings import MAX_IMPACTS, REST_SPEED_RANGE
from ..validate import boolean, integer, real

__all__ = ["DEFAULT_MAX_IMPACTS", "TIME_MAX", "Transient"]

#: Longest run, in model time units (a 1e9 s record on a 1 m block is 3e9: beyond it).
TIME_MAX = 1e9
#: Default impact bound: free rocking from ``|theta'| ~ 1`` down to the Zeno cut-off takes
#: ``ln(1e-6) / ln(e)`` impacts, ~1,400 for ``e = 0.99``; a long record adds a few per second.
DEFAULT_MAX_IMPACTS = 100_000


@dataclass(frozen=True)
class Transient:
    """How a run under a pulse or a record is integrated.

    Parameters
    ----------
    free_time : float
        Model time units of free rocking after the excitation ends, in ``[0, 1e9]``; default
        100 (about 14 small-amplitude rocking cycles of a slender block, ``2 pi / p = 7.3``).
    duration : float, optional
        A hard limit on the run's model time instead, in ``(0, 1e9]``: the run stops there even
        during the excitation.
    stop_when_decided : bool
        Stop as soon as the outcome and ``max |theta|`` can no longer change: after the
        excitation, once the block is at rest, or its energy, which free rocking only loses,
        is below the tipping energy and no more than the potential energy at the largest
        ``|theta|`` so far (``rockjit.model.free_rocking_decided``). Default
        ``False`` (rock on to the time limit); the spectra and fragility curves set it.
    max_impacts : int, optional
        Bound on the number of impacts (default 100,000); reaching it ends the run unresolved.
    rest_speed : float
        The Zeno cut-off in ``[1e-12, 0.1]``: an impact leaving with ``|theta'| < rest_speed``
        puts the block at rest (default ``1e-6``, as for harmonic runs).
    theta_over : float
        Overturning threshold on ``|theta|`` in ``(0, pi/2]``, default ``pi/2`` (the block lies
        on its side).
    record : bool
        Keep the trajectory ``(t, theta, theta')`` at the solver's points (default ``True``);
        the grids turn it off.

    Examples
    --------
    >>> from rockjit import Transient
    >>> Transient(free_time=20.0).limit(end=12.5)
    32.5
    """

    free_time: float = 100.0
    duration: float | None = None
    stop_when_decided: bool = False
    max_impacts: int | None = None
    rest_speed: float = 1e-6
    theta_over: float = 0.5 * math.pi
    record: bool = True

    def __post_init__(self):
        _set = lambda **kw: [object.__setattr__(self, k, v) for k, v in kw.items()]  # noqa
        _set(free_time=real("free_time", self.free_time, 0.0, TIME_MAX))
        if self.duration is not None:
            _set(duration=real("duration", self.duration, 0.0, TIME_MAX, lo_open=True))
        _set(stop_when_decided=boolean("stop_when_decided", self.stop_when_decided),
             record=boolean("record", self.record))
        if self.max_impacts is not None:
            _set(max_impacts=integer("max_impacts", self.max_impacts, 1, MAX_IMPACTS))
        if isinstance(self.rest_speed, (int, float)) and self.rest_speed == 0:
            raise ValueError("rest_speed must be > 0 (got 0): with e < 1 the impacts of a Zeno "
                             "cascade accumulate in finite time")
        _set(rest_speed=real("rest_speed", self.rest_speed, *REST_SPEED_RANGE),
             theta_over=real("theta_over", self.theta_over, 0.0, 0.5 * math.pi, lo_open=True))

    def replace(self, **changes):
        """A copy with some fields changed (validated again)."""
        return replace(self, **changes)

    def limit(self, end):
        """The run's time limit for an excitation that ends at model time ``end``:
        ``duration``, or ``end + free_time``."""
        return self.duration if self.duration is not None else end + self.free_time

    def impact_bound(self):
        """``max_impacts``, or ``DEFAULT_MAX_IMPACTS`` (100,000)."""
        return DEFAULT_MAX_IMPACTS if self.max_impacts is None else self.max_impacts
