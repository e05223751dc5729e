"""Grid results as labelled ``xarray.Dataset`` objects: what the ``to_xarray()`` methods build.

Coordinates are the grid's axes by value (``alpha``, ``omega``, ``theta0``, ``dtheta0``, named
as the result names them), each with ``units`` and ``long_name``; data variables are the
result's arrays under the same names, with the behaviour names on ``label`` as CF flags
(``flag_values``, ``flag_meanings``); the dataset's attributes are the block, the excitation
and the settings as plain numbers and strings (booleans as 0/1, ``None`` left out, nested
settings flattened to ``outer_inner``), so that ``ds.to_netcdf(path)`` writes them with any
engine, the netCDF3 one of scipy included.

xarray is optional (``pip install rockjit[xarray]``): it is imported here, when a result is
converted, and nowhere else.
"""

from __future__ import annotations

import numpy as np

__all__ = ["basin_dataset", "chart_dataset", "erosion_dataset", "plane_dataset",
           "sweep_dataset", "xarray"]

#: netCDF3 (scipy's engine) holds 32-bit integers only.
_INT32 = np.iinfo(np.int32)

#: ``(units, long_name)`` of each coordinate and variable; the time unit is the model's,
#: ``1/Omega0`` (docs/theory/model.md).
META = {
    "alpha": ("1", "forcing amplitude A/R"),
    "omega": ("1", "forcing frequency Omega/Omega0"),
    "theta0": ("rad", "initial rotation theta0"),
    "dtheta0": ("rad", "initial angular velocity theta0' (per unit time 1/Omega0)"),
    "r0": ("1", "forcing oscillator's start r0 = sin(phase)"),
    "s0": ("1", "forcing oscillator's start s0 = cos(phase)"),
    "label": ("1", "behaviour"),
    "motion": ("1", "behaviour of the motion the run settled on (before an overturn)"),
    "period": ("1", "period in forcing periods (0: none)"),
    "attractor": ("1", "outcome: the attractor reached (-1 overturn, -2 unresolved)"),
    "uncertain": ("1", "outcome changes when the initial state moves by the uncertainty"),
    "lambda_max": ("1/(1/Omega0)", "largest Lyapunov exponent (Floquet where periodic)"),
    "lambda_window": ("1/(1/Omega0)",
                      "largest Lyapunov exponent, finite-window QR average"),
    "t_end": ("1/Omega0", "time the run stopped"),
    "t_overturn": ("1/Omega0", "first instant |theta| reached theta_over (nan: never)"),
    "strobe": ("1", "(theta, theta') at t = kT over the classified stretch (nan-padded)"),
    "impact_section": ("1", "(t mod T, theta'-) of the impacts over the classified stretch "
                            "(nan-padded)"),
    "GIM": ("1", "global integrity measure"),
    "IF": ("1", "integrity factor"),
    "basin_entropy": ("1", "basin entropy Sb"),
    "boundary_basin_entropy": ("1", "boundary basin entropy Sbb"),
    "overturn": ("percent", "cells that overturn"),
    "fraction": ("percent", "cells that reach the branch"),
    "overturn_onset": ("1", "smallest alpha that overturns on the chart, per omega"),
}


def xarray():
    """The ``xarray`` module, or an ``ImportError`` that says how to install it."""
    try:
        import xarray as xr
    except ImportError as exc:
        raise ImportError("to_xarray() needs xarray, an optional dependency of rockjit: "
                          "pip install rockjit[xarray]") from exc
    return xr


def _meta(name, **more):
    units, long_name = META[name]
    return dict(units=units, long_name=long_name, **more)


def _attr(value):
    """A netCDF-safe attribute value: a number, a string or a 1-D numeric array; ``None``
    when there is nothing to write (the key is then left out)."""
    if value is None:
        return None
    if isinstance(value, (bool, np.bool_)):
        return int(value)
    if isinstance(value, (int, np.integer)):
        value = int(value)
        return value if _INT32.min <= value <= _INT32.max else float(value)
    if isinstance(value, (float, np.floating)):
        return float(value)
    if isinstance(value, str):
        return value
    if isinstance(value, (list, tuple, np.ndarray)):
        try:
            arr = np.asarray(value)
        except (TypeError, ValueError):
            return str(value)
        if arr.ndim == 1 and arr.size and arr.dtype.kind in "biuf":
            if arr.dtype.kind == "b":
                return arr.astype(np.int32)
            if arr.dtype.kind in "iu" and arr.min() >= _INT32.min and arr.max() <= _INT32.max:
                return arr.astype(np.int32)
            return arr.astype(float)
        return str(list(value)) if isinstance(value, (list, tuple)) else str(value.tolist())
    return str(value)


def _attrs(pairs, prefix=""):
    """``{name: value}`` made netCDF-safe: dicts flattened (``outer_inner``), ``None`` left
    out."""
    out = {}
    for key, value in pairs.items():
        name = f"{prefix}{key}"
        if isinstance(value, dict):
            out.update(_attrs(value, prefix=f"{name}_"))
            continue
        value = _attr(value)
        if value is not None:
            out[name] = value
    return out


def dataset_attrs(block, forcing, settings, kind, **more):
    """The dataset's attributes: the grid's ``kind``, the block (``hb``, ``law``, ``e`` with the
    constant law, ``xi``, ``restitution``), the excitation's given fields (``alpha``,
    ``omega``, ``phase`` or ``r0, s0``; not what the grid sweeps) and the settings."""
    import rockjit
    attrs = dict(kind=kind, rockjit_version=rockjit.__version__, hb=block.hb, law=block.law,
                 e=block.e, xi=block.xi, restitution=block.restitution)
    if forcing is not None:
        attrs.update({k: getattr(forcing, k, None) for k in
                      ("alpha", "omega", "phase", "r0", "s0")})
    attrs.update(settings or {})
    attrs.update(more)
    return _attrs(attrs)


def _flags(names, attrs):
    """CF flags of a behaviour-coded variable: its codes and their names."""
    names = [str(n) for n in np.asarray(names)]
    return dict(attrs, flag_values=np.arange(len(names), dtype=np.int32),
                flag_meanings=" ".join(names))


def _attractor_flags(attractors, attrs):
    """CF flags of an attractor map: ``-2`` unresolved, ``-1`` overturn, then each attractor
    as ``attractor<id>_<behaviour>_p<period>``."""
    values = [-2, -1] + [int(a.id) for a in attractors]
    meanings = ["unresolved", "overturn"] + [f"attractor{a.id}_{a.behaviour}_p{a.period}"
                                             for a in attractors]
    return dict(attrs, flag_values=np.asarray(values, dtype=np.int32),
                flag_meanings=" ".join(meanings))


def _grid_variables(res, dims, names):
    """The variables every grid result has, where present: label, period, attractor,
    uncertain, lambda_max, lambda_window, t_end (``dims`` of the label's axes)."""
    out = {"label": (dims, np.asarray(res.label), _flags(names, _meta("label"))),
           "period": (dims, np.asarray(res.period), _meta("period"))}
    if res.attractor is not None:
        out["attractor"] = (dims, np.asarray(res.attractor),
                            _attractor_flags(res.attractors, _meta("attractor")))
    if res.uncertain is not None:
        out["uncertain"] = (dims, np.asarray(res.uncertain), _meta("uncertain"))
    for name in ("lambda_max", "lambda_window", "t_end"):
        value = getattr(res, name)
        if value is not None:
            out[name] = (dims, np.asarray(value), _meta(name))
    return out


def _coord(name, values, dim=None):
    return ((dim or name,), np.asarray(values), _meta(name))


def sweep_dataset(res):
    """:meth:`rockjit.SweepResult.to_xarray`."""
    xr = xarray()
    dims = ("alpha",)
    data = _grid_variables(res, dims, res.names)
    data["strobe"] = (("alpha", "strobe_sample", "strobe_var"), np.asarray(res.strobe),
                      _meta("strobe"))
    data["impact_section"] = (("alpha", "impact", "impact_var"),
                              np.asarray(res.impact_section), _meta("impact_section"))
    if res.t_overturn is not None:
        data["t_overturn"] = (dims, np.asarray(res.t_overturn), _meta("t_overturn"))
    if res.motion is not None:
        data["motion"] = (dims, np.asarray(res.motion), _flags(res.names, _meta("motion")))
    coords = {"alpha": _coord("alpha", res.alpha),
              "strobe_var": ("strobe_var", np.array(["theta", "dtheta"])),
              "impact_var": ("impact_var", np.array(["t_mod_T", "dtheta_minus"]))}
    return xr.Dataset(data, coords=coords,
                      attrs=dataset_attrs(res.block, res.forcing, res.settings, "sweep"))


def basin_dataset(res):
    """:meth:`rockjit.BasinResult.to_xarray`."""
    xr = xarray()
    coords = {"theta0": _coord("theta0", res.theta0), "dtheta0": _coord("dtheta0", res.dtheta0)}
    return xr.Dataset(_grid_variables(res, ("theta0", "dtheta0"), res.names), coords=coords,
                      attrs=dataset_attrs(res.block, res.forcing, res.settings, "basin"))


def plane_dataset(res, kind="plane", **more):
    """:meth:`rockjit.PlaneResult.to_xarray`: dimensions ``(state, alpha, omega)``, the
    initial states ``z0`` as the coordinates ``theta0, dtheta0, r0, s0`` along ``state``."""
    xr = xarray()
    z0 = np.asarray(res.z0, dtype=float).reshape(-1, 4)
    coords = {"state": ("state", np.arange(z0.shape[0]),
                        dict(long_name="index of the initial state z0")),
              "alpha": _coord("alpha", res.alpha), "omega": _coord("omega", res.omega)}
    for k, name in enumerate(("theta0", "dtheta0", "r0", "s0")):
        coords[name] = _coord(name, z0[:, k], dim="state")
    return xr.Dataset(_grid_variables(res, ("state", "alpha", "omega"), res.names),
                      coords=coords,
                      attrs=dataset_attrs(res.block, res.forcing, res.settings, kind, **more))


def chart_dataset(res):
    """:meth:`rockjit.orbits.ChartResult.to_xarray`: its plane's dataset, the overturn onset
    per ``omega``, the curves' section phase and the chart's ranges."""
    ds = plane_dataset(res.plane, kind="chart", chart_phase=res.phase,
                       n_curves=len(res.curves), alpha_range=res.alpha_range,
                       omega_range=res.omega_range)
    ds["overturn_onset"] = (("omega",), np.asarray(res.overturn_onset),
                            _meta("overturn_onset"))
    return ds


def erosion_dataset(res, names):
    """:meth:`rockjit.basins.erosion.ErosionResult.to_xarray` (``names``: the behaviour names
    its label codes index)."""
    xr = xarray()
    dims3 = ("alpha", "theta0", "dtheta0")
    data = {name: (("alpha",), np.asarray(getattr(res, name)), _meta(name))
            for name in ("GIM", "IF", "basin_entropy", "boundary_basin_entropy", "overturn")}
    data["label"] = (dims3, np.asarray(res.label), _flags(names, _meta("label")))
    branches = res.branches
    data["attractor"] = (dims3, np.asarray(res.attractor), dict(
        _meta("attractor"), long_name="outcome: the branch reached (-1 overturn, "
                                      "-2 unresolved)",
        flag_values=np.asarray([-2, -1] + [int(b["id"]) for b in branches], dtype=np.int32),
        flag_meanings=" ".join(["unresolved", "overturn"] +
                               [f"branch{b['id']}_{b['behaviour']}_p{b['period']}"
                                for b in branches])))
    data["fraction"] = (("branch", "alpha"), res.fractions(), _meta("fraction"))
    data["branch_period"] = (("branch",), np.asarray([int(b["period"]) for b in branches],
                                                     dtype=np.int64),
                             dict(units="1", long_name="the branch's period"))
    data["branch_behaviour"] = (("branch",), np.asarray([str(b["behaviour"]) for b in branches],
                                                        dtype=str),
                                dict(long_name="the branch's behaviour"))
    coords = {"alpha": _coord("alpha", res.alpha), "theta0": _coord("theta0", res.theta0),
              "dtheta0": _coord("dtheta0", res.dtheta0),
              "branch": ("branch", np.asarray([int(b["id"]) for b in branches], dtype=np.int64),
                         dict(long_name="branch id: an attractor continued across alpha"))}
    return xr.Dataset(data, coords=coords,
                      attrs=dataset_attrs(res.block, res.forcing, res.settings, "erosion"))
