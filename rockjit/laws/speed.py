"""A restitution law that depends on the impact: Housner's coefficient, softened at fast impacts.

Impacts lose a larger share of their speed the faster they are, as contact mechanics finds for
impacts that yield: the coefficient falls from its slow-impact value as the approach speed
grows. Here the slow-impact value is Housner's ``e_H`` and the fall is hyperbolic,

    e(v) = e_H / (1 + v / v_half),    v = |theta'(-)|,

so that ``e`` is ``e_H`` at a grazing impact, half of it at ``v = v_half`` (in the model's
units of angular velocity) and tends to zero for very fast ones. The integrator calls
:func:`speed_coefficient` at every impact, with its derivative for the saltation matrix.
"""

from __future__ import annotations

from dataclasses import dataclass

from .._jit import jit
from ..validate import real
from .base import RestitutionLaw, register
from .housner import check_housner, e_housner

__all__ = ["SpeedDependent", "V_HALF_RANGE", "speed_coefficient"]

#: Allowed range of ``v_half``.
V_HALF_RANGE = (1e-6, 1e6)


@jit(nrt=False)
def speed_coefficient(speed, e, v_half):
    """``(e(v), d(e(v) v)/dv)`` at approach speed ``v = speed >= 0``, with ``e`` the
    slow-impact coefficient: ``e(v) = e / (1 + v/v_half)`` and ``d(e(v) v)/dv = e / (1 +
    v/v_half)^2``."""
    q = 1.0 / (1.0 + speed / v_half)
    return e * q, e * q * q


@dataclass(frozen=True)
class SpeedDependent(RestitutionLaw):
    """Housner's coefficient softened at fast impacts: ``e(v) = e_H / (1 + v / v_half)``.

    Parameters
    ----------
    v_half : float
        The approach speed ``|theta'(-)|`` at which the coefficient is half of Housner's,
        in ``[1e-6, 1e6]``; default 1.

    Examples
    --------
    >>> from rockjit.laws import SpeedDependent
    >>> law = SpeedDependent(v_half=0.5)
    >>> law.at_impact(0.5, 0.25), law.at_impact(0.0, 0.25)
    (0.125, 0.25)
    """

    v_half: float = 1.0
    name = "speed"
    label = "Housner, speed-softened"
    colour = "#CC79A7"  # Okabe and Ito's reddish purple
    line = dict(color="k", ls="-.", marker="D")
    order = 10
    impact = staticmethod(speed_coefficient)

    def __post_init__(self):
        object.__setattr__(self, "v_half", real("v_half", self.v_half, *V_HALF_RANGE))

    @property
    def shape(self):
        """``v_half``, the compiled impact function's parameter."""
        return self.v_half

    def coefficient(self, thc, e=None):
        """Housner's ``e_H``: the coefficient of a slow impact."""
        return float(e_housner(thc))

    def check(self, hb):
        """Refuse ``hb < 1/sqrt(2)``, where ``e_H`` would be negative."""
        check_housner(hb, "the speed-softened Housner law")

    def describe(self):
        """The law and its ``v_half``."""
        return f"{self.label} (v_half = {self.v_half:g})"


register(SpeedDependent())
