"""The names of a session's files, and how to tell a session folder (no heavy imports: output checks use it).

    RESULTS/<study>/<participant>/.lock                     the participant's lock (session_lock)
    RESULTS/<study>/<participant>/<session>/session.json    the description (session)
    RESULTS/<study>/<participant>/<session>/events.jsonl    the event log (session_log)
    RESULTS/<study>/<participant>/<session>/audio*.wav, audio_cues.csv   what was heard (engine/audio/recorder.py)
"""

import os
import stat
from pathlib import Path

SESSION_FILE = "session.json"
EVENTS_FILE = "events.jsonl"
LOCK_FILE = ".lock"
FORMAT = "studyapp-session/1"


def is_session_folder(folder):
    """True when ``folder`` holds an ``events.jsonl``, or a ``session.json`` of this format (or one that is
    not a regular file, a FIFO: never opened, and taken as a damaged session's, so nothing is written beside it)."""
    folder = Path(folder)
    if os.path.lexists(folder / EVENTS_FILE):
        return True
    try:
        # O_NONBLOCK: a FIFO opens at once instead of waiting for a writer
        fd = os.open(folder / SESSION_FILE, os.O_RDONLY | os.O_NONBLOCK)
    except OSError:
        return os.path.lexists(folder / SESSION_FILE) and not os.path.isfile(folder / SESSION_FILE)
    try:
        if not stat.S_ISREG(os.fstat(fd).st_mode):
            return not stat.S_ISDIR(os.fstat(fd).st_mode)
        return FORMAT.encode() in os.read(fd, 200)  # written by json.dump, "format" first
    except OSError:
        return False
    finally:
        os.close(fd)
