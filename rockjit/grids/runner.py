"""The grid runner: a grid's cells cut into chunks, run in this process or on a Dask cluster,
resumable from a chunk store, with progress between chunks.

Each chunk is one call of a runner function (:func:`rockjit._engine.kernel.run_chunk`: the
compiled parallel kernel on those cells), in this process or as a task on a
``dask.distributed.Client``, whose workers run the same compiled kernels. Results are placed
into the full output arrays as chunks arrive; with a store (:class:`rockjit.storage.chunkstore.
ChunkStore`) every finished chunk is saved, and a rerun computes only what is missing. Dask is
optional and imported only when a client is given.

In this process, a grid's cells run as *pieces*: calls of the kernel on one thread each, as
many at once as there are threads, each thread taking the next piece as soon as its last one
is done (:func:`local_plan`, :func:`pieces`). No thread waits for another at the end of a
chunk, and the pieces shrink as the grid nears its end (guided scheduling: a piece holds the
cells left over twice the threads, between :data:`PIECE_MIN` and :data:`PIECE_MAX` cells, and
never crosses a chunk's end), so that the last pieces are short. A chunk (the unit of progress,
of resumption and of Dask tasks) is placed once all its pieces are done. A cell's results do
not depend on its chunk, its piece, its thread or what runs beside it.

On Dask, each chunk is a task whose key is unique to the computation (its fingerprint, the
chunk's bounds and a nonce of the call), so that computations sharing a scheduler never get
each other's results; each task returns its tag with its arrays, and a result whose tag is not
the one sent is refused. A computation waits for the scheduler to have a worker, saying so,
and gives up with :class:`NoWorkers` after ``worker_timeout`` seconds without one (at the start
or when every worker is lost mid-run).
"""

from __future__ import annotations

import asyncio
import concurrent.futures as cf
import contextlib
import contextvars
import itertools
import secrets
import sys
import time

import numba
import numpy as np

from .._engine import kernel
from ..storage import chunkstore as chunks
from ..storage.chunkstore import DamagedChunk

__all__ = ["NoWorkers", "PIECE_MAX", "PIECE_MIN", "WORKER_TIMEOUT", "local_plan", "pieces",
           "run_chunks", "run_grid", "wait_for_workers", "worker_timeout"]

#: Seconds a computation on a Dask client waits for a worker before giving up (the default of
#: ``Execution(worker_timeout=...)``; ``rockjit.grids.runner.worker_timeout(seconds)`` sets
#: another for a block of code, as ``--scheduler-timeout`` does).
WORKER_TIMEOUT = 60.0
_WORKER_TIMEOUT = contextvars.ContextVar("rockjit_worker_timeout", default=None)
#: Seconds between two looks at the scheduler's workers while no chunk finishes.
POLL = 1.0


class NoWorkers(RuntimeError):
    """A Dask scheduler had no worker for longer than the timeout; ``address``, ``timeout``."""

    def __init__(self, address, timeout, lost=False):
        self.address, self.timeout, self.lost = address, timeout, lost
        what = "lost its workers, and none joined again" if lost else "had no worker"
        super().__init__(f"the Dask scheduler at {address} {what} in {timeout:g} s")


@contextlib.contextmanager
def worker_timeout(seconds):
    """Within the block, computations on Dask wait ``seconds`` for a worker (by default)."""
    token = _WORKER_TIMEOUT.set(float(seconds))
    try:
        yield
    finally:
        _WORKER_TIMEOUT.reset(token)


def _timeout(value):
    if value is None:
        value = _WORKER_TIMEOUT.get()
    return WORKER_TIMEOUT if value is None else float(value)


def _address(client):
    try:
        return client.scheduler.address
    except AttributeError:
        return "?"


def _n_workers(client):
    return len(client.nthreads())


def wait_for_workers(client, timeout=None, message=None, lost=False):
    """Return once ``client``'s scheduler has a worker; raise :class:`NoWorkers` after
    ``timeout`` seconds (default :data:`WORKER_TIMEOUT`, or :func:`worker_timeout`'s) without
    one. While it waits, ``message(text)`` (default a line on stderr) hears so once."""
    if _n_workers(client):
        return
    timeout = _timeout(timeout)
    say = chunks._say if message is None else message
    address = _address(client)
    say(f"waiting for a worker on the Dask scheduler at {address} (giving up after "
        f"{timeout:g} s)")
    deadline = time.monotonic() + timeout
    while not _n_workers(client):
        left = deadline - time.monotonic()
        if left <= 0:
            raise NoWorkers(address, timeout, lost)
        time.sleep(min(0.2, left))
    say(f"a worker joined the Dask scheduler at {address}")


def _tagged(runner, tag, *args):
    """A chunk's task on a worker: ``runner(*args)`` with ``tag`` (the chunk's identity)."""
    return tag, runner(*args)


def _fingerprint(runner, inputs, n, chunk):
    """The computation's fingerprint: its arrays' bytes and everything else it is given."""
    arrays = [x for x in inputs if isinstance(x, np.ndarray)]
    rest = [None if isinstance(x, np.ndarray) else repr(x) for x in inputs]
    name = f"{getattr(runner, '__module__', '')}.{getattr(runner, '__qualname__', repr(runner))}"
    return chunks.fingerprint(arrays, dict(runner=name, rest=rest, n=int(n), chunk=int(chunk)))


#: The fewest cells of a piece (the last pieces of a grid; a chunk smaller than this is one
#: piece): eight lanes' worth of cells four times over, so that a piece's lanes stay busy.
PIECE_MIN = 32
#: The most cells of a piece (the first pieces of a large grid): bounds the outputs held by
#: the pieces running at once.
PIECE_MAX = 4096


def _thread_safe_layer():
    """Whether numba's threading layer lets two threads of this process launch parallel
    kernels at once (``tbb`` and ``omp`` do; ``workqueue`` ends the process if it sees it)."""
    numba.get_num_threads()  # starts the threading layer, if not yet started
    try:
        return numba.threading_layer() in ("tbb", "omp")
    except ValueError:
        return False


def local_plan(threads):
    """How a grid runs in this process on ``threads`` threads: ``(threads_per_call, at_once)``.

    Where numba's threading layer lets several threads launch kernels at once
    (:func:`_thread_safe_layer`), ``(1, threads)``: pieces of one thread each, ``threads`` at
    once (never more threads busy than asked for). Otherwise ``(threads, 1)``: one chunk at a
    time on all the threads."""
    threads = max(1, int(threads))
    return (1, threads) if _thread_safe_layer() else (threads, 1)


def pieces(bounds, at_once, smallest=PIECE_MIN, largest=PIECE_MAX):
    """The pieces ``(a, b, k)`` of the chunks ``bounds`` (``[(a, b), ...]``; ``k`` the chunk's
    index), in order: each holds the cells not yet given out over ``2 * at_once``, at least
    ``smallest`` and at most ``largest``, and never crosses its chunk's end.

    >>> [p[:2] for p in pieces([(0, 60), (60, 75)], 2, smallest=8, largest=20)]
    [(0, 18), (18, 32), (32, 42), (42, 50), (50, 58), (58, 60), (60, 68), (68, 75)]
    """
    left = sum(b - a for a, b in bounds)
    for k, (a, b) in enumerate(bounds):
        while a < b:
            size = max(smallest, min(largest, left // (2 * max(1, at_once))))
            end = min(b, a + size)
            yield a, end, k
            left -= end - a
            a = end


def run_grid(y0s, pars, ipar, cpar, *, tangent, n_pts, n_imp_pts, label, execution):
    """All cells through :func:`rockjit._engine.kernel.run_chunk`, chunk by chunk, as
    ``execution`` (a :class:`rockjit.Execution`) says: threads, chunk size, lanes, in this
    process or on a Dask cluster, with a chunk store, with progress.

    The chunk defaults to :func:`rockjit._engine.kernel.default_chunk` (a twentieth of the
    grid), or to the chunk of the store already begun for the same computation. In this
    process the cells run as pieces on one thread each, as many at once as threads
    (:func:`local_plan`, :func:`pieces`). With ``execution.device == "cuda"`` each chunk runs
    on the GPU instead (:func:`rockjit._engine.gpu.run_chunk`, chunks of
    :func:`rockjit._engine.gpu.default_chunk` cells by default), here or on a Dask worker;
    here, the next chunk starts on the GPU while the host places and stores the last
    (:func:`run_chunks`' ``ahead``).

    Returns the outputs by name: ``res`` (the kernels' rows; :func:`rockjit._engine.kernel.
    grid_results` names them), ``pts``, ``imp``, ``n_got``, ``n_imp_got``. With a Dask
    cluster, a scheduler without workers is waited for ``execution.worker_timeout`` seconds
    (:func:`run_chunks`).
    """
    ex = execution
    n = y0s.shape[0]
    outputs_ = kernel.grid_outputs(n, n_pts, n_imp_pts)
    cuda = ex.device == "cuda"
    # on the GPU (rockjit._engine.gpu), one cell per thread; the same inputs and outputs
    run_chunk = kernel.run_chunk
    if cuda:
        from .._engine import gpu
        run_chunk = gpu.run_chunk
    key = None
    if ex.store is not None:
        # the GPU's results differ from the CPU's in the last bits: a store is one device's
        how = dict(tangent=bool(tangent), n_pts=n_pts, n_imp_pts=n_imp_pts)
        key = chunks.fingerprint((y0s, pars, ipar, cpar),
                                 dict(how, device="cuda") if cuda else how)
    chunk = ex.chunk
    if chunk is None and key is not None:
        chunk = chunks.ChunkStore.stored_chunk(ex.store, key, n)
    if chunk is None:
        chunk = gpu.default_chunk(n) if cuda else kernel.default_chunk(n)
    with _client(ex) as client:
        threads, at_once = ex.threads, 1
        if client is None and not cuda:
            # the calling thread's count (numba.set_num_threads is per thread)
            total = numba.get_num_threads() if ex.threads is None else ex.threads
            threads, at_once = local_plan(total)
        cs = None if key is None else chunks.ChunkStore(ex.store, key, n, chunk,
                                                        message=ex.message)
        run_chunks(run_chunk, (bool(tangent), y0s, pars, ipar, cpar, n_pts, n_imp_pts,
                               threads, ex.lanes), n, chunk, outputs_, client=client,
                   store=cs, progress=ex.progress, label=label, message=ex.message,
                   worker_timeout=ex.worker_timeout, at_once=at_once, ahead=cuda)
    return outputs_


@contextlib.contextmanager
def _client(execution):
    """The Dask client of an execution: the one given, one opened on its scheduler for the
    computation (closed after it), or ``None``."""
    if execution.scheduler is None:
        yield execution.client
        return
    from dask.distributed import Client
    client = Client(execution.scheduler)
    try:
        yield client
    finally:
        client.close()


class _Progress:
    """Progress on stderr (``stream``): a :mod:`tqdm` bar on a terminal; plain lines otherwise.

    On a terminal the bar redraws itself in place: its description is ``label`` (what is
    counted: the grid, the block's law and the fixed forcing, e.g. ``"basin hb=1 housner
    alpha=0.66 omega=1.3"``), then the percentage, ``done/total cells``, the time elapsed and
    left, and the rate. Cells loaded from a chunk store count as done from the start and not
    in the rate.

    When ``stream`` is not a terminal (a log file, a pipe, a notebook's captured stderr), tqdm
    is not used: it redraws by writing ``\r`` before each refresh even to a file (also with
    ``mininterval=5``), so a log would hold one ever-growing line of bars. There, plain lines
    are written instead, ``"<label>: done/total cells, 12.0 s elapsed, ~30.0 s left"``, at
    most one every :attr:`EVERY` seconds plus the last, so that the log stays readable.
    """

    EVERY = 5.0

    def __init__(self, total, label, enabled, done=0, stream=None):
        self.total, self.label, self.enabled = total, label, enabled
        self.stream = sys.stderr if stream is None else stream
        try:
            self.tty = bool(self.stream.isatty())
        except (AttributeError, ValueError):
            self.tty = False
        self.t0 = self.last = time.perf_counter()
        self.done = self.start = done
        self.pending = False
        self.bar = None
        if enabled and self.tty:
            from tqdm import tqdm
            self.bar = tqdm(total=total, initial=done, desc=label, file=self.stream,
                            unit="cells", smoothing=0, dynamic_ncols=True, leave=True,
                            bar_format="{desc}: {percentage:3.0f}%|{bar}| {n_fmt}/{total_fmt} "
                                       "cells [{elapsed}<{remaining}, {rate_fmt}]")

    def _line(self):
        el = time.perf_counter() - self.t0
        fresh = self.done - self.start
        eta = el / fresh * (self.total - self.done) if fresh else float("nan")
        return (f"{self.label}: {self.done}/{self.total} cells, {el:.1f} s elapsed, "
                f"~{eta:.1f} s left")

    def update(self, n):
        self.done += n
        if not self.enabled:
            return
        if self.bar is not None:
            self.bar.update(n)
        elif time.perf_counter() - self.last >= self.EVERY or self.done >= self.total:
            self.stream.write(self._line() + "\n")
            self.stream.flush()
            self.last = time.perf_counter()
            self.pending = False
        else:
            self.pending = True

    def close(self):
        if not self.enabled:
            return
        if self.bar is not None:
            self.bar.close()
        elif self.pending:
            self.stream.write(self._line() + "\n")
            self.pending = False
            self.stream.flush()


class _Callback:
    """Progress told to a callable ``progress(done, total)`` instead of stderr: once at the
    start, then after each chunk. What it raises stops the run."""

    def __init__(self, total, progress, done):
        self.total, self.progress, self.done = total, progress, done
        progress(done, total)

    def update(self, n):
        self.done += n
        self.progress(self.done, self.total)

    def close(self):
        pass


def run_chunks(runner, inputs, n, chunk, outputs, *, client=None, store=None, progress=False,
               label="cells", task_prefix="rockjit", message=None, worker_timeout=None,
               at_once=1, ahead=False):
    """Run ``runner`` over chunks of ``n`` cells and fill ``outputs`` in place.

    Parameters
    ----------
    runner : callable
        ``runner(*inputs_of_chunk) -> dict name -> array`` for cells ``a:b``; module-level, so
        that Dask can send it to workers.
    inputs : tuple
        Arguments of ``runner``; arrays whose first axis has length ``n`` are sliced per chunk,
        everything else is passed whole.
    outputs : dict name -> ndarray
        Preallocated results, first axis ``n``; chunk ``a:b`` is written to ``[a:b]``.
    client : dask.distributed.Client, optional
        Run the chunks as tasks on this cluster (retried if a worker is lost). Each task's key
        holds the computation's fingerprint, the chunk's bounds and a nonce of this call, and
        its result comes back with that tag: a result of another computation is refused
        (``RuntimeError``), never placed.
    store : ChunkStore, optional
        Load finished chunks from it and save new ones to it. A stored chunk that cannot be
        read back whole is discarded, reported through ``store.message`` ("discarded damaged
        chunk cells-...; recomputing") and computed again. The store's lock is taken for the
        run (if :meth:`ChunkStore.close` gave it back) and released when this function
        returns or raises.
    progress : bool or callable
        Report progress on stderr (a tqdm bar on a terminal, else plain lines at most every
        5 s and the last, described by ``label``); or call ``progress(done, total)`` with the cells finished, once before the first chunk
        and after each; an exception it raises stops the run between two chunks.
    label : str
        What the progress counts, its description: the grid, the law and the fixed forcing
        (:func:`rockjit.grids.plan.progress_label`).
    message : callable, optional
        ``message(text)`` for the wait for Dask workers (default: the store's, else a line on
        stderr).
    worker_timeout : float, optional
        Seconds to wait, with a client, for the scheduler to have a worker, at the start or
        after losing them all, before raising :class:`NoWorkers` (default
        :data:`WORKER_TIMEOUT`, or the value :func:`worker_timeout` set).
    at_once : int
        In this process, how many calls of ``runner`` run at once, each in a thread of its own
        (``runner`` must release the GIL to gain from it, as numba's kernels do); default one
        call per chunk, one at a time, in the calling thread. With more than one, ``runner`` is
        called on pieces of the chunks (:func:`pieces`; a chunk's outputs are the concatenation
        of its pieces', so every output must have the cells on its first axis), and each chunk
        is placed once all its pieces are done. When a call, the progress callback or an
        interrupt raises, no call starts any more; the calls already running are waited for
        (and their finished chunks kept in the store) before the exception propagates.
    ahead : bool
        In this process, with one call at a time: call ``runner`` in a thread of its own, on
        whole chunks, and start the next chunk's call before the chunk just finished is placed,
        stored and reported. For a device that computes on its own (the GPU): it runs the next
        chunk while the host copies and saves the last. Errors as with ``at_once``.
    """
    if message is None and store is not None:
        message = store.message
    if store is not None:
        store.acquire()
    try:
        return _run_chunks(runner, inputs, n, chunk, outputs, client, store, progress, label,
                           task_prefix, message, _timeout(worker_timeout),
                           max(1, int(at_once)), bool(ahead))
    finally:
        if store is not None:
            store.close()


def _run_chunks(runner, inputs, n, chunk, outputs, client, store, progress, label,
                task_prefix, message, timeout, at_once=1, ahead=False):
    bounds = [(a, min(n, a + chunk)) for a in range(0, n, chunk)]
    todo = []
    for a, b in bounds:
        if store is not None and store.has(a, b):
            try:
                loaded = store.load(a, b, like=outputs)
            except DamagedChunk as exc:
                store.discard(a, b)
                store.message(f"discarded damaged chunk {exc.name} ({exc.reason}); "
                              f"recomputing")
                todo.append((a, b))
                continue
            for k, v in loaded.items():
                outputs[k][a:b] = v
        else:
            todo.append((a, b))
    done = n - sum(b - a for a, b in todo)
    if callable(progress):
        bar = _Callback(n, progress, done)
    else:
        bar = _Progress(n, label, progress, done=done)

    def args(a, b):
        return tuple(x[a:b] if isinstance(x, np.ndarray) and x.ndim and x.shape[0] == n else x
                     for x in inputs)

    def place(a, b, out):
        if store is not None:
            store.save(a, b, out)
        for k, v in out.items():
            outputs[k][a:b] = v
        bar.update(b - a)

    try:
        if client is None and at_once == 1 and not ahead:
            for a, b in todo:
                place(a, b, runner(*args(a, b)))
        elif client is None:
            _at_once(runner, todo, args, place, store, at_once, whole=ahead)
        elif todo:
            _on_dask(client, runner, inputs, n, chunk, todo, args, place, task_prefix, message,
                     timeout)
    finally:
        bar.close()
    return outputs


def _at_once(runner, todo, args, place, store, at_once, whole=False):
    """The chunks ``todo`` in this process, ``at_once`` calls running at a time, each in a
    thread of its own, on the chunks' :func:`pieces` (``whole``: on the chunks themselves);
    each chunk placed once all its pieces are done, after the next call has started (see
    :func:`run_chunks`)."""
    work = ((a, b, k) for k, (a, b) in enumerate(todo)) if whole else pieces(todo, at_once)
    parts = [{} for _ in todo]  # per chunk: its finished pieces' outputs by their start
    left = [b - a for a, b in todo]  # per chunk: cells not yet finished
    pending = {}

    def whole(k):
        got = parts[k]
        if len(got) == 1:
            return next(iter(got.values()))
        starts = sorted(got)
        return {name: np.concatenate([got[a][name] for a in starts]) for name in got[starts[0]]}

    with cf.ThreadPoolExecutor(max_workers=at_once, thread_name_prefix="rockjit-cells") as pool:
        def start(n_more):
            for a, b, k in itertools.islice(work, n_more):
                pending[pool.submit(runner, *args(a, b))] = (a, b, k)

        def finish(fut):
            a, b, k = pending.pop(fut)
            parts[k][a] = fut.result()
            left[k] -= b - a
            return k

        try:
            start(at_once)
            while pending:
                done, _ = cf.wait(pending, return_when=cf.FIRST_COMPLETED)
                for fut in sorted(done, key=pending.get):
                    k = finish(fut)
                    start(1)  # the next call starts before this chunk is placed and saved
                    if not left[k]:
                        out, parts[k] = whole(k), None
                        place(*todo[k], out)
        finally:
            # after an error nothing new starts; what runs finishes, and the chunks it
            # completes are kept if stored
            for fut in list(pending):
                if fut.cancel():
                    del pending[fut]
            for fut in list(pending):
                try:
                    k = finish(fut)
                except BaseException:  # noqa: BLE001 - the first error is the one raised
                    continue
                if not left[k] and store is not None:
                    store.save(*todo[k], whole(k))


def _on_dask(client, runner, inputs, n, chunk, todo, args, place, task_prefix, message,
             timeout):
    """The chunks ``todo`` as tasks on ``client``, each placed as it arrives (see
    :func:`run_chunks`)."""
    from dask.distributed import wait

    wait_for_workers(client, timeout, message)
    fp = _fingerprint(runner, inputs, n, chunk)
    nonce = secrets.token_hex(4)
    pending = {}
    for a, b in todo:
        tag = f"{fp}:{a}:{b}"
        fut = client.submit(_tagged, runner, tag, *args(a, b), retries=3, pure=False,
                            key=f"{task_prefix}-{fp[:16]}-{nonce}-{a}-{b}")
        pending[fut] = (a, b, tag)
    try:
        while pending:
            try:
                done = wait(list(pending), timeout=POLL, return_when="FIRST_COMPLETED").done
            except (TimeoutError, asyncio.TimeoutError):
                if not _n_workers(client):
                    wait_for_workers(client, timeout, message, lost=True)
                continue
            for fut in done:
                a, b, tag = pending.pop(fut)
                result = fut.result()
                if not (isinstance(result, tuple) and len(result) == 2 and result[0] == tag):
                    raise RuntimeError(f"the Dask task {fut.key} returned a result that is not "
                                       f"its chunk's (another computation's?); nothing of it "
                                       f"was used")
                place(a, b, result[1])
    finally:
        if pending:
            client.cancel(list(pending))
