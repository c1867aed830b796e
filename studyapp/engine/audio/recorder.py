"""What the participant heard, kept with the data: a WAV file and its trial cues, written off the real-time thread.

The sink hands what it outputs (the signal chain's output, engine/signal_chain.py:
what goes to the headphones) to ``write``, which only copies it into a queue:
a file sink every block, a device sink every device period from its callback,
as played, so the file is sample-aligned with what reached the device. A
period the FIFO could not fill (an underrun: the engine was late) is played
with silence for the rest, and that silence is in the file too, its place
marked by an ``underrun`` row in the cues (as is a period the device itself
reported as an underflow). ``write`` also takes the period's place in the
sink's output *stream* (``start``: the FIFO's read position) and how many of
its frames came from it (``got``); the writer maps stream positions to file
frames with them. A writer thread of the worker process turns
the queue into a WAV file at the sink's rate (wav.py: 16-bit PCM mono). The file is written as it grows, its header made valid
after every write, so a worker that is killed leaves a readable file up to its
last write; a kill between a write and its header's update leaves a header
that counts fewer frames than the file holds, which the session's resume
repairs from the file's size and reports (io/wav_header.py). If the writer falls ``QUEUE_SECONDS`` behind (a stalled disk),
blocks are dropped rather than waiting, counted in ``dropped`` and written as
silence once the writer catches up, so the file's timeline stays the engine's.

Besides the steps' ``start`` and ``end`` the cues mark where the bow was put
on the string and lifted (``bow_on``, ``bow_off``: the output is silent from
a ``bow_off`` on, signal_chain.py) and every ``underrun``. Each row's
``limited`` is the number of the file's samples the output limiter bent
between the row before it (or the file's start) and this row: the samples
above the limiter's knee (signal_chain.KNEE; a bent sample is always above
it, an untouched one never), so a step's count is the sum of its rows after
its ``start`` up to its ``end``. A cue that arrives for audio written before
the last write (rare: cues name a position ahead) counts up to that write's start.

Files are never overwritten: ``audio.wav`` is taken only if no file of that name
exists, else ``audio-2.wav``, ``audio-3.wav``, ...: one file per engine run of a
session (a resumed session, a restarted engine). A file appears under its name
with its header already written (made without a name, then linked:
``free_names.name_unnamed``), so a kill never leaves an empty, unreadable WAV
file. ``audio_cues.csv`` is opened without following a link
(``own_files.open_own``): a link planted under its name is refused, never
written through, and the cues are then left out with a warning. The WAV file
and ``audio_cues.csv`` are created with the permissions ``mode`` (the session's
files' mode, 0600 or 0660: participant data), whatever the umask.

Cues. ``cue(..., at)`` notes a trial boundary at the stream position ``at``:
the worker calls it when it applies an ``AudioCue`` command, at a block
boundary, with the position at which the first sample of the block run after
it will be heard (``SignalChain.next_frame``: the chain's lookahead and the
resampler's timing included). The writer turns it into the file's frame once
the audio reaching that position has been written (a gap before it moves it
on), so ``sample`` is where the trial's first sample is in the file. The
controller sends the cue right after the trial's knob mapping; the two
usually arrive in the same block, at worst a block (2 ms) apart.
The writer appends it to ``audio_cues.csv`` beside the file (columns
``CUE_COLUMNS``), one row per cue, shared by every file of the session.
"""

import contextlib
import csv
import os
import queue
import threading
from pathlib import Path

import numpy as np

from studyapp.engine.audio.wav import open_wav, pcm16
from studyapp.engine.signal_chain import KNEE
from studyapp.io.free_names import claim, name_unnamed, unnamed
from studyapp.io.own_files import NotOurFile, open_own

QUEUE_SECONDS = 10.0  # of audio the writer may fall behind before blocks are dropped
CUES_FILE = "audio_cues.csv"
CUE_COLUMNS = ("file", "sample", "seconds", "step", "task", "trial", "event", "limited")


def _whole_wav(path, rate, mode):
    """(file, wave writer, name) of a new WAV file under the first free name of ``path``, its header written.

    The file is made without a name (``free_names.unnamed``) and named only once its header is
    on disk, so no kill leaves an empty, unreadable ``audio.wav``."""
    fd = unnamed(path.parent, mode)
    name = None
    if fd is None:  # a filesystem without O_TMPFILE: reserved by name, its header written at once
        fd, name = claim(path, mode)
    file = open(fd, "w+b")  # noqa: SIM115 - the writer thread closes it
    try:
        wav = open_wav(file, rate)
        wav.writeframes(b"")  # the header, for 0 frames
        file.flush()
        if name is None:
            name = name_unnamed(fd, path)
    except BaseException:
        file.close()
        raise
    return file, wav, Path(name)


class AudioRecorder:
    def __init__(self, path, rate, mode=0o600):
        self.rate = float(rate)
        self.mode = mode
        self._file, self._wav, self.path = _whole_wav(Path(path), self.rate, mode)
        self.cues_path = self.path.parent / CUES_FILE
        self.cues_refused = None  # why audio_cues.csv could not be written (a link planted there), or None
        self.capacity = int(QUEUE_SECONDS * self.rate)
        self.frames = 0  # frames of the file's timeline so far, dropped ones included
        self.stream = None  # the stream position after the last write (None: nothing written yet)
        self.dropped = 0  # frames the writer could not take in time (written as silence)
        self.gaps = 0  # device periods written with a gap (underruns)
        self.error = None  # what stopped the writer (a full disk), or None
        self._queued = 0  # frames handed to the queue (by the real-time thread) ...
        self._taken = 0  # ... and taken from it (by the writer)
        self._stopped = False  # the writer took the end of the queue
        self._queue = queue.SimpleQueue()
        self._pending = []  # the writer's cues waiting for the audio at their position
        self._where = None  # the writer's last (file frame, stream position) pair
        self._context = {"step": "", "task": "", "trial": ""}  # the last cue's trial, for underrun rows
        self._above = (0, 0, np.zeros(0, dtype=np.int64))  # the writer's (frame, count before it, running count)
        self._counted = 0  # samples above the knee up to the last row
        self._thread = threading.Thread(target=self._run, name="studyapp-audio-recorder", daemon=True)
        self._thread.start()

    # the real-time side: never waits ---------------------------------------------------
    def write(self, samples, start=None, got=None, underflow=False):
        """What was played: ``samples``, the first ``got`` (default: all) from stream position ``start``."""
        n = samples.shape[0]
        got = n if got is None else int(got)
        start = (self.stream or 0) if start is None else int(start)
        frame = self.frames
        self.frames += n
        self.stream = start + got
        if got < n or underflow:
            self.gaps += 1
        if self._queued - self._taken + n > self.capacity or self.error is not None:
            self.dropped += n
            return
        self._queue.put(("audio", frame, start, got, underflow, np.array(samples, dtype=np.float64)))
        self._queued += n

    def cue(self, step, task, trial, event, at=None):
        """A row of the cues at stream position ``at`` (default: where the next write starts).

        ``step`` None: the step, task and trial of the cue before it (``bow_on`` and ``bow_off`` rows).
        """
        at = (self.stream or 0) if at is None else int(at)
        self._queue.put(("cue", at, {"step": step, "task": task, "trial": trial, "event": event}))

    def sync(self, timeout=10.0):
        """Wait until the writer has written everything queued so far, every pending cue's row included
        (placed on the timeline as ``stop`` places them); False if it did not within ``timeout`` s.

        Not for the real-time thread: a headless session calls it before it logs a response, so a kill
        never leaves an answered step without its rows in ``audio_cues.csv`` (issue 41, item 15)."""
        reached = threading.Event()
        self._queue.put(("sync", reached))
        return reached.wait(timeout)

    def stop(self):
        """Let the writer finish what is queued (and a trailing gap) and close the file; ``join`` waits for it."""
        self._queue.put(("end", self.frames))
        self._queue.put(None)

    def join(self, timeout=None):
        self._thread.join(timeout)
        return not self._thread.is_alive()

    # the writer thread -----------------------------------------------------------------
    def _run(self):
        with contextlib.suppress(OSError, AttributeError):  # leave the worker's real-time priority
            os.sched_setscheduler(0, os.SCHED_OTHER, os.sched_param(0))
        try:
            with self._file, self._wav as wav:
                self._write_all(wav)
        except OSError as exc:
            self.error = f"{self.path}: {exc.strerror or exc}"
            self._discard()

    def _write_all(self, wav):
        written = 0  # frames in the file
        while True:
            items = [self._queue.get()]
            while True:  # take everything queued: one write, one header patch
                try:
                    items.append(self._queue.get_nowait())
                except queue.Empty:
                    break
            chunks, rows, done, synced = [], [], False, []
            for item in items:
                if item is None:
                    done = self._stopped = True
                elif item[0] == "sync":
                    rows += self._resolve(None)
                    synced.append(item[1])
                elif item[0] == "audio":
                    _, frame, start, got, underflow, samples = item
                    chunks.append(bytes(2 * (frame - written)) + pcm16(samples))  # dropped frames: silence
                    self._count_above(frame, samples)
                    written = frame + samples.shape[0]
                    self._taken += samples.shape[0]
                    self._where = (frame, start, start + got)
                    rows += self._resolve(start + got)
                    if got < samples.shape[0] or underflow:
                        at = frame + got if got < samples.shape[0] else frame
                        rows.append(self._row(at, {**self._context, "event": "underrun"}))
                elif item[0] == "cue":
                    self._pending.append(item[1:])
                    if self._where is not None:
                        rows += self._resolve(self._where[2])  # a cue for audio already written
                else:  # the end: a trailing gap, and every cue left at its place on the timeline
                    chunks.append(bytes(2 * max(item[1] - written, 0)))
                    written = max(item[1], written)
                    rows += self._resolve(None)
            if chunks:
                wav.writeframes(b"".join(chunks))
            for row in rows:
                self._append_cue(row)
            for reached in synced:
                reached.set()
            if done:
                return

    def _resolve(self, before):
        """Rows for the pending cues at stream positions below ``before`` (None: all of them)."""
        frame, start, _ = self._where or (0, 0, 0)
        ready = [c for c in self._pending if before is None or c[0] < before]
        self._pending = [c for c in self._pending if not (before is None or c[0] < before)]
        rows = []
        for at, fields in sorted(ready, key=lambda c: c[0]):
            if fields["step"] is None:
                fields = {**fields, **self._context}
            self._context = {k: fields[k] for k in ("step", "task", "trial")}
            rows.append(self._row(max(frame + at - start, 0), fields))
        return rows

    def _count_above(self, frame, samples):
        """Note the samples above the knee in the write at ``frame`` (its running count, for the rows within it)."""
        start, before, running = self._above
        total = before + (int(running[-1]) if running.size else 0)
        self._above = (frame, total, np.cumsum(np.abs(samples) > KNEE))

    def _above_before(self, sample):
        """Samples above the knee in the file before frame ``sample`` (as far as the writes so far tell)."""
        start, before, running = self._above
        k = min(max(sample - start, 0), running.size)
        return before + (int(running[k - 1]) if k else 0)

    def _row(self, sample, fields):
        upto = self._above_before(sample)
        limited, self._counted = max(upto - self._counted, 0), max(upto, self._counted)
        return {"file": self.path.name, "sample": sample, "seconds": f"{sample / self.rate:.6f}", **fields,
                "limited": limited}

    def _append_cue(self, row):
        if self.cues_refused is not None:
            return
        try:
            fd, created = open_own(self.cues_path, os.O_WRONLY | os.O_APPEND, self.mode)  # never through a link
        except OSError as exc:
            self.cues_refused = f"{exc}" if isinstance(exc, NotOurFile) else f"{self.cues_path}: {exc.strerror or exc}"
            return
        with open(fd, "a", newline="", encoding="utf-8") as f:
            writer = csv.DictWriter(f, fieldnames=CUE_COLUMNS)
            if created or os.fstat(fd).st_size == 0:
                writer.writeheader()
            writer.writerow(row)

    def _discard(self):
        """After a write error: keep taking the queue so the real-time side never fills it."""
        while not self._stopped and (item := self._queue.get()) is not None:
            if item[0] == "audio":
                self._taken += item[-1].shape[0]
            elif item[0] == "sync":
                item[1].set()  # nothing more will be written: no one waits for it


class Recordings:
    """A worker's recordings of what is heard: the one in progress, fed by ``sink``, and every one of the run.

    ``notice(text, level, topic)`` tells the parent what happened to them.
    """

    def __init__(self, sink, notice):
        self.sink = sink
        self.notice = notice
        self.current = None  # the recording in progress (RecordAudio), or None
        self.made = []  # every recorder of this run: closed, with what it wrote, in close()

    def record(self, path, mode):
        """Stop the recording in progress (its writer finishes on its own), then start one at ``path`` (None: none)."""
        if self.current is not None:
            self.current.stop()
            self.sink.recorder = self.current = None
        if path is None:
            return
        if not self.sink.render:
            self.notice(f"audio: the {self.sink.description} sink renders no audio: nothing to record", "warning", "audio")
            return
        self.current = self.sink.recorder = AudioRecorder(path, self.sink.rate, mode)
        self.made.append(self.current)
        self.notice(f"audio: recording what is heard to {self.current.path}", "info", "audio")

    def cue(self, step, task, trial, event):
        """A row of the cues, at the block the worker runs next (``None`` step: the last cue's trial)."""
        if self.current is not None:
            self.current.cue(step, task, trial, event, at=self.sink.next_frame())

    def close(self, timeout=5.0):
        """Let every recording's writer finish; say what one could not write."""
        if self.current is not None:
            self.current.stop()
            self.sink.recorder = self.current = None  # the sink's flush on close is not the session's
        for recorder in self.made:
            if not recorder.join(timeout):
                self.notice(f"audio: {recorder.path}: the writer did not finish within {timeout:g} s", "warning", "audio")
            if recorder.error:
                self.notice(f"audio: recording stopped: {recorder.error}", "warning", "audio")
            if recorder.cues_refused:
                self.notice(f"audio: no cues written: {recorder.cues_refused}", "warning", "audio")
            if recorder.dropped:
                self.notice(f"audio: {recorder.path}: {recorder.dropped} frames dropped (the disk fell behind), "
                            "written as silence", "warning", "audio")

    def summary(self):
        return [{"file": str(r.path), "frames": r.frames, "dropped": r.dropped, "error": r.error} for r in self.made]
