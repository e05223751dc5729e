"""The private compiled engine: the Dormand–Prince stepper with located impacts, the
behaviour classifier, the lockstep lanes and the kernels' argument layout.

Nothing outside this package indexes the kernels' parameter vectors or output rows: the public
modules hand it validated objects and receive named arrays back (:mod:`.kernel`). It imports the
physics (:mod:`rockjit.model`) and nothing of storage or scheduling.
"""
