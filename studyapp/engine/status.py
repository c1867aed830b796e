"""The engine's shared status block: one writer (the worker), any reader, never torn.

A sequence lock: the writer makes the sequence number odd, writes every field,
then makes it even again; a reader copies the fields between two reads of the
sequence number and keeps the copy only when both reads are equal and even.
(x86-64 keeps stores and loads in program order; see ring.py.)

A reader never waits on the writer for long and never fails: when the writer
stays mid-record (preempted between its two increments on a loaded machine,
or stopped there), the reader gives back the last record it read whole. Its
heartbeat then only ages, which is what a stalled writer's heartbeat should
do. Why it must not fail: the force guard reads at real-time priority, one
step above the worker, so on the worker's core its ``sched_yield`` never lets
the writer finish; a reader that raised after 1,000 yields killed the guard
under load, and the worker, finding the guard silent, cut its own force and
latched a fault (CI of 2026-11-25: "writer never finished a record").

Beside the locked record sit words the parent writes and the worker reads:
``force_enable``, and why it was last cleared (``force_off_reason``, one of
``FORCE_OFF_REASONS``, and for the watchdog ``force_off_silence``, the seconds
the worker had not answered, and ``force_off_time``, when). The force guard
(engine/guard.py) clears it when the worker stops answering, so a worker that
is merely slow, not dead, zeroes its force at its next block; the
experimenter's emergency stop clears it too, and so does the worker itself when
the guard's own heartbeat (``guard_heartbeat``) grows older than its deadline.
The reason is written before the word is cleared, so the worker's fault text
says which (``safety.force_off_text``) instead of blaming the watchdog for an
operator's stop. Each word is one aligned float64: read and written whole.
"""

import time
from multiprocessing import shared_memory

import numpy as np

from studyapp.engine.shm_names import new_name

NUMBERS = (
    "heartbeat",  # time.monotonic() at the end of the last block
    "state",  # one of STATES
    "rate",  # nominal haptic rate, Hz
    "block",  # samples per block
    "blocks",  # blocks run
    "samples",  # haptic samples run
    "achieved_rate",  # samples per second of wall time over the last second
    "load",  # compute time of the last block / block period
    "load_mean",  # mean of load over the last second
    "load_max",  # largest load over the last second
    "deadline_misses",  # blocks finished after their deadline on the pacing clock
    "audio_underruns",  # device periods the engine did not fill in time (silence played)
    "audio_xruns",  # xruns the audio device itself reported
    "audio_limited",  # output samples the limiter bent (above its knee: signal_chain.py)
    "faults",  # faults raised so far (latched or not)
    "fault_latched",  # 1 while a latched fault holds the force at zero
    "fmax",  # F_max in force now, N
    "force_scale",  # safety ramp gain, 0..1
    "command_latency",  # last command: send -> first block run with it, s
    "command_latency_max",  # largest of those, s
    "midi_messages",  # MIDI messages received
    "audio_paced",  # 1 when the audio clock paces the loop, 0 for the monotonic timer
    "device_frames",  # a link device's sensor frames received (engine/device_link.py; 0 without one)
    "device_late",  # force frames it answered too late for their sample
    "device_missing",  # device samples never received
    "device_lost",  # device frames lost (sequence gaps)
    "device_corrupt",  # device frames that did not check (never applied)
)

TEXTS = {"source": 32, "fault": 200, "audio": 120, "midi": 120}

_HEARTBEAT, _STATE = NUMBERS.index("heartbeat"), NUMBERS.index("state")

STATES = ("starting", "running", "stopping", "stopped", "failed")
# "parent": cleared without a reason given; "guard": the worker found the force guard silent; "operator" and
# "participant": the emergency stop, by the experimenter's controls or by Esc on the participant's window;
# "owner": the guard found the engine's owning process stopped or gone
FORCE_OFF_REASONS = ("parent", "operator", "watchdog", "guard", "participant", "owner")

_SEQ = 8
SPINS = 100  # yields before a reader of the whole record starts sleeping
WAITS = 20  # sleeps of WAIT s after those, before it gives back its last whole record
WAIT = 0.0005
_ENABLE = 5 * 8  # force_enable, force_off_reason, force_off_silence, force_off_time, guard_heartbeat


class StatusBlock:
    """The record in shared memory. ``create()`` in the parent, ``attach(name)`` in the worker."""

    def __init__(self, shm, owner):
        self._shm = shm
        self._owner = owner
        buf = shm.buf
        self._seq = np.ndarray((1,), dtype=np.int64, buffer=buf)
        self._enable = np.ndarray((5,), dtype=np.float64, buffer=buf, offset=_SEQ)
        offset = _SEQ + _ENABLE
        self._numbers = np.ndarray((len(NUMBERS),), dtype=np.float64, buffer=buf, offset=offset)
        offset += 8 * len(NUMBERS)
        self._texts = np.ndarray((sum(TEXTS.values()),), dtype=np.uint8, buffer=buf, offset=offset)
        self._slices = {}
        start = 0
        for key, size in TEXTS.items():
            self._slices[key] = slice(start, start + size)
            start += size
        self.values = np.zeros(len(NUMBERS))
        self.texts = {key: "" for key in TEXTS}
        self._index = {key: i for i, key in enumerate(NUMBERS)}
        self._last = None  # the last record read whole (reader side)
        self._last_beat = ("starting", 0.0)

    @classmethod
    def size(cls):
        return _SEQ + _ENABLE + 8 * len(NUMBERS) + sum(TEXTS.values())

    @classmethod
    def create(cls):
        shm = shared_memory.SharedMemory(name=new_name("status"), create=True, size=cls.size())
        block = cls(shm, owner=True)
        block._seq[0] = 0
        block._enable[:] = (1.0, 0.0, 0.0, 0.0, 0.0)
        block._numbers[:] = 0.0
        block._texts[:] = 0
        return block

    @classmethod
    def attach(cls, name):
        return cls(shared_memory.SharedMemory(name=name), owner=False)

    @property
    def name(self):
        return self._shm.name

    # writer side ---------------------------------------------------------
    def set(self, **fields):
        """Stage fields (numbers or texts) for the next ``publish``."""
        for key, value in fields.items():
            if key in self.texts:
                self.texts[key] = str(value)
            elif key == "state":
                self.values[self._index[key]] = STATES.index(value)
            else:
                self.values[self._index[key]] = value

    def get(self, key):
        """A staged number (writer side)."""
        return self.values[self._index[key]]

    def publish(self, texts=False):
        """Copy the staged record into shared memory; ``texts=True`` copies the texts too."""
        self._seq[0] += 1
        self._numbers[:] = self.values
        if texts:
            for key, sl in self._slices.items():
                raw = self.texts[key].encode("utf-8", "replace")[: sl.stop - sl.start]
                field = self._texts[sl]
                field[:] = 0
                field[: len(raw)] = np.frombuffer(raw, dtype=np.uint8)
        self._seq[0] += 1

    # reader side ---------------------------------------------------------
    def read(self):
        """A consistent snapshot: a dict of every number and text (``state`` as its name).

        While the writer stays mid-record longer than the reader waits (``SPINS``
        yields, then ``WAITS`` sleeps of ``WAIT``), the last whole snapshot.
        """
        for attempt in range(SPINS + WAITS):
            before = int(self._seq[0])
            if before % 2 == 0:
                numbers = self._numbers.copy()
                texts = self._texts.copy()
                if int(self._seq[0]) == before:
                    self._last = self._snapshot(numbers, texts)
                    return dict(self._last)
            time.sleep(0 if attempt < SPINS else WAIT)
        if self._last is None:  # nothing read whole yet: the record as it stands, each word whole
            return self._snapshot(self._numbers.copy(), self._texts.copy())
        return dict(self._last)

    def _snapshot(self, numbers, texts):
        out = {key: float(numbers[i]) for i, key in enumerate(NUMBERS)}
        for key in ("blocks", "samples", "deadline_misses", "audio_underruns", "audio_xruns",
                    "audio_limited", "faults", "midi_messages", "block"):
            out[key] = int(out[key])
        out["state"] = STATES[int(out["state"])]
        out["fault_latched"] = bool(out["fault_latched"])
        out["audio_paced"] = bool(out["audio_paced"])
        for key, sl in self._slices.items():
            out[key] = bytes(texts[sl]).rstrip(b"\0").decode("utf-8", "replace")
        return out

    # the parent's word ---------------------------------------------------
    @property
    def force_enable(self):
        return bool(self._enable[0])

    @force_enable.setter
    def force_enable(self, on):
        if on:
            self._enable[1:4] = 0.0
        self._enable[0] = 1.0 if on else 0.0

    def disable_force(self, reason, silence=0.0):
        """Clear ``force_enable``, saying why (``FORCE_OFF_REASONS``; the watchdog gives the silence in s)."""
        self._enable[1] = FORCE_OFF_REASONS.index(reason)
        self._enable[2] = float(silence)
        self._enable[3] = time.monotonic()
        self._enable[0] = 0.0

    @property
    def force_off_reason(self):
        return FORCE_OFF_REASONS[int(self._enable[1])]

    @property
    def force_off_silence(self):
        return float(self._enable[2])

    @property
    def force_off_time(self):
        """``time.monotonic()`` when ``force_enable`` was last cleared (0 while it is set)."""
        return float(self._enable[3])

    @property
    def guard_heartbeat(self):
        """``time.monotonic()`` of the force guard's last round (0 before it started)."""
        return float(self._enable[4])

    def guard_beat(self):
        self._enable[4] = time.monotonic()

    def worker_beat(self):
        """(state, heartbeat) of the worker, from one consistent record (the guard's cheap read).

        The guard's read does not wait: with the writer mid-record it gives the
        last pair it read whole, whose heartbeat ages until the writer finishes
        (module docstring).
        """
        for _ in range(3):
            before = int(self._seq[0])
            if before % 2 == 0:
                state, beat = self._numbers[_STATE], self._numbers[_HEARTBEAT]
                if int(self._seq[0]) == before:
                    self._last_beat = (STATES[int(state)], float(beat))
                    break
        return self._last_beat

    def close(self):
        self._seq = self._enable = self._numbers = self._texts = None
        self._shm.close()
        if self._owner:
            self._shm.unlink()
            self._owner = False
