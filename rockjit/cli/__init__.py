"""The ``rockjit`` command line (:mod:`.main`) and what each command leaves on disk
(:mod:`.outputs`)."""
