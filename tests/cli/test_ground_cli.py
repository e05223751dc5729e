"""The command line's ground-motion commands, end to end on small grids.

Checked: ``rockjit spectrum`` writes spectrum.npz, spectrum.png and summary.json with
``"min_overturn": [{"ratio", "amplitude", "mode"}, ...]`` at the top level for one law and inside
each law's object with ``--law both`` (beside where the laws differ), the same numbers as the
API; ``rockjit fragility`` on record files writes its arrays, both figures and the fitted curves
per law and size; ``--method scipy`` gives the compiled path's outcomes; an unknown method is
refused with exit status 2 and one line.
"""

from __future__ import annotations

import json

import numpy as np

import rockjit
from rockjit import Block, Pulse
from rockjit.cli.main import main


def _run(argv, capsys):
    rc = main(argv)
    return rc, capsys.readouterr().err


def test_spectrum_both_laws(tmp_path, capsys):
    out = tmp_path / "sp"
    rc, err = _run(["spectrum", "--hb", "4", "--law", "both", "--pulse", "sine",
                    "--ratio-range", "1", "5", "--amplitude-range", "1.5", "9", "--grid", "3",
                    "3", "--tol", "1e-5", "--quiet", "--out", str(out)], capsys)
    assert rc == 0, err
    s = json.loads((out / "summary.json").read_text())
    assert {"housner", "mao", "comparison"} <= set(s)
    for law in ("housner", "mao"):
        rows = s[law]["min_overturn"]
        assert [r["ratio"] for r in rows] == [1.0, 3.0, 5.0]
        for r in rows:
            assert set(r) == {"ratio", "amplitude", "mode"}
            assert r["mode"] in ("with impact", "without impact", None)
    with np.load(out / "spectrum.npz") as z:
        assert z["outcome_housner"].shape == (3, 3) and z["outcome_mao"].shape == (3, 3)
        np.testing.assert_array_equal(z["ratio"], [1.0, 3.0, 5.0])
    assert (out / "spectrum.png").stat().st_size > 1000
    # the same numbers as the library's
    sp = rockjit.spectrum(Block(hb=4, law="mao"), Pulse("sine"), [1.0, 3.0, 5.0],
                          [1.5, 5.25, 9.0], tol=1e-5)
    got = [r["amplitude"] for r in s["mao"]["min_overturn"]]
    np.testing.assert_allclose(got, sp.min_overturn, rtol=1e-12)


def test_spectrum_one_law_at_the_top_level(tmp_path, capsys):
    out = tmp_path / "sp"
    rc, err = _run(["spectrum", "--hb", "2", "--law", "mao", "--pulse", "ricker",
                    "--ratio-range", "2", "2", "--amplitude-range", "1.2", "4", "--grid", "1",
                    "2", "--tol", "1e-3", "--quiet", "--out", str(out)], capsys)
    assert rc == 0, err
    s = json.loads((out / "summary.json").read_text())
    assert s["law"] == "mao" and len(s["min_overturn"]) == 1
    assert s["pulse"] == "ricker" and "min_overturn_without_impact" in s


def _csv(path, seed):
    rng = np.random.default_rng(seed)
    t = np.arange(401) * 0.01
    a = sum(rng.normal(0, 0.1) * np.sin(2 * np.pi * f * t + rng.uniform(0, 6))
            for f in (0.6, 1.4, 3.1)) * np.sin(np.pi * t / t[-1]) ** 2
    path.write_text("time (s),acceleration (g)\n" +
                    "".join(f"{x:.2f},{y:.8f}\n" for x, y in zip(t, a)))
    return str(path)


def test_fragility_on_record_files(tmp_path, capsys):
    files = [_csv(tmp_path / "a.csv", 1), _csv(tmp_path / "b.csv", 2)]
    out = tmp_path / "fr"
    rc, err = _run(["fragility", "--hb", "3", "--law", "both", "--size", "0.5", "2",
                    "--records", *files, "--intensities", "0.9", "2", "4", "--free-time", "20",
                    "--quiet", "--out", str(out)], capsys)
    assert rc == 0, err
    s = json.loads((out / "summary.json").read_text())
    assert set(s["laws"]) == {"housner", "mao"} and s["sizes"] == [0.5, 2.0]
    assert s["records"] == ["a", "b"] and s["intensity"] == [0.9, 2.0, 4.0]
    for law in ("housner", "mao"):
        for size in ("0.5", "2"):
            d = s["laws"][law]["sizes"][size]
            assert d["fraction_overturned"][0] == 0.0  # below uplift: nothing moves
            assert d["overturn"]["status"] in ("ok", "unidentified", "all_survive",
                                               "all_overturn")
    with np.load(out / "fragility.npz") as z:
        assert z["outcome"].shape == (2, 2, 2, 3) and z["scale"].shape == (2, 3)
    for png in ("fragility.png", "rotation.png"):
        assert (out / png).stat().st_size > 1000


def test_the_scipy_path_on_request_and_a_bad_method(tmp_path, capsys):
    args = ["spectrum", "--hb", "4", "--ratio-range", "1", "4", "--amplitude-range", "1.5",
            "8", "--grid", "3", "3", "--tol", "1e-3", "--quiet"]
    outs = {}
    for method in ("rockjit", "scipy"):
        rc, err = _run(args + ["--method", method, "--out", str(tmp_path / method)], capsys)
        assert rc == 0, err
        s = json.loads((tmp_path / method / "summary.json").read_text())
        assert s["method"] == {"rockjit": "rockjit", "scipy": "scipy:DOP853"}[method]
        with np.load(tmp_path / method / "spectrum.npz") as z:
            outs[method] = z["outcome"]
    assert np.array_equal(outs["rockjit"], outs["scipy"]) and len(np.unique(outs["scipy"])) > 1
    rc, err = _run(args + ["--method", "compiled", "--out", str(tmp_path / "x")], capsys)
    assert rc == 2 and err.count("\n") == 1 and "method must be" in err
    assert not (tmp_path / "x").exists()


def test_a_figure_that_cannot_be_drawn_keeps_the_spectrums_data(tmp_path, monkeypatch, capsys):
    # the spectrum was computed, then drawing it raised: "internal error", nothing written
    import importlib
    argv = ["spectrum", "--hb", "4", "--pulse", "sine", "--ratio-range", "1", "5",
            "--amplitude-range", "1.5", "9", "--grid", "2", "2", "--tol", "1e-3", "--quiet"]
    rc, err = _run(argv + ["--out", str(tmp_path / "drawn")], capsys)
    assert rc == 0, err

    def overflow(*a, **k):
        raise OverflowError("math range error")

    monkeypatch.setattr(importlib.import_module("rockjit.ground.figures"), "fig_spectrum",
                        overflow)
    out = tmp_path / "failed"
    rc, err = _run(argv + ["--out", str(out)], capsys)
    assert rc == 3
    assert err == ("rockjit: warning: spectrum.png could not be drawn (OverflowError: math range "
                   "error); the data were written without it (exit status 3)\n")
    s = json.loads((out / "summary.json").read_text())
    assert s["figures_failed"] == [{"name": "spectrum.png",
                                    "error": "OverflowError: math range error"}]
    assert "spectrum.png" not in {f["name"] for f in s["files"]}
    assert sorted(p.name for p in out.iterdir()) == [".rockjit-files.json", "spectrum.npz",
                                                     "summary.json"]
    with np.load(out / "spectrum.npz") as got, np.load(tmp_path / "drawn" / "spectrum.npz") as ref:
        assert sorted(got.files) == sorted(ref.files)
        for k in ref.files:  # the data as the run that could draw them wrote them
            assert np.array_equal(got[k], ref[k], equal_nan=got[k].dtype.kind == "f"), k


def test_fragility_names_the_path_it_runs_on_and_writes_no_unidentified_estimate(tmp_path,
                                                                                 capsys):
    recs = [_csv(tmp_path / "a.csv", 1), _csv(tmp_path / "b.csv", 3)]
    base = ["fragility", "--hb", "3", "--size", "1", "--records", *recs, "--intensities", "3",
            "--free-time", "5"]
    said = {}
    for method in ("rockjit", "scipy"):
        rc, err = _run(base + ["--method", method, "--out", str(tmp_path / method)], capsys)
        assert rc == 0, err
        said[method] = [line for line in err.splitlines() if " runs (" in line]
    assert len(said["rockjit"]) == 1 and said["rockjit"][0].endswith("on the compiled path")
    assert len(said["scipy"]) == 1 and said["scipy"][0].endswith("on the scipy path (DOP853)")
    # two records at one intensity, one of them overturning the block: the likelihood is flat
    # in beta, no fit is identified, and none is written as one
    s = json.loads((tmp_path / "rockjit" / "summary.json").read_text())
    d = s["laws"]["housner"]["sizes"]["1"]
    assert d["fraction_overturned"] == [0.5]
    assert d["overturn"]["status"] == "unidentified"
    assert d["overturn"]["reason"].startswith("one intensity level")
    for fit in d.values():
        if isinstance(fit, dict):
            assert fit["status"] != "ok"
            assert fit["median"] == "nan" and fit["beta"] == "nan"
            assert len(fit["median_ci"]) == 2 and len(fit["beta_ci"]) == 2


def test_an_interrupted_spectrum_command_resumes_from_its_chunks(tmp_path, monkeypatch, capsys):
    # the rerun of an interrupted spectrum started from zero: no chunk store was kept
    import importlib
    batch = importlib.import_module("rockjit.ground.batch")
    real = batch.KERNELS["scipy"]
    grid_cells = []  # the grid's cells computed (the bisections' amplitudes lie between them)
    stop = []

    def kernel(blocks, sources, block_of, source_of, gain, *rest):
        if np.isin(gain, (1.5, 9.0)).all():
            grid_cells.append(len(gain))
            if stop and len(grid_cells) == stop[0]:
                raise KeyboardInterrupt
        return real(blocks, sources, block_of, source_of, gain, *rest)

    monkeypatch.setitem(batch.KERNELS, "scipy", kernel)
    argv = ["spectrum", "--hb", "4", "--ratio-range", "1", "5", "--amplitude-range", "1.5", "9",
            "--grid", "2", "2", "--tol", "1e-2", "--method", "scipy", "--quiet"]
    rc, err = _run(argv + ["--out", str(tmp_path / "whole")], capsys)
    assert rc == 0 and sum(grid_cells) == 4, err
    grid_cells.clear()
    stop.append(3)  # Ctrl-C as the third chunk starts
    out = tmp_path / "o"
    rc, err = _run(argv + ["--out", str(out)], capsys)
    assert rc == 130 and f"finished chunks wait in {out}.chunks" in err, err
    assert not out.exists() and grid_cells == [1, 1, 1]  # two chunks of one cell, then Ctrl-C
    grid_cells.clear()
    stop.clear()
    rc, err = _run(argv + ["--out", str(out)], capsys)
    assert rc == 0, err
    assert sum(grid_cells) == 2  # only the two cells missing were computed
    assert not (tmp_path / "o.chunks").exists()  # removed once published
    with np.load(out / "spectrum.npz") as got, np.load(tmp_path / "whole" / "spectrum.npz") as ref:
        for k in ref.files:
            assert got[k].tobytes() == ref[k].tobytes(), k
