"""The numerical stress suite: seeded extreme cases for ``rockjit.single`` and the checks
every run must pass.

What it is for: finding inputs on which the compiled integrator misbehaves (a NaN, a wrong
ending, unbounded work, impacts that stop advancing time, broken exact symmetries) by running
thousands of seeded cases over and beyond the study's ranges, and checking each result against
properties that must hold whatever the dynamics. Two users import it as ``stress`` (from
``tests/``, where it lives): ``tests/test_stress.py`` runs a fast subset in the test suite, and
``benchmarks/bench_stress.py`` runs the full suite and tabulates the outcome
(benchmarks/README.md, "Stress suite"). Everything is a pure function of a seed, so a
failing case can be rerun by its id (``python benchmarks/bench_stress.py --case ID``).

Cases cover hb in [0.75, 20], alpha in [0, 3] (half of them with ``alpha omega^2 hb`` in [0, 4],
near the uplift threshold), omega in [0.05, 20], e in [0, 1] (Housner, Mao and constant laws,
e = 0 and e = 1 included), damping 0, the study's or up to 0.5, N from 8 to 1024,
closed or embedded forcing (on and off the unit circle), with and without exponents and
recording, and these initial states:

``random``
    mostly around the unforced block's separatrix (``|theta0|`` up to 1.2 times the tipping angle
    ``pi/2 - thc``, ``|theta0'|`` up to 1.2 times the speed that reaches it from 0), a quarter
    anywhere in ``|theta0| < theta_over``, ``|theta0'| < 2``; any phase;
``near_zero``
    ``theta0, theta0'`` among 0, subnormals, 1e-300, 1e-15, 1e-8 (side selection, start at rest);
``grazing``
    a dip that just touches ``theta = 0`` (forcing above the uplift threshold turns the block
    back near the corner, the speed set to ``(1 + eps)`` times the touching one), and a block at
    rest with ``alpha omega^2`` a hair above or below ``cot(thc)``;
``near_overturn``
    ``|theta0|`` a hair below, at, or beyond ``theta_over``; at the upright unstable equilibrium
    ``theta0 = +-(pi/2 - thc)`` give or take 1e-12;
``long_horizon``
    thousands of periods;
``impact_bound``
    ``max_impacts`` from 1 to 100, to exercise the bound.

The extreme cases take the suite beyond those ranges with three more categories, drawn by
:func:`extreme_cases` (ids ``x<seed>-<i>``, so that the ids of the cases above stay what they
were); their horizon is cut so that no run is given more than ``MAX_GRID_STEPS`` grid steps:

``stiff_damping``
    ``random`` cases with damping ``xi`` log-uniform in [0.5, 500] (500 itself now and then). The
    fixed explicit step is stable only for ``h * 3/4 xi`` below a bound, so a default N must be
    raised past it, and an explicit ``n_steps`` below it refused (a ``ValueError`` naming
    ``n_steps``: counted as ``refused``);
``wide_omega``
    ``random`` cases with ``omega`` log-uniform in [1e-3, 1e3] (both ends now and then), half of
    them with forcing near the uplift threshold (``alpha omega^2 hb`` in [0, 4], whatever alpha
    that takes). At slow forcing the default N grows as ``T / 0.1``, ~63 000 steps per period at
    omega = 1e-3, and such runs get few periods;
``through_rest``
    orbits that pass through rest: under forcing above the uplift threshold
    (``alpha omega^2 = m cot(thc)``, ``m`` in [1.02, 4], mostly below 1.5), from rest
    (``theta0 = theta0' = 0``) or rocking, mostly with a low restitution (``e`` in [0.02, 0.3])
    so that impacts accumulate into a Zeno rest and the forcing lifts the block again; mostly
    with exponents, and with ``rest_speed`` from 1e-8 to 1e-3.

Checks of every run (:func:`check_run`; each returns a list of problems, empty when it passes):

``status``
    the run ended with one of ``done, overturned, rest, max_impacts`` (``nonfinite`` is a fail);
``finite``
    no NaN or inf in ``t, state, strobe, strobe_half, impacts, max_error_estimate, trajectory,
    lyapunov_running`` and the tangent; the exponents are finite except for their documented
    sentinels: ``-inf`` for a run that came to rest, from the first impact on with ``e = 0`` and
    after a rest phase (both collapse every perturbation), ``nan`` when the run ended before the
    averaging window began;
``time``
    ``0 <= t <= periods T``, ``t = periods T`` for ``done``, and as many stroboscopic samples as
    periods completed;
``work``
    ``n_rhs <= 1 + 6 N periods + 56 (n_impacts + n_rest + 2)``: six stages per grid step, and at
    most 8 Newton re-steps (48), one re-started substep (6) and one refresh (1) per event;
``bookkeeping``
    ``n_impacts <= max_impacts``, the bound reached exactly when the status says so, impact times
    ordered within ``[0, t]``, ``theta'+ = e theta'-`` exactly, ``|theta| <= theta_over`` at
    every sample, an overturned run ends on the threshold, a run at rest ends at
    ``theta = theta' = 0`` with forcing too weak to lift it;
``progress``
    impacts advance time: no more than ``STALL`` (100) of them at one floating-point instant;
``rest_exponents``
    an orbit that passes through rest within the averaging window (``n_rest_window > 0``) has no
    positive exponent: a rest phase holds ``theta = theta' = 0`` until the forcing lifts the
    block, whatever the perturbation, so every perturbation dies and the exponents are ``-inf``
    (docs/theory/exponents.md; a wrong update once gave lambda1 = +1.95 on such an orbit).

Hitting the impact bound is not a failure; it is counted and reported as such. Neither is the
refusal of a grid too coarse to integrate (``T/N`` above rockjit's step limit, an embedded step
beyond the oscillator's stability, or a step beyond the explicit stability of a large
damping): it must be a ``ValueError`` naming ``n_steps`` first (any other exception fails the
``status`` check), and it is counted as ``refused``.

Exact checks that ride along:

``energy``
    ``e = 1, xi = 0, alpha = 0``: ``E = theta'^2 / 2 + 3/4 sin(thc + |theta|)`` is conserved
    (at a resolved step, ``h <= 0.025``) to ``1e-10 + 1e-12 n_impacts``;
``mirror_embedded``
    with the 4-D embedding the mirror ``(theta, theta', r, s) -> -(theta, theta', r, s)`` is exact
    in floating point (every operation of the kernel is odd in the state), so the mirrored run
    must be the negated run bit for bit, on any horizon, chaotic or not;
``mirror_closed``
    with the closed form the mirror is ``(theta, theta', phase) -> (-theta, -theta', phase + pi)``,
    i.e. ``t -> t + T/2``; ``sin(x + pi) != -sin(x)`` in the last bit, so the runs are compared
    over the stretch where two twin runs with the phase moved by +-1e-13 (a hundred times the
    rounding of ``phase + pi``) still agree with the original to 1e-8 (the run's own rounding
    horizon): there the mirrored run must agree to 1e-7 of the orbit's size (times: of
    ``max(1, t)``), impacts, samples, end and status included;
``threads``
    a basin and a sweep with 1 and 2 numba threads are identical bit for bit.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np

import rockjit
from rockjit.excitation import Harmonic
from rockjit.model import Block
from rockjit.settings import Classification, Execution, Integration, Lattice, default_max_impacts
from rockjit.single import steps_per_period

RANGES = dict(hb=(0.75, 20.0), alpha=(0.0, 3.0), omega=(0.05, 20.0), e=(0.0, 1.0))
CATEGORIES = ("random", "near_zero", "grazing", "near_overturn", "long_horizon",
              "impact_bound")
#: The extreme cases: the categories beyond the ranges above (:func:`extreme_cases`)
EXTREME_CATEGORIES = ("stiff_damping", "wide_omega", "through_rest")
EXTREME_RANGES = dict(xi=(0.5, 500.0), omega=(1e-3, 1e3))
ALL_CATEGORIES = CATEGORIES + EXTREME_CATEGORIES
RUN_CHECKS = ("status", "finite", "time", "work", "bookkeeping", "progress", "rest_exponents")
EXACT_CHECKS = ("energy", "mirror_embedded", "mirror_closed", "threads")
KNOWN_STATUS = ("done", "overturned", "rest", "max_impacts")
HALF_PI = 0.5 * math.pi

#: Steps longer than this do not resolve the rocking (its time scale is 1): an event located
#: inside one is only as good as the step (see :func:`observations`).
H_RESOLVED = 1.0

#: ``progress``: more impacts than this at one floating-point instant is a stall.
STALL = 100

#: rhs evaluations an event may cost beyond its grid step: 8 Newton re-steps of 6 stages, the
#: re-started rest of the step (6) and the refreshed first stage (1), rounded up
EVENT_RHS = 56

#: The most grid steps (N times periods) an extreme case is given: its periods are cut to fit.
MAX_GRID_STEPS = 400_000

#: ``h * 3/4 xi`` an explicit Dormand–Prince step stays stable below (its stability interval
#: on the negative real axis is ~3.3; taken lower to estimate the N a stiff case will need).
STIFF_HXI = 2.5


_BLOCK = ("hb", "law", "e", "xi")
_FORCING = ("alpha", "omega", "phase", "r0", "s0")
_INTEGRATION = ("n_steps", "periods", "window", "max_impacts", "rest_speed", "theta_over",
                "stop_at_overturn", "qr_every")


def objects(kw):
    """The objects of rockjit's API from a case's flat keywords.

    Cases are drawn, stored and printed as flat keywords (``hb``, ``alpha``, ``omega``,
    ``theta0``, ``periods``, ...), the keywords of :class:`rockjit.Block`,
    :class:`rockjit.Harmonic` and :class:`rockjit.Integration` together, plus ``theta0``,
    ``dtheta0`` and ``forcing="embedded"``. A state given without a phase starts the forcing
    at ``(r0, s0) = (0, 1)``.

    Parameters
    ----------
    kw : dict
        The flat keywords.

    Returns
    -------
    block : Block
    forcing : Harmonic
    state : tuple of float or None
        ``(theta0, theta0')``, or ``None`` (the study's).
    integration : Integration
    rest : dict
        The keywords left (``lyapunov``, ``record_stride``, ...).

    Examples
    --------
    >>> from stress import objects
    >>> block, forcing, state, integration, rest = objects(
    ...     dict(hb=1.0, alpha=0.6, omega=1.3, theta0=0.1, periods=20, lyapunov=True))
    >>> forcing.start()[1:], state, integration.periods, rest
    ((0.0, 1.0), (0.1, 0.0), 20, {'lyapunov': True})
    """
    kw = dict(kw)
    block = Block(**{k: kw.pop(k) for k in _BLOCK if k in kw})
    forcing = Harmonic(**{k: kw.pop(k) for k in _FORCING if k in kw},
                       embedded=kw.pop("forcing", "closed") == "embedded")
    theta0, dtheta0 = kw.pop("theta0", None), kw.pop("dtheta0", None)
    state = None if theta0 is None and dtheta0 is None else (theta0 or 0.0, dtheta0 or 0.0)
    if state is not None and not forcing.phase_given:
        forcing = forcing.replace(r0=0.0, s0=1.0)
    integration = Integration(**{k: kw.pop(k) for k in _INTEGRATION if k in kw})
    return block, forcing, state, integration, kw


def simulate_flat(**kw):
    """:func:`rockjit.simulate` of a case's flat keywords (:func:`objects`).

    Parameters
    ----------
    **kw
        The flat keywords of a case.

    Returns
    -------
    Result
        The run.

    Examples
    --------
    >>> from stress import simulate_flat
    >>> simulate_flat(hb=1.0, alpha=0.6, omega=1.3, theta0=0.1, periods=20).status
    'done'
    """
    block, forcing, state, integration, rest = objects(kw)
    return rockjit.simulate(block, forcing, state, integration=integration, **rest)


@dataclass
class Case:
    """One stress run: :func:`simulate_flat` of ``kwargs``.

    Attributes
    ----------
    id : str
        ``s<seed>-<i>`` (:func:`cases`) or ``x<seed>-<i>`` (:func:`extreme_cases`): the case
        drawn again by :func:`case_by_id`.
    category : str
        What kind of case it is (the module's categories).
    kwargs : dict
        The run's flat keywords.

    Examples
    --------
    >>> from stress import Case, run_case
    >>> case = Case("demo", "random", dict(hb=1.0, alpha=0.6, omega=1.3, periods=20))
    >>> result, problems, refusal = run_case(case)
    >>> result.status, any(problems.values()), refusal
    ('done', False, None)
    """

    id: str
    category: str
    kwargs: dict = field(default_factory=dict)


# --------------------------------------------------------------------------- drawing


def _logu(rng, lo, hi):
    return float(np.exp(rng.uniform(math.log(lo), math.log(hi))))


def _pick(rng, seq):
    return seq[int(rng.integers(len(seq)))]


def _params(rng):
    """Block parameters over the documented ranges (RANGES), end points included now and then."""
    u = rng.random()
    hb = 0.75 if u < 0.05 else 20.0 if u < 0.1 else _logu(rng, *RANGES["hb"])
    u = rng.random()
    alpha = 0.0 if u < 0.05 else 3.0 if u < 0.1 else float(rng.uniform(*RANGES["alpha"]))
    u = rng.random()
    omega = 0.05 if u < 0.05 else 20.0 if u < 0.1 else _logu(rng, *RANGES["omega"])
    if rng.random() < 0.5:
        # half the time, forcing near the uplift threshold (alpha omega^2 hb in [0, 4]), where
        # the block rocks for long rather than overturning at once (alpha <= 3 still)
        alpha = min(RANGES["alpha"][1], float(rng.uniform(0.0, 4.0)) / (hb * omega**2))
    kw = dict(hb=hb, alpha=alpha, omega=omega)
    _law(rng, kw)
    u = rng.random()
    if u < 0.2:
        kw["xi"] = 0.0
    elif u < 0.3:
        kw["xi"] = float(rng.uniform(0.0, 0.5))
    return kw


def _law(rng, kw):
    law = _pick(rng, ("housner", "mao", "constant"))
    kw["law"] = law
    if law == "constant":
        u = rng.random()
        kw["e"] = 0.0 if u < 0.2 else 1.0 if u < 0.4 else float(rng.uniform(*RANGES["e"]))


def grid_n(kw):
    """The N a case runs with: its own, or simulate's default for its period."""
    return kw.get("n_steps") or steps_per_period(2 * math.pi / kw["omega"], rockjit.DEFAULT_N)


def _settings(rng, kw, max_periods, lo_periods=1):
    """Grid, horizon, switches and the less common parameters."""
    if rng.random() < 0.3:
        kw["n_steps"] = int(_pick(rng, (8, 16, 32, 64, 128, 512, 1024)))
    n = grid_n(kw)
    kw["periods"] = max(1, int(_logu(rng, lo_periods, max_periods + 0.999)))
    u = rng.random()
    if u < 0.1:
        kw["theta_over"] = float(rng.uniform(0.05, HALF_PI))
    u = rng.random()
    if u < 0.1:
        kw["rest_speed"] = 1e-10  # nearly no cut-off (0 is refused)
    elif u < 0.2:
        kw["rest_speed"] = 1e-3
    if rng.random() < 0.2:
        kw["lyapunov"] = True
    if rng.random() < 0.1 and n * kw["periods"] <= 200_000:
        kw["record_stride"] = int(_pick(rng, (1, 7, 64)))
    return kw


def _phase(rng, kw, phase=None):
    """Closed forcing with a phase, or (20 %) the embedding, off the unit circle now and then."""
    phi = float(rng.uniform(0.0, 2.0 * math.pi)) if phase is None else phase
    if rng.random() < 0.2:
        kw["forcing"] = "embedded"
        rad = 1.0 if rng.random() < 0.7 else _logu(rng, 0.3, 2.0)
        kw["r0"] = rad * math.sin(phi)
        kw["s0"] = rad * math.cos(phi)
    else:
        kw["phase"] = phi


def _theta_over(kw):
    return kw.get("theta_over", HALF_PI)


def _thc(kw):
    return math.atan(kw["hb"])


def case_random(rng, max_periods):
    kw = _settings(rng, _params(rng), max_periods)
    if rng.random() < 0.25:
        kw["theta0"] = float(rng.uniform(-0.99, 0.99) * _theta_over(kw))
        kw["dtheta0"] = float(rng.uniform(-2.0, 2.0))
    else:
        # around the unforced block's separatrix: the tipping angle pi/2 - thc, and the speed
        # that carries the block from theta = 0 up to it
        thc = _thc(kw)
        tip = HALF_PI - thc
        v_tip = math.sqrt(1.5 * (1.0 - math.sin(thc)))
        kw["theta0"] = float(np.clip(rng.uniform(-1.2, 1.2) * tip, -0.99 * _theta_over(kw),
                                     0.99 * _theta_over(kw)))
        kw["dtheta0"] = float(rng.uniform(-1.2, 1.2) * v_tip)
    _phase(rng, kw)
    return kw


def case_near_zero(rng, max_periods):
    kw = _settings(rng, _params(rng), max_periods)
    kw["theta0"] = float(_pick(rng, (0.0, 0.0, 5e-324, -5e-324, 1e-300, -1e-15, 1e-8)))
    kw["dtheta0"] = float(_pick(rng, (0.0, 5e-324, -1e-300, 1e-12, -1e-6,
                                      float(rng.uniform(-1, 1)))))
    _phase(rng, kw)
    return kw


def case_grazing(rng, max_periods):
    kw = _params(rng)
    thc = _thc(kw)
    cot = 1.0 / kw["hb"]
    a_max = RANGES["alpha"][1]
    if rng.random() < 0.6:
        # a dip to theta = 0: forcing above the uplift threshold at the start turns the block back
        # near its corner; the speed is (1 + eps) times the one that just touches theta = 0
        margin = _logu(rng, 1.05, 4.0)
        om_lo = max(RANGES["omega"][0], math.sqrt(cot * margin / a_max) * 1.0001)
        kw["omega"] = _logu(rng, om_lo, RANGES["omega"][1])
        kw["alpha"] = min(a_max, cot * margin / kw["omega"] ** 2)
        aw2 = kw["alpha"] * kw["omega"] ** 2
        side = _pick(rng, (1.0, -1.0))
        a = 0.75 * (aw2 * math.sin(thc) - math.cos(thc))
        delta = float(_pick(rng, (1e-12, 1e-8, 1e-5, 1e-3)))
        eps = float(_pick(rng, (-1e-6, -1e-10, 0.0, 1e-10, 1e-6)))
        v = math.sqrt(2.0 * a * delta) * (1.0 + eps)
        kw["theta0"] = side * delta
        kw["dtheta0"] = -side * v
        _settings(rng, kw, max_periods)
        kw.pop("theta_over", None)
        _phase(rng, kw, phase=side * 0.5 * math.pi)
    else:
        # at rest, the forcing a hair above (lifts, barely) or below (never lifts) the threshold
        eta = float(_pick(rng, (1e-12, 1e-9, 1e-6, 1e-3))) * _pick(rng, (1.0, -1.0))
        om_lo = max(RANGES["omega"][0], math.sqrt(cot * (1 + abs(eta)) / a_max) * 1.0001)
        kw["omega"] = _logu(rng, om_lo, RANGES["omega"][1])
        kw["alpha"] = cot * (1.0 + eta) / kw["omega"] ** 2
        kw["theta0"] = 0.0
        kw["dtheta0"] = 0.0
        _settings(rng, kw, max_periods)
        _phase(rng, kw)
    return kw


def case_near_overturn(rng, max_periods):
    kw = _settings(rng, _params(rng), max_periods)
    side = _pick(rng, (1.0, -1.0))
    u = rng.random()
    th_over = _theta_over(kw)
    if u < 0.45:
        eps = float(_pick(rng, (0.0, 1e-15, 1e-9, 1e-4)))
        kw["theta0"] = side * (th_over - eps)
        kw["dtheta0"] = float(rng.uniform(-1.0, 1.0))
    elif u < 0.9:
        # the upright position: an unstable equilibrium without forcing (theta_over must be
        # beyond it for the case to mean anything)
        kw.pop("theta_over", None)
        if rng.random() < 0.5:
            kw["alpha"] = 0.0
        delta = float(_pick(rng, (-1e-6, -1e-12, 0.0, 1e-12, 1e-6)))
        kw["theta0"] = side * (HALF_PI - _thc(kw) + delta)
        kw["dtheta0"] = 0.0
    else:
        kw["theta0"] = side * float(rng.uniform(th_over, 3.0))
        kw["dtheta0"] = float(rng.uniform(-1.0, 1.0))
    _phase(rng, kw)
    return kw


def case_long_horizon(rng, max_periods, long_periods):
    kw = case_random(rng, max_periods)
    kw.pop("record_stride", None)
    hi = max(2, min(long_periods, 4_000_000 // grid_n(kw)))
    kw["periods"] = max(1, int(_logu(rng, max(1, hi // 10), hi)))
    return kw


def case_impact_bound(rng, max_periods):
    kw = case_random(rng, max_periods)
    kw["max_impacts"] = int(_pick(rng, (1, 2, 3, 10, 100)))
    return kw


def cases(n, seed=0, *, max_periods=200, long_periods=20_000):
    """``n`` seeded stress cases, the categories in turn.

    Parameters
    ----------
    n : int
        Number of cases.
    seed : int
        Seed: the same seed draws the same cases on every machine.
    max_periods : int
        Bound on the horizon of every category but ``long_horizon``.
    long_periods : int
        Bound on the horizon of ``long_horizon`` cases (and at most 4e6 grid steps).

    Returns
    -------
    list of Case
        Ids ``s<seed>-<i>``.

    Examples
    --------
    >>> from stress import cases
    >>> [(c.id, c.category) for c in cases(3)]
    [('s0-0', 'random'), ('s0-1', 'near_zero'), ('s0-2', 'grazing')]
    """
    out = []
    for i in range(n):
        cat = CATEGORIES[i % len(CATEGORIES)]
        rng = np.random.default_rng([seed, i])
        if cat == "long_horizon":
            kw = case_long_horizon(rng, max_periods, long_periods)
        else:
            kw = globals()[f"case_{cat}"](rng, max_periods)
        out.append(Case(id=f"s{seed}-{i}", category=cat, kwargs=kw))
    return out


# --------------------------------------------------------------------------- the extreme cases


def cost_n(kw):
    """The N a case is expected to run with: :func:`grid_n`, and at least the N that keeps a
    stiff damping stable (``h * 3/4 xi <= STIFF_HXI``)."""
    n = grid_n(kw)
    xi = kw.get("xi", 0.0)
    if not kw.get("n_steps") and xi > 0:
        n = max(n, 2 * math.ceil(2 * math.pi / kw["omega"] * 0.75 * xi / (2 * STIFF_HXI)))
    return n


def _fit(kw, max_steps=MAX_GRID_STEPS):
    """Cut the horizon to ``max_steps`` grid steps (one period at least); no recording of runs
    longer than 200 000 steps."""
    n = cost_n(kw)
    kw["periods"] = max(1, min(kw["periods"], max_steps // n))
    if n * kw["periods"] > 200_000:
        kw.pop("record_stride", None)
    return kw


def case_stiff_damping(rng, max_periods):
    kw = case_random(rng, max_periods)
    lo, hi = EXTREME_RANGES["xi"]
    kw["xi"] = hi if rng.random() < 0.1 else _logu(rng, lo, hi)
    return _fit(kw)


def case_wide_omega(rng, max_periods):
    kw = case_random(rng, max_periods)
    lo, hi = EXTREME_RANGES["omega"]
    u = rng.random()
    kw["omega"] = lo if u < 0.05 else hi if u < 0.1 else _logu(rng, lo, hi)
    if rng.random() < 0.5:
        # near the uplift threshold, whatever alpha that takes (1e6 at omega = 1e-3)
        kw["alpha"] = float(rng.uniform(0.0, 4.0)) / (kw["hb"] * kw["omega"] ** 2)
    return _fit(kw)


def case_through_rest(rng, max_periods):
    kw = _params(rng)
    cot = 1.0 / kw["hb"]
    a_max = RANGES["alpha"][1]
    # forcing above the uplift threshold, so that a block at rest is lifted again; mostly a
    # little above it, where a lifted block comes back to rest within the period
    m = _logu(rng, 1.02, 1.5) if rng.random() < 0.75 else _logu(rng, 1.5, 4.0)
    om_lo = max(RANGES["omega"][0], math.sqrt(cot * m / a_max) * 1.0001)
    kw["omega"] = _logu(rng, om_lo, RANGES["omega"][1])
    kw["alpha"] = cot * m / kw["omega"] ** 2
    if rng.random() < 0.7:  # a low restitution: impacts accumulate into a Zeno rest
        kw["law"] = "constant"
        kw["e"] = float(rng.uniform(0.02, 0.3))
    if rng.random() < 0.5:
        kw["theta0"] = 0.0
        kw["dtheta0"] = 0.0
    else:
        tip = HALF_PI - _thc(kw)
        kw["theta0"] = float(rng.uniform(-0.5, 0.5) * tip)
        kw["dtheta0"] = float(rng.uniform(-0.3, 0.3))
    _settings(rng, kw, max_periods, lo_periods=min(5, max_periods))
    kw.pop("theta_over", None)
    kw["lyapunov"] = bool(rng.random() < 0.7)
    kw["rest_speed"] = float(_pick(rng, (1e-8, 1e-6, 1e-6, 1e-4, 1e-3)))
    _phase(rng, kw)
    return _fit(kw)


def extreme_cases(n, seed=0, *, max_periods=200):
    """``n`` seeded cases beyond the study's ranges (strong damping, slow and fast forcing,
    orbits through rest: ``EXTREME_CATEGORIES``), in turn.

    Parameters
    ----------
    n : int
        Number of cases.
    seed : int
        Seed.
    max_periods : int
        Bound on the horizon (cut further so that no run exceeds ``MAX_GRID_STEPS`` steps).

    Returns
    -------
    list of Case
        Ids ``x<seed>-<i>``, drawn from their own seeds, so that :func:`cases` keeps its ids.

    Examples
    --------
    >>> from stress import extreme_cases
    >>> [(c.id, c.category) for c in extreme_cases(3)]
    [('x0-0', 'stiff_damping'), ('x0-1', 'wide_omega'), ('x0-2', 'through_rest')]
    """
    out = []
    for i in range(n):
        cat = EXTREME_CATEGORIES[i % len(EXTREME_CATEGORIES)]
        rng = np.random.default_rng([seed, 5, i])
        kw = globals()[f"case_{cat}"](rng, max_periods)
        out.append(Case(id=f"x{seed}-{i}", category=cat, kwargs=kw))
    return out


def case_by_id(case_id, *, max_periods=200, long_periods=20_000):
    """The case ``s<seed>-<i>`` (:func:`cases`) or ``x<seed>-<i>`` (:func:`extreme_cases`),
    drawn again.

    Parameters
    ----------
    case_id : str
        The case's id.
    max_periods, long_periods : int
        The horizon settings of the run that listed it.

    Returns
    -------
    Case

    Examples
    --------
    >>> from stress import case_by_id
    >>> case = case_by_id("s0-1")
    >>> case.category, case.kwargs["periods"], case.kwargs["dtheta0"]
    ('near_zero', 1, -1e-300)
    """
    pre, idx = case_id.split("-")
    kind, seed, i = pre[0], int(pre[1:]), int(idx)
    if kind == "s":
        return cases(i + 1, seed, max_periods=max_periods, long_periods=long_periods)[i]
    if kind == "x":
        return extreme_cases(i + 1, seed, max_periods=max_periods)[i]
    raise ValueError(f"case id must look like s0-29 or x0-29 (got {case_id!r})")


# --------------------------------------------------------------------------- per-run checks


def _bad(x):
    a = np.asarray(x, dtype=float)
    return a.size and not np.all(np.isfinite(a))


def check_status(kw, res):
    if res.status not in KNOWN_STATUS:
        return [f"status {res.status!r}"]
    return []


def check_finite(kw, res):
    probs = []
    for name in ("t", "state", "strobe", "strobe_half", "impacts", "max_error_estimate",
                 "trajectory"):
        v = getattr(res, name)
        if v is not None and _bad(v):
            probs.append(f"non-finite in {name}")
    # an impact with e = 0, and a rest phase, collapse every perturbation: -inf from there on
    collapse = (res.block.restitution == 0.0 and res.n_impacts > 0) or res.n_rest > 0 or \
        res.extra.get("collapses", 0) > 0  # (also a start at rest)
    if res.lyapunov_running is not None:
        lr = np.asarray(res.lyapunov_running)
        if np.any(np.isnan(lr)) or np.any(lr == np.inf) or \
                (np.any(lr == -np.inf) and not collapse):
            probs.append("non-finite in lyapunov_running")
    if "tangent" in res.extra and _bad(res.extra["tangent"]):
        probs.append("non-finite in extra['tangent']")
    if res.lyapunov is not None:
        lam = np.asarray(res.lyapunov)
        if res.status == "rest":
            if not np.all(lam == -np.inf):
                probs.append(f"lyapunov {lam} for a run at rest (expected -inf)")
        elif res.t <= res.window[0]:
            if not np.all(np.isnan(lam)):
                probs.append(f"lyapunov {lam} with an empty window (expected nan)")
        elif _bad(lam) and not (collapse and np.all(lam == -np.inf)):
            probs.append(f"non-finite lyapunov {lam}")
    return probs


def check_time(kw, res):
    probs = []
    T = res.period
    t_end = res.periods * T
    if not (0.0 <= res.t <= t_end * (1 + 1e-12)):
        probs.append(f"t = {res.t!r} outside [0, periods T = {t_end!r}]")
    if res.status == "done" and abs(res.t - t_end) > 1e-12 * t_end:
        probs.append(f"done at t = {res.t!r} != periods T = {t_end!r}")
    k = res.t / T
    ks = res.strobe.shape[0] - 1  # completed periods
    if not (math.floor(k * (1 - 1e-12)) <= ks <= math.floor(k * (1 + 1e-12)) + 0):
        probs.append(f"{ks} periods sampled at t = {k:.17g} T")
    kh = res.strobe_half.shape[0]
    if not (math.floor(k * (1 - 1e-12) + 0.5) <= kh <= math.floor(k * (1 + 1e-12) + 0.5)):
        probs.append(f"{kh} half-period samples at t = {k:.17g} T")
    return probs


def work_bound(kw, res):
    """Upper bound on ``n_rhs`` (see the module docstring)."""
    return 1 + 6 * res.n_steps * res.periods + EVENT_RHS * (res.n_impacts + res.n_rest + 2)


def check_work(kw, res):
    probs = []
    bound = work_bound(kw, res)
    if res.n_rhs > bound:
        probs.append(f"n_rhs = {res.n_rhs} > bound {bound}")
    if res.n_grid_steps > res.n_steps * res.periods:
        probs.append(f"{res.n_grid_steps} grid steps > N periods")
    return probs


def check_bookkeeping(kw, res):
    probs = []
    b = res.block
    max_imp = kw.get("max_impacts") or default_max_impacts(res.periods)
    n = res.n_impacts
    if n > max_imp:
        probs.append(f"{n} impacts > max_impacts {max_imp}")
    if (res.status == "max_impacts") != (n == max_imp):
        probs.append(f"status {res.status!r} with {n} of max_impacts {max_imp}")
    imp = res.impacts
    if imp.shape != (n, 3):
        probs.append(f"impacts has shape {imp.shape} for {n} impacts")
    elif n:
        ti = imp[:, 0]
        if np.any(np.diff(ti) < 0) or ti[0] < 0 or ti[-1] > res.t:
            probs.append("impact times out of order or outside [0, t]")
        with np.errstate(invalid="ignore"):
            jumped = b.restitution * imp[:, 1]
        if not np.array_equal(imp[:, 2], jumped):
            probs.append("theta'+ != e theta'- at an impact")
    th_over = _theta_over(kw)
    for name in ("strobe", "strobe_half"):
        a = getattr(res, name)
        if a.size and np.nanmax(np.abs(a[:, 0])) > th_over * (1 + 1e-12) and \
                abs(kw.get("theta0", 0.0)) < th_over:
            probs.append(f"|theta| > theta_over in {name}")
    if res.status == "overturned" and res.period / res.n_steps <= H_RESOLVED:
        off = overturn_offset(kw, res)
        if off > 1e-9:
            probs.append(f"overturned at |theta| = {abs(res.state[0])!r}, {off:.3g} off the "
                         "threshold")
    if res.status == "rest":
        aw2 = res.forcing.aw2
        rad = max(1.0, math.hypot(res.state[2], res.state[3]))
        if res.state[0] != 0.0 or res.state[1] != 0.0:
            probs.append(f"at rest with state {res.state[:2]}")
        if aw2 * rad > b.cot * (1 + 1e-12):
            probs.append("rest for good although the forcing can lift the block")
    return probs


def overturn_offset(kw, res):
    """How far an overturned run's final ``|theta|`` is from the threshold (or from
    ``|theta0|`` for a run that started beyond it)."""
    th_over = _theta_over(kw)
    th0 = abs(kw.get("theta0", 0.0))
    want = th0 if th0 >= th_over else th_over
    return abs(abs(float(res.state[0])) - want) / max(1.0, want)


def observations(kw, res):
    """Outcomes that are reported, not failed: the impact bound reached; an overturn on a grid
    too coarse to resolve the rocking (``h > H_RESOLVED``) that ended off the threshold."""
    out = []
    if res.status == "max_impacts":
        out.append("impact_bound")
    if res.status == "overturned" and res.period / res.n_steps > H_RESOLVED and \
            overturn_offset(kw, res) > 1e-9:
        out.append("coarse_overturn_off_threshold")
    return out


def longest_stall(res):
    """``(k, t)``: the most impacts recorded at one and the same time ``t``, in a row."""
    t = res.impacts[:, 0]
    if t.size < 2:
        return int(t.size), (float(t[0]) if t.size else math.nan)
    same = np.concatenate(([False], t[1:] == t[:-1], [False]))
    # runs of True in `same`: a run of length L means L + 1 impacts at one instant
    edges = np.flatnonzero(np.diff(same.astype(np.int8)))
    if edges.size == 0:
        return 1, float(t[0])
    starts, ends = edges[::2], edges[1::2]
    i = int(np.argmax(ends - starts))
    return int(ends[i] - starts[i] + 1), float(t[starts[i]])


def check_progress(kw, res):
    """Impacts must advance time: more than ``STALL`` of them at one instant is a stall (the Zeno
    cut-off ``rest_speed > 0`` ends every cascade)."""
    k, t = longest_stall(res)
    if k > STALL:
        return [f"{k} impacts at the one instant t = {t!r} (the run makes no progress)"]
    return []


def check_rest_exponents(kw, res):
    """An orbit through rest within the averaging window has no positive exponent: a rest phase
    erases every perturbation (the exponents are ``-inf``, docs/theory/exponents.md)."""
    if res.lyapunov is None or res.n_rest_window == 0:
        return []
    lam = np.asarray(res.lyapunov)
    if np.any(lam > 0.0):
        return [f"lyapunov {lam} with {res.n_rest_window} rest phases in the window "
                "(expected -inf: a rest phase erases every perturbation)"]
    return []


RUN_CHECK_FUNCS = dict(status=check_status, finite=check_finite, time=check_time,
                       work=check_work, bookkeeping=check_bookkeeping, progress=check_progress,
                       rest_exponents=check_rest_exponents)


def check_run(kw, res):
    """The checks every run must pass (``RUN_CHECKS``; the module docstring says each).

    Parameters
    ----------
    kw : dict
        The run's flat keywords.
    res : Result
        Its result.

    Returns
    -------
    dict of str to list of str
        ``{check: [problems]}``; an empty list passes.

    Examples
    --------
    >>> from stress import check_run, simulate_flat
    >>> kw = dict(hb=1.0, alpha=0.6, omega=1.3, periods=20)
    >>> problems = check_run(kw, simulate_flat(**kw))
    >>> sorted(problems), any(problems.values())
    (['bookkeeping', 'finite', 'progress', 'rest_exponents', 'status', 'time', 'work'], False)
    """
    out = {}
    for name in RUN_CHECKS:
        try:
            out[name] = RUN_CHECK_FUNCS[name](kw, res)
        except Exception as exc:  # a check that cannot even run is a failure of that check
            out[name] = [f"check raised {type(exc).__name__}: {exc}"]
    return out


def refused(exc):
    """Is ``exc`` one of rockjit's documented refusals: a grid too coarse to integrate (a
    ``ValueError`` whose message opens with the parameter's name, ``n_steps``), or a start at or
    past the overturning threshold (``state[0] (theta0) must satisfy |theta0| < theta_over``)?"""
    return isinstance(exc, ValueError) and (
        str(exc).startswith("n_steps") or str(exc).startswith("state[0] (theta0) must satisfy"))


def run_case(case):
    """Run one case and check it.

    A grid too coarse to integrate (``T/N`` beyond rockjit's step limit, an embedded step beyond
    the oscillator's stability, or a step beyond the explicit stability of a large damping) must
    be refused with a ``ValueError`` naming ``n_steps``:
    that is ``(None, {no problems}, message)``. Any other exception is a failure of the
    ``status`` check.

    Parameters
    ----------
    case : Case
        The case.

    Returns
    -------
    result : Result or None
        The run (``None`` when it raised).
    problems : dict of str to list of str
        :func:`check_run`'s problems.
    refusal : str or None
        The message of a documented refusal.

    Examples
    --------
    >>> from stress import Case, run_case
    >>> coarse = Case("demo", "random", dict(hb=1.0, alpha=0.6, omega=0.05, n_steps=8))
    >>> result, problems, refusal = run_case(coarse)
    >>> result is None, refusal.startswith("n_steps must be >=")
    (True, True)
    """
    try:
        res = simulate_flat(**case.kwargs)
    except Exception as exc:
        probs = {k: [] for k in RUN_CHECKS}
        if refused(exc):
            return None, probs, str(exc)
        probs["status"] = [f"raised {type(exc).__name__}: {exc}"]
        return None, probs, None
    return res, check_run(case.kwargs, res), None


# --------------------------------------------------------------------------- exact checks


def energy_cases(n, seed=0, *, max_periods=50, h_max=0.025, t_max=300.0):
    """Unforced elastic rocking without damping, at a resolved step ``h <= h_max``."""
    out = []
    for i in range(n):
        rng = np.random.default_rng([seed, 1, i])
        hb = _logu(rng, *RANGES["hb"])
        omega = _logu(rng, *RANGES["omega"])
        thc = math.atan(hb)
        T = 2.0 * math.pi / omega
        n_steps = max(8, 2 * math.ceil(T / (2 * h_max)))
        periods = max(1, min(max_periods, int(t_max / T)))
        # mostly below the energy of the upright position (bounded rocking), sometimes above
        frac = float(rng.uniform(0.0, 1.0 if rng.random() < 0.8 else 1.2))
        th0 = float(rng.choice((-1.0, 1.0)) * frac * (HALF_PI - thc))
        dth0 = float(rng.uniform(-0.3, 0.3))
        kw = dict(hb=hb, alpha=0.0, omega=omega, law="constant", e=1.0, xi=0.0, theta0=th0,
                  dtheta0=dth0, phase=float(rng.uniform(0, 2 * math.pi)), periods=periods,
                  n_steps=n_steps, record_stride=max(1, n_steps // 32))
        if rng.random() < 0.2:  # the embedded kernel is a separate compilation: check it too
            phi = kw.pop("phase")
            kw.update(forcing="embedded", r0=math.sin(phi), s0=math.cos(phi))
        out.append(Case(id=f"e{seed}-{i}", category="energy", kwargs=kw))
    return out


def energy(thc, theta, dtheta):
    """``theta'^2 / 2 + 3/4 sin(thc + |theta|)``, conserved for ``e = 1, xi = 0, alpha = 0``."""
    return 0.5 * np.asarray(dtheta) ** 2 + 0.75 * np.sin(thc + np.abs(theta))


def check_energy(kw, res):
    """Largest energy error over the trajectory, samples, final state and impacts."""
    b = res.block
    if not (b.restitution == 1.0 and b.xi == 0.0 and res.forcing.alpha == 0.0):
        return ["not an energy-conserving case"]
    thc = b.thc
    e0 = float(energy(thc, kw["theta0"], kw["dtheta0"]))
    pts = [res.state[None, :2], res.strobe[:, :2], res.strobe_half[:, :2]]
    if res.trajectory is not None:
        pts.append(res.trajectory[:, 1:3])
    x = np.concatenate(pts)
    es = [energy(thc, x[:, 0], x[:, 1])]
    if res.n_impacts:
        es += [energy(thc, 0.0, res.impacts[:, 1]), energy(thc, 0.0, res.impacts[:, 2])]
    err = float(np.max(np.abs(np.concatenate(es) - e0)))
    tol = 1e-10 + 1e-12 * res.n_impacts
    if not err <= tol:  # a NaN fails too
        return [f"energy error {err:.3g} > {tol:.3g}"]
    return []


def mirror_cases(n, seed=0, *, max_periods=200, embedded=True):
    """Pairs ``(case, mirrored case)``; with ``embedded`` the 4-D embedding, else the closed
    form with the phase moved by pi, followed by the two twins (phase moved by +-``TWIN``)."""
    out = []
    for i in range(n):
        rng = np.random.default_rng([seed, 2 if embedded else 3, i])
        cat = CATEGORIES[i % len(CATEGORIES)]
        kw = case_long_horizon(rng, max_periods, max_periods) if cat == "long_horizon" else \
            globals()[f"case_{cat}"](rng, max_periods)
        # keep the case's own phase (a grazing dip needs its push), drop its forcing
        if "phase" in kw:
            phi = kw["phase"]
        else:
            phi = math.atan2(kw["r0"], kw["s0"])
        for k in ("phase", "r0", "s0", "forcing", "record_stride"):
            kw.pop(k, None)
        a = dict(kw)
        b = dict(kw, theta0=-kw["theta0"], dtheta0=-kw["dtheta0"])
        if embedded:
            rad = 1.0 if rng.random() < 0.7 else _logu(rng, 0.3, 2.0)
            r0, s0 = rad * math.sin(phi), rad * math.cos(phi)
            a.update(forcing="embedded", r0=r0, s0=s0)
            b.update(forcing="embedded", r0=-r0, s0=-s0)
            group = (a, b)
        else:
            a["phase"] = phi
            b["phase"] = phi + math.pi
            group = (a, b, dict(a, phase=phi + TWIN), dict(a, phase=phi - TWIN))
        out.append(Case(id=f"m{'e' if embedded else 'c'}{seed}-{i}", category=cat,
                        kwargs=dict(group=group)))
    return out


def check_mirror_exact(a, b):
    """The mirrored run is the negated run, bit for bit (embedded forcing). A NaN matches a NaN
    here: non-finite output is the ``finite`` check's business."""
    probs = []
    if a.status != b.status or not _same(a.t, b.t) or a.n_impacts != b.n_impacts:
        probs.append(f"status/t/impacts {a.status}/{a.t!r}/{a.n_impacts} vs "
                     f"{b.status}/{b.t!r}/{b.n_impacts}")
        return probs
    for name in ("state", "strobe", "strobe_half"):
        x, y = getattr(a, name), getattr(b, name)
        if x.shape != y.shape or not _same(x, -y):
            probs.append(f"{name} not mirrored exactly")
    if not (_same(a.impacts[:, 0], b.impacts[:, 0]) and _same(a.impacts[:, 1:],
                                                                -b.impacts[:, 1:])):
        probs.append("impacts not mirrored exactly")
    return probs


def _same(x, y):
    return np.array_equal(np.asarray(x, dtype=float), np.asarray(y, dtype=float),
                          equal_nan=True)


#: mirror_closed: the twins move the phase by +-TWIN, a hundred times more than the rounding of
#: phase + pi; a stretch of the run is compared when both twins agree with the original to PRED
#: there, and the mirrored run must then agree to MIRROR_TOL (relative to the orbit's size for
#: states, to max(1, t) for times).
TWIN = 1e-13
PRED = 1e-8
MIRROR_TOL = 1e-7


def _trace(res, sign=1.0):
    """The comparable outputs of a run: impacts ``(t, theta'-)``, samples, end."""
    return dict(status=res.status, n_imp=res.n_impacts, t=res.t,
                imp_t=res.impacts[:, 0], imp_v=sign * res.impacts[:, 1],
                strobe=sign * res.strobe[:, :2], end=sign * res.state[:2])


def _diff(p, q, scale, t_scale, k=None):
    """Largest relative difference of traces p and q; with ``k``, only up to t = kT (the
    samples 0..k and the impacts before), else the whole run (then status and impact counts must
    agree, or the difference is inf)."""
    if k is None:
        if p["status"] != q["status"] or p["n_imp"] != q["n_imp"] or \
                p["strobe"].shape != q["strobe"].shape:
            return math.inf
        d = [abs(p["t"] - q["t"]) / t_scale, np.max(np.abs(p["end"] - q["end"])) / scale]
        ti, tj, vi, vj = p["imp_t"], q["imp_t"], p["imp_v"], q["imp_v"]
        si, sj = p["strobe"], q["strobe"]
    else:
        si, sj = p["strobe"][:k + 1], q["strobe"][:k + 1]
        if si.shape != sj.shape:
            return math.inf
        return float(np.max(np.abs(si - sj), initial=0.0)) / scale
    if ti.size:
        d += [np.max(np.abs(ti - tj)) / t_scale, np.max(np.abs(vi - vj)) / scale]
    d.append(float(np.max(np.abs(si - sj), initial=0.0)) / scale)
    d = float(max(d))
    return d if math.isfinite(d) else math.inf


def check_mirror_closed(a, b, *twins):
    """``b`` (mirrored: ``-theta0, -theta0'``, phase + pi) is ``-a`` wherever the twins (phase
    +-``TWIN``) show that ``a`` is determined to better than ``PRED``.

    If the twins agree with ``a`` over the whole run (status, impact count, every impact, sample
    and the end), the whole mirrored run is compared; otherwise the stroboscopic samples up to
    the last period where the twins still agree. Returns ``(problems, compared)`` where
    ``compared`` is ``"whole"`` or the number of periods compared.
    """
    pa, pb = _trace(a), _trace(b, -1.0)
    pcs = [_trace(c) for c in twins]
    parts = [np.abs(pa["strobe"]).ravel(), np.abs(pa["end"]), np.abs(pa["imp_v"])]
    scale = max(float(np.max(np.concatenate(parts), initial=0.0)), 1e-300)
    t_scale = max(1.0, a.t)
    probs = []
    dt = max(_diff(pa, pc, scale, t_scale) for pc in pcs)
    if dt <= PRED:
        d = _diff(pa, pb, scale, t_scale)
        if not d <= MIRROR_TOL:
            probs.append(f"mirrored run differs by {d:.3g} (relative; the twins by {dt:.3g}): "
                         f"{a.status}/{a.n_impacts} vs {b.status}/{b.n_impacts}")
        return probs, "whole"
    n = min(p["strobe"].shape[0] for p in [pa] + pcs)
    k = 0
    while k + 1 < n and max(_diff(pa, pc, scale, t_scale, k + 1) for pc in pcs) <= PRED:
        k += 1
    d = _diff(pa, pb, scale, t_scale, k)
    if not d <= MIRROR_TOL:
        probs.append(f"mirrored samples differ by {d:.3g} (relative) over {k} periods")
    return probs, k


def threads_cases(n, seed=0, *, max_periods=100, grid=8):
    """Basin and sweep settings over the same ranges, for 1 against 2 threads."""
    out = []
    for i in range(n):
        rng = np.random.default_rng([seed, 4, i])
        kw = _params(rng)
        kw["periods"] = max(2, int(_logu(rng, 2, max_periods)))
        kw["lyapunov"] = bool(rng.random() < 0.5)
        kw["early_stop"] = bool(rng.random() < 0.7)
        if rng.random() < 0.3:
            kw["n_steps"] = int(_pick(rng, (16, 64, 256)))
        kw["kind"] = "basin" if i % 2 == 0 else "sweep"
        kw["grid"] = grid
        out.append(Case(id=f"t{seed}-{i}", category="threads", kwargs=kw))
    return out


def run_threads_case(case, threads):
    """The basin or sweep of ``case`` with ``threads`` threads (``None`` if its grid is refused
    as too coarse)."""
    try:
        return _run_threads_case(case, threads)
    except ValueError as exc:
        if refused(exc):
            return None
        raise


def _run_threads_case(case, threads):
    kw = dict(case.kwargs)
    kind = kw.pop("kind")
    grid = kw.pop("grid")
    classification = Classification(early_stop=kw.pop("early_stop", True))
    alpha = kw.pop("alpha")
    block, forcing, _, integration, rest = objects(kw)
    execution = Execution(threads=threads)
    if kind == "basin":
        return rockjit.basin(block, forcing.replace(alpha=alpha), Lattice(grid),
                             integration=integration, classification=classification,
                             execution=execution, **rest)
    alphas = np.linspace(0.0, max(alpha, 0.05), grid * grid)
    return rockjit.sweep(block, forcing, alphas, integration=integration,
                         classification=classification, execution=execution, **rest)


def check_threads(one, two):
    probs = []
    names = ("label", "period", "t_end", "lambda_max") + \
        (("strobe", "impact_section") if hasattr(one, "strobe") else ())
    for name in names:
        x, y = getattr(one, name), getattr(two, name)
        if x is None and y is None:
            continue
        if x is None or y is None or not np.array_equal(x, y, equal_nan=True):
            probs.append(f"{name} differs between 1 and 2 threads")
    return probs


def threads_available():
    import numba
    return numba.config.NUMBA_NUM_THREADS >= 2
