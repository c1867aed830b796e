"""Read a small text file a person gave us (a protocol, a parameter file) without trusting it.

Only a regular file is read (``/dev/zero`` or a FIFO would never end), and at
most ``LIMIT_BYTES`` of it: such files are a few kilobytes, so a larger one is
refused before it costs memory or parse time. TOML nested deeper than Python's
recursion limit is refused too (``tomllib`` would raise ``RecursionError``).
Every problem is one ``UserError`` naming the file.
"""

import os
import stat
import tomllib
from pathlib import Path

from studyapp.errors import UserError

LIMIT_BYTES = 1 << 20


def read_bytes(path, what):
    """The bytes of the regular file ``path`` (``what`` names it in messages, e.g. "protocol")."""
    path = Path(path)
    try:
        with open(path, "rb") as f:
            if not stat.S_ISREG(os.fstat(f.fileno()).st_mode):
                raise UserError(f"{path}: not a regular file: allowed is a {what} file")
            data = f.read(LIMIT_BYTES + 1)
    except FileNotFoundError:
        raise UserError(f"{path}: cannot read the {what}: no such file") from None
    except IsADirectoryError:
        raise UserError(f"{path}: is a folder: allowed is a {what} file") from None
    except OSError as exc:
        raise UserError(f"{path}: cannot read the {what} ({exc.strerror or exc})") from None
    if len(data) > LIMIT_BYTES:
        raise UserError(f"{path}: larger than {LIMIT_BYTES >> 20} MB: allowed is a {what} file up to that size")
    return data


def parse_toml(text, source):
    """``tomllib.loads(text)``, with every failure as one ``UserError`` naming ``source``."""
    try:
        return tomllib.loads(text)
    except tomllib.TOMLDecodeError as exc:
        raise UserError(f"{source}: invalid TOML ({exc})") from None
    except RecursionError:
        raise UserError(f"{source}: invalid TOML (nested too deeply)") from None


def read_toml(path, what):
    """(text, document) of the TOML file ``path``; UTF-8 only."""
    data = read_bytes(path, what)
    try:
        text = data.decode("utf-8")
    except UnicodeDecodeError:
        raise UserError(f"{path}: not UTF-8 text: allowed is a UTF-8 TOML {what} file") from None
    return text, parse_toml(text, path)
