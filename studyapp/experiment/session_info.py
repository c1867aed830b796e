"""What the experimenter tells about a session, and the Latin-square row it runs: checked before anything is written.

Stored in session.json when the session is created (``Session.create``):

- ``experimenter``: a short name (``EXPERIMENTER_ALLOWED``), or None;
- ``session_number``: an integer 1 to 999 (the lab's own count: day 1, day 2, ...), or None;
- ``notes``: free text up to ``NOTES_MAX`` characters (lines allowed), or "";
- ``order_row`` and ``order_row_source``: the order the schedule follows. Each
  task's balanced Latin square has n rows (n, or 2n for an odd number of
  conditions: ``latin_square.williams_rows``), and order row r gives repetition
  k of a task row (r + k) mod n. So the whole schedule repeats every L rows, L
  the least common multiple of the tasks' row counts (``order_rows``): r is
  0 to L - 1. By default r is the participant's enrolment index mod L
  (``"enrolment"``, the first participant row 0); the experimenter can set it
  (``"set"``), e.g. to give a replacement participant the order of the one who
  dropped out.
"""

import math
import re

from studyapp.errors import UserError
from studyapp.experiment.latin_square import williams_rows

EXPERIMENTER_PATTERN = re.compile(r"[^\W_][\w .'-]{0,39}")
EXPERIMENTER_ALLOWED = "1 to 40 letters, digits, spaces, '.', \"'\", '-' or '_', starting with a letter or digit"
SESSION_NUMBER_RANGE = (1, 999)
NOTES_MAX = 2000


def check_experimenter(name):
    """The experimenter's name, stripped, or None when not given."""
    if name is None or not str(name).strip():
        return None
    name = str(name).strip()
    if not EXPERIMENTER_PATTERN.fullmatch(name):
        shown = name if len(name) <= 40 else name[:37] + "..."
        raise UserError(f"experimenter {shown!r}: allowed is a short name of {EXPERIMENTER_ALLOWED}")
    return name


def check_session_number(number):
    """The session number (an int 1 to 999), or None when not given."""
    if number is None or number == "":
        return None
    low, high = SESSION_NUMBER_RANGE
    try:
        value = int(str(number).strip())
    except ValueError:
        value = None
    if value is None or not low <= value <= high:
        raise UserError(f"session number {number!r}: allowed is a whole number from {low} to {high}")
    return value


def check_notes(notes):
    """The notes (stripped; "" when not given): at most ``NOTES_MAX`` characters, no control characters but line breaks."""
    text = "" if notes is None else str(notes).strip()
    if len(text) > NOTES_MAX:
        raise UserError(f"notes: {len(text)} characters: allowed is at most {NOTES_MAX}")
    bad = next((c for c in text if ord(c) < 32 and c not in "\n\t"), None)
    if bad is not None:
        raise UserError(f"notes: control character {bad!r}: allowed is text with line breaks and tabs")
    return text


def square_rows(protocol):
    """{task: the number of rows of its balanced Latin square}."""
    return {task: len(williams_rows(len(protocol.task(task).conditions))) for task in protocol.tasks}


def order_rows(protocol):
    """L: the number of distinct orders (the schedule repeats every L order rows)."""
    return math.lcm(*square_rows(protocol).values())


def check_order_row(protocol, row):
    """The order row (an int 0 to L - 1), or None when not given (the enrolment index decides)."""
    if row is None or row == "":
        return None
    count = order_rows(protocol)
    try:
        value = int(str(row).strip())
    except ValueError:
        value = None
    if value is None or not 0 <= value < count:
        sizes = ", ".join(f"{task} {n} rows" for task, n in square_rows(protocol).items())
        raise UserError(f"order row {row!r}: allowed is 0 to {count - 1} for {protocol.path} "
                        f"(its Latin squares: {sizes})")
    return value


def order_text(info):
    """How a session's order is shown: 'order row 3 of 6 (set)' or '... (enrolment)'."""
    row = info.get("order_row")
    if row is None:
        return f"order row {info.get('participant_index', '?')} (enrolment; stored before order rows were)"
    return f"order row {row} of {info['order_rows']} ({info['order_row_source']})"
