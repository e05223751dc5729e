"""``python -m rockjit``: the command line, through the same entry point as the ``rockjit``
script (:func:`rockjit.cli.main`)."""

from .cli import main

raise SystemExit(main())
