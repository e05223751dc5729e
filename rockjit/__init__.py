"""rockjit: the forced rigid rocking block (Housner's model), fast and checked.

A Numba-compiled fixed-step Dormand–Prince integrator with located impacts, rest and overturning,
checked against a scipy ``solve_ivp`` reference path driven by the same model code. The public
API is a handful of small validated objects (the block, the excitation, the settings) and the
entry points that take them; docs/ holds the theory and the guides.

The names below load on first use (numpy, numba and the compiled kernels are not imported by
``import rockjit`` itself), so that the command line can handle Ctrl-C from its first instant.
"""

import importlib

#: Where each public name lives.
_HOMES = {
    "explore": "rockjit.explorer",
    "erosion": "rockjit.basins.erosion",
    "safety": "rockjit.integrity", "SafetyResult": "rockjit.integrity",
    "fatal_shock": "rockjit.integrity", "edge_state": "rockjit.integrity",
    "fate": "rockjit.basins.fate",
    "Harmonic": "rockjit.excitation",
    "Pulse": "rockjit.ground", "Record": "rockjit.ground", "HarmonicSum": "rockjit.ground", "Transient": "rockjit.ground",
    "fragility": "rockjit.ground", "spectrum": "rockjit.ground",
    "chart": "rockjit.orbits.plane_chart", "ChartCurves": "rockjit.orbits.plane_chart",
    "alpha_grid": "rockjit.grids", "basin": "rockjit.grids", "plane": "rockjit.grids",
    "sweep": "rockjit.grids",
    "Block": "rockjit.model", "delta_e_percent": "rockjit.model", "e_housner": "rockjit.model",
    "e_mao": "rockjit.model", "thc_from_hb": "rockjit.model",
    "BEHAVIOURS": "rockjit.result", "BasinResult": "rockjit.result",
    "PlaneResult": "rockjit.result", "Result": "rockjit.result", "SweepResult": "rockjit.result",
    "Classification": "rockjit.settings", "Execution": "rockjit.settings",
    "Integration": "rockjit.settings", "Lattice": "rockjit.settings",
    "DEFAULT_N": "rockjit.single", "Z0_STUDY": "rockjit.single", "Scipy": "rockjit.single",
    "classify_result": "rockjit.single", "simulate": "rockjit.single",
}

__all__ = sorted(_HOMES)
__version__ = "0.2.0.dev0"


def __getattr__(name):
    home = _HOMES.get(name)
    if home is None:
        raise AttributeError(f"module 'rockjit' has no attribute {name!r}")
    value = getattr(importlib.import_module(home), name)
    globals()[name] = value
    return value


def __dir__():
    return sorted(set(globals()) | set(__all__))
