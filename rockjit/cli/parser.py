"""The ``rockjit`` argument parser: the program's own options and its commands, in the order
``rockjit --help`` lists them (each command declared, with its plan and run, in the module of
its group)."""

from __future__ import annotations

from .. import __version__
from .grid_commands import (add_basin_command, add_erosion_command, add_plane_command,
                            add_safety_command, add_sweep_command)
from .ground_commands import add_fragility_command, add_spectrum_command
from .messages import PROG
from .orbit_commands import add_chart_command, add_orbits_command
from .single_commands import add_fate_command, add_trajectory_command
from .study_commands import (add_compile_command, add_cor_command, add_explore_command,
                             add_paper_command)
from .usage import Parser

#: The declarations of the commands, in the order ``rockjit --help`` lists them.
COMMANDS = (add_trajectory_command,
            add_sweep_command,
            add_basin_command,
            add_plane_command,
            add_erosion_command,
            add_safety_command,
            add_orbits_command,
            add_chart_command,
            add_fate_command,
            add_spectrum_command,
            add_fragility_command,
            add_compile_command,
            add_cor_command,
            add_paper_command,
            add_explore_command)


def build_parser():
    """The argument parser (its ``error`` raises :class:`UsageError`)."""
    parser = Parser(prog=PROG, description="The harmonically forced rigid rocking block "
                    "(Housner's model): single runs, bifurcation sweeps, basins, figures.")
    parser.add_argument("--version", action="version", version=f"%(prog)s {__version__}")
    sub = parser.add_subparsers(dest="command", required=True, metavar="COMMAND",
                                parser_class=Parser)
    for add in COMMANDS:
        add(sub)
    return parser
