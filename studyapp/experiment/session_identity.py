"""One session is one session wherever it lies: a copied session folder is counted once.

A session folder copied (``cp -r P1/S P1/S2``, or a whole participant folder
``cp -r P1 P1copy``) holds the same session twice; exported as it was, every
response counted twice (issue 41, item 14). A session is named by what it
wrote when it began, not by where it lies: the first line of its
``events.jsonl``, the ``session_created`` record with the whole description
(study, participant, session id, start time to the millisecond, seed,
protocol), CRC-checked like every line (``log_scan.classify``). Two folders
whose logs begin with the same line hold one session: its ``session_key``
is the line's SHA-256.

Of the folders holding one session, ``counted_once`` keeps the one that went
furthest (most answered steps: a copy taken mid-session is behind the
original), then the one in its own place (``<study>/<participant>/<session>``
as its description names them), then the first by path; each other folder is
one line naming both. A folder without a readable first record (no log, a
damaged first line, a log of a version before ``session_created``) has no key
and is counted as it is.
"""

import hashlib
import os
import stat

from studyapp.experiment.log_scan import classify
from studyapp.experiment.records import SESSION_CREATED
from studyapp.experiment.session_description import DESCRIPTION_LIMIT
from studyapp.experiment.session_files import EVENTS_FILE

_CHUNK = 1 << 16


def _first_line(path):
    """The first line of the regular file ``path`` without its newline (None: no such file, not a regular
    file, or no newline within the description's limit)."""
    try:
        fd = os.open(path, os.O_RDONLY | os.O_NONBLOCK | os.O_CLOEXEC)
    except OSError:
        return None
    try:
        if not stat.S_ISREG(os.fstat(fd).st_mode):
            return None
        data = b""
        while b"\n" not in data and len(data) <= DESCRIPTION_LIMIT:
            chunk = os.read(fd, _CHUNK)
            if not chunk:
                break
            data += chunk
        return data.split(b"\n", 1)[0] if b"\n" in data else None
    except OSError:
        return None
    finally:
        os.close(fd)


def session_key(folder):
    """``(SHA-256 of the session_created line, its description)`` of the session in ``folder``, or None."""
    line = _first_line(os.path.join(folder, EVENTS_FILE))
    if line is None:
        return None
    event, why, _ = classify(line)
    if why is not None or event.get("type") != SESSION_CREATED or not isinstance(event.get("description"), dict):
        return None
    return hashlib.sha256(line).hexdigest(), event["description"]


def _at_home(folder, description):
    """True when ``folder`` is ``<study>/<participant>/<session>`` as the description names them."""
    names = (description.get("study"), description.get("participant"), description.get("session"))
    return (folder.parent.parent.name, folder.parent.name, folder.name) == names


def counted_once(found):
    """``(kept, copies)`` of ``found``: ``[(folder, rows)]``, each session once (module docstring).

    ``kept``: the ``(folder, rows)`` counted; ``copies``: one line per folder left out, naming both."""
    groups, order = {}, []
    for folder, rows in found:
        key = session_key(folder)
        if key is None:
            order.append([(folder, rows, None)])
            continue
        if key[0] not in groups:
            groups[key[0]] = []
            order.append(groups[key[0]])
        groups[key[0]].append((folder, rows, key[1]))
    kept, copies = [], []
    for group in order:
        if len(group) > 1:
            group = sorted(group, key=lambda item: (-len({row.get("step") for row in item[1]}),
                                                    not _at_home(item[0], item[2]), str(item[0])))
        folder, rows, description = group[0]
        kept.append((folder, rows))
        for other, other_rows, _ in group[1:]:
            copies.append(f"{other}: a copy of session {description.get('session')!r} of participant "
                          f"{description.get('participant')!r} in {folder} (the same {SESSION_CREATED} record): "
                          f"counted once, from {folder}")
    return kept, copies
