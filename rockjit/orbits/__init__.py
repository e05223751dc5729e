"""Periodic orbits of the stroboscopic map: shooting, continuation and located bifurcations."""
