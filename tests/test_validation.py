"""Input checking of ``rockjit.single``: every invalid input is a ValueError naming the parameter.

Checked against SPEC.md's ranges (§1-3) and STYLE.md 12, on both the compiled and the scipy path
(the wrapper validates before it dispatches, so no integration runs in these tests).
"""

import math

import numpy as np
import pytest

import rockjit
from rockjit.single import MAX_STEP

BASE = dict(hb=1.0, alpha=0.6, omega=1.3, periods=1)
NAN = math.nan

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
    (dict(forcing="open"), "forcing"),
    (dict(r0=0.5, s0=0.5), "r0"),                      # off the circle with closed forcing
    (dict(r0=0.0), "r0"),                              # r0 without s0
    (dict(s0=1.0), "s0"),                              # s0 without r0
    (dict(r0=0.0, s0=0.0, forcing="embedded"), "r0"),  # no phase at the origin
    (dict(r0=NAN, s0=1.0), "r0"),
    (dict(phase=NAN), "phase"),
    (dict(phase=0.3, r0=0.0, s0=1.0), "phase"),
    (dict(z0=(0.1, 0.2, 0.3)), "z0"),
    (dict(z0=(0.1, 0.2, 0.0, 1.0), theta0=0.1), "z0"),
    (dict(z0=(NAN, 0.2, 0.0, 1.0)), "theta0|z0"),
    (dict(theta0=NAN), "theta0"),
    (dict(dtheta0=NAN), "dtheta0"),
    (dict(theta0=math.inf), "theta0"),
]


def _id(case):
    changes, _ = case
    return ",".join(f"{k}={v!r}" for k, v in changes.items())


@pytest.mark.parametrize("method", ["rockjit", "scipy:DOP853"])
@pytest.mark.parametrize("case", CASES, ids=[_id(c) for c in CASES])
def test_invalid_input_names_the_parameter(case, method):
    changes, match = case
    with pytest.raises(ValueError, match=match):
        rockjit.simulate(**{**BASE, "method": method, **changes})


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
        rockjit.simulate(**{**BASE, **changes})


def test_valid_edge_values_are_accepted():
    # the edges of the allowed ranges are allowed (a guard against over-eager checks)
    r = rockjit.simulate(1.0 / math.sqrt(2.0) + 1e-12, 0.0, 1.3, periods=1, theta0=0.1,
                         dtheta0=0.0, n_steps=8, theta_over=0.5 * math.pi)
    assert r.status in ("done", "rest")
    r = rockjit.simulate(1.0, 0.6, 1.3, e=0.0, periods=1, n_steps=8)
    assert r.status in ("done", "rest", "overturned")
    r = rockjit.simulate(1.0, 0.6, 1.3, e=1.0, periods=1.0, n_steps=8.0)
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
        rockjit.simulate(**kw)
    need = int(err.value.args[0].split(">= ")[1].split()[0])
    res = rockjit.simulate(**dict(kw, n_steps=need))  # the minimum it names is accepted
    assert res.status in ("done", "overturned", "rest", "max_impacts")
    assert np.all(np.isfinite(res.state))


def test_slow_forcing_raises_the_default_step_count():
    res = rockjit.simulate(hb=2.0, alpha=0.3, omega=0.05, periods=1, theta0=0.1, dtheta0=0.0)
    assert res.period / res.n_steps <= MAX_STEP
    assert res.n_steps > rockjit.DEFAULT_N


# ---- issue 10: strong damping, the Zeno cut-off, the start, memory -----------------------------

def test_strong_damping_raises_the_default_step_count_and_stays_bounded():
    # xi = 200 at N = 160 is past the step's stability (3/4 xi T/N = 3.6 > 3.3): the run used
    # to overturn at t = 2.17 with an error estimate of 1.4e2. Radau says it stays bounded.
    r = rockjit.simulate(1.0, 0.6, 1.3, xi=200.0, periods=10)
    assert 0.75 * 200.0 * r.period / r.n_steps <= 1.0
    ref = rockjit.simulate(1.0, 0.6, 1.3, xi=200.0, periods=10, method="scipy:Radau",
                           rtol=1e-10, atol=1e-12)
    assert r.status == ref.status == "done"
    np.testing.assert_allclose(r.state[:2], ref.state[:2], atol=1e-7)


def test_an_unstable_explicit_step_count_is_refused_naming_the_n_needed():
    with pytest.raises(ValueError, match=r"n_steps must be >= (\d+).*damping") as err:
        rockjit.simulate(1.0, 0.6, 1.3, xi=200.0, n_steps=160, periods=1)
    need = int(err.value.args[0].split(">= ")[1].split()[0])
    T = 2 * math.pi / 1.3
    assert 0.75 * 200.0 * T / need <= 3.0 < 0.75 * 200.0 * T / (need - 2)
    assert rockjit.simulate(1.0, 0.6, 1.3, xi=200.0, n_steps=need, periods=1).status == "done"


def test_rest_speed_zero_is_refused():
    # it piled impacts at one instant until the impact bound
    with pytest.raises(ValueError, match="rest_speed must be > 0"):
        rockjit.simulate(1.0, 0.6, 1.3, e=0.5, rest_speed=0.0, periods=1)


@pytest.mark.parametrize("kw, match", [
    (dict(theta0=2.0), "theta0"),                               # the CLI refused it, the API ran
    (dict(omega=1e300), "omega"), (dict(omega=1e-300), "omega"),  # OverflowError
    (dict(omega=1e-8), "omega"),                                 # MemoryError
    (dict(periods=10**12), "would need .* fits"),               # numpy's 29 TiB error
    (dict(n_steps=4_000_000_000), "would need .* fits"),
    (dict(periods=99999999999999999999), "periods must be in"),  # was "must be an integer"
    (dict(periods=10**14), "would need .* fits"),
    (dict(method="scipy", rtol=-1.0), "rtol"),                   # a TypeError with complex
    (dict(method="scipy:FOO"), "method"),                        # scipy's own error
])
def test_issue_10_inputs_are_refused_by_the_api(kw, match):
    with pytest.raises(ValueError, match=match):
        rockjit.simulate(**{**BASE, **kw})


def test_memory_estimate_names_the_need_and_the_limit():
    from rockjit.validate import memory
    with pytest.raises(ValueError, match=r"x would need 1\.0 GiB; at most 800\.0 MiB fits"):
        memory("x", 2.0**30, limit=1000 * 2.0**20)
    memory("x", 2.0**20, limit=1000 * 2.0**20)  # fits: no error


def test_blocks_made_once_and_refusals_never_remembered():
    """simulate.make_block keeps the blocks it made from plain numbers (a run's fixed cost): the
    same arguments give the same block, other arguments another, and a refused block is refused
    again (nothing invalid is kept)."""
    from rockjit.single import make_block
    a = make_block(1.0, 0.6, 1.3, "housner")
    assert make_block(1.0, 0.6, 1.3, "housner") is a
    b = make_block(1.0, 0.6, 1.3, "mao")
    assert b is not a and b.restitution != a.restitution
    assert make_block(np.float64(1.0), 0.6, 1.3, "housner") == a  # not kept, still equal
    for _ in range(2):
        with pytest.raises(ValueError, match="alpha"):
            make_block(1.0, -0.6, 1.3, "housner")
    with pytest.raises(ValueError, match="hb"):
        make_block(0.5, 0.6, 1.3, "housner")  # below 1/sqrt(2) for Housner's law
    assert make_block(0.5, 0.6, 1.3, "mao").hb == 0.5
