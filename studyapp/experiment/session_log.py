"""The append-only event log of a session: ``events.jsonl``.

One JSON object per line. ``append`` stamps each event with ``seq`` (0, 1, 2,
... over the whole session, across resumes), ``mono`` (``time.monotonic()``,
seconds; comparable within one run of the program only) and ``wall`` (local
ISO-8601 time with its UTC offset, millisecond precision), writes the line,
flushes it and ``os.fsync``s the file before returning, so an event that
``append`` returned from survives a crash of the program or of the machine.

A crash can at worst leave a torn last line (the machine lost power during
the write). ``read_events`` skips it, and opening the log for appending
truncates it first (recording how many bytes it dropped in a ``log_repaired``
event), so the file stays valid JSON-lines.
"""

import json
import os
import time
from datetime import datetime
from pathlib import Path


def wall_time():
    """Now as local ISO-8601 time with its UTC offset, e.g. 2014-07-01T14:03:22.135+02:00."""
    return datetime.now().astimezone().isoformat(timespec="milliseconds")


def _good_prefix(data):
    """(events, length) of the complete, valid lines at the start of ``data`` (bytes)."""
    events, end = [], 0
    for line in data.splitlines(keepends=True):
        if not line.endswith(b"\n"):
            break
        try:
            events.append(json.loads(line))
        except ValueError:
            break
        end += len(line)
    return events, end


def read_events(path):
    """The events of the log at ``path`` (a torn or corrupt tail is left out)."""
    try:
        data = Path(path).read_bytes()
    except FileNotFoundError:
        return []
    return _good_prefix(data)[0]


def fsync_directory(path):
    """Make a new directory entry (a created file) durable too."""
    fd = os.open(path, os.O_RDONLY)
    try:
        os.fsync(fd)
    finally:
        os.close(fd)


class SessionLog:
    """Appends events to ``path``, each one on disk before ``append`` returns."""

    def __init__(self, path):
        self.path = Path(path)
        existed = self.path.exists()
        data = self.path.read_bytes() if existed else b""
        events, end = _good_prefix(data)
        self._file = open(self.path, "ab")
        if end < len(data):
            self._file.truncate(end)
            self._file.seek(end)
        if not existed:
            fsync_directory(self.path.parent)
        self.seq = events[-1]["seq"] + 1 if events else 0
        if end < len(data):
            self.append({"type": "log_repaired", "dropped_bytes": len(data) - end})

    def append(self, event):
        """Stamp ``event`` (a dict with a ``type``), write it durably and return the stamped copy."""
        record = {"seq": self.seq, "mono": time.monotonic(), "wall": wall_time(), **event}
        line = json.dumps(record, separators=(",", ":"), allow_nan=False) + "\n"
        self._file.write(line.encode("utf-8"))
        self._file.flush()
        os.fsync(self._file.fileno())
        self.seq += 1
        return record

    def close(self):
        self._file.close()

    def __enter__(self):
        return self

    def __exit__(self, *exc):
        self.close()
