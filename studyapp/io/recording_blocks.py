"""A recording (``.npz`` or ``.h5``, see ``studyapp.io.recording``) read a block of samples at a time.

``RecordingBlocks(path)`` reads the metadata and the columns' names and
lengths; ``blocks(size)`` yields ``{name: float64 array}`` for runs of
``size`` samples, so memory stays that of one block whatever the recording's
length. An ``.npz`` file is a ZIP archive of one ``.npy`` member per column:
each member is read as a stream (its header, then ``size`` values at a time).
An ``.h5`` file is read by slicing its datasets.

The sample rate is the metadata's ``rate``, else ``(n - 1) / (t[-1] - t[0])``
from the ``t`` column to 6 decimals, as ``recording.load`` finds it. Every
problem is one ``InputDataError`` naming the file.
"""

import zipfile
from pathlib import Path

import numpy as np

from studyapp.errors import InputDataError
from studyapp.io.archive_bounds import check_dtype, check_h5, open_npz
from studyapp.io.recording import check_file, meta_rate, parse_meta

SUFFIXES = (".npz", ".h5", ".hdf5")


class _NpyStream:
    """One ``.npy`` member of an ``.npz`` archive: its length, then its values in order."""

    def __init__(self, archive, member, path):
        self.file = archive.open(member)
        version = np.lib.format.read_magic(self.file)
        if version == (1, 0):
            shape, _, dtype = np.lib.format.read_array_header_1_0(self.file)
        elif version == (2, 0):
            shape, _, dtype = np.lib.format.read_array_header_2_0(self.file)
        else:
            raise InputDataError(f"{path}: {member}: .npy format {version} is not supported")
        check_dtype(dtype, member[:-4], path)
        self.shape, self.dtype = shape, dtype

    def read(self, n):
        data = self.file.read(n * self.dtype.itemsize)
        if len(data) != n * self.dtype.itemsize:
            raise InputDataError(f"{self.file.name}: ends early")
        return np.frombuffer(data, dtype=self.dtype).astype(np.float64)


class RecordingBlocks:
    """An open recording; use as a context manager, or call ``close``."""

    def __init__(self, path):
        self.path = Path(path)
        suffix = self.path.suffix.lower()
        if suffix not in SUFFIXES:
            raise InputDataError(f"{path}: not a recording: allowed suffixes are {', '.join(SUFFIXES)}")
        check_file(self.path)  # a FIFO, a device, a sparse file
        self._h5 = self._zip = None
        try:
            shapes = self._open_h5() if suffix != ".npz" else self._open_npz()
        except InputDataError:
            self.close()
            raise
        except Exception as exc:  # any reader failure is a bad input file, reported in one line
            self.close()
            raise InputDataError(f"{path}: not a readable {suffix} recording ({type(exc).__name__}: {exc})") from None
        if not shapes or len(set(shapes.values())) != 1 or len(next(iter(shapes.values()))) != 1:
            self.close()
            raise InputDataError(f"{path}: recording columns must be 1-D arrays of one length, "
                                 f"got shapes {sorted(set(shapes.values()))}")
        self.names = list(shapes)
        self.length = next(iter(shapes.values()))[0]
        if self.length == 0:
            self.close()
            raise InputDataError(f"{path}: no samples: allowed is a recording of at least one sample")
        self.rate = self._rate()

    def _open_npz(self):
        self._zip, _ = open_npz(self.path)  # what each member unpacks to, checked before unpacking
        self.meta, members = {}, {}
        for member in self._zip.namelist():
            if not member.endswith(".npy"):
                raise InputDataError(f"{self.path}: member {member!r} is not an .npy array")
            if member == "__meta__.npy":
                with self._zip.open(member) as f:
                    self.meta = parse_meta(str(np.lib.format.read_array(f, allow_pickle=False)), self.path)
            else:
                members[member[:-4]] = member
        self._members = members
        shapes = {}
        for name, member in members.items():
            stream = _NpyStream(self._zip, member, self.path)
            shapes[name] = stream.shape
            stream.file.close()
        return shapes

    def _open_h5(self):
        import h5py

        self._h5 = h5py.File(self.path, "r")
        raw = self._h5.attrs.get("meta", "{}")
        self.meta = parse_meta(raw.decode() if isinstance(raw, bytes) else str(raw), self.path)
        check_h5(self._h5, self.path)
        return {name: self._h5[name].shape for name in self._h5.keys()}

    def _rate(self):
        rate = meta_rate(self.meta, self.path)
        if rate is None and "t" in self.names and self.length > 1:
            first = last = None
            for block in self.blocks(1 << 16, ["t"]):
                first = block["t"][0] if first is None else first
                last = block["t"][-1]
            span = float(last - first)
            rate = round((self.length - 1) / span, 6) if span > 0 else None
        try:
            rate = float(rate)
        except (TypeError, ValueError):
            rate = None
        if rate is None or not np.isfinite(rate) or rate <= 0:
            raise InputDataError(f"{self.path}: no valid sample rate (metadata 'rate' or a 't' column)")
        return rate

    def blocks(self, size, names=None):
        """Yield ``{name: float64 array}`` for runs of up to ``size`` samples of the columns ``names`` (default all)."""
        names = list(self.names if names is None else names)
        try:
            if self._h5 is not None:
                for start in range(0, self.length, size):
                    yield {n: np.asarray(self._h5[n][start:start + size], dtype=np.float64) for n in names}
                return
            streams = {n: _NpyStream(self._zip, self._members[n], self.path) for n in names}
            try:
                for start in range(0, self.length, size):
                    n = min(size, self.length - start)
                    yield {name: s.read(n) for name, s in streams.items()}
            finally:
                for s in streams.values():
                    s.file.close()
        except (OSError, ValueError, zipfile.BadZipFile) as exc:
            raise InputDataError(f"{self.path}: not a readable recording ({type(exc).__name__}: {exc})") from None

    def close(self):
        for handle in (self._zip, self._h5):
            if handle is not None:
                handle.close()

    def __enter__(self):
        return self

    def __exit__(self, *exc):
        self.close()

