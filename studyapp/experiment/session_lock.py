"""One running session per participant: an exclusive OS lock on the participant's folder.

``ParticipantLock(folder)`` takes ``fcntl.flock(LOCK_EX | LOCK_NB)`` on
``<participant folder>/.lock`` and holds it until ``release`` (the session's
``close``) or until the process ends. The kernel drops a flock when its
holder dies, however it dies (SIGKILL, a crash, a power cut), so a stale lock
never needs clearing: the next start simply takes it. The file keeps one line
naming the latest holder (host, PID, start time); a start that finds the lock
taken is refused with that line, so two programs (two ``run --resume``, a
``run`` and the GUI, two consoles) can never write one participant's log at once.

flock is advisory and local: it holds between programs on one machine, and
on NFS only where the server supports it (Linux NFSv4 does). Keep a results
folder shared between machines on one machine's disk.

The participant's lock is a file beside the sessions, and a file can be
deleted: a start after that takes a fresh lock on a new file while the
first program still writes. So every writer of a session's log (``run``,
``--resume``, ``notes --add``, the console) also holds ``session_log.LogLock``, a flock
on the log itself (``events.jsonl``), through the descriptor it appends
with: it lives as long as that descriptor, the file's name plays no part,
and it is the same lock whatever path (a symbolic link to the folder, a
copy of its path) led to the file. A second writer is refused before it
writes a byte (issue 33, item 2).

Every lock file and log is opened without following a link
(``data_modes.open_file``): a ``.lock`` or ``events.jsonl`` planted as a link
is refused, never written through.

``StudyLock(folder)`` is the same lock held on a study folder for the moment
it takes to enrol a participant, so two participants started at once get
different enrolment indices (and Latin-square rows).

A lock file is removed (a start that failed cleans up the folders it made)
only by a program that holds its lock at that moment: ``release(remove=True)``
by the holder, ``remove_if_free`` by anyone who can take it. Unlinking a
lock another program holds would let a third start take a fresh lock on a new
file beside the holder, and write the same log at once.
"""

import fcntl
import json
import os
import socket
import time
from pathlib import Path

from studyapp.errors import UserError
from studyapp.experiment.data_modes import NotOurFile, open_file
from studyapp.experiment.session_files import LOCK_FILE
from studyapp.experiment.session_log import wall_time
from studyapp.io.small_files import read_regular


def _acquire(path, blocking):
    """An fd holding flock on ``path``, or None when another process holds it (``blocking`` False)."""
    while True:
        fd = open_file(path, os.O_RDWR)
        try:
            fcntl.flock(fd, fcntl.LOCK_EX | (0 if blocking else fcntl.LOCK_NB))
        except BlockingIOError:
            os.close(fd)
            return None
        # The file may have been replaced while we waited (a participant folder
        # removed after a failed start): a lock on an unlinked file locks nothing.
        if _same_file(path, fd):
            return fd
        os.close(fd)


def _same_file(path, fd):
    try:
        return os.stat(path).st_ino == os.fstat(fd).st_ino
    except FileNotFoundError:
        return False


def remove_if_free(folder):
    """Remove ``folder``'s lock file if no program holds it (taken for the moment); False if one does."""
    path = Path(folder) / LOCK_FILE
    try:
        fd = os.open(path, os.O_RDWR | os.O_NOFOLLOW | os.O_NONBLOCK | os.O_CLOEXEC)
    except FileNotFoundError:
        return True
    except OSError:
        return False  # a link or a special file: not the app's to remove
    try:
        fcntl.flock(fd, fcntl.LOCK_EX | fcntl.LOCK_NB)
    except BlockingIOError:
        os.close(fd)
        return False
    try:
        if _same_file(path, fd):
            path.unlink()
    finally:
        os.close(fd)  # a program that opened the file meanwhile finds it unlinked, and takes a new one
    return True


def _holder(path):
    """The holder's line; the holder writes it just after taking the lock, so wait a moment for it."""
    deadline = time.monotonic() + 1.0
    while True:
        try:
            holder = json.loads(read_regular(path, "lock", 4096))
            return f"PID {holder['pid']} on host {holder['host']} since {holder['started']}"
        except (OSError, ValueError, KeyError, TypeError):
            if time.monotonic() > deadline:
                return "a program that has not said which (an older version, or one still starting)"
            time.sleep(0.02)


class ParticipantLock:
    """The exclusive lock on a participant's folder (``UserError`` naming the holder when taken)."""

    def __init__(self, folder, participant):
        self.path = Path(folder) / LOCK_FILE
        try:
            self._fd = _acquire(self.path, blocking=False)
        except NotOurFile:
            raise
        except OSError as exc:
            raise UserError(f"{self.path}: cannot lock the participant's folder ({exc.strerror or exc}): "
                            "allowed is a writable results folder") from None
        if self._fd is None:
            raise UserError(f"participant {participant!r} is in a session already, held by {_holder(self.path)} "
                            f"(lock {self.path}): allowed is to wait until it ends, or another participant ID")
        holder = {"pid": os.getpid(), "host": socket.gethostname(), "started": wall_time()}
        try:
            os.ftruncate(self._fd, 0)
            os.pwrite(self._fd, (json.dumps(holder) + "\n").encode("utf-8"), 0)
        except OSError:
            pass  # a full disk: the lock holds all the same, only its holder goes unnamed

    def release(self, remove=False):
        """Drop the lock; with ``remove``, first unlink its file (while still held, so no one else's)."""
        if self._fd is not None:
            if remove and _same_file(self.path, self._fd):
                self.path.unlink()
            os.close(self._fd)  # closing the last fd of the open file drops the flock
            self._fd = None

    @property
    def held(self):
        return self._fd is not None


class StudyLock:
    """A short exclusive lock on a study folder (waits for the holder; ``with StudyLock(folder):``)."""

    def __init__(self, folder):
        self.path = Path(folder) / LOCK_FILE

    def __enter__(self):
        self._fd = _acquire(self.path, blocking=True)
        return self

    def __exit__(self, *exc):
        os.close(self._fd)

