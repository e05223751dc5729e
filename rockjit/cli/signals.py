"""The signals of a command: SIGINT and SIGTERM give one outcome per run.

A command's state is a namespace with ``received`` (the signals that arrived, in order),
``final`` (once true, signals are only recorded) and ``out`` (its
:class:`~rockjit.storage.output_dir.OutputDir`, or None). Its handler (:func:`interrupt_handler`)
records each SIGINT or SIGTERM and, until ``final`` is set or ``out`` is published, raises
``KeyboardInterrupt`` carrying the signal in ``signum``: before publication a signal interrupts
the run (exit status 128 + signum, ``--out`` as it was); after it, the run has succeeded and
the signal changes nothing. The console script's entry point (:func:`rockjit.cli.main`)
installs the handler before rockjit's numerical modules load, so that Ctrl-C during the imports
is handled too; the handler is marked with ``rockjit_state``, so that :func:`command_interrupts`
finds it and uses it. This module imports only the standard library, for that entry point.
"""

import contextlib
import signal
import sys
import threading
import types

__all__ = ["command_interrupts", "installed_interrupts", "interrupt_handler", "interrupted",
           "quiet_lost_interrupts", "signal_name"]


def interrupt_handler(state):
    """The SIGINT and SIGTERM handler of a command's ``state`` (see the module's opening)."""
    def handler(signum, frame):
        state.received.append(signum)
        if state.final or getattr(state.out, "published", False):
            return
        exc = KeyboardInterrupt()
        exc.signum = signum
        raise exc
    handler.rockjit_state = state
    return handler


def installed_interrupts():
    """The state of the command handler installed for both SIGINT and SIGTERM, or ``None``."""
    state = getattr(signal.getsignal(signal.SIGINT), "rockjit_state", None)
    if state is not None and getattr(signal.getsignal(signal.SIGTERM), "rockjit_state",
                                     None) is state:
        return state
    return None


@contextlib.contextmanager
def command_interrupts():
    """SIGINT and SIGTERM handled for one command (:func:`interrupt_handler`).

    Reuses the handler already installed by the program's entry point, if there is one, and
    leaves it in place; otherwise installs one for the block and puts the previous handlers
    back on exit. Outside the main thread nothing is installed.

    Yields
    ------
    namespace
        The state: ``received``, ``final``, ``out``.
    """
    state = installed_interrupts()
    if state is not None:
        yield state
        return
    state = types.SimpleNamespace(received=[], final=False, out=None)
    old = {}
    hook = sys.unraisablehook
    if threading.current_thread() is threading.main_thread():
        handler = interrupt_handler(state)
        for s in (signal.SIGINT, signal.SIGTERM):
            try:
                old[s] = signal.signal(s, handler)
            except (ValueError, OSError):
                pass
        sys.unraisablehook = quiet_lost_interrupts(state, hook)
    try:
        yield state
    finally:
        for s, h in old.items():
            signal.signal(s, signal.SIG_DFL if h is None else h)
        sys.unraisablehook = hook


def quiet_lost_interrupts(state, previous):
    """A ``sys.unraisablehook`` that drops the KeyboardInterrupt of a signal raised where it
    cannot propagate (in a finalizer: Python would print "Exception ignored in ..." and a
    traceback, and go on). The signal is in ``state.received``, and the command acts on it
    before publishing (see :func:`interrupted`). Anything else goes to ``previous``."""
    def hook(unraisable):
        if issubclass(unraisable.exc_type, KeyboardInterrupt) and state.received:
            return
        previous(unraisable)
    return hook


def interrupted(state):
    """Raise the KeyboardInterrupt of a signal that arrived (``state.received``) but whose
    KeyboardInterrupt did not reach the command: swallowed by a finalizer, or by a library's
    ``except BaseException``. Called before work and before publishing, so that a signal
    before publication always interrupts."""
    if state.received and not state.final:
        exc = KeyboardInterrupt()
        exc.signum = state.received[-1]
        raise exc


def signal_name(signum):
    """``"SIGINT"``, ``"SIGTERM"``, ..."""
    try:
        return signal.Signals(signum).name
    except ValueError:
        return f"signal {signum}"
