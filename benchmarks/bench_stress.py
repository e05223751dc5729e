"""The seeded numerical stress suite, full run: thousands of extreme single runs, checked.

Thousands of seeded runs over hb in [0.75, 20], alpha in [0, 3], omega in [0.05, 20], e in [0, 1]
(Housner, Mao, constant), N from 8 to 1024, closed and embedded forcing, from initial states near
0, grazing, near overturning, and over long horizons; and cases beyond those ranges: damping up
to xi = 500, omega from 1e-3 to 1e3, orbits through rest (tests/stress.py says exactly
which). Every run must end with a known status, within the work bound, with no NaN or inf in
its output; the impact bound, when hit, is counted and reported. The exact checks ride
along: energy conservation (e = 1, xi = 0, no forcing), the mirror symmetry (exact with the
embedding, to the run's rounding horizon with the closed form) and 1 against 2 threads.
tests/test_stress.py runs a fast subset of the same generator.

    python benchmarks/bench_stress.py           # full run (a few minutes)
    python benchmarks/bench_stress.py --quick   # smoke mode (~10 s with warm caches)

Writes stress.{md,csv,json,png} to benchmarks/results/ (benchmarks/results/quick/ with --quick,
or --out DIR). Failing cases are listed with their ids and inputs; ``--case ID`` reruns one.
Exit status: 0 when every check passed, ``FOUND_FAILURES`` (3) when the suite ran and found
failures (its report lists them), anything else when the script itself failed.
"""

from __future__ import annotations

import collections
import math
import sys
import time

import numpy as np

import _common as H

import rockjit
from rockjit import Block, Execution, Harmonic, Integration

sys.path.insert(0, str(H.ROOT / "tests"))  # the suite's cases and checks: tests/stress.py
import stress as S  # noqa: E402

#: n_runs: the stress cases of the study's ranges; n_extreme: the cases beyond them
FULL = dict(n_runs=3000, n_extreme=3900, max_periods=200, long_periods=20_000, n_energy=300,
            n_mirror=500, n_threads=40, threads_grid=10, threads_periods=100)
QUICK = dict(n_runs=120, n_extreme=60, max_periods=20, long_periods=50, n_energy=30,
             n_mirror=30, n_threads=4, threads_grid=6, threads_periods=20)
FOUND_FAILURES = 3
STATUSES = ("done", "overturned", "rest", "max_impacts", "nonfinite", "refused", "raised")
CSV_HEADERS = ["id", "category", "hb", "alpha", "omega", "law", "e", "n_steps", "periods",
               "forcing", "status", "t", "n_impacts", "n_rhs", "work_bound", "wall_s",
               "failed_checks"]


def warm_up():
    """Load (or compile) every kernel variant, so that run times exclude compilation."""
    t0 = time.perf_counter()
    block, two = Block(hb=1.0), Integration(periods=2, n_steps=16)
    for embedded in (False, True):
        forcing = Harmonic(alpha=0.6, omega=1.3, embedded=embedded)
        for lyap in (False, True):
            for stride in (None, 4):
                rockjit.simulate(block, forcing, (0.1, 0.0), integration=two, lyapunov=lyap,
                                 record_stride=stride)
    for lyap in (False, True):
        rockjit.basin(block, Harmonic(alpha=0.6, omega=1.3), 2,
                      integration=Integration(periods=2), lyapunov=lyap,
                      execution=Execution(threads=1))
    return time.perf_counter() - t0


def regime(kw):
    """A short description of a case's regime for the failure tables."""
    h = 2 * math.pi / kw["omega"] / S.grid_n(kw)
    law = kw.get("law", "housner")
    if law == "constant":
        law = f"e={kw['e']:.3g}"
    bits = [law, f"h={h:.3g}"]
    if kw.get("xi", 0.0) > 1.0:
        bits.append(f"xi={kw['xi']:.3g}")
    if kw.get("forcing") == "embedded":
        bits.append(f"embedded, rho0={math.hypot(kw['r0'], kw['s0']):.3g}")
    if kw.get("lyapunov"):
        bits.append("lyapunov")
    return ", ".join(bits)


class Tally:
    """What the run checks found over every ``simulate`` call of the suite."""

    def __init__(self):
        self.fail = {k: [] for k in S.RUN_CHECKS}
        self.obs = collections.Counter()
        self.checked = collections.Counter()
        self.refused = 0
        self.work_ratio = []

    def add(self, case, res, probs, source):
        self.checked[source] += 1
        if res is None and not any(probs.values()):
            self.refused += 1
        for k, v in probs.items():
            if v:
                self.fail[k].append(dict(id=case.id, category=case.category, problems=v,
                                         kwargs=case.kwargs if source == "stress" else
                                         dict(case.kwargs, note=f"from {source}"),
                                         regime=regime(case.kwargs)))
        if res is not None:
            for o in S.observations(case.kwargs, res):
                self.obs[o] += 1
            self.work_ratio.append(res.n_rhs / S.work_bound(case.kwargs, res))

    @property
    def runs(self):
        """Calls that went through the run checks (not refused)."""
        return sum(self.checked.values()) - self.refused

    @property
    def failures(self):
        return sum(len(v) for v in self.fail.values())


# --------------------------------------------------------------------------- experiments

def stress_runs(cases, tally):
    """Every stress case through the run checks: ``(status counts, CSV rows, walls)``."""
    by_status = collections.Counter()
    rows, walls = [], []
    for case in cases:
        t0 = time.perf_counter()
        res, probs, refusal = S.run_case(case)
        wall = time.perf_counter() - t0
        if res is not None:
            walls.append(wall)
        status = res.status if res is not None else ("refused" if refusal else "raised")
        by_status[(case.category, status)] += 1
        tally.add(case, res, probs, "stress")
        kw = case.kwargs
        rows.append([case.id, case.category, kw["hb"], kw["alpha"], kw["omega"],
                     kw.get("law", "housner"), kw.get("e"), kw.get("n_steps", rockjit.DEFAULT_N),
                     kw["periods"], kw.get("forcing", "closed"), status,
                     None if res is None else res.t, None if res is None else res.n_impacts,
                     None if res is None else res.n_rhs,
                     None if res is None else S.work_bound(kw, res), wall,
                     ";".join(k for k, v in probs.items() if v)])
    return by_status, rows, walls


def energy_runs(cfg, seed, tally):
    """Unforced elastic rocking without damping: the energy must be conserved."""
    out = dict(tried=0, failed=[], refused=0)
    for case in S.energy_cases(cfg["n_energy"], seed, max_periods=max(cfg["max_periods"], 50)):
        res, probs, refusal = S.run_case(case)
        tally.add(case, res, probs, "energy")
        out["tried"] += 1
        pr = [f"run failed: {refusal}"] if res is None else S.check_energy(case.kwargs, res)
        if pr:
            out["failed"].append(dict(id=case.id, problems=pr, kwargs=case.kwargs))
    return out


def mirror_runs(cfg, seed, embedded, tally, compared):
    """The mirror symmetry, exact with the embedding, to the rounding horizon closed-form."""
    key = "mirror_embedded" if embedded else "mirror_closed"
    out = dict(tried=0, failed=[], refused=0)
    for case in S.mirror_cases(cfg["n_mirror"], seed, max_periods=cfg["max_periods"],
                               embedded=embedded):
        results, refusals = [], []
        for j, kw in enumerate(case.kwargs["group"]):
            sub = S.Case(id=f"{case.id}/{j}", category=case.category, kwargs=kw)
            res, probs, refusal = S.run_case(sub)
            tally.add(sub, res, probs, key)
            results.append(res)
            refusals.append(refusal)
        if all(refusals):
            out["refused"] += 1
            continue
        out["tried"] += 1
        if any(r is None for r in results):
            pr = ["a run raised or only one of the pair was refused"]
        elif embedded:
            pr = S.check_mirror_exact(*results)
        else:
            pr, k = S.check_mirror_closed(*results)
            compared["whole run" if k == "whole" else
                     ("no period" if k == 0 else "leading periods")] += 1
        if pr:
            out["failed"].append(dict(id=case.id, problems=pr, kwargs=case.kwargs["group"][0]))
    return out


def threads_runs(cfg, seed):
    """Basins and sweeps with 1 and 2 threads, bit for bit."""
    out = dict(tried=0, failed=[], refused=0)
    for case in S.threads_cases(cfg["n_threads"], seed, max_periods=cfg["threads_periods"],
                                grid=cfg["threads_grid"]):
        one = S.run_threads_case(case, 1)
        two = S.run_threads_case(case, 2)
        if one is None and two is None:
            out["refused"] += 1
            continue
        out["tried"] += 1
        pr = ["refused with one thread count only"] if one is None or two is None else \
            S.check_threads(one, two)
        if pr:
            out["failed"].append(dict(id=case.id, problems=pr, kwargs=case.kwargs))
    return out


# --------------------------------------------------------------------------- the report

def markdown(m):
    cfg, tally, exact, seed, quick = m["cfg"], m["tally"], m["exact"], m["seed"], m["quick"]
    by_status = m["by_status"]
    cats = [c for c in S.ALL_CATEGORIES if any(by_status[(c, s)] for s in STATUSES)]
    cat_rows = [[c] + [by_status[(c, s)] for s in STATUSES]
                + [sum(by_status[(c, s)] for s in STATUSES)] for c in cats]
    cat_rows.append(["all"] + [sum(by_status[(c, s)] for c in cats) for s in STATUSES]
                    + [m["n_cases"]])
    check_rows = [[f"`{k}` (every run)", tally.runs, len(tally.fail[k]),
                   f"{tally.refused} refused" if tally.refused else ""] for k in S.RUN_CHECKS]
    for k in S.EXACT_CHECKS:
        label = f"`{k}`" + ("" if k != "threads" or m["threads_ok"] else " (skipped: 1 thread)")
        check_rows.append([label, exact[k]["tried"], len(exact[k]["failed"]),
                           f"{exact[k]['refused']} refused" if exact[k]["refused"] else ""])
    obs_rows = [["impact bound hit (status `max_impacts`)", tally.obs["impact_bound"]],
                [f"overturned off the threshold on a grid with h > {S.H_RESOLVED:g}",
                 tally.obs["coarse_overturn_off_threshold"]]]
    fail_rows = []
    for k in S.RUN_CHECKS:
        for f in tally.fail[k][:12]:
            fail_rows.append([f"`{k}`", f["id"], f["category"], f["regime"],
                              f["problems"][0][:90]])
        if len(tally.fail[k]) > 12:
            fail_rows.append([f"`{k}`", f"... {len(tally.fail[k]) - 12} more", "", "", ""])
    for k in S.EXACT_CHECKS:
        for f in exact[k]["failed"][:12]:
            fail_rows.append([f"`{k}`", f["id"], "", regime(f["kwargs"]),
                              f["problems"][0][:90]])
    wall, wr, secs = np.array(m["walls"]), tally.work_ratio, m["seconds"]
    md = "".join([
        f"#### Stress suite: results, seed {seed}{H.quick_note(quick)}\n",
        f"{m['n_cases']} stress runs ({cfg['n_runs']} over the study's ranges, "
        f"{cfg['max_periods']} periods at most, long horizons up to {cfg['long_periods']}; "
        f"{cfg['n_extreme']} beyond them: xi up to 500, omega from 1e-3 to 1e3, orbits "
        f"through rest), {cfg['n_energy']} energy runs, {cfg['n_mirror']} mirror cases of each "
        f"kind (2 runs each embedded, 4 closed: run, mirror, two twins), "
        f"{exact['threads']['tried']} basins/sweeps with 1 and 2 threads: "
        f"{tally.runs + tally.refused} `simulate` calls in all; {tally.refused} were refused as "
        f"too coarse (ValueError naming n_steps, as documented), the {tally.runs} runs went "
        "through the run checks.\n\n",
        "Runs by category and final status:\n\n",
        H.md_table(["category"] + [f"`{s}`" for s in STATUSES] + ["runs"], cat_rows),
        "\nChecks (tests/stress.py defines each):\n\n",
        H.md_table(["check", "tried", "failed", "not run"], check_rows),
        "\nReported, not failed:\n\n",
        H.md_table(["outcome", "runs"], obs_rows),
        "\nClosed-form mirror, what could be compared (the twins' agreement decides): "
        + ", ".join(f"{v} {k}" for k, v in sorted(m["compared"].items())) + ".\n",
        f"\nWork: n_rhs / bound at most {max(wr):.3f} (median {np.median(wr):.3f}); wall time "
        f"per stress run: median {1e3 * np.median(wall):.2f} ms, max {np.max(wall):.2f} s; "
        f"stress runs {secs['stress']:.0f} s, energy {secs['energy']:.0f} s, mirror "
        f"{secs['mirror']:.0f} s, threads {secs['threads']:.0f} s, after {secs['warm']:.0f} s "
        "loading the kernels.\n",
    ])
    if fail_rows:
        md += ("\nFailures (rerun one with `python benchmarks/bench_stress.py --case ID"
               f"{' --quick' if quick else ''}`" + (f" `--seed {seed}`" if seed else "")
               + "):\n\n"
               + H.md_table(["check", "case", "category", "regime", "first problem"],
                            fail_rows))
    return md + f"\n{H.env_line(m['env'])}\n"


def plot(rows):
    """Coverage: each stress run at (omega, hb) and (omega, alpha), coloured by its status."""
    plt = H.pyplot()
    colours = dict(done="C0", overturned="C3", rest="C2", max_impacts="C1", refused="0.7",
                   nonfinite="k", raised="m")
    fig, axes = plt.subplots(1, 2, figsize=(10, 4.2), layout="constrained")
    for st, col in colours.items():
        sel = [r for r in rows if r[10] == st]
        if not sel:
            continue
        om = [r[4] for r in sel]
        axes[0].scatter(om, [r[2] for r in sel], s=4, c=col, label=f"{st} ({len(sel)})")
        axes[1].scatter(om, [r[3] for r in sel], s=4, c=col)
    for ax, name in zip(axes, ("hb", "alpha")):
        ax.set_xscale("log")
        ax.set_xlabel("omega")
        ax.set_ylabel(name)
        ax.grid(True, alpha=0.3)
    axes[0].set_yscale("log")
    axes[1].set_yscale("symlog", linthresh=3.0)  # the slowest forcing takes alpha to 1e6
    axes[0].legend(fontsize=7, markerscale=3)
    fig.suptitle(f"Stress runs by final status ({len(rows)} runs)", fontsize=10)
    return fig


def rerun(case_id, cfg):
    """Rerun one stress case by id and print its result and checks."""
    case = S.case_by_id(case_id, max_periods=cfg["max_periods"],
                        long_periods=cfg["long_periods"])
    print(case)
    res, probs, refusal = S.run_case(case)
    print(res if res is not None else f"refused: {refusal}")
    for k, v in probs.items():
        print(f"{k}: {'ok' if not v else v}")
    return 0


# --------------------------------------------------------------------------- main

def main(argv=None):
    def options(p):
        p.add_argument("--seed", type=int, default=0,
                       help="seed of the case generator (default 0)")
        p.add_argument("--case", default=None,
                       help="rerun one stress case by id (e.g. s0-29, x0-7)")

    b = H.Bench(__doc__, argv, options=options)
    cfg = QUICK if b.quick else FULL
    seed = b.args.seed
    if b.args.case:
        return rerun(b.args.case, cfg)
    secs = dict(warm=warm_up())
    print(f"kernels loaded in {secs['warm']:.1f} s")
    tally = Tally()

    t0 = time.perf_counter()
    cases = S.cases(cfg["n_runs"], seed, max_periods=cfg["max_periods"],
                    long_periods=cfg["long_periods"])
    cases += S.extreme_cases(cfg["n_extreme"], seed, max_periods=cfg["max_periods"])
    by_status, rows, walls = stress_runs(cases, tally)
    secs["stress"] = time.perf_counter() - t0
    print(f"{len(cases)} stress runs in {secs['stress']:.1f} s")

    # the exact checks (their runs go through the run checks too)
    exact = {}
    t0 = time.perf_counter()
    exact["energy"] = energy_runs(cfg, seed, tally)
    secs["energy"] = time.perf_counter() - t0
    t0 = time.perf_counter()
    compared = collections.Counter()
    for embedded in (True, False):
        exact["mirror_embedded" if embedded else "mirror_closed"] = mirror_runs(
            cfg, seed, embedded, tally, compared)
    secs["mirror"] = time.perf_counter() - t0
    t0 = time.perf_counter()
    threads_ok = S.threads_available()
    exact["threads"] = threads_runs(cfg, seed) if threads_ok else \
        dict(tried=0, failed=[], refused=0)
    secs["threads"] = time.perf_counter() - t0

    m = dict(cfg=cfg, seed=seed, quick=b.quick, env=b.env, tally=tally, exact=exact,
             by_status=by_status, n_cases=len(cases), walls=walls, compared=compared,
             threads_ok=threads_ok, seconds=secs)
    b.report("stress", markdown=markdown(m), csv=(CSV_HEADERS, rows),
             data=dict(seed=seed, quick=b.quick, config=cfg, environment=b.env,
                       runs_checked=dict(tally.checked),
                       by_status={f"{c}/{s}": v for (c, s), v in by_status.items()},
                       run_failures=tally.fail,
                       exact={k: dict(tried=v["tried"], failed=v["failed"])
                              for k, v in exact.items()},
                       observations=dict(tally.obs), mirror_closed_compared=dict(compared),
                       refused=tally.refused, work_ratio_max=max(tally.work_ratio),
                       wall_median_s=float(np.median(walls)), wall_max_s=float(np.max(walls)),
                       seconds=secs),
             figures=[("stress.png", plot(rows), 110)])
    n_fail = tally.failures + sum(len(v["failed"]) for v in exact.values())
    return FOUND_FAILURES if n_fail else 0


if __name__ == "__main__":
    sys.exit(main())
