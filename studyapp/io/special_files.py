"""FIFOs, devices and sockets: told apart from files by their status, before anything opens them.

Opening a FIFO for reading waits for a writer, and for writing waits for a
reader; a device such as ``/dev/zero`` never ends. So every path a person
names, as an input or an output, is checked here by ``os.stat`` (which
follows links and opens nothing) before it is opened, and refused with one
line naming it (``NotARegularFile``, a ``UserError``). A reader that then
opens the path still opens it with ``O_NONBLOCK`` and checks the open
descriptor (``small_files.open_regular``): the path could change between the
two.
"""

import os
import stat

from studyapp.errors import UserError


class NotARegularFile(UserError, OSError):
    """The path names a FIFO, a device, a socket: never read (an ``OSError`` too, for callers that skip those)."""


def kind(mode):
    """What a non-regular, non-folder ``st_mode`` is ("a FIFO", "a device", "a socket"), or None."""
    if stat.S_ISFIFO(mode):
        return "a FIFO"
    if stat.S_ISCHR(mode) or stat.S_ISBLK(mode):
        return "a device"
    if stat.S_ISSOCK(mode):
        return "a socket"
    return None


def special_kind(path):
    """``kind`` of what ``path`` names (links followed), or None (a file, a folder, or nothing there)."""
    try:
        return kind(os.stat(path).st_mode)
    except (OSError, ValueError):  # missing, a broken link, a name the system refuses: not special
        return None


def refuse_special(path, allowed, name=None):
    """``NotARegularFile`` when ``path`` is a FIFO, device or socket; ``name`` (default the path) names it."""
    found = special_kind(path)
    if found is not None:
        raise NotARegularFile(f"{name or path}: not a regular file ({found}): allowed is {allowed}")
