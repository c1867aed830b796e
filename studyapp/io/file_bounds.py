"""Files too big to read, or mostly holes: refused from their status, before a byte is read.

A *sparse* file is one whose length (``st_size``) is mostly holes: blocks never
written, which take no disk (``st_blocks``, in 512-byte units) and read as
zero bytes. ``truncate -s 3G x.csv`` makes one in an instant; a reader then
reads 3 GB of NUL bytes as one line, for minutes. No file the app reads is
written that way (its outputs, a recording, a CSV from a spreadsheet or a
logger are written through), so a file longer than ``SPARSE_MIN_BYTES`` whose
disk blocks hold less than ``1 / SPARSE_RATIO`` of its length is refused,
naming it and both sizes. (A compressing file system, btrfs or ZFS, reports its
compressed blocks; text compresses about 3 to 5 times, well short of 32.)

``check_size`` bounds a file a reader holds whole in memory.
"""

from studyapp.errors import InputDataError

SPARSE_MIN_BYTES = 1 << 20  # a small file's blocks say little (inline data, tail packing)
SPARSE_RATIO = 32


def _mb(n):
    return f"{n / (1 << 20):.3g} MB" if n >= 1 << 20 else f"{n} bytes"


def is_sparse(status):
    """True when the file of ``status`` (an ``os.stat_result``) is mostly holes (module docstring)."""
    return status.st_size > SPARSE_MIN_BYTES and status.st_blocks * 512 * SPARSE_RATIO < status.st_size


def check_not_sparse(status, path, what):
    """``InputDataError`` naming ``path`` (a ``what`` file) when its ``status`` shows a sparse file."""
    if is_sparse(status):
        raise InputDataError(f"{path}: {_mb(status.st_size)} long but only {_mb(status.st_blocks * 512)} on disk "
                             f"(a sparse file, mostly holes): allowed is a {what} file written in full")


def check_size(size, limit, path, what):
    """``InputDataError`` naming ``path`` when ``size`` bytes (a file, or what it unpacks to) exceed ``limit``."""
    if size > limit:
        raise InputDataError(f"{path}: {_mb(size)}: allowed is a {what} of at most {_mb(limit)}")
