"""The device sink's FIFO: float32 samples from the engine thread to the audio callback, without a lock."""

import numpy as np


class Fifo:
    """Single-producer, single-consumer float32 FIFO between the engine thread and the audio callback.

    Each side moves only its own counter, after touching the data, and a
    Python int assignment is atomic under the GIL, so no lock is needed.
    """

    def __init__(self, capacity):
        self.capacity = int(capacity)
        self._data = np.zeros(self.capacity, dtype=np.float32)
        self._written = 0
        self._read = 0

    @property
    def level(self):
        return self._written - self._read

    @property
    def read_position(self):
        """Frames read so far: the position in the written stream of the next frame read."""
        return self._read

    def write(self, samples):
        n = min(samples.shape[0], self.capacity - self.level)
        start = self._written % self.capacity
        split = min(n, self.capacity - start)
        self._data[start:start + split] = samples[:split]
        self._data[:n - split] = samples[split:n]
        self._written += n
        return n

    def read_into(self, out):
        n = min(out.shape[0], self.level)
        start = self._read % self.capacity
        split = min(n, self.capacity - start)
        out[:split] = self._data[start:start + split]
        out[split:n] = self._data[:n - split]
        self._read += n
        return n
