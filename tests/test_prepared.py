"""Prepared runs (``rockjit.simulate.prepare``) and the reuse inside ``rockjit.simulate``: a run
made ready once and called again with a new state or amplitude gives the run a fresh plan
gives, at the forcing phase the prepared run was made with.

The references are fresh plans run one by one (``rockjit.single.run(simulate.plan(...))``, no
reuse), and for the embedded forcing an exact identity: the oscillator ``(r, s)`` integrated
with the block stays on ``(sin(omega t + phi), cos(omega t + phi))``.
"""

import math
import pickle

import numpy as np
import pytest

import rockjit
from rockjit import Block, Harmonic, Integration
from rockjit import single
from rockjit.single import STUDY_PHASE

BLOCK = Block(hb=1, law="housner")
RUNS = Integration(periods=20)


def fresh(forcing, state):
    """A run from a fresh plan, nothing reused."""
    return single.run(rockjit.simulate.plan(BLOCK, forcing, state, integration=RUNS))


def same(a, b):
    assert a.status == b.status
    assert a.n_impacts == b.n_impacts
    assert np.array_equal(a.state, b.state)
    assert np.array_equal(a.strobe, b.strobe)
    assert np.array_equal(a.impacts, b.impacts)


@pytest.mark.parametrize("embedded", [False, True])
def test_a_new_state_keeps_the_prepared_phase(embedded):
    # prepared from the study's state: the study's forcing phase, for every later state
    run = rockjit.simulate.prepare(BLOCK, Harmonic(alpha=0.8, omega=1.3, embedded=embedded),
                                   integration=RUNS)
    r0, s0 = STUDY_PHASE
    phased = Harmonic(alpha=0.8, omega=1.3, embedded=embedded, r0=r0, s0=s0)
    for state in ((0.05, 0.0), (-0.2, 0.3), (0.0, -0.1)):
        got = run(state=state)
        same(got, fresh(phased, state))
        assert got.n_impacts > 0  # the block rocks: the phase matters


def test_the_embedded_oscillator_stays_on_its_circle():
    run = rockjit.simulate.prepare(BLOCK, Harmonic(alpha=0.8, omega=1.3, embedded=True),
                                   integration=RUNS)
    phi = math.atan2(*STUDY_PHASE)
    res = run(state=(0.05, 0.0))
    r, s = res.state[2:4]
    # the integrated oscillator drifts by the integrator's error (~1e-8 over 20 periods at
    # the default N); the wrong phase would put it ~0.8 away
    assert abs(r - math.sin(1.3 * res.t + phi)) <= 1e-7
    assert abs(s - math.cos(1.3 * res.t + phi)) <= 1e-7


def test_a_new_amplitude_is_the_fresh_run_at_that_amplitude():
    run = rockjit.simulate.prepare(BLOCK, Harmonic(alpha=0.6, omega=1.3, phase=0.4),
                                   integration=RUNS)
    for alpha in (0.7, 0.9):
        got = run(state=(0.05, 0.0), alpha=alpha)
        assert got.forcing.alpha == alpha
        same(got, fresh(Harmonic(alpha=alpha, omega=1.3, phase=0.4), (0.05, 0.0)))


def test_every_output_of_a_new_amplitude_is_the_fresh_run_s():
    # exponents and a recorded trajectory: every array and number of the result, against a
    # fresh plan at that amplitude
    forcing = Harmonic(alpha=0.6, omega=1.3, phase=0.4)
    kw = dict(integration=RUNS, lyapunov=True, record_stride=4)
    run = rockjit.simulate.prepare(BLOCK, forcing, (0.05, 0.0), **kw)
    for alpha in (0.8, 0.955):
        got = run(state=(0.05, 0.0), alpha=alpha)
        want = single.run(rockjit.simulate.plan(BLOCK, forcing.replace(alpha=alpha),
                                                (0.05, 0.0), **kw))
        assert got.forcing == want.forcing and got.window == want.window
        for name in ("status", "t", "n_impacts", "n_grid_steps", "n_rhs", "n_rest",
                     "n_rest_window", "n_impacts_window", "max_error_estimate"):
            assert getattr(got, name) == getattr(want, name), name
        for name in ("state", "strobe", "strobe_half", "impacts", "trajectory", "lyapunov",
                     "lyapunov_running"):
            assert np.array_equal(getattr(got, name), getattr(want, name)), name
        assert got.extra.keys() == want.extra.keys()
        assert np.array_equal(got.extra["tangent"], want.extra["tangent"])
        assert got.n_impacts > 0 and np.isfinite(got.lyapunov[0])


def test_a_prepared_run_travels_by_pickle_after_its_first_call():
    # worker processes (Dask) receive prepared runs by pickle, called or not
    run = rockjit.simulate.prepare(BLOCK, Harmonic(alpha=0.8, omega=1.3), integration=RUNS)
    first = run(state=(0.05, 0.0))
    run(state=(0.05, 0.0))
    copy = pickle.loads(pickle.dumps(run))
    same(copy(state=(0.05, 0.0)), first)
    same(copy(state=(0.05, 0.0)), first)


def test_simulate_reuses_a_run_only_at_the_same_phase():
    # the study's state starts at the study's phase, a given state at phase 0: a run from a
    # given state after one from the study's state is the fresh run from that state
    forcing = Harmonic(alpha=0.8, omega=1.3)
    single._PREPARED.clear()
    rockjit.simulate(BLOCK, forcing, integration=RUNS)
    again = rockjit.simulate(BLOCK, forcing, (0.05, 0.0), integration=RUNS)
    same(again, fresh(forcing, (0.05, 0.0)))
    # and the other way round
    single._PREPARED.clear()
    rockjit.simulate(BLOCK, forcing, (0.05, 0.0), integration=RUNS)
    same(rockjit.simulate(BLOCK, forcing, integration=RUNS), fresh(forcing, None))


@pytest.mark.parametrize("state, match", [((0.1, math.nan), "dtheta0"), ((2.0, 0.0), "theta0"),
                                          ((0.1,), "two numbers"), ("ab", "state")])
def test_a_bad_state_is_refused(state, match):
    run = rockjit.simulate.prepare(BLOCK, Harmonic(alpha=0.6, omega=1.3), integration=RUNS)
    with pytest.raises(ValueError, match=match):
        run(state=state)
