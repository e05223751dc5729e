"""Work against precision: rockjit against scipy's solve_ivp, on four scenes.

rockjit at N = 16, 32, ..., 1024 steps per period; ``solve_ivp`` (rockjit's scipy path, same
model code, the same closed-form forcing, analytic Jacobian for the implicit methods) with BDF,
Radau, LSODA, RK45 and DOP853 at rtol = 1e-3, ..., 1e-12, atol = 1e-3 rtol (the study's ratio).
A method's tighter tolerances are skipped once one run costs more than ``--cap`` seconds.

Scenes (Housner restitution, z0 = rockjit.Z0_STUDY):

- ``periodic``: the study's reference run, hb=1, alpha=0.6, omega=1.3, 50 periods; error of the
  final (theta, theta');
- ``chaotic``: hb=1, alpha=0.955, omega=1.3 (lambda1 ~ 0.13), 5 periods, before nearby
  trajectories separate; error of the final (theta, theta');
- ``overturn``: hb=2, alpha=0.5, omega=1.6 (the study's hb=2 frequency), overturns at t ~ 11.2
  after 3 impacts; error of the overturning time (condition number |dt_over/dtheta0| ~ 60);
- ``overturn_study``: the study's overturning example hb=2, alpha=0.448, omega=1.3, t ~ 23.7
  after 9 impacts; error of the overturning time, ill-conditioned (|dt_over/dtheta0| ~ 2e4), so
  double precision alone limits any method to ~1e-11.

The reference of each scene is computed two independent ways, rockjit at N = 8192 (the errors are
measured against it) and a scipy solver at its tightest tolerances (DOP853 at rtol 1e-13 for the
periodic scene, Radau at rtol 1e-13 for the others, see REF2); the larger of their difference and
of rockjit's own change from N = 4096 to 8192 is the floor below which an error is not
resolved. A run with another status or another number of impacts than the reference is marked,
not silently plotted. A last table shows the transient-chaos case hb=1, alpha=0.969, omega=1.3,
whose overturning time no double-precision method determines.

    python benchmarks/bench_work_precision.py           # full (~7 min)
    python benchmarks/bench_work_precision.py --quick   # smoke (~30 s)

Writes work_precision.{md,csv,json} and work_precision_<scene>.png to benchmarks/results/
(benchmarks/results/quick/ with --quick, or --out DIR).
"""

from __future__ import annotations

import math
import sys

import numpy as np

import _common as H

import rockjit
from rockjit import Block, Harmonic, Integration, Scipy

METHODS = ("BDF", "Radau", "LSODA", "RK45", "DOP853")
NS = (16, 32, 64, 128, 160, 256, 512, 1024)
RTOLS = tuple(10.0 ** -k for k in range(3, 13))
N_REF = 8192
#: The independent second reference of each scene: DOP853 where it is cheap and exact enough;
#: Radau for the scenes that end on an event, where DOP853's event time (brentq on its dense
#: output) scatters by ~1e-11 from one tolerance to the next (Radau takes 70 s on the periodic
#: scene, DOP853 0.5 s).
REF2 = dict(periodic=("DOP853", dict(rtol=1e-13, atol=1e-15)),
            chaotic=("Radau", dict(rtol=1e-13, atol=1e-16)),
            overturn=("Radau", dict(rtol=1e-13, atol=1e-16)),
            overturn_study=("Radau", dict(rtol=1e-13, atol=1e-16)))
REF_DOP = dict(rtol=1e-13, atol=1e-15)
ATOL_RATIO = 1e-3


def scene_run(hb, alpha, omega, periods):
    """A run of a scene: Housner restitution, from the study's initial state (``state=None``)."""
    return dict(block=Block(hb=hb, law="housner"), forcing=Harmonic(alpha=alpha, omega=omega),
                periods=periods)


SCENES = {
    "periodic": dict(run=scene_run(1.0, 0.6, 1.3, 50), measure="state",
                     title="periodic: hb=1, alpha=0.6, omega=1.3, 50 periods"),
    "chaotic": dict(run=scene_run(1.0, 0.955, 1.3, 5), measure="state",
                    title="chaotic: hb=1, alpha=0.955, omega=1.3, 5 periods"),
    "overturn": dict(run=scene_run(2.0, 0.5, 1.6, 10), measure="overturn",
                     title="overturn: hb=2, alpha=0.5, omega=1.6 (t_over ~ 11.2)"),
    "overturn_study": dict(run=scene_run(2.0, 0.448, 1.3, 10), measure="overturn",
                           title="overturn_study: hb=2, alpha=0.448, omega=1.3 (t_over ~ 23.7, "
                                 "ill-conditioned)"),
}
HARD = scene_run(1.0, 0.969, 1.3, 30)


def simulate(run, n_steps=None, method="rockjit"):
    """One ``rockjit.simulate`` of a scene's run at ``n_steps`` or through ``method``."""
    return rockjit.simulate(run["block"], run["forcing"],
                            integration=Integration(periods=run["periods"], n_steps=n_steps),
                            method=method)


def error(measure, res, ref):
    """``(error, impact-time error, flag)``; flag is '' when status and impact count agree."""
    flag = ""
    if res.status != ref.status:
        flag = f"status {res.status}"
    elif res.n_impacts != ref.n_impacts:
        flag = f"{res.n_impacts} impacts (ref {ref.n_impacts})"
    if measure == "overturn":
        err = abs(res.t - ref.t) if res.status == "overturned" else math.nan
    else:
        err = float(np.max(np.abs(res.state[:2] - ref.state[:2]))) if res.status == ref.status \
            else math.nan
    t_err = H.impact_time_error(res, ref)
    return err, t_err if isinstance(t_err, float) else math.nan, flag


def time_scipy(run, method, rtol, repeats):
    """Run once; when cheap (< 1 s), ``repeats - 1`` more; median wall and the result."""
    scipy = Scipy(method, rtol=rtol, atol=ATOL_RATIO * rtol)
    dt, res = H.timed(simulate, run, method=scipy)
    walls = [dt]
    if dt < 1.0:
        for _ in range(repeats - 1):
            walls.append(H.timed(simulate, run, method=scipy)[0])
    return walls, res


def references(name, run, measure, quick):
    """The scene's reference (rockjit at N_REF), its independent second reference and the
    floor below which an error is not resolved."""
    ref = simulate(run, N_REF)
    half = simulate(run, N_REF // 2)
    m2, tol2 = REF2[name] if not quick else ("DOP853", REF_DOP)
    ref2_wall, ref2 = H.timed(simulate, run, method=Scipy(m2, **tol2))
    d2, _, flag2 = error(measure, ref2, ref)
    dop = ref2 if m2 == "DOP853" else simulate(run, method=Scipy("DOP853", **REF_DOP))
    d_dop, _, flag_dop = error(measure, dop, ref)
    d_half, _, _ = error(measure, half, ref)
    print(f"[{name}] reference rockjit N={N_REF}: {ref.status} t={ref.t:.15g} "
          f"impacts={ref.n_impacts}; {m2} {tol2}: {ref2.status} t={ref2.t:.15g} "
          f"impacts={ref2.n_impacts}; difference {d2:.3g} {flag2}; DOP853 {d_dop:.3g}; "
          f"N={N_REF // 2} {d_half:.3g}")
    return ref, dict(
        ref=dict(status=ref.status, t=ref.t, state=ref.state, n_impacts=ref.n_impacts,
                 n_rhs=ref.n_rhs),
        ref2=dict(method=m2, tol=tol2, status=ref2.status, t=ref2.t, state=ref2.state,
                  n_impacts=ref2.n_impacts, wall_s=ref2_wall, difference=d2, flag=flag2),
        dop853=dict(tol=REF_DOP, difference=d_dop, flag=flag_dop),
        half=dict(n=N_REF // 2, difference=d_half),
        floor=max(d2, d_half), floor_flag=flag2)


def rockjit_rows(run, measure, ref, ns, repeats):
    """rockjit at each N, interleaved: one row per N."""
    t = H.side_by_side({n: (lambda n=n: simulate(run, n)) for n in ns}, repeats)
    rows = []
    for n in ns:
        r = t.result[n]
        err, t_err, flag = error(measure, r, ref)
        rows.append(dict(method="rockjit", setting=f"N={n}", n=n, rtol=None,
                         wall_s=t.median(n), wall_all_s=t.wall[n], n_rhs=r.n_rhs,
                         error=err, impact_time_error=t_err, flag=flag, status=r.status,
                         n_impacts=r.n_impacts, error_estimate=r.max_error_estimate))
        print(f"  rockjit N={n}: {rows[-1]['wall_s']:.3g} s, error {err:.3g} {flag}")
    return rows


def scipy_rows(run, measure, ref, method, rtols, repeats, cap):
    """One scipy method at each rtol, until a run takes longer than ``cap``: one row per rtol."""
    rows = []
    skipped_from = None
    for rtol in rtols:
        if skipped_from is not None:
            rows.append(dict(method=method, setting=f"rtol={rtol:.0e}", n=None, rtol=rtol,
                             wall_s=math.nan, wall_all_s=[], n_rhs=None, error=math.nan,
                             impact_time_error=math.nan,
                             flag=f"skipped (rtol={skipped_from:.0e} took > {cap:g} s)",
                             status=None, n_impacts=None, error_estimate=math.nan))
            continue
        walls, r = time_scipy(run, method, rtol, repeats)
        err, t_err, flag = error(measure, r, ref)
        rows.append(dict(method=method, setting=f"rtol={rtol:.0e}", n=None, rtol=rtol,
                         wall_s=H.median(walls), wall_all_s=walls, n_rhs=r.n_rhs, error=err,
                         impact_time_error=t_err, flag=flag, status=r.status,
                         n_impacts=r.n_impacts, error_estimate=math.nan))
        print(f"  {method} rtol={rtol:.0e}: {rows[-1]['wall_s']:.3g} s, error {err:.3g} {flag}")
        if max(walls) > cap:
            skipped_from = rtol
    return rows


def run_scene(name, scene, quick, cap):
    """One scene: its references, rockjit at every N, each scipy method at every rtol."""
    run = dict(scene["run"])
    if quick and name == "periodic":
        run["periods"] = 10
    measure = scene["measure"]
    ref, refs = references(name, run, measure, quick)
    rows = rockjit_rows(run, measure, ref, (16, 64, 256) if quick else NS, 3 if quick else 21)
    for m in METHODS:
        rows += scipy_rows(run, measure, ref, m, (1e-3, 1e-6, 1e-9) if quick else RTOLS,
                           2 if quick else 3, cap)
    return dict(name=name, run=H.encode(dict(run, state=None)), measure=measure,
                title=scene["title"], rows=rows, **refs)


def hard_table(quick):
    """The transient-chaos case: overturning times from rockjit and DOP853 at tight settings."""
    rows = []
    for n in ((256, 1024) if quick else (256, 1024, 4096, 16384, 65536)):
        r = simulate(HARD, n)
        rows.append(["rockjit", f"N={n}", r.status, r.t, r.n_impacts])
    for rtol in ((1e-10,) if quick else (1e-10, 1e-11, 1e-12, 1e-13)):
        r = simulate(HARD, method=Scipy("DOP853", rtol=rtol, atol=rtol * 1e-2))
        rows.append(["DOP853", f"rtol={rtol:.0e}", r.status, r.t, r.n_impacts])
    return rows


def cheapest(rows, target):
    """The cheapest unflagged run with error <= target: ``(wall, setting)`` or None."""
    ok = [r for r in rows if not r["flag"] and r["error"] <= target]
    if not ok:
        return None
    r = min(ok, key=lambda r: r["wall_s"])
    return r["wall_s"], r["setting"]


def markdown(scenes, hard, cap, quick, env):
    n_def = rockjit.DEFAULT_N
    md = [f"#### Work–precision: results{H.quick_note(quick)}\n"]
    md.append(f"References: errors are measured against rockjit at N = {N_REF}; the "
              "independent second reference is a scipy solver at its tightest tolerances. "
              f"The floor is the larger of their difference and the change of rockjit's from "
              f"N = {N_REF // 2} to {N_REF} (its own rounding); an error below it is not "
              "resolved.\n\n")
    ref_rows = []
    for s in scenes.values():
        q = "t_over" if s["measure"] == "overturn" else "final (theta, theta')"
        r2 = s["ref2"]
        ref_rows.append([s["name"], q, s["ref"]["status"], s["ref"]["n_impacts"],
                         f"{s['ref']['t']:.15g}",
                         f"{r2['method']} rtol {r2['tol']['rtol']:.0e}, atol "
                         f"{r2['tol']['atol']:.0e}",
                         r2["difference"], r2["flag"] or "agree", s["dop853"]["difference"],
                         s["half"]["difference"], s["floor"]])
    md.append(H.md_table(["scene", "error of", "status", "impacts", "t end", "second reference",
                          "difference", "status, impacts", "DOP853 1e-13 difference",
                          f"N={N_REF // 2} difference", "floor"], ref_rows))

    md.append("\nCheapest run that reaches a target error (median wall time; in brackets the "
              "setting; `—`: none did, within the cap):\n\n")
    sum_rows = []
    for target in (1e-6, 1e-10):
        for s in scenes.values():
            if target < s["floor"]:
                continue
            row = [f"{target:.0e}", s["name"]]
            base = cheapest([r for r in s["rows"] if r["method"] == "rockjit"], target)
            for m in ("rockjit",) + METHODS:
                c = cheapest([r for r in s["rows"] if r["method"] == m], target)
                if c is None:
                    row.append("—")
                elif m == "rockjit" or base is None:
                    row.append(f"{H.fmt(c[0])} s ({c[1]})")
                else:
                    row.append(f"{H.fmt(c[0])} s ({c[1]}), {H.fmt(c[0] / base[0])}x")
            sum_rows.append(row)
    md.append(H.md_table(["target", "scene", "rockjit", *METHODS], sum_rows))
    md.append("\nscipy cells: wall time, setting, and how many times rockjit's cheapest run at "
              "the same target it costs.\n")

    md.append(f"\nrockjit by N (default N = {n_def}): error, largest impact-time error, embedded "
              "error estimate (largest per step), median wall time:\n\n")
    n_rows = []
    ns = [r["n"] for r in next(iter(scenes.values()))["rows"] if r["method"] == "rockjit"]
    for n in ns:
        row = [f"{n}" + (" (default)" if n == n_def else "")]
        for s in scenes.values():
            r = next(r for r in s["rows"] if r["n"] == n)
            e = H.fmt(r["error"]) + (" †" if r["error"] < s["floor"] else "")
            row += [e if not r["flag"] else f"{e} [{r['flag']}]", r["impact_time_error"],
                    r["error_estimate"], r["wall_s"]]
        n_rows.append(row)
    hdr = ["N"]
    for s in scenes.values():
        q = "t_over err" if s["measure"] == "overturn" else "state err"
        hdr += [f"{s['name']}: {q}", "impact t err", "estimate", "wall (s)"]
    md.append(H.md_table(hdr, n_rows))
    md.append("\n† below the floor (the two references' difference): not resolved.\n")

    md.append("\nEvery run, per scene: error (median wall time in s); flags in brackets:\n")
    for s in scenes.values():
        md.append(f"\n*{s['title']}*\n\n")
        rtol_list = sorted({r["rtol"] for r in s["rows"] if r["rtol"] is not None},
                           reverse=True)
        trows = []
        for rtol in rtol_list:
            row = [f"{rtol:.0e}"]
            for m in METHODS:
                r = next(r for r in s["rows"] if r["method"] == m and r["rtol"] == rtol)
                if r["flag"].startswith("skipped"):
                    row.append("skipped")
                else:
                    cell = f"{H.fmt(r['error'])} ({H.fmt(r['wall_s'])})"
                    row.append(cell + (f" [{r['flag']}]" if r["flag"] else ""))
            trows.append(row)
        md.append(H.md_table(["rtol", *METHODS], trows))
    md.append(f"\nskipped: a looser rtol of the method already took more than {cap:g} s. "
              f"atol = {ATOL_RATIO:g} rtol. rockjit: medians of {3 if quick else 21} "
              "interleaved runs; scipy: median of 3 when a run takes < 1 s, else one run; "
              "every wall time is a whole `rockjit.simulate` call (Python overhead included).\n")

    md.append("\nTransient chaos, hb=1, alpha=0.969, omega=1.3 (overturns after ~45 impacts): "
              "the overturning time at ever tighter settings:\n\n")
    md.append(H.md_table(["method", "setting", "status", "t", "impacts"],
                         [[a, b, c, f"{d:.12g}", e] for a, b, c, d, e in hard]))
    md.append(f"\n{H.env_line(env)}\n")
    return "".join(md)


def csv_rows(scenes):
    return [[s["name"], r["method"], r["setting"], r["wall_s"], r["n_rhs"], r["error"],
             r["impact_time_error"], r["status"], r["n_impacts"], r["flag"]]
            for s in scenes.values() for r in s["rows"]]


def main(argv=None):
    def options(p):
        p.add_argument("--cap", type=float, default=None,
                       help="skip a method's tighter rtols once a run takes longer than this "
                            "(seconds; default 8, 2 with --quick)")

    b = H.Bench(__doc__, argv, options=options)
    quick = b.quick
    cap = b.args.cap if b.args.cap is not None else (2.0 if quick else 8.0)
    simulate(scene_run(1.0, 0.6, 1.3, 2))  # load the kernel

    scenes = {name: run_scene(name, sc, quick, cap) for name, sc in SCENES.items()}
    hard = hard_table(quick)

    b.report("work_precision", markdown=markdown(scenes, hard, cap, quick, b.env),
             csv=(["scene", "method", "setting", "wall_median_s", "n_rhs", "error",
                   "impact_time_error", "status", "n_impacts", "flag"], csv_rows(scenes)),
             data=dict(quick=quick, cap_s=cap, atol_ratio=ATOL_RATIO, n_ref=N_REF, ref2=REF2,
                       ref_dop853=REF_DOP, environment=b.env, scenes=scenes,
                       hard=[dict(method=a, setting=m, status=c, t=d, n_impacts=e)
                             for a, m, c, d, e in hard]),
             figures=[(f"work_precision_{s['name']}.png", plot(s, rockjit.DEFAULT_N), 120)
                      for s in scenes.values()])
    return 0


def plot(s, n_def):
    plt = H.pyplot()
    fig, ax = plt.subplots(figsize=(6.4, 4.6), layout="constrained")
    tiny = 1e-17
    marks = dict(rockjit="o", BDF="s", Radau="D", LSODA="^", RK45="v", DOP853="P")
    for i, m in enumerate(("rockjit",) + METHODS):
        rows = [r for r in s["rows"] if r["method"] == m and not math.isnan(r["wall_s"])
                and not math.isnan(r["error"])]
        good = [r for r in rows if not r["flag"]]
        bad = [r for r in rows if r["flag"]]
        col = f"C{i}"
        if good:
            ax.plot([r["wall_s"] for r in good], [max(r["error"], tiny) for r in good],
                    marker=marks[m], color=col, lw=1.2 if m == "rockjit" else 0.9, ms=4,
                    label=m if m == "rockjit" else f"scipy {m}")
        if bad:
            ax.plot([r["wall_s"] for r in bad], [max(r["error"], tiny) for r in bad], ls="none",
                    marker="x", color=col, ms=7)
        if m == "rockjit":
            for r in good:
                ax.annotate(f"{r['n']}", (r["wall_s"], max(r["error"], tiny)), fontsize=6,
                            xytext=(3, 3), textcoords="offset points",
                            weight="bold" if r["n"] == n_def else None)
        elif good:
            for r in (good[0], good[-1]):
                ax.annotate(f"{r['rtol']:.0e}", (r["wall_s"], max(r["error"], tiny)),
                            fontsize=5, color=col, xytext=(3, -7), textcoords="offset points")
    if s["floor"] > 0:
        ax.axhline(s["floor"], color="0.5", ls="--", lw=0.8, label="reference floor")
    ax.plot([], [], "kx", ls="none", label="other status / impact count")
    ax.set_xscale("log")
    ax.set_yscale("log")
    ax.set_xlabel("wall time per run (s)")
    ax.set_ylabel("error of t_over" if s["measure"] == "overturn" else
                  "final-state error max|d(theta, theta')|")
    ax.set_title(s["title"], fontsize=8)
    ax.grid(True, which="both", alpha=0.25)
    ax.legend(fontsize=6.5, loc="best")
    return fig


if __name__ == "__main__":
    sys.exit(main())
