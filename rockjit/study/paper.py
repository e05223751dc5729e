"""The study rockjit reproduces (SPEC.md §7): every constant of it, and its pipeline, ``paper``.

The constants are the study's parameters: the slenderness ratios with their forcing frequencies
and amplitude ranges, the sweeps' step, the zoom, the initial states of the single runs, the
gallery, the basins. :func:`plan_paper` validates a paper's settings (nothing computed) and
:func:`paper` computes every figure and table and writes them into an output directory object
(:class:`rockjit.storage.files.OutputDir` on the command line): figures 1-6 of the study, and beyond it
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
from ..single import DEFAULT_N, Z0_STUDY, classify_result, simulate
from ..validate import integer, memory, pair, real

__all__ = ["ALPHA_STEP", "BASIN_CASES", "BASIN_GRID", "EROSION", "EROSION_GRID", "EROSION_STEP",
           "GALLERY", "LAWS_IC", "LAWS_RUN", "PERIODS", "REFERENCE_RUN", "STUDY", "Z0", "ZOOM",
           "PaperPlan", "after_the_fall", "e_table", "paper", "plan_paper"]

#: The initial state of the single runs and sweeps, ``(theta, theta', r, s)``. (Defined in
#: rockjit.single, whose default it is.)
Z0 = Z0_STUDY

#: Per slenderness ratio: the forcing frequency and the amplitude range of each law's sweep.
STUDY = {
    1: dict(omega=1.3, alpha_range={"housner": (0.5, 1.0), "mao": (0.3, 0.8)}),
    2: dict(omega=1.6, alpha_range={"housner": (0.1, 0.5), "mao": (0.1, 0.5)}),
}
#: The sweeps' amplitude step, the number of periods and the asymptotic window's start.
ALPHA_STEP = 0.001
PERIODS = 500
WINDOW = 400
#: The zoomed Housner hb=1 diagram.
ZOOM = (0.88, 0.98)
#: Figure 2: the reference symmetric run.
REFERENCE_RUN = dict(hb=1.0, alpha=0.6, omega=1.3, law="housner")
#: Figure 3: the behaviour gallery, ``name: (hb, alpha, omega, (theta0, theta0') or None for
#: the study's z0, the forcing point (r0, s0))``; the study's
#: "multiperiodic" example (alpha = 0.969) is transient chaos ending in overturning once
#: integrated accurately (README, "What the study's settings hide"): both it and a robust
#: period-2 orbit of the same family are shown.
GALLERY = {
    "rest / damped": (1.0, 0.15, 1.0, (0.05, 0.0), Z0[2:]),
    "asymmetric": (1.0, 0.8, 1.3, None, Z0[2:]),
    "multiperiodic": (1.0, 0.92, 1.3, None, Z0[2:]),
    "study's 'multiperiodic'": (1.0, 0.969, 1.3, None, Z0[2:]),
    "overturn": (2.0, 0.448, 1.3, None, Z0[2:]),
}
#: The gallery's run whose outcome is decided by round-off, and the ensemble that measures it.
TRANSIENT_CHAOS = "study's 'multiperiodic'"
FATE_ENSEMBLE = 64
#: Figure 4: Housner vs Mao time series at this block, from these ``(theta0, theta0')`` with
#: ``(r0, s0) = (0, 1)``.
LAWS_RUN = dict(hb=2.0, alpha=0.2, omega=1.6)
LAWS_IC = ((0.8586, -0.8182), (-0.0505, -0.2121), (0.3535, -0.3333))
#: Figure 6: the basins ``(hb, alpha, omega)``, over ``linspace(-1, 1, BASIN_GRID)^2`` at
#: ``(r0, s0) = (0, 1)``.
BASIN_CASES = ((1.0, 0.66, 1.3), (2.0, 0.2, 1.6))
BASIN_GRID = 100
#: Erosion profiles (beyond the study): per slenderness ratio, the forcing frequency and the
#: amplitude range over which both laws' basins are followed (the union of the sweeps'
#: ranges), every EROSION_STEP.
EROSION = {1: dict(omega=1.3, alpha_range=(0.3, 1.0)), 2: dict(omega=1.6, alpha_range=(0.1, 0.5))}
#: The paper's erosion profiles are a survey (a 40 x 40 basin every 0.02: 36 and 21 basins per
#: law, ~1/12 of the cells of a 100 x 100 profile every 0.01, which `rockjit erosion` computes).
EROSION_STEP = 0.02
EROSION_GRID = 40
#: The restitution table's slenderness ratios and figure 1's range.
E_TABLE_HB = (1.0, 1.5, 2.0, 2.5, 3.0, 4.0, 5.0)
E_FIGURE_HB_MAX = 6.0
#: Most points recorded of a single run's trajectory.
MAX_TRAJ_POINTS = 50_000

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
    """Figure 1 and the e-table into ``out``; returns the table as dicts."""
    from ..plotting.figures import fig_restitution
    rows = e_table(hb_values)
    out.figure(fig_name, fig_restitution((1 / math.sqrt(2), hb_max)))
    out.table(table_stem, E_HEADER, rows, E_FMT)
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


def plan_paper(*, grid=BASIN_GRID, periods=PERIODS, n_steps=None, alpha_step=ALPHA_STEP,
               zoom=ZOOM, zoom_step=None, erosion_step=EROSION_STEP,
               erosion_grid=EROSION_GRID, as_published=False, execution=None) -> PaperPlan:
    """Validate a paper's settings; every grid is planned here and the memory of all of them
    together checked, nothing run.

    ``n_steps=None`` takes the library's defaults (``DEFAULT_N`` for single runs, ``GRID_N`` for
    sweeps and basins). ``zoom`` must lie inside the Housner hb=1 range. ``as_published`` adds
    figure 5 as the study computed it: its sweeps integrated on past overturning. ``grid``
    sizes every basin, the erosion profiles' included unless ``erosion_grid`` says otherwise.
    """
    execution = Execution() if execution is None else execution
    grid = integer("grid", grid, 2, 10**5)
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
                     memory_bytes=total)


def after_the_fall(sw):
    """What a sweep integrated past overturning plots where the block fell: the share of its
    amplitudes whose points and exponent come from motion after the fall, and that motion's
    behaviours, exponent signs and distinct attractors (continued along the amplitudes)."""
    from ..basins.identity import identify_along
    fell = np.isfinite(sw.t_overturn)
    plotted = fell & np.isin(sw.motion, [BEHAVIOURS.index(b) for b in
                                         ("symmetric", "asymmetric", "multiperiodic",
                                          "chaotic", "aperiodic")])
    n = sw.alpha.size
    motions = {BEHAVIOURS[c]: int(np.count_nonzero(plotted & (sw.motion == c)))
               for c in np.unique(sw.motion[plotted])}
    lam = sw.lambda_max[plotted]
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


def paper(out, plan=None, *, execution=None, say=None):
    """Compute every figure and table of the study into ``out``; returns the summary's results.

    Parameters
    ----------
    out : rockjit.storage.files.OutputDir
        Where the files go (``json``, ``npz``, ``figure``, ``table`` methods); the caller
        publishes it.
    plan : PaperPlan, optional
        From :func:`plan_paper`; default the study's settings.
    execution : Execution, optional
        The grids' progress, Dask client and chunk store: with a store directory, each grid
        keeps its chunks in a store of its own beneath it, so that an interrupted paper
        resumes.
    say : callable, optional
        ``say(message)`` for one line of progress per part.
    """
    from ..basins.identity import attractor_agreement
    from ..orbits import continue_branches
    from ..plotting.figures import (agreement, fig_attractors, fig_basin_compare,
                                    fig_bifurcation, fig_branches, fig_erosion, fig_gallery,
                                    fig_laws_timeseries, fig_trajectory)

    p = plan_paper() if plan is None else plan
    execution = Execution() if execution is None else execution
    say = say or (lambda msg: None)
    walls = {}
    results = {}
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
    done("fig1", t0)

    t0 = part(2, "fig2", "reference run alpha=0.6, omega=1.3, hb=1, Housner")
    ref = simulate(Block(hb=REFERENCE_RUN["hb"], law=REFERENCE_RUN["law"]),
                   Harmonic(alpha=REFERENCE_RUN["alpha"], omega=REFERENCE_RUN["omega"]),
                   **run_kw)
    tr = ref.trajectory
    out.npz("fig2_reference.npz", t=tr[:, 0], theta=tr[:, 1], dtheta=tr[:, 2],
            strobe=ref.strobe, impacts=ref.impacts, lyapunov_running=ref.lyapunov_running)
    out.figure("fig2_reference.png", fig_trajectory(ref))
    name, per = classify_result(ref)
    results["fig2"] = dict(status=ref.status, behaviour=name, period=per,
                           lambda_max=ref.lambda_max, lyapunov=ref.lyapunov)
    done("fig2", t0)

    t0 = part(3, "fig3", "behaviour gallery")
    gal = {k: simulate(Block(hb=hb), Harmonic(alpha=alpha, omega=omega, r0=pt[0], s0=pt[1]),
                       state, **run_kw)
           for k, (hb, alpha, omega, state, pt) in GALLERY.items()}
    # the study's "multiperiodic" example is transient chaos: its fate, with either forcing,
    # is a probability over initial states within round-off of z0 (issue 14)
    hb, alpha, omega, state, pt = GALLERY[TRANSIENT_CHAOS]
    fates = {forcing: fate(Block(hb=hb), Harmonic(alpha=alpha, omega=omega, r0=pt[0], s0=pt[1],
                                                  embedded=forcing == "embedded"),
                           state, integration=integration, ensemble=FATE_ENSEMBLE,
                           execution=within("fate").replace(store=None))
             for forcing in ("closed", "embedded")}
    note = "transient chaos; over {} runs within 1e-10 of z0:\n".format(FATE_ENSEMBLE) + \
        "\n".join(f"{forcing}: " + ", ".join(f"{k} {v:.0%}" for k, v in f.probabilities.items())
                  for forcing, f in fates.items())
    out.figure("fig3_gallery.png", fig_gallery(gal, notes={TRANSIENT_CHAOS: note}))
    results["fig3_fates"] = {forcing: f.to_summary() for forcing, f in fates.items()}
    results["fig3"] = {k: dict(zip(("behaviour", "period"), classify_result(r)),
                               status=r.status, lambda_max=r.lambda_max)
                       for k, r in gal.items()}
    done("fig3", t0)

    t0 = part(4, "fig4", "Housner vs Mao time series, alpha=0.2, omega=1.6, hb=2")
    rows = [{law: simulate(Block(hb=LAWS_RUN["hb"], law=law),
                           Harmonic(alpha=LAWS_RUN["alpha"], omega=LAWS_RUN["omega"], r0=0.0,
                                    s0=1.0), (th0, dth0), **run_kw)
             for law in ("housner", "mao")} for th0, dth0 in LAWS_IC]
    out.figure("fig4_laws_timeseries.png", fig_laws_timeseries(rows))
    results["fig4"] = [{law: dict(zip(("behaviour", "period"), classify_result(r)),
                                  status=r.status) for law, r in row.items()}
                       for row in rows]
    done("fig4", t0)

    t0 = part(5, "fig5", "bifurcation sweeps (4 + zoom)")
    sweeps = {}
    sweep_rows = []
    for (hb, law), gp in p.sweeps.items():
        alphas = gp.axes["alpha"]
        say(f"paper: sweep {law} hb={hb:g}, {alphas.size} amplitudes")
        sw = sweeps[(hb, law)] = grid(gp, f"sweep_hb{hb}_{law}")
        out.npz(f"fig5_sweep_hb{hb}_{law}.npz", **sw.arrays())
        fr = sw.fractions()
        sweep_rows.append([hb, law, STUDY[hb]["omega"], float(alphas[0]), float(alphas[-1]),
                           int(alphas.size)] + [fr[n] for n in BEHAVIOURS])
    for hb in STUDY:
        out.figure(f"fig5_bifurcation_hb{hb}.png", fig_bifurcation(
            {law: sweeps[(hb, law)] for law in ("housner", "mao")},
            title=f"Bifurcation diagrams, h/b = {hb}, \u03c9 = {STUDY[hb]['omega']}"))
    zoom = p.zoom_sweep.axes["alpha"]
    say(f"paper: zoom sweep Housner hb=1, {zoom.size} amplitudes")
    zsw = grid(p.zoom_sweep, "sweep_zoom")
    out.npz("fig5_sweep_zoom_hb1_housner.npz", **zsw.arrays())
    out.figure("fig5_bifurcation_zoom.png", fig_bifurcation(
        zsw, alpha_limits=tuple(p.zoom),
        title=f"Zoom: Housner, h/b = 1, \u03c9 = 1.3, \u03b1 in [{p.zoom[0]:g}, "
              f"{p.zoom[1]:g}]"))
    fr = zsw.fractions()
    sweep_rows.append([1, "housner (zoom)", STUDY[1]["omega"], float(zoom[0]),
                       float(zoom[-1]), int(zoom.size)] + [fr[n] for n in BEHAVIOURS])
    sweep_header = ["hb", "law", "omega", "alpha_start", "alpha_end", "n_alpha"] + \
        [f"{n}_percent" for n in BEHAVIOURS]
    out.table("sweep_table", sweep_header, sweep_rows,
              {h: ".1f" for h in sweep_header[6:]} | {"omega": "g", "alpha_start": "g",
                                                      "alpha_end": "g"})
    results["fig5"] = [dict(zip(sweep_header, r)) for r in sweep_rows]
    # the branches of periodic orbits over the diagrams, bifurcations located (issue 13)
    bif_rows = []
    conts = {}
    for (hb, law), sw in sweeps.items():
        say(f"paper: periodic orbits {law} hb={hb:g}, continued from the sweep's attractors")
        conts[(hb, law)] = cont = continue_branches(Block(hb=float(hb), law=law),
                                                    Harmonic(omega=STUDY[hb]["omega"]),
                                                    STUDY[hb]["alpha_range"][law], sweep=sw)
        out.figure(f"fig5_branches_hb{hb}_{law}.png", fig_branches(cont, sw))
        for bf in sorted(cont.bifurcations, key=lambda b: b.alpha):
            mu = sorted(np.abs(bf.multipliers), reverse=True)
            bif_rows.append([hb, law, bf.type, bf.alpha, bf.period, mu[0], mu[1]])
    out.figure("fig5_branches_zoom.png", fig_branches(conts[(1, "housner")], zsw,
                                                      limits=tuple(p.zoom)))
    bif_header = ["hb", "law", "type", "alpha", "period", "abs_mu1", "abs_mu2"]
    out.table("bifurcation_table", bif_header, bif_rows,
              {"hb": "g", "alpha": ".9f", "abs_mu1": ".4g", "abs_mu2": ".4g"})
    results["bifurcations"] = [dict(zip(bif_header, r)) for r in bif_rows]
    if p.published:
        results["fig5_as_published"] = {}
        for hb in STUDY:
            cols = {}
            for law in ("housner", "mao"):
                say(f"paper: sweep {law} hb={hb:g} as published (past overturning)")
                pub = grid(p.published[(hb, law)], f"sweep_hb{hb}_{law}_published")
                out.npz(f"fig5_sweep_hb{hb}_{law}_as_published.npz", **pub.arrays())
                cols[law] = sweeps[(hb, law)]
                cols[f"{law}, as published"] = pub
                results["fig5_as_published"][f"hb{hb}_{law}"] = after_the_fall(pub)
            out.figure(f"fig5_bifurcation_hb{hb}_as_published.png", fig_bifurcation(
                cols, title=f"h/b = {hb}, \u03c9 = {STUDY[hb]['omega']}: the physical diagrams "
                            f"and the study's (integrated on past |\u03b8| = \u03c0/2)"))
    done("fig5", t0)

    t0 = part(6, "fig6", f"basins, {p.grid}x{p.grid} cells, both laws, two cases")
    basin_rows = []
    results["fig6"] = []
    for hb, alpha, omega in BASIN_CASES:
        bs = {}
        for law in ("housner", "mao"):
            say(f"paper: basin {law} hb={hb:g} alpha={alpha:g} omega={omega:g}")
            bs[law] = grid(p.basins[(hb, law)], f"basin_hb{hb:g}_{law}")
        basins_done[(hb, alpha, omega)] = bs
        agree = agreement(bs["housner"].label, bs["mao"].label)
        tag = f"hb{hb:g}"
        out.npz(f"fig6_basin_{tag}.npz", theta0=bs["housner"].theta0,
                dtheta0=bs["housner"].dtheta0, label_housner=bs["housner"].label,
                label_mao=bs["mao"].label, names=np.asarray(bs["housner"].names, dtype=str))
        out.figure(f"fig6_basin_{tag}.png", fig_basin_compare(bs["housner"], bs["mao"]))
        entry = dict(hb=hb, alpha=alpha, omega=omega, agreement=agree)
        for law, b in bs.items():
            fr = b.fractions()
            entry[law] = dict(fractions=fr)
            basin_rows.append([hb, alpha, omega, law] + [fr[n] for n in BEHAVIOURS] + [agree])
        results["fig6"].append(entry)
    basin_header = ["hb", "alpha", "omega", "law"] + [f"{n}_percent" for n in BEHAVIOURS] + \
        ["agreement_percent"]
    out.table("basin_table", basin_header, basin_rows,
              {h: ".1f" for h in basin_header[4:]} | {"hb": "g", "alpha": "g", "omega": "g"})
    done("fig6", t0)

    t0 = part(7, "fig7", "attractor maps of the basins, their entropy and integrity")
    rows = []
    results["fig7"] = []
    for hb, alpha, omega in BASIN_CASES:
        bs = basins_done[(hb, alpha, omega)]
        out.figure(f"fig7_attractors_hb{hb:g}.png", fig_attractors(bs))
        agree = attractor_agreement(bs["housner"], bs["mao"])
        entry = dict(hb=hb, alpha=alpha, omega=omega, attractor_agreement=agree)
        for law, b in bs.items():
            m = b.measures()
            entry[law] = dict(attractors=b.attractor_summary(), **m)
            rows.append([hb, alpha, omega, law, len(b.attractors), m["basin_entropy"],
                         m["boundary_basin_entropy"], m["uncertainty_exponent"]["alpha"],
                         m["integrity"]["GIM"], m["integrity"]["IF"], agree["percent"]])
        results["fig7"].append(entry)
    out.table("attractor_table", ATTRACTOR_HEADER, rows,
              {h: ".3f" for h in ATTRACTOR_HEADER[5:]} | {"hb": "g", "alpha": "g",
                                                          "omega": "g"})
    done("fig7", t0)

    t0 = part(8, "fig8", "erosion profiles, both laws, hb = 1 and 2")
    results["fig8"] = {}
    for hb in EROSION:
        prof = {}
        for law in ("housner", "mao"):
            say(f"paper: erosion {law} hb={hb:g}, {p.erosions[(hb, law)].alpha.size} "
                f"amplitudes")
            prof[law] = erosion_run(p.erosions[(hb, law)], within(f"erosion_hb{hb}_{law}"))
        out.figure(f"fig8_erosion_hb{hb}.png", fig_erosion(prof))
        out.npz(f"fig8_erosion_hb{hb}.npz", alpha=prof["housner"].alpha,
                theta0=prof["housner"].theta0, dtheta0=prof["housner"].dtheta0,
                **{k: v for law, r in prof.items() for k, v in r.arrays(f"_{law}").items()})
        results["fig8"][f"hb{hb}"] = {law: r.to_summary() for law, r in prof.items()}
    done("fig8", t0)

    # ---- extra figure: the forcing plane with exact boundaries (rockjit.chart) --------------
    t0 = time.perf_counter()
    say("paper [extra] fig9: the forcing plane with its bifurcation curves, both laws")
    results["fig9"] = _fig9_charts(out, integration, within, say)
    results["fig9_wall_s"] = time.perf_counter() - t0  # (apart from the study's parts)
    say(f"paper: fig9 done in {results['fig9_wall_s']:.1f} s")
    # ---- end of the extra figure ----------------------------------------------------------

    results.update(wall_s_parts=walls, zoom_step=p.zoom_step, record_stride=p.stride,
                   total_s=time.perf_counter() - t_all)
    return results


# ---- extra figure: the forcing plane with exact boundaries (rockjit.chart) ------------------
#: The paper's charts: coarse (a survey, as the erosion profiles: `rockjit chart` computes the
#: 200 x 200 chart and the period-2 curves), over the plane around both slendernesses' study
#: frequencies.
CHART = dict(alpha_range=(0.2, 1.2), omega_range=(0.8, 3.0), grid=(40, 40),
             seed_omegas=(1.3, 2.4), max_period=1, sweep_step=0.01)


def _fig9_charts(out, integration, within, say):
    """Figure 9: per slenderness, both laws' charts with their curves, side by side and
    overlaid; returns the curves (type, period, law, points) per slenderness."""
    from ..orbits.plane_chart import chart
    from ..plotting.chart import fig_chart
    found = {}
    for hb in STUDY:
        res = {}
        for law in ("housner", "mao"):
            say(f"paper: chart {law} hb={hb:g}")
            try:
                res[law] = chart(Block(hb=float(hb), law=law), **CHART, integration=integration,
                                 execution=within(f"chart_hb{hb}_{law}"))
            except ValueError as exc:  # no seed on the lines (a quick paper's short runs)
                found[f"hb{hb}_{law}_refused"] = str(exc)
        if res:
            out.figure(f"fig9_chart_hb{hb}.png", fig_chart(res))
        found[f"hb{hb}"] = [c.to_dict() for r in res.values() for c in r.curves]
    return found
# ---- end of the extra figure ----------------------------------------------------------------
