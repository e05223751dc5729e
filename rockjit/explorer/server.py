"""The explorer's web server: a Bokeh server in a thread of its own, bound to 127.0.0.1 on a free
port by default, every request checked (:mod:`.guard`) before Bokeh sees it, with a handle to
stop it (and to show it in a notebook)."""

from __future__ import annotations

import errno
import socket
import sys
import threading
import webbrowser

from .guard import HostPolicy, is_loopback, is_wildcard

__all__ = ["Explorer", "exposure_warning", "free_port", "start"]

#: How long a session without a connection lasts (a page requested but never connected, or a
#: closed tab), and how often the server looks for them, in milliseconds.
UNUSED_SESSION_MS = 15_000
CHECK_SESSIONS_MS = 2_000
#: The largest request body and websocket message the server reads, in bytes: the page sends
#: only small events.
MAX_BODY = 1 << 20


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


def exposure_warning(address, port):
    """The one-line warning printed when the server listens on an address other machines can
    reach (``None`` for a loopback address)."""
    if is_loopback(address):
        return None
    where = "every address of this machine" if is_wildcard(address) else address
    return (f"rockjit explore: warning: --address {address} exposes the explorer to the "
            f"network: any machine that can reach {where} on port {port} can use it and make "
            f"it compute")


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

    def __init__(self, server, loop, thread, address, port, pages, policy):
        self._server, self._loop, self._thread = server, loop, thread
        self.address, self.port = address, port
        self._pages, self.policy = pages, policy
        # a wildcard address is no address to browse to: this machine's own loopback is
        host = "127.0.0.1" if address == "0.0.0.0" else "::1" if is_wildcard(address) \
            else address
        self.url = f"http://{_host(host)}:{port}/"

    def stats(self):
        """What the server holds now: ``sessions`` open, ``pages`` computing, ``workers``
        (worker threads alive) and ``busy`` (those computing), and ``refused`` (requests
        refused so far by the Host and Origin checks)."""
        out = self._pages.stats()
        out["refused"] = self._server.refused
        return out

    @property
    def running(self):
        return self._thread.is_alive()

    def stop(self, timeout=10.0):
        """Stop the server and the computations of its open pages."""
        self._pages.close_all()
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


def _guarded(app, policy):
    """The Bokeh application ``app`` behind the Host and Origin checks of ``policy``: a Tornado
    connection delegate that answers a refused request with 403 and its reason, before Bokeh
    sees any of it, and hands the others to Bokeh."""
    from tornado import httputil

    class Guarded(httputil.HTTPServerConnectionDelegate):
        refused = 0

        def start_request(self, server_conn, request_conn):
            return Request(server_conn, request_conn)

        def on_close(self, server_conn):
            app.on_close(server_conn)

    class Request(httputil.HTTPMessageDelegate):
        def __init__(self, server_conn, request_conn):
            self.server_conn, self.conn = server_conn, request_conn
            self.inner, self.reason = None, None

        def headers_received(self, start_line, headers):
            self.reason = policy.refusal(headers)
            if self.reason is None:
                self.inner = app.start_request(self.server_conn, self.conn)
                return self.inner.headers_received(start_line, headers)
            guard.refused += 1
            return None

        def data_received(self, chunk):
            return None if self.inner is None else self.inner.data_received(chunk)

        def finish(self):
            if self.inner is not None:
                return self.inner.finish()
            body = f"rockjit explore: refused: {self.reason}\n".encode()
            self.conn.write_headers(
                httputil.ResponseStartLine("HTTP/1.1", 403, "Forbidden"),
                httputil.HTTPHeaders({"Content-Type": "text/plain; charset=utf-8",
                                      "X-Content-Type-Options": "nosniff",
                                      "Content-Length": str(len(body))}), body)
            self.conn.finish()
            return None

        def on_connection_close(self):
            if self.inner is not None:
                self.inner.on_connection_close()

    guard = Guarded()
    return guard


class _Server:
    """The Bokeh server's parts: its Tornado application, the HTTP server in front of it."""

    def __init__(self, base, guarded):
        self.base, self.guarded = base, guarded

    @property
    def refused(self):
        return self.guarded.refused

    def stop(self):
        self.base.stop()


def _headers(policy):
    """A Tornado output transform that adds the explorer's headers to every response of the
    application: who may frame it, and no guessing of content types."""
    from tornado.web import OutputTransform
    ancestors = f"frame-ancestors {policy.frame_ancestors()}"

    class Headers(OutputTransform):
        def transform_first_chunk(self, status_code, headers, chunk, finishing):
            headers["Content-Security-Policy"] = ancestors
            headers["X-Content-Type-Options"] = "nosniff"
            return status_code, headers, chunk
    return Headers


def _serve(address, port, policy, pages, ready, box):
    import asyncio
    from functools import partial

    from bokeh.application import Application
    from bokeh.application.handlers import FunctionHandler
    from bokeh.server.server import BaseServer
    from bokeh.server.tornado import BokehTornado
    from tornado.httpserver import HTTPServer
    from tornado.ioloop import IOLoop
    from tornado.netutil import bind_sockets

    from .app import document

    asyncio.set_event_loop(asyncio.new_event_loop())
    loop = IOLoop.current()
    sockets = []
    try:
        sockets = bind_sockets(port, address or None)
        port = sockets[0].getsockname()[1]
        app = BokehTornado({"/": Application(FunctionHandler(partial(document, pages=pages)))},
                           extra_websocket_origins=policy.websocket_origins(),
                           websocket_max_message_size_bytes=MAX_BODY,
                           unused_session_lifetime_milliseconds=UNUSED_SESSION_MS,
                           check_unused_sessions_milliseconds=CHECK_SESSIONS_MS,
                           transforms=[_headers(policy)])
        guarded = _guarded(app, policy)
        http = HTTPServer(guarded, xheaders=False, max_body_size=MAX_BODY)
        http.add_sockets(sockets)
        base = BaseServer(loop, app, http)
        base.start()
    except Exception as exc:  # told to the starting thread
        for sock in sockets:
            sock.close()
        box["error"] = exc
        ready.set()
        loop.close()
        return
    box.update(server=_Server(base, guarded), loop=loop, port=port)
    ready.set()
    try:
        loop.start()
    finally:
        loop.close(all_fds=True)


def start(*, port=0, address="127.0.0.1", browser=True, block=False, quiet=False,
          allow_hosts=()):
    """Start the explorer (see :func:`rockjit.explorer.explore`); returns its :class:`Explorer`."""
    from ..validate import integer
    from .pages import Pages
    _need_bokeh()
    port = integer("port", port, 0, 65535)
    if not isinstance(address, str) or not address.strip() or any(c.isspace() for c in address):
        raise ValueError(f"address must be a host address such as '127.0.0.1' (got {address!r})")
    if isinstance(allow_hosts, str):
        allow_hosts = (allow_hosts,)
    policy = HostPolicy(address, allow_hosts)
    if port == 0:
        free_port(address)  # a ValueError naming the address when nothing can listen there
    ready, box, pages = threading.Event(), {}, Pages()
    thread = threading.Thread(target=_serve, args=(address, port, policy, pages, ready, box),
                              name="rockjit-explore-server", daemon=True)
    thread.start()
    ready.wait()
    exc = box.get("error")
    if exc is not None:
        thread.join()
        if isinstance(exc, OSError) and exc.errno == errno.EADDRINUSE:
            raise ValueError(f"port {port} on {address} is in use: give another --port, or "
                             f"0 for a free one") from None
        if isinstance(exc, OSError):  # socket.gaierror included
            raise ValueError(f"cannot listen on {address}:{port} ({exc.strerror or exc})") \
                from None
        raise exc
    handle = Explorer(box["server"], box["loop"], thread, address, box["port"], pages, policy)
    warning = exposure_warning(address, handle.port)
    if warning:
        print(warning, file=sys.stderr, flush=True)
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
