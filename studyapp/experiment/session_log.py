"""The append-only event log of a session: ``events.jsonl``.

One JSON object per line. ``append`` stamps each event with ``seq`` (0, 1, 2,
... over the whole session, across resumes), ``mono`` (``time.monotonic()``,
seconds; comparable within one run of the program only), ``wall`` (local
ISO-8601 time with its UTC offset, millisecond precision) and, as its last
key, ``crc``: the CRC-32 (8 hex digits) of the line's bytes without the
``,"crc":"..."`` part. It writes the line with one ``os.write``, and
``os.fsync``s the file before returning, so an event that ``append`` returned
from survives a crash of the program or of the machine.

Reading (``read_log``) checks every line and never lets one bad line hide
the others:

- a complete line that is not valid JSON or fails its checksum is *damaged*:
  it is left out, reported by its line number, and the valid lines after it
  are kept. Valid JSON that is not an event object is *malformed* (not
  corruption: an edited file): the export refuses it, resuming treats it as damaged. Opening the log for appending leaves it in place (nothing
  but a torn last line is ever removed), copies it to ``events.jsonl.damaged``
  and logs a ``log_damaged`` event the first time it is seen.
- the bytes after the last newline are a *torn* last line (the machine lost
  power, or the disk filled, during a write; the event was never confirmed).
  Opening the log for appending copies them to ``events.jsonl.torn-<time>``,
  truncates them and logs a ``log_repaired`` event. A torn line that passes
  its checksum lacks only its newline, which is added instead.

Every such finding is also a line in ``SessionLog.notes`` for the program to
show. A write that fails (disk full, file too large, I/O error) is undone by
truncating the file back to its last complete line, and raises
``LogWriteError``: the file stays valid, and resuming continues it.
"""

import json
import os
import re
import time
import zlib
from dataclasses import dataclass, field
from datetime import datetime
from pathlib import Path

from studyapp.atomic import atomic_open
from studyapp.errors import UserError
from studyapp.experiment.data_modes import file_mode, open_file
from studyapp.small_files import read_regular

DAMAGED_SUFFIX = ".damaged"
LOG_LIMIT = 1 << 30  # bytes: a long study's log is a few MB; above this it is not a session log
TORN_SUFFIX = ".torn-"
_CRC_TAIL = re.compile(rb',"crc":"([0-9a-f]{8})"\}$')


class LogWriteError(UserError):
    """The session log could not be written (disk full, a write error); nothing was torn."""


def wall_time():
    """Now as local ISO-8601 time with its UTC offset, e.g. 2014-07-01T14:03:22.135+02:00."""
    return datetime.now().astimezone().isoformat(timespec="milliseconds")


def encode(record):
    """The log line (bytes, newline included) of ``record``, its CRC-32 appended as key ``crc``."""
    body = json.dumps(record, separators=(",", ":"), allow_nan=False).encode("utf-8")
    return body[:-1] + b',"crc":"%08x"}\n' % zlib.crc32(body)


def decode(line):
    """(event, None) for a valid line (bytes, no newline), else (None, why it is damaged)."""
    try:
        event = json.loads(line)
    except ValueError:
        return None, "not valid JSON"
    if not isinstance(event, dict) or "type" not in event:
        return None, "not an event"
    if "crc" in event:
        match = _CRC_TAIL.search(line)
        if match is None or zlib.crc32(line[: match.start()] + b"}") != int(match.group(1), 16):
            return None, "checksum mismatch"
        del event["crc"]
    return event, None


@dataclass
class LogScan:
    """What ``scan`` found in a log's bytes."""

    events: list = field(default_factory=list)
    lines: list = field(default_factory=list)      # the 1-based line number of each event
    damaged: list = field(default_factory=list)    # (line number, reason, raw bytes with newline)
    malformed: list = field(default_factory=list)  # the same, for valid JSON that is not an event
    torn: bytes = b""                              # an incomplete last line
    completed: bool = False                        # the last line was whole but for its newline

    def messages(self, name):
        """One line per damaged line, naming ``name`` (e.g. the file) and the line number."""
        return [f"{name} line {n}: damaged ({why}), left out; the lines after it are kept"
                for n, why, _ in self.damaged]


def scan(data):
    """Check every line of ``data`` (the bytes of a log); see the module docstring."""
    result = LogScan()
    *complete, tail = data.split(b"\n")
    for number, line in enumerate(complete, start=1):
        event, why = decode(line)
        if event is None:
            (result.malformed if why == "not an event" else result.damaged).append((number, why, line + b"\n"))
        else:
            result.events.append(event)
            result.lines.append(number)
    if tail:
        event, _ = decode(tail)
        if event is not None and _CRC_TAIL.search(tail):
            result.events.append(event)
            result.lines.append(len(complete) + 1)
            result.completed = True
        else:
            result.torn = tail
    return result


def read_log(path):
    """``scan`` of the log at ``path`` (empty when there is none); ``UserError`` for a FIFO or device
    (never read: it would block or never end) or a log above ``LOG_LIMIT``."""
    try:
        return scan(read_regular(path, "session log (events.jsonl)", LOG_LIMIT))
    except FileNotFoundError:
        return LogScan()


def read_events(path):
    """The valid events of the log at ``path`` (damaged lines and a torn tail left out)."""
    return read_log(path).events


def fsync_directory(path):
    """Make a new directory entry (a created file) durable too."""
    fd = os.open(path, os.O_RDONLY)
    try:
        os.fsync(fd)
    finally:
        os.close(fd)


def _write_copy(path, data):
    with atomic_open(path, "wb", permissions=file_mode()) as f:
        f.write(data)
        f.flush()
        os.fsync(f.fileno())


class SessionLog:
    """Appends events to ``path``, each one on disk before ``append`` returns."""

    def __init__(self, path):
        self.path = Path(path)
        self.notes = []
        existed = self.path.exists()
        self._fd = open_file(self.path, os.O_WRONLY | os.O_APPEND)
        try:
            self._open(existed)
        except BaseException:
            os.close(self._fd)
            raise

    def _open(self, existed):
        if not existed:
            fsync_directory(self.path.parent)
        data = read_regular(self.path, "session log (events.jsonl)", LOG_LIMIT)
        log = scan(data)
        self._size = len(data) - len(log.torn)
        self.seq = max((e["seq"] for e in log.events if isinstance(e.get("seq"), int)), default=-1) + 1
        repairs = []
        if log.torn:
            stamp = datetime.now().strftime("%Y%m%dT%H%M%S")
            copy = self.path.with_name(f"{self.path.name}{TORN_SUFFIX}{stamp}")
            self._guard(lambda: _write_copy(copy, log.torn))
            self._guard(lambda: (os.ftruncate(self._fd, self._size), os.fsync(self._fd)))
            self.notes.append(f"{self.path}: a torn last line ({len(log.torn)} bytes, an event never "
                              f"confirmed) removed; a copy is kept in {copy.name}")
            repairs.append({"type": "log_repaired", "dropped_bytes": len(log.torn), "copy": copy.name})
        elif log.completed:
            self._write(b"\n")
            self.notes.append(f"{self.path}: the last line lacked its newline (checksum valid): completed")
        bad = sorted(log.damaged + log.malformed)
        if bad:
            side = self.path.with_name(self.path.name + DAMAGED_SUFFIX)
            quarantined = b"".join(raw for _, _, raw in bad)
            first_time = not side.exists() or side.read_bytes() != quarantined
            if first_time:
                self._guard(lambda: _write_copy(side, quarantined))
                repairs.append({"type": "log_damaged", "lines": [n for n, _, _ in bad], "copy": side.name})
            self.notes.extend(f"{self.path} line {n}: damaged ({why}), set aside in {side.name}; "
                              "the lines after it are kept" for n, why, _ in bad)
        for event in repairs:
            self.append(event)

    def _guard(self, action):
        try:
            action()
        except OSError as exc:
            raise LogWriteError(f"{self.path}: cannot repair the session log ({exc.strerror or exc}): "
                                "allowed is to free disk space and try again") from None

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
                                "stopped, nothing torn: free disk space, then resume it") from None
        self._size += len(line)

    def append(self, event):
        """Stamp ``event`` (a dict with a ``type``), write it durably and return the stamped copy."""
        record = {"seq": self.seq, "mono": time.monotonic(), "wall": wall_time(), **event}
        self._write(encode(record))
        self.seq += 1
        return record

    def close(self):
        if self._fd is not None:
            os.close(self._fd)
            self._fd = None

    def __enter__(self):
        return self

    def __exit__(self, *exc):
        self.close()
