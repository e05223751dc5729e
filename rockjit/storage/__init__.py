"""Storage: atomic files and a command's output directory (:mod:`.files`), and the resumable
store of finished grid chunks with its lock (:mod:`.chunkstore`)."""
