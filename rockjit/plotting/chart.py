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

try:  # the palette's home after the figures' rework; figures.py's until then
    from .style import BEHAVIOUR_COLOURS, LAW_COLOURS
except ImportError:  # pragma: no cover - depends on the rework's state
    from .figures import BEHAVIOUR_COLOURS, LAW_COLOURS

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
_LAW_NAMES = {"housner": "Housner", "mao": "Mao", "constant": "constant e"}
#: The overturn boundary's colour (apart from the behaviours' and the curves').
OVERTURN_EDGE = "#ffd400"


def _figure(**kw):
    from matplotlib.figure import Figure
    kw.setdefault("layout", "constrained")
    return Figure(**kw)


def _extent(x, y):
    def half(v):
        return (v[-1] - v[0]) / (len(v) - 1) / 2 if len(v) > 1 and v[-1] > v[0] else 0.5
    dx, dy = half(x), half(y)
    return (x[0] - dx, x[-1] + dx, y[0] - dy, y[-1] + dy)


def _cmap():
    from matplotlib.colors import BoundaryNorm, ListedColormap
    cmap = ListedColormap([BEHAVIOUR_COLOURS[n] for n in BEHAVIOURS])
    return cmap, BoundaryNorm(np.arange(len(BEHAVIOURS) + 1) - 0.5, cmap.N)


def _label(curve):
    return CURVE_LABELS[curve.type] + str(curve.period).translate(_SUB)


def _law(block):
    return _LAW_NAMES.get(block.law, block.law) if block.law != "constant" else \
        f"e = {block.restitution:g}"


def _curves(ax, res, colour, halo, lw1=2.0, labels=True):
    """Draw a result's curves, their codimension-two points and labels."""
    from matplotlib import patheffects
    fx = [patheffects.withStroke(linewidth=lw1 + 2.2, foreground=halo)] if halo else None
    for c in res.curves:
        lw = lw1 if c.period == 1 else 0.7 * lw1
        ax.plot(c.omega, c.alpha, ls=CURVE_STYLES[c.type], lw=lw, color=colour, zorder=5,
                path_effects=fx, solid_capstyle="butt", gid=f"{c.type}:{c.period}:{c.law}")
        for c2 in c.codim2:
            ax.plot(c2.omega, c2.alpha, marker="*", ms=9, color=colour, mec="w", mew=0.6,
                    zorder=7, ls="")
        if labels and len(c) > 1:
            k = int(0.35 * (len(c) - 1)) if c.type in ("fold", "grazing") else \
                int(0.6 * (len(c) - 1))
            ax.annotate(_label(c), (c.omega[k], c.alpha[k]), xytext=(4, 3),
                        textcoords="offset points", fontsize=8, color=colour, zorder=8,
                        bbox=dict(boxstyle="round,pad=0.15", fc="white", ec=colour, lw=0.6,
                                  alpha=0.85))


def _overturn_edge(ax, res, colour=OVERTURN_EDGE):
    """The edge of the overturning cells (the overturn boundary of the initial state)."""
    from matplotlib import patheffects
    lab = res.label()
    over = (lab == BEHAVIOURS.index("overturn")).astype(float)
    if not over.any() or over.all() or min(over.shape) < 2:
        return
    cs = ax.contour(np.asarray(res.plane.omega), np.asarray(res.plane.alpha), over,
                    levels=[0.5], colors=[colour], linewidths=2.2, zorder=4)
    for artist in getattr(cs, "collections", [cs]):
        artist.set_path_effects([patheffects.withStroke(linewidth=4.0, foreground="k")])


def _chart_panel(ax, res, show_y=True):
    lab = res.label()
    cmap, norm = _cmap()
    ax.imshow(lab, origin="lower", cmap=cmap, norm=norm, interpolation="nearest",
              aspect="auto", extent=_extent(np.asarray(res.plane.omega),
                                            np.asarray(res.plane.alpha)))
    _overturn_edge(ax, res)
    _curves(ax, res, "k", "w")
    ax.set_xlim(*res.omega_range)
    ax.set_ylim(*res.alpha_range)
    ax.set_xlabel("\u03c9")
    if show_y:
        ax.set_ylabel("\u03b1")
    b = res.block
    ax.set_title(f"{_law(b)} (e = {b.restitution:.3f})", fontsize=10)


def _legend_handles(results):
    from matplotlib.lines import Line2D
    from matplotlib.patches import Patch
    types = [t for t in CURVE_STYLES if any(c.type == t for r in results for c in r.curves)]
    h = [Line2D([], [], color="k", ls=CURVE_STYLES[t], lw=1.8, label=_NAMES[t])
         for t in types]
    h.append(Line2D([], [], color=OVERTURN_EDGE, lw=2.2, label="overturn boundary (z\u2080)",
                    path_effects=None))
    if any(c.codim2 for r in results for c in r.curves):
        h.append(Line2D([], [], color="k", marker="*", ls="", ms=9,
                        label="codimension-two point"))
    labs = np.concatenate([r.label().ravel() for r in results])
    fr = fractions(labs)
    h += [Patch(color=BEHAVIOUR_COLOURS[n], label=f"{n} {fr[n]:.0f} %") for n in BEHAVIOURS
          if fr[n] > 0]
    return h


def fig_chart(results, title=None):
    """The chart(s) of behaviours with the bifurcation curves over them.

    Parameters
    ----------
    results : ChartResult or dict of ChartResult
        One law's chart (:func:`rockjit.chart`), or two laws' of the same block and ranges
        (``{law: result}``): then each law's chart with its curves side by side, and a third
        panel with both laws' curves on one chart, over the cells where the laws' behaviours
        differ.
    title : str, optional

    Returns
    -------
    matplotlib.figure.Figure

    Notes
    -----
    ``omega`` across, ``alpha`` up. Curves by type: fold solid, symmetry breaking dashed,
    period doubling dash-dotted, grazing dotted; period 1 thick, period 2 thinner; each
    labelled on the chart (F, SB, PD, G with the period). The overturn boundary is the edge
    of the cells whose run from the chart's initial state overturns.

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
    from matplotlib.lines import Line2D
    from matplotlib.patches import Patch

    if not isinstance(results, dict):
        results = {results.block.law: results}
    res = list(results.values())
    first = res[0]
    if len(res) == 1:
        fig = _figure(figsize=(9.0, 6.6))
        ax = fig.add_subplot(1, 1, 1)
        _chart_panel(ax, first)
        ax.legend(handles=_legend_handles(res), loc="upper left", bbox_to_anchor=(1.01, 1.0),
                  fontsize=8, frameon=False)
    else:
        fig = _figure(figsize=(17.0, 6.2))
        axes = fig.subplots(1, len(res) + 1, sharey=True)
        for i, r in enumerate(res):
            _chart_panel(axes[i], r, show_y=i == 0)
        ax = axes[-1]
        laws = [r.block.law for r in res]
        labs = [r.label() for r in res]
        differ = np.zeros(labs[0].shape, bool)
        for lab in labs[1:]:
            differ |= lab != labs[0]
        from matplotlib.colors import ListedColormap
        ax.imshow(differ.astype(float), origin="lower", aspect="auto", interpolation="nearest",
                  cmap=ListedColormap(["#ffffff", "#d9d9d9"]), vmin=0, vmax=1,
                  extent=_extent(np.asarray(first.plane.omega), np.asarray(first.plane.alpha)))
        for r in res:
            colour = LAW_COLOURS.get(r.block.law, "k")
            _overturn_edge(ax, r, colour=colour)
            _curves(ax, r, colour, "w", labels=True)
        ax.set_xlim(*first.omega_range)
        ax.set_ylim(*first.alpha_range)
        ax.set_xlabel("\u03c9")
        ax.set_title("both laws' curves (grey: the behaviours differ, "
                     f"{100.0 * differ.mean():.0f} % of cells)", fontsize=10)
        h = _legend_handles(res)
        h += [Line2D([], [], color=LAW_COLOURS.get(law, "k"), lw=2.0,
                     label=f"{_LAW_NAMES.get(law, law)}'s curves and overturn boundary")
              for law in laws]
        h.append(Patch(color="#d9d9d9", label="behaviours differ"))
        fig.legend(handles=h, loc="outside lower center", ncols=6, fontsize=8, frameon=False)
    b = first.block
    fig.suptitle(title or f"The forcing plane, h/b = {b.hb:g}: behaviours from z\u2080 and the "
                 f"bifurcation curves", fontsize=11)
    return fig
