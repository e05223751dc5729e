"""Recorded ground motions: the readers agree with each other, the record is the piecewise-linear
forcing docs/theory/ground-motions.md describes, played in model time ``t sqrt(g/R)``, and bad
records are refused with one line that names the file and the problem.

Checked: a record read from a PEER ``.AT2`` file, from a CSV file and from arrays is the same
record and gives the same run, bit for bit; ``f`` at the samples, between them and after the
end; the uplift windows against a dense evaluation; the PGV of a known history; that a record
sampled from a one-sine pulse on a block of size ``R`` reproduces the pulse's run (the time
scaling), to the interpolation error; the FEMA P695 sets when the ``records`` extra is there.
"""

from __future__ import annotations

import math
import os
import threading
import tracemalloc

import numpy as np
import pytest

import rockjit
from rockjit import Block, Pulse, Record, Scipy, Transient
from rockjit.ground import read_at2, read_record, read_table
from rockjit.ground.records import G

TIGHT = Scipy("DOP853", rtol=1e-11, atol=1e-13)


def _accel(n=400, dt=0.01, seed=3):
    """A smooth random-looking history in g, starting and ending at zero."""
    rng = np.random.default_rng(seed)
    t = np.arange(n) * dt
    a = sum(rng.normal(0, 0.15) * np.sin(2 * np.pi * f * t + rng.uniform(0, 6))
            for f in (0.7, 1.3, 2.9, 4.1))
    return a * np.sin(np.pi * t / t[-1]) ** 2


def write_at2(path, a, dt, units="G", layout="new"):
    lines = ["PEER NGA STRONG MOTION DATABASE RECORD",
             "Synthetic, 1/1/2000, test station, 000",
             f"ACCELERATION TIME SERIES IN UNITS OF {units}"]
    if layout == "new":
        lines.append(f"NPTS=  {len(a)}, DT=   {dt:.4f} SEC")
    else:
        lines.append(f"  {len(a)}   {dt:.4f}   NPTS, DT")
    for k in range(0, len(a), 5):
        lines.append("".join(f"{v:15.7E}" for v in a[k:k + 5]))
    path.write_text("\n".join(lines) + "\n")
    return path


def write_csv(path, t, a, header="time (s),acceleration (g)", sep=","):
    rows = [header] if header else []
    rows += [f"{float(x)!r}{sep}{float(y)!r}" for x, y in zip(t, a)]
    path.write_text("\n".join(rows) + "\n")
    return path


def test_at2_csv_and_arrays_give_the_same_record_and_run(tmp_path):
    dt = 0.01
    a = np.round(_accel(dt=dt), 7)  # what the .AT2's seven digits keep
    t = np.arange(a.size) * dt
    recs = [read_at2(write_at2(tmp_path / "r.AT2", a, dt), size=1.0),
            read_at2(write_at2(tmp_path / "old.at2", a, dt, layout="old"), size=1.0),
            read_table(write_csv(tmp_path / "r.csv", t, a), size=1.0),
            read_record(write_csv(tmp_path / "r.txt", t, a, header=None, sep="  "), size=1.0),
            Record.from_arrays(t, a, size=1.0), Record(a, dt, size=1.0)]
    for r in recs:
        assert r.n == a.size and r.dt == pytest.approx(dt, rel=1e-12)
        np.testing.assert_array_equal(r.accel, a)
    block = Block(hb=3, law="mao")
    scale = 2.2 / (recs[0].pga * block.hb)
    runs = [rockjit.simulate(block, r.scaled(scale), method=TIGHT,
                             integration=Transient(free_time=20.0)) for r in recs]
    assert runs[0].n_impacts > 0  # the comparison has something to compare
    for r in runs[1:]:
        assert r.status == runs[0].status
        # dt from a time column is (t[-1] - t[0]) / (n - 1): equal to rounding
        np.testing.assert_allclose(r.impacts, runs[0].impacts, rtol=1e-9, atol=1e-12)
        assert r.max_rotation == pytest.approx(runs[0].max_rotation, rel=1e-9)
    # the same record from the same numbers runs identically
    assert runs[0].impacts.tolist() == runs[1].impacts.tolist()


def test_piecewise_linear_in_model_time():
    a = np.array([0.0, 0.2, -0.4, 0.1])
    r = Record(a, 0.02, size=2.0)
    tf = math.sqrt(G / 2.0)
    assert r.time_factor == pytest.approx(tf) and r.dt_model == pytest.approx(0.02 * tf)
    assert r.p == pytest.approx(math.sqrt(3 * G / 8.0))
    assert Record(a, 0.02, p=r.p).size == pytest.approx(2.0)
    tk = np.arange(4) * r.dt_model
    np.testing.assert_allclose(r.f(tk), a, atol=1e-15)
    np.testing.assert_allclose(r.f(tk[:-1] + 0.5 * r.dt_model), 0.5 * (a[1:] + a[:-1]))
    f = r.scalar()
    for x in np.linspace(-0.1, r.end + 0.1, 57):
        assert f(float(x)) == pytest.approx(float(r.f(x)), abs=1e-15)
    assert r.f(r.end + 1e-9) == 0.0 and r.f(-1e-9) == 0.0
    assert r.scaled(3.0).f(tk[2]) == pytest.approx(-1.2)
    assert r.scaled(3.0).pga == pytest.approx(1.2)


def test_pgv_of_a_known_history():
    # a constant 0.1 g for 1 s, then back: v = g * 0.1 * t, largest 0.981 m/s (trapezoids
    # are exact on the linear pieces)
    dt = 0.01
    a = np.r_[np.zeros(1), np.full(101, 0.1), np.zeros(1)]
    r = Record(a, dt)
    assert r.pgv == pytest.approx(G * 0.1 * (101 * dt), rel=1e-12)


@pytest.mark.parametrize("threshold", [0.05, 0.13, 0.3])
def test_windows_match_a_dense_evaluation(threshold):
    r = Record(_accel(n=300), 0.01, size=0.7)
    w = r.windows(threshold)
    t = np.linspace(0.0, r.end, 200_001)
    inside = np.zeros(t.size, dtype=bool)
    for t0, t1, sg in w:
        sel = (t > t0) & (t < t1)
        inside |= sel
        assert np.all(sg * r.f(t[sel]) > threshold - 1e-12)
        assert abs(abs(r.f(t0)) - threshold) < 1e-12 or t0 == 0.0
    np.testing.assert_array_equal(inside | (np.abs(r.f(t)) <= threshold + 1e-12),
                                  np.ones(t.size, dtype=bool))
    assert np.all(np.abs(r.f(t[~inside])) <= threshold + 1e-9)


def test_a_sampled_pulse_plays_like_the_pulse():
    """A one-sine pulse sampled into a record of a block of size R is, in model time, the
    pulse itself: its run agrees with the pulse's to the linear interpolation's error,
    O(dt^2): uplift and the first impacts, at two sample steps."""
    block = Block(hb=4, law="housner", xi=0.0)
    pulse = Pulse("sine", ratio=2.0, amplitude=1.15).bind(block)
    R = 2.5
    tf = math.sqrt(G / R)
    settings = Transient(duration=6.0)
    ref = rockjit.simulate(block, pulse, method=TIGHT, integration=settings)
    assert ref.n_impacts >= 3 and ref.status == "time_limit"
    errs = []
    for m in (800, 1600):
        dt_model = pulse.end / m
        tk = np.arange(m + 1) * dt_model
        rec = Record(pulse.f(tk), dt_model / tf, size=R)
        assert rec.end == pytest.approx(pulse.end, rel=1e-12)
        run = rockjit.simulate(block, rec, method=TIGHT, integration=settings)
        assert run.n_impacts == ref.n_impacts
        assert abs(run.t_uplift - ref.t_uplift) < 1e-5
        errs.append(np.max(np.abs(run.impacts[:, :2] - ref.impacts[:, :2])))
    assert errs[1] < 3e-4
    assert 3.0 < errs[0] / errs[1] < 5.0  # second order in the sample step


def test_a_record_needs_the_blocks_size():
    r = Record(_accel(), 0.01)
    with pytest.raises(ValueError, match="size"):
        rockjit.simulate(Block(hb=2), r, method="scipy")
    with pytest.raises(ValueError, match="size"):
        r.f(0.1)
    with pytest.raises(ValueError, match="not both"):
        Record(_accel(), 0.01, size=1.0, p=2.0)
    with pytest.raises(ValueError, match="size must be in"):
        Record(_accel(), 0.01, size=0.0)


# ---- bad records ------------------------------------------------------------------------------

def _at2(tmp_path, body, units="G", head=None):
    p = tmp_path / "bad.AT2"
    p.write_text("PEER\nline two\n" + f"ACCELERATION TIME SERIES IN UNITS OF {units}\n"
                 + (head or "NPTS=  3, DT=   .0100 SEC") + "\n" + body + "\n")
    return p


BAD = [
    ("empty csv", "bad.csv", "", "no samples"),
    ("header only", "bad.csv", "time (s),acc (g)\n", "no samples"),
    ("nan", "bad.csv", "0,0\n0.01,nan\n0.02,0.1\n", "not finite"),
    ("inf", "bad.csv", "0,0\n0.01,0.1\n0.02,-inf\n", "not finite"),
    ("time goes back", "bad.csv", "0,0\n0.02,0.1\n0.01,0.1\n", "does not increase"),
    ("repeated time", "bad.csv", "0,0\n0.01,0.1\n0.01,0.1\n", "does not increase"),
    ("uneven", "bad.csv", "0,0\n0.01,0.1\n0.03,0.1\n0.04,0\n", "uneven"),
    ("m/s^2", "bad.csv", "time (s),acceleration (m/s^2)\n0,0\n0.01,1\n", "not g"),
    ("cm/s2 brackets", "bad.csv", "t [s]; a [cm/s2]\n0;0\n0.01;1\n", "not g"),
    ("time in ms", "bad.csv", "time (ms),acc (g)\n0,0\n10,0.1\n", "not seconds"),
    ("units column", "bad.csv", "time,accel,units\n0,0,g\n0.01,0.1,m/s2\n", "not g"),
    ("one column", "bad.csv", "0\n0.01\n", "two are needed"),
    ("three columns", "bad.csv", "0,0,1\n0.01,0.1,1\n", "two are expected"),
    ("text value", "bad.csv", "0,0\n0.01,abc\n", "not a number"),
    ("one sample", "bad.csv", "0,0.1\n", "at least two"),
]


@pytest.mark.parametrize("name, fname, text, problem", BAD, ids=[b[0] for b in BAD])
def test_bad_table_is_refused_in_one_line_naming_the_file(tmp_path, name, fname, text,
                                                          problem):
    p = tmp_path / fname
    p.write_text(text)
    with pytest.raises(ValueError) as info:
        read_record(p, size=1.0)
    msg = str(info.value)
    assert "\n" not in msg and str(p) in msg and problem in msg, msg


AT2_BAD = [
    ("cm/s/s units", dict(body="0.1 0.2 0.3", units="CM/S/S"), "not g"),
    ("npts mismatch", dict(body="0.1 0.2"), "NPTS = 3"),
    ("nan sample", dict(body="0.1 NaN 0.3"), "not finite"),
    ("text sample", dict(body="0.1 x 0.3"), "not a number"),
    ("no dt", dict(body="0.1 0.2 0.3", head="NPTS= 3"), "NPTS and DT"),
    ("zero dt", dict(body="0.1 0.2 0.3", head="NPTS= 3, DT= 0.0 SEC"), "not positive"),
    ("empty", dict(body="", head="NPTS= 0, DT= 0.01 SEC"), "no samples"),
]


@pytest.mark.parametrize("name, kw, problem", AT2_BAD, ids=[b[0] for b in AT2_BAD])
def test_bad_at2_is_refused_in_one_line_naming_the_file(tmp_path, name, kw, problem):
    p = _at2(tmp_path, **kw)
    with pytest.raises(ValueError) as info:
        read_record(p)
    msg = str(info.value)
    assert "\n" not in msg and str(p) in msg and problem in msg, msg


def test_missing_file_and_short_header_are_refused(tmp_path):
    with pytest.raises(ValueError, match=r"record .*nope\.AT2: cannot be read"):
        read_record(tmp_path / "nope.AT2")
    p = tmp_path / "short.AT2"
    p.write_text("only\nthree\nlines\n")
    with pytest.raises(ValueError, match="fewer than four header lines"):
        read_record(p)


@pytest.mark.parametrize("accel, problem", [
    ([], "no samples"), ([0.1], "one sample"), ([0.0, np.nan], "not finite"),
    ([[0.0, 1.0]], "one column"), (["a", "b"], "not numbers")])
def test_bad_arrays_are_refused(accel, problem):
    with pytest.raises(ValueError, match=problem):
        Record(accel, 0.01, name="mine")


def test_arrays_with_a_time_column_are_checked():
    with pytest.raises(ValueError, match="uneven"):
        Record.from_arrays([0, 0.01, 0.025], [0, 1, 0], name="mine")
    with pytest.raises(ValueError, match="does not increase"):
        Record.from_arrays([0, 0.01, 0.01], [0, 1, 0], name="mine")
    with pytest.raises(ValueError, match="3 times for 2"):
        Record.from_arrays([0, 0.01, 0.02], [0, 1], name="mine")
    # a record that starts later keeps its step
    r = Record.from_arrays([5.0, 5.01, 5.02], [0, 1, 0], name="mine")
    assert r.dt == pytest.approx(0.01)


def test_fema_p695_sets():
    pytest.importorskip("h5py")
    pytest.importorskip("hdf5plugin")
    from rockjit.ground.fema import fema_set
    try:
        far = fema_set("farfield", size=1.0)
    except ValueError as exc:
        pytest.skip(str(exc))
    assert len(far) == 44 and len(fema_set("nearfield")) == 56
    assert len(fema_set("nearfield-pulse", components=("a",))) == 14
    # FEMA P695 table A-4A: record 1 (Northridge, Beverly Hills - Mulhol), PGAmax 0.52 g and
    # PGVmax 63 cm/s over its two components
    first = [r for r in far if r.name.startswith("farfield 1a ") or
             r.name.startswith("farfield 1b ")]
    assert len(first) == 2 and "Northridge" in first[0].name
    assert max(r.pga for r in first) == pytest.approx(0.52, abs=0.005)
    assert max(r.pgv for r in first) == pytest.approx(0.63, abs=0.01)
    assert all(r.dt > 0 and r.n > 100 and r.size == 1.0 for r in far)
    with pytest.raises(ValueError, match="record set must be one of"):
        fema_set("nearby")


def test_a_pickled_record_is_the_same_read_only_record():
    import pickle
    r = Record(_accel(), 0.01, size=2.0, scale=1.5, name="mine")
    q = pickle.loads(pickle.dumps(r))
    assert (q.name, q.dt, q.size, q.scale) == (r.name, r.dt, r.size, r.scale)
    np.testing.assert_array_equal(q.accel, r.accel)
    assert not q.accel.flags.writeable
    with pytest.raises(ValueError, match="read-only"):
        q.accel[0] = 1.0


# ---- what is not a record file: devices, pipes, other encodings, endless or huge files -------

def _refusal(path, **kw):
    with pytest.raises(ValueError) as info:
        read_record(path, size=1.0, **kw)
    msg = str(info.value)
    assert "\n" not in msg, msg
    return msg


@pytest.mark.parametrize("path", ["/dev/null", "/dev/zero"])
def test_a_device_is_refused_as_not_a_regular_file(path):
    # /dev/zero and /dev/urandom were read to the end of memory (MemoryError); /dev/null
    # read as an empty file. The device is refused before a byte is read
    if not os.path.exists(path):
        pytest.skip(f"no {path} here")
    msg = _refusal(path)
    assert path in msg and "character device, not a regular file" in msg, msg


def test_a_directory_is_refused_as_not_a_regular_file(tmp_path):
    assert "a directory, not a regular file" in _refusal(tmp_path)


def test_a_fifo_is_refused_without_waiting_for_a_writer(tmp_path):
    # opening a FIFO for reading blocked until some other process wrote to it
    if not hasattr(os, "mkfifo"):
        pytest.skip("no FIFOs here")
    fifo = tmp_path / "motion.csv"
    os.mkfifo(fifo)
    got = []
    reader = threading.Thread(target=lambda: got.append(_refusal(fifo)), daemon=True)
    reader.start()
    reader.join(10.0)
    if reader.is_alive():  # release the blocked reader before failing
        os.close(os.open(fifo, os.O_WRONLY | os.O_NONBLOCK))
        reader.join(10.0)
        pytest.fail("reading a FIFO waited for a writer")
    assert got and "a pipe (FIFO), not a regular file" in got[0], got


@pytest.mark.parametrize("path", [None, 3, "", b"motion.csv", 1.5])
def test_a_path_that_is_not_a_path_is_a_value_error(path):
    # None and 3 raised TypeError from inside pathlib
    with pytest.raises(ValueError, match=r"^record path must be a file's path"):
        read_record(path)


@pytest.mark.parametrize("encoding", ["utf-16", "utf-16-le", "utf-16-be", "utf-32"])
def test_a_utf16_or_utf32_file_is_refused_naming_its_encoding(tmp_path, encoding):
    p = tmp_path / "motion.csv"
    p.write_bytes("time (s),acc (g)\n0,0\n0.01,0.1\n0.02,0\n".encode(encoding))
    msg = _refusal(p)
    assert str(p) in msg and f"{encoding[:6].upper()} encoded" in msg, msg


def test_a_utf8_byte_order_mark_is_read_as_text(tmp_path):
    p = tmp_path / "motion.csv"
    p.write_bytes(b"\xef\xbb\xbf0,0\n0.01,0.1\n0.02,0\n")
    np.testing.assert_array_equal(read_record(p, size=1.0).accel, [0.0, 0.1, 0.0])


@pytest.mark.parametrize("value", ["1_0", "1_000.5", "\u0661", "\uff11", "0.1e1_0"])
@pytest.mark.parametrize("kind", ["table", "first row", "at2"])
def test_numbers_only_in_ascii_decimals(tmp_path, value, kind):
    # Python's float() reads '1_0' as 10 and other scripts' digits as digits; the command
    # line refuses them, and so does a record file, on its first row too (not skipped as a
    # header)
    if kind == "table":
        p = tmp_path / "motion.csv"
        p.write_text(f"0,0\n0.01,{value}\n0.02,0\n", encoding="utf-8")
    elif kind == "first row":
        p = tmp_path / "motion.csv"
        p.write_text(f"0,{value}\n0.01,0\n0.02,0\n", encoding="utf-8")
    else:
        p = _at2(tmp_path, f"0.0 {value} 0.0")
    msg = _refusal(p)
    assert repr(value) in msg and "not a number" in msg, msg


def test_the_sample_limit_stops_the_reading(tmp_path, monkeypatch):
    # the limit was checked after the whole file was read: here the rows past the limit are
    # not even looked at (the bad row after them would be refused otherwise)
    from rockjit.ground import records
    monkeypatch.setattr(records, "MAX_SAMPLES", 1000)
    p = tmp_path / "long.csv"
    p.write_text("".join(f"{0.01 * k:.2f},0.1\n" for k in range(1500)) + "0.01,oops\n")
    assert "more than 1000 samples" in _refusal(p)
    q = _at2(tmp_path, " ".join(["0.1"] * 1500 + ["oops"]), head="NPTS= 1500, DT= .01 SEC")
    assert "more than 1000 samples" in _refusal(q)


def test_the_byte_limit_is_checked_while_reading(tmp_path, monkeypatch):
    from rockjit.ground import records
    monkeypatch.setattr(records, "MAX_BYTES", 4096)
    p = tmp_path / "big.csv"
    p.write_text("".join(f"{0.01 * k:.2f},0.1\n" for k in range(1000)))
    assert "bytes, more than 4096" in _refusal(p)  # known from its size before reading
    # a file that says it is empty and is not (the kernel's files): counted while read
    status = "/proc/self/status"
    if not os.path.exists(status) or os.stat(status).st_size:
        pytest.skip("no regular file that understates its size here")
    monkeypatch.setattr(records, "MAX_BYTES", 8)  # passed within the first line
    assert "more than 8 bytes" in _refusal(status)


def test_a_long_table_is_read_in_modest_memory(tmp_path):
    # 10^7 lines peaked at 2.5 GB (a Python tuple per row), ~190 bytes a line here. The
    # samples themselves take 16 bytes a line (time and acceleration), their checks and the
    # record's own copy a few times that; allow 100
    n = 20_000
    p = tmp_path / "long.csv"
    dt = 0.001
    p.write_text("time (s),acc (g)\n" + "".join(f"{k * dt:.3f},{0.1 * (k % 7 - 3):.1f}\n"
                                                for k in range(n)))
    tracemalloc.start()
    try:
        rec = read_record(p, size=1.0)
        peak = tracemalloc.get_traced_memory()[1]
    finally:
        tracemalloc.stop()
    assert rec.n == n and rec.dt == pytest.approx(dt)
    np.testing.assert_array_equal(rec.accel, [float(f"{0.1 * (k % 7 - 3):.1f}")
                                              for k in range(n)])
    assert peak < 100 * n, f"{peak / n:.0f} bytes a line"
