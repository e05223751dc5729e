"""Seeds of a continuation from a sweep: one per periodic attractor of its cells, the section
the sweep fixes, and the sweep run first when neither seeds nor a sweep are given
(:func:`rockjit.orbits.continue_branches`)."""

from __future__ import annotations

import math

import numpy as np

from ..grids import plan as gp
from ..grids import sweep_grid
from ..settings import Integration
from ..validate import real
from .types import Shooting

__all__ = ["same_system", "seeding_sweep", "sweep_section", "sweep_seeds"]


def sweep_seeds(sw, max_period):
    """One seed per periodic cell of a sweep: ``(alpha, cycle (p, 2), p)``, by period."""
    names = [str(n) for n in sw.names]
    periodic = {names.index(n) for n in ("symmetric", "asymmetric", "multiperiodic")}
    out = []
    for i, a in enumerate(np.asarray(sw.alpha)):
        p = int(sw.period[i])
        if int(sw.label[i]) not in periodic or not 1 <= p <= max_period:
            continue
        pts = np.asarray(sw.strobe[i])
        pts = pts[np.all(np.isfinite(pts), axis=1)]
        if pts.shape[0] < p:
            continue
        out.append((float(a), pts[-p:].copy(), p, None))
    out.sort(key=lambda s: (s[2], s[0]))
    return out


def same_system(sweep, block, forcing):
    """Refuse a sweep of another block or frequency."""
    sb, sf = sweep.block, sweep.forcing
    if not (math.isclose(sb.hb, block.hb) and math.isclose(sf.omega, forcing.omega)
            and sb.law == block.law and math.isclose(sb.restitution, block.restitution)
            and math.isclose(sb.xi, block.xi)):
        raise ValueError(f"sweep must be of the same block (hb={block.hb}, "
                         f"omega={forcing.omega}, law={block.law}, xi={block.xi}); got "
                         f"hb={sb.hb}, omega={sf.omega}, law={sb.law}, xi={sb.xi}")


def seeding_sweep(block, forcing, alpha_range, sweep_step, shooting):
    """The sweep of step ``sweep_step`` over ``alpha_range`` that seeds the branches when
    neither seeds nor a sweep are given, with the shooting runs' ``theta_over`` and
    ``rest_speed``."""
    step = real("sweep_step", sweep_step, 0.0, None, lo_open=True)
    runs = Shooting() if shooting is None else shooting
    return sweep_grid.sweep(block, forcing, gp.alpha_grid(alpha_range, step),
                            integration=Integration(theta_over=runs.theta_over,
                                                    rest_speed=runs.rest_speed))


def sweep_section(sweep, block, forcing, phase, shooting):
    """The section a sweep fixes and the shooting runs' settings it gives when none are:
    ``(phase, shooting)``; a sweep of another system, or a phase given that is not the
    sweep's, is refused."""
    same_system(sweep, block, forcing)
    z = sweep.settings.get("z0")
    sphase = math.atan2(z[2], z[3]) if z is not None else 0.0
    if forcing.phase_given and not math.isclose(phase, sphase, abs_tol=1e-12):
        raise ValueError(f"the forcing's phase must be the sweep's forcing phase "
                         f"{sphase!r} (got {phase!r})")
    if shooting is None:
        shooting = Shooting(theta_over=sweep.settings.get("theta_over", 0.5 * math.pi),
                            rest_speed=sweep.settings.get("rest_speed", 1e-6))
    return sphase, shooting
