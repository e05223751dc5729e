"""The figures of the ground-motion analyses: overturning spectra and fragility curves.

Each function takes result objects and returns a :class:`matplotlib.figure.Figure` built
without :mod:`matplotlib.pyplot` (as :mod:`rockjit.plotting.figures` does); the restitution laws
keep their colours (:data:`rockjit.plotting.style.LAW_COLOURS`).
"""

from __future__ import annotations

import numpy as np

from .response import OUTCOMES

__all__ = ["OUTCOME_COLOURS", "fig_fragility", "fig_rotation", "fig_spectrum",
           "fig_transient"]

#: One colour per outcome (rockjit.ground.response.OUTCOMES).
OUTCOME_COLOURS = ("#f2f2f2", "#f4a259", "#b2182b", "#e377c2")
_LAW_NAMES = {"housner": "Housner", "mao": "Mao et al.", "constant": "constant e"}
_STYLES = ("-", "--", ":", "-.")


def _figure(**kw):
    from matplotlib.figure import Figure
    return Figure(**kw)


def _law_colour(law):
    from ..plotting.style import LAW_COLOURS
    return LAW_COLOURS.get(law, "k")


def _edges(v):
    """Cell edges around increasing centres ``v`` (geometric when all positive)."""
    v = np.asarray(v, dtype=float)
    if v.size == 1:
        return np.array([v[0] * 0.9, v[0] * 1.1]) if v[0] > 0 else np.array([v[0] - 0.5,
                                                                                v[0] + 0.5])
    mid = 0.5 * (v[1:] + v[:-1])
    return np.concatenate(([v[0] - (mid[0] - v[0])], mid, [v[-1] + (v[-1] - mid[-1])]))


def _outcome_map(ax, sp):
    from matplotlib.colors import BoundaryNorm, ListedColormap
    cmap = ListedColormap(OUTCOME_COLOURS)
    norm = BoundaryNorm(np.arange(len(OUTCOMES) + 1) - 0.5, cmap.N)
    ax.pcolormesh(_edges(sp.ratio), _edges(sp.amplitude), sp.outcome.T, cmap=cmap, norm=norm,
                  rasterized=True)


def _boundaries(ax, sp, colour="k", label_prefix=""):
    fin = np.isfinite(sp.min_overturn)
    if fin.any():
        ax.plot(sp.ratio[fin], sp.min_overturn[fin], "o-", color=colour, ms=3, lw=1.2,
                label=f"{label_prefix}minimum overturning amplitude")
    fin = np.isfinite(sp.min_no_impact)
    if fin.any():
        ax.plot(sp.ratio[fin], sp.min_no_impact[fin], "s--", color=colour, ms=2.5, lw=0.9,
                label=f"{label_prefix}overturning without impact")


def _closed_form(ax, sp):
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
    ax.plot(r, k, color="0.3", lw=0.8, ls=":", label="slender linearised block, without impact")


def fig_spectrum(results, comparison=None):
    """Overturning spectra: per law, the outcome of every cell over
    ``(omega_p / p, a_p / (g tan alpha_s))`` with the located boundaries; with two laws, a
    third panel of the cells where they differ and both laws' minimum overturning amplitude.
    ``results``: a :class:`~rockjit.ground.spectrum.SpectrumResult` or a dict law -> one."""
    from matplotlib.patches import Patch
    if not isinstance(results, dict):
        results = {results.block.law: results}
    sps = list(results.values())
    n = len(sps) + (1 if len(sps) == 2 else 0)
    fig = _figure(figsize=(4.6 * n, 4.2), layout="constrained")
    axes = fig.subplots(1, n, sharey=True, squeeze=False)[0]
    first = sps[0]
    kind = {"sine": "one-sine pulse", "cosine": "one-cosine pulse",
            "ricker": "Ricker wavelet"}[first.pulse.kind]
    for ax, sp in zip(axes, sps):
        _outcome_map(ax, sp)
        _closed_form(ax, sp)
        _boundaries(ax, sp)
        ax.set_title(f"{_LAW_NAMES.get(sp.block.law, sp.block.law)} (e = "
                     f"{sp.block.restitution:.3f})", fontsize=10)
    if len(sps) == 2:
        ax = axes[2]
        a, b = sps
        diff = (a.outcome != b.outcome).astype(float)
        ax.pcolormesh(_edges(a.ratio), _edges(a.amplitude), np.where(diff.T > 0, 1.0, np.nan),
                      cmap="Greys", vmin=0, vmax=1.6, rasterized=True)
        for sp in sps:
            fin = np.isfinite(sp.min_overturn)
            ax.plot(sp.ratio[fin], sp.min_overturn[fin], "o-", ms=3, lw=1.2,
                    color=_law_colour(sp.block.law),
                    label=f"{_LAW_NAMES.get(sp.block.law)}: minimum overturning")
        pct = 100.0 * float(diff.mean())
        ax.set_title(f"where the laws differ ({pct:.1f} % of cells, grey)", fontsize=10)
        ax.legend(fontsize=7, loc="upper left")
    for ax in axes:
        ax.set_xlabel("\u03c9\u209a / p")
        ax.set_xlim(_edges(first.ratio)[[0, -1]])
        ax.set_ylim(_edges(first.amplitude)[[0, -1]])
    axes[0].set_ylabel("a\u209a / (g tan \u03b1)")
    handles = [Patch(color=c, label=o) for c, o in zip(OUTCOME_COLOURS, OUTCOMES)
               if np.any([np.any(sp.outcome == OUTCOMES.index(o)) for sp in sps])]
    h2, l2 = axes[0].get_legend_handles_labels()
    axes[0].legend(handles + h2, [h.get_label() for h in handles] + l2, fontsize=7,
                   loc="upper left")
    fig.suptitle(f"Overturning spectrum, {kind}, h/b = {first.block.hb:g}", fontsize=11)
    return fig


def _curve(ax, x, frac, fit, colour, ls, label):
    ax.plot(x, frac, "o", color=colour, ms=4, mfc="none")
    xs = np.geomspace(x.min() / 1.5 if x.min() > 0 else 1e-3, x.max() * 1.5, 300)
    if fit.status in ("ok", "separated"):
        p = fit.probability(xs)
        med = f"{fit.median:.3g}"
        beta = f"{fit.beta:.2f}" if fit.status == "ok" else "0"
        ax.plot(xs, p, color=colour, ls=ls, lw=1.2, label=f"{label}: median {med}, "
                                                           f"\u03b2 {beta}")
    else:
        ax.plot([], [], color=colour, ls=ls, label=f"{label}: {fit.status.replace('_', ' ')}")


def _xlabel(res):
    return "PGA / (g tan \u03b1)" if res.measure == "pga" else "PGV (m/s)"


def fig_fragility(res):
    """The fragility curves of a :class:`~rockjit.ground.fragility.FragilityResult`: the
    fraction of records that overturned the block at each intensity (circles) and the fitted
    lognormal curves, one colour per law and one line style per size."""
    fig = _figure(figsize=(6.4, 4.4), layout="constrained")
    ax = fig.subplots()
    frac = res.fraction("overturn")
    for li, law in enumerate(res.laws):
        for si, size in enumerate(res.sizes):
            _curve(ax, res.intensity, frac[li, si], res.fits[law][float(size)]["overturn"],
                   _law_colour(law), _STYLES[si % len(_STYLES)],
                   f"{_LAW_NAMES.get(law, law)}, R = {size:g} m")
    ax.set_xlabel(_xlabel(res))
    ax.set_ylabel("P(overturn)")
    ax.set_ylim(-0.03, 1.03)
    ax.legend(fontsize=7, loc="lower right")
    ax.set_title(f"Fragility, h/b = {res.block.hb:g}, {len(res.records)} records", fontsize=10)
    return fig


def fig_rotation(res):
    """Rotation exceedance: ``P(max |theta| / alpha_s >= level)`` for each fitted level, one
    panel each, laws and sizes as in :func:`fig_fragility`."""
    from .fragility import EXCEEDANCE
    fig = _figure(figsize=(4.6 * len(EXCEEDANCE), 4.2), layout="constrained")
    axes = fig.subplots(1, len(EXCEEDANCE), sharey=True, squeeze=False)[0]
    for ax, lv in zip(axes, EXCEEDANCE):
        frac = res.fraction(f"exceed_{lv:g}")
        for li, law in enumerate(res.laws):
            for si, size in enumerate(res.sizes):
                _curve(ax, res.intensity, frac[li, si],
                       res.fits[law][float(size)][f"exceed_{lv:g}"], _law_colour(law),
                       _STYLES[si % len(_STYLES)], f"{_LAW_NAMES.get(law, law)}, R = {size:g} m")
        ax.set_xlabel(_xlabel(res))
        ax.set_title(f"max|\u03b8| / \u03b1 \u2265 {lv:g}", fontsize=10)
        ax.legend(fontsize=6, loc="lower right")
    axes[0].set_ylabel("P(exceeded)")
    axes[0].set_ylim(-0.03, 1.03)
    return fig


def fig_transient(result):
    """One transient run: ``theta / alpha_s`` and the base acceleration ``f / tan alpha_s``
    against time, the impacts marked."""
    fig = _figure(figsize=(7.0, 4.2), layout="constrained")
    ax, axf = fig.subplots(2, 1, sharex=True, height_ratios=(2, 1))
    a = result.alpha_s
    tr = result.trajectory
    if tr is not None and len(tr):
        ax.plot(tr[:, 0], tr[:, 1] / a, color="k", lw=0.7)
    for t in result.impacts[:, 0]:
        ax.axvline(t, color="0.7", lw=0.5)
    ax.axhline(1.0, color="0.5", ls=":", lw=0.8)
    ax.axhline(-1.0, color="0.5", ls=":", lw=0.8)
    ax.set_ylabel("\u03b8 / \u03b1")
    t_end = max(result.t, 1e-9)
    ts = np.linspace(0.0, t_end, 4000)
    axf.plot(ts, result.excitation.f(ts) * result.block.hb, color="#1f77b4", lw=0.7)
    axf.axhline(1.0, color="0.5", ls=":", lw=0.8)
    axf.axhline(-1.0, color="0.5", ls=":", lw=0.8)
    axf.set_ylabel("f / tan \u03b1")
    axf.set_xlabel("t (units of \u221a(R/g))")
    mode = f", {result.mode}" if result.mode else ""
    ax.set_title(f"{result.status}{mode}; max|\u03b8|/\u03b1 = {result.max_rotation:.3g}",
                 fontsize=10)
    return fig
