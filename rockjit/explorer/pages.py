"""The pages one explorer server holds: how many sessions are open, how many pages compute
(a bound: :data:`MAX_PAGES`), and their worker threads.

A session opens with every request of the page's address (a browser's, or any other program's)
and holds only a placeholder: the page is built, and its worker thread started, when the
browser's websocket is open and the page has loaded (Bokeh's ``DocumentReady`` event, which
only a websocket from an allowed origin can carry). A page stops computing when its websocket
closes (the tab is closed or reloaded) and gives its place back.
"""

from __future__ import annotations

import threading
import weakref

__all__ = ["MAX_PAGES", "Pages"]

#: Pages that may compute at once on one server; a further tab is told to close one.
MAX_PAGES = 4


class Pages:
    """The counts of one server (thread-safe).

    Parameters
    ----------
    limit : int
        Pages that may compute at once.
    """

    def __init__(self, limit=MAX_PAGES):
        self.limit = int(limit)
        self._lock = threading.Lock()
        self._sessions = 0
        self._live = set()
        self._workers = weakref.WeakSet()

    def opened(self):
        """A session was created (its document function ran)."""
        with self._lock:
            self._sessions += 1

    def closed(self):
        """A session was destroyed."""
        with self._lock:
            self._sessions = max(0, self._sessions - 1)

    def room(self):
        """Whether one more page may compute."""
        with self._lock:
            return len(self._live) < self.limit

    def claim(self, page):
        """Give ``page`` a place among the computing pages; ``False`` when they are all
        taken."""
        with self._lock:
            if page in self._live:
                return True
            if len(self._live) >= self.limit:
                return False
            self._live.add(page)
            return True

    def started(self, computer):
        """A page started its worker (a :class:`rockjit.explorer.worker.Computer`)."""
        with self._lock:
            self._workers.add(computer)

    def release(self, page):
        """``page`` stopped computing."""
        with self._lock:
            self._live.discard(page)

    def close_all(self):
        """Stop every page's computations (the server stops)."""
        with self._lock:
            live = list(self._live)
        for page in live:
            page.stop_work()

    def stats(self):
        """``sessions`` open, ``pages`` computing, ``workers``: worker threads still running
        (a closed page's until its current piece of work ends), ``busy``: those computing."""
        with self._lock:
            workers = [c for c in self._workers if c.alive]
            out = dict(sessions=self._sessions, pages=len(self._live))
        out.update(workers=len(workers), busy=sum(1 for c in workers if not c.idle()))
        return out
