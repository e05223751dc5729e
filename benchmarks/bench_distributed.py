"""The same (alpha, omega) plane in-process and on a two-worker Dask LocalCluster.

Issue 6: what distribution costs. The plane (Housner, h/b = 1, alpha in [0.3, 1.0], omega in
[0.8, 2.0], the study's z0, lambda_max on) runs in this process with numba's threads, and as
chunks on a LocalCluster of two single-threaded worker processes, for several chunk sizes; the
results must be identical. The overhead per chunk is the extra wall time of the cluster run over
the in-process one divided by the number of chunks (on this 2-core machine both use both cores).
The workers' first chunk loads the compiled kernels from numba's cache: the cluster is warmed
with a tiny plane first, and compile time is reported apart.

    python benchmarks/bench_distributed.py            # full: 60 x 60 plane, 500 periods
    python benchmarks/bench_distributed.py --quick    # smoke: 16 x 16, 100 periods
"""

from __future__ import annotations

import numpy as np

import _common as C

from rockjit import analysis as an


def main():
    args = C.parser(__doc__.splitlines()[0]).parse_args()
    out = C.out_dir(args)
    from dask.distributed import Client, LocalCluster

    grid = (16, 16) if args.quick else (60, 60)
    periods = 100 if args.quick else 500
    repeats = 1 if args.quick else 3
    kw = dict(hb=1, alpha_range=(0.3, 1.0), omega_range=(0.8, 2.0), grid=grid, periods=periods)
    n = grid[0] * grid[1]
    chunk_sizes = [n // 4, n // 16, n // 64] if not args.quick else [n // 4, n // 16]

    t_compile, _ = C.timed(an.plane, **dict(kw, grid=(2, 2), periods=5))
    ref = an.plane(**kw)  # warm, and the reference result
    cluster = LocalCluster(n_workers=2, threads_per_worker=1, processes=True,
                           dashboard_address=None)
    client = Client(cluster)
    try:
        t_warm_workers, _ = C.timed(an.plane, **dict(kw, grid=(2, 2), periods=5),
                                    client=client, chunk=2)
        cases = {"in-process": lambda: an.plane(**kw)}
        for c in chunk_sizes:
            cases[f"cluster, {c} cells/chunk"] = (lambda c=c: an.plane(**kw, chunk=c,
                                                                      client=client))
        times = {k: [] for k in cases}
        identical = {}
        for _ in range(repeats):
            for k, fn in cases.items():
                dt, res = C.timed(fn)
                times[k].append(dt)
                identical[k] = bool(np.array_equal(res.label, ref.label) and np.array_equal(
                    res.lambda_max, ref.lambda_max, equal_nan=True))
    finally:
        client.close()
        cluster.close()

    base = C.median(times["in-process"])
    rows = []
    for k in cases:
        med = C.median(times[k])
        size = max(64, -(-n // 20)) if k == "in-process" else int(k.split(", ")[1].split()[0])
        n_chunks = -(-n // size)  # in-process runs the default chunking (progress between)
        per_chunk = None if k == "in-process" else (med - base) / n_chunks
        rows.append((k, n_chunks, med, med / base, per_chunk, "yes" if identical[k] else "NO"))
    headers = ("run", "chunks", "wall median s", "ratio to in-process",
               "overhead per chunk s", "identical to in-process")
    table = C.md_table(headers, rows)
    env = C.environment()
    note = (f"Plane {grid[0]} x {grid[1]} = {n} cells, {periods} periods, lambda_max on; "
            f"median of {repeats}, cases interleaved. Compile (first call, this process): "
            f"{t_compile:.1f} s; workers' first chunk (cache load): {t_warm_workers:.1f} s. "
            f"{C.env_line(env)}\n")
    C.write_text(out / "distributed.md", table + "\n" + note)
    C.write_csv(out / "distributed.csv", headers, rows)
    C.write_json(out / "distributed.json", dict(rows=[dict(zip(headers, r)) for r in rows],
                                                compile_s=t_compile, env=env,
                                                worker_warmup_s=t_warm_workers))
    plt = C.pyplot()
    fig, ax = plt.subplots(figsize=(7, 3.6))
    ax.barh([r[0] for r in rows][::-1], [r[2] for r in rows][::-1], color="#4c72b0")
    ax.set_xlabel("wall time [s] (median)")
    ax.set_title(f"{grid[0]}x{grid[1]} plane, {periods} periods: in-process vs 2-worker "
                 "LocalCluster", fontsize=9)
    fig.tight_layout()
    C.save_figure(fig, out / "distributed.png", dpi=120)
    C.update_readme(args, "distributed", table + "\n" + note)
    print(table)
    print(note)


if __name__ == "__main__":
    main()
