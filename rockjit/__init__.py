"""rockjit: the harmonically forced rigid rocking block, fast and checked.

A Numba-compiled fixed-step Dormand–Prince integrator with located impacts, rest and overturning
(SPEC.md), checked against a scipy ``solve_ivp`` reference path driven by the same model code.
"""

from .model import Block, delta_e_percent, e_housner, e_mao, thc_from_hb
from .result import Result
from .single import DEFAULT_N, Z0_STUDY, simulate

__all__ = [
    "Block", "DEFAULT_N", "Result", "Z0_STUDY", "delta_e_percent", "e_housner", "e_mao",
    "simulate", "thc_from_hb",
]
__version__ = "0.1.0"
