"""What each command leaves on disk: its data (``.npz``), its figures and its summary.

One function per kind of result writes it into an output directory object
(:class:`rockjit.storage.output_dir.OutputDir`, or anything with its ``npz``, ``figure`` and
``describe`` methods) and returns the JSON-ready part of ``summary.json`` that describes it.
The command line (:mod:`rockjit.cli`) and the paper (:func:`rockjit.study.paper.paper`) both
write through these, so a sweep or a basin has the same files wherever it was computed. Every
file is described (``out.describe``): ``summary.json`` lists each with what it holds.

The data come first and never depend on a figure: a figure that cannot be drawn or written is
left out and noted (``out.figure_failed``; ``summary.json``'s ``figures_failed``), and the
command goes on (the command line publishes the data and says so, exit status 3).
"""

from __future__ import annotations

import functools

import numpy as np

__all__ = ["basins", "chart", "erosion", "fate", "fragility", "manifest", "orbits", "plane",
           "spectrum", "sweep", "trajectory"]


def manifest(out):
    """``[{"name": ..., "holds": ...}]`` of every file written, ``summary.json`` included."""
    holds = dict(getattr(out, "holds", {}))
    holds.setdefault("summary.json", "this manifest, the command, its inputs, rockjit's "
                                     "version, the wall time and the results in numbers")
    return [dict(name=n, holds=holds.get(n, "")) for n in sorted(set(out.written)
                                                                 | {"summary.json"})]


def summary(out, command, inputs, wall, **results):
    """``summary.json``'s content: the command and its inputs, rockjit's version, the wall
    time, the behaviour names, every file written with what it holds (``files``), the figures
    that could not be drawn (``figures_failed``, only if any) and the command's ``results``."""
    from . import __version__
    from .result import BEHAVIOURS
    failed = list(getattr(out, "figure_errors", []))
    extra = dict(figures_failed=failed) if failed else {}
    return dict(command=command, rockjit_version=__version__, inputs=inputs, wall_s=wall,
                behaviours=list(BEHAVIOURS), files=manifest(out), **extra, **results)


def _figure(out, name, draw, holds):
    """Draw a figure (``draw()``, or a figure already drawn), write it in the output's format
    and describe it; returns its name. Where it cannot be drawn or written and ``out`` can note
    that (``figure_failed``), it is noted and ``None`` returned: the data stay."""
    fig = None
    try:
        fig = draw() if callable(draw) else draw
        written = out.figure(name, fig)
    except Exception as exc:  # any failure of a drawing: the data must not be lost with it
        if not hasattr(out, "figure_failed"):
            raise
        if fig is not None:
            import matplotlib.pyplot as plt
            plt.close(fig)
        out.figure_failed(name, exc)
        return None
    written = written if isinstance(written, str) else name
    out.describe(written, holds)
    return written


def _npz(out, name, holds, **arrays):
    out.npz(name, **arrays)
    out.describe(name, holds)
    return name


def trajectory(out, res, *, npz="trajectory.npz", png="trajectory.png"):
    """One run: its arrays (``Result.arrays``) and
    :func:`rockjit.plotting.timeseries.fig_trajectory`."""
    from .single import classify_result
    from .plotting.timeseries import fig_trajectory
    name, period = classify_result(res)
    _npz(out, npz, "the run's arrays: t, theta, dtheta, r, s (recorded trajectory), strobe, "
                   "strobe_half, impacts (t, dtheta-, dtheta+), lyapunov_running", **res.arrays())
    _figure(out, png, lambda: fig_trajectory(res, (name, period)),
            f"theta(t) over the first and the last periods, the running exponent and the "
            f"phase portrait (data: {npz})")
    return dict(res.summary(), behaviour=name, period=period)


def sweep(out, sw, *, npz="sweep.npz", png="bifurcation.png"):
    """A sweep: its arrays and its bifurcation diagram."""
    from .plotting.forcing import fig_bifurcation
    _npz(out, npz, "the sweep: alpha, label (behaviour codes, names), period, lambda_max "
                   "(exact where periodic), lambda_window (finite-window estimate), strobe "
                   "(theta, theta' at kT), impact_section, t_end, attractor", **sw.arrays())
    if png:
        _figure(out, png, lambda: fig_bifurcation(sw),
                f"bifurcation diagram: theta'(kT) against alpha by behaviour, lambda_max "
                f"below (data: {npz})")
    summary = dict(n_alpha=int(sw.alpha.size), fractions=sw.fractions(), settings=sw.settings,
                   restitution=sw.block.restitution, attractors=sw.attractor_summary())
    if sw.uncertain is not None:
        summary["uncertain_percent"] = 100.0 * float(np.mean(sw.uncertain))
    return summary


def basins(out, res, *, npz="basin.npz", png="basin.png", attractors_png="attractors.png"):
    """One basin, or two laws' (a dict ``law: BasinResult``): the labels, attractor maps and
    (when computed) exponents and uncertain cells, per law when there are two; the behaviour
    map (with the two laws' agreement) and the attractor map with its measures."""
    from .grids.identity import agreement, attractor_agreement
    from .plotting.basins import fig_attractors, fig_basin, fig_basin_compare
    if not isinstance(res, dict):
        res = {res.block.law: res}
    first = next(iter(res.values()))
    arrays = dict(theta0=first.theta0, dtheta0=first.dtheta0,
                  names=np.asarray(first.names, dtype=str))

    def of(b, suffix):
        a = {"label": b.label, "period": b.period, "t_end": b.t_end, "attractor": b.attractor,
             "lambda_max": b.lambda_max, "lambda_window": b.lambda_window,
             "uncertain": b.uncertain}
        return {k + suffix: v for k, v in a.items() if v is not None}

    def summary(b):
        s = b.summary()
        if b.uncertain is not None:
            s["uncertain_percent"] = 100.0 * float(np.mean(b.uncertain))
        return s

    if len(res) == 1:
        arrays.update(of(first, ""))
        results = summary(first)
        draw = functools.partial(fig_basin, first)
    else:
        for law, b in res.items():
            arrays.update(of(b, f"_{law}"))
        results = {law: summary(b) for law, b in res.items()}
        a, b = res.values()
        results["agreement"] = agreement(a.label, b.label)
        if a.attractor is not None and b.attractor is not None:
            results["attractor_agreement"] = attractor_agreement(a, b)
        draw = functools.partial(fig_basin_compare, a, b)
    laws = " per law (suffix _<law>)" if len(res) > 1 else ""
    _npz(out, npz, f"theta0, dtheta0 and{laws} label (label[i, j] of theta0[i], dtheta0[j]), "
                   f"period, t_end, attractor ids, exponents and uncertain cells when "
                   f"computed", **arrays)
    _figure(out, png, draw, f"the behaviour of each initial state{laws}"
                           + (" and where the laws agree" if len(res) > 1 else "")
                           + f" (data: {npz})")
    if attractors_png and first.attractor is not None:
        _figure(out, attractors_png, lambda: fig_attractors(res),
                f"the attractor each initial state reaches, by name, with basin entropy and "
                f"integrity (data: {npz}, attractor)")
    results.update(r0=first.settings.get("r0"), s0=first.settings.get("s0"))
    return results


def plane(out, pl, *, npz="plane.npz", png="plane.png"):
    """A plane from its first initial state: its arrays and its map."""
    from .plotting.forcing import fig_plane
    arrays = dict(alpha=pl.alpha, omega=pl.omega, z0=pl.z0, label=pl.label[0],
                  period=pl.period[0], lambda_max=pl.lambda_max[0], t_end=pl.t_end[0],
                  names=np.asarray(pl.names, dtype=str))
    if pl.lambda_window is not None:
        arrays["lambda_window"] = pl.lambda_window[0]
    for key in ("attractor", "uncertain"):
        if getattr(pl, key) is not None:
            arrays[key] = getattr(pl, key)[0]
    _npz(out, npz, "alpha, omega, z0, label (label[i, j] of alpha[i], omega[j]), period, "
                   "lambda_max (exact where periodic), lambda_window, t_end, attractor",
         **arrays)
    _figure(out, png, lambda: fig_plane(pl),
            f"behaviour and lambda_max over the forcing plane (data: {npz})")
    summary = dict(fractions=pl.fractions(), settings=pl.settings,
                   restitution=pl.block.restitution, attractors=pl.attractor_summary())
    if pl.uncertain is not None:
        summary["uncertain_percent"] = 100.0 * float(np.mean(pl.uncertain))
    return summary


def erosion(out, res, *, npz="erosion.npz", png="erosion.png"):
    """Erosion profiles (a dict ``law: ErosionResult``): per law, the profile's arrays, and the
    profile figure."""
    from .plotting.basins import fig_erosion
    first = next(iter(res.values()))
    _npz(out, npz, "alpha, theta0, dtheta0 and per law (suffix _<law>): GIM, IF, fractions "
                   "(each attractor's percent at each alpha), overturn, basin_entropy, the "
                   "attractor and label maps of every basin",
         alpha=first.alpha, theta0=first.theta0, dtheta0=first.dtheta0,
         **{k: v for law, r in res.items() for k, v in r.arrays(f"_{law}").items()})
    _figure(out, png, lambda: fig_erosion(res),
            f"integrity (GIM, IF) against alpha and the basin of each attractor, stacked "
            f"(data: {npz})")
    return {law: r.to_summary() for law, r in res.items()}


def fate(out, fr, *, npz="fate.npz", png="fate.png"):
    """An ensemble's outcomes: the members' initial states, outcomes and end times, and a
    figure of the outcome probabilities and the end times against the horizon."""
    from .plotting.fates import fig_fate
    _npz(out, npz, "the members' initial states, outcome ids (-1 overturn, -2 unresolved, "
                   "attractors from 0) and end times", initial=fr.initial, outcome=fr.outcome,
         t_end=fr.t_end)
    _figure(out, png, lambda: fig_fate(fr),
            f"each outcome's probability and when each member's run ended (data: {npz})")
    return fr.to_summary()


def orbits(out, res, *, npz="orbits.npz", png="orbits.png", caption="orbits.md"):
    """Branches of periodic orbits (``(Continuation, SweepResult)``): the branches' and
    bifurcations' arrays, the diagram with the branches over the sweep's dots, its caption
    (every bifurcation and where each branch stops) and the summary (``"bifurcations"``: type,
    alpha, period, multipliers, state)."""
    from .plotting.branches import branch_caption, fig_branches
    cont, sw = res
    summary, arrays = cont.to_summary()
    _npz(out, npz, "per branch i: branch{i}_value, _cycle, _multipliers, _stable, ...; the "
                   "bifurcations: bif_type, bif_value, bif_period, bif_multipliers",
         **arrays)
    _figure(out, png, lambda: fig_branches(cont, sw),
            f"branches of periodic orbits over the sweep, bifurcations marked (data: {npz}; "
            f"list: {caption})")
    out.text(caption, branch_caption(cont))
    out.describe(caption, "the branches' caption: every bifurcation with its multipliers and "
                          "where and why each branch stops")
    summary["sweep_fractions"] = sw.fractions()
    return summary


def chart(out, res, *, npz="chart.npz", png="chart.png"):
    """Charts with their bifurcation curves (a dict ``law: ChartResult``): the charts' labels
    and every curve's arrays (``curve{i}_alpha``, ``_omega``, ``_state``, ``_multipliers``,
    ``_condition``, ...; ``curve_type``, ``curve_period``, ``curve_law``), the figure
    (:func:`rockjit.plotting.chart.fig_chart`), and the summary: ``"curves"`` (type, period,
    law, points ``[[alpha, omega], ...]``, ends, codimension-two points, residuals) and, per
    law, the chart's fractions, seeds, refusals and timing."""
    from .plotting.chart import fig_chart
    arrays, charts, curves = {}, {}, []
    two = len(res) > 1
    for law, r in res.items():
        summary, a = r.to_summary(suffix=f"_{law}" if two else "")
        arrays.update(a)
        charts[law] = summary
        for c in r.curves:
            arrays.update(c.arrays(f"curve{len(curves)}_"))
            curves.append(c)
    arrays["curve_type"] = np.array([c.type for c in curves], dtype="U24")
    arrays["curve_period"] = np.array([c.period for c in curves], np.int64)
    arrays["curve_law"] = np.array([c.law for c in curves], dtype="U16")
    _npz(out, npz, "the charts' labels, periods and axes (suffix _<law> with two laws) and "
                   "every bifurcation curve: curve{i}_alpha, _omega, _state, _multipliers, "
                   "_condition; curve_type, curve_period, curve_law", **arrays)
    figure = _figure(out, png, lambda: fig_chart(res),
                     f"the behaviour chart over (alpha, omega) with its bifurcation curves, per "
                     f"law and both overlaid (data: {npz})")
    return dict(curves=[c.to_dict() for c in curves], charts=charts, figure=figure)


def spectrum(out, res, *, npz="spectrum.npz", png="spectrum.png"):
    """Overturning spectra (a dict ``law: SpectrumResult``): the grid and, per law (suffixed
    ``_<law>`` with two laws), the outcomes, demands and located boundaries; the figure; the
    summary (``min_overturn`` per law, and where two laws differ)."""
    from .ground.figures import fig_spectrum
    from .ground.response import OUTCOMES
    from .ground.spectrum import compare
    first = next(iter(res.values()))
    arrays = dict(ratio=first.ratio, amplitude=first.amplitude,
                  outcomes=np.asarray(OUTCOMES, dtype=str))
    two = len(res) == 2
    for law, sp in res.items():
        arrays.update(sp.arrays(f"_{law}" if len(res) > 1 else ""))
    _npz(out, npz, "the spectrum's axes ratio (omega_p/p) and amplitude (a_p/(g tan alpha)) "
                   "and, per law (suffix _<law> with two laws), every cell's outcome (index "
                   "into outcomes), max rotation and the located minimum overturning amplitude "
                   "per ratio with its mode", **arrays)
    comparison = compare(*res.values()) if two else None
    _figure(out, png, lambda: fig_spectrum(res),
            f"the overturning spectrum: the two modes of overturning and the safe region, per "
            f"law (data: {npz})")
    if len(res) == 1:
        return dict(first.summary(), outcomes=list(OUTCOMES))
    summary = {law: sp.summary() for law, sp in res.items()}
    summary["outcomes"] = list(OUTCOMES)
    if comparison is not None:
        summary["comparison"] = comparison
    return summary


def fragility(out, fr, *, npz="fragility.npz", png="fragility.png", rotation_png="rotation.png"):
    """An incremental dynamic analysis: every run's outcome and demand, the fitted curves'
    figures and their summary."""
    from .ground.figures import fig_fragility, fig_rotation
    from .ground.response import OUTCOMES
    _npz(out, npz, "every run of the incremental dynamic analysis: record, size, intensity, "
                   "law, outcome (index into outcomes), max rotation; the fitted fragility "
                   "curves' medians and dispersions", outcomes=np.asarray(OUTCOMES, dtype=str),
         **fr.arrays())
    _figure(out, png, lambda: fig_fragility(fr),
            f"the overturning fraction against intensity with the lognormal fragility fits, "
            f"both laws (data: {npz})")
    _figure(out, rotation_png, lambda: fig_rotation(fr),
            f"rotation exceedance (max|theta|/alpha_s >= 0.5 and 1) against intensity "
            f"(data: {npz})")
    return dict(fr.summary(), outcomes=list(OUTCOMES))
