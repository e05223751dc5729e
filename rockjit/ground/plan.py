"""A single run under a transient excitation: validated into a plan, then run.

:func:`rockjit.simulate` hands a pulse or a record here (:func:`plan_transient`): the block
starts at rest unless a state is given, the integration settings are a
:class:`rockjit.Transient` (a transient excitation has no period to count), and the run goes
to the compiled path (:mod:`rockjit.ground.compiled`, ``method="rockjit"``, the default) or
the scipy reference path (:mod:`rockjit.ground.reference`).
"""

from __future__ import annotations

from dataclasses import dataclass

from ..model import Block
from ..validate import real, real_array
from .settings import Transient

__all__ = ["TransientPlan", "grid_settings", "plan_run", "plan_transient", "run_transient"]


@dataclass(frozen=True)
class TransientPlan:
    """A validated run under a pulse or a record: everything :func:`run_transient` needs."""

    block: Block
    excitation: object   # bound Pulse or Record
    state: tuple         # (theta0, theta0')
    settings: Transient
    method: object       # "rockjit" or a Scipy

    def run(self):
        """Run the plan (:func:`run_transient`)."""
        return run_transient(self)


def grid_settings(integration):
    """The settings of a grid's runs: ``integration`` (default :class:`Transient`) stopping
    once decided and keeping no trajectory."""
    from ..settings import Integration
    if integration is None:
        integration = Transient()
    if isinstance(integration, Integration):
        raise ValueError("a pulse or a record has no period to count: give "
                         "integration=rockjit.Transient(...) instead of a rockjit.Integration")
    if not isinstance(integration, Transient):
        raise ValueError(f"integration must be a rockjit.Transient "
                         f"(got {type(integration).__name__})")
    return integration.replace(stop_when_decided=True, record=False)


def bind(excitation, block):
    """``excitation`` bound to ``block``, with what a single run needs checked."""
    from ..plugs.pulse import Pulse
    if isinstance(excitation, Pulse):
        excitation.require("ratio", "amplitude", why="a run under a pulse")
    return excitation.bind(block)


def initial_state(state, settings):
    """``(theta0, theta0')``: at rest when ``state`` is None."""
    if state is None:
        return (0.0, 0.0)
    z = real_array("state", state, "two numbers (theta0, theta0')")
    if z.shape != (2,):
        raise ValueError(f"state must be two numbers (theta0, theta0') (got {state!r})")
    th = real("state[0] (theta0)", float(z[0]))
    if abs(th) >= settings.theta_over:
        raise ValueError(f"state[0] (theta0) must satisfy |theta0| < theta_over = "
                         f"{settings.theta_over:.6g} (got {th:g}): the block would start "
                         f"overturned")
    return (th, real("state[1] (dtheta0)", float(z[1]), -1e6, 1e6))


def plan_transient(block, forcing, state, integration, lyapunov, record_stride, method):
    """The plan of :func:`rockjit.simulate` for a pulse or a record; ``method`` is
    ``"rockjit"`` (the compiled path) or a :class:`rockjit.Scipy`."""
    from ..settings import Integration
    if integration is None:
        integration = Transient()
    if isinstance(integration, Integration):
        raise ValueError("a pulse or a record has no period to count: give "
                         "integration=rockjit.Transient(free_time=..., duration=...) "
                         "instead of a rockjit.Integration")
    if not isinstance(integration, Transient):
        raise ValueError(f"integration must be a rockjit.Transient for a pulse or a record "
                         f"(got {type(integration).__name__})")
    if lyapunov is not False:
        raise ValueError("lyapunov=True is only available for the harmonic forcing")
    if record_stride is not None:
        raise ValueError("record_stride counts the steps of a forcing period; a run under a "
                         "pulse or a record keeps the solver's points (Transient(record=...))")
    excitation = bind(forcing, block)
    return TransientPlan(block=block, excitation=excitation,
                         state=initial_state(state, integration), settings=integration,
                         method=method)


def plan_run(excitation, block, state, integration, lyapunov, record_stride, method):
    """The plan of a single run under a pulse or a record (``Excitation.plan_run`` of the
    transient excitations, which :func:`rockjit.simulate` asks)."""
    return plan_transient(block, excitation, state, integration, lyapunov, record_stride,
                          method)


def run_transient(p: TransientPlan):
    """Run a :class:`TransientPlan`: on the compiled path (:mod:`rockjit.ground.compiled`) or
    the scipy reference path (:mod:`rockjit.ground.reference`)."""
    if p.method == "rockjit":
        from .compiled import run_compiled
        return run_compiled(p.block, p.excitation, p.state, p.settings)
    from .reference import run_scipy
    return run_scipy(p.block, p.excitation, p.state, p.settings, p.method)
