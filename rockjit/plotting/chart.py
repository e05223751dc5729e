"""The forcing plane with exact boundaries (:func:`rockjit.chart`): the brute-force chart of
behaviours with the bifurcation curves drawn over it, for one restitution law or two side by
side and overlaid. matplotlib is imported lazily; figures are built without pyplot.

Each curve type has its line style (:data:`CURVE_STYLES`) and is labelled on the chart
(:data:`CURVE_LABELS`, the period as a subscript); the overturn boundary of the chart's initial
state is the edge of its overturning cells.
"""

from __future__ import annotations

import numpy as np

from ..result import BEHAVIOURS, fractions

from .cells import extent
from .style import (BEHAVIOUR_COLOURS, LAW_COLOURS, LAW_NAMES, behaviour_cmap, figure, letter,
                    suptitle)
from .style import styled as _styled

__all__ = ["CURVE_LABELS", "CURVE_STYLES", "fig_chart"]

#: Line style of each curve type.
CURVE_STYLES = {"fold": "-", "symmetry_breaking": (0, (7, 3)),
                "period_doubling": (0, (7, 2.5, 1.5, 2.5)), "grazing": (0, (1.5, 2))}
#: Short label of each curve type (followed by the period).
CURVE_LABELS = {"fold": "F", "symmetry_breaking": "SB", "period_doubling": "PD",
                "grazing": "G"}
_NAMES = {"fold": "fold", "symmetry_breaking": "symmetry breaking",
          "period_doubling": "period doubling", "grazing": "grazing"}
_SUB = str.maketrans("0123456789", "\u2080\u2081\u2082\u2083\u2084\u2085\u2086\u2087\u2088"
                                   "\u2089")
#: The hatching of the cells where two laws' behaviours differ.
DIFFER_HATCH = "////"
#: The overturn boundary's colour (apart from the behaviours' and the curves').
OVERTURN_EDGE = "#ffd400"


#: The chart's cells are drawn this many times finer: each behaviour's share interpolated
#: linearly between the cells' centres, each fine pixel given the largest (a boundary drawn
#: as the straight lines between computed cells, not as the cells' staircase).
FINER = 6


def _fine(x, k=FINER):
    """The axis ``x`` ``k`` times finer, its ends kept."""
    x = np.asarray(x, float)
    if x.size < 2:
        return x
    return np.linspace(x[0], x[-1], (x.size - 1) * k + 1)


def _shares(lab, x, y):
    """Each behaviour's indicator interpolated bilinearly onto the finer grid:
    ``(codes, shares[code, iy, ix])``."""
    lab = np.asarray(lab)
    xf, yf = _fine(x), _fine(y)
    codes = np.unique(lab)
    out = np.empty((codes.size, yf.size, xf.size))
    for k, c in enumerate(codes):
        ind = (lab == c).astype(float)
        along = np.array([np.interp(xf, x, row) for row in ind]) if len(x) > 1 else ind
        out[k] = np.array([np.interp(yf, y, col) for col in along.T]).T if len(y) > 1 \
            else along
    return codes, out


def _map(ax, lab, x, y, **kw):
    """A chart's labels (``lab[i, j]`` of ``y[i]``, ``x[j]``) drawn on the finer grid."""
    x, y = np.asarray(x, float), np.asarray(y, float)
    codes, sh = _shares(lab, x, y)
    fine = codes[np.argmax(sh, axis=0)]
    ax.imshow(fine, origin="lower", aspect="auto", interpolation="nearest",
              extent=extent(_fine(x), _fine(y)), **kw)


def _label(curve):
    """A curve's label on the chart: its type's letters, its period as a subscript."""
    return CURVE_LABELS[curve.type] + str(curve.period).translate(_SUB)


def _curves(ax, res, colour, halo, lw1=1.5, labels=True):
    """Draw a result's curves, their codimension-two points and labels; returns the labels
    with the curve each sits on (``[(annotation, omega, alpha)]``)."""
    from matplotlib import patheffects
    fx = [patheffects.withStroke(linewidth=lw1 + 1.6, foreground=halo)] if halo else None
    placed = []
    for c in res.curves:
        lw = lw1 if c.period == 1 else 0.7 * lw1
        ax.plot(c.omega, c.alpha, ls=CURVE_STYLES[c.type], lw=lw, color=colour, zorder=5,
                path_effects=fx, solid_capstyle="butt", gid=f"{c.type}:{c.period}:{c.law}")
        for c2 in c.codim2:
            ax.plot(c2.omega, c2.alpha, marker="*", ms=7, color=colour, mec="w", mew=0.5,
                    zorder=7, ls="")
        if labels and len(c) > 1:
            k = int(0.35 * (len(c) - 1)) if c.type in ("fold", "grazing") else \
                int(0.6 * (len(c) - 1))
            ann = ax.annotate(_label(c), (c.omega[k], c.alpha[k]), xytext=(3, 2),
                              textcoords="offset points", fontsize=7, color=colour, zorder=8,
                              bbox=dict(boxstyle="round,pad=0.15", fc="white", ec=colour,
                                        lw=0.5, alpha=0.85))
            placed.append((ann, np.asarray(c.omega), np.asarray(c.alpha)))
    return placed


def _unclash(fig, placed):
    """Move each curve's label along its curve until it overprints no label placed before it
    (tried at 60, 35, 80, 20, 90, 50, 10 % of the curve, inside the view)."""
    from matplotlib.backends.backend_agg import FigureCanvasAgg
    canvas = fig.canvas if isinstance(fig.canvas, FigureCanvasAgg) else FigureCanvasAgg(fig)
    canvas.draw()
    r = canvas.get_renderer()
    kept = []
    for ann, om, al in placed:
        ax = ann.axes
        (x0, x1), (y0, y1) = ax.get_xlim(), ax.get_ylim()
        inside = np.flatnonzero((om >= x0) & (om <= x1) & (al >= y0) & (al <= y1))
        tries = [None] + ([inside[int(f * (inside.size - 1))] for f in
                           (0.6, 0.35, 0.8, 0.2, 0.9, 0.5, 0.1)] if inside.size else [])
        for k in tries:
            if k is not None:
                ann.xy = (om[k], al[k])
            bb = ann.get_window_extent(r).expanded(1.05, 1.1)
            if not any(bb.overlaps(o) for o in kept):
                break
        kept.append(ann.get_window_extent(r))


def _overturn_edge(ax, res, colour=OVERTURN_EDGE):
    """The edge of the overturning cells (the overturn boundary of the initial state): where
    the overturn share, interpolated between the cells' centres, crosses one half."""
    from matplotlib import patheffects
    lab = res.label()
    over = (lab == BEHAVIOURS.index("overturn")).astype(float)
    if not over.any() or over.all() or min(over.shape) < 2:
        return
    cs = ax.contour(np.asarray(res.plane.omega), np.asarray(res.plane.alpha), over,
                    levels=[0.5], colors=[colour], linewidths=1.6, zorder=4)
    for artist in getattr(cs, "collections", [cs]):
        artist.set_path_effects([patheffects.withStroke(linewidth=2.8, foreground="k")])


def _chart_panel(ax, res, i, show_y=True):
    """One law's chart with its overturn boundary and curves; returns the curves' labels."""
    cmap, norm = behaviour_cmap()
    _map(ax, res.label(), res.plane.omega, res.plane.alpha, cmap=cmap, norm=norm)
    _overturn_edge(ax, res)
    placed = _curves(ax, res, "k", "w")
    ax.set_xlim(*res.omega_range)
    ax.set_ylim(*res.alpha_range)
    ax.set_xlabel("$\\omega$")
    if show_y:
        ax.set_ylabel("$\\alpha$")
    b = res.block
    letter(ax, i, f"{LAW_NAMES.get(b.law, b.law)} ($e = {b.restitution:.3f}$)")
    return placed


def _share_words(pct):
    """A percentage in words, a small nonzero share as ``< 1 %``."""
    return "< 1 %" if 0 < pct < 0.5 else f"{pct:.0f} %"


def _legend_handles(results):
    """The charts' legend: the curve types drawn, the overturn boundary, the codimension-two
    points and each behaviour present with its share."""
    from matplotlib.lines import Line2D
    from matplotlib.patches import Patch
    types = [t for t in CURVE_STYLES if any(c.type == t for r in results for c in r.curves)]
    h = [Line2D([], [], color="k", ls=CURVE_STYLES[t], lw=1.0, label=_NAMES[t])
         for t in types]
    if any(0 < np.mean(r.label() == BEHAVIOURS.index("overturn")) < 1 for r in results):
        h.append(Line2D([], [], color=OVERTURN_EDGE, lw=1.6, label="overturn boundary ($z_0$)",
                        path_effects=None))
    if any(c.codim2 for r in results for c in r.curves):
        h.append(Line2D([], [], color="k", marker="*", ls="", ms=7,
                        label="codimension-two point"))
    labs = np.concatenate([r.label().ravel() for r in results])
    fr = fractions(labs)
    h += [Patch(facecolor=BEHAVIOUR_COLOURS[n], edgecolor="0.5", lw=0.4,
                label=f"{n} {_share_words(fr[n])}") for n in BEHAVIOURS if fr[n] > 0]
    return h


@_styled
def fig_chart(results, title=None):
    """The chart(s) of behaviours with the bifurcation curves over them.

    Parameters
    ----------
    results : ChartResult or dict of ChartResult
        One law's chart (:func:`rockjit.chart`), or two laws' of the same block and ranges
        (``{law: result}``): then each law's chart with its curves, and a third panel with
        both laws' curves on one chart, over the cells where the laws' behaviours differ.
    title : str, optional

    Returns
    -------
    matplotlib.figure.Figure

    Notes
    -----
    ``omega`` across, ``alpha`` up. Curves by type: fold solid, symmetry breaking dashed,
    period doubling dash-dotted, grazing dotted; period 1 thick, period 2 thinner; each
    labelled on the chart (F, SB, PD, G with the period), labels moved along their curves so
    that none overprints another. The overturn boundary is the edge of the cells whose run
    from the chart's initial state overturns. The cells are drawn :data:`FINER` times finer,
    each behaviour's share interpolated linearly between the computed cells' centres, so that
    a boundary between behaviours is drawn as straight segments between computed cells rather
    than as their staircase.

    Examples
    --------
    >>> from rockjit import Block, chart
    >>> from rockjit.plotting.chart import fig_chart
    >>> from rockjit.orbits import ChartCurves
    >>> res = chart(Block(hb=1), (0.7, 0.95), (1.25, 1.35), grid=(6, 5),
    ...             curves=ChartCurves(seed_omegas=[1.3], types="symmetry_breaking",
    ...                                max_period=1))
    >>> fig = fig_chart(res)
    >>> [t.get_text() for t in fig.axes[0].texts]
    ['SB\u2081']
    """
    if not isinstance(results, dict):
        results = {results.block.law: results}
    res = list(results.values())
    fig, placed = _one_law(res) if len(res) == 1 else _laws_side_by_side(res)
    b = res[0].block
    suptitle(fig, title or f"The forcing plane, $h/b = {b.hb:g}$: behaviours from $z_0$ and "
                           f"the bifurcation curves")
    _unclash(fig, placed)
    return fig


_LEGEND_KW = dict(handlelength=4.0, frameon=False)


def _one_law(res):
    """One law's chart with its legend at the right; returns the figure and the curves'
    labels."""
    fig = figure("double", 0.58)
    ax = fig.add_subplot(1, 1, 1)
    placed = _chart_panel(ax, res[0], 0)
    fig.legend(handles=_legend_handles(res), loc="outside right center", **_LEGEND_KW)
    return fig, placed


def _laws_side_by_side(res):
    """Two laws' charts side by side, both laws' curves overlaid below them and the legend in
    the fourth cell of the 2 x 2 grid; returns the figure and the curves' labels."""
    fig = figure("double", 0.86)
    gs = fig.add_gridspec(2, 2)
    axes = [fig.add_subplot(gs[0, 0])]
    axes.append(fig.add_subplot(gs[0, 1], sharey=axes[0]))
    axes.append(fig.add_subplot(gs[1, 0], sharey=axes[0]))
    placed = []
    for i, r in enumerate(res[:2]):
        placed += _chart_panel(axes[i], r, i, show_y=i == 0)
    labs = [r.label() for r in res]
    differ = np.zeros(labs[0].shape, bool)
    for lab in labs[1:]:
        differ |= lab != labs[0]
    placed += _overlay_panel(axes[-1], res, differ)
    fig.legend(handles=_overlay_legend(res, differ), loc="center", bbox_to_anchor=(0.76, 0.27),
               ncols=1, **_LEGEND_KW)
    return fig, placed


def _hatched(differ):
    """Whether the overlay hatches the cells where the laws differ (some do, on a grid of
    more than one row and column)."""
    return differ.any() and min(differ.shape) > 1


def _overlay_panel(ax, res, differ):
    """Every law's curves and overturn boundary on one chart, in the law's colour, over the
    cells where their behaviours differ (hatched); returns the curves' labels."""
    first = res[0]
    # hatched where the behaviours differ (grey would read as the rest behaviour's)
    x, y = np.asarray(first.plane.omega, float), np.asarray(first.plane.alpha, float)
    if _hatched(differ):
        _, sh = _shares(differ.astype(int), x, y)
        share = sh[-1] if differ.all() or not differ.any() else sh[1]
        cs = ax.contourf(_fine(x), _fine(y), share, levels=[0.5, 1.01], colors="none",
                         hatches=[DIFFER_HATCH])
        cs.set_edgecolor("0.55")
        cs.set_linewidth(0)
        if hasattr(cs, "set_hatchcolor"):
            cs.set_hatchcolor("0.55")
    placed = []
    for r in res:
        colour = LAW_COLOURS.get(r.block.law, "k")
        _overturn_edge(ax, r, colour=colour)
        placed += _curves(ax, r, colour, "w", labels=True)
    ax.set_xlim(*first.omega_range)
    ax.set_ylim(*first.alpha_range)
    ax.set_xlabel("$\\omega$")
    ax.set_ylabel("$\\alpha$")
    letter(ax, 2, f"both laws' curves; hatched: the behaviours differ "
                  f"({_share_words(100.0 * differ.mean())} of cells)")
    return placed


def _overlay_legend(res, differ):
    """The overlay's legend: the chart's entries, each law's colour, and the hatching."""
    from matplotlib.lines import Line2D
    from matplotlib.patches import Patch
    h = _legend_handles(res)
    h += [Line2D([], [], color=LAW_COLOURS.get(law, "k"), lw=1.6,
                 label=f"{LAW_NAMES.get(law, law)}'s curves and overturn boundary")
          for law in (r.block.law for r in res)]
    if _hatched(differ):
        h.append(Patch(facecolor="white", edgecolor="0.4", lw=0.4, hatch=DIFFER_HATCH,
                       label="behaviours differ"))
    return h
