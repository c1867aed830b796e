"""Read a small text file a person gave us (a protocol, a parameter file) without trusting it.

Only a regular file is read (``/dev/zero`` or ``/dev/urandom`` would never
end), and it is opened without blocking, so a FIFO is refused at once instead
of waiting forever for a writer (``open_regular``, for every reader of a file
a person or a crash could have replaced: protocols, parameter files, CSV
inputs, a session's session.json and events.jsonl), nor a sparse one
(``file_bounds``). At most ``LIMIT_BYTES`` of a small file is read: such files
are a few kilobytes, so a larger one is refused before it costs memory or parse
time. TOML nested deeper than Python's recursion limit is refused too
(``tomllib`` would raise ``RecursionError``), and JSON nested deeper than
``bounded_json.MAX_DEPTH`` (``read_json``).
Every problem is one ``UserError`` naming the file.
"""

import errno
import os
import stat
import tomllib
from pathlib import Path

from studyapp.errors import InputDataError, UserError
from studyapp.io import bounded_json
from studyapp.io.file_bounds import check_not_sparse
from studyapp.io.special_files import NotARegularFile, kind

LIMIT_BYTES = 1 << 20


def open_regular(path, what, mode="rb", **kwargs):
    """``open(path, mode)`` for reading, for a regular file only (``NotARegularFile`` otherwise).

    The file is opened with ``O_NONBLOCK`` (a FIFO opens at once instead of waiting for a
    writer), its type checked on the open descriptor, then blocking restored. Other failures
    are the usual ``OSError`` (``FileNotFoundError``, ``IsADirectoryError``, ...).
    """
    fd = os.open(path, os.O_RDONLY | os.O_NONBLOCK | os.O_CLOEXEC)
    try:
        status = os.fstat(fd)
        if stat.S_ISDIR(status.st_mode):
            raise IsADirectoryError(errno.EISDIR, "Is a directory", str(path))
        if not stat.S_ISREG(status.st_mode):
            raise NotARegularFile(f"{path}: not a regular file ({kind(status.st_mode) or 'a FIFO, device or socket'}): "
                                  f"allowed is a {what} file")
        check_not_sparse(status, path, what)
        os.set_blocking(fd, True)
        return os.fdopen(fd, mode, **kwargs)
    except BaseException:
        os.close(fd)
        raise


def _size(limit):
    return f"{limit >> 20} MB" if limit >= 1 << 20 else f"{limit} bytes"


def read_regular(path, what, limit):
    """The bytes of the regular file ``path``, at most ``limit`` of them (``UserError`` if larger)."""
    with open_regular(path, what) as f:
        data = f.read(limit + 1)
    if len(data) > limit:
        raise UserError(f"{path}: larger than {_size(limit)}: allowed is a {what} file up to that size")
    return data


def read_bytes(path, what, limit=LIMIT_BYTES):
    """The bytes of the regular file ``path`` (``what`` names it in messages, e.g. "protocol")."""
    path = Path(path)
    try:
        data = read_regular(path, what, limit)
    except FileNotFoundError:
        raise UserError(f"{path}: cannot read the {what}: no such file") from None
    except IsADirectoryError:
        raise UserError(f"{path}: is a folder: allowed is a {what} file") from None
    except UserError:
        raise
    except OSError as exc:
        raise UserError(f"{path}: cannot read the {what} ({exc.strerror or exc})") from None
    return data


def read_json(path, what, limit=LIMIT_BYTES):
    """The JSON document in the regular file ``path`` (at most ``limit`` bytes, nested at most
    ``bounded_json.MAX_DEPTH`` levels); every failure one ``UserError`` naming the file."""
    data = read_bytes(path, what, limit)
    try:
        return bounded_json.loads(data)
    except ValueError as exc:  # invalid JSON, nested too deeply, not UTF-8
        raise InputDataError(f"{path}: not valid JSON ({exc}): allowed is a {what} file") from None


def parse_toml(text, source):
    """``tomllib.loads(text)``, with every failure as one ``UserError`` naming ``source``."""
    try:
        return tomllib.loads(text)
    except tomllib.TOMLDecodeError as exc:
        raise UserError(f"{source}: invalid TOML ({exc})") from None
    except RecursionError:
        raise UserError(f"{source}: invalid TOML (nested too deeply)") from None


def read_toml(path, what):
    """(text, document) of the TOML file ``path``; UTF-8 only."""
    data = read_bytes(path, what)
    try:
        text = data.decode("utf-8")
    except UnicodeDecodeError:
        raise UserError(f"{path}: not UTF-8 text: allowed is a UTF-8 TOML {what} file") from None
    return text, parse_toml(text, path)
