"""Parameter planes: one run per forcing ``(alpha, omega)`` of a grid, from one or more initial
states, the brute-force chart of behaviours over the forcing plane."""

from __future__ import annotations

import numpy as np

from .._engine import kernel
from ..result import PlaneResult
from ..single import initial_state
from ..validate import boolean, real_array
from . import plan as gp
from ..entry import entry_point

__all__ = ["plane"]


def _states(state):
    """``state`` as rows ``(theta0, theta0')``; ``None`` stays ``None`` (the study's)."""
    if state is None:
        return [None]
    z = np.atleast_2d(real_array("state", state, "(theta0, theta0') or m rows of them"))
    if z.ndim != 2 or z.shape[1] != 2 or z.shape[0] == 0:
        raise ValueError(f"state must be (theta0, theta0') or m rows of them "
                         f"(got shape {z.shape})")
    return list(z)


@entry_point(gp.run)
def plane(block, alpha_range, omega_range, *, grid=(50, 50), state=None, forcing=None,
          integration=None, classification=None, lyapunov=True,
          execution=None) -> PlaneResult:
    """Behaviour and ``lambda_max`` at each ``(alpha, omega)`` of a grid (a rocking chart).

    Parameters
    ----------
    block : Block
        The block.
    alpha_range, omega_range : pair of float
        Ranges, ends included: ``0 <= alpha0 <= alpha1`` and ``0 < omega0 <= omega1``.
    grid : pair of int
        Points ``(NA, NW)`` along alpha and omega.
    state : array_like, shape (2,) or (m, 2), optional
        Initial state(s) ``(theta0, theta0')``; default the study's ``z0``.
    forcing : Harmonic, optional
        The forcing's phase (``Harmonic(phase=...)``, no ``alpha`` or ``omega``: the plane
        sweeps both); default the study's for the study's state, else ``(r0, s0) = (0, 1)``.
    integration, classification, lyapunov, execution :
        As in :func:`rockjit.sweep`.

    Returns
    -------
    PlaneResult
        ``label[m, i, j]`` of initial state ``m``, ``alpha[i]``, ``omega[j]``, with periods,
        ``lambda_max`` and the attractors continued across the plane.

    Examples
    --------
    >>> import rockjit
    >>> from rockjit import Block
    >>> pl = rockjit.plane(Block(hb=1), (0.5, 0.6), (1.2, 1.3), grid=(2, 2))
    >>> pl.label.shape
    (1, 2, 2)
    """
    integration, classification, execution = gp.objects(block, integration, classification,
                                                        execution)
    forcing = gp.harmonic(forcing, "-alpha", "-omega", why="a plane")
    (a0, a1, na), (w0, w1, nw) = gp.forcing_axes(alpha_range, omega_range, grid, gp.MAX_CELLS)
    starts = [initial_state(z, forcing, integration) for z in _states(state)]
    z = np.array([s[:2] + s[3:] for s in starts])
    phis = [s[2] for s in starts]
    M = z.shape[0]
    first = forcing.replace(alpha=a0, omega=w0)
    par, ipar, cpar, settings = gp.common(block, first, phis[0], integration, classification)
    lyapunov = boolean("lyapunov", lyapunov)
    # cycle points: the attractors' identity, and each periodic cell's exact exponent
    n_pts = settings["pmax"] if classification.attractors or lyapunov else 0
    nbytes = gp.grid_memory(f"grid = ({na}, {nw})", float(M) * na * nw, settings, execution,
                            n_pts, lyapunov=lyapunov,
                            copies=2 if classification.uncertainty else 1)
    alphas = np.linspace(a0, a1, na)
    omegas = np.linspace(w0, w1, nw)
    Z, A, W = np.meshgrid(np.arange(M), alphas, omegas, indexing="ij")
    n = Z.size
    pars = np.tile(par, (n, 1))
    phi = np.asarray(phis)[Z.ravel()]
    kernel.vary(pars, alpha=A.ravel(), omega=W.ravel(), n_steps=settings["n_steps"], phi=phi)
    zz = z[Z.ravel()]
    y0s = np.stack([zz[:, 0], zz[:, 1], np.sin(phi), np.cos(phi)], 1)
    settings.update(lyapunov=lyapunov)
    return gp.GridPlan(kind="plane", block=block, forcing=forcing, y0s=y0s, pars=pars,
                       ipar=ipar, cpar=cpar, tangent=lyapunov, n_pts=n_pts, n_imp_pts=0,
                       axes=dict(alpha=alphas, omega=omegas, z0=z), shape=(M, na, nw),
                       settings=settings, memory_bytes=nbytes,
                       attractors=classification.attractors,
                       uncertainty=classification.uncertainty)
