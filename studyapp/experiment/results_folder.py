"""Where a study's results go: one absolute folder, whatever the working directory, and the order rows it used.

A relative results folder meant one folder per working directory: a launcher
started elsewhere began a new study, gave Latin-square rows again and could
enrol a participant twice (issue 31 item 6). So every command takes the
folder as an absolute path (``absolute``: ``~`` expanded, made absolute
against the working directory once, when given) and, when none is given, the
default does not depend on the working directory (``default_results``):

    $STUDYAPP_RESULTS                       when set (a lab's shared folder)
    $XDG_DATA_HOME/studyapp/results         else ($XDG_DATA_HOME defaults to ~/.local/share)

The console remembers the folder last used in the machine's settings
(gui/setup_panel.py), starting from the same default.

``used_rows`` lists the order rows (``session.json``'s ``order_row``) the
study's participants of one kind (real or simulated, as enrolment counts
them) already have, so ``plan`` and ``run`` can say which rows the study has
used before a new participant takes one.
"""

import os
from pathlib import Path

from studyapp.experiment.enrolment import first_sessions, is_simulated

ENVIRONMENT = "STUDYAPP_RESULTS"


def default_results():
    """The results folder when none is given (module docstring), absolute."""
    given = os.environ.get(ENVIRONMENT)
    if given:
        return absolute(given)
    data = os.environ.get("XDG_DATA_HOME") or os.path.join(os.path.expanduser("~"), ".local", "share")
    return absolute(os.path.join(data, "studyapp", "results"))


def absolute(folder):
    """``folder`` with ``~`` expanded, absolute (against the working directory now); the default for None."""
    if folder is None:
        return default_results()
    return Path(os.path.abspath(os.path.expanduser(str(folder))))


def used_rows(study_folder, simulated):
    """{order row: [participants]} of the participants of one kind (``simulated`` or real) under ``study_folder``."""
    rows = {}
    for name, info in first_sessions(study_folder):
        if info is None or is_simulated(info) != bool(simulated) or not isinstance(info.get("order_row"), int):
            continue
        rows.setdefault(info["order_row"], []).append(name)
    return dict(sorted(rows.items()))


def used_rows_text(study_folder, simulated):
    """One line: the order rows the study's participants of this kind already have, and by whom."""
    kind = "simulated" if simulated else "real"
    rows = used_rows(study_folder, simulated)
    if not rows:
        return f"order rows used by {kind} participants: none yet"
    listed = "; ".join(f"{row} ({', '.join(names)})" for row, names in rows.items())
    return f"order rows used by {kind} participants: {listed}"
