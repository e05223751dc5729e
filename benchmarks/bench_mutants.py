"""Mutation testing: small deliberate bugs that the independent tests must catch.

Each *mutant* replaces one exact piece of text, found exactly once, in one source file of the
package: in the engine (the vector field, its Jacobian, the jump map and the saltation matrix,
rest and uplift, the Dormand–Prince tableau, the event location, the tangent dynamics and
exponents, the classification) and in the analyses built on it (the fragility fits and
capacities, the ground-motion path's stopping rule, the continuation of periodic orbits and its
bifurcations, the basin measures, the explorer). For each, the package and its tests are
copied to a fresh temporary folder, the mutation is applied there (the working tree is never
touched), and a chosen subset of the tests that check rockjit against something independent
of it (``tests/physics.py``, the ``spec`` fixture of ``tests/conftest.py``, the slow
classifier of ``tests/grids/test_grids.py``, closed forms, libm, the order conditions, the scipy
path, brute-force references, Monte-Carlo calibration) runs in a fresh process with its own
numba cache (``NUMBA_CACHE_DIR`` inside the copy: rockjit caches compiled code with
``cache=True``, so a shared cache could serve the unmutated kernels). A mutant is *caught* when
that run fails, and *survived* when it passes: a survivor is a weak test, to be strengthened
against an independent reference.

Before the mutants, the same test subsets run on an unmutated copy (the *baseline*), which must
pass: otherwise every mutant would look caught.

    python benchmarks/bench_mutants.py           # every mutant (~25 min on 2 cores)
    python benchmarks/bench_mutants.py --quick   # smoke: the baseline and three cheap mutants
    python benchmarks/bench_mutants.py --only housner-restitution saltation-entry
    python benchmarks/bench_mutants.py --areas continuation integrity   # those areas' mutants

Writes mutants.{md,csv,json} to benchmarks/results/ (benchmarks/results/quick/ with --quick,
or --out DIR). A run of some of the mutants (``--only``, ``--areas``) into a folder that holds
an earlier run's mutants.json keeps that run's rows for the others (the same mutant, text for
text), so that the page lists every mutant; the page says which rows ran when. Exits 1 if a
mutant survived or the baseline failed.
"""

from __future__ import annotations

import shutil
import subprocess
import sys
import tempfile
import time
from dataclasses import dataclass
from pathlib import Path

import _common as H

#: What a copy holds: the package, its tests and the project file (nothing else is needed).
COPY = ("rockjit", "tests", "pyproject.toml")
#: Wall-clock limit of one mutant's test run (a mutant that hangs counts as caught, marked).
TIMEOUT_S = 300

# the test subsets (pytest node ids); each compiled-run subset costs one cold compile (~25 s)
PI = "tests/test_physics_independent.py::"
RESTITUTION = [PI + "test_restitution_matches_the_published_values",
               PI + "test_restitution_laws_match_the_papers_formulas"]
ACCEL = [PI + "test_accel_matches_the_corner_equations"]
JAC = [PI + "test_accel_jac_matches_partials_and_finite_differences"]
SALTATION = [PI + "test_saltation_matches_muellers_formula"]
UPLIFT = [PI + "test_uplift_time_matches_a_brute_force_scan"]
RUNS = [PI + "test_run_matches_the_independent_integrator"]
RUN_SYMMETRIC = [RUNS[0] + "[symmetric-compiled]"]  # one compiled run: the cheapest check
FLOQUET = [PI + "test_floquet_multipliers_match_the_finite_difference_monodromy[p1-symmetric]"]
TI = "tests/_engine/test_integrate.py::"


@dataclass(frozen=True)
class Mutant:
    """One deliberate bug: in ``file``, the text ``old`` (exactly once) becomes ``new``."""

    name: str
    area: str
    file: str
    old: str
    new: str
    breaks: str
    tests: tuple


def _m(name, area, file, old, new, breaks, tests):
    return Mutant(name, area, file, old, new, breaks, tuple(tests))


MODEL = "rockjit/model.py"
HARMONIC = "rockjit/plugs/harmonic.py"
HOUSNER = "rockjit/laws/housner.py"
MAO = "rockjit/laws/mao.py"
SPEED = "rockjit/laws/speed.py"
INTEG = "rockjit/_engine/integrate.py"
TABLEAU = "rockjit/_engine/tableau.py"
EVENTS = "rockjit/_engine/events.py"
LAYOUT = "rockjit/_engine/layout.py"
STEP = "rockjit/_engine/step.py"
KERNEL = "rockjit/_engine/kernel.py"
CLASSIFY = "rockjit/_engine/classify.py"

MUTANTS = [
    # ---- restitution laws
    _m("housner-restitution", "restitution", HOUSNER,
       "return 1.0 - 1.5 * np.cos(thc) ** 2", "return 1.0 - 1.4 * np.cos(thc) ** 2",
       "Housner's coefficient 1 - 1.5 cos^2 becomes 1 - 1.4 cos^2", RESTITUTION),
    _m("mao-restitution", "restitution", MAO,
       "3.0 * t**4 * (0.5 * np.pi - thc)", "3.0 * t**3 * (0.5 * np.pi - thc)",
       "a power of tan(thc) in Mao's numerator (equal at hb = 1 only)", RESTITUTION),
    # ---- vector field
    _m("gravity-sign", "vector field", MODEL,
       "return fma(f, a1, -a2), fma(f, a2, a1)", "return fma(f, a1, a2), fma(f, a2, a1)",
       "the sign of the gravity term of the corner equation", ACCEL),
    _m("damping-sign", "vector field", MODEL,
       "return fma(-damping_rate(xi), dtheta, fma(P, c, Q * s))",
       "return fma(damping_rate(xi), dtheta, fma(P, c, Q * s))",
       "damping pushes instead of resisting", ACCEL),
    _m("damping-near", "vector field", MODEL,
       "return fma(-damping_rate(xi), dtheta, fma(P, cn, (Q * d) * sn))",
       "return fma(-0.7 * xi, dtheta, fma(P, cn, (Q * d) * sn))",
       "the damping factor 3/4 becomes 0.7 on the integrator's fast path only", RUN_SYMMETRIC),
    _m("sine-polynomial", "vector field", MODEL,
       "1.0, -0.1666666666666666, 0.008333333333332672,",
       "1.0, -0.1666666666666666, 0.00833333333333,",
       "a coefficient of the sine polynomial, rounded at 1e-14",
       ["tests/test_model.py::test_sincos_polynomial_matches_libm_on_its_range"]),
    _m("oscillator", "vector field", HARMONIC,
       "return r + omega * s - r * q, s - omega * r - s * q",
       "return r + omega * s - r * q, s - omega * r - r * q",
       "the forcing oscillator's radial term of s",
       ["tests/plugs/test_harmonic.py::test_oscillator_on_the_circle_is_the_closed_form"]),
    # ---- Jacobian
    _m("jacobian-slope", "Jacobian", MODEL,
       "return fma(Q, c, -(P * s))", "return fma(Q, c, P * s)",
       "d theta''/d theta: a sign in the slope", JAC),
    _m("jacobian-forcing", "Jacobian", MODEL,
       "0.75 * fma(sthc, c, side * cthc * s)", "0.75 * fma(sthc, c, -side * cthc * s)",
       "d theta''/d f: a sign", JAC),
    # ---- jump map, saltation
    _m("jump-coefficient", "jump map", MODEL,
       "return e * dtheta_minus", "return math.sqrt(e) * dtheta_minus",
       "the velocity scaled by sqrt(e), an energy coefficient taken for a velocity one",
       SALTATION),
    _m("jump-side-flip", "jump map", INTEG,
       "    side = -side\n    impacts = out.impacts", "    impacts = out.impacts",
       "the block stays on its corner after an impact", RUN_SYMMETRIC),
    _m("saltation-entry", "saltation", MODEL,
       "return (f_plus - e_slope * f_minus) / dtheta_minus",
       "return (f_plus - f_minus) / dtheta_minus",
       "Müller's (F+ - e F-) / theta'- loses its e", SALTATION),
    _m("speed-law-slope", "saltation", SPEED,
       "return e * q, e * q * q", "return e * q, e * q",
       "the speed-dependent law's jump slope d(e(v) v)/dv taken as e(v)",
       [PI + "test_saltation_of_a_law_that_depends_on_the_impact_matches_muellers_formula",
        PI + "test_floquet_multipliers_match_the_finite_difference_monodromy[p1-speed]"]),
    _m("saltation-applied", "saltation", INTEG,
       "y[NS + 2 * c + 1] = s10 * v0 + e_slope * v1",
       "y[NS + 2 * c + 1] = s10 * v1 + e_slope * v1",
       "the saltation matrix applied to the wrong tangent component", FLOQUET),
    # ---- rest and uplift
    _m("rest-cutoff", "rest/uplift", INTEG,
       "if abs(dth_p) < par[P_REST] or dth_p == 0.0:",
       "if abs(dth_m) < par[P_REST] or dth_p == 0.0:",
       "the Zeno cut-off compares the incoming speed, not the outgoing one",
       [RUNS[0] + "[rest-compiled]", RUNS[0] + "[uplift-compiled]"]),
    _m("uplift-time", "rest/uplift", HARMONIC,
       "return t + (math.pi - u + a) / omega", "return t + (math.pi - u - a) / omega",
       "the next uplift instant after the forcing's crest", UPLIFT),
    _m("uplift-side", "rest/uplift", INTEG,
       "side = 1 if forcing_now(EMBED4, t_up, y, par) > 0.0 else -1",
       "side = 1 if forcing_now(EMBED4, t_up, y, par) < 0.0 else -1",
       "a lifted block rocks onto the wrong corner", [RUNS[0] + "[uplift-compiled]"]),
    _m("uplift-threshold", "rest/uplift", KERNEL,
       "par[ig.P_COT] = block.cot", "par[ig.P_COT] = 1.01 * block.cot",
       "the uplift threshold cot(thc) one per cent high", [RUNS[0] + "[uplift-compiled]"]),
    _m("theta-over", "rest/uplift", KERNEL,
       "par[ig.P_THOVER] = integration.theta_over",
       "par[ig.P_THOVER] = 0.99 * integration.theta_over",
       "the overturning threshold one per cent low",
       [TI + "test_overturn_threshold_is_a_parameter"]),
    # ---- integrator
    _m("tableau-b1", "integrator", TABLEAU,
       "((35, 384), (0, 1),", "((35, 385), (0, 1),",
       "the first fifth-order weight of Dormand–Prince", RUN_SYMMETRIC),
    _m("tableau-c3", "integrator", TABLEAU,
       "Fraction(3, 10), Fraction(4, 5), Fraction(8, 9),",
       "Fraction(3, 10), Fraction(8001, 10000), Fraction(8, 9),",
       "the fourth stage's time c_3 = 4/5 off by 1e-4", RUN_SYMMETRIC),
    _m("forcing-jerk", "integrator", INTEG,
       "ftab[j, FT_DF0] = harmonic.slope(aw3, c0)", "ftab[j, FT_DF0] = harmonic.slope(aw3, s0)",
       "the forcing's time derivative at a step's start (the event interpolant's data)",
       RUN_SYMMETRIC),
    # ---- event location
    _m("event-newton-tol", "event location", EVENTS,
       "poly6(g1, d2, d3, d4, d5, d6, d7, x), a, b, 1e-9)",
       "poly6(g1, d2, d3, d4, d5, d6, d7, x), a, b, 1e-2)",
       "the Newton iteration on the interpolant stops at 1e-2 of a step, not 1e-9",
       [TI + "test_event_on_the_interpolant_against_dop853"]),
    _m("event-trust", "event location", LAYOUT,
       "LOCATE_TOL = DELTA_EULER  # see locate_interp", "LOCATE_TOL = 1e-2  # see locate_interp",
       "the interpolant trusted however large its error estimate",
       [TI + "test_dip_through_zero_within_one_step_is_found"]),
    _m("event-grazing", "event location", EVENTS,
       "if g0 > 0.0 and d0 < 0.0 and d1 > 0.0:", "if g0 > 0.0 and d0 < 0.0 and d1 > 1e300:",
       "a dip through theta = 0 within one step goes unseen",
       [TI + "test_dip_through_zero_within_one_step_is_found"]),
    # ---- tangent dynamics, exponents
    _m("tangent-damping", "exponents", STEP,
       "jb = -damping_rate(par[P_XI])", "jb = 0.0 * damping_rate(par[P_XI])",
       "the tangent dynamics forget the damping", FLOQUET),
    _m("qr-log", "exponents", INTEG,
       "lam_sum[1] += l2", "lam_sum[1] += l1",
       "the second exponent accumulates the first one's stretch",
       ["tests/_engine/test_lyapunov.py::test_running_exponents_satisfy_the_identity_at_every_period"]),
    # ---- classification
    _m("period-tolerance", "classification", CLASSIFY,
       "lim = tol * orbit_scale(strobe, half, k0, k1) + 1e-300",
       "lim = 1e5 * tol * orbit_scale(strobe, half, k0, k1) + 1e-300",
       "the period test's tolerance 1e5 times too loose",
       ["tests/grids/test_grids.py::test_a_period_two_orbit_just_past_its_doubling"]),
    _m("symmetry-test", "classification", CLASSIFY,
       "if abs(half[j, c] + strobe[j, c]) > lim:", "if abs(half[j, c] - strobe[j, c]) > lim:",
       "the mirror symmetry x(T/2) = -x(0) tested as x(T/2) = x(0)",
       ["tests/grids/test_grids.py::test_gallery_labels[symmetric]"]),
]

FITTING = "rockjit/ground/fitting.py"
FRAGILITY = "rockjit/ground/fragility.py"
TRANSIENT = "rockjit/_engine/transient.py"
ARCLENGTH = "rockjit/orbits/arclength.py"
BIFURCATIONS = "rockjit/orbits/bifurcations.py"
MEASURES = "rockjit/measures.py"
EXPLORER = "rockjit/explorer/requests.py"
TO = "tests/orbits/test_orbits.py::"
TM = "tests/test_measures.py::"
TF = "tests/ground/test_ground_fragility.py::"

MUTANTS += [
    # ---- ground motions: fits, capacities, the compiled path's stopping rule
    _m("fit-se-beta", "fitting", FITTING,
       "beta / math.sqrt(2 * n),", "beta / math.sqrt(n),",
       "the capacity fit's standard error of beta 41 % too large (beta / sqrt(n))",
       [TF + "test_capacity_fit_standard_errors_and_intervals_by_monte_carlo"]),
    _m("fit-beta-ci", "fitting", FITTING,
       "math.sqrt(ss / float(chi2.ppf(alpha / 2, n - 1))))",
       "math.sqrt(ss / float(chi2.ppf(alpha / 2, n))))",
       "the upper end of beta's interval from chi-square with n degrees of freedom, not n - 1",
       [TF + "test_capacity_fit_standard_errors_and_intervals_by_monte_carlo"]),
    _m("capacity-below-list", "fragility", FRAGILITY,
       "if np.argmax(o) > 0 else np.nan", "if np.argmax(o) >= 0 else np.nan",
       "a record that overturns at the lowest intensity gets it as its capacity, not 'below "
       "the list'", [TF + "test_capacity_below_the_list"]),
    _m("transient-decided-mirror", "transient", TRANSIENT,
       "free_rocking_decided(th, v, max_th, thc, th_top)",
       "free_rocking_decided(max(th, 0.0), v, max_th, thc, th_top)",
       "the compiled path's stopping rule takes a block on the theta < 0 side for upright",
       ["tests/ground/test_ground_stopping.py::test_the_compiled_path_decides_as_the_full_run_ends"]),
    # ---- periodic orbits: continuation and bifurcations
    _m("arclength-step-bound", "continuation", ARCLENGTH,
       "ds = min(1.3 * ds, self.ds_max)", "ds = min(1.3 * ds, 1.1 * self.ds_max)",
       "the continuation's step grows to 1.1 ds_max",
       [TO + "test_no_step_is_longer_than_ds_max"]),
    _m("arclength-step-unbounded", "continuation", ARCLENGTH,
       "ds = min(1.3 * ds, self.ds_max)", "ds = 1.3 * ds",
       "the continuation's step grows without bound",
       [TO + "test_no_step_moves_the_parameter_by_more_than_ds_max[study]"]),
    _m("bifurcation-twice", "continuation", ARCLENGTH,
       "            if self.reported(bf):\n                continue\n", "",
       "a bifurcation met again on a branch that retraces another is reported twice",
       [TO + "test_no_bifurcation_is_reported_twice[coarse]"]),
    _m("pitchfork-or-fold", "bifurcations", BIFURCATIONS,
       "and jb is not None and ja * jb < 0)", "and jb is not None and ja * jb > 0)",
       "a symmetric orbit's multiplier +1 classed as a fold where the half map's is -1 "
       "(a symmetry-breaking pitchfork), and the reverse",
       [TO + "test_symmetry_breaking_near_078"]),
    _m("bifurcation-tolerance", "bifurcations", BIFURCATIONS,
       "xtol = min(1e-6, max(1e-13, 0.1 * self.param_tol",
       "xtol = min(1e-3, max(1e-13, 1e5 * self.param_tol",
       "Brent's method on the test function stops at 1e-3 of the chord, not 1e-8 in alpha",
       [TO + "test_located_to_1e8_by_independent_shooting"]),
    # ---- basin measures
    _m("lim-truncation", "integrity", MEASURES,
       "    i = np.clip(np.rint((cycle[:, 0] - th[0]) / h0).astype(int), 0, th.size - 1)\n"
       "    j = np.clip(np.rint((cycle[:, 1] - dth[0]) / h1).astype(int), 0, dth.size - 1)",
       "    i = np.clip(((cycle[:, 0] - th[0]) / h0).astype(int), 0, th.size - 1)\n"
       "    j = np.clip(((cycle[:, 1] - dth[0]) / h1).astype(int), 0, dth.size - 1)",
       "the local integrity measure takes the node below a cycle point, not the nearest",
       [TM + "test_lim_matches_a_brute_force_reference_between_nodes"]),
    _m("if-spacings", "integrity", MEASURES,
       "np.minimum(_edt(safe, (h0, h1)), border)", "np.minimum(_edt(safe, (h1, h0)), border)",
       "the integrity factor's distances with the two grid spacings swapped",
       [TM + "test_integrity_factor_matches_a_brute_force_search"]),
    _m("entropy-boundary", "entropy", MEASURES,
       "boundary = n_outcomes > 1", "boundary = n_outcomes > 0",
       "every box counted as a boundary box in the boundary basin entropy",
       [TM + "test_entropy_matches_a_slow_reference_on_random_maps",
        TM + "test_half_plane_entropy_counts_the_straddling_boxes"]),
    # ---- the explorer
    _m("explorer-nearest-cell", "explorer", EXPLORER,
       "k = int(round((v - axis[0]) / step))", "k = int((v - axis[0]) / step)",
       "a click picks the lattice point below it, not the nearest",
       ["tests/explorer/test_explore.py::test_nearest_cell"]),
]

QUICK_NAMES = ("housner-restitution", "saltation-entry", "uplift-time")


# --------------------------------------------------------------------------- the experiment

def make_copy(dest: Path):
    """The package, its tests and pyproject.toml under ``dest`` (no caches, no results)."""
    ignore = shutil.ignore_patterns("__pycache__", "*.pyc", ".pytest_cache")
    for name in COPY:
        src = H.ROOT / name
        if src.is_dir():
            shutil.copytree(src, dest / name, ignore=ignore)
        else:
            shutil.copy2(src, dest / name)


def check_mutant(m: Mutant):
    """The mutant's old text occurs exactly once in its file, and differs from the new one."""
    text = (H.ROOT / m.file).read_text(encoding="utf-8")
    n = text.count(m.old)
    if n != 1 or m.old == m.new:
        raise SystemExit(f"mutant {m.name}: its text occurs {n} times in {m.file} (must be 1)")


def run_tests(tests, mutant=None):
    """Run ``tests`` in a fresh copy, with ``mutant`` applied. Returns ``(outcome, seconds,
    tail)``: outcome "passed", "failed", "timeout" or "error" (pytest could not run them)."""
    with tempfile.TemporaryDirectory(prefix="rockjit-mutant-") as tmp:
        tmp = Path(tmp)
        make_copy(tmp)
        if mutant is not None:
            path = tmp / mutant.file
            text = path.read_text(encoding="utf-8")
            assert text.count(mutant.old) == 1
            path.write_text(text.replace(mutant.old, mutant.new), encoding="utf-8")
        env = H.child_env(NUMBA_CACHE_DIR=str(tmp / "numba-cache"), MPLBACKEND="Agg")
        env["PYTHONPATH"] = str(tmp)  # the copy's rockjit, never the working tree's
        cmd = [sys.executable, "-m", "pytest", "-x", "-q", "-p", "no:cacheprovider", *tests]
        t0 = time.perf_counter()
        try:
            proc = subprocess.run(cmd, cwd=tmp, env=env, capture_output=True, text=True,
                                  timeout=TIMEOUT_S)
        except subprocess.TimeoutExpired:
            return "timeout", time.perf_counter() - t0, ""
        dt = time.perf_counter() - t0
        tail = (proc.stdout + proc.stderr)[-3000:]
        outcome = {0: "passed", 1: "failed"}.get(proc.returncode, "error")
        return outcome, dt, tail


def first_failure(tail: str) -> str:
    """The first ``FAILED``/``ERROR`` line of pytest's summary, shortened."""
    for line in tail.splitlines():
        if line.startswith(("FAILED", "ERROR")):
            return line[:160]
    return ""


def is_caught(row) -> bool:
    """The tests failed: an assertion ("caught"), a hang ("caught (timeout)") or a crash
    ("caught (error)")."""
    return row["outcome"].startswith("caught")


# --------------------------------------------------------------------------- the report

def carried_rows(path: Path, chosen):
    """The rows of an earlier run's ``mutants.json`` for the mutants not run now, each marked
    with what it ran on and when (``ran``): only a mutant still defined with the same file and
    text, in the order of :data:`MUTANTS`. Empty when there is no such file."""
    if not path.is_file():
        return []
    import json
    old = json.loads(path.read_text(encoding="utf-8"))
    env = old.get("environment", {})
    then = H.env_line(env) if env else "an earlier run"
    by_name = {r["name"]: r for r in old.get("mutants", [])}
    ran = {m.name for m in chosen}
    out = []
    for m in MUTANTS:
        r = by_name.get(m.name)
        if m.name in ran or r is None or (r["file"], r["old"], r["new"]) != (m.file, m.old,
                                                                            m.new):
            continue
        out.append(dict(r, ran=r.get("ran", then)))
    return out


def in_order(rows):
    """``rows`` in the order of :data:`MUTANTS`."""
    rank = {m.name: k for k, m in enumerate(MUTANTS)}
    return sorted(rows, key=lambda r: rank[r["name"]])


def markdown(rows, baseline, total_s, env):
    caught = sum(is_caught(r) for r in rows)
    stamp = H.env_line(env)
    now = [r for r in rows if r["ran"] == stamp]
    earlier = sorted({r["ran"] for r in rows} - {stamp})
    kept = "; ".join(f"{sum(r['ran'] == e for r in rows)} of them {e[0].lower()}{e[1:]}"
                     .rstrip(".") for e in earlier)
    body = [[r["name"], r["area"], f"`{r['file']}`", r["breaks"],
             ", ".join(f"`{t.split('/')[-1]}`" for t in r["tests"]),
             r["outcome"] + ("" if is_caught(r) else " ✗"), f"{r['seconds']:.1f}"]
            for r in rows]
    return "".join([
        "#### Mutants: deliberate bugs the independent tests must catch\n",
        "Each row is one small bug put into a fresh copy of the package (never the working "
        "tree), and the subset of the independent tests that must catch it (rockjit against "
        "tests/physics.py, the `spec` fixture's solve_ivp integration, the slow classifier, "
        "closed forms, libm, the order conditions, the scipy path, brute-force references "
        "and Monte-Carlo calibration), run with a fresh numba cache. *caught*: "
        "the tests failed; *survived* ✗: they passed, a weak test.\n\n",
        H.md_table(["mutant", "area", "file", "what it breaks", "tests", "outcome", "s"], body),
        f"\n**{caught} of {len(rows)} caught**; baseline (every subset of this run, "
        f"unmutated): {baseline['outcome']} in {baseline['seconds']:.1f} s; this run "
        f"{total_s / 60:.1f} min for {len(now)} mutant{'s' * (len(now) != 1)} (each row's "
        "time includes a cold compile of the kernels its tests need).",
        (f" The other {len(rows) - len(now)} rows are kept from earlier runs: {kept}."
         if earlier else ""), "\n",
        "\n`python benchmarks/bench_mutants.py` (one mutant: `--only NAME`; some areas: "
        "`--areas AREA ...`).\n",
        f"\n{H.env_line(env)}\n"])


def options(p):
    p.add_argument("--only", nargs="+", metavar="NAME", default=None,
                   help="run only these mutants (names from the table)")
    p.add_argument("--areas", nargs="+", metavar="AREA", default=None,
                   help="run only the mutants of these areas (the table's area column)")


def main(argv=None):
    b = H.Bench(__doc__, argv, options=options)
    for m in MUTANTS:
        check_mutant(m)
    names = [m.name for m in MUTANTS]
    assert len(set(names)) == len(names)
    chosen = MUTANTS
    if b.args.only:
        unknown = set(b.args.only) - set(names)
        if unknown:
            b.parser.error(f"unknown mutants: {', '.join(sorted(unknown))}")
        chosen = [m for m in chosen if m.name in b.args.only]
    if b.args.areas:
        areas = {m.area for m in MUTANTS}
        unknown = set(b.args.areas) - areas
        if unknown:
            b.parser.error(f"unknown areas: {', '.join(sorted(unknown))} (the areas are "
                           f"{', '.join(sorted(areas))})")
        chosen = [m for m in chosen if m.area in b.args.areas]
    if not (b.args.only or b.args.areas) and b.quick:
        chosen = [m for m in MUTANTS if m.name in QUICK_NAMES]

    stamp = H.env_line(b.env)
    t_start = time.perf_counter()
    all_tests = list(dict.fromkeys(t for m in chosen for t in m.tests))
    outcome, dt, tail = run_tests(all_tests)
    baseline = dict(outcome=outcome, seconds=dt, tests=all_tests)
    print(f"baseline: {outcome} in {dt:.1f} s", flush=True)
    if outcome != "passed":
        print(tail, file=sys.stderr)

    rows = []
    for m in chosen:
        outcome, dt, tail = run_tests(list(m.tests), m)
        verdict = {"passed": "survived", "failed": "caught"}.get(
            outcome, f"caught ({outcome})")
        rows.append(dict(name=m.name, area=m.area, file=m.file, old=m.old, new=m.new,
                         breaks=m.breaks, tests=list(m.tests), outcome=verdict,
                         seconds=dt, failure=first_failure(tail), ran=stamp))
        print(f"{m.name:24s} {verdict:18s} {dt:6.1f} s  {rows[-1]['failure']}", flush=True)
    total = time.perf_counter() - t_start
    if len(chosen) < len(MUTANTS) and not b.quick:
        rows = in_order(rows + carried_rows(b.out / "mutants.json", chosen))

    b.report("mutants",
             markdown=markdown(rows, baseline, total, b.env),
             csv=(["mutant", "area", "file", "breaks", "tests", "outcome", "seconds"],
                  [[r["name"], r["area"], r["file"], r["breaks"], " ".join(r["tests"]),
                    r["outcome"], r["seconds"]] for r in rows]),
             data=dict(baseline=baseline, mutants=rows, total_s=total,
                       caught=sum(is_caught(r) for r in rows), total=len(rows),
                       environment=b.env))
    ok = baseline["outcome"] == "passed" and all(is_caught(r) for r in rows
                                                 if r["ran"] == stamp)
    return 0 if ok else 1


if __name__ == "__main__":
    sys.exit(main())
