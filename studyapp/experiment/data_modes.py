"""Who may read participant data: the permissions of the results folders and files.

Participant data stays private to the experimenter's account by default:
every folder the app creates under the results folder (the results folder
itself when it has to create it, the study, participant and session folders)
gets mode 0700 and every file in them (``session.json``, ``events.jsonl``,
the lock, the set-aside copies, and ``audio*.wav`` and ``audio_cues.csv``,
which the session controller asks the engine to create with ``file_mode()``)
mode 0600, whatever the umask.

On a lab machine where the experimenters share a Unix group, set the
environment variable ``STUDYAPP_GROUP_SHARED=1``: folders then get 0770 and
files 0660 (read and write for the owner and the group, nothing for others).
The group is the folder's group as the operating system assigns it; make the
results folder belong to the lab's group (``chgrp lab results; chmod 2770
results``) so that everything created below it does too.

Folders that exist already (a results folder made by hand) keep their modes.
"""

import os
from pathlib import Path

from studyapp.io.own_files import NotOurFile, open_own  # noqa: F401 - NotOurFile: the error open_file raises

SHARED_VARIABLE = "STUDYAPP_GROUP_SHARED"
PRIVATE = (0o700, 0o600)
GROUP_SHARED = (0o770, 0o660)


def group_shared():
    """True when ``STUDYAPP_GROUP_SHARED`` asks for group-shared data (1, true, yes, on)."""
    return os.environ.get(SHARED_VARIABLE, "").strip().lower() in ("1", "true", "yes", "on")


def folder_mode():
    return (GROUP_SHARED if group_shared() else PRIVATE)[0]


def file_mode():
    return (GROUP_SHARED if group_shared() else PRIVATE)[1]


def make_folders(path):
    """Create ``path`` and its missing parents, each new one with ``folder_mode()``; return the new ones."""
    path = Path(path)
    missing = []
    while not path.exists():
        missing.append(path)
        path = path.parent
    mode = folder_mode()
    made = []
    for folder in reversed(missing):
        try:
            folder.mkdir(mode=mode)
        except FileExistsError:
            continue  # made by a concurrent start meanwhile; its modes are its maker's
        # mkdir's mode passes through the umask; the setting must not
        os.chmod(folder, mode)
        made.append(folder)
    return made


def open_file(path, flags):
    """``os.open`` of ``path``, never through a link (``own_files.open_own``: ``NotOurFile`` for a link, FIFO
    or device); a file it creates gets ``file_mode()`` (not masked by the umask)."""
    return open_own(path, flags, file_mode())[0]
