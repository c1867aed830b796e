"""Check an output path before a command does any work, so a bad one costs nothing and leaves nothing.

A check creates and removes one temporary file in the nearest existing folder
above the output: the only way to know a folder is writable (root passes
``os.access`` on a read-only mount). The writes themselves are atomic
(``studyapp.io.atomic``); an error later (a full disk) is reported by
``studyapp.cli.main`` in one line.

Participant data is never an output. No command writes into a session folder
(one holding ``events.jsonl``, or the ``session.json`` of a session): its
``events.jsonl``, ``session.json``, ``audio*.wav`` and ``audio_cues.csv`` are
what the participant did, and ``--resume`` and ``export`` read them. Nor over a
session lock (``.lock``: replacing it would let a second program in beside the
holder), nor over one of the command's own inputs: an output file is none of
them, and an output folder is not an input folder and holds no input file (the
command's fixed file names could fall on one).

Every spelling of a path is checked: empty, a NUL, a trailing ``/`` (``Path``
would drop it: ``-o x.csv/``), a FIFO, device or socket (never opened:
``special_files``), a link, and ``..`` after a link (checked as spelled and as
the file system follows it). An ``--audio wav:FILE`` is an output too
(``check_audio``): a ``.wav`` name outside every session folder.
"""

import os
import tempfile
from pathlib import Path

from studyapp.errors import UserError
from studyapp.io.special_files import refuse_special
from studyapp.experiment.session_files import EVENTS_FILE, LOCK_FILE, SESSION_FILE, is_session_folder


def _existing_parent(path, option):
    parent = path.parent
    while not parent.exists():
        if parent.is_symlink():
            raise UserError(f"{_named(option, path)}: {parent} is a broken link")
        parent = parent.parent
    if not parent.is_dir():
        raise UserError(f"{_named(option, path)}: cannot create a file in {parent}: it is a file, not a directory")
    _probe(parent, f"{_named(option, path)}: cannot create a file in {parent}")


def _refuse_session_data(path, folder, option):
    """``path`` is an output written in ``folder``: refused when that, or the nearest folder that exists
    above it (where the missing ones would be made), or any folder above that, is a session folder.

    Both as spelled and as the file system finds it: ``os.path.abspath`` drops ``link/..`` by its
    letters, while the system follows the link first (``realpath``), so ``link/../SESSION`` lands in
    the session whichever way it is read."""
    places = []
    for start in dict.fromkeys([Path(os.path.abspath(folder)), Path(os.path.realpath(folder))]):
        while not start.exists() and start != start.parent:
            start = start.parent
        places += [start, *start.parents, start.resolve(), *start.resolve().parents]
    for place in dict.fromkeys(places):
        if is_session_folder(place):
            raise UserError(f"{_named(option, path)}: inside the session folder {place}, whose {EVENTS_FILE}, "
                            f"{SESSION_FILE} and audio files are participant data: allowed is a path outside "
                            "every session folder")


def _same(a, b):
    """One file (or folder) by either name: the same path, or the same inode (a link)."""
    if os.path.abspath(a) == os.path.abspath(b):
        return True
    try:
        return os.path.samefile(a, b)
    except OSError:
        return False


def _named(option, path):
    """How a message names the path given to ``option``: ``-o x.csv``, ``--audio wav:x.wav``."""
    return f"{option}{path}" if option.endswith(":") else f"{option} {path}"


def _spelled(path, option, allowed):
    """Refuse a path that names nothing writable by its spelling alone: empty (``Path("")`` is the working
    folder), holding a NUL, or, for a file, ending in ``/`` (which ``Path`` would drop)."""
    text = os.fspath(path)
    if not text.strip():
        raise UserError(f"{_named(option, repr(text))}: empty: allowed is {allowed}")
    if "\0" in text:
        raise UserError(f"{_named(option, repr(text))}: holds a NUL character: allowed is {allowed}")
    if allowed == "a file name" and (text.endswith(("/", "/.", "/..")) or text in (".", "..")):
        raise UserError(f"{_named(option, text)}: ends in '/' or '.', so names a folder: allowed is a file name")
    return Path(text)


def check_file(path, option="-o", inputs=()):
    """Raise ``UserError`` unless ``path`` can become a file (not a folder, participant data nor one of ``inputs``)."""
    path = _spelled(path, option, "a file name")
    refuse_special(path, "a file name (not a FIFO, device or socket)", f"{_named(option, path)}")
    if path.is_dir():
        raise UserError(f"{_named(option, path)}: is a directory: allowed is a file name")
    if path.exists() and not path.is_file():
        raise UserError(f"{_named(option, path)}: is not a regular file")
    for source in inputs:
        if _same(path, source):
            raise UserError(f"{_named(option, path)}: is {source}, which this command reads or writes: "
                            "allowed is another file name")
    _refuse_session_data(path, path.parent, option)
    if path.name == LOCK_FILE and path.exists():
        raise UserError(f"{_named(option, path)}: is a session lock: allowed is another file name")
    if path.is_symlink():  # the atomic write replaces the link itself, but say no to aiming at participant data
        _refuse_session_data(path, path.resolve().parent, option)
    _existing_parent(path, option)


def check_folder(path, option="-o", inputs=()):
    """Raise ``UserError`` unless ``path`` is a writable folder or can be created as one, holding none of ``inputs``."""
    path = _spelled(path, option, "a folder")
    if path.exists() and not path.is_dir():
        raise UserError(f"{_named(option, path)}: exists and is not a directory")
    _refuse_session_data(path, path, option)
    if path.is_dir():
        for source in inputs:
            source = Path(source)
            if _same(path, source) or (not source.is_dir() and _same(path, source.parent)):
                what = "is the input folder" if _same(path, source) else f"holds the input {source}"
                raise UserError(f"{_named(option, path)}: {what}: allowed is a folder of its own for the outputs")
        _probe(path, f"{_named(option, path)}: cannot create a file in it")
        return
    _existing_parent(path, option)


def check_audio(spec, option="--audio", inputs=()):
    """Raise ``UserError`` unless an ``--audio`` spec's ``wav:FILE`` (if it is one) is a ``.wav`` file that
    ``check_file`` allows. The sink never writes over a file (it takes FILE-2, FILE-3, ...: engine/audio/sinks.py),
    so what is checked is the folder it writes in: no session folder, and no name that is a folder, a FIFO,
    participant data or an input (beside which the numbered name would fall)."""
    text = (spec or "").strip()
    if not text.startswith("wav:"):
        return
    path = text[4:]
    if not path.lower().endswith(".wav"):
        raise UserError(f"{_named(option, text)}: allowed is wav:FILE with a file name ending in .wav")
    check_file(path, f"{option} wav:", inputs)


def _probe(folder, refusal):
    """Create and delete a file in ``folder`` (as root, permissions alone do not tell); ``refusal`` if it fails."""
    try:
        fd, probe = tempfile.mkstemp(prefix=".studyapp-probe.", dir=folder)
    except OSError as exc:
        raise UserError(f"{refusal} ({exc.strerror or exc})") from None
    os.close(fd)
    os.unlink(probe)
