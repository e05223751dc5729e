"""α sweeps: one run per forcing amplitude from one initial state, the data of a bifurcation
diagram with ``lambda_max`` below it."""

from __future__ import annotations

import numpy as np

from .._engine import kernel
from ..excitation import check_acceleration
from ..result import SweepResult
from ..single import initial_state
from ..validate import boolean, integer
from . import plan as gp
from ..entry import entry_point

__all__ = ["sweep"]


@entry_point(gp.run)
def sweep(block, forcing, alphas, state=None, *, integration=None, classification=None,
          lyapunov=True, n_points=None, n_impact_points=400, execution=None) -> SweepResult:
    """Bifurcation sweep over the forcing amplitude ``alpha``.

    Parameters
    ----------
    block : Block
        The block.
    forcing : Harmonic
        The excitation with its frequency ``omega`` and no ``alpha`` (the sweep's own); its
        phase, or the study's.
    alphas : array_like, shape (n,)
        The amplitudes (:func:`rockjit.alpha_grid` makes an evenly spaced range).
    state : pair of float, optional
        The initial ``(theta0, theta0')`` of every run; default the study's ``z0``.
    integration : Integration, optional
        Periods, steps per period (default here :data:`rockjit.grids.plan.GRID_N`), window, ...
    classification : Classification, optional
        The period test, early stopping, attractor identity, the uncertain-cell test.
    lyapunov : bool
        Compute ``lambda_max`` (it tells chaotic from aperiodic).
    n_points : int, optional
        Stroboscopic samples kept per amplitude (default the window's length).
    n_impact_points : int
        Impact-section points kept per amplitude.
    execution : Execution, optional
        Threads, chunks, Dask, a chunk store, progress (never changes a result).

    Returns
    -------
    SweepResult
        Labels, periods, ``lambda_max``, stroboscopic and impact sections per amplitude, and
        the attractors continued along the amplitudes.

    Examples
    --------
    >>> import rockjit
    >>> from rockjit import Block, Harmonic
    >>> sw = rockjit.sweep(Block(hb=1), Harmonic(omega=1.3), rockjit.alpha_grid((0.5, 0.6), 0.05))
    >>> [str(n) for n in sw.names[sw.label]]
    ['rest', 'rest', 'symmetric']

    Below ``alpha = 1/omega^2 = 0.59`` the forcing cannot lift the block (``alpha omega^2 <
    b/h``): it comes to rest.
    """
    integration, classification, execution = gp.objects(block, integration, classification,
                                                        execution)
    forcing = gp.harmonic(forcing, "omega", "-alpha", why="a sweep")
    alphas = gp.alphas_array(alphas)
    check_acceleration(float(alphas.max()), forcing.omega)
    th, dth, phi, r0, s0 = initial_state(state, forcing, integration)
    first = forcing.replace(alpha=float(alphas[0]))
    par, ipar, cpar, settings = gp.common(block, first, phi, integration, classification)
    n = alphas.size
    lyapunov = boolean("lyapunov", lyapunov)
    n_points = gp.n_points("n_points", n_points, settings["periods"] - settings["window"] + 1)
    n_impact_points = integer("n_impact_points", n_impact_points, 0, 10**6)
    nbytes = gp.grid_memory("alphas", n, settings, execution, n_points, n_impact_points,
                            lyapunov,
                            copies=2 if classification.uncertainty else 1)
    y0s = np.tile(np.array([th, dth, r0, s0]), (n, 1))
    pars = np.tile(par, (n, 1))
    kernel.vary(pars, alpha=alphas)
    settings.update(z0=(th, dth, r0, s0), lyapunov=lyapunov)
    return gp.GridPlan(kind="sweep", block=block, forcing=forcing, y0s=y0s, pars=pars,
                       ipar=ipar, cpar=cpar, tangent=lyapunov, n_pts=n_points,
                       n_imp_pts=n_impact_points, axes=dict(alpha=alphas), shape=(n,),
                       settings=settings, memory_bytes=nbytes,
                       attractors=classification.attractors, phi=phi,
                       uncertainty=classification.uncertainty)
