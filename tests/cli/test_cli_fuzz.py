"""Seeded fuzz test of the command line: every bad input is refused cleanly, before any work.

What ``rockjit.cli.main`` promises for every invalid argument vector:
exit status 2; exactly one line on stderr, starting with ``rockjit: error:`` and naming the
offending option or parameter; nothing on stdout, no traceback, no warning; nothing written (the
command runs with the current directory set to an empty temporary directory and ``--out`` inside
it; afterwards that directory holds exactly what it held before: no ``--out``, no
``<out>.chunks``, no stray file); and no large allocation before the refusal.

The cases (``CASES``, printable with ``pytest --collect-only -q``):

- ``refusals: ...``: hand-written command lines that once got past the checks or ended in a
  traceback (overflowing frequencies and periods, grids too large for memory, unwritable
  ``--out``, a plain file where the chunk store goes, ...), and the numerical settings that
  must be refused (an explicit N below the damping's stability limit, a zero Zeno cut-off, an
  impact bound too large to allocate), literally;
- generated: every subcommand, every option that takes a value, given values outside the range
  its documentation states (docs/theory, the docstrings, ``--help``) and malformed values (``nan``,
  ``inf``, ``1e308``, ``5e-324``, ``abc``, ``""``, ``1,5``, ``0x10``, ...), numbers that are not
  ASCII decimal (``1_0``, Arabic-Indic or fullwidth digits, spaces), required options left out,
  the wrong number of values; the scipy tolerances whatever the method; ``--scheduler``
  addresses of the wrong form (checked before connecting), bad ``--scheduler-timeout`` values;
  every ``--out`` that cannot be published (dangling or looping links, a directory named like
  an output file, names too long for the file system). Refusal is asserted only where the value
  is really invalid.
- ``numbers: ...``: non-ASCII numbers in single and multi-valued options, literally.

The edges (``EDGE_CASES``): every option of every command that takes numbers (read from the
parser, so that a new one cannot escape) has its documented range in
``rockjit.cli.ranges.RANGES`` (built from the library's constants); each is given both ends of
its range, the numbers just outside them, and ``1e-320``, ``1e308``, ``-1e308``, ``-0.0``,
``nan``, ``inf`` (integers: ``0``, ``-1``, ``1e15`` and a 20-digit one), inside a small valid
command line. Each must end in exit status 2 with one line (naming the option where the value
is outside its range), or reach its (guarded) work; a seeded draw of the accepted ones, with
the values that once crashed after validation (``EDGE_REGRESSIONS``), runs for real on small
grids and must end in exit status 0 with its outputs written, or 2 with one line: never a
traceback.

Options the command line did not have but its documented model implies carry ``[guessed --NAME]``
in their ids: ``--max-impacts`` must exist; ``--xi`` cases are skipped while the parser does not
have it; ``--rest-speed`` is tried only on ``trajectory``, the one command that has it.

Nothing here computes: the entry points of real work (``GUARDED``, the one list to update after a
refactor) are replaced by a sentinel raising :class:`NotRefused`, so a case that slips past
validation fails at once ("not refused before work") instead of compiling or allocating. The seed
(``ROCKJIT_FUZZ_SEED``) chooses the valid values each bad one is embedded in and the order of the
options; the case ids do not depend on it.
"""

from __future__ import annotations

import contextlib
import hashlib
import importlib
import io
import math
import os
import random
import re
import shlex
import stat
import tempfile
import tracemalloc
import warnings
import zlib
from dataclasses import dataclass
from functools import lru_cache

import numba
import pytest

from rockjit.cli.main import build_parser, main
from rockjit.cli.ranges import range_of

# ---------------------------------------------------------------------------------------------
# The entry points of real work: reaching one means the input was not refused before work.
# "module:attribute"; the CLI imports some of them lazily inside functions, so the module
# attributes are what is patched. Update this list after a refactor (test_guards_exist says
# which entries have gone).
# ---------------------------------------------------------------------------------------------

GUARDED = (
    "rockjit.single:run",                  # the run of a single run's plan (`trajectory`)
    "rockjit.grids.plan:run",              # the run of every grid plan (sweep, basin, plane)
    "rockjit.basins.erosion:run",
    "rockjit.basins.fate:run",
    "rockjit.orbits.arclength:run",        # the work of `orbits`
    "rockjit.orbits.plane_chart:run",      # the work of `chart`
    "rockjit._engine.kernel:run_chunk",
    "rockjit._engine.integrate:build",
    "rockjit.ground.batch:run_batch",     # every run of `spectrum` and `fragility`
    "rockjit.ground.spectrum:run",
    "rockjit.ground.fragility:run",
    "rockjit.ground.reference:run_scipy",
    "rockjit.study.paper:write_e_table",  # the work of `cor` (and of `paper`'s first part)
    "rockjit.study.paper:paper",
    "rockjit.storage.atomic:atomic_open",       # every file the CLI writes goes through these
    "rockjit.storage.atomic:write_json",
    "rockjit.storage.atomic:write_npz",
    "rockjit.storage.atomic:write_csv",
    "rockjit.storage.atomic:write_text",
    "rockjit.storage.atomic:save_figure",
    "rockjit.explorer.server:Explorer",     # `explore`: its server is up (after the checks)
)
#: Patched as well where they exist (names of a refactor in progress); absent ones are ignored.
GUARDED_IF_PRESENT = (
    "rockjit._engine.kernel:run_single",
    "rockjit.grids.runner:run_grid",
    "rockjit._engine.kernel:run_chunk",
)

SEED = int(os.environ.get("ROCKJIT_FUZZ_SEED", "20240610"))
#: A refusal must come before any large allocation (the whole validation needs well under this).
ALLOC_LIMIT = 64 * 2**20
MAX_THREADS = numba.config.NUMBA_NUM_THREADS
MEMORY_MESSAGE = r"would need .+at most .+fits"
#: argparse's words when it takes a negative number for an option
TAKEN_FOR_AN_OPTION = r"expected (one|at least one|\d+) argument"


class NotRefused(BaseException):
    """Raised by a guarded entry point: the case got past validation (BaseException, so that no
    ``except Exception`` in the CLI can turn it into an error line)."""


# ---------------------------------------------------------------------------------------------
# What a message must contain to name each option or parameter (CLI or library spelling)
# ---------------------------------------------------------------------------------------------

NAMES = {
    "--hb": r"\bhb\b", "--hb-values": r"\bhb\b", "--hb-max": r"\bhb\b|\bhb[-_]max\b",
    "--alpha": r"\balpha\b", "--omega": r"\bomega\b", "--law": r"\blaw\b",
    "--e": r"(^|[\s'\"(])(--)?e\b",
    "--theta0": r"(?<!d)theta0", "--dtheta0": r"dtheta0", "--phase": r"\bphase\b",
    "--r0": r"\br0\b", "--s0": r"\bs0\b",
    "--method": r"\bmethod\b", "--forcing": r"\bforcing\b", "--rtol": r"\brtol\b",
    "--atol": r"\batol\b", "--lyapunov": r"lyapunov", "--max-points": r"max[-_ ]points",
    "--periods": r"\bperiods\b", "--n-steps": r"\bn[-_]steps\b", "--threads": r"\bthreads\b",
    "--out": r"--out|\bout\b",
    "--alpha-range": r"\balpha", "--alpha-step": r"alpha[-_]step", "--grid": r"\bgrid\b",
    "--theta-range": r"(?<!d)theta", "--dtheta-range": r"dtheta", "--omega-range": r"\bomega",
    "--zoom": r"\bzoom\b(?![-_])", "--zoom-step": r"zoom[-_]step",
    "--xi": r"\bxi\b", "--rest-speed": r"rest[-_]speed", "--max-impacts": r"max[-_]impacts",
    "--uncertainty": r"\buncertainty\b", "--erosion-step": r"erosion[-_]step",
    "--ensemble": r"\bensemble\b", "--spread": r"\bspread\b", "--seed": r"\bseed\b",
    "--erosion-grid": r"erosion[-_]grid", "--lattice": r"\blattice\b", "--levels": r"levels",
    "--max-period": r"max[-_]period",
    "--scheduler": r"--scheduler\b(?!-)", "--scheduler-timeout": r"scheduler[-_]timeout",
    "--seed-omegas": r"seed[-_]omegas",
    "--pulse": r"--pulse\b", "--ratio-range": r"\bratio", "--amplitude-range": r"\bamplitude",
    "--tol": r"\btol\b", "--free-time": r"free[-_]time", "--size": r"\bsizes?\b",
    "--records": r"\brecords?\b", "--measure": r"\bmeasure\b",
    "--intensities": r"\bintensit(y|ies)\b",
    "--style": r"--style\b", "--format": r"--format\b", "--port": r"\bport\b",
    "--device": r"--device\b",
    "--address": r"\baddress\b|cannot listen on", "--allow-host": r"allow[-_]hosts?",
}

NARGS = {"--alpha-range": 2, "--omega-range": 2, "--theta-range": 2, "--dtheta-range": 2,
         "--zoom": 2, "--hb-values": "+", "--spread": 2, "--seed-omegas": "+",
         "--ratio-range": 2, "--amplitude-range": 2, "--size": "+", "--records": "+",
         "--intensities": "+", "--levels": "+"}
FLAGS = {"--quiet", "--lyapunov", "--no-lyapunov", "--full-length", "--no-browser"}

NONFINITE = ["nan", "inf", "-inf"]
#: strings no number parser takes; each option gets two of them, rotating from option to option
#: (they all end in the same type check: all four on every option would only slow the module)
MALFORMED = ["abc", "", "1,5", "0x10"]
#: numbers Python's float() and int() take but the command line must not: only ASCII decimal
#: numbers are numbers (no "_" separators, no other scripts' digits, no spaces); each option
#: gets two of them, rotating like MALFORMED
NOT_ASCII = ["1_0", "\u0663", "\uff11", "-\u0663", "+\uff11", " 1", "1 ", "1e1_0", "0.\u0665"]
#: numbers that are not integers (an integer option must refuse each)
NOT_INT = ["nan", "inf", "-inf", "1e308", "5e-324", "2.5"]
HUGE_INT = "99999999999999999999"


# Record files for `rockjit fragility`: a valid one for the base command lines and bad ones
# (written once, outside the cases' working directories, which must stay empty).
_RECORD_DIR = tempfile.mkdtemp(prefix="rockjit-fuzz-records-")


def _record_file(name, text):
    path = os.path.join(_RECORD_DIR, name)
    with open(path, "w") as fh:
        fh.write(text)
    return path


RECORD_OK = _record_file("ok.csv", "time (s),acc (g)\n" + "".join(
    f"{0.01 * k:.2f},{0.3 * math.sin(0.5 * k):.6f}\n" for k in range(50)))
_BAD_RECORDS = {
    "empty": _record_file("empty.csv", ""),
    "nan": _record_file("nan.csv", "0,0\n0.01,nan\n0.02,0.1\n"),
    "time goes back": _record_file("back.csv", "0,0\n0.02,0.1\n0.01,0\n"),
    "uneven": _record_file("uneven.csv", "0,0\n0.01,0.1\n0.03,0.1\n0.04,0\n"),
    "m/s^2": _record_file("units.csv", "time (s),acc (m/s^2)\n0,0\n0.01,1\n"),
    "AT2 in cm/s/s": _record_file("cms.AT2", "PEER\nx\nACCELERATION TIME SERIES IN UNITS OF "
                                             "CM/S/S\nNPTS=  2, DT=   .0100 SEC\n 1.0 2.0\n"),
    "AT2 NPTS": _record_file("npts.AT2", "PEER\nx\nACCELERATION TIME SERIES IN UNITS OF G\n"
                                         "NPTS=  3, DT=   .0100 SEC\n 0.1 0.2\n"),
}


# ---------------------------------------------------------------------------------------------
# Cases
# ---------------------------------------------------------------------------------------------

@dataclass
class Case:
    """One invalid command line.

    ``set`` maps an option to its values (a list; ``[]``: the option given last with no value),
    ``True`` (a flag) or ``None`` (left out), over a valid base drawn for the command.
    """

    id: str
    cmd: str
    set: dict
    names: str                          # a regular expression the error line must match
    forbid: tuple = ()                  # regular expressions it must not match
    setup: str | None = None            # "out-file", "chunks-file", ... (see _prepare)
    guessed: str | None = None          # an option the CLI may not have yet
    guessed_required: bool = False      # ... which it must have (else: skip while absent)
    memory: bool = False                # must be refused by a memory estimate
    extra_ok: bool = False              # "unrecognized arguments" is the right answer
    nargs_ok: bool = False              # "expected N arguments" is the right answer
    base: bool = True                   # embed in a valid base command line
    n_at_least: int | None = None       # the message must give a number >= this (the N needed)


def _q(values):
    return " ".join(shlex.quote(v) for v in values)


def _id(cmd, opt, vals, note=""):
    if vals is None:
        s = f"{cmd} without {opt}"
    elif vals == []:
        s = f"{cmd} {opt} (no value)"
    else:
        s = f"{cmd} {opt} {_q(vals)}"
    return s + (f" {note}" if note else "")


def _values(cmd, opt, values, extra=None, **kw):
    """One case per value of a single-valued option (``extra``: options set alongside)."""
    return [Case(_id(cmd, opt, [v]) + (f" ({_ctx(extra)})" if extra else ""), cmd,
                 {**(extra or {}), opt: [v]}, NAMES[opt], **kw) for v in values]


def _ctx(extra):
    return ", ".join(opt if val is True else f"{opt} {_q(val)}" for opt, val in extra.items())


def _pairs(cmd, opt, pairs, **kw):
    """One case per value list of a multi-valued option; wrong counts allowed where they are."""
    out = []
    for vals in pairs:
        n = NARGS[opt]
        wrong_count = (n == "+" and not vals) or (n != "+" and len(vals) != n)
        extra = n != "+" and len(vals) > n
        out.append(Case(_id(cmd, opt, vals), cmd, {opt: vals},
                        NAMES[opt] if not extra else re.escape(vals[-1]),
                        nargs_ok=wrong_count, extra_ok=extra, **kw))
    return out


def _missing(cmd, opts):
    return [Case(_id(cmd, o, None), cmd, {o: None}, NAMES[o]) for o in opts]


def _out_cases(cmd):
    return [
        Case(f"{cmd} --out ''", cmd, {"--out": [""]}, NAMES["--out"]),
        Case(f"{cmd} --out /proc/x", cmd, {"--out": ["/proc/x"]}, NAMES["--out"]),
        Case(f"{cmd} --out <an existing file>", cmd, {}, NAMES["--out"], setup="out-file"),
        Case(f"{cmd} --out <inside a file>", cmd, {}, NAMES["--out"], setup="out-in-file"),
        Case(f"{cmd} --frobnicate 1", cmd, {"--frobnicate": ["1"]}, "frobnicate",
             extra_ok=True),
        # found only after the work (exit 2 after minutes, chunks left behind), or a traceback
        Case(f"{cmd} --out <a dangling link>", cmd, {}, NAMES["--out"], setup="out-dangling"),
        Case(f"{cmd} --out <a link to itself>", cmd, {}, NAMES["--out"], setup="out-loop"),
        Case(f"{cmd} --out <inside a dangling link>", cmd, {}, NAMES["--out"],
             setup="out-in-dangling"),
        Case(f"{cmd} --out <holding a directory summary.json>", cmd, {}, NAMES["--out"],
             setup="out-holds-summary-dir"),
        Case(f"{cmd} --out <a name of 256 bytes>", cmd, {"--out": ["x" * 256]},
             NAMES["--out"]),
        Case(f"{cmd} --out <a path of 4200 bytes>", cmd, {"--out": ["d/" * 2100]},
             NAMES["--out"]),
    ]


def _malformed(cmd, opt):
    """Two of :data:`MALFORMED`, rotating with the option (fixed, not drawn: stable ids)."""
    k = zlib.crc32(f"{cmd} {opt}".encode())
    return [MALFORMED[k % 4], MALFORMED[(k + 2) % 4]]


def _not_ascii(cmd, opt):
    """Two of :data:`NOT_ASCII`, rotating with the option (fixed: stable ids)."""
    k = zlib.crc32(f"{opt} {cmd}".encode())
    n = len(NOT_ASCII)
    return [NOT_ASCII[k % n], NOT_ASCII[(k + 4) % n]]


def _real_opt(cmd, opt, bad, extra=None):
    return _values(cmd, opt, NONFINITE + bad + _malformed(cmd, opt) + _not_ascii(cmd, opt),
                   extra)


def _int_opt(cmd, opt, bad):
    cases = _values(cmd, opt, bad + NOT_INT + _malformed(cmd, opt) + _not_ascii(cmd, opt))
    for c in cases:
        if c.set[opt] == [HUGE_INT]:  # an integer: too large, not "not an integer"
            c.forbid = (r"must be an integer",)
    return cases


def _block_cases(cmd, alpha=True, omega=True, laws_ok=("housner", "mao", "constant")):
    c = _real_opt(cmd, "--hb", ["0", "-1", "-1e308"])
    # below 1/sqrt(2) the Housner law has e_H < 0 (docs/theory/impacts.md)
    c += _values(cmd, "--hb", ["0.5", "5e-324"], {"--law": ["housner"]})
    c += _values(cmd, "--law", [v for v in ("abc", "", "HOUSNER", "0", "both")
                                if v not in laws_ok])
    c += _real_opt(cmd, "--e", ["-0.1", "1.5", "-1e308", "1e308", HUGE_INT],
                   {"--law": ["constant"]})
    c += _values(cmd, "--e", ["0.5"], {"--law": ["housner"]})       # e only with constant
    c.append(Case(f"{cmd} --law constant without --e", cmd, {"--law": ["constant"],
                                                              "--e": None}, NAMES["--e"]))
    if alpha:
        c += _real_opt(cmd, "--alpha", ["-1", "-1e-3", "-1e308"])
    if omega:
        # 1e308: alpha omega^2 overflows; 5e-324: the period overflows
        c += _real_opt(cmd, "--omega", ["0", "-1.3", "-1e-3", "-1e308", "1e308", "5e-324"])
    return c


def _state_cases(cmd, theta=True):
    c = []
    if theta:
        c += _real_opt(cmd, "--theta0", ["1.5708", "-2", "1e308", "-1e308", HUGE_INT])
        c += _real_opt(cmd, "--dtheta0", [])
    c += _real_opt(cmd, "--phase", [])
    c += _values(cmd, "--phase", ["0.3"], {"--r0": ["0"], "--s0": ["1"]})
    # with the closed-form forcing (r0, s0) must lie on the unit circle, not at the origin
    forcing = [_values(cmd, "--r0", ["0.5", "1e308", "-1e308"], {"--s0": ["1"]}),
               _values(cmd, "--s0", ["0", "0.5", "-1e308"], {"--r0": ["0"]}),
               [Case(f"{cmd} --r0 0 without --s0", cmd, {"--r0": ["0"], "--s0": None},
                     r"\b[rs]0\b"),
                Case(f"{cmd} --s0 1 without --r0", cmd, {"--s0": ["1"], "--r0": None},
                     r"\b[rs]0\b")]]
    for group in forcing:
        for case in group:
            if cmd not in ("trajectory", "fate"):  # only these take --forcing
                case.forbid = (r"embedded",)
        c += group
    c += _values(cmd, "--r0", NONFINITE + _malformed(cmd, "--r0"), {"--s0": ["1"]})
    c += _values(cmd, "--s0", NONFINITE + _malformed(cmd, "--s0"), {"--r0": ["0"]})
    return c


def _run_cases(cmd):
    c = _int_opt(cmd, "--periods", ["0", "-1", HUGE_INT])
    c += _int_opt(cmd, "--n-steps", ["0", "-2", "6", "7", "63", HUGE_INT])
    c += _int_opt(cmd, "--threads", ["0", "-1", str(MAX_THREADS + 1), HUGE_INT])
    c.append(Case(_id(cmd, "--periods", []), cmd, {"--periods": []}, NAMES["--periods"],
                  nargs_ok=True))
    return c


def _chunks_case(cmd):
    # a plain file where the chunk store goes once ended in NotADirectoryError
    return [Case(f"{cmd} <out>.chunks is a plain file", cmd, {}, r"chunks", setup="chunks-file"),
            Case(f"{cmd} <out>.chunks is a dangling link", cmd, {}, r"chunks.*--out",
                 setup="chunks-dangling"),
            Case(f"{cmd} --out <a name of 250 bytes: no room for .chunks>", cmd,
                 {"--out": ["x" * 250]}, r"--out.*chunks")]


def _scheduler_cases(cmd):
    """--scheduler is checked before connecting: the address's form (tcp://HOST:PORT, the port
    in range) or an existing scheduler file; --scheduler-timeout is a positive time."""
    c = _values(cmd, "--scheduler", ["", " ", "tcp://127.0.0.1:99999", "tcp://127.0.0.1:0",
                                     "http://127.0.0.1:8786", "tcp://a b:8786",
                                     "no-such-scheduler-file.json", "tcp://", "127.0.0.1"])
    c += _real_opt(cmd, "--scheduler-timeout", ["0", "-1", "1e7"])
    return c


def _guessed(cmd, required_max_impacts, rest_speed=False):
    """Options the specification implies and the CLI may not have yet (ids say so);
    ``--rest-speed`` only where the command has it (a single run's)."""
    c = []
    mi = "[guessed --max-impacts]"
    for v in ["0", "-1", HUGE_INT] + NOT_INT + _malformed(cmd, "--max-impacts"):
        c.append(Case(_id(cmd, "--max-impacts", [v], mi), cmd, {"--max-impacts": [v]},
                      NAMES["--max-impacts"], guessed="--max-impacts",
                      guessed_required=required_max_impacts))
    for v in ["-1", "-1e-3"] + NONFINITE + _malformed(cmd, "--xi"):
        c.append(Case(_id(cmd, "--xi", [v], "[guessed --xi]"), cmd, {"--xi": [v]},
                      NAMES["--xi"], guessed="--xi"))
    for v in (["-1", "-1e-8"] + NONFINITE + _malformed(cmd, "--rest-speed")
              if rest_speed else []):
        c.append(Case(_id(cmd, "--rest-speed", [v], "[guessed --rest-speed]"), cmd,
                      {"--rest-speed": [v]}, NAMES["--rest-speed"], guessed="--rest-speed"))
    return c


def _trajectory():
    cmd = "trajectory"
    c = _block_cases(cmd) + _state_cases(cmd) + _run_cases(cmd)
    c += _values(cmd, "--method", ["abc", "", "scipy:FOO", "scipy:", "SCIPY", "rockjit:RK45",
                                   "scipy:rk45"])
    c += _values(cmd, "--forcing", ["abc", "", "open", "CLOSED"])
    for tol in ("--rtol", "--atol"):
        for method in ("scipy", "scipy:RK45"):
            c += _real_opt(cmd, tol, ["-1", "-1e-6", "-1e308"], {"--method": [method]})
        # invalid numbers whatever the method: the compiled one ignores them, but took them
        bad = ["-1", "0"] + (["1", "2"] if tol == "--rtol" else [])
        c += _real_opt(cmd, tol, bad)
        c += _values(cmd, tol, ["-1", "nan"], {"--method": ["rockjit"]})
    c.append(Case(f"{cmd} --method scipy --lyapunov", cmd,
                  {"--method": ["scipy"], "--lyapunov": True}, NAMES["--lyapunov"]))
    c += _int_opt(cmd, "--max-points", ["0", "1", "-1"])
    c += _missing(cmd, ["--hb", "--alpha", "--omega", "--out"])
    c += _out_cases(cmd) + _guessed(cmd, required_max_impacts=True, rest_speed=True)
    return c


def _sweep():
    cmd = "sweep"
    c = _block_cases(cmd, alpha=False) + _state_cases(cmd) + _run_cases(cmd)
    c += _pairs(cmd, "--alpha-range", [
        ["0.5"], ["0.5", "0.6", "0.7"], ["0.6", "0.5"], ["-0.1", "0.5"], ["-1e-3", "0.5"],
        ["nan", "0.5"], ["0.5", "nan"], ["0.5", "inf"], ["-inf", "0.5"],
        ["0.5", "1e308"], ["0.5", HUGE_INT],          # 1e23 amplitudes: cannot fit
        ["abc", "0.5"], ["", "0.5"], ["0.5", "1,5"], ["0x10", "0.5"]])
    # 5e-324: (end - start) / step overflows
    c += _real_opt(cmd, "--alpha-step", ["0", "-0.001", "-1e308", "5e-324"])
    c += _missing(cmd, ["--hb", "--omega", "--alpha-range", "--out"])
    c += _out_cases(cmd) + _chunks_case(cmd) + _guessed(cmd, required_max_impacts=False)
    return c


def _basin():
    cmd = "basin"
    c = _block_cases(cmd, laws_ok=("housner", "mao", "constant", "both"))
    c.append(Case("basin --law both --e 0.5", cmd, {"--law": ["both"], "--e": ["0.5"]},
                  NAMES["--e"]))
    c += _state_cases(cmd, theta=False) + _run_cases(cmd)
    c += _int_opt(cmd, "--grid", ["0", "-1", HUGE_INT])
    c += _pairs(cmd, "--theta-range", [
        ["1"], ["-1", "0", "1"], ["1", "-1"], ["-2", "1"], ["0", "1.6"], ["-1.5708", "0"],
        ["nan", "1"], ["-inf", "1"], ["0", "inf"], ["-1e308", "1e308"],
        ["abc", "1"], ["", "1"], ["1,5", "1"]])
    c += _pairs(cmd, "--dtheta-range", [
        ["1"], ["-1", "0", "1"], ["1", "-1"], ["nan", "1"], ["-inf", "1"], ["0", "inf"],
        ["-1e308", "1e308"],                           # hi - lo overflows: no grid spacing
        ["abc", "1"], ["0x10", "1"], ["1", ""]])
    c += _missing(cmd, ["--hb", "--alpha", "--omega", "--out"])
    c += _out_cases(cmd) + _chunks_case(cmd) + _guessed(cmd, required_max_impacts=False)
    return c


def _plane():
    cmd = "plane"
    c = _block_cases(cmd, alpha=False, omega=False) + _state_cases(cmd) + _run_cases(cmd)
    c += _pairs(cmd, "--alpha-range", [
        ["0.5"], ["0.5", "0.6", "0.7"], ["0.6", "0.5"], ["-0.1", "0.5"], ["-1e-3", "0.5"],
        ["nan", "0.5"], ["0.5", "inf"], ["-inf", "0.5"], ["-1e308", "0.5"],
        ["abc", "0.5"], ["", "0.5"], ["0.5", "1,5"]])
    c += _pairs(cmd, "--omega-range", [
        ["1"], ["1", "1.5", "2"], ["2", "1"], ["0", "1"], ["-1", "1"], ["-1e-3", "1"],
        ["nan", "1"], ["1", "inf"], ["-inf", "1"], ["5e-324", "1"], ["1", "1e308"],
        ["abc", "1"], ["1", ""], ["0x10", "1"]])
    grid_pairs = [["5"], ["5", "5", "5"], ["0", "5"], ["5", "0"], ["-1", "5"],
                  [HUGE_INT, "2"], ["abc", "5"], ["5", "2.5"], ["nan", "5"], ["1e308", "5"],
                  ["", "5"]]
    for vals in grid_pairs:
        extra = len(vals) > 2
        c.append(Case(_id(cmd, "--grid", vals), cmd, {"--grid": vals},
                      NAMES["--grid"] if not extra else re.escape(vals[-1]),
                      nargs_ok=len(vals) != 2, extra_ok=extra))
    c += _missing(cmd, ["--hb", "--alpha-range", "--omega-range", "--out"])
    c += _out_cases(cmd) + _chunks_case(cmd) + _guessed(cmd, required_max_impacts=False)
    return c


def _cor():
    cmd = "cor"
    c = _pairs(cmd, "--hb-values", [
        [], ["0.5"], ["0"], ["-1"], ["-1e-3"], ["5e-324"], ["-1e308"], ["1", "0.5"],
        ["nan"], ["inf"], ["-inf"], ["abc"], [""], ["1,5"], ["0x10"], ["2", "nan"]])
    c += _real_opt(cmd, "--hb-max", ["0.7", "0.5", "0", "-1", "-1e308", "5e-324"])
    c += _missing(cmd, ["--out"])
    c += _out_cases(cmd)
    return c


def _paper():
    cmd = "paper"
    c = _run_cases(cmd)
    c += _int_opt(cmd, "--grid", ["0", "-3", HUGE_INT])
    c += _real_opt(cmd, "--alpha-step", ["0", "-0.1", "-1e308", "5e-324"])
    # the zoom lies inside the Housner hb=1 range [0.5, 1] (docs/theory/study.md), start <= end
    c += _pairs(cmd, "--zoom", [
        ["0.9"], ["0.9", "0.95", "0.97"], ["0.2", "0.3"], ["0.9", "1.1"], ["-0.9", "0.95"],
        ["nan", "0.9"], ["0.9", "inf"], ["-inf", "0.9"], ["abc", "0.9"], ["0.9", ""],
        ["0.9", "1,5"]])
    c += _real_opt(cmd, "--zoom-step", ["0", "-0.01", "-1e308", "5e-324"])
    c += _missing(cmd, ["--out"])
    c += _out_cases(cmd)
    return c


def _stable_n(omega, xi, stability=3.31):
    """Fewest steps per period an explicit Dormand-Prince step takes stably against the damping
    rate 3/4 xi (a lower bound of the N a refusal must name)."""
    return math.ceil(2.0 * math.pi / omega * 0.75 * xi / stability)


def _refusals():
    """Hand-written command lines that must be refused, literally: ones that once got past
    the checks or ended in a traceback, and the numerical settings that must be refused."""
    traj = {"--hb": ["1"], "--alpha": ["0.6"], "--omega": ["1.3"]}
    sweep = {"--hb": ["1"], "--omega": ["1.3"], "--alpha-range": ["0.5", "0.6"]}
    basin = {"--hb": ["1"], "--alpha": ["0.66"], "--omega": ["1.3"]}
    plane = {"--hb": ["1"], "--alpha-range": ["0.5", "0.6"]}

    def case(text, cmd, opts, names, **kw):
        return Case(f"refusals: {text}", cmd, opts, names, base=False, **kw)

    out = {"--out": ["{out}"]}
    return [
        case("trajectory --omega 1e300 --out o", "trajectory",
             {**traj, "--omega": ["1e300"], "--out": ["o"]}, NAMES["--omega"]),
        case("trajectory --omega 1e-300", "trajectory", {**traj, "--omega": ["1e-300"], **out},
             NAMES["--omega"]),
        case("trajectory --omega 1e-8 (API: MemoryError)", "trajectory",
             {**traj, "--omega": ["1e-8"], **out}, r"\bomega\b|\bn[-_]steps\b"),
        case("trajectory --periods 1000000000000", "trajectory",
             {**traj, "--periods": ["1000000000000"], **out}, NAMES["--periods"]),
        case("trajectory --n-steps 4000000000 --periods 1", "trajectory",
             {**traj, "--n-steps": ["4000000000"], "--periods": ["1"], **out},
             NAMES["--n-steps"]),
        case("sweep --alpha-range 0.5 0.6 --alpha-step 1e-12", "sweep",
             {**sweep, "--alpha-step": ["1e-12"], **out}, NAMES["--alpha-step"]),
        case("basin --grid 100000", "basin", {**basin, "--grid": ["100000"], **out},
             NAMES["--grid"], memory=True),
        case("basin --grid 1000000000", "basin", {**basin, "--grid": ["1000000000"], **out},
             NAMES["--grid"], memory=True),
        case("trajectory --method scipy --rtol=-1", "trajectory",
             {**traj, "--method": ["scipy"], "--rtol=-1": True, **out}, NAMES["--rtol"]),
        case("plane --omega-range 1 1e300", "plane",
             {**plane, "--omega-range": ["1", "1e300"], **out}, NAMES["--omega-range"]),
        case("plane --omega-range 1e-300 1", "plane",
             {**plane, "--omega-range": ["1e-300", "1"], **out}, NAMES["--omega-range"]),
        case("trajectory --out /proc/x", "trajectory", {**traj, "--out": ["/proc/x"]},
             NAMES["--out"]),
        case("trajectory --out ''", "trajectory", {**traj, "--out": [""]}, NAMES["--out"]),
        case("basin with <out>.chunks a plain file", "basin", {**basin, **out}, r"chunks",
             setup="chunks-file"),
        case("trajectory --periods 99999999999999999999", "trajectory",
             {**traj, "--periods": [HUGE_INT], **out}, NAMES["--periods"],
             forbid=(r"must be an integer",)),
        case("paper --zoom 0.99 0.9", "paper", {"--zoom": ["0.99", "0.9"], **out},
             NAMES["--zoom"], forbid=(r"alpha[-_]range",)),
        case("basin --r0 .5 --s0 .5", "basin", {**basin, "--r0": [".5"], "--s0": [".5"], **out},
             r"\b[rs]0\b", forbid=(r"embedded",)),
        case("trajectory --dtheta0 -inf", "trajectory", {**traj, "--dtheta0": ["-inf"], **out},
             NAMES["--dtheta0"]),
        case("trajectory --theta0 2 (the API runs it, the CLI refuses it)", "trajectory",
             {**traj, "--theta0": ["2"], **out}, NAMES["--theta0"]),
        case("trajectory --method scipy:FOO", "trajectory",
             {**traj, "--method": ["scipy:FOO"], **out}, NAMES["--method"]),
        # stiff damping: an explicit N below the stability limit in h*3/4*xi is refused,
        # naming the N needed, at least T * 3/4 xi / 3.31 (Dormand-Prince's stability interval
        # on the negative real axis is about [-3.31, 0]): 220 for xi = 200, 548 for xi = 500
        case("trajectory --xi 200 --n-steps 64 [guessed --xi]", "trajectory",
             {**traj, "--xi": ["200"], "--n-steps": ["64"], **out}, NAMES["--n-steps"],
             guessed="--xi", n_at_least=_stable_n(1.3, 200)),
        case("sweep --xi 500 --n-steps 64 [guessed --xi]", "sweep",
             {**sweep, "--alpha-step": ["0.05"], "--xi": ["500"], "--n-steps": ["64"], **out},
             NAMES["--n-steps"], guessed="--xi", n_at_least=_stable_n(1.3, 500)),
        # rest_speed = 0 piles impacts at one instant; refused unless the accumulation
        # point of the impacts (docs/theory/impacts.md) is computed (then drop this case)
        case("trajectory --rest-speed 0 [guessed --rest-speed]", "trajectory",
             {**traj, "--rest-speed": ["0"], **out}, NAMES["--rest-speed"],
             guessed="--rest-speed"),
        # --max-impacts exists; a bound whose impact table cannot fit is refused
        case("trajectory --max-impacts 99999999999999999999 [guessed --max-impacts]",
             "trajectory", {**traj, "--max-impacts": [HUGE_INT], **out},
             NAMES["--max-impacts"], guessed="--max-impacts", guessed_required=True),
    ]


def _grid_extras(cmd):
    """Options every grid command has beyond the study's (uncertain cells)."""
    return _real_opt(cmd, "--uncertainty", ["0", "-1e-6", "0.9", "1e308", "5e-324"])


def _erosion():
    cmd = "erosion"
    c = _block_cases(cmd, alpha=False, laws_ok=("housner", "mao", "constant", "both"))
    c += _run_cases(cmd)
    c += _pairs(cmd, "--alpha-range", [
        ["0.5"], ["0.6", "0.5"], ["-0.1", "0.5"], ["nan", "0.5"], ["0.5", "inf"],
        ["0.5", "1e308"], ["abc", "0.5"]])
    c += _real_opt(cmd, "--alpha-step", ["0", "-0.01", "5e-324"])
    c += _int_opt(cmd, "--grid", ["0", "-1", HUGE_INT])
    c += _values(cmd, "--grid", ["100000"])            # the stack of basins cannot fit
    c += _missing(cmd, ["--hb", "--omega", "--alpha-range", "--out"])
    c += _out_cases(cmd) + _chunks_case(cmd)
    return c


def _orbits():
    cmd = "orbits"
    c = _block_cases(cmd, alpha=False)
    c += _pairs(cmd, "--alpha-range", [
        ["0.5"], ["0.6", "0.5"], ["0.5", "0.5"], ["-0.1", "0.5"], ["nan", "0.5"],
        ["0.5", "inf"], ["abc", "0.5"]])
    c += _real_opt(cmd, "--alpha-step", ["0", "-0.01", "5e-324"])
    c += _int_opt(cmd, "--periods", ["0", "-1", HUGE_INT])
    c += _int_opt(cmd, "--max-period", ["0", "-1", "257", HUGE_INT])
    c += _int_opt(cmd, "--threads", ["0", "-1", str(MAX_THREADS + 1), HUGE_INT])
    c += _missing(cmd, ["--hb", "--omega", "--alpha-range", "--out"])
    c += _out_cases(cmd) + _chunks_case(cmd)
    return c


def _chart():
    """``rockjit chart``: the plane's options (from the study's z0: no state), the seed lines
    (inside --omega-range), the longest period followed."""
    cmd = "chart"
    c = _block_cases(cmd, alpha=False, omega=False,
                     laws_ok=("housner", "mao", "constant", "both"))
    c.append(Case("chart --law both --e 0.5", cmd, {"--law": ["both"], "--e": ["0.5"]},
                  NAMES["--e"]))
    c += _run_cases(cmd)
    c += _pairs(cmd, "--alpha-range", [
        ["0.5"], ["0.5", "0.6", "0.7"], ["0.6", "0.5"], ["0.5", "0.5"], ["-0.1", "0.5"],
        ["nan", "0.5"], ["0.5", "inf"], ["-inf", "0.5"], ["abc", "0.5"], ["", "0.5"]])
    c += _pairs(cmd, "--omega-range", [
        ["1"], ["1", "1.5", "2"], ["2", "1"], ["1.3", "1.3"], ["0", "1"], ["-1", "1"],
        ["nan", "1"], ["1", "inf"], ["5e-324", "1"], ["1", "1e308"], ["abc", "1"], ["1", ""]])
    for vals in [["5"], ["5", "5", "5"], ["0", "5"], ["5", "0"], ["-1", "5"], [HUGE_INT, "2"],
                 ["abc", "5"], ["5", "2.5"], ["nan", "5"], ["1e308", "5"]]:
        extra = len(vals) > 2
        c.append(Case(_id(cmd, "--grid", vals), cmd, {"--grid": vals},
                      NAMES["--grid"] if not extra else re.escape(vals[-1]),
                      nargs_ok=len(vals) != 2, extra_ok=extra))
    # the seed lines must lie inside --omega-range (a base's range is within [0.8, 3])
    c += _pairs(cmd, "--seed-omegas", [[], ["0.1"], ["1.3", "9"], ["-1"], ["nan"], ["inf"],
                                       ["abc"], [""], ["1,5"]])
    c += _int_opt(cmd, "--max-period", ["0", "-1", "17", HUGE_INT])
    c += _missing(cmd, ["--hb", "--alpha-range", "--omega-range", "--out"])
    c += _out_cases(cmd) + _chunks_case(cmd)
    return c


def _safety():
    """``rockjit safety``: the plane's forcing ranges and grid (at most 1000 a side), every
    basin's lattice (at least 2 a side), the contour levels (fractions in [0, 1])."""
    cmd = "safety"
    c = _block_cases(cmd, alpha=False, omega=False,
                     laws_ok=("housner", "mao", "constant", "both"))
    c.append(Case("safety --law both --e 0.5", cmd, {"--law": ["both"], "--e": ["0.5"]},
                  NAMES["--e"]))
    c += _state_cases(cmd, theta=False) + _run_cases(cmd)
    c += _pairs(cmd, "--alpha-range", [
        ["0.5"], ["0.5", "0.6", "0.7"], ["0.6", "0.5"], ["0.5", "0.5"], ["-0.1", "0.5"],
        ["nan", "0.5"], ["0.5", "inf"], ["-inf", "0.5"], ["0.5", "1e308"], ["abc", "0.5"],
        ["", "0.5"], ["0.5", "1,5"], ["0x10", "0.5"]])
    c += _pairs(cmd, "--omega-range", [
        ["1"], ["1", "1.5", "2"], ["2", "1"], ["1.3", "1.3"], ["0", "1"], ["-1", "1"],
        ["nan", "1"], ["1", "inf"], ["-inf", "1"], ["5e-324", "1"], ["1", "1e308"],
        ["abc", "1"], ["1", ""], ["1,5", "2"]])
    for vals in [["5"], ["5", "5", "5"], ["0", "5"], ["5", "0"], ["-1", "5"], ["1001", "2"],
                 ["2", "1001"], [HUGE_INT, "2"], ["abc", "5"], ["5", "2.5"], ["nan", "5"],
                 ["1e308", "5"], ["", "5"]]:
        extra = len(vals) > 2
        c.append(Case(_id(cmd, "--grid", vals), cmd, {"--grid": vals},
                      NAMES["--grid"] if not extra else re.escape(vals[-1]),
                      nargs_ok=len(vals) != 2, extra_ok=extra))
    # one point a side is no two-dimensional lattice: the integrity measures need one
    c += _int_opt(cmd, "--lattice", ["1", "0", "-1", "100001", HUGE_INT])
    c += _pairs(cmd, "--levels", [
        [], ["abc"], [""], ["nan"], ["inf"], ["-inf"], ["1.5"], ["-0.1"], ["1,5"], ["0x10"],
        ["0.5", "nan"], ["0.5", "1.5"]])
    c += _missing(cmd, ["--hb", "--alpha-range", "--omega-range", "--out"])
    c += _out_cases(cmd) + _chunks_case(cmd)
    return c


def _fate():
    cmd = "fate"
    c = _block_cases(cmd) + _state_cases(cmd) + _run_cases(cmd)
    c += _int_opt(cmd, "--ensemble", ["0", "1", "-5", HUGE_INT])
    c += _int_opt(cmd, "--seed", ["-1", HUGE_INT])
    c += _pairs(cmd, "--spread", [
        ["1e-10"], ["1e-8", "1e-10"], ["0", "1e-10"], ["-1e-12", "1e-10"], ["1e-3", "0.5"],
        ["nan", "1e-10"], ["1e-12", "inf"], ["abc", "1e-10"]])
    c += _values(cmd, "--forcing", ["abc", "open"])
    c += _missing(cmd, ["--hb", "--alpha", "--omega", "--out"])
    c += _out_cases(cmd)
    return c


def _transient_cases(cmd):
    """Options of the commands on pulses and records (spectrum, fragility)."""
    c = _real_opt(cmd, "--free-time", ["-1", "-1e-3", "1e10", "1e308"])
    c += _values(cmd, "--method", ["abc", "", "rockjit:RK45", "scipy:FOO", "SCIPY",
                                   "scipy:rk45"])
    # refused whatever the method: the compiled one ignores them, but takes them
    for method in ("rockjit", "scipy"):
        c += _real_opt(cmd, "--rtol", ["0", "-1", "-1e-6", "-1e308", "1", "2"],
                       {"--method": [method]})
        c += _real_opt(cmd, "--atol", ["0", "-1", "-1e-6", "-1e308"], {"--method": [method]})
    c += _real_opt(cmd, "--xi", ["-1", "-1e-3", "1e5", "1e308"])
    # no --threads option: the compiled path takes numba's threads (Execution(threads=...) in
    # the API)
    c.append(Case(f"{cmd} --threads 2", cmd, {"--threads": ["2"]}, r"--threads",
                  extra_ok=True))
    return c


def _spectrum():
    cmd = "spectrum"
    c = _block_cases(cmd, alpha=False, omega=False,
                     laws_ok=("housner", "mao", "constant", "both"))
    c.append(Case("spectrum --law both --e 0.5", cmd, {"--law": ["both"], "--e": ["0.5"]},
                  NAMES["--e"]))
    c += _values(cmd, "--pulse", ["abc", "", "SINE", "square", "0"])
    c += _pairs(cmd, "--ratio-range", [
        ["1"], ["1", "2", "3"], ["2", "1"], ["1", "1"], ["0", "2"], ["-1", "2"],
        ["1", "1e4"], ["1e-4", "1"], ["5e-324", "1"], ["nan", "2"], ["1", "inf"],
        ["-inf", "1"], ["1", "1e308"], ["abc", "2"], ["", "2"], ["1", "1,5"], ["0x10", "2"]])
    c += _pairs(cmd, "--amplitude-range", [
        ["1"], ["1", "2", "3"], ["3", "1"], ["2", "2"], ["-1", "2"], ["-1e-3", "2"],
        ["1", "1e7"], ["1", "1e308"], ["nan", "2"], ["1", "inf"], ["-inf", "1"],
        ["abc", "2"], ["", "2"], ["1", "1,5"], ["0x10", "2"]])
    grid_pairs = [["5"], ["5", "5", "5"], ["0", "5"], ["5", "0"], ["-1", "5"], ["5", "-3"],
                  [HUGE_INT, "2"], ["20000", "2"], ["abc", "5"], ["5", "2.5"], ["nan", "5"],
                  ["1e308", "5"], ["", "5"]]
    for vals in grid_pairs:
        extra = len(vals) > 2
        c.append(Case(_id(cmd, "--grid", vals), cmd, {"--grid": vals},
                      NAMES["--grid"] if not extra else re.escape(vals[-1]),
                      nargs_ok=len(vals) != 2, extra_ok=extra))
    c += _real_opt(cmd, "--tol", ["0", "-1e-6", "0.5", "1", "1e-13", "5e-324", "1e308"])
    c += _transient_cases(cmd)
    c += _missing(cmd, ["--hb", "--ratio-range", "--amplitude-range", "--out"])
    c += _out_cases(cmd)
    return c


def _fragility():
    cmd = "fragility"
    c = _block_cases(cmd, alpha=False, omega=False,
                     laws_ok=("housner", "mao", "constant", "both"))
    c += _pairs(cmd, "--size", [
        [], ["0"], ["-1"], ["-1e-3"], ["1e-4"], ["1e5"], ["1e308"], ["5e-324"], ["nan"],
        ["inf"], ["-inf"], ["1", "1"], ["1", "nan"], ["abc"], [""], ["1,5"], ["0x10"]])
    c += _pairs(cmd, "--records", [
        [], ["nearby"], ["FARFIELD"], [""], ["no-such-file.AT2"], ["farfield.csv"]])
    c += _pairs(cmd, "--intensities", [
        [], ["0"], ["-1"], ["2", "1"], ["1", "1"], ["nan"], ["inf"], ["-inf"], ["1e7"],
        ["1e308"], ["1", "abc"], [""], ["1,5"], ["0x10"], ["5e-324", "-1"]])
    c += _values(cmd, "--measure", ["abc", "", "PGA", "sa", "0"])
    c += [Case(f"{cmd} --records {name} (a bad record file)", cmd, {"--records": [path]},
               r"\brecord\b.*" + re.escape(path) if not path.endswith(".AT2") else
               re.escape(path)) for name, path in _BAD_RECORDS.items()]
    c += _transient_cases(cmd)
    c += _missing(cmd, ["--hb", "--size", "--records", "--out"])
    c += _out_cases(cmd)
    return c


def _explore():
    """``rockjit explore``: the port and the address are refused before the server starts
    (no browser: ``--no-browser`` on every case)."""
    cmd, quiet = "explore", {"--no-browser": True}
    c = _values(cmd, "--port", ["-1", "65536", HUGE_INT] + NOT_INT + _malformed(cmd, "--port")
                + _not_ascii(cmd, "--port"), quiet)
    # not a host address, or not one of this machine's (the OS's choice of port)
    c += _values(cmd, "--address", ["", " ", "a b", "999.1.1.1", "8.8.8.8"], quiet)
    c += _values(cmd, "--allow-host", ["", "a b", "*.lab", "x" * 300], quiet)
    # a port, a scheme, an empty label, an unclosed bracket, a name of 257 characters made of
    # valid labels (a host name has at most 253), and a bad name after a good one
    c += _values(cmd, "--allow-host", ["host:8000", "http://lab", "a..b", ".lab", "[::1",
                                       ("a" * 63 + ".") * 4 + "a"], quiet)
    # (the option repeated: its second occurrence written among the first one's values)
    c.append(Case(f"{cmd} --allow-host lab --allow-host 'a b'", cmd,
                  {**quiet, "--allow-host": ["lab", "--allow-host", "a b"]},
                  NAMES["--allow-host"]))
    return c


def _commands_with(opt):
    """The commands of the parser that take ``opt``."""
    import argparse
    sub = next(a for a in build_parser()._actions if isinstance(a, argparse._SubParsersAction))
    return sorted(name for name, p in sub.choices.items()
                  if any(opt in a.option_strings for a in p._actions))


def _figure_options():
    """``--style`` and ``--format``: a choice, on every command that draws."""
    return [c for cmd in _commands_with("--style")
            for c in _values(cmd, "--style", ["", "PAPER", "bogus"])
            + _values(cmd, "--format", ["", "jpg", "PNG"])]


def _device_options():
    """``--device``: a choice, on every grid command; ``cuda`` refused where it cannot run."""
    return [c for cmd in _commands_with("--device")
            for c in _values(cmd, "--device", ["", "gpu", "CUDA"]
                             + (["cuda"] if cmd in BASES else []))]


def _misc():
    return [
        Case("(no command)", "", {}, r"COMMAND|command", base=False),
        Case("frobnicate --out x", "frobnicate", {"--out": ["{out}"]}, r"frobnicate",
             base=False),
        # rockjit compile takes only --quiet: everything else is refused
        Case("compile --all", "compile", {"--all": True}, r"--all", extra_ok=True, base=False),
        Case("compile --out x", "compile", {"--out": ["{out}"]}, r"--out", extra_ok=True,
             base=False),
        Case("compile --threads 2", "compile", {"--threads": ["2"]}, r"--threads",
             extra_ok=True, base=False),
        Case("compile --quiet nan", "compile", {"--quiet": ["nan"]}, r"nan", extra_ok=True,
             base=False),
    ]


def _numbers():
    """Numbers as a hostile user types them: digit separators, other scripts' digits (Arabic-
    Indic, fullwidth), spaces, in single and multi-valued options; each was taken as a number."""
    basin = {"--hb": ["1"], "--alpha": ["0.66"], "--omega": ["1.3"], "--out": ["{out}"]}

    def case(text, cmd, opts, names):
        return Case(f"numbers: {text}", cmd, opts, names, base=False)

    return [
        case("basin --grid 1_0", "basin", {**basin, "--grid": ["1_0"]}, NAMES["--grid"]),
        case("basin --grid \u0663", "basin", {**basin, "--grid": ["\u0663"]}, NAMES["--grid"]),
        case("basin --grid \uff11", "basin", {**basin, "--grid": ["\uff11"]}, NAMES["--grid"]),
        case("basin --alpha \uff10.\uff16", "basin", {**basin, "--alpha": ["\uff10.\uff16"]},
             NAMES["--alpha"]),
        case("basin --theta-range -\u0661 1", "basin",
             {**basin, "--theta-range": ["-\u0661", "1"]}, NAMES["--theta-range"]),
        case("plane --grid 5 \u0663", "plane",
             {"--hb": ["1"], "--alpha-range": ["0.5", "0.6"], "--omega-range": ["1", "2"],
              "--grid": ["5", "\u0663"], "--out": ["{out}"]}, NAMES["--grid"]),
        case("sweep --alpha-range 0.5 0.6_0", "sweep",
             {"--hb": ["1"], "--omega": ["1.3"], "--alpha-range": ["0.5", "0.6_0"],
              "--out": ["{out}"]}, NAMES["--alpha-range"]),
        case("cor --hb-values 1 \uff12", "cor", {"--hb-values": ["1", "\uff12"],
                                               "--out": ["{out}"]}, NAMES["--hb-values"]),
        case("trajectory --periods '1 0'", "trajectory",
             {"--hb": ["1"], "--alpha": ["0.6"], "--omega": ["1.3"], "--periods": ["1 0"],
              "--out": ["{out}"]}, NAMES["--periods"]),
    ]


CASES = (_refusals() + _trajectory() + _sweep() + _basin() + _plane() + _cor() + _paper()
         + _erosion() + _safety() + _fate() + _orbits() + _chart() + _grid_extras("sweep")
         + _grid_extras("basin")
         + _grid_extras("plane") + _real_opt("paper", "--erosion-step", ["0", "-0.01", "5e-324"])
         + _int_opt("paper", "--erosion-grid", ["0", "-1", HUGE_INT])
         + [c for cmd in ("sweep", "basin", "plane", "erosion", "orbits", "paper", "chart",
                          "safety", "spectrum", "fragility")
            for c in _scheduler_cases(cmd)]
         + [c for cmd in ("chart", "erosion", "orbits", "fate")
            for c in _real_opt(cmd, "--xi", ["-1", "-1e-3", "1e5"])]
         + _numbers() + _spectrum() + _fragility() + _explore() + _figure_options() + _misc())


# ---------------------------------------------------------------------------------------------
# Valid command lines the bad values are embedded in (drawn with the seed)
# ---------------------------------------------------------------------------------------------

BASES = {
    "trajectory": {"--hb": ["1", "1.5", "2", "3"], "--alpha": ["0", "0.2", "0.6", "0.8"],
                   "--omega": ["1", "1.3", "1.6", "2.5"], "--law": [None, "housner", "mao"],
                   "--periods": [None, "1", "5", "20"], "--n-steps": [None, "64", "160"]},
    "sweep": {"--hb": ["1", "1.5", "2"], "--omega": ["1", "1.3", "1.6"],
              "--alpha-range": [("0.5", "0.6"), ("0.1", "0.2"), ("0.3", "0.35")],
              "--alpha-step": [None, "0.01", "0.05"], "--law": [None, "housner", "mao"],
              "--periods": [None, "5", "20"], "--n-steps": [None, "64"]},
    "basin": {"--hb": ["1", "2"], "--alpha": ["0.2", "0.66"], "--omega": ["1.3", "1.6"],
              "--law": [None, "housner", "mao", "both"], "--grid": [None, "4", "10"],
              "--periods": [None, "5", "20"], "--n-steps": [None, "64"]},
    "plane": {"--hb": ["1", "2"], "--alpha-range": [("0.1", "0.5"), ("0.5", "1")],
              "--omega-range": [("0.5", "2"), ("1", "1.6")], "--grid": [None, ("4", "5")],
              "--law": [None, "housner", "mao"], "--periods": [None, "5", "20"],
              "--n-steps": [None, "64"]},
    "cor": {"--hb-values": [None, ("1", "2"), ("1.5",)], "--hb-max": [None, "6", "3"]},
    "paper": {"--grid": [None, "4", "10"], "--periods": [None, "5", "20"],
              "--alpha-step": [None, "0.1", "0.05"], "--n-steps": [None, "64"]},
    "erosion": {"--hb": ["1", "2"], "--omega": ["1.3", "1.6"],
                "--alpha-range": [("0.5", "0.6"), ("0.1", "0.2")],
                "--alpha-step": [None, "0.05"], "--law": [None, "housner", "both"],
                "--grid": [None, "4"], "--periods": [None, "5"], "--n-steps": [None, "64"]},
    "orbits": {"--hb": ["1", "2"], "--omega": ["1.3", "1.6"],
               "--alpha-range": [("0.5", "0.6"), ("0.1", "0.2")],
               "--alpha-step": [None, "0.01"], "--law": [None, "housner", "mao"]},
    "chart": {"--hb": ["1", "2"], "--alpha-range": [("0.2", "1.2"), ("0.5", "1")],
              "--omega-range": [("0.8", "3"), ("1", "1.6")], "--grid": [None, ("4", "5")],
              "--law": [None, "housner", "mao", "both"], "--periods": [None, "5", "20"],
              "--max-period": [None, "1", "2"]},
    "safety": {"--hb": ["1", "2"], "--alpha-range": [("0.5", "0.6"), ("0.1", "0.2")],
               "--omega-range": [("1.2", "1.3"), ("1", "1.6")], "--grid": [None, ("2", "3")],
               "--lattice": [None, "4"], "--law": [None, "housner", "both"],
               "--periods": [None, "5"], "--levels": [None, ("0.5",), ("0.2", "0.8")]},
    "fate": {"--hb": ["1", "2"], "--alpha": ["0.6", "0.969"], "--omega": ["1.3", "1.6"],
             "--ensemble": [None, "8"], "--periods": [None, "5"], "--n-steps": [None, "64"]},
    "spectrum": {"--hb": ["1", "2", "4"], "--law": [None, "housner", "mao", "both"],
                 "--pulse": [None, "sine", "cosine", "ricker"],
                 "--ratio-range": [("1", "4"), ("0.5", "8")],
                 "--amplitude-range": [("1", "5"), ("1.5", "12")],
                 "--grid": [None, ("3", "4")], "--tol": [None, "1e-4"]},
    "fragility": {"--hb": ["2", "3"], "--law": [None, "mao", "both"],
                  "--size": [("1",), ("0.5", "2")], "--records": [(RECORD_OK,)],
                  "--intensities": [None, ("1.5", "3")], "--measure": [None, "pga"]},
}


CASES += _device_options()


def argv_of(case, out):
    """The case's argument vector, options in a seeded order, ``{out}`` replaced."""
    rng = random.Random(f"{SEED}:{case.id}")
    opts = {}
    if case.base and case.cmd in BASES:
        for opt, choices in BASES[case.cmd].items():
            v = rng.choice(choices)
            if v is not None:
                opts[opt] = [v] if isinstance(v, str) else list(v)
        if rng.random() < 0.5:
            opts["--quiet"] = True
        opts["--out"] = ["{out}"]
    for opt, v in case.set.items():
        opts[opt] = v
    groups, last = [], []
    for opt, v in opts.items():
        if v is None:
            continue
        if v is True:
            groups.append([opt])
        elif v == []:
            last.append([opt])
        else:
            groups.append([opt] + [out if x == "{out}" else x for x in v])
    rng.shuffle(groups)
    argv = [case.cmd] if case.cmd else []
    for g in groups + last:
        argv += g
    return argv


# ---------------------------------------------------------------------------------------------
# Running a case
# ---------------------------------------------------------------------------------------------

@lru_cache(maxsize=None)
def _cli_options(cmd):
    """The option strings the parser knows for subcommand ``cmd``."""
    sub = next(a for a in build_parser()._actions if a.dest == "command")
    return frozenset(sub.choices[cmd]._option_string_actions) if cmd in sub.choices else \
        frozenset()


def _resolve(target):
    mod_name, attr = target.split(":")
    try:
        mod = importlib.import_module(mod_name)
    except ImportError:
        return None, attr
    return mod, attr


@pytest.fixture(scope="module")
def reached():
    """Replace every entry point of real work by a sentinel; the list records what was reached."""
    calls = []
    # import every module the CLI may import lazily first: one imported while the patches are
    # in place would keep a sentinel under its own name for the rest of the test run
    for name in ("grids.plan", "ground.batch", "ground.spectrum", "ground.fragility",
                 "ground.reference", "grids.identity", "basins.erosion", "basins.fate",
                 "orbits.arclength", "orbits.plane_chart", "outputs", "plotting.figures",
                 "study.paper"):
        importlib.import_module(f"rockjit.{name}")
    _GUARDS["calls"] = calls
    _GUARDS["mp"] = _install_guards(calls)
    yield calls
    _GUARDS.pop("mp").undo()


#: The sentinels in place (``mp``) and the list they record into (``calls``), while ``reached``
#: is: :func:`unguarded` lifts them for the tests that run real work.
_GUARDS = {}


def _install_guards(calls):
    mp = pytest.MonkeyPatch()
    for target in GUARDED + GUARDED_IF_PRESENT:
        mod, attr = _resolve(target)
        if mod is None or not hasattr(mod, attr):
            continue

        def sentinel(*args, _target=target, **kwargs):
            calls.append(_target)
            raise NotRefused(f"{_target} was called")

        # an entry point plans through its .plan (validation only): that stays reachable
        if hasattr(getattr(mod, attr), "plan"):
            sentinel.plan = getattr(mod, attr).plan
        mp.setattr(mod, attr, sentinel)
    return mp


@pytest.fixture
def unguarded():
    """The real entry points of work for one test, the sentinels put back after it."""
    mp = _GUARDS.pop("mp", None)
    if mp is not None:
        mp.undo()
    try:
        yield
    finally:
        if mp is not None:
            _GUARDS["mp"] = _install_guards(_GUARDS["calls"])


def _snapshot(root):
    """Everything under ``root``: path -> (kind, mode, size, content hash)."""
    snap = {}
    for dirpath, dirnames, filenames in os.walk(root):
        for name in dirnames + filenames:
            p = os.path.join(dirpath, name)
            st = os.lstat(p)
            digest = None
            if stat.S_ISREG(st.st_mode):
                with open(p, "rb") as fh:
                    digest = hashlib.sha256(fh.read()).hexdigest()
            snap[os.path.relpath(p, root)] = (stat.S_IFMT(st.st_mode), stat.S_IMODE(st.st_mode),
                                              st.st_size, digest)
    return snap


def _prepare(case, root):
    """Files the case needs beforehand; returns the ``--out`` path to use."""
    out = os.path.join(root, "out")
    if case.setup == "out-file":
        with open(out, "w") as fh:
            fh.write("a user's file, not a directory\n")
    elif case.setup == "out-in-file":
        with open(os.path.join(root, "f"), "w") as fh:
            fh.write("a user's file\n")
        out = os.path.join(root, "f", "sub")
    elif case.setup == "chunks-file":
        with open(out + ".chunks", "w") as fh:
            fh.write("a user's file named like the chunk store\n")
    elif case.setup == "out-dangling":
        os.symlink(os.path.join(root, "nowhere"), out)
    elif case.setup == "out-loop":
        os.symlink("out", out)
    elif case.setup == "out-in-dangling":
        os.symlink(os.path.join(root, "nowhere"), out)
        out = os.path.join(out, "sub")
    elif case.setup == "out-holds-summary-dir":
        os.makedirs(os.path.join(out, "summary.json"))
    elif case.setup == "chunks-dangling":
        os.symlink(os.path.join(root, "nowhere"), out + ".chunks")
    return out


def run_main(argv, reached, cwd, trace=False):
    """``main(argv)`` in ``cwd``; returns (status or None, exception or None, stdout, stderr,
    warnings, peak bytes allocated or None when not traced)."""
    reached.clear()
    out, err = io.StringIO(), io.StringIO()
    tracing = tracemalloc.is_tracing()
    old_cwd = os.getcwd()
    peak = None
    with warnings.catch_warnings(record=True) as caught, contextlib.redirect_stdout(out), \
            contextlib.redirect_stderr(err):
        warnings.simplefilter("always")
        os.chdir(cwd)
        if trace:
            if not tracing:
                tracemalloc.start()
            tracemalloc.reset_peak()
            base = tracemalloc.get_traced_memory()[0]
        try:
            rc, exc = main(argv), None
        except KeyboardInterrupt:
            raise
        except BaseException as e:  # noqa: BLE001 - any escape is a finding, reported below
            rc, exc = None, e
        finally:
            os.chdir(old_cwd)
            if trace:
                peak = tracemalloc.get_traced_memory()[1] - base
                if not tracing:
                    tracemalloc.stop()
    return rc, exc, out.getvalue(), err.getvalue(), list(caught), peak


#: values that ask for something big: allocation is traced on the cases that use them (tracing
#: every case would triple the module's time)
BIG = {HUGE_INT, "1e308", "-1e308", "5e-324", "1e300", "1e-300", "1e-8", "1e-12",
       "1000000000000", "4000000000", "100000", "1000000000"}


def _traced(case):
    return any(isinstance(v, list) and BIG.intersection(v) for v in case.set.values())


@pytest.fixture(scope="module")
def workdir(tmp_path_factory):
    return tmp_path_factory.mktemp("fuzz")


def _param(case):
    """A case, skipped while it needs a guessed option the parser does not have (optional)."""
    absent = case.guessed and not case.guessed_required and \
        case.guessed not in _cli_options(case.cmd)
    marks = pytest.mark.skip(reason=f"guessed option {case.guessed} is not in `rockjit "
                                    f"{case.cmd}`: expose it, or adjust this case") \
        if absent else ()
    return pytest.param(case, id=case.id, marks=marks)


@pytest.mark.parametrize("case", [_param(c) for c in CASES])
def test_bad_input_is_refused(case, reached, workdir):
    root = tempfile.mkdtemp(dir=workdir)  # the current directory of the command
    out = _prepare(case, root)
    argv = argv_of(case, out)
    before = _snapshot(root)
    rc, exc, stdout, stderr, caught, peak = run_main(argv, reached, root, _traced(case))
    problem = verdict(case, rc, exc, stdout, stderr, caught, peak, reached)
    if problem is None and _snapshot(root) != before:
        problem = "wrote: files changed under the current directory"
    if problem:
        # pytrace=False: the message says it all (and rendering ~200 tracebacks is slow)
        pytest.fail(f"{problem}\nargv = {argv!r}\nstderr = {stderr!r}", pytrace=False)


def verdict(case, rc, exc, stdout, stderr, caught, peak, reached):
    """The first way the command failed the specification (a short cause first), or None."""
    if isinstance(exc, NotRefused):
        return f"not refused before work: reached {reached[0]}"
    if exc is not None:
        return f"traceback: raised {type(exc).__name__}: {exc}"
    if rc != 2:
        return f"exit status {rc}, not 2"
    if "Traceback" in stdout + stderr:
        return "traceback in the output"
    if stdout:
        return f"wrote on stdout: {stdout!r}"
    if not (stderr.endswith("\n") and stderr.count("\n") == 1):
        return "not one line on stderr"
    line = stderr.rstrip("\n")
    if not line.startswith("rockjit: error:"):
        return "the line does not start with 'rockjit: error:'"
    if caught:
        return f"warned: {[str(w.message) for w in caught]}"
    msg = line[len("rockjit: error:"):]
    if not case.extra_ok and "unrecognized arguments" in msg:
        return "refused as an unknown option"
    if not case.nargs_ok and re.search(TAKEN_FOR_AN_OPTION, msg):
        return "a value was taken for an option (argparse and negative numbers)"
    if not re.search(case.names, msg):
        return f"the message does not name {case.names!r}"
    for pattern in case.forbid:
        if re.search(pattern, msg):
            return f"the message says {pattern!r}"
    if case.n_at_least is not None and not any(
            int(n) >= case.n_at_least for n in re.findall(r"(?<![\d.])\d+(?![\d.])", msg)):
        return f"the message does not give the N needed (>= {case.n_at_least})"
    if case.memory and not re.search(MEMORY_MESSAGE, msg):
        return "no memory estimate ('would need ...; at most ... fits') in the message"
    if peak is not None and peak >= ALLOC_LIMIT:
        return f"allocated {peak / 2**20:.0f} MiB before refusing"
    return None


# ---------------------------------------------------------------------------------------------
# Negative numbers in e-notation are numbers
# ---------------------------------------------------------------------------------------------

#: (command line up to the value, the value's words, argparse dest, the number expected)
ACCEPTED = [
    (["trajectory", "--hb", "1", "--alpha", "0.6", "--omega", "1.3"], ["--theta0", "-1e-3"],
     "theta0", -1e-3),
    (["trajectory", "--hb", "1", "--alpha", "0.6", "--omega", "1.3"], ["--dtheta0", "-2.5e-1"],
     "dtheta0", -0.25),
    (["basin", "--hb", "1", "--alpha", "0.66", "--omega", "1.3"],
     ["--dtheta-range", "-1e-2", "1e-2"], "dtheta_range", [-0.01, 0.01]),
    (["basin", "--hb", "1", "--alpha", "0.66", "--omega", "1.3"],
     ["--theta-range", "-1E-1", "-1e-2"], "theta_range", [-0.1, -0.01]),
    (["sweep", "--hb", "1", "--omega", "1.3", "--alpha-range", "0.5", "0.6"],
     ["--theta0", "-2e-1"], "theta0", -0.2),
    (["plane", "--hb", "1", "--alpha-range", "0.5", "0.6", "--omega-range", "1", "2"],
     ["--phase", "-1e-1"], "phase", -0.1),
    (["basin", "--hb", "1", "--alpha", "0.66", "--omega", "1.3"], ["--r0", "-1e-3", "--s0", "1"],
     "r0", -1e-3),
    (["trajectory", "--hb", "1", "--alpha", "0.6", "--omega", "1.3"], ["--dtheta0", "-.5e+0"],
     "dtheta0", -0.5),
]
ACCEPTED_IDS = [f"{base[0]} {' '.join(words)}" for base, words, _, _ in ACCEPTED]


@pytest.mark.parametrize("base, words, dest, value", ACCEPTED, ids=ACCEPTED_IDS)
def test_negative_e_notation_parses(base, words, dest, value):
    try:
        args = build_parser().parse_args(base + words + ["--out", "unused"])
    except Exception as exc:  # noqa: BLE001 - the CLI's parser raises UsageError
        pytest.fail(f"refused at parsing: {exc}", pytrace=False)
    got = getattr(args, dest)
    assert (list(got) if isinstance(value, list) else got) == pytest.approx(value)


@pytest.mark.parametrize("base, words", [a[:2] for a in ACCEPTED[:3]], ids=ACCEPTED_IDS[:3])
def test_negative_e_notation_passes_validation(base, words, reached, tmp_path):
    # valid input: validation lets it through to the (guarded) work, with no error line
    rc, exc, _, err, _, _ = run_main(base + words + ["--quiet", "--out", str(tmp_path / "o")],
                                     reached, tmp_path)
    if not isinstance(exc, NotRefused):
        pytest.fail(f"not let through: status {rc}, exception {exc!r}, stderr {err!r}",
                    pytrace=False)
    assert err == ""


# ---------------------------------------------------------------------------------------------
# The test's own machinery
# ---------------------------------------------------------------------------------------------

def test_guards_exist():
    missing = [t for t in GUARDED if (lambda m, a: m is None or not hasattr(m, a))(*_resolve(t))]
    assert not missing, f"update GUARDED at the top of this file: {missing} no longer exist"


def test_cases_are_distinct_and_many():
    ids = [c.id for c in CASES]
    assert len(ids) == len(set(ids)), sorted({i for i in ids if ids.count(i) > 1})
    assert len({tuple(argv_of(c, "OUT")) + (c.setup,) for c in CASES}) == len(CASES)
    assert len(CASES) > 150
    for c in CASES:
        for opt in c.set:
            assert opt in NAMES or opt in FLAGS or opt.startswith("--rtol=") or \
                opt == "--frobnicate" or c.extra_ok, (c.id, opt)  # extra_ok: must not exist


@pytest.mark.parametrize("argv", [
    ["spectrum", "--hb", "4", "--law", "both", "--ratio-range", "1", "4", "--amplitude-range",
     "1", "6", "--grid", "3", "3"],
    ["fragility", "--hb", "2", "--size", "1", "--records", RECORD_OK, "--intensities", "1.5"]],
    ids=["spectrum", "fragility"])
def test_guard_stops_valid_ground_motion_commands(argv, reached, tmp_path):
    # a valid spectrum or fragility gets through validation to its (guarded) work
    rc, exc, _, err, _, _ = run_main(argv + ["--quiet", "--out", str(tmp_path / "o")],
                                     reached, tmp_path)
    assert isinstance(exc, NotRefused) and reached[0] in GUARDED, (rc, exc, err)
    assert err == "" and not (tmp_path / "o").exists()


def test_guard_stops_a_valid_command(reached, tmp_path):
    # the sentinel does fire on a valid command line: the refusal test can tell the difference
    rc, exc, _, err, _, _ = run_main(["basin", "--hb", "1", "--alpha", "0.66", "--omega", "1.3",
                                      "--grid", "4", "--quiet", "--out", str(tmp_path / "o")],
                                     reached, tmp_path)
    assert isinstance(exc, NotRefused) and reached[0] in GUARDED + GUARDED_IF_PRESENT
    assert err == "" and not (tmp_path / "o").exists()


# ---------------------------------------------------------------------------------------------
# The edges of every documented range: refused in one line, or run to the end
# ---------------------------------------------------------------------------------------------

def _numeric_options():
    """``(command, option, nargs)`` of every option of the parser that takes numbers."""
    import argparse
    sub = next(a for a in build_parser()._actions if isinstance(a, argparse._SubParsersAction))
    return [(cmd, a.option_strings[-1], a.nargs) for cmd, p in sorted(sub.choices.items())
            for a in p._actions if a.type in (int, float) and a.option_strings]


#: Values at the edge of every range, whatever the range: tiny (subnormal too), huge, signed
#: zero, non-finite
EDGE_REALS = ["1e-320", "1e308", "-1e308", "-0.0", "nan", "inf"]
EDGE_INTS = ["0", "-1", "1000000000000000", HUGE_INT]


def _edge_values(kind, lo, hi):
    """The range's ends and the numbers just outside them, and the generic edges."""
    vals = []
    for bound, outward in ((lo, -math.inf), (hi, math.inf)):
        if bound is None:
            continue
        if kind == "int":
            vals += [str(int(bound)), str(int(bound) + (1 if outward > 0 else -1))]
        else:
            vals += [repr(float(bound)), repr(math.nextafter(float(bound), outward))]
    vals += EDGE_INTS if kind == "int" else EDGE_REALS
    return list(dict.fromkeys(vals))


#: Small valid command lines the edge values are put into: where a run happens it is short
EDGE_BASES = {
    "trajectory": "--hb 2 --alpha 0.2 --omega 1.3 --periods 1 --max-points 100",
    "sweep": "--hb 2 --omega 1.3 --alpha-range 0.1 0.1 --alpha-step 0.05 --periods 1",
    "basin": "--hb 2 --alpha 0.2 --omega 1.3 --grid 2 --periods 1",
    "plane": "--hb 2 --alpha-range 0.1 0.2 --omega-range 1.2 1.3 --grid 2 2 --periods 1",
    "erosion": "--hb 2 --omega 1.3 --alpha-range 0.1 0.1 --alpha-step 0.05 --grid 2 --periods 1",
    "orbits": "--hb 2 --omega 1.3 --alpha-range 0.1 0.11 --alpha-step 0.01 --periods 2 "
              "--max-period 1",
    "chart": "--hb 2 --alpha-range 0.1 0.2 --omega-range 1.2 1.3 --grid 2 2 --periods 2 "
             "--max-period 1 --seed-omegas 1.25",
    "safety": "--hb 2 --alpha-range 0.1 0.2 --omega-range 1.2 1.3 --grid 2 2 --lattice 2 "
              "--periods 1",
    "fate": "--hb 2 --alpha 0.2 --omega 1.3 --periods 1 --ensemble 2",
    "spectrum": "--hb 4 --ratio-range 1 2 --amplitude-range 1 2 --grid 2 2 --free-time 5",
    "fragility": f"--hb 3 --size 1 --records {RECORD_OK} --intensities 1.5 --free-time 5",
    "cor": "--hb-values 2 --hb-max 3",
    "paper": "--grid 2 --periods 1 --alpha-step 0.5 --erosion-grid 2 --erosion-step 0.5",
    "explore": "--no-browser",
}
#: Commands whose accepted edge values are taken to their (guarded) work and not further: the
#: paper's whole set of figures and the explorer's server are not short runs
GUARD_ONLY = {"paper", "explore"}
#: Accepted edge values that ask for much legitimate work (minutes, not years, or a server):
#: checked as far as the start of the work
LONG_EDGES = {("fate", "--ensemble", "1000000"), ("spectrum", "--grid", "10000"),
              ("fragility", "--size", "0.001"),  # a 1 mm block: about a minute
              ("safety", "--grid", "1000")}


def _long(case):
    cmd, opt, vals = case
    return any((cmd, opt, v) in LONG_EDGES for v in vals)


def _edge_cases():
    cases = []
    for cmd, opt, nargs in _numeric_options():
        rng = range_of(cmd, opt)
        assert rng is not None, f"{cmd} {opt}: add its documented range to RANGES"
        kind, lo, hi = rng
        for v in _edge_values(kind, lo, hi):
            vals = [v, v] if nargs == 2 else [v]
            cases.append((cmd, opt, vals))
        if nargs == 2 and lo is not None and hi is not None:
            cases.append((cmd, opt, [_edge_values(kind, lo, hi)[0],
                                     _edge_values(kind, lo, hi)[2]]))
    return cases


EDGE_CASES = _edge_cases()


def _edge_argv(cmd, opt, vals, out):
    words = shlex.split(EDGE_BASES[cmd])
    if opt in words:  # the edge value replaces the base's
        k = words.index(opt)
        n = 1
        while k + n < len(words) and not words[k + n].startswith("--"):
            n += 1
        del words[k:k + n]
    return [cmd] + words + [opt] + vals + (["--out", out] if cmd != "explore" else []) \
        + ["--quiet"] * (cmd != "explore")


def test_every_numeric_option_has_a_documented_range():
    # a new option cannot escape the edge test: its range must be listed here
    missing = [(c, o) for c, o, _ in _numeric_options() if range_of(c, o) is None]
    assert not missing, missing
    assert set(EDGE_BASES) == {c for c, _, _ in _numeric_options()} | {"explore"} - {""}


def _edge_id(case):
    cmd, opt, vals = case
    return f"{cmd} {opt} {' '.join(vals)}"


def _run_edge(cmd, opt, vals, tmp_path, guarded):
    """``main`` on the edge case, the work's entry points guarded or real: ``(problem, the
    error line)``; no problem is exit status 0 (with its summary written), or 2 with one line,
    or its (guarded) work reached."""
    argv = _edge_argv(cmd, opt, vals, str(tmp_path / "out"))
    if guarded and "mp" not in _GUARDS:
        _GUARDS["mp"] = _install_guards(_GUARDS["calls"])
    rc, exc, stdout, stderr, _, _ = run_main(argv, _GUARDS["calls"], tmp_path)
    where = f"\nargv = {argv!r}\nstderr = {stderr!r}"
    if isinstance(exc, NotRefused):
        return (None if guarded else f"reached a guard while unguarded{where}"), None
    if exc is not None:
        return f"raised {type(exc).__name__}: {exc}{where}", None
    if "Traceback" in stdout + stderr or "internal error" in stderr:
        return f"a traceback or an internal error{where}", None
    if rc == 0:
        return (None if (tmp_path / "out" / "summary.json").exists()
                else f"no summary{where}"), None
    if rc != 2:
        return f"exit status {rc}{where}", None
    if not (stderr.startswith("rockjit: error:") and stderr.count("\n") == 1):
        return f"not one line 'rockjit: error: ...'{where}", None
    return None, stderr


@pytest.mark.parametrize("case", EDGE_CASES, ids=[_edge_id(c) for c in EDGE_CASES])
def test_the_edges_of_every_range_are_refused_in_one_line_or_accepted(case, tmp_path,
                                                                      reached):
    """Every edge value: exit status 2 with one line, or let through to the work (guarded);
    a value outside its range refused, naming the option."""
    problem, line = _run_edge(*case, tmp_path, guarded=True)
    if problem is None and not _inside(case):
        cmd, opt, vals = case
        if line is None:
            problem = f"accepted outside its documented range {range_of(cmd, opt)}"
        elif not re.search(NAMES[opt], line.removeprefix("rockjit: error:")):
            problem = f"the message does not name {opt}: {line!r}"
    if problem:
        pytest.fail(problem, pytrace=False)


def _inside(case):
    cmd, opt, vals = case
    kind, lo, hi = range_of(cmd, opt)
    try:
        x = [(int if kind == "int" else float)(v) for v in vals]
    except (ValueError, OverflowError):
        return False
    return all((kind == "int" or math.isfinite(v)) and (lo is None or v >= lo)
               and (hi is None or v <= hi) for v in x)


#: Edge values that once ended in a traceback after validation, run for real on every command
#: that takes them (the rest of the accepted edge values are drawn, EDGE_RUNS_PER_COMMAND a
#: command, with the seed)
EDGE_REGRESSIONS = {("--xi", ("1e-320",)), ("--periods", ("922337203685478",)),
                    ("--ratio-range", ("0.005", "0.01"))}
EDGE_RUNS_PER_COMMAND = 2


def _edge_runs():
    rng = random.Random(f"{SEED}:edges")
    runs = []
    for cmd in sorted(EDGE_BASES):
        if cmd in GUARD_ONLY:
            continue
        inside = [c for c in EDGE_CASES if c[0] == cmd and _inside(c)
                  and not _long(c)]
        runs += rng.sample(inside, min(EDGE_RUNS_PER_COMMAND, len(inside)))
        for opt, vals in sorted(EDGE_REGRESSIONS):
            if any(o == opt for c, o, _ in _numeric_options() if c == cmd):
                case = (cmd, opt, list(vals))
                if case not in runs:
                    runs.append(case)
    return runs


EDGE_RUNS = _edge_runs()


@pytest.mark.parametrize("case", EDGE_RUNS, ids=[_edge_id(c) for c in EDGE_RUNS])
def test_accepted_edges_run_to_the_end(case, tmp_path, reached, unguarded):
    """Accepted edge values, run for real on small grids: exit status 0 with the outputs
    written, or 2 with one line (a check only the run can make); never a traceback."""
    problem, _ = _run_edge(*case, tmp_path, guarded=False)
    if problem:
        pytest.fail(problem, pytrace=False)
