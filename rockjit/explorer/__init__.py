"""``rockjit explore`` and :func:`rockjit.explore`: the basin, a cell's run, the bifurcation diagram and both laws, live in a
browser, recomputed as the parameters change.

The compute side (:mod:`.requests`: parameters, coarse-to-fine stages, the Python call of each
view; :mod:`.worker`: the worker thread, newer requests superseding older ones) needs nothing
beyond rockjit; the user interface (:mod:`.app`, the page, with one module per view:
:mod:`.basin_panel`, :mod:`.run_panel`, :mod:`.sweep_panel`, :mod:`.compare_panel`; the
exports, :mod:`.export`; what they draw with, :mod:`.drawing`) and its server (:mod:`.server`)
need Bokeh, the ``explore`` extra: ``pip install 'rockjit[explore]'``. What the server lets in is
:mod:`.guard`'s; how many pages compute at once, :mod:`.pages`.

``rockjit.explore()`` starts the server (:func:`explore`).
"""

from __future__ import annotations

__all__ = ["explore"]


def explore(*, port=0, address="127.0.0.1", browser=True, block=False, quiet=False,
            allow_hosts=()):
    """Start the explorer's web server and return its handle.

    Parameters
    ----------
    port : int
        Port to listen on; 0 (default) takes a free one.
    address : str
        Address to bind; default ``127.0.0.1``, so that only this machine can connect.
        ``"::1"`` is IPv6's loopback; ``"0.0.0.0"`` (or ``"::"``) listens on every address of
        the machine, so that other machines can connect: a warning says so.
    allow_hosts : sequence of str
        More host names to accept in a request's ``Host`` header, beyond the bound address,
        ``localhost`` for a loopback address, and this machine's host name for another (for
        instance the name other machines use for this one). Every request naming another
        host is refused (a defence against DNS rebinding: docs/guide/explore.md).
    browser : bool
        Open the system's web browser on the explorer's address.
    block : bool
        Serve until interrupted (Ctrl-C) instead of returning at once. By default the server
        runs in a background thread and the call returns: a notebook or a shell goes on, and in
        a notebook the handle shows the explorer inline.
    quiet : bool
        Do not print the address.

    Returns
    -------
    Explorer
        ``.url``, ``.stop()``, ``.wait()``; in a notebook it shows the explorer in a frame.

    Examples
    --------
    >>> import rockjit
    >>> ex = rockjit.explore(browser=False, quiet=True)   # a free port on 127.0.0.1
    >>> ex.running, ex.url.startswith("http://127.0.0.1:")
    (True, True)
    >>> ex.stop()
    >>> ex.running
    False
    """
    from .server import start
    return start(port=port, address=address, browser=browser, block=block, quiet=quiet,
                 allow_hosts=allow_hosts)
