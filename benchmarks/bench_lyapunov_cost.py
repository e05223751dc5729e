"""Issue 3: what the Lyapunov exponents cost, on the study's reference run.

The run: hb=1, alpha=0.6, omega=1.3, Housner restitution, z0 = rockjit.Z0_STUDY, 500 periods,
exponents averaged over the last 100 (SPEC.md §5, §7). Measured side by side in one process, in
alternating order: ``lyapunov=False`` against ``lyapunov=True`` (tangent dynamics and saltation
matrices compiled in) at the default N and at N=64; compile time of each kernel measured apart in
fresh processes. Also reported: lambda1, lambda2, and the exact identity
``lambda1 + lambda2 = -3/4 xi + 2 nu ln(e)`` with ``nu = n_impacts_window / window length``.

There is no scipy variational path: exponents exist only on the compiled path, so there is no
reference timing to compare with.

    python benchmarks/bench_lyapunov_cost.py           # full measurement (~1 min)
    python benchmarks/bench_lyapunov_cost.py --quick   # smoke mode (20 periods)

Writes lyapunov_cost.{md,csv,json,png} to benchmarks/results/ (benchmarks/results/quick/ with
--quick, or --out DIR).
"""

from __future__ import annotations

import math
import sys
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parent))
import _common as C  # noqa: E402

import rockjit  # noqa: E402


def identity(res):
    """``(lambda1 + lambda2, -3/4 xi + 2 nu ln e, nu)`` over the run's window (SPEC.md §5)."""
    b = res.block
    t0, t1 = res.window
    nu = res.n_impacts_window / (t1 - t0)
    return float(np.sum(res.lyapunov)), -0.75 * b.xi + 2.0 * nu * math.log(b.restitution), nu


def main(argv=None):
    args = C.parser(__doc__.splitlines()[0]).parse_args(argv)
    out = C.out_dir(args)
    quick = args.quick
    periods = 20 if quick else 500
    repeats = 3 if quick else 21
    n_def = rockjit.DEFAULT_N
    ns = [n_def] + [n for n in (64,) if n != n_def]
    base = dict(C.REFERENCE_RUN, z0=rockjit.Z0_STUDY, periods=periods)

    def run(n, lyap):
        return rockjit.simulate(**base, n_steps=n, lyapunov=lyap)

    env = C.environment()
    print(C.env_line(env))

    first_inproc = {}
    for lyap in (False, True):
        first_inproc[lyap], _ = C.timed(run, n_def, lyap)
        print(f"first call in process, lyapunov={lyap}: {first_inproc[lyap]:.3f} s")

    results = {}

    def keep(key):
        def call():
            results[key] = run(*key)
        return call

    # (N, False), (N, True) adjacent: the rotation of C.interleaved alternates which goes first
    cases = {(n, lyap): keep((n, lyap)) for n in ns for lyap in (False, True)}
    times = C.interleaved(cases, repeats)
    med = {k: C.median(v) for k, v in times.items()}

    compile_info = {}
    for lyap in (False, True):
        warm = med[(n_def, lyap)]
        if quick:
            compile_info[lyap] = dict(cold=None, cached=None, inproc_s=first_inproc[lyap] - warm)
        else:
            ct = C.compile_times(dict(base, n_steps=n_def, lyapunov=lyap))
            compile_info[lyap] = dict(inproc_s=first_inproc[lyap] - warm, **ct)
            print(f"compile lyapunov={lyap}: cold {ct['cold']['compile_s']:.2f} s, "
                  f"cached {ct['cached']['compile_s']:.2f} s")

    # ---- cost table
    cost_headers = ["N", "lyapunov=False (s)", "lyapunov=True (s)", "cost ratio", "n_rhs",
                    "impacts"]
    cost_rows, records = [], []
    for n in ns:
        r0, r1 = results[(n, False)], results[(n, True)]
        # the tangent kernel is a separate compilation: its trajectory may round differently
        same_path = dict(n_rhs_equal=r0.n_rhs == r1.n_rhs,
                         state_difference=float(np.max(np.abs(r0.state - r1.state))))
        ratio = med[(n, True)] / med[(n, False)]
        cost_rows.append([f"{n}" + (" (default)" if n == n_def else ""), med[(n, False)],
                          med[(n, True)], ratio, r1.n_rhs, r1.n_impacts])
        s, rhs, nu = identity(r1)
        records.append(dict(n_steps=n, wall_median_off_s=med[(n, False)],
                            wall_median_on_s=med[(n, True)], cost_ratio=ratio,
                            wall_all_off_s=times[(n, False)], wall_all_on_s=times[(n, True)],
                            n_rhs=r1.n_rhs, n_impacts=r1.n_impacts,
                            lambda1=float(r1.lyapunov[0]), lambda2=float(r1.lyapunov[1]),
                            lambda_sum=s, identity_rhs=rhs, identity_error=abs(s - rhs), nu=nu,
                            n_impacts_window=r1.n_impacts_window, n_rest_window=r1.n_rest_window,
                            window=list(r1.window), status=r1.status,
                            on_vs_off=same_path))

    # ---- exponents table
    lam_headers = ["N", "lambda1", "lambda2", "lambda1 + lambda2", "-3/4 xi + 2 nu ln e",
                   "identity error", "nu (impacts / unit time)", "rest phases in window"]
    lam_rows = [[r["n_steps"], r["lambda1"], r["lambda2"], r["lambda_sum"], r["identity_rhs"],
                 r["identity_error"], r["nu"], r["n_rest_window"]] for r in records]

    comp_headers = ["kernel", "compile, cold (s)", "compile, cached (s)"]
    comp_rows = []
    for lyap in (False, True):
        ci = compile_info[lyap]
        name = "lyapunov=True (tangent)" if lyap else "lyapunov=False"
        if ci["cold"] is None:
            comp_rows.append([name + " [in-process first call]", ci["inproc_s"], None])
        else:
            comp_rows.append([name, ci["cold"]["compile_s"], ci["cached"]["compile_s"]])

    r_def = results[(n_def, True)]
    w0, w1 = r_def.window
    md_text = "".join([
        f"### Lyapunov cost: reference run, {periods} periods, window "
        f"[{w0 / r_def.period:.0f}T, {w1 / r_def.period:.0f}T]"
        f"{' (QUICK MODE)' if quick else ''}\n",
        C.md_table(cost_headers, cost_rows),
        f"\nMedians of {repeats} warm runs each, the four cases interleaved in one process in "
        f"rotating order. Ratio = with / without exponents. There is no scipy variational path "
        f"(exponents are computed only by the compiled integrator), so no reference timing.\n\n",
        C.md_table(lam_headers, lam_rows),
        "\nIdentity (SPEC.md §5): lambda1 + lambda2 = -3/4 xi + 2 nu ln e over the window, "
        f"xi = {r_def.block.xi:.6g}, e = {r_def.block.restitution:.6g}.\n\n",
        C.md_table(comp_headers, comp_rows),
        "\nCompile: first call in a fresh process minus the warm median; cold = empty numba "
        "cache, cached = the cache the cold process wrote.\n",
        f"\n{C.env_line(env)}\n"])
    C.write_text(out / "lyapunov_cost.md", md_text)
    C.update_readme(args, "lyapunov_cost", md_text)
    C.write_csv(out / "lyapunov_cost.csv",
                ["n_steps", "wall_median_off_s", "wall_median_on_s", "cost_ratio", "n_rhs",
                 "lambda1", "lambda2", "lambda_sum", "identity_rhs", "identity_error"],
                [[r[k] for k in ("n_steps", "wall_median_off_s", "wall_median_on_s",
                                 "cost_ratio", "n_rhs", "lambda1", "lambda2", "lambda_sum",
                                 "identity_rhs", "identity_error")] for r in records])
    C.write_json(out / "lyapunov_cost.json", dict(
        run=dict(base, z0=list(rockjit.Z0_STUDY)), quick=quick, repeats=repeats,
        default_n=n_def, environment=env, rows=records,
        compile={str(k): v for k, v in compile_info.items()},
        first_call_in_process_s={str(k): v for k, v in first_inproc.items()},
        lyapunov_running={str(n): results[(n, True)].lyapunov_running for n in ns}))
    C.check_unchanged(env)
    plot(out / "lyapunov_cost.png", ns, results, n_def)
    print(md_text)
    return 0


def plot(path, ns, results, n_def):
    plt = C.pyplot()
    fig, ax = plt.subplots(figsize=(6.4, 4.2), layout="constrained")
    r = results[(n_def, True)]
    k = np.arange(r.lyapunov_running.shape[0])
    for j, c in ((0, "C0"), (1, "C1")):
        ax.plot(k[1:], r.lyapunov_running[1:, j], color=c, lw=1.2,
                label=f"lambda{j + 1}(t), N={n_def}")
        ax.axhline(r.lyapunov[j], color=c, ls="--", lw=0.8,
                   label=f"lambda{j + 1} over window = {r.lyapunov[j]:.4f}")
    for n in ns:
        if n != n_def:
            rr = results[(n, True)]
            ax.plot(k[1:], rr.lyapunov_running[1:, 0], color="k", lw=0.6, ls=":",
                    label=f"lambda1(t), N={n}")
    ax.axvspan(r.window[0] / r.period, r.window[1] / r.period, color="0.9", zorder=0,
               label="averaging window")
    ax.set_xscale("log")
    ax.set_xlabel("t / T (periods)")
    ax.set_ylabel("running estimate lambda(t)")
    ax.set_title("Reference run (hb=1, alpha=0.6, omega=1.3, Housner): running exponents",
                 fontsize=9)
    ax.legend(fontsize=7)
    ax.grid(True, alpha=0.3)
    C.save_figure(fig, path, dpi=130)
    plt.close(fig)


if __name__ == "__main__":
    sys.exit(main())
