"""Reading recorded ground motions: :class:`Record` (:mod:`rockjit.plugs.record`) from files.

Records come from arrays (:class:`Record`, :meth:`Record.from_arrays`), from a PEER NGA
``.AT2`` file (:func:`read_at2`), from a two-column text or CSV file of time in seconds and
acceleration in ``g`` (:func:`read_table`), or from the FEMA P695 record sets
(:func:`rockjit.ground.fema.fema_set`). A bad record (empty, not finite, time not increasing or
unevenly spaced, acceleration not in ``g``) is refused with one ``ValueError`` line that names the
file and the problem. A record file must be a regular file of UTF-8 (or ASCII) text with numbers
in ASCII decimals; it is read a line at a time and refused as soon as it passes
``MAX_SAMPLES`` samples or ``MAX_BYTES`` bytes, so that a device, a pipe or a huge file
neither blocks nor fills the memory.
"""

from __future__ import annotations

import codecs
import math
import os
import re
import stat
from array import array
from pathlib import Path

import numpy as np

from ..plugs.record import (G, MAX_SAMPLES, SIZE_RANGE, Record, _even_step, _named, _numbers,
                            _refuse)

__all__ = ["G", "Record", "SIZE_RANGE", "read_at2", "read_record", "read_table"]

#: Largest record file read, in bytes: room for MAX_SAMPLES rows of two numbers and their
#: separators. Both limits are checked while reading, which stops as soon as one is passed.
MAX_BYTES = 40 * MAX_SAMPLES
#: Longest line of a record file, in bytes.
MAX_LINE = 2**20


def _file_kind(mode):
    for test, kind in ((stat.S_ISDIR, "a directory"), (stat.S_ISFIFO, "a pipe (FIFO)"),
                       (stat.S_ISCHR, "a character device"), (stat.S_ISBLK, "a block device"),
                       (stat.S_ISSOCK, "a socket")):
        if test(mode):
            return kind
    return "not a plain file"


def _path_of(path):
    """``path`` as a file name, or a ``ValueError`` naming what it is instead."""
    if isinstance(path, os.PathLike):
        path = os.fspath(path)
    if not isinstance(path, str) or not path:
        raise ValueError(f"record path must be a file's path, a non-empty str or a path "
                         f"(got {path!r})")
    return path


def _encoding_problem(raw):
    """Why the first line ``raw`` (bytes) is not UTF-8 text, or ``None``."""
    for bom, name in ((codecs.BOM_UTF32_LE, "UTF-32"), (codecs.BOM_UTF32_BE, "UTF-32"),
                      (codecs.BOM_UTF16_LE, "UTF-16"), (codecs.BOM_UTF16_BE, "UTF-16")):
        if raw.startswith(bom):
            return (f"it is {name} encoded (it starts with a {name} byte order mark); save it "
                    f"as UTF-8 or ASCII text")
    return None


def _lines(path):
    """The lines of a record file as ``(number, text)``, read one at a time: the file must be a
    regular file (not a device, a pipe or a directory, which could be endless or block) of
    UTF-8 or ASCII text, at most ``MAX_BYTES`` long, no line longer than ``MAX_LINE``."""
    src = str(path)
    try:  # O_NONBLOCK: opening a FIFO must not wait for a writer
        fd = os.open(path, os.O_RDONLY | getattr(os, "O_NONBLOCK", 0))
    except OSError as exc:
        raise ValueError(f"record {src}: cannot be read ({exc.strerror or exc})") from None
    try:
        st = os.fstat(fd)
        if not stat.S_ISREG(st.st_mode):
            _refuse(src, f"it is {_file_kind(st.st_mode)}, not a regular file")
        if st.st_size > MAX_BYTES:
            _refuse(src, f"it holds {st.st_size} bytes, more than {MAX_BYTES}")
        fh = os.fdopen(fd, "rb")
    except BaseException:
        os.close(fd)
        raise
    with fh:
        total = 0
        lineno = 0
        while True:
            try:
                raw = fh.readline(MAX_LINE + 1)
            except OSError as exc:
                raise ValueError(f"record {src}: cannot be read "
                                 f"({exc.strerror or exc})") from None
            if not raw:
                return
            lineno += 1
            total += len(raw)
            if total > MAX_BYTES:
                _refuse(src, f"it holds more than {MAX_BYTES} bytes")
            if len(raw) > MAX_LINE:
                _refuse(src, f"line {lineno} is longer than {MAX_LINE} bytes")
            if lineno == 1:
                problem = _encoding_problem(raw)
                if problem:
                    _refuse(src, problem)
                if raw.startswith(codecs.BOM_UTF8):
                    raw = raw[len(codecs.BOM_UTF8):]
            if b"\x00" in raw:
                even, odd = raw[0::2].strip(b"\x00\r\n"), raw[1::2].strip(b"\x00\r\n")
                utf16 = not even or not odd  # ASCII in UTF-16: every other byte is NUL
                _refuse(src, f"line {lineno} holds NUL bytes: "
                             + ("it looks UTF-16 encoded; save it as UTF-8 or ASCII text"
                                if utf16 else "it is not a text file"))
            yield lineno, raw.decode("utf-8", errors="replace")


#: A number in a record file: ASCII decimal digits only (no ``_`` separators, no other
#: scripts' digits), or ``nan`` / ``inf`` (refused as not finite, by name).
_DECIMAL = r"[-+]?(?:[0-9]+\.?[0-9]*|\.[0-9]+)(?:[{exponent}][-+]?[0-9]+)?"
_NOT_FINITE = r"[-+]?(?:nan|inf|infinity)"
_NUMBER = re.compile(_DECIMAL.format(exponent="eE") + "|" + _NOT_FINITE, re.IGNORECASE)
#: The same with Fortran's ``D`` exponents (``.AT2`` files).
_NUMBER_D = re.compile(_DECIMAL.format(exponent="eEdD") + "|" + _NOT_FINITE, re.IGNORECASE)


_SEPARATORS = re.compile(r"[,;\s]+")
#: A row of a table that is two plain numbers (and nothing else but separators).
_ROW = re.compile(r"[ \t]*({0})[ \t]*[,; \t][ \t]*({0})[ \t]*\r?\n?".format(
    _DECIMAL.format(exponent="eE")))


def _number(token, pattern=_NUMBER):
    """``token`` as a float, or ``None`` where it is not a number as a record writes one."""
    if pattern.fullmatch(token) is None:
        return None
    return float(token.replace("D", "E").replace("d", "e"))


def _too_many(src):
    _refuse(src, f"it holds more than {MAX_SAMPLES} samples")


_FLOAT = r"[-+]?(?:\d+\.?\d*|\.\d+)(?:[eEdD][-+]?\d+)?"


def read_at2(path, *, size=None, p=None, name=None) -> Record:
    """A PEER NGA ``.AT2`` record: four header lines (the third states the units, which must
    be ``g``; the fourth ``NPTS`` and ``DT``, in either of the database's two layouts), then
    the accelerations.

    Parameters
    ----------
    path : str or path
        The file.
    size : float, optional
        The block's half-diagonal ``R`` in metres (see :class:`rockjit.Record`).
    p : float, optional
        The block's frequency parameter in rad/s, instead of ``size``.
    name : str, optional
        The record's name; default the file's name without its suffix.

    Returns
    -------
    Record
        The record; a bad file is refused with one ``ValueError`` line naming it and the
        problem.

    Examples
    --------
    >>> import pathlib, tempfile
    >>> from rockjit.ground import read_at2
    >>> header = ("PEER NGA STRONG MOTION DATABASE RECORD\\nAn example, component 000\\n"
    ...           "ACCELERATION TIME SERIES IN UNITS OF G\\nNPTS=    5, DT=   .0100 SEC\\n")
    >>> with tempfile.TemporaryDirectory() as d:
    ...     path = pathlib.Path(d) / "example.AT2"
    ...     _ = path.write_text(header + "  0.0  0.1  -0.2  0.05  0.0\\n")
    ...     rec = read_at2(path, size=1.0)
    >>> rec, rec.pga
    (Record('example', n=5, dt=0.01, size=1), 0.2)
    """
    path = _path_of(path)
    src = str(path)
    stream = _lines(path)
    npts, dt = _at2_header(src, stream)
    values = _at2_samples(src, stream)
    if values.size == 0:
        _refuse(src, "it holds no samples")
    if values.size != npts:
        _refuse(src, f"the header says NPTS = {npts} but the file holds {values.size} values")
    if not math.isfinite(dt) or dt <= 0:
        _refuse(src, f"the time step DT = {dt:g} is not positive")
    bad = ~np.isfinite(values)
    if bad.any():
        k = int(np.argmax(bad))
        _refuse(src, f"sample {k} is not finite ({values[k]})")
    name = name or Path(path).stem
    return _named(src, name, lambda: Record(values, dt, size=size, p=p, name=name))


def _at2_header(src, stream):
    """``(NPTS, DT)`` from the four header lines of an ``.AT2`` file (taken from ``stream``,
    :func:`_lines`), its units checked."""
    lines = [text.rstrip("\r\n") for _, (_, text) in zip(range(4), stream)]
    if len(lines) < 4:
        _refuse(src, "not a PEER .AT2 file (fewer than four header lines)")
    _at2_units(src, lines[2])
    return _at2_npts_dt(src, lines[3])


def _at2_units(src, line):
    """Refuse an ``.AT2`` header's units line ``line`` unless it states ``g``."""
    units = line.upper()
    if "UNITS OF" in units or "UNITS" in units:
        m = re.search(r"UNITS\s+(?:OF\s+)?([A-Z/0-9*^. ]+)", units)
        unit = m.group(1).strip().split()[0] if m and m.group(1).strip() else ""
        if unit != "G":
            _refuse(src, f"the accelerations are in {unit or 'unstated units'}, not g "
                         f"(header line 3: {line.strip()!r})")
    else:
        _refuse(src, f"the header does not state the units (line 3: {line.strip()!r}); "
                     f"an .AT2 record must be in units of g")


def _at2_npts_dt(src, line):
    """``(NPTS, DT)`` from an ``.AT2`` header's fourth line, in either of the database's two
    layouts (``NPTS= 2999, DT= .0100 SEC`` or ``2999   0.0100   NPTS, DT``)."""
    head = line.upper()
    m_n = re.search(r"NPTS\s*=\s*(\d+)", head)
    m_dt = re.search(r"DT\s*=\s*(" + _FLOAT + ")", head)
    if m_n and m_dt:
        return int(m_n.group(1)), float(m_dt.group(1).replace("D", "E"))
    nums = re.findall(_FLOAT, head)
    if len(nums) >= 2 and "NPTS" in head:
        try:
            return int(float(nums[0])), float(nums[1].replace("D", "E"))
        except ValueError:
            pass
    _refuse(src, f"line 4 does not give NPTS and DT ({line.strip()!r})")


def _at2_samples(src, stream):
    """The accelerations of an ``.AT2`` file, the rest of ``stream`` (:func:`_lines`) after its
    header: numbers (Fortran's ``D`` exponents allowed), at most ``MAX_SAMPLES``."""
    got = array("d")
    for _, text in stream:
        for token in text.split():
            v = _number(token, _NUMBER_D)
            if v is None:
                _refuse(src, f"{token!r} among the accelerations is not a number")
            if len(got) >= MAX_SAMPLES:
                _too_many(src)
            got.append(v)
    return np.frombuffer(got, dtype=float) if got else np.zeros(0)


_UNIT = re.compile(r"[\(\[]\s*([^\)\]]*?)\s*[\)\]]")
_ACCEL_UNITS = {"g", "g0", "gs"}
_TIME_UNITS = {"s", "sec", "second", "seconds"}


def _header_units(src, header):
    """Check a header's column names: time in seconds, acceleration in ``g`` where a unit is
    written; returns the number of columns named."""
    cols = [c.strip() for c in re.split(r"[,;\t]|\s{2,}", header.strip()) if c.strip()]
    if len(cols) == 1:
        cols = header.split()
    for k, col in enumerate(cols):
        m = _UNIT.search(col)
        unit = m.group(1).strip().lower() if m else None
        if unit is None:
            m2 = re.search(r"[_ ]in[_ ](\S+)$|_(\w+)$", col.lower())
            unit = (m2.group(1) or m2.group(2)) if m2 else None
            if unit not in _ACCEL_UNITS | _TIME_UNITS | {"ms2", "mps2", "cms2", "gal"}:
                unit = None
        if unit is None:
            continue
        if k == 0 and unit not in _TIME_UNITS:
            _refuse(src, f"the time column is in {unit!r}, not seconds (header {col!r})")
        if k == 1 and unit not in _ACCEL_UNITS:
            _refuse(src, f"the acceleration column is in {unit!r}, not g (header {col!r}); "
                         f"divide by 9.81 m/s^2 first")
    return cols


def read_table(path, *, size=None, p=None, name=None) -> Record:
    """A record from a text or CSV file of two columns, time (s) and acceleration (``g``),
    separated by commas, semicolons, tabs or spaces; ``#`` starts a comment; one header line
    of column names is allowed, and a unit written in it (``acc (g)``, ``a [m/s^2]``) must be
    ``g`` for the acceleration and seconds for the time. A third column named ``unit(s)`` must
    say ``g`` on every row.

    Parameters
    ----------
    path : str or path
        The file.
    size : float, optional
        The block's half-diagonal ``R`` in metres (see :class:`rockjit.Record`).
    p : float, optional
        The block's frequency parameter in rad/s, instead of ``size``.
    name : str, optional
        The record's name; default the file's name without its suffix.

    Returns
    -------
    Record
        The record; a bad file is refused with one ``ValueError`` line naming it and the
        problem.

    Examples
    --------
    >>> import pathlib, tempfile
    >>> from rockjit.ground import read_table
    >>> with tempfile.TemporaryDirectory() as d:
    ...     path = pathlib.Path(d) / "motion.csv"
    ...     _ = path.write_text("time (s), acc (g)\\n0.00, 0.0\\n0.01, 0.1\\n0.02, -0.2\\n"
    ...                         "0.03, 0.05\\n")
    ...     rec = read_table(path, size=1.0)
    >>> rec, rec.pga
    (Record('motion', n=4, dt=0.01, size=1), 0.2)
    >>> with tempfile.TemporaryDirectory() as d:       # doctest: +ELLIPSIS
    ...     path = pathlib.Path(d) / "cms2.csv"
    ...     _ = path.write_text("t (s), a (cm/s^2)\\n0, 0\\n0.01, 98.1\\n")
    ...     read_table(path)
    Traceback (most recent call last):
    ...
    ValueError: record ...cms2.csv: the acceleration column is in 'cm/s^2', not g (header 'a (cm/s^2)'); divide by 9.81 m/s^2 first
    """
    path = _path_of(path)
    src = str(path)
    times, accels = array("d"), array("d")
    header = units_col = None
    row = _ROW.fullmatch
    for lineno, line in _lines(path):
        m = row(line) if units_col is None else None
        if m is not None:  # the common row, two plain numbers: no more checks to make
            t, a = float(m.group(1)), float(m.group(2))
        else:
            line = line.split("#", 1)[0].strip()
            if not line:
                continue
            fields = [x for x in _SEPARATORS.split(line) if x]
            if not times and header is None and _is_header(line, fields):
                header = line
                units_col = _units_column(_header_units(src, header))
                continue
            t, a = _row_numbers(src, lineno, _without_units(src, lineno, fields, units_col))
        if len(times) >= MAX_SAMPLES:
            _too_many(src)
        times.append(t)
        accels.append(a)
    if not times:
        _refuse(src, "it holds no samples")
    return Record.from_arrays(np.frombuffer(times, dtype=float),
                              np.frombuffer(accels, dtype=float), size=size, p=p,
                              name=name or Path(path).stem, source=src)


def _is_header(line, fields):
    """Whether a table's first line names its columns: words, no number. A first line of
    numbers, one of them written in a way refused here ('1_0', other scripts' digits), is a
    row, refused as such, not a header to skip."""
    return any(c.isalpha() for c in line) and \
        not any(_number(x) is not None for x in fields[:2])


def _units_column(cols):
    """The index of the column named ``unit`` or ``units`` (the last), or ``None``."""
    units_col = None
    for k, col in enumerate(cols):
        if re.fullmatch(r"units?", col.strip().lower()):
            units_col = k
    return units_col


def _without_units(src, lineno, fields, units_col):
    """A row's ``fields`` less its units column (if the table has one), which must say ``g``."""
    if units_col is None:
        return fields
    if len(fields) <= units_col:
        _refuse(src, f"line {lineno} has no value in its units column")
    unit = fields[units_col].lower()
    if unit not in _ACCEL_UNITS:
        _refuse(src, f"line {lineno} gives the acceleration in {fields[units_col]!r}, "
                     f"not g")
    return fields[:units_col] + fields[units_col + 1:]


def _row_numbers(src, lineno, fields):
    """``(time, acceleration)`` from a row's two ``fields``, or a refusal naming the line."""
    if len(fields) < 2:
        _refuse(src, f"line {lineno} has {len(fields)} column: two are needed "
                     f"(time in s, acceleration in g)")
    if len(fields) > 2:
        _refuse(src, f"line {lineno} has {len(fields)} columns: two are expected "
                     f"(time in s, acceleration in g)")
    t, a = _number(fields[0]), _number(fields[1])
    if t is None or a is None:
        bad = fields[0] if t is None else fields[1]
        _refuse(src, f"line {lineno}: {bad!r} is not a number (ASCII digits, '.', "
                     f"'e' and a sign)")
    return t, a


def read_record(path, *, size=None, p=None, name=None) -> Record:
    """A record from a file: ``.AT2`` (PEER NGA) by its suffix, anything else as a two-column
    table (:func:`read_table`).

    Parameters
    ----------
    path : str or path
        The file.
    size : float, optional
        The block's half-diagonal ``R`` in metres (see :class:`rockjit.Record`).
    p : float, optional
        The block's frequency parameter in rad/s, instead of ``size``.
    name : str, optional
        The record's name; default the file's name without its suffix.

    Returns
    -------
    Record
        The record; a bad file is refused with one ``ValueError`` line naming it and the
        problem.

    Examples
    --------
    >>> import pathlib, tempfile
    >>> from rockjit.ground import read_record
    >>> with tempfile.TemporaryDirectory() as d:
    ...     path = pathlib.Path(d) / "motion.txt"
    ...     _ = path.write_text("0.00 0.0\\n0.02 0.15\\n0.04 -0.1\\n")
    ...     rec = read_record(path, size=2.0, name="a text file")
    >>> rec.name, rec.n, rec.dt
    ('a text file', 3, 0.02)
    """
    path = _path_of(path)
    if Path(path).suffix.lower() == ".at2":
        return read_at2(path, size=size, p=p, name=name)
    return read_table(path, size=size, p=p, name=name)
