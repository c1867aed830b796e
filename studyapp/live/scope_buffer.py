"""What the live scope draws: the newest seconds of each channel, reduced to what a screen can show. No Qt.

``ScopeBuffer`` keeps the last ``seconds`` (5 s) of every channel in a ring of
float64, appended block by block from the engine's telemetry.

``envelope(x, k)`` is peak (min/max) decimation: the samples are cut into
bins of k consecutive samples and each bin becomes two points, its minimum
and its maximum, in the order they occur in the bin. A trace of n samples
becomes 2 n / k points, and drawn as a line it covers exactly the band the
full trace would cover in each pixel column: spikes (the noise the rating
task is about) are never smoothed away, as plain subsampling would do.

``window(duration, columns)`` returns, per channel, the envelope of the last
``duration`` seconds with about ``columns`` bins (the plot's width in pixels),
and the time axis in seconds relative to the newest sample (-duration .. 0).
Bins are aligned to absolute sample numbers, so a bin's content does not
change as new samples arrive and the drawing does not shimmer.
"""

import numpy as np
from numba import njit

MAX_SECONDS = 5.0


@njit(cache=True)
def _envelope_rows(x, k, out):
    for c in range(x.shape[0]):
        for b in range(x.shape[1] // k):
            base = b * k
            low = high = base
            for i in range(base + 1, base + k):
                if x[c, i] < x[c, low]:
                    low = i
                elif x[c, i] > x[c, high]:
                    high = i
            first, second = (low, high) if low <= high else (high, low)
            out[c, 2 * b] = x[c, first]
            out[c, 2 * b + 1] = x[c, second]


def envelope(x, k):
    """Min and max of each bin of ``k`` samples, interleaved in time order, along the last axis.

    ``x`` is ``(n,)`` or ``(channels, n)`` with n a multiple of k; the result has 2 n / k points per row.
    """
    x = np.asarray(x, dtype=np.float64)
    if k <= 1:
        return x.copy()
    rows = np.ascontiguousarray(x.reshape(-1, x.shape[-1]))
    out = np.empty((rows.shape[0], 2 * (rows.shape[1] // k)))
    _envelope_rows(rows, int(k), out)
    return out.reshape(*x.shape[:-1], -1)


class ScopeBuffer:
    def __init__(self, rate, channels, seconds=MAX_SECONDS):
        self.rate = float(rate)
        self.channels = tuple(channels)
        self.capacity = max(2, int(np.ceil(seconds * self.rate)))
        self.data = np.zeros((len(self.channels), self.capacity))
        self.end = 0  # absolute sample number after the newest sample
        self.count = 0  # samples held (<= capacity)

    def append(self, rows, end=None):
        """Add ``rows`` (``(channels, m)``) whose last sample is number ``end - 1`` (default: continues)."""
        rows = np.asarray(rows, dtype=np.float64)
        m = rows.shape[1]
        end = self.end + m if end is None else int(end)
        if end - m != self.end:
            # samples were lost or this is a new stream: start over rather than join unrelated samples
            self.count = 0
        if m > self.capacity:
            rows = rows[:, m - self.capacity:]
            m = self.capacity
        first = (end - m) % self.capacity
        split = min(m, self.capacity - first)
        self.data[:, first:first + split] = rows[:, :split]
        self.data[:, :m - split] = rows[:, split:]
        self.end = end
        self.count = min(self.capacity, self.count + m)

    def latest(self, n):
        """The newest ``min(n, count)`` samples of every channel, oldest first: ``(channels, n)``."""
        n = min(int(n), self.count)
        start = (self.end - n) % self.capacity
        split = min(n, self.capacity - start)
        return np.concatenate([self.data[:, start:start + split], self.data[:, :n - split]], axis=1)

    def window(self, duration, columns):
        """``(t, {channel: y})``: the envelope of the last ``duration`` s in about ``columns`` bins."""
        wanted = max(1, int(round(duration * self.rate)))
        k = max(1, wanted // max(1, int(columns)))
        # drop the oldest samples so that bins start at multiples of k (absolute sample numbers)
        have = min(wanted, self.count)
        first = self.end - have
        first += (-first) % k
        n = (self.end - first) // k * k
        if n <= 0:
            return np.zeros(0), {c: np.zeros(0) for c in self.channels}
        rows = self.latest(self.end - first)[:, :n]
        times = (first + np.arange(n) - self.end) / self.rate
        if k == 1:
            return times, {c: rows[i] for i, c in enumerate(self.channels)}
        # a bin's two points sit at its first and its last sample's time
        t = np.empty(2 * (n // k))
        t[0::2] = times[0::k]
        t[1::2] = times[k - 1::k]
        reduced = envelope(rows, k)
        return t, {c: reduced[i] for i, c in enumerate(self.channels)}
