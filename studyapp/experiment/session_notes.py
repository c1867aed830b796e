"""The experimenter's notes on a session: free text logged with its time as a ``note`` event.

A note is one event in the session's events.jsonl, ``{"type": "note",
"text": ..., "by": "experimenter"}``, stamped like every event with ``seq``,
``mono`` and ``wall`` (session_log.py); during a session it also carries the
``step`` and ``task`` shown when it was written. Notes at the start
(``--notes``, the console's Notes field) stay in session.json as before;
these are the ones added as things happen, and after.

- During a session: the console's note box (``SessionController.add_note``)
  appends to the open log.
- After it (finished, aborted, or a crash): ``add_note(folder, text)`` takes
  the participant's lock of the session's real folder (``session_lock``:
  refused, naming the holder, while a session of theirs runs in another
  program; a link to the folder leads to the same lock) and the log's own
  lock (``session_log.LogLock``), appends, and lets go;
  ``studyapp notes SESSION_DIR --add TEXT`` and the console (its last
  session) use it. The log is read first, without the lock: one that is
  refused (a FIFO, a device, a folder, too large or sparse, or holding no
  valid event at all) is refused with the participant's folder, its .lock
  included, unchanged.
- ``list_notes(results)``: every note under a results folder, for
  ``studyapp notes RESULTS_DIR`` (a table on stdout, or CSV with ``-o``).
  Notes are not responses, so ``export`` carries none: a note of several
  lines would break the table's one-line cells, as session.json's notes would.

The text is checked as session.json's notes (``session_info.check_notes``:
at most 2000 characters, line breaks and tabs but no other control
characters); an empty note is refused.
"""

import os
from pathlib import Path

import pandas as pd

from studyapp.errors import UserError
from studyapp.experiment import records
from studyapp.experiment.export import session_folders_under
from studyapp.experiment.session_description import read_description, session_folders
from studyapp.experiment.session_files import EVENTS_FILE, SESSION_FILE
from studyapp.experiment.session_info import check_notes
from studyapp.experiment.session_lock import ParticipantLock
from studyapp.experiment.session_log import SessionLog, read_log
from studyapp.io.special_files import refuse_special

NOTE = records.NOTE
NOTE_COLUMNS = ["study", "participant", "session", "wall", "step", "task", "text"]


def note_event(text):
    """The ``note`` event of ``text`` (checked), without its stamps."""
    text = check_notes(text)
    if not text:
        raise UserError("note: empty: allowed is some text")
    return records.note(text)


def session_folder_of(path):
    """The session folder ``path`` names: a session folder, or a participant folder (its latest session)."""
    path = Path(path)
    if (path / SESSION_FILE).exists() or (path / EVENTS_FILE).exists():
        return path
    sessions = session_folders(path)
    if sessions:
        return sessions[-1]
    raise UserError(f"{path}: not a session folder (no {SESSION_FILE} or {EVENTS_FILE}) nor a participant folder "
                    "holding one: allowed is a session's folder under results/<study>/<participant>/")


def add_note(folder, text):
    """Append a note to the session in ``folder`` that no program has open; returns the stamped event."""
    event = note_event(text)
    # the real folder: a link's own parent is not the participant's folder, and its lock not theirs
    folder = Path(os.path.realpath(session_folder_of(folder)))
    info, _ = read_description(folder)
    # read-only, before the lock: a log that is refused (a FIFO, a device, a folder, too large) is refused
    # with the participant's folder, its .lock included, unchanged
    refuse_special(folder / EVENTS_FILE, "a session log file", f"{folder / EVENTS_FILE}")
    log = read_log(folder / EVENTS_FILE)
    if not log.events and (log.damaged or log.malformed or log.torn):
        raise UserError(f"{folder / EVENTS_FILE}: holds no valid event ({len(log.damaged) + len(log.malformed)} "
                        "damaged lines): allowed is a session's log; nothing written")
    lock = ParticipantLock(folder.parent, info["participant"])
    try:
        with SessionLog(folder / EVENTS_FILE) as log:
            return log.append(event)
    finally:
        lock.release()


def list_notes(results):
    """DataFrame ``NOTE_COLUMNS``: every note of every session at or below ``results``, oldest first per session."""
    root = Path(results)
    if root.exists() and not root.is_dir():
        raise UserError(f"{root}: is a file: allowed is a results folder (or any folder inside it)")
    if not root.is_dir():
        raise UserError(f"{root}: no such results folder")
    rows = []
    for folder in session_folders_under(root):
        try:
            info, _ = read_description(folder)
        except UserError:
            continue
        for event in read_log(folder / EVENTS_FILE).events:
            if event.get("type") == NOTE:
                rows.append({"study": info.get("study"), "participant": info.get("participant"),
                             "session": info.get("session"), "wall": event.get("wall"), "step": event.get("step"),
                             "task": event.get("task"), "text": event.get("text")})
    frame = pd.DataFrame(rows, columns=NOTE_COLUMNS)
    frame["step"] = frame["step"].astype("Int64")
    return frame
