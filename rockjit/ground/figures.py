"""The figures of the ground-motion analyses: overturning spectra and fragility curves.

Each function takes result objects and returns a :class:`matplotlib.figure.Figure` built
without :mod:`matplotlib.pyplot` (as :mod:`rockjit.plotting.figures` does); the restitution laws
keep their colours (:data:`rockjit.plotting.style.LAW_COLOURS`).
"""

from __future__ import annotations

import numpy as np

from ..plotting import cells
from ..plotting.style import LAW_NAMES, figure
from ..plotting.style import styled as _styled
from .response import OUTCOMES

__all__ = ["OUTCOME_COLOURS", "fig_fragility", "fig_rotation", "fig_spectrum",
           "fig_transient"]

#: One colour per outcome (rockjit.ground.response.OUTCOMES).
OUTCOME_COLOURS = ("#f2f2f2", "#f4a259", "#b2182b", "#e377c2")
_STYLES = ("-", "--", ":", "-.")


def _edges(v):
    """Cell edges around increasing centres ``v`` (a single one spans 0.9-1.1 of itself: the
    axes are logarithmic)."""
    return cells.edges(v, lone_ratio=0.1)


#: The axes' quantities, in the study's symbols (theta_c the block's critical angle).
RATIO = r"$\omega_p / p$"
AMPLITUDE = r"$a_p / (g \cot\theta_c)$"


def _law_colour(law):
    from ..plotting.style import LAW_COLOURS
    return LAW_COLOURS.get(law, "k")


def _outcome_map(ax, sp):
    from matplotlib.colors import BoundaryNorm, ListedColormap
    cmap = ListedColormap(OUTCOME_COLOURS)
    norm = BoundaryNorm(np.arange(len(OUTCOMES) + 1) - 0.5, cmap.N)
    ax.pcolormesh(_edges(sp.ratio), _edges(sp.amplitude), sp.outcome.T, cmap=cmap, norm=norm,
                  rasterized=True)


def _boundaries(ax, sp, colour="k", label_prefix=""):
    # a marker at each located point while they are few enough to be told apart
    few = sp.ratio.size <= 30
    fin = np.isfinite(sp.min_overturn)
    if fin.any():
        ax.plot(sp.ratio[fin], sp.min_overturn[fin], ls="-", marker="o" if few else "",
                color=colour, ms=2, lw=1.0, label=f"{label_prefix}minimum overturning amplitude")
    fin = np.isfinite(sp.min_no_impact)
    if fin.any():
        ax.plot(sp.ratio[fin], sp.min_no_impact[fin], ls="--", marker="s" if few else "",
                color=colour, ms=1.8, lw=0.8, label=f"{label_prefix}overturning without impact")


def _closed_form(ax, sp):
    """The slender linearised block's boundary of overturning without impact, where it lies in
    the panel (nothing drawn, and no legend entry, where it does not)."""
    from .closed_forms import cosine_no_impact, sine_no_impact
    fn = {"sine": sine_no_impact, "cosine": cosine_no_impact}.get(sp.pulse.kind)
    if fn is None:
        return
    r = np.linspace(sp.ratio.min(), sp.ratio.max(), 200)
    k = []
    for x in r:
        try:
            k.append(fn(x))
        except ValueError:
            k.append(np.nan)
    k = np.asarray(k, float)
    lo, hi = _edges(sp.amplitude)[[0, -1]]
    if not np.any(np.isfinite(k) & (k >= lo) & (k <= hi)):
        return
    ax.plot(r, k, color="0.3", lw=0.8, ls=":", label="slender linearised block, without impact")


@_styled
def fig_spectrum(results):
    """Overturning spectra: per law, the outcome of every cell over
    ``(omega_p / p, a_p / (g cot theta_c))`` with the located boundaries; with two laws, a
    third panel of the cells where they differ and both laws' minimum overturning amplitude.
    ``results``: a :class:`~rockjit.ground.spectrum.SpectrumResult` or a dict law -> one. The
    legends sit below the panels, off the data."""
    from matplotlib.patches import Patch
    if not isinstance(results, dict):
        results = {results.block.law: results}
    sps = list(results.values())
    n = len(sps) + (1 if len(sps) == 2 else 0)
    fig = figure("single" if n == 1 else "double", 1.05 if n == 1 else 0.5)
    axes = fig.subplots(1, n, sharey=True, squeeze=False)[0]
    first = sps[0]
    kind = {"sine": "one-sine pulse", "cosine": "one-cosine pulse",
            "ricker": "Ricker wavelet"}[first.pulse.kind]
    letters = "abcdefgh"
    for i, (ax, sp) in enumerate(zip(axes, sps)):
        _outcome_map(ax, sp)
        _closed_form(ax, sp)
        _boundaries(ax, sp)
        ax.set_title(f"{letters[i]}) {LAW_NAMES.get(sp.block.law, sp.block.law)} "
                     f"($e = {sp.block.restitution:.3f}$)", loc="left")
    extra = []
    if len(sps) == 2:
        ax = axes[2]
        a, b = sps
        diff = (a.outcome != b.outcome).astype(float)
        ax.pcolormesh(_edges(a.ratio), _edges(a.amplitude), np.where(diff.T > 0, 1.0, np.nan),
                      cmap="Greys", vmin=0, vmax=1.6, rasterized=True)
        for ls, sp in zip(("-", "--"), sps):
            fin = np.isfinite(sp.min_overturn)
            if fin.any():
                ax.plot(sp.ratio[fin], sp.min_overturn[fin], ls=ls, lw=1.0,
                        marker="o" if sp.ratio.size <= 30 else "", ms=2,
                        color=_law_colour(sp.block.law),
                        label=f"{LAW_NAMES.get(sp.block.law, sp.block.law)}: minimum overturning")
        pct = 100.0 * float(diff.mean())
        ax.set_title(f"c) the laws differ: {pct:.1f} %", loc="left")
        if diff.any():
            from matplotlib import colormaps
            from matplotlib.colors import to_hex
            extra.append(Patch(facecolor=to_hex(colormaps["Greys"](1.0 / 1.6)),
                               edgecolor="0.5", lw=0.4, label="cells whose outcomes differ"))
    for ax in axes:
        ax.set_xlabel(RATIO)
        ax.set_xlim(_edges(first.ratio)[[0, -1]])
        ax.set_ylim(_edges(first.amplitude)[[0, -1]])
    axes[0].set_ylabel(AMPLITUDE)
    handles = [Patch(facecolor=c, edgecolor="0.5", lw=0.4, label=o)
               for c, o in zip(OUTCOME_COLOURS, OUTCOMES)
               if np.any([np.any(sp.outcome == OUTCOMES.index(o)) for sp in sps])]
    seen = set()
    for ax in axes:  # each line once, though every law's panel draws it
        for h in ax.get_legend_handles_labels()[0]:
            if h.get_label() not in seen:
                seen.add(h.get_label())
                handles.append(h)
    fig.legend(handles=handles + extra, loc="outside lower center", ncols=1 if n == 1 else 3)
    from ..plotting.style import suptitle
    suptitle(fig, f"Overturning spectrum, {kind}, $h/b = {first.block.hb:g}$")
    return fig


def _law_marker(law):
    """The law's marker (:data:`rockjit.plotting.style.LAW_LINES`): two laws' points that
    coincide stay both visible."""
    from ..plotting.style import LAW_LINES
    return LAW_LINES.get(law, LAW_LINES["constant"])["marker"]


def _curve(ax, x, frac, fit, colour, ls, label, marker="o"):
    """The fraction observed at each intensity (open circles) and, where the fit's status is
    ``"ok"``, the fitted curve over the intensities of the data only; returns the legend
    entry."""
    from matplotlib.lines import Line2D
    x = np.asarray(x, float)
    ax.plot(x, frac, ls="", marker=marker, color=colour, ms=3.5 if marker == "o" else 4.5,
            mfc="none", mew=0.8)
    if fit.status == "ok":
        xs = np.geomspace(x.min(), x.max(), 300) if x.min() > 0 else \
            np.linspace(x.min(), x.max(), 300)
        ax.plot(xs, fit.probability(xs), color=colour, ls=ls, lw=1.0)
        return Line2D([], [], color=colour, ls=ls, lw=1.0, marker=marker, ms=3, mfc="none",
                      mew=0.8, label=f"{label}: median {fit.median:.3g}, "
                                     f"$\\beta$ {fit.beta:.2f}")
    return Line2D([], [], color=colour, ls="", marker=marker, ms=3, mfc="none", mew=0.8,
                  label=f"{label}: no fit ({fit.status.replace('_', ' ')})")


def _xlabel(res):
    return r"PGA / $(g \cot\theta_c)$" if res.measure == "pga" else "PGV [m/s]"


@_styled
def fig_fragility(res):
    """The fragility curves of a :class:`~rockjit.ground.fragility.FragilityResult`: the
    fraction of records that overturned the block at each intensity (circles) and the fitted
    lognormal curves over the intensities run (a fit whose status is not ``"ok"`` draws no
    curve; its legend entry says why), one colour per law and one line style per size."""
    fig = figure("single", 1.1)
    ax = fig.subplots()
    frac = res.fraction("overturn")
    handles = []
    for li, law in enumerate(res.laws):
        for si, size in enumerate(res.sizes):
            handles.append(_curve(ax, res.intensity, frac[li, si],
                                  res.fits[law][float(size)]["overturn"], _law_colour(law),
                                  _STYLES[si % len(_STYLES)],
                                  f"{LAW_NAMES.get(law, law)}, $R = {size:g}$ m",
                                  _law_marker(law)))
    ax.set_xlabel(_xlabel(res))
    ax.set_ylabel("P(overturn)")
    ax.set_ylim(-0.03, 1.03)
    ax.legend(handles=handles, loc="upper center", bbox_to_anchor=(0.5, -0.2), ncols=1,
              handlelength=3.0)
    ax.set_title(f"Fragility, $h/b = {res.block.hb:g}$, {len(res.records)} records")
    return fig


@_styled
def fig_rotation(res):
    """Rotation exceedance: ``P(max |theta| / (pi/2 - theta_c) >= level)`` for each fitted
    level, one panel each, laws and sizes as in :func:`fig_fragility`."""
    from .fragility import EXCEEDANCE
    fig = figure("double", 0.55)
    axes = fig.subplots(1, len(EXCEEDANCE), sharey=True, squeeze=False)[0]
    for ax, lv in zip(axes, EXCEEDANCE):
        frac = res.fraction(f"exceed_{lv:g}")
        handles = []
        for li, law in enumerate(res.laws):
            for si, size in enumerate(res.sizes):
                handles.append(_curve(ax, res.intensity, frac[li, si],
                                      res.fits[law][float(size)][f"exceed_{lv:g}"],
                                      _law_colour(law), _STYLES[si % len(_STYLES)],
                                      f"{LAW_NAMES.get(law, law)}, $R = {size:g}$ m",
                                      _law_marker(law)))
        ax.set_xlabel(_xlabel(res))
        ax.set_title(f"$\\max|\\theta| / (\\pi/2 - \\theta_c) \\geq {lv:g}$")
        ax.legend(handles=handles, loc="upper center", bbox_to_anchor=(0.5, -0.22), ncols=1,
                  handlelength=3.0)
    axes[0].set_ylabel("P(exceeded)")
    axes[0].set_ylim(-0.03, 1.03)
    return fig


@_styled
def fig_transient(result):
    """One transient run: ``theta / (pi/2 - theta_c)`` and the base acceleration
    ``f / cot theta_c`` against time, the impacts marked."""
    fig = figure("double", 0.5)
    ax, axf = fig.subplots(2, 1, sharex=True, height_ratios=(2, 1))
    a = result.alpha_s
    tr = result.trajectory
    if tr is not None and len(tr):
        ax.plot(tr[:, 0], tr[:, 1] / a, color="k", lw=0.7)
    for t in result.impacts[:, 0]:
        ax.axvline(t, color="0.7", lw=0.5)
    ax.axhline(1.0, color="0.5", ls=":", lw=0.8)
    ax.axhline(-1.0, color="0.5", ls=":", lw=0.8)
    ax.set_ylabel(r"$\theta / (\pi/2 - \theta_c)$")
    t_end = max(result.t, 1e-9)
    ts = np.linspace(0.0, t_end, 4000)
    axf.plot(ts, result.excitation.f(ts) * result.block.hb, color="#1f77b4", lw=0.7)
    axf.axhline(1.0, color="0.5", ls=":", lw=0.8)
    axf.axhline(-1.0, color="0.5", ls=":", lw=0.8)
    axf.set_ylabel(r"$f / \cot\theta_c$")
    axf.set_xlabel(r"$t$ [units of $\sqrt{R/g}$]")
    mode = f", {result.mode}" if result.mode else ""
    ax.set_title(f"{result.status}{mode}; $\\max|\\theta| / (\\pi/2 - \\theta_c) = "
                 f"{result.max_rotation:.3g}$")
    return fig
