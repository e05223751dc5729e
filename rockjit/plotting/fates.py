"""The figure of an ensemble of nearby runs (:func:`rockjit.fate`): each outcome's
probability, and when each member's run ended against its initial perturbation."""

from __future__ import annotations

import re

import numpy as np

from . import style as S
from .common import PAD

__all__ = ["fig_fate"]


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
