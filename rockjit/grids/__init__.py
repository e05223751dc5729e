"""Grids of runs: α sweeps, basins of attraction and parameter planes, run chunk by chunk on the
compiled engine (in this process or on a Dask cluster, resumable from a chunk store)."""
