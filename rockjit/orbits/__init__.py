"""Periodic orbits of the stroboscopic map: shooting, continuation and located bifurcations.

A period-``p`` orbit of the forced block is a fixed point of ``P^p``, ``P`` the stroboscopic map
``(theta, theta')(kT) -> (theta, theta')((k+1)T)`` at a fixed forcing phase (docs/theory/global-dynamics.md). This
package finds such orbits by Newton's method (shooting), follows them as a forcing parameter
(``alpha`` or ``omega``) varies by pseudo-arclength continuation, and locates where they
bifurcate. It is built on the public :func:`rockjit.simulate` only.

What lives where
----------------
:mod:`.types`
    The settings (:class:`Shooting`, :class:`ContinuationSettings`), the results
    (:class:`PeriodicOrbit`, :class:`Branch`, :class:`Bifurcation`, :class:`Continuation`), the
    refusal :class:`OrbitRefused` with its :data:`REASONS`, and :data:`BIFURCATION_TYPES`.
:mod:`.shooting`
    The flow (every run of the package, one call of :func:`rockjit.simulate`), the Newton
    solver on the full and the half map, what a converged run says about its orbit, and
    :func:`periodic_orbit`.
:mod:`.bifurcations`
    Detection between two branch points and location: fold, symmetry breaking, period
    doubling, Neimark–Sacker (test functions, Brent's method) and grazing, overturning and
    rest (bisection).
:mod:`.grazing`
    The grazing condition: the depth of an excursion's turning point near ``theta = 0`` (or
    ``theta_over``), refined by quintic Hermite interpolation, and how far a run that crossed
    went beyond.
:mod:`.arclength`
    Pseudo-arclength continuation and branch switching: :func:`continuation`,
    :func:`continue_branches` (the branches of a sweep's periodic attractors) and the entry
    point :func:`orbits_of_sweep` (the sweep and its branches; its ``.plan`` validates, and
    :func:`rockjit.orbits.arclength.run` executes a plan).
:mod:`.sweep_seeds`
    The seeds a sweep gives a continuation (one per periodic attractor), the section the
    sweep fixes, and the sweep run first when neither seeds nor a sweep are given.
:mod:`.curve_types`
    What the curves in the forcing plane ``(alpha, omega)`` are: :data:`CURVE_TYPES`, the
    codimension-two points met (:class:`Codim2Point`, :data:`CODIM2_TYPES`), the ends
    (:data:`CURVE_ENDS`) and :class:`CurveSettings`.
:mod:`.extended`
    The extended system of each curve type (the fixed-point equations and one defining
    condition, unknowns ``(theta, theta', alpha, omega)``) and its Jacobian.
:mod:`.tracer`
    Pseudo-arclength continuation of an extended system: the corrector, the march, the
    codimension-two points met and the ends.
:mod:`.bifurcation_curve`
    The curve followed, :class:`BifurcationCurve`.
:mod:`.curves`
    Codimension-one curves in the forcing plane: a located fold, symmetry breaking, period
    doubling or grazing followed in both forcing parameters (:func:`continue_curve`),
    :func:`relocate` to check a point against the one-parameter location.
:mod:`.plane_chart`
    The entry point :func:`chart`: the brute-force chart of behaviours over ``(alpha, omega)``
    and every curve seeded from the bifurcations located on a few ``omega`` lines of it (its
    ``.plan`` validates, :func:`rockjit.orbits.plane_chart.run` executes a plan).

The imports go one way: ``types`` <- ``shooting`` <- ``grazing`` <- ``bifurcations`` <-
``arclength`` <- ``curve_types`` <- ``extended`` <- ``tracer`` <- ``bifurcation_curve`` <-
``curves`` <- ``plane_chart``. Cycles are compared with
``rockjit.grids.cycles.cycle_distance``, as the attractors of the grids.

Examples
--------
>>> from rockjit import Block, Harmonic
>>> from rockjit.orbits import periodic_orbit
>>> periodic_orbit(Block(hb=1), Harmonic(alpha=0.8, omega=1.3), (-0.3, -0.3)).impacts
2

Notes
-----
Saltation and grazing: di Bernardo, Budd, Champneys, Kowalczyk (2008), *Piecewise-smooth
Dynamical Systems*, Springer, ch. 2 and 6 (grazing of impacting orbits). Continuation and test
functions: Seydel (2010), *Practical Bifurcation and Stability Analysis*, 3rd ed., Springer;
Kuznetsov (2004), *Elements of Applied Bifurcation Theory*, 3rd ed., Springer; Doedel, Keller,
Kernévez (1991), "Numerical analysis and control of bifurcation problems", Int. J. Bifurcation
and Chaos 1(3), 493–520 and 1(4), 745–772; Keller (1977), "Numerical solution of bifurcation
and nonlinear eigenvalue problems", in *Applications of Bifurcation Theory*, Academic Press.
"""

from .arclength import continuation, continue_branches, orbits_of_sweep
from .bifurcation_curve import BifurcationCurve
from .curve_types import CODIM2_TYPES, CURVE_ENDS, CURVE_TYPES, Codim2Point, CurveSettings
from .curves import continue_curve, relocate
from .plane_chart import ChartCurves, ChartResult, chart
from .shooting import N_ORBIT, periodic_orbit
from .types import (BIFURCATION_TYPES, REASONS, Bifurcation, Branch, Continuation,
                    ContinuationSettings, OrbitRefused, PeriodicOrbit, Shooting)

__all__ = ["BIFURCATION_TYPES", "CODIM2_TYPES", "CURVE_ENDS", "CURVE_TYPES", "N_ORBIT",
           "REASONS", "Bifurcation", "BifurcationCurve", "Branch", "ChartResult",
           "ChartCurves", "Codim2Point", "Continuation", "ContinuationSettings", "CurveSettings",
           "OrbitRefused", "PeriodicOrbit", "Shooting", "chart", "continuation",
           "continue_branches", "continue_curve", "orbits_of_sweep", "periodic_orbit",
           "relocate"]
