"""The study's single runs (figures 2 to 4): the exponent a run reports as the grids do (the
Floquet exponent of the orbit it settled on), the arrays its time-series figure draws, and the
words that say what each run does."""

from __future__ import annotations

import math

from ..excitation import Harmonic
from .settings import FIRST_PERIODS, LAST_PERIODS

__all__ = ["drawn_arrays", "exponents", "floquet_of_run", "laws_captions", "outcome_words",
           "same_orbit"]


def _phase_of(res):
    """The forcing phase of a run (its stroboscopic samples carry ``r, s`` at ``t = 0``)."""
    return math.atan2(float(res.strobe[0, 2]), float(res.strobe[0, 3]))


def floquet_of_run(res, behaviour):
    """The Floquet exponent ``ln|mu1| / (pT)`` of the periodic orbit a run settled on (its
    last cycle point), or ``nan`` when it did not settle on one."""
    from ..grids.identity import floquet
    name, p = behaviour
    if name not in ("symmetric", "asymmetric", "multiperiodic") or p < 1 or \
            res.strobe.shape[0] <= p:
        return math.nan
    f = res.forcing
    _, lam = floquet(res.block, Harmonic(alpha=f.alpha, omega=f.omega), _phase_of(res),
                     res.integration, res.n_steps, res.strobe[-1, :2], p)
    return float(lam[0])


def exponents(res, behaviour, exact=None):
    """A run's ``lambda_max`` as the grids report it: the Floquet exponent of the periodic orbit
    it settled on (exact), else the window's estimate, kept as ``lambda_window``."""
    exact = floquet_of_run(res, behaviour) if exact is None else exact
    return dict(lambda_max=exact if math.isfinite(exact) or exact == -math.inf
                else res.lambda_max, lambda_window=res.lambda_max)


def drawn_arrays(res, prefix, first=FIRST_PERIODS, last=LAST_PERIODS):
    """The arrays a time-series figure draws of one run: ``theta(t)`` over its first and last
    periods and the phase portrait's stretch, impacts inserted (``t, theta, dtheta``), and its
    stroboscopic samples."""
    from ..plotting.timeseries import with_impacts
    T = res.period
    t_w = res.window[0] if res.window is not None else 0.8 * res.periods * T
    out = {}
    for what, (t0, t1) in (("first", (0.0, first * T)), ("last", (res.t - last * T, res.t)),
                           ("phase", (t_w if res.t > t_w + T else 0.0, res.t))):
        t, th, dth = with_impacts(res, t0, t1)
        out.update({f"{prefix}{what}_t": t, f"{prefix}{what}_theta": th,
                    f"{prefix}{what}_dtheta": dth})
    out[f"{prefix}strobe"] = res.strobe[:, :2]
    out[f"{prefix}impacts"] = res.impacts
    return out


def outcome_words(probabilities):
    """A fate's outcome probabilities in words: ``"overturn 91%, period-7 9%"``."""
    from ..plotting.fates import _outcome_names
    words, _ = _outcome_names(list(probabilities))
    return ", ".join(f"{words[k]} {v:.0%}" for k, v in probabilities.items())


def same_orbit(a, b, behaviour_a, behaviour_b, tol=1e-4):
    """Two runs of one system that settled on the same periodic orbit (cycles within ``tol``
    of their size, any shift)."""
    from ..grids.cycles import cycle_distance, cycle_size
    if behaviour_a != behaviour_b or behaviour_a[0] not in ("symmetric", "asymmetric",
                                                            "multiperiodic"):
        return False
    p = behaviour_a[1]
    ca, cb = a.strobe[-p:, :2], b.strobe[-p:, :2]
    return bool(cycle_distance(ca, cb) <= tol * max(cycle_size(ca), cycle_size(cb), 1e-12))


def laws_captions(rows, behaviours):
    """The line under each row of figure 4: what each law's run does, and which rows reach the
    same orbit."""
    from ..plotting.style import law_name
    letters = "abcdefgh"
    caps = []
    for i, row in enumerate(rows):
        parts = []
        for law, res in row.items():
            beh = behaviours[i][law]
            name, p = beh
            what = (f"overturns at $t = {res.t:.3g}$" if res.status == "overturned" else
                    f"comes to rest at $t = {res.t:.3g}$" if res.status == "rest" else
                    f"settles on a {name} period-{p} orbit" if p else f"is {name}")
            same = [letters[j] for j, other in enumerate(rows) if j != i and
                    law in other and same_orbit(res, other[law], beh, behaviours[j][law])]
            if same:
                what += f" (the one of row{'s' if len(same) > 1 else ''} {', '.join(same)})"
            parts.append(f"{law_name(res.block)} {what}")
        caps.append("; ".join(parts) + ".")
    return caps
