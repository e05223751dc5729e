"""Figures over the forcing: the bifurcation diagram of an amplitude sweep (figure 5 of the
study: stroboscopic points, each amplitude's behaviour and ``lambda_max``) and the behaviour
map of the forcing plane with ``lambda_max`` beside it."""

from __future__ import annotations

import numpy as np

from ..result import BEHAVIOURS, fractions
from . import cells
from . import style as S
from .common import LINE_COLOURS, LONE_HALF, PAD, _behaviour_handles
from .style import BEHAVIOUR_COLOURS, SYMBOLS

__all__ = ["fig_bifurcation", "fig_plane"]


# ---------------------------------------------------------------------------------------------
# Figure 5: bifurcation diagrams
# ---------------------------------------------------------------------------------------------

def _is_published(sw):
    return sw.settings.get("stop_at_overturn") is False


def _bifurcation_column(fig, gs_col, sw, alpha_limits, show_y, col, short=False):
    ax = fig.add_subplot(gs_col[0])
    ax_s = fig.add_subplot(gs_col[1], sharex=ax)
    ax_l = fig.add_subplot(gs_col[2], sharex=ax)
    alpha = np.asarray(sw.alpha)
    label = np.asarray(sw.label)
    sel = np.ones(alpha.shape, bool)
    if alpha_limits is not None:
        sel = (alpha >= alpha_limits[0] - 1e-12) & (alpha <= alpha_limits[1] + 1e-12)
    names = [str(n) for n in sw.names]
    pts = np.asarray(sw.strobe)[:, :, 1]
    present = []
    dense = pts.shape[1] * max(int(sel.sum()), 1)
    size = 0.8 if dense > 20000 else 2.0
    for code, name in enumerate(names):
        m = sel & (label == code)
        if not m.any():
            continue
        present.append(name)
        a = np.repeat(alpha[m], pts.shape[1])
        y = pts[m].ravel()
        ok = np.isfinite(y)
        ax.scatter(a[ok], y[ok], s=size, color=BEHAVIOUR_COLOURS[name], lw=0,
                   rasterized=True)
    ax.set_ylabel(SYMBOLS["strobe"] if show_y else "")
    published = _is_published(sw)
    S.letter(ax, col, S.law_name(sw.block)
             + ("" if short else f", $h/b = {sw.block.hb:g}$, $\\omega = {sw.forcing.omega:g}$")
             + (",\nas published" if published else ""))
    ax.tick_params(labelbottom=False)

    # a strip: the behaviour of every alpha, including those without stroboscopic points
    cmap, norm = S.behaviour_cmap()
    edges = cells.edges(alpha, lone=LONE_HALF)
    ax_s.pcolormesh(edges, [0, 1], label[None, :], cmap=cmap, norm=norm, rasterized=True)
    # the strip's name as its one tick label (a horizontal axis label is laid out badly)
    ax_s.set_yticks([0.5], ["class"] if show_y else [""])
    ax_s.tick_params(axis="y", length=0, labelsize=7)
    ax_s.tick_params(labelbottom=False)

    lam = np.asarray(sw.lambda_window if published and sw.lambda_window is not None
                     else sw.lambda_max, float)
    if np.isfinite(lam[sel]).any():
        fin = lam[sel & np.isfinite(lam)]
        lo, hi = min(float(fin.min()), 0.0), max(float(fin.max()), 0.0)
        pad = 0.08 * max(hi - lo, 0.1)
        lo, hi = lo - pad, hi + pad
    else:
        lo, hi = -1.0, 0.5
    ax_l.set_ylim(lo, hi)
    show = sel & ~np.isnan(lam)
    # a thin line through consecutive finite values, broken where there is none
    ax_l.plot(alpha[sel], np.where(np.isfinite(lam[sel]), lam[sel], np.nan), lw=0.5,
              color="0.65", zorder=1)
    any_rest = False
    for code, name in enumerate(names):
        m = show & (label == code)
        fin = m & np.isfinite(lam)
        ax_l.scatter(alpha[fin], lam[fin], s=4, color=BEHAVIOUR_COLOURS[name], lw=0, zorder=2)
        neg = m & np.isneginf(lam)
        if neg.any():  # lambda = -inf (rest, or an orbit through rest): the panel's bottom
            any_rest = True
            ax_l.scatter(alpha[neg], np.full(neg.sum(), lo), marker="v", s=14,
                         color=LINE_COLOURS[name], zorder=3, clip_on=False)
    ax_l.axhline(0, color="k", lw=0.6)
    ax_l.set_xlabel(SYMBOLS["alpha"])
    if show_y:
        ax_l.set_ylabel(SYMBOLS["lambda_max"] + (" (window)" if published else ""))
    if alpha_limits is not None:
        ax.set_xlim(*alpha_limits)
    elif alpha.size > 1:
        ax.set_xlim(edges[0], edges[-1])
    return present, any_rest


@S.styled
def fig_bifurcation(sweeps, alpha_limits=None, title=None):
    """Figure 5: stroboscopic ``theta'`` against ``alpha``, coloured by behaviour, a strip with
    every amplitude's behaviour, and ``lambda_max`` below.

    Parameters
    ----------
    sweeps : SweepResult or dict of str -> SweepResult
        One sweep, or several drawn side by side (e.g. the two laws), lettered a), b), ...
    alpha_limits : (float, float), optional
        Draw only this range of ``alpha`` (the zoom).
    title : str, optional

    Notes
    -----
    ``lambda_max`` is the sweep's: exact (the Floquet exponent) where a cell settled on a
    periodic orbit. A sweep integrated on past overturning (the study's way) shows its
    finite-window estimate ``lambda_window``, as the study did. ``lambda = -inf`` (rest, or an
    orbit through rest) is drawn as a triangle at the bottom of the lower panel; ``nan``
    (overturn, or not computed) is skipped.
    """
    if not isinstance(sweeps, dict):
        sweeps = {"": sweeps}
    if not sweeps:
        raise ValueError("sweeps must hold at least one sweep")
    if alpha_limits is not None:
        alpha_limits = tuple(float(v) for v in alpha_limits)
    n = len(sweeps)
    from matplotlib.lines import Line2D
    fig = S.figure("single" if n == 1 and S.current().name == "paper"
                   else ("double" if n > 1 else 0.6), 0.95 if n == 1 else 0.58, pad=PAD)
    gs = fig.add_gridspec(3, n, height_ratios=(2.4, 0.12, 1.0))
    present, any_rest = set(), False
    for c, sw in enumerate(sweeps.values()):
        got, rest = _bifurcation_column(fig, [gs[r, c] for r in range(3)], sw, alpha_limits,
                                        c == 0, c, short=n > 2)
        present |= set(got)
        any_rest |= rest
    order = [nm for nm in BEHAVIOURS if nm in present]
    handles = _behaviour_handles(order, marker=True)
    if any_rest:
        handles.append(Line2D([], [], ls="", marker="v", ms=5, color="0.3",
                              label=r"$\lambda = -\infty$ (through rest)"))
    width = fig.get_figwidth()
    ncols = len(handles) if n > 1 and width >= 10 else \
        min(len(handles), max(2, int(width // 1.7)))
    fig.legend(handles=handles, loc="outside lower center", ncols=max(1, ncols))
    S.suptitle(fig, title)
    return fig


# ---------------------------------------------------------------------------------------------
# Parameter plane (rocking chart)
# ---------------------------------------------------------------------------------------------

@S.styled
def fig_plane(plane_result, state=0, title=None):
    """Behaviour over the forcing plane (``omega`` across, ``alpha`` up) and ``lambda_max``
    beside it (exact where a cell is periodic).

    ``plane_result.label[state, i, j]`` belongs to ``alpha[i]``, ``omega[j]``.
    """
    p = plane_result
    lab = np.asarray(p.label)[state]
    lam = np.array(p.lambda_max, dtype=float)[state]
    ext = cells.extent(np.asarray(p.omega), np.asarray(p.alpha))
    cmap, norm = S.behaviour_cmap()
    fig = S.figure("double", 0.5, pad=PAD)
    ax, axl = fig.subplots(1, 2, sharey=True)
    ax.imshow(lab, origin="lower", cmap=cmap, norm=norm, interpolation="nearest",
              aspect="auto", extent=ext)
    ax.set_xlabel(SYMBOLS["omega"])
    ax.set_ylabel(SYMBOLS["alpha"])
    fr = fractions(lab)
    names = [n for n in BEHAVIOURS if fr[n] > 0]
    ax.legend(handles=_behaviour_handles(names, [f"{n} {fr[n]:.1f} %" for n in names]),
              loc="upper center", bbox_to_anchor=(0.5, -0.13), ncols=3)
    S.letter(ax, 0, "behaviour")
    finite = lam[np.isfinite(lam)]
    lim = max(float(np.abs(finite).max()), 1e-3) if finite.size else 1.0
    im = axl.imshow(np.where(np.isfinite(lam), lam, np.nan), origin="lower", cmap="RdBu_r",
                    vmin=-lim, vmax=lim, interpolation="nearest", aspect="auto", extent=ext)
    fig.colorbar(im, ax=axl, label=SYMBOLS["lambda_max"] + " (blank: overturn, rest, "
                                                           "not computed)")
    axl.set_xlabel(SYMBOLS["omega"])
    S.letter(axl, 1, SYMBOLS["lambda_max"])
    z = np.asarray(p.z0)[state]
    S.suptitle(fig, title or f"{S.law_name(p.block)}, $h/b = {p.block.hb:g}$, from "
                             f"$(\\theta_0, \\theta'_0) = ({z[0]:g}, {z[1]:g})$, "
                             f"{lab.shape[0]} $\\times$ {lab.shape[1]} forcings")
    return fig
