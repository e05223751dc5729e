"""The study's settings: the runs, sweeps, basins, figures and charts that ``rockjit paper``
computes and draws, by name (``rockjit.study.paper`` runs them, ``rockjit.study.report``
captions them)."""

from __future__ import annotations

from ..single import Z0_STUDY

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
#: Figure 3: the behaviour gallery, ``caption: (hb, alpha, omega, (theta0, theta0') or None
#: for the study's z0, the forcing point (r0, s0))``; the study's "multiperiodic" example
#: (alpha = 0.969) is transient chaos ending in overturning once integrated accurately
#: (docs/theory/study.md, "What the study's settings hide"): both it and a robust period-2
#: orbit of the same family are shown. The rest case starts from a tilt of 0.7 (the study's
#: 0.05 comes to rest within 0.73 time units, nine impacts drawn from a handful of points):
#: long enough to show the damped rocking decay to rest.
GALLERY = {
    "rest after damped rocking": (1.0, 0.15, 1.0, (0.7, 0.0), Z0[2:]),
    "asymmetric": (1.0, 0.8, 1.3, None, Z0[2:]),
    "period-2 of the multiperiodic family": (1.0, 0.92, 1.3, None, Z0[2:]),
    "the study's 'multiperiodic' example": (1.0, 0.969, 1.3, None, Z0[2:]),
    "overturn": (2.0, 0.448, 1.3, None, Z0[2:]),
}
#: The gallery's run whose outcome is decided by round-off, and the ensemble that measures it.
TRANSIENT_CHAOS = "the study's 'multiperiodic' example"
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
#: law, ~1/12 of the cells of a 100 x 100 profile every 0.01, which `rockjit erosion` computes):
#: the grid they take when the paper's grid is not given.
EROSION_STEP = 0.02
EROSION_GRID = 40
#: The restitution table's slenderness ratios and figure 1's range.
E_TABLE_HB = (1.0, 1.5, 2.0, 2.5, 3.0, 4.0, 5.0)
E_FIGURE_HB_MAX = 6.0
#: Most points recorded of a single run's trajectory.
MAX_TRAJ_POINTS = 50_000

#: Periods of theta(t) shown at the start and at the end of a run in figures 2 and 3 (and
#: kept in figure 4's data).
FIRST_PERIODS = 8
LAST_PERIODS = 4
#: Periods of theta(t) shown at the end of each run in figure 4 (the laws' time series).
LAWS_PERIODS = 8

#: The paper's charts: coarse (a survey, as the erosion profiles: `rockjit chart` computes the
#: 200 x 200 chart and the period-2 curves), over the plane around both slendernesses' study
#: frequencies.
CHART = dict(alpha_range=(0.2, 1.2), omega_range=(0.8, 3.0), grid=(40, 40),
             curves=dict(seed_omegas=(1.3, 2.4), max_period=1, sweep_step=0.01))
