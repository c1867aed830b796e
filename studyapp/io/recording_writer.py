"""A recording written a block of samples at a time, so memory stays that of one block.

``RecordingWriter(path, columns)`` opens the output (format by suffix, as
``recording.save``); ``write(block)`` appends ``{name: array}`` for every
column; ``finish(meta)`` completes the file and gives it its name. Until then
nothing is at ``path``: the writer works on a temporary (``studyapp.io.atomic``),
so a failure or a kill leaves no partial recording. The files are those
``recording.save`` writes and ``recording.load`` / ``RecordingBlocks`` read:

- ``.csv``: the header, then each block's rows as they come;
- ``.h5``: one chunked, growing dataset per column; the metadata at the end
  (io/h5_output.py: a full disk is one error naming the file, checked after each block);
- ``.npz``: a ZIP member per column cannot grow while another is written, so
  each column goes to its own unnamed temporary file (``O_TMPFILE``: a kill
  leaves nothing) as raw float64, and ``finish`` streams them one after
  another into the archive's ``.npy`` members (header first, the length then
  known), freeing each as it is copied. The disk holds the columns once more
  than the archive during ``finish`` at worst: ``bytes_needed`` counts it.

``bytes_needed(suffix, samples, columns)`` is the disk space a recording takes
(an upper bound): 8 bytes per value for ``.h5`` (and one chunk per column),
16 for ``.npz`` (the temporaries and the archive), ``CSV_BYTES_PER_VALUE`` = 25 for ``.csv`` (``%.17g``
writes at most 24 characters and a separator).
"""

import contextlib
import shutil
import tempfile
import zipfile
from pathlib import Path

import numpy as np

from studyapp.errors import InputDataError
from studyapp.io.atomic import atomic_open
from studyapp.io.h5_output import H5Output
from studyapp.io.recording import _meta_json, _suffix

CSV_BYTES_PER_VALUE = 25
H5_CHUNK = 1 << 12  # samples per HDF5 chunk (32 KB): a chunk is stored whole, so a short file stays short
_COPY = 1 << 20  # bytes per copy step into the archive


def bytes_needed(suffix, samples, columns):
    """Upper bound of the bytes on disk a recording of ``samples`` x ``columns`` values takes while written."""
    values = int(samples) * int(columns)
    if suffix == ".csv":
        return values * CSV_BYTES_PER_VALUE + 4096
    if suffix == ".h5":  # the last chunk of each column is stored whole
        return (values + int(columns) * H5_CHUNK) * 8 + 65536
    return 2 * values * 8 + 65536


class _Meta:
    """What ``_meta_json`` reads of a recording: its rate and metadata."""

    def __init__(self, rate, meta):
        self.rate = float(rate)
        self.meta = meta


class RecordingWriter:
    """Use as a context manager: leaving it without ``finish`` (an error) leaves no file at ``path``."""

    def __init__(self, path, columns):
        self.path = Path(path)
        self.suffix = _suffix(path)
        self.columns = tuple(columns)
        self.samples = 0
        self._stack = contextlib.ExitStack()
        self._done = False
        try:
            if self.suffix == ".csv":
                self._file = self._stack.enter_context(atomic_open(self.path, "w", newline=""))
                self._file.write(",".join(self.columns) + "\n")
            elif self.suffix == ".h5":
                self._h5 = self._stack.enter_context(H5Output(self.path))
                self._datasets = [self._h5.file.create_dataset(name, shape=(0,), maxshape=(None,), dtype="f8",
                                                               chunks=(H5_CHUNK,)) for name in self.columns]
            else:
                self._parts = {name: self._stack.enter_context(tempfile.TemporaryFile(dir=self.path.parent))
                               for name in self.columns}
        except BaseException:
            self._stack.close()
            raise

    def write(self, block):
        """Append ``block`` (``{name: 1-D array}``, one length, every column)."""
        arrays = [np.ascontiguousarray(block[name], dtype=np.float64) for name in self.columns]
        n = arrays[0].shape[0]
        if any(a.shape != (n,) for a in arrays):
            raise InputDataError(f"{self.path}: a block's columns must be 1-D arrays of one length")
        if self.suffix == ".csv":
            np.savetxt(self._file, np.column_stack(arrays), delimiter=",", fmt="%.17g")
        elif self.suffix == ".h5":
            try:
                for dataset, values in zip(self._datasets, arrays):
                    dataset.resize((self.samples + n,))
                    dataset[self.samples:] = values
            except Exception:
                self._h5.check()  # HDF5 reading back what the full disk dropped: the disk's error, not HDF5's
                raise
            self._h5.check()
        else:
            for name, values in zip(self.columns, arrays):
                self._parts[name].write(values.tobytes())
        self.samples += n

    def finish(self, rate, meta):
        """Complete the file with its metadata (``.h5``, ``.npz``; a CSV carries none) and give it its name."""
        text = _meta_json(_Meta(rate, meta))
        if self.suffix == ".h5":
            self._h5.file.attrs["meta"] = text
        elif self.suffix == ".npz":
            self._write_npz(text)
        self._done = True
        self._stack.close()  # closes (and so renames) the temporary over the target

    def _write_npz(self, text):
        header = {"descr": np.lib.format.dtype_to_descr(np.dtype("<f8")), "fortran_order": False,
                  "shape": (self.samples,)}
        with atomic_open(self.path, "wb") as f, zipfile.ZipFile(f, "w", zipfile.ZIP_STORED, allowZip64=True) as z:
            with z.open("__meta__.npy", "w") as member:
                np.lib.format.write_array(member, np.array(text), allow_pickle=False)
            for name in self.columns:
                part = self._parts.pop(name)
                part.seek(0)
                with z.open(f"{name}.npy", "w", force_zip64=True) as member:
                    np.lib.format.write_array_header_1_0(member, header)
                    shutil.copyfileobj(part, member, _COPY)
                part.close()

    def __enter__(self):
        return self

    def __exit__(self, exc_type, exc, tb):
        if self._done:
            return
        if exc_type is None:  # left without finish: the atomic writers drop their temporary on an error
            exc_type, exc = RuntimeError, RuntimeError("recording left unfinished")
        self._stack.__exit__(exc_type, exc, tb)
