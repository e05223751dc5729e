"""The command line and the atomic writers.

Commands run in-process through ``rockjit.cli.main`` on tiny settings; they share three
compiled kernel variants (single run with exponents and recording, sweep grid with exponents,
basin grid without), so that the module stays quick.
"""

import errno
import fnmatch
import json
import math
import os
import subprocess
import sys
import tempfile
from pathlib import Path

import numpy as np
import pytest

import rockjit
from rockjit import outputs
from rockjit.grids import plan as grid_plan
from rockjit.storage import atomic as rio
from rockjit import BEHAVIOURS, Block, Harmonic, Integration
from rockjit.cli.main import OUTPUTS, main

TINY = ["--periods", "20", "--n-steps", "64", "--quiet"]
PNG = b"\x89PNG\r\n\x1a\n"
BASIN = ["basin", "--hb", "1", "--alpha", "0.66", "--omega", "1.3", "--grid", "6"] + TINY


def _summary(d):
    s = json.loads((d / "summary.json").read_text())
    # every file a command writes is one the command line checks for before any work (a
    # directory of that name inside --out is refused then, not when publishing)
    declared = OUTPUTS[s["command"]] + ("summary.json", ".rockjit-files.json")
    for entry in s["files"]:
        name = entry["name"]
        assert entry["holds"], f"{name}: summary.json says nothing of what it holds"
        assert any(fnmatch.fnmatchcase(name, pattern) for pattern in declared), \
            f"{name}: add it to rockjit.cli.main.OUTPUTS[{s['command']!r}]"
    return s


def _is_png(path):
    return path.read_bytes()[:8] == PNG


def _check_fractions(fr):
    assert list(fr) == list(BEHAVIOURS)
    assert sum(fr.values()) == pytest.approx(100.0)


def _no_temp_files(root):
    return not [p for p in root.rglob("*") if p.name.endswith(rio.TMP_SUFFIX)]


# ---------------------------------------------------------------------------------------------
# the commands
# ---------------------------------------------------------------------------------------------

def test_trajectory(tmp_path):
    out = tmp_path / "traj"
    rc = main(["trajectory", "--hb", "1", "--alpha", "0.6", "--omega", "1.3", "--lyapunov",
               "--max-points", "300", "--out", str(out)] + TINY)
    assert rc == 0
    z = np.load(out / "trajectory.npz")
    for key in ("t", "theta", "dtheta", "strobe", "impacts", "lyapunov_running"):
        assert key in z.files
    assert 2 <= z["t"].size <= 300
    assert z["strobe"].shape == (21, 4) and z["lyapunov_running"].shape == (21, 2)
    np.testing.assert_allclose(z["strobe"][0], rockjit.Z0_STUDY, atol=1e-4)
    s = _summary(out)
    assert s["status"] == "done" and s["behaviour"] == "symmetric"
    assert float(s["lambda_max"]) < 0 and s["rockjit_version"] == rockjit.__version__
    run_time = s["wall_s"]  # recorded, not judged: timing belongs to benchmarks/
    assert s["inputs"]["alpha"] == 0.6 and isinstance(run_time, float)
    assert _is_png(out / "trajectory.png")


def test_sweep(tmp_path):
    out = tmp_path / "sweep"
    rc = main(["sweep", "--hb", "1", "--omega", "1.3", "--alpha-range", "0.5", "1.0",
               "--alpha-step", "0.05", "--out", str(out)] + TINY)
    assert rc == 0
    z = np.load(out / "sweep.npz")
    n = 11
    np.testing.assert_allclose(z["alpha"], 0.5 + 0.05 * np.arange(n))
    assert z["label"].shape == z["period"].shape == z["lambda_max"].shape == (n,)
    assert z["strobe"].ndim == 3 and z["strobe"].shape[0] == n and z["strobe"].shape[2] == 2
    assert z["impact_section"].shape[0] == n
    assert list(z["names"]) == list(BEHAVIOURS) and z["label"].max() < len(z["names"])
    s = _summary(out)
    _check_fractions(s["fractions"])
    for name, pct in s["fractions"].items():
        code = BEHAVIOURS.index(name)
        assert pct == pytest.approx(100 * np.mean(z["label"] == code))
    assert s["n_alpha"] == n
    assert _is_png(out / "bifurcation.png")


def test_basin_one_law(tmp_path):
    out = tmp_path / "basin"
    assert main(BASIN + ["--law", "mao", "--out", str(out)]) == 0
    z = np.load(out / "basin.npz")
    np.testing.assert_allclose(z["theta0"], np.linspace(-1, 1, 6))
    np.testing.assert_allclose(z["dtheta0"], np.linspace(-1, 1, 6))
    assert z["label"].shape == (6, 6) and z["label"].dtype.kind == "i"
    assert set(np.unique(z["label"])) <= set(range(len(z["names"])))
    assert list(z["names"]) == list(BEHAVIOURS)
    s = _summary(out)
    _check_fractions(s["fractions"])
    assert s["law"] == "mao" and s["r0"] == 0.0 and s["s0"] == 1.0
    assert _is_png(out / "basin.png")


def test_basin_both_laws_and_orientation(tmp_path):
    out = tmp_path / "both"
    assert main(BASIN + ["--law", "both", "--out", str(out)]) == 0
    z = np.load(out / "basin.npz")
    lh, lm = z["label_housner"], z["label_mao"]
    assert lh.shape == lm.shape == (6, 6) and "label" not in z.files
    s = _summary(out)
    for law in ("housner", "mao"):
        _check_fractions(s[law]["fractions"])
    assert 0 <= s["agreement"] <= 100
    assert s["agreement"] == pytest.approx(100.0 * np.count_nonzero(lh == lm) / lh.size)
    # label[i, j] belongs to theta0[i], dtheta0[j]: check a cell the transpose would get wrong
    over = BEHAVIOURS.index("overturn")
    cells = [(i, j) for i in range(6) for j in range(6)
             if (lh[i, j] == over) != (lh[j, i] == over)]
    assert cells, "the test needs a basin that is not symmetric under transposition"
    i, j = cells[0]
    r = rockjit.simulate(Block(1.0, "housner"), Harmonic(alpha=0.66, omega=1.3, r0=0.0, s0=1.0),
                         (z["theta0"][i], z["dtheta0"][j]),
                         integration=Integration(periods=20, n_steps=64), lyapunov=True,
                         record_stride=64)
    assert (r.status == "overturned") == (lh[i, j] == over)


def test_cor(tmp_path):
    out = tmp_path / "cor"
    assert main(["cor", "--hb-values", "1", "2", "--out", str(out), "--quiet"]) == 0
    rows = (out / "e_table.csv").read_text().splitlines()
    assert rows[0] == "hb,thc,e_H,e_M,delta_e_percent"
    vals = [list(map(float, r.split(","))) for r in rows[1:]]
    np.testing.assert_allclose([v[2] for v in vals], [0.25, 0.7], atol=1e-12)
    np.testing.assert_allclose([v[3] for v in vals], [0.582, 0.830], atol=5e-4)
    np.testing.assert_allclose([v[4] for v in vals], [79.85, 17.03], atol=5e-3)
    md = (out / "e_table.md").read_text()
    assert "| 1 | 0.7854 | 0.250 | 0.582 | 79.85 |" in md
    assert _summary(out)["table"][1]["e_H"] == pytest.approx(0.7)
    assert _is_png(out / "restitution.png")


def test_paper_quick(tmp_path):
    out = tmp_path / "paper"
    rc = main(["paper", "--out", str(out), "--grid", "4", "--periods", "20", "--n-steps", "64",
               "--alpha-step", "0.1", "--zoom-step", "0.05", "--quiet"])
    assert rc == 0
    figs = ["fig1_restitution", "fig2_reference", "fig3_gallery", "fig4_laws_timeseries",
            "fig5_bifurcation_hb1", "fig5_bifurcation_hb2", "fig5_bifurcation_zoom",
            "fig6_basin_hb1", "fig6_basin_hb2", "fig7_attractors_hb1", "fig7_attractors_hb2",
            "fig8_erosion_hb1", "fig8_erosion_hb2"]
    for f in figs:
        assert _is_png(out / f"{f}.png"), f
    for t in ("e_table", "basin_table", "sweep_table", "attractor_table"):
        assert (out / f"{t}.csv").exists() and (out / f"{t}.md").exists()
    s = _summary(out)
    parts = s["wall_s_parts"]
    assert list(parts) == ["fig1", "fig2", "fig3", "fig4", "fig5", "fig6", "fig7", "fig8"]
    assert sorted(f["name"] for f in s["files"]) == sorted(p.name for p in out.iterdir())
    assert all(f["holds"] for f in s["files"])  # the manifest says what each file holds
    for case, tag in zip(s["fig6"], ("hb1", "hb2")):
        z = np.load(out / f"fig6_basin_{tag}.npz")
        assert z["label_housner"].shape == (4, 4)
        assert case["agreement"] == pytest.approx(
            100 * np.mean(z["label_housner"] == z["label_mao"]))
        _check_fractions(case["mao"]["fractions"])
    basin_rows = (out / "basin_table.csv").read_text().splitlines()
    assert len(basin_rows) == 1 + 4
    z = np.load(out / "fig5_sweep_hb2_mao.npz")
    np.testing.assert_allclose(z["alpha"], [0.1, 0.2, 0.3, 0.4, 0.5])
    assert _no_temp_files(out)


# ---------------------------------------------------------------------------------------------
# bad input: one line, exit 2, nothing written
# ---------------------------------------------------------------------------------------------

TRAJ = ["trajectory", "--hb", "1", "--alpha", "0.6", "--omega", "1.3"]
SWEEP = ["sweep", "--hb", "1", "--omega", "1.3", "--alpha-range", "0.5", "0.6"]


@pytest.mark.parametrize("argv, word", [
    (["basin", "--hb", "-1", "--alpha", "0.66", "--omega", "1.3"],
     "hb must be in [0.01, 100] (got -1)"),
    (BASIN + ["--law", "foo"], "law"),
    (BASIN + ["--grid", "0"], "grid"),
    (BASIN + ["--law", "both", "--e", "0.5"], "--e"),
    (BASIN + ["--theta-range", "-2", "1"], "theta_range"),
    (BASIN + ["--r0", "0.5", "--s0", "0.5"], "(r0, s0)"),
    (BASIN + ["--threads", "0"], "threads"),
    (BASIN + ["--periods", "0"], "periods"),
    (BASIN + ["--n-steps", "63"], "n_steps"),
    (TRAJ[:2] + ["nan"] + TRAJ[3:], "hb must be finite"),
    (TRAJ + ["--law", "mao", "--e", "0.3"], "e is only given"),
    (TRAJ + ["--alpha", "-0.1"], "alpha"),
    (TRAJ + ["--method", "scipy:FOO"], "method"),
    (TRAJ + ["--method", "scipy", "--lyapunov"], "lyapunov=True is only available"),
    (TRAJ + ["--theta0", "2"], "theta0"),
    (TRAJ + ["--omega", "abc"], "--omega"),
    (TRAJ[:-2], "--omega"),
    (SWEEP + ["--alpha-step", "0"], "alpha_step"),
    (SWEEP[:6] + ["0.6", "0.5"], "alpha_range"),
    (SWEEP + ["--hb", "0.5"], "hb must be >= 1/sqrt(2)"),
    (["cor", "--hb-values", "0.5"], "hb"),
    (["cor", "--hb-max", "0.7"], "hb"),
    (["paper", "--grid", "-3"], "grid"),
    (["paper", "--alpha-step", "-0.1"], "alpha_step"),
    (["paper", "--zoom", "0.2", "0.3"], "zoom"),
    (["paper", "--periods", "0"], "periods"),
    (["frobnicate"], "invalid choice"),
    (["compile", "--everything"], "unrecognized arguments"),
])
def test_bad_input(argv, word, tmp_path, capsys):
    out = tmp_path / "out"
    rc = main(argv + ["--out", str(out)])
    err = capsys.readouterr().err
    assert rc == 2
    lines = err.strip().splitlines()
    assert len(lines) == 1 and lines[0].startswith("rockjit: error: ")
    assert word in lines[0]
    assert not out.exists()


def test_out_is_a_file(tmp_path, capsys):
    f = tmp_path / "file"
    f.write_text("x")
    assert main(["cor", "--out", str(f)]) == 2
    assert "--out" in capsys.readouterr().err
    assert f.read_text() == "x"


def test_help(capsys):
    assert main(["--help"]) == 0
    assert "trajectory" in capsys.readouterr().out
    assert main(["basin", "--help"]) == 0
    assert "--law" in capsys.readouterr().out


def test_python_m_rockjit_help():
    p = subprocess.run([sys.executable, "-m", "rockjit", "--help"], capture_output=True,
                       text=True, timeout=120)
    assert p.returncode == 0
    for cmd in ("trajectory", "sweep", "basin", "cor", "paper"):
        assert cmd in p.stdout
    p = subprocess.run([sys.executable, "-m", "rockjit", "cor", "--hb-values", "0.1",
                        "--out", "unused"], capture_output=True, text=True, timeout=120)
    assert p.returncode == 2 and p.stderr.count("\n") == 1


# ---------------------------------------------------------------------------------------------
# interruptions leave nothing half-written
# ---------------------------------------------------------------------------------------------

def test_interrupt_during_computation(tmp_path, monkeypatch, capsys):
    real = grid_plan.run
    calls = []

    def basin_then_interrupt(plan, execution=None):
        calls.append(plan.block.law)
        if len(calls) == 2:  # mid-way: the first law done, the second interrupted
            raise KeyboardInterrupt
        return real(plan, execution)

    monkeypatch.setattr(grid_plan, "run", basin_then_interrupt)
    out = tmp_path / "out"
    assert main(BASIN + ["--law", "both", "--out", str(out)]) == 130
    assert calls == ["housner", "mao"]
    assert "interrupted" in capsys.readouterr().err
    assert not out.exists()


def test_interrupt_during_writing(tmp_path, monkeypatch):
    real = rio.write_csv

    def half_then_interrupt(path, header, rows):
        with rio.atomic_open(path, "w") as fh:
            fh.write(",".join(header)[:5])
            raise KeyboardInterrupt

    monkeypatch.setattr(rio, "write_csv", half_then_interrupt)
    out = tmp_path / "out"
    assert main(["cor", "--out", str(out), "--quiet"]) == 130
    # a command's outputs are published as one unit: the figure written before the
    # interruption is not there either, and nothing is left beside --out
    assert not out.exists()
    assert list(tmp_path.iterdir()) == []
    monkeypatch.setattr(rio, "write_csv", real)


def test_atomic_writer_keeps_the_old_file(tmp_path):
    target = tmp_path / "a.json"
    rio.write_json(target, {"x": 1})
    with pytest.raises(KeyboardInterrupt):
        with rio.atomic_open(target, "w") as fh:
            fh.write('{"x": 2, "trunc')
            raise KeyboardInterrupt
    assert json.loads(target.read_text()) == {"x": 1}
    assert sorted(p.name for p in tmp_path.iterdir()) == ["a.json"]


def test_atomic_npz_interrupted(tmp_path, monkeypatch):
    def boom(fh, **arrays):
        fh.write(b"PK\x03\x04 partial")
        raise KeyboardInterrupt

    monkeypatch.setattr(np, "savez", boom)
    with pytest.raises(KeyboardInterrupt):
        rio.write_npz(tmp_path / "d.npz", a=np.arange(3))
    assert list(tmp_path.iterdir()) == []


# ---------------------------------------------------------------------------------------------
# writers
# ---------------------------------------------------------------------------------------------

def test_json_conventions(tmp_path):
    obj = {"i": np.int64(3), "f": np.float32(0.5), "b": np.bool_(True), "t": (1, 2),
           "a": np.array([[1.0, np.nan], [np.inf, -np.inf]]), "n": None, "m": -math.inf}
    rio.write_json(tmp_path / "s.json", obj)
    text = (tmp_path / "s.json").read_text()
    back = json.loads(text, parse_constant=lambda c: pytest.fail(f"non-standard {c}"))
    assert back == {"i": 3, "f": 0.5, "b": True, "t": [1, 2],
                    "a": [[1.0, "nan"], ["inf", "-inf"]], "n": None, "m": "-inf"}
    assert math.isinf(float(back["m"])) and math.isnan(float(back["a"][0][1]))
    with pytest.raises(TypeError, match="cannot write object to JSON"):
        rio.write_json(tmp_path / "bad.json", {"x": object()})
    assert not (tmp_path / "bad.json").exists() and _no_temp_files(tmp_path)


def test_npz_and_csv_round_trip(tmp_path):
    rio.write_npz(tmp_path / "d.npz", x=np.arange(4.0), names=np.array(BEHAVIOURS))
    z = np.load(tmp_path / "d.npz")  # allow_pickle=False
    assert list(z["names"]) == list(BEHAVIOURS) and z["x"].tolist() == [0, 1, 2, 3]
    rio.write_csv(tmp_path / "t.csv", ["a", "b"], [[1, 0.1], ["x", -math.inf]])
    assert (tmp_path / "t.csv").read_text().splitlines() == ["a,b", "1,0.1", "x,-inf"]


# ---------------------------------------------------------------------------------------------
# what a user is told: quiet runs, runs stopped early, stale files
# ---------------------------------------------------------------------------------------------

def test_quiet_means_quiet_even_for_a_degenerate_grid(tmp_path, capsys):
    # basin --theta-range 0 0 let a matplotlib UserWarning through --quiet
    rc = main(BASIN + ["--theta-range", "0", "0", "--out", str(tmp_path / "b")])
    assert rc == 0
    assert capsys.readouterr().err == ""


def test_a_run_stopped_before_its_end_says_so(tmp_path, capsys):
    # it exited 0 and printed lambda "nan" without a word
    rc = main(TRAJ + ["--max-impacts", "5", "--lyapunov", "--out", str(tmp_path / "t")] + TINY)
    assert rc == 0
    err = capsys.readouterr().err
    assert "warning: the run stopped at t = " in err and "--max-impacts" in err
    assert _summary(tmp_path / "t")["status"] == "max_impacts"


def test_a_second_command_into_the_same_folder_warns_of_stale_files(tmp_path, capsys):
    out = tmp_path / "o"
    assert main(["cor", "--out", str(out), "--quiet"]) == 0
    (out / "mine.txt").write_text("a user's file")
    assert main(BASIN + ["--out", str(out)]) == 0
    err = capsys.readouterr().err
    assert "warning:" in err and "rockjit cor" in err
    assert (out / "mine.txt").read_text() == "a user's file"  # never touched


# ---------------------------------------------------------------------------------------------
# beyond the study: attractors, erosion, fates
# ---------------------------------------------------------------------------------------------

def test_basin_writes_attractors_and_their_measures(tmp_path):
    out = tmp_path / "b"
    assert main(BASIN + ["--law", "both", "--grid", "12", "--uncertainty", "1e-3",
                         "--out", str(out)]) == 0
    z = np.load(out / "basin.npz")
    s = _summary(out)
    for law in ("housner", "mao"):
        ids = z[f"attractor_{law}"]
        assert ids.shape == (12, 12) and z[f"uncertain_{law}"].dtype == bool
        att = s[law]["attractors"]
        assert [a["id"] for a in att] == list(range(len(att)))
        for a in att:  # each attractor's fraction is its share of the map
            assert a["fraction"] == pytest.approx(100 * np.mean(ids == a["id"]))
        assert 0 <= s[law]["integrity"]["GIM"] <= 1
        assert s[law]["integrity"]["GIM"] == pytest.approx(np.mean(ids >= 0))
        assert s[law]["uncertain_percent"] == pytest.approx(100 * z[f"uncertain_{law}"].mean())
    assert "percent" in s["attractor_agreement"]
    assert _is_png(out / "attractors.png")


def test_erosion_command(tmp_path):
    out = tmp_path / "e"
    assert main(["erosion", "--hb", "1", "--omega", "1.3", "--law", "both", "--alpha-range",
                 "0.6", "0.7", "--alpha-step", "0.05", "--grid", "8", "--out", str(out)]
                + TINY) == 0
    z = np.load(out / "erosion.npz")
    np.testing.assert_allclose(z["alpha"], [0.6, 0.65, 0.7])
    s = _summary(out)
    for law in ("housner", "mao"):
        assert z[f"GIM_{law}"].shape == (3,) and z[f"attractor_{law}"].shape == (3, 8, 8)
        np.testing.assert_allclose(z[f"GIM_{law}"], np.mean(z[f"attractor_{law}"] >= 0,
                                                            axis=(1, 2)))
        assert len(s[law]["branches"]) == z[f"fractions_{law}"].shape[0]
    assert _is_png(out / "erosion.png")


def test_fate_command_and_a_trajectory_past_overturning(tmp_path):
    out = tmp_path / "f"
    assert main(["fate", "--hb", "1", "--alpha", "0.969", "--omega", "1.3", "--ensemble", "16",
                 "--periods", "200", "--out", str(out), "--quiet"]) == 0
    s = _summary(out)
    assert sum(s["probabilities"].values()) == pytest.approx(1.0)
    z = np.load(out / "fate.npz")
    assert z["initial"].shape == (16, 2) and z["outcome"].shape == (16,)
    out = tmp_path / "t"
    assert main(TRAJ[:2] + ["1", "--alpha", "0.72", "--omega", "1.3", "--law", "mao",
                            "--continue-past-overturn", "--periods", "20", "--out", str(out),
                            "--quiet"]) == 0
    s = _summary(out)
    assert s["behaviour"] == "overturn" and s["status"] == "done"
    assert 0 < float(s["t_overturn"]) < 20 * 2 * math.pi / 1.3


def test_orbits_command(tmp_path):
    out = tmp_path / "o"
    assert main(["orbits", "--hb", "1", "--omega", "1.3", "--alpha-range", "0.70", "0.85",
                 "--alpha-step", "0.005", "--periods", "300", "--out", str(out),
                 "--quiet"]) == 0
    s = _summary(out)
    types = [b["type"] for b in s["bifurcations"]]
    assert "symmetry_breaking" in types
    sb = next(b for b in s["bifurcations"] if b["type"] == "symmetry_breaking")
    assert 0.77 < sb["alpha"] < 0.79  # the sweep's symmetric-to-asymmetric transition
    z = np.load(out / "orbits.npz")
    assert z["bif_alpha"].size == len(types)
    assert _is_png(out / "orbits.png")


def test_compile_fills_a_cold_cache_and_says_so(tmp_path):
    """``rockjit compile``'s machinery on a fresh numba cache: cold before, cached after, and a
    command's first run announces the wait only while the cache is cold."""
    code = (
        "import sys\n"
        "from rockjit._jit import cached_kernels\n"
        "from rockjit._engine.kernel import compile_kernels\n"
        "assert not cached_kernels(), 'cache not cold'\n"
        "compiled = compile_kernels(['grid'], processes=1)\n"
        "assert set(compiled) == {'grid'}  # the variants it compiled (their times unread)\n"
        "assert cached_kernels(), 'nothing cached'\n"
    )
    env = {**__import__("os").environ, "NUMBA_CACHE_DIR": str(tmp_path / "cache")}
    done = subprocess.run([sys.executable, "-c", code], env=env, capture_output=True, text=True)
    assert done.returncode == 0, done.stderr
    assert any(p.suffix == ".nbc" for p in (tmp_path / "cache").rglob("*"))


def test_compile_refuses_an_unknown_variant():
    from rockjit._engine.kernel import compile_kernels
    with pytest.raises(ValueError, match="kernel variant must be one of"):
        compile_kernels(["warp-drive"])


# ---------------------------------------------------------------------------------------------
# errors while running: one line, a report, exit status 1, --out as it was
# ---------------------------------------------------------------------------------------------

@pytest.fixture
def reports(tmp_path, monkeypatch):
    """Where the error reports go (the temporary directory, here one of the test's own)."""
    d = tmp_path / "reports"
    d.mkdir()
    monkeypatch.setattr(tempfile, "tempdir", str(d))
    return d


def _error_and_report(err, reports, start):
    """The one line on stderr starts with ``start`` and names the report, which holds the
    traceback; returns the line."""
    assert "Traceback" not in err and err.endswith("\n") and err.count("\n") == 1, err
    line = err.rstrip("\n")
    assert line.startswith(start), line
    found = sorted(reports.glob("rockjit-error-*.txt"))
    assert len(found) == 1 and f"the traceback is in {found[0]}" in line
    assert "Traceback (most recent call last)" in found[0].read_text()
    return line


def _stages(root):
    return [p for p in Path(root).rglob("*") if "rockjit-stage" in p.name]


@pytest.mark.parametrize("cause", ["no space left", "a bug"])
def test_an_error_while_running_is_one_line_and_a_report(tmp_path, monkeypatch, capsys, reports,
                                                         cause):
    # _internal_error called tempfile without importing it: every such error ended in a
    # NameError traceback, and no report
    if cause == "no space left":
        def full(path, **arrays):
            raise OSError(errno.ENOSPC, os.strerror(errno.ENOSPC), str(path))
        monkeypatch.setattr(rio, "write_npz", full)
        start = "rockjit: error: No space left on device: "
    else:
        def bug(*args, **kwargs):
            raise RuntimeError("something rockjit did not expect")
        monkeypatch.setattr(outputs, "summary", bug)
        start = "rockjit: internal error: RuntimeError: something rockjit did not expect; "
    out = tmp_path / "b"
    assert main(BASIN + ["--out", str(out)]) == 1
    line = _error_and_report(capsys.readouterr().err, reports, start)
    assert "--out is as it was" in line
    assert not out.exists() and not _stages(tmp_path)


def _mount(*args):
    if os.geteuid() != 0:
        pytest.skip("mounting a small file system needs root")
    done = subprocess.run(["mount", *map(str, args)], capture_output=True, text=True)
    if done.returncode:
        pytest.skip(f"cannot mount here: {done.stderr.strip()}")


@pytest.fixture
def mounts():
    """Mount tmpfs file systems for a test (as root, where mounting is allowed; else skip);
    unmounted afterwards."""
    made = []

    def tmpfs(where, size="1m"):
        where.mkdir(parents=True, exist_ok=True)
        _mount("-t", "tmpfs", "-o", f"size={size}", "tmpfs", where)
        made.append(where)
        return where

    yield tmpfs
    for where in reversed(made):
        subprocess.run(["umount", "-l", str(where)], capture_output=True)


def test_a_full_disk_is_one_line_and_a_report(tmp_path, mounts, capsys, reports):
    disk = mounts(tmp_path / "disk", size="64k")
    (disk / "filler").write_bytes(b"\0" * 56 * 1024)  # a few kilobytes left
    out = disk / "cor"
    assert main(["cor", "--out", str(out), "--quiet"]) == 1
    _error_and_report(capsys.readouterr().err, reports, "rockjit: error: No space left on "
                                                        "device")
    assert sorted(p.name for p in disk.iterdir()) == ["filler"]  # nothing left behind


def test_a_read_only_out_is_refused_before_any_work(tmp_path, mounts, monkeypatch, capsys):
    # the probe looked only at --out's parent: the run computed, then failed to stage its
    # outputs inside --out (a NameError traceback)
    ro = mounts(tmp_path / "ro")
    (ro / "inside").mkdir()
    mounts(ro / "inside", size="1m")  # writable, in a directory that will be read-only
    _mount("-o", "remount,ro", ro)
    monkeypatch.setattr(grid_plan, "run", lambda *a, **k: pytest.fail("not refused before work"))
    assert main(BASIN + ["--out", str(ro)]) == 2
    err = capsys.readouterr().err
    assert err.startswith(f"rockjit: error: --out {ro} cannot be created or written (Read-only "
                          f"file system)") and err.count("\n") == 1
    # --out writable, but not where a grid command keeps its chunks (beside it)
    assert main(BASIN + ["--out", str(ro / "inside")]) == 2
    err = capsys.readouterr().err
    assert err.startswith(f"rockjit: error: {ro / 'inside'}.chunks (where --out's unfinished "
                          f"chunks wait) cannot be created or written (Read-only file system)")
    monkeypatch.undo()
    assert main(["cor", "--out", str(ro / "inside"), "--quiet"]) == 0  # it has no chunks


def test_a_chunk_replaced_by_a_directory_is_recomputed(tmp_path, monkeypatch, capsys):
    from rockjit._engine import kernel
    from rockjit.grids import runner
    out = tmp_path / "b"
    real_run_chunk, real_run_grid = kernel.run_chunk, runner.run_grid
    n = []

    def interrupt_at_the_third(*a):
        if len(n) == 2:
            raise KeyboardInterrupt
        n.append(1)
        return real_run_chunk(*a)

    def small_chunks(*a, **kw):
        return real_run_grid(*a, **dict(kw, execution=kw["execution"].replace(chunk=6)))

    monkeypatch.setattr(runner, "run_grid", small_chunks)
    monkeypatch.setattr(kernel, "run_chunk", interrupt_at_the_third)
    assert main(BASIN + ["--out", str(out)]) == 130
    store = tmp_path / "b.chunks" / "housner"  # the store of the one law
    first = store / "cells-0000000000-0000000006.npz"
    assert first.is_file()
    first.unlink()
    first.mkdir()
    (first / "x").write_text("")
    monkeypatch.setattr(kernel, "run_chunk", real_run_chunk)
    capsys.readouterr()
    assert main(BASIN[:-1] + ["--out", str(out)]) == 0
    err = capsys.readouterr().err
    assert "discarded damaged chunk cells-0000000000-0000000006.npz" in err and "Traceback" \
        not in err
    assert not (tmp_path / "b.chunks").exists()
    whole = rockjit.basin(Block(1), Harmonic(alpha=0.66, omega=1.3), 6,
                          integration=Integration(periods=20, n_steps=64))
    np.testing.assert_array_equal(np.load(out / "basin.npz")["label"], whole.label)


def test_long_out_names(tmp_path, capsys):
    # 230 characters: the name of the staging directory beside --out grew too long, once the
    # work was done; over 255, check_out raised OSError (a traceback)
    for name, argv in [("o" * 230, BASIN), ("c" * 250, ["cor", "--quiet"])]:
        assert main(argv + ["--out", str(tmp_path / name)]) == 0
        assert (tmp_path / name / "summary.json").is_file()
    # a grid command keeps its chunks beside --out, in <out>.chunks: 7 bytes more
    for name, argv, says in [("b" * 250, BASIN, "at most 248"),
                             ("c" * 256, ["cor", "--quiet"], "at most 255"),
                             ("d/" * 2100 + "d", ["cor", "--quiet"], "as an absolute path")]:
        assert main(argv + ["--out", str(tmp_path / name)]) == 2
        err = capsys.readouterr().err
        assert err.startswith("rockjit: error: --out") and says in err, err
        assert err.count("\n") == 1
    assert sorted(p.name for p in tmp_path.iterdir()) == ["c" * 250, "o" * 230]


# ---------------------------------------------------------------------------------------------
# every problem with --out, before any work
# ---------------------------------------------------------------------------------------------

def _dangling(out):
    out.symlink_to(out.parent / "nowhere")


def _looping(out):
    out.symlink_to(out.name)


def _output_named_dir(out):
    out.mkdir()
    (out / "basin.npz").mkdir()
    (out / "basin.npz" / "mine.txt").write_text("a user's file")


def _chunks_dangling(out):
    Path(f"{out}.chunks").symlink_to("nowhere")


def _store_is_a_file(out):
    Path(f"{out}.chunks").mkdir()
    Path(f"{out}.chunks", "mao").write_text("a user's file")


@pytest.mark.parametrize("setup, says", [
    (_dangling, "is a symbolic link to "),
    (_looping, "is a symbolic link in a loop"),
    (_output_named_dir, "holds a directory basin.npz where this command writes a file"),
    (_chunks_dangling, "chunks wait) is a symbolic link to nowhere, which does not exist"),
    (_store_is_a_file, "mao, where --out's unfinished chunks of a grid wait, is not a "
                       "directory"),
], ids=["dangling-link", "looping-link", "dir-named-like-output", "chunks-dangling-link",
        "store-is-a-file"])
def test_out_problems_are_found_before_any_work(tmp_path, monkeypatch, capsys, setup, says):
    # a dangling or looping --out was refused as "an existing file", and a directory named like
    # an output file only when publishing: both after the work, with its chunks left behind
    out = tmp_path / "o"
    setup(out)
    before = sorted(str(p) for p in tmp_path.rglob("*"))
    monkeypatch.setattr(grid_plan, "run", lambda *a, **k: pytest.fail("not refused before work"))
    assert main(BASIN + ["--law", "both", "--out", str(out)]) == 2
    err = capsys.readouterr().err
    assert err.startswith("rockjit: error: ") and err.count("\n") == 1 and "--out" in err
    assert says in err, err
    assert sorted(str(p) for p in tmp_path.rglob("*")) == before


def test_a_cold_cache_is_told_kernel_by_kernel(tmp_path, monkeypatch):
    # the harmonic kernels cached and the pulses' kernel not: a spectrum's first run still
    # compiles, and the check says so
    from rockjit._jit import cached_kernels
    monkeypatch.delenv("NUMBA_CACHE_DIR", raising=False)
    cache = tmp_path / "pkg" / "_engine" / "__pycache__"
    cache.mkdir(parents=True)
    (cache / "integrate.run-12.py311.1.nbc").write_bytes(b"")
    assert cached_kernels(tmp_path / "pkg")
    assert not cached_kernels(tmp_path / "pkg", modules=("transient",))
    (cache / "transient.run_cells-558.py311.1.nbc").write_bytes(b"")
    assert cached_kernels(tmp_path / "pkg", modules=("transient",))
