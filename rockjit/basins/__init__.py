"""Basins and what lives in them: attractor identity (:mod:`.identity`), basin entropy,
uncertainty and integrity (:mod:`.measures`), erosion profiles (:mod:`.erosion`) and fates
decided by round-off (:mod:`.fate`)."""
