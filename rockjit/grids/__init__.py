"""Grids of runs: α sweeps (:mod:`.sweep_grid`), basins of attraction (:mod:`.basin_grid`) and
parameter planes (:mod:`.plane_grid`), planned together (:mod:`.plan`) and run chunk by chunk on
the compiled engine, in this process or on a Dask cluster, resumable from a chunk store
(:mod:`.runner`); each cell named by the attractor it reaches (:mod:`.identity`, its cycles
compared by :mod:`.cycles`)."""

from .basin_grid import basin
from .plan import GRID_N, alpha_grid
from .plane_grid import plane
from .sweep_grid import sweep

__all__ = ["GRID_N", "alpha_grid", "basin", "plane", "sweep"]
