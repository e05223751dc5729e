"""The study rockjit reproduces: its constants and its pipeline, :func:`paper`."""
