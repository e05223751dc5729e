"""``python -m rockjit``: the command line (see :mod:`rockjit.cli.main`)."""

from .cli.main import entry

raise SystemExit(entry())
