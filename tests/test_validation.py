"""Input checking of the API's objects and of ``rockjit.simulate``: every invalid input is a
ValueError naming the parameter.

Checked against the documented ranges (docs/theory/model.md, impacts.md), on both the compiled and the scipy path.
Each parameter is checked where it now lives: the block's in ``Block``, the excitation's in
``Harmonic``, the integration's in ``Integration``, the grids' in ``Classification``, ``Lattice``
and ``Execution``, the reference path's in ``Scipy``, what a run combines (its state, the step's
stability, its memory) in ``simulate`` (which validates before it dispatches, so no integration
runs in these tests).
"""

import math

import numba
import numpy as np
import pytest

import rockjit
from rockjit import (Block, Classification, Execution, Harmonic, Integration, Lattice, Scipy)
from rockjit.single import MAX_STEP
from stress import simulate_flat

BASE = dict(hb=1.0, alpha=0.6, omega=1.3, periods=1)
NAN = math.nan

OWNERS = ((Block, ("hb", "law", "e", "xi")),
          (Harmonic, ("alpha", "omega", "phase", "r0", "s0", "embedded")),
          (Integration, ("n_steps", "periods", "window", "max_impacts", "rest_speed",
                         "theta_over", "stop_at_overturn", "qr_every")))


def simulate(method="rockjit", rtol=None, atol=None, **kw):
    """``rockjit.simulate`` with each keyword given to the object that owns it (the block's to
    ``Block``, the excitation's to ``Harmonic``, the integration's to ``Integration``, ``rtol``
    and ``atol`` to the method's ``Scipy``), the rest (``state``, ``lyapunov``,
    ``record_stride``) to ``simulate`` itself. The objects are made inside the call, so a
    refusal by any of them is the call's."""
    block, forcing, integration = (cls(**{k: kw.pop(k) for k in names if k in kw})
                                   for cls, names in OWNERS)
    if rtol is not None or atol is not None:
        tol = {k: v for k, v in dict(rtol=rtol, atol=atol).items() if v is not None}
        method = Scipy(method.partition(":")[2] or "BDF", **tol)
    return rockjit.simulate(block, forcing, integration=integration, method=method, **kw)


# (changes to BASE, regular expression the message must match)
CASES = [
    (dict(hb=0.0), "hb"),
    (dict(hb=-1.0), "hb"),
    (dict(hb=math.inf), "hb"),
    (dict(hb=NAN), "hb"),
    (dict(hb="tall"), "hb"),
    (dict(hb=0.5, law="housner"), "hb"),               # e_H < 0 below 1/sqrt(2)
    (dict(hb=0.5), "hb"),                              # Housner is the default law
    (dict(e=1.5), r"^e\b"),
    (dict(e=-0.1), r"^e\b"),
    (dict(e=NAN), r"^e\b"),
    (dict(e=0.5, law="mao"), r"^e\b"),
    (dict(e=0.5, law="housner"), r"^e\b"),
    (dict(law="constant"), r"^e\b"),                   # constant law without e
    (dict(law="coulomb"), "law"),
    (dict(omega=0.0), "omega"),
    (dict(omega=-1.3), "omega"),
    (dict(omega=NAN), "omega"),
    (dict(alpha=-0.1), "alpha"),
    (dict(alpha=NAN), "alpha"),
    (dict(alpha=math.inf), "alpha"),
    (dict(xi=-1e-3), "xi"),
    (dict(xi=NAN), "xi"),
    (dict(periods=0), "periods"),
    (dict(periods=2.5), "periods"),
    (dict(periods=NAN), "periods"),
    (dict(n_steps=255), "n_steps"),
    (dict(n_steps=6), "n_steps"),
    (dict(n_steps=100.5), "n_steps"),
    (dict(theta_over=0.0), "theta_over"),
    (dict(theta_over=2.0), "theta_over"),
    (dict(theta_over=-0.3), "theta_over"),
    (dict(theta_over=NAN), "theta_over"),
    (dict(rest_speed=-1.0), "rest_speed"),
    (dict(max_impacts=0), "max_impacts"),
    (dict(window=1), "window"),                        # must be < periods
    (dict(window=-1), "window"),
    (dict(record_stride=0), "record_stride"),
    (dict(embedded="open"), "embedded"),               # was forcing="open"
    (dict(r0=0.5, s0=0.5), "r0"),                      # off the circle with closed forcing
    (dict(r0=0.0), "r0"),                              # r0 without s0
    (dict(s0=1.0), "s0"),                              # s0 without r0
    (dict(r0=0.0, s0=0.0, embedded=True), "r0"),       # no phase at the origin
    (dict(r0=NAN, s0=1.0), "r0"),
    (dict(phase=NAN), "phase"),
    (dict(phase=0.3, r0=0.0, s0=1.0), "phase"),
    (dict(state=(0.1, 0.2, 0.3)), "state"),
    (dict(state=(0.1, 0.2, 0.0, 1.0)), "state"),  # four numbers: theta, theta', r, s
    (dict(state=(NAN, 0.2)), "theta0|state"),
    (dict(state=(NAN, 0.0)), "theta0"),
    (dict(state=(0.0, NAN)), "dtheta0"),
    (dict(state=(math.inf, 0.0)), "theta0"),
]


class _Client:
    """A stand-in Dask client (only its presence matters), with a repr the same in every
    process: a test's id must not hold an address."""

    def __repr__(self):
        return "<a client>"


def _id(case):
    changes, _ = case
    return ",".join(f"{k}={v!r}" for k, v in changes.items())


@pytest.mark.parametrize("method", ["rockjit", "scipy:DOP853"])
@pytest.mark.parametrize("case", CASES, ids=[_id(c) for c in CASES])
def test_invalid_input_names_the_parameter(case, method):
    changes, match = case
    with pytest.raises(ValueError, match=match):
        simulate(**{**BASE, "method": method, **changes})


@pytest.mark.parametrize("changes, match", [
    (dict(method="rk4"), "method"),
    (dict(method="scipy:NOPE"), "method"),
    (dict(method=None), "method"),
    (dict(qr_every=-1, lyapunov=True), "qr_every"),
    (dict(method="scipy:DOP853", lyapunov=True), "lyapunov"),
    (dict(method="scipy:DOP853", rtol=NAN), "rtol"),
    (dict(method="scipy:DOP853", atol=NAN), "atol"),
], ids=lambda v: repr(v) if isinstance(v, dict) else v)
def test_invalid_settings_name_the_setting(changes, match):
    with pytest.raises(ValueError, match=match):
        simulate(**{**BASE, **changes})


# ---- the objects' own checks -------------------------------------------------------------------

# (object, its keywords, regular expression the message must match): the fields the cases above
# do not reach through simulate, each refused by its object's constructor
OBJECT_CASES = [
    (Harmonic, dict(r0=1.0), "r0 and s0"),                       # r0 without s0
    (Harmonic, dict(s0=1.0), "r0 and s0"),
    (Harmonic, dict(alpha=1e9, omega=1e4), r"alpha \* omega\*\*2"),
    (Harmonic, dict(embedded=1), "embedded"),
    (Integration, dict(n_steps=9), "n_steps must be even"),
    (Integration, dict(n_steps=True), "n_steps"),
    (Integration, dict(max_impacts=2.5), "max_impacts"),
    (Integration, dict(rest_speed=0.2), "rest_speed"),           # beyond 0.1
    (Integration, dict(rest_speed=1e-13), "rest_speed"),         # below 1e-12
    (Integration, dict(qr_every=-1), "qr_every"),
    (Integration, dict(qr_every=1.5), "qr_every"),
    (Integration, dict(stop_at_overturn="False"), "stop_at_overturn"),
    (Integration, dict(stop_at_overturn=1), "stop_at_overturn"),
    (Classification, dict(tol=0.0), "tol"),
    (Classification, dict(tol=1.0), "tol"),
    (Classification, dict(tol=NAN), "tol"),
    (Classification, dict(settle_tol=2e-6), "settle_tol"),       # > tol
    (Classification, dict(settle_tol=0.0), "settle_tol"),
    (Classification, dict(pmax=0), "pmax"),
    (Classification, dict(pmax=1001), "pmax"),
    (Classification, dict(lam_tol=NAN), "lam_tol"),
    (Classification, dict(settle_reps=1), "settle_reps"),
    (Classification, dict(early_stop="yes"), "early_stop"),
    (Classification, dict(attractors=None), "attractors"),
    (Classification, dict(uncertainty=0.6), "uncertainty"),
    (Classification, dict(uncertainty=0.0), "uncertainty"),
    (Lattice, dict(grid=0), "grid"),
    (Lattice, dict(grid=2.5), "grid"),
    (Lattice, dict(theta_range=(1.0, -1.0)), "theta_range"),
    (Lattice, dict(theta_range=(NAN, 1.0)), "theta_range"),
    (Lattice, dict(theta_range=1.0), "theta_range"),
    (Lattice, dict(dtheta_range=(-2e6, 0.0)), "dtheta_range"),
    (Execution, dict(threads=0), "threads"),
    (Execution, dict(threads=numba.config.NUMBA_NUM_THREADS + 1), "threads"),
    (Execution, dict(chunk=0), "chunk"),
    (Execution, dict(lanes=0), "lanes"),
    (Execution, dict(lanes=9), "lanes"),
    (Execution, dict(client=_Client(), scheduler="tcp://localhost:8786"), "client or scheduler"),
    (Execution, dict(scheduler=" "), "scheduler"),
    (Execution, dict(store=3), "store"),
    (Execution, dict(message="stderr"), "message"),
    (Execution, dict(progress="yes"), "progress"),
    (Scipy, dict(method="NOPE"), "method"),
    (Scipy, dict(rtol=0.0), "rtol"),
    (Scipy, dict(rtol=1.0), "rtol"),
    (Scipy, dict(atol=0.0), "atol"),
]


@pytest.mark.parametrize("cls, kw, match", OBJECT_CASES,
                         ids=[f"{c.__name__}-{_id((kw, None))}" for c, kw, _ in OBJECT_CASES])
def test_objects_refuse_bad_fields_naming_them(cls, kw, match):
    with pytest.raises(ValueError, match=match):
        cls(**kw)


def test_objects_accept_the_edges_of_their_ranges():
    assert Classification(settle_tol=1e-6).settle_tol == Classification().tol  # settle <= tol
    assert Integration(rest_speed=1e-12).rest_speed == 1e-12
    assert Integration(rest_speed=0.1).rest_speed == 0.1
    assert Integration(n_steps=8, periods=1, window=0).n_steps == 8
    assert Lattice(grid=1).cells == 1
    assert Execution(threads=1, lanes=1, chunk=1).lanes == 1
    assert Execution(lanes=8).lanes == 8
    assert Classification(pmax=1000, uncertainty=0.5).pmax == 1000


def test_an_unknown_keyword_is_a_type_error_naming_it():
    # the objects are dataclasses: a keyword that is not a field (here the reference path's
    # tolerance given to the integration) is Python's TypeError, naming the keyword
    with pytest.raises(TypeError, match="rtol"):
        Integration(rtol=None)
    with pytest.raises(TypeError, match="alpha"):
        Block(hb=1.0, alpha=0.6)  # the forcing moved to Harmonic
    with pytest.raises(TypeError, match="theta_over"):
        Block(hb=1.0, theta_over=1.0)  # moved to Integration
    with pytest.raises(TypeError, match="rtol"):
        rockjit.simulate(Block(1.0), Harmonic(alpha=0.6, omega=1.3), rtol=1e-9)


# ---- values of the wrong kind --------------------------------------------------------------------

ONE = dict(integration=Integration(periods=1))


@pytest.mark.parametrize("call, match", [
    (lambda: Integration(stop_at_overturn="False"), "stop_at_overturn"),
    (lambda: rockjit.simulate(Block(1.0), Harmonic(alpha=0.6, omega=1.3), lyapunov="no", **ONE),
     "lyapunov"),
    (lambda: rockjit.simulate(Block(1.0), Harmonic(alpha=0.6, omega=1.3), lyapunov=1, **ONE),
     "lyapunov"),
    (lambda: rockjit.sweep(Block(1.0), Harmonic(omega=1.3), [True, False], **ONE), "alphas"),
    (lambda: rockjit.sweep(Block(1.0), Harmonic(omega=1.3), [0.5 + 1j], **ONE), "alphas"),
    (lambda: rockjit.simulate(Block(1.0), Harmonic(alpha=0.6, omega=1.3), [[0.1, 0.0], [0.0, 0.0]],
                              **ONE), "state"),
    (lambda: rockjit.sweep(Block(1.0), Harmonic(omega=1.3), [0.5], [[0.1, 0.0], [0.0, 0.0]],
                           **ONE), "state"),
    (lambda: rockjit.simulate(Block(1.0), Harmonic(alpha=0.6, omega=1.3), (0.1 + 1j, 0.0), **ONE),
     "state"),
    (lambda: Block(hb=1 + 2j), "hb"),
    (lambda: Harmonic(alpha=0.6 + 0j, omega=1.3), "alpha"),
    (lambda: Integration(periods=2 + 0j), "periods"),
    (lambda: Block(hb=True), "hb"),
], ids=["stop_at_overturn-str", "lyapunov-str", "lyapunov-int", "alphas-bool", "alphas-complex",
        "state-2x2", "sweep-state-2x2", "state-complex", "hb-complex", "alpha-complex",
        "periods-complex", "hb-bool"])
def test_values_of_the_wrong_kind_are_refused_naming_the_parameter(call, match):
    with pytest.raises(ValueError, match=match):
        call()


# Text, numpy's complex scalars and booleans are not numbers: the API refuses them rather
# than read them (float("1"), a dropped imaginary part, True as 1.0).
@pytest.mark.parametrize("call, match", [
    (lambda: Block(hb="1"), "hb"),
    (lambda: Harmonic(alpha="0.6", omega=1.3), "alpha"),
    (lambda: Integration(periods="5"), "periods"),
    (lambda: Lattice(grid="10"), "grid"),
    (lambda: rockjit.simulate(Block(1.0), Harmonic(alpha=0.6, omega=1.3), ("0.1", "0"), **ONE),
     "state"),
], ids=["hb", "alpha", "periods", "grid", "state"])
def test_strings_are_refused_as_numbers(call, match):
    with pytest.raises(ValueError, match=match):
        call()


@pytest.mark.parametrize("call, match", [
    (lambda: Block(hb=np.complex128(1 + 2j)), "hb"),
    (lambda: Integration(periods=np.complex128(3 + 1j)), "periods"),
], ids=["hb", "periods"])
def test_numpy_complex_scalars_are_refused(call, match):
    with pytest.raises(ValueError, match=match):
        call()


def test_a_boolean_state_is_refused():
    with pytest.raises(ValueError, match="state"):
        rockjit.simulate(Block(1.0), Harmonic(alpha=0.6, omega=1.3), (True, False), **ONE)


def test_valid_edge_values_are_accepted():
    # the edges of the allowed ranges are allowed (a guard against over-eager checks)
    r = rockjit.simulate(Block(1.0 / math.sqrt(2.0) + 1e-12), Harmonic(alpha=0.0, omega=1.3),
                         (0.1, 0.0),
                         integration=Integration(periods=1, n_steps=8, theta_over=0.5 * math.pi))
    assert r.status in ("done", "rest")
    r = rockjit.simulate(Block(1.0, e=0.0), Harmonic(alpha=0.6, omega=1.3),
                         integration=Integration(periods=1, n_steps=8))
    assert r.status in ("done", "rest", "overturned")
    r = rockjit.simulate(Block(1.0, e=1.0), Harmonic(alpha=0.6, omega=1.3),
                         integration=Integration(periods=1.0, n_steps=8.0))
    assert r.periods == 1 and r.n_steps == 8


# Grids too coarse to integrate, found by the stress suite: they ended in overflow ('nonfinite')
# before the step was checked; now they are refused up front, naming n_steps and its minimum.
COARSE = [
    dict(hb=11.194041521341587, alpha=1.2893302282542554, omega=0.5017722545517583, law="mao",
         n_steps=8, periods=3, theta0=-0.0453, dtheta0=-0.0764, forcing="embedded",
         r0=-0.1572209610859118, s0=-0.9875634508198561),
    dict(hb=1.9357337261955216, alpha=0.5743672537145474, omega=0.2853226042346317,
         law="mao", n_steps=32, periods=3, theta0=-0.248, dtheta0=-0.453, forcing="embedded",
         r0=-1.3785167226179953, s0=0.634529364573173),
    dict(hb=2.0, alpha=0.3, omega=0.05, n_steps=64, periods=1, theta0=0.1, dtheta0=0.0),
]


@pytest.mark.parametrize("kw", COARSE, ids=["embedded h=1.6", "embedded rho=1.5", "h=2"])
def test_too_coarse_a_grid_is_refused(kw):
    with pytest.raises(ValueError, match=r"n_steps must be >= (\d+)") as err:
        simulate_flat(**kw)
    need = int(err.value.args[0].split(">= ")[1].split()[0])
    res = simulate_flat(**dict(kw, n_steps=need))  # the minimum it names is accepted
    assert res.status in ("done", "overturned", "rest", "max_impacts")
    assert np.all(np.isfinite(res.state))


def test_slow_forcing_raises_the_default_step_count():
    res = rockjit.simulate(Block(hb=2.0), Harmonic(alpha=0.3, omega=0.05), (0.1, 0.0),
                           integration=Integration(periods=1))
    assert res.period / res.n_steps <= MAX_STEP
    assert res.n_steps > rockjit.DEFAULT_N


# ---- strong damping, the Zeno cut-off, the start, memory ---------------------------------------

def test_strong_damping_raises_the_default_step_count_and_stays_bounded():
    # xi = 200 at N = 160 is past the step's stability (3/4 xi T/N = 3.6 > 3.3): the run used
    # to overturn at t = 2.17 with an error estimate of 1.4e2. Radau says it stays bounded.
    run = (Block(1.0, xi=200.0), Harmonic(alpha=0.6, omega=1.3))
    r = rockjit.simulate(*run, integration=Integration(periods=10))
    assert 0.75 * 200.0 * r.period / r.n_steps <= 1.0
    ref = rockjit.simulate(*run, integration=Integration(periods=10),
                           method=Scipy("Radau", rtol=1e-10, atol=1e-12))
    assert r.status == ref.status == "done"
    np.testing.assert_allclose(r.state[:2], ref.state[:2], atol=1e-7)


def test_an_unstable_explicit_step_count_is_refused_naming_the_n_needed():
    run = (Block(1.0, xi=200.0), Harmonic(alpha=0.6, omega=1.3))
    with pytest.raises(ValueError, match=r"n_steps must be >= (\d+).*damping") as err:
        rockjit.simulate(*run, integration=Integration(n_steps=160, periods=1))
    need = int(err.value.args[0].split(">= ")[1].split()[0])
    T = 2 * math.pi / 1.3
    assert 0.75 * 200.0 * T / need <= 3.0 < 0.75 * 200.0 * T / (need - 2)
    assert rockjit.simulate(*run, integration=Integration(n_steps=need, periods=1)).status == \
        "done"


def test_rest_speed_zero_is_refused():
    # it piled impacts at one instant until the impact bound
    with pytest.raises(ValueError, match="rest_speed must be > 0"):
        rockjit.simulate(Block(1.0, e=0.5), Harmonic(alpha=0.6, omega=1.3),
                         integration=Integration(rest_speed=0.0, periods=1))


@pytest.mark.parametrize("kw, match", [
    (dict(state=(2.0, 0.0)), "theta0"),                         # the CLI refused it, the API ran
    (dict(omega=1e300), "omega"), (dict(omega=1e-300), "omega"),  # OverflowError
    (dict(omega=1e-8), "omega"),                                 # MemoryError
    (dict(periods=10**12), "would need .* fits"),               # numpy's 29 TiB error
    (dict(n_steps=4_000_000_000), "would need .* fits"),
    (dict(periods=99999999999999999999), "periods must be in"),  # was "must be an integer"
    (dict(periods=10**14), "would need .* fits"),
    (dict(method="scipy", rtol=-1.0), "rtol"),                   # a TypeError with complex
    (dict(method="scipy:FOO"), "method"),                        # scipy's own error
])
def test_inputs_beyond_what_a_run_can_take_are_refused_before_it_starts(kw, match):
    with pytest.raises(ValueError, match=match):
        simulate(**{**BASE, **kw})


def test_memory_estimate_names_the_need_and_the_limit():
    from rockjit.validate import memory
    with pytest.raises(ValueError, match=r"x would need 1\.0 GiB; at most 800\.0 MiB fits"):
        memory("x", 2.0**30, limit=1000 * 2.0**20)
    memory("x", 2.0**20, limit=1000 * 2.0**20)  # fits: no error


def test_equal_arguments_make_equal_blocks_and_refusals_repeat():
    """A Block is a value: the same arguments give an equal block (hashable, so it may key a
    cache), other arguments another, numpy's floats the same as Python's; a refused block or
    forcing is refused again (nothing invalid is kept)."""
    a = Block(1.0, "housner")
    assert Block(1.0, "housner") == a and hash(Block(1.0, "housner")) == hash(a)
    b = Block(1.0, "mao")
    assert b != a and b.restitution != a.restitution
    assert Block(np.float64(1.0), "housner") == a and type(Block(np.float64(1.0)).hb) is float
    for _ in range(2):
        with pytest.raises(ValueError, match="alpha"):
            Harmonic(alpha=-0.6, omega=1.3)
    with pytest.raises(ValueError, match="hb"):
        Block(0.5, "housner")  # below 1/sqrt(2) for Housner's law
    assert Block(0.5, "mao").hb == 0.5


# ---- the ends of the documented ranges -------------------------------------------------------

#: Dampings inside the documented range [0, 1e4] too small to change a run: the renormalisation
#: interval's quotient QR_CONTRACTION / (3/4 xi h) overflows an integer (subnormal xi too)
TINY_XI = [1e-320, 2e-308, 2e-307]


@pytest.mark.parametrize("xi", TINY_XI)
def test_a_damping_too_small_to_matter_runs_as_undamped(xi):
    # it ended in OverflowError ("cannot convert float infinity to integer"); such a damping
    # changes no rounded sum of the equations, so the run is the undamped one, bit for bit
    kw = dict(hb=1.0, alpha=0.6, omega=1.3, periods=3, lyapunov=True)
    got, undamped = simulate(xi=xi, **kw), simulate(xi=0.0, **kw)
    assert got.status == undamped.status and got.n_impacts == undamped.n_impacts
    np.testing.assert_array_equal(got.state, undamped.state)
    np.testing.assert_array_equal(got.lyapunov, undamped.lyapunov)


@pytest.mark.parametrize("xi", TINY_XI)
def test_a_damping_too_small_to_matter_grids_as_undamped(xi):
    forcing, lattice = Harmonic(alpha=0.66, omega=1.3), Lattice(2)
    kw = dict(integration=Integration(periods=2), lyapunov=True,
              execution=Execution(threads=1, progress=False))
    got = rockjit.basin(Block(1.0, xi=xi), forcing, lattice, **kw)
    undamped = rockjit.basin(Block(1.0, xi=0.0), forcing, lattice, **kw)
    np.testing.assert_array_equal(got.label, undamped.label)
    np.testing.assert_array_equal(got.lambda_max, undamped.lambda_max)
    np.testing.assert_array_equal(got.t_end, undamped.t_end)


def test_renormalisation_interval_by_brute_force():
    # the interval is the largest k <= N/2 with k * 3/4 xi h <= QR_CONTRACTION (at least 1):
    # counted here in exact rationals, over dampings from subnormal to the range's end
    from fractions import Fraction

    from rockjit._engine.kernel import QR_CONTRACTION, default_qr_every
    for n_steps, h in ((64, 0.07), (160, 0.03), (8, 0.5)):
        for xi in TINY_XI + [1e-300, 1e-6, 2.208e-4, 1.0, 105.0, 1e4]:
            c = Fraction(0.75 * xi * h)  # the kernel's own rounded product
            k = n_steps // 2
            while k > 1 and k * c > Fraction(QR_CONTRACTION):
                k -= 1
            assert default_qr_every(n_steps, h, xi) == k, (n_steps, h, xi)


def test_default_impact_bound_fits_the_kernels_counter_for_every_period_count():
    # 10,000 x 922337203685478 periods overflowed int64 (OverflowError from numpy)
    # docs/theory/impacts.md: 10,000 impacts a period, at least 100,000; capped at 2**62 (the
    # settings' MAX_IMPACTS), which the bound of 461168601842739 periods or more would pass
    from rockjit.settings import MAX_PERIODS
    expected = {1: 100_000, 10: 100_000, 500: 5_000_000, 10**4: 100_000_000,
                461168601842738: 4_611_686_018_427_380_000,
                461168601842739: 4_611_686_018_427_387_904,
                922337203685478: 4_611_686_018_427_387_904,
                10**15: 4_611_686_018_427_387_904}
    assert MAX_PERIODS in expected
    for periods, want in expected.items():
        bound = Integration(periods=periods).impact_bound()
        assert bound == want and bound < 2**63


@pytest.mark.parametrize("periods", [922337203685478, 10**15])
def test_the_largest_period_counts_are_refused_by_their_memory_not_an_overflow(periods):
    with pytest.raises(ValueError, match=r"would need .* fits"):
        simulate(**{**BASE, "periods": periods})
    with pytest.raises(ValueError, match=r"over periods = .* would need .* fits"):
        rockjit.basin(Block(1.0), Harmonic(alpha=0.66, omega=1.3), Lattice(2),
                      integration=Integration(periods=periods))


# ---- the closed forms of the pulses over the whole ratio range -------------------------------

def _sine_reference(beta):
    """The one-sine boundary in mpmath, straight from its definition: the root ``a`` of
    ``(sqrt(a^2 - 1) - beta) exp((2 pi - arcsin(1/a)) / beta) = a`` by bisection (over
    ``log(sqrt(a^2 - 1) - beta)``: the root lies as close as ``e^(-3 pi / (2 beta))`` above
    ``sqrt(1 + beta^2)``), and the least ``phi = 1 - a sin(beta tau) / (1 + beta^2) +
    A cosh(tau - tau_u) + B sinh(tau - tau_u)`` on the pulse's 2000 points, at enough digits
    for ``cosh(2 pi / beta)`` to cancel."""
    mp = pytest.importorskip("mpmath")
    with mp.workdps(int(2 * math.pi / beta / math.log(10)) + 40):
        b = mp.mpf(beta)
        f = lambda a: (mp.sqrt(a * a - 1) - b) * mp.exp((2 * mp.pi - mp.asin(1 / a)) / b) - a
        a_of = lambda t: mp.sqrt(1 + (b + mp.exp(t)) ** 2)
        lo, hi = -2 * mp.pi / b - 10, mp.log(4 + b * b)
        assert f(a_of(lo)) < 0 < f(a_of(hi))
        for _ in range(200):
            mid = (lo + hi) / 2
            lo, hi = (mid, hi) if f(a_of(mid)) < 0 else (lo, mid)
        a = a_of(lo)
        tu = mp.asin(1 / a) / b
        A, B = -b * b / (1 + b * b), a * b * mp.cos(b * tu) / (1 + b * b)
        phi = min(1 - a * mp.sin(b * t) / (1 + b * b) + A * mp.cosh(t - tu) + B * mp.sinh(t - tu)
                  for t in mp.linspace(tu, 2 * mp.pi / b, 2001)[1:])
        return float(a), phi > 0


def test_closed_forms_at_the_smallest_ratio_take_their_quasi_static_limit():
    # at beta = 1e-3 (the range's end) the root lies within e^(-3 pi / (2 beta)) = e^-4712 of
    # sqrt(1 + beta^2), the one-cosine boundary within e^(-2 pi / beta) of 1 + beta^2
    from rockjit.ground.closed_forms import cosine_no_impact, sine_no_impact
    from rockjit.plugs.pulse import RATIO_RANGE
    beta = RATIO_RANGE[0]
    assert sine_no_impact(beta) == pytest.approx(math.sqrt(1 + beta * beta), rel=1e-15)
    assert cosine_no_impact(beta) == pytest.approx(1 + beta * beta, rel=1e-15)


@pytest.mark.parametrize("beta", [0.005, 0.01, 0.1, 1.0, 10.0, 1e3])
def test_closed_forms_hold_over_the_whole_ratio_range(beta):
    # exp(2 pi / beta) overflowed below beta ~ 0.009 (OverflowError after a spectrum's work),
    # and cosh - sinh cancelled into a false "strikes the ground" at beta = 0.01 and 0.1
    from rockjit.ground.closed_forms import cosine_no_impact, sine_no_impact
    from rockjit.plugs.pulse import RATIO_RANGE
    assert RATIO_RANGE[0] <= beta <= RATIO_RANGE[1]
    a_ref, applies = _sine_reference(beta)
    if applies:
        assert sine_no_impact(beta) == pytest.approx(a_ref, rel=1e-13)
    else:
        with pytest.raises(ValueError, match="closed form does not apply"):
            sine_no_impact(beta)
    mp = pytest.importorskip("mpmath")
    with mp.workdps(40):
        ref = (1 + mp.mpf(beta) ** 2) / (1 - mp.exp(-2 * mp.pi / beta))
    assert cosine_no_impact(beta) == pytest.approx(float(ref), rel=1e-14)
