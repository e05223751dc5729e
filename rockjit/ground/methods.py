"""The integration methods of the transient runs: the compiled path or which scipy path.

Kept apart from :mod:`rockjit.ground.plan`, which :mod:`rockjit.single` imports: the method
objects live in :mod:`rockjit.single`, and this module is the one place of the ground-motion
package that imports it.
"""

from __future__ import annotations

__all__ = ["check_method", "transient_scipy"]


def transient_scipy():
    """The scipy path the spectra and fragility curves use by default: DOP853 at
    ``rtol = 1e-10, atol = 1e-12`` (an explicit method suits the non-stiff block; the tight
    tolerances keep the bisections' outcomes a property of the model, not of the solver)."""
    from ..single import Scipy
    return Scipy("DOP853", rtol=1e-10, atol=1e-12)


def check_method(method):
    """``"rockjit"`` (the compiled path), or the :class:`rockjit.Scipy` of ``method``
    (``"scipy"``, ``"scipy:<M>"`` or a Scipy)."""
    from ..single import _method
    return _method(method)
