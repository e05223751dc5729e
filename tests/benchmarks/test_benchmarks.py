"""Every benchmark script still runs: its ``--quick`` mode, into a temporary folder.

Each script of ``benchmarks/`` runs as a user runs it (``python benchmarks/bench_X.py --quick
--out DIR``, in a subprocess importing this checkout), and must exit cleanly and write the files
benchmarks/README.md promises, each readable: the JSON strict (no NaN or Infinity literals:
rockjit's convention writes them as strings), the CSV with the columns the README quotes and a
rectangular body, the PNG a PNG, the Markdown a table. A ``--quick`` run must never touch the
committed results or the README.

The CSV's values are checked too, column by column (:data:`VALUES`): times positive, errors and
differences non-negative (and small where the physics says they must be), counts integral,
statuses and names from their known sets, the comparisons that must come out equal (a cluster
against in-process, two versions of one tree, attractor identity against none) equal. No timing
is asserted beyond being a positive number (timings are the scripts' business). The stress
suite's script may exit with its "checks failed" status only for failures listed in
:data:`EXPECTED_STRESS_FAILURES`.
"""

from __future__ import annotations

import csv
import hashlib
import importlib.util
import json
import math
import os
import subprocess
import sys
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[2]
BENCH = ROOT / "benchmarks"
PNG_MAGIC = b"\x89PNG\r\n\x1a\n"

#: script -> (CSV columns, figures); the columns are the ones the scripts wrote before the
#: harness was shared (benchmarks/README.md and the committed results quote them)
SCRIPTS = {
    "bench_reference_run.py": (
        ["method", "n_steps_or_tol", "forcing", "wall_median_s", "compile_cold_s",
         "compile_cached_s", "final_state_error", "max_impact_time_error", "n_rhs",
         "speedup_vs_bdf"], ["reference_run.png"]),
    "bench_event_accuracy.py": (
        ["orbit", "n_steps", "vs_converged", "vs_dop853_atol_1e-12", "vs_dop853_atol_1e-14"],
        ["event_accuracy.png"]),
    "bench_lyapunov_cost.py": (
        ["n_steps", "wall_median_off_s", "wall_median_on_s", "cost_ratio", "n_rhs", "lambda1",
         "lambda2", "lambda_sum", "identity_rhs", "identity_error"], ["lyapunov_cost.png"]),
    "bench_work_precision.py": (
        ["scene", "method", "setting", "wall_median_s", "n_rhs", "error", "impact_time_error",
         "status", "n_impacts", "flag"],
        [f"work_precision_{s}.png" for s in ("periodic", "chaotic", "overturn",
                                             "overturn_study")]),
    "bench_throughput.py": (["table", "key", "value"], ["throughput.png"]),
    "bench_grids.py": (
        ["item", "case", "n_steps", "wall_median_s", "runs", "target_s", "agreement_percent"],
        ["grids_timing.png", "grids_agreement.png", "grids_sweep_resolution.png"]),
    "bench_paper.py": (
        ["run", "kind", "wall_outside_s", "wall_s", "fig1", "fig2", "fig3", "fig4", "fig5",
         "fig6", "fig7", "fig8"], ["paper.png"]),
    "bench_distributed.py": (
        ["run", "chunks", "wall median s", "ratio to in-process", "overhead per chunk s",
         "identical to in-process"], ["distributed.png"]),
    "bench_ground.py": (
        ["computation", "runs", "compiled_median_s", "compiled_runs_per_s", "target_s",
         "scipy_sampled_runs", "scipy_s_per_run", "scipy_extrapolated_s", "speedup",
         "outcomes_equal", "max_rotation_max_diff", "t_overturn_max_diff"], ["ground.png"]),
    "bench_attractors.py": (["hb", "alpha", "omega", "law", "grid", "without_s", "with_s",
                             "overhead", "measures_s", "n_attractors", "labels_equal"],
                            ["attractors.png"]),
    "bench_safety.py": (["law", "chart", "lattice", "periods", "threads", "wall_s",
                         "s_per_basin", "60x60_s", "60x60", "mean_safe"], ["safety.png"]),
    "bench_cores.py": (["threads", "case", "median s", "speed-up", "yardstick speed-up",
                        "share of the yardstick's", "labels as 1 thread"], ["cores.png"]),
    "bench_orbits.py": (["measurement", "value", "unit", "target"],
                        ["orbits.png", "orbits_branches.png"]),
    "bench_versions.py": (["case", "base_s", "this_s", "ratio", "cpu_ratio", "pair_min",
                           "pair_max", "base_ns_step", "this_ns_step", "identical"],
                          ["versions.png"]),
    "bench_compile.py": (
        ["root", "group", "item", "mode", "n", "wall_s", "wall_min_s", "wall_max_s", "cpu_s",
         "first_call_s", "compile_cpu_s", "compiles", "typing", "ir_inlining", "front_end_other",
         "lowering", "llvm_parse_link", "llvm_opt", "llvm_codegen", "cache", "other"],
        ["compile.png"]),
    "bench_lanes.py": (["basin", "grid", "lanes", "cells_per_s", "ns_per_cell_step",
                        "speedup_vs_1", "scalar_steps", "time_vector", "time_scalar", "bound"],
                       ["lanes.png"]),
    "bench_explore.py": (["measurement", "median_s", "min_s", "max_s", "n", "target_s"], []),
    "bench_mutants.py": (["mutant", "area", "file", "breaks", "tests", "outcome", "seconds"], []),
    "bench_stress.py": (
        ["id", "category", "hb", "alpha", "omega", "law", "e", "n_steps", "periods", "forcing",
         "status", "t", "n_impacts", "n_rhs", "work_bound", "wall_s", "failed_checks"],
        ["stress.png"]),
    "bench_chart.py": (
        ["run", "chart_s", "seeds_s", "curves_s", "total_s", "cpu_s", "cells", "curves",
         "curve_points", "load1"], ["chart.png", "chart_laws.png"]),
    "bench_gpu.py": (
        ["case", "cells", "gpu_s", "cpu_s", "cpu_basis", "speedup", "cells_per_s_gpu",
         "labels_differ", "differ_unflagged", "max_strobe_diff", "measured"], []),
}

#: bench_stress.py exits with this status when the suite ran and its checks found failures
#: (its report and its JSON list them); any other non-zero status is a broken script
STRESS_FOUND_FAILURES = 3

#: Failures the stress suite's quick run may report without the test failing, as (check, case
#: id): none. Every check passes on every quick case today; a failure that is understood and
#: accepted for a while would be listed here, so that any other still fails the test.
EXPECTED_STRESS_FAILURES = frozenset()


# ---------------------------------------------------------------------------------------------
# what a CSV cell may hold

def _float(cell):
    try:
        return float(cell)
    except ValueError:
        return None


def _rule(name, test):
    test.__name__ = name
    return test


def positive(cell):
    x = _float(cell)
    return x is not None and math.isfinite(x) and x > 0


def nonneg(cell):
    x = _float(cell)
    return x is not None and math.isfinite(x) and x >= 0


def finite(cell):
    x = _float(cell)
    return x is not None and math.isfinite(x)


def text(cell):
    return bool(cell.strip())


def count(minimum=0):
    def test(cell):
        x = _float(cell)
        return x is not None and math.isfinite(x) and x == int(x) and x >= minimum
    return _rule(f"an integer >= {minimum}", test)


def between(lo, hi):
    def test(cell):
        x = _float(cell)
        return x is not None and math.isfinite(x) and lo <= x <= hi
    return _rule(f"a number in [{lo:g}, {hi:g}]", test)


def one_of(*values):
    return _rule(f"one of {values}", lambda cell: cell in values)


def empty_or(rule):
    return _rule(f"empty or {rule.__name__}", lambda cell: cell == "" or rule(cell))


def nan_or(rule):
    return _rule(f"nan or {rule.__name__}", lambda cell: cell == "nan" or rule(cell))


def num(row, column):
    return float(row[column])


STRESS_STATUSES = ("done", "overturned", "rest", "max_impacts", "nonfinite", "refused",
                   "raised")
STRESS_CATEGORIES = ("random", "near_zero", "grazing", "near_overturn", "long_horizon",
                     "impact_bound", "stiff_damping", "wide_omega", "through_rest")
STRESS_RUN_CHECKS = ("status", "finite", "time", "work", "bookkeeping", "progress",
                     "rest_exponents")
LAWS = ("housner", "mao", "constant")

#: script -> (rules by column, rules across a row). A quick run is small but real: its
#: numbers must be numbers of the right kind and in a sane range. Columns with no rule are
#: free text.
VALUES = {
    "bench_explore.py": (
        dict(measurement=text, median_s=nan_or(positive), min_s=nan_or(positive),
             max_s=nan_or(positive), n=count(0), target_s=empty_or(positive)),
        [("a stage has times exactly when it ran",
          lambda r: (r["median_s"] == "nan") == (r["n"] == "0")
          == ("not run" in r["measurement"])),
         ("the median lies between the extremes", lambda r: r["n"] == "0"
          or num(r, "min_s") <= num(r, "median_s") <= num(r, "max_s"))]),
    "bench_mutants.py": (
        dict(mutant=text, area=text, file=_rule("a file of the package", lambda c:
                                              c.startswith("rockjit/") and c.endswith(".py")),
             breaks=text, tests=_rule("pytest node ids", lambda c: c.startswith("tests/")),
             outcome=one_of("caught", "caught (timeout)", "caught (error)"), seconds=positive),
        []),
    "bench_chart.py": (
        dict(run=count(0), chart_s=positive, seeds_s=positive, curves_s=positive,
             total_s=positive, cpu_s=positive, cells=count(1), curves=count(1),
             curve_points=count(2), load1=nonneg),
        [("the parts fit in the total", lambda r: num(r, "chart_s") + num(r, "seeds_s")
          + num(r, "curves_s") <= num(r, "total_s") + 1e-6),
         ("each curve has points", lambda r: num(r, "curve_points") >= 2 * num(r, "curves"))]),
    "bench_reference_run.py": (
        dict(method=one_of("rockjit", "scipy BDF (the study's)"), n_steps_or_tol=text,
             forcing=one_of("closed", "embedded"), wall_median_s=positive,
             compile_cold_s=empty_or(_rule("same kernel or a number", lambda c: c == "same "
                                           "kernel" or finite(c))),
             compile_cached_s=empty_or(_rule("same kernel or a number", lambda c: c == "same "
                                             "kernel" or finite(c))),
             final_state_error=between(0, 1e-3), max_impact_time_error=between(0, 1e-2),
             n_rhs=count(1), speedup_vs_bdf=positive),
        [("the BDF path is the speed-ups' unit", lambda r: r["method"] == "rockjit"
          or num(r, "speedup_vs_bdf") == 1.0)]),
    "bench_event_accuracy.py": (
        dict(orbit=text, n_steps=count(8), vs_converged=between(0, 1e-6),
             **{"vs_dop853_atol_1e-12": between(0, 1e-6),
                "vs_dop853_atol_1e-14": between(0, 1e-6)}),
        []),
    "bench_lyapunov_cost.py": (
        dict(n_steps=count(8), wall_median_off_s=positive, wall_median_on_s=positive,
             cost_ratio=positive, n_rhs=count(1), lambda1=finite, lambda2=finite,
             lambda_sum=finite, identity_rhs=finite, identity_error=between(0, 1e-6)),
        [("lambda1 >= lambda2", lambda r: num(r, "lambda1") >= num(r, "lambda2")),
         ("lambda_sum = lambda1 + lambda2", lambda r: abs(
             num(r, "lambda1") + num(r, "lambda2") - num(r, "lambda_sum")) < 1e-12)]),
    "bench_work_precision.py": (
        dict(scene=one_of("periodic", "chaotic", "overturn", "overturn_study"),
             method=one_of("rockjit", "BDF", "Radau", "LSODA", "RK45", "DOP853"),
             setting=text, wall_median_s=nan_or(positive), n_rhs=empty_or(count(1)),
             error=nan_or(nonneg), impact_time_error=nan_or(nonneg),
             status=empty_or(one_of("done", "overturned", "rest", "max_impacts")),
             n_impacts=empty_or(count(0))),
        [("rockjit is timed and ends as the reference does", lambda r: r["method"] != "rockjit"
          or (positive(r["wall_median_s"]) and nonneg(r["error"]) and not r["flag"])),
         ("a run that was made has a status, a time and its work", lambda r:
          r["flag"].startswith("skipped") or (r["status"] != "" and positive(r["wall_median_s"])
                                              and count(1)(r["n_rhs"])))]),
    "bench_throughput.py": (
        # call_overhead_us positive: no path costs less than the compiled run alone
        dict(table=one_of("ns_per_step", "micro_ns", "call_us", "call_overhead_us",
                          "trajectories_per_s", "basin_size_wall_s", "basin_periods_wall_s",
                          "threads_speedup", "lyapunov_ratio", "compile_cold_s",
                          "compile_cached_s", "memory_peak_mib"),
             key=text, value=positive),
        []),
    "bench_grids.py": (
        dict(item=text, case=text, n_steps=one_of("64", "128", "256"), wall_median_s=positive,
             runs=count(1), target_s=empty_or(positive),
             agreement_percent=empty_or(between(0, 100))),
        []),
    "bench_paper.py": (
        dict(run=count(0), kind=one_of("cold", "second", "warm-up", "warm"),
             wall_outside_s=positive, wall_s=positive,
             **{f"fig{k}": nonneg for k in range(1, 9)}),
        [("the whole command takes longer than its own parts", lambda r:
          num(r, "wall_outside_s") >= num(r, "wall_s"))]),
    "bench_distributed.py": (
        {"run": text, "chunks": count(1), "wall median s": positive,
         "ratio to in-process": positive, "overhead per chunk s": empty_or(finite),
         "identical to in-process": one_of("yes")},
        []),
    "bench_ground.py": (
        dict(computation=text, runs=count(1), compiled_median_s=positive,
             compiled_runs_per_s=positive, target_s=empty_or(positive),
             scipy_sampled_runs=count(1), scipy_s_per_run=positive,
             scipy_extrapolated_s=positive, speedup=positive,
             outcomes_equal=_rule("k/k: every sampled outcome the same",
                                  lambda c: len(set(c.split("/"))) == 1 and c[0] != "0"),
             max_rotation_max_diff=between(0, 1e-6), t_overturn_max_diff=between(0, 1e-6)),
        [("the extrapolation is per run times runs", lambda r: abs(
            num(r, "scipy_extrapolated_s") - num(r, "scipy_s_per_run") * num(r, "runs"))
          <= 1e-9 * num(r, "scipy_extrapolated_s"))]),
    "bench_attractors.py": (
        dict(hb=positive, alpha=nonneg, omega=positive, law=one_of(*LAWS), grid=count(1),
             without_s=positive, with_s=positive,
             overhead=_rule("a number > -1", lambda c: finite(c) and float(c) > -1),
             measures_s=nonneg, n_attractors=count(1), labels_equal=one_of("True")),
        [("overhead = with / without - 1", lambda r: abs(
            num(r, "with_s") / num(r, "without_s") - 1 - num(r, "overhead")) < 1e-9)]),
    "bench_safety.py": (
        {"law": one_of(*LAWS), "chart": text, "lattice": count(2), "periods": count(1),
         "threads": count(1), "wall_s": positive, "s_per_basin": positive,
         "60x60_s": positive, "60x60": one_of("measured", "extrapolated"),
         "mean_safe": between(0, 1)},
        [("the 60x60 time is 3600 basins at the time per basin", lambda r: abs(
            num(r, "60x60_s") - 3600 * num(r, "s_per_basin")) <= 1e-2 * num(r, "60x60_s"))]),
    "bench_cores.py": (
        {"threads": count(1), "case": text, "median s": positive, "speed-up": positive,
         "yardstick speed-up": positive, "share of the yardstick's": positive,
         "labels as 1 thread": one_of("yes", "—")},
        [("the share is the speed-up over the yardstick's", lambda r: abs(
            num(r, "speed-up") / num(r, "yardstick speed-up")
            - num(r, "share of the yardstick's")) <= 1e-9),
         ("one thread is the unit", lambda r: r["threads"] != "1"
          or num(r, "speed-up") == 1.0),
         ("the yardstick has no labels, every basin the one-thread labels", lambda r:
          (r["labels as 1 thread"] == "—") == (r["case"] == "yardstick"))]),
    "bench_orbits.py": ({}, []),  # its values are checked where its conversion is
    "bench_versions.py": (
        dict(case=one_of("run", "run+lyapunov", "basin", "sweep"), base_s=positive,
             this_s=positive, ratio=positive, cpu_ratio=positive, pair_min=positive,
             pair_max=positive, base_ns_step=empty_or(positive),
             this_ns_step=empty_or(positive), identical=one_of("True")),
        [("pair_min <= pair_max", lambda r: num(r, "pair_min") <= num(r, "pair_max")),
         ("ns per step for the single runs only", lambda r:
          (r["base_ns_step"] != "") == r["case"].startswith("run"))]),
    "bench_compile.py": (
        dict(root=text, group=one_of("kernel", "command", "speed"), item=text,
             mode=one_of("cold", "warm"), n=count(1), wall_s=positive, wall_min_s=positive,
             wall_max_s=positive, cpu_s=empty_or(nonneg), first_call_s=empty_or(positive),
             compile_cpu_s=empty_or(nonneg), compiles=empty_or(count(0)),
             **{k: empty_or(between(-1e-6, 1e4)) for k in (
                 "typing", "ir_inlining", "front_end_other", "lowering", "llvm_parse_link",
                 "llvm_opt", "llvm_codegen", "cache", "other")}),
        [("wall_min_s <= wall_s <= wall_max_s", lambda r:
          num(r, "wall_min_s") <= num(r, "wall_s") <= num(r, "wall_max_s")),
         ("a kernel's cold process compiles", lambda r: r["group"] != "kernel"
          or r["mode"] != "cold" or num(r, "compiles") >= 1)]),
    "bench_lanes.py": (
        dict(basin=one_of("full length", "early stop"), grid=text,
             lanes=one_of("1", "2", "4", "8"), cells_per_s=positive, ns_per_cell_step=positive,
             speedup_vs_1=positive, scalar_steps=empty_or(between(0, 1)),
             time_vector=empty_or(between(0, 1)), time_scalar=empty_or(between(0, 1)),
             bound=empty_or(positive)),
        [("one lane is the unit of the speed-ups and has no cycle counts; more have them",
          lambda r: (num(r, "speedup_vs_1") == 1.0 and r["bound"] == "") if r["lanes"] == "1"
          else r["bound"] != "")]),
    "bench_gpu.py": (
        dict(case=text, cells=count(1), gpu_s=empty_or(positive),
             cpu_s=empty_or(nan_or(positive)), speedup=empty_or(nan_or(positive)), cells_per_s_gpu=empty_or(positive),
             labels_differ=empty_or(count(0)), differ_unflagged=empty_or(count(0)),
             max_strobe_diff=empty_or(nan_or(nonneg)), measured=one_of("yes", "no")),
        [("a case not measured has no times; a measured one has its GPU time",
          lambda r: (r["measured"] == "no") == (r["gpu_s"] == "")),
         ("no more cells differ, not flagged, than differ", lambda r:
          r["differ_unflagged"] == "" or num(r, "differ_unflagged") <= num(r, "labels_differ"))]),
    "bench_stress.py": (
        dict(id=text, category=one_of(*STRESS_CATEGORIES), hb=positive, alpha=nonneg,
             omega=positive, law=one_of(*LAWS), e=empty_or(between(0, 1)), n_steps=count(8),
             periods=count(1), forcing=one_of("closed", "embedded"),
             status=one_of(*STRESS_STATUSES), t=empty_or(nonneg), n_impacts=empty_or(count(0)),
             n_rhs=empty_or(count(1)), work_bound=empty_or(count(1)), wall_s=positive,
             failed_checks=_rule("check names", lambda c: c == "" or set(c.split(";"))
                                 <= set(STRESS_RUN_CHECKS))),
        [("a run that went through has its time, impacts and work; a refused one none",
          lambda r: (r["status"] in ("refused", "raised")) == (r["t"] == "")),
         ("work within the bound", lambda r: r["n_rhs"] == ""
          or num(r, "n_rhs") <= num(r, "work_bound")),
         ("a known final status unless a check failed", lambda r: r["failed_checks"] != ""
          or r["status"] in ("done", "overturned", "rest", "max_impacts", "refused"))]),
}


def check_values(script, rows):
    """Every cell of a CSV body against :data:`VALUES`; the problems found, as text."""
    header, body = rows[0], rows[1:]
    rules, row_rules = VALUES[script]
    assert set(rules) <= set(header), f"{script}: rules for absent columns"
    problems = []
    for i, cells in enumerate(body, start=2):
        row = dict(zip(header, cells))
        for column, rule in rules.items():
            if not rule(row[column]):
                problems.append(f"line {i}, {column} = {row[column]!r}: not {rule.__name__}")
        for what, rule in row_rules:
            try:
                ok = rule(row)
            except (ValueError, KeyError, ZeroDivisionError) as exc:
                ok, what = False, f"{what} ({type(exc).__name__}: {exc})"
            if not ok:
                problems.append(f"line {i}: {what}: {row}")
    return problems


def stress_failures(data):
    """``{(check, case id)}`` of the failures bench_stress.py's JSON lists."""
    found = {(check, f["id"]) for check, fs in data["run_failures"].items() for f in fs}
    found |= {(check, f["id"]) for check, e in data["exact"].items() for f in e["failed"]}
    return found


def _env():
    path = os.environ.get("PYTHONPATH", "")
    return dict(os.environ, PYTHONPATH=str(ROOT) + (os.pathsep + path if path else ""),
                MPLBACKEND="Agg")


def _run(script, *args, cwd, timeout=600):
    return subprocess.run([sys.executable, str(BENCH / script), *args], cwd=cwd, env=_env(),
                          capture_output=True, text=True, timeout=timeout)


def _strict(name):
    raise ValueError(f"{name} is not strict JSON")


def _fingerprint():
    """The committed results and the README, as they are on disk."""
    files = sorted(p for p in (BENCH / "results").glob("*") if p.is_file())
    files.append(BENCH / "README.md")
    return {p.name: hashlib.sha256(p.read_bytes()).hexdigest() for p in files}


def test_every_script_is_tested():
    assert sorted(p.name for p in BENCH.glob("bench_*.py")) == sorted(SCRIPTS)


def test_every_script_has_its_value_rules():
    assert sorted(VALUES) == sorted(SCRIPTS)


@pytest.mark.parametrize("script", ["bench_stress.py", "bench_versions.py"])
def test_the_value_rules_can_fail(script):
    header = SCRIPTS[script][0]
    good = {"bench_stress.py": ["s0-0", "random", "1.8", "0.0", "0.05", "mao", "", "160", "5",
                                "closed", "overturned", "1.99", "1", "146", "37909", "0.0007",
                                ""],
            "bench_versions.py": ["run", "0.1", "0.1", "1.0", "1.0", "0.9", "1.1", "70", "71",
                                  "True"]}[script]
    assert check_values(script, [header, good]) == []
    bad = dict(zip(header, good))
    if script == "bench_stress.py":
        bad.update(n_rhs="40000", status="nonfinite")  # over the bound, unchecked NaN
    else:
        bad.update(identical="False", this_s="nan")
    problems = check_values(script, [header, [bad[c] for c in header]])
    assert len(problems) >= 2, problems


def test_stress_failures_are_read_from_its_json():
    data = dict(run_failures=dict(work=[dict(id="s0-3")], status=[]),
                exact=dict(threads=dict(failed=[dict(id="t0-1")]), energy=dict(failed=[])))
    assert stress_failures(data) == {("work", "s0-3"), ("threads", "t0-1")}


@pytest.mark.slow
@pytest.mark.parametrize("script", sorted(SCRIPTS))
def test_quick_mode_writes_what_it_promises(script, tmp_path):
    if script == "bench_distributed.py":
        pytest.importorskip("dask.distributed")
    columns, figures = SCRIPTS[script]
    name = script[len("bench_"):-len(".py")]
    before = _fingerprint()
    out = tmp_path / "out"
    proc = _run(script, "--quick", "--out", str(out), cwd=tmp_path)
    ok = (0, STRESS_FOUND_FAILURES) if script == "bench_stress.py" else (0,)
    assert proc.returncode in ok, proc.stdout[-2000:] + proc.stderr[-4000:]

    md = (out / f"{name}.md").read_text(encoding="utf-8")
    assert "|---|" in md

    data = json.loads((out / f"{name}.json").read_text(encoding="utf-8"),
                      parse_constant=_strict)
    assert isinstance(data, dict) and data

    with open(out / f"{name}.csv", newline="", encoding="utf-8") as f:
        rows = list(csv.reader(f))
    assert rows[0] == columns
    assert len(rows) > 1 and all(len(r) == len(columns) for r in rows[1:])
    problems = check_values(script, rows)
    assert not problems, f"{script}: {len(problems)} bad values:\n" + "\n".join(problems[:20])

    if script == "bench_stress.py":
        found = stress_failures(data)
        # the exit status says whether the checks failed, the report lists them, and only the
        # expected ones may fail
        assert proc.returncode == (STRESS_FOUND_FAILURES if found else 0), sorted(found)
        assert ("Failures (rerun one with" in md) == bool(found)
        assert not found - EXPECTED_STRESS_FAILURES, sorted(found - EXPECTED_STRESS_FAILURES)
        listed = {(c, r[0]) for r in rows[1:] for c in r[-1].split(";") if c}
        assert listed <= found, sorted(listed - found)

    for fig in figures:
        assert (out / fig).read_bytes()[:8] == PNG_MAGIC, fig
    assert _fingerprint() == before  # a smoke run never touches the committed results


def test_quick_refuses_to_write_the_committed_results(tmp_path):
    before = _fingerprint()
    proc = _run("bench_event_accuracy.py", "--quick", "--out", str(BENCH / "results"),
                cwd=tmp_path, timeout=120)
    assert proc.returncode == 2
    assert "--quick never writes to benchmarks/results/" in proc.stderr
    assert _fingerprint() == before


def test_quick_defaults_to_the_ignored_quick_folder(tmp_path):
    code = ("import _common as H; "
            "b = H.Bench('doc', ['--quick']); "
            "print(b.out_path.resolve(), b.publishes); "
            "b = H.Bench('doc', []); "
            "print(b.out_path.resolve(), b.publishes)")
    env = _env()
    env["PYTHONPATH"] = str(BENCH) + os.pathsep + env["PYTHONPATH"]
    proc = subprocess.run([sys.executable, "-c", code], cwd=tmp_path, env=env,
                          capture_output=True, text=True, timeout=120)
    assert proc.returncode == 0, proc.stderr
    lines = [x for x in proc.stdout.splitlines() if not x.startswith("Measured on")]
    assert lines[-2] == f"{(BENCH / 'results' / 'quick').resolve()} False"
    assert lines[-1] == f"{(BENCH / 'results').resolve()} True"


#: The modules each peer needs (the optional extra ``peers``).
PEER_MODULES = {"cvode": ("sksundae",), "diffrax": ("jax", "diffrax", "optimistix"),
                "nbkode": ("nbkode",)}


@pytest.mark.slow
def test_peers_quick_mode_checks_before_it_times(tmp_path):
    """benchmarks/peers/bench_peers.py --quick, with whichever peers are installed
    (``pip install -e ".[peers]"``; CI installs ".[test]", which has none). Each peer that does
    not import is reported as missing, with the reason, and left out, and the rest of the run
    (rockjit and scipy's work-precision, the basin) still writes every file. Each peer that
    imports must pass the quick run's own correctness checks: the reference run's impact count
    and times (against rockjit at N = 8192) and the basin's labels (against
    ``rockjit.basin``) on its subgrid, each peer's model written independently."""
    installed = sorted(name for name, mods in PEER_MODULES.items()
                       if all(importlib.util.find_spec(m) is not None for m in mods))
    before = _fingerprint()
    out = tmp_path / "out"
    proc = _run("peers/bench_peers.py", "--quick", "--out", str(out), cwd=tmp_path,
                timeout=1800)
    assert proc.returncode == 0, proc.stdout[-2000:] + proc.stderr[-4000:]
    md = (out / "peers.md").read_text(encoding="utf-8")
    assert "|---|" in md
    data = json.loads((out / "peers.json").read_text(encoding="utf-8"),
                      parse_constant=_strict)
    assert sorted(data["checks"]) == installed, data.get("missing")
    assert sorted(data["missing"]) == sorted(set(PEER_MODULES) - set(installed))
    for peer, why in data["missing"].items():
        assert why.startswith(("ModuleNotFoundError", "ImportError")), (peer, why)
        assert f"{peer} ({why})" in md  # the table says which peers are not there, and why
    for peer, check in data["checks"].items():
        assert check["reference"] and check["basin"], (peer, check["why"])
    assert sorted(row["peer"] for row in data["reference_check"]) == installed
    for row in data["reference_check"]:
        assert row["n_impacts"] == row["ref_n_impacts"] > 0, row
    assert data["reference"]["n_impacts"] > 0  # rockjit's own reference run, peers or not
    methods = {r["method"] for s in data["scenes"].values() for r in s["rows"]}
    assert {"rockjit", "scipy DOP853"} <= methods
    with open(out / "peers.csv", newline="", encoding="utf-8") as f:
        rows = list(csv.reader(f))
    # the CSV's column names (its timings are the benchmark's, never checked here)
    assert rows[0] == ["scene", "method", "setting", "wall_median_s", "error", "status",
                       "n_impacts", "flag"]
    assert len(rows) > 1 and all(len(r) == len(rows[0]) for r in rows[1:])
    for fig in ("peers_wp_periodic.png", "peers_wp_chaotic.png", "peers_basin.png"):
        assert (out / fig).read_bytes()[:8] == PNG_MAGIC, fig
    assert _fingerprint() == before  # a smoke run never touches the committed results
