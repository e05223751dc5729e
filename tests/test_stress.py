"""The numerical stress suite, fast subset.

The seeded generator and the checks live in ``tests/stress.py``, shared with the full
run ``benchmarks/bench_stress.py``; here a few dozen cases per kind, 50 periods at most, must pass
every check with no failure. The checks themselves are tested first: each must catch the fault it
is meant to catch, injected into an otherwise good result. Cases are flat keywords (the form the
suite draws, stores and prints them in), run through ``stress.simulate_flat``, which makes the
API's objects of them.
"""

from __future__ import annotations

import dataclasses
import math

import numpy as np
import pytest

import rockjit
import stress as S

SEED = 0
N_CASES = 60
MAX_PERIODS = 50


def _group(case):
    """The runs of a mirror case, or None if its grid is refused as too coarse (all or none of
    a group is: the mirror has the same grid and |(r0, s0)|)."""
    out = []
    for kw in case.kwargs["group"]:
        try:
            out.append(S.simulate_flat(**kw))
        except ValueError as exc:
            assert S.refused(exc), exc
            out.append(None)
    assert all(r is None for r in out) or all(r is not None for r in out)
    return None if out[0] is None else out


def _report(failures):
    return "\n".join(f"{cid}: {probs} {kw}" for cid, probs, kw in failures)


# ---- the checks catch what they are meant to catch --------------------------------------------

@pytest.fixture(scope="module")
def good():
    kw = dict(hb=1.0, alpha=0.6, omega=1.3, law="housner", periods=20, lyapunov=True,
              record_stride=8)
    res = S.simulate_flat(**kw)
    assert all(not v for v in S.check_run(kw, res).values())
    return kw, res


def _failed(kw, res):
    return {k for k, v in S.check_run(kw, res).items() if v}


@pytest.mark.parametrize("field", ["state", "strobe", "strobe_half", "impacts", "trajectory",
                                   "lyapunov_running"])
@pytest.mark.parametrize("bad", [math.nan, math.inf])
def test_finite_check_catches_injected_nan_and_inf(good, field, bad):
    kw, res = good
    arr = getattr(res, field).copy()
    arr.flat[arr.size // 2] = bad
    assert "finite" in _failed(kw, dataclasses.replace(res, **{field: arr}))


def test_finite_check_on_scalars_and_exponents(good):
    kw, res = good
    assert "finite" in _failed(kw, dataclasses.replace(res, max_error_estimate=math.nan))
    assert "finite" in _failed(kw, dataclasses.replace(res, lyapunov=np.array([0.1, math.nan])))
    # the documented sentinel -inf belongs to a run at rest only
    assert "finite" in _failed(kw, dataclasses.replace(res, lyapunov=np.array([-math.inf] * 2)))


def test_status_time_work_and_bookkeeping_checks_catch_faults(good):
    kw, res = good
    assert "status" in _failed(kw, dataclasses.replace(res, status="nonfinite"))
    assert "time" in _failed(kw, dataclasses.replace(res, t=res.t * 1.001))
    assert "time" in _failed(kw, dataclasses.replace(res, strobe=res.strobe[:-2]))
    assert "work" in _failed(kw, dataclasses.replace(res, n_rhs=S.work_bound(kw, res) + 1))
    imp = res.impacts.copy()
    imp[3, 2] *= 1 + 1e-15  # theta'+ != e theta'- in the last bit
    assert "bookkeeping" in _failed(kw, dataclasses.replace(res, impacts=imp))
    assert "bookkeeping" in _failed(kw, dataclasses.replace(res, impacts=imp[::-1].copy()))
    assert "bookkeeping" in _failed(kw, dataclasses.replace(res, n_impacts=res.n_impacts + 1))
    # the impact bound: reaching it is fine only under its own status
    capped = dict(kw, max_impacts=res.n_impacts)
    assert "bookkeeping" in _failed(capped, res)
    assert not _failed(capped, dataclasses.replace(res, status="max_impacts"))
    assert S.observations(capped, dataclasses.replace(res, status="max_impacts")) == \
        ["impact_bound"]
    # impacts that stop advancing time: a stall
    imp = np.repeat(res.impacts[:1], S.STALL + 1, axis=0)
    stalled = dataclasses.replace(res, impacts=imp, n_impacts=len(imp))
    assert "progress" in _failed(kw, stalled)


def test_rest_exponents_check_catches_a_positive_exponent_through_rest(good):
    kw, res = good
    through_rest = dataclasses.replace(res, n_rest=3, n_rest_window=2)
    assert "rest_exponents" in _failed(kw, dataclasses.replace(
        through_rest, lyapunov=np.array([0.1, -2.0])))
    # -inf (every perturbation erased), or no positive exponent, passes; so does a positive
    # exponent of an orbit that does not pass through rest in the window
    assert not _failed(kw, dataclasses.replace(through_rest, lyapunov=np.array([-np.inf] * 2)))
    assert "rest_exponents" not in _failed(kw, dataclasses.replace(
        through_rest, lyapunov=np.array([-0.1, -2.0])))
    assert "rest_exponents" not in _failed(kw, dataclasses.replace(
        res, lyapunov=np.array([0.1, -2.0])))


def test_finite_check_allows_minus_inf_only_after_a_collapse(good):
    kw, res = good
    lr = res.lyapunov_running.copy()
    lr[len(lr) // 2:] = -np.inf
    assert "finite" in _failed(kw, dataclasses.replace(res, lyapunov_running=lr))
    # after a rest phase every perturbation has died: -inf is the documented sentinel
    assert not _failed(kw, dataclasses.replace(res, lyapunov_running=lr, n_rest=1))


def test_energy_check_catches_a_drift():
    case = S.energy_cases(1, SEED)[0]
    res = S.simulate_flat(**case.kwargs)
    assert res.n_impacts > 0 and S.check_energy(case.kwargs, res) == []
    strobe = res.strobe.copy()
    strobe[-1, 1] *= 1 + 1e-8
    assert S.check_energy(case.kwargs, dataclasses.replace(res, strobe=strobe))
    imp = res.impacts.copy()
    imp[-1, 2] *= 1 - 1e-8  # a restitution of 1 - 1e-8 at one impact
    assert S.check_energy(case.kwargs, dataclasses.replace(res, impacts=imp))


def test_mirror_checks_catch_an_asymmetry():
    a, b = next(r for c in S.mirror_cases(40, SEED, max_periods=MAX_PERIODS)
                if c.category == "random" and (r := _group(c)) is not None)
    assert S.check_mirror_exact(a, b) == []
    strobe = b.strobe.copy()
    strobe[-1, 0] = np.nextafter(strobe[-1, 0], np.inf)  # one ulp
    assert S.check_mirror_exact(a, dataclasses.replace(b, strobe=strobe))

    for case in S.mirror_cases(40, SEED, max_periods=MAX_PERIODS, embedded=False):
        runs = _group(case)
        if runs and runs[0].status == "done" and np.abs(runs[0].strobe[:, :2]).max() > 0:
            break
    probs, compared = S.check_mirror_closed(*runs)
    assert probs == [] and compared == "whole"
    b = runs[1]
    strobe = b.strobe.copy()
    strobe[len(strobe) // 2, :2] += 1e-6 * np.abs(strobe[:, :2]).max()
    assert S.check_mirror_closed(runs[0], dataclasses.replace(b, strobe=strobe), *runs[2:])[0]
    # the un-mirrored run is not its own mirror image
    assert S.check_mirror_closed(runs[0], runs[0], *runs[2:])[0]


def test_threads_check_catches_a_difference():
    case = S.threads_cases(1, SEED, max_periods=10, grid=4)[0]
    one = S.run_threads_case(case, 1)
    assert S.check_threads(one, one) == []
    label = one.label.copy()
    label.flat[0] = (label.flat[0] + 1) % len(rockjit.BEHAVIOURS)
    assert S.check_threads(one, dataclasses.replace(one, label=label))


def test_cases_are_seeded_and_cover_the_ranges():
    a = S.cases(N_CASES, SEED, max_periods=MAX_PERIODS)
    b = S.cases(N_CASES, SEED, max_periods=MAX_PERIODS)
    assert [c.kwargs for c in a] == [c.kwargs for c in b]
    assert {c.category for c in a} == set(S.CATEGORIES)
    kws = [c.kwargs for c in S.cases(600, SEED, max_periods=MAX_PERIODS,
                                     long_periods=MAX_PERIODS)]
    for name, (lo, hi) in S.RANGES.items():
        v = np.array([kw[name] for kw in kws if name in kw])
        assert v.min() >= lo and v.max() <= hi
        assert v.min() <= lo + 0.1 * (hi - lo) and v.max() >= hi - 0.1 * (hi - lo)
    laws = {kw["law"] for kw in kws}
    assert laws == {"housner", "mao", "constant"}
    assert {0.0, 1.0} <= {kw["e"] for kw in kws if "e" in kw}
    assert any(kw.get("forcing") == "embedded" for kw in kws)
    assert all(kw["periods"] <= MAX_PERIODS for kw in kws)


def test_extreme_cases_are_seeded_and_cover_their_ranges():
    a = S.extreme_cases(90, SEED, max_periods=MAX_PERIODS)
    assert [c.kwargs for c in a] == [c.kwargs for c in S.extreme_cases(90, SEED,
                                                                       max_periods=MAX_PERIODS)]
    # their own ids and seeds: the ids of the study-range cases stay what they were
    assert {c.id[0] for c in a} == {"x"}
    assert [c.kwargs for c in S.cases(12, SEED)] == [c.kwargs for c in S.cases(12, SEED)]
    kws = {cat: [c.kwargs for c in S.extreme_cases(900, SEED) if c.category == cat]
           for cat in S.EXTREME_CATEGORIES}
    xi = np.array([kw["xi"] for kw in kws["stiff_damping"]])
    assert xi.min() >= 0.5 and xi.max() == 500.0 and np.median(xi) > 5.0
    om = np.array([kw["omega"] for kw in kws["wide_omega"]])
    assert om.min() == 1e-3 and om.max() == 1e3
    assert np.mean(om < 0.05) > 0.3 and np.mean(om > 20.0) > 0.3  # beyond the study's range
    rest = kws["through_rest"]
    at_rest = [kw for kw in rest if kw["theta0"] == 0.0 and kw["dtheta0"] == 0.0]
    assert len(at_rest) > len(rest) / 4
    for kw in rest:  # forcing that lifts a block at rest: the orbit passes through rest
        assert kw["alpha"] * kw["omega"] ** 2 * kw["hb"] > 1.0
    assert sum(kw["lyapunov"] for kw in rest) > len(rest) / 2
    for kw in sum(kws.values(), []):
        assert S.cost_n(kw) * kw["periods"] <= max(S.MAX_GRID_STEPS, S.cost_n(kw))


def test_case_ids_rerun_the_same_case():
    case = S.case_by_id("x0-7", max_periods=MAX_PERIODS)
    assert case.kwargs == S.extreme_cases(8, SEED, max_periods=MAX_PERIODS)[7].kwargs
    case = S.case_by_id("s0-29", max_periods=MAX_PERIODS, long_periods=MAX_PERIODS)
    assert case.kwargs == S.cases(30, SEED, max_periods=MAX_PERIODS,
                                  long_periods=MAX_PERIODS)[29].kwargs
    with pytest.raises(ValueError, match="case id"):
        S.case_by_id("q0-1")


# ---- the fast subset ---------------------------------------------------------------------------

def test_stress_runs_pass_every_check():
    failures = {k: [] for k in S.RUN_CHECKS}
    statuses = set()
    for case in S.cases(N_CASES, SEED, max_periods=MAX_PERIODS, long_periods=MAX_PERIODS):
        res, probs, refusal = S.run_case(case)
        statuses.add(res.status if res is not None else "refused" if refusal else "raised")
        for k, v in probs.items():
            if v:
                failures[k].append((case.id, v, case.kwargs))
    assert {"done", "overturned", "rest", "max_impacts"} <= statuses  # every ending exercised
    for k in S.RUN_CHECKS:
        assert not failures[k], f"check {k!r} failed:\n{_report(failures[k])}"


def test_extreme_runs_pass_every_check():
    """The extreme cases: damping up to xi = 500, omega from 1e-3 to 1e3, orbits through rest.
    A grid refused as too coarse for the damping (a ValueError naming n_steps) passes."""
    failures = {k: [] for k in S.RUN_CHECKS}
    for case in S.extreme_cases(45, SEED, max_periods=20):
        res, probs, refusal = S.run_case(case)
        for k, v in probs.items():
            if v:
                failures[k].append((case.id, v, case.kwargs))
    for k in S.RUN_CHECKS:
        assert not failures[k], f"check {k!r} failed:\n{_report(failures[k])}"


def test_energy_is_conserved():
    failures = []
    for case in S.energy_cases(20, SEED, max_periods=MAX_PERIODS):
        res, probs, refusal = S.run_case(case)
        assert refusal is None
        pr = S.check_energy(case.kwargs, res) + sum(probs.values(), [])
        if pr:
            failures.append((case.id, pr, case.kwargs))
    assert not failures, _report(failures)


def test_mirror_symmetry_is_exact_with_the_embedding():
    failures = []
    for case in S.mirror_cases(20, SEED, max_periods=MAX_PERIODS):
        runs = _group(case)
        if runs is None:
            continue
        pr = S.check_mirror_exact(*runs)
        if pr:
            failures.append((case.id, pr, case.kwargs["group"][0]))
    assert not failures, _report(failures)


def test_mirror_symmetry_with_the_closed_form():
    failures = []
    whole = 0
    for case in S.mirror_cases(20, SEED, max_periods=MAX_PERIODS, embedded=False):
        runs = _group(case)
        if runs is None:
            continue
        pr, compared = S.check_mirror_closed(*runs)
        whole += compared == "whole"
        if pr:
            failures.append((case.id, pr, case.kwargs["group"][0]))
    assert not failures, _report(failures)
    assert whole >= 15  # most runs are determined to rounding over their whole length


@pytest.mark.skipif(not S.threads_available(), reason="needs 2 numba threads")
def test_one_and_two_threads_agree_bit_for_bit():
    failures = []
    for case in S.threads_cases(4, SEED, max_periods=20, grid=6):
        one, two = S.run_threads_case(case, 1), S.run_threads_case(case, 2)
        assert (one is None) == (two is None)
        pr = [] if one is None else S.check_threads(one, two)
        if pr:
            failures.append((case.id, pr, case.kwargs))
    assert not failures, _report(failures)


# ---- failures the full stress run found, reduced to one run each ------------------------------

def test_exponents_with_e0_are_minus_inf_not_nan():
    """e = 0: every impact ends at rest, and the saltation [[0, 0], [s10, 0]] leaves the tangent
    vectors parallel; Gram–Schmidt divided by a zero norm (NaN tangent, NaN lambda1, a
    meaningless lambda2 of 1.93). Found by the stress suite (s0-29, s0-62, ...); the exponents
    are now -inf, the documented sentinel of a collapse."""
    kw = dict(hb=1.0, alpha=0.6, omega=1.3, e=0.0, periods=10, lyapunov=True)
    res = S.simulate_flat(**kw)
    assert res.n_impacts > 0
    assert S.check_finite(kw, res) == []
    assert np.all(res.lyapunov == -np.inf)


def test_uplift_at_the_threshold_makes_progress():
    """A block at rest under forcing a hair above the uplift threshold (alpha omega^2 = (1 +
    1e-12) cot thc): at the uplift instant the acceleration rounds to <= 0, the flight is too
    short to resolve and ends at rest at the same instant, and the uplift is found again at that
    instant: 100 000 zero-velocity impacts at t = 2.1416, status max_impacts (10 million with
    max_impacts=1e7). Found by the stress suite (s0-872, s0-1556, s0-2312, s0-2474). Fixed: a
    flight ending at rest within rounding of its uplift holds the block at rest until the grid
    point (both paths)."""
    kw = dict(hb=2.0, alpha=0.5 * (1 + 1e-12) / 0.5**2, omega=0.5, law="housner", theta0=0.0,
              dtheta0=0.0, phase=0.5, periods=2)
    res = S.simulate_flat(**kw)
    probs = S.check_run(kw, res)
    assert not any(probs.values()), probs


#: A start of the embedded oscillator far off the unit circle, rho = 8: its radial rate
#: 3 rho^2 - 1 = 191 is stiff, and at the default N the explicit step was unstable there (the run
#: ended 'nonfinite' with NaN everywhere). Found by the stress suite.
FAR_OFF = dict(hb=1.0, alpha=0.5, omega=1.3, law="housner", theta0=0.1, dtheta0=0.0, r0=8.0,
               s0=0.0, forcing="embedded", periods=5)


def _far_off_n():
    """The N the explicit step needs from rho = 8, worked out here: h (3 rho^2 + 1) <= 1.5."""
    h_max = 1.5 / (3.0 * 8.0**2 + 1.0)
    return 2 * math.ceil(2 * math.pi / FAR_OFF["omega"] / (2 * h_max))


def test_embedding_far_off_the_circle_is_refused_at_the_default_step():
    assert rockjit.DEFAULT_N < _far_off_n()  # the default is too coarse here
    with pytest.raises(ValueError, match=r"n_steps must be >= (\d+) here: the embedded") as err:
        S.simulate_flat(**FAR_OFF)
    assert S.refused(err.value)  # a documented refusal, counted as such by the suite
    assert int(err.value.args[0].split(">= ")[1].split()[0]) == _far_off_n()


def test_embedding_far_off_the_circle_at_the_step_it_needs_stays_finite():
    kw = dict(FAR_OFF, n_steps=_far_off_n())
    res = S.simulate_flat(**kw)
    probs = S.check_run(kw, res)
    assert not any(probs.values()), probs
    # alpha omega^2 = 0.85 < cot(thc) = 1: the block comes to rest for good, within 2 periods
    assert res.status == "rest" and np.all(np.isfinite(res.strobe)) and res.t > res.period
    # the oscillator's radius followed its contraction, rho(t) = (1 + (1/64 - 1) e^(-2t))^(-1/2)
    # (measured: within 2.5e-8 at t = T, 6e-10 at the end)
    t = np.append(np.arange(len(res.strobe)) * res.period, res.t)
    rho = np.hypot(*np.vstack([res.strobe[:, 2:], res.state[2:]]).T)
    assert rho[0] == 8.0
    np.testing.assert_allclose(rho, (1.0 + (1.0 / 64.0 - 1.0) * np.exp(-2.0 * t)) ** -0.5,
                               rtol=0, atol=1e-6)


def test_bookkeeping_knows_the_default_impact_bound_grows_with_periods():
    """The default bound is 10,000 impacts a period, at least 100,000; the check
    assumed 100,000 and failed 8 long runs that rightly went past it (s0-2812: 614,224 impacts
    in 811 periods, status done). Reduced: an elastic bounce at 1e-6 rad/s over 15 periods
    piles 150,000 impacts, reaching its own bound exactly (s0-1711)."""
    kw = dict(hb=1.6637121582875023, alpha=0.0, omega=6.517861886497169, law="constant", e=1.0,
              periods=15, theta0=-1e-15, dtheta0=-1e-06, phase=5.333658663223674)
    res = S.simulate_flat(**kw)
    assert res.status == "max_impacts" and res.n_impacts == 15 * 10_000  # independent: the rule
    assert S.check_bookkeeping(kw, res) == []
    assert S.check_bookkeeping(dict(kw, max_impacts=100_000), res) != []  # a smaller bound fails


def test_the_harness_examples_run():
    """The examples in the harness's docstrings (tests/stress.py) run as written."""
    import doctest
    failed, tried = doctest.testmod(S, optionflags=doctest.ELLIPSIS | doctest.NORMALIZE_WHITESPACE)
    assert tried > 0 and failed == 0
