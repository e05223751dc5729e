"""The constant restitution law: the coefficient is a number the block gives."""

from __future__ import annotations

from .base import RestitutionLaw, register

__all__ = ["Constant"]


class Constant(RestitutionLaw):
    """``e`` given with the block (``Block(hb, e=0.5)``), the same at every impact.

    Examples
    --------
    >>> from rockjit import Block
    >>> b = Block(hb=2, e=0.5)
    >>> b.law, b.restitution
    ('constant', 0.5)
    """

    name = "constant"
    order = 2
    label = "constant $e$"
    colour = "#009E73"  # Okabe and Ito's bluish green
    line = dict(color="k", ls=":", marker="^")
    needs_e = True

    def coefficient(self, thc, e=None):
        """The block's coefficient (see :meth:`RestitutionLaw.coefficient`)."""
        return e


register(Constant())
