"""Figures of periodic-orbit branches (:mod:`rockjit.orbits`): the continued branches over a
sweep's stroboscopic points with their bifurcations and branch ends marked
(:func:`fig_branches`), and the Markdown caption that lists them (:func:`branch_caption`)."""

from __future__ import annotations

import numpy as np

from . import style as S
from .common import GROUPED_PERIOD, PAD
from .style import BEHAVIOUR_COLOURS, SYMBOLS

__all__ = ["BIFURCATION_MARKERS", "END_MARKERS", "branch_caption", "fig_branches"]


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


# How the branches of each period are told apart: colour (the behaviour their stable orbits
# have), and for periods past 2 a marker along the line; periods from GROUPED_PERIOD on are one
# group.
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
    c = continuation
    comp = int(component)
    if comp not in (0, 1):
        raise ValueError(f"component must be 0 (theta) or 1 (theta') (got {component!r})")
    fig = S.figure("double", 0.66, pad=PAD)
    ax = fig.add_subplot()
    legend = _Legend()
    if sweep is not None:
        _sweep_dots(ax, sweep, comp, legend)
    groups = _branch_lines(ax, c, comp, mirrors, legend)
    _bifurcation_marks(ax, c, comp, mirrors, legend)
    ends = _branch_ends(c, comp, mirrors)
    view = _set_view(ax, c, comp, limits)
    _end_marks(ax, ends, view, legend)
    fig.legend(handles=legend.handles(groups, view), loc="outside lower center", ncols=3)
    b, f = c.block, c.forcing
    fixed = (f"$\\omega = {f.omega:g}$" if c.parameter == "alpha" else
             f"$\\alpha = {f.alpha:g}$")
    S.suptitle(fig, title or f"Periodic orbits, {S.law_name(b)}, $h/b = {b.hb:g}$, {fixed}; "
                             f"sampled at $t = kT$ at the forcing phase "
                             f"$\\varphi = {c.phase:.4g}$ of the study's $z_0$")
    return fig


def _in_view(artist, view):
    """Whether any point of a line or a scatter lies within ``view``, ``((x0, x1), (y0, y1))``."""
    (x0, x1), (y0, y1) = view
    if hasattr(artist, "get_offsets"):
        xy = np.asarray(artist.get_offsets(), float).reshape(-1, 2)
    else:
        xy = np.column_stack([np.asarray(v, float) for v in artist.get_data()])
    return bool(np.any((xy[:, 0] >= min(x0, x1)) & (xy[:, 0] <= max(x0, x1))
                       & (xy[:, 1] >= min(y0, y1)) & (xy[:, 1] <= max(y0, y1))))


class _Legend:
    """The legend of :func:`fig_branches`: each entry's handle with the artists it names; an
    entry is kept when one of its artists draws within the view."""

    def __init__(self):
        self.entries = {}   # key -> (handle, artists)

    def add(self, key, handle, artist):
        """Name ``artist`` by the entry ``key`` (whose handle is the first one given)."""
        self.entries.setdefault(key, (handle, []))[1].append(artist)

    def handles(self, groups, view):
        """The handles of the entries drawn within ``view``: the sweep's behaviours, the
        branches' groups (in ``groups``' order), solid and dashed where such lines show, then
        bifurcations and branch ends."""
        from matplotlib.lines import Line2D
        entries = self.entries
        stab = [(Line2D([], [], color="0.3", lw=1.1, ls="-", label="stable orbits: solid"),
                 True),
                (Line2D([], [], color="0.3", lw=0.8, ls=(0, (3.0, 1.5)),
                        label="unstable orbits: dashed"), False)]
        shown = [key for key, (_, arts) in entries.items()
                 if any(_in_view(a, view) for a in arts)]
        handles = [entries[key][0] for key in shown
                   if isinstance(key, str) and key.startswith("sweep ")]
        branch_lines = [ln for key in shown if isinstance(key, tuple) for ln in entries[key][1]
                        if _in_view(ln, view)]
        handles += [entries[key][0] for key in groups if key in shown]
        for h, stable in stab:
            if any((ln.get_linestyle() == "-") == stable for ln in branch_lines):
                handles.append(h)
        handles += [entries[key][0] for key in shown if isinstance(key, str)
                    and not key.startswith("sweep ")]
        return handles


def _sweep_dots(ax, sweep, comp, legend):
    """The sweep's stroboscopic points beneath the branches, small dots tinted by behaviour."""
    from matplotlib.lines import Line2D
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
        legend.add(f"sweep {name}", Line2D([], [], ls="", marker="o", ms=3.5,
                                           color=S.tint(BEHAVIOUR_COLOURS[name], 0.35),
                                           label=f"sweep: {name}"), dots)


def _branch_lines(ax, c, comp, mirrors, legend):
    """Every branch's line through each of its cycle points (and its mirror orbit's), solid
    where stable and dashed where not, in its group's colour and marker; returns the groups
    in the legend's order (by period, symmetric first)."""
    from matplotlib.lines import Line2D
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
                    legend.add(group, None, line)
    for group in groups:
        lab, colour, mk = group
        if group in legend.entries:
            legend.entries[group] = (Line2D([], [], color=colour, lw=1.4, marker=mk or "",
                                            ms=3.5, label=lab), legend.entries[group][1])
    return groups


def _bifurcation_marks(ax, c, comp, mirrors, legend):
    """Each located bifurcation's cycle points (and its mirror's), in its type's marker."""
    from matplotlib.lines import Line2D
    for bf in sorted(c.bifurcations, key=lambda b: b.value):
        mk = BIFURCATION_MARKERS.get(bf.type, "o")
        pts_b = [np.asarray(bf.cycle)]
        if mirrors and bf.has_mirror and getattr(bf, "cycle_half", None) is not None:
            pts_b.append(-np.asarray(bf.cycle_half))
        for cy in pts_b:
            dots = ax.scatter(np.full(cy.shape[0], bf.value), cy[:, comp], marker=mk,
                              s=22 if bf.period <= 2 else 11, facecolor="white", edgecolor="k",
                              lw=0.8, zorder=5)
            legend.add(f"bif {bf.type}", Line2D([], [], ls="", marker=mk, ms=4.5,
                                                markerfacecolor="white", markeredgecolor="k",
                                                label=_BIF_WORDS.get(bf.type, bf.type)), dots)


def _branch_ends(c, comp, mirrors):
    """Where branches stop inside the range, and why: ``{(marker, words): {"points": [(x, y)],
    "branches": n}}``, every cycle point of each stopping end."""
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
    return ends


def _set_view(ax, c, comp, limits):
    """The axes' labels and range: the continuation's bounds, or ``limits`` with the vertical
    range fitted to what is drawn within them; returns the view ``((x0, x1), (y0, y1))``."""
    ax.set_xlabel(SYMBOLS.get(c.parameter, c.parameter))
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
    return ax.get_xlim(), ax.get_ylim()


def _end_marks(ax, ends, view, legend):
    """The branch ends' markers, each point once at the view's resolution (branches that stop
    at one point, each cycle point of a period-p orbit, pile up otherwise)."""
    from matplotlib.lines import Line2D
    (x0, x1), (y0, y1) = view
    for (mk, words), got in ends.items():
        p = np.unique(np.round(np.asarray(got["points"]) /
                               [(x1 - x0) * 2e-3, (y1 - y0) * 2e-3]), axis=0) * \
            [(x1 - x0) * 2e-3, (y1 - y0) * 2e-3]
        line, = ax.plot(p[:, 0], p[:, 1], ls="", marker=mk, ms=4.5, color="k", mew=1.0,
                        zorder=6)
        n = got["branches"]
        legend.add(f"end {words}", Line2D([], [], ls="", marker=mk, ms=4.5, color="k", mew=1.0,
                                          label=f"{words} ({n} branch{'es' if n > 1 else ''})"),
                   line)


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
