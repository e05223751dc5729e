"""Storage: atomic writes (:mod:`.atomic`), a command's output directory published as one unit
(:mod:`.output_dir`), which files of an output directory rockjit wrote and the lock of the
command publishing there (:mod:`.ownership`), who holds a lock or a hidden directory
(:mod:`.processes`), the resumable store of finished grid chunks with its lock
(:mod:`.chunkstore`), and results as xarray datasets (:mod:`.labelled`)."""
