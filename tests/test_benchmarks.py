"""Every benchmark script still runs: its ``--quick`` mode, into a temporary folder.

Each script of ``benchmarks/`` runs as a user runs it (``python benchmarks/bench_X.py --quick
--out DIR``, in a subprocess importing this checkout), and must exit cleanly and write the files
benchmarks/README.md promises, each readable: the JSON strict (no NaN or Infinity literals:
rockjit's convention writes them as strings), the CSV with the columns the README quotes and a
rectangular body, the PNG a PNG, the Markdown a table. A ``--quick`` run must never touch the
committed results or the README. No timing is asserted (timings are the scripts' business).
"""

from __future__ import annotations

import csv
import hashlib
import importlib.util
import json
import os
import subprocess
import sys
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parent.parent
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
    "bench_attractors.py": (["hb", "alpha", "omega", "law", "grid", "without_s", "with_s",
                             "overhead", "measures_s", "n_attractors", "labels_equal"],
                            ["attractors.png"]),
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
    "bench_stress.py": (
        ["id", "category", "hb", "alpha", "omega", "law", "e", "n_steps", "periods", "forcing",
         "status", "t", "n_impacts", "n_rhs", "work_bound", "wall_s", "failed_checks"],
        ["stress.png"]),
}

#: bench_stress.py exits with this status when the suite ran and its checks found failures
#: (tests/test_stress.py is where they must be 0); any other non-zero status is a broken script
STRESS_FOUND_FAILURES = 3


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
    if proc.returncode == STRESS_FOUND_FAILURES:
        assert "Failures (rerun one with" in md

    data = json.loads((out / f"{name}.json").read_text(encoding="utf-8"),
                      parse_constant=_strict)
    assert isinstance(data, dict) and data

    with open(out / f"{name}.csv", newline="", encoding="utf-8") as f:
        rows = list(csv.reader(f))
    assert rows[0] == columns
    assert len(rows) > 1 and all(len(r) == len(columns) for r in rows[1:])

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
    ``rockjit.grids.grids.basin``) on its subgrid, each peer's model written independently."""
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
    assert [row["peer"] for row in data["reference_check"]] == installed
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
