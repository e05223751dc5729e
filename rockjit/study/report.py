"""The page a reader opens first: ``index.html`` of a paper's output directory.

One self-contained HTML page (no script; images linked by relative names, so the directory can
be moved or served as it is) with every figure and its caption, every table, the study's
published numbers beside this run's (:func:`published_beside`) and the list of every file with
what it holds (the same manifest as ``summary.json``'s ``files``).
"""

from __future__ import annotations

import datetime
import html
import math

import numpy as np

from ..plotting.style import LAW_NAMES
from ..settings import Integration
from .settings import (BASIN_CASES, CHART, E_FIGURE_HB_MAX, FIRST_PERIODS, GALLERY,
                       LAST_PERIODS, LAWS_PERIODS, LAWS_RUN, REFERENCE_RUN)

__all__ = ["E_TABLE_PUBLISHED", "FATES_NOTE", "FATES_PUBLISHED", "GIM_PUBLISHED", "SHARES_PUBLISHED",
           "TRANSITIONS", "published_beside", "write_index"]

#: The study's restitution table (docs/theory/study.md, "Settings"): hb -> (e_H, e_M, delta e %).
E_TABLE_PUBLISHED = {1.0: (0.250, 0.582, 79.85), 2.0: (0.700, 0.830, 17.03)}

#: The transitions of the study's diagrams located by continuation (docs/theory/study.md,
#: "Where the study's transitions are", N = 384): (hb, law, what, type, period, alpha).
TRANSITIONS = (
    (1, "housner", "the symmetric orbit is born (fold)", "fold", 1, 0.5573344),
    (1, "housner", "the unstable symmetric arm ends (grazing)", "grazing", 1, 0.7240259),
    (1, "housner", "symmetric to asymmetric (symmetry-breaking pitchfork)",
     "symmetry_breaking", 1, 0.7797983),
    (1, "housner", "period doubling 1 to 2", "period_doubling", 1, 0.9115105),
    (1, "housner", "period doubling 2 to 4", "period_doubling", 2, 0.9309524),
    (1, "housner", "period doubling 4 to 8", "period_doubling", 4, 0.9347827),
    (1, "housner", "period doubling 8 to 16", "period_doubling", 8, 0.9355972),
    (1, "housner", "period-7 window: fold", "fold", 7, 0.9409954),
    (1, "housner", "period-7 window: doubling", "period_doubling", 7, 0.9410159),
    (1, "housner", "period-3 window: fold", "fold", 3, 0.9456216),
    (1, "housner", "period-3 window: doubling", "period_doubling", 3, 0.9462934),
    (1, "housner", "period-3 window: doubling of the 6", "period_doubling", 6, 0.9466089),
    (1, "mao", "symmetry breaking (an orbit z0 never reaches)", "symmetry_breaking", 1,
     0.787602),
    (2, "housner", "symmetry breaking", "symmetry_breaking", 1, 0.383496),
    (2, "housner", "period doubling 1 to 2", "period_doubling", 1, 0.466240),
    (2, "housner", "period doubling 2 to 4", "period_doubling", 2, 0.476120),
    (2, "housner", "period doubling 4 to 8", "period_doubling", 4, 0.478028),
    (2, "housner", "period doubling 8 to 16", "period_doubling", 8, 0.478433),
    (2, "mao", "symmetry breaking", "symmetry_breaking", 1, 0.396706),
    (2, "mao", "period doubling 1 to 2", "period_doubling", 1, 0.478184),
    (2, "mao", "period doubling 2 to 4", "period_doubling", 2, 0.486288),
    (2, "mao", "period doubling 4 to 8", "period_doubling", 4, 0.487541),
    (2, "mao", "period doubling 8 to 16", "period_doubling", 8, 0.487789),
)

#: The study's "multiperiodic" example (hb = 1, alpha = 0.969): outcome probabilities over 64
#: runs within 1e-10 of z0 as first computed (rockjit 0.1.0, whose impacts were located by a
#: second Runge-Kutta step, not on the step's interpolant); the study itself ran one run and
#: called its motion multiperiodic. :func:`published_beside` puts this run's beside them.
FATES_PUBLISHED = {"closed": {"overturn": 0.91, "period-7": 0.09},
                   "embedded": {"overturn": 0.64, "period-7": 0.36}}

#: Why an ensemble's shares move between versions of the integration (the page's note).
FATES_NOTE = (
    "The study integrated one run from <i>z</i><sub>0</sub> and called its motion "
    "multiperiodic; rockjit runs {n} members from initial states moved by four units in the last "
    "place up to 10<sup>-10</sup> (log-uniform, seeded) and counts how each ends. The motion is "
    "transient chaos: its finite-time exponent (&lambda;<sub>1</sub> = {lam}) grows a "
    "perturbation of 10<sup>-10</sup> to 1 % of the orbit by <i>t</i> = {hor}, before the "
    "nominal run overturns (<i>t</i> = {t_end}). The members moved least follow the nominal "
    "run and overturn with it; the few moved most decide their own fate, and which of those "
    "settle on the period-7 orbit depends on differences as small as the integration's own "
    "rounding. The reference column was computed by rockjit 0.1.0, which located impacts by a "
    "second Runge&ndash;Kutta step; this version locates them on the step's interpolant, a "
    "change of that size, which redraws those members. The shares are therefore estimates of "
    "one distribution, each member worth {step} points: their difference here is {diff} "
    "member{s}. With the study's embedded forcing, whose phase drifts with the step, far more "
    "members leave the nominal path.")

#: Mean global integrity over alpha = 0.3-0.9, hb = 1, from 100 x 100 basins every 0.01 at 500
#: periods (the documentation quotes it; tests/docs/test_readme.py recomputes it).
GIM_PUBLISHED = {"housner": 0.56, "mao": 0.30}

#: The study's diagrams integrated on past overturning: the percent of amplitudes plotted from
#: motion after the fall, (hb, law) -> percent.
SHARES_PUBLISHED = {(1, "housner"): 7.0, (1, "mao"): 47.1, (2, "housner"): 10.5,
                    (2, "mao"): 45.1}


def _num(v, fmt):
    """``v`` formatted by ``fmt``, or a dash when it is missing or not finite."""
    try:
        v = float(v)
    except (TypeError, ValueError):
        return "–"
    return "–" if not math.isfinite(v) else format(v, fmt)


def published_beside(results):
    """The study's published numbers beside this run's: ``{"e_table": rows,
    "transitions": rows, "fates": rows, "gim": rows, "as_published": rows}``, each row a dict
    with ``published`` and ``rockjit``."""
    out = {}
    e_rows = []
    mine = {round(r["hb"], 6): r for r in results.get("e_table", [])}
    for hb, (eh, em, de) in E_TABLE_PUBLISHED.items():
        r = mine.get(round(hb, 6), {})
        e_rows.append(dict(hb=hb, e_H_published=eh, e_H=r.get("e_H", math.nan),
                           e_M_published=em, e_M=r.get("e_M", math.nan),
                           delta_e_published=de, delta_e=r.get("delta_e_percent", math.nan)))
    out["e_table"] = e_rows
    bifs = results.get("bifurcations", [])
    t_rows = []
    for hb, law, what, kind, period, alpha in TRANSITIONS:
        cand = [b["alpha"] for b in bifs if b["hb"] == hb and b["law"] == law and
                b["type"] == kind and int(b["period"]) == period]
        near = min(cand, key=lambda a: abs(a - alpha)) if cand else math.nan
        t_rows.append(dict(hb=hb, law=law, transition=what, type=kind, period=period,
                           alpha_published=alpha, alpha=near,
                           difference=near - alpha if cand else math.nan))
    out["transitions"] = t_rows
    fates = results.get("fig3_fates", {})
    f_rows = []
    for forcing, probs in FATES_PUBLISHED.items():
        got = fates.get(forcing, {}).get("probabilities", {})
        for outcome, pub in probs.items():
            if outcome == "overturn":
                v = got.get("overturn", 0.0) if got else math.nan
            else:
                per = outcome.split("-")[1]
                v = sum(x for k, x in got.items() if f" p={per} " in f"{k} ") if got \
                    else math.nan
            f_rows.append(dict(forcing=forcing, outcome=outcome, published=pub, rockjit=v))
    out["fates"] = f_rows
    closed = fates.get("closed", {})
    n = (closed.get("settings") or {}).get("ensemble")
    if n:
        over = next((r for r in f_rows if r["forcing"] == "closed" and
                     r["outcome"] == "overturn"), None)
        diff = round(abs(over["rockjit"] - over["published"]) * n) if over and \
            math.isfinite(over["rockjit"]) else math.nan
        out["fates_note"] = FATES_NOTE.format(
            n=n, lam=_num(closed.get("lambda1"), ".2f"), hor=_num(closed.get("horizon"), ".0f"),
            t_end=_num((closed.get("nominal") or {}).get("t_end"), ".1f"),
            step=_num(100 / n, ".1f"), diff=diff, s="" if diff == 1 else "s")
    g_rows = []
    prof = results.get("fig8", {}).get("hb1", {})
    for law, pub in GIM_PUBLISHED.items():
        r = prof.get(law)
        v = math.nan
        if r is not None:
            a, gim = np.asarray(r["alpha"], float), np.asarray(r["GIM"], float)
            m = (a >= 0.3 - 1e-9) & (a <= 0.9 + 1e-9)
            v = float(gim[m].mean()) if m.any() else math.nan
        g_rows.append(dict(law=law, published=pub, rockjit=v))
    out["gim"] = g_rows
    pub = results.get("fig5_as_published")
    if pub:
        out["as_published"] = [dict(hb=hb, law=law, published=share,
                                    rockjit=pub.get(f"hb{hb}_{law}", {}).get(
                                        "plotted_after_fall_percent", math.nan))
                               for (hb, law), share in SHARES_PUBLISHED.items()]
    return out


# ---------------------------------------------------------------------------------------------
# the page
# ---------------------------------------------------------------------------------------------

_CSS = """
body { font-family: Georgia, 'DejaVu Serif', serif; max-width: 70rem; margin: 2rem auto;
       padding: 0 1rem; line-height: 1.45; color: #222; }
h1 { font-size: 1.7rem; } h2 { margin-top: 2.5rem; border-bottom: 1px solid #ccc; }
figure { margin: 1rem 0 2rem; } figure img { max-width: 100%; height: auto;
       border: 1px solid #eee; }
figcaption { font-size: 0.95rem; color: #333; margin-top: 0.4rem; }
table { border-collapse: collapse; margin: 0.8rem 0 1.5rem; font-size: 0.88rem; }
th, td { border: 1px solid #ccc; padding: 0.2rem 0.5rem; text-align: right; }
th { background: #f3f3f3; } td.l, th.l { text-align: left; }
nav ul { columns: 2; } code { font-size: 0.9em; }
.note { color: #555; font-size: 0.9rem; }
"""


def _table(header, rows, left=()):
    """An HTML table, the columns numbered in ``left`` aligned left."""
    h = "".join(f'<th class="l">{html.escape(c)}</th>' if i in left else
                f"<th>{html.escape(c)}</th>" for i, c in enumerate(header))
    body = []
    for r in rows:
        body.append("<tr>" + "".join(
            f'<td class="l">{html.escape(str(v))}</td>' if i in left else
            f"<td>{html.escape(str(v))}</td>" for i, v in enumerate(r)) + "</tr>")
    return f"<table><thead><tr>{h}</tr></thead><tbody>{''.join(body)}</tbody></table>"


def _img(name, alt):
    """An image of the page, or a link to it when it is a PDF."""
    if name.endswith(".pdf"):
        return (f'<p><a href="{html.escape(name)}">{html.escape(name)}</a> '
                f'(PDF)</p>')
    return f'<img src="{html.escape(name)}" alt="{html.escape(alt)}">'


def _caption_restitution(results, plan):
    """Figure 1's caption: the two laws against the block's angle."""
    return ("The restitution laws. Housner's <i>e</i><sub>H</sub> (solid) and Mao et al.'s "
            "<i>e</i><sub>M</sub> (dashed) against the block's angle &theta;<sub>c</sub>, for "
            f"<i>h/b</i> from 1/&radic;2 to {E_FIGURE_HB_MAX:g}, with their symmetric difference "
            "&Delta;<i>e</i> "
            "(dotted, right axis). The boxes give the values at <i>h/b</i> = 1 and 2 (the "
            "e-table below).")


def _caption_reference(results, plan):
    """Figure 2's caption: the reference run, its window and its two exponents."""
    f2 = results.get("fig2", {})
    lam = _num(f2.get("lambda_window"), ".4f")
    flo = _num(f2.get("lambda_max"), ".4f")
    w0, w1 = Integration(periods=plan.periods).window_start(), plan.periods
    ref = REFERENCE_RUN
    return (f"The reference symmetric run: &alpha; = {ref['alpha']:g}, &omega; = "
            f"{ref['omega']:g}, <i>h/b</i> = {ref['hb']:g}, {ref['law'].capitalize()}, from the "
            "study's <i>z</i><sub>0</sub>. a) &theta;(<i>t</i>) over the "
            f"first {FIRST_PERIODS} periods (the transient) and b) over the last "
            f"{LAST_PERIODS}; c) the running "
            "largest Lyapunov exponent from <i>t</i> = 0, its average over the asymptotic window "
            f"[{w0}<i>T</i>, {w1}<i>T</i>] ({lam}, dashed) and the Floquet exponent of the "
            f"orbit ({flo}, dotted); d) the phase portrait over the window. Impacts are the "
            "vertical jumps at &theta; = 0, circles the stroboscopic points <i>t</i> = "
            "<i>kT</i>.")


def _caption_gallery(results, plan):
    """Figure 3's caption: the gallery's cases, with the transient chaos's fates."""
    fates = results.get("fig3_fates", {})
    fw = "; ".join(f"{k}: " + ", ".join(f"{n} {v:.0%}" for n, v in
                                        f.get("probabilities", {}).items())
                   for k, f in fates.items())
    n_fate = (fates.get("closed", {}).get("settings") or {}).get("ensemble", "the")
    tilt = GALLERY["rest after damped rocking"][3][0]
    return ("The behaviour gallery (Housner), one row per case: &theta;(<i>t</i>) over the "
            f"first {FIRST_PERIODS} and the last {LAST_PERIODS} periods (the whole run when it "
            "is short), and "
            "the phase portrait of the asymptotic window (the whole run when it ended before). "
            f"a) rest after damped rocking, from a tilt &theta;<sub>0</sub> = {tilt:g} (the "
            "study's smaller tilt comes to rest too soon to show the decay); b) asymmetric; "
            "c) a robust period-2 orbit of the "
            "multiperiodic family; d) the study's 'multiperiodic' example, transient chaos "
            f"that overturns (over {n_fate} runs within 10<sup>-10</sup> of <i>z</i><sub>0</sub>: "
            f"{html.escape(fw)}); e) overturn.")


def _caption_laws(results, plan):
    """Figure 4's caption: the two laws in time, with each row's own line."""
    caps4 = " ".join(f"{'abc'[i]}) {html.escape(r.get('caption', ''))}"
                     for i, r in enumerate(results.get("fig4", [])))
    laws = LAWS_RUN
    return (f"Housner against Mao et al. in time: <i>h/b</i> = {laws['hb']:g}, &alpha; = "
            f"{laws['alpha']:g}, &omega; = {laws['omega']:g}, "
            "(<i>r</i><sub>0</sub>, <i>s</i><sub>0</sub>) = (0, 1), from three initial states. "
            f"Each row: each law's &theta;(<i>t</i>) over the last {LAWS_PERIODS} periods of its "
            f"run, "
            "where it has settled (the whole run when it overturns or rests sooner), and its "
            f"phase portrait, in its behaviour's colour. {caps4}")


def _caption_diagrams(results, plan):
    """Figure 5's caption: the bifurcation diagrams, the zoom and the study's way."""
    return ("Bifurcation diagrams: &theta;'(<i>kT</i>) over the classified stretch against "
            "&alpha;, coloured by behaviour, the behaviour of every amplitude in the strip, "
            "and &lambda;<sub>max</sub>(&alpha;) below: the Floquet exponent "
            "ln|&mu;<sub>1</sub>|/(<i>pT</i>) of the exact monodromy where the run settled on "
            "a periodic orbit, the finite-window estimate elsewhere (chaotic, aperiodic); "
            "triangles at the bottom: &lambda; = &minus;&infin; (rest, or an orbit through "
            "rest). Both laws at <i>h/b</i> = 1 (&omega; = 1.3) and 2 (&omega; = 1.6), and a "
            f"zoom of Housner's <i>h/b</i> = 1 diagram over &alpha; &isin; "
            f"[{plan.zoom[0]:g}, {plan.zoom[1]:g}] at a step of {plan.zoom_step:g}."
            + (" The <code>_as_published</code> figures put beside each law the study's way: "
               "integrated on past overturning (grey points: what a fallen block did), its "
               "&lambda;<sub>max</sub> the finite-window estimate." if plan.published else ""))


def _caption_branches(results, plan):
    """Figure 5's continuation: the branches of periodic orbits over the diagrams."""
    return ("Beyond the study: the branches of periodic orbits continued in &alpha; over "
            "each diagram's points (stable solid, unstable dashed; the mirror image of "
            "every asymmetric orbit too, so both arms of each pitchfork), each branch in "
            "the colour of the behaviour its stable orbits have, periods 3 and 4 with "
            "triangles and squares along the line and periods 5 and more as one group "
            "(circles). Markers: the located "
            "bifurcations, and where a branch stops (the block overturns or comes to rest, "
            "an impact grazes). Each figure's list of bifurcations with their multipliers, "
            "and of branches with where they stop, is its <code>.md</code> file.")


def _caption_basins(results, plan):
    """Figure 6's caption: both laws' basins of the two cases and where they agree."""
    g = plan.grid
    (hb1, a1, o1), (hb2, a2, o2) = BASIN_CASES
    return (f"Basins of attraction of both laws ({g} &times; {g} initial states "
            "(&theta;<sub>0</sub>, &theta;'<sub>0</sub>) at (<i>r</i><sub>0</sub>, "
            f"<i>s</i><sub>0</sub>) = (0, 1)) at <i>h/b</i> = {hb1:g} (&alpha; = {a1:g}, "
            f"&omega; = {o1:g}) and {hb2:g} (&alpha; = {a2:g}, &omega; = {o2:g}), with the "
            "percentage of each behaviour, and "
            "c) the cells where the laws give the same behaviour (white) or not (black).")


def _caption_attractors(results, plan):
    """Figure 7's caption: the attractor maps and their measures."""
    return ("Beyond the study: the attractor each initial state of figure 6 reaches, each in "
            "a tint of its behaviour's colour and named by what it is (the study's single "
            "'symmetric' class is two attractors: a rocking orbit and an orbit that comes to "
            "rest every half period, with Floquet multipliers 0), cycle points starred; basin "
            "entropy <i>S</i><sub>b</sub>, boundary basin entropy <i>S</i><sub>bb</sub>, "
            "global integrity GIM and integrity factor IF in the titles.")


def _caption_erosion(results, plan):
    """Figure 8's caption: the erosion profiles, their grid and their step."""
    eg, es = plan.erosion_grid, plan.erosion_step
    return (f"Beyond the study: erosion profiles, a {eg} &times; {eg} basin every "
            f"&Delta;&alpha; = {es:g}. a) GIM and b) IF against &alpha; for both laws; below, "
            "for each law, "
            "the basin of each attractor followed across the amplitudes, stacked as steps "
            "(each basin holds for its own amplitude), overturn on top. Attractors of one kind "
            "(behaviour, period, rocking or through rest: hatched) share one colour and one "
            "legend entry, parted by thin white lines. The basins compute no Lyapunov "
            "exponent, so what figure 5 calls chaotic is counted as aperiodic here (no period "
            "up to 16).")


def _caption_plane(results, plan):
    """Figure 9's caption: the forcing plane with its curves, seeded where the chart says."""
    seeds = " and ".join(f"{w:g}" for w in CHART["curves"]["seed_omegas"])
    return ("Beyond the study: the forcing plane (&alpha;, &omega;) of both laws at <i>h/b</i> "
            "= 1 and 2, from the study's <i>z</i><sub>0</sub>, a coarse brute-force chart of "
            "behaviours with the bifurcation curves of the period-1 orbits followed across it "
            "by two-parameter continuation (fold solid, symmetry breaking dashed, period "
            f"doubling dash-dotted, grazing dotted), seeded on the lines &omega; = {seeds}; "
            "a) and b) each law alone, c) both laws' curves overlaid (hatched: the laws' "
            "behaviours differ). Cells are drawn six times finer, each behaviour's share "
            "interpolated linearly between the computed cells. "
            "<code>rockjit chart</code> computes the 200 &times; 200 chart and the period-2 "
            "curves.")


#: Each figure's caption, written from the results and the plan (the study's words,
#: docs/theory/study.md, and what is drawn).
_CAPTIONS = {1: _caption_restitution, 2: _caption_reference, 3: _caption_gallery,
             4: _caption_laws, 5: _caption_diagrams, "5b": _caption_branches,
             6: _caption_basins, 7: _caption_attractors, 8: _caption_erosion,
             9: _caption_plane}


def _captions(results, plan):
    """Each figure's caption (the study's words, docs/theory/study.md, and what is drawn)."""
    return {k: caption(results, plan) for k, caption in _CAPTIONS.items()}


_TITLES = {1: "Figure 1. Restitution laws", 2: "Figure 2. The reference symmetric run",
           3: "Figure 3. The behaviour gallery", 4: "Figure 4. Housner against Mao in time",
           5: "Figure 5. Bifurcation diagrams", "5b": "Figure 5, continued: periodic orbits",
           6: "Figure 6. Basins of attraction", 7: "Figure 7. Attractor maps",
           8: "Figure 8. Erosion profiles", 9: "Figure 9. The forcing plane"}


def _published_html(pub):
    """The study's published numbers beside this run's, as the page's tables."""
    parts = []
    parts.append("<h3>The restitution table</h3>")
    parts.append(_table(["h/b", "e_H study", "e_H rockjit", "e_M study", "e_M rockjit",
                         "Δe % study", "Δe % rockjit"],
                        [[_num(r["hb"], "g"), _num(r["e_H_published"], ".3f"),
                          _num(r["e_H"], ".3f"), _num(r["e_M_published"], ".3f"),
                          _num(r["e_M"], ".3f"), _num(r["delta_e_published"], ".2f"),
                          _num(r["delta_e"], ".2f")] for r in pub["e_table"]]))
    parts.append("<h3>Where the transitions are</h3><p class='note'>The study describes its "
                 "diagrams in words; the reference values are those located by continuation "
                 "(docs/theory/study.md, &ldquo;Where the study's transitions are&rdquo;), "
                 "beside the nearest bifurcation of the same type and period this run located "
                 "(&ndash;: none, the continuation being seeded by this run's sweeps, whose "
                 "step may miss a window).</p>")
    parts.append(_table(["h/b", "law", "transition", "α reference", "α this run",
                         "difference"],
                        [[r["hb"], LAW_NAMES.get(r["law"], r["law"]), r["transition"],
                          _num(r["alpha_published"], ".7f"), _num(r["alpha"], ".7f"),
                          _num(r["difference"], ".1e")] for r in pub["transitions"]],
                        left=(1, 2)))
    parts.append("<h3>The study's 'multiperiodic' example</h3>")
    if pub.get("fates_note"):
        parts.append(f"<p class='note'>{pub['fates_note']}</p>")
    parts.append(_table(["forcing", "outcome", "reference (rockjit 0.1.0)", "this run"],
                        [[r["forcing"], r["outcome"], _num(r["published"], ".0%"),
                          _num(r["rockjit"], ".0%")] for r in pub["fates"]], left=(0, 1)))
    parts.append("<h3>Global integrity, h/b = 1</h3><p class='note'>Mean GIM over &alpha; = "
                 "0.3&ndash;0.9; the reference from 100 &times; 100 basins every 0.01, this "
                 "run from its erosion profiles' grid.</p>")
    parts.append(_table(["law", "reference", "this run"],
                        [[LAW_NAMES.get(r["law"], r["law"]), _num(r["published"], ".2f"),
                          _num(r["rockjit"], ".2f")] for r in pub["gim"]], left=(0,)))
    if "as_published" in pub:
        parts.append("<h3>The study's diagrams integrated past overturning</h3>")
        parts.append(_table(["h/b", "law", "share plotted after the fall, reference",
                             "this run"],
                            [[r["hb"], LAW_NAMES.get(r["law"], r["law"]),
                              _num(r["published"], ".1f") + " %",
                              _num(r["rockjit"], ".1f") + " %"] for r in pub["as_published"]],
                            left=(1,)))
    return "".join(parts)


def _results_tables(results):
    """The run's tables (restitution, sweeps, basins, attractors, bifurcations) in HTML."""
    from ..result import BEHAVIOURS
    parts = []
    e = results.get("e_table", [])
    if e:
        parts.append("<h3 id='e_table'>e_table: the restitution laws</h3>")
        parts.append(_table(["h/b", "θc", "e_H", "e_M", "Δe %"],
                            [[_num(r["hb"], "g"), _num(r["thc"], ".4f"), _num(r["e_H"], ".3f"),
                              _num(r["e_M"], ".3f"), _num(r["delta_e_percent"], ".2f")]
                             for r in e]))
    sw = results.get("fig5", [])
    if sw:
        parts.append("<h3 id='sweep_table'>sweep_table: percent of amplitudes per behaviour"
                     "</h3>")
        parts.append(_table(["h/b", "law", "ω", "α from", "to", "n"] + list(BEHAVIOURS),
                            [[_num(r["hb"], "g"), r["law"], _num(r["omega"], "g"),
                              _num(r["alpha_start"], "g"), _num(r["alpha_end"], "g"),
                              r["n_alpha"]] + [_num(r[f"{n}_percent"], ".1f")
                                               for n in BEHAVIOURS] for r in sw], left=(1,)))
    b6 = results.get("fig6", [])
    if b6:
        parts.append("<h3 id='basin_table'>basin_table: percent of cells per behaviour</h3>")
        rows = []
        for e in b6:
            for law in ("housner", "mao"):
                fr = e[law]["fractions"]
                rows.append([_num(e["hb"], "g"), _num(e["alpha"], "g"), _num(e["omega"], "g"),
                             LAW_NAMES[law]] + [_num(fr[n], ".1f") for n in BEHAVIOURS]
                            + [_num(e["agreement"], ".1f")])
        parts.append(_table(["h/b", "α", "ω", "law"] + list(BEHAVIOURS) + ["agreement %"],
                            rows, left=(3,)))
    a7 = results.get("fig7", [])
    if a7:
        parts.append("<h3 id='attractor_table'>attractor_table: attractors, entropy, "
                     "integrity</h3>")
        rows = []
        for e in a7:
            for law in ("housner", "mao"):
                m = e[law]
                rows.append([_num(e["hb"], "g"), LAW_NAMES[law], len(m["attractors"]),
                             "; ".join(f"{a['name'].replace('$', '')} {a['fraction']:.1f} %"
                                       for a in m["attractors"]),
                             _num(m["basin_entropy"], ".3f"),
                             _num(m["boundary_basin_entropy"], ".3f"),
                             _num(m["uncertainty_exponent"]["alpha"], ".3f"),
                             _num(m["integrity"]["GIM"], ".3f"),
                             _num(m["integrity"]["IF"], ".3f"),
                             _num(e["attractor_agreement"]["percent"], ".1f")])
        parts.append(_table(["h/b", "law", "n", "attractors", "S_b", "S_bb", "uncertainty "
                             "exponent", "GIM", "IF", "attractor agreement %"], rows,
                            left=(1, 3)))
    bif = results.get("bifurcations", [])
    if bif:
        parts.append("<h3 id='bifurcation_table'>bifurcation_table: every located "
                     "bifurcation</h3>")
        parts.append(_table(["h/b", "law", "type", "α", "period", "|μ1|", "|μ2|"],
                            [[_num(r["hb"], "g"), LAW_NAMES.get(r["law"], r["law"]),
                              r["type"].replace("_", " "), _num(r["alpha"], ".9f"), r["period"],
                              _num(r["abs_mu1"], ".4g"), _num(r["abs_mu2"], ".4g")]
                             for r in bif], left=(1, 2)))
    return "".join(parts)


def write_index(out, results, figures, plan):
    """Write ``index.html`` into ``out`` and describe it.

    ``figures`` maps a figure's number (1-8, ``"5b"`` for the branches) to the names of its
    image files as written.
    """
    from .. import __version__
    caps = _captions(results, plan)
    name = "index.html"
    holds = dict(getattr(out, "holds", {}))
    holds[name] = "this page: every figure with its caption, every table, the study's " \
                  "published numbers beside this run's, and every file"
    holds.setdefault("summary.json", "every number of this run (and this list of files, "
                                     "as files: [{name, holds}]), the inputs, rockjit's "
                                     "version, the wall times")
    names = sorted(set(out.written) | {name, "summary.json"})
    data = {n for n in names if n.endswith((".npz", ".csv", ".md"))}
    body = [f"<h1>The forced rocking block: Housner's and Mao et al.'s restitution laws</h1>",
            f"<p>Every figure and table of the study (docs/theory/study.md), recomputed by "
            f"rockjit {html.escape(__version__)} on "
            f"{datetime.date.today().isoformat()}: {plan.periods} forcing periods, amplitude "
            f"step {plan.alpha_step:g}, basins of {plan.grid} &times; {plan.grid} cells, "
            f"erosion profiles of {plan.erosion_grid} &times; {plan.erosion_grid} every "
            f"{plan.erosion_step:g}. The numbers are in <a href='summary.json'>summary.json"
            f"</a>; every file is listed <a href='#files'>at the end</a>.</p>",
            "<nav><ul>"]
    for k, title in _TITLES.items():
        if figures.get(k):
            body.append(f"<li><a href='#fig{k}'>{html.escape(title)}</a></li>")
    body.append("<li><a href='#published'>The study's numbers beside this run's</a></li>"
                "<li><a href='#tables'>Tables</a></li><li><a href='#files'>Files</a></li>"
                "</ul></nav>")
    for k, title in _TITLES.items():
        imgs = figures.get(k) or []
        if not imgs:
            continue
        body.append(f"<section id='fig{k}'><h2>{html.escape(title)}</h2>")
        for img in imgs:
            stem = img.rsplit(".", 1)[0]
            linked = [n for n in sorted(data) if n.startswith(stem) or
                      (n.rsplit(".", 1)[0] in holds.get(img, "") and n != img)]
            extra = (" Data and captions: " + ", ".join(
                f"<a href='{html.escape(n)}'>{html.escape(n)}</a>" for n in linked) + ".") \
                if linked else ""
            body.append(f"<figure>{_img(img, title)}<figcaption><b>{html.escape(img)}</b>. "
                        f"{caps.get(k, '')}{extra}</figcaption></figure>")
        body.append("</section>")
    pub = results.get("published") or {}
    if pub:
        body.append("<section id='published'><h2>The study's numbers beside this run's</h2>"
                    + _published_html(pub) + "</section>")
    body.append("<section id='tables'><h2>Tables</h2><p class='note'>Also as CSV and "
                "Markdown files (listed below).</p>" + _results_tables(results) + "</section>")
    body.append("<section id='files'><h2>Files</h2>")
    body.append("<table><thead><tr><th class='l'>file</th><th class='l'>what it holds</th>"
                "</tr></thead><tbody>")
    for n in names:
        body.append(f"<tr><td class='l'><a href='{html.escape(n)}'>{html.escape(n)}</a></td>"
                    f"<td class='l'>{html.escape(holds.get(n, ''))}</td></tr>")
    body.append("</tbody></table></section>")
    page = ("<!DOCTYPE html>\n<html lang='en'><head><meta charset='utf-8'>"
            "<meta name='viewport' content='width=device-width, initial-scale=1'>"
            "<title>rockjit: the study's figures and tables</title>"
            f"<style>{_CSS}</style></head><body>\n" + "\n".join(body) + "\n</body></html>\n")
    out.text(name, page)
    if hasattr(out, "describe"):
        out.describe(name, holds[name])
    return name
