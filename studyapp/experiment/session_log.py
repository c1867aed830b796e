"""The append-only event log of a session: ``events.jsonl``.

One JSON object per line. ``append`` stamps each event with ``seq`` (0, 1, 2,
... over the whole session, across resumes), ``mono`` (``time.monotonic()``,
seconds; comparable within one run of the program only), ``wall`` (local
ISO-8601 time with its UTC offset, millisecond precision) and, as its last
key, ``crc``: the CRC-32 (8 hex digits) of the line's bytes without the
``,"crc":"..."`` part. It writes the line with one ``os.write``, and
``os.fsync``s the file before returning, so an event that ``append`` returned
from survives a crash of the program or of the machine.

Reading (``read_log``, ``log_scan``) checks every line, its checksum first,
and never lets one bad line hide the others. Opening the log for appending
(``SessionLog``) repairs only what was never confirmed:

- a damaged or malformed line stays in place (nothing but the bytes after the
  last confirmed event is ever removed); it is copied to
  ``events.jsonl.damaged`` and a ``log_damaged`` event is logged the first
  time it is seen.
- a torn last line (or the damaged newline of the last confirmed event) is
  copied to ``events.jsonl.torn-<time>`` and truncated, and ``log_repaired``
  logged; a last confirmed event that lacks its newline gets one.

Every such finding is also a line in ``SessionLog.notes`` for the program to
show. The log is written only under its ``LogLock`` (a flock on the file itself,
held through the descriptor it appends with; session_lock.py says why), and
never through a link (``data_modes.open_file``). A write that fails (disk full, file too large, I/O error) is undone by
truncating the file back to its last complete line, and raises
``LogWriteError``: the file stays valid, and resuming continues it.
"""

import fcntl
import json
import os
import time
import zlib
from datetime import datetime
from pathlib import Path

from studyapp.io.atomic import atomic_open
from studyapp.errors import UserError
from studyapp.experiment import records
from studyapp.experiment.data_modes import file_mode, open_file
from studyapp.io.small_files import read_regular
from studyapp.experiment.log_scan import LOG_LIMIT, read_events, read_log, scan  # noqa: F401 - the log's readers, here too

DAMAGED_SUFFIX = ".damaged"
TORN_SUFFIX = ".torn-"


class LogWriteError(UserError):
    """The session log could not be written (disk full, a write error); nothing was torn.

    ``reason`` is the system's word for it (e.g. "No space left on device")."""

    def __init__(self, message, reason=None):
        super().__init__(message)
        self.reason = reason


def wall_time():
    """Now as local ISO-8601 time with its UTC offset, e.g. 2014-07-01T14:03:22.135+02:00."""
    return datetime.now().astimezone().isoformat(timespec="milliseconds")


def encode(record):
    """The log line (bytes, newline included) of ``record``, its CRC-32 appended as key ``crc``."""
    body = json.dumps(record, separators=(",", ":"), allow_nan=False).encode("utf-8")
    return body[:-1] + b',"crc":"%08x"}\n' % zlib.crc32(body)


def fsync_directory(path):
    """Make a new directory entry (a created file) durable too."""
    fd = os.open(path, os.O_RDONLY)
    try:
        os.fsync(fd)
    finally:
        os.close(fd)


def _read_all(fd, path):
    """The bytes of the open log ``fd`` (the file locked, not whatever its name points to now)."""
    size = os.fstat(fd).st_size
    if size > LOG_LIMIT:
        raise UserError(f"{path}: larger than {LOG_LIMIT >> 20} MB: allowed is a session log (events.jsonl) "
                        "file up to that size")
    chunks, done = [], 0
    while done < size:
        chunk = os.pread(fd, size - done, done)
        if not chunk:
            break
        chunks.append(chunk)
        done += len(chunk)
    return b"".join(chunks)


def _read_or_none(path):
    try:
        return read_regular(path, "set-aside copy", LOG_LIMIT)
    except (OSError, UserError):
        return None


def _write_copy(path, data):
    with atomic_open(path, "wb", permissions=file_mode()) as f:
        f.write(data)
        f.flush()
        os.fsync(f.fileno())


class LogLock:
    """The exclusive lock on a session's log, held through the descriptor the log is appended with.

    ``fd``: ``events.jsonl`` opened for appending (created if missing, never through a link).
    ``UserError`` when another program holds it: that program writes the session now."""

    def __init__(self, path):
        self.path = Path(path)
        self.fd = open_file(self.path, os.O_RDWR | os.O_APPEND)
        try:
            fcntl.flock(self.fd, fcntl.LOCK_EX | fcntl.LOCK_NB)
        except BlockingIOError:
            os.close(self.fd)
            self.fd = None
            raise UserError(f"{self.path}: another program is writing this session now (its log is locked, "
                            "whatever became of the participant's .lock): allowed is to wait until it ends") from None
        except BaseException:
            os.close(self.fd)
            raise

    def release(self):
        if self.fd is not None:
            os.close(self.fd)
            self.fd = None


class SessionLog:
    """Appends events to ``path``, each one on disk before ``append`` returns.

    ``lock``: the ``LogLock`` of ``path`` when the caller took it already (then the log owns it)."""

    def __init__(self, path, lock=None):
        self.path = Path(path)
        self.notes = []
        existed = os.path.lexists(self.path)
        self._lock = LogLock(self.path) if lock is None else lock
        self._fd = self._lock.fd
        try:
            self._open(existed)
        except BaseException:
            self._lock.release()
            raise

    def _open(self, existed):
        if not existed:
            fsync_directory(self.path.parent)
        data = _read_all(self._fd, self.path)
        log = scan(data)
        self._size = len(data) - len(log.cut)
        self.seq = max((e["seq"] for e in log.events if isinstance(e.get("seq"), int)), default=-1) + 1
        repairs = []
        if log.cut:
            stamp = datetime.now().strftime("%Y%m%dT%H%M%S")
            copy = self.path.with_name(f"{self.path.name}{TORN_SUFFIX}{stamp}")
            self._guard(lambda: _write_copy(copy, log.cut))
            self._guard(lambda: (os.ftruncate(self._fd, self._size), os.fsync(self._fd)))
            what = (f"a torn last line ({len(log.torn)} bytes, an event never confirmed)" if log.torn else "")
            if log.completed:
                what = " and ".join(filter(None, ["the damaged newline of the last confirmed event", what]))
            self.notes.append(f"{self.path}: {what} removed; a copy is kept in {copy.name}")
            repairs.append(records.log_repaired(len(log.cut), copy.name))
        if log.completed:
            self._write(b"\n")
            self.notes.append(f"{self.path}: the last line lacked its newline (checksum valid: confirmed): completed")
        self.notes.extend(f"{self.path} line {n}: confirmed events run together (a damaged newline): all kept"
                          for n in log.mended)
        bad = sorted(log.damaged + log.malformed)
        if bad:
            side = self.path.with_name(self.path.name + DAMAGED_SUFFIX)
            quarantined = b"".join(raw for _, _, raw in bad)
            first_time = _read_or_none(side) != quarantined
            if first_time:
                self._guard(lambda: _write_copy(side, quarantined))
                repairs.append(records.log_damaged([n for n, _, _ in bad], side.name))
            self.notes.extend(f"{self.path} line {n}: damaged ({why}), set aside in {side.name}; "
                              "the lines after it are kept" for n, why, _ in bad)
        for event in repairs:
            self.append(event)

    def _guard(self, action):
        try:
            action()
        except OSError as exc:
            raise LogWriteError(f"{self.path}: cannot repair the session log ({exc.strerror or exc}): "
                                "allowed is to free disk space and try again", exc.strerror or str(exc)) from None

    def _write(self, line):
        try:
            done = 0
            while done < len(line):
                done += os.write(self._fd, line[done:])
            os.fsync(self._fd)
        except OSError as exc:
            try:
                os.ftruncate(self._fd, self._size)  # take back a partial line: the file stays whole
            except OSError:
                pass  # then the next open removes it as a torn last line, keeping a copy
            raise LogWriteError(f"{self.path}: cannot write the session log ({exc.strerror or exc}): the session "
                                "stopped, nothing torn: free disk space, then resume it", exc.strerror or str(exc)) from None
        self._size += len(line)

    def append(self, event):
        """Stamp ``event`` (a dict with a ``type``), write it durably and return the stamped copy."""
        record = {"seq": self.seq, "mono": time.monotonic(), "wall": wall_time(), **event}
        self._write(encode(record))
        self.seq += 1
        return record

    def close(self):
        if self._fd is not None:
            self._lock.release()
            self._fd = None

    def __enter__(self):
        return self

    def __exit__(self, *exc):
        self.close()
