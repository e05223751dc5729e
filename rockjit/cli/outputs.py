"""What each command leaves on disk: its data (``.npz``), its figures and its summary.

One function per kind of result writes it into an output directory object
(:class:`rockjit.storage.files.OutputDir`, or anything with its ``npz`` and ``figure`` methods) and returns
the JSON-ready part of ``summary.json`` that describes it. The command line and the paper
(:func:`rockjit.study.paper`) both write through these, so a sweep or a basin has the same files
wherever it was computed.
"""

from __future__ import annotations

import numpy as np

__all__ = ["basins", "erosion", "fate", "fragility", "orbits", "plane", "spectrum", "sweep",
           "trajectory"]


def summary(out, command, inputs, wall, **results):
    """``summary.json``'s content: the command and its inputs, rockjit's version, the wall
    time, the behaviour names, every file written, and the command's ``results``."""
    from .. import __version__
    from ..result import BEHAVIOURS
    return dict(command=command, rockjit_version=__version__, inputs=inputs, wall_s=wall,
                behaviours=list(BEHAVIOURS), files=sorted(out.written + ["summary.json"]),
                **results)


def trajectory(out, res, *, npz="trajectory.npz", png="trajectory.png"):
    """One run: its arrays (``Result.arrays``) and :func:`rockjit.plotting.figures.fig_trajectory`."""
    from ..single import classify_result
    from ..plotting.figures import fig_trajectory
    name, period = classify_result(res)
    out.npz(npz, **res.arrays())
    out.figure(png, fig_trajectory(res))
    return dict(res.summary(), behaviour=name, period=period)


def sweep(out, sw, *, npz="sweep.npz", png="bifurcation.png"):
    """A sweep: its arrays and its bifurcation diagram."""
    from ..plotting.figures import fig_bifurcation
    out.npz(npz, **sw.arrays())
    if png:
        out.figure(png, fig_bifurcation(sw))
    summary = dict(n_alpha=int(sw.alpha.size), fractions=sw.fractions(), settings=sw.settings,
                   restitution=sw.block.restitution, attractors=sw.attractor_summary())
    if sw.uncertain is not None:
        summary["uncertain_percent"] = 100.0 * float(np.mean(sw.uncertain))
    return summary


def basins(out, res, *, npz="basin.npz", png="basin.png", attractors_png="attractors.png"):
    """One basin, or two laws' (a dict ``law: BasinResult``): the labels, attractor maps and
    (when computed) exponents and uncertain cells, per law when there are two; the behaviour
    map (with the two laws' agreement) and the attractor map with its measures."""
    from ..basins.identity import attractor_agreement
    from ..plotting.figures import agreement, fig_attractors, fig_basin, fig_basin_compare
    if not isinstance(res, dict):
        res = {res.block.law: res}
    first = next(iter(res.values()))
    arrays = dict(theta0=first.theta0, dtheta0=first.dtheta0,
                  names=np.asarray(first.names, dtype=str))

    def of(b, suffix):
        a = {"label": b.label, "period": b.period, "t_end": b.t_end, "attractor": b.attractor,
             "lambda_max": b.lambda_max, "uncertain": b.uncertain}
        return {k + suffix: v for k, v in a.items() if v is not None}

    def summary(b):
        s = b.summary()
        if b.uncertain is not None:
            s["uncertain_percent"] = 100.0 * float(np.mean(b.uncertain))
        return s

    if len(res) == 1:
        arrays.update(of(first, ""))
        results = summary(first)
        fig = fig_basin(first)
    else:
        for law, b in res.items():
            arrays.update(of(b, f"_{law}"))
        results = {law: summary(b) for law, b in res.items()}
        a, b = res.values()
        results["agreement"] = agreement(a.label, b.label)
        if a.attractor is not None and b.attractor is not None:
            results["attractor_agreement"] = attractor_agreement(a, b)
        fig = fig_basin_compare(a, b)
    out.npz(npz, **arrays)
    out.figure(png, fig)
    if attractors_png and first.attractor is not None:
        out.figure(attractors_png, fig_attractors(res))
    results.update(r0=first.settings.get("r0"), s0=first.settings.get("s0"))
    return results


def plane(out, pl, *, npz="plane.npz", png="plane.png"):
    """A plane from its first initial state: its arrays and its map."""
    from ..plotting.figures import fig_plane
    arrays = dict(alpha=pl.alpha, omega=pl.omega, z0=pl.z0, label=pl.label[0],
                  period=pl.period[0], lambda_max=pl.lambda_max[0], t_end=pl.t_end[0],
                  names=np.asarray(pl.names, dtype=str))
    for key in ("attractor", "uncertain"):
        if getattr(pl, key) is not None:
            arrays[key] = getattr(pl, key)[0]
    out.npz(npz, **arrays)
    out.figure(png, fig_plane(pl))
    summary = dict(fractions=pl.fractions(), settings=pl.settings,
                   restitution=pl.block.restitution, attractors=pl.attractor_summary())
    if pl.uncertain is not None:
        summary["uncertain_percent"] = 100.0 * float(np.mean(pl.uncertain))
    return summary


def erosion(out, res, *, npz="erosion.npz", png="erosion.png"):
    """Erosion profiles (a dict ``law: ErosionResult``): per law, the profile's arrays, and the
    profile figure."""
    from ..plotting.figures import fig_erosion
    first = next(iter(res.values()))
    out.npz(npz, alpha=first.alpha, theta0=first.theta0, dtheta0=first.dtheta0,
            **{k: v for law, r in res.items() for k, v in r.arrays(f"_{law}").items()})
    out.figure(png, fig_erosion(res))
    return {law: r.to_summary() for law, r in res.items()}


def fate(out, fr, *, npz="fate.npz", png="fate.png"):
    """An ensemble's outcomes: the members' initial states, outcomes and end times, and a
    figure of the outcome probabilities and the end times against the horizon."""
    from ..plotting.figures import fig_fate
    out.npz(npz, initial=fr.initial, outcome=fr.outcome, t_end=fr.t_end)
    out.figure(png, fig_fate(fr))
    return fr.to_summary()


def orbits(out, res, *, npz="orbits.npz", png="orbits.png"):
    """Branches of periodic orbits (``(Continuation, SweepResult)``): the branches' and
    bifurcations' arrays, the diagram with the branches over the sweep's dots, and the summary
    (``"bifurcations"``: type, alpha, period, multipliers, state)."""
    from ..plotting.figures import fig_branches
    cont, sw = res
    summary, arrays = cont.to_summary()
    out.npz(npz, **arrays)
    out.figure(png, fig_branches(cont, sw))
    summary["sweep_fractions"] = sw.fractions()
    return summary


def spectrum(out, res, *, npz="spectrum.npz", png="spectrum.png"):
    """Overturning spectra (a dict ``law: SpectrumResult``): the grid and, per law (suffixed
    ``_<law>`` with two laws), the outcomes, demands and located boundaries; the figure; the
    summary (``min_overturn`` per law, and where two laws differ)."""
    from ..ground.figures import fig_spectrum
    from ..ground.response import OUTCOMES
    from ..ground.spectrum import compare
    first = next(iter(res.values()))
    arrays = dict(ratio=first.ratio, amplitude=first.amplitude,
                  outcomes=np.asarray(OUTCOMES, dtype=str))
    two = len(res) == 2
    for law, sp in res.items():
        arrays.update(sp.arrays(f"_{law}" if len(res) > 1 else ""))
    out.npz(npz, **arrays)
    comparison = compare(*res.values()) if two else None
    out.figure(png, fig_spectrum(res, comparison))
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
    from ..ground.figures import fig_fragility, fig_rotation
    from ..ground.response import OUTCOMES
    out.npz(npz, outcomes=np.asarray(OUTCOMES, dtype=str), **fr.arrays())
    out.figure(png, fig_fragility(fr))
    out.figure(rotation_png, fig_rotation(fr))
    return dict(fr.summary(), outcomes=list(OUTCOMES))
