"""Global safety over the forcing plane: integrity charts (:mod:`.chart`), the minimal fatal
shock of an attractor (:mod:`.shock`) and the edge state on the safe basin's boundary
(:mod:`.edge`), on the batches of runs of :mod:`.outcome`."""

from .chart import SafetyResult, safety
from .edge import EdgeState, edge_state
from .shock import FatalShock, fatal_shock, fatal_shock_chart, fatal_shocks

__all__ = ["EdgeState", "FatalShock", "SafetyResult", "edge_state", "fatal_shock",
           "fatal_shock_chart", "fatal_shocks", "safety"]
