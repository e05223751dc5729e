"""The explorer's computations off the server's event loop: one worker thread, a request per
view, newer requests superseding older ones.

Each view (the basin, the run, the bifurcation diagram, the two laws) is a *channel*. A request
on a channel is a list of stages (functions of a progress callback, :mod:`.requests`): the
basin's are its 50², 100² and 200² lattices. Submitting a request supersedes the channel's
previous one: its progress callback raises :class:`Cancelled` at its grid's next chunk, and
whatever it returns after that is dropped. A result is published only while its request is
still the channel's newest, decided under the same lock that :meth:`Computer.submit` takes, so
that a superseded request never publishes.

One thread computes, one stage at a time: the compiled grids already use every core, and two of
them at once would only share the cores. Between stages (and between the chunks of a stage) the
worker takes the most urgent stage first: a click's run before the basin, the basin before the
bifurcation diagram, the two laws last; a stage may rank itself otherwise (its ``rank``
attribute, a number on the channels' scale 0, 1, 2, 3: the basin's finest lattice ranks after
the bifurcation diagram, so that a change shows every view before refining). A stage
interrupted for a more urgent one is run again from its start later.
"""

from __future__ import annotations

import sys
import threading
import time
import traceback
from dataclasses import dataclass, field

__all__ = ["CHANNELS", "Cancelled", "Computer", "Event"]

#: The channels, most urgent first.
CHANNELS = ("run", "basin", "sweep", "compare")


class Cancelled(Exception):
    """Raised inside a computation whose request was superseded or cancelled."""


class _Preempted(Exception):
    """Raised inside a stage when a more urgent channel has work: the stage runs again later."""


@dataclass
class Event:
    """What the worker tells the user interface.

    ``kind`` is ``"progress"`` (``stage`` label, ``fraction`` done), ``"result"`` (``value``:
    the stage's view; ``final`` when it was the request's last stage), ``"error"`` (``message``:
    the library's ``ValueError`` message, or the type and message of an unexpected exception)
    or ``"done"``.
    """

    kind: str
    channel: str
    request: int
    stage: str = ""
    fraction: float = 0.0
    value: object = None
    final: bool = False
    message: str = ""


@dataclass
class _Request:
    number: int
    stages: list
    next: int = 0
    started: float = field(default_factory=time.perf_counter)


class Computer:
    """The worker thread and its channels.

    Parameters
    ----------
    publish : callable
        ``publish(event)`` for each :class:`Event`, called from the worker thread while the
        event's request is its channel's newest (keep it short: a user interface schedules the
        event on its own loop and checks :meth:`is_current` again there).
    progress_every : float
        Least time between two progress events of a stage, in seconds.
    """

    def __init__(self, publish, progress_every=0.1):
        self._publish = publish
        self._every = progress_every
        self._cond = threading.Condition()
        self._counter = 0
        self._latest = {c: 0 for c in CHANNELS}
        self._pending = {}
        self._closed = False
        self._busy = None
        self._thread = threading.Thread(target=self._loop, name="rockjit-explore", daemon=True)
        self._thread.start()

    # the interface ----------------------------------------------------------------------------
    def submit(self, channel, stages):
        """Start a request on ``channel``; it supersedes the channel's previous one. Returns the
        request's number."""
        if channel not in self._latest:
            raise ValueError(f"channel must be one of {', '.join(CHANNELS)} (got {channel!r})")
        with self._cond:
            self._counter += 1
            n = self._counter
            self._latest[channel] = n
            self._pending[channel] = _Request(n, list(stages))
            self._cond.notify_all()
        return n

    def cancel(self, channel):
        """Supersede the channel's request with nothing."""
        with self._cond:
            self._counter += 1
            self._latest[channel] = self._counter
            self._pending.pop(channel, None)
            self._cond.notify_all()

    @property
    def alive(self):
        """Whether the worker thread still runs (after :meth:`close`, until the piece of work
        it is in ends)."""
        return self._thread.is_alive()

    def is_current(self, channel, number):
        """Whether request ``number`` is still the channel's newest."""
        with self._cond:
            return self._latest.get(channel) == number

    def idle(self):
        """True when nothing is pending or computing."""
        with self._cond:
            return not self._pending and self._busy is None

    def wait_idle(self, timeout=None):
        """Wait until :meth:`idle`; returns whether it is."""
        end = None if timeout is None else time.monotonic() + timeout
        with self._cond:
            while self._pending or self._busy is not None:
                left = None if end is None else end - time.monotonic()
                if left is not None and left <= 0:
                    return False
                self._cond.wait(left)
            return True

    def close(self, timeout=5.0):
        """Cancel everything and stop the thread: it ends at the current stage's next progress
        call (a grid's next chunk). Waits up to ``timeout`` seconds for it (0: does not wait, as
        on a server's event loop)."""
        with self._cond:
            self._closed = True
            for c in CHANNELS:
                self._counter += 1
                self._latest[c] = self._counter
            self._pending.clear()
            self._cond.notify_all()
        if timeout and threading.current_thread() is not self._thread:
            self._thread.join(timeout)

    # the worker -------------------------------------------------------------------------------
    def _emit(self, event):
        """Publish ``event`` if its request is current (under the lock: a submit cannot slip in
        between the check and the publication)."""
        with self._cond:
            if self._latest.get(event.channel) != event.request:
                return False
            try:
                self._publish(event)
            except Exception:  # a broken listener must not stop the worker
                traceback.print_exc(file=sys.stderr)
            return True

    def _rank(self, channel):
        """The rank of the channel's next stage (lower runs first)."""
        req = self._pending[channel]
        stage = req.stages[req.next]
        return (getattr(stage, "rank", CHANNELS.index(channel)), CHANNELS.index(channel))

    def _most_urgent(self):
        return min(self._pending, key=self._rank, default=None)

    def _loop(self):
        while True:
            with self._cond:
                while not self._closed and not self._pending:
                    self._cond.wait()
                if self._closed:
                    return
                channel = self._most_urgent()
                req = self._pending[channel]
                self._busy = (channel, req.number)
            try:
                self._run_stage(channel, req)
            finally:
                with self._cond:
                    self._busy = None
                    self._cond.notify_all()

    def _check(self, channel, req):
        """Raise :class:`Cancelled` if the request was superseded, :class:`_Preempted` if a more
        urgent stage waits."""
        with self._cond:
            if self._closed or self._latest.get(channel) != req.number:
                raise Cancelled
            mine = self._rank(channel)
            if any(self._rank(c) < mine for c in self._pending if c != channel):
                raise _Preempted

    def _run_stage(self, channel, req):
        stage = req.stages[req.next]
        label = getattr(stage, "label", channel)
        last = [0.0]

        def progress(done, total):
            self._check(channel, req)
            now = time.perf_counter()
            if done == 0 or done >= total or now - last[0] >= self._every:
                last[0] = now
                self._emit(Event("progress", channel, req.number, stage=label,
                                 fraction=done / total if total else 1.0))

        try:
            self._check(channel, req)
            self._emit(Event("progress", channel, req.number, stage=label, fraction=0.0))
            value = stage(progress)
        except Cancelled:
            return
        except _Preempted:
            return  # stays pending at the same stage
        except ValueError as exc:  # the library refused: its message
            self._finish(channel, req)
            self._emit(Event("error", channel, req.number, stage=label, message=str(exc)))
            return
        except Exception as exc:  # a bug: said in the interface, the traceback on stderr
            traceback.print_exc(file=sys.stderr)
            self._finish(channel, req)
            self._emit(Event("error", channel, req.number, stage=label,
                             message=f"{type(exc).__name__}: {exc}"))
            return
        req.next += 1
        final = req.next >= len(req.stages)
        if final:
            self._finish(channel, req)
        self._emit(Event("result", channel, req.number, stage=label, value=value, final=final))
        if final:
            self._emit(Event("done", channel, req.number, stage=label, fraction=1.0))

    def _finish(self, channel, req):
        with self._cond:
            if self._pending.get(channel) is req:
                del self._pending[channel]
