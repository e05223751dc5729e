"""The study's figures (docs/theory/study.md, "The figures"), one function each.

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
"""

from __future__ import annotations

import math
import re

import numpy as np

from ..model import delta_e_percent, e_housner, e_mao, thc_from_hb
from ..result import BEHAVIOURS, fractions
from . import cells
from . import style as S
from .style import AGREE_COLOUR, BEHAVIOUR_COLOURS, DISAGREE_COLOUR, LAW_LINES, SYMBOLS

__all__ = ["BEHAVIOUR_COLOURS", "BIFURCATION_MARKERS", "END_MARKERS", "branch_caption",
           "fig_attractors", "fig_basin", "fig_basin_compare", "fig_bifurcation",
           "fig_branches", "fig_erosion", "fig_fate", "fig_gallery", "fig_laws_timeseries",
           "fig_plane", "fig_restitution", "fig_trajectory"]

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


def _behaviour_words(behaviour):
    """``(name, period)`` in words: ``symmetric``, ``period-2``, ..."""
    name, p = behaviour
    if name == "multiperiodic":
        return f"period-{p} (multiperiodic)"
    if name in ("symmetric", "asymmetric"):
        return f"{name}, $p = {p}$"
    return name


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


# ---------------------------------------------------------------------------------------------
# Figure 1: restitution laws
# ---------------------------------------------------------------------------------------------

@S.styled
def fig_restitution(hb_range=(1.0 / math.sqrt(2.0), 6.0), n=400, marks=(1.0, 2.0)):
    """Figure 1: ``e_H`` and ``e_M`` against ``theta_c``, with ``Delta e %`` on a twin axis.

    Parameters
    ----------
    hb_range : (float, float)
        Slenderness range; the Housner law needs ``hb >= 1/sqrt(2)``.
    n : int
        Number of points.
    marks : sequence of float
        Slenderness values marked, with their values in boxes below the curves.
    """
    lo, hi = (float(v) for v in hb_range)
    if not 1.0 / math.sqrt(2.0) - 1e-12 <= lo < hi:
        raise ValueError(f"hb_range must satisfy 1/sqrt(2) <= start < end (got {lo}, {hi})")
    thc = np.linspace(thc_from_hb(lo), thc_from_hb(hi), n)
    eh, em = e_housner(thc), e_mao(thc)
    de = delta_e_percent(em, eh)
    fig = S.figure("single", 0.95, pad=PAD)
    ax = fig.add_subplot()
    deg = np.degrees(thc)
    ax.plot(deg, eh, color="k", ls=LAW_LINES["housner"]["ls"], lw=1.5,
            label=r"$e_H$, Housner (1963)")
    ax.plot(deg, em, color="k", ls=LAW_LINES["mao"]["ls"], lw=1.5,
            label=r"$e_M$, Mao et al. (2024)")
    ax.set_xlabel(r"$\theta_c = \arctan(h/b)$  [degrees]")
    ax.set_ylabel(r"coefficient of restitution $e$")
    # room above the curves for the values at the marked slendernesses
    ax.set_ylim(0, 1.4)
    ax.set_yticks(np.linspace(0, 1, 6))
    ax2 = ax.twinx()
    ax2.plot(deg, de, color="0.55", ls=":", lw=1.5, label=r"$\Delta e$ (right axis)")
    ax2.set_ylabel(r"$\Delta e$  [%]")
    top_de = max(1.0, float(np.nanmax(de)))
    ax2.set_ylim(0, top_de * 1.4)
    from matplotlib.ticker import MaxNLocator
    ax2.set_yticks([v for v in MaxNLocator(5).tick_values(0, top_de) if v <= top_de * 1.001])
    # the values at the marked slendernesses: the points on the curves, each line marked by
    # its h/b on the top axis, and the values in one box in the empty lower right
    rows = []
    for hb in marks:
        t = float(thc_from_hb(hb))
        h, m = float(e_housner(t)), float(e_mao(t))
        x = np.degrees(t)
        ax.axvline(x, color="0.75", lw=0.8, ls="-", zorder=0)
        ax.plot([x, x], [h, m], "o", color="k", ms=3, zorder=5)
        rows.append(f"$h/b = {hb:g}$: $e_H = {h:.3f}$, $e_M = {m:.3f}$, "
                    f"$\\Delta e = {float(delta_e_percent(m, h)):.2f}$ %")
    if rows:
        ax.text(0.97, 0.97, "\n".join(rows), transform=ax.transAxes, ha="right", va="top",
                fontsize=7, zorder=6,
                bbox=dict(boxstyle="round,pad=0.25", fc="white", ec="0.75", lw=0.6))
    lines = ax.get_legend_handles_labels()
    lines2 = ax2.get_legend_handles_labels()
    fig.legend(lines[0] + lines2[0], lines[1] + lines2[1], loc="outside lower center",
               ncols=2)
    top = ax.secondary_xaxis("top", functions=(
        lambda d: np.tan(np.radians(np.clip(d, 1e-3, 89.9))),
        lambda hb: np.degrees(np.arctan(hb))))
    top.set_xticks([1, 1.5, 2, 3, 4, 6])
    top.set_xticklabels(["1", "1.5", "2", "3", "4", "6"])
    top.set_xlabel(r"$h/b$")
    S.suptitle(fig, "Coefficient of restitution: Housner against Mao et al.")
    return fig


# ---------------------------------------------------------------------------------------------
# time series: windows of a run, impacts as vertical jumps
# ---------------------------------------------------------------------------------------------

def _wrap(text, fig, fraction=0.95):
    """``text`` broken into lines that fit ``fraction`` of the figure's width (at the style's
    font size, about half an em a character; mathtext counted as it is drawn, and never
    broken)."""
    import matplotlib
    size = matplotlib.rcParams["font.size"]
    per_line = max(20, int(fig.get_figwidth() * fraction * 72 / (0.55 * size)))

    def drawn(w):
        return len(re.sub(r"\$[^$]*\$", lambda m: "x" * max(1, len(m.group()) // 2), w))

    out = []
    for para in text.split("\n"):
        # words, a piece of mathtext with what is glued to it being one word
        words = re.findall(r"(?:[^\s$]*\$[^$]*\$)+[^\s$]*|\S+", para)
        line, n = [], 0
        for w in words:
            k = drawn(w) + 1
            if line and n + k > per_line:
                out.append(" ".join(line))
                line, n = [], 0
            line.append(w)
            n += k
        out.append(" ".join(line))
    return "\n".join(out)


def _need_traj(result):
    if result.trajectory is None or result.trajectory.shape[0] == 0:
        raise ValueError("the result has no trajectory: simulate with record_stride=...")


def _window_start(result):
    if result.window is not None:
        return float(result.window[0])
    return round(0.8 * result.periods) * result.period


def with_impacts(result, t0=-math.inf, t1=math.inf):
    """``(t, theta, theta')`` of the recorded trajectory within ``[t0, t1]`` with every impact
    inserted as two points at ``theta = 0``, ``theta'-`` then ``theta'+``: a line through them
    draws the impact as the vertical jump it is, not as a slanted chord between samples."""
    tr = result.trajectory
    keep = (tr[:, 0] >= t0) & (tr[:, 0] <= t1)
    t, th, dth = tr[keep, 0], tr[keep, 1], tr[keep, 2]
    imp = np.asarray(result.impacts).reshape(-1, 3)
    imp = imp[(imp[:, 0] >= t0) & (imp[:, 0] <= t1)]
    if imp.shape[0] == 0:
        return t, th, dth
    ti = np.repeat(imp[:, 0], 2)
    thi = np.zeros(ti.size)
    dthi = np.column_stack([imp[:, 1], imp[:, 2]]).ravel()
    order = np.concatenate([np.zeros(t.size), np.tile([1.0, 2.0], imp.shape[0])])
    tt = np.concatenate([t, ti])
    idx = np.lexsort((order, tt))
    return tt[idx], np.concatenate([th, thi])[idx], np.concatenate([dth, dthi])[idx]


def _time_panel(ax, result, t0, t1, colour, **kw):
    t, th, _ = with_impacts(result, t0, t1)
    ax.plot(t, th, color=colour, lw=kw.pop("lw", 1.0), **kw)
    ax.axhline(0, color="0.8", lw=0.5, zorder=0)
    ax.set_xlim(t0, t1)


def _phase_panel(ax, result, colour, strobe=True, whole=False, label=None):
    """The phase portrait of the asymptotic window (the whole run when it ended before the
    window, or when ``whole``), impacts as vertical jumps, the stroboscopic points circled.
    Returns whether the window was drawn."""
    t_w = _window_start(result)
    in_window = not whole and result.t > t_w + result.period
    t0 = t_w if in_window else -math.inf
    _, th, dth = with_impacts(result, t0)
    ax.plot(th, dth, color=colour, lw=0.9, label=label)
    if strobe:
        k0 = int(round(t_w / result.period)) if in_window else 0
        s = result.strobe[k0:]
        if s.shape[0]:
            ax.plot(s[:, 0], s[:, 1], "o", ms=4, mfc="none", mec="k", mew=0.8,
                    label=r"$t = kT$")
    ax.set_xlabel(SYMBOLS["theta_unit"])
    ax.set_ylabel(SYMBOLS["dtheta_unit"])
    return in_window


def _mark_end(ax, result):
    """A run that overturned: the threshold, and a marker where it fell."""
    if result.status == "overturned":
        over = result.integration.theta_over
        sign = np.sign(result.state[0]) or 1.0
        ax.axhline(sign * over, color=BEHAVIOUR_COLOURS["overturn"], ls=":", lw=0.8)
        ax.plot([result.t], [sign * over], marker="v" if sign < 0 else "^", ms=6,
                color=BEHAVIOUR_COLOURS["overturn"], ls="")
    elif result.status == "rest":
        ax.plot([result.t], [0.0], marker="o", ms=5, color=LINE_COLOURS["rest"], ls="")


def _rest_inset(ax, result, colour):
    """An inset of a run that came to rest: the speed before each of its impacts,
    ``|theta'-|``, on a log scale against the impact's number (each impact keeps ``e`` of the
    speed, so the rocking decays too fast to see at the fall's scale: on a log scale every
    impact shows), in the empty upper right of the panel, joined to nothing."""
    imp = np.asarray(result.impacts).reshape(-1, 3)
    speed = np.abs(imp[:, 1])
    keep = speed > 0
    if np.count_nonzero(keep) < 2:
        return
    k = np.arange(1, imp.shape[0] + 1)[keep]
    ins = ax.inset_axes([0.72, 0.45, 0.2, 0.28])
    ins.plot(k, speed[keep], "o-", color=colour, ms=2.5, lw=0.8)
    ins.set_yscale("log")
    ins.set_xlim(0.5, imp.shape[0] + 0.5)
    ins.tick_params(labelsize=7)
    ins.yaxis.tick_right()  # the labels away from the falling curve on the left
    ins.xaxis.get_major_locator().set_params(integer=True)
    ins.set_title(f"$|\\theta'^-|$ at impacts 1 to {imp.shape[0]}", fontsize=7)


def _windows(result, first, last):
    """``[(t0, t1, what)]``: the first ``first`` periods and the last ``last`` periods of the
    run, or the whole run as one window when it is not longer than both."""
    T = result.period
    if result.t <= (first + last + 1) * T:
        return [(0.0, max(result.t, T * 1e-3), "whole run")]
    return [(0.0, first * T, f"first {first} periods"),
            (result.t - last * T, result.t, f"last {last} periods")]


# ---------------------------------------------------------------------------------------------
# Figure 2: one run
# ---------------------------------------------------------------------------------------------

@S.styled
def fig_trajectory(result, behaviour, *, exponent=None, title=None, first=8, last=4):
    """Figure 2: ``theta(t)`` over the transient's first periods and over the last periods,
    the running exponent ``lambda_1(t)``, and the phase portrait of the asymptotic window with
    its stroboscopic points, impacts drawn as vertical jumps.

    Parameters
    ----------
    result : Result
        A run with a trajectory (``record_stride``); ``lambda_1(t)`` is drawn when it computed
        exponents.
    behaviour : (str, int)
        Its behaviour and period (``rockjit.classify_result(result)``): the lines' colour.
    exponent : float, optional
        The exact exponent of the orbit it settled on (the Floquet exponent), drawn beside the
        window's estimate.
    first, last : int
        Periods shown at the start and at the end.
    """
    _need_traj(result)
    colour = LINE_COLOURS[behaviour[0]]
    lam = result.lyapunov_running
    fig = S.figure("double", 0.52, pad=PAD)
    gs = fig.add_gridspec(2, 3, width_ratios=(1.5, 1.0, 1.25))
    wins = _windows(result, first, last)
    axes_t = []
    if len(wins) == 1:
        axes_t.append(fig.add_subplot(gs[0, :2]))
    else:
        axes_t.append(fig.add_subplot(gs[0, 0]))
        axes_t.append(fig.add_subplot(gs[0, 1], sharey=axes_t[0]))
    for i, (ax, (t0, t1, what)) in enumerate(zip(axes_t, wins)):
        _time_panel(ax, result, t0, t1, colour)
        _mark_end(ax, result)
        ax.set_xlabel(SYMBOLS["t_unit"])
        S.letter(ax, i, what)
    axes_t[0].set_ylabel(SYMBOLS["theta_unit"])
    ax_l = fig.add_subplot(gs[1, :2])
    fig_legend = None
    if lam is not None and lam.shape[0] > 1:
        k = np.arange(1, lam.shape[0])
        ax_l.plot(k * result.period, lam[1:, 0], color="k", lw=1.0,
                  label=r"running $\lambda_1(t)$ from $t = 0$")
        ax_l.axhline(0, color="0.6", lw=0.6)
        t_w = _window_start(result)
        if result.t > t_w:
            ax_l.axvspan(t_w, result.t, color="0.88", lw=0, zorder=0)
        if result.lyapunov is not None and np.isfinite(result.lyapunov[0]):
            ax_l.axhline(result.lyapunov[0], color=colour, lw=1.0, ls="--",
                         label=f"$\\lambda_\\mathrm{{max}}$ over the window "
                               f"$= {result.lyapunov[0]:.4f}$")
        if exponent is not None and np.isfinite(exponent):
            ax_l.axhline(exponent, color=colour, lw=1.0, ls=":",
                         label=f"Floquet exponent of the orbit $= {exponent:.4f}$")
        fin = lam[1:, 0][np.isfinite(lam[1:, 0])]
        if fin.size:  # the estimate's range, with room for the legend above it
            lo, hi = float(fin.min()), float(fin.max())
            span = max(hi - lo, 0.05 * max(abs(lo), abs(hi), 1e-3))
            ax_l.set_ylim(lo - 0.1 * span, hi + 0.1 * span)
        hs, ls_ = ax_l.get_legend_handles_labels()
        if result.t > t_w:
            from matplotlib.patches import Patch
            hs.append(Patch(facecolor="0.88", edgecolor="0.6", lw=0.5))
            ls_.append("asymptotic window")
        fig_legend = (hs, ls_)
        ax_l.set_ylabel(r"$\lambda_1$")
        ax_l.set_xlim(0, result.t)
    else:
        ax_l.text(0.5, 0.5, "Lyapunov exponents not computed", ha="center", va="center",
                  transform=ax_l.transAxes, color="0.4")
    ax_l.set_xlabel(SYMBOLS["t_unit"])
    S.letter(ax_l, len(axes_t), "running largest Lyapunov exponent")
    ax_p = fig.add_subplot(gs[:, 2])
    in_window = _phase_panel(ax_p, result, colour)
    S.letter(ax_p, len(axes_t) + 1, "phase portrait,\n" + ("asymptotic window" if in_window
                                                            else "whole run"))
    hp, lp = ax_p.get_legend_handles_labels()
    if fig_legend is not None:  # one legend below the figure, off the data
        fig.legend(fig_legend[0] + hp, fig_legend[1] + lp, loc="outside lower center",
                   ncols=3)
    elif hp:
        fig.legend(hp, lp, loc="outside lower center")
    S.suptitle(fig, title or f"{_params(result)}: {_behaviour_words(behaviour)}")
    return fig


# ---------------------------------------------------------------------------------------------
# Figure 3: behaviour gallery
# ---------------------------------------------------------------------------------------------

@S.styled
def fig_gallery(results, behaviours, notes=None, *, first=8, last=4):
    """Figure 3: one row per run: ``theta(t)`` over its first and its last periods (the whole
    run when it is short) and its phase portrait, coloured by its behaviour.

    Parameters
    ----------
    results : dict of str -> Result
        Caption -> run (each with a trajectory), one row each, lettered a), b), ...
    behaviours : dict of str -> (str, int)
        Caption -> the run's behaviour and period.
    notes : dict of str -> str, optional
        Caption -> a line printed with that run's title (e.g. an ensemble's outcome
        probabilities, for a run whose fate is decided by round-off).
    """
    if not results:
        raise ValueError("results must hold at least one run")
    n = len(results)
    fig = S.figure("double", 0.25 * n + 0.08, pad=PAD)
    subs = np.atleast_1d(fig.subfigures(n, 1))
    for r, ((caption, res), sub) in enumerate(zip(results.items(), subs)):
        _need_traj(res)
        beh = behaviours[caption]
        colour = LINE_COLOURS[beh[0]]
        gs = sub.add_gridspec(1, 3, width_ratios=(1.5, 1.0, 0.9))
        wins = _windows(res, first, last)
        if len(wins) == 1:
            axes = [sub.add_subplot(gs[0, :2])]
        else:
            axes = [sub.add_subplot(gs[0, 0])]
            axes.append(sub.add_subplot(gs[0, 1], sharey=axes[0]))
        for ax, (t0, t1, what) in zip(axes, wins):
            _time_panel(ax, res, t0, t1, colour)
            _mark_end(ax, res)
            ax.text(0.99, 0.97, what, transform=ax.transAxes, ha="right", va="top",
                    fontsize=7, color="0.35",
                    bbox=dict(fc="white", ec="none", alpha=0.8, pad=1.0))
            if r == n - 1:
                ax.set_xlabel(SYMBOLS["t_unit"])
        axes[0].set_ylabel(SYMBOLS["theta_unit"])
        b, f = res.block, res.forcing
        what = (f"overturns at $t = {res.t:.5g}$" if res.status == "overturned" else
                f"at rest from $t = {res.t:.3g}$" if res.status == "rest" else
                _behaviour_words(beh))
        head = (f"{'abcdefghijklmnopqrstuvwxyz'[r]}) {caption}: $\\alpha = {f.alpha:g}$, "
                f"$\\omega = {f.omega:g}$, $h/b = {b.hb:g}$ $\\rightarrow$ {what}")
        if notes and caption in notes:
            head += "\n" + notes[caption]
        sub.suptitle(_wrap(head, fig), x=0.01, ha="left", fontsize="medium")
        if res.status == "rest":
            _rest_inset(axes[0], res, colour)
        ax_p = sub.add_subplot(gs[0, 2])
        _phase_panel(ax_p, res, colour)
        if r != n - 1:
            ax_p.set_xlabel("")
    S.suptitle(fig, f"Behaviour gallery ({S.law_name(next(iter(results.values())).block)}): "
                    "time series and phase portraits (impacts as vertical jumps, "
                    "circles at $t = kT$)")
    return fig


# ---------------------------------------------------------------------------------------------
# Figure 4: Housner vs Mao time series
# ---------------------------------------------------------------------------------------------

@S.styled
def fig_laws_timeseries(runs, behaviours, *, periods=8):
    """Figure 4: the two laws from the same initial states, one row per initial state: each
    law's ``theta(t)`` over the last ``periods`` periods of its run, where it has settled (the
    whole run when it overturns or comes to rest sooner), one above the other so that neither
    hides the other, and its phase portrait, each run in its behaviour's colour. What each run
    does is said in its phase portrait's title; the figure's caption belongs outside the
    image.

    Parameters
    ----------
    runs : sequence of dict law -> Result
        One row per initial state; in each row the runs of each law (with trajectories).
    behaviours : sequence of dict law -> (str, int)
        Each run's behaviour and period.
    periods : int
        Forcing periods of ``theta(t)`` shown.
    """
    runs = list(runs)
    if not runs:
        raise ValueError("runs must hold at least one initial state")
    n = len(runs)
    fig = S.figure("double", 0.27 * n + 0.04, pad=PAD)
    subs = np.atleast_1d(fig.subfigures(n, 1))
    for i, (row, sub) in enumerate(zip(runs, subs)):
        laws = list(row)
        gs = sub.add_gridspec(len(laws), 1 + len(laws), width_ratios=(2.4,) + (1.0,) * len(laws))
        z = None
        ax_first = None
        for k, law in enumerate(laws):
            res = row[law]
            _need_traj(res)
            beh = behaviours[i][law]
            colour = LINE_COLOURS[beh[0]]
            ax = sub.add_subplot(gs[k, 0])
            ax_first = ax_first or ax
            T = res.period
            settled = res.status not in ("overturned", "rest") and res.t > (periods + 1) * T
            t0, t1 = (res.t - periods * T, res.t) if settled else (0.0, max(res.t, 1e-3 * T))
            _time_panel(ax, res, t0, t1, colour)
            _mark_end(ax, res)
            ax.text(0.99, 0.95, f"last {periods} periods" if settled else "whole run",
                    transform=ax.transAxes, ha="right", va="top", fontsize=7, color="0.35",
                    bbox=dict(fc="white", ec="none", alpha=0.8, pad=1.0))
            ax.set_ylabel(f"{S.law_name(res.block)}\n" + SYMBOLS["theta_unit"])
            if k == len(laws) - 1:
                ax.set_xlabel(SYMBOLS["t_unit"])
            ax_p = sub.add_subplot(gs[:, 1 + k])
            _phase_panel(ax_p, res, colour, strobe=False)
            what = _behaviour_words(beh)
            if res.status == "overturned":
                what = f"overturns at $t = {res.t:.3g}$"
            elif res.status == "rest":
                what = f"at rest from $t = {res.t:.3g}$"
            ax_p.set_title(f"{S.law_name(res.block)}:\n{what}", fontsize=7)
            if k:
                ax_p.set_ylabel("")
            z = res.trajectory[0, 1:3]
        S.letter(ax_first, i, f"from $(\\theta_0, \\theta'_0) = ({z[0]:.4f}, {z[1]:.4f})$")
    r0 = next(iter(runs[0].values()))
    b, f = r0.block, r0.forcing
    S.suptitle(fig, f"Housner against Mao et al. in time: $h/b = {b.hb:g}$, "
                    f"$\\alpha = {f.alpha:g}$, $\\omega = {f.omega:g}$, "
                    f"$(r_0, s_0) = (0, 1)$")
    return fig


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


# ---------------------------------------------------------------------------------------------
# an ensemble's fates
# ---------------------------------------------------------------------------------------------

_OUTCOME = re.compile(r"^(?P<b>[a-z]+)(?: p=(?P<p>\d+))?(?: \([a-z]+\))?$")


def _outcome_names(keys):
    """An ensemble's outcome keys (``"multiperiodic p=7"``) in words (``"period-7"``)."""
    items = []
    for k in keys:
        m = _OUTCOME.match(k)
        items.append(dict(behaviour=m["b"], period=int(m["p"] or 0), multipliers=None) if m
                     else dict(behaviour=k, period=0, multipliers=None))
    return dict(zip(keys, S.attractor_names(items))), {k: it["behaviour"]
                                                         for k, it in zip(keys, items)}


@S.styled
def fig_fate(fate_result, title=None):
    """An ensemble of nearby runs: each outcome's probability, and when each member stopped
    against its initial perturbation, with the predictability horizon marked."""
    fr = fate_result
    fig = S.figure("double", 0.4, pad=PAD)
    ax, ax_t = fig.subplots(1, 2, width_ratios=(1, 1.5))
    keys = list(fr.probabilities)
    words, behs = _outcome_names(keys)
    colours = dict(zip(keys, S.attractor_colours([dict(behaviour=behs[k]) for k in keys])))
    ax.barh(range(len(keys)), [fr.probabilities[k] for k in keys],
            color=[colours[k] for k in keys], edgecolor="0.4", lw=0.5)
    ax.set_yticks(range(len(keys)), [words[k] for k in keys])
    ax.set_xlim(0, 1)
    ax.set_xlabel("probability")
    S.letter(ax, 0, "outcomes")
    d = np.abs(fr.initial - fr.initial[0]).max(axis=1)
    rel = d / max(np.abs(fr.initial[0]).max(), 1e-300)
    ok = rel > 0
    by_id = {v: k for k, v in fr.ids.items()}
    for v in np.unique(fr.outcome):
        key = by_id.get(int(v))
        m = ok & (fr.outcome == v)
        ax_t.scatter(rel[m], fr.t_end[m], s=14, color=colours.get(key, "0.5"),
                     edgecolor="0.3", lw=0.3, label=words.get(key, "other"))
    ax_t.set_xscale("log")
    ax_t.set_xlabel("initial perturbation (relative)")
    ax_t.set_ylabel(r"$t$ at the end (overturn, rest, or the last period)")
    if np.isfinite(fr.horizon_rounding):
        ax_t.axhline(fr.horizon_rounding, color="k", ls="--", lw=0.8,
                     label=f"horizon of rounding $t^* = {fr.horizon_rounding:.0f}$")
    ax_t.legend(loc="best")
    S.letter(ax_t, 1, "when each member's run ended")
    b, f = fr.block, fr.forcing
    S.suptitle(fig, title or f"Fates of {fr.outcome.size} nearby runs: {S.law_name(b)}, "
                             f"$h/b = {b.hb:g}$, $\\alpha = {f.alpha:g}$, "
                             f"$\\omega = {f.omega:g}$; $\\lambda_1$ of the transient "
                             f"${fr.lambda1:.3g}$")
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


# ---------------------------------------------------------------------------------------------
# Periodic-orbit branches (rockjit.orbits) over a sweep
# ---------------------------------------------------------------------------------------------

#: Marker of each bifurcation type in :func:`fig_branches`.
BIFURCATION_MARKERS = {"fold": "o", "symmetry_breaking": "D", "period_doubling": "s",
                       "neimark_sacker": "*", "grazing": "X"}
_BIF_WORDS = {"fold": "fold", "symmetry_breaking": "symmetry-breaking pitchfork",
              "period_doubling": "period doubling", "neimark_sacker": "Neimark-Sacker",
              "grazing": "grazing"}
#: Where a branch stops, and why: its marker and words (ends at the range, on joining a branch,
#: at a branch point or closing a loop are not marked: the line goes on, or the range ends).
END_MARKERS = {"overturn": ("^", "branch ends: the block overturns"),
               "rest": ("v", "branch ends: the block comes to rest"),
               "passes_through_rest": ("v", "branch ends: the block comes to rest"),
               "grazing": ("|", "branch ends: an impact grazes"),
               "no_convergence": ("x", "branch ends: no convergence"),
               "max_impacts": ("x", "branch ends: no convergence"),
               "nonfinite": ("x", "branch ends: no convergence"),
               "singular": ("x", "branch ends: no convergence"),
               "unstable": ("x", "branch ends: no convergence"),
               "max_points": ("x", "branch ends: the point budget"),
               "budget": ("x", "branch ends: the point budget")}


#: How the branches of each period are told apart: colour (the behaviour their stable orbits
#: have), and for periods past 2 a marker along the line; periods from 5 on are one group (more
#: shades of one green than a reader can tell apart).
GROUPED_PERIOD = 5


def _branch_group(br):
    """``(label, colour, marker)`` of a branch's group."""
    green = BEHAVIOUR_COLOURS["multiperiodic"]
    if br.period == 1:
        if br.symmetric:
            return "period 1, symmetric", BEHAVIOUR_COLOURS["symmetric"], None
        return "period 1, asymmetric", S.shade(BEHAVIOUR_COLOURS["asymmetric"], 0.35), None
    if br.period == 2:
        return "period 2", green, None
    # three prongs for period 3, four for period 4, a hexagon for the longer ones: shapes
    # that no bifurcation or branch end uses
    if br.period == 3:
        return "period 3", S.shade(green, 0.45), "2"
    if br.period == 4:
        return "period 4", S.shade(green, 0.45), "+"
    return f"period $\\geq {GROUPED_PERIOD}$", S.tint(green, 0.4), "h"


def _branch_runs(value, y, stable, t_next, period, mu=None):
    """Pieces ``(x, y, stable)`` of one branch line: broken where an impact crosses the
    sampling instant (the time to the next impact jumps by more than a quarter period, and the
    sampled point jumps) and where the stability changes. There both pieces meet at the point
    where the largest multiplier's modulus ``mu`` crosses 1, interpolated between the two
    branch points (without ``mu``: at the first point of the new stability)."""
    n = value.shape[0]
    cut = np.zeros(n, bool)  # cut[i]: no line between i-1 and i
    if n > 1:
        jump = np.abs(np.diff(t_next)) > 0.25 * period[1:]
        cut[1:] = jump | ~np.isfinite(y[1:]) | ~np.isfinite(y[:-1])
    runs = []
    start = 0
    head = None  # the crossing point a piece starts from
    for i in range(1, n + 1):
        if i == n or cut[i] or stable[i] != stable[start]:
            change = i < n and not cut[i]
            xs, ys = list(value[start:i]), list(y[start:i])
            if head is not None:
                xs.insert(0, head[0])
                ys.insert(0, head[1])
            head = None
            if change:
                w = 1.0
                if mu is not None and np.isfinite(mu[i - 1]) and np.isfinite(mu[i]) and \
                        mu[i] != mu[i - 1]:
                    w = float(np.clip((1.0 - mu[i - 1]) / (mu[i] - mu[i - 1]), 0.0, 1.0))
                head = (value[i - 1] + w * (value[i] - value[i - 1]),
                        y[i - 1] + w * (y[i] - y[i - 1]))
                xs.append(head[0])
                ys.append(head[1])
            if len(xs) >= 2 or (len(xs) == 1 and not change):
                runs.append((np.asarray(xs), np.asarray(ys), bool(stable[start])))
            start = i
    return runs


@S.styled
def fig_branches(continuation, sweep=None, *, component=1, title=None, limits=None,
                 mirrors=True):
    """Branches of periodic orbits drawn over a sweep's dots, bifurcations and branch ends
    marked.

    Parameters
    ----------
    continuation : rockjit.orbits.Continuation
        From :func:`rockjit.orbits.continue_branches` (or :func:`~rockjit.orbits.continuation`).
    sweep : SweepResult, optional
        Its stroboscopic points are drawn beneath the branches as small dots coloured by
        behaviour; it must be sampled at the continuation's forcing phase
        (``continue_branches`` uses the sweep's).
    component : {0, 1}
        Draw ``theta`` (0) or ``theta'`` (1, the bifurcation diagrams' choice) at ``kT``.
    title : str, optional
    limits : (float, float), optional
        Parameter range drawn.
    mirrors : bool
        Also draw the mirror image ``-x(kT + T/2)`` of every non-symmetric orbit (the same
        multipliers; a sweep from one initial state shows one of the two): both arms of every
        symmetry-breaking pitchfork.

    Notes
    -----
    Stable orbits (both multipliers inside the unit circle) are solid lines, unstable ones
    dashed; each branch in the colour of the behaviour its stable orbits have (period 1
    symmetric or asymmetric; periods 2, 3, ... in tints of the multiperiodic colour). The line
    of each cycle point breaks where an impact crosses the sampling instant ``kT``, where the
    sampled ``theta'`` jumps by the factor ``e``. The list of bifurcations with their
    multipliers is :func:`branch_caption`'s.
    """
    from matplotlib.lines import Line2D

    c = continuation
    comp = int(component)
    if comp not in (0, 1):
        raise ValueError(f"component must be 0 (theta) or 1 (theta') (got {component!r})")
    pname = c.parameter
    sym = SYMBOLS.get(pname, pname)
    fig = S.figure("double", 0.66, pad=PAD)
    ax = fig.add_subplot()
    # legend entry -> (handle, artists it names): an entry is kept when one of its artists
    # draws within the view
    entries = {}

    def entry(key, handle, artist):
        entries.setdefault(key, (handle, []))[1].append(artist)

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
            dots = ax.scatter(a[ok], yv[ok], s=2.0, color=S.tint(BEHAVIOUR_COLOURS[name], 0.35),
                              lw=0, rasterized=True, zorder=2)
            entry(f"sweep {name}", Line2D([], [], ls="", marker="o", ms=3.5,
                                          color=S.tint(BEHAVIOUR_COLOURS[name], 0.35),
                                          label=f"sweep: {name}"), dots)
    groups = {}
    for br in sorted(c.branches, key=lambda b: (b.period, not b.symmetric)):
        groups.setdefault(_branch_group(br), None)
    for br in c.branches:
        T = 2.0 * np.pi / np.asarray(br.omega)
        group = _branch_group(br)
        _, colour, mk = group
        mu_abs = np.abs(np.asarray(br.multipliers)).max(axis=1)
        cycles = [(br.cycle, br.t_next_impact)]
        if mirrors and br.mirror_cycle is not None:
            # the mirror orbit at kT is the orbit at kT + T/2, reflected
            cycles.append((br.mirror_cycle, br.t_next_impact_half))
        for cyc, tn in cycles:
            for k in range(br.period):
                for x, yv, st in _branch_runs(np.asarray(br.value), cyc[:, k, comp],
                                              np.asarray(br.stable), tn[:, k], T, mu_abs):
                    line, = ax.plot(x, yv, ls="-" if st else (0, (3.0, 1.5)),
                                    lw=1.1 if st else 0.8, color=colour, zorder=4,
                                    marker=mk or "", ms=3.2, markevery=0.07, mew=0.7,
                                    mfc=colour if st else "white")
                    entry(group, None, line)
    for group in groups:
        lab, colour, mk = group
        if group in entries:
            entries[group] = (Line2D([], [], color=colour, lw=1.4, marker=mk or "", ms=3.5,
                                     label=lab), entries[group][1])
    stab = [(Line2D([], [], color="0.3", lw=1.1, ls="-", label="stable orbits: solid"), True),
            (Line2D([], [], color="0.3", lw=0.8, ls=(0, (3.0, 1.5)),
                    label="unstable orbits: dashed"), False)]
    bifs = sorted(c.bifurcations, key=lambda b: b.value)
    for bf in bifs:
        mk = BIFURCATION_MARKERS.get(bf.type, "o")
        pts_b = [np.asarray(bf.cycle)]
        if mirrors and bf.has_mirror and getattr(bf, "cycle_half", None) is not None:
            pts_b.append(-np.asarray(bf.cycle_half))
        for cy in pts_b:
            dots = ax.scatter(np.full(cy.shape[0], bf.value), cy[:, comp], marker=mk,
                              s=22 if bf.period <= 2 else 11, facecolor="white", edgecolor="k",
                              lw=0.8, zorder=5)
            entry(f"bif {bf.type}", Line2D([], [], ls="", marker=mk, ms=4.5,
                                           markerfacecolor="white", markeredgecolor="k",
                                           label=_BIF_WORDS.get(bf.type, bf.type)), dots)
    # where a branch stops inside the range, and why: each point once (branches that stop at
    # one point, each cycle point of a period-p orbit, pile up otherwise)
    ends = {}
    for br in c.branches:
        cycles = [br.cycle] + ([br.mirror_cycle] if mirrors and br.mirror_cycle is not None
                               else [])
        for side, why in zip((0, -1), br.ends):
            if why not in END_MARKERS:
                continue
            mk, words = END_MARKERS[why]
            got = ends.setdefault((mk, words), dict(points=[], branches=0))
            got["branches"] += 1
            for cyc in cycles:
                got["points"] += [(float(br.value[side]), float(v)) for v in cyc[side, :, comp]]
    ax.set_xlabel(sym)
    ax.set_ylabel(SYMBOLS["strobe"] if comp == 1 else SYMBOLS["strobe_theta"])
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
    (x0, x1), (y0, y1) = ax.get_xlim(), ax.get_ylim()
    for (mk, words), got in ends.items():
        p = np.unique(np.round(np.asarray(got["points"]) /
                               [(x1 - x0) * 2e-3, (y1 - y0) * 2e-3]), axis=0) * \
            [(x1 - x0) * 2e-3, (y1 - y0) * 2e-3]
        line, = ax.plot(p[:, 0], p[:, 1], ls="", marker=mk, ms=4.5, color="k", mew=1.0,
                        zorder=6)
        n = got["branches"]
        entry(f"end {words}", Line2D([], [], ls="", marker=mk, ms=4.5, color="k", mew=1.0,
                                     label=f"{words} ({n} branch{'es' if n > 1 else ''})"),
              line)

    def in_view(artist):
        if hasattr(artist, "get_offsets"):
            xy = np.asarray(artist.get_offsets(), float).reshape(-1, 2)
        else:
            xy = np.column_stack([np.asarray(v, float) for v in artist.get_data()])
        return bool(np.any((xy[:, 0] >= min(x0, x1)) & (xy[:, 0] <= max(x0, x1))
                           & (xy[:, 1] >= min(y0, y1)) & (xy[:, 1] <= max(y0, y1))))

    handles = []
    shown = [key for key, (_, arts) in entries.items() if any(in_view(a) for a in arts)]
    for key in shown:
        if isinstance(key, str) and key.startswith("sweep "):
            handles.append(entries[key][0])
    branch_lines = [ln for key in shown if isinstance(key, tuple) for ln in entries[key][1]
                    if in_view(ln)]
    handles += [entries[key][0] for key in groups if key in shown]
    for h, stable in stab:
        if any((ln.get_linestyle() == "-") == stable for ln in branch_lines):
            handles.append(h)
    handles += [entries[key][0] for key in shown if isinstance(key, str)
                and not key.startswith("sweep ")]
    fig.legend(handles=handles, loc="outside lower center", ncols=3)
    b, f = c.block, c.forcing
    fixed = (f"$\\omega = {f.omega:g}$" if pname == "alpha" else f"$\\alpha = {f.alpha:g}$")
    S.suptitle(fig, title or f"Periodic orbits, {S.law_name(b)}, $h/b = {b.hb:g}$, {fixed}; "
                             f"sampled at $t = kT$ at the forcing phase "
                             f"$\\varphi = {c.phase:.4g}$ of the study's $z_0$")
    return fig


def branch_caption(continuation, name=None):
    """A caption in Markdown for :func:`fig_branches`: what is drawn, every located
    bifurcation (parameter, period, multipliers) and every branch with where and why it
    stops."""
    c = continuation
    b, f = c.block, c.forcing
    p = "alpha" if c.parameter == "alpha" else "omega"
    lines = [f"# {name or 'Periodic orbits'}: {S.law_name(b).replace('$', '')}, h/b = {b.hb:g}",
             "",
             f"Branches of periodic orbits continued in {p} over {list(c.bounds)} (stable "
             f"solid, unstable dashed; mirror images of asymmetric orbits drawn too), over the "
             f"sweep's stroboscopic points. Section t = kT at the forcing phase "
             f"phi = {c.phase:.6g} (the study's z0: r0 = -0.7778, s0 = 0.6284).", "",
             "## Bifurcations", ""]
    bifs = sorted(c.bifurcations, key=lambda x: x.value)
    if bifs:
        lines += [f"| # | type | {p} | period | mu1 | mu2 |", "|---|---|---|---|---|---|"]
        for i, bf in enumerate(bifs):
            mu = [f"{m.real:.4g}" if abs(m.imag) < 1e-12 else f"{m.real:.3g}{m.imag:+.3g}i"
                  for m in np.asarray(bf.multipliers)]
            lines.append(f"| {i + 1} | {_BIF_WORDS.get(bf.type, bf.type)} | {bf.value:.9f} | "
                         f"{bf.period} | {mu[0]} | {mu[1]} |")
    else:
        lines.append("No bifurcation located.")
    lines += ["", "## Branches", "", f"| # | period | kind | {p} from | to | ends |",
              "|---|---|---|---|---|---|"]
    from ..orbits.types import REASONS
    for i, br in enumerate(c.branches):
        why = ", ".join(f"{w} ({REASONS.get(w, w)})" if w in REASONS else w for w in br.ends)
        lines.append(f"| {i} | {br.period} | {'symmetric' if br.symmetric else 'asymmetric'} | "
                     f"{br.value.min():.6f} | {br.value.max():.6f} | {why} |")
    return "\n".join(lines) + "\n"
