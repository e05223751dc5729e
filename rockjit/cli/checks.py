"""The checks of the command line's own options, made before any work (the library checks
the rest): ``--device``, ``--threads``, the scipy path's tolerances, ``--scheduler``, and
``--out`` with the files each command writes into it."""

from __future__ import annotations

from .usage import UsageError

#: The files each command writes into --out besides summary.json (names or fnmatch patterns):
#: a directory of one of these names inside --out is refused before any work.
OUTPUTS = {
    "trajectory": ("trajectory.npz", "trajectory.*"),
    "sweep": ("sweep.npz", "bifurcation.*"),
    "basin": ("basin.npz", "basin.*", "attractors.*"),
    "plane": ("plane.npz", "plane.*"),
    "erosion": ("erosion.npz", "erosion.*"),
    "safety": ("safety.npz", "safety_*"),
    "orbits": ("orbits.npz", "orbits.*"),
    "fate": ("fate.npz", "fate.*"),
    "cor": ("restitution.*", "e_table.csv", "e_table.md"),
    "paper": ("fig*", "*_table.csv", "*_table.md", "index.html"),
    "chart": ("chart.npz", "chart.*"),
    "spectrum": ("spectrum.npz", "spectrum.*"),
    "fragility": ("fragility.npz", "fragility.*", "rotation.*"),
}
#: The commands whose grids keep their finished chunks in <out>.chunks.
CHUNKED = ("sweep", "basin", "plane", "erosion", "safety", "orbits", "chart", "paper",
           "spectrum", "fragility")


def check_device(args):
    """``--device cuda`` is refused in one line, before any work, with the scipy reference path
    (``--method scipy``, which runs on the CPU only) and on a machine without a usable GPU."""
    if getattr(args, "device", "cpu") == "cuda":
        from ..settings import cuda_refusal, scipy_on_cuda
        if getattr(args, "method", "rockjit") != "rockjit":
            raise UsageError(scipy_on_cuda("--device cuda", "--device cpu", "--method rockjit"))
        refusal = cuda_refusal("--device cuda", "--device cpu")
        if refusal is not None:
            raise UsageError(refusal)


def check_run(args):
    """``--threads`` fits numba's; the scipy path's tolerances are valid numbers whatever the
    method; ``--scheduler`` needs dask and ``--scheduler-timeout`` is a positive time; ``--out``
    can be written (:func:`rockjit.storage.output_dir.check_out`)."""
    from ..validate import integer, real
    if getattr(args, "threads", None) is not None:
        import numba
        integer("threads", args.threads, 1, numba.config.NUMBA_NUM_THREADS)
    if getattr(args, "rtol", None) is not None:  # as rockjit.simulate.plan checks them for scipy
        real("rtol", args.rtol, 0.0, 1.0, lo_open=True, hi_open=True)
        real("atol", args.atol, 0.0, None, lo_open=True)
    if getattr(args, "scheduler_timeout", None) is not None:
        real("--scheduler-timeout", args.scheduler_timeout, 0.0, 1e6, lo_open=True)
    if getattr(args, "scheduler", None):
        try:
            import dask.distributed  # noqa: F401
        except ImportError:
            raise UsageError("--scheduler needs dask: pip install 'rockjit[dask]'") from None
    from ..storage.output_dir import check_out
    check_out(args.out, name="--out", files=OUTPUTS.get(args.command, ()),
              chunks=args.command in CHUNKED)
