"""Write files whole or not at all, and leave no temporary behind, even when killed.

A command that fails half-way must not leave a half-written output behind, so
every output is written to a temporary file and renamed over its target only
once complete (``os.replace`` is atomic on POSIX within a filesystem).

Where the temporary goes decides what a kill (SIGKILL, a power cut) leaves:

- ``atomic_open`` (a file object) writes to an *unnamed* file in the target's
  folder (Linux ``O_TMPFILE``): until it is complete it has no name, so a kill
  leaves nothing at all. Only then is it given a temporary name and renamed
  over the target, two system calls apart.
- ``atomic_path`` (for writers that need a path: HDF5, figures) needs a named
  temporary, ``.<target name>.<8 random characters><target suffix>``.

Either way the writer holds an exclusive lock (``F_OFD_SETLK``) on its temporary for as
long as it lives, so a temporary that is named but unlocked was left by a
writer that died: the next write of the same target removes it
(``remove_stale``), and a temporary a live writer holds is never touched.
Where ``O_TMPFILE`` is not supported (some network filesystems) ``atomic_open``
falls back to the named temporary.
"""

import contextlib
import errno
import fcntl
import os
import re
import secrets
import stat
import struct
import tempfile
from pathlib import Path

_NO_TMPFILE = (errno.EOPNOTSUPP, errno.EISDIR, errno.EINVAL, errno.ENOENT)
_ALPHABET = "abcdefghijklmnopqrstuvwxyz0123456789_"  # mkstemp's


def _whole_file(kind):
    """A ``struct flock`` over the whole file: l_type, l_whence, l_start, l_len, l_pid (32 bytes)."""
    return struct.pack("@hhqqi4x", kind, os.SEEK_SET, 0, 0, 0)


def hold(fd):
    """Hold an open-file-description write lock (``F_OFD_SETLKW``) on ``fd`` until it is closed.

    Not ``flock``: HDF5 flocks the files it writes and would find ours taken. An OFD
    lock conflicts with another open of the file (in any process, this one too) only.
    Where locks are not supported the write goes on unlocked: ``_unheld`` then fails
    too, so no one removes the temporary."""
    with contextlib.suppress(OSError):
        fcntl.fcntl(fd, fcntl.F_OFD_SETLKW, _whole_file(fcntl.F_WRLCK))


def _unheld(fd):
    """True when no writer holds the file of ``fd`` (open read-only: a read lock tests for the write lock)."""
    try:
        fcntl.fcntl(fd, fcntl.F_OFD_SETLK, _whole_file(fcntl.F_RDLCK))
    except OSError:
        return False
    return True


def default_mode():
    """The permissions ``open()`` would give a new file under the user's umask."""
    umask = os.umask(0)
    os.umask(umask)
    return 0o666 & ~umask


def remove_stale(target):
    """Remove the temporaries of ``target`` that no live writer holds (a killed writer's); return their paths."""
    target = Path(target)
    pattern = re.compile(re.escape(f".{target.name}.") + f"[{_ALPHABET}]{{8}}" + re.escape(target.suffix))
    removed = []
    try:
        names = [n for n in os.listdir(target.parent) if pattern.fullmatch(n)]
    except OSError:
        return removed
    for name in names:
        path = target.parent / name
        try:
            fd = os.open(path, os.O_RDONLY | os.O_NOFOLLOW | os.O_NONBLOCK)
        except OSError:
            continue  # gone already (renamed by its writer), or not ours to open
        try:
            # a regular file, unheld, and still the one under that name (not renamed meanwhile)
            if (stat.S_ISREG(os.fstat(fd).st_mode) and _unheld(fd)
                    and os.stat(path, follow_symlinks=False).st_ino == os.fstat(fd).st_ino):
                os.unlink(path)
                removed.append(path)
        except OSError:
            pass  # gone meanwhile: nothing to do
        finally:
            os.close(fd)
    return removed


def _unnamed(folder):
    """An fd of a new unnamed file in ``folder`` (``O_TMPFILE``), or None where that is not supported."""
    flag = getattr(os, "O_TMPFILE", None)
    if flag is None:
        return None
    try:
        return os.open(folder, flag | os.O_WRONLY, 0o600)
    except OSError as exc:
        if exc.errno in _NO_TMPFILE:
            return None
        raise


def _name(fd, target):
    """Give the unnamed file ``fd`` a temporary name beside ``target`` and return it."""
    folder = os.open(target.parent, os.O_RDONLY | os.O_DIRECTORY)
    try:
        while True:
            name = f".{target.name}.{''.join(secrets.choice(_ALPHABET) for _ in range(8))}{target.suffix}"
            try:
                # linkat(AT_SYMLINK_FOLLOW) of /proc/self/fd/N; without dir fds os.link calls
                # plain link(), which would not follow that link
                os.link(f"/proc/self/fd/{fd}", name, src_dir_fd=folder, dst_dir_fd=folder, follow_symlinks=True)
                return target.parent / name
            except FileExistsError:
                continue
    finally:
        os.close(folder)


@contextlib.contextmanager
def _temporary(target, mode, named):
    """Yield ``(fd, path)`` of a new locked temporary for ``target``, and rename it to ``target`` on success.

    ``path`` is None until the end unless ``named`` (or ``O_TMPFILE`` is not supported)."""
    target = Path(target)
    target.parent.mkdir(parents=True, exist_ok=True)
    remove_stale(target)
    fd = _unnamed(target.parent)
    tmp = None
    try:
        if fd is None:
            fd, name = tempfile.mkstemp(prefix=f".{target.name}.", suffix=target.suffix, dir=target.parent)
            tmp = Path(name)
        hold(fd)  # ours while we live: remove_stale leaves it alone
        # mkstemp and O_TMPFILE make the file private (0600); an output gets the usual permissions unless told
        os.fchmod(fd, default_mode() if mode is None else mode)
        if named and tmp is None:
            tmp = _name(fd, target)
        yield fd, tmp
        if tmp is None:
            tmp = _name(fd, target)  # named (and locked) only for the moment until the rename
        os.replace(tmp, target)
    except BaseException as exc:
        if tmp is not None:
            with contextlib.suppress(FileNotFoundError):
                os.unlink(tmp)
        if isinstance(exc, OSError) and exc.filename is None:
            # a failed write (a full disk) names no file: name the output, so the one-line error can
            raise OSError(exc.errno, exc.strerror or str(exc), str(target)) from exc
        raise
    finally:
        if fd is not None:
            os.close(fd)


@contextlib.contextmanager
def atomic_path(target, mode=None):
    """Yield a temporary path beside ``target``; rename it to ``target`` on success.

    ``mode`` (e.g. 0o600) sets the file's permissions; by default they follow the umask.
    """
    with _temporary(target, mode, named=True) as (_, tmp):
        yield tmp


@contextlib.contextmanager
def atomic_open(target, mode="w", permissions=None, **kwargs):
    """Open a temporary file for ``target``; it replaces ``target`` when closed without error."""
    with _temporary(target, permissions, named=False) as (fd, _), open(fd, mode, closefd=False, **kwargs) as f:
        yield f
