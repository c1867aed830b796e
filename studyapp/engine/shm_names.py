"""Names of the engine's shared memory and semaphores, so that a start can remove what a killed run left.

The engine's status block, telemetry ring and event ring are POSIX shared
memory (``/dev/shm/<name>``), and its command queue holds three named POSIX
semaphores (``/dev/shm/sem.<name>``). Python's resource tracker removes them
when the program ends, unless the tracker is killed too (a kill of the whole
process group): then 3 segments (3.3 MB) and 3 semaphores stayed in /dev/shm
for good (issue 33, item 5). So every one of them is named
``studyapp-<pid>-<kind>-<random>``, ``<pid>`` the process that made it, and
``remove_stale`` (called by every engine start) unlinks those whose maker is
no longer alive. A live maker's are never touched (a reused PID only keeps a
stale name until that process ends).
"""

import contextlib
import multiprocessing
import os
import re
import secrets

FOLDER = "/dev/shm"
PREFIX = "studyapp"
_STALE = re.compile(rf"^(?:sem\.)?{PREFIX}-(\d+)-")


def new_name(kind):
    """A fresh shared-memory name for a segment of ``kind`` (e.g. "status"), made by this process."""
    return f"{PREFIX}-{os.getpid()}-{kind}-{secrets.token_hex(4)}"


def name_semaphores():
    """Make multiprocessing name this process's semaphores ``studyapp-<pid>-...`` (a queue holds three).

    multiprocessing has no public hook for it: its ``semprefix`` is the one (``/mp`` otherwise)."""
    config = getattr(multiprocessing.current_process(), "_config", None)
    if isinstance(config, dict):
        config["semprefix"] = f"/{PREFIX}-{os.getpid()}"


def _alive(pid):
    try:
        os.kill(pid, 0)
    except ProcessLookupError:
        return False
    except PermissionError:
        return True  # another user's process
    return True


def remove_stale(folder=FOLDER):
    """Unlink the segments and semaphores of this app whose maker is dead; return their names."""
    try:
        names = os.listdir(folder)
    except OSError:
        return []
    removed = []
    for name in names:
        match = _STALE.match(name)
        if match is None or _alive(int(match.group(1))):
            continue
        with contextlib.suppress(OSError):
            os.unlink(os.path.join(folder, name))
            removed.append(name)
    return removed
