"""Issue 5: the seeded numerical stress suite, full run.

Thousands of seeded runs over hb in [0.75, 20], alpha in [0, 3], omega in [0.05, 20], e in [0, 1]
(Housner, Mao, constant), N from 8 to 1024, closed and embedded forcing, from initial states near
0, grazing, near overturning, and over long horizons (benchmarks/stress.py says exactly which).
Every run must end with a known status, within the work bound, with no NaN or inf in its output;
the impact bound, when hit, is counted and reported. The exact checks ride along: energy
conservation (e = 1, xi = 0, no forcing), the mirror symmetry (exact with the embedding, to the
run's rounding horizon with the closed form) and 1 against 2 threads. tests/test_stress.py runs a
fast subset of the same generator.

    python benchmarks/bench_stress.py           # full run (~1 min)
    python benchmarks/bench_stress.py --quick   # smoke mode (~10 s with warm caches)

Writes stress.{md,csv,json,png} to benchmarks/results/ (benchmarks/results/quick/ with --quick,
or --out DIR). Failing cases are listed with their ids and inputs; ``--case ID`` reruns one.
"""

from __future__ import annotations

import collections
import math
import sys
import time
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parent))
import _common as C  # noqa: E402
import stress as S  # noqa: E402

import rockjit  # noqa: E402

FULL = dict(n_runs=3000, max_periods=200, long_periods=20_000, n_energy=300, n_mirror=500,
            n_threads=40, threads_grid=10, threads_periods=100)
QUICK = dict(n_runs=120, max_periods=20, long_periods=50, n_energy=30, n_mirror=30,
             n_threads=4, threads_grid=6, threads_periods=20)


def warm_up():
    """Load (or compile) every kernel variant, so that run times exclude compilation."""
    t0 = time.perf_counter()
    base = dict(hb=1.0, alpha=0.6, omega=1.3, periods=2, n_steps=16, theta0=0.1, dtheta0=0.0)
    for forcing in ("closed", "embedded"):
        for lyap in (False, True):
            for stride in (None, 4):
                rockjit.simulate(**base, forcing=forcing, lyapunov=lyap, record_stride=stride)
    for lyap in (False, True):
        rockjit.analysis.basin(1.0, 0.6, 1.3, grid=2, periods=2, lyapunov=lyap, threads=1)
    return time.perf_counter() - t0


def _regime(kw):
    """A short description of a case's regime for the failure tables."""
    h = 2 * math.pi / kw["omega"] / S.grid_n(kw)
    law = kw.get("law", "housner")
    if law == "constant":
        law = f"e={kw['e']:.3g}"
    bits = [law, f"h={h:.3g}"]
    if kw.get("forcing") == "embedded":
        bits.append(f"embedded, rho0={math.hypot(kw['r0'], kw['s0']):.3g}")
    if kw.get("lyapunov"):
        bits.append("lyapunov")
    return ", ".join(bits)


def main(argv=None):
    p = C.parser(__doc__.splitlines()[0])
    p.add_argument("--seed", type=int, default=0, help="seed of the case generator (default 0)")
    p.add_argument("--case", default=None, help="rerun one stress case by id (e.g. s0-29)")
    args = p.parse_args(argv)
    cfg = QUICK if args.quick else FULL
    seed = args.seed
    if args.case:
        return rerun(args.case, cfg)
    out = C.out_dir(args)
    env = C.environment()
    print(C.env_line(env))
    warm_s = warm_up()
    print(f"kernels loaded in {warm_s:.1f} s")

    run_fail = {k: [] for k in S.RUN_CHECKS}
    obs = collections.Counter()
    by_status = collections.Counter()
    rows = []
    n_checked = collections.Counter()
    n_refused = 0
    walls = []
    work_ratio = []
    t_start = time.perf_counter()

    def checked(case, res, probs, source):
        nonlocal n_refused
        n_checked[source] += 1
        if res is None and not any(probs.values()):
            n_refused += 1
        for k, v in probs.items():
            if v:
                run_fail[k].append(dict(id=case.id, category=case.category, problems=v,
                                        kwargs=case.kwargs if source == "stress" else
                                        dict(case.kwargs, note=f"from {source}"),
                                        regime=_regime(case.kwargs)))
        if res is not None:
            for o in S.observations(case.kwargs, res):
                obs[o] += 1
            bound = S.work_bound(case.kwargs, res)
            work_ratio.append(res.n_rhs / bound)

    # ---- the stress runs
    cases = S.cases(cfg["n_runs"], seed, max_periods=cfg["max_periods"],
                    long_periods=cfg["long_periods"])
    for case in cases:
        t0 = time.perf_counter()
        res, probs, refusal = S.run_case(case)
        wall = time.perf_counter() - t0
        if res is not None:
            walls.append(wall)
        status = res.status if res is not None else ("refused" if refusal else "raised")
        by_status[(case.category, status)] += 1
        checked(case, res, probs, "stress")
        kw = case.kwargs
        rows.append([case.id, case.category, kw["hb"], kw["alpha"], kw["omega"],
                     kw.get("law", "housner"), kw.get("e"), kw.get("n_steps", rockjit.DEFAULT_N),
                     kw["periods"], kw.get("forcing", "closed"), status,
                     None if res is None else res.t, None if res is None else res.n_impacts,
                     None if res is None else res.n_rhs,
                     None if res is None else S.work_bound(kw, res), wall,
                     ";".join(k for k, v in probs.items() if v)])
    stress_s = time.perf_counter() - t_start
    print(f"{len(cases)} stress runs in {stress_s:.1f} s")

    # ---- exact checks (their runs go through the run checks too)
    exact = {k: dict(tried=0, failed=[], refused=0) for k in S.EXACT_CHECKS}
    t0 = time.perf_counter()
    for case in S.energy_cases(cfg["n_energy"], seed, max_periods=max(cfg["max_periods"], 50)):
        res, probs, refusal = S.run_case(case)
        checked(case, res, probs, "energy")
        exact["energy"]["tried"] += 1
        pr = [f"run failed: {refusal}"] if res is None else S.check_energy(case.kwargs, res)
        if pr:
            exact["energy"]["failed"].append(dict(id=case.id, problems=pr, kwargs=case.kwargs))
    energy_s = time.perf_counter() - t0

    t0 = time.perf_counter()
    compared = collections.Counter()
    for embedded in (True, False):
        key = "mirror_embedded" if embedded else "mirror_closed"
        for case in S.mirror_cases(cfg["n_mirror"], seed, max_periods=cfg["max_periods"],
                                   embedded=embedded):
            results, refusals = [], []
            for j, kw in enumerate(case.kwargs["group"]):
                sub = S.Case(id=f"{case.id}/{j}", category=case.category, kwargs=kw)
                res, probs, refusal = S.run_case(sub)
                checked(sub, res, probs, key)
                results.append(res)
                refusals.append(refusal)
            if all(refusals):
                exact[key]["refused"] += 1
                continue
            exact[key]["tried"] += 1
            if any(r is None for r in results):
                pr = ["a run raised or only one of the pair was refused"]
            elif embedded:
                pr = S.check_mirror_exact(*results)
            else:
                pr, k = S.check_mirror_closed(*results)
                compared["whole run" if k == "whole" else
                          ("no period" if k == 0 else "leading periods")] += 1
            if pr:
                exact[key]["failed"].append(dict(id=case.id, problems=pr,
                                                 kwargs=case.kwargs["group"][0]))
    mirror_s = time.perf_counter() - t0

    t0 = time.perf_counter()
    threads_ok = S.threads_available()
    if threads_ok:
        for case in S.threads_cases(cfg["n_threads"], seed, max_periods=cfg["threads_periods"],
                                    grid=cfg["threads_grid"]):
            one = S.run_threads_case(case, 1)
            two = S.run_threads_case(case, 2)
            if one is None and two is None:
                exact["threads"]["refused"] += 1
                continue
            exact["threads"]["tried"] += 1
            pr = ["refused with one thread count only"] if one is None or two is None else \
                S.check_threads(one, two)
            if pr:
                exact["threads"]["failed"].append(dict(id=case.id, problems=pr,
                                                       kwargs=case.kwargs))
    threads_s = time.perf_counter() - t0
    C.check_unchanged(env)

    # ---- tables
    statuses = ("done", "overturned", "rest", "max_impacts", "nonfinite", "refused", "raised")
    cat_rows = []
    for cat in S.CATEGORIES:
        cat_rows.append([cat] + [by_status[(cat, s)] for s in statuses]
                        + [sum(by_status[(cat, s)] for s in statuses)])
    cat_rows.append(["all"] + [sum(by_status[(c, s)] for c in S.CATEGORIES) for s in statuses]
                    + [len(cases)])
    n_runs_all = sum(n_checked.values()) - n_refused
    check_rows = []
    for k in S.RUN_CHECKS:
        check_rows.append([f"`{k}` (every run)", n_runs_all, len(run_fail[k]),
                           f"{n_refused} refused" if n_refused else ""])
    for k in S.EXACT_CHECKS:
        tried = exact[k]["tried"]
        label = f"`{k}`" + ("" if k != "threads" or threads_ok else " (skipped: 1 thread)")
        check_rows.append([label, tried, len(exact[k]["failed"])
                           ] + ([f"{exact[k]['refused']} refused"] if exact[k]["refused"] else
                                [""]))
    obs_rows = [["impact bound hit (status `max_impacts`)", obs["impact_bound"]],
                [f"overturned off the threshold on a grid with h > {S.H_RESOLVED:g}",
                 obs["coarse_overturn_off_threshold"]],
                [f"Zeno cascade stalled (> {S.STALL} impacts at one instant) with the cut-off "
                 "off, `rest_speed = 0`", obs["zeno_stall_without_cutoff"]]]

    fail_rows = []
    for k in S.RUN_CHECKS:
        for f in run_fail[k][:12]:
            fail_rows.append([f"`{k}`", f["id"], f["category"], f["regime"],
                              f["problems"][0][:90]])
        if len(run_fail[k]) > 12:
            fail_rows.append([f"`{k}`", f"... {len(run_fail[k]) - 12} more", "", "", ""])
    for k in S.EXACT_CHECKS:
        for f in exact[k]["failed"][:12]:
            fail_rows.append([f"`{k}`", f["id"], "", _regime(f["kwargs"]), f["problems"][0][:90]])

    wall = np.array(walls)
    quick = args.quick
    md = "".join([
        f"#### Stress suite: results, seed {seed}{' (QUICK MODE)' if quick else ''}\n",
        f"{len(cases)} stress runs ({cfg['max_periods']} periods at most, "
        f"long horizons up to {cfg['long_periods']}), "
        f"{cfg['n_energy']} energy runs, {cfg['n_mirror']} mirror cases of each kind "
        f"(2 runs each embedded, 4 closed: run, mirror, two twins), "
        f"{exact['threads']['tried']} basins/sweeps with 1 and 2 threads: "
        f"{n_runs_all + n_refused} `simulate` calls in all; {n_refused} were refused as too "
        f"coarse (ValueError naming n_steps, as documented), the {n_runs_all} runs went "
        "through the run checks.\n\n",
        "Runs by category and final status:\n\n",
        C.md_table(["category"] + [f"`{s}`" for s in statuses] + ["runs"], cat_rows),
        "\nChecks (benchmarks/stress.py defines each):\n\n",
        C.md_table(["check", "tried", "failed", "not run"], check_rows),
        "\nReported, not failed:\n\n",
        C.md_table(["outcome", "runs"], obs_rows),
        "\nClosed-form mirror, what could be compared (the twins' agreement decides): "
        + ", ".join(f"{v} {k}" for k, v in sorted(compared.items())) + ".\n",
        f"\nWork: n_rhs / bound at most {max(work_ratio):.3f} (median "
        f"{np.median(work_ratio):.3f}); wall time per stress run: median "
        f"{1e3 * np.median(wall):.2f} ms, max {np.max(wall):.2f} s; stress runs "
        f"{stress_s:.0f} s, energy {energy_s:.0f} s, mirror {mirror_s:.0f} s, threads "
        f"{threads_s:.0f} s, after {warm_s:.0f} s loading the kernels.\n",
    ])
    if fail_rows:
        md += ("\nFailures (rerun one with `python benchmarks/bench_stress.py --case ID"
               f"{' --quick' if quick else ''}`" + (f" `--seed {seed}`" if seed else "")
               + "):\n\n"
               + C.md_table(["check", "case", "category", "regime", "first problem"],
                            fail_rows))
    md += f"\n{C.env_line(env)}\n"
    C.write_text(out / "stress.md", md)
    C.update_readme(args, "stress", md)
    C.write_csv(out / "stress.csv",
                ["id", "category", "hb", "alpha", "omega", "law", "e", "n_steps", "periods",
                 "forcing", "status", "t", "n_impacts", "n_rhs", "work_bound", "wall_s",
                 "failed_checks"], rows)
    C.write_json(out / "stress.json", dict(
        seed=seed, quick=quick, config=cfg, environment=env, runs_checked=dict(n_checked),
        by_status={f"{c}/{s}": v for (c, s), v in by_status.items()},
        run_failures=run_fail, exact={k: dict(tried=v["tried"], failed=v["failed"])
                                      for k, v in exact.items()},
        observations=dict(obs), mirror_closed_compared=dict(compared), refused=n_refused,
        work_ratio_max=max(work_ratio), wall_median_s=float(np.median(wall)),
        wall_max_s=float(np.max(wall))))
    plot(out / "stress.png", cases, rows)
    print(md)
    n_fail = sum(len(v) for v in run_fail.values()) + sum(len(v["failed"])
                                                          for v in exact.values())
    return 1 if n_fail else 0


def plot(path, cases, rows):
    """Coverage: each stress run at (omega, hb), coloured by its final status."""
    plt = C.pyplot()
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
    axes[0].legend(fontsize=7, markerscale=3)
    fig.suptitle(f"Stress runs by final status ({len(cases)} runs)", fontsize=10)
    C.save_figure(fig, path, dpi=110)
    plt.close(fig)


def rerun(case_id, cfg):
    """Rerun one stress case by id and print its result and checks."""
    pre, idx = case_id.split("-")
    seed = int(pre[1:])
    i = int(idx)
    case = S.cases(i + 1, seed, max_periods=cfg["max_periods"],
                   long_periods=cfg["long_periods"])[i]
    print(case)
    res, probs, refusal = S.run_case(case)
    print(res if res is not None else f"refused: {refusal}")
    for k, v in probs.items():
        print(f"{k}: {'ok' if not v else v}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
