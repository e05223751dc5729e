"""Which initial states overturn: batches of runs at one forcing, from states at its phase.

The minimal fatal shock (:mod:`.shock`) and the edge state (:mod:`.edge`) ask one question of
many initial states ``(theta0, theta0')`` at once: does the block overturn within the run's
periods? :class:`Outcomes` plans the forcing's runs once (the same packed settings as a basin's
cells: :func:`rockjit.grids.plan.common`, early stopping on) and answers for any batch of states
through the grid runner, so that a batch runs on every thread like a basin's cells.
"""

from __future__ import annotations

import numpy as np

from .._engine import kernel
from ..grids import plan as gp
from ..grids import runner
from ..result import OVERTURN
from ..settings import Execution

__all__ = ["Outcomes"]


class Outcomes:
    """The fate of initial states at one forcing: :meth:`fatal` says which overturn.

    Parameters
    ----------
    block : Block
    forcing : Harmonic
        With ``alpha`` and ``omega``; its phase is every state's.
    integration, classification : optional
        As in :func:`rockjit.basin` (``periods`` is the horizon of a run).
    threads : int, optional
        Threads of the compiled runs (default numba's).
    """

    def __init__(self, block, forcing, integration=None, classification=None, threads=None):
        integration, classification, _ = gp.objects(block, integration, classification, None)
        self.forcing = gp.harmonic(forcing, "alpha", "omega", why="a fatal-shock search")
        self.block, self.integration = block, integration
        phi, self.r0, self.s0 = self.forcing.start()
        self.par, self.ipar, self.cpar, self.settings = gp.common(
            block, self.forcing, phi, integration, classification)
        self.execution = Execution(threads=threads, progress=False)
        self.runs = 0

    def fatal(self, states):
        """``bool`` array: which rows ``(theta0, theta0')`` of ``states`` overturn (states at
        or beyond ``theta_over`` count as overturned without a run)."""
        z = np.atleast_2d(np.asarray(states, dtype=float))
        out = np.ones(z.shape[0], dtype=bool)
        inside = np.abs(z[:, 0]) < self.integration.theta_over
        if inside.any():
            zi = z[inside]
            y0s = np.column_stack([zi[:, 0], zi[:, 1], np.full(len(zi), self.r0),
                                   np.full(len(zi), self.s0)])
            pars = np.tile(self.par, (len(zi), 1))
            res = runner.run_grid(y0s, pars, self.ipar, self.cpar, tangent=False, n_pts=0,
                                  n_imp_pts=0, label="", execution=self.execution)
            out[inside] = kernel.grid_results(res)["label"] == OVERTURN
            self.runs += len(zi)
        return out
