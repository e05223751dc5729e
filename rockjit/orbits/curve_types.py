"""What the bifurcation curves in the forcing plane ``(alpha, omega)`` are and how they are
followed: the curve types (:data:`CURVE_TYPES`), the codimension-two points a curve reports
(:data:`CODIM2_TYPES`, each a :class:`Codim2Point`), why a curve ends (:data:`CURVE_ENDS`), and
the continuation's settings (:class:`CurveSettings`). The curve itself is a
:class:`~rockjit.orbits.bifurcation_curve.BifurcationCurve`; the definitions are in
:mod:`.curves`.
"""

from __future__ import annotations

from dataclasses import dataclass, replace

import numpy as np

from ..validate import integer, real
from .types import _set

__all__ = ["CODIM2_TYPES", "CURVE_ENDS", "CURVE_TYPES", "Codim2Point", "CurveSettings"]

#: The codimension-one curves followed.
CURVE_TYPES = ("fold", "symmetry_breaking", "period_doubling", "grazing")

#: The codimension-two points a curve reports (:mod:`.curves`, "Codimension two").
CODIM2_TYPES = ("fold_flip", "resonance_1_1", "resonance_1_2", "cusp", "grazing_fold",
                "grazing_symmetry_breaking", "grazing_period_doubling", "double_grazing",
                "degenerate_pitchfork", "degenerate_flip")

#: Why a curve ends at either end.
CURVE_ENDS = {
    "range": "it leaves the chart (last point on its edge)",
    "grazing": "its orbit's impact count changes: it meets a grazing curve",
    "overturn": "its orbit overturns (reaches theta_over)",
    "rest": "its orbit comes to rest",
    "branch_point": "its orbit becomes symmetric, or of half the period",
    "closed": "the curve closes on itself",
    "unstable": "its orbit's largest multiplier exceeds max_multiplier",
    "no_convergence": "the corrector fails at the smallest step",
    "max_points": "the bound on points",
    "budget": "the bound on runs",
}


@dataclass(frozen=True)
class CurveSettings:
    """How a curve is followed in the plane.

    Parameters
    ----------
    ds0, ds_min, ds_max : float
        First, smallest and largest pseudo-arclength step in ``(theta, theta', alpha, omega)``,
        ``0 < ds_min <= ds0 <= ds_max``; defaults 0.01, ``1e-7``, 0.04.
    max_points : int
        Points per direction, ``>= 2``; default 1000.
    max_calls : int
        Runs spent per curve, ``>= 1``; default 200,000.
    param_tol : float
        Codimension-two points and curve ends are located to this in the plane, ``> 0``;
        default ``1e-8``.
    max_multiplier : float
        A curve is not followed where its orbit's largest ``|mu|`` exceeds this (end
        ``"unstable"``; a seed beyond it is refused), ``> 1``; default ``1e4``. So unstable an
        orbit is invisible to the brute-force chart, and its shooting degrades: a state error
        along the unstable direction grows by ``|mu|`` over the cycle, beyond the reach of the
        differences of the grazing condition, and the steps shrink without end.

    Examples
    --------
    >>> from rockjit.orbits import CurveSettings
    >>> CurveSettings().ds_max
    0.04
    >>> CurveSettings(ds0=1.0)
    Traceback (most recent call last):
    ...
    ValueError: need ds_min <= ds0 <= ds_max (got 1e-07, 1.0, 0.04)
    """

    ds0: float = 0.01
    ds_min: float = 1e-7
    ds_max: float = 0.04
    max_points: int = 1000
    max_calls: int = 200_000
    param_tol: float = 1e-8
    max_multiplier: float = 1e4

    def __post_init__(self):
        _set(self, max_multiplier=real("max_multiplier", self.max_multiplier, 1.0, None,
                                       lo_open=True))
        for name in ("ds0", "ds_min", "ds_max", "param_tol"):
            _set(self, **{name: real(name, getattr(self, name), 0.0, None, lo_open=True)})
        if not self.ds_min <= self.ds0 <= self.ds_max:
            raise ValueError(f"need ds_min <= ds0 <= ds_max (got {self.ds_min}, {self.ds0}, "
                             f"{self.ds_max})")
        _set(self, max_points=integer("max_points", self.max_points, 2),
             max_calls=integer("max_calls", self.max_calls, 1))

    def replace(self, **changes):
        """A copy with some fields changed (validated again)."""
        return replace(self, **changes)


@dataclass
class Codim2Point:
    """A codimension-two point met along a curve (one of :data:`CODIM2_TYPES`).

    Attributes
    ----------
    type : str
    alpha, omega : float
    state : ndarray, shape (2,)
        The orbit's first cycle point there (at the curve's phase).
    multipliers : ndarray of complex, shape (2,)
    index : int
        The curve point it lies after (between points ``index`` and ``index + 1``; at an end,
        the end point).
    located : bool
        Located by Brent's method to ``param_tol`` (False: the nearest curve point).
    detail : str

    Examples
    --------
    >>> import numpy as np
    >>> from rockjit.orbits import Codim2Point
    >>> c = Codim2Point("cusp", 0.65, 3.8, np.zeros(2), np.array([1.0, 0.48]), 12, False)
    >>> c.to_dict()["type"], c.to_dict()["multipliers"]
    ('cusp', [[1.0, 0.0], [0.48, 0.0]])
    """

    type: str
    alpha: float
    omega: float
    state: np.ndarray
    multipliers: np.ndarray
    index: int
    located: bool = True
    detail: str = ""

    def to_dict(self):
        """JSON-ready (multipliers as ``[re, im]`` pairs)."""
        return dict(type=self.type, alpha=float(self.alpha), omega=float(self.omega),
                    state=np.asarray(self.state, float).tolist(),
                    multipliers=[[float(m.real), float(m.imag)] for m in self.multipliers],
                    index=int(self.index), located=bool(self.located), detail=self.detail)
