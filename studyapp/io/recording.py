"""Signal recordings: the paper's data set format (Sec. 6.1), on disk and in memory.

A ``Recording`` is a sample rate, a set of equally long columns and a dict of
metadata. On disk it is one of

- ``.h5``  HDF5: one dataset per column, metadata as JSON in the root attribute ``meta``;
- ``.npz`` NumPy: one array per column plus ``__meta__`` (JSON text);
- ``.csv`` exchange: a header with the columns ``COLUMNS`` in that order, then one row per
  sample, nothing else (any CSV reader takes it as is). It carries no metadata: ``load``
  recovers the rate from ``t``. A leading ``# {json}`` comment line is accepted on input.

The metadata's ``environment`` is ``studyapp.provenance.environment()`` of the program that wrote
the file: versions, git commit, CPU model, BLAS kernels.

Units are SI: t (s), position (m), velocity_lvt, velocity_true, string_velocity (m/s),
acceleration, acceleration_true (m/s^2), force (N, the force commanded on the handle),
audio (arbitrary units, the body filter's output).

Writes are atomic (``studyapp.io.atomic``): a failure leaves no partial file. ``load``
raises ``InputDataError`` naming the file and what is wrong with it. It holds the whole
recording in memory, so it reads at most ``LOAD_LIMIT`` bytes: the file, and what an
archive's members unpack to, checked before anything is read (``archive_bounds``;
a FIFO, device or sparse file is refused from its status, ``special_files``,
``file_bounds``); a column must hold real numbers (not booleans, complex numbers
or text), and the metadata's ``rate`` a positive number.
"""

import json
import os
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from studyapp import __version__
from studyapp.errors import InputDataError, UserError
from studyapp.io import bounded_json
from studyapp.io.archive_bounds import check_h5, open_npz
from studyapp.io.file_bounds import check_not_sparse, check_size
from studyapp.io.small_files import open_regular
from studyapp.io.special_files import refuse_special
from studyapp.io.atomic import atomic_open
from studyapp.io.h5_output import H5Output
from studyapp.provenance import environment

COLUMNS = (
    "t", "position", "velocity_lvt", "acceleration", "velocity_true",
    "acceleration_true", "force", "string_velocity", "audio",
)
SUFFIXES = (".h5", ".npz", ".csv")
LOAD_LIMIT = 1 << 30  # bytes a whole recording may take in memory: 15 M samples of 9 columns, 50 min at 5 kHz
HEADER_LIMIT = 1 << 20  # characters of a CSV recording's metadata line or header
FORMAT_VERSION = 1  # stored as meta["format"]; meta["version"] is the app's version


@dataclass
class Recording:
    """``rate`` (Hz), ``columns`` (name -> 1-D float64 array, all the same length), ``meta``."""

    rate: float
    columns: dict
    meta: dict = field(default_factory=dict)

    def __post_init__(self):
        self.rate = float(self.rate)
        self.columns = {k: np.ascontiguousarray(v, dtype=np.float64) for k, v in self.columns.items()}
        lengths = {v.shape for v in self.columns.values()}
        if len(lengths) > 1 or any(len(s) != 1 for s in lengths):
            raise InputDataError(f"recording columns must be 1-D arrays of one length, got shapes {sorted(lengths)}")

    def __len__(self):
        return next(iter(self.columns.values())).shape[0] if self.columns else 0

    def __getitem__(self, name):
        return self.columns[name]


def _suffix(path):
    suffix = Path(path).suffix.lower()
    if suffix not in SUFFIXES:
        raise UserError(f"{path}: unknown recording format {suffix or '(no suffix)'!r}: allowed are {', '.join(SUFFIXES)}")
    return suffix


def check_path(path):
    """Raise ``UserError`` unless ``path`` has a recording suffix (call before a long job)."""
    _suffix(path)


def _meta_json(recording):
    """The metadata as written: the recording's own, its rate, and the environment of the writer (the
    software and machine writing the file now, even when the recording was read from another's)."""
    meta = {"format": FORMAT_VERSION, "version": __version__, **recording.meta, "rate": recording.rate,
            "environment": environment()}
    return json.dumps(meta, sort_keys=True, default=_plain)


def _plain(value):
    if isinstance(value, np.generic):
        return value.item()
    if isinstance(value, np.ndarray):
        return value.tolist()
    raise TypeError(f"metadata value {value!r} is not JSON")


def save(recording, path):
    """Write ``recording`` to ``path`` (format by suffix: .h5, .npz or .csv), atomically."""
    suffix = _suffix(path)
    meta = _meta_json(recording)
    if suffix == ".npz":
        with atomic_open(path, "wb") as f:
            np.savez(f, __meta__=np.array(meta), **recording.columns)
    elif suffix == ".h5":
        with H5Output(path) as out:
            out.file.attrs["meta"] = meta
            for name, values in recording.columns.items():
                out.file.create_dataset(name, data=values)
    else:
        missing = [c for c in COLUMNS if c not in recording.columns]
        if missing:
            raise InputDataError(f"{path}: a CSV recording needs the columns {', '.join(COLUMNS)}; missing {', '.join(missing)}")
        table = np.column_stack([recording.columns[c] for c in COLUMNS])
        with atomic_open(path, "w", newline="") as f:
            f.write(",".join(COLUMNS) + "\n")
            np.savetxt(f, table, delimiter=",", fmt="%.17g")


def check_file(path):
    """``InputDataError`` unless ``path`` is a regular file, not sparse (file_bounds); its ``os.stat``."""
    refuse_special(path, "a recording file")
    if not os.path.exists(path):
        raise InputDataError(f"{path}: no such file")
    if not os.path.isfile(path):
        raise InputDataError(f"{path}: not a regular file: allowed is a recording file")
    status = os.stat(path)
    check_not_sparse(status, path, "recording")
    return status


def load(path):
    """Read a recording written by ``save`` (or any CSV with the ``COLUMNS`` header), at most ``LOAD_LIMIT``
    bytes of it (a file, or what its members unpack to: archive_bounds)."""
    path = Path(path)
    suffix = _suffix(path)
    check_size(check_file(path).st_size, LOAD_LIMIT, path, "recording file")
    try:
        if suffix == ".npz":
            columns, meta = _load_npz(path)
        elif suffix == ".h5":
            columns, meta = _load_h5(path)
        else:
            columns, meta = _load_csv(path)
    except InputDataError:
        raise
    except Exception as exc:  # any parser failure is a bad input file, reported in one line
        raise InputDataError(f"{path}: not a readable {suffix} recording ({type(exc).__name__}: {exc})") from None
    if not columns or not any(len(values) for values in columns.values()):
        raise InputDataError(f"{path}: no samples: allowed is a recording of at least one sample")
    rate = meta_rate(meta, path)
    if rate is None and "t" in columns and len(columns["t"]) > 1:
        # t is k / rate printed to 17 digits: the rate comes back to within rounding
        span = float(columns["t"][-1] - columns["t"][0])
        rate = round((len(columns["t"]) - 1) / span, 6) if span > 0 else None
    if rate is None or not np.isfinite(float(rate)) or float(rate) <= 0:
        raise InputDataError(f"{path}: no valid sample rate (metadata 'rate' or a 't' column)")
    try:
        return Recording(float(rate), columns, meta)
    except InputDataError as exc:
        raise InputDataError(f"{path}: {exc}") from None


def meta_rate(meta, path):
    """The metadata's ``rate`` as a float, or None when it has none; ``InputDataError`` naming ``path``
    for one that is no positive finite number (metadata is any JSON: ``"abc"``, a list, ``true``)."""
    rate = meta.get("rate")
    if rate is None:
        return None
    if not isinstance(rate, bool):
        try:
            value = float(rate)
        except (TypeError, ValueError):
            value = None
        if value is not None and np.isfinite(value) and value > 0:
            return value
    raise InputDataError(f"{path}: metadata 'rate' = {rate!r}: allowed is a sample rate in Hz (a positive number)")


def parse_meta(text, path):
    """The metadata JSON ``text`` as a dict; ``InputDataError`` naming ``path`` otherwise."""
    try:
        meta = bounded_json.loads(text)
    except ValueError as exc:  # invalid, or nested too deeply
        raise InputDataError(f"{path}: metadata is not valid JSON ({exc})") from None
    if not isinstance(meta, dict):
        raise InputDataError(f"{path}: metadata must be a JSON object")
    return meta


def _load_npz(path):
    archive, _ = open_npz(path, LOAD_LIMIT)
    archive.close()
    with np.load(path, allow_pickle=False) as data:
        meta = parse_meta(str(data["__meta__"]), path) if "__meta__" in data.files else {}
        columns = {k: np.asarray(data[k], dtype=np.float64) for k in data.files if k != "__meta__"}
    return columns, meta


def _load_h5(path):
    import h5py

    with h5py.File(path, "r") as f:
        raw = f.attrs.get("meta", "{}")
        meta = parse_meta(raw.decode() if isinstance(raw, bytes) else str(raw), path)
        check_h5(f, path, LOAD_LIMIT)
        columns = {k: np.asarray(f[k][()], dtype=np.float64) for k in f.keys()}
    return columns, meta


def _load_csv(path):
    meta = {}
    # -sig: a byte order mark (Excel's CSV UTF-8) is accepted
    with open_regular(path, "recording", "r", encoding="utf-8-sig") as f:
        first = f.readline(HEADER_LIMIT)
        if first.startswith("#"):
            meta = parse_meta(first[1:].strip(), path)
            header = f.readline(HEADER_LIMIT)
        else:
            header = first
        names = [h.strip() for h in header.strip().split(",")]
        twice = next((n for i, n in enumerate(names) if n in names[:i]), None)
        if twice is not None:
            raise InputDataError(f"{path}: column {twice!r} appears twice in the header: allowed is each column once")
        missing = [c for c in COLUMNS if c not in names]
        if missing:
            raise InputDataError(f"{path}: CSV header lacks the column(s) {', '.join(missing)}; expected {', '.join(COLUMNS)}")
        try:
            table = np.loadtxt(f, delimiter=",", ndmin=2)
        except ValueError as exc:
            raise InputDataError(f"{path}: bad CSV cell ({exc})") from None
    if table.size == 0:
        table = np.zeros((0, len(names)))
    if table.shape[1] != len(names):
        raise InputDataError(f"{path}: rows have {table.shape[1]} cells, header has {len(names)}")
    return {name: table[:, i].copy() for i, name in enumerate(names)}, meta
