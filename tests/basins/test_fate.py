"""Fates decided by round-off: ensembles, horizons, uncertain cells.

- an ensemble's probabilities sum to 1 and do not depend on the number of threads;
- the predictability horizon of a chaotic run against the time two runs ``eps`` apart take to
  separate, measured here with plain runs;
- the cells inside a periodic attractor's basin are never uncertain; those flagged lie on the
  basin's boundary;
- a single run's own horizon is reported, and refused inputs name their parameter.
"""

import math

import numba
import numpy as np
import pytest

import rockjit
from rockjit import Block, Classification, Execution, Harmonic, Integration
from rockjit.basins import fate as F
from rockjit.single import Z0_STUDY

BLOCK = Block(hb=1.0, law="housner")
CHAOTIC = Harmonic(alpha=0.955, omega=1.3)  # tests/_engine/test_lyapunov.py
TRANSIENT = Harmonic(alpha=0.969, omega=1.3)  # transient chaos ending in overturning


def test_probabilities_sum_to_one_and_ignore_the_thread_count():
    kw = dict(ensemble=40, integration=Integration(periods=300))
    one = F.fate(BLOCK, TRANSIENT, **kw, execution=Execution(threads=1))
    two = F.fate(BLOCK, TRANSIENT, **kw,
                 execution=Execution(threads=min(2, numba.config.NUMBA_NUM_THREADS)))
    assert sum(one.probabilities.values()) == pytest.approx(1.0)
    assert one.probabilities == two.probabilities
    np.testing.assert_array_equal(one.t_end, two.t_end)
    # member 0 is the nominal run itself
    assert one.t_end[0] == pytest.approx(one.nominal.t, abs=1e-9)


def test_horizon_matches_the_separation_time_of_two_runs():
    # lambda1 of the chaotic orbit, over a long run
    integration = Integration(periods=300)
    lam1 = rockjit.simulate(BLOCK, CHAOTIC, integration=integration, lyapunov=True).lyapunov[0]
    assert lam1 > 0.05
    eps = 1e-10
    T = 2 * math.pi / CHAOTIC.omega
    a = rockjit.simulate(BLOCK, CHAOTIC, integration=integration, record_stride=8)
    z0 = rockjit.Z0_STUDY
    b = rockjit.simulate(BLOCK, CHAOTIC.replace(r0=z0[2], s0=z0[3]), (z0[0] * (1 + eps), z0[1]),
                         integration=integration, record_stride=8)
    n = min(len(a.trajectory), len(b.trajectory))
    d = np.abs(a.trajectory[:n, 1:3] - b.trajectory[:n, 1:3]).max(axis=1)
    size = np.abs(a.trajectory[:n, 1:3]).max()
    t_sep = a.trajectory[np.argmax(d > F.HORIZON_TOL * size), 0]
    predicted = F.horizon(lam1, eps * abs(z0[0]) / size)
    assert predicted / 2 <= t_sep <= 2 * predicted, (t_sep, predicted, T)


def test_no_uncertain_cell_inside_a_periodic_basin():
    b = rockjit.basin(BLOCK, Harmonic(alpha=0.66, omega=1.3), 40,
                      integration=Integration(periods=300),
                      classification=Classification(uncertainty=1e-3))
    ids = b.attractor
    # a cell is interior when it and its eight neighbours reach the same attractor
    inner = np.zeros_like(ids, dtype=bool)
    core = ids[1:-1, 1:-1]
    same = np.ones_like(core, dtype=bool)
    for di in (-1, 0, 1):
        for dj in (-1, 0, 1):
            same &= ids[1 + di:ids.shape[0] - 1 + di, 1 + dj:ids.shape[1] - 1 + dj] == core
    inner[1:-1, 1:-1] = same & (core >= 0)
    assert inner.sum() > 100
    assert not np.any(b.uncertain & inner)
    assert b.uncertain.any()  # a perturbation of 1e-3 does move some boundary cells


def test_a_single_run_reports_its_own_horizon():
    r = rockjit.simulate(BLOCK, CHAOTIC, integration=Integration(periods=300), lyapunov=True)
    lam = r.lyapunov_running[-1, 0]
    assert r.horizon == pytest.approx(math.log(F.HORIZON_TOL / np.finfo(float).eps) / lam)
    assert r.beyond_horizon  # 300 chaotic periods: far beyond what rounding allows
    s = rockjit.simulate(BLOCK, Harmonic(alpha=0.6, omega=1.3),
                         integration=Integration(periods=100), lyapunov=True)
    assert s.horizon == math.inf and not s.beyond_horizon  # a stable orbit forgets errors


@pytest.mark.parametrize("kw, match", [
    (dict(ensemble=1), "ensemble"), (dict(spread=(1e-3, 1e-1)), "spread"),
    (dict(spread=(0.0, 1e-10)), "spread"), (dict(seed=-1), "seed"),
])
def test_fate_refuses_bad_input(kw, match):
    with pytest.raises(ValueError, match=match):
        F.fate(BLOCK, TRANSIENT, integration=Integration(periods=10), **kw)


def test_each_member_of_an_ensemble_is_its_own_plain_run():
    """The ensemble's grid kernel against a plain ``simulate`` from each member's start."""
    kw = dict(integration=Integration(periods=150))
    fr = F.fate(BLOCK, TRANSIENT, **kw, ensemble=6, seed=3)
    assert isinstance(fr, F.FateResult) and len(fr.t_end) == 6
    for (th, dth), t_end, outcome in zip(fr.initial, fr.t_end, fr.outcome):
        # fate's default forcing point, the study's
        alone = rockjit.simulate(BLOCK, TRANSIENT.replace(r0=Z0_STUDY[2], s0=Z0_STUDY[3]),
                                 (th, dth), **kw)
        assert alone.t == pytest.approx(t_end, abs=1e-9)
        assert (alone.status == "overturned") == (outcome == -1)


def test_outcome_keys_name_attractors_by_what_they_are_not_by_their_ids():
    from rockjit.grids.identity import Attractor

    def att(i, behaviour, period, x):
        return Attractor(id=i, behaviour=behaviour, period=period, points=np.array([[x, 0.1]]),
                         fraction=10.0, n_cells=1, lam=np.zeros(2))

    # a mirror pair, a period-7 orbit, rest and a chaotic cloud, numbered one way, then the other
    found = [att(0, "asymmetric", 1, 0.2), att(1, "asymmetric", 1, -0.2),
             att(2, "multiperiodic", 7, 0.0), att(3, "rest", 0, 0.0), att(4, "chaotic", 0, 0.3)]
    keys = F.outcome_keys(found)
    assert keys == {-1: "overturn", -2: "unresolved", 0: "asymmetric p=1 (b)",
                    1: "asymmetric p=1 (a)", 2: "multiperiodic p=7", 3: "rest", 4: "chaotic"}
    renumbered = [att(4 - a.id, a.behaviour, a.period, a.points[0, 0]) for a in found]
    again = F.outcome_keys(renumbered)
    by_position = {(a.behaviour, float(a.points[0, 0])): keys[a.id] for a in found}
    assert {(a.behaviour, float(a.points[0, 0])): again[a.id] for a in renumbered} == by_position


def test_an_ensembles_keys_are_readable_and_map_to_its_outcomes():
    f = F.fate(BLOCK, TRANSIENT, ensemble=24, integration=Integration(periods=300))
    assert all("#" not in k for k in f.probabilities)
    assert set(f.ids) == set(f.probabilities)
    for key, v in f.ids.items():
        assert f.probabilities[key] == pytest.approx(np.mean(f.outcome == v))
