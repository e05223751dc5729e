"""Basins over a parameter and under round-off: erosion profiles (:mod:`.erosion`) and fates
decided by round-off (:mod:`.fate`); the attractors they name are the grids'
(:mod:`rockjit.grids.identity`), and each map's measures are :mod:`rockjit.measures`'."""
