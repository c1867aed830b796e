"""A session's description (session.json, or its copy in the log's ``session_created`` event) and a
participant's session folders, read without writing anything.

The log's copy is the one trusted: every line of events.jsonl carries a CRC-32
(log_scan.py), session.json none. So a session.json that is missing, damaged,
or that differs in any field from the log's ``session_created`` copy is read
from the log, with one note per differing field (``.../session.json: field
'participant' differs from the session_created record of events.jsonl
('SIM03' here, 'SIM02' there): the log's copy is used``). A session whose log
lacks that event (begun before this version, or its first line damaged) is
read from session.json, whose protocol text must still match its own SHA-256.

Below session.py, which writes them, so that enrolment.py (which session.py uses) can read them too.
"""

import hashlib
from pathlib import Path

from studyapp.errors import UserError
from studyapp.experiment import records
from studyapp.experiment.session_files import EVENTS_FILE, FORMAT, SESSION_FILE
from studyapp.experiment.session_log import read_log
from studyapp.io import bounded_json
from studyapp.io.small_files import open_regular

CREATED = records.SESSION_CREATED
DESCRIPTION_LIMIT = 32 << 20  # bytes: a protocol is at most 1 MB; its text, settings and schedule, JSON-escaped


def session_folders(participant_folder):
    """The session folders (holding a session.json or an events.jsonl) of one participant, oldest first."""
    folder = Path(participant_folder)
    if not folder.is_dir():
        return []
    return sorted({p.parent for name in (SESSION_FILE, EVENTS_FILE) for p in folder.glob(f"*/{name}")})


def _check_description(info, where):
    if not isinstance(info, dict) or info.get("format") != FORMAT:
        got = info.get("format") if isinstance(info, dict) else type(info).__name__
        raise ValueError(f"format {got!r}, allowed is {FORMAT!r}")
    for key in ("participant", "session", "seed", "protocol", "schedule"):
        if key not in info:
            raise ValueError(f"no {key!r}")
    # the types every reader relies on: a hand-edited or damaged file is damaged, not a traceback
    _check_types(info, _TYPES, "")
    _check_types(info["protocol"], _PROTOCOL_TYPES, "protocol.")
    for number, trial in enumerate(info["schedule"]):
        if not isinstance(trial, dict):
            raise ValueError(f"'schedule[{number}]' is {type(trial).__name__}, allowed is an object")
        _check_types(trial, _TRIAL_TYPES, f"schedule[{number}].")
    return info


_TYPES = {"participant": str, "session": str, "seed": int, "protocol": dict, "schedule": list, "study": str,
          "simulated": bool, "order_row": int}
_PROTOCOL_TYPES = {"sha256": str, "text": str, "path": str}
_TRIAL_TYPES = {"step": int, "task": str, "trial": int, "conditions": list}


def _check_types(values, types, prefix):
    for key, kind in types.items():
        if key in values and not (isinstance(values[key], kind)
                                  and (kind is bool or not isinstance(values[key], bool))):
            raise ValueError(f"{prefix}{key!r} is {type(values[key]).__name__}, allowed is {kind.__name__}")


def protocol_problem(info):
    """Why the description's protocol text does not match its own SHA-256, or None."""
    protocol = info.get("protocol")
    if not isinstance(protocol, dict) or not isinstance(protocol.get("text"), str):
        return "its protocol has no text"
    if hashlib.sha256(protocol["text"].encode("utf-8")).hexdigest() != protocol.get("sha256"):
        return "its protocol text does not match its sha256"
    return None


def _first_difference(here, there, name):
    """The dotted name of the first place where ``here`` and ``there`` differ (``name`` when it is the value)."""
    if isinstance(here, dict) and isinstance(there, dict):
        for key in sorted(set(here) | set(there), key=str):
            if key not in here or key not in there or here[key] != there[key]:
                return _first_difference(here.get(key), there.get(key), f"{name}.{key}")
    if isinstance(here, list) and isinstance(there, list) and len(here) == len(there):
        for i, (a, b) in enumerate(zip(here, there)):
            if a != b:
                return _first_difference(a, b, f"{name}[{i}]")
    return name


def _shown(value):
    text = "missing" if value is _MISSING else repr(value)
    return text if len(text) <= 40 else text[:37] + "..."


_MISSING = object()


def differences(stored, logged, path):
    """One line per top-level field in which session.json (``stored``) differs from the log's copy."""
    lines = []
    for key in sorted(set(stored) | set(logged), key=str):
        here, there = stored.get(key, _MISSING), logged.get(key, _MISSING)
        if here == there and (here is _MISSING) == (there is _MISSING):
            continue
        field = _first_difference(here, there, key) if here is not _MISSING and there is not _MISSING else key
        shown = (f" ({_shown(here)} here, {_shown(there)} there)"
                 if not isinstance(here, (dict, list)) and not isinstance(there, (dict, list)) else "")
        lines.append(f"{path}: field {field!r} differs from the {CREATED} record of {EVENTS_FILE}{shown}: "
                     "the log's copy is used")
    return lines


def _read_json(path):
    """(session.json's description, None) or (None, why it cannot be used)."""
    try:
        with open_regular(path, "session description", "r", encoding="utf-8") as f:  # a FIFO is damaged, not waited on
            data = f.read(DESCRIPTION_LIMIT + 1)
        if len(data) > DESCRIPTION_LIMIT:
            raise ValueError(f"larger than {DESCRIPTION_LIMIT >> 20} MB")
        return _check_description(bounded_json.loads(data), path), None
    except (OSError, ValueError, UnicodeDecodeError, RecursionError) as exc:
        return None, "missing" if isinstance(exc, FileNotFoundError) else f"damaged ({exc})"


def logged_description(log):
    """The description in the ``session_created`` event of ``log`` (a ``LogScan``), or None."""
    created = next((e for e in log.events if e.get("type") == CREATED), None)
    try:
        return _check_description(created.get("description") if created else None, None)
    except ValueError:
        return None


def read_description(folder, log=None):
    """(the session's description, notes) of the session ``folder``, read without writing anything.

    The log's ``session_created`` copy when there is one (``log``: the folder's
    ``LogScan`` if already read), with a note per field session.json differs in
    (or one saying session.json is missing or damaged); else session.json.
    ``UserError`` (one line) when neither holds a usable description.
    """
    folder = Path(folder)
    path = folder / SESSION_FILE
    stored, problem = _read_json(path)
    logged = logged_description(read_log(folder / EVENTS_FILE) if log is None else log)
    if logged is not None:
        if stored is None:
            return logged, [f"{path}: {problem}; its content is read from the {CREATED} event of {EVENTS_FILE}"]
        return logged, differences(stored, logged, path)
    if stored is None:
        raise UserError(f"{path}: {problem}, and {folder / EVENTS_FILE} holds no session description to rebuild "
                        "it from: allowed is to restore session.json from a backup")
    wrong = protocol_problem(stored)
    if wrong is not None:
        raise UserError(f"{path}: {wrong}, and {folder / EVENTS_FILE} holds no session description to check it "
                        "against: allowed is to restore session.json from a backup")
    return stored, []
