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
from contextlib import contextmanager
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
from .runs import drawn_arrays, exponents, floquet_of_run, laws_captions, outcome_words
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
    from . import report

    pp = _Paper(out, plan_paper() if plan is None else plan,
                Execution() if execution is None else execution, say or (lambda msg: None))
    t_all = time.perf_counter()
    for part in (_fig1_restitution, _fig2_reference, _fig3_gallery, _fig4_laws,
                 _fig5_diagrams, _fig6_basins, _fig7_attractors, _fig8_erosion, _fig9_plane):
        part(pp)
    p, results = pp.plan, pp.results
    results.update(wall_s_parts=pp.walls, zoom_step=p.zoom_step, record_stride=p.stride,
                   grid=p.grid, erosion_grid=p.erosion_grid, erosion_step=p.erosion_step,
                   total_s=time.perf_counter() - t_all)
    results["published"] = report.published_beside(results)
    report.write_index(out, results, pp.figures, p)
    return results


class _Paper:
    """One paper in the making: its plan, where its files go and how it says its progress, and
    what it has made so far (the results, each figure's names as written, each part's wall
    time, the basins that figure 7 maps again)."""

    N_PARTS = 8

    def __init__(self, out, plan, execution, say):
        self.out, self.plan, self.execution, self.say = out, plan, execution, say
        self.walls, self.results, self.basins = {}, {}, {}
        self.figures = {}  # figure number -> names written, for the report
        self.integration = Integration(periods=plan.periods, n_steps=plan.n_steps)
        self.run_kw = dict(integration=self.integration, record_stride=plan.stride,
                           lyapunov=True)
        self.every_step = dict(self.run_kw, record_stride=1)  # short windows are drawn

    def within(self, name):
        """The execution of one grid: its own chunk store beneath the paper's."""
        store = self.execution.store
        return self.execution.replace(store=None if store is None else Path(store) / name)

    def grid(self, gp, name):
        """Run one planned grid in its own chunk store."""
        return run_grid(gp, self.within(name))

    @contextmanager
    def part(self, i, name, what):
        """One part of the paper: its progress line, and its wall time once it is done."""
        self.say(f"paper [{i}/{self.N_PARTS}] {name}: {what}")
        t0 = time.perf_counter()
        yield
        self.walls[name] = time.perf_counter() - t0
        self.say(f"paper: {name} done in {self.walls[name]:.1f} s")

    def describe(self, name, holds):
        """Say what a file holds (the summary's manifest), where ``out`` keeps one."""
        if hasattr(self.out, "describe"):
            self.out.describe(name, holds)

    def figure(self, name, fig, holds):
        """Write a figure (in ``out``'s format), describe it; returns the name written."""
        written = self.out.figure(name, fig)
        written = written if isinstance(written, str) else name
        self.describe(written, holds)
        return written

    def npz(self, name, holds, **arrays):
        """Write a figure's data, describe it; returns its name."""
        self.out.npz(name, **arrays)
        self.describe(name, holds)
        return name

    def table(self, stem, header, rows, fmt, holds):
        """Write a table as CSV and Markdown, describe both."""
        self.out.table(stem, header, rows, fmt)
        for ext in ("csv", "md"):
            self.describe(f"{stem}.{ext}", holds)


def _fig1_restitution(pp):
    """Figure 1 and the restitution table."""
    with pp.part(1, "fig1", "restitution laws and the e-table"):
        pp.results["e_table"] = write_e_table(pp.out, E_TABLE_HB, E_FIGURE_HB_MAX,
                                              "fig1_restitution.png", "e_table")
        pp.figures[1] = [n for n in pp.out.written if n.startswith("fig1_") and
                         not n.endswith(".npz")]


def _fig2_reference(pp):
    """Figure 2: the reference run with its data, behaviour and exponents."""
    from ..plotting.timeseries import fig_trajectory
    with pp.part(2, "fig2", "reference run alpha=0.6, omega=1.3, hb=1, Housner"):
        ref = simulate(Block(hb=REFERENCE_RUN["hb"], law=REFERENCE_RUN["law"]),
                       Harmonic(alpha=REFERENCE_RUN["alpha"], omega=REFERENCE_RUN["omega"]),
                       **pp.run_kw)
        beh = classify_result(ref)
        exact = floquet_of_run(ref, beh)
        tr = ref.trajectory
        pp.npz("fig2_reference.npz", "figure 2's run: t, theta, dtheta (recorded trajectory), "
               "strobe (theta, theta', r, s at kT), impacts (t, theta'-, theta'+), "
               "lyapunov_running (lambda1, lambda2 at kT)", t=tr[:, 0], theta=tr[:, 1],
               dtheta=tr[:, 2], strobe=ref.strobe, impacts=ref.impacts,
               lyapunov_running=ref.lyapunov_running)
        pp.figures[2] = [pp.figure("fig2_reference.png",
                                   fig_trajectory(ref, beh, exponent=exact, first=FIRST_PERIODS,
                                                  last=LAST_PERIODS),
                                   "figure 2: the reference run's theta(t) (first and last "
                                   "periods), running exponent and phase portrait (data: "
                                   "fig2_reference.npz)")]
        pp.results["fig2"] = dict(status=ref.status, behaviour=beh[0], period=beh[1],
                                  **exponents(ref, beh, exact), lyapunov=ref.lyapunov)


def _fig3_gallery(pp):
    """Figure 3: the behaviour gallery with its data, and the fates of its transient chaos."""
    from ..plotting.timeseries import fig_gallery
    with pp.part(3, "fig3", "behaviour gallery"):
        gal = {k: simulate(Block(hb=hb), Harmonic(alpha=alpha, omega=omega, r0=pt[0],
                                                  s0=pt[1]), state, **pp.every_step)
               for k, (hb, alpha, omega, state, pt) in GALLERY.items()}
        gal_beh = {k: classify_result(r) for k, r in gal.items()}
        fates = _transient_chaos_fates(pp)
        note = (f"over {FATE_ENSEMBLE} runs within $10^{{-10}}$ of $z_0$: closed form: "
                f"{outcome_words(fates['closed'].probabilities)}; embedded: "
                f"{outcome_words(fates['embedded'].probabilities)}")
        arrays = {}
        for i, (k, r) in enumerate(gal.items()):
            arrays.update(drawn_arrays(r, f"c{i}_"))
        arrays["cases"] = np.array(list(gal), dtype=str)
        arrays["params"] = np.array([[hb, a, w] for hb, a, w, _, _ in GALLERY.values()])
        pp.npz("fig3_gallery.npz", "figure 3's runs, case i = cases[i] (hb, alpha, omega in "
               "params[i]): c{i}_first_*, c{i}_last_*, c{i}_phase_* (t, theta, dtheta with "
               "impacts inserted) as drawn, c{i}_strobe, c{i}_impacts", **arrays)
        pp.figures[3] = [pp.figure("fig3_gallery.png",
                                   fig_gallery(gal, gal_beh, notes={TRANSIENT_CHAOS: note},
                                               first=FIRST_PERIODS, last=LAST_PERIODS),
                                   "figure 3: the behaviour gallery, one row per case: "
                                   "theta(t) over the first and last periods and the phase "
                                   "portrait (data: fig3_gallery.npz)")]
        pp.results["fig3_fates"] = {forcing: f.to_summary() for forcing, f in fates.items()}
        pp.results["fig3"] = {k: dict(behaviour=gal_beh[k][0], period=gal_beh[k][1],
                                      status=r.status, t_end=r.t, **exponents(r, gal_beh[k]),
                                      state0=list(r.trajectory[0, 1:3]))
                              for k, r in gal.items()}


def _transient_chaos_fates(pp):
    """The fates of the study's "multiperiodic" example, which is transient chaos: with either
    forcing (closed form, embedded), a probability over initial states within round-off of
    z0."""
    hb, alpha, omega, state, pt = GALLERY[TRANSIENT_CHAOS]
    return {forcing: fate(Block(hb=hb), Harmonic(alpha=alpha, omega=omega, r0=pt[0], s0=pt[1],
                                                 embedded=forcing == "embedded"),
                          state, integration=pp.integration, ensemble=FATE_ENSEMBLE,
                          execution=pp.within("fate").replace(store=None))
            for forcing in ("closed", "embedded")}


def _fig4_laws(pp):
    """Figure 4: both laws in time from each initial state, with their data and each row's
    caption."""
    from ..plotting.timeseries import fig_laws_timeseries
    with pp.part(4, "fig4", "Housner vs Mao time series, alpha=0.2, omega=1.6, hb=2"):
        rows = [{law: simulate(Block(hb=LAWS_RUN["hb"], law=law),
                               Harmonic(alpha=LAWS_RUN["alpha"], omega=LAWS_RUN["omega"],
                                        r0=0.0, s0=1.0), (th0, dth0), **pp.every_step)
                 for law in ("housner", "mao")} for th0, dth0 in LAWS_IC]
        row_beh = [{law: classify_result(r) for law, r in row.items()} for row in rows]
        captions = laws_captions(rows, row_beh)
        arrays = {}
        for i, row in enumerate(rows):
            for law, r in row.items():
                arrays.update(drawn_arrays(r, f"r{i}_{law}_"))
        arrays["initial_states"] = np.array(LAWS_IC)
        pp.npz("fig4_laws_timeseries.npz", "figure 4's runs, row i from initial_states[i], "
               "law housner or mao: r{i}_{law}_first_*, _last_*, _phase_* (t, theta, dtheta "
               "with impacts inserted) as drawn, _strobe, _impacts", **arrays)
        pp.figures[4] = [pp.figure("fig4_laws_timeseries.png",
                                   fig_laws_timeseries(rows, row_beh, periods=LAWS_PERIODS),
                                   "figure 4: Housner against Mao et al. from three initial "
                                   "states (data: fig4_laws_timeseries.npz)")]
        pp.results["fig4"] = [
            {law: dict(behaviour=row_beh[i][law][0], period=row_beh[i][law][1],
                       status=r.status, t_end=r.t,
                       t_overturn=r.t if r.status == "overturned" else math.nan)
             for law, r in row.items()} | {"caption": captions[i]}
            for i, row in enumerate(rows)]


#: What a sweep's data file holds (figure 5's files).
_SWEEP_WORDS = ("the sweep: alpha, label (codes into names), period, lambda_max (exact "
                "Floquet exponent where periodic), lambda_window (the study's finite-window "
                "estimate), strobe (theta, theta' at kT over the classified stretch), "
                "impact_section, t_end, attractor")


def _fig5_diagrams(pp):
    """Figure 5: the bifurcation sweeps and the zoom with their table, the branches of
    periodic orbits over them, and (when planned) the diagrams as the study computed them."""
    with pp.part(5, "fig5", "bifurcation sweeps (4 + zoom)"):
        pp.figures[5] = []
        sweeps, rows = _fig5_sweeps(pp)
        zsw = _fig5_zoom(pp, rows)
        _fig5_table(pp, sweeps, rows)
        _fig5_branches(pp, sweeps, zsw)
        if pp.plan.published:
            _fig5_as_published(pp, sweeps)


def _sweep_row(hb, law, alphas, sw):
    """A sweep's row of the sweep table: its settings and the percent of each behaviour."""
    fr = sw.fractions()
    return [hb, law, STUDY[hb]["omega"], float(alphas[0]), float(alphas[-1]),
            int(alphas.size)] + [fr[n] for n in BEHAVIOURS]


def _fig5_sweeps(pp):
    """Both laws' sweeps at each slenderness with their data, and figure 5's diagrams of them;
    returns the sweeps and their rows of the sweep table."""
    sweeps, rows = {}, []
    for (hb, law), gp in pp.plan.sweeps.items():
        alphas = gp.axes["alpha"]
        pp.say(f"paper: sweep {law} hb={hb:g}, {alphas.size} amplitudes")
        sw = sweeps[(hb, law)] = pp.grid(gp, f"sweep_hb{hb}_{law}")
        pp.npz(f"fig5_sweep_hb{hb}_{law}.npz", f"figure 5, {law} h/b = {hb}: " + _SWEEP_WORDS,
               **sw.arrays())
        rows.append(_sweep_row(hb, law, alphas, sw))
    for hb in STUDY:
        pp.figures[5].append(pp.figure(
            f"fig5_bifurcation_hb{hb}.png",
            draw_fig5({law: sweeps[(hb, law)] for law in ("housner", "mao")}, hb),
            f"figure 5: bifurcation diagrams of both laws at h/b = {hb} with lambda_max (data: "
            f"fig5_sweep_hb{hb}_housner.npz, fig5_sweep_hb{hb}_mao.npz)"))
    return sweeps, rows


def _fig5_zoom(pp, rows):
    """Figure 5's zoom of the Housner h/b = 1 diagram with its data, its row appended to
    ``rows``; returns its sweep."""
    from ..plotting.forcing import fig_bifurcation
    p = pp.plan
    zoom = p.zoom_sweep.axes["alpha"]
    pp.say(f"paper: zoom sweep Housner hb=1, {zoom.size} amplitudes")
    zsw = pp.grid(p.zoom_sweep, "sweep_zoom")
    pp.npz("fig5_sweep_zoom_hb1_housner.npz", "figure 5's zoom, Housner h/b = 1: "
           + _SWEEP_WORDS, **zsw.arrays())
    pp.figures[5].append(pp.figure(
        "fig5_bifurcation_zoom.png", fig_bifurcation(
            zsw, alpha_limits=tuple(p.zoom),
            title=f"Zoom: Housner, $h/b = 1$, $\\omega = 1.3$, $\\alpha \\in "
                  f"[{p.zoom[0]:g}, {p.zoom[1]:g}]$"),
        "figure 5's zoom of the Housner h/b = 1 diagram (data: "
        "fig5_sweep_zoom_hb1_housner.npz)"))
    rows.append(_sweep_row(1, "housner (zoom)", zoom, zsw))
    return zsw


def _fig5_table(pp, sweeps, rows):
    """The sweep table (the percent of amplitudes of each behaviour) and the range of each
    sweep's exponents, exact and of the window."""
    header = ["hb", "law", "omega", "alpha_start", "alpha_end", "n_alpha"] + \
        [f"{n}_percent" for n in BEHAVIOURS]
    pp.table("sweep_table", header, rows,
             {h: ".1f" for h in header[6:]} | {"omega": "g", "alpha_start": "g",
                                               "alpha_end": "g"},
             "figure 5's sweeps: the percent of amplitudes of each behaviour")
    pp.results["fig5"] = [dict(zip(header, r)) for r in rows]
    pp.results["fig5_lambda"] = {
        f"hb{hb}_{law}": dict(exact_min=_finite(sw.lambda_max, min),
                              exact_max=_finite(sw.lambda_max, max),
                              window_min=_finite(sw.lambda_window, min),
                              window_max=_finite(sw.lambda_window, max))
        for (hb, law), sw in sweeps.items()}


def _fig5_branches(pp, sweeps, zsw):
    """The branches of periodic orbits over each diagram and over the zoom, and the table of
    every located bifurcation."""
    from ..plotting.branches import fig_branches
    rows, conts = [], {}
    pp.figures["5b"] = []
    for (hb, law), sw in sweeps.items():
        conts[(hb, law)] = cont = _branches_of(pp, hb, law, sw)
        for bf in sorted(cont.bifurcations, key=lambda b: b.alpha):
            mu = sorted(np.abs(bf.multipliers), reverse=True)
            rows.append([hb, law, bf.type, bf.alpha, bf.period, mu[0], mu[1]])
    pp.figures["5b"].append(pp.figure(
        "fig5_branches_zoom.png", fig_branches(conts[(1, "housner")], zsw,
                                               limits=tuple(pp.plan.zoom)),
        "the Housner h/b = 1 branches over the zoom (data: fig5_branches_hb1_housner.npz, "
        "fig5_sweep_zoom_hb1_housner.npz; list: fig5_branches_hb1_housner.md)"))
    header = ["hb", "law", "type", "alpha", "period", "abs_mu1", "abs_mu2"]
    pp.table("bifurcation_table", header, rows,
             {"hb": "g", "alpha": ".9f", "abs_mu1": ".4g", "abs_mu2": ".4g"},
             "every located bifurcation: h/b, law, type, alpha, period, |mu1|, |mu2|")
    pp.results["bifurcations"] = [dict(zip(header, r)) for r in rows]


def _branches_of(pp, hb, law, sw):
    """One diagram's branches of periodic orbits, continued from its sweep's attractors, with
    their data, caption and figure; returns the continuation."""
    from ..orbits import continue_branches
    from ..plotting.branches import branch_caption, fig_branches
    pp.say(f"paper: periodic orbits {law} hb={hb:g}, continued from the sweep's attractors")
    cont = continue_branches(Block(hb=float(hb), law=law), Harmonic(omega=STUDY[hb]["omega"]),
                             STUDY[hb]["alpha_range"][law], sweep=sw)
    stem = f"fig5_branches_hb{hb}_{law}"
    _, arrays = cont.to_summary()
    pp.npz(f"{stem}.npz", f"the branches of {law} h/b = {hb}: per branch i "
           f"branch{{i}}_value, _cycle (n, p, 2), _cycle_half, _multipliers, _stable, "
           f"_impacts; the bifurcations bif_type, bif_value, bif_period, bif_multipliers",
           **arrays)
    pp.out.text(f"{stem}.md", branch_caption(cont, "Figure 5, periodic orbits"))
    pp.describe(f"{stem}.md", f"the caption of {stem}: every bifurcation with its "
                              f"multipliers, every branch with where and why it stops")
    pp.figures["5b"].append(pp.figure(
        f"{stem}.png", fig_branches(cont, sw),
        f"periodic orbits of {law} h/b = {hb} continued over the sweep, stable solid and "
        f"unstable dashed, bifurcations marked (data: {stem}.npz; list: {stem}.md)"))
    return cont


def _fig5_as_published(pp, sweeps):
    """Figure 5 as the study computed it (integrated on past overturning) beside each law's
    diagram, with what its points after the fall are."""
    from ..plotting.forcing import fig_bifurcation
    pp.results["fig5_as_published"] = {}
    for hb in STUDY:
        cols = {}
        for law in ("housner", "mao"):
            pp.say(f"paper: sweep {law} hb={hb:g} as published (past overturning)")
            pub = pp.grid(pp.plan.published[(hb, law)], f"sweep_hb{hb}_{law}_published")
            pp.npz(f"fig5_sweep_hb{hb}_{law}_as_published.npz",
                   f"figure 5 as published, {law} h/b = {hb} (integrated on past "
                   f"overturning): " + _SWEEP_WORDS + ", t_overturn, motion", **pub.arrays())
            cols[law] = sweeps[(hb, law)]
            cols[f"{law}, as published"] = pub
            pp.results["fig5_as_published"][f"hb{hb}_{law}"] = after_the_fall(pub)
        pp.figures[5].append(pp.figure(
            f"fig5_bifurcation_hb{hb}_as_published.png", fig_bifurcation(
                cols, title=f"$h/b = {hb}$, $\\omega = {STUDY[hb]['omega']}$: the "
                            f"physical diagrams and the study's (integrated on past "
                            f"$|\\theta| = \\pi/2$)"),
            f"figure 5 at h/b = {hb} beside the study's way (integrated past overturning, "
            f"its finite-window exponent) (data: fig5_sweep_hb{hb}_*_as_published.npz)"))


def _basins_of(pp, hb, alpha, omega):
    """Both laws' basins of one case, kept for figure 7; returns ``{law: BasinResult}``."""
    bs = {}
    for law in ("housner", "mao"):
        pp.say(f"paper: basin {law} hb={hb:g} alpha={alpha:g} omega={omega:g}")
        bs[law] = pp.grid(pp.plan.basins[(hb, law)], f"basin_hb{hb:g}_{law}")
    pp.basins[(hb, alpha, omega)] = bs
    return bs


def _fig6_basins(pp):
    """Figure 6: both laws' basins of each case with their data, where the laws agree, and the
    basin table."""
    from ..grids.identity import agreement
    from ..plotting.basins import fig_basin_compare
    p = pp.plan
    with pp.part(6, "fig6", f"basins, {p.grid}x{p.grid} cells, both laws, two cases"):
        rows = []
        pp.results["fig6"] = []
        pp.figures[6] = []
        for hb, alpha, omega in BASIN_CASES:
            bs = _basins_of(pp, hb, alpha, omega)
            agree = agreement(bs["housner"].label, bs["mao"].label)
            tag = f"hb{hb:g}"
            pp.npz(f"fig6_basin_{tag}.npz", f"figure 6, h/b = {hb:g}: theta0, dtheta0, "
                   f"label_housner, label_mao (label[i, j] of theta0[i], dtheta0[j]), names",
                   theta0=bs["housner"].theta0, dtheta0=bs["housner"].dtheta0,
                   label_housner=bs["housner"].label, label_mao=bs["mao"].label,
                   names=np.asarray(bs["housner"].names, dtype=str))
            pp.figures[6].append(pp.figure(f"fig6_basin_{tag}.png",
                                           fig_basin_compare(bs["housner"], bs["mao"]),
                                           f"figure 6: basins of both laws at h/b = {hb:g} and "
                                           f"where they agree (data: fig6_basin_{tag}.npz)"))
            entry = dict(hb=hb, alpha=alpha, omega=omega, agreement=agree)
            for law, b in bs.items():
                fr = b.fractions()
                entry[law] = dict(fractions=fr)
                rows.append([hb, alpha, omega, law] + [fr[n] for n in BEHAVIOURS] + [agree])
            pp.results["fig6"].append(entry)
        header = ["hb", "alpha", "omega", "law"] + [f"{n}_percent" for n in BEHAVIOURS] + \
            ["agreement_percent"]
        pp.table("basin_table", header, rows,
                 {h: ".1f" for h in header[4:]} | {"hb": "g", "alpha": "g", "omega": "g"},
                 "figure 6's basins: percent of each behaviour per law, and the laws' agreement")


def _attractor_arrays(bs):
    """Figure 7's data of one case: the cells' initial states and, per law, each cell's
    attractor and each attractor's name, behaviour, period and fraction."""
    from ..plotting.style import attractor_names
    arrays = dict(theta0=bs["housner"].theta0, dtheta0=bs["housner"].dtheta0)
    for law, b in bs.items():
        arrays[f"attractor_{law}"] = b.attractor
        arrays[f"names_{law}"] = np.array(attractor_names(b.attractors), dtype=str)
        arrays[f"behaviour_{law}"] = np.array([a.behaviour for a in b.attractors], dtype=str)
        arrays[f"period_{law}"] = np.array([a.period for a in b.attractors], dtype=np.int64)
        arrays[f"fraction_{law}"] = np.array([a.fraction for a in b.attractors])
    return arrays


def _fig7_attractors(pp):
    """Figure 7: the attractor maps of figure 6's basins with their data, entropy and
    integrity, and the attractor table."""
    from ..grids.identity import attractor_agreement
    from ..plotting.basins import fig_attractors
    from ..plotting.style import attractor_names
    with pp.part(7, "fig7", "attractor maps of the basins, their entropy and integrity"):
        rows = []
        pp.results["fig7"] = []
        pp.figures[7] = []
        for hb, alpha, omega in BASIN_CASES:
            bs = pp.basins[(hb, alpha, omega)]
            ms = {law: b.measures() for law, b in bs.items()}
            tag = f"hb{hb:g}"
            pp.npz(f"fig7_attractors_{tag}.npz", f"figure 7, h/b = {hb:g}: theta0, dtheta0, "
                   f"per law attractor_<law> (ids: >= 0 the attractor, -1 overturn, -2 "
                   f"unresolved), names_<law>, behaviour_<law>, period_<law>, fraction_<law> "
                   f"by id", **_attractor_arrays(bs))
            pp.figures[7].append(pp.figure(f"fig7_attractors_{tag}.png", fig_attractors(bs, ms),
                                           f"figure 7: the attractor each initial state reaches "
                                           f"at h/b = {hb:g}, by name, with basin entropy and "
                                           f"integrity (data: fig7_attractors_{tag}.npz)"))
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
            pp.results["fig7"].append(entry)
        pp.table("attractor_table", ATTRACTOR_HEADER, rows,
                 {h: ".3f" for h in ATTRACTOR_HEADER[5:]} | {"hb": "g", "alpha": "g",
                                                             "omega": "g"},
                 "figure 7's measures: attractors, basin entropy, boundary basin entropy, "
                 "uncertainty exponent, GIM, IF, the laws' attractor agreement")


def _fig8_erosion(pp):
    """Figure 8: both laws' erosion profiles at each slenderness, with their data."""
    from ..plotting.basins import fig_erosion
    from ..plotting.style import attractor_names
    with pp.part(8, "fig8", "erosion profiles, both laws, hb = 1 and 2"):
        pp.results["fig8"] = {}
        pp.figures[8] = []
        for hb in EROSION:
            prof = {}
            for law in ("housner", "mao"):
                pp.say(f"paper: erosion {law} hb={hb:g}, "
                       f"{pp.plan.erosions[(hb, law)].alpha.size} amplitudes")
                prof[law] = erosion_run(pp.plan.erosions[(hb, law)],
                                        pp.within(f"erosion_hb{hb}_{law}"))
            pp.figures[8].append(pp.figure(f"fig8_erosion_hb{hb}.png", fig_erosion(prof),
                                           f"figure 8: erosion profiles of both laws at h/b = "
                                           f"{hb} (data: fig8_erosion_hb{hb}.npz)"))
            pp.npz(f"fig8_erosion_hb{hb}.npz", f"figure 8, h/b = {hb}: alpha, theta0, dtheta0 "
                   f"and per law (suffix _<law>) GIM, IF, fractions (each attractor's percent "
                   f"at each alpha), overturn, basin_entropy, attractor and label maps of every "
                   f"basin", alpha=prof["housner"].alpha, theta0=prof["housner"].theta0,
                   dtheta0=prof["housner"].dtheta0,
                   **{k: v for law, r in prof.items() for k, v in r.arrays(f"_{law}").items()})
            pp.results["fig8"][f"hb{hb}"] = {law: r.to_summary() | dict(names=attractor_names(
                r.branches)) for law, r in prof.items()}


def _finite(a, fn):
    """``fn`` (min or max) of the finite values of ``a``, or ``nan`` when there are none."""
    a = np.asarray(a, float) if a is not None else np.zeros(0)
    a = a[np.isfinite(a)]
    return float(fn(a)) if a.size else math.nan


# ---- extra figure: the forcing plane with exact boundaries (rockjit.chart) ------------------


def _fig9_plane(pp):
    """Figure 9, beyond the study's parts and timed apart from them: the forcing plane of both
    laws with its bifurcation curves."""
    t0 = time.perf_counter()
    pp.say("paper [extra] fig9: the forcing plane with its bifurcation curves, both laws")
    pp.results["fig9"], pp.figures[9] = _fig9_charts(pp)
    pp.results["fig9_wall_s"] = time.perf_counter() - t0  # (apart from the study's parts)
    pp.say(f"paper: fig9 done in {pp.results['fig9_wall_s']:.1f} s")


def _fig9_charts(pp):
    """Figure 9: per slenderness, both laws' charts with their curves, side by side and
    overlaid; returns the curves (type, period, law, points) per slenderness."""
    from ..orbits.plane_chart import ChartCurves, chart
    from ..outputs import chart as write_chart
    found, names = {}, []
    for hb in STUDY:
        res = {}
        for law in ("housner", "mao"):
            pp.say(f"paper: chart {law} hb={hb:g}")
            try:
                kw = dict(CHART, curves=ChartCurves(**CHART["curves"]))
                res[law] = chart(Block(hb=float(hb), law=law), **kw,
                                 integration=pp.integration,
                                 execution=pp.within(f"chart_hb{hb}_{law}"))
            except ValueError as exc:  # no seed on the lines (a quick paper's short runs)
                found[f"hb{hb}_{law}_refused"] = str(exc)
        if res:
            written = write_chart(pp.out, res, npz=f"fig9_chart_hb{hb}.npz",
                                  png=f"fig9_chart_hb{hb}.png")
            names.append(written.pop("figure"))
            found[f"hb{hb}"] = written["curves"]
    return found, names
# ---- end of the extra figure ----------------------------------------------------------------
