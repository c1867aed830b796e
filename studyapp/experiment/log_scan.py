"""Reading a session's event log (``events.jsonl``): every line checked, its checksum first.

Each line the log writes (``session_log.encode``) ends with ``,"crc":"XXXXXXXX"}``:
the CRC-32 of the line's bytes without that part (and with its closing brace).
The checksum is checked before anything else is read from a line, so what a
damaged line seems to say (a ``"type"`` flipped to ``"typa"``) never counts:

- a line whose checksum verifies is *confirmed*: it was written whole and
  fsynced, whatever happened to the newline after it. Two confirmed lines run
  together by a damaged newline are both kept (``mended``: the line's number);
  a confirmed last line whose newline is missing or damaged is kept too.
- a line whose checksum fails, that is not valid JSON, or that lacks its
  checksum after a line that has one, is *damaged*: left out and reported by
  its line number; the lines after it are kept.
- a line that is valid JSON but not an event object, without a checksum or
  with a valid one, was written by hand or by another program: *malformed*
  (the export refuses it; resuming sets it aside like a damaged one).
- the bytes after the last confirmed event, when they do not end in a newline,
  are a *torn* last line: a write cut short (power lost, the disk full); that
  event was never confirmed.

Lines without a checksum before the first line that has one (a session begun
by a version that wrote none) are read as they are.
"""

import re
import zlib
from dataclasses import dataclass, field

from studyapp.errors import UserError
from studyapp.io import bounded_json
from studyapp.io.small_files import read_regular

_CRC = re.compile(rb',"crc":"([0-9a-f]{8})"\}')
_CRC_END = re.compile(rb',"crc":"([0-9a-f]{8})"\}$')
LOG_LIMIT = 1 << 30  # bytes: a long study's log is a few MB; above this it is not a session log
NOT_AN_EVENT = "not an event"
NO_CHECKSUM = "no checksum"


def _event(text):
    """The JSON object ``text`` holds as an event (a dict with a ``type``), or the reason it is not one."""
    try:
        event = bounded_json.loads(text)  # a line nested too deeply is not valid JSON either
    except ValueError:
        return None, "not valid JSON"
    if not isinstance(event, dict) or "type" not in event:
        return None, NOT_AN_EVENT
    return event, None


def _verified(chunk, start, match):
    """True when the record ``chunk[start:match.end()]`` (``match`` its checksum) passes its checksum."""
    return zlib.crc32(chunk[start: match.start()] + b"}") == int(match.group(1), 16)


def classify(line):
    """``(event, why, checked)`` of one line (bytes, no newline): ``why`` None for an event.

    ``checked`` says whether the line carried a checksum that verified."""
    match = _CRC_END.search(line)
    if match is not None:
        if not _verified(line, 0, match):  # damaged, whatever it seems to say; the reason says what shows
            return None, "checksum mismatch" if _event(line)[1] != "not valid JSON" else "not valid JSON", False
        event, why = _event(line)
        if event is not None:
            del event["crc"]
        return event, why, True
    event, why = _event(line)
    if event is not None and "crc" in event:
        return None, "checksum mismatch", False  # a checksum, but not where it belongs
    return event, why, False


def _records(chunk):
    """The confirmed records at the start of ``chunk``, one damaged byte (a newline) between two.

    Returns (events, where the last of them ends). A chunk that holds one record
    and nothing else is not asked for: ``classify`` has judged it."""
    events, start, end = [], 0, 0
    for match in _CRC.finditer(chunk):
        if match.start() < start or not _verified(chunk, start, match):
            continue
        event, _ = _event(chunk[start: match.end()])
        if event is None:
            continue
        del event["crc"]
        events.append(event)
        end = match.end()
        start = end + 1  # the damaged newline
    return events, end


@dataclass
class LogScan:
    """What ``scan`` found in a log's bytes."""

    events: list = field(default_factory=list)
    lines: list = field(default_factory=list)      # the 1-based line number of each event
    damaged: list = field(default_factory=list)    # (line number, reason, raw bytes with newline)
    malformed: list = field(default_factory=list)  # the same, for valid JSON that is not an event
    mended: list = field(default_factory=list)     # line numbers holding confirmed events run together
    torn: bytes = b""                              # an unconfirmed, incomplete last line
    cut: bytes = b""                               # the bytes after the last confirmed event that resume removes
    completed: bool = False                        # the last confirmed event lacks its newline

    def messages(self, name):
        """One line per damaged line, naming ``name`` (e.g. the file) and the line number."""
        return [f"{name} line {n}: damaged ({why}), left out; the lines after it are kept"
                for n, why, _ in self.damaged]


def scan(data):
    """Check every line of ``data`` (the bytes of a log); see the module docstring."""
    result = LogScan()
    *complete, tail = data.split(b"\n")
    found = []  # (line number, event, why, checked, raw)
    for number, line in enumerate(complete, start=1):
        event, why, checked = classify(line)
        if event is None and why != NOT_AN_EVENT:
            events, end = _records(line)
            found += [(number, e, None, True, None) for e in events]
            if events and end == len(line):
                result.mended.append(number)
                continue
        found.append((number, event, why, checked, line + b"\n"))
    checksummed = False  # from the first line that has one on, every line must
    for number, event, why, checked, raw in found:
        checksummed = checksummed or checked
        if event is not None and checksummed and not checked:
            event, why = None, NO_CHECKSUM
        if event is not None:
            result.events.append(event)
            result.lines.append(number)
        elif why is not None:
            (result.malformed if why == NOT_AN_EVENT else result.damaged).append((number, why, raw))
    if tail:
        event, _, checked = classify(tail)
        events, end = ([event], len(tail)) if event is not None and checked else _records(tail)
        result.events += events
        result.lines += [len(complete) + 1] * len(events)
        result.completed = bool(events)
        result.cut = tail[end:]
        result.torn = result.cut[1:] if events else result.cut  # after a confirmed event, its damaged newline
    return result


def read_log(path):
    """``scan`` of the log at ``path`` (empty when there is none); ``UserError`` for a FIFO or device
    (never read: it would block or never end), a folder, a sparse file or a log above ``LOG_LIMIT``."""
    try:
        return scan(read_regular(path, "session log (events.jsonl)", LOG_LIMIT))
    except FileNotFoundError:
        return LogScan()
    except IsADirectoryError:
        raise UserError(f"{path}: is a folder: allowed is a session log file") from None
    except UserError:
        raise
    except OSError as exc:  # permissions, an I/O error: one line, never a traceback
        raise UserError(f"{path}: cannot read the session log ({exc.strerror or exc})") from None


def read_events(path):
    """The valid events of the log at ``path`` (damaged lines and a torn tail left out)."""
    return read_log(path).events


def _repeats(values, lines):
    """{value: [line numbers]} of the values (whole numbers) that occur more than once."""
    seen = {}
    for value, line in zip(values, lines):
        if isinstance(value, int) and not isinstance(value, bool):
            seen.setdefault(value, []).append(line)
    return {value: at for value, at in seen.items() if len(at) > 1}


def written_twice(log):
    """What shows that two programs appended to one log (a ``LogScan``), or None.

    Each program numbers its events ``seq`` from the end of the log it opened, and
    a step is answered once (resume skips answered steps); a repeated ``seq`` or a
    second ``response`` for a step means two writers at once (issue 21, item 1)."""
    found = []
    seqs = _repeats([e.get("seq") for e in log.events], log.lines)
    responses = [(e.get("step"), line) for e, line in zip(log.events, log.lines) if e.get("type") == "response"]
    steps = _repeats([s for s, _ in responses], [line for _, line in responses])
    for what, repeats in (("step", steps), ("seq", seqs)):
        if repeats:
            value, lines = min(repeats.items(), key=lambda item: item[1][0])
            kind = "steps with more than one response" if what == "step" else "seq values repeated"
            found.append(f"{len(repeats)} {kind} (first: {what} {value}, lines {', '.join(map(str, lines))})")
    return "; ".join(found) or None
