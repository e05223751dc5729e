"""Files rockjit writes: the user's umask, outputs published as one unit, chunk stores that
refuse a second run, survive damage and report progress readably, and a numba cache check that
deletes only numba's files of this package.

The references are independent of the code under test: the mode a plain ``open``/``mkdir``
gets under the same umask, byte snapshots of directories taken before an operation, outputs
computed directly without chunks, and the cache folder numba's own locator names.
"""

import io
import json
import os
import signal
import stat
import subprocess
import sys
import textwrap
from pathlib import Path

import numpy as np
import pytest
from numba.core.caching import _CacheLocator

from rockjit import _jit
from rockjit.grids import runner as grid_runner
from rockjit.storage import chunkstore as chunks
from rockjit.storage import atomic
from rockjit.storage import output_dir as rio
from rockjit.storage.processes import host_name
from rockjit.storage.ownership import RECORD

ROOT = Path(__file__).resolve().parents[2]


# ---------------------------------------------------------------------------------------------
# helpers
# ---------------------------------------------------------------------------------------------

@pytest.fixture(params=[0o022, 0o077], ids=["umask022", "umask077"])
def umask(request):
    old = os.umask(request.param)
    try:
        yield request.param
    finally:
        os.umask(old)


def _mode(path):
    return stat.S_IMODE(os.lstat(path).st_mode)


def _plain_modes(tmp_path):
    """The modes a plain open() and mkdir() give under the current umask (the kernel's)."""
    ref = tmp_path / "ref"
    ref.mkdir()
    with open(ref / "f", "w") as fh:
        fh.write("x")
    os.mkdir(ref / "d")
    modes = _mode(ref / "f"), _mode(ref / "d")
    (ref / "f").unlink()
    (ref / "d").rmdir()
    ref.rmdir()
    return modes


def _snapshot(root):
    """Every entry under ``root`` (hidden ones included) with its bytes and mode."""
    root = Path(root)
    if not os.path.lexists(root):
        return None
    snap = {}
    for p in sorted(root.rglob("*")):
        rel = str(p.relative_to(root))
        snap[rel] = (p.read_bytes() if p.is_file() else "<dir>", _mode(p))
    return snap


class _Fig:
    """Stands in for a matplotlib figure: ``savefig`` writes bytes, ``during`` runs first."""

    def __init__(self, during=None):
        self.during = during
        self.cleared = False

    def savefig(self, buf, format=None, dpi=None):
        if self.during:
            self.during()
        buf.write(b"\x89PNG fake " + str(format).encode())

    def clear(self):
        self.cleared = True


def _run_child(code, *args, **kw):
    env = dict(os.environ, PYTHONPATH=str(ROOT))
    return subprocess.Popen([sys.executable, "-c", textwrap.dedent(code), *map(str, args)],
                            stdin=subprocess.PIPE, stdout=subprocess.PIPE,
                            stderr=subprocess.PIPE, text=True, env=env, **kw)


def _expect_line(proc, want):
    line = proc.stdout.readline().strip()
    if line != want:
        proc.kill()
        _, err = proc.communicate(timeout=60)
        pytest.fail(f"child said {line!r}, expected {want!r}; stderr:\n{err}")


# ---------------------------------------------------------------------------------------------
# 1. the user's umask
# ---------------------------------------------------------------------------------------------

def test_writers_follow_the_umask(tmp_path, umask):
    f_mode, _ = _plain_modes(tmp_path)
    assert f_mode == 0o666 & ~umask
    atomic.write_json(tmp_path / "a.json", {"x": 1})
    atomic.write_text(tmp_path / "a.txt", "x")
    atomic.write_npz(tmp_path / "a.npz", x=np.arange(3))
    atomic.write_csv(tmp_path / "a.csv", ["a"], [[1.0]])
    atomic.save_figure(_Fig(), tmp_path / "a.png")
    with atomic.atomic_open(tmp_path / "b.bin", "wb") as fh:
        fh.write(b"x")
    for name in ("a.json", "a.txt", "a.npz", "a.csv", "a.png", "b.bin"):
        assert _mode(tmp_path / name) == f_mode, name


def test_output_dir_follows_the_umask(tmp_path, umask):
    f_mode, d_mode = _plain_modes(tmp_path)
    fresh = tmp_path / "deep" / "fresh"  # parents made too
    with rio.OutputDir(fresh, command="cor") as out:
        out.json("summary.json", {"command": "cor"})
        out.table("t", ["a"], [[1.0]])
    assert _mode(tmp_path / "deep") == d_mode and _mode(fresh) == d_mode
    assert {p.name: _mode(p) for p in fresh.iterdir()} == \
        {"summary.json": f_mode, "t.csv": f_mode, "t.md": f_mode, RECORD: f_mode}
    existing = tmp_path / "existing"
    existing.mkdir()
    with rio.OutputDir(existing) as out:
        out.npz("x.npz", x=np.arange(2))
    assert _mode(existing / "x.npz") == f_mode and _mode(existing / RECORD) == f_mode


def test_chunk_store_follows_the_umask(tmp_path, umask):
    f_mode, d_mode = _plain_modes(tmp_path)
    path = tmp_path / "out.chunks" / "basin"
    store = chunks.ChunkStore(path, "key", 4, 2)
    assert _mode(path) == d_mode and _mode(path.parent) == d_mode
    assert _mode(path / "lock.json") == f_mode
    assert _mode(path / "manifest.json") == f_mode
    store.save(0, 2, {"y": np.zeros(2)})
    assert _mode(path / "cells-0000000000-0000000002.npz") == f_mode
    store.close()


# ---------------------------------------------------------------------------------------------
# 2. a command's outputs published as one unit
# ---------------------------------------------------------------------------------------------

def test_publish_into_a_new_directory(tmp_path):
    out = tmp_path / "out"
    o = rio.OutputDir(out, command="basin")
    o.npz("basin.npz", label=np.arange(4))
    fig = _Fig()
    o.figure("basin.png", fig)
    o.json("summary.json", {"command": "basin", "files": o.written + ["summary.json"]})
    assert fig.cleared
    assert not out.exists()  # nothing visible before publish
    stage = o.staging
    assert stage.parent == tmp_path and stage.name.startswith(".out.")
    assert o.publish() is None  # nothing to warn about
    assert o.written == [RECORD, "basin.npz", "basin.png", "summary.json"]
    assert sorted(p.name for p in tmp_path.iterdir()) == ["out"]  # the stage was renamed
    assert sorted(p.name for p in out.iterdir()) == \
        [RECORD, "basin.npz", "basin.png", "summary.json"]
    assert np.load(out / "basin.npz")["label"].tolist() == [0, 1, 2, 3]
    assert json.loads((out / "summary.json").read_text())["files"] == \
        [RECORD, "basin.npz", "basin.png", "summary.json"]
    assert o.published and o.interrupted is None and o.warning is None


def test_publish_into_an_existing_directory_keeps_the_users_files(tmp_path, monkeypatch):
    out = tmp_path / "out"
    with rio.OutputDir(out, command="basin") as o:  # an earlier run's basin.npz
        o.npz("basin.npz", label=np.arange(5))
    (out / "notes.txt").write_text("mine")
    moved = []
    real = os.replace

    def record(src, dst):
        moved.append(Path(dst).name)
        return real(src, dst)

    with rio.OutputDir(out, command="basin") as o:
        o.json("summary.json", {"command": "basin", "files": ["basin.npz", "summary.json"]})
        o.npz("basin.npz", label=np.arange(3))
        monkeypatch.setattr(os, "replace", record)
    monkeypatch.setattr(os, "replace", real)
    assert moved[-3:] == [RECORD, "basin.npz", "summary.json"]  # the record first
    assert sorted(p.name for p in out.iterdir()) == \
        [RECORD, "basin.npz", "notes.txt", "summary.json"]
    assert (out / "notes.txt").read_text() == "mine"
    assert np.load(out / "basin.npz")["label"].tolist() == [0, 1, 2]
    assert sorted(p.name for p in tmp_path.iterdir()) == ["out"]


@pytest.mark.parametrize("existing", [False, True])
def test_keyboard_interrupt_inside_a_write_leaves_out_untouched(tmp_path, monkeypatch,
                                                                existing):
    out = tmp_path / "sub" / "out"
    if existing:
        out.mkdir(parents=True)
        (out / "summary.json").write_text('{"command": "basin", "files": ["summary.json"]}')
        (out / "basin.png").write_bytes(b"old figure")
    before_out, before_root = _snapshot(out), _snapshot(tmp_path)

    def boom(fh, **arrays):
        fh.write(b"PK\x03\x04 partial")
        raise KeyboardInterrupt

    with pytest.raises(KeyboardInterrupt):
        with rio.OutputDir(out, command="basin") as o:
            o.figure("basin.png", _Fig())
            o.json("summary.json", {"command": "basin"})
            monkeypatch.setattr(np, "savez", boom)
            o.npz("basin.npz", label=np.arange(3))
    assert _snapshot(out) == before_out
    assert _snapshot(tmp_path) == before_root  # no stage, no parent left behind


@pytest.fixture
def ctrl_c():
    """Ctrl-C raises KeyboardInterrupt, as in a terminal: a shell starting the tests in the
    background (``cmd &``) makes them ignore SIGINT, and a sent SIGINT would do nothing."""
    old = signal.signal(signal.SIGINT, signal.default_int_handler)
    yield
    signal.signal(signal.SIGINT, old)


@pytest.mark.parametrize("existing", [False, True])
def test_signal_during_staging_leaves_out_untouched(tmp_path, existing, ctrl_c):
    out = tmp_path / "out"
    if existing:
        out.mkdir()
        (out / "trajectory.png").write_bytes(b"old")
    before = _snapshot(tmp_path)
    with pytest.raises(KeyboardInterrupt):
        with rio.OutputDir(out) as o:
            o.npz("trajectory.npz", t=np.arange(5.0))
            o.figure("trajectory.png", _Fig(lambda: os.kill(os.getpid(), signal.SIGINT)))
            o.json("summary.json", {})
    assert _snapshot(tmp_path) == before


@pytest.mark.parametrize("existing", [False, True])
def test_signal_during_publish_is_deferred(tmp_path, monkeypatch, existing):
    out = tmp_path / "out"
    if existing:  # an earlier run's
        with rio.OutputDir(out) as o:
            o.npz("plane.npz", label=np.arange(2))
    handler = signal.getsignal(signal.SIGINT)
    real = {"rename": os.rename, "replace": os.replace}

    def interrupting(name):
        def move(src, dst):
            if Path(dst) == out or Path(dst).parent == out:  # a move into out
                os.kill(os.getpid(), signal.SIGINT)  # arrives in the middle of the moves
            return real[name](src, dst)
        return move

    o = rio.OutputDir(out, command="plane")
    o.npz("plane.npz", label=np.arange(6))
    o.json("summary.json", {"command": "plane"})
    monkeypatch.setattr(os, "rename", interrupting("rename"))
    monkeypatch.setattr(os, "replace", interrupting("replace"))
    o.publish()  # no KeyboardInterrupt: the outputs are published, the run can succeed
    monkeypatch.undo()
    assert o.published and o.interrupted == signal.SIGINT
    assert signal.getsignal(signal.SIGINT) is handler
    assert sorted(p.name for p in out.iterdir()) == [RECORD, "plane.npz", "summary.json"]
    assert np.load(out / "plane.npz")["label"].tolist() == list(range(6))


CHILD_PUBLISH = """
    import os, signal, sys, time
    from rockjit.storage import output_dir as rio
    out = rio.OutputDir(sys.argv[1], command="basin")
    out.text("a.txt", "new a")
    out.text("summary.json", "new summary")
    if sys.argv[2] == "staging":
        print("staging", flush=True)
        time.sleep(60)  # SIGTERM's default action ends the process here
    real = os.replace
    def slow(src, dst):
        if os.path.dirname(dst) != sys.argv[1]:
            return real(src, dst)  # not a move into out
        print("publishing", flush=True)
        time.sleep(0.5)  # SIGTERM arrives while the files are being moved
        real(src, dst)
    os.replace = slow
    out.publish()
    print("published", out.interrupted == signal.SIGTERM, flush=True)
"""


def test_sigterm_in_another_process(tmp_path):
    out = tmp_path / "out"
    with rio.OutputDir(out) as o:  # an earlier run's
        o.text("a.txt", "old a")
        o.text("summary.json", "old summary")
    (out / "user.txt").write_text("mine")
    before = _snapshot(tmp_path)
    # killed while staging: --out untouched; the next run removes the dead run's stage
    p = _run_child(CHILD_PUBLISH, out, "staging")
    _expect_line(p, "staging")
    assert [d.name for d in out.iterdir() if d.name.startswith(".rockjit-stage-")]
    p.send_signal(signal.SIGTERM)
    assert p.wait(timeout=60) == -signal.SIGTERM
    left = [d for d in out.iterdir() if d.name.startswith(".rockjit-stage-")]
    assert len(left) == 1 and str(p.pid) in left[0].name
    o = rio.OutputDir(out)
    o.text("x.txt", "")  # the first write clears stages of dead runs
    o.discard()
    assert _snapshot(tmp_path) == before
    # terminated while publishing: the set is published whole and the run succeeds
    p = _run_child(CHILD_PUBLISH, out, "publish")
    _expect_line(p, "publishing")
    p.send_signal(signal.SIGTERM)
    stdout, stderr = p.communicate(timeout=60)
    assert p.returncode == 0, stderr
    assert stdout.split("\n")[-2] == "published True"
    assert {f: (out / f).read_text() for f in ("a.txt", "summary.json", "user.txt")} == \
        {"a.txt": "new a", "summary.json": "new summary", "user.txt": "mine"}
    assert sorted(p.name for p in out.iterdir()) == [RECORD, "a.txt", "summary.json",
                                                     "user.txt"]


def test_stale_stages_only_of_dead_runs_on_this_host(tmp_path):
    out = tmp_path / "out"
    dead = subprocess.Popen([sys.executable, "-c", "pass"])
    dead.wait()
    host = host_name()
    stages = {"dead": tmp_path / f".out.rockjit-stage-{host}-{dead.pid}-00000000",
              "alive": tmp_path / f".out.rockjit-stage-{host}-{os.getppid()}-00000000",
              "elsewhere": tmp_path / f".out.rockjit-stage-otherhost-{dead.pid}-00000000",
              "user": tmp_path / ".out.rockjit-stage-notes"}
    for d in stages.values():
        d.mkdir()
        (d / "f").write_text("x")
    o = rio.OutputDir(out)
    o.text("a.txt", "a")
    assert not stages["dead"].exists()
    assert all(stages[k].exists() for k in ("alive", "elsewhere", "user"))
    o.discard()


def test_stale_warning_names_files_of_another_command(tmp_path):
    out = tmp_path / "out"
    old = {"command": "sweep", "files": ["sweep.npz", "bifurcation.png", "summary.json"]}
    with rio.OutputDir(out) as o:  # an earlier run of another command
        o.json("summary.json", old)
        o.text("sweep.npz", "s")
        o.text("bifurcation.png", "b")
    o = rio.OutputDir(out, command="basin")
    o.npz("basin.npz", x=np.arange(2))
    o.json("summary.json", {"command": "basin", "files": ["basin.npz", "summary.json"]})
    w = o.stale_warning()
    assert "\n" not in w and "sweep.npz" in w and "bifurcation.png" in w and "sweep" in w
    assert o.publish() == w == o.warning
    assert (out / "sweep.npz").read_bytes() == b"s"  # warned about, never deleted
    assert (out / "bifurcation.png").read_bytes() == b"b"
    # the same command again, writing the same files: nothing to say
    o = rio.OutputDir(out, command="basin")
    o.npz("basin.npz", x=np.arange(2))
    o.json("summary.json", {"command": "basin", "files": ["basin.npz", "summary.json"]})
    assert o.stale_warning() is None
    o.discard()
    # another command whose files this run all replaces: still said (the command read from
    # the summary.json this run stages when not given)
    o = rio.OutputDir(out)
    o.npz("basin.npz", x=np.arange(2))
    o.json("summary.json", {"command": "plane"})
    assert "basin" in o.stale_warning() and "plane" in o.stale_warning()
    o.discard()


def test_refusals_leave_everything_as_it_was(tmp_path):
    (tmp_path / "file").write_text("mine")
    with pytest.raises(ValueError, match="existing file"):
        rio.OutputDir(tmp_path / "file").text("a.txt", "")
    (tmp_path / "link").symlink_to(tmp_path / "nowhere")
    with pytest.raises(ValueError, match="existing file"):
        rio.OutputDir(tmp_path / "link").text("a.txt", "")
    with pytest.raises(ValueError, match="empty|''"):
        rio.OutputDir("")
    out = tmp_path / "out"
    (out / "summary.json").mkdir(parents=True)  # a directory where a file would go
    before = _snapshot(tmp_path)
    with pytest.raises(ValueError, match="in the way"):
        with rio.OutputDir(out) as o:
            o.text("a.txt", "a")
            o.json("summary.json", {})
    assert _snapshot(tmp_path) == before
    for bad in ("../x", "a/b", "..", ""):
        with pytest.raises(ValueError, match="plain file name"):
            rio.OutputDir(out).text(bad, "")
    assert _snapshot(tmp_path) == before


def test_check_out_finds_what_publishing_would_refuse(tmp_path):
    # each of these was found only when staging or publishing, after the work
    (tmp_path / "dangling").symlink_to(tmp_path / "nowhere")
    (tmp_path / "loop").symlink_to("loop")
    (tmp_path / "out" / "basin.npz").mkdir(parents=True)
    (tmp_path / "out.chunks").mkdir()
    (tmp_path / "out.chunks" / "mao").write_text("mine")
    (tmp_path / "s" / "summary.json").mkdir(parents=True)
    before = _snapshot(tmp_path)
    for out, says in [(tmp_path / "dangling", "is a symbolic link to "),
                      (tmp_path / "loop", "is a symbolic link in a loop"),
                      (tmp_path / "dangling" / "sub", "cannot be created: "),
                      (tmp_path / ("x" * 256), "256 bytes long; at most 255"),
                      (tmp_path / "a" / ("d/" * 2100), "as an absolute path")]:
        with pytest.raises(ValueError, match="^--out ") as refused:
            rio.check_out(out, name="--out")
        assert says in str(refused.value)
    with pytest.raises(ValueError, match="holds a directory basin.npz where"):
        rio.check_out(tmp_path / "out", name="--out", files=("basin.npz",))
    with pytest.raises(ValueError, match="holds a directory summary.json where"):
        rio.check_out(tmp_path / "s", name="--out")  # summary.json: every command's
    with pytest.raises(ValueError, match="mao, where --out's unfinished chunks"):
        rio.check_out(tmp_path / "out", name="--out", chunks=True)
    rio.check_out(tmp_path / "out", name="--out")  # without chunks, and without that file
    with pytest.raises(ValueError, match=r"<name>.chunks, and at most 255 bytes fit"):
        rio.check_out(tmp_path / ("y" * 250), name="--out", chunks=True)
    rio.check_out(tmp_path / ("y" * 248), name="--out", chunks=True)
    assert _snapshot(tmp_path) == before  # the checks leave nothing behind


def test_staging_names_stay_short_beside_a_long_out(tmp_path):
    out = tmp_path / ("o" * 240)  # its staging directory beside it would need 280 bytes
    with rio.OutputDir(out) as o:
        o.text("a.txt", "a")
        stage = o.staging
        assert len(stage.name) <= 255 and stage.parent == tmp_path
    assert (out / "a.txt").read_text() == "a" and sorted(os.listdir(tmp_path)) == [out.name]


def test_nothing_written_creates_nothing(tmp_path):
    with rio.OutputDir(tmp_path / "a" / "out") as o:
        pass
    assert o.publish() is None and o.written == [] and list(tmp_path.iterdir()) == []


def test_table_writes_csv_and_markdown(tmp_path):
    with rio.OutputDir(tmp_path / "out") as o:
        o.table("e_table", ["hb", "e"], [[1, 0.123456], ["x", float("nan")]], fmt={"e": ".3f"})
    assert (tmp_path / "out" / "e_table.csv").read_text().splitlines() == \
        ["hb,e", "1,0.123456", "x,nan"]
    assert (tmp_path / "out" / "e_table.md").read_text() == \
        "| hb | e |\n|---|---|\n| 1 | 0.123 |\n| x | nan |\n"
    assert o.written == [RECORD, "e_table.csv", "e_table.md"]


# ---------------------------------------------------------------------------------------------
# 3. chunk stores
# ---------------------------------------------------------------------------------------------

N, CHUNK = 23, 5
BOUNDS = [(a, min(N, a + CHUNK)) for a in range(0, N, CHUNK)]


def _runner(x, calls=None):
    if calls is not None:
        calls.append((int(x[0]), int(x[-1]) + 1))
    return {"y": np.sin(x) * 1e3 + x ** 2, "k": (x * 7).astype(np.int64) % 5,
            "pair": np.stack([np.cos(x), x], axis=1)}


def _direct():
    """The outputs computed in one go, without chunks or a store."""
    x = np.arange(N, dtype=float)
    return _runner(x)


def _outputs():
    return {"y": np.zeros(N), "k": np.zeros(N, dtype=np.int64), "pair": np.zeros((N, 2))}


def _run(store, calls=None, **kw):
    x = np.arange(N, dtype=float)
    out = _outputs()
    grid_runner.run_chunks(lambda xs: _runner(xs, calls), (x,), N, CHUNK, out, store=store, **kw)
    return out


def _open(path, message=None):
    kw = {} if message is None else dict(message=message)
    return chunks.ChunkStore(path, chunks.fingerprint((np.arange(N, dtype=float),), {}), N,
                             CHUNK, **kw)


def _same(a, b):
    assert a.keys() == b.keys()
    for k in a:
        assert a[k].dtype == b[k].dtype and a[k].tobytes() == b[k].tobytes(), k


def test_chunks_are_written_by_the_atomic_writer(tmp_path, monkeypatch):
    store = tmp_path / "s"
    _run(_open(store))
    old = (store / "cells-0000000000-0000000005.npz").read_bytes()

    def boom(fh, **arrays):
        fh.write(b"PK\x03\x04 partial")
        raise KeyboardInterrupt

    s = _open(store)
    monkeypatch.setattr(np, "savez", boom)
    with pytest.raises(KeyboardInterrupt):
        s.save(0, 5, _runner(np.arange(5.0)))
    monkeypatch.undo()
    s.close()
    assert (store / "cells-0000000000-0000000005.npz").read_bytes() == old
    names = sorted(p.name for p in store.iterdir())
    assert names == sorted(["manifest.json"] + [f"cells-{a:010d}-{b:010d}.npz"
                                                for a, b in BOUNDS])  # no temporary, no lock


def test_damaged_chunks_are_discarded_and_recomputed(tmp_path, capsys):
    store = tmp_path / "s"
    _same(_run(_open(store)), _direct())
    names = [store / f"cells-{a:010d}-{b:010d}.npz" for a, b in BOUNDS]
    data = names[0].read_bytes()
    names[0].write_bytes(data[: len(data) // 2])  # truncated
    names[1].write_bytes(b"not a zip archive at all")
    good = _runner(np.arange(10.0, 15.0))
    np.savez(names[2], y=good["y"], k=good["k"])  # an array missing
    np.savez(names[3], y=good["y"][:3], k=good["k"], pair=good["pair"])  # wrong shape
    np.savez(names[4], y=good["y"][:3].astype(np.float32), k=good["k"][:3],
             pair=good["pair"][:3])  # wrong dtype
    calls = []
    again = _run(_open(store), calls)
    _same(again, _direct())
    assert sorted(calls) == BOUNDS  # exactly the damaged ones, computed again
    err = capsys.readouterr().err.splitlines()
    assert [line for line in err if "discarded damaged chunk" in line] == err
    assert len(err) == len(BOUNDS)
    for line, path in zip(err, names):
        assert line.startswith(f"rockjit: discarded damaged chunk {path.name} ")
        assert line.endswith("; recomputing")
    assert "(not an .npz archive)" in err[1] and "'pair'" in err[2]
    calls.clear()
    _same(_run(_open(store), calls), _direct())  # now whole again: loaded, not computed
    assert calls == []


def test_a_chunk_replaced_by_a_directory_is_removed_and_recomputed(tmp_path):
    # its discard raised IsADirectoryError, so it was never recomputed and every rerun failed
    store = tmp_path / "s"
    _run(_open(store))
    chunk = store / "cells-0000000005-0000000010.npz"
    chunk.unlink()
    chunk.mkdir()
    (chunk / "inside").write_text("x")
    msgs, calls = [], []
    _same(_run(_open(store, msgs.append), calls), _direct())
    assert calls == [(5, 10)] and len(msgs) == 1
    assert msgs[0].startswith(f"discarded damaged chunk {chunk.name} ") and chunk.is_file()
    other = store / "cells-0000000010-0000000015.npz"
    other.unlink()
    other.mkdir()  # one left for the clean-up: it is rockjit's own, and goes too
    assert chunks.remove_stores(store, message=msgs.append)
    assert not store.exists()


def test_bit_flip_in_a_chunk_is_caught_by_the_checksum(tmp_path):
    store = tmp_path / "s"
    _run(_open(store))
    path = store / "cells-0000000005-0000000010.npz"
    raw = bytearray(path.read_bytes())
    i = raw.index(b"\x93NUMPY") + 128 + 3  # inside the first array's data (header: 128 B)
    raw[i] ^= 0x01
    path.write_bytes(bytes(raw))
    msgs, calls = [], []
    _same(_run(_open(store, msgs.append), calls), _direct())
    assert calls == [(5, 10)] and len(msgs) == 1 and path.name in msgs[0]


def test_store_path_that_is_a_file(tmp_path):
    (tmp_path / "f").write_text("mine")
    with pytest.raises(ValueError, match="existing file"):
        _open(tmp_path / "f")
    with pytest.raises(ValueError, match="cannot be created"):
        _open(tmp_path / "f" / "basin")
    assert (tmp_path / "f").read_text() == "mine"


def test_one_store_one_run_in_this_process(tmp_path):
    a = _open(tmp_path / "s")
    with pytest.raises(ValueError, match=f"pid {os.getpid()}"):
        _open(tmp_path / "s")
    a.close()
    assert not (tmp_path / "s" / "lock.json").exists()
    _open(tmp_path / "s").close()


def test_lock_released_when_the_run_raises(tmp_path):
    store = tmp_path / "s"

    def runner(x):
        if x[0] >= 10:
            raise KeyboardInterrupt
        return _runner(x)

    s = _open(store)
    with pytest.raises(KeyboardInterrupt):
        grid_runner.run_chunks(runner, (np.arange(N, dtype=float),), N, CHUNK, _outputs(), store=s)
    assert not s.locked and not (store / "lock.json").exists()
    calls = []
    _same(_run(_open(store), calls), _direct())  # resumes: only the missing chunks
    assert sorted(calls) == BOUNDS[2:]


def test_lock_of_another_host_is_refused(tmp_path):
    store = tmp_path / "s"
    store.mkdir()
    (store / "lock.json").write_text(json.dumps({"pid": 1, "host": "elsewhere", "token": "t"}))
    with pytest.raises(ValueError, match="host elsewhere.*pid 1"):
        _open(store)
    assert not chunks.remove_stores(store, message=lambda m: None)
    assert (store / "lock.json").exists()


def _lock(pid, **kw):
    return json.dumps(dict(pid=pid, host=host_name(), token="t", **kw))


def _proc(path):
    try:
        return Path(path).read_text()
    except OSError:
        return None


def _start_ticks(pid):
    """Field 22 of ``/proc/<pid>/stat`` (read here independently of rockjit)."""
    text = _proc(f"/proc/{pid}/stat")
    return None if text is None else int(text[text.rindex(")") + 2:].split()[19])


def _boot_id():
    text = _proc("/proc/sys/kernel/random/boot_id")
    return None if text is None else text.strip()


def _boot_time():
    text = _proc("/proc/stat") or ""
    return next(float(line.split()[1]) for line in text.splitlines() if line.startswith("btime"))


needs_proc = pytest.mark.skipif(_start_ticks(1) is None or _boot_id() is None,
                                reason="needs /proc (pid start times, the boot id)")


@needs_proc
@pytest.mark.parametrize("lock, why", [
    (dict(start="later", boot="this"), "started later"),
    (dict(start="same", boot="another boot"), "restarted"),
    (dict(written="before boot"), "started after the lock was written"),
], ids=["pid-reused", "rebooted", "old-lock-before-boot"])
def test_a_lock_naming_a_live_pid_of_another_process_is_taken_over(tmp_path, lock, why):
    # pid 1 is alive, but it is not the process that wrote these locks: such a lock was
    # refused on every rerun (pids are reused after a reboot, and in containers)
    store = tmp_path / "s"
    store.mkdir()
    start = _start_ticks(1)
    fields = {}
    if "start" in lock:
        fields["start"] = start + 1 if lock["start"] == "later" else start
        fields["boot"] = _boot_id() if lock["boot"] == "this" else "another boot"
    (store / "lock.json").write_text(_lock(1, **fields))
    if lock.get("written") == "before boot":  # rockjit 0.1.0's lock, from before this boot
        t = _boot_time() - 3600
        os.utime(store / "lock.json", (t, t))
    msgs = []
    s = _open(store, msgs.append)
    assert s.locked and len(msgs) == 1, msgs
    assert msgs[0].startswith(f"took over the chunk store {store} from pid 1 on ")
    assert why in msgs[0]
    s.close()


@needs_proc
def test_a_live_owners_lock_is_refused_saying_how_to_take_the_store_over(tmp_path):
    store = tmp_path / "s"
    store.mkdir()
    lock = store / "lock.json"
    for fields in (dict(start=_start_ticks(1), boot=_boot_id()),  # pid 1 itself
                   {}):  # no start time, written after pid 1 started: cannot tell
        lock.write_text(_lock(1, **fields))
        with pytest.raises(ValueError) as refused:
            _open(store)
        msg = str(refused.value)
        assert "in use by another rockjit run (pid 1 on " in msg
        assert msg.endswith(f"if no rockjit run is using it (pid 1 is another program), "
                            f"delete {lock}")
    lock.unlink()
    s = _open(store)  # the lock it writes names its process exactly
    mine = json.loads(lock.read_text())
    assert mine["pid"] == os.getpid() and mine["start"] == _start_ticks(os.getpid())
    assert mine["boot"] == _boot_id()
    s.close()


CHILD_RUN = """
    import sys
    from pathlib import Path
    import numpy as np
    from rockjit.grids import runner as grid_runner
    from rockjit.storage import chunkstore as chunks
    def runner(x):
        if x[0] == 5:  # the second chunk: wait for the parent
            print("computing", flush=True)
            sys.stdin.readline()
        return {"y": x * 2.0}
    x = np.arange(23.0)
    out = {"y": np.zeros(23)}
    store = chunks.ChunkStore(sys.argv[1], chunks.fingerprint((x,), {}), 23, 5)
    grid_runner.run_chunks(runner, (x,), 23, 5, out, store=store)
    gone = chunks.remove_stores(Path(sys.argv[1]).parent)  # as the command line does
    print("removed" if gone else "kept", flush=True)
"""


def _open_like_child(path, message=None):
    x = np.arange(23.0)
    kw = {} if message is None else dict(message=message)
    return chunks.ChunkStore(path, chunks.fingerprint((x,), {}), 23, 5, **kw)


def test_a_second_run_on_a_store_in_use(tmp_path):
    root = tmp_path / "out.chunks"
    store = root / "basin"
    p = _run_child(CHILD_RUN, store)
    _expect_line(p, "computing")
    # the owner is alive: refused, naming it; its store is neither used nor removed
    with pytest.raises(ValueError, match=f"in use by another rockjit run \\(pid {p.pid} "):
        _open_like_child(store)
    msgs = []
    assert not chunks.remove_stores(root, message=msgs.append)
    assert len(msgs) == 1 and f"pid {p.pid}" in msgs[0] and "kept" in msgs[0]
    assert (store / "cells-0000000000-0000000005.npz").exists()
    p.stdin.write("\n")
    p.stdin.flush()
    stdout, stderr = p.communicate(timeout=120)
    assert p.returncode == 0 and stdout.strip() == "removed", stderr
    assert not root.exists()  # the owner finished and removed its store


def test_a_dead_owners_lock_is_taken_over(tmp_path):
    store = tmp_path / "s"
    p = _run_child(CHILD_RUN, store)
    _expect_line(p, "computing")
    p.kill()
    p.wait(timeout=60)
    lock = json.loads((store / "lock.json").read_text())
    assert lock["pid"] == p.pid and lock["host"] == host_name()
    (store / ".cells-0000000005-0000000010.npz.0badc0de.tmp").write_bytes(b"half")
    msgs = []
    s = _open_like_child(store, msgs.append)
    assert s.locked and len(msgs) == 1
    assert f"pid {p.pid}" in msgs[0] and "no longer running" in msgs[0]
    assert json.loads((store / "lock.json").read_text())["pid"] == os.getpid()
    assert not list(store.glob(".*.tmp"))  # the killed run's temporary file is gone
    (store / "notes.txt").write_text("mine")
    assert not s.cleanup()  # the user's file keeps the directory
    assert sorted(p.name for p in store.iterdir()) == ["notes.txt"]


def test_remove_store_deletes_only_rockjits_files(tmp_path):
    root = tmp_path / "out.chunks"
    for name in ("housner", "mao"):
        _run(_open(root / name))
    assert chunks.remove_stores(root)
    assert not root.exists()
    _run(_open(root / "mao"))
    (root / "readme.txt").write_text("mine")
    assert not chunks.remove_stores(root)
    assert sorted(str(p.relative_to(root)) for p in root.rglob("*")) == ["readme.txt"]


def _fake_clock(monkeypatch):
    now = [0.0]
    monkeypatch.setattr(grid_runner.time, "perf_counter", lambda: now[0])
    return now


def test_progress_in_a_log_file_is_plain_throttled_lines(tmp_path, monkeypatch, capsys):
    now = _fake_clock(monkeypatch)
    x = np.arange(N, dtype=float)

    def runner(xs):
        now[0] += 2.0  # each chunk takes 2 s
        return _runner(xs)

    grid_runner.run_chunks(runner, (x,), N, CHUNK, _outputs(), progress=True, label="basin")
    err = capsys.readouterr().err
    assert "\r" not in err
    lines = err.splitlines()
    # chunks end at 2, 4, 6, 8, 10 s: a line once 5 s have passed since the last (6 s), then
    # the last one (10 s)
    assert [line.split(",")[0] for line in lines] == ["basin: 15/23 cells", "basin: 23/23 cells"]
    # the clock is the fake one above, so this checks the line's arithmetic and format, not a
    # timing: the fake clock read 6 s at that line, and 8 cells were left at 15 cells per 6 s
    # (8 x 6 / 15 = 3.2 s)
    assert lines[0] == "basin: 15/23 cells, 6.0 s elapsed, ~3.2 s left"


class _Tty(io.StringIO):
    def isatty(self):
        return True


def test_progress_on_a_terminal_is_a_tqdm_bar_on_one_line(monkeypatch):
    tty = _Tty()
    monkeypatch.setattr(sys, "stderr", tty)
    grid_runner.run_chunks(_runner, (np.arange(N, dtype=float),), N, CHUNK, _outputs(),
                           progress=True, label="basin hb=1 mao")
    text = tty.getvalue()
    # tqdm redraws after a \r (as often as its own throttle allows) and ends the line once
    assert text.startswith("\r") and text.count("\n") == 1 and text.endswith("\n")
    draws = text.rstrip("\n").split("\r")[1:]
    assert draws and all(d.startswith("basin hb=1 mao: ") for d in draws)
    assert f"{N}/{N} cells" in draws[-1] and "100%" in draws[-1]


def test_progress_in_a_log_file_stays_a_few_lines_over_many_chunks(monkeypatch, capsys):
    now = _fake_clock(monkeypatch)
    n, chunk = 1000, 5  # 200 chunks of 0.1 s each: 20 s

    def runner(xs):
        now[0] += 0.1
        return {"y": 2.0 * xs}

    grid_runner.run_chunks(runner, (np.arange(n, dtype=float),), n, chunk,
                           {"y": np.zeros(n)}, progress=True, label="sweep hb=2 housner")
    err = capsys.readouterr().err
    assert "\r" not in err
    lines = err.splitlines()
    assert 2 <= len(lines) <= 5, lines  # one line per 5 s and the last, not one per chunk
    assert all(line.startswith("sweep hb=2 housner: ") for line in lines)
    assert lines[-1].startswith(f"sweep hb=2 housner: {n}/{n} cells")


@pytest.mark.parametrize("law", ["housner", "mao"])
def test_a_grids_progress_names_the_grid_the_law_and_the_forcing(law, capsys):
    import rockjit
    rockjit.basin(rockjit.Block(hb=1, law=law), rockjit.Harmonic(alpha=0.66, omega=1.3),
                  grid=4, integration=rockjit.Integration(periods=10),
                  execution=rockjit.Execution(progress=True))
    lines = capsys.readouterr().err.splitlines()
    assert lines and all(line.startswith(f"basin hb=1 {law} alpha=0.66 omega=1.3: ")
                         for line in lines), lines
    assert lines[-1].startswith(f"basin hb=1 {law} alpha=0.66 omega=1.3: 16/16 cells")


def test_progress_callable_hears_each_chunk_and_can_stop_the_run(capsys):
    heard = []
    grid_runner.run_chunks(_runner, (np.arange(N, dtype=float),), N, CHUNK, _outputs(),
                           progress=lambda done, total: heard.append((done, total)))
    assert heard == [(0, N)] + [(b, N) for _, b in BOUNDS]
    assert capsys.readouterr().err == ""  # told to the callable, not to stderr

    class Stop(Exception):
        pass

    calls = []

    def stop_after_two(done, total):
        if done >= 2 * CHUNK:
            raise Stop

    with pytest.raises(Stop):
        grid_runner.run_chunks(lambda x: _runner(x, calls), (np.arange(N, dtype=float),), N,
                               CHUNK, _outputs(), progress=stop_after_two)
    assert calls == BOUNDS[:2]  # stopped between chunks: no third chunk was run


def test_execution_takes_a_progress_callable_and_refuses_other_values():
    from rockjit import Execution
    hook = lambda done, total: None  # noqa: E731
    assert Execution(progress=hook).progress is hook
    with pytest.raises(ValueError, match="progress must be True, False or a callable"):
        Execution(progress="yes")


# ---------------------------------------------------------------------------------------------
# 4. numba's cache: only the package's own files are deleted
# ---------------------------------------------------------------------------------------------

def _package(tmp_path, extra=()):
    pkg = tmp_path / "src" / "rockjit"
    pkg.mkdir(parents=True)
    for name in _jit._SOURCES + ("cli.py",) + tuple(extra):
        (pkg / name).write_text(f"# {name}\n")
    for name in ("integrate.py", "analysis.py"):  # modules that compile import the policy
        (pkg / name).write_text("from ._jit import jit\n")
    return pkg


OURS = ("model.accel_near-341.py311.nbi", "model.accel_near-341.py311.1.nbc",
        "integrate._build.locals.run-1111.py311.3.nbc", "analysis._grid-88.py311.nbi")


def _put(folder, names, text="x"):
    folder.mkdir(parents=True, exist_ok=True)
    for n in names:
        (folder / n).write_text(text)


def test_check_cache_deletes_only_numbas_files_of_the_package(tmp_path, monkeypatch):
    root = tmp_path / "numba-cache"
    monkeypatch.setenv("NUMBA_CACHE_DIR", str(root))
    monkeypatch.setattr(_jit, "_user_wide_dir", lambda: tmp_path / "user-wide")
    pkg = _package(tmp_path)
    numba_dir = root / _CacheLocator.get_suitable_cache_subpath(str(pkg / "model.py"))
    other_checkout = root / _CacheLocator.get_suitable_cache_subpath(
        str(tmp_path / "elsewhere" / "rockjit" / "model.py"))
    decoys = {root / "my-rockjit-notes": ["keep.nbi", "keep.nbc"],
              numba_dir: ["other.nbc", "other.f-1.py311.nbi", "notes.txt", "model.nbi"],
              other_checkout: list(OURS),
              pkg / "__pycache__": ["model.cpython-311.pyc"]}
    for folder, names in decoys.items():
        _put(folder, names)
    _put(numba_dir, OURS)
    _put(pkg / "__pycache__", OURS)

    def survivors():
        return {f: sorted(p.name for p in f.iterdir() if p.name != _jit.STAMP)
                for f in decoys}

    _jit.check_cache(pkg)  # no stamp: nothing there can be trusted
    assert survivors() == {f: sorted(n) for f, n in decoys.items()}
    assert (numba_dir / _jit.STAMP).exists() and (pkg / "__pycache__" / _jit.STAMP).exists()
    assert not (tmp_path / "user-wide").exists()  # a folder numba will not use
    _put(numba_dir, OURS, "fresh")
    _jit.check_cache(pkg)  # sources unchanged: kept
    assert all((numba_dir / n).read_text() == "fresh" for n in OURS)
    (pkg / "cli.py").write_text("# cli.py, edited\n")  # not compiled: kept
    _jit.check_cache(pkg)
    assert all((numba_dir / n).exists() for n in OURS)
    (pkg / "model.py").write_text("# model.py, edited\n")
    _jit.check_cache(pkg)
    assert not any((numba_dir / n).exists() for n in OURS)
    assert survivors() == {f: sorted(n) for f, n in decoys.items()}


def test_check_cache_covers_every_module_that_compiles(tmp_path, monkeypatch):
    monkeypatch.delenv("NUMBA_CACHE_DIR", raising=False)
    monkeypatch.setattr(_jit, "_user_wide_dir", lambda: tmp_path / "user-wide")
    pkg = _package(tmp_path, extra=("kernel.py",))
    (pkg / "kernel.py").write_text("from ._jit import jit\n")
    cache = pkg / "__pycache__"
    _jit.check_cache(pkg)
    _put(cache, ["kernel.run_chunk_kernel-12.py311.nbi", "kernel.run_chunk_kernel-12.py311.1.nbc"])
    (pkg / "kernel.py").write_text("from ._jit import jit\n# edited\n")
    _jit.check_cache(pkg)
    assert not list(cache.glob("*.nb[ic]"))


def test_check_cache_user_wide_folder_when_pycache_is_unusable(tmp_path, monkeypatch):
    monkeypatch.delenv("NUMBA_CACHE_DIR", raising=False)
    wide = tmp_path / "user-wide"
    monkeypatch.setattr(_jit, "_user_wide_dir", lambda: wide)
    pkg = _package(tmp_path)
    (pkg / "__pycache__").write_text("a file where numba's folder would be")
    _jit.check_cache(pkg)
    folder = wide / _CacheLocator.get_suitable_cache_subpath(str(pkg / "integrate.py"))
    assert (folder / _jit.STAMP).exists()
    _put(folder, OURS + ("other.f-1.py311.nbi",))
    (pkg / "integrate.py").write_text("# edited\n")
    _jit.check_cache(pkg)
    assert sorted(p.name for p in folder.iterdir()) == sorted([_jit.STAMP, "other.f-1.py311.nbi"])


# ---------------------------------------------------------------------------------------------
# 6. only rockjit's own files are replaced; one command at a time per output directory
# ---------------------------------------------------------------------------------------------

SPECTRUM = ["spectrum", "--hb", "4", "--ratio-range", "1", "5", "--amplitude-range", "1.5", "9",
            "--grid", "2", "2", "--tol", "1e-3", "--quiet"]


def _no_work(monkeypatch):
    """Any computation of a spectrum fails the test: the refusal must come before it."""
    import importlib
    spectrum_module = importlib.import_module("rockjit.ground.spectrum")
    monkeypatch.setattr(spectrum_module, "run",
                        lambda *a, **k: pytest.fail("not refused before any work"))


def _published(out, files):
    """An earlier rockjit run's ``files`` (name -> bytes) published into ``out``."""
    with rio.OutputDir(out) as o:
        for name, data in files.items():
            with atomic.atomic_open(o.file(name), "wb") as fh:
                fh.write(data)


def test_a_users_files_are_refused_before_any_work(tmp_path, monkeypatch, capsys):
    # a user's summary.json and spectrum.png were replaced, exit 0, nothing said
    from rockjit.cli.main import main
    out = tmp_path / "o"
    out.mkdir()
    (out / "summary.json").write_text('{"mine": true}')
    (out / "spectrum.png").write_bytes(b"my figure")
    (out / "notes.txt").write_text("mine too")
    before = _snapshot(tmp_path)
    _no_work(monkeypatch)
    assert main(SPECTRUM + ["--out", str(out)]) == 2
    err = capsys.readouterr().err
    assert err.startswith(f"rockjit: error: --out {out} holds spectrum.png, summary.json") \
        and err.count("\n") == 1, err
    assert "notes.txt" not in err  # not a name spectrum writes
    assert _snapshot(tmp_path) == before


def test_a_file_changed_since_rockjit_wrote_it_is_the_users(tmp_path):
    out = tmp_path / "o"
    _published(out, {"summary.json": b"{}", "spectrum.png": b"rockjit's figure"})
    patterns = ("spectrum.npz", "spectrum.*")
    from rockjit.storage.ownership import unproven
    assert unproven(out, patterns) == []  # both provably rockjit's: replaced without a word
    with rio.OutputDir(out) as o:
        o.claim(files=patterns)
        o.text("spectrum.png", "a new figure")
    assert (out / "spectrum.png").read_text() == "a new figure"
    (out / "spectrum.png").write_text("a new figure, edited")  # same name, the user's bytes
    os.symlink("summary.json", out / "spectrum.npz")  # a link is never rockjit's
    assert unproven(out, patterns) == ["spectrum.npz", "spectrum.png"]
    assert unproven(out, patterns, figure_format="pdf") == ["spectrum.npz"]
    before = _snapshot(tmp_path)
    with pytest.raises(ValueError, match=r"holds spectrum.npz, spectrum.png, which rockjit did "
                                         r"not write \(or which changed since"):
        rio.OutputDir(out).claim(files=patterns)
    # written without a claim (the API): refused whole when publishing, nothing moved
    o = rio.OutputDir(out)
    o.text("summary.json", "new")
    o.text("spectrum.png", "new")
    with pytest.raises(ValueError, match="holds spectrum.png, .*nothing of this run was "
                                         "published"):
        o.publish()
    o.discard()
    assert _snapshot(tmp_path) == before


def test_a_folder_of_an_older_version_is_refused_saying_how_to_proceed(tmp_path, monkeypatch,
                                                                       capsys):
    # written before rockjit kept a record: its files cannot be told from the user's
    from rockjit.cli.main import main
    out = tmp_path / "o"
    out.mkdir()
    (out / "summary.json").write_text(json.dumps({"command": "spectrum",
                                                  "rockjit_version": "0.1.0"}))
    (out / "spectrum.npz").write_bytes(b"PK\x03\x04")
    before = _snapshot(tmp_path)
    _no_work(monkeypatch)
    assert main(SPECTRUM + ["--out", str(out)]) == 2
    err = capsys.readouterr().err
    assert "says rockjit 0.1.0 wrote" in err and "choose an empty or new --out" in err
    assert err.count("\n") == 1 and _snapshot(tmp_path) == before
    # a record that cannot be read proves nothing either
    _published(tmp_path / "d", {"spectrum.npz": b"x"})
    (tmp_path / "d" / RECORD).write_text("{not json")
    with pytest.raises(ValueError, match="record of the files it wrote there .* cannot be read"):
        rio.OutputDir(tmp_path / "d").claim(files=("spectrum.npz",))


def test_the_record_lists_every_file_and_survives_a_run_killed_between_moves(tmp_path,
                                                                            monkeypatch):
    out = tmp_path / "o"
    _published(out, {"a.npz": b"old a", "b.npz": b"old b", "summary.json": b"old"})
    real = os.replace
    moves = []

    def dies_after_two(src, dst):
        if Path(dst).parent == out:
            moves.append(Path(dst).name)
            if len(moves) == 3:
                raise SystemExit("killed")  # as if the process died here
        return real(src, dst)

    o = rio.OutputDir(out)
    o.text("a.npz", "new a")
    o.text("b.npz", "new b")
    o.text("summary.json", "new")
    monkeypatch.setattr(os, "replace", dies_after_two)
    with pytest.raises(SystemExit):
        o.publish()
    monkeypatch.undo()
    o._unlock()
    assert moves[:2] == [RECORD, "a.npz"]  # the record first
    assert (out / "a.npz").read_text() == "new a" and (out / "b.npz").read_text() == "old b"
    from rockjit.storage.ownership import unproven
    assert unproven(out, ("*.npz",)) == []  # the new a and the old b: both rockjit's
    record = json.loads((out / RECORD).read_text())
    import hashlib
    for name in ("a.npz", "b.npz", "summary.json"):  # against digests computed here
        data = (out / name).read_bytes()
        assert {"size": len(data), "sha256": hashlib.sha256(data).hexdigest()} in \
            record["files"][name]["versions"]


def test_one_command_at_a_time_per_output_directory(tmp_path):
    for out in (tmp_path / "new", tmp_path / "existing"):
        if out.name == "existing":
            out.mkdir()
        first = rio.OutputDir(out)
        first.claim()
        with pytest.raises(ValueError, match=f"^out {out} is being written by another rockjit "
                                             f"run \\(pid {os.getpid()}, since "):
            rio.OutputDir(out).claim()
        first.text("summary.json", "first")
        first.publish()
        with rio.OutputDir(out) as second:  # free again once the first has published
            second.text("summary.json", "second")
        assert (out / "summary.json").read_text() == "second"
    assert sorted(os.listdir(tmp_path)) == ["existing", "new"]  # no lock file left


CHILD_CLAIM = """
    import sys, time
    from rockjit.storage import output_dir as rio
    out = rio.OutputDir(sys.argv[1])
    out.claim(name="--out")
    print("claimed", flush=True)
    time.sleep(120)
"""


def test_a_second_command_is_refused_until_the_first_ends_however_it_ends(tmp_path, capsys):
    from rockjit.cli.main import main
    out = tmp_path / "o"
    child = _run_child(CHILD_CLAIM, out)
    _expect_line(child, "claimed")
    assert main(["cor", "--quiet", "--out", str(out)]) == 2
    err = capsys.readouterr().err
    assert err == (f"rockjit: error: --out {out} is being written by another rockjit run "
                   f"(pid {child.pid}, since {err.split('since ')[1].split(')')[0]}); wait for "
                   f"it to finish, or choose another --out\n")
    child.kill()  # SIGKILL: no clean-up of its own; the kernel gives its lock back
    child.wait(timeout=60)
    assert main(["cor", "--quiet", "--out", str(out)]) == 0
    assert sorted(os.listdir(tmp_path)) == ["o"]


def test_a_run_that_finds_out_published_by_another_meanwhile_refuses(tmp_path):
    # --out absent when the first run took it (its lock beside --out); made and published into
    # by a second run (its lock inside) before the first publishes
    out = tmp_path / "o"
    first = rio.OutputDir(out)
    first.claim()
    first.text("summary.json", "first")
    out.mkdir()
    with rio.OutputDir(out) as second:
        second.text("summary.json", "second")
    with pytest.raises(ValueError, match="was written by another rockjit run while this one "
                                         "ran; nothing of this run was published"):
        first.publish()
    first.discard()
    assert (out / "summary.json").read_text() == "second"
    assert sorted(os.listdir(tmp_path)) == ["o"]


# ---------------------------------------------------------------------------------------------
# 7. a figure that cannot be drawn never loses the data
# ---------------------------------------------------------------------------------------------

def test_a_figure_that_cannot_be_drawn_keeps_a_trajectorys_data(tmp_path, monkeypatch, capsys):
    import importlib
    from rockjit.cli.main import main
    argv = ["trajectory", "--hb", "1", "--alpha", "0.6", "--omega", "1.3", "--periods", "20",
            "--n-steps", "64", "--quiet", "--format", "svg"]
    assert main(argv + ["--out", str(tmp_path / "drawn")]) == 0

    def broken(*a, **k):
        raise RuntimeError("no room\nfor the legend")

    monkeypatch.setattr(importlib.import_module("rockjit.plotting.timeseries"), "fig_trajectory",
                        broken)
    out = tmp_path / "failed"
    capsys.readouterr()
    assert main(argv + ["--out", str(out)]) == 3
    assert capsys.readouterr().err == (
        "rockjit: warning: trajectory.svg could not be drawn (RuntimeError: no room for the "
        "legend); the data were written without it (exit status 3)\n")
    assert sorted(os.listdir(out)) == [RECORD, "summary.json", "trajectory.npz"]
    summary = json.loads((out / "summary.json").read_text())
    assert summary["figures_failed"] == [{"name": "trajectory.svg",
                                          "error": "RuntimeError: no room for the legend"}]
    with np.load(out / "trajectory.npz") as got, \
            np.load(tmp_path / "drawn" / "trajectory.npz") as ref:
        assert sorted(got.files) == sorted(ref.files)
        for k in ref.files:
            assert np.array_equal(got[k], ref[k], equal_nan=True), k
    # the record proves what was written: a rerun that can draw replaces the files
    monkeypatch.undo()
    assert main(argv + ["--out", str(out)]) == 0
    assert sorted(os.listdir(out)) == [RECORD, "summary.json", "trajectory.npz",
                                       "trajectory.svg"]


# ---------------------------------------------------------------------------------------------
# 8. spectra and fragility analyses resume from their chunk stores
# ---------------------------------------------------------------------------------------------

class _Stop(Exception):
    pass


def _interrupted_then_resumed(compute, store, after):
    """``compute(execution)`` stopped by its progress callback once ``after`` chunks are done,
    then run again on the same store: (the cells counted done when the rerun started, its
    result)."""
    from rockjit import Execution
    calls = []

    def stop(done, total):
        calls.append(done)
        if len(calls) == after + 1:  # the first call is before any chunk
            raise _Stop

    with pytest.raises(_Stop):
        compute(Execution(chunk=2, store=store, progress=stop))
    assert len([p for p in Path(store).iterdir() if p.name.startswith("cells-")]) == after
    seen = []
    res = compute(Execution(chunk=2, store=store, progress=lambda d, t: seen.append(d)))
    return seen[0], res


def test_an_interrupted_spectrum_resumes_bit_for_bit(tmp_path):
    # run_batch ignored Execution.store: nothing was kept and a rerun started from zero
    from rockjit import Block, Execution, Pulse, spectrum
    args = (Block(hb=4), Pulse("sine"), [1.0, 2.0, 4.0], [1.5, 3.0, 6.0, 9.0])

    def compute(ex):
        return spectrum(*args, tol=1e-3, execution=ex)

    whole = spectrum(*args, tol=1e-3, execution=Execution(chunk=2, progress=False))
    done, resumed = _interrupted_then_resumed(compute, tmp_path / "store", 3)
    assert done == 6  # three chunks of two cells loaded, not computed again
    for name in ("outcome", "max_rotation", "t_overturn", "n_impacts", "min_overturn",
                 "min_mode", "min_no_impact"):
        a, b = getattr(resumed, name), getattr(whole, name)
        assert a.dtype == b.dtype and a.tobytes() == b.tobytes(), name


def test_an_interrupted_fragility_analysis_resumes_bit_for_bit(tmp_path):
    from rockjit import Block, Execution, Record, fragility
    rng = np.random.default_rng(3)
    t = np.arange(300) * 0.01
    records = [Record(rng.normal(0, 0.1, t.size) * np.sin(np.pi * t / t[-1]), 0.01,
                      name=f"r{i}") for i in range(2)]
    args = (Block(hb=3), records, [0.5], [1.0, 2.5, 4.0])

    def compute(ex):
        return fragility(*args, laws=("housner", "mao"), execution=ex)

    whole = compute(Execution(chunk=2, progress=False))
    done, resumed = _interrupted_then_resumed(compute, tmp_path / "store", 2)
    assert done == 4
    for name in ("outcome", "max_rotation", "t_overturn"):
        a, b = getattr(resumed, name), getattr(whole, name)
        assert a.dtype == b.dtype and a.tobytes() == b.tobytes(), name
    # another analysis is not mixed with these chunks
    with pytest.raises(ValueError, match="holds the chunks of a different computation"):
        fragility(Block(hb=3), records, [0.5], [1.0, 2.5, 4.5], laws=("housner", "mao"),
                  execution=Execution(chunk=2, store=tmp_path / "store", progress=False))


def test_a_run_whose_out_appeared_after_its_claim_respects_the_lock_inside(tmp_path):
    out = tmp_path / "o"
    first = rio.OutputDir(out)
    first.claim()  # --out absent: the lock beside it
    out.mkdir()
    second = rio.OutputDir(out)
    second.claim()  # --out present: the lock inside it
    first.text("summary.json", "first")  # staged inside --out now
    with pytest.raises(ValueError, match="is being written by another rockjit run"):
        first.publish()
    first.discard()
    second.text("summary.json", "second")
    second.publish()
    assert (out / "summary.json").read_text() == "second"
    assert sorted(os.listdir(out)) == [RECORD, "summary.json"]
