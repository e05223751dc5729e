"""The same (alpha, omega) plane in-process and on a two-worker Dask LocalCluster.

What distribution costs. The plane (Housner, h/b = 1, alpha in [0.3, 1.0], omega in
[0.8, 2.0], the study's z0, lambda_max on) runs in this process with numba's threads, and as
chunks on a LocalCluster of two single-threaded worker processes, for several chunk sizes; the
results must be identical. The overhead per chunk is the extra wall time of the cluster run over
the in-process one divided by the number of chunks (on this 2-core machine both use both cores).
The workers' first chunk loads the compiled kernels from numba's cache: the cluster is warmed
with a tiny plane first, and compile time is reported apart.

    python benchmarks/bench_distributed.py            # full: 60 x 60 plane, 500 periods
    python benchmarks/bench_distributed.py --quick    # smoke: 16 x 16, 100 periods

Writes distributed.{md,csv,json,png} to benchmarks/results/ (benchmarks/results/quick/ with
--quick, or --out DIR).
"""

from __future__ import annotations

import sys

import numpy as np

import _common as H

import rockjit
from rockjit import Block, Execution, Integration

FULL = dict(grid=(60, 60), periods=500, repeats=3, chunk_divisors=(4, 16, 64))
QUICK = dict(grid=(16, 16), periods=100, repeats=1, chunk_divisors=(4, 16))
HEADERS = ("run", "chunks", "wall median s", "ratio to in-process", "overhead per chunk s",
           "identical to in-process")


def plane(grid, periods, execution=None):
    """The plane (hb=1, Housner, from the study's initial state, lambda_max on)."""
    return rockjit.plane(Block(hb=1.0), (0.3, 1.0), (0.8, 2.0), grid=grid,
                         integration=Integration(periods=periods), execution=execution)


# --------------------------------------------------------------------------- the experiment

def in_process_and_cluster(cfg, chunk_sizes, repeats):
    """The plane in this process and on the cluster at each chunk size, interleaved.

    Returns ``(wall times by case, identical to the in-process result by case, compile s,
    workers' warm-up s)``.
    """
    from dask.distributed import Client, LocalCluster

    grid, periods = cfg["grid"], cfg["periods"]
    t_compile, _ = H.timed(plane, (2, 2), 5)
    ref = plane(grid, periods)  # warm, and the reference result
    cluster = LocalCluster(n_workers=2, threads_per_worker=1, processes=True,
                           dashboard_address=None)
    client = Client(cluster)
    try:
        t_workers, _ = H.timed(plane, (2, 2), 5, Execution(client=client, chunk=2))
        cases = {"in-process": lambda: plane(grid, periods)}
        for c in chunk_sizes:
            cases[f"cluster, {c} cells/chunk"] = (
                lambda c=c: plane(grid, periods, Execution(client=client, chunk=c)))
        t = H.side_by_side(cases, repeats)
    finally:
        client.close()
        cluster.close()
    identical = {k: bool(np.array_equal(res.label, ref.label)
                         and np.array_equal(res.lambda_max, ref.lambda_max, equal_nan=True))
                 for k, res in t.result.items()}
    return t.wall, identical, t_compile, t_workers


def rows(times, identical, n):
    base = H.median(times["in-process"])
    out = []
    for k in times:
        med = H.median(times[k])
        size = max(64, -(-n // 20)) if k == "in-process" else int(k.split(", ")[1].split()[0])
        n_chunks = -(-n // size)  # in-process runs the default chunking (progress between)
        per_chunk = None if k == "in-process" else (med - base) / n_chunks
        out.append((k, n_chunks, med, med / base, per_chunk, "yes" if identical[k] else "NO"))
    return out


# --------------------------------------------------------------------------- the report

def plot(table, cfg):
    plt = H.pyplot()
    fig, ax = plt.subplots(figsize=(7, 3.6))
    ax.barh([r[0] for r in table][::-1], [r[2] for r in table][::-1], color="#4c72b0")
    ax.set_xlabel("wall time [s] (median)")
    ax.set_title(f"{cfg['grid'][0]}x{cfg['grid'][1]} plane, {cfg['periods']} periods: "
                 "in-process vs 2-worker LocalCluster", fontsize=9)
    fig.tight_layout()
    return fig


def main(argv=None):
    b = H.Bench(__doc__, argv)
    cfg = QUICK if b.quick else FULL
    g = cfg["grid"]
    n = g[0] * g[1]
    times, identical, t_compile, t_workers = in_process_and_cluster(
        cfg, [n // d for d in cfg["chunk_divisors"]], cfg["repeats"])
    table = rows(times, identical, n)
    md = (H.md_table(HEADERS, table) + "\n"
          + f"Plane {g[0]} x {g[1]} = {n} cells, {cfg['periods']} periods, lambda_max on; "
            f"median of {cfg['repeats']}, cases interleaved. Compile (first call, this process): "
            f"{t_compile:.1f} s; workers' first chunk (cache load): {t_workers:.1f} s. "
            f"{H.env_line(b.env)}\n")
    b.report("distributed", markdown=md, csv=(HEADERS, table),
             data=dict(rows=[dict(zip(HEADERS, r)) for r in table], compile_s=t_compile,
                       env=b.env, worker_warmup_s=t_workers, raw_wall_s=times),
             figures=[("distributed.png", plot(table, cfg), 120)])
    return 0


if __name__ == "__main__":
    sys.exit(main())
