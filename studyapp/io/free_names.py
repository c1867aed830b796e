"""Names never written over: ``take.wav``, else ``take-2.wav``, ``take-3.wav``, ...: the first free one.

Outputs that must never replace an earlier one (a WAV take, the recording of
what a participant heard, a session's folder) take the first free name of
``numbered_names``. Where two writers may race for it, ``claim`` reserves the
name with an exclusive create (``O_EXCL``), so each keeps its own.

A file that must appear whole or not at all (a WAV file: a 0-byte one is
unreadable) is made without a name first (``unnamed``: Linux ``O_TMPFILE``,
nothing is left if the program is killed), its header written, and only then
linked under the first free name (``name_unnamed``: ``linkat``, which fails
rather than replace a file that exists).
"""

import errno
import itertools
import os
from pathlib import Path


def numbered(path, number):
    """``take.wav`` for 1, ``take-2.wav`` for 2, ... (a name without a suffix: ``name``, ``name-2``, ...)."""
    path = Path(path)
    return path if number == 1 else path.with_name(f"{path.stem}-{number}{path.suffix}")


def numbered_names(path):
    """``path``, then ``path-2``, ``path-3``, ...: the names a file that never overwrites takes, in order."""
    return (numbered(path, number) for number in itertools.count(1))


def first_free(path):
    """The first of ``numbered_names(path)`` that does not exist (not reserved: see ``claim``)."""
    return next(name for name in numbered_names(path) if not os.path.lexists(name))


def create(path, mode):
    """An fd of the new file ``path`` (``FileExistsError`` if it exists) with permissions ``mode``, not the umask's."""
    fd = os.open(path, os.O_WRONLY | os.O_CREAT | os.O_EXCL, mode)
    os.fchmod(fd, mode)
    return fd


def claim(path, mode=0o600):
    """``(fd, name)``: the first free numbered name of ``path``, created exclusively with permissions ``mode``."""
    for name in numbered_names(path):
        try:
            return create(name, mode), name
        except FileExistsError:
            continue


def unnamed(folder, mode=0o600):
    """An fd of a new file without a name in ``folder`` (``O_TMPFILE``), permissions ``mode``; None where the
    filesystem does not support that."""
    flag = getattr(os, "O_TMPFILE", None)
    if flag is None:
        return None
    try:
        fd = os.open(folder, flag | os.O_RDWR | os.O_CLOEXEC, mode)
    except OSError as exc:
        if exc.errno in (errno.EOPNOTSUPP, errno.EISDIR, errno.EINVAL):
            return None
        raise
    os.fchmod(fd, mode)
    return fd


def name_unnamed(fd, path):
    """Link the unnamed file ``fd`` under the first free numbered name of ``path``; return that name."""
    path = Path(path)
    folder = os.open(path.parent, os.O_RDONLY | os.O_DIRECTORY | os.O_CLOEXEC)
    try:
        for name in numbered_names(path):
            try:
                # linkat(AT_SYMLINK_FOLLOW) of /proc/self/fd/N: the way to name an O_TMPFILE file
                os.link(f"/proc/self/fd/{fd}", name.name, src_dir_fd=folder, dst_dir_fd=folder, follow_symlinks=True)
                return name
            except FileExistsError:
                continue
    finally:
        os.close(folder)
