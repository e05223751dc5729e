"""Figures of runs in time (figures 2 to 4 of the study): one run's ``theta(t)``, running
exponent and phase portrait; a gallery of behaviours; the two laws from the same initial
states. Impacts are drawn as the vertical jumps they are (:func:`with_impacts`)."""

from __future__ import annotations

import math
import re

import numpy as np

from . import style as S
from .common import LINE_COLOURS, PAD, _params
from .style import BEHAVIOUR_COLOURS, SYMBOLS

__all__ = ["fig_gallery", "fig_laws_timeseries", "fig_trajectory", "with_impacts"]


def _behaviour_words(behaviour):
    """``(name, period)`` in words: ``symmetric``, ``period-2``, ..."""
    name, p = behaviour
    if name == "multiperiodic":
        return f"period-{p} (multiperiodic)"
    if name in ("symmetric", "asymmetric"):
        return f"{name}, $p = {p}$"
    return name


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
    """Refuse a result recorded without its trajectory."""
    if result.trajectory is None or result.trajectory.shape[0] == 0:
        raise ValueError("the result has no trajectory: simulate with record_stride=...")


def _window_start(result):
    """The start of a run's asymptotic window (its periods' last fifth when it carries none)."""
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
    """``theta(t)`` over ``[t0, t1]``, impacts as vertical jumps."""
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
    fig = S.figure("double", 0.52, pad=PAD)
    gs = fig.add_gridspec(2, 3, width_ratios=(1.5, 1.0, 1.25))
    axes_t = _time_windows(fig, gs, result, colour, first, last)
    ax_l = fig.add_subplot(gs[1, :2])
    fig_legend = _running_exponent(ax_l, result, colour, exponent)
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


def _time_windows(fig, gs, result, colour, first, last):
    """Figure 2's top row: ``theta(t)`` over the first and the last periods (one panel for the
    whole run when it is short), sharing their vertical axis; returns the axes."""
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
    return axes_t


def _running_exponent(ax_l, result, colour, exponent):
    """The running exponent ``lambda_1(t)`` with the window's estimate and the orbit's Floquet
    exponent, the asymptotic window shaded; returns the legend's ``(handles, labels)``, or
    ``None`` (with a note in the panel) when the run computed no exponents."""
    lam = result.lyapunov_running
    if lam is None or lam.shape[0] <= 1:
        ax_l.text(0.5, 0.5, "Lyapunov exponents not computed", ha="center", va="center",
                  transform=ax_l.transAxes, color="0.4")
        return None
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
    ax_l.set_ylabel(r"$\lambda_1$")
    ax_l.set_xlim(0, result.t)
    return hs, ls_


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
