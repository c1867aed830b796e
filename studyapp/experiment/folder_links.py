"""No file of a results folder is written through a link: the folders below the results folder are real folders.

``own_files.open_own`` refuses a *file* planted as a link (``.lock``,
``events.jsonl``). A *folder* planted as a link (``RESULTS/<study>`` or
``RESULTS/<study>/<participant>`` a symbolic link to somewhere else) would
carry every file of the session, its lock, log and audio, to wherever it
points (issue 41, item 13). So a start or resume checks each folder from just
below the results folder down to the session's, without following links
(``os.lstat``), before it creates or writes anything: a link, or anything that
is not a folder, is refused with one line naming it.

The results folder itself is the experimenter's choice (given with
``--results``, a lab's shared folder may well be a link) and is not checked.
"""

import os
import stat
from pathlib import Path

from studyapp.errors import UserError


def refuse_links(results, folder):
    """Raise ``UserError`` when a folder from just below ``results`` down to ``folder`` is a link or not a folder.

    Folders that do not exist yet pass: the app makes them itself (``data_modes.make_folders``)."""
    results, folder = Path(results), Path(folder)
    below = folder.relative_to(results).parts
    path = results
    for part in below:
        path = path / part
        try:
            info = os.lstat(path)
        except FileNotFoundError:
            return
        if stat.S_ISLNK(info.st_mode):
            raise UserError(f"{path}: a link to {os.readlink(path)}, not a folder this app made: "
                            "allowed is to remove the link (the app writes no file through a link)")
        if not stat.S_ISDIR(info.st_mode):
            raise UserError(f"{path}: not a folder: allowed is to remove it, or another results folder")
