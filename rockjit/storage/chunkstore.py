"""The store of finished grid chunks: resumable grid computations, one run at a time.

A grid (the cells of a sweep, a basin, a parameter plane, a spectrum) is cut into chunks of
consecutive cells (:mod:`rockjit.grids.runner`). With a store directory (:class:`ChunkStore`),
every finished chunk is written there atomically (:func:`rockjit.storage.atomic.atomic_open`,
with the user's umask) beside a manifest holding a fingerprint of the whole computation (inputs,
settings, chunking, rockjit's version). Running the same computation again with the same
directory loads the finished chunks and computes only the missing ones, so an interrupted run,
or one that lost workers, resumes; the result equals an uninterrupted run's bit for bit, because
each cell is computed independently of the chunking and of where it runs. A directory that holds
another computation's chunks is refused rather than mixed in. A chunk that cannot be read back
whole (truncated, not a zip archive, arrays missing or of the wrong shape or type) is discarded
and computed again, and the run says so.

A store is used by one run at a time: a lock file (``lock.json``: the owner's pid and host, and
where the system tells them, that process's start time and the boot id) makes a second run on
the same store refuse with a ``ValueError`` naming the owner while it is alive, and saying how
to take the store over when it is not. A lock is stale, taken over (and the run says so), when
its process no longer exists on this host, or when its pid now belongs to another process: one
that started at another time, or that runs under another boot (pids are reused after a reboot,
and from one container's life to the next). A lock without a start time (rockjit 0.1.0's) is
stale when its pid's process started after the lock was written.
:func:`rockjit.grids.runner.run_chunks` releases the lock when it returns or raises;
:func:`remove_stores` deletes a store only when it can hold the lock, and only the files rockjit
wrote there.
"""

from __future__ import annotations

import contextlib
import dataclasses
import errno
import hashlib
import json
import os
import re
import secrets
import shutil
import sys
import time
import weakref
from pathlib import Path

import numpy as np

from .atomic import atomic_open, create_temp, write_text
from .processes import boot_id, host_name, pid_alive, process_start, process_start_time

__all__ = ["ChunkStore", "DamagedChunk", "fingerprint", "fingerprint_of", "remove_stores"]


def fingerprint(arrays, settings):
    """SHA-256 over the arrays' bytes (with dtype and shape) and the settings as JSON."""
    from .. import __version__

    h = hashlib.sha256()
    for a in arrays:
        a = np.ascontiguousarray(a)
        h.update(f"{a.dtype.str}{a.shape}".encode())
        h.update(a.tobytes())
    h.update(json.dumps(settings, sort_keys=True, default=str).encode())
    h.update(__version__.encode())
    return h.hexdigest()


def fingerprint_of(*objects):
    """:func:`fingerprint` of ``objects``: dataclasses by their type and fields, arrays by their
    bytes, floats exactly (``repr``), containers item by item."""
    arrays = []

    def canonical(obj):
        if isinstance(obj, np.ndarray):
            arrays.append(obj)
            return f"<array {len(arrays) - 1}>"
        if dataclasses.is_dataclass(obj) and not isinstance(obj, type):
            return {"type": f"{type(obj).__module__}.{type(obj).__qualname__}",
                    **{f.name: canonical(getattr(obj, f.name))
                       for f in dataclasses.fields(obj)}}
        if isinstance(obj, (list, tuple)):
            return [canonical(x) for x in obj]
        if isinstance(obj, dict):
            return {str(k): canonical(obj[k]) for k in sorted(obj, key=str)}
        if isinstance(obj, np.generic):
            obj = obj.item()
        if isinstance(obj, float):
            return repr(obj)
        if obj is None or isinstance(obj, (bool, int, str)):
            return obj
        return repr(obj)

    settings = canonical(list(objects))
    return fingerprint(arrays, settings)


class DamagedChunk(ValueError):
    """A stored chunk that cannot be read back whole.

    Attributes
    ----------
    name : str
        The chunk's file name (``cells-<start>-<end>.npz``).
    reason : str
        What is wrong with it, in one line.
    """

    def __init__(self, name, reason):
        self.name = name
        self.reason = " ".join(str(reason).split())
        super().__init__(f"damaged chunk {name}: {self.reason}")


def _say(msg):
    print(f"rockjit: {msg}", file=sys.stderr, flush=True)


# ---- the store's lock --------------------------------------------------------------------------

LOCK = "lock.json"
_HELD = {}  # absolute lock path -> token, for the locks this process holds
_CHUNK = re.compile(r"cells-(\d{10})-(\d{10})\.npz")
_OWN_TEMP = re.compile(r"\.(cells-\d{10}-\d{10}\.npz|manifest\.json)\..+\.tmp"
                       r"|\.tmp-.+\.(npz|json)")  # (the second: rockjit <= 0.1.0's names)
_LOCK_TEMP = re.compile(r"\.lock\.json\..+\.tmp")


@contextlib.contextmanager
def _guard(directory):
    """Serialise lock take-overs in ``directory`` among processes (``flock`` where available)."""
    try:
        import fcntl
        fd = os.open(directory, os.O_RDONLY)
    except (ImportError, OSError):
        yield
        return
    try:
        with contextlib.suppress(OSError):
            fcntl.flock(fd, fcntl.LOCK_EX)
        yield
    finally:
        os.close(fd)


def _read_lock(path):
    """The lock's ``{"pid", "host", "token"}``; ``None`` if absent, ``False`` if unreadable."""
    try:
        info = json.loads(Path(path).read_text(encoding="utf-8"))
    except FileNotFoundError:
        return None
    except (OSError, ValueError):
        return False
    if (not isinstance(info, dict) or not isinstance(info.get("pid"), int)
            or not isinstance(info.get("host"), str)):
        return False
    return info


def _release(path, token):
    with _guard(Path(path).parent):
        have = _read_lock(path)
        if have and have.get("token") == token:
            Path(path).unlink(missing_ok=True)
    if _HELD.get(str(path)) == token:
        del _HELD[str(path)]


class _Lock:
    """``<directory>/lock.json``: which process (pid, host) uses a store."""

    def __init__(self, directory, message):
        self.dir = Path(directory)
        self.path = Path(os.path.abspath(self.dir / LOCK))
        self.message = message
        self.token = None
        self._finalizer = None

    @property
    def held(self):
        return self.token is not None and _HELD.get(str(self.path)) == self.token

    def _create(self, data):
        fd, tmp = create_temp(self.dir, f".{LOCK}.")
        try:
            with os.fdopen(fd, "wb") as fh:
                fh.write(data)
                fh.flush()
                os.fsync(fh.fileno())
            try:
                os.link(tmp, self.path)  # atomic: the lock appears complete or not at all
                return True
            except FileExistsError:
                return False
            except OSError as exc:
                if exc.errno not in (errno.EPERM, errno.ENOTSUP, errno.EOPNOTSUPP,
                                     errno.ENOSYS, errno.EMLINK, errno.EXDEV):
                    raise
            try:  # no hard links on this file system: exclusive create
                fd = os.open(self.path, os.O_WRONLY | os.O_CREAT | os.O_EXCL, 0o666)
            except FileExistsError:
                return False
            with os.fdopen(fd, "wb") as fh:
                fh.write(data)
                fh.flush()
                os.fsync(fh.fileno())
            return True
        finally:
            tmp.unlink(missing_ok=True)

    def acquire(self):
        """Take the lock, or raise ``ValueError`` naming the live owner."""
        if self.held:
            return
        token = secrets.token_hex(8)
        me, host = os.getpid(), host_name()
        data = json.dumps(dict(pid=me, host=host, token=token, start=process_start(me),
                               boot=boot_id(),
                               since=time.strftime("%Y-%m-%dT%H:%M:%S%z"))).encode()
        for attempt in range(100):
            if self._create(data):
                self.token = token
                _HELD[str(self.path)] = token
                self._finalizer = weakref.finalize(self, _release, self.path, token)
                return
            have = _read_lock(self.path)
            if have is None:  # released meanwhile
                continue
            if have is False:  # being written without hard links, or damaged
                if attempt < 20:
                    time.sleep(0.05)
                    continue
                raise ValueError(f"{self.dir} has an unreadable lock file; if no other rockjit "
                                 f"run is using it, delete {self.path}")
            pid, owner = have["pid"], have["host"]
            since = f", since {have['since']}" if isinstance(have.get("since"), str) else ""
            if owner != host:
                raise ValueError(f"{self.dir} is in use by a rockjit run on host {owner} "
                                 f"(pid {pid}{since}); wait for it to finish, or, if no rockjit "
                                 f"run is using it any more, delete {self.path}")
            if pid == me and have.get("token") == _HELD.get(str(self.path)):
                raise ValueError(f"{self.dir} is in use by another run in this process "
                                 f"(pid {pid}); one run at a time per store")
            why = "which is no longer running" if pid == me else self._stale(have)
            if why is None:
                raise ValueError(f"{self.dir} is in use by another rockjit run (pid {pid} on "
                                 f"{owner}{since}); wait for it to finish, or use another "
                                 f"output directory; if no rockjit run is using it (pid {pid} "
                                 f"is another program), delete {self.path}")
            with _guard(self.dir):  # its owner is gone: take it over, unless another run did
                if _read_lock(self.path) == have:
                    self.path.unlink(missing_ok=True)
                    self.message(f"took over the chunk store {self.dir} from pid {pid} on "
                                 f"{owner}, {why}")
        raise ValueError(f"{self.dir}: could not take the lock {self.path}")

    def _stale(self, have):
        """Why the lock ``have``, of a process on this host, is stale, or ``None`` when its
        owner may still be running (see the module docstring)."""
        pid = have["pid"]
        if not pid_alive(pid):
            return "which is no longer running"
        boot, now = have.get("boot"), boot_id()
        if isinstance(boot, str) and now is not None and boot != now:
            return (f"which ran before this machine restarted (pid {pid} is now another "
                    f"process)")
        start, now = have.get("start"), process_start(pid)
        if isinstance(start, int) and not isinstance(start, bool) and now is not None:
            return None if now == start else (f"which is no longer running (pid {pid} is now "
                                              f"another process, started later)")
        if start is None:  # a lock without a start time: compare with when it was written
            started = process_start_time(pid)
            try:
                written = os.stat(self.path).st_mtime
            except OSError:
                return None
            if started is not None and started > written + 1.0:
                return (f"which is no longer running (pid {pid} is now another process, "
                        f"started after the lock was written)")
        return None

    def release(self):
        """Give the lock back (removes the lock file if it is still this run's)."""
        if self._finalizer is not None:
            self._finalizer()  # _release(path, token), once
            self._finalizer = None
        self.token = None


# ---- the store ---------------------------------------------------------------------------------

class ChunkStore:
    """Finished chunks of one computation in a directory (see the module docstring).

    Opening a store takes its lock (``ValueError`` if another live run holds it), removes the
    temporary files of runs that were killed while writing, and checks or writes the manifest.

    Parameters
    ----------
    directory : str or Path
        The store; created (with its parents) if absent. An existing plain file is refused.
    key : str
        The computation's :func:`fingerprint`.
    n, chunk : int
        The number of cells and the chunk length.
    message : callable, optional
        ``message(text)`` for what the store has to say (a taken-over lock, a discarded chunk);
        default: a line ``rockjit: <text>`` on stderr.
    """

    MANIFEST = "manifest.json"
    LOCK = LOCK

    def __init__(self, directory, key, n, chunk, *, message=None):
        self.dir = Path(directory)
        self.key = key
        self.n = int(n)
        self.chunk = int(chunk)
        self.message = _say if message is None else message
        if os.path.lexists(self.dir) and not self.dir.is_dir():
            raise ValueError(f"store must be a directory (got {self.dir}, an existing file)")
        try:
            self.dir.mkdir(parents=True, exist_ok=True)
        except OSError as exc:
            raise ValueError(f"store {self.dir} cannot be created "
                             f"({exc.strerror or exc})") from None
        self._lock = _Lock(self.dir, self.message)
        try:
            self._lock.acquire()
        except OSError as exc:
            raise ValueError(f"store {self.dir} cannot be written "
                             f"({exc.strerror or exc})") from None
        try:
            self._remove_temporaries()
            self._check_manifest()
        except BaseException:
            self._lock.release()
            raise

    @classmethod
    def _read_manifest(cls, directory):
        """The manifest of the store in ``directory`` (``{"key", "n", "chunk"}``), or ``None``
        where it is absent, unreadable or not a JSON object."""
        try:
            have = json.loads((Path(directory) / cls.MANIFEST).read_text(encoding="utf-8"))
        except (OSError, ValueError):
            return None
        return have if isinstance(have, dict) else None

    @classmethod
    def stored_chunk(cls, directory, key, n):
        """The chunk length of the store in ``directory`` if its manifest is that of the
        computation ``key`` on ``n`` cells, else ``None`` (no store, another computation, an
        unreadable manifest). Read without opening the store (its lock is not taken).

        A rerun that gives no chunk uses it: the first run may have been given a chunk other
        than the default, and the store refuses any other chunk as another computation."""
        have = cls._read_manifest(directory)
        if have is None or have.get("key") != key or have.get("n") != n:
            return None
        chunk = have.get("chunk")
        return chunk if type(chunk) is int and chunk >= 1 else None

    def _check_manifest(self):
        man = self.dir / self.MANIFEST
        want = {"key": self.key, "n": self.n, "chunk": self.chunk}
        if man.exists():
            have = self._read_manifest(self.dir)
            if have != want:
                raise ValueError(
                    f"{self.dir} holds the chunks of a different computation (other inputs or "
                    f"settings); use another output directory or delete {self.dir}")
        elif any(_CHUNK.fullmatch(p.name) for p in self.dir.iterdir()):
            raise ValueError(f"{self.dir} holds chunks without a manifest (of a different "
                             f"computation?); use another output directory or delete {self.dir}")
        else:
            write_text(man, json.dumps(want))

    def _remove_temporaries(self):
        now = time.time()
        for p in self.dir.iterdir():
            if _OWN_TEMP.fullmatch(p.name):
                _remove(p)
            elif _LOCK_TEMP.fullmatch(p.name):  # another run's, while it takes a lock
                with contextlib.suppress(OSError):
                    if now - p.stat().st_mtime > 60:
                        p.unlink(missing_ok=True)

    # -- the lock -------------------------------------------------------------------------------

    @property
    def locked(self):
        """Whether this store holds its directory's lock."""
        return self._lock.held

    def acquire(self):
        """Take the lock again after :meth:`close` (``ValueError`` if another run holds it)."""
        self._lock.acquire()

    def close(self):
        """Release the lock (the chunks stay for a later run)."""
        self._lock.release()

    def __enter__(self):
        return self

    def __exit__(self, *exc):
        self.close()
        return False

    def cleanup(self):
        """Delete the store (see :func:`remove_stores`); returns whether the directory is gone."""
        return remove_stores(self.dir, message=self.message, _lock=self._lock)

    # -- chunks ---------------------------------------------------------------------------------

    def _path(self, a, b):
        return self.dir / f"cells-{a:010d}-{b:010d}.npz"

    def has(self, a, b):
        return self._path(a, b).exists()

    def load(self, a, b, like=None):
        """Chunk ``a:b``'s arrays by name.

        Parameters
        ----------
        like : dict name -> ndarray, optional
            The full output arrays: the chunk must hold exactly these names, each of shape
            ``(b - a,) + like[name].shape[1:]`` and of the same dtype.

        Raises
        ------
        DamagedChunk
            If the file cannot be read whole (truncated, not an ``.npz``, a bad checksum) or
            does not match ``like``.
        """
        path = self._path(a, b)
        try:
            with open(path, "rb") as fh:
                if fh.read(4) != b"PK\x03\x04":
                    raise DamagedChunk(path.name, "not an .npz archive")
        except OSError as exc:
            raise DamagedChunk(path.name, f"{type(exc).__name__}: {exc}") from None
        try:
            with np.load(path, allow_pickle=False) as z:
                out = {k: z[k] for k in z.files}
        except Exception as exc:  # any way a damaged file fails to read
            raise DamagedChunk(path.name, f"{type(exc).__name__}: {exc}") from None
        if like is not None:
            if set(out) != set(like):
                raise DamagedChunk(path.name, f"arrays {sorted(out)}, expected {sorted(like)}")
            for k, ref in like.items():
                want = (b - a,) + tuple(ref.shape[1:])
                if out[k].shape != want or out[k].dtype != ref.dtype:
                    raise DamagedChunk(path.name, f"array {k!r} is {out[k].dtype}{out[k].shape}"
                                                  f", expected {ref.dtype}{want}")
        return out

    def save(self, a, b, out):
        """Write chunk ``a:b`` atomically (:func:`rockjit.storage.atomic.atomic_open`)."""
        with atomic_open(self._path(a, b), "wb") as fh:
            np.savez(fh, **out)

    def discard(self, a, b):
        """Delete chunk ``a:b`` (a damaged one, before computing it again), whatever it is: a
        directory in its place is removed with its contents (the store is rockjit's own)."""
        _remove(self._path(a, b))


def _remove(path):
    """Remove ``path``: a file, a link, or a directory with its contents; absent is fine."""
    path = Path(path)
    if path.is_dir() and not path.is_symlink():
        shutil.rmtree(path)
    else:
        path.unlink(missing_ok=True)


def remove_stores(directory, *, message=None, _lock=None):
    """Delete a chunk store, or every store directly inside ``directory``, when not in use.

    A store (a directory holding ``manifest.json`` or ``lock.json``) is deleted only when this
    run holds its lock or can take it; a store in use by another live run is kept (and
    ``message`` says so). Only the files rockjit writes there (chunks, manifest, lock,
    temporary files) are deleted; a directory is removed only once it is empty, so a file of
    the user's keeps it and its parents.

    Parameters
    ----------
    directory : str or Path
        A store, or a folder of stores (the command line's ``<out>.chunks``).
    message : callable, optional
        As for :class:`ChunkStore`.

    Returns
    -------
    bool
        Whether ``directory`` is gone.
    """
    d = Path(directory)
    say = _say if message is None else message
    if not os.path.isdir(d) or os.path.islink(d):  # (os.path: False for a name too long)
        return not os.path.lexists(d)

    def is_store(p):
        return (p / ChunkStore.MANIFEST).is_file() or (p / LOCK).is_file()

    stores = [d] if is_store(d) else [p for p in sorted(d.iterdir())
                                      if p.is_dir() and not p.is_symlink() and is_store(p)]
    for s in stores:
        lock = _lock if _lock is not None and _lock.path == Path(os.path.abspath(s / LOCK)) \
            else _Lock(s, say)
        try:
            lock.acquire()
        except ValueError as exc:
            say(f"kept {s}: {exc}")
            continue
        try:
            for p in s.iterdir():
                if _CHUNK.fullmatch(p.name) or _OWN_TEMP.fullmatch(p.name) or \
                        p.name == ChunkStore.MANIFEST:
                    _remove(p)
        finally:
            lock.release()
        with contextlib.suppress(OSError):
            s.rmdir()
    if d not in stores:
        with contextlib.suppress(OSError):
            d.rmdir()
    return not os.path.lexists(d)
