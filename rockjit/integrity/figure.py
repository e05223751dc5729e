"""Integrity charts on paper and on disk: a figure per law, the two laws' difference, and the
``rockjit safety`` command's files (through :mod:`rockjit.outputs`' publishing)."""

from __future__ import annotations

import numpy as np

from ..plotting import cells
from ..plotting import style as S

__all__ = ["fig_fatal_shock", "fig_safety", "fig_safety_difference", "write"]

#: The default contour levels of the safe fraction.
LEVELS = (0.5, 0.9)
_DASHES = ("-", "--", ":", "-.")
#: The study's frequency, whose column is the erosion profile.
OMEGA_STUDY = 1.3


def _axes_labels(ax):
    from ..plotting.style import SYMBOLS
    ax.set_xlabel(SYMBOLS.get("omega", r"$\omega$"))
    ax.set_ylabel(SYMBOLS.get("alpha", r"$\alpha$"))


def _legend(fig, handles):
    if handles:
        fig.legend(handles=handles, loc="outside lower center", ncols=min(2, len(handles)))


def _study_line(ax, chart, handles):
    from matplotlib.lines import Line2D
    if chart.omega[0] <= OMEGA_STUDY <= chart.omega[-1] and chart.omega.size > 1:
        ax.axvline(OMEGA_STUDY, color="0.35", lw=0.8, ls=(0, (1, 2)))
        handles.append(Line2D([], [], color="0.35", lw=0.8, ls=(0, (1, 2)),
                              label=r"$\omega = 1.3$ (erosion profile)"))


@S.styled
def fig_safety(chart, levels=LEVELS):
    """The safe fraction of one law's chart over ``(omega, alpha)``, with its contours at
    ``levels`` (e.g. the forcings where 50 % and 90 % of the initial states are safe)."""
    from matplotlib.lines import Line2D
    fig = S.figure("single", 0.85, pad=None)
    ax = fig.add_subplot()
    mesh = ax.pcolormesh(cells.edges(chart.omega), cells.edges(chart.alpha), chart.safe, vmin=0, vmax=1,
                         cmap="viridis", shading="flat")
    fig.colorbar(mesh, ax=ax, label="safe fraction")
    handles = []
    if chart.alpha.size > 1 and chart.omega.size > 1:
        for lev, ls in zip(levels, _DASHES):
            if np.nanmin(chart.safe) < lev < np.nanmax(chart.safe):
                ax.contour(chart.omega, chart.alpha, chart.safe, levels=[lev], colors="white",
                           linestyles=ls, linewidths=1.0)
                handles.append(Line2D([], [], color="black", ls=ls, lw=1.0,
                                      label=f"{100 * lev:g} % safe"))
    _study_line(ax, chart, handles)
    _axes_labels(ax)
    ax.set_title(f"{S.law_name(chart.block)}, $h/b = {chart.block.hb:g}$")
    _legend(fig, handles)
    return fig


@S.styled
def fig_safety_difference(charts):
    """The difference of two laws' safe fractions (first minus second) over ``(omega,
    alpha)``."""
    (la, a), (lb, b) = list(charts.items())[:2]
    d = a.safe - b.safe
    fig = S.figure("single", 0.85, pad=None)
    ax = fig.add_subplot()
    top = float(np.nanmax(np.abs(d))) or 1.0
    mesh = ax.pcolormesh(cells.edges(a.omega), cells.edges(a.alpha), d, vmin=-top, vmax=top,
                         cmap="RdBu", shading="flat")
    fig.colorbar(mesh, ax=ax, label="difference of safe fractions")
    handles = []
    _study_line(ax, a, handles)
    _axes_labels(ax)
    ax.set_title(f"{S.law_name(a.block)} minus {S.law_name(b.block)}")
    _legend(fig, handles)
    return fig


@S.styled
def fig_fatal_shock(basin_result, shocks, edge=None):
    """A basin (safe cells shaded, overturning white) with each attractor's minimal fatal shock
    (``shocks``: ``{id: FatalShock}``, :func:`rockjit.integrity.fatal_shocks`) drawn as an
    arrow from its point with the circle of that radius, and the edge state (an
    :class:`~rockjit.integrity.EdgeState`) on the boundary."""
    from matplotlib.colors import ListedColormap
    from matplotlib.lines import Line2D
    from matplotlib.patches import Circle, Patch
    b = basin_result
    fig = S.figure("single", 0.85, pad=None)
    ax = fig.add_subplot()
    safe = (np.asarray(b.label) != 0).astype(float)
    ax.pcolormesh(cells.edges(b.theta0), cells.edges(b.dtheta0), safe.T, cmap=ListedColormap(
        ["white", "#c6dbef"]), vmin=0, vmax=1, shading="flat")
    handles = [Patch(facecolor="#c6dbef", edgecolor="0.5", label="safe initial states")]
    for k, (aid, sh) in enumerate(shocks.items()):
        x, d = sh.point, sh.delta
        ax.plot(*x, marker="o", ms=4, color="black", ls="none")
        ax.annotate("", xy=x + d, xytext=x, arrowprops=dict(arrowstyle="->", lw=1.0,
                                                              color="#d62728"))
        ax.add_patch(Circle(x, sh.norm, fill=False, ls="--", lw=0.7, color="#d62728"))
    handles.append(Line2D([], [], color="#d62728", lw=1.0, marker=">", ms=4,
                          label="minimal fatal shock"))
    if edge is not None:
        ax.plot(*edge.state, marker="*", ms=8, color="#ff7f0e", mec="black", mew=0.5,
                ls="none")
        handles.append(Line2D([], [], color="#ff7f0e", marker="*", ms=8, mec="black",
                              mew=0.5, ls="none", label=f"edge state (period {edge.period})"))
    ax.set_xlim(b.theta0[0], b.theta0[-1])
    ax.set_ylim(b.dtheta0[0], b.dtheta0[-1])
    ax.set_aspect("equal")
    from ..plotting.style import SYMBOLS
    ax.set_xlabel(SYMBOLS.get("theta0", r"$\theta_0$"))
    ax.set_ylabel(SYMBOLS.get("dtheta0", r"$\theta'_0$"))
    _legend(fig, handles)
    return fig


def write(out, charts, levels=LEVELS, *, npz="safety.npz"):
    """The files of ``rockjit safety`` (``charts``: ``{law: SafetyResult}``): the arrays of
    every law, a figure per law and, with two laws, their difference; returns the JSON-ready
    summary."""
    from ..outputs import _figure as publish, _npz
    first = next(iter(charts.values()))
    _npz(out, npz, "alpha, omega, theta0, dtheta0 and per law (suffix _<law>): safe (fraction "
                   "of initial states that do not overturn), GIM, IF, LIM (of the largest "
                   "safe attractor), n_attractors, behaviours; over (alpha, omega)",
         alpha=first.alpha, omega=first.omega, theta0=first.theta0, dtheta0=first.dtheta0,
         **{k: v for law, r in charts.items() for k, v in r.arrays(f"_{law}").items()})
    for law, r in charts.items():
        publish(out, f"safety_{law}.png", lambda r=r: fig_safety(r, levels),
                f"the safe fraction of the {law} law over (omega, alpha), contours at "
                f"{', '.join(f'{100 * v:g} %' for v in levels)} (data: {npz})")
    if len(charts) > 1:
        publish(out, "safety_difference.png", lambda: fig_safety_difference(charts),
                f"the difference of the first two laws' safe fractions (data: {npz})")
    return {law: r.to_summary() for law, r in charts.items()}
