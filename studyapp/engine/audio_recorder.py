"""What the participant heard, kept with the data: a WAV file and its trial cues, written off the real-time thread.

The sink hands every block it outputs (after the volume, the mute and the
reference tone: what goes to the headphones, engine/audio.py) to ``write``,
which only copies it into a queue; a writer thread of the worker process turns
the queue into a 16-bit PCM mono WAV at the sink's rate (the stdlib ``wave``
module writes integer PCM only; 16 bits keep 96 dB, more than headphones in a
quiet room show). The file is written as it grows, its header made valid
after every write, so a worker that is killed leaves a readable file up to its
last write. If the writer falls ``QUEUE_SECONDS`` behind (a stalled disk),
blocks are dropped rather than waiting, counted in ``dropped`` and written as
silence once the writer catches up, so the file's timeline stays the engine's.

Files are never overwritten (``free_path``): ``audio.wav`` is reserved with an
exclusive create, else ``audio-2.wav``, ``audio-3.wav``, ...: one file per
engine run of a session (a resumed session, a restarted engine). The WAV file
and ``audio_cues.csv`` are created with the permissions ``mode`` (the session's
files' mode, 0600 or 0660: participant data), whatever the umask.

Cues. ``cue(...)`` notes a trial boundary at the recording's current frame: the
worker calls it when it applies an ``AudioCue`` command, at a block boundary,
so ``sample`` is the file's frame of the first sample of the block run after it.
The controller sends the cue right after the trial's knob mapping; the two
usually arrive in the same block, at worst a block (2 ms) apart. The sound
itself lags by the resampler's short filter delay.
The writer appends it to ``audio_cues.csv`` beside the file (columns
``CUE_COLUMNS``), one row per cue, shared by every file of the session.
"""

import contextlib
import csv
import os
import queue
import threading
import wave
from pathlib import Path

import numpy as np

QUEUE_SECONDS = 10.0  # of audio the writer may fall behind before blocks are dropped
CUES_FILE = "audio_cues.csv"
CUE_COLUMNS = ("file", "sample", "seconds", "step", "task", "trial", "event")


def numbered(path, number):
    """``take.wav`` for 1, ``take-2.wav`` for 2, ..."""
    path = Path(path)
    return path if number == 1 else path.with_name(f"{path.stem}-{number}{path.suffix}")


def create(path, mode):
    """An fd of the new file ``path`` (``FileExistsError`` if it exists) with permissions ``mode``, not the umask's."""
    fd = os.open(path, os.O_WRONLY | os.O_CREAT | os.O_EXCL, mode)
    os.fchmod(fd, mode)
    return fd


def free_path(path, mode=0o600):
    """``(file object, path)``: ``path`` or the first free numbered name, created exclusively (never overwriting)."""
    number = 1
    while True:
        candidate = numbered(path, number)
        try:
            return open(create(candidate, mode), "wb"), candidate  # noqa: SIM115 - the writer thread closes it
        except FileExistsError:
            number += 1


def pcm16(samples):
    return np.round(np.clip(samples, -1.0, 1.0) * 32767.0).astype("<i2").tobytes()


class AudioRecorder:
    def __init__(self, path, rate, mode=0o600):
        self.rate = float(rate)
        self.mode = mode
        self._file, self.path = free_path(path, mode)
        self.cues_path = self.path.parent / CUES_FILE
        self.capacity = int(QUEUE_SECONDS * self.rate)
        self.frames = 0  # frames of the file's timeline so far, dropped ones included
        self.dropped = 0  # frames the writer could not take in time (written as silence)
        self.error = None  # what stopped the writer (a full disk), or None
        self._queued = 0  # frames handed to the queue (by the real-time thread) ...
        self._taken = 0  # ... and taken from it (by the writer)
        self._gap = 0  # frames dropped since the last block that got through
        self._stopped = False  # the writer took the end of the queue
        self._queue = queue.SimpleQueue()
        self._thread = threading.Thread(target=self._run, name="studyapp-audio-recorder", daemon=True)
        self._thread.start()

    # the real-time side: never waits ---------------------------------------------------
    def write(self, samples):
        n = samples.shape[0]
        self.frames += n
        if self._queued - self._taken + n > self.capacity or self.error is not None:
            self.dropped += n
            self._gap += n
            return
        self._queue.put(("audio", self._gap, np.array(samples, dtype=np.float64)))
        self._queued += n
        self._gap = 0

    def cue(self, step, task, trial, event):
        self._queue.put(("cue", {"file": self.path.name, "sample": self.frames,
                                 "seconds": f"{self.frames / self.rate:.6f}", "step": step, "task": task,
                                 "trial": trial, "event": event}))

    def stop(self):
        """Let the writer finish what is queued (and a trailing gap) and close the file; ``join`` waits for it."""
        self._queue.put(("audio", self._gap, np.zeros(0)))
        self._gap = 0
        self._queue.put(None)

    def join(self, timeout=None):
        self._thread.join(timeout)
        return not self._thread.is_alive()

    # the writer thread -----------------------------------------------------------------
    def _run(self):
        with contextlib.suppress(OSError, AttributeError):  # leave the worker's real-time priority
            os.sched_setscheduler(0, os.SCHED_OTHER, os.sched_param(0))
        try:
            with self._file, wave.open(self._file, "wb") as wav:
                wav.setnchannels(1)
                wav.setsampwidth(2)
                wav.setframerate(int(round(self.rate)))
                self._write_all(wav)
        except OSError as exc:
            self.error = f"{self.path}: {exc.strerror or exc}"
            self._discard()

    def _write_all(self, wav):
        while True:
            items = [self._queue.get()]
            while True:  # take everything queued: one write, one header patch
                try:
                    items.append(self._queue.get_nowait())
                except queue.Empty:
                    break
            chunks, done = [], False
            for item in items:
                if item is None:
                    done = self._stopped = True
                elif item[0] == "audio":
                    _, gap, samples = item
                    chunks.append(bytes(2 * gap) + pcm16(samples))
                    self._taken += samples.shape[0]
                else:
                    if chunks:
                        wav.writeframes(b"".join(chunks))
                        chunks = []
                    self._append_cue(item[1])
            if chunks:
                wav.writeframes(b"".join(chunks))
            if done:
                return

    def _append_cue(self, row):
        new = not self.cues_path.exists() or self.cues_path.stat().st_size == 0
        with contextlib.suppress(FileExistsError):
            os.close(create(self.cues_path, self.mode))
        with open(self.cues_path, "a", newline="", encoding="utf-8") as f:
            writer = csv.DictWriter(f, fieldnames=CUE_COLUMNS)
            if new:
                writer.writeheader()
            writer.writerow(row)

    def _discard(self):
        """After a write error: keep taking the queue so the real-time side never fills it."""
        while not self._stopped and (item := self._queue.get()) is not None:
            if item[0] == "audio":
                self._taken += item[2].shape[0]
