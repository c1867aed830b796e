"""Open a file in a data folder without following a link: only a file the app itself made is written.

A results folder can hold what someone else put there: a symbolic link named
``.lock``, ``events.jsonl`` or ``audio_cues.csv`` pointing at any file (as
root, any file of the system), a hard link to one, a FIFO. ``open_own`` opens
with ``O_NOFOLLOW`` (a symbolic link is refused by the kernel, ``ELOOP``),
creates with ``O_EXCL``, and checks an existing file on its open descriptor:
a regular file with a single name. Anything else is ``NotOurFile``, one line
naming the file (issue 33, item 3).
"""

import errno
import os
import stat

from studyapp.errors import UserError


class NotOurFile(UserError, OSError):
    """A file in a data folder that the app did not create: a symbolic or hard link, a FIFO, a device."""


def open_own(path, flags, mode):
    """``os.open(path, flags)`` of a file the app made, or a new one created (``O_EXCL``) with permissions ``mode``.

    Returns ``(fd, created)``."""
    flags |= os.O_NOFOLLOW | os.O_CLOEXEC
    try:
        fd = os.open(path, flags | os.O_CREAT | os.O_EXCL, mode)
    except FileExistsError:
        return _open_existing(path, flags), False
    os.fchmod(fd, mode)  # not masked by the umask
    return fd, True


def _open_existing(path, flags):
    try:
        fd = os.open(path, flags | os.O_NONBLOCK)  # a FIFO opens at once, to be refused below
    except OSError as exc:
        if exc.errno == errno.ELOOP:
            raise NotOurFile(f"{path}: a symbolic link, not a file this app made: allowed is to remove it "
                             "(the app writes no file through a link)") from None
        raise
    info = os.fstat(fd)
    if not stat.S_ISREG(info.st_mode) or info.st_nlink != 1:
        os.close(fd)
        what = "a hard link to another file" if stat.S_ISREG(info.st_mode) else "not a regular file"
        raise NotOurFile(f"{path}: {what}, not a file this app made: allowed is to remove it "
                         "(the app writes no file through a link)")
    os.set_blocking(fd, True)
    return fd
