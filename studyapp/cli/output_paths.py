"""Check an output path before a command does any work, so a bad one costs nothing and leaves nothing.

A check creates and removes one temporary file in the nearest existing folder
above the output: the only way to know a folder is writable (root passes
``os.access`` on a read-only mount). The writes themselves are atomic
(``studyapp.atomic``); an error later (a full disk) is reported by
``studyapp.cli.main`` in one line.
"""

import os
import tempfile
from pathlib import Path

from studyapp.errors import UserError


def _existing_parent(path, option):
    parent = path.parent
    while not parent.exists():
        if parent.is_symlink():
            raise UserError(f"{option} {path}: {parent} is a broken link")
        parent = parent.parent
    if not parent.is_dir():
        raise UserError(f"{option} {path}: cannot create a file in {parent}: it is a file, not a directory")
    _probe(parent, f"{option} {path}: cannot create a file in {parent}")


def check_file(path, option="-o", inputs=()):
    """Raise ``UserError`` unless ``path`` can become a file (it is not a folder nor one of ``inputs``)."""
    path = Path(path)
    if path.is_dir():
        raise UserError(f"{option} {path}: is a directory: allowed is a file name")
    if path.exists() and not path.is_file():
        raise UserError(f"{option} {path}: is not a regular file")
    for source in inputs:
        if path.exists() and Path(source).exists() and os.path.samefile(path, source):
            raise UserError(f"{option} {path}: is the input file: allowed is another file name")
    _existing_parent(path, option)


def check_folder(path, option="-o"):
    """Raise ``UserError`` unless ``path`` is a writable folder or can be created as one."""
    path = Path(path)
    if path.exists() and not path.is_dir():
        raise UserError(f"{option} {path}: exists and is not a directory")
    if path.is_dir():
        _probe(path, f"{option} {path}: cannot create a file in it")
        return
    _existing_parent(path, option)


def _probe(folder, refusal):
    """Create and delete a file in ``folder`` (as root, permissions alone do not tell); ``refusal`` if it fails."""
    try:
        fd, probe = tempfile.mkstemp(prefix=".studyapp-probe.", dir=folder)
    except OSError as exc:
        raise UserError(f"{refusal} ({exc.strerror or exc})") from None
    os.close(fd)
    os.unlink(probe)
