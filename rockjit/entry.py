"""How an entry point is made: its signature written once, for planning and for running.

An entry point's body checks its inputs together and returns a plan; :func:`entry_point` wraps
it so that calling it runs the plan, while the planning function stays reachable as
``entry.plan``: the command line plans first (refusing bad input before any work) and runs
later, with the same parameters and the same messages.
"""

from __future__ import annotations

import functools

__all__ = ["entry_point"]


def entry_point(execute):
    """Decorate a planning function: the result keeps its parameters and docstring, plans,
    then returns ``execute(plan, execution)`` (``execution`` the call's keyword of that name,
    or ``None``); the planning function is ``entry.plan``."""
    def decorate(plan_fn):
        @functools.wraps(plan_fn)
        def entry(*args, **kwargs):
            return execute(plan_fn(*args, **kwargs), kwargs.get("execution"))

        entry.plan = plan_fn
        return entry
    return decorate
