"""WAV files of what is heard: one format, and never a file written over an earlier one.

Every WAV file the app writes (a ``wav:FILE`` sink, the session's recording of
what the participant heard) is 16-bit PCM mono at the sink's rate: the stdlib
``wave`` module writes integer PCM only, and 16 bits keep 96 dB, more than
headphones in a quiet room show. A sample x in [-1, 1] is stored as
round(32767 x), clipped to that range first.

A file is never written over another: its name is the first free one of
``take.wav``, ``take-2.wav``, ``take-3.wav``, ... (``numbered_names``),
reserved by an exclusive create (``claim``), so two writers of the same name at
once both keep their take.
"""

import itertools
import os
import wave
from pathlib import Path

import numpy as np


def pcm16(samples):
    """The bytes of 16-bit little-endian PCM for ``samples`` in [-1, 1]."""
    return np.round(np.clip(samples, -1.0, 1.0) * 32767.0).astype("<i2").tobytes()


def open_wav(file, rate):
    """A ``wave`` writer of 16-bit mono PCM at ``rate`` (Hz) on ``file`` (a path or a binary file object)."""
    wav = wave.open(file, "wb")
    wav.setnchannels(1)
    wav.setsampwidth(2)
    wav.setframerate(int(round(rate)))
    return wav


def numbered(path, number):
    """``take.wav`` for 1, ``take-2.wav`` for 2, ..."""
    path = Path(path)
    return path if number == 1 else path.with_name(f"{path.stem}-{number}{path.suffix}")


def numbered_names(path):
    """``path``, then ``path-2``, ``path-3``, ...: the names a file that never overwrites takes, in order."""
    return (numbered(path, number) for number in itertools.count(1))


def create(path, mode):
    """An fd of the new file ``path`` (``FileExistsError`` if it exists) with permissions ``mode``, not the umask's."""
    fd = os.open(path, os.O_WRONLY | os.O_CREAT | os.O_EXCL, mode)
    os.fchmod(fd, mode)
    return fd


def claim(path, mode=0o600):
    """``(fd, name)``: the first free numbered name of ``path``, created exclusively with permissions ``mode``."""
    for name in numbered_names(path):
        try:
            return create(name, mode), name
        except FileExistsError:
            continue
