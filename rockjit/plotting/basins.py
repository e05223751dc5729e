"""Figures of basins of attraction (figures 6 to 8 of the study): each initial state's
behaviour, two laws' basins and where they agree, attractor maps with their basin entropy and
integrity, and erosion profiles over the amplitude."""

from __future__ import annotations

import math

import numpy as np

from ..result import BEHAVIOURS, fractions
from . import cells
from . import style as S
from .common import GROUPED_PERIOD, LONE_HALF, PAD, _behaviour_handles, _params
from .style import AGREE_COLOUR, BEHAVIOUR_COLOURS, DISAGREE_COLOUR, LAW_LINES, SYMBOLS

__all__ = ["APERIODIC_NOTE", "fig_attractors", "fig_basin", "fig_basin_compare", "fig_erosion"]


# ---------------------------------------------------------------------------------------------
# Figure 6: basins
# ---------------------------------------------------------------------------------------------

def _basin_axes(ax, b, show_y=True):
    cmap, norm = S.behaviour_cmap()
    # label[i, j] belongs to theta0[i], dtheta0[j]: rows of the image are dtheta0
    ax.imshow(np.asarray(b.label).T, origin="lower", cmap=cmap, norm=norm,
              interpolation="nearest", aspect="auto",
              extent=cells.extent(np.asarray(b.theta0), np.asarray(b.dtheta0)))
    ax.set_xlabel(SYMBOLS["theta0"])
    if show_y:
        ax.set_ylabel(SYMBOLS["dtheta0"])


def _basin_legend(ax, b):
    fr = fractions(b.label)
    names = [n for n in BEHAVIOURS if fr[n] > 0]
    ax.legend(handles=_behaviour_handles(names, [f"{n} {fr[n]:.1f} %" for n in names]),
              loc="upper center", bbox_to_anchor=(0.5, -0.16), ncols=1)


def _cells(b):
    n = np.shape(b.label)
    return f"${n[0]} \\times {n[1]}$ initial states"


@S.styled
def fig_basin(basin_result, title=None):
    """Figure 6 (one law): the behaviour of each ``(theta0, theta0')``, with percentages."""
    b = basin_result
    fig = S.figure("single" if S.current().name == "paper" else 0.48, 1.12, pad=PAD)
    ax = fig.add_subplot()
    _basin_axes(ax, b)
    _basin_legend(ax, b)
    S.letter(ax, 0, f"{S.law_name(b.block)}, {_cells(b)}")
    S.suptitle(fig, title or f"Basins: {_params(b)}")
    return fig


@S.styled
def fig_basin_compare(housner_basin, mao_basin, title=None):
    """Figure 6: the basins under both laws and where they agree.

    The third panel shows the cells where the two laws give the same behaviour (white) and
    where they differ (black); its legend gives the percentages.
    """
    from matplotlib.colors import ListedColormap
    from matplotlib.patches import Patch
    a, b = housner_basin, mao_basin
    if np.shape(a.label) != np.shape(b.label) or not (
            np.allclose(a.theta0, b.theta0) and np.allclose(a.dtheta0, b.dtheta0)):
        raise ValueError("the two basins must be computed on the same grid")
    agree = np.asarray(a.label) == np.asarray(b.label)
    pct = 100.0 * float(np.mean(agree)) if agree.size else math.nan
    fig = S.figure("double", 0.46, pad=PAD)
    axes = fig.subplots(1, 3, sharey=True)
    for i, res in enumerate((a, b)):
        _basin_axes(axes[i], res, show_y=i == 0)
        _basin_legend(axes[i], res)
        S.letter(axes[i], i, S.law_name(res.block))
    axes[2].imshow(agree.T.astype(int), origin="lower", interpolation="nearest",
                   aspect="auto", cmap=ListedColormap([DISAGREE_COLOUR, AGREE_COLOUR]),
                   vmin=0, vmax=1,
                   extent=cells.extent(np.asarray(a.theta0), np.asarray(a.dtheta0)))
    axes[2].set_xlabel(SYMBOLS["theta0"])
    S.letter(axes[2], 2, f"agreement: {pct:.1f} %")
    axes[2].legend(handles=[Patch(facecolor=AGREE_COLOUR, edgecolor="0.5", lw=0.5,
                                  label=f"same behaviour {pct:.1f} %"),
                            Patch(facecolor=DISAGREE_COLOUR, edgecolor="0.5", lw=0.5,
                                  label=f"different {100 - pct:.1f} %")],
                   loc="upper center", bbox_to_anchor=(0.5, -0.16), ncols=1,
                   title=f"of the {_cells(a)}")
    blk, frc = a.block, a.forcing
    S.suptitle(fig, title or f"Basins of attraction, $h/b = {blk.hb:g}$, "
                             f"$\\alpha = {frc.alpha:g}$, $\\omega = {frc.omega:g}$, "
                             f"$(r_0, s_0) = ({a.settings.get('r0', 0):.4g}, "
                             f"{a.settings.get('s0', 1):.4g})$, {_cells(a)}")
    return fig


# ---------------------------------------------------------------------------------------------
# Figure 7: attractor maps
# ---------------------------------------------------------------------------------------------

def _attractor_panel(ax, ids, theta0, dtheta0, attractors, show_y=True):
    """The attractor map (``ids[i, j]`` of ``theta0[i], dtheta0[j]``), each attractor in a tint
    of its behaviour's colour, each periodic one's cycle starred; returns the legend handles
    (every coloured area, by name and percentage)."""
    from matplotlib.colors import BoundaryNorm, ListedColormap
    from matplotlib.lines import Line2D
    from matplotlib.patches import Patch
    n = max(len(attractors), 1)
    colours = S.attractor_colours(attractors) or [BEHAVIOUR_COLOURS["unresolved"]]
    cmap = ListedColormap([BEHAVIOUR_COLOURS["unresolved"], BEHAVIOUR_COLOURS["overturn"]]
                          + colours)
    norm = BoundaryNorm(np.arange(-2, n + 1) - 0.5, cmap.N)
    ax.imshow(np.asarray(ids).T, origin="lower", cmap=cmap, norm=norm, interpolation="nearest",
              aspect="auto", extent=cells.extent(np.asarray(theta0), np.asarray(dtheta0)))
    ax.set_xlabel(SYMBOLS["theta0"])
    if show_y:
        ax.set_ylabel(SYMBOLS["dtheta0"])
    handles = []
    names = S.attractor_names(attractors)
    ids = np.asarray(ids)
    for a, c, name in zip(attractors, colours, names):
        handles.append(Patch(facecolor=c, edgecolor="0.5", lw=0.4,
                             label=f"{name}, {a.fraction:.1f} %"))
        if a.period:
            ax.plot(a.points[:, 0], a.points[:, 1], ls="", marker="*", ms=10, mfc=c, mec="k",
                    mew=0.8)
    over = 100.0 * np.mean(ids == -1)
    if over:
        handles.append(Patch(facecolor=BEHAVIOUR_COLOURS["overturn"], edgecolor="0.5", lw=0.4,
                             label=f"overturn, {over:.1f} %"))
    unres = 100.0 * np.mean(ids == -2)
    if unres:
        handles.append(Patch(facecolor=BEHAVIOUR_COLOURS["unresolved"], edgecolor="0.5",
                             lw=0.4, label=f"unresolved, {unres:.1f} %"))
    if any(a.period for a in attractors):
        handles.append(Line2D([], [], ls="", marker="*", ms=8, mfc="w", mec="k",
                              label=r"cycle points at $t = kT$"))
    return handles


@S.styled
def fig_attractors(basins, measures=None, title=None):
    """Attractor maps of one or two basins (a dict ``law: BasinResult``, or one result), each
    with its basin entropy and integrity.

    ``measures`` (a dict ``law: BasinResult.measures()``) are computed when not given.
    """
    if not isinstance(basins, dict):
        basins = {basins.block.law: basins}
    measures = measures or {law: b.measures() for law, b in basins.items()}
    fig = S.figure("double" if len(basins) > 1 else 0.5, 0.62 if len(basins) > 1 else 1.2,
                   pad=PAD)
    axes = np.atleast_1d(fig.subplots(1, len(basins), sharey=True))
    for i, (ax, (law, b)) in enumerate(zip(axes, basins.items())):
        handles = _attractor_panel(ax, b.attractor, b.theta0, b.dtheta0, b.attractors,
                                   show_y=i == 0)
        m = measures[law]
        S.letter(ax, i, f"{S.law_name(b.block)}: basin entropy $S_b = "
                        f"{m['basin_entropy']:.3f}$,\n"
                        f"boundary basin entropy $S_{{bb}} = "
                        f"{m['boundary_basin_entropy']:.3f}$,\n"
                        f"global integrity measure GIM $= {m['integrity']['GIM']:.3f}$,\n"
                        f"integrity factor IF $= {m['integrity']['IF']:.3f}$")
        ax.legend(handles=handles, loc="upper center", bbox_to_anchor=(0.5, -0.13), ncols=1,
                  title=f"of the {_cells(b)}")
    b0 = next(iter(basins.values()))
    blk, frc = b0.block, b0.forcing
    S.suptitle(fig, title or f"Attractors, $h/b = {blk.hb:g}$, $\\alpha = {frc.alpha:g}$, "
                             f"$\\omega = {frc.omega:g}$, {_cells(b0)}")
    return fig


# ---------------------------------------------------------------------------------------------
# Figure 8: erosion profiles
# ---------------------------------------------------------------------------------------------

#: What the erosion profiles call a basin with no period up to ``pmax``: the basins compute no
#: exponent, so chaotic motion is counted as aperiodic there (docs/theory/behaviours.md).
APERIODIC_NOTE = "(no period up to 16; no exponents computed,\nso chaotic motion counts here)"


def _erosion_areas(r):
    """``[(label, colour, hatch, [fractions over alpha of each attractor])]`` of a profile's
    stack: one area per kind of attractor (behaviour, period, whether it passes through rest),
    its attractors stacked inside it, in the behaviours' order."""
    fr = r.fractions()
    kinds = {}
    for i, br in enumerate(r.branches):
        rest = bool(S._through_rest(br))
        period = int(br.get("period") or 0)
        if br["behaviour"] == "multiperiodic":
            period = min(period, GROUPED_PERIOD)
        key = (BEHAVIOURS.index(br["behaviour"]), period, rest)
        kinds.setdefault(key, []).append(i)
    areas = []
    for key in sorted(kinds):
        idx = kinds[key]
        br = r.branches[idx[0]]
        beh = br["behaviour"]
        name = S._base_name(br)
        colour = BEHAVIOUR_COLOURS.get(beh, "#999999")
        hatch = "//////" if key[2] else None
        if beh == "multiperiodic":
            # periods 2, 3 and 4 told apart by lightness, the longer ones together, dotted
            colour = {3: S.shade(colour, 0.45), 4: S.tint(colour, 0.5)}.get(key[1], colour)
            if key[1] >= GROUPED_PERIOD:
                name = f"period $\\geq {GROUPED_PERIOD}$" + (" through rest" if key[2] else "")
                hatch = hatch or "...."
        n = len(idx)
        if n > 1:
            name += f" ({n} attractors)"
        areas.append((name, colour, hatch, [fr[i] for i in idx]))
    return areas


@S.styled
def fig_erosion(profiles, title=None):
    """Erosion profiles (a dict ``law: ErosionResult``, or one): the global integrity measure
    GIM and the integrity factor IF against the amplitude for each law, and below, for each
    law, the basin fractions of its attractors, stacked as steps over the amplitudes (each
    basin holds for its amplitude, none is interpolated), overturn on top."""
    if not isinstance(profiles, dict):
        profiles = {profiles.block.law: profiles}
    n = len(profiles)
    fig = S.figure("double", 0.30 + 0.30 * n, pad=PAD)
    gs = fig.add_gridspec(1 + n, 2, height_ratios=[1.0] + [1.15] * n,
                          width_ratios=(1.0, 1.0))
    ax_g = fig.add_subplot(gs[0, 0])
    ax_i = fig.add_subplot(gs[0, 1], sharex=ax_g)
    for law, r in profiles.items():
        st = LAW_LINES.get(law, LAW_LINES["constant"])
        for ax, v in ((ax_g, r.GIM), (ax_i, r.IF)):
            ax.plot(r.alpha, v, color=st["color"], ls=st["ls"], marker=st["marker"], ms=3,
                    mfc="white", lw=1.2, label=S.law_name(r.block))
    for ax, what, i in ((ax_g, "global integrity measure GIM", 0),
                        (ax_i, "integrity factor IF", 1)):
        ax.set_ylim(-0.02, 1.02)
        ax.grid(alpha=0.3)
        ax.legend(loc="upper right")
        ax.set_xlabel(SYMBOLS["alpha"])
        S.letter(ax, i, what)
    for k, (law, r) in enumerate(profiles.items()):
        axk = fig.add_subplot(gs[1 + k, 0], sharex=ax_g)
        ax_leg = fig.add_subplot(gs[1 + k, 1])
        ax_leg.axis("off")
        edges = cells.edges(r.alpha, lone=LONE_HALF)
        areas = _erosion_areas(r)
        bottom = np.zeros(r.alpha.size)
        from matplotlib.patches import Patch
        handles = []
        for name, colour, hatch, parts in areas:
            top = bottom + np.sum(parts, axis=0)
            edge = S.shade(colour, 0.5) if hatch == "//////" else ("white" if hatch else
                                                                    colour)
            axk.stairs(top, edges, baseline=bottom.copy(), fill=True, facecolor=colour,
                       edgecolor=edge, hatch=hatch, lw=0)
            # the attractors of one kind, each its own band, parted by thin white lines
            inner = bottom.copy()
            for f in parts[:-1]:
                inner = inner + f
                axk.stairs(inner, edges, baseline=None, color="white", lw=0.4)
            handles.append(Patch(facecolor=colour, edgecolor=edge if hatch else "0.5",
                                 hatch=hatch, lw=0.4,
                                 label=f"{name}, up to {(top - bottom).max():.1f} %"
                                 + ("\n" + APERIODIC_NOTE if name.startswith("aperiodic")
                                    else "")))
            bottom = top
        axk.stairs(np.full(r.alpha.size, 100.0), edges, baseline=bottom, fill=True,
                   color=BEHAVIOUR_COLOURS["overturn"], lw=0)
        handles.append(Patch(facecolor=BEHAVIOUR_COLOURS["overturn"], edgecolor="0.5", lw=0.4,
                             label="overturn (and unresolved)"))
        axk.set_ylim(0, 100)
        axk.set_xlim(edges[0], edges[-1])
        axk.set_ylabel("% of cells")
        axk.set_xlabel(SYMBOLS["alpha"])
        g = r.attractor.shape[1]
        S.letter(axk, 2 + k, f"{S.law_name(r.block)}: basin of each attractor, ${g} \\times "
                             f"{g}$ cells every $\\Delta\\alpha = {r.settings.get('alpha_step'):g}$")
        ax_leg.legend(handles=handles, loc="center left", ncols=1)
    r0 = next(iter(profiles.values()))
    g = r0.attractor.shape[1]
    step = r0.settings.get("alpha_step")
    S.suptitle(fig, title or f"Erosion profiles, $h/b = {r0.block.hb:g}$, "
                             f"$\\omega = {r0.forcing.omega:g}$: a ${g} \\times {g}$ basin "
                             f"every $\\Delta\\alpha = {step:g}$")
    return fig
