"""The documented range of every numeric option of the command line, in one table.

``RANGES`` maps an option to ``(kind, lo, hi)``: ``kind`` is ``"real"`` or ``"int"``, ``lo`` and
``hi`` the ends of the range its documentation states (``None``: no bound on that side), read
from the library's own constants where it has them; ``RANGES_BY_COMMAND`` holds the
``(command, option)`` pairs whose range differs. The options are checked by the library's
objects (a value outside is a ``ValueError`` naming the option and its range); this table says
what those ranges are, and the command line's edge test tries both ends of each and the numbers
just outside them. Every option of the parser that takes numbers must be in it.
"""

from __future__ import annotations

import math

__all__ = ["RANGES", "RANGES_BY_COMMAND", "range_of"]


def _tables():
    """``(RANGES, RANGES_BY_COMMAND)``, from the library's constants (a moved bound moves the
    table)."""
    from ..excitation import ALPHA_MAX, OMEGA_RANGE
    from ..plugs.pulse import AMPLITUDE_MAX, RATIO_RANGE
    from ..ground.records import SIZE_RANGE
    from ..ground.settings import TIME_MAX
    from ..integrity.chart import MAX_LATTICE, MAX_SIDE
    from ..model import HB_RANGE, XI_MAX
    from ..settings import MAX_IMPACTS, MAX_N, MAX_PERIODS, REST_SPEED_RANGE
    half_pi = 0.5 * math.pi
    common = {
        "--hb": ("real", *HB_RANGE), "--e": ("real", 0.0, 1.0), "--xi": ("real", 0.0, XI_MAX),
        "--alpha": ("real", 0.0, ALPHA_MAX), "--omega": ("real", *OMEGA_RANGE),
        "--theta0": ("real", -half_pi, half_pi), "--dtheta0": ("real", -1e6, 1e6),
        "--phase": ("real", None, None), "--r0": ("real", -1e3, 1e3),
        "--s0": ("real", -1e3, 1e3), "--periods": ("int", 1, MAX_PERIODS),
        "--n-steps": ("int", 8, MAX_N), "--max-impacts": ("int", 1, MAX_IMPACTS),
        "--threads": ("int", 1, _max_threads()), "--rtol": ("real", 0.0, 1.0),
        "--atol": ("real", 0.0, None), "--rest-speed": ("real", *REST_SPEED_RANGE),
        "--max-points": ("int", 2, None), "--alpha-range": ("real", 0.0, ALPHA_MAX),
        "--alpha-step": ("real", 0.0, None), "--grid": ("int", 1, 10**9),
        "--theta-range": ("real", -half_pi, half_pi), "--dtheta-range": ("real", -1e6, 1e6),
        "--omega-range": ("real", *OMEGA_RANGE), "--uncertainty": ("real", 1e-15, 0.5),
        "--scheduler-timeout": ("real", 0.0, 1e6), "--max-period": ("int", 1, 256),
        "--seed-omegas": ("real", *OMEGA_RANGE), "--ensemble": ("int", 2, 10**6),
        "--spread": ("real", 0.0, 1e-2), "--seed": ("int", 0, 2**63 - 1),
        "--ratio-range": ("real", *RATIO_RANGE), "--amplitude-range": ("real", 0, AMPLITUDE_MAX),
        "--tol": ("real", 1e-12, 0.1), "--free-time": ("real", 0.0, TIME_MAX),
        "--size": ("real", *SIZE_RANGE), "--intensities": ("real", 0.0, 1e6),
        "--hb-values": ("real", 1 / math.sqrt(2), HB_RANGE[1]),
        "--hb-max": ("real", 1 / math.sqrt(2), 100.0), "--zoom": ("real", 0.5, 1.0),
        "--zoom-step": ("real", 0.0, 1.0), "--erosion-step": ("real", 0.0, 1.0),
        "--erosion-grid": ("int", 2, 10**5), "--lattice": ("int", 2, MAX_LATTICE),
        "--levels": ("real", 0.0, 1.0), "--port": ("int", 0, 65535),
    }
    by_command = {("chart", "--max-period"): ("int", 1, 16),
                  ("plane", "--grid"): ("int", 1, 10**18), ("chart", "--grid"): ("int", 1, 10**18),
                  ("spectrum", "--grid"): ("int", 1, 10**4), ("paper", "--grid"): ("int", 2, 10**5),
                  ("paper", "--alpha-step"): ("real", 0.0, 1.0),
                  ("safety", "--grid"): ("int", 1, MAX_SIDE)}
    return common, by_command


def _max_threads():
    import numba
    return numba.config.NUMBA_NUM_THREADS


RANGES, RANGES_BY_COMMAND = _tables()


def range_of(command, option):
    """``(kind, lo, hi)`` of ``option`` in ``command``, or ``None`` where it has none listed."""
    return RANGES_BY_COMMAND.get((command, option), RANGES.get(option))
