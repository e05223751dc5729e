"""rockjit: the forced rigid rocking block (Housner's model), fast and checked.

A Numba-compiled fixed-step Dormand–Prince integrator with located impacts, rest and overturning,
checked against a scipy ``solve_ivp`` reference path driven by the same model code. The public
API is a handful of small validated objects (the block, the excitation, the settings) and the
entry points that take them; docs/ holds the theory and the guides.
"""

from .basins.erosion import erosion
from .basins.fate import fate
from .excitation import Harmonic
from .grids import alpha_grid, basin, plane, sweep
from .ground import Pulse, Record, Transient, fragility, spectrum
from .model import Block, delta_e_percent, e_housner, e_mao, thc_from_hb
from .result import BEHAVIOURS, BasinResult, PlaneResult, Result, SweepResult
from .settings import Classification, Execution, Integration, Lattice
from .single import DEFAULT_N, Z0_STUDY, Scipy, classify_result, simulate

__all__ = [
    "BEHAVIOURS", "BasinResult", "Block", "Classification", "DEFAULT_N", "Execution",
    "Harmonic", "Integration", "Lattice", "PlaneResult", "Pulse", "Record", "Result", "Scipy",
    "SweepResult", "Transient", "Z0_STUDY", "alpha_grid", "basin", "classify_result",
    "delta_e_percent", "e_housner", "e_mao", "erosion", "fate", "fragility", "plane",
    "simulate", "spectrum", "sweep", "thc_from_hb",
]
__version__ = "0.2.0.dev0"
