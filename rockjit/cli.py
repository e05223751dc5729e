"""The ``rockjit`` command line: single runs, sweeps, basins, the restitution table, the paper.

Every subcommand validates all of its input before any computation (a bad value ends the
command with one line ``rockjit: error: ...`` on stderr and exit status 2, having written
nothing), computes, and only then creates ``--out DIR`` and writes its data, its figure(s) and
``summary.json`` there, each file atomically (:mod:`rockjit.io`), ``summary.json`` last. An
interrupted command (Ctrl-C: exit status 130) leaves no partial or temporary file; only
``paper``, which writes each part as soon as it is done, can leave the complete files of the
parts finished before the interruption (and no ``summary.json``).

JSON files write non-finite numbers as the strings ``"nan"``, ``"inf"``, ``"-inf"``
(:mod:`rockjit.io`).
"""

from __future__ import annotations

import argparse
import math
import os
import shutil
import sys
import time
from pathlib import Path

import numpy as np

__all__ = ["main", "build_parser"]

PROG = "rockjit"

#: The study's settings (SPEC.md §7).
STUDY = {
    1: dict(omega=1.3, alpha_range={"housner": (0.5, 1.0), "mao": (0.3, 0.8)}),
    2: dict(omega=1.6, alpha_range={"housner": (0.1, 0.5), "mao": (0.1, 0.5)}),
}
ZOOM = (0.88, 0.98)
LAWS_IC = ((0.8586, -0.8182), (-0.0505, -0.2121), (0.3535, -0.3333))
BASIN_CASES = ((1.0, 0.66, 1.3), (2.0, 0.2, 1.6))
MAX_TRAJ_POINTS = 50_000
IVP_METHODS = ("RK23", "RK45", "DOP853", "Radau", "BDF", "LSODA")


class UsageError(Exception):
    """Bad command-line input: reported in one line, exit status 2."""


class _Parser(argparse.ArgumentParser):
    def error(self, message):  # one line, not argparse's usage dump
        raise UsageError(message)


# ---------------------------------------------------------------------------------------------
# Small helpers
# ---------------------------------------------------------------------------------------------

def _say(args, msg):
    if not getattr(args, "quiet", False):
        print(f"{PROG}: {msg}", file=sys.stderr, flush=True)


def _check_out(out):
    """``out`` must be a directory or creatable as one; nothing is created here."""
    p = Path(out)
    if p.exists() and not p.is_dir():
        raise UsageError(f"--out must be a directory (got {out}, an existing file)")
    q = p
    while not q.exists():
        q = q.parent
    if not q.is_dir() or not os.access(q, os.W_OK | os.X_OK):
        raise UsageError(f"--out {out} cannot be created or written ({q} is not writable)")
    return p


def _check_threads(threads):
    if threads is None:
        return None
    import numba
    hi = numba.config.NUMBA_NUM_THREADS
    if not 1 <= threads <= hi:
        raise UsageError(f"threads must be in [1, {hi}] (got {threads})")
    return threads


def _check_positive_int(name, value, lo=1):
    if value < lo:
        raise UsageError(f"{name} must be >= {lo} (got {value})")
    return value


def _block(hb, alpha, omega, law, e):
    from .model import Block
    return Block(hb=hb, alpha=alpha, omega=omega, law=law, e=e)


def _settings(periods, n_steps, period=None, default=None):
    """Validated periods and steps per period; ``n_steps=None`` resolves to the library's
    default for a forcing period ``period`` (or stays None when that is not known here)."""
    from .simulate import check_settings, steps_per_period
    if n_steps is None and period is not None:
        n_steps = steps_per_period(period, default)
    periods, n_checked, *_ = check_settings(periods, 8 if n_steps is None else n_steps,
                                            100_000, None, None)
    return periods, (None if n_steps is None else n_checked)


def _forcing(args, default):
    """``(phi, r0, s0)`` from ``--phase`` or ``--r0/--s0``, else ``default = (r0, s0)``."""
    from .simulate import forcing_phase
    forcing = getattr(args, "forcing", "closed")
    if args.phase is None and args.r0 is None and args.s0 is None:
        return forcing_phase(None, default[0], default[1], forcing)
    return forcing_phase(args.phase, args.r0, args.s0, forcing)


def _version():
    from . import __version__
    return __version__


class _Out:
    """Creates the output directory on the first write and lists what was written."""

    def __init__(self, path):
        self.path = Path(path)
        self.written = []

    def _target(self, name):
        self.path.mkdir(parents=True, exist_ok=True)
        self.written.append(name)
        return self.path / name

    def json(self, name, obj):
        from .io import write_json
        write_json(self._target(name), obj)

    def npz(self, name, **arrays):
        from .io import write_npz
        write_npz(self._target(name), **arrays)

    def figure(self, name, fig):
        from .io import save_figure
        save_figure(fig, self._target(name))
        fig.clear()

    def table(self, stem, header, rows, fmt=None):
        """CSV and Markdown versions of one table."""
        from .io import write_csv, write_text
        write_csv(self._target(stem + ".csv"), header, rows)
        write_text(self._target(stem + ".md"), _markdown(header, rows, fmt))


def _markdown(header, rows, fmt=None):
    fmt = fmt or {}

    def cell(i, v):
        if isinstance(v, (float, np.floating)):
            return format(float(v), fmt.get(header[i], ".4g"))
        return str(v)

    lines = ["| " + " | ".join(header) + " |",
             "|" + "|".join("---" for _ in header) + "|"]
    lines += ["| " + " | ".join(cell(i, v) for i, v in enumerate(r)) + " |" for r in rows]
    return "\n".join(lines) + "\n"


def _inputs(args):
    return {k: v for k, v in vars(args).items() if k not in ("func", "validate")}


def _summary(args, wall, **results):
    from .analysis import BEHAVIOURS
    return dict(command=args.command, rockjit_version=_version(), inputs=_inputs(args),
                wall_s=wall, behaviours=list(BEHAVIOURS), **results)


# ---------------------------------------------------------------------------------------------
# trajectory
# ---------------------------------------------------------------------------------------------

def _check_method(method, lyapunov):
    if method == "rockjit" or method == "scipy":
        ok = True
    elif method.startswith("scipy:"):
        ok = method.split(":", 1)[1] in IVP_METHODS
    else:
        ok = False
    if not ok:
        raise UsageError(f"method must be 'rockjit', 'scipy' or 'scipy:<one of "
                         f"{', '.join(IVP_METHODS)}>' (got {method!r})")
    if lyapunov and method != "rockjit":
        raise UsageError("--lyapunov needs --method rockjit")


def _trajectory_validate(args):
    from .simulate import Z0_STUDY, _real
    from .simulate import DEFAULT_N
    block = _block(args.hb, args.alpha, args.omega, args.law, args.e)
    periods, n_steps = _settings(args.periods, args.n_steps, block.period, DEFAULT_N)
    _check_method(args.method, args.lyapunov)
    theta0 = _real("theta0", Z0_STUDY[0] if args.theta0 is None else args.theta0)
    dtheta0 = _real("dtheta0", Z0_STUDY[1] if args.dtheta0 is None else args.dtheta0)
    if abs(theta0) >= block.theta_over:
        raise UsageError(f"theta0 must satisfy |theta0| < pi/2 (got {theta0})")
    phi, r0, s0 = _forcing(args, Z0_STUDY[2:])
    _check_positive_int("max-points", args.max_points, 2)
    _check_threads(args.threads)
    _check_out(args.out)
    stride = max(1, math.ceil(periods * n_steps / args.max_points))
    kw = dict(law=block.law, e=block.e, theta0=theta0, dtheta0=dtheta0, r0=r0, s0=s0,
              periods=periods, n_steps=n_steps, forcing=args.forcing, method=args.method,
              lyapunov=args.lyapunov, record_stride=stride, rtol=args.rtol, atol=args.atol)
    return kw


def _trajectory_run(args, kw):
    from .analysis import classify_result
    from .plotting import fig_trajectory
    from .simulate import simulate
    _say(args, f"trajectory: {args.periods} periods, {args.method} "
               "(the first call of a kernel variant compiles it, ~10-20 s)")
    t0 = time.perf_counter()
    res = simulate(args.hb, args.alpha, args.omega, **kw)
    wall = time.perf_counter() - t0
    name, period = classify_result(res)
    tr = res.trajectory
    arrays = dict(t=tr[:, 0], theta=tr[:, 1], dtheta=tr[:, 2], r=tr[:, 3], s=tr[:, 4],
                  strobe=res.strobe, strobe_half=res.strobe_half, impacts=res.impacts)
    if res.lyapunov_running is not None:
        arrays["lyapunov_running"] = res.lyapunov_running
    out = _Out(args.out)
    out.npz("trajectory.npz", **arrays)
    out.figure("trajectory.png", fig_trajectory(res))
    results = dict(status=res.status, message=res.message, behaviour=name, period=period,
                   t_end=res.t, final_state=res.state, n_impacts=res.n_impacts,
                   n_rest=res.n_rest, record_stride=kw["record_stride"],
                   restitution=res.block.restitution,
                   max_error_estimate=res.max_error_estimate, method=res.method)
    if res.lyapunov is not None:
        results.update(lambda_max=res.lyapunov[0], lyapunov=res.lyapunov, window=res.window)
    out.json("summary.json", _summary(args, wall, files=list(out.written) + ["summary.json"],
                                      **results))
    _say(args, f"trajectory: {res.status}, {name}; wrote {args.out}")


# ---------------------------------------------------------------------------------------------
# grids: where chunks run (in-process or Dask) and where finished chunks wait (resumable)
# ---------------------------------------------------------------------------------------------

def _z0_and_run_checks(args, block):
    """The grid commands' initial state ``(theta0, theta0', r0, s0)`` (the study's z0 where not
    given) and their common checks: threads, output path, scheduler."""
    from .simulate import Z0_STUDY, _real
    theta0 = _real("theta0", Z0_STUDY[0] if args.theta0 is None else args.theta0)
    dtheta0 = _real("dtheta0", Z0_STUDY[1] if args.dtheta0 is None else args.dtheta0)
    if abs(theta0) >= block.theta_over:
        raise UsageError(f"theta0 must satisfy |theta0| < pi/2 (got {theta0})")
    _, r0, s0 = _forcing(args, Z0_STUDY[2:])
    _check_threads(args.threads)
    _check_out(args.out)
    _dist_validate(args)
    return theta0, dtheta0, r0, s0


def _dist_validate(args):
    if getattr(args, "scheduler", None):
        try:
            import dask.distributed  # noqa: F401
        except ImportError:
            raise UsageError("--scheduler needs dask: pip install 'rockjit[dask]'") from None


def _chunk_dir(args, name):
    """Finished chunks of grid ``name`` wait in ``<out>.chunks/name`` until the command ends:
    a rerun of an interrupted command resumes from them; ``--out`` itself is written only
    once everything is computed."""
    return Path(str(Path(args.out)) + ".chunks") / name


class _Grids:
    """Keyword arguments for the analysis functions: the Dask client and the chunk stores."""

    def __init__(self, args):
        self.args = args
        self.client = None
        if getattr(args, "scheduler", None):
            from dask.distributed import Client
            _say(args, f"{args.command}: connecting to the Dask scheduler at {args.scheduler}")
            try:
                self.client = Client(args.scheduler, timeout="15s")
            except (OSError, TimeoutError) as exc:
                raise UsageError(f"cannot reach the Dask scheduler at {args.scheduler} "
                                 f"({exc})") from None

    def kw(self, name):
        return dict(client=self.client, store=_chunk_dir(self.args, name))

    def finish(self):
        """Everything is written: the resumable chunks are no longer needed."""
        shutil.rmtree(Path(str(Path(self.args.out)) + ".chunks"), ignore_errors=True)

    def close(self):
        if self.client is not None:
            self.client.close()


# ---------------------------------------------------------------------------------------------
# sweep
# ---------------------------------------------------------------------------------------------

def _sweep_validate(args):
    from .analysis import alpha_grid
    alphas = alpha_grid(args.alpha_range, args.alpha_step)
    block = _block(args.hb, float(alphas[0]), args.omega, args.law, args.e)
    _block(args.hb, float(alphas[-1]), args.omega, args.law, args.e)
    _settings(args.periods, args.n_steps)
    return dict(alphas=alphas, law=block.law, e=block.e, z0=_z0_and_run_checks(args, block))


def _sweep_arrays(sw):
    return dict(alpha=sw.alpha, label=sw.label, period=sw.period, lambda_max=sw.lambda_max,
                strobe=sw.strobe, impact_section=sw.impact_section, t_end=sw.t_end,
                names=np.asarray(sw.names, dtype=str))


def _sweep_run(args, kw):
    from .analysis import sweep
    from .plotting import fig_bifurcation
    t0 = time.perf_counter()
    grids = _Grids(args)
    try:
        sw = sweep(args.hb, args.omega, kw["alphas"], law=kw["law"], e=kw["e"], z0=kw["z0"],
                   periods=args.periods, n_steps=args.n_steps, lyapunov=not args.no_lyapunov,
                   early_stop=not args.full_length, threads=args.threads,
                   progress=not args.quiet, **grids.kw("sweep"))
    finally:
        grids.close()
    wall = time.perf_counter() - t0
    out = _Out(args.out)
    out.npz("sweep.npz", **_sweep_arrays(sw))
    out.figure("bifurcation.png", fig_bifurcation(sw))
    out.json("summary.json", _summary(
        args, wall, files=list(out.written) + ["summary.json"], n_alpha=int(sw.alpha.size),
        fractions=sw.fractions(), settings=sw.settings, restitution=sw.block.restitution))
    grids.finish()
    _say(args, f"sweep: {sw.alpha.size} amplitudes in {wall:.1f} s; wrote {args.out}")


# ---------------------------------------------------------------------------------------------
# basin
# ---------------------------------------------------------------------------------------------

def _range(name, rng, theta_over=None):
    lo, hi = rng
    if not (math.isfinite(lo) and math.isfinite(hi)) or hi < lo:
        raise UsageError(f"{name} must be two finite numbers, start <= end (got {lo}, {hi})")
    if theta_over is not None and max(abs(lo), abs(hi)) >= theta_over:
        raise UsageError(f"{name} must lie inside (-pi/2, pi/2) (got {lo}, {hi})")
    return lo, hi


def _laws(law):
    return ("housner", "mao") if law == "both" else (law,)


def _basin_validate(args):
    if args.law == "both" and args.e is not None:
        raise UsageError("--e goes with --law constant, not --law both")
    blocks = [_block(args.hb, args.alpha, args.omega, law, args.e) for law in _laws(args.law)]
    _check_positive_int("grid", args.grid)
    _range("theta-range", args.theta_range, blocks[0].theta_over)
    _range("dtheta-range", args.dtheta_range)
    _settings(args.periods, args.n_steps)
    _, r0, s0 = _forcing(args, (0.0, 1.0))
    _check_threads(args.threads)
    _check_out(args.out)
    _dist_validate(args)
    return dict(blocks=blocks, r0=r0, s0=s0)


def basin_summary(b):
    """The per-law part of a basin's ``summary.json``."""
    lab = np.asarray(b.label)
    counts = {str(n): int(np.count_nonzero(lab == c)) for c, n in enumerate(b.names)}
    return dict(law=b.block.law, restitution=b.block.restitution, fractions=b.fractions(),
                counts=counts, settings=b.settings)


def _basin_compute(args, block, r0, s0, grids):
    from .analysis import basin
    return basin(block.hb, block.alpha, block.omega, law=block.law, e=block.e, grid=args.grid,
                 theta_range=args.theta_range, dtheta_range=args.dtheta_range, r0=r0, s0=s0,
                 periods=args.periods, n_steps=args.n_steps, lyapunov=args.lyapunov,
                 early_stop=not args.full_length, threads=args.threads,
                 progress=not args.quiet, **grids.kw(block.law))


def _basin_run(args, kw):
    from .plotting import agreement, fig_basin, fig_basin_compare
    t0 = time.perf_counter()
    res = {}
    grids = _Grids(args)
    try:
        for block in kw["blocks"]:
            _say(args, f"basin: {block.law}, {args.grid}x{args.grid} cells, "
                       f"{args.periods} periods")
            res[block.law] = _basin_compute(args, block, kw["r0"], kw["s0"], grids)
    finally:
        grids.close()
    wall = time.perf_counter() - t0
    first = next(iter(res.values()))
    arrays = dict(theta0=first.theta0, dtheta0=first.dtheta0,
                  names=np.asarray(first.names, dtype=str))
    out = _Out(args.out)
    if len(res) == 1:
        arrays.update(label=first.label, period=first.period, t_end=first.t_end)
        if first.lambda_max is not None:
            arrays["lambda_max"] = first.lambda_max
        results = basin_summary(first)
        fig = fig_basin(first)
    else:
        for law, b in res.items():
            arrays[f"label_{law}"] = b.label
            arrays[f"period_{law}"] = b.period
            arrays[f"t_end_{law}"] = b.t_end
            if b.lambda_max is not None:
                arrays[f"lambda_max_{law}"] = b.lambda_max
        results = {law: basin_summary(b) for law, b in res.items()}
        results["agreement"] = agreement(res["housner"].label, res["mao"].label)
        fig = fig_basin_compare(res["housner"], res["mao"])
    out.npz("basin.npz", **arrays)
    out.figure("basin.png", fig)
    out.json("summary.json", _summary(args, wall, files=list(out.written) + ["summary.json"],
                                      grid=args.grid, r0=kw["r0"], s0=kw["s0"], **results))
    grids.finish()
    _say(args, f"basin: done in {wall:.1f} s; wrote {args.out}")


# ---------------------------------------------------------------------------------------------
# plane
# ---------------------------------------------------------------------------------------------

def _plane_validate(args):
    lo, hi = _range("alpha-range", args.alpha_range)
    if lo < 0:
        raise UsageError(f"alpha-range must satisfy 0 <= start <= end (got {lo}, {hi})")
    wlo, whi = _range("omega-range", args.omega_range)
    if wlo <= 0:
        raise UsageError(f"omega-range must satisfy 0 < start <= end (got {wlo}, {whi})")
    block = _block(args.hb, lo, wlo, args.law, args.e)
    for g in args.grid:
        _check_positive_int("grid", g)
    _settings(args.periods, args.n_steps)
    return dict(law=block.law, e=block.e, z0=_z0_and_run_checks(args, block))


def _plane_run(args, kw):
    from .analysis import plane
    from .plotting import fig_plane
    t0 = time.perf_counter()
    grids = _Grids(args)
    try:
        p = plane(args.hb, args.alpha_range, args.omega_range, grid=args.grid, law=kw["law"],
                  e=kw["e"], z0=kw["z0"], periods=args.periods, n_steps=args.n_steps,
                  lyapunov=not args.no_lyapunov, early_stop=not args.full_length,
                  threads=args.threads, progress=not args.quiet, **grids.kw("plane"))
    finally:
        grids.close()
    wall = time.perf_counter() - t0
    out = _Out(args.out)
    out.npz("plane.npz", alpha=p.alpha, omega=p.omega, z0=p.z0, label=p.label[0],
            period=p.period[0], lambda_max=p.lambda_max[0], t_end=p.t_end[0],
            names=np.asarray(p.names, dtype=str))
    out.figure("plane.png", fig_plane(p))
    out.json("summary.json", _summary(
        args, wall, files=list(out.written) + ["summary.json"], grid=list(args.grid),
        fractions=p.fractions(), settings=p.settings, restitution=p.block.restitution,
        scheduler=args.scheduler))
    grids.finish()
    _say(args, f"plane: {p.label.size} cells in {wall:.1f} s; wrote {args.out}")


# ---------------------------------------------------------------------------------------------
# cor
# ---------------------------------------------------------------------------------------------

def _cor_validate(args):
    for hb in args.hb_values:
        _block(hb, 0.0, 1.0, "housner", None)
    _block(args.hb_max, 0.0, 1.0, "housner", None)
    if args.hb_max <= 1 / math.sqrt(2):
        raise UsageError(f"hb-max must be > 1/sqrt(2) (got {args.hb_max})")
    _check_out(args.out)
    return {}


def e_table(hb_values):
    """Rows ``(hb, thc, e_H, e_M, delta_e %)`` of the restitution table."""
    from .model import delta_e_percent, e_housner, e_mao, thc_from_hb
    rows = []
    for hb in hb_values:
        thc = float(thc_from_hb(hb))
        eh, em = float(e_housner(thc)), float(e_mao(thc))
        rows.append((float(hb), thc, eh, em, float(delta_e_percent(em, eh))))
    return rows


E_HEADER = ("hb", "thc", "e_H", "e_M", "delta_e_percent")
E_FMT = {"hb": "g", "thc": ".4f", "e_H": ".3f", "e_M": ".3f", "delta_e_percent": ".2f"}


def _write_cor(out, hb_values, hb_max, fig_name, table_stem):
    from .plotting import fig_restitution
    rows = e_table(hb_values)
    out.figure(fig_name, fig_restitution((1 / math.sqrt(2), hb_max)))
    out.table(table_stem, E_HEADER, rows, E_FMT)
    return [dict(zip(E_HEADER, r)) for r in rows]


def _cor_run(args, kw):
    t0 = time.perf_counter()
    out = _Out(args.out)
    table = _write_cor(out, args.hb_values, args.hb_max, "restitution.png", "e_table")
    out.json("summary.json", _summary(args, time.perf_counter() - t0,
                                      files=list(out.written) + ["summary.json"], table=table))
    _say(args, f"cor: wrote {args.out}")


# ---------------------------------------------------------------------------------------------
# paper
# ---------------------------------------------------------------------------------------------

def _paper_validate(args):
    from .analysis import alpha_grid
    _settings(args.periods, args.n_steps)
    _check_positive_int("grid", args.grid)
    if not args.alpha_step > 0 or not math.isfinite(args.alpha_step):
        raise UsageError(f"alpha-step must be > 0 (got {args.alpha_step})")
    zoom_step = args.alpha_step / 4 if args.zoom_step is None else args.zoom_step
    if not zoom_step > 0 or not math.isfinite(zoom_step):
        raise UsageError(f"zoom-step must be > 0 (got {zoom_step})")
    grids = {}
    for hb, st in STUDY.items():
        for law, rng in st["alpha_range"].items():
            grids[(hb, law)] = alpha_grid(rng, args.alpha_step)
    zoom = alpha_grid(args.zoom, zoom_step)
    if args.zoom[0] < STUDY[1]["alpha_range"]["housner"][0] or \
            args.zoom[1] > STUDY[1]["alpha_range"]["housner"][1]:
        raise UsageError(f"zoom must lie inside the Housner hb=1 range "
                         f"{STUDY[1]['alpha_range']['housner']} (got {tuple(args.zoom)})")
    _check_threads(args.threads)
    _check_out(args.out)
    return dict(grids=grids, zoom=zoom, zoom_step=zoom_step)


def _paper_run(args, kw):
    from .analysis import BEHAVIOURS, basin, classify_result, sweep
    from .plotting import (agreement, fig_basin_compare, fig_bifurcation, fig_gallery,
                           fig_laws_timeseries, fig_trajectory)
    from .simulate import Z0_STUDY, simulate

    out = _Out(args.out)
    walls = {}
    results = {}
    n_parts = 6
    from .simulate import DEFAULT_N
    n_single = args.n_steps  # None: the library's defaults (DEFAULT_N, GRID_N)
    n_grid = args.n_steps
    stride = max(1, math.ceil(args.periods * (n_single or DEFAULT_N) / MAX_TRAJ_POINTS))
    run_kw = dict(periods=args.periods, n_steps=n_single, record_stride=stride,
                  lyapunov=True)
    t_all = time.perf_counter()

    def part(i, name, what):
        _say(args, f"paper [{i}/{n_parts}] {name}: {what}")
        return time.perf_counter()

    def done(name, t0):
        walls[name] = time.perf_counter() - t0
        _say(args, f"paper: {name} done in {walls[name]:.1f} s")

    # 1. restitution
    t0 = part(1, "fig1", "restitution laws and the e-table")
    results["e_table"] = _write_cor(out, (1.0, 1.5, 2.0, 2.5, 3.0, 4.0, 5.0), 6.0,
                                    "fig1_restitution.png", "e_table")
    done("fig1", t0)

    # 2. reference symmetric run
    t0 = part(2, "fig2", "reference run alpha=0.6, omega=1.3, hb=1, Housner")
    ref = simulate(1.0, 0.6, 1.3, "housner", z0=Z0_STUDY, **run_kw)
    tr = ref.trajectory
    out.npz("fig2_reference.npz", t=tr[:, 0], theta=tr[:, 1], dtheta=tr[:, 2],
            strobe=ref.strobe, impacts=ref.impacts, lyapunov_running=ref.lyapunov_running)
    out.figure("fig2_reference.png", fig_trajectory(ref))
    name, p = classify_result(ref)
    results["fig2"] = dict(status=ref.status, behaviour=name, period=p,
                           lambda_max=ref.lambda_max, lyapunov=ref.lyapunov)
    done("fig2", t0)

    # 3. gallery
    t0 = part(3, "fig3", "behaviour gallery")
    gal = {
        "rest / damped": simulate(1.0, 0.15, 1.0, "housner", theta0=0.05, dtheta0=0.0,
                                  r0=Z0_STUDY[2], s0=Z0_STUDY[3], **run_kw),
        "asymmetric": simulate(1.0, 0.8, 1.3, "housner", z0=Z0_STUDY, **run_kw),
        # The study's multiperiodic example (alpha = 0.969) is transient chaos ending in
        # overturning once integrated accurately (README, "What the study's settings hide");
        # both it and a robust period-2 orbit of the same family are shown.
        "multiperiodic": simulate(1.0, 0.92, 1.3, "housner", z0=Z0_STUDY, **run_kw),
        "study's 'multiperiodic'": simulate(1.0, 0.969, 1.3, "housner", z0=Z0_STUDY,
                                            **run_kw),
        "overturn": simulate(2.0, 0.448, 1.3, "housner", z0=Z0_STUDY, **run_kw),
    }
    out.figure("fig3_gallery.png", fig_gallery(gal))
    results["fig3"] = {k: dict(zip(("behaviour", "period"), classify_result(r)),
                               status=r.status, lambda_max=r.lambda_max)
                       for k, r in gal.items()}
    done("fig3", t0)

    # 4. Housner vs Mao time series
    t0 = part(4, "fig4", "Housner vs Mao time series, alpha=0.2, omega=1.6, hb=2")
    rows = []
    for th0, dth0 in LAWS_IC:
        rows.append({law: simulate(2.0, 0.2, 1.6, law, theta0=th0, dtheta0=dth0, r0=0.0,
                                   s0=1.0, **run_kw) for law in ("housner", "mao")})
    out.figure("fig4_laws_timeseries.png", fig_laws_timeseries(rows))
    results["fig4"] = [{law: dict(zip(("behaviour", "period"), classify_result(r)),
                                  status=r.status) for law, r in row.items()}
                       for row in rows]
    done("fig4", t0)

    # 5. bifurcation diagrams
    t0 = part(5, "fig5", "bifurcation sweeps (4 + zoom)")
    sweeps = {}
    skw = dict(periods=args.periods, n_steps=n_grid, threads=args.threads,
               progress=not args.quiet, lyapunov=True)
    sweep_rows = []
    for (hb, law), alphas in kw["grids"].items():
        _say(args, f"paper: sweep {law} hb={hb:g}, {alphas.size} amplitudes")
        sw = sweep(float(hb), STUDY[hb]["omega"], alphas, law=law, **skw)
        sweeps[(hb, law)] = sw
        out.npz(f"fig5_sweep_hb{hb}_{law}.npz", **_sweep_arrays(sw))
        fr = sw.fractions()
        sweep_rows.append([hb, law, STUDY[hb]["omega"], float(alphas[0]), float(alphas[-1]),
                           int(alphas.size)] + [fr[n] for n in BEHAVIOURS])
    for hb in STUDY:
        out.figure(f"fig5_bifurcation_hb{hb}.png", fig_bifurcation(
            {law: sweeps[(hb, law)] for law in ("housner", "mao")},
            title=f"Bifurcation diagrams, h/b = {hb}, \u03c9 = {STUDY[hb]['omega']}"))
    _say(args, f"paper: zoom sweep Housner hb=1, {kw['zoom'].size} amplitudes")
    zsw = sweep(1.0, STUDY[1]["omega"], kw["zoom"], law="housner", **skw)
    out.npz("fig5_sweep_zoom_hb1_housner.npz", **_sweep_arrays(zsw))
    out.figure("fig5_bifurcation_zoom.png", fig_bifurcation(
        zsw, alpha_limits=tuple(args.zoom),
        title=f"Zoom: Housner, h/b = 1, \u03c9 = 1.3, \u03b1 in [{args.zoom[0]:g}, "
              f"{args.zoom[1]:g}]"))
    fr = zsw.fractions()
    sweep_rows.append([1, "housner (zoom)", STUDY[1]["omega"], float(kw["zoom"][0]),
                       float(kw["zoom"][-1]), int(kw["zoom"].size)] +
                      [fr[n] for n in BEHAVIOURS])
    sweep_header = ["hb", "law", "omega", "alpha_start", "alpha_end", "n_alpha"] + \
        [f"{n}_percent" for n in BEHAVIOURS]
    out.table("sweep_table", sweep_header, sweep_rows,
              {h: ".1f" for h in sweep_header[6:]} | {"omega": "g", "alpha_start": "g",
                                                      "alpha_end": "g"})
    results["fig5"] = [dict(zip(sweep_header, r)) for r in sweep_rows]
    done("fig5", t0)

    # 6. basins
    t0 = part(6, "fig6", f"basins, {args.grid}x{args.grid} cells, both laws, two cases")
    basin_rows = []
    results["fig6"] = []
    for hb, alpha, omega in BASIN_CASES:
        bs = {}
        for law in ("housner", "mao"):
            _say(args, f"paper: basin {law} hb={hb:g} alpha={alpha:g} omega={omega:g}")
            bs[law] = basin(hb, alpha, omega, law=law, grid=args.grid, r0=0.0, s0=1.0,
                            periods=args.periods, n_steps=n_grid, threads=args.threads,
                            progress=not args.quiet)
        agree = agreement(bs["housner"].label, bs["mao"].label)
        tag = f"hb{hb:g}"
        out.npz(f"fig6_basin_{tag}.npz", theta0=bs["housner"].theta0,
                dtheta0=bs["housner"].dtheta0, label_housner=bs["housner"].label,
                label_mao=bs["mao"].label, names=np.asarray(bs["housner"].names, dtype=str))
        out.figure(f"fig6_basin_{tag}.png", fig_basin_compare(bs["housner"], bs["mao"]))
        entry = dict(hb=hb, alpha=alpha, omega=omega, agreement=agree)
        for law, b in bs.items():
            fr = b.fractions()
            entry[law] = dict(fractions=fr)
            basin_rows.append([hb, alpha, omega, law] + [fr[n] for n in BEHAVIOURS] + [agree])
        results["fig6"].append(entry)
    basin_header = ["hb", "alpha", "omega", "law"] + [f"{n}_percent" for n in BEHAVIOURS] + \
        ["agreement_percent"]
    out.table("basin_table", basin_header, basin_rows,
              {h: ".1f" for h in basin_header[4:]} | {"hb": "g", "alpha": "g", "omega": "g"})
    done("fig6", t0)

    total = time.perf_counter() - t_all
    out.json("summary.json", _summary(args, total, wall_s_parts=walls,
                                      files=list(out.written) + ["summary.json"],
                                      zoom_step=kw["zoom_step"], record_stride=stride,
                                      **results))
    _say(args, f"paper: all parts done in {total:.1f} s; wrote {args.out}")


# ---------------------------------------------------------------------------------------------
# the parser
# ---------------------------------------------------------------------------------------------

def _add_block(p, alpha=True, omega=True, law_choices="housner, mao or constant"):
    p.add_argument("--hb", type=float, required=True, help="slenderness h/b (> 0)")
    p.add_argument("--law", default="housner",
                   help=f"restitution law: {law_choices} (default housner)")
    p.add_argument("--e", type=float, default=None,
                   help="constant coefficient of restitution in [0, 1] (with --law constant)")
    if alpha:
        p.add_argument("--alpha", type=float, required=True, help="forcing amplitude A/R")
    if omega:
        p.add_argument("--omega", type=float, required=True,
                       help="forcing frequency Omega/Omega0")


def _add_run(p, periods=500, grid=False, both=False):
    from .analysis import GRID_N
    from .simulate import DEFAULT_N, MAX_STEP
    p.add_argument("--periods", type=int, default=periods,
                   help=f"forcing periods to integrate (default {periods})")
    if both:
        note = f"default {DEFAULT_N} for single runs, {GRID_N} for sweeps and basins"
        default = None
    else:
        default = None
        note = f"default {GRID_N if grid else DEFAULT_N}, raised if T/N > {MAX_STEP}"
    p.add_argument("--n-steps", type=int, default=default,
                   help=f"steps per forcing period, even ({note})")


def _add_state(p, default_note):
    p.add_argument("--theta0", type=float, default=None, help="initial angle")
    p.add_argument("--dtheta0", type=float, default=None, help="initial angular velocity")
    _add_phase(p, default_note)


def _add_phase(p, default_note):
    g = p.add_mutually_exclusive_group()
    g.add_argument("--phase", type=float, default=None,
                   help="forcing phase phi in r = sin(omega t + phi)")
    g.add_argument("--r0", type=float, default=None, help="forcing oscillator r(0) (with --s0)")
    p.add_argument("--s0", type=float, default=None,
                   help=f"forcing oscillator s(0) (with --r0); {default_note}")


def _add_grid_run(p, lyapunov_default):
    """Options of the grid commands (sweep, basin, plane)."""
    _add_run(p, grid=True)
    if lyapunov_default:
        p.add_argument("--no-lyapunov", action="store_true",
                       help="skip the exponents (chaotic is then reported as aperiodic)")
    else:
        p.add_argument("--lyapunov", action="store_true",
                       help="compute exponents (tells chaotic from aperiodic)")
    p.add_argument("--full-length", action="store_true", help="disable early stopping")
    _add_common(p)
    _add_scheduler(p)


def _add_scheduler(p):
    p.add_argument("--scheduler", default=None, metavar="ADDRESS",
                   help="run the chunks of cells on this Dask scheduler (e.g. "
                        "tcp://host:8786); default in this process")


def _add_common(p, threads=True):
    p.add_argument("--out", required=True, help="output directory (created if missing)")
    if threads:
        p.add_argument("--threads", type=int, default=None,
                       help="numba threads (default all); results do not depend on it")
    p.add_argument("--quiet", action="store_true", help="no progress on stderr")


def build_parser():
    """The argument parser (its ``error`` raises :class:`UsageError`)."""
    parser = _Parser(prog=PROG, description="The harmonically forced rigid rocking block "
                     "(Housner's model): single runs, bifurcation sweeps, basins, figures.")
    parser.add_argument("--version", action="version", version=f"%(prog)s {_version()}")
    sub = parser.add_subparsers(dest="command", required=True, metavar="COMMAND")

    p = sub.add_parser("trajectory", help="one run: trajectory.npz, trajectory.png",
                       description="Simulate one run; write trajectory.npz (t, theta, dtheta, "
                       "r, s, strobe, strobe_half, impacts, lyapunov_running), trajectory.png "
                       "and summary.json.")
    _add_block(p)
    _add_state(p, "default: the study's z0 = (-0.2254, -0.1597, -0.7778, 0.6284)")
    _add_run(p)
    p.add_argument("--method", default="rockjit",
                   help="rockjit (compiled), scipy or scipy:<solve_ivp method> (default "
                        "rockjit)")
    p.add_argument("--forcing", default="closed", choices=("closed", "embedded"),
                   help="closed-form forcing or the 4-D oscillator embedding")
    p.add_argument("--rtol", type=float, default=1e-6, help="scipy path tolerance")
    p.add_argument("--atol", type=float, default=1e-9, help="scipy path tolerance")
    p.add_argument("--lyapunov", action="store_true", help="compute Lyapunov exponents")
    p.add_argument("--max-points", type=int, default=MAX_TRAJ_POINTS,
                   help=f"at most this many recorded points (default {MAX_TRAJ_POINTS})")
    _add_common(p)
    p.set_defaults(validate=_trajectory_validate, func=_trajectory_run)

    p = sub.add_parser("sweep", help="bifurcation sweep over alpha: sweep.npz, bifurcation.png",
                       description="Sweep the forcing amplitude; write sweep.npz, "
                       "bifurcation.png and summary.json (fractions of each behaviour).")
    _add_block(p, alpha=False)
    p.add_argument("--alpha-range", type=float, nargs=2, required=True,
                   metavar=("START", "END"), help="amplitudes from START to END (included)")
    p.add_argument("--alpha-step", type=float, default=0.001, help="step (default 0.001)")
    _add_state(p, "default: the study's z0")
    _add_grid_run(p, lyapunov_default=True)
    p.set_defaults(validate=_sweep_validate, func=_sweep_run)

    p = sub.add_parser("basin", help="basin of attraction: basin.npz, basin.png",
                       description="Classify a grid of initial states (theta0, dtheta0); "
                       "write basin.npz (label[i, j] belongs to theta0[i], dtheta0[j]), "
                       "basin.png and summary.json (percentages; with --law both, "
                       "per law and the agreement).")
    _add_block(p, law_choices="housner, mao, constant or both")
    p.add_argument("--grid", type=int, default=100, help="cells per side (default 100)")
    p.add_argument("--theta-range", type=float, nargs=2, default=(-1.0, 1.0),
                   metavar=("LO", "HI"), help="theta0 range (default -1 1)")
    p.add_argument("--dtheta-range", type=float, nargs=2, default=(-1.0, 1.0),
                   metavar=("LO", "HI"), help="dtheta0 range (default -1 1)")
    _add_phase(p, "default (r0, s0) = (0, 1)")
    _add_grid_run(p, lyapunov_default=False)
    p.set_defaults(validate=_basin_validate, func=_basin_run)

    p = sub.add_parser("plane", help="behaviours over (alpha, omega): plane.npz, plane.png",
                       description="Classify a grid over the forcing plane (alpha, omega) "
                       "from one initial state; write plane.npz (label[i, j] belongs to "
                       "alpha[i], omega[j]), plane.png and summary.json. Runs in-process or, "
                       "with --scheduler, on a Dask cluster; an interrupted run resumes.")
    _add_block(p, law_choices="housner, mao or constant", alpha=False, omega=False)
    p.add_argument("--alpha-range", type=float, nargs=2, required=True,
                   metavar=("START", "END"), help="amplitudes (ends included)")
    p.add_argument("--omega-range", type=float, nargs=2, required=True,
                   metavar=("START", "END"), help="frequencies (ends included)")
    p.add_argument("--grid", type=int, nargs=2, default=(50, 50), metavar=("NA", "NW"),
                   help="points along alpha and omega (default 50 50)")
    _add_state(p, "default: the study's z0")
    _add_grid_run(p, lyapunov_default=True)
    p.set_defaults(validate=_plane_validate, func=_plane_run)

    p = sub.add_parser("cor", help="restitution laws: figure 1 and the e-table",
                       description="Figure 1 (e_H, e_M against thc, with delta e %) and a "
                       "table of e_H, e_M, delta e % (CSV and Markdown).")
    p.add_argument("--hb-values", type=float, nargs="+",
                   default=[1.0, 1.5, 2.0, 2.5, 3.0, 4.0, 5.0], help="rows of the table")
    p.add_argument("--hb-max", type=float, default=6.0, help="largest h/b in the figure")
    _add_common(p, threads=False)
    p.set_defaults(validate=_cor_validate, func=_cor_run)

    p = sub.add_parser("paper", help="every figure and table of the study (SPEC.md 7)",
                       description="Regenerate figures 1-6 and the tables of the study. "
                       "Smaller --grid, --periods, --alpha-step give a quick version.")
    p.add_argument("--grid", type=int, default=100, help="basin cells per side (default 100)")
    _add_run(p, both=True)
    p.add_argument("--alpha-step", type=float, default=0.001, help="sweep step (default 0.001)")
    p.add_argument("--zoom", type=float, nargs=2, default=ZOOM, metavar=("START", "END"),
                   help=f"alpha range of the zoomed Housner hb=1 diagram (default "
                        f"{ZOOM[0]} {ZOOM[1]})")
    p.add_argument("--zoom-step", type=float, default=None,
                   help="step of the zoom sweep (default alpha-step / 4)")
    _add_common(p)
    p.set_defaults(validate=_paper_validate, func=_paper_run)
    return parser


def _error(msg):
    msg = " ".join(str(msg).split())  # always one line
    print(f"{PROG}: error: {msg}", file=sys.stderr, flush=True)
    return 2


def main(argv=None):
    """Run the command line; returns the exit status (0, 2 bad input, 130 interrupted)."""
    parser = build_parser()
    try:
        args = parser.parse_args(argv)
    except UsageError as exc:
        return _error(exc)
    except SystemExit as exc:  # --help, --version
        return exc.code if isinstance(exc.code, int) else 0
    try:
        kw = args.validate(args)
    except (UsageError, ValueError) as exc:
        return _error(exc)
    import matplotlib
    matplotlib.use("Agg")
    try:
        args.func(args, kw)
    except KeyboardInterrupt:
        print(f"\n{PROG}: interrupted; no file was left half-written", file=sys.stderr)
        return 130
    except (UsageError, ValueError) as exc:  # a check made only once running
        return _error(exc)
    return 0
