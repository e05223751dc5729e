"""``python -m rockjit``: the command line (see :mod:`rockjit.cli`)."""

from .cli import main

raise SystemExit(main())
