"""Housner's restitution law: angular momentum about the new corner is conserved."""

from __future__ import annotations

import math

import numpy as np

from .base import RestitutionLaw, register

__all__ = ["HB_MIN_HOUSNER", "Housner", "e_housner"]

#: The least slenderness with ``e_H >= 0``.
HB_MIN_HOUSNER = 1.0 / math.sqrt(2.0)


def e_housner(thc):
    """Housner's coefficient of restitution ``e_H = 1 - 1.5 cos^2(thc)``.

    Conserves angular momentum about the new corner (Housner 1963). Negative for
    ``thc < arctan(1/sqrt(2))``, where the law has no physical meaning.

    Parameters
    ----------
    thc : float or array_like
        Angle of the block's diagonal from the ground, radians (:func:`rockjit.thc_from_hb`).

    Returns
    -------
    float or ndarray
        ``e_H``.

    See Also
    --------
    e_mao : Mao et al.'s law.

    Examples
    --------
    >>> import rockjit
    >>> round(float(rockjit.e_housner(rockjit.thc_from_hb(1.0))), 12)
    0.25
    >>> round(float(rockjit.e_housner(rockjit.thc_from_hb(2.0))), 12)
    0.7
    """
    return 1.0 - 1.5 * np.cos(thc) ** 2


def check_housner(hb, name="the Housner law"):
    """Refuse ``hb < 1/sqrt(2)``, where ``e_H`` would be negative."""
    if hb < HB_MIN_HOUSNER:
        raise ValueError(f"hb must be >= 1/sqrt(2) = {HB_MIN_HOUSNER:.6f} for {name} "
                         f"(got {hb}); e_H would be negative")


class Housner(RestitutionLaw):
    """Housner's law (1963): ``e = e_H(thc)``, one coefficient per block
    (:func:`rockjit.e_housner`).

    Examples
    --------
    >>> from rockjit import Block
    >>> round(Block(hb=2, law="housner").restitution, 12)
    0.7
    """

    name = "housner"
    order = 0
    label = "Housner"
    colour = "#0072B2"  # Okabe and Ito's blue
    line = dict(color="k", ls="-", marker="o")

    def coefficient(self, thc, e=None):
        """The block's coefficient (see :meth:`RestitutionLaw.coefficient`)."""
        return float(e_housner(thc))

    def check(self, hb):
        """Refuse ``hb < 1/sqrt(2)``, where ``e_H`` would be negative."""
        check_housner(hb)


register(Housner())
