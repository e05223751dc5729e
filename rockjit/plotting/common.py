"""What the study's figures share: their layout pads, the behaviours' line colours and legend
handles, a result's parameters in words, and the period from which orbits are drawn as one group.

The figure modules of :mod:`rockjit.plotting` draw with these; nothing here draws a figure.
"""

from __future__ import annotations

from . import style as S
from .style import BEHAVIOUR_COLOURS

#: The figures' constrained-layout pads, in inches: a little more than the default (3 points),
#: since constrained layout can leave a rotated axis label a point or two beyond the canvas's
#: edge when a column's tick labels widen.
PAD = (0.06, 0.05)
#: Half the width of the cell of a diagram's single amplitude.
LONE_HALF = 0.5e-3
#: Lines of a behaviour: its colour, except the pale ones (rest), darkened to be seen as a line.
LINE_COLOURS = dict(BEHAVIOUR_COLOURS, rest="#8C8C8C")


def _params(res):
    """The block and forcing of a result, in words."""
    b, f = res.block, res.forcing
    return (f"{S.law_name(b)}, $h/b = {b.hb:g}$, $\\alpha = {f.alpha:g}$, "
            f"$\\omega = {f.omega:g}$")


def _behaviour_handles(names, labels=None, marker=False):
    from matplotlib.lines import Line2D
    from matplotlib.patches import Patch
    out = []
    for i, n in enumerate(names):
        lab = n if labels is None else labels[i]
        if marker:
            out.append(Line2D([], [], ls="", marker="o", ms=5, color=BEHAVIOUR_COLOURS[n],
                              mec="0.45", mew=0.4, label=lab))
        else:
            out.append(Patch(facecolor=BEHAVIOUR_COLOURS[n], edgecolor="0.6", lw=0.4,
                             label=lab))
    return out




#: Periods from this one on are drawn as one group (more shades of one green than a reader can
#: tell apart): the branches of periodic orbits (:mod:`rockjit.plotting.branches`) and the areas
#: of the erosion profiles (:mod:`rockjit.plotting.basins`).
GROUPED_PERIOD = 5
