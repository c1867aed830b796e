"""What a recording archive unpacks to, bounded from its directory before anything is unpacked.

An ``.npz`` is a zip archive of ``.npy`` arrays; an ``.h5`` holds datasets that
may be compressed. A few megabytes of either can unpack to gigabytes (a *zip
bomb*: deflate packs a run of zeros about 1000 to 1), which a reader would
spend minutes and all its memory on. Both formats say in their directory what
each member unpacks to (the zip's central directory ``file_size``, which
``zipfile`` also never reads past; an HDF5 dataset's shape and its storage
size), so that is checked first:

- a member unpacking to more than ``BOMB_MIN_BYTES`` and to more than
  ``RATIO_MAX`` times its packed size is refused (real signals pack 1.1 to
  about 3 to 1; ``np.savez`` does not pack at all);
- a reader that holds the whole recording in memory (``recording.load``) also
  passes ``limit``: the members together at most that many bytes;
- an ``.npy`` member's header must describe numbers (not booleans, complex
  numbers, text or objects) and claim no more data than the member holds
  (``np.load`` allocates the header's shape before reading).

Every refusal is one ``InputDataError`` naming the file and the member.
"""

import zipfile

import numpy as np

from studyapp.errors import InputDataError
from studyapp.io.file_bounds import check_size

BOMB_MIN_BYTES = 1 << 26  # 64 MB: below this, unpacking is quick whatever the ratio
RATIO_MAX = 100
META_LIMIT = 1 << 20  # bytes of metadata JSON: a few hundred are written
NUMBER_KINDS = "iuf"  # integers and floats: a sample; a boolean or complex column is no signal


def check_dtype(dtype, column, path):
    """``InputDataError`` unless ``dtype`` (numpy, or None for an HDF5 group) holds plain real numbers."""
    if dtype is None or dtype.hasobject or dtype.kind not in NUMBER_KINDS or dtype.names is not None:
        raise InputDataError(f"{path}: column {column!r} holds {dtype or 'a group'}: allowed are real numbers "
                             "(integers or floats)")


def _check_packing(unpacked, packed, where):
    if unpacked > BOMB_MIN_BYTES and unpacked > RATIO_MAX * max(packed, 1):
        raise InputDataError(f"{where}: unpacks to {unpacked} bytes from {packed} ({unpacked // max(packed, 1)} to 1, "
                             f"a zip bomb?): allowed is at most {RATIO_MAX} to 1 above {BOMB_MIN_BYTES >> 20} MB")


def _npy_header(archive, info, path):
    """(shape, dtype) from the ``.npy`` header of the zip member ``info``."""
    with archive.open(info) as f:
        version = np.lib.format.read_magic(f)
        if version == (1, 0):
            shape, _, dtype = np.lib.format.read_array_header_1_0(f)
        elif version == (2, 0):
            shape, _, dtype = np.lib.format.read_array_header_2_0(f)
        else:
            raise InputDataError(f"{path}: {info.filename}: .npy format {version} is not supported")
        return shape, dtype, f.tell()


def check_npz(archive, path, limit=None):
    """Check the zip ``archive`` (an open ``zipfile.ZipFile`` of the ``.npz`` at ``path``) before reading it.

    Returns {member name: (shape, dtype)} of its arrays (``__meta__.npy``, text, included)."""
    total = 0
    headers = {}
    for info in archive.infolist():
        where = f"{path}: member {info.filename!r}"
        if info.filename in headers:
            raise InputDataError(f"{where} appears twice: allowed is each column once")
        if not info.filename.endswith(".npy"):
            raise InputDataError(f"{where} is not an .npy array")
        _check_packing(info.file_size, info.compress_size, where)
        total += info.file_size
        if limit is not None:
            check_size(total, limit, path, "recording unpacked")
        shape, dtype, offset = _npy_header(archive, info, path)
        if info.filename == "__meta__.npy":
            check_size(info.file_size, META_LIMIT, f"{path}: metadata", "metadata text")
        else:
            check_dtype(dtype, info.filename[:-4], path)
        if int(np.prod(shape, dtype=object)) * dtype.itemsize > info.file_size - offset:
            raise InputDataError(f"{where}: its header claims {shape} of {dtype}, more than the member holds")
        headers[info.filename] = (shape, dtype)
    return headers


def open_npz(path, limit=None):
    """An open ``zipfile.ZipFile`` of the ``.npz`` at ``path``, checked (``check_npz``), and its headers."""
    archive = zipfile.ZipFile(path)
    try:
        return archive, check_npz(archive, path, limit)
    except BaseException:
        archive.close()
        raise


def check_h5(h5file, path, limit=None):
    """Check the open ``h5py.File`` of ``path``: every top-level item a dataset of numbers, packed within bounds."""
    total = 0
    for name in h5file.keys():
        dataset = h5file[name]
        check_dtype(getattr(dataset, "dtype", None), name, path)
        unpacked = int(dataset.size) * dataset.dtype.itemsize
        _check_packing(unpacked, dataset.id.get_storage_size(), f"{path}: dataset {name!r}")
        total += unpacked
        if limit is not None:
            check_size(total, limit, path, "recording unpacked")
