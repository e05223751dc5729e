"""What the command line accepts: its parser class, whose errors are one line
(:class:`UsageError`, exit status 2), and the values of its options (exactly ASCII decimal
numbers, a Dask scheduler's address)."""

from __future__ import annotations

import argparse
import os
import re


class UsageError(Exception):
    """Bad command-line input: reported in one line, exit status 2."""


class Parser(argparse.ArgumentParser):
    """argparse with one-line errors; the options declared ``type=float`` and ``type=int``
    parsed by :func:`_real` and :func:`_int` (exactly ASCII decimal numbers); and anything that
    starts like a negative number taken as a value (``--theta0 -1e-3``, ``--dtheta0 -inf``, and
    ``-1_0`` too, for the number parser to refuse), not as an option."""

    def __init__(self, *a, **kw):
        super().__init__(*a, **kw)
        self.register("type", float, _real)
        self.register("type", int, _int)
        self._negative_number_matcher = re.compile(r"^-(\.?\d|(inf|infinity|nan)$)",
                                                   re.IGNORECASE)

    def error(self, message):
        raise UsageError(message)


# ---------------------------------------------------------------------------------------------
# the values of options: exactly ASCII decimal numbers, a Dask scheduler's address
# ---------------------------------------------------------------------------------------------

_DECIMAL = re.compile(r"[+-]?([0-9]+(\.[0-9]*)?|\.[0-9]+)([eE][+-]?[0-9]+)?")
_NONFINITE = re.compile(r"[+-]?(inf|infinity|nan)", re.IGNORECASE)
_INTEGER = re.compile(r"[+-]?[0-9]+")


def _real(text):
    """A real number option: ``[+-]digits[.digits][e[+-]digits]`` in ASCII, or ``inf``, ``nan``
    (the range checks refuse those, naming the option); no ``_``, no other digits or spaces."""
    if _DECIMAL.fullmatch(text) or _NONFINITE.fullmatch(text):
        return float(text)
    raise argparse.ArgumentTypeError(f"must be a number such as 0.5, -2 or 1e-3 (got {text!r})")


def _int(text):
    """An integer option: ``[+-]digits`` in ASCII."""
    if _INTEGER.fullmatch(text):
        try:
            return int(text)
        except ValueError:  # more digits than Python converts
            raise argparse.ArgumentTypeError(f"is too large ({len(text)} digits)") from None
    raise argparse.ArgumentTypeError(f"must be an integer such as 100 (got {text!r})")


_ADDRESS = re.compile(r"(?:(?P<scheme>[A-Za-z][A-Za-z0-9+.-]*)://)?"
                      r"(?P<host>\[[0-9A-Fa-f:.]+\]|[A-Za-z0-9_.-]+)(?::(?P<port>[0-9]+))?")


def scheduler_address(text):
    """``--scheduler``: a Dask scheduler's address, ``tcp://HOST:PORT`` (or ``tls://``, or
    ``HOST:PORT``) with 1 <= PORT <= 65535, or the path of an existing scheduler file (written by
    ``dask scheduler --scheduler-file``). Checked before connecting."""
    if not text.strip():
        raise argparse.ArgumentTypeError("must be a Dask scheduler's address, tcp://HOST:PORT, "
                                         "or a scheduler file (got an empty string)")
    if "://" not in text and os.path.isfile(text):
        return text
    m = _ADDRESS.fullmatch(text)
    scheme = (m.group("scheme") or "tcp").lower() if m else None
    if m is None or scheme not in ("tcp", "tls") or ("://" not in text and not m.group("port")):
        hint = (" (no such scheduler file)" if "://" not in text and ":" not in text else "")
        raise argparse.ArgumentTypeError(f"must be a Dask scheduler's address, tcp://HOST:PORT, "
                                         f"or an existing scheduler file (got {text!r}){hint}")
    port = m.group("port")
    if port is not None and not 1 <= int(port) <= 65535:
        raise argparse.ArgumentTypeError(f"port must be in [1, 65535] (got {int(port)} in "
                                         f"{text!r})")
    return text
