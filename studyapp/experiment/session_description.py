"""A session's description (session.json, or its copy in the log's ``session_created`` event) and a
participant's session folders, read without writing anything.

Below session.py, which writes them, so that enrolment.py (which session.py uses) can read them too.
"""

import json
from pathlib import Path

from studyapp.errors import UserError
from studyapp.experiment import records
from studyapp.experiment.session_files import EVENTS_FILE, FORMAT, SESSION_FILE
from studyapp.experiment.session_log import read_log
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
    return info


def read_description(folder):
    """(the session's description, notes) of the session ``folder``, read without writing anything.

    From session.json; when that is missing or damaged, from the ``session_created``
    event of events.jsonl (a note says so). ``UserError`` (one line) when neither holds it.
    """
    folder = Path(folder)
    path = folder / SESSION_FILE
    try:
        with open_regular(path, "session description", "r", encoding="utf-8") as f:  # a FIFO is damaged, not waited on
            return _check_description(json.loads(f.read(LIMIT_BYTES)), path), []
    except (OSError, ValueError, UnicodeDecodeError) as exc:
        problem = "missing" if isinstance(exc, FileNotFoundError) else f"damaged ({exc})"
    created = next((e for e in read_log(folder / EVENTS_FILE).events if e.get("type") == CREATED), None)
    try:
        info = _check_description(created.get("description") if created else None, path)
    except ValueError:
        raise UserError(f"{path}: {problem}, and {folder / EVENTS_FILE} holds no session description to rebuild "
                        "it from: allowed is to restore session.json from a backup") from None
    return info, [f"{path}: {problem}; its content is read from the session_created event of {EVENTS_FILE}"]
