"""Which files of an output directory rockjit wrote, and one command at a time publishing there.

**The record.** Every output directory rockjit publishes into holds ``.rockjit-files.json``,
rockjit's record of the files it wrote there: each file's name, size and SHA-256 digest, and a
token of the run that published last. A file is *rockjit's* when the record names it and its
bytes still have the recorded size and digest (and it is a regular file, not a link): a file of
the user's, or one the user has changed since, is never rockjit's, whatever its name. rockjit
replaces only its own files (:func:`unproven` finds the others before any work).

While files are moved into place one by one, the record is moved first, and it names for a file
being replaced both the new digest and the one it replaces, so that a run killed between two
moves leaves every file provably rockjit's, old or new.

A directory written before rockjit kept a record holds no ``.rockjit-files.json``: its files
cannot be told from the user's, and none of them is replaced.

**The lock.** A command holds :class:`PublishLock` from its checks, before any work, until its
outputs are published (or discarded): an advisory ``flock`` on a hidden file, ``.rockjit-lock``
inside the output directory when it exists, else ``.<name>.rockjit-lock`` beside the first part
of its path that does not exist yet (where it will be made). A second command publishing into the
same place is refused while the first holds it. The kernel releases the lock of a process that
dies, however it dies; the file left behind is reused by the next run and removed when it is
done. Where the system or the file system offers no ``flock``, only the check below holds.

As a second line of defence, a command compares the record's run token when it publishes with
the one it saw in its checks: a directory published into by another run meanwhile (which the
lock would only miss if the directory came into existence during the run) is refused, not
silently overwritten.
"""

from __future__ import annotations

import contextlib
import errno
import fnmatch
import hashlib
import json
import os
import secrets
import stat
import time
import weakref
from pathlib import Path

__all__ = ["LOCK", "RECORD", "PublishLock", "Record", "digest", "lock_path", "unproven"]

#: rockjit's record of the files it wrote into an output directory.
RECORD = ".rockjit-files.json"
#: The lock file inside an existing output directory.
LOCK = ".rockjit-lock"
#: The record's layout version.
FORMAT = 1
#: What the record says of itself (in ``summary.json``'s list of files).
RECORD_HOLDS = ("rockjit's record of the files it wrote into this directory (each one's name, "
                "size and SHA-256 digest): rockjit replaces no other file")
#: Figure formats rockjit writes (``--format``), and the other suffixes of its files.
FIGURE_SUFFIXES = ("png", "pdf", "svg")
DATA_SUFFIXES = ("npz", "csv", "md", "json", "html")


def digest(path):
    """``(size, SHA-256 hex digest)`` of the regular file ``path`` (a link is not followed);
    ``None`` when it is not a regular file or cannot be read."""
    flags = os.O_RDONLY | getattr(os, "O_NOFOLLOW", 0) | getattr(os, "O_CLOEXEC", 0)
    try:
        fd = os.open(path, flags | getattr(os, "O_NONBLOCK", 0))  # a FIFO must not block
    except OSError:
        return None
    try:
        if not stat.S_ISREG(os.fstat(fd).st_mode):
            return None
        h, size = hashlib.sha256(), 0
        while True:
            block = os.read(fd, 1 << 20)
            if not block:
                break
            h.update(block)
            size += len(block)
        return size, h.hexdigest()
    except OSError:
        return None
    finally:
        os.close(fd)


class Record:
    """rockjit's record of an output directory (see the module docstring).

    Attributes
    ----------
    state : {"absent", "none", "ok", "damaged"}
        The directory does not exist; it holds no record; the record was read; it could not be.
    files : dict
        ``name -> {"versions": [{"size": int, "sha256": hex}, ...]}``: the contents the file
        may have and be rockjit's (one, or two while it is being replaced).
    run : str or None
        The token of the run that published last.
    problem : str or None
        Why a damaged record could not be read.
    """

    def __init__(self, state, files=None, run=None, problem=None):
        self.state, self.files, self.run, self.problem = state, files or {}, run, problem

    @classmethod
    def read(cls, out):
        """The record of directory ``out``."""
        out = Path(out)
        if not os.path.isdir(out):
            return cls("absent")
        path = out / RECORD
        if not os.path.lexists(path):
            return cls("none")
        if os.path.islink(path) or not path.is_file():
            return cls("damaged", problem="it is not a plain file")
        try:
            data = json.loads(path.read_text(encoding="utf-8"))
        except (OSError, ValueError) as exc:
            return cls("damaged", problem=f"{type(exc).__name__}: {exc}")
        files = data.get("files") if isinstance(data, dict) else None
        ok = isinstance(files, dict) and data.get("format") == FORMAT and all(
            isinstance(e, dict) and isinstance(e.get("versions"), list)
            and all(isinstance(v, dict) and isinstance(v.get("size"), int)
                    and isinstance(v.get("sha256"), str) for v in e["versions"])
            for e in files.values())
        if not ok:
            return cls("damaged", problem="not a record of this layout")
        run = data.get("run") if isinstance(data.get("run"), str) else None
        return cls("ok", files, run)

    def proves(self, out, name, have=None):
        """Whether ``out/name`` is rockjit's: named here, with a recorded size and digest
        (``have``: its :func:`digest`, if known)."""
        entry = self.files.get(name)
        if entry is None:
            return False
        have = digest(Path(out) / name) if have is None else have
        return have is not None and any(have == (v["size"], v["sha256"])
                                        for v in entry["versions"])

    @staticmethod
    def write_data(files, command, version):
        """The JSON object of a record of ``files`` (``name -> entry``), with a new run token."""
        return {"format": FORMAT, "written_by": "rockjit", "rockjit_version": version,
                "command": command, "run": secrets.token_hex(8),
                "files": {n: files[n] for n in sorted(files)}}


def _matches(name, patterns, figure_format):
    """Whether ``name`` is one a command writing ``patterns`` (names or ``fnmatch``
    patterns) may write: a pattern ``stem.*`` stands for ``stem`` with a suffix rockjit writes,
    the figures' in ``figure_format`` (default ``png``)."""
    suffixes = DATA_SUFFIXES + ((figure_format or "png"),)
    for p in patterns:
        if p.endswith(".*"):
            stem = p[:-2]
            if any(fnmatch.fnmatchcase(name, f"{stem}.{s}") for s in suffixes):
                return True
        elif fnmatch.fnmatchcase(name, p):
            return True
    return False


def unproven(out, patterns, figure_format=None, record=None):
    """The files in directory ``out`` that a command writing ``patterns`` might replace and that
    are not provably rockjit's (:meth:`Record.proves`), in name order. Only names matching the
    patterns are looked at (and ``summary.json`` and the record always)."""
    out = Path(out)
    record = Record.read(out) if record is None else record
    if record.state == "absent":
        return []
    found = []
    with os.scandir(out) as entries:
        for e in entries:
            if e.name == RECORD or not _matches(e.name, ("summary.json",) + tuple(patterns),
                                                figure_format):
                continue
            if e.is_dir(follow_symlinks=False):
                continue  # refused on its own (a directory in the way)
            if not record.proves(out, e.name):
                found.append(e.name)
    return sorted(found)


def refusal(out, names, record, name="out"):
    """The one line that refuses to publish over ``names`` in ``out``."""
    shown = ", ".join(names[:5]) + (f" and {len(names) - 5} more" if len(names) > 5 else "")
    them = "it" if len(names) == 1 else "them"
    if record.state == "damaged":
        return (f"{name} {out}: rockjit's record of the files it wrote there ({RECORD}) cannot "
                f"be read ({record.problem}), so rockjit cannot tell its files ({shown}) from "
                f"yours and replaces none; choose an empty or new {name}")
    if record.state == "none":
        older = _older_version(out)
        whose = (f"which summary.json says rockjit {older} wrote, but without rockjit's "
                 f"record of its files ({RECORD}; older versions kept none)" if older
                 else f"and no record of rockjit's files ({RECORD})")
        return (f"{name} {out} holds {shown}, {whose}: rockjit cannot tell {them} from files "
                f"of yours and replaces none; choose an empty or new {name}, or move {them} "
                f"away")
    return (f"{name} {out} holds {shown}, which rockjit did not write (or which changed since "
            f"it wrote {them}) and does not replace; choose another {name}, or move {them} "
            f"away")


def _older_version(out):
    """The version of rockjit that ``out/summary.json`` says wrote it, or ``None``."""
    try:
        with open(Path(out) / "summary.json", encoding="utf-8") as fh:
            summary = json.loads(fh.read(1 << 20))
    except (OSError, ValueError):
        return None
    version = summary.get("rockjit_version") if isinstance(summary, dict) else None
    return " ".join(version.split())[:40] if isinstance(version, str) else None


# ---- the lock ----------------------------------------------------------------------------------

def _name_max(directory):
    """The longest file name (bytes) the file system of ``directory`` takes (255 if unknown)."""
    try:
        return int(os.pathconf(directory, "PC_NAME_MAX"))
    except (OSError, ValueError, AttributeError, TypeError):
        return 255


def _nearest(path):
    """``path`` (absolute) or its nearest ancestor that exists (as a link, file or directory)."""
    q = Path(path).absolute()
    while not os.path.lexists(q) and q != q.parent:
        q = q.parent
    return q


def lock_path(out):
    """Where the lock of a command publishing into ``out`` is (see the module docstring)."""
    out = Path(os.path.abspath(out))
    if os.path.isdir(out):
        return out / LOCK
    parent = _nearest(out.parent)
    first = parent / out.relative_to(parent).parts[0]  # the first part that does not exist
    name = f".{first.name}.rockjit-lock"
    if len(os.fsencode(name)) > _name_max(parent):
        name = f".{hashlib.sha256(os.fsencode(first.name)).hexdigest()[:16]}.rockjit-lock"
    return first.parent / name


def _release(path, fd):
    with contextlib.suppress(OSError):
        os.unlink(path)  # while holding it: a run waiting on this file sees it is gone
    with contextlib.suppress(OSError):
        os.close(fd)


class PublishLock:
    """The lock of a command publishing into ``out`` (see the module docstring).

    Parameters
    ----------
    out : str or Path
        The output directory.
    path : Path, optional
        The lock file (default :func:`lock_path`).
    name : str
        How messages name the directory (``"--out"`` on the command line).
    """

    def __init__(self, out, path=None, name="out"):
        self.out = Path(out)
        self.path = Path(lock_path(out) if path is None else path)
        self.name = name
        self._finalizer = None

    @property
    def held(self):
        return self._finalizer is not None and self._finalizer.alive

    def acquire(self):
        """Take the lock, or raise ``ValueError`` (one line) naming the run that holds it."""
        if self.held:
            return
        try:
            import fcntl
        except ImportError:  # no flock on this system: the publish-time check only
            fcntl = None
        data = json.dumps(dict(pid=os.getpid(), since=time.strftime("%Y-%m-%dT%H:%M:%S%z")))
        for _ in range(50):
            try:
                fd = os.open(self.path, os.O_RDWR | os.O_CREAT | getattr(os, "O_CLOEXEC", 0),
                             0o666)
            except OSError as exc:
                raise ValueError(f"{self.name} {self.out}: cannot make the lock {self.path} "
                                 f"({exc.strerror or exc})") from None
            if fcntl is not None:
                try:
                    fcntl.flock(fd, fcntl.LOCK_EX | fcntl.LOCK_NB)
                except OSError as exc:
                    if exc.errno in (errno.EWOULDBLOCK, errno.EAGAIN, errno.EACCES):
                        owner = _read_owner(fd)
                        os.close(fd)
                        self._refuse(owner)
                    # no flock on this file system: the publish-time check only
                try:  # the file locked must still be the lock (its last holder unlinks it)
                    same = os.path.samestat(os.fstat(fd), os.stat(self.path))
                except OSError:
                    same = False
                if not same:
                    os.close(fd)
                    continue
            with contextlib.suppress(OSError):
                os.ftruncate(fd, 0)
                os.pwrite(fd, data.encode(), 0)
            self._finalizer = weakref.finalize(self, _release, str(self.path), fd)
            return
        raise ValueError(f"{self.name} {self.out}: could not take the lock {self.path}")

    def _refuse(self, owner):
        who = f" (pid {owner['pid']}, since {owner['since']})" if owner else ""
        raise ValueError(f"{self.name} {self.out} is being written by another rockjit run"
                         f"{who}; wait for it to finish, or choose another {self.name}")

    def release(self):
        """Give the lock back and remove its file."""
        if self._finalizer is not None:
            self._finalizer()
            self._finalizer = None


def _read_owner(fd):
    try:
        owner = json.loads(os.pread(fd, 4096, 0).decode())
    except (OSError, ValueError, UnicodeDecodeError):
        return None
    if isinstance(owner, dict) and isinstance(owner.get("pid"), int) and \
            isinstance(owner.get("since"), str):
        return owner
    return None
