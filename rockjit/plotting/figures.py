"""The study's figures (docs/theory/study.md, "The figures"), one function each, under one name.

Every function takes result objects (:class:`rockjit.result.Result`,
:class:`~rockjit.result.SweepResult`, :class:`~rockjit.result.BasinResult`, ...) and what was
computed about them (a run's behaviour, an ensemble's outcomes, a basin's measures), and returns
a :class:`matplotlib.figure.Figure` built without :mod:`matplotlib.pyplot`, so no GUI backend is
needed and nothing is kept in pyplot's figure registry; save it with
:func:`rockjit.storage.atomic.save_figure` or ``fig.savefig``. Nothing here computes a result:
behaviours are passed in (``rockjit.classify_result`` gives a run's) or read from a grid's
labels.

The visual language (colours, names, symbols, sizes, panel letters) is
:mod:`rockjit.plotting.style`'s; figures drawn inside ``style.use("paper")`` are sized for a
journal's columns and have no figure titles.

Each figure is drawn in the module of what it shows, and is importable from there too:

- :mod:`rockjit.plotting.restitution`: the restitution laws (figure 1);
- :mod:`rockjit.plotting.timeseries`: runs in time (figures 2 to 4);
- :mod:`rockjit.plotting.forcing`: bifurcation diagrams (figure 5) and the forcing plane;
- :mod:`rockjit.plotting.basins`: basins, attractor maps and erosion profiles (figures 6 to 8);
- :mod:`rockjit.plotting.fates`: an ensemble's fates;
- :mod:`rockjit.plotting.branches`: branches of periodic orbits and their caption.
"""

from __future__ import annotations

from .basins import fig_attractors, fig_basin, fig_basin_compare, fig_erosion
from .branches import BIFURCATION_MARKERS, END_MARKERS, branch_caption, fig_branches
from .fates import fig_fate
from .forcing import fig_bifurcation, fig_plane
from .restitution import fig_restitution
from .style import BEHAVIOUR_COLOURS
from .timeseries import fig_gallery, fig_laws_timeseries, fig_trajectory, with_impacts

__all__ = ["BEHAVIOUR_COLOURS", "BIFURCATION_MARKERS", "END_MARKERS", "branch_caption",
           "fig_attractors", "fig_basin", "fig_basin_compare", "fig_bifurcation",
           "fig_branches", "fig_erosion", "fig_fate", "fig_gallery", "fig_laws_timeseries",
           "fig_plane", "fig_restitution", "fig_trajectory", "with_impacts"]
