"""Events from the worker to the parent through shared memory: no thread, no lock, no system call.

A ``multiprocessing.Queue`` would do, but its ``put`` hands the message to a
feeder thread that must take the GIL to pickle and send it. In the worker
that thread runs at normal priority: on a busy machine it can be descheduled
while holding the GIL, and the real-time threads (the loop, PortAudio's
callback) then wait behind it. So the worker pickles each event itself into a
slot of a ring in shared memory, and the parent polls the ring.

Layout: ``int64[3]`` header (events written, slots, slot size), then the slots,
each ``uint32`` length + pickled bytes. The writer fills slot ``n % slots`` and
only then raises the count to ``n + 1``; a reader copies slot ``i`` and keeps it
if the count is still below ``i + slots`` afterwards (the writer overwrites
slot ``i`` only while the count equals ``i + slots``, so an event that old is
skipped, as lost). A reader that
falls a whole ring behind is told how many events it lost. An event too large
for a slot is replaced by a short ``events.Notice`` saying so.
"""

import pickle
from multiprocessing import shared_memory

import numpy as np

from studyapp.engine.events import Notice
from studyapp.engine.shm_names import new_name

_HEADER = 3
SLOTS = 256
SLOT_SIZE = 4096


class EventRing:
    def __init__(self, shm, owner):
        self._shm = shm
        self._owner = owner
        self._header = np.ndarray((_HEADER,), dtype=np.int64, buffer=shm.buf)
        self.slots = int(self._header[1])
        self.slot_size = int(self._header[2])
        self._data = np.ndarray((self.slots, self.slot_size), dtype=np.uint8, buffer=shm.buf,
                                offset=_HEADER * 8)
        self.position = 0  # reader side: next event to read
        self.lost = 0

    @classmethod
    def create(cls, slots=SLOTS, slot_size=SLOT_SIZE):
        shm = shared_memory.SharedMemory(name=new_name("events"), create=True, size=_HEADER * 8 + slots * slot_size)
        np.ndarray((_HEADER,), dtype=np.int64, buffer=shm.buf)[:] = (0, slots, slot_size)
        return cls(shm, owner=True)

    @classmethod
    def attach(cls, name):
        return cls(shared_memory.SharedMemory(name=name), owner=False)

    @property
    def name(self):
        return self._shm.name

    def put(self, event):
        """Append one picklable event (writer side; never blocks)."""
        raw = pickle.dumps(event, protocol=pickle.HIGHEST_PROTOCOL)
        if len(raw) + 4 > self.slot_size:
            text = f"an event of {len(raw)} bytes was too large to pass on: {event!s}"
            keep = self.slot_size // 2
            while len(raw) + 4 > self.slot_size:
                raw = pickle.dumps(Notice(text[:keep], "warning"))
                keep //= 2
        n = int(self._header[0])
        slot = self._data[n % self.slots]
        slot[:4] = np.frombuffer(np.uint32(len(raw)).tobytes(), dtype=np.uint8)
        slot[4:4 + len(raw)] = np.frombuffer(raw, dtype=np.uint8)
        self._header[0] = n + 1

    def get(self):
        """The next event, or ``None`` when there is none (reader side)."""
        while True:
            written = int(self._header[0])
            if self.position >= written:
                return None
            if written - self.position >= self.slots:
                # slot (written % slots) may be being overwritten right now: skip past it
                self.lost += written - self.slots + 1 - self.position
                self.position = written - self.slots + 1
            slot = self._data[self.position % self.slots].copy()
            if int(self._header[0]) >= self.position + self.slots:
                continue  # overwritten while we copied: skip ahead on the next pass
            self.position += 1
            length = int(np.frombuffer(slot[:4].tobytes(), dtype=np.uint32)[0])
            return pickle.loads(slot[4:4 + length].tobytes())

    def close(self):
        self._header = self._data = None
        self._shm.close()
        if self._owner:
            self._shm.unlink()
            self._owner = False
