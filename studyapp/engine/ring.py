"""Shared-memory ring buffers: telemetry from the worker to any reader, never torn.

One writer (the engine's worker) appends blocks of samples to several named
channels; any number of readers, in any process, copy the newest samples.
Nothing blocks and nothing locks: the writer must never wait for a slow GUI.

Layout of the shared memory::

    int64[4]   header: started, committed, capacity, channels
    float64[channels, capacity]   data; sample number n of channel c is at [c, n % capacity]

Writing a block of m samples (a seqlock for rings): raise ``started`` to the new
total, write the samples (``stage``), raise ``committed`` to the same total
(``commit``). Between the two the block is *staged*: written, not yet readable.
``withhold`` zeroes channels of a staged block from any process; the force
guard uses it so that a block staged before a trip, by a worker stopped before
its commit, is committed with its force withheld (engine/guard.py). Reading samples
[a, b): take ``b <= committed`` before copying, copy, then read ``started``
again. The slots being overwritten at any moment hold samples older than
``started - capacity``, so the copy is intact exactly when ``a >= started -
capacity`` (with ``started`` read after the copy); otherwise the reader copies
again. This relies on stores being seen in program order and loads not being
reordered with each other, which holds on x86-64 (TSO); aligned int64 stores are
atomic there. On weaker memory models (ARM) the counters would need fences.
"""

from dataclasses import dataclass
from multiprocessing import shared_memory

import numpy as np

from studyapp.engine.shm_names import new_name

_HEADER = 4
_STARTED, _COMMITTED, _CAPACITY, _CHANNELS = range(_HEADER)


@dataclass(frozen=True)
class RingSpec:
    """What a process needs to attach to a ring: its shared-memory name, channels, capacity."""

    name: str
    channels: tuple
    capacity: int


class TornRead(RuntimeError):
    """The writer lapped the reader on every retry (the reader asked for too much)."""


class Ring:
    """A multi-channel ring of float64 samples in shared memory.

    ``Ring.create(channels, capacity)`` makes a new one (the owner unlinks it);
    ``Ring.attach(spec)`` opens an existing one from another process.
    """

    def __init__(self, shm, channels, capacity, owner):
        self._shm = shm
        self.channels = tuple(channels)
        self.capacity = int(capacity)
        self._owner = owner
        self._index = {c: i for i, c in enumerate(self.channels)}
        self._header = np.ndarray((_HEADER,), dtype=np.int64, buffer=shm.buf)
        self._data = np.ndarray(
            (len(self.channels), self.capacity), dtype=np.float64, buffer=shm.buf, offset=_HEADER * 8
        )

    @classmethod
    def create(cls, channels, capacity):
        channels = tuple(channels)
        if len(set(channels)) != len(channels) or not channels:
            raise ValueError(f"channels: need distinct names, got {channels!r}")
        if capacity < 2:
            raise ValueError(f"capacity: need at least 2 samples, got {capacity}")
        size = _HEADER * 8 + len(channels) * int(capacity) * 8
        shm = shared_memory.SharedMemory(name=new_name("ring"), create=True, size=size)
        ring = cls(shm, channels, capacity, owner=True)
        ring._header[:] = (0, 0, capacity, len(channels))
        ring._data[:] = 0.0
        return ring

    @classmethod
    def attach(cls, spec):
        shm = shared_memory.SharedMemory(name=spec.name)
        ring = cls(shm, spec.channels, spec.capacity, owner=False)
        if ring._header[_CAPACITY] != spec.capacity or ring._header[_CHANNELS] != len(spec.channels):
            raise ValueError(f"ring {spec.name}: shape does not match its spec")
        return ring

    @property
    def spec(self):
        return RingSpec(self._shm.name, self.channels, self.capacity)

    @property
    def committed(self):
        """Number of samples written so far (per channel)."""
        return int(self._header[_COMMITTED])

    def index(self, channel):
        return self._index[channel]

    def write(self, block):
        """Append a block: a ``(channels, m)`` array, or a dict ``{channel: m samples}`` naming all channels."""
        self.stage(block)
        self.commit()

    def stage(self, block):
        """Write a block without making it readable yet (``commit`` does); arguments as ``write``."""
        if isinstance(block, dict):
            block = np.stack([np.asarray(block[c], dtype=np.float64) for c in self.channels])
        m = block.shape[1]
        start = int(self._header[_COMMITTED])
        if m > self.capacity:
            block = block[:, m - self.capacity:]
            start += m - self.capacity
            m = self.capacity
        end = start + m
        self._header[_STARTED] = end
        head, tail, split = self._spans(start, m)
        self._data[:, head] = block[:, :split]
        self._data[:, tail] = block[:, split:]

    def commit(self):
        """Make the staged block readable."""
        self._header[_COMMITTED] = self._header[_STARTED]

    def withhold(self, channels):
        """Zero ``channels`` (names) of the staged block, if one is staged; returns the samples zeroed."""
        start, end = int(self._header[_COMMITTED]), int(self._header[_STARTED])
        m = min(end - start, self.capacity)
        if m <= 0:
            return 0
        head, tail, _ = self._spans(start, m)
        rows = [self._index[c] for c in channels]
        self._data[rows, head] = 0.0
        self._data[rows, tail] = 0.0
        return m

    def _spans(self, start, m):
        """The slots of samples [start, start + m): (slice to the end of the data, slice from its start, split)."""
        first = start % self.capacity
        split = min(m, self.capacity - first)
        return slice(first, first + split), slice(0, m - split), split

    def _copy(self, a, b):
        head, tail, split = self._spans(a, b - a)
        out = np.empty((len(self.channels), b - a))
        out[:, :split] = self._data[:, head]
        out[:, split:] = self._data[:, tail]
        return out

    def read_since(self, position, limit=None, retries=8):
        """Samples from ``position`` up to the newest: ``(data (channels, n), start, end)``.

        ``start`` is greater than ``position`` when samples were lost (the reader
        fell more than a ring behind). ``limit`` caps ``n`` to the newest samples.
        """
        for _ in range(retries):
            end = int(self._header[_COMMITTED])
            start = max(int(position), end - self.capacity)
            if limit is not None:
                start = max(start, end - int(limit))
            start = min(start, end)
            data = self._copy(start, end)
            overwritten = int(self._header[_STARTED]) - self.capacity
            if start >= overwritten:
                return data, start, end
            position = overwritten
        raise TornRead(f"ring {self._shm.name}: writer lapped the reader {retries} times")

    def read_latest(self, n):
        """The newest ``n`` samples (fewer at the start): ``(data (channels, n), end)``."""
        data, _, end = self.read_since(0, limit=n)
        return data, end

    def close(self):
        self._header = None
        self._data = None
        self._shm.close()
        if self._owner:
            self._shm.unlink()
            self._owner = False
