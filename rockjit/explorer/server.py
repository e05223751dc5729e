"""The explorer's web server: a Bokeh server bound to 127.0.0.1 on a free port, in a thread of
its own, with a handle to stop it (and to show it in a notebook)."""

from __future__ import annotations

import errno
import socket
import sys
import threading
import webbrowser

__all__ = ["Explorer", "free_port", "start"]


def _need_bokeh():
    try:
        import bokeh  # noqa: F401
    except ImportError:
        raise ImportError("rockjit explore needs Bokeh: pip install 'rockjit[explore]'") \
            from None


def free_port(address="127.0.0.1"):
    """A port free on ``address`` now (the OS's choice); ``ValueError`` when nothing can
    listen on ``address`` (not a host address, or not one of this machine's)."""
    family = socket.AF_INET6 if ":" in address else socket.AF_INET
    try:
        with socket.socket(family, socket.SOCK_STREAM) as s:
            s.bind((address, 0))
            return s.getsockname()[1]
    except OSError as exc:  # socket.gaierror included
        raise ValueError(f"cannot listen on {address} ({exc.strerror or exc})") from None


def _host(address):
    return f"[{address}]" if ":" in address else address


class Explorer:
    """A running explorer: its address, and how to stop it.

    Attributes
    ----------
    url : str
        Where it is served, e.g. ``http://127.0.0.1:50213/``.
    address, port :
        What the server's socket is bound to.
    """

    def __init__(self, server, loop, thread, address, port):
        self._server, self._loop, self._thread = server, loop, thread
        self.address, self.port = address, port
        self.url = f"http://{_host(address)}:{port}/"

    @property
    def running(self):
        return self._thread.is_alive()

    def stop(self, timeout=10.0):
        """Stop the server and the computations of its open pages."""
        if not self._thread.is_alive():
            return

        def shut():
            try:
                self._server.stop()
            finally:
                self._loop.stop()
        self._loop.add_callback(shut)
        self._thread.join(timeout)

    def wait(self):
        """Serve until Ctrl-C (or :meth:`stop` from another thread)."""
        try:
            while self._thread.is_alive():
                self._thread.join(0.5)
        except KeyboardInterrupt:
            self.stop()
            raise

    def __repr__(self):
        state = "running" if self.running else "stopped"
        return f"<rockjit explorer at {self.url} ({state})>"

    def _repr_html_(self):
        return (f'<p>rockjit explorer at <a href="{self.url}" target="_blank">{self.url}</a> '
                f'(<code>.stop()</code> stops it)</p><iframe src="{self.url}" width="100%" '
                f'height="900" style="border: 1px solid #ddd"></iframe>')


def _serve(address, port, ready, box):
    import asyncio

    from bokeh.application import Application
    from bokeh.application.handlers import FunctionHandler
    from bokeh.server.server import Server
    from tornado.ioloop import IOLoop

    from .app import document

    asyncio.set_event_loop(asyncio.new_event_loop())
    loop = IOLoop.current()
    try:
        origins = [f"{_host(address)}:{port}"]
        if address in ("127.0.0.1", "::1"):
            origins.append(f"localhost:{port}")
        server = Server({"/": Application(FunctionHandler(document))}, io_loop=loop,
                        address=address, port=port, allow_websocket_origin=origins,
                        num_procs=1, unused_session_lifetime_milliseconds=30_000,
                        check_unused_sessions_milliseconds=10_000)
        server.start()
    except Exception as exc:  # told to the starting thread
        box["error"] = exc
        ready.set()
        loop.close()
        return
    box.update(server=server, loop=loop)
    ready.set()
    try:
        loop.start()
    finally:
        loop.close(all_fds=True)


def start(*, port=0, address="127.0.0.1", browser=True, block=False, quiet=False):
    """Start the explorer (see :func:`rockjit.explorer.explore`); returns its :class:`Explorer`."""
    from ..validate import integer
    _need_bokeh()
    port = integer("port", port, 0, 65535)
    if not isinstance(address, str) or not address:
        raise ValueError(f"address must be a host address such as '127.0.0.1' (got {address!r})")
    tries = 5 if port == 0 else 1
    for attempt in range(tries):
        p = free_port(address) if port == 0 else port
        ready, box = threading.Event(), {}
        thread = threading.Thread(target=_serve, args=(address, p, ready, box),
                                  name="rockjit-explore-server", daemon=True)
        thread.start()
        ready.wait()
        exc = box.get("error")
        if exc is None:
            break
        thread.join()
        in_use = isinstance(exc, OSError) and exc.errno == errno.EADDRINUSE
        if not (in_use and attempt + 1 < tries):
            if in_use:
                raise ValueError(f"port {p} on {address} is in use: give another --port, or "
                                 f"0 for a free one") from None
            if isinstance(exc, OSError):
                raise ValueError(f"cannot listen on {address}:{p} ({exc.strerror or exc})") \
                    from None
            raise exc
    handle = Explorer(box["server"], box["loop"], thread, address, p)
    if not quiet:
        print(f"rockjit explore: serving on {handle.url} (Ctrl-C stops it)", flush=True)
    if browser:
        try:
            opened = webbrowser.open(handle.url)
        except Exception:  # no browser is no error: the address is printed
            opened = False
        if not opened and not quiet:
            print("rockjit explore: no browser could be opened here; open the address above",
                  file=sys.stderr, flush=True)
    if block:
        handle.wait()
    return handle
