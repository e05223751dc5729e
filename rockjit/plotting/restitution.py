"""The restitution laws' figure (figure 1 of the study): the coefficients ``e_H`` and ``e_M``
against the critical angle, with their difference on a twin axis."""

from __future__ import annotations

import math

import numpy as np

from ..model import delta_e_percent, e_housner, e_mao, thc_from_hb
from . import style as S
from .common import PAD
from .style import LAW_LINES

__all__ = ["fig_restitution"]


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
