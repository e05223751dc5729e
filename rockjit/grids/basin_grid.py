"""Basins of attraction: one run per initial state ``(theta0, theta0')`` of a lattice, at one
forcing, each cell labelled by its behaviour and the attractor it reaches."""

from __future__ import annotations

import numpy as np

from ..result import BasinResult
from ..settings import Lattice
from ..validate import boolean
from . import plan as gp
from ..entry import entry_point

__all__ = ["basin", "lattice"]


def lattice(grid):
    """A :class:`rockjit.Lattice` from ``grid``: a lattice, or its number of points per side."""
    return grid if isinstance(grid, Lattice) else Lattice(grid)


@entry_point(gp.run)
def basin(block, forcing, grid=100, *, integration=None, classification=None, lyapunov=False,
          execution=None) -> BasinResult:
    """Basin of attraction over ``(theta0, theta0')`` on a ``grid x grid`` lattice.

    Parameters
    ----------
    block : Block
        The block.
    forcing : Harmonic
        The excitation with its ``alpha`` and ``omega``; its phase is every cell's (default
        ``(r0, s0) = (0, 1)``, the study's basins').
    grid : int or Lattice
        Points per side over ``theta0, theta0'`` in ``[-1, 1]``, or a :class:`rockjit.Lattice`
        with other ranges; default 100.
    integration, classification, execution :
        As in :func:`rockjit.sweep`.
    lyapunov : bool
        Compute each cell's ``lambda_max`` too.

    Returns
    -------
    BasinResult
        ``label[i, j]``, ``period[i, j]`` and ``attractor[i, j]`` of ``theta0[i]``,
        ``dtheta0[j]``; the attractors; ``measures()`` gives basin entropy and integrity.

    Examples
    --------
    >>> import rockjit
    >>> from rockjit import Block, Harmonic
    >>> b = rockjit.basin(Block(hb=1), Harmonic(alpha=0.66, omega=1.3), grid=20)
    >>> b.label.shape, round(sum(b.fractions().values()))
    ((20, 20), 100)
    """
    integration, classification, execution = gp.objects(block, integration, classification,
                                                        execution)
    forcing = gp.harmonic(forcing, "alpha", "omega", why="a basin")
    lat = lattice(grid)
    th_rng = lat.theta_range
    if max(abs(th_rng[0]), abs(th_rng[1])) >= integration.theta_over:
        raise ValueError(f"theta_range must lie inside (-theta_over, theta_over) = "
                         f"(-{integration.theta_over:.6g}, {integration.theta_over:.6g}) "
                         f"(got {th_rng})")
    phi, r0, s0 = forcing.start()
    par, ipar, cpar, settings = gp.common(block, forcing, phi, integration, classification)
    lyapunov = boolean("lyapunov", lyapunov)
    # cycle points: the attractors' identity, and each periodic cell's exact exponent
    n_pts = settings["pmax"] if classification.attractors or lyapunov else 0
    nbytes = gp.grid_memory(f"grid = {lat.grid}", float(lat.grid) ** 2, settings, execution,
                            n_pts, lyapunov=lyapunov,
                            copies=2 if classification.uncertainty else 1)
    th, dth = lat.axes()
    TH, DTH = np.meshgrid(th, dth, indexing="ij")
    y0s = np.stack([TH.ravel(), DTH.ravel(), np.full(TH.size, r0), np.full(TH.size, s0)], 1)
    pars = np.tile(par, (TH.size, 1))
    settings.update(r0=r0, s0=s0, phase=phi, lyapunov=lyapunov, grid=lat.grid,
                    theta_range=list(lat.theta_range), dtheta_range=list(lat.dtheta_range))
    return gp.GridPlan(kind="basin", block=block, forcing=forcing, y0s=y0s, pars=pars,
                       ipar=ipar, cpar=cpar, tangent=lyapunov, n_pts=n_pts, n_imp_pts=0,
                       axes=dict(theta0=th, dtheta0=dth), shape=(lat.grid, lat.grid),
                       settings=settings, memory_bytes=nbytes,
                       attractors=classification.attractors, phi=phi,
                       uncertainty=classification.uncertainty)
