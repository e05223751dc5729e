"""Global safety: integrity charts against erosion profiles and separate basins, the minimal
fatal shock against a brute-force lattice of initial states, the edge state against runs from
either side of it; bad input refused."""

import json

import numpy as np
import pytest

import rockjit
from rockjit import Block, Harmonic, Integration, Lattice
from rockjit import measures as M
from rockjit.result import OVERTURN

BLOCK = Block(hb=1.0)
SHORT = Integration(periods=60)
#: An attractor of h/b = 1 at alpha = 0.66, omega = 1.3 (a symmetric period-1 cycle) and the
#: forcing; its point is checked to stay safe by the tests that use it.
FORCING = Harmonic(alpha=0.66, omega=1.3)
POINT = (-0.2825, -0.164)


@pytest.fixture(scope="module")
def chart():
    return rockjit.safety(BLOCK, (0.6, 0.7), (1.2, 1.3), grid=(3, 2), lattice=8,
                          integration=SHORT)


def test_the_column_at_omega_1_3_is_the_erosion_profile(chart):
    prof = rockjit.erosion(BLOCK, Harmonic(omega=1.3), chart.alpha, grid=8, integration=SHORT,
                           floquet=False)
    j = chart.column(1.3)
    assert chart.omega[j] == 1.3
    np.testing.assert_array_equal(chart.GIM[:, j], prof.GIM)
    np.testing.assert_array_equal(chart.IF[:, j], prof.IF)
    # safe: the cells that do not overturn; the profile counts those that do, in percent
    np.testing.assert_allclose(chart.safe[:, j], 1 - prof.overturn / 100, rtol=0, atol=1e-12)


def test_every_forcing_is_its_basin_computed_alone(chart):
    for i, a in enumerate(chart.alpha):
        for j, w in enumerate(chart.omega):
            b = rockjit.basin(BLOCK, Harmonic(alpha=float(a), omega=float(w)), 8,
                              integration=SHORT)
            pts = {x.id: np.asarray(x.points).reshape(-1, 2) for x in b.attractors}
            integ = M.integrity(b.attractor, b.theta0, b.dtheta0, pts or None)
            assert chart.safe[i, j] == np.mean(b.label != OVERTURN)
            assert chart.GIM[i, j] == integ.GIM and chart.IF[i, j] == integ.IF
            assert chart.n_attractors[i, j] == len(b.attractors)
            if b.attractors:
                biggest = max(b.attractors, key=lambda x: x.n_cells)
                assert chart.LIM[i, j] == integ.LIM[biggest.id]
                assert sorted(r["behaviour"] for r in chart.attractors[i][j]) == \
                    sorted(x.behaviour for x in b.attractors)
            else:
                assert np.isnan(chart.LIM[i, j])


def test_chart_labels_and_text(chart):
    ds = chart.to_xarray()
    assert ds.GIM.dims == ("alpha", "omega")
    np.testing.assert_array_equal(ds.safe.values, chart.safe)
    text = repr(chart)
    assert text.startswith("<rockjit.SafetyResult: 3×2 forcings × 8×8 basins>")
    assert max(len(line) for line in text.splitlines()) <= 100


def test_chart_resumes_from_its_store(tmp_path, monkeypatch):
    from rockjit import Execution
    from rockjit._engine import kernel
    calls = []
    ex = Execution(store=tmp_path / "store", progress=lambda d, t: calls.append((d, t)))
    kw = dict(grid=(2, 2), lattice=4, integration=SHORT, execution=ex)
    a = rockjit.safety(BLOCK, (0.6, 0.7), (1.2, 1.3), **kw)
    assert calls[0] == (0, 64) and calls[-1] == (64, 64)
    calls.clear()

    def no_runs(*args, **kwargs):
        raise AssertionError("a chunk was computed again")

    monkeypatch.setattr(kernel, "run_chunk", no_runs)
    b = rockjit.safety(BLOCK, (0.6, 0.7), (1.2, 1.3), **kw)
    np.testing.assert_array_equal(a.GIM, b.GIM)
    np.testing.assert_array_equal(a.LIM, b.LIM)
    assert calls[0] == (32, 64) and calls[-1] == (64, 64)


@pytest.mark.parametrize("kw, name", [
    (dict(alpha_range=(0.7, 0.6)), "alpha_range"),
    (dict(alpha_range=(0.6, 0.6)), "alpha_range"),
    (dict(omega_range=(0, 1.3)), "omega_range"),
    (dict(grid=(2, 0)), "grid[1]"),
    (dict(grid=(2, 1001)), "grid[1]"),
    (dict(lattice=1), "lattice"),
])
def test_chart_refuses_bad_input(kw, name):
    args = dict(alpha_range=(0.6, 0.7), omega_range=(1.2, 1.3), grid=(2, 2), lattice=4)
    args.update(kw)
    with pytest.raises(ValueError, match=name.replace("[", r"\[").replace("]", r"\]")):
        rockjit.safety.plan(BLOCK, args.pop("alpha_range"), args.pop("omega_range"), **args)


def test_shock_never_exceeds_the_nearest_fatal_cell_of_a_fine_lattice():
    integ = Integration(periods=100)
    x = np.array(POINT)
    half = 0.8
    fine = rockjit.basin(BLOCK, FORCING, Lattice(81, (x[0] - half, x[0] + half),
                                                 (x[1] - half, x[1] + half)),
                         integration=integ)
    TH, DTH = np.meshgrid(fine.theta0, fine.dtheta0, indexing="ij")
    fatal = fine.label == OVERTURN
    nearest = np.min(np.hypot(TH - x[0], DTH - x[1])[fatal])
    assert nearest < half  # the lattice holds a fatal cell nearer than its edge
    s = rockjit.fatal_shock(BLOCK, FORCING, x, integration=integ)
    assert s.norm <= nearest
    # the lattice is fine: the continuous minimum is within a cell's diagonal of its nearest
    assert s.norm >= nearest - np.hypot(*(2 * half / 80,) * 2)
    assert s.accuracy <= 1e-4
    np.testing.assert_allclose(s.delta, s.norm * s.direction, rtol=1e-12)
    # converged: a search ten times tighter moves the norm by less than the accuracy asked
    t = rockjit.fatal_shock(BLOCK, FORCING, x, integration=integ, rtol=1e-5, angle_tol=1e-4)
    assert abs(t.norm - s.norm) <= 1e-4 * s.norm


def test_shock_is_fatal_and_its_safe_end_is_safe():
    # the shock's two ends checked by runs of the basin grid (the same path, one cell each)
    integ = Integration(periods=100)
    s = rockjit.fatal_shock(BLOCK, FORCING, POINT, integration=integ, rtol=1e-3)
    inner = s.point + s.delta * (1 - s.accuracy)
    for z, want in ((s.point + s.delta, True), (inner, False), (s.point, False)):
        b = rockjit.basin(BLOCK, FORCING, Lattice(2, (z[0], z[0] + 1e-300),
                                                  (z[1], z[1] + 1e-300)), integration=integ)
        assert bool(b.label[0, 0] == OVERTURN) is want


@pytest.mark.parametrize("kw, message", [
    (dict(grid=(2,)), r"^grid must be two integers \(na, nw\) \(got \(2,\)\)$"),
    (dict(grid=5), r"^grid must be two integers \(na, nw\) \(got 5\)$"),
    # the sides' bounds differ (the plane's grids are bounded by their memory only)
    (dict(grid=(0, 2)), r"^grid\[0\] must be in \[1, 10+\] \(got 0\)$"),
    (dict(grid=(2, 2.5)), r"^grid\[1\] must be an integer"),
    (dict(alpha_range=(0.7, 0.6)), r"^alpha_range must satisfy start <= end"),
    (dict(omega_range=(0, 1.3)), r"^omega_range\[0\]"),
    # a frequency above 1e4; then alpha omega^2 = 1e9 above the largest acceleration, 1e8
    (dict(alpha_range=(0.5, 1.0), omega_range=(1.2, 2e4)), r"^omega_range\[1\]"),
    (dict(alpha_range=(0.5, 1e3), omega_range=(1.2, 1e3)),
     r"^the forcing acceleration alpha \* omega\*\*2 must be <= 1e\+08 "
     r"\(got alpha = 1000, omega = 1000: 1e\+09\)$"),
])
def test_plane_and_chart_refuse_a_bad_forcing_grid_alike(kw, message):
    """The (alpha, omega) grid of the plane and of the safety chart is checked by the same
    rules, with the same words."""
    args = dict(alpha_range=(0.6, 0.7), omega_range=(1.2, 1.3), grid=(2, 2))
    args.update(kw)
    a, w = args.pop("alpha_range"), args.pop("omega_range")
    with pytest.raises(ValueError, match=message):
        rockjit.plane.plan(BLOCK, a, w, **args)
    with pytest.raises(ValueError, match=message):
        rockjit.safety.plan(BLOCK, a, w, lattice=4, **args)


def test_shock_refuses_bad_input():
    with pytest.raises(ValueError, match="point"):
        rockjit.fatal_shock(BLOCK, FORCING, (1.4, 3.0), integration=SHORT)
    with pytest.raises(ValueError, match="rtol"):
        rockjit.fatal_shock(BLOCK, FORCING, POINT, rtol=0.5)
    with pytest.raises(ValueError, match="point"):
        rockjit.fatal_shock(BLOCK, FORCING, [1.0, 2.0, 3.0])


def test_edge_state_lies_on_the_boundary():
    integ = Integration(periods=200)
    s = rockjit.fatal_shock(BLOCK, FORCING, POINT, integration=integ, rtol=1e-3)
    e = rockjit.edge_state(BLOCK, FORCING, s.point, s.point + s.delta, periods=200, track=60)
    assert e.residual <= 1e-10
    mu = np.abs(e.multipliers)
    assert mu[0] > 1 > mu[1]  # a saddle: one direction across the boundary
    # its unstable direction from the monodromy; runs from either side, close by, part ways
    w, v = np.linalg.eig(e.orbit.monodromy)
    u = np.real(v[:, np.argmax(np.abs(w))])
    u /= np.linalg.norm(u)
    ends = []
    for sign in (1, -1):
        z = e.state + sign * 1e-6 * u
        r = rockjit.simulate(BLOCK, FORCING, (float(z[0]), float(z[1])), integration=integ)
        ends.append(rockjit.classify_result(r)[0] == "overturn")
    assert sorted(ends) == [False, True]


def test_cli_safety_both_laws(tmp_path):
    from rockjit.cli.main import main
    out = tmp_path / "out"
    rc = main(["safety", "--hb", "1", "--law", "both", "--alpha-range", "0.6", "0.7",
               "--omega-range", "1.2", "1.3", "--grid", "2", "2", "--lattice", "4",
               "--periods", "30", "--out", str(out), "--quiet"])
    assert rc == 0
    names = {p.name for p in out.iterdir()}
    assert {"safety.npz", "safety_housner.png", "safety_mao.png", "safety_difference.png",
            "summary.json"} <= names
    with np.load(out / "safety.npz") as z:
        assert z["safe_mao"].shape == (2, 2)
    summ = json.dumps(json.loads((out / "summary.json").read_text()))
    assert '"law": "mao"' in summ and '"law": "housner"' in summ


@pytest.mark.parametrize("argv", [
    ["--alpha-range", "0.7", "0.6", "--omega-range", "1.2", "1.3"],
    ["--alpha-range", "0.6", "0.7", "--omega-range", "1.2", "1.3", "--levels", "1.5"],
    ["--alpha-range", "0.6", "0.7", "--omega-range", "1.2", "1.3", "--lattice", "1"],
])
def test_cli_safety_refuses_bad_ranges(tmp_path, capsys, argv):
    from rockjit.cli.main import main
    rc = main(["safety", "--hb", "1", *argv, "--out", str(tmp_path / "o")])
    err = capsys.readouterr().err.strip().splitlines()
    assert rc == 2 and len(err) == 1 and err[0].startswith("rockjit: error:")
    assert not (tmp_path / "o").exists()


def test_shock_chart_is_bounded_by_each_basins_nearest_fatal_cell():
    from rockjit.integrity import fatal_shock_chart
    ch = rockjit.safety(BLOCK, (0.62, 0.66), (1.3, 1.3), grid=(2, 1), lattice=41,
                        integration=SHORT)
    norms = fatal_shock_chart(ch, rtol=1e-3, radius=1.0)
    TH, DTH = np.meshgrid(ch.theta0, ch.dtheta0, indexing="ij")
    for i, a in enumerate(ch.alpha):
        b = rockjit.basin(BLOCK, Harmonic(alpha=float(a), omega=1.3), 41, integration=SHORT)
        x = np.asarray(ch.attractors[i][0][0]["points"]).reshape(-1, 2)
        fatal = b.label == OVERTURN
        nearest = min(np.min(np.hypot(TH - p[0], DTH - p[1])[fatal]) for p in x)
        assert 0 < norms[i, 0] <= nearest


def test_chart_on_a_dask_cluster_is_the_chart_in_process(chart):
    distributed = pytest.importorskip("dask.distributed")
    from rockjit import Execution
    cluster = distributed.LocalCluster(n_workers=1, threads_per_worker=1, processes=False,
                                       dashboard_address=":0")
    try:
        with distributed.Client(cluster) as client:
            on = rockjit.safety(BLOCK, (0.6, 0.7), (1.2, 1.3), grid=(3, 2), lattice=8,
                                integration=SHORT,
                                execution=Execution(client=client, chunk=40))
    finally:
        cluster.close()
    for name in ("safe", "GIM", "IF", "LIM", "n_attractors"):
        np.testing.assert_array_equal(getattr(on, name), getattr(chart, name), err_msg=name)


def test_figures_read_in_a_journal(chart):
    import matplotlib
    matplotlib.use("Agg")
    from rockjit.integrity.figure import fig_fatal_shock, fig_safety, fig_safety_difference
    from rockjit.plotting import legibility as L
    mao = rockjit.safety(Block(hb=1, law="mao"), (0.6, 0.7), (1.2, 1.3), grid=(3, 2),
                         lattice=8, integration=SHORT)
    b = rockjit.basin(BLOCK, FORCING, 12, integration=SHORT)
    shock = rockjit.fatal_shock(BLOCK, FORCING, POINT, integration=SHORT, rtol=1e-2,
                                directions=16, radii=8, angle_tol=0.05)
    figs = [fig_safety(chart, (0.5, 0.53)), fig_safety(mao),
            fig_safety_difference({"housner": chart, "mao": mao}),
            fig_fatal_shock(b, {0: shock})]
    for fig in figs:
        assert L.problems(fig) == []
