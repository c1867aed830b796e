"""WAV files of what is heard: one format, and never a file written over an earlier one.

Every WAV file the app writes (a ``wav:FILE`` sink, the session's recording of
what the participant heard) is 16-bit PCM mono at the sink's rate: the stdlib
``wave`` module writes integer PCM only, and 16 bits keep 96 dB, more than
headphones in a quiet room show. A sample x in [-1, 1] is stored as
round(32767 x), clipped to that range first.

A file is never written over another: its name is the first free one of
``take.wav``, ``take-2.wav``, ``take-3.wav``, ... (studyapp/free_names.py),
reserved by an exclusive create, so two writers of the same name at once both
keep their take.
"""

import wave

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
