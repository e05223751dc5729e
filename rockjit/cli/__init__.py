"""The ``rockjit`` command line (:mod:`.main`: a command's run; :mod:`.parser` and the modules
of the command groups it declares: the parser and the commands, which write through
:mod:`rockjit.outputs`; :mod:`.signals`: SIGINT and SIGTERM), and its entry point :func:`main`,
which handles SIGINT and SIGTERM from its first instant, the imports of rockjit's modules
included.

Importing the numerical modules (numpy, numba) takes a noticeable time, and Ctrl-C during it
would end in a ``KeyboardInterrupt`` traceback. The package ``rockjit`` loads its public names
lazily, and :mod:`.signals` imports only the standard library, so this module installs the
command's signal handler (:func:`~.signals.interrupt_handler`) before anything numerical loads.
:func:`rockjit.cli.main.main` then finds that handler and uses it; once it has returned, the
two signals are ignored for the rest of the process's life, so that a signal after the run
cannot change its exit status. A signal during the imports ends the program with one line and
exit status 130 (SIGINT) or 143 (SIGTERM), nothing written.
"""

import signal
import sys
import types

from .signals import interrupt_handler, quiet_lost_interrupts


def main():
    """Run ``rockjit`` with the arguments of the command line; returns the exit status."""
    state = types.SimpleNamespace(received=[], final=False, out=None)
    handler = interrupt_handler(state)
    for s in (signal.SIGINT, signal.SIGTERM):
        signal.signal(s, handler)
    sys.unraisablehook = quiet_lost_interrupts(state, sys.unraisablehook)
    try:
        from .main import main as run
        if state.received:  # a signal whose KeyboardInterrupt was swallowed while importing
            raise KeyboardInterrupt
        return run()
    except BaseException as exc:  # during the imports, or in the last instants of a run
        state.final = True
        # a signal: KeyboardInterrupt, or what it became on its way out (an ImportError when
        # it interrupted the import of an extension module)
        if not isinstance(exc, KeyboardInterrupt) and (not state.received
                                                       or isinstance(exc, SystemExit)):
            raise
        signum = getattr(exc, "signum", None) or (state.received[-1] if state.received
                                                  else signal.SIGINT)
        out = state.out
        if out is not None and out.published:
            return 0
        if out is not None:
            out.discard()
        print(f"\nrockjit: interrupted ({signal.Signals(signum).name}); --out is as it was",
              file=sys.stderr, flush=True)
        return 128 + signum
    finally:
        state.final = True
        _settle()


def _settle():
    """The outcome is decided: SIGINT and SIGTERM are ignored for the last instants of the
    exit (the interpreter would otherwise put their default actions back while it finalizes,
    and a signal then would kill the process that has already succeeded)."""
    for s in (signal.SIGINT, signal.SIGTERM):
        signal.signal(s, signal.SIG_IGN)
