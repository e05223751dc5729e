"""Grid results as xarray Datasets: coordinates by value, every array kept, attributes that a
netCDF file can hold, values that survive the round trip, and the message without xarray."""

from __future__ import annotations

import subprocess
import sys

import numpy as np
import pytest

import rockjit
from rockjit import Block, Classification, Harmonic, Integration
from rockjit.orbits.plane_chart import ChartResult

xr = pytest.importorskip("xarray")

SHORT = Integration(periods=60)


@pytest.fixture(scope="module")
def sweep():
    # 0.66 is a grid value; stop_at_overturn=False keeps t_overturn and motion
    return rockjit.sweep(Block(hb=1), Harmonic(omega=1.3), [0.6, 0.66, 0.8, 1.2],
                         integration=Integration(periods=60, stop_at_overturn=False),
                         n_impact_points=6)


@pytest.fixture(scope="module")
def basin():
    return rockjit.basin(Block(hb=1, law="mao"), Harmonic(alpha=0.66, omega=1.3), grid=8,
                         integration=SHORT, lyapunov=True,
                         classification=Classification(uncertainty=1e-3))


@pytest.fixture(scope="module")
def plane():
    z0 = [(0.0, 0.0), (0.1, -0.05)]
    return rockjit.plane(Block(hb=1), (0.5, 0.8), (1.2, 1.4), state=z0, grid=(3, 2),
                         integration=SHORT)


@pytest.fixture(scope="module")
def erosion():
    return rockjit.erosion(Block(hb=1), Harmonic(omega=1.3), [0.6, 0.7], grid=8,
                           integration=SHORT)


def _same(a, b):
    a, b = np.asarray(a), np.asarray(b)
    return a.shape == b.shape and np.array_equal(a, b, equal_nan=a.dtype.kind == "f")


def _plain_attrs(attrs):
    """Every attribute is a number, a string or a 1-D numeric array: no bool, dict, None."""
    for key, value in attrs.items():
        assert not isinstance(value, (bool, np.bool_, dict, type(None))), (key, value)
        assert isinstance(value, (int, float, str, np.ndarray, np.integer, np.floating)), \
            (key, value)


def _round_trip(ds, tmp_path, names=("label", "lambda_max")):
    path = tmp_path / "grid.nc"
    ds.to_netcdf(path, engine="scipy")
    with xr.open_dataset(path, engine="scipy") as back:
        back = back.load()
    for name in names:
        assert np.array_equal(back[name].values, ds[name].values, equal_nan=True), name
    for name in ds.coords:
        assert np.array_equal(back[name].values, ds[name].values), name
    return back


# ------------------------------------------------------------------------------- sweep

def test_sweep_coordinates_and_variables_are_the_results(sweep):
    ds = sweep.to_xarray()
    assert _same(ds.alpha.values, sweep.alpha)
    assert ds.alpha.attrs["long_name"] and "units" in ds.alpha.attrs
    for name in ("label", "period", "lambda_max", "lambda_window", "attractor", "t_end",
                 "strobe", "impact_section", "t_overturn", "motion"):
        assert _same(ds[name].values, getattr(sweep, name)), name
        assert ds[name].dims[0] == "alpha", name
    assert ds.strobe.dims == ("alpha", "strobe_sample", "strobe_var")
    assert ds.strobe_var.values.tolist() == ["theta", "dtheta"]
    assert ds.impact_section.dims == ("alpha", "impact", "impact_var")
    assert ds.label.attrs["flag_meanings"].split() == list(rockjit.BEHAVIOURS)
    assert ds.label.attrs["flag_values"].tolist() == list(range(len(rockjit.BEHAVIOURS)))
    assert ds.attrs["omega"] == 1.3 and "alpha" not in ds.attrs  # the sweep's own axis
    assert ds.attrs["hb"] == 1.0 and ds.attrs["law"] == "housner"
    assert ds.attrs["stop_at_overturn"] == 0 and ds.attrs["lyapunov"] == 1
    assert ds.attrs["z0"].shape == (4,)
    _plain_attrs(ds.attrs)


def test_sweep_selects_by_value(sweep):
    ds = sweep.to_xarray()
    k = int(np.argmin(np.abs(sweep.alpha - 0.66)))
    assert ds.sel(alpha=0.66, method="nearest").label.item() == sweep.label[k]
    assert ds.sel(alpha=0.661, method="nearest").alpha.item() == sweep.alpha[k]
    assert _same(ds.sel(alpha=0.8).strobe.values, sweep.strobe[2])


def test_sweep_round_trips_through_netcdf3(sweep, tmp_path):
    ds = sweep.to_xarray()
    back = _round_trip(ds, tmp_path, names=("label", "lambda_max", "strobe", "t_overturn"))
    assert back.attrs["law"] == "housner" and back.attrs["omega"] == 1.3
    assert back.label.attrs["flag_meanings"] == ds.label.attrs["flag_meanings"]


# ------------------------------------------------------------------------------- basin

def test_basin_coordinates_and_variables_are_the_results(basin):
    ds = basin.to_xarray()
    assert ds.label.dims == ("theta0", "dtheta0")
    assert _same(ds.theta0.values, basin.theta0) and _same(ds.dtheta0.values, basin.dtheta0)
    for name in ("label", "period", "lambda_max", "lambda_window", "attractor", "uncertain",
                 "t_end"):
        assert _same(ds[name].values, getattr(basin, name)), name
    meanings = ds.attractor.attrs["flag_meanings"].split()
    assert meanings[:2] == ["unresolved", "overturn"]
    assert len(meanings) == 2 + len(basin.attractors)
    assert ds.attrs["law"] == "mao" and ds.attrs["alpha"] == 0.66
    assert ds.attrs["restitution"] == basin.block.restitution
    assert ds.attrs["uncertainty"] == 1e-3
    assert "e" not in ds.attrs  # None (not the constant law) is left out
    _plain_attrs(ds.attrs)


def test_basin_selects_by_value_and_round_trips(basin, tmp_path):
    ds = basin.to_xarray()
    i, j = 2, 5
    cell = ds.sel(theta0=basin.theta0[i] + 1e-3, dtheta0=basin.dtheta0[j] - 1e-3,
                  method="nearest")
    assert cell.label.item() == basin.label[i, j]
    assert _same(ds.sel(theta0=basin.theta0[i]).label.values, basin.label[i])
    back = _round_trip(ds, tmp_path, names=("label", "lambda_max", "uncertain", "attractor"))
    assert back.uncertain.dtype == bool


def test_constant_law_writes_its_coefficient():
    b = rockjit.basin(Block(hb=2, e=0.8), Harmonic(alpha=0.3, omega=1.6), grid=3,
                      integration=Integration(periods=20))
    ds = b.to_xarray()
    assert ds.attrs["law"] == "constant" and ds.attrs["e"] == 0.8
    assert "lambda_max" not in ds  # not computed: no variable rather than a None
    _plain_attrs(ds.attrs)


# ------------------------------------------------------------------------------- plane

def test_plane_has_the_states_as_a_dimension(plane, tmp_path):
    ds = plane.to_xarray()
    assert ds.label.dims == ("state", "alpha", "omega")
    assert _same(ds.alpha.values, plane.alpha) and _same(ds.omega.values, plane.omega)
    for k, name in enumerate(("theta0", "dtheta0", "r0", "s0")):
        assert _same(ds[name].values, plane.z0[:, k]), name
    for name in ("label", "period", "lambda_max", "t_end"):
        assert _same(ds[name].values, getattr(plane, name)), name
    cell = ds.sel(state=1, alpha=0.66, omega=1.39, method="nearest")
    i = int(np.argmin(np.abs(plane.alpha - 0.66)))
    j = int(np.argmin(np.abs(plane.omega - 1.39)))
    assert cell.label.item() == plane.label[1, i, j]
    _plain_attrs(ds.attrs)
    _round_trip(ds, tmp_path)


def test_chart_is_its_plane_with_the_overturn_onset(plane):
    onset = np.array([0.7, np.nan])
    res = ChartResult(block=plane.block, plane=plane, alpha_range=(0.5, 0.8),
                      omega_range=(1.2, 1.4), seed_omegas=(), curves=[], seeds=[], refused=[],
                      overturn_onset=onset, phase=0.25)
    ds = res.to_xarray()
    assert _same(ds.label.values, plane.label)
    assert _same(ds.overturn_onset.values, onset) and ds.overturn_onset.dims == ("omega",)
    assert ds.attrs["kind"] == "chart" and ds.attrs["chart_phase"] == 0.25
    assert ds.attrs["alpha_range"].tolist() == [0.5, 0.8] and ds.attrs["n_curves"] == 0
    _plain_attrs(ds.attrs)


# ------------------------------------------------------------------------------- erosion

def test_erosion_profile_converts_and_round_trips(erosion, tmp_path):
    ds = erosion.to_xarray()
    assert _same(ds.alpha.values, erosion.alpha)
    assert _same(ds.theta0.values, erosion.theta0)
    for name in ("GIM", "IF", "basin_entropy", "boundary_basin_entropy", "overturn", "label",
                 "attractor"):
        assert _same(ds[name].values, getattr(erosion, name)), name
    assert _same(ds.fraction.values, erosion.fractions())
    assert ds.branch_behaviour.values.tolist() == [b["behaviour"] for b in erosion.branches]
    assert ds.sel(alpha=0.7).GIM.item() == erosion.GIM[1]
    _plain_attrs(ds.attrs)
    back = _round_trip(ds, tmp_path, names=("label", "GIM", "fraction", "attractor"))
    assert back.branch_behaviour.values.tolist() == ds.branch_behaviour.values.tolist()


# ------------------------------------------------------------------------------- optional

def test_without_xarray_the_message_says_how_to_install_it(sweep, basin, plane, erosion,
                                                           monkeypatch):
    monkeypatch.setitem(sys.modules, "xarray", None)  # "import xarray" now fails
    for res in (sweep, basin, plane, erosion):
        with pytest.raises(ImportError, match=r"pip install rockjit\[xarray\]"):
            res.to_xarray()


def test_importing_rockjit_does_not_import_xarray():
    code = ("import sys, rockjit, rockjit.storage.labelled, rockjit.basins.erosion, "
            "rockjit.orbits.plane_chart; print('xarray' in sys.modules)")
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True,
                         check=True)
    assert out.stdout.strip() == "False"
