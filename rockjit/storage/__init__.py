"""Storage: atomic files and a command's output directory (:mod:`.files`), which files of an
output directory rockjit wrote and the lock of the command publishing there
(:mod:`.ownership`), and the resumable store of finished grid chunks with its lock
(:mod:`.chunkstore`)."""
