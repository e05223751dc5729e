"""What the explorer's server lets in: the host names a request's ``Host`` header may give (a
defence against DNS rebinding) and the ``Origin`` a page or a websocket must come from.

A page of another site can make the browser send requests to the explorer: it can point an
``<img>`` at ``http://127.0.0.1:PORT/``, or give a name of its own that it later resolves to
this machine (DNS rebinding: the browser then sends ``Host: evil.example``). The server
therefore checks, on every HTTP request and on the websocket's opening request:

- the ``Host`` header names this server: for a loopback address, the address itself or
  ``localhost``; for ``0.0.0.0`` or ``::`` (every address of the machine), any IP address,
  ``localhost`` or this machine's host name; for another address, that address or this
  machine's host name; and any name given in ``allow_hosts``. The port is not compared, so
  that a forwarded port (``ssh -L``) works;
- an ``Origin`` header, where there is one, is the same origin as the ``Host`` (``http`` or
  ``https``, the same host and port), and the websocket's opening request must have one;
- and every response says which pages may show it in a frame (:meth:`HostPolicy.
  frame_ancestors`), so that another site cannot run the explorer in a hidden frame of its own.

Nothing here imports a web framework: :class:`HostPolicy` decides from the header values, and
:mod:`.server` applies it to every request before Bokeh sees it.
"""

from __future__ import annotations

import ipaddress
import re
import socket
from urllib.parse import urlsplit

__all__ = ["HostPolicy", "host_name", "is_loopback", "is_wildcard"]

_LABEL = r"[a-z0-9_]([a-z0-9_-]{0,61}[a-z0-9_])?"
_NAME = re.compile(rf"^{_LABEL}(\.{_LABEL})*$")


def _ip(text):
    """The IP address ``text`` names (IPv6 with or without brackets), or ``None``."""
    t = text[1:-1] if text.startswith("[") and text.endswith("]") else text
    try:
        return ipaddress.ip_address(t)
    except ValueError:
        return None


def host_name(text):
    """``text`` as the host part of a ``Host`` header would give it: lower case, an IPv6
    address in brackets; ``ValueError`` when it is neither a host name nor an IP address."""
    if not isinstance(text, str) or not text.strip():
        raise ValueError(f"allow_hosts: {text!r} is not a host name or an IP address")
    t = text.strip().lower()
    ip = _ip(t)
    if ip is not None:
        return f"[{ip.compressed}]" if ip.version == 6 else ip.compressed
    if "*" in t or not _NAME.match(t) or len(t) > 253:
        raise ValueError(f"allow_hosts: {text!r} is not a host name or an IP address "
                         f"(no wildcards)")
    return t


def is_wildcard(address):
    """Whether binding to ``address`` listens on every address of the machine."""
    return address in ("", "0.0.0.0", "::")


def is_loopback(address):
    """Whether ``address`` reaches this machine only (``127.0.0.0/8``, ``::1``, ``localhost``)."""
    if address.lower() == "localhost":
        return True
    ip = _ip(address)
    return ip is not None and ip.is_loopback


def _split(host):
    """``(name, port)`` of a ``Host`` header value (port ``None`` when absent), or ``None``
    when it is malformed."""
    host = host.strip().lower()
    if host.startswith("["):
        end = host.find("]")
        if end < 0:
            return None
        name, rest = host[:end + 1], host[end + 1:]
        if _ip(name) is None:
            return None
    else:
        name, sep, port = host.partition(":")
        rest = sep + port
    if rest and not (rest.startswith(":") and rest[1:].isdigit() and len(rest) <= 6):
        return None
    return name, (int(rest[1:]) if rest else None)


class HostPolicy:
    """The names and origins a server bound to ``address`` accepts (see the module's
    docstring).

    Parameters
    ----------
    address : str
        The address the server is bound to.
    allow_hosts : iterable of str
        More names to accept in the ``Host`` header (a name other machines use for this one,
        or a proxy's); checked by :func:`host_name`.
    """

    def __init__(self, address, allow_hosts=()):
        self.address = address
        self.any_ip = is_wildcard(address)
        names = {host_name(n) for n in allow_hosts}
        if is_loopback(address) or self.any_ip:
            names.add("localhost")
        if address.lower() == "localhost":
            names.update(("127.0.0.1", "[::1]"))
        elif not self.any_ip:
            names.add(host_name(address))
        if not is_loopback(address):
            try:
                names.add(host_name(socket.gethostname()))
            except (OSError, ValueError):
                pass
        self.names = frozenset(names)

    def allows_host(self, host):
        """Whether a ``Host`` header value names this server."""
        parts = _split(host or "")
        if parts is None:
            return False
        name, ip = parts[0], _ip(parts[0])
        if ip is not None:  # the address as this policy writes it: [::1], 127.0.0.1
            name = f"[{ip.compressed}]" if ip.version == 6 else ip.compressed
        return name in self.names or (self.any_ip and ip is not None)

    def allows_origin(self, origin, host):
        """Whether an ``Origin`` header value is this server's own page as the ``Host`` header
        names it."""
        if not origin or not self.allows_host(host):
            return False
        try:
            o = urlsplit(origin.strip())
        except ValueError:
            return False
        if o.scheme not in ("http", "https") or o.path not in ("", "/") or o.query:
            return False
        return o.netloc.lower() == host.strip().lower()

    def refusal(self, headers):
        """Why a request with these headers (a mapping, case-insensitive as HTTP's) is refused,
        or ``None`` when it is let in."""
        host = headers.get("Host")
        if not host:
            return "a request without a Host header"
        if not self.allows_host(host):
            return f"Host {_quote(host)} does not name this server"
        origin = headers.get("Origin")
        websocket = "websocket" in (headers.get("Upgrade") or "").lower()
        if origin is None and websocket:
            return "a websocket without an Origin header"
        if origin is not None and not self.allows_origin(origin, host):
            return f"Origin {_quote(origin)} is not this server's page"
        return None

    def frame_ancestors(self):
        """The pages that may show the explorer in a frame (a ``Content-Security-Policy``'s
        ``frame-ancestors``): its own, and pages served by this machine's loopback or by the
        names it accepts (a notebook's inline view), so that another site's page cannot run it
        in a hidden frame."""
        hosts = {"localhost", "127.0.0.1"} | {n for n in self.names if not n.startswith("[")}
        return " ".join(["'self'"] + [f"{scheme}://{h}:*" for h in sorted(hosts)
                                      for scheme in ("http", "https")])

    def websocket_origins(self):
        """Patterns for Bokeh's own websocket origin check (``host:port``, ``*`` a wildcard),
        a second check behind :meth:`refusal`."""
        out = {f"{n}:*" for n in self.names}
        if self.any_ip:
            out.add("*.*.*.*:*")
            if self.address in ("", "::"):
                out.add("*")  # an IPv6 address cannot be written as Bokeh's pattern
        return sorted(out)


def _quote(text):
    """A header value in a message: printable ASCII, at most 80 characters."""
    t = "".join(c if " " <= c <= "~" else "?" for c in str(text))
    return repr(t[:80] + ("..." if len(t) > 80 else ""))
