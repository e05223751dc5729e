"""The study's figures (SPEC.md §7), one function each; matplotlib is imported lazily.

Every function takes result objects (:class:`rockjit.Result`, :class:`rockjit.grids.grids.SweepResult`,
:class:`rockjit.grids.grids.BasinResult`) and returns a :class:`matplotlib.figure.Figure` built
without :mod:`matplotlib.pyplot`, so no GUI backend is needed and nothing is kept in pyplot's
figure registry; save it with :func:`rockjit.storage.files.save_figure` or ``fig.savefig``.

Behaviours have one colour everywhere: :data:`BEHAVIOUR_COLOURS`.
"""

from __future__ import annotations

import math

import numpy as np

from ..single import classify_result
from ..result import BEHAVIOURS, fractions
from ..model import delta_e_percent, e_housner, e_mao, thc_from_hb

__all__ = ["BEHAVIOUR_COLOURS", "LAW_COLOURS", "agreement", "fig_attractors", "fig_basin",
           "fig_basin_compare", "fig_bifurcation", "fig_erosion", "fig_fate", "fig_gallery",
           "fig_laws_timeseries", "fig_plane", "fig_restitution", "fig_trajectory"]

#: One colour per behaviour name (analysis.BEHAVIOURS), used by every figure.
BEHAVIOUR_COLOURS = {
    "overturn": "#3b3b3b",
    "rest": "#bdbdbd",
    "symmetric": "#1f77b4",
    "asymmetric": "#2ca02c",
    "multiperiodic": "#ff7f0e",
    "chaotic": "#d62728",
    "aperiodic": "#9467bd",
    "unresolved": "#e377c2",
}
#: Colours of the restitution laws in comparisons.
LAW_COLOURS = {"housner": "#1f77b4", "mao": "#d62728", "constant": "#2ca02c"}

_LAW_NAMES = {"housner": "Housner", "mao": "Mao", "constant": "constant e"}
_GREEK = {"theta": "\u03b8", "dtheta": "\u03b8\u2032", "lambda": "\u03bb", "alpha": "\u03b1",
          "omega": "\u03c9"}


def _figure(**kw):
    from matplotlib.figure import Figure
    kw.setdefault("layout", "constrained")
    return Figure(**kw)


def _law(block):
    if block.law == "constant":
        return f"e = {block.restitution:g}"
    return _LAW_NAMES.get(block.law, block.law)


def _params(res):
    """The block and forcing of a result, in words."""
    b, f = res.block, res.forcing
    return f"{_law(b)}, h/b = {b.hb:g}, \u03b1 = {f.alpha:g}, \u03c9 = {f.omega:g}"


def agreement(label_a, label_b):
    """Percentage of cells where two label arrays agree."""
    a = np.asarray(label_a)
    b = np.asarray(label_b)
    if a.shape != b.shape:
        raise ValueError(f"label arrays differ in shape ({a.shape} vs {b.shape})")
    return 100.0 * np.count_nonzero(a == b) / a.size if a.size else math.nan


def _cmap():
    from matplotlib.colors import BoundaryNorm, ListedColormap
    cmap = ListedColormap([BEHAVIOUR_COLOURS[n] for n in BEHAVIOURS])
    norm = BoundaryNorm(np.arange(len(BEHAVIOURS) + 1) - 0.5, cmap.N)
    return cmap, norm


def _behaviour_handles(names, labels=None, marker=False):
    from matplotlib.lines import Line2D
    from matplotlib.patches import Patch
    out = []
    for i, n in enumerate(names):
        lab = n if labels is None else labels[i]
        if marker:
            out.append(Line2D([], [], ls="", marker="o", ms=5, color=BEHAVIOUR_COLOURS[n],
                              label=lab))
        else:
            out.append(Patch(color=BEHAVIOUR_COLOURS[n], label=lab))
    return out


# ---------------------------------------------------------------------------------------------
# Figure 1: restitution laws
# ---------------------------------------------------------------------------------------------

def fig_restitution(hb_range=(1.0 / math.sqrt(2.0), 6.0), n=400, marks=(1.0, 2.0)):
    """Figure 1: ``e_H`` and ``e_M`` against ``thc``, with ``Δe%`` on a twin axis.

    Parameters
    ----------
    hb_range : (float, float)
        Slenderness range; the Housner law needs ``hb >= 1/sqrt(2)``.
    n : int
        Number of points.
    marks : sequence of float
        Slenderness values marked with a vertical line and their values.
    """
    lo, hi = (float(v) for v in hb_range)
    if not 1.0 / math.sqrt(2.0) - 1e-12 <= lo < hi:
        raise ValueError(f"hb_range must satisfy 1/sqrt(2) <= start < end (got {lo}, {hi})")
    thc = np.linspace(thc_from_hb(lo), thc_from_hb(hi), n)
    eh, em = e_housner(thc), e_mao(thc)
    de = delta_e_percent(em, eh)
    fig = _figure(figsize=(7.0, 4.2))
    ax = fig.add_subplot()
    deg = np.degrees(thc)
    ax.plot(deg, eh, color=LAW_COLOURS["housner"], label="$e_H$ (Housner 1963)")
    ax.plot(deg, em, color=LAW_COLOURS["mao"], label="$e_M$ (Mao et al. 2024)")
    ax.set_xlabel("$\\theta_c$ = arctan(h/b)  [degrees]")
    ax.set_ylabel("coefficient of restitution $e$")
    ax.set_ylim(0, 1.02)
    ax2 = ax.twinx()
    ax2.plot(deg, de, color="0.35", ls="--", label="$\\Delta e$ % (right axis)")
    ax2.set_ylabel("$\\Delta e$  [%]")
    ax2.set_ylim(0, max(1.0, float(np.nanmax(de))) * 1.05)
    for hb in marks:
        t = float(thc_from_hb(hb))
        h, m = float(e_housner(t)), float(e_mao(t))
        ax.axvline(np.degrees(t), color="0.6", lw=0.8, ls=":")
        ax.plot([np.degrees(t)] * 2, [h, m], "o", color="k", ms=3.5, zorder=5)
        # on the twin axes, which are drawn above the first ones: the box hides the curves
        ax2.annotate(f"h/b = {hb:g}\n$e_H$ = {h:.3f}\n$e_M$ = {m:.3f}\n"
                     f"$\\Delta e$ = {float(delta_e_percent(m, h)):.2f} %",
                     (np.degrees(t), 0.03), xycoords=ax.transData, xytext=(4, 0),
                     textcoords="offset points", fontsize=8, va="bottom", zorder=6,
                     bbox=dict(boxstyle="round,pad=0.25", fc="white", ec="0.8"))
    lines = ax.get_legend_handles_labels()
    lines2 = ax2.get_legend_handles_labels()
    ax.legend(lines[0] + lines2[0], lines[1] + lines2[1], loc="center right", fontsize=9)
    top = ax.secondary_xaxis("top", functions=(
        lambda d: np.tan(np.radians(np.clip(d, 1e-3, 89.9))),
        lambda hb: np.degrees(np.arctan(hb))))
    top.set_xticks([1, 1.5, 2, 3, 4, 6, 10])
    top.set_xticklabels(["1", "1.5", "2", "3", "4", "6", "10"])
    top.set_xlabel("h/b")
    ax.set_title("Coefficient of restitution: Housner vs Mao et al.")
    return fig


# ---------------------------------------------------------------------------------------------
# Figure 2: one run
# ---------------------------------------------------------------------------------------------

def _window_start(result):
    if result.window is not None:
        return float(result.window[0])
    return round(0.8 * result.periods) * result.period


def _window_traj(result):
    """Trajectory rows of the asymptotic window; the whole run when the window is empty."""
    tr = result.trajectory
    w = tr[tr[:, 0] >= _window_start(result) - 1e-9]
    return (w, True) if w.shape[0] >= 2 else (tr, False)


def _need_traj(result):
    if result.trajectory is None or result.trajectory.shape[0] == 0:
        raise ValueError("the result has no trajectory: simulate with record_stride=...")


def _phase(ax, result, colour="k", label=None, strobe=True):
    w, in_window = _window_traj(result)
    ax.plot(w[:, 1], w[:, 2], lw=0.6, color=colour, label=label)
    if strobe and in_window:
        s = result.strobe
        k0 = int(round(_window_start(result) / result.period))
        s = s[k0:]
        if s.shape[0]:
            ax.plot(s[:, 0], s[:, 1], "o", ms=3.5, mfc="none", color="#d62728",
                    label="t = kT" if label is None else None)
    ax.set_xlabel("\u03b8")
    ax.set_ylabel("\u03b8\u2032")
    return in_window


def fig_trajectory(result, title=None):
    """Figure 2: ``θ(t)``, ``λ(t)`` and the phase portrait of the window for one run.

    ``result`` needs a trajectory (``record_stride``); ``λ(t)`` is drawn when the run computed
    Lyapunov exponents (``result.lyapunov_running`` at ``t = kT``).
    """
    _need_traj(result)
    tr = result.trajectory
    lam = result.lyapunov_running
    fig = _figure(figsize=(10.5, 6.0))
    gs = fig.add_gridspec(2, 2, width_ratios=(1.7, 1.0))
    ax_t = fig.add_subplot(gs[0, 0])
    ax_l = fig.add_subplot(gs[1, 0], sharex=ax_t)
    ax_p = fig.add_subplot(gs[:, 1])
    ax_t.plot(tr[:, 0], tr[:, 1], lw=0.5, color="k")
    ax_t.set_ylabel("\u03b8  [rad]")
    t_w = _window_start(result)
    for ax in (ax_t, ax_l):
        ax.axvspan(t_w, max(result.t, t_w), color="#1f77b4", alpha=0.08, lw=0)
    ax_t.set_title("\u03b8(t); shaded: the asymptotic window", fontsize=10)
    if lam is not None and lam.shape[0] > 1:
        k = np.arange(1, lam.shape[0])
        ax_l.plot(k * result.period, lam[1:, 0], color="#d62728", lw=1.0, label="\u03bb\u2081(t)")
        ax_l.axhline(0, color="0.5", lw=0.6)
        if result.lyapunov is not None and np.isfinite(result.lyapunov[0]):
            ax_l.axhline(result.lyapunov[0], color="#d62728", lw=0.8, ls="--",
                         label=f"\u03bb_max over the window = {result.lyapunov[0]:.4f}")
        ax_l.legend(fontsize=8, loc="upper right")
        ax_l.set_ylabel("\u03bb\u2081  (running estimate)")
    else:
        ax_l.text(0.5, 0.5, "Lyapunov exponents not computed", ha="center", va="center",
                  transform=ax_l.transAxes, color="0.4")
    ax_l.set_xlabel("t  (units of 1/\u03a9\u2080)")
    in_window = _phase(ax_p, result)
    ax_p.set_title("phase portrait, " + ("asymptotic window" if in_window else "whole run")
                   + "\n(circles: stroboscopic points t = kT)", fontsize=10)
    name, p = classify_result(result)
    beh = name + (f", period {p}" if name == "multiperiodic" else "")
    fig.suptitle(title or f"{_params(result)}: {beh} ({result.status})")
    return fig


# ---------------------------------------------------------------------------------------------
# Figure 3: behaviour gallery
# ---------------------------------------------------------------------------------------------

def fig_gallery(results, notes=None):
    """Figure 3: ``θ(t)`` and phase portrait of each run, titled with its behaviour.

    Parameters
    ----------
    results : dict of str -> Result
        Caption -> run (each with a trajectory), one column each.
    notes : dict of str -> str, optional
        Caption -> a note printed under that run's time series (e.g. an ensemble's outcome
        probabilities, for a run whose fate is decided by round-off).
    """
    if not results:
        raise ValueError("results must hold at least one run")
    n = len(results)
    fig = _figure(figsize=(3.6 * n, 6.2))
    axes = fig.subplots(2, n, squeeze=False)
    for c, (caption, res) in enumerate(results.items()):
        _need_traj(res)
        name, p = classify_result(res)
        colour = BEHAVIOUR_COLOURS[name]
        tr = res.trajectory
        ax = axes[0, c]
        ax.plot(tr[:, 0], tr[:, 1], lw=0.5, color=colour)
        ax.set_xlabel("t")
        if c == 0:
            ax.set_ylabel("\u03b8  [rad]")
        b, f = res.block, res.forcing
        beh = name + (f" (period {p})" if name == "multiperiodic" else "")
        ax.set_title(f"{caption}\n\u03b1={f.alpha:g}, \u03c9={f.omega:g}, h/b={b.hb:g}\n"
                     f"classified: {beh}", fontsize=9,
                     bbox=dict(boxstyle="round,pad=0.3", fc=colour, alpha=0.25, lw=0))
        if res.status == "overturned":
            ax.axhline(np.sign(tr[-1, 1]) * res.integration.theta_over, color="0.5", ls=":", lw=0.8)
        if notes and caption in notes:
            ax.text(0.02, 0.03, notes[caption], transform=ax.transAxes, fontsize=7,
                    va="bottom", bbox=dict(boxstyle="round,pad=0.3", fc="w", alpha=0.85,
                                           lw=0.5))
        in_window = _phase(axes[1, c], res, colour=colour)
        axes[1, c].set_title("window" if in_window else "whole run", fontsize=8)
    fig.suptitle(f"Behaviour gallery ({_law(next(iter(results.values())).block)})")
    return fig


# ---------------------------------------------------------------------------------------------
# Figure 4: Housner vs Mao time series
# ---------------------------------------------------------------------------------------------

def fig_laws_timeseries(runs, t_max=None):
    """Figure 4: the two laws from the same initial states.

    Parameters
    ----------
    runs : sequence of dict law -> Result
        One row per initial state; in each row the runs of each law (with trajectories).
    t_max : float, optional
        Show ``θ(t)`` up to this time only (default: the whole run).
    """
    runs = list(runs)
    if not runs:
        raise ValueError("runs must hold at least one initial state")
    fig = _figure(figsize=(11.0, 2.7 * len(runs) + 0.6))
    gs = fig.add_gridspec(len(runs), 2, width_ratios=(2.2, 1.0))
    for i, row in enumerate(runs):
        ax_t = fig.add_subplot(gs[i, 0])
        ax_p = fig.add_subplot(gs[i, 1])
        z = None
        for law, res in row.items():
            _need_traj(res)
            tr = res.trajectory
            if t_max is not None:
                tr = tr[tr[:, 0] <= t_max]
            colour = LAW_COLOURS.get(law, None)
            name, p = classify_result(res)
            beh = name + (f" {p}" if name == "multiperiodic" else "")
            lab = f"{_law(res.block)}: {beh}"
            ax_t.plot(tr[:, 0], tr[:, 1], lw=0.6, color=colour, label=lab, alpha=0.85)
            _phase(ax_p, res, colour=colour, strobe=False)
            z = tr[0, 1:3]
        ax_t.set_ylabel("\u03b8  [rad]")
        ax_t.legend(fontsize=8, loc="upper right")
        ax_t.set_title(f"(\u03b8\u2080, \u03b8\u2080\u2032) = ({z[0]:.4f}, {z[1]:.4f})",
                       fontsize=10, loc="left")
        ax_p.set_title("phase portrait: window (whole run if it overturned)", fontsize=9)
        if i == len(runs) - 1:
            ax_t.set_xlabel("t  (units of 1/\u03a9\u2080)")
    r0 = next(iter(runs[0].values()))
    b, f = r0.block, r0.forcing
    fig.suptitle(f"Housner vs Mao: h/b = {b.hb:g}, \u03b1 = {f.alpha:g}, \u03c9 = {f.omega:g}")
    return fig


# ---------------------------------------------------------------------------------------------
# Figure 5: bifurcation diagrams
# ---------------------------------------------------------------------------------------------

def _bifurcation_column(fig, gs_col, sw, alpha_limits, show_y):
    ax = fig.add_subplot(gs_col[0])
    ax_s = fig.add_subplot(gs_col[1], sharex=ax)
    ax_l = fig.add_subplot(gs_col[2], sharex=ax)
    alpha = np.asarray(sw.alpha)
    label = np.asarray(sw.label)
    sel = np.ones(alpha.shape, bool)
    if alpha_limits is not None:
        sel = (alpha >= alpha_limits[0] - 1e-12) & (alpha <= alpha_limits[1] + 1e-12)
    names = [str(n) for n in sw.names]
    pts = sw.strobe[:, :, 1]
    present = []
    for code, name in enumerate(names):
        m = sel & (label == code)
        if not m.any():
            continue
        present.append(name)
        a = np.repeat(alpha[m], pts.shape[1])
        y = pts[m].ravel()
        ok = np.isfinite(y)
        ax.scatter(a[ok], y[ok], s=0.6, color=BEHAVIOUR_COLOURS[name], lw=0, rasterized=True)
    ax.set_ylabel("\u03b8\u2032(kT)" if show_y else "")
    published = sw.settings.get("stop_at_overturn") is False
    ax.set_title(f"{_law(sw.block)}, h/b = {sw.block.hb:g}, \u03c9 = {sw.forcing.omega:g}"
                 + (" \u2014 as published: integrated past overturning" if published else ""),
                 fontsize=9 if published else 10)
    ax.tick_params(labelbottom=False)

    # a strip: the behaviour of every alpha, including those without stroboscopic points
    cmap, norm = _cmap()
    if alpha.size > 1:
        d = np.diff(alpha)
        edges = np.concatenate([[alpha[0] - d[0] / 2], alpha[:-1] + d / 2,
                                [alpha[-1] + d[-1] / 2]])
    else:
        edges = np.array([alpha[0] - 0.5e-3, alpha[0] + 0.5e-3])
    ax_s.pcolormesh(edges, [0, 1], label[None, :], cmap=cmap, norm=norm, rasterized=True)
    ax_s.set_yticks([])
    ax_s.set_ylabel("class" if show_y else "", rotation=0, ha="right", va="center",
                    fontsize=8)
    ax_s.tick_params(labelbottom=False)

    lam = np.asarray(sw.lambda_max, float)
    if np.isfinite(lam[sel]).any():
        fin = lam[sel & np.isfinite(lam)]
        lo, hi = float(fin.min()), float(fin.max())
        pad = 0.08 * max(hi - lo, 1e-3)
        lo, hi = min(lo, 0.0) - pad, max(hi, 0.0) + pad
    else:
        lo, hi = -1.0, 0.5
    ax_l.set_ylim(lo, hi)
    show = sel & ~np.isnan(lam)
    # a thin line through consecutive finite values, broken where there is none
    ax_l.plot(alpha[sel], np.where(np.isfinite(lam[sel]), lam[sel], np.nan), lw=0.5,
              color="0.6", zorder=1)
    any_rest = False
    for code, name in enumerate(names):
        m = show & (label == code)
        fin = m & np.isfinite(lam)
        ax_l.scatter(alpha[fin], lam[fin], s=4, color=BEHAVIOUR_COLOURS[name], lw=0, zorder=2)
        neg = m & np.isneginf(lam)
        if neg.any():  # rest: lambda = -inf, drawn at the panel's bottom
            any_rest = True
            ax_l.scatter(alpha[neg], np.full(neg.sum(), lo), marker="v", s=14,
                         color=BEHAVIOUR_COLOURS[name], zorder=3, clip_on=False)
    ax_l.axhline(0, color="k", lw=0.6)
    ax_l.set_xlabel("\u03b1")
    ax_l.set_ylabel("\u03bb_max" if show_y else "")
    if alpha_limits is not None:
        ax.set_xlim(*alpha_limits)
    elif alpha.size > 1:
        ax.set_xlim(edges[0], edges[-1])
    return present, any_rest


def fig_bifurcation(sweeps, alpha_limits=None, title=None):
    """Figure 5: stroboscopic ``θ'`` against ``α``, coloured by behaviour, ``λ_max`` below.

    Parameters
    ----------
    sweeps : SweepResult or dict of str -> SweepResult
        One sweep, or several drawn side by side (e.g. the two laws).
    alpha_limits : (float, float), optional
        Draw only this range of ``α`` (the zoom).
    title : str, optional

    Notes
    -----
    ``λ_max = -inf`` (rest) is drawn as a ``▼`` at the bottom of the lower panel; ``nan``
    (overturn, or not computed) is skipped. A thin strip between the panels gives the
    behaviour of every ``α``, including those with no stroboscopic points (rest, overturn).
    """
    if not isinstance(sweeps, dict):
        sweeps = {"": sweeps}
    if not sweeps:
        raise ValueError("sweeps must hold at least one sweep")
    if alpha_limits is not None:
        alpha_limits = tuple(float(v) for v in alpha_limits)
    n = len(sweeps)
    from matplotlib.lines import Line2D
    fig = _figure(figsize=(6.0 * n + 0.5, 6.6))
    gs = fig.add_gridspec(3, n, height_ratios=(2.4, 0.12, 1.0), hspace=0.02)
    present, any_rest = set(), False
    for c, sw in enumerate(sweeps.values()):
        got, rest = _bifurcation_column(fig, [gs[r, c] for r in range(3)], sw, alpha_limits, c == 0)
        present |= set(got)
        any_rest |= rest
    order = [nm for nm in BEHAVIOURS if nm in present]
    handles = _behaviour_handles(order, marker=True)
    if any_rest:
        handles.append(Line2D([], [], ls="", marker="v", ms=5, color=BEHAVIOUR_COLOURS["rest"],
                              label="\u03bb = \u2212\u221e (rest)"))
    fig.legend(handles=handles, loc="outside lower center", ncols=max(1, len(handles)),
               fontsize=9, frameon=False)
    if title:
        fig.suptitle(title)
    return fig


# ---------------------------------------------------------------------------------------------
# Figure 6: basins
# ---------------------------------------------------------------------------------------------

def _basin_axes(ax, b, show_y=True):
    cmap, norm = _cmap()
    # label[i, j] belongs to theta0[i], dtheta0[j]: rows of the image are dtheta0
    ax.imshow(np.asarray(b.label).T, origin="lower", cmap=cmap, norm=norm,
              interpolation="nearest", aspect="auto",
              extent=_extent(np.asarray(b.theta0), np.asarray(b.dtheta0)))
    ax.set_xlabel("\u03b8\u2080")
    if show_y:
        ax.set_ylabel("\u03b8\u2080\u2032")


def _basin_legend(ax, b):
    fr = fractions(b.label)
    names = [n for n in BEHAVIOURS if fr[n] > 0]
    ax.legend(handles=_behaviour_handles(names, [f"{n} {fr[n]:.1f} %" for n in names]),
              loc="upper center", bbox_to_anchor=(0.5, -0.14), ncols=2, fontsize=8,
              frameon=False)


def fig_basin(basin_result, title=None):
    """Figure 6 (one law): the behaviour of each ``(θ0, θ0')``, with percentages."""
    b = basin_result
    fig = _figure(figsize=(5.2, 5.6))
    ax = fig.add_subplot()
    _basin_axes(ax, b)
    _basin_legend(ax, b)
    ax.set_title(title or f"Basins: {_params(b)}", fontsize=10)
    return fig


def fig_basin_compare(housner_basin, mao_basin, title=None):
    """Figure 6: the basins under both laws and their point-wise agreement.

    The third panel shows where the two laws give the same behaviour; its title gives the
    agreement percentage.
    """
    from matplotlib.colors import ListedColormap
    from matplotlib.patches import Patch
    a, b = housner_basin, mao_basin
    if np.shape(a.label) != np.shape(b.label) or not (
            np.allclose(a.theta0, b.theta0) and np.allclose(a.dtheta0, b.dtheta0)):
        raise ValueError("the two basins must be computed on the same grid")
    agree = np.asarray(a.label) == np.asarray(b.label)
    pct = agreement(a.label, b.label)
    fig = _figure(figsize=(15.0, 5.8))
    axes = fig.subplots(1, 3, sharey=True)
    for i, res in enumerate((a, b)):
        _basin_axes(axes[i], res, show_y=i == 0)
        _basin_legend(axes[i], res)
        axes[i].set_title(_law(res.block), fontsize=11)
    axes[2].imshow(agree.T.astype(int), origin="lower", interpolation="nearest",
                   aspect="auto", cmap=ListedColormap(["#7b3294", "#e8e8e8"]), vmin=0, vmax=1,
                   extent=_extent(np.asarray(a.theta0), np.asarray(a.dtheta0)))
    axes[2].set_xlabel("\u03b8\u2080")
    axes[2].set_title(f"agreement: {pct:.1f} % of cells", fontsize=11)
    axes[2].legend(handles=[Patch(color="#e8e8e8", label=f"same behaviour {pct:.1f} %"),
                            Patch(color="#7b3294", label=f"different {100 - pct:.1f} %")],
                   loc="upper center", bbox_to_anchor=(0.5, -0.14), ncols=1, fontsize=8,
                   frameon=False)
    blk, frc = a.block, a.forcing
    fig.suptitle(title or f"Basins of attraction, h/b = {blk.hb:g}, \u03b1 = {frc.alpha:g}, "
                 f"\u03c9 = {frc.omega:g}, (r\u2080, s\u2080) = "
                 f"({a.settings.get('r0', 0):.4g}, {a.settings.get('s0', 1):.4g})")
    return fig


# ---------------------------------------------------------------------------------------------
# Attractors, integrity, erosion (issue 12)
# ---------------------------------------------------------------------------------------------

def _attractor_colours(n):
    """Distinct colours for attractor ids 0..n-1 (tab10, then tab20b/c)."""
    from matplotlib import colormaps
    base = list(colormaps["tab10"].colors) + list(colormaps["tab20b"].colors) + \
        list(colormaps["tab20c"].colors)
    return [base[i % len(base)] for i in range(n)]


def _attractor_panel(ax, ids, theta0, dtheta0, attractors, show_y=True):
    """The attractor map (``ids[i, j]`` of ``theta0[i], dtheta0[j]``) with each periodic
    attractor's cycle marked; returns the legend handles."""
    from matplotlib.colors import BoundaryNorm, ListedColormap
    from matplotlib.lines import Line2D
    from matplotlib.patches import Patch
    n = max(len(attractors), 1)
    colours = [BEHAVIOUR_COLOURS["unresolved"], BEHAVIOUR_COLOURS["overturn"]] + \
        _attractor_colours(n)
    cmap = ListedColormap(colours)
    norm = BoundaryNorm(np.arange(-2, n + 1) - 0.5, cmap.N)
    ax.imshow(np.asarray(ids).T, origin="lower", cmap=cmap, norm=norm, interpolation="nearest",
              aspect="auto", extent=_extent(np.asarray(theta0), np.asarray(dtheta0)))
    ax.set_xlabel("\u03b8\u2080")
    if show_y:
        ax.set_ylabel("\u03b8\u2080\u2032")
    handles = []
    for a, c in zip(attractors, colours[2:]):
        name = f"{a.id}: {a.behaviour}" + (f" p={a.period}" if a.period > 1 else "") + \
            f", {a.fraction:.1f} %"
        handles.append(Patch(color=c, label=name))
        if a.period:
            ax.plot(a.points[:, 0], a.points[:, 1], ls="", marker="*", ms=11, mfc=c, mec="k",
                    mew=0.8)
    over = 100.0 * np.mean(np.asarray(ids) == -1)
    if over:
        handles.append(Patch(color=colours[1], label=f"overturn, {over:.1f} %"))
    unres = 100.0 * np.mean(np.asarray(ids) == -2)
    if unres:
        handles.append(Patch(color=colours[0], label=f"unresolved, {unres:.1f} %"))
    handles.append(Line2D([], [], ls="", marker="*", ms=9, mfc="w", mec="k",
                          label="cycle points at t = kT"))
    return handles


def fig_attractors(basins, title=None):
    """Attractor maps of one or two basins (a dict ``law: BasinResult``, or one result), each
    with its basin entropy and integrity in the panel's title."""
    if not isinstance(basins, dict):
        basins = {basins.block.law: basins}
    fig = _figure(figsize=(6.4 * len(basins), 6.6))
    axes = np.atleast_1d(fig.subplots(1, len(basins), sharey=True))
    for i, (ax, b) in enumerate(zip(axes, basins.values())):
        handles = _attractor_panel(ax, b.attractor, b.theta0, b.dtheta0, b.attractors,
                                   show_y=i == 0)
        m = b.measures()
        ax.set_title(f"{_law(b.block)}: S_b = {m['basin_entropy']:.3f}, "
                     f"S_bb = {m['boundary_basin_entropy']:.3f}\n"
                     f"GIM = {m['integrity']['GIM']:.3f}, IF = {m['integrity']['IF']:.3f}",
                     fontsize=10)
        ax.legend(handles=handles, loc="upper center", bbox_to_anchor=(0.5, -0.12), ncols=2,
                  fontsize=7.5, frameon=False)
    b0 = next(iter(basins.values()))
    blk, frc = b0.block, b0.forcing
    fig.suptitle(title or f"Attractors, h/b = {blk.hb:g}, \u03b1 = {frc.alpha:g}, "
                 f"\u03c9 = {frc.omega:g}", fontsize=11)
    return fig


def fig_erosion(profiles, title=None):
    """Erosion profiles (a dict ``law: ErosionResult``, or one): GIM and IF against the
    amplitude for each law on top (the classic erosion profile), and below, for each law, the
    stacked basin fractions of its attractor branches (overturn on top, in grey)."""
    if not isinstance(profiles, dict):
        profiles = {profiles.block.law: profiles}
    fig = _figure(figsize=(10.0, 3.6 + 3.0 * len(profiles)))
    gs = fig.add_gridspec(1 + len(profiles), 1, height_ratios=[1.2] + [1] * len(profiles))
    ax = fig.add_subplot(gs[0])
    for law, r in profiles.items():
        c = LAW_COLOURS.get(law, "k")
        ax.plot(r.alpha, r.GIM, color=c, lw=1.8, label=f"GIM, {_law(r.block)}")
        ax.plot(r.alpha, r.IF, color=c, lw=1.4, ls="--", label=f"IF, {_law(r.block)}")
    ax.set_ylim(-0.02, 1.02)
    ax.set_ylabel("integrity")
    ax.legend(fontsize=8, ncols=2)
    ax.grid(alpha=0.3)
    for k, (law, r) in enumerate(profiles.items()):
        axk = fig.add_subplot(gs[1 + k], sharex=ax)
        fr = r.fractions()
        colours = _attractor_colours(len(r.branches))
        labels = [f"{b['id']}: {b['behaviour']}" + (f" p={b['period']}" if b["period"] > 1
                                                     else "") for b in r.branches]
        if len(fr):
            axk.stackplot(r.alpha, fr, colors=colours, labels=labels, lw=0)
        top = fr.sum(axis=0) if len(fr) else np.zeros_like(r.alpha)
        axk.fill_between(r.alpha, top, 100.0, color=BEHAVIOUR_COLOURS["overturn"], alpha=0.55,
                         lw=0, label="overturn / unresolved")
        axk.set_ylim(0, 100)
        axk.set_ylabel(f"{_law(r.block)}: % of cells")
        big = [i for i in np.argsort(-fr.max(axis=1))[:8]] if len(fr) else []
        handles, labs = axk.get_legend_handles_labels()
        keep = [j for j, lab in enumerate(labs) if lab == "overturn / unresolved" or
                any(lab == labels[i] for i in big)]
        axk.legend([handles[j] for j in keep], [labs[j] for j in keep], fontsize=7,
                   loc="center left", bbox_to_anchor=(1.0, 0.5), frameon=False)
    fig.axes[-1].set_xlabel("\u03b1")
    r0 = next(iter(profiles.values()))
    fig.suptitle(title or f"Erosion profiles, h/b = {r0.block.hb:g}, "
                 f"\u03c9 = {r0.forcing.omega:g}, {r0.attractor.shape[1]}\u00b2 cells per basin",
                 fontsize=11)
    return fig


def fig_fate(fate_result, title=None):
    """An ensemble of nearby runs: each outcome's probability, and when each member stopped
    against its initial perturbation, with the predictability horizon marked."""
    fr = fate_result
    fig = _figure(figsize=(11.0, 4.4))
    ax, ax_t = fig.subplots(1, 2, width_ratios=(1, 1.5))
    names = list(fr.probabilities)
    colours = [BEHAVIOUR_COLOURS.get(n.split()[0], "#7f7f7f") for n in names]
    ax.barh(range(len(names)), [fr.probabilities[n] for n in names], color=colours)
    ax.set_yticks(range(len(names)), names, fontsize=8)
    ax.set_xlim(0, 1)
    ax.set_xlabel("probability")
    d = np.abs(fr.initial - fr.initial[0]).max(axis=1)
    rel = d / max(np.abs(fr.initial[0]).max(), 1e-300)
    ok = rel > 0
    for v, c in zip(np.unique(fr.outcome), _attractor_colours(len(np.unique(fr.outcome)))):
        m = ok & (fr.outcome == v)
        lab = "overturn" if v == -1 else ("unresolved" if v == -2 else f"attractor {v}")
        ax_t.scatter(rel[m], fr.t_end[m], s=12, color=BEHAVIOUR_COLOURS["overturn"]
                     if v == -1 else c, label=lab)
    ax_t.set_xscale("log")
    ax_t.set_xlabel("initial perturbation (relative)")
    ax_t.set_ylabel("t at the end (overturn, rest, or the last period)")
    if np.isfinite(fr.horizon_rounding):
        ax_t.axhline(fr.horizon_rounding, color="k", ls="--", lw=0.8,
                     label=f"horizon of rounding t* = {fr.horizon_rounding:.0f}")
    ax_t.legend(fontsize=8)
    b, f = fr.block, fr.forcing
    fig.suptitle(title or f"Fates of {fr.outcome.size} nearby runs: {_law(b)}, h/b = {b.hb:g}, "
                 f"\u03b1 = {f.alpha:g}, \u03c9 = {f.omega:g}; \u03bb\u2081 of the "
                 f"transient {fr.lambda1:.3g}", fontsize=10)
    return fig


# ---------------------------------------------------------------------------------------------
# Parameter plane (rocking chart)
# ---------------------------------------------------------------------------------------------

def _extent(x, y):
    """``imshow`` extent of a grid over axes ``x, y``: half a cell beyond the end points (half
    a unit for an axis of one point, or of equal points, so the extent is never empty)."""
    def half(v):
        return (v[-1] - v[0]) / (len(v) - 1) / 2 if len(v) > 1 and v[-1] > v[0] else 0.5
    dx, dy = half(x), half(y)
    return (x[0] - dx, x[-1] + dx, y[0] - dy, y[-1] + dy)


def fig_plane(plane_result, state=0, title=None):
    """Behaviour over the forcing plane (omega across, alpha up) and lambda_max beside it.

    ``plane_result.label[state, i, j]`` belongs to ``alpha[i]``, ``omega[j]``.
    """
    p = plane_result
    lab = np.asarray(p.label)[state]
    lam = np.array(p.lambda_max, dtype=float)[state]
    ext = _extent(np.asarray(p.omega), np.asarray(p.alpha))
    cmap, norm = _cmap()
    fig = _figure(figsize=(11.5, 5.6))
    ax, axl = fig.subplots(1, 2, sharey=True)
    ax.imshow(lab, origin="lower", cmap=cmap, norm=norm, interpolation="nearest",
              aspect="auto", extent=ext)
    ax.set_xlabel("\u03c9")
    ax.set_ylabel("\u03b1")
    fr = fractions(lab)
    names = [n for n in BEHAVIOURS if fr[n] > 0]
    ax.legend(handles=_behaviour_handles(names, [f"{n} {fr[n]:.1f} %" for n in names]),
              loc="upper center", bbox_to_anchor=(0.5, -0.12), ncols=3, fontsize=8,
              frameon=False)
    finite = lam[np.isfinite(lam)]
    lim = max(float(np.abs(finite).max()), 1e-3) if finite.size else 1.0
    im = axl.imshow(np.where(np.isfinite(lam), lam, np.nan), origin="lower", cmap="RdBu_r",
                    vmin=-lim, vmax=lim, interpolation="nearest", aspect="auto", extent=ext)
    fig.colorbar(im, ax=axl, label="\u03bb\u2098\u2090\u2093 (blank: overturn, rest, not "
                 "computed)")
    axl.set_xlabel("\u03c9")
    z = np.asarray(p.z0)[state]
    fig.suptitle(title or f"{_law(p.block)}, h/b = {p.block.hb:g}, from (\u03b8, \u03b8\u2032,"
                 f" r, s) = ({z[0]:g}, {z[1]:g}, {z[2]:g}, {z[3]:g})", fontsize=11)
    return fig


# ---------------------------------------------------------------------------------------------
# Periodic-orbit branches (rockjit.orbits) over a sweep
# ---------------------------------------------------------------------------------------------

#: Marker of each bifurcation type in :func:`fig_branches`.
BIFURCATION_MARKERS = {"fold": "o", "symmetry_breaking": "D", "period_doubling": "s",
                       "neimark_sacker": "*", "grazing": "X"}
_BIF_SHORT = {"fold": "fold", "symmetry_breaking": "SB", "period_doubling": "PD",
              "neimark_sacker": "NS", "grazing": "graze"}


#: Colours of the periods of orbit branches (distinct from BEHAVIOUR_COLOURS).
PERIOD_COLOURS = ("#222222", "#8c564b", "#17becf", "#bcbd22", "#7f7f7f", "#393b79", "#ad494a",
                  "#637939")


def _branch_runs(value, y, stable, t_next, period):
    """Pieces ``(x, y, stable)`` of one branch line: broken where an impact crosses the
    sampling instant (the time to the next impact jumps by more than a quarter period, and the
    sampled point jumps) and where the stability changes (the point of change belongs to both
    pieces, so the line stays connected)."""
    n = value.shape[0]
    cut = np.zeros(n, bool)  # cut[i]: no line between i-1 and i
    if n > 1:
        jump = np.abs(np.diff(t_next)) > 0.25 * period[1:]
        cut[1:] = jump | ~np.isfinite(y[1:]) | ~np.isfinite(y[:-1])
    runs = []
    start = 0
    for i in range(1, n + 1):
        if i == n or cut[i] or stable[i] != stable[start]:
            stop = i if (i == n or cut[i]) else i + 1
            if stop - start >= 2 or (stop - start == 1 and (i == n or cut[i])):
                runs.append((value[start:stop], y[start:stop], bool(stable[start])))
            start = i
    return runs


def fig_branches(continuation, sweep=None, *, component=1, title=None, limits=None,
                 mirrors=True, max_listed=32):
    """Branches of periodic orbits drawn over a sweep's dots, bifurcations marked and listed.

    Parameters
    ----------
    continuation : rockjit.orbits.Continuation
        From :func:`rockjit.orbits.continue_branches` (or :func:`~rockjit.orbits.continuation`).
    sweep : SweepResult, optional
        Its stroboscopic points are drawn as dots coloured by behaviour; it must be sampled at
        the continuation's forcing phase (``continue_branches`` uses the sweep's).
    component : {0, 1}
        Draw ``theta`` (0) or ``theta'`` (1, the bifurcation diagrams' choice) at ``kT``.
    title : str, optional
    limits : (float, float), optional
        Parameter range drawn.
    mirrors : bool
        Also draw the mirror image ``-x(kT + T/2)`` of every non-symmetric orbit (the same
        multipliers; a sweep from one initial state shows one of the two).
    max_listed : int
        Bifurcations listed beside the plot (the rest are counted).

    Notes
    -----
    Stable orbits (both multipliers inside the unit circle) are solid lines, unstable ones
    dashed; one colour per period. The line of each cycle point breaks where an impact crosses
    the sampling instant ``kT``, where the sampled ``theta'`` jumps by the factor ``e``.
    Bifurcations are numbered in the list in order of the parameter.
    """
    from matplotlib.lines import Line2D

    c = continuation
    comp = int(component)
    if comp not in (0, 1):
        raise ValueError(f"component must be 0 (theta) or 1 (theta') (got {component!r})")
    pname = c.parameter
    sym = _GREEK.get(pname, pname)
    fig = _figure(figsize=(13.0, 6.4))
    gs = fig.add_gridspec(1, 2, width_ratios=(3.2, 1.25))
    ax = fig.add_subplot(gs[0])
    ax_l = fig.add_subplot(gs[1])
    ax_l.axis("off")
    handles = []
    if sweep is not None:
        alpha = np.asarray(sweep.alpha)
        label = np.asarray(sweep.label)
        pts = np.asarray(sweep.strobe)[:, :, comp]
        names = [str(n) for n in sweep.names]
        for code, name in enumerate(names):
            m = label == code
            if not m.any():
                continue
            a = np.repeat(alpha[m], pts.shape[1])
            yv = pts[m].ravel()
            ok = np.isfinite(yv)
            if not ok.any():
                continue
            ax.scatter(a[ok], yv[ok], s=1.6, color=BEHAVIOUR_COLOURS[name], lw=0, alpha=0.7,
                       rasterized=True, zorder=4)
            handles.append(Line2D([], [], ls="", marker="o", ms=4, alpha=0.7,
                                  color=BEHAVIOUR_COLOURS[name], label=f"sweep: {name}"))
    periods = sorted({br.period for br in c.branches})
    pcol = {p: PERIOD_COLOURS[i % len(PERIOD_COLOURS)] for i, p in enumerate(periods)}
    for br in c.branches:
        T = 2.0 * np.pi / np.asarray(br.omega)
        cycles = [(br.cycle, br.t_next_impact, 1.1)]
        if mirrors and br.mirror_cycle is not None:
            # the mirror orbit at kT is the orbit at kT + T/2, reflected
            cycles.append((br.mirror_cycle, br.t_next_impact_half, 0.8))
        for cyc, tn, lw in cycles:
            for k in range(br.period):
                for x, yv, st in _branch_runs(np.asarray(br.value), cyc[:, k, comp],
                                              np.asarray(br.stable), tn[:, k], T):
                    ax.plot(x, yv, ls="-" if st else (0, (4, 2.5)), lw=lw,
                            color=pcol[br.period], zorder=3)
    for p in periods:
        handles.append(Line2D([], [], color=pcol[p], lw=1.5, label=f"period {p}"))
    handles.append(Line2D([], [], color="k", lw=1.3, ls="-", label="stable"))
    handles.append(Line2D([], [], color="k", lw=1.3, ls="--", label="unstable"))
    bifs = sorted(c.bifurcations, key=lambda b: b.value)
    present = []
    for i, bf in enumerate(bifs):
        mk = BIFURCATION_MARKERS.get(bf.type, "o")
        cyc = np.asarray(bf.cycle)
        pts_b = [cyc]
        if mirrors and bf.has_mirror and getattr(bf, "cycle_half", None) is not None:
            pts_b.append(-np.asarray(bf.cycle_half))
        for cy in pts_b:
            ax.scatter(np.full(cy.shape[0], bf.value), cy[:, comp], marker=mk,
                       s=40 if bf.period <= 2 else 18, facecolor="white", edgecolor="k",
                       lw=1.0, zorder=5)
        ax.annotate(str(i + 1), (bf.value, cyc[0, comp]), textcoords="offset points",
                    xytext=(4, 4), fontsize=7, zorder=6)
        if bf.type not in present:
            present.append(bf.type)
    for t in present:
        handles.append(Line2D([], [], ls="", marker=BIFURCATION_MARKERS.get(t, "o"), ms=6,
                              markerfacecolor="white", markeredgecolor="k",
                              label=t.replace("_", " ")))
    ax.set_xlabel(sym)
    ax.set_ylabel("\u03b8\u2032(kT)" if comp == 1 else "\u03b8(kT)")
    xlim = tuple(float(v) for v in (limits if limits is not None else c.bounds))
    ax.set_xlim(*xlim)
    if limits is not None:  # fit the vertical range to what is drawn in the window
        ys = []
        for line in ax.get_lines():
            x, yv = (np.asarray(v, float) for v in line.get_data())
            ys.append(yv[(x >= xlim[0]) & (x <= xlim[1])])
        for coll in ax.collections:
            off = np.asarray(coll.get_offsets(), float).reshape(-1, 2)
            ys.append(off[(off[:, 0] >= xlim[0]) & (off[:, 0] <= xlim[1]), 1])
        ys = np.concatenate(ys) if ys else np.zeros(0)
        ys = ys[np.isfinite(ys)]
        if ys.size:
            lo, hi = float(ys.min()), float(ys.max())
            pad = 0.05 * max(hi - lo, 1e-3)
            ax.set_ylim(lo - pad, hi + pad)
    ax.legend(handles=handles, loc="best", fontsize=7, ncols=2, framealpha=0.85)
    lines = [f"{'#':>2}  {'type':<6} {sym:<12} {'p':<2} \u03bc1, \u03bc2"]
    for i, bf in enumerate(bifs[:max_listed]):
        mu = [f"{m.real:.4g}" if abs(m.imag) < 1e-12 else f"{m.real:.3g}{m.imag:+.3g}i"
              for m in np.asarray(bf.multipliers)]
        lines.append(f"{i + 1:>2}  {_BIF_SHORT.get(bf.type, bf.type):<6} "
                     f"{bf.value:<12.9f} {bf.period:<2} {', '.join(mu)}")
    if len(bifs) > max_listed:
        lines.append(f"... and {len(bifs) - max_listed} more")
    if not bifs:
        lines.append("(no bifurcation located)")
    ax_l.text(0.0, 1.0, "\n".join(lines), va="top", ha="left", family="monospace",
              fontsize=7.5, transform=ax_l.transAxes)
    b, f = c.block, c.forcing
    fixed = (f"\u03c9 = {f.omega:g}" if pname == "alpha" else f"\u03b1 = {f.alpha:g}")
    ax.set_title(title or f"Periodic orbits: {_law(b)}, h/b = {b.hb:g}, {fixed}, "
                 f"phase {c.phase:.4g}", fontsize=10)
    return fig
