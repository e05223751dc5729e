"""Short text of the result types (their ``repr``): what was computed, its shape, the headline
numbers, in a handful of lines, as xarray prints a dataset.

Every result type's ``__repr__`` calls :func:`text`; the arrays themselves stay one attribute
away (``print(res.label)``). A summary never prints an array's values, so its length does not
grow with the grid.
"""

from __future__ import annotations

import math

import numpy as np

__all__ = ["MAX_LINES", "MAX_WIDTH", "text"]

#: The longest a summary gets: lines, and characters per line.
MAX_LINES = 12
MAX_WIDTH = 100


def _g(v, fmt=".4g"):
    try:
        v = float(v)
    except (TypeError, ValueError):
        return str(v)
    return format(v, fmt) if math.isfinite(v) else str(v)


def _shape(a):
    return "None" if a is None else "(" + ", ".join(str(n) for n in np.shape(a)) + \
        ("," if np.ndim(a) == 1 else "") + ")"


def _span(a, name=""):
    a = np.asarray(a, dtype=float).ravel()
    lead = f"{name} " if name else ""
    if a.size == 0:
        return lead + "none"
    if a.size == 1:
        return lead + _g(a[0])
    return f"{lead}{_g(a.min())} to {_g(a.max())} ({a.size} values)"


def _block(b):
    if b is None:
        return "–"
    e = getattr(b, "restitution", None)
    return f"h/b = {_g(b.hb)}, {b.law} law" + (f" (e = {_g(e, '.3f')})" if e is not None else "")


def _shares(percent, limit=4):
    """``{name: percent}`` as "name 52.0 %, ...", largest first, zeros left out."""
    items = sorted(((k, float(v)) for k, v in percent.items() if float(v) > 0),
                   key=lambda kv: -kv[1])
    words = [f"{k} {v:.1f} %" for k, v in items[:limit]]
    if len(items) > limit:
        words.append(f"… {len(items) - limit} more")
    return ", ".join(words) if words else "none"


def _arrays(obj, names):
    """The arrays ``names`` of ``obj`` grouped by shape: "label, period (501,); strobe (...)"."""
    groups = {}
    for n in names:
        a = getattr(obj, n, None)
        if a is not None:
            groups.setdefault(_shape(a), []).append(n)
    return "; ".join(f"{', '.join(ns)} {shape}" for shape, ns in groups.items())


def _wrap(key, value):
    """One row, its value carried on to further lines at "; " or ", " where it is too long."""
    lines, head = [], f"  {key:<11} "
    while len(head) + len(value) > MAX_WIDTH:
        room = MAX_WIDTH - len(head)
        cut = max(value.rfind("; ", 0, room), value.rfind(", ", 0, room))
        if cut <= 0:
            break
        lines.append(head + value[:cut + 1])
        value, head = value[cut + 2:], " " * len(head)
    return lines + [head + value]


def _lines(title, rows):
    out = [f"<rockjit.{title}>"]
    for k, v in rows:
        if v is not None:
            out += _wrap(k, v)
    out = [_one(ln) for ln in out]
    return "\n".join(out[:MAX_LINES])


def _one(line):
    return line if len(line) <= MAX_WIDTH else line[:MAX_WIDTH - 1] + "…"


def _attractors(res):
    atts = getattr(res, "attractors", None) or []
    if not atts:
        return None
    names = [a.name for a in atts]
    shown = ", ".join(names[:4]) + (f", … {len(names) - 4} more" if len(names) > 4 else "")
    return f"{len(atts)}: {shown}"


def _forcing(f, skip=()):
    if f is None:
        return None
    parts = [f"{k} = {_g(getattr(f, k))}" for k in ("alpha", "omega")
             if k not in skip and getattr(f, k, None) is not None]
    if getattr(f, "embedded", False):
        parts.append("embedded")
    return (type(f).__name__ + (": " + ", ".join(parts) if parts else "")) if parts or \
        type(f).__name__ != "Harmonic" else "Harmonic"


def _sweep(r):
    return _lines(f"SweepResult: {r.alpha.size} amplitudes", [
        ("block", _block(r.block)), ("forcing", _forcing(r.forcing, skip=("alpha",))),
        ("alpha", _span(r.alpha)),
        ("behaviours", _shares(r.fractions())),
        ("attractors", _attractors(r)),
        ("arrays", _arrays(r, ("label", "period", "lambda_max", "lambda_window", "t_end",
                               "strobe", "impact_section")))])


def _basin(r):
    g = "×".join(str(n) for n in np.shape(r.label))
    return _lines(f"BasinResult: {g} initial states", [
        ("block", _block(r.block)), ("forcing", _forcing(r.forcing)),
        ("theta0", _span(r.theta0)), ("dtheta0", _span(r.dtheta0)),
        ("behaviours", _shares(r.fractions())),
        ("attractors", _attractors(r)),
        ("arrays", _arrays(r, ("label", "period", "lambda_max", "t_end", "attractor",
                               "uncertain")))])


def _plane(r):
    m, na, nw = np.shape(r.label)
    return _lines(f"PlaneResult: {na}×{nw} forcings, {m} initial state{'s' * (m != 1)}", [
        ("block", _block(r.block)),
        ("alpha", _span(r.alpha)), ("omega", _span(r.omega)),
        ("behaviours", _shares(r.fractions())),
        ("attractors", _attractors(r)),
        ("arrays", _arrays(r, ("label", "period", "lambda_max", "t_end", "attractor")))])


def _erosion(r):
    g = "×".join(str(n) for n in np.shape(r.attractor)[1:])
    a = np.asarray(r.alpha, dtype=float)
    ends = (lambda x: f"{_g(x[0], '.3f')} at alpha = {_g(a[0])} to {_g(x[-1], '.3f')} at "
                      f"{_g(a[-1])}") if a.size else (lambda x: "–")
    return _lines(f"ErosionResult: {a.size} amplitudes × {g} basins", [
        ("block", _block(r.block)), ("forcing", _forcing(r.forcing, skip=("alpha",))),
        ("alpha", _span(a)),
        ("GIM", ends(np.asarray(r.GIM))), ("IF", ends(np.asarray(r.IF))),
        ("branches", f"{len(r.branches)} attractors followed across the amplitudes"),
        ("arrays", _arrays(r, ("GIM", "IF", "overturn", "basin_entropy", "attractor",
                               "label")))])


def _safety(r):
    na, nw = np.shape(r.safe)
    g = "×".join(str(np.size(x)) for x in (r.theta0, r.dtheta0))
    s = np.asarray(r.safe, dtype=float)
    return _lines(f"SafetyResult: {na}×{nw} forcings × {g} basins", [
        ("block", _block(r.block)),
        ("alpha", _span(r.alpha)), ("omega", _span(r.omega)),
        ("safe", f"{_g(np.nanmin(s), '.3f')} to {_g(np.nanmax(s), '.3f')} of the initial states"
                 if s.size else None),
        ("attractors", f"up to {int(np.max(r.n_attractors, initial=0))} per forcing"),
        ("arrays", _arrays(r, ("safe", "GIM", "IF", "LIM", "n_attractors")))])


def _fate(r):
    return _lines(f"FateResult: {np.size(r.outcome)} runs near one initial state", [
        ("block", _block(r.block)), ("forcing", _forcing(r.forcing)),
        ("outcomes", ", ".join(f"{k} {v:.1%}" for k, v in r.probabilities.items())),
        ("lambda1", f"{_g(r.lambda1, '.3f')} (the nominal run's transient)"),
        ("horizon", f"{_g(r.horizon, '.1f')} at the largest perturbation, "
                    f"{_g(r.horizon_rounding, '.1f')} from rounding alone"),
        ("arrays", _arrays(r, ("outcome", "t_end", "initial")))])


def _attractor(a):
    lam = np.asarray(a.lam, dtype=float)
    mu = "" if a.multipliers is None else \
        ", |mu| = " + ", ".join(_g(abs(m), ".3g") for m in np.asarray(a.multipliers))
    return _one(f"Attractor({a.id}: {a.name}, {a.fraction:.1f} % of the cells, "
                f"lambda1 = {_g(lam[0], '.3g')}{mu})")


def _orbit(o):
    mu = ", ".join(_g(abs(m), ".4g") for m in np.asarray(o.multipliers))
    return _lines(f"PeriodicOrbit: period {o.period}, "
                  f"{'symmetric' if o.symmetric else 'asymmetric'}, "
                  f"{'stable' if o.stable else 'unstable'}", [
                      ("block", _block(o.block)),
                      ("forcing", f"alpha = {_g(o.alpha, '.7g')}, omega = {_g(o.omega, '.7g')}"),
                      ("state", "theta, theta' = " + ", ".join(_g(v, ".6g")
                                                              for v in np.ravel(o.state)[:2])),
                      ("|mu|", mu),
                      ("impacts", f"{o.impacts} per {o.period} period{'s' * (o.period != 1)}"),
                      ("residual", f"{_g(o.residual, '.2e')} after {o.iterations} iterations")])


def _branch(b):
    v = np.asarray(b.value, dtype=float)
    st = np.asarray(b.stable, dtype=bool)
    return _lines(f"Branch: period {b.period}, {len(v)} orbits along {b.parameter}", [
        (b.parameter, _span(v)),
        ("stable", f"{int(st.sum())} of {st.size} orbits"),
        ("kind", "symmetric" if b.symmetric else "asymmetric"),
        ("ends", "; ".join(str(e) for e in b.ends) if b.ends else "–"),
        ("origin", str(b.origin))])


def _bifurcation(b):
    mu = ", ".join(_g(abs(m), ".4g") for m in np.asarray(b.multipliers))
    where = f"{b.parameter} = {_g(b.value, '.9g')}" + ("" if b.located else " (not located)")
    return _one(f"Bifurcation({b.type.replace('_', ' ')}, period {b.period}, {where}, "
                f"omega = {_g(b.omega, '.7g')}, |mu| = {mu})")


def _continuation(c):
    kinds = {}
    for b in c.bifurcations:
        kinds[b.type.replace("_", " ")] = kinds.get(b.type.replace("_", " "), 0) + 1
    return _lines(f"Continuation: {len(c.branches)} branches along {c.parameter}", [
        ("block", _block(getattr(c, "block", None))),
        ("periods", ", ".join(str(p) for p in sorted({b.period for b in c.branches})) or "–"),
        ("bifurcations", ", ".join(f"{n} {k}" for k, n in kinds.items()) or "none")])


def _chart(r):
    na, nw = np.shape(r.label())
    kinds = {}
    for c in r.curves:
        t = str(getattr(c, "type", "curve")).replace("_", " ")
        kinds[t] = kinds.get(t, 0) + 1
    return _lines(f"ChartResult: {na}×{nw} forcings and {len(r.curves)} bifurcation curves", [
        ("block", _block(r.block)),
        ("alpha", f"{_g(r.alpha_range[0])} to {_g(r.alpha_range[1])}"),
        ("omega", f"{_g(r.omega_range[0])} to {_g(r.omega_range[1])}"),
        ("behaviours", _shares(r.plane.fractions())),
        ("curves", ", ".join(f"{n} {k}" for k, n in kinds.items()) or "none"),
        ("seeds", f"{len(r.seeds)} bifurcations on the seed lines, {len(r.refused)} refused")])


def _spectrum(r):
    shares = r.fractions()
    return _lines(f"SpectrumResult: {np.size(r.ratio)}×{np.size(r.amplitude)} pulses", [
        ("block", _block(r.block)), ("pulse", getattr(r.pulse, "kind", str(r.pulse))),
        ("ratio", _span(r.ratio)), ("amplitude", _span(r.amplitude)),
        ("outcomes", _shares(shares)),
        ("method", f"{r.method or '–'}, {r.n_runs} runs"),
        ("arrays", _arrays(r, ("outcome", "max_rotation", "t_overturn", "n_impacts",
                               "min_overturn")))])


def _fit(fit, size):
    """A lognormal fit's median and beta, or why there are none: its status, with the headline
    of its reason (what comes before the first ":") where that is short and the median's bound
    where there is one."""
    where = f"size {_g(size)}"
    if fit.status == "ok":
        return f"median {_g(fit.median, '.3g')}, beta {_g(fit.beta, '.3g')} ({where})"
    words = fit.status.replace("_", " ")
    head = fit.reason.split(":", 1)[0].strip()
    if head and len(head) <= _SHORT_REASON:
        words += f": {head}"
    if math.isfinite(fit.bound):
        where = f"bound {_g(fit.bound, '.3g')}, {where}"
    return f"{words} ({where})"


#: The longest headline of a reason a summary quotes (the whole reason is in ``.reason``).
_SHORT_REASON = 48


def _fragility(r):
    laws = ", ".join(r.laws)
    rows = [("block", _block(r.block)), ("laws", laws),
            ("sizes", ", ".join(_g(s) for s in np.ravel(r.sizes))),
            ("records", f"{len(r.records)} records"),
            ("intensity", _span(r.intensity, r.measure))]
    for law in r.laws:
        by_size = r.fits.get(law) or {}   # a result may hold no fits
        if not by_size:
            continue
        size, fits = next(iter(by_size.items()))
        fit = fits.get("overturn")
        if fit is not None:
            rows.append((law, f"overturn {_fit(fit, size)}"))
    rows.append(("arrays", _arrays(r, ("outcome", "max_rotation", "t_overturn", "scale"))))
    return _lines(f"FragilityResult: {len(r.laws)} law{'s' * (len(r.laws) != 1)} × "
                  f"{np.size(r.sizes)} size{'s' * (np.size(r.sizes) != 1)} × "
                  f"{len(r.records)} records × {np.size(r.intensity)} intensities", rows)


_BY_TYPE = {"SweepResult": _sweep, "BasinResult": _basin, "PlaneResult": _plane,
            "ErosionResult": _erosion, "SafetyResult": _safety,
            "FateResult": _fate, "Attractor": _attractor,
            "PeriodicOrbit": _orbit, "Branch": _branch, "Bifurcation": _bifurcation,
            "Continuation": _continuation, "ChartResult": _chart,
            "SpectrumResult": _spectrum, "FragilityResult": _fragility}


def text(obj):
    """The short text of a result (the module docstring): a few lines, none wider than
    :data:`MAX_WIDTH`, whatever the size of the arrays.

    Parameters
    ----------
    obj : object
        A result: ``SweepResult``, ``BasinResult``, ``PlaneResult``, ``ErosionResult``,
        ``FateResult``, ``Attractor``, ``PeriodicOrbit``, ``Branch``, ``Bifurcation``,
        ``Continuation``, ``ChartResult``, ``SpectrumResult`` or ``FragilityResult``.

    Returns
    -------
    str

    Examples
    --------
    >>> import rockjit
    >>> from rockjit import Block, Harmonic, Integration
    >>> b = rockjit.basin(Block(hb=1), Harmonic(alpha=0.66, omega=1.3), grid=10,
    ...                   integration=Integration(periods=100))
    >>> print(b)  # doctest: +ELLIPSIS
    <rockjit.BasinResult: 10×10 initial states>
      block       h/b = 1, housner law (e = 0.250)
      forcing     Harmonic: alpha = 0.66, omega = 1.3
      theta0      -1 to 1 (10 values)
      dtheta0     -1 to 1 (10 values)
      behaviours  symmetric 52.0 %, overturn 48.0 %
      attractors  2: symmetric p=1, symmetric p=1
      arrays      label, period, t_end, attractor (10, 10)
    """
    return _BY_TYPE[type(obj).__name__](obj)
