"""The names of a session's files, and how to tell a session folder (no heavy imports: output checks use it).

    RESULTS/<study>/<participant>/.lock                     the participant's lock (session_lock)
    RESULTS/<study>/<participant>/<session>/session.json    the description (session)
    RESULTS/<study>/<participant>/<session>/events.jsonl    the event log (session_log)
    RESULTS/<study>/<participant>/<session>/audio*.wav, audio_cues.csv   what was heard (engine/audio/recorder.py)
"""

import os
from pathlib import Path

SESSION_FILE = "session.json"
EVENTS_FILE = "events.jsonl"
LOCK_FILE = ".lock"
FORMAT = "studyapp-session/1"


def is_session_folder(folder):
    """True when ``folder`` holds an ``events.jsonl``, or a ``session.json`` of this format."""
    folder = Path(folder)
    if os.path.lexists(folder / EVENTS_FILE):
        return True
    try:
        with open(folder / SESSION_FILE, "rb") as f:  # written by json.dump, "format" first
            return FORMAT.encode() in f.read(200)
    except OSError:
        return False
