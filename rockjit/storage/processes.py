"""Who holds a lock or a hidden directory: this machine's name, whether a process lives, when it
started and under which boot, so that what a dead run left behind can be told from a live
run's and removed."""

from __future__ import annotations

import os
import socket

__all__ = ["boot_id", "boot_time", "host_name", "pid_alive", "process_start",
           "process_start_time"]


def host_name():
    """This machine's name, reduced to letters, digits, ``.``, ``-`` and ``_``."""
    name = "".join(c if c.isalnum() or c in ".-_" else "_" for c in socket.gethostname())
    return name or "localhost"


def pid_alive(pid):
    """Whether process ``pid`` exists on this machine (a zombie counts as alive)."""
    if pid <= 0:
        return False
    try:
        os.kill(pid, 0)
    except ProcessLookupError:
        return False
    except PermissionError:  # another user's process
        return True
    except OSError:
        return True  # cannot tell: assume alive, which never deletes anything
    return True


def process_start(pid):
    """When process ``pid`` started, in clock ticks since boot (``/proc/<pid>/stat``, field
    22), or ``None`` where that cannot be read (no such process, no ``/proc``). Together with
    the pid it names one process: a pid reused by a later process has a later start."""
    try:
        with open(f"/proc/{int(pid)}/stat", "rb") as fh:
            stat_line = fh.read()
        # the command name (field 2) is in parentheses and may hold spaces or ')'
        return int(stat_line[stat_line.rindex(b")") + 2:].split()[19])
    except (OSError, ValueError, IndexError):
        return None


def boot_id():
    """This boot's identifier (``/proc/sys/kernel/random/boot_id``), or ``None`` where there is
    none: a pid recorded under another boot id names a process of an earlier boot."""
    try:
        with open("/proc/sys/kernel/random/boot_id", encoding="ascii") as fh:
            return fh.read().strip() or None
    except (OSError, ValueError):
        return None


def boot_time():
    """When this machine booted (seconds since the epoch; ``btime`` of ``/proc/stat``), or
    ``None`` where that cannot be read."""
    try:
        with open("/proc/stat", encoding="ascii") as fh:
            for line in fh:
                if line.startswith("btime "):
                    return float(line.split()[1])
    except (OSError, ValueError, IndexError):
        pass
    return None


def process_start_time(pid):
    """When process ``pid`` started, in seconds since the epoch, or ``None`` (see
    :func:`process_start`)."""
    ticks, booted = process_start(pid), boot_time()
    if ticks is None or booted is None:
        return None
    try:
        return booted + ticks / os.sysconf("SC_CLK_TCK")
    except (AttributeError, ValueError, OSError):
        return None
