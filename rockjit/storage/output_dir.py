"""A command's output directory: its files staged in a hidden directory and published together.

A failure or an interrupt before :meth:`OutputDir.publish` leaves ``--out`` exactly as it was,
and files rockjit did not write are never deleted or replaced (:mod:`.ownership`). Each file is
written atomically (:mod:`.atomic`); what a dead run left behind is told from a live run's by
its host and process (:mod:`.processes`).
"""

from __future__ import annotations

import contextlib
import errno
import fnmatch
import hashlib
import json
import os
import secrets
import shutil
import signal
import threading
from pathlib import Path

from . import atomic  # its writers looked up at each call: a test may replace one
from .ownership import (RECORD, RECORD_HOLDS, PublishLock, Record, _name_max, _nearest, digest,
                        lock_path, refusal, unproven)
from .processes import host_name, pid_alive

__all__ = ["SUMMARY", "OutputDir", "check_out", "chunk_root", "defer_signals"]


@contextlib.contextmanager
def defer_signals(signums=(signal.SIGINT, signal.SIGTERM)):
    """Hold back ``signums`` for the duration of the block.

    Handlers that only record the signal stand in for the current ones, which are put back on
    exit. The recorded signals are not raised again: the caller decides what they mean.
    Outside the main thread, where Python cannot set handlers, nothing is deferred.

    Yields
    ------
    list of int
        The signals that arrived, in order (filled while the block runs).
    """
    got = []
    old = {}
    if threading.current_thread() is threading.main_thread():
        for s in signums:
            try:
                old[s] = signal.signal(s, lambda signum, frame: got.append(signum))
            except (ValueError, OSError):
                pass
    try:
        yield got
    finally:
        for s, h in old.items():
            signal.signal(s, signal.SIG_DFL if h is None else h)


_STAGE = "rockjit-stage"
SUMMARY = "summary.json"


def _mkdir_unique(parent, prefix):
    for _ in range(100):
        path = parent / f"{prefix}{secrets.token_hex(4)}"
        try:
            os.mkdir(path, 0o777)
        except FileExistsError:
            continue
        return path
    raise FileExistsError(errno.EEXIST, "no unused directory name", str(parent))


def _makedirs(path):
    """Create ``path`` and its missing parents (``0o777`` less the umask); the ones made."""
    missing = []
    p = Path(os.path.abspath(path))
    while not os.path.lexists(p):
        missing.append(p)
        p = p.parent
    made = []
    try:
        for d in reversed(missing):
            os.mkdir(d, 0o777)
            made.append(d)
    except BaseException:
        _rmdirs(made)
        raise
    return made


def _rmdirs(made):
    for d in reversed(made):
        try:
            os.rmdir(d)
        except OSError:
            break


def _remove_stale_stages(parent, prefix):
    """Remove staging directories ``<prefix><host>-<pid>-<random>`` of dead runs on this host."""
    host = host_name()
    try:
        entries = list(os.scandir(parent))
    except OSError:
        return
    for e in entries:
        if not e.name.startswith(prefix) or not e.is_dir(follow_symlinks=False):
            continue
        parts = e.name[len(prefix):].rsplit("-", 2)
        if len(parts) != 3 or parts[0] != host or not parts[1].isdigit():
            continue
        if not pid_alive(int(parts[1])):
            shutil.rmtree(e.path, ignore_errors=True)


def _check_name(name):
    if (not isinstance(name, str) or name in ("", ".", "..") or "/" in name or os.sep in name
            or (os.altsep and os.altsep in name) or name.startswith(".rockjit-")):
        raise ValueError(f"an output file name must be a plain file name (got {name!r})")
    return name


def chunk_root(out):
    """Where the unfinished chunks of the grids of a command writing ``out`` wait."""
    return Path(str(Path(out)) + ".chunks")


def _path_max(directory):
    """The longest path (bytes) the system takes (4096 if unknown)."""
    try:
        return int(os.pathconf(directory, "PC_PATH_MAX"))
    except (OSError, ValueError, AttributeError, TypeError):
        return 4096


def _link_problem(path):
    """Why the symbolic link ``path`` cannot be followed (it dangles, it loops), or ``None``."""
    try:
        os.stat(path)
        return None
    except OSError as exc:
        try:
            target = os.readlink(path)
        except OSError:
            target = "?"
        if exc.errno == errno.ELOOP:
            return f"a symbolic link in a loop ({path} -> {target})"
        if exc.errno in (errno.ENOENT, errno.ENOTDIR):
            return f"a symbolic link to {target}, which does not exist"
        return f"a symbolic link that cannot be followed ({exc.strerror or exc})"


def _short(text, keep=200):
    text = str(text)
    return text if len(text) <= keep else f"{text[:keep // 2 - 2]}...{text[-(keep // 2 - 2):]}"


def _probe(directory):
    """Make and remove a hidden directory in ``directory``: ``OSError`` if it cannot be written."""
    os.rmdir(_mkdir_unique(Path(directory), ".rockjit-probe-"))


#: Room kept, below the system's longest path, for the names rockjit adds inside ``--out`` and
#: ``<out>.chunks`` (a staging directory, a file, its temporary name).
PATH_ROOM = 256


def check_out(out, *, name="out", files=(), chunks=False):
    """Refuse, before any work, an output directory rockjit could not publish into.

    Raises ``ValueError`` naming ``name`` for: an empty name; a name too long for the file
    system (any of its parts, ``<out>.chunks`` when ``chunks``, or the whole path with room
    for what is written inside it); an existing file, or a symbolic link that dangles or loops
    (``--out`` itself or the part of it that exists); a place where no directory can be made or
    written (probed by making and removing a hidden one where the outputs will be staged:
    inside ``out`` if it exists, else in its nearest existing parent); a directory inside ``out``
    named like a file the command writes (``files``: names or ``fnmatch`` patterns;
    ``summary.json`` always); and, when the command keeps chunks (``chunks``), a
    ``<out>.chunks`` that is not a writable directory or holds a file where a chunk store would
    go (a name without a dot).
    """
    text = os.fspath(out)
    if not text.strip():
        raise ValueError(f"{name} must name a directory (got an empty string)")
    try:
        _check_out(Path(text), text, name, (SUMMARY,) + tuple(files), chunks)
    except OSError as exc:  # what the checks did not foresee, still before any work
        raise ValueError(f"{name} {_short(text)} cannot be used "
                         f"({exc.strerror or exc})") from None


def _check_out(p, out, name, files, chunks):
    absolute = p.absolute()
    q = _nearest(absolute)
    limit = _name_max(q if os.path.isdir(q) else q.parent)
    for part in absolute.parts:
        if len(os.fsencode(part)) > limit:
            raise ValueError(f"{name} {_short(out)}: the name {_short(part, 60)} is "
                             f"{len(os.fsencode(part))} bytes long; at most {limit} fit on "
                             f"this file system")
    if chunks and len(os.fsencode(absolute.name + ".chunks")) > limit:
        raise ValueError(f"{name}'s last name {_short(absolute.name, 60)} is "
                         f"{len(os.fsencode(absolute.name))} bytes long: this command keeps "
                         f"its unfinished chunks beside it in <name>.chunks, and at most "
                         f"{limit} bytes fit, so {name}'s last name can have at most "
                         f"{limit - len('.chunks')}")
    room = _path_max(q if os.path.isdir(q) else q.parent) - PATH_ROOM
    if len(os.fsencode(str(absolute))) > room:
        raise ValueError(f"{name} {_short(out)} is {len(os.fsencode(str(absolute)))} bytes "
                         f"long as an absolute path; at most {room} leave room for the files "
                         f"written inside it")
    if q != absolute:  # --out is made inside q
        if os.path.islink(q) and _link_problem(q):
            raise ValueError(f"{name} {_short(out)} cannot be created: {q} is "
                             f"{_link_problem(q)}")
        if not os.path.isdir(q):
            raise ValueError(f"{name} {_short(out)} cannot be created: {q} is a file, not a "
                             f"directory")
        stage = q
    else:
        if os.path.islink(p) and _link_problem(p):
            raise ValueError(f"{name} {_short(out)} is {_link_problem(p)}; remove the link "
                             f"or choose another {name}")
        if not os.path.isdir(p):
            raise ValueError(f"{name} must be a directory (got {_short(out)}, an existing "
                             f"file)")
        stage = p
        with os.scandir(p) as entries:
            for e in entries:
                if any(fnmatch.fnmatchcase(e.name, f) for f in files) and \
                        e.is_dir(follow_symlinks=False):
                    raise ValueError(f"{name} {_short(out)} holds a directory {e.name} where "
                                     f"this command writes a file of that name; move it "
                                     f"away or choose another {name}")
    try:
        _probe(stage)
    except OSError as exc:
        raise ValueError(f"{name} {_short(out)} cannot be created or written "
                         f"({exc.strerror or exc})") from None
    if chunks:
        _check_chunk_root(out, name)


def _check_chunk_root(out, name):
    c = chunk_root(out)
    where = f"{_short(c)} (where {name}'s unfinished chunks wait)"
    if os.path.lexists(c):
        if os.path.islink(c) and _link_problem(c):
            raise ValueError(f"{where} is {_link_problem(c)}; remove it or choose another "
                             f"{name}")
        if not os.path.isdir(c):
            raise ValueError(f"{where} exists and is not a directory; move it away or choose "
                             f"another {name}")
        with os.scandir(c) as entries:
            for e in entries:  # rockjit's stores there: directories, named without a dot
                if "." not in e.name and not e.is_dir():
                    raise ValueError(f"{_short(c / e.name)}, where {name}'s unfinished "
                                     f"chunks of a grid wait, is not a directory; move it "
                                     f"away or choose another {name}")
        at = c
    else:
        at = _nearest(c.absolute().parent)
        if not os.path.isdir(at):
            return  # made with --out (checked above)
    try:
        _probe(at)
    except OSError as exc:
        raise ValueError(f"{where} cannot be created or written ({exc.strerror or exc})") \
            from None


def _sibling_prefix(out):
    """The names of ``out``'s staging directories beside it: ``.<name>.rockjit-stage-``, or
    ``.<hash of the name>.rockjit-stage-`` where the name is too long for the file system to
    take ``<host>-<pid>-<random>`` after it."""
    if not out.name:
        return None
    prefix = f".{out.name}.{_STAGE}-"
    longest = len(os.fsencode(prefix + host_name())) + len("-4294967296-") + 8
    if longest > _name_max(_nearest(out.parent)):
        digest = hashlib.sha256(os.fsencode(out.name)).hexdigest()[:16]
        prefix = f".{digest}.{_STAGE}-"
    return prefix


class OutputDir:
    """The files of one command, staged in a hidden directory and published together.

    Files are written (each atomically, with the user's umask) into a staging directory on the
    same file system as ``path``: a hidden sibling ``.<name>.rockjit-stage-<host>-<pid>-<random>``
    when ``path`` does not exist yet, a hidden ``.rockjit-stage-<host>-<pid>-<random>`` inside it
    when it does (so the moves stay on its file system even when it is a mount point, and its
    parent need not be writable). :meth:`publish` then moves them into place:

    - ``path`` absent: one atomic :func:`os.rename` of the staging directory to ``path``;
    - ``path`` present: each file :func:`os.replace`\\ d over its namesake, ``summary.json``
      last.

    SIGINT and SIGTERM are deferred (``defer_signals``) for these few moves, so an
    interrupt cannot split the set. A signal that arrived is recorded in ``interrupted``,
    not raised: the outputs are published and the run can report success.

    On any failure or interrupt before :meth:`publish`, :meth:`discard` (called by the ``with``
    statement) removes the staging directory and any parent directories it made, and ``path``
    is exactly as before. Staging directories of runs that died (their pid no longer exists on
    this host) are removed when the next run on the same ``path`` starts writing.

    Only rockjit's own files are ever replaced (``rockjit.storage.ownership``): ``path``
    holds rockjit's record of the files it wrote there (``.rockjit-files.json``, published
    with the outputs and listed in ``written``), and a file the record does not prove
    rockjit's (the user's, one changed since, one of a directory written before rockjit kept
    a record) is never replaced: :meth:`claim` refuses it before any work, and
    :meth:`publish` refuses the whole set (``ValueError``, nothing published) rather than
    replace it. One command at a time: :meth:`claim` (or the first write) takes the lock of
    ``path`` (``rockjit.storage.ownership.PublishLock``), held until :meth:`publish`
    or :meth:`discard`; a second :class:`OutputDir` on the same ``path`` is refused while it
    is held, and :meth:`publish` refuses if another run published into ``path`` meanwhile.

    Parameters
    ----------
    path : str or Path
        The output directory (``--out``).
    command : str, optional
        The command writing it, for :meth:`stale_warning`; by default the ``"command"`` of the
        ``summary.json`` this run stages.

    Attributes
    ----------
    path : Path
    written : list of str
        The names written so far, in order.
    published : bool
        Whether :meth:`publish` has completed.
    interrupted : int or None
        The signal (``signal.SIGINT``, ``signal.SIGTERM``) that arrived during :meth:`publish`,
        if one did.
    warning : str or None
        :meth:`stale_warning` as it stood when :meth:`publish` began (what it returned).
    figure_errors : list of dict
        ``{"name", "error"}`` of each figure that could not be drawn (:meth:`figure_failed`).

    Examples
    --------
    The command line's use: stage the files, publish them together (or discard them all on
    any failure), and report a note about files of an earlier run that stay:

    >>> import tempfile
    >>> from pathlib import Path
    >>> import numpy as np
    >>> from rockjit.storage.output_dir import OutputDir
    >>> out = OutputDir(Path(tempfile.mkdtemp()) / "basin")
    >>> try:
    ...     out.npz("basin.npz", label=np.zeros((2, 2), dtype=int))
    ...     out.json("summary.json", {"command": "basin",
    ...                               "files": out.written + ["summary.json"]})
    ...     note = out.publish()
    ... except BaseException:
    ...     out.discard()
    ...     raise
    >>> sorted(p.name for p in out.path.iterdir()), note is None
    (['.rockjit-files.json', 'basin.npz', 'summary.json'], True)
    """

    def __init__(self, path, command=None):
        if not os.fspath(path):
            raise ValueError("out must name a directory (got '')")
        self.path = Path(path)
        self.command = command
        self.written = []
        #: What each file holds, in words (:meth:`describe`), for the summary's manifest.
        self.holds = {}
        #: Figures' format (``png``, ``pdf``, ``svg``: the suffix of their names is replaced)
        #: and resolution; ``None`` keeps each name's suffix.
        self.figure_format = None
        self.dpi = 150
        self.published = False
        self.interrupted = None
        self.warning = None
        self.figure_errors = []
        self.name = "out"
        self._stage = None
        self._inside = False
        self._made = []
        self._lock = None
        self._seen = None

    # -- the claim ------------------------------------------------------------------------------

    def claim(self, files=None, figure_format=None, name="out"):
        """Take ``path`` for this command, before any work: its lock, and the record's state.

        Raises ``ValueError`` (one line naming ``name``) when another run holds the lock, when
        rockjit's record there cannot be read, or, given ``files`` (the names or ``fnmatch``
        patterns the command writes; ``stem.*`` stands for its data and figures in
        ``figure_format``), when ``path`` holds a file of those names that is not provably
        rockjit's. Called by the first write if not before; released by :meth:`publish` and
        :meth:`discard`.
        """
        if self._lock is not None:
            return
        self.name = name
        lock = PublishLock(self.path, name=name)
        lock.acquire()
        try:
            rec = Record.read(self.path)
            theirs = []
            if files is not None and rec.state != "damaged":
                theirs = unproven(self.path, files, figure_format or self.figure_format, rec)
            if theirs or rec.state == "damaged":
                raise ValueError(refusal(self.path, theirs, rec, name))
        except BaseException:
            lock.release()
            raise
        self._seen = rec.run if rec.state == "ok" else None
        self._lock = lock

    def _unlock(self, also=None):
        for lock in (self._lock, also):
            if lock is not None:
                lock.release()
        self._lock = None

    # -- staging --------------------------------------------------------------------------------

    @property
    def staging(self):
        """The staging directory (``None`` before the first write, after :meth:`publish` and
        after :meth:`discard`)."""
        return self._stage

    def _stage_dir(self):
        if self.published:
            raise RuntimeError(f"{self.path} was already published")
        if self._stage is not None:
            return self._stage
        out = self.path
        if os.path.lexists(out) and not out.is_dir():
            raise ValueError(f"out must be a directory (got {out}, an existing file)")
        claimed = self._lock is None
        self.claim()
        try:
            stage = self._make_stage()
        except BaseException:
            if claimed:
                self._unlock()
            raise
        self._add(RECORD)  # written at publish
        self.holds.setdefault(RECORD, RECORD_HOLDS)
        return stage

    def _make_stage(self):
        out = self.path
        host, pid = host_name(), os.getpid()
        sibling = _sibling_prefix(out)
        if os.path.lexists(out):
            _remove_stale_stages(out, f".{_STAGE}-")
            if sibling:
                _remove_stale_stages(out.parent, sibling)
            self._inside = True
            self._stage = _mkdir_unique(out, f".{_STAGE}-{host}-{pid}-")
            return self._stage
        try:
            self._made = _makedirs(out.parent)
        except OSError as exc:
            raise ValueError(f"out {out} cannot be created ({exc.strerror or exc})") from None
        try:
            _remove_stale_stages(out.parent, sibling)
            self._inside = False
            self._stage = _mkdir_unique(out.parent, f"{sibling}{host}-{pid}-")
        except BaseException:
            _rmdirs(self._made)
            self._made = []
            raise
        return self._stage

    def file(self, name):
        """The staged path of ``name``, for a writer of its own; ``name`` is listed as written.

        Write it completely (e.g. with ``rockjit.storage.atomic.atomic_open``) before
        :meth:`publish`.
        """
        _check_name(name)
        path = self._stage_dir() / name
        self._add(name)
        return path

    def _target(self, name):
        _check_name(name)
        return self._stage_dir() / name

    def _add(self, name):
        if name not in self.written:
            self.written.append(name)

    def json(self, name, obj):
        """Stage ``obj`` as strict JSON (``write_json``)."""
        atomic.write_json(self._target(name), obj)
        self._add(name)

    def npz(self, name, **arrays):
        """Stage arrays as an ``.npz`` archive (``write_npz``)."""
        atomic.write_npz(self._target(name), **arrays)
        self._add(name)

    def figure(self, name, fig, *, dpi=None):
        """Stage a matplotlib figure (``save_figure``) in the format ``figure_format`` at
        ``self.dpi`` (or ``dpi``), then clear it to free its memory; returns the name written
        (its suffix the format's)."""
        if self.figure_format:
            name = f"{Path(name).stem}.{self.figure_format}"
        atomic.save_figure(fig, self._target(name), dpi=dpi or self.dpi)
        self._add(name)
        fig.clear()
        return name

    def figure_failed(self, name, exc):
        """Note that the figure ``name`` could not be drawn or written (``exc``): the command
        goes on without it (its data are written all the same) and says so."""
        if self.figure_format:
            name = f"{Path(name).stem}.{self.figure_format}"
        self.figure_errors.append(
            {"name": name, "error": f"{type(exc).__name__}: {' '.join(str(exc).split())}"})

    def describe(self, name, holds):
        """Say what file ``name`` holds (one line), for the manifest of ``summary.json``."""
        self.holds[name] = " ".join(str(holds).split())

    def csv(self, name, header, rows):
        """Stage a CSV table (``write_csv``)."""
        atomic.write_csv(self._target(name), header, rows)
        self._add(name)

    def text(self, name, text):
        """Stage a text file (``write_text``)."""
        atomic.write_text(self._target(name), text)
        self._add(name)

    def table(self, stem, header, rows, fmt=None):
        """Stage CSV and Markdown versions of one table: ``<stem>.csv``, ``<stem>.md``."""
        self.csv(stem + ".csv", header, rows)
        self.text(stem + ".md", atomic.markdown_table(header, rows, fmt))

    # -- publishing -----------------------------------------------------------------------------

    def stale_warning(self):
        """One line about files of an earlier rockjit run in ``path`` that stay, or ``None``.

        Read from ``path/summary.json``: a warning when it names another command, or lists
        files that this run has not written (so far) and that still exist. Those files are kept.
        """
        try:
            old = json.loads((self.path / SUMMARY).read_text(encoding="utf-8"))
        except (OSError, ValueError):
            return None
        if not isinstance(old, dict) or not isinstance(old.get("command"), str):
            return None
        cmd = old["command"]
        files = old.get("files") if isinstance(old.get("files"), list) else []
        kept = []
        for f in files:
            if isinstance(f, dict):  # the manifest: {"name": ..., "holds": ...}
                f = f.get("name")
            try:
                f = _check_name(f)
            except ValueError:
                continue
            if f not in self.written and os.path.lexists(self.path / f):
                kept.append(f)
        if kept:
            names = ", ".join(kept[:5]) + (f" and {len(kept) - 5} more" if len(kept) > 5 else "")
            return (f"{self.path} also holds {names} from an earlier `rockjit {cmd}` run; "
                    f"this run does not write them and leaves them there")
        command = self.command
        if command is None and self._stage is not None and SUMMARY in self.written:
            try:  # the command this run's own summary.json names
                command = json.loads((self._stage / SUMMARY).read_text(encoding="utf-8"))
                command = command.get("command") if isinstance(command, dict) else None
            except (OSError, ValueError):
                command = None
        if isinstance(command, str) and cmd != command:
            return (f"{self.path} held the outputs of an earlier `rockjit {cmd}` run; this "
                    f"`rockjit {command}` run replaces them")
        return None

    def publish(self):
        """Move the staged files into ``path`` as one unit (see the class docstring).

        Raises ``ValueError``, having published nothing, when ``path`` now holds a file this
        run would replace that is not provably rockjit's, or another run published into
        ``path`` since :meth:`claim`.

        Returns
        -------
        str or None
            :meth:`stale_warning` as it stood before the move (also kept in ``warning``):
            one line for the command line to print, or ``None``. The names published are
            ``written``.
        """
        if self.published:
            return self.warning
        stage = self._stage
        if stage is None:  # nothing was written: nothing to create
            self.published = True
            self._unlock()
            return None
        names = [n for n in self.written if n != RECORD]
        missing = [n for n in names if not (stage / n).is_file()]
        if missing:
            raise FileNotFoundError(errno.ENOENT, "staged output never written",
                                    str(stage / missing[0]))
        order = [n for n in names if n != SUMMARY] + [n for n in names if n == SUMMARY]
        self.warning = self.stale_warning()
        inside = None  # the lock inside path, when path appeared after this run's claim
        try:
            if self._inside and self._lock.path != lock_path(self.path):
                inside = PublishLock(self.path, name=self.name)
                inside.acquire()
            if self._inside:
                self._check_targets(order)
            self._stage_record(order)
            with defer_signals() as got:
                moved = False
                if not self._inside:
                    try:
                        os.rename(stage, self.path)
                        moved = True
                    except OSError as exc:  # path appeared meanwhile: publish file by file
                        if exc.errno not in (errno.EEXIST, errno.ENOTEMPTY):
                            raise
                        self._check_targets(order)
                        inside = PublishLock(self.path, name=self.name)
                        inside.acquire()
                        self._stage_record(order)
                if not moved:
                    for n in [RECORD] + order:  # the record first: it proves old and new
                        os.replace(stage / n, self.path / n)
                    shutil.rmtree(stage, ignore_errors=True)
                self._stage = None
                self._made = []
                self.published = True
        finally:
            if inside is not None:
                inside.release()
        self._unlock()
        self.interrupted = got[0] if got else None
        return self.warning

    def _stage_record(self, order):
        """Check that ``path`` is as :meth:`claim` saw it (no other run published there since)
        and that each of ``order`` it holds is rockjit's; stage the record of the files rockjit
        will have there: this run's, and the earlier ones still rockjit's."""
        from .. import __version__
        rec = Record.read(self.path)
        now = rec.run if rec.state == "ok" else None
        if rec.state == "damaged" or now != self._seen:
            raise ValueError(f"{self.name} {self.path} was written by another rockjit run while "
                             f"this one ran; nothing of this run was published: run it again, "
                             f"or choose another {self.name}")
        files, theirs = {}, []
        for n, entry in rec.files.items():  # earlier files that stay, still rockjit's
            if n not in order:
                have = digest(self.path / n)
                versions = [v for v in entry["versions"] if have == (v["size"], v["sha256"])]
                if versions:
                    files[n] = {"versions": versions}
        for n in order:
            size, sha = digest(self._stage / n)
            versions = [{"size": size, "sha256": sha}]
            target = self.path / n
            if os.path.lexists(target):
                have = digest(target)
                if not rec.proves(self.path, n, have):
                    theirs.append(n)
                    continue
                if have != (size, sha):  # until it is replaced, the old one is rockjit's too
                    versions.append({"size": have[0], "sha256": have[1]})
            files[n] = {"versions": versions}
        if theirs:
            raise ValueError(refusal(self.path, theirs, rec, self.name)
                             + "; nothing of this run was published")
        atomic.write_json(self._stage / RECORD, Record.write_data(files, self.command, __version__))

    def _check_targets(self, names):
        if not self.path.is_dir():
            raise ValueError(f"out must be a directory (got {self.path}, an existing file)")
        for n in names:
            t = self.path / n
            if t.is_dir() and not t.is_symlink():
                raise ValueError(f"cannot write {t}: a directory of that name is in the way")

    def discard(self):
        """Remove the staging directory and any parent directories it made, and give the lock
        back: ``path`` is as before."""
        if self._stage is not None:
            shutil.rmtree(self._stage, ignore_errors=True)
            self._stage = None
        _rmdirs(self._made)
        self._made = []
        self._unlock()

    def __enter__(self):
        return self

    def __exit__(self, exc_type, exc, tb):
        if exc_type is None:
            try:
                self.publish()
            except BaseException:
                self.discard()
                raise
        else:
            self.discard()
        return False
