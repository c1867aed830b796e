"""A session's description (session.json, or its copy in the log's ``session_created`` event) and a
participant's session folders, read without writing anything.

Below session.py, which writes them, so that enrolment.py (which session.py uses) can read them too.
"""

from pathlib import Path

from studyapp.errors import UserError
from studyapp.experiment import records
from studyapp.experiment.session_files import EVENTS_FILE, FORMAT, SESSION_FILE
from studyapp.experiment.session_log import read_log
from studyapp.io import bounded_json
from studyapp.io.small_files import LIMIT_BYTES, open_regular

CREATED = records.SESSION_CREATED


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


def read_description(folder):
    """(the session's description, notes) of the session ``folder``, read without writing anything.

    From session.json; when that is missing or damaged, from the ``session_created``
    event of events.jsonl (a note says so). ``UserError`` (one line) when neither holds it.
    """
    folder = Path(folder)
    path = folder / SESSION_FILE
    try:
        with open_regular(path, "session description", "r", encoding="utf-8") as f:  # a FIFO is damaged, not waited on
            return _check_description(bounded_json.loads(f.read(LIMIT_BYTES)), path), []
    except (OSError, ValueError, UnicodeDecodeError) as exc:
        problem = "missing" if isinstance(exc, FileNotFoundError) else f"damaged ({exc})"
    created = next((e for e in read_log(folder / EVENTS_FILE).events if e.get("type") == CREATED), None)
    try:
        info = _check_description(created.get("description") if created else None, path)
    except ValueError:
        raise UserError(f"{path}: {problem}, and {folder / EVENTS_FILE} holds no session description to rebuild "
                        "it from: allowed is to restore session.json from a backup") from None
    return info, [f"{path}: {problem}; its content is read from the session_created event of {EVENTS_FILE}"]
