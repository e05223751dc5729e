"""The study rockjit reproduces (docs/theory/study.md): every constant of it, and its pipeline,
``paper``.

The constants are the study's parameters: the slenderness ratios with their forcing frequencies
and amplitude ranges, the sweeps' step, the zoom, the initial states of the single runs, the
gallery, the basins. :func:`plan_paper` validates a paper's settings (nothing computed) and
:func:`paper` computes every figure and table and writes them into an output directory object
(:class:`rockjit.storage.output_dir.OutputDir` on the command line): figures 1-6 of the study, and beyond it
the branches of periodic orbits over its bifurcation diagrams with their located bifurcations
(figure 5's ``fig5_branches_*``, ``bifurcation_table``), the attractor maps of its basins with
their entropy and integrity (figure 7) and the erosion profiles of both laws (figure 8). Its
grids run on the chunk store, so an interrupted paper resumes, and on a Dask cluster when a
client is given.
"""

from __future__ import annotations

import math
import time
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from ..basins.erosion import erosion
from ..basins.erosion import run as erosion_run
from ..basins.fate import fate
from ..excitation import Harmonic
from ..grids import alpha_grid, basin, sweep
from ..grids.plan import run as run_grid
from ..model import Block, delta_e_percent, e_housner, e_mao, thc_from_hb
from ..result import BEHAVIOURS
from ..settings import Execution, Integration
from ..single import DEFAULT_N, classify_result, simulate
from ..validate import integer, memory, pair, real
from .settings import (  # noqa: F401  (the study's settings, by their names here too)
    Z0, STUDY, ALPHA_STEP, PERIODS, WINDOW, ZOOM, REFERENCE_RUN, GALLERY, TRANSIENT_CHAOS,
    FATE_ENSEMBLE, LAWS_RUN, LAWS_IC, BASIN_CASES, BASIN_GRID, EROSION, EROSION_STEP,
    EROSION_GRID, E_TABLE_HB, E_FIGURE_HB_MAX, MAX_TRAJ_POINTS, FIRST_PERIODS, LAST_PERIODS,
    LAWS_PERIODS, CHART)

__all__ = ["ALPHA_STEP", "BASIN_CASES", "BASIN_GRID", "EROSION", "EROSION_GRID", "EROSION_STEP",
           "GALLERY", "LAWS_IC", "LAWS_RUN", "PERIODS", "REFERENCE_RUN", "STUDY", "Z0", "ZOOM",
           "PaperPlan", "after_the_fall", "draw_fig5", "e_table", "paper", "plan_paper"]

E_HEADER = ("hb", "thc", "e_H", "e_M", "delta_e_percent")
ATTRACTOR_HEADER = ("hb", "alpha", "omega", "law", "n_attractors", "basin_entropy",
                    "boundary_basin_entropy", "uncertainty_exponent", "GIM", "IF",
                    "attractor_agreement_percent")
E_FMT = {"hb": "g", "thc": ".4f", "e_H": ".3f", "e_M": ".3f", "delta_e_percent": ".2f"}


def e_table(hb_values):
    """Rows ``(hb, thc, e_H, e_M, delta_e %)`` of the restitution table."""
    rows = []
    for hb in hb_values:
        thc = float(thc_from_hb(hb))
        eh, em = float(e_housner(thc)), float(e_mao(thc))
        rows.append((float(hb), thc, eh, em, float(delta_e_percent(em, eh))))
    return rows


def write_e_table(out, hb_values, hb_max, fig_name, table_stem):
    """Figure 1 with its data (``<fig>.npz``: the curves) and the e-table into ``out``;
    returns the table as dicts."""
    from ..plotting.restitution import fig_restitution
    rows = e_table(hb_values)
    hb_range = (1 / math.sqrt(2), hb_max)
    fig = fig_restitution(hb_range)
    name = out.figure(fig_name, fig) or fig_name
    data = Path(fig_name).stem + ".npz"
    thc = np.linspace(thc_from_hb(hb_range[0]), thc_from_hb(hb_range[1]), 400)
    eh, em = e_housner(thc), e_mao(thc)
    out.npz(data, thc=thc, hb=np.tan(thc), e_H=eh, e_M=em, delta_e_percent=delta_e_percent(em, eh))
    out.table(table_stem, E_HEADER, rows, E_FMT)
    if hasattr(out, "describe"):
        out.describe(name, f"figure 1: e_H and e_M against theta_c with delta e % (data: {data})")
        out.describe(data, "figure 1's curves: thc, hb, e_H, e_M, delta_e_percent")
        for ext in ("csv", "md"):
            out.describe(f"{table_stem}.{ext}", "the restitution table: hb, thc, e_H, e_M, "
                                                "delta e %")
    return [dict(zip(E_HEADER, r)) for r in rows]


@dataclass(frozen=True)
class PaperPlan:
    """Validated settings of :func:`paper`, with every grid's plan made."""

    grid: int
    periods: int
    n_steps: int | None
    alpha_step: float
    zoom: tuple
    zoom_step: float
    sweeps: dict            # (hb, law) -> GridPlan
    zoom_sweep: object      # GridPlan
    basins: dict            # (hb, law) -> GridPlan
    erosions: dict          # (hb, law) -> ErosionPlan
    stride: int
    published: dict         # (hb, law) -> GridPlan of the sweep as the study computed it, or {}
    memory_bytes: float = 0.0
    erosion_grid: int = EROSION_GRID
    erosion_step: float = EROSION_STEP


def plan_paper(*, grid=None, periods=PERIODS, n_steps=None, alpha_step=ALPHA_STEP,
               zoom=ZOOM, zoom_step=None, erosion_step=EROSION_STEP,
               erosion_grid=None, as_published=False, execution=None) -> PaperPlan:
    """Validate a paper's settings; every grid is planned here and the memory of all of them
    together checked, nothing run.

    ``n_steps=None`` takes the library's defaults (``DEFAULT_N`` for single runs, ``GRID_N`` for
    sweeps and basins). ``zoom`` must lie inside the Housner hb=1 range. ``as_published`` adds
    figure 5 as the study computed it: its sweeps integrated on past overturning. ``grid``
    sizes every basin of the paper, the erosion profiles' included (unless ``erosion_grid``
    says otherwise); not given, the study's basins are :data:`BASIN_GRID` cells a side and the
    erosion profiles' survey :data:`EROSION_GRID`.
    """
    execution = Execution() if execution is None else execution
    if erosion_grid is None:
        erosion_grid = EROSION_GRID if grid is None else grid
    grid = integer("grid", BASIN_GRID if grid is None else grid, 2, 10**5)
    periods = integer("periods", periods, 1)
    alpha_step = real("alpha_step", alpha_step, 0.0, 1.0, lo_open=True)
    h_rng = STUDY[1]["alpha_range"]["housner"]
    zoom = pair("zoom", zoom, 0.0, None)
    if zoom[0] < h_rng[0] or zoom[1] > h_rng[1]:
        raise ValueError(f"zoom must lie inside the Housner hb=1 range {h_rng} (got {zoom})")
    integration = Integration(periods=periods, n_steps=n_steps)
    kw = dict(integration=integration, execution=execution, lyapunov=True)
    sweeps = {(hb, law): sweep.plan(Block(hb=float(hb), law=law),
                                    Harmonic(omega=st["omega"]), alpha_grid(rng, alpha_step),
                                    **kw)
              for hb, st in STUDY.items() for law, rng in st["alpha_range"].items()}
    past = dict(kw, integration=integration.replace(stop_at_overturn=False))
    published = {(hb, law): sweep.plan(Block(hb=float(hb), law=law),
                                       Harmonic(omega=st["omega"]),
                                       alpha_grid(rng, alpha_step), **past)
                 for hb, st in STUDY.items() for law, rng in st["alpha_range"].items()} \
        if as_published else {}
    zoom_step = alpha_step / 4 if zoom_step is None else \
        real("zoom_step", zoom_step, 0.0, 1.0, lo_open=True)
    if not (zoom[1] - zoom[0]) / zoom_step < 1e8:
        raise ValueError(f"zoom_step = {zoom_step:g} over zoom {zoom} would make "
                         f"{(zoom[1] - zoom[0]) / zoom_step:.3g} amplitudes; give a larger "
                         f"zoom_step")
    zoom_sweep = sweep.plan(Block(hb=1.0, law="housner"), Harmonic(omega=STUDY[1]["omega"]),
                            alpha_grid(zoom, zoom_step), **kw)
    basins = {(hb, law): basin.plan(Block(hb=hb, law=law),
                                    Harmonic(alpha=alpha, omega=omega, r0=0.0, s0=1.0), grid,
                                    integration=integration, execution=execution)
              for hb, alpha, omega in BASIN_CASES for law in ("housner", "mao")}
    erosion_step = real("erosion_step", erosion_step, 1e-6, 1.0)
    erosion_grid = integer("erosion_grid", erosion_grid, 2, 10**4)
    erosions = {(hb, law): erosion.plan(Block(hb=float(hb), law=law),
                                        Harmonic(omega=ev["omega"], r0=0.0, s0=1.0),
                                        alpha_grid(ev["alpha_range"], erosion_step),
                                        erosion_grid, integration=integration,
                                        execution=execution)
                for hb, ev in EROSION.items() for law in ("housner", "mao")}
    if n_steps is not None:  # single runs take it too: check it against their blocks
        for hb, alpha, omega, _, _ in GALLERY.values():
            simulate.plan(Block(hb=hb), Harmonic(alpha=alpha, omega=omega),
                          integration=integration)
    stride = max(1, math.ceil(periods * (n_steps or DEFAULT_N) / MAX_TRAJ_POINTS))
    total = sum(gp.memory_bytes for gp in (*sweeps.values(), *published.values(),
                                           zoom_sweep, *basins.values())) + \
        sum(ep.grid_plan.memory_bytes for ep in erosions.values())
    memory("the paper's grids together", total)
    return PaperPlan(grid=grid, periods=periods, n_steps=n_steps, alpha_step=alpha_step,
                     zoom=zoom, zoom_step=zoom_step, sweeps=sweeps, zoom_sweep=zoom_sweep,
                     basins=basins, erosions=erosions, stride=stride, published=published,
                     memory_bytes=total, erosion_grid=erosion_grid, erosion_step=erosion_step)


def draw_fig5(sweeps, hb):
    """Figure 5 at slenderness ``hb``: the bifurcation diagrams of ``sweeps`` (``{law:
    SweepResult}``, the paper's sweeps) side by side. The paper draws its figure 5 with it,
    and so does the README's headline image (docs/_static/make_headline.py)."""
    from ..plotting.forcing import fig_bifurcation
    return fig_bifurcation(sweeps, title=f"Bifurcation diagrams, $h/b = {hb:g}$, "
                                         f"$\\omega = {STUDY[hb]['omega']}$")


def after_the_fall(sw):
    """What a sweep integrated past overturning plots where the block fell: the share of its
    amplitudes whose points and exponent come from motion after the fall, and that motion's
    behaviours, exponent signs and distinct attractors (continued along the amplitudes)."""
    from ..grids.identity import identify_along
    fell = np.isfinite(sw.t_overturn)
    plotted = fell & np.isin(sw.motion, [BEHAVIOURS.index(b) for b in
                                         ("symmetric", "asymmetric", "multiperiodic",
                                          "chaotic", "aperiodic")])
    n = sw.alpha.size
    motions = {BEHAVIOURS[c]: int(np.count_nonzero(plotted & (sw.motion == c)))
               for c in np.unique(sw.motion[plotted])}
    # the exponent the study plotted: its finite window's
    lam = (sw.lambda_window if sw.lambda_window is not None else sw.lambda_max)[plotted]
    n_got = np.count_nonzero(np.isfinite(sw.strobe[..., 0]), axis=1)
    label = np.where(plotted, sw.motion, BEHAVIOURS.index("overturn"))
    _, found = identify_along(label, sw.period, sw.strobe, n_got, (n,))
    return dict(n_alpha=n, fell_percent=100.0 * fell.mean(),
                plotted_after_fall_percent=100.0 * plotted.mean(), motions=motions,
                lambda_positive=int(np.count_nonzero(lam > 0)),
                lambda_negative=int(np.count_nonzero(lam <= 0)),
                attractors_after_fall=[dict(behaviour=a.behaviour, period=a.period,
                                            alpha=[float(sw.alpha[a.extent[0]]),
                                                   float(sw.alpha[a.extent[1]])])
                                       for a in found])



# ---------------------------------------------------------------------------------------------
# the pipeline
# ---------------------------------------------------------------------------------------------



def _describe(out, name, holds):
    if hasattr(out, "describe"):
        out.describe(name, holds)


def _figure(out, name, fig, holds):
    """Write a figure (in ``out``'s format), describe it; returns the name written."""
    written = out.figure(name, fig)
    written = written if isinstance(written, str) else name
    _describe(out, written, holds)
    return written


def _npz(out, name, holds, **arrays):
    out.npz(name, **arrays)
    _describe(out, name, holds)
    return name


def _table(out, stem, header, rows, fmt, holds):
    out.table(stem, header, rows, fmt)
    for ext in ("csv", "md"):
        _describe(out, f"{stem}.{ext}", holds)


def _phase_of(res):
    """The forcing phase of a run (its stroboscopic samples carry ``r, s`` at ``t = 0``)."""
    return math.atan2(float(res.strobe[0, 2]), float(res.strobe[0, 3]))


def floquet_of_run(res, behaviour):
    """The Floquet exponent ``ln|mu1| / (pT)`` of the periodic orbit a run settled on (its
    last cycle point), or ``nan`` when it did not settle on one."""
    from ..grids.identity import floquet
    name, p = behaviour
    if name not in ("symmetric", "asymmetric", "multiperiodic") or p < 1 or \
            res.strobe.shape[0] <= p:
        return math.nan
    f = res.forcing
    _, lam = floquet(res.block, Harmonic(alpha=f.alpha, omega=f.omega), _phase_of(res),
                     res.integration, res.n_steps, res.strobe[-1, :2], p)
    return float(lam[0])


def _exponents(res, behaviour, exact=None):
    """A run's ``lambda_max`` as the grids report it: the Floquet exponent of the periodic orbit
    it settled on (exact), else the window's estimate, kept as ``lambda_window``."""
    exact = floquet_of_run(res, behaviour) if exact is None else exact
    return dict(lambda_max=exact if math.isfinite(exact) or exact == -math.inf
                else res.lambda_max, lambda_window=res.lambda_max)


def _drawn(res, prefix, first=FIRST_PERIODS, last=LAST_PERIODS):
    """The arrays a time-series figure draws of one run: ``theta(t)`` over its first and last
    periods and the phase portrait's stretch, impacts inserted (``t, theta, dtheta``), and its
    stroboscopic samples."""
    from ..plotting.timeseries import with_impacts
    T = res.period
    t_w = res.window[0] if res.window is not None else 0.8 * res.periods * T
    out = {}
    for what, (t0, t1) in (("first", (0.0, first * T)), ("last", (res.t - last * T, res.t)),
                           ("phase", (t_w if res.t > t_w + T else 0.0, res.t))):
        t, th, dth = with_impacts(res, t0, t1)
        out.update({f"{prefix}{what}_t": t, f"{prefix}{what}_theta": th,
                    f"{prefix}{what}_dtheta": dth})
    out[f"{prefix}strobe"] = res.strobe[:, :2]
    out[f"{prefix}impacts"] = res.impacts
    return out


def _outcome_words(probabilities):
    from ..plotting.fates import _outcome_names
    words, _ = _outcome_names(list(probabilities))
    return ", ".join(f"{words[k]} {v:.0%}" for k, v in probabilities.items())


def _same_orbit(a, b, behaviour_a, behaviour_b, tol=1e-4):
    """Two runs of one system that settled on the same periodic orbit (cycles within ``tol``
    of their size, any shift)."""
    from ..grids.cycles import cycle_distance, cycle_size
    if behaviour_a != behaviour_b or behaviour_a[0] not in ("symmetric", "asymmetric",
                                                            "multiperiodic"):
        return False
    p = behaviour_a[1]
    ca, cb = a.strobe[-p:, :2], b.strobe[-p:, :2]
    return bool(cycle_distance(ca, cb) <= tol * max(cycle_size(ca), cycle_size(cb), 1e-12))


def laws_captions(rows, behaviours):
    """The line under each row of figure 4: what each law's run does, and which rows reach the
    same orbit."""
    from ..plotting.style import law_name
    letters = "abcdefgh"
    caps = []
    for i, row in enumerate(rows):
        parts = []
        for law, res in row.items():
            beh = behaviours[i][law]
            name, p = beh
            what = (f"overturns at $t = {res.t:.3g}$" if res.status == "overturned" else
                    f"comes to rest at $t = {res.t:.3g}$" if res.status == "rest" else
                    f"settles on a {name} period-{p} orbit" if p else f"is {name}")
            same = [letters[j] for j, other in enumerate(rows) if j != i and
                    law in other and _same_orbit(res, other[law], beh, behaviours[j][law])]
            if same:
                what += f" (the one of row{'s' if len(same) > 1 else ''} {', '.join(same)})"
            parts.append(f"{law_name(res.block)} {what}")
        caps.append("; ".join(parts) + ".")
    return caps


def paper(out, plan=None, *, execution=None, say=None):
    """Compute every figure and table of the study into ``out``; returns the summary's results.

    Every figure has its data file, every file is described (``out.describe``, the summary's
    manifest) and ``index.html`` shows them all, with the study's published numbers beside
    this run's (:mod:`rockjit.study.report`).

    Parameters
    ----------
    out : rockjit.storage.output_dir.OutputDir
        Where the files go (``json``, ``npz``, ``figure``, ``table``, ``text`` methods); the
        caller publishes it.
    plan : PaperPlan, optional
        From :func:`plan_paper`; default the study's settings.
    execution : Execution, optional
        The grids' progress, Dask client and chunk store: with a store directory, each grid
        keeps its chunks in a store of its own beneath it, so that an interrupted paper
        resumes.
    say : callable, optional
        ``say(message)`` for one line of progress per part.
    """
    from ..grids.identity import agreement, attractor_agreement
    from ..orbits import continue_branches
    from ..plotting.basins import fig_attractors, fig_basin_compare, fig_erosion
    from ..plotting.branches import branch_caption, fig_branches
    from ..plotting.forcing import fig_bifurcation
    from ..plotting.timeseries import fig_gallery, fig_laws_timeseries, fig_trajectory
    from ..plotting.style import attractor_names
    from . import report

    p = plan_paper() if plan is None else plan
    execution = Execution() if execution is None else execution
    say = say or (lambda msg: None)
    walls = {}
    results = {}
    figures = {}  # figure number -> names written, for the report
    n_parts = 8
    basins_done = {}
    integration = Integration(periods=p.periods, n_steps=p.n_steps)
    run_kw = dict(integration=integration, record_stride=p.stride, lyapunov=True)
    t_all = time.perf_counter()

    def within(name):
        """The execution of one grid: its own chunk store beneath the paper's."""
        store = execution.store
        return execution.replace(store=None if store is None else Path(store) / name)

    def grid(gp, name):
        return run_grid(gp, within(name))

    def part(i, name, what):
        say(f"paper [{i}/{n_parts}] {name}: {what}")
        return time.perf_counter()

    def done(name, t0):
        walls[name] = time.perf_counter() - t0
        say(f"paper: {name} done in {walls[name]:.1f} s")

    t0 = part(1, "fig1", "restitution laws and the e-table")
    results["e_table"] = write_e_table(out, E_TABLE_HB, E_FIGURE_HB_MAX, "fig1_restitution.png",
                                       "e_table")
    figures[1] = [n for n in out.written if n.startswith("fig1_") and not n.endswith(".npz")]
    done("fig1", t0)

    t0 = part(2, "fig2", "reference run alpha=0.6, omega=1.3, hb=1, Housner")
    ref = simulate(Block(hb=REFERENCE_RUN["hb"], law=REFERENCE_RUN["law"]),
                   Harmonic(alpha=REFERENCE_RUN["alpha"], omega=REFERENCE_RUN["omega"]),
                   **run_kw)
    beh = classify_result(ref)
    exact = floquet_of_run(ref, beh)
    tr = ref.trajectory
    _npz(out, "fig2_reference.npz", "figure 2's run: t, theta, dtheta (recorded trajectory), "
         "strobe (theta, theta', r, s at kT), impacts (t, theta'-, theta'+), lyapunov_running "
         "(lambda1, lambda2 at kT)", t=tr[:, 0], theta=tr[:, 1], dtheta=tr[:, 2],
         strobe=ref.strobe, impacts=ref.impacts, lyapunov_running=ref.lyapunov_running)
    figures[2] = [_figure(out, "fig2_reference.png",
                          fig_trajectory(ref, beh, exponent=exact, first=FIRST_PERIODS,
                                         last=LAST_PERIODS),
                          "figure 2: the reference run's theta(t) (first and last periods), "
                          "running exponent and phase portrait (data: fig2_reference.npz)")]
    results["fig2"] = dict(status=ref.status, behaviour=beh[0], period=beh[1],
                           **_exponents(ref, beh, exact), lyapunov=ref.lyapunov)
    done("fig2", t0)

    t0 = part(3, "fig3", "behaviour gallery")
    one = dict(run_kw, record_stride=1)  # short windows are drawn: every step
    gal = {k: simulate(Block(hb=hb), Harmonic(alpha=alpha, omega=omega, r0=pt[0], s0=pt[1]),
                       state, **one)
           for k, (hb, alpha, omega, state, pt) in GALLERY.items()}
    gal_beh = {k: classify_result(r) for k, r in gal.items()}
    # the study's "multiperiodic" example is transient chaos: its fate, with either forcing,
    # is a probability over initial states within round-off of z0
    hb, alpha, omega, state, pt = GALLERY[TRANSIENT_CHAOS]
    fates = {forcing: fate(Block(hb=hb), Harmonic(alpha=alpha, omega=omega, r0=pt[0], s0=pt[1],
                                                  embedded=forcing == "embedded"),
                           state, integration=integration, ensemble=FATE_ENSEMBLE,
                           execution=within("fate").replace(store=None))
             for forcing in ("closed", "embedded")}
    note = (f"over {FATE_ENSEMBLE} runs within $10^{{-10}}$ of $z_0$: closed form: "
            f"{_outcome_words(fates['closed'].probabilities)}; embedded: "
            f"{_outcome_words(fates['embedded'].probabilities)}")
    arrays = {}
    for i, (k, r) in enumerate(gal.items()):
        arrays.update(_drawn(r, f"c{i}_"))
    arrays["cases"] = np.array(list(gal), dtype=str)
    arrays["params"] = np.array([[hb, a, w] for hb, a, w, _, _ in GALLERY.values()])
    _npz(out, "fig3_gallery.npz", "figure 3's runs, case i = cases[i] (hb, alpha, omega in "
         "params[i]): c{i}_first_*, c{i}_last_*, c{i}_phase_* (t, theta, dtheta with impacts "
         "inserted) as drawn, c{i}_strobe, c{i}_impacts", **arrays)
    figures[3] = [_figure(out, "fig3_gallery.png",
                          fig_gallery(gal, gal_beh, notes={TRANSIENT_CHAOS: note},
                                      first=FIRST_PERIODS, last=LAST_PERIODS),
                          "figure 3: the behaviour gallery, one row per case: theta(t) over "
                          "the first and last periods and the phase portrait "
                          "(data: fig3_gallery.npz)")]
    results["fig3_fates"] = {forcing: f.to_summary() for forcing, f in fates.items()}
    results["fig3"] = {k: dict(behaviour=gal_beh[k][0], period=gal_beh[k][1], status=r.status,
                               t_end=r.t, **_exponents(r, gal_beh[k]),
                               state0=list(r.trajectory[0, 1:3]))
                       for k, r in gal.items()}
    done("fig3", t0)

    t0 = part(4, "fig4", "Housner vs Mao time series, alpha=0.2, omega=1.6, hb=2")
    rows = [{law: simulate(Block(hb=LAWS_RUN["hb"], law=law),
                           Harmonic(alpha=LAWS_RUN["alpha"], omega=LAWS_RUN["omega"], r0=0.0,
                                    s0=1.0), (th0, dth0), **one)
             for law in ("housner", "mao")} for th0, dth0 in LAWS_IC]
    row_beh = [{law: classify_result(r) for law, r in row.items()} for row in rows]
    captions = laws_captions(rows, row_beh)
    arrays = {}
    for i, row in enumerate(rows):
        for law, r in row.items():
            arrays.update(_drawn(r, f"r{i}_{law}_"))
    arrays["initial_states"] = np.array(LAWS_IC)
    _npz(out, "fig4_laws_timeseries.npz", "figure 4's runs, row i from initial_states[i], law "
         "housner or mao: r{i}_{law}_first_*, _last_*, _phase_* (t, theta, dtheta with impacts "
         "inserted) as drawn, _strobe, _impacts", **arrays)
    figures[4] = [_figure(out, "fig4_laws_timeseries.png",
                          fig_laws_timeseries(rows, row_beh, periods=LAWS_PERIODS),
                          "figure 4: Housner against Mao et al. from three initial states "
                          "(data: fig4_laws_timeseries.npz)")]
    results["fig4"] = [{law: dict(behaviour=row_beh[i][law][0], period=row_beh[i][law][1],
                                  status=r.status, t_end=r.t,
                                  t_overturn=r.t if r.status == "overturned" else math.nan)
                        for law, r in row.items()} | {"caption": captions[i]}
                       for i, row in enumerate(rows)]
    done("fig4", t0)

    t0 = part(5, "fig5", "bifurcation sweeps (4 + zoom)")
    sweeps = {}
    sweep_rows = []
    figures[5] = []
    sweep_words = ("the sweep: alpha, label (codes into names), period, lambda_max (exact "
                   "Floquet exponent where periodic), lambda_window (the study's finite-window "
                   "estimate), strobe (theta, theta' at kT over the classified stretch), "
                   "impact_section, t_end, attractor")
    for (hb, law), gp in p.sweeps.items():
        alphas = gp.axes["alpha"]
        say(f"paper: sweep {law} hb={hb:g}, {alphas.size} amplitudes")
        sw = sweeps[(hb, law)] = grid(gp, f"sweep_hb{hb}_{law}")
        _npz(out, f"fig5_sweep_hb{hb}_{law}.npz", f"figure 5, {law} h/b = {hb}: " + sweep_words,
             **sw.arrays())
        fr = sw.fractions()
        sweep_rows.append([hb, law, STUDY[hb]["omega"], float(alphas[0]), float(alphas[-1]),
                           int(alphas.size)] + [fr[n] for n in BEHAVIOURS])
    for hb in STUDY:
        figures[5].append(_figure(
            out, f"fig5_bifurcation_hb{hb}.png",
            draw_fig5({law: sweeps[(hb, law)] for law in ("housner", "mao")}, hb),
            f"figure 5: bifurcation diagrams of both laws at h/b = {hb} with lambda_max (data: "
            f"fig5_sweep_hb{hb}_housner.npz, fig5_sweep_hb{hb}_mao.npz)"))
    zoom = p.zoom_sweep.axes["alpha"]
    say(f"paper: zoom sweep Housner hb=1, {zoom.size} amplitudes")
    zsw = grid(p.zoom_sweep, "sweep_zoom")
    _npz(out, "fig5_sweep_zoom_hb1_housner.npz", "figure 5's zoom, Housner h/b = 1: "
         + sweep_words, **zsw.arrays())
    figures[5].append(_figure(
        out, "fig5_bifurcation_zoom.png", fig_bifurcation(
            zsw, alpha_limits=tuple(p.zoom),
            title=f"Zoom: Housner, $h/b = 1$, $\\omega = 1.3$, $\\alpha \\in "
                  f"[{p.zoom[0]:g}, {p.zoom[1]:g}]$"),
        "figure 5's zoom of the Housner h/b = 1 diagram (data: "
        "fig5_sweep_zoom_hb1_housner.npz)"))
    fr = zsw.fractions()
    sweep_rows.append([1, "housner (zoom)", STUDY[1]["omega"], float(zoom[0]),
                       float(zoom[-1]), int(zoom.size)] + [fr[n] for n in BEHAVIOURS])
    sweep_header = ["hb", "law", "omega", "alpha_start", "alpha_end", "n_alpha"] + \
        [f"{n}_percent" for n in BEHAVIOURS]
    _table(out, "sweep_table", sweep_header, sweep_rows,
           {h: ".1f" for h in sweep_header[6:]} | {"omega": "g", "alpha_start": "g",
                                                   "alpha_end": "g"},
           "figure 5's sweeps: the percent of amplitudes of each behaviour")
    results["fig5"] = [dict(zip(sweep_header, r)) for r in sweep_rows]
    results["fig5_lambda"] = {
        f"hb{hb}_{law}": dict(exact_min=_finite(sw.lambda_max, min),
                              exact_max=_finite(sw.lambda_max, max),
                              window_min=_finite(sw.lambda_window, min),
                              window_max=_finite(sw.lambda_window, max))
        for (hb, law), sw in sweeps.items()}
    # the branches of periodic orbits over the diagrams, bifurcations located
    bif_rows = []
    conts = {}
    figures["5b"] = []
    for (hb, law), sw in sweeps.items():
        say(f"paper: periodic orbits {law} hb={hb:g}, continued from the sweep's attractors")
        conts[(hb, law)] = cont = continue_branches(Block(hb=float(hb), law=law),
                                                    Harmonic(omega=STUDY[hb]["omega"]),
                                                    STUDY[hb]["alpha_range"][law], sweep=sw)
        stem = f"fig5_branches_hb{hb}_{law}"
        summary_c, arrays_c = cont.to_summary()
        _npz(out, f"{stem}.npz", f"the branches of {law} h/b = {hb}: per branch i "
             f"branch{{i}}_value, _cycle (n, p, 2), _cycle_half, _multipliers, _stable, "
             f"_impacts; the bifurcations bif_type, bif_value, bif_period, bif_multipliers",
             **arrays_c)
        out.text(f"{stem}.md", branch_caption(cont, f"Figure 5, periodic orbits"))
        _describe(out, f"{stem}.md", f"the caption of {stem}: every bifurcation with its "
                                     f"multipliers, every branch with where and why it stops")
        figures["5b"].append(_figure(
            out, f"{stem}.png", fig_branches(cont, sw),
            f"periodic orbits of {law} h/b = {hb} continued over the sweep, stable solid and "
            f"unstable dashed, bifurcations marked (data: {stem}.npz; list: {stem}.md)"))
        for bf in sorted(cont.bifurcations, key=lambda b: b.alpha):
            mu = sorted(np.abs(bf.multipliers), reverse=True)
            bif_rows.append([hb, law, bf.type, bf.alpha, bf.period, mu[0], mu[1]])
    figures["5b"].append(_figure(
        out, "fig5_branches_zoom.png", fig_branches(conts[(1, "housner")], zsw,
                                                    limits=tuple(p.zoom)),
        "the Housner h/b = 1 branches over the zoom (data: fig5_branches_hb1_housner.npz, "
        "fig5_sweep_zoom_hb1_housner.npz; list: fig5_branches_hb1_housner.md)"))
    bif_header = ["hb", "law", "type", "alpha", "period", "abs_mu1", "abs_mu2"]
    _table(out, "bifurcation_table", bif_header, bif_rows,
           {"hb": "g", "alpha": ".9f", "abs_mu1": ".4g", "abs_mu2": ".4g"},
           "every located bifurcation: h/b, law, type, alpha, period, |mu1|, |mu2|")
    results["bifurcations"] = [dict(zip(bif_header, r)) for r in bif_rows]
    if p.published:
        results["fig5_as_published"] = {}
        for hb in STUDY:
            cols = {}
            for law in ("housner", "mao"):
                say(f"paper: sweep {law} hb={hb:g} as published (past overturning)")
                pub = grid(p.published[(hb, law)], f"sweep_hb{hb}_{law}_published")
                _npz(out, f"fig5_sweep_hb{hb}_{law}_as_published.npz",
                     f"figure 5 as published, {law} h/b = {hb} (integrated on past "
                     f"overturning): " + sweep_words + ", t_overturn, motion", **pub.arrays())
                cols[law] = sweeps[(hb, law)]
                cols[f"{law}, as published"] = pub
                results["fig5_as_published"][f"hb{hb}_{law}"] = after_the_fall(pub)
            figures[5].append(_figure(
                out, f"fig5_bifurcation_hb{hb}_as_published.png", fig_bifurcation(
                    cols, title=f"$h/b = {hb}$, $\\omega = {STUDY[hb]['omega']}$: the "
                                f"physical diagrams and the study's (integrated on past "
                                f"$|\\theta| = \\pi/2$)"),
                f"figure 5 at h/b = {hb} beside the study's way (integrated past overturning, "
                f"its finite-window exponent) (data: fig5_sweep_hb{hb}_*_as_published.npz)"))
    done("fig5", t0)

    t0 = part(6, "fig6", f"basins, {p.grid}x{p.grid} cells, both laws, two cases")
    basin_rows = []
    results["fig6"] = []
    figures[6] = []
    for hb, alpha, omega in BASIN_CASES:
        bs = {}
        for law in ("housner", "mao"):
            say(f"paper: basin {law} hb={hb:g} alpha={alpha:g} omega={omega:g}")
            bs[law] = grid(p.basins[(hb, law)], f"basin_hb{hb:g}_{law}")
        basins_done[(hb, alpha, omega)] = bs
        agree = agreement(bs["housner"].label, bs["mao"].label)
        tag = f"hb{hb:g}"
        _npz(out, f"fig6_basin_{tag}.npz", f"figure 6, h/b = {hb:g}: theta0, dtheta0, "
             f"label_housner, label_mao (label[i, j] of theta0[i], dtheta0[j]), names",
             theta0=bs["housner"].theta0, dtheta0=bs["housner"].dtheta0,
             label_housner=bs["housner"].label, label_mao=bs["mao"].label,
             names=np.asarray(bs["housner"].names, dtype=str))
        figures[6].append(_figure(out, f"fig6_basin_{tag}.png",
                                  fig_basin_compare(bs["housner"], bs["mao"]),
                                  f"figure 6: basins of both laws at h/b = {hb:g} and where they "
                                  f"agree (data: fig6_basin_{tag}.npz)"))
        entry = dict(hb=hb, alpha=alpha, omega=omega, agreement=agree)
        for law, b in bs.items():
            fr = b.fractions()
            entry[law] = dict(fractions=fr)
            basin_rows.append([hb, alpha, omega, law] + [fr[n] for n in BEHAVIOURS] + [agree])
        results["fig6"].append(entry)
    basin_header = ["hb", "alpha", "omega", "law"] + [f"{n}_percent" for n in BEHAVIOURS] + \
        ["agreement_percent"]
    _table(out, "basin_table", basin_header, basin_rows,
           {h: ".1f" for h in basin_header[4:]} | {"hb": "g", "alpha": "g", "omega": "g"},
           "figure 6's basins: percent of each behaviour per law, and the laws' agreement")
    done("fig6", t0)

    t0 = part(7, "fig7", "attractor maps of the basins, their entropy and integrity")
    rows = []
    results["fig7"] = []
    figures[7] = []
    for hb, alpha, omega in BASIN_CASES:
        bs = basins_done[(hb, alpha, omega)]
        ms = {law: b.measures() for law, b in bs.items()}
        tag = f"hb{hb:g}"
        arrays = dict(theta0=bs["housner"].theta0, dtheta0=bs["housner"].dtheta0)
        for law, b in bs.items():
            arrays[f"attractor_{law}"] = b.attractor
            arrays[f"names_{law}"] = np.array(attractor_names(b.attractors), dtype=str)
            arrays[f"behaviour_{law}"] = np.array([a.behaviour for a in b.attractors], dtype=str)
            arrays[f"period_{law}"] = np.array([a.period for a in b.attractors], dtype=np.int64)
            arrays[f"fraction_{law}"] = np.array([a.fraction for a in b.attractors])
        _npz(out, f"fig7_attractors_{tag}.npz", f"figure 7, h/b = {hb:g}: theta0, dtheta0, per "
             f"law attractor_<law> (ids: >= 0 the attractor, -1 overturn, -2 unresolved), "
             f"names_<law>, behaviour_<law>, period_<law>, fraction_<law> by id", **arrays)
        figures[7].append(_figure(out, f"fig7_attractors_{tag}.png", fig_attractors(bs, ms),
                                  f"figure 7: the attractor each initial state reaches at h/b = "
                                  f"{hb:g}, by name, with basin entropy and integrity (data: "
                                  f"fig7_attractors_{tag}.npz)"))
        agree = attractor_agreement(bs["housner"], bs["mao"])
        entry = dict(hb=hb, alpha=alpha, omega=omega, attractor_agreement=agree)
        for law, b in bs.items():
            m = ms[law]
            entry[law] = dict(attractors=[dict(a.to_dict(), name=n) for a, n in
                                          zip(b.attractors, attractor_names(b.attractors))],
                              **m)
            rows.append([hb, alpha, omega, law, len(b.attractors), m["basin_entropy"],
                         m["boundary_basin_entropy"], m["uncertainty_exponent"]["alpha"],
                         m["integrity"]["GIM"], m["integrity"]["IF"], agree["percent"]])
        results["fig7"].append(entry)
    _table(out, "attractor_table", ATTRACTOR_HEADER, rows,
           {h: ".3f" for h in ATTRACTOR_HEADER[5:]} | {"hb": "g", "alpha": "g", "omega": "g"},
           "figure 7's measures: attractors, basin entropy, boundary basin entropy, "
           "uncertainty exponent, GIM, IF, the laws' attractor agreement")
    done("fig7", t0)

    t0 = part(8, "fig8", "erosion profiles, both laws, hb = 1 and 2")
    results["fig8"] = {}
    figures[8] = []
    for hb in EROSION:
        prof = {}
        for law in ("housner", "mao"):
            say(f"paper: erosion {law} hb={hb:g}, {p.erosions[(hb, law)].alpha.size} "
                f"amplitudes")
            prof[law] = erosion_run(p.erosions[(hb, law)], within(f"erosion_hb{hb}_{law}"))
        figures[8].append(_figure(out, f"fig8_erosion_hb{hb}.png", fig_erosion(prof),
                                  f"figure 8: erosion profiles of both laws at h/b = {hb} "
                                  f"(data: fig8_erosion_hb{hb}.npz)"))
        _npz(out, f"fig8_erosion_hb{hb}.npz", f"figure 8, h/b = {hb}: alpha, theta0, dtheta0 "
             f"and per law (suffix _<law>) GIM, IF, fractions (each attractor's percent at "
             f"each alpha), overturn, basin_entropy, attractor and label maps of every basin",
             alpha=prof["housner"].alpha, theta0=prof["housner"].theta0,
             dtheta0=prof["housner"].dtheta0,
             **{k: v for law, r in prof.items() for k, v in r.arrays(f"_{law}").items()})
        results["fig8"][f"hb{hb}"] = {law: r.to_summary() | dict(names=attractor_names(
            r.branches)) for law, r in prof.items()}
    done("fig8", t0)

    # ---- extra figure: the forcing plane with exact boundaries (rockjit.chart) --------------
    t0 = time.perf_counter()
    say("paper [extra] fig9: the forcing plane with its bifurcation curves, both laws")
    results["fig9"], figures[9] = _fig9_charts(out, integration, within, say)
    results["fig9_wall_s"] = time.perf_counter() - t0  # (apart from the study's parts)
    say(f"paper: fig9 done in {results['fig9_wall_s']:.1f} s")
    # ---- end of the extra figure ----------------------------------------------------------

    results.update(wall_s_parts=walls, zoom_step=p.zoom_step, record_stride=p.stride,
                   grid=p.grid, erosion_grid=p.erosion_grid, erosion_step=p.erosion_step,
                   total_s=time.perf_counter() - t_all)
    results["published"] = report.published_beside(results)
    report.write_index(out, results, figures, p)
    return results


def _finite(a, fn):
    a = np.asarray(a, float) if a is not None else np.zeros(0)
    a = a[np.isfinite(a)]
    return float(fn(a)) if a.size else math.nan


# ---- extra figure: the forcing plane with exact boundaries (rockjit.chart) ------------------


def _fig9_charts(out, integration, within, say):
    """Figure 9: per slenderness, both laws' charts with their curves, side by side and
    overlaid; returns the curves (type, period, law, points) per slenderness."""
    from ..orbits.plane_chart import ChartCurves, chart
    from ..plotting.chart import fig_chart
    from ..outputs import chart as write_chart
    found, names = {}, []
    for hb in STUDY:
        res = {}
        for law in ("housner", "mao"):
            say(f"paper: chart {law} hb={hb:g}")
            try:
                kw = dict(CHART, curves=ChartCurves(**CHART["curves"]))
                res[law] = chart(Block(hb=float(hb), law=law), **kw, integration=integration,
                                 execution=within(f"chart_hb{hb}_{law}"))
            except ValueError as exc:  # no seed on the lines (a quick paper's short runs)
                found[f"hb{hb}_{law}_refused"] = str(exc)
        if res:
            written = write_chart(out, res, npz=f"fig9_chart_hb{hb}.npz",
                                  png=f"fig9_chart_hb{hb}.png")
            names.append(written.pop("figure"))
            found[f"hb{hb}"] = written["curves"]
    return found, names
# ---- end of the extra figure ----------------------------------------------------------------
