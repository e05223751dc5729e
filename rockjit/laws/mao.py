"""Mao et al.'s restitution law: the kinetic energy kept through the impact."""

from __future__ import annotations

import numpy as np

from .base import RestitutionLaw, register

__all__ = ["Mao", "e_mao"]


def e_mao(thc):
    """Mao et al. (2024) coefficient of restitution ``e_M = sqrt(N / D)``.

    ``N = tan(thc)(tan^2(thc) - 3) + 3 tan^4(thc)(pi/2 - thc) + 3 thc`` and
    ``D = 4 tan(thc) sec^2(thc)``: the kinetic energy kept through the impact
    (docs/theory/impacts.md).

    Parameters
    ----------
    thc : float or array_like
        Angle of the block's diagonal from the ground, radians (:func:`rockjit.thc_from_hb`).

    Returns
    -------
    float or ndarray
        ``e_M``.

    See Also
    --------
    e_housner : Housner's law.

    Examples
    --------
    >>> import rockjit
    >>> round(float(rockjit.e_mao(rockjit.thc_from_hb(1.0))), 3)
    0.582
    >>> round(float(rockjit.e_mao(rockjit.thc_from_hb(2.0))), 3)
    0.83
    """
    t = np.tan(thc)
    num = t * (t * t - 3.0) + 3.0 * t**4 * (0.5 * np.pi - thc) + 3.0 * thc
    den = 4.0 * t / np.cos(thc) ** 2
    return np.sqrt(num / den)


class Mao(RestitutionLaw):
    """Mao et al.'s law (2024): ``e = e_M(thc)``, one coefficient per block
    (:func:`rockjit.e_mao`).

    Examples
    --------
    >>> from rockjit import Block
    >>> round(Block(hb=2, law="mao").restitution, 3)
    0.83
    """

    name = "mao"
    order = 1
    label = "Mao et al."
    colour = "#D55E00"  # Okabe and Ito's vermillion
    line = dict(color="k", ls=(0, (5, 2)), marker="s")

    def coefficient(self, thc, e=None):
        """The block's coefficient (see :meth:`RestitutionLaw.coefficient`)."""
        return float(e_mao(thc))


register(Mao())
