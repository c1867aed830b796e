"""A faulty link, seeded: transport latency and jitter, frame loss and bit errors.

What the device receives is held for ``latency`` + U(0, ``jitter``) seconds
after it arrives (a serial line keeps order, so a frame is never released
before the one ahead of it). Each frame, in either direction, is lost with
probability ``loss`` and, if not, has one of its bits flipped with
probability ``corrupt`` (its delimiter included, so a flip may also merge it
with the next frame). Frames are cut at the 0x00 delimiters; a partial frame
waits for the rest.
"""

import numpy as np


class LinkFaults:
    def __init__(self, seed=0, latency=0.0, jitter=0.0, loss=0.0, corrupt=0.0):
        self.latency = latency
        self.jitter = jitter
        self.loss = loss
        self.corrupt = corrupt
        self._rng = np.random.default_rng(np.random.SeedSequence([int(seed), 0x11F]))
        self._partial = bytearray()
        self._queue = []  # (release time, bytes)
        self._last_release = 0.0
        self.lost = {"in": 0, "out": 0}
        self.flipped = {"in": 0, "out": 0}

    @property
    def idle(self):
        return not (self.latency or self.jitter or self.loss or self.corrupt)

    def _frames(self, data, keep_partial):
        buf = self._partial if keep_partial else bytearray()
        buf += data
        out = []
        while True:
            end = buf.find(b"\x00")
            if end < 0:
                break
            out.append(bytes(buf[:end + 1]))
            del buf[:end + 1]
        if not keep_partial and buf:
            out.append(bytes(buf))
        return out

    def _damage(self, frame, way):
        if self.loss and self._rng.random() < self.loss:
            self.lost[way] += 1
            return b""
        if self.corrupt and self._rng.random() < self.corrupt:
            bit = int(self._rng.integers(len(frame) * 8))
            frame = bytearray(frame)
            frame[bit // 8] ^= 1 << (bit % 8)
            self.flipped[way] += 1
            return bytes(frame)
        return frame

    def incoming(self, data, now):
        """Bytes from the host that arrived at ``now`` (s)."""
        if not data:
            return
        if self.idle:
            self._queue.append((now, data))
            return
        for frame in self._frames(data, keep_partial=True):
            frame = self._damage(frame, "in")
            if frame:
                delay = self.latency + (self._rng.random() * self.jitter if self.jitter else 0.0)
                self._last_release = max(self._last_release, now + delay)
                self._queue.append((self._last_release, frame))

    def due(self, now):
        """The bytes whose time has come, in order."""
        n = 0
        while n < len(self._queue) and self._queue[n][0] <= now:
            n += 1
        if not n:
            return b""
        out = b"".join(d for _, d in self._queue[:n])
        del self._queue[:n]
        return out

    def next_release(self):
        return self._queue[0][0] if self._queue else None

    def outgoing(self, data):
        """Bytes to the host, after loss and bit errors (no delay)."""
        if not data or not (self.loss or self.corrupt):
            return data
        return b"".join(self._damage(f, "out") for f in self._frames(data, keep_partial=False))
