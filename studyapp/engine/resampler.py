"""Streaming polyphase resampler: the string's audio from the haptic rate to the device rate.

Rational resampling by up/down (Crochiere and Rabiner, *Multirate Digital Signal
Processing*, 1983, ch. 4): zero-stuff by ``up``, low-pass with an FIR ``h``,
keep every ``down``-th sample. Only the taps that meet a non-zero input are
computed (the polyphase form)::

    y[k] = sum_n x[n] h[k*down + half - n*up],     0 <= k*down + half - n*up < len(h)

``h`` is scipy's design for ``scipy.signal.resample_poly`` (a Kaiser-windowed
sinc, beta 5, cut-off at the lower Nyquist rate, ``half = 10*max(up, down)``,
gain ``up``), and the output index is centred the same way, so the streamed
output equals ``resample_poly`` of the whole stream sample for sample, however
the stream is cut into blocks: no click can appear at a block edge. Output k is
emitted once the newest input it needs (n = (k*down + half) // up) has
arrived: output k is the signal at time k/out_rate, and it becomes available
half/up input samples after the input at that time (10 input samples when
upsampling).
"""

from fractions import Fraction

import numpy as np
from numba import njit
from scipy.signal import firwin

from studyapp.errors import ParameterError

MAX_FACTOR = 4096


def ratio(in_rate, out_rate, max_factor=MAX_FACTOR):
    """``(up, down)`` with ``out_rate/in_rate ~= up/down`` and both at most ``max_factor``.

    Exact when the rates allow it (5 kHz -> 48 kHz: 48/5); otherwise the
    nearest such fraction, which changes the pitch by its relative error.
    """
    if not (in_rate > 0 and out_rate > 0):
        raise ParameterError(f"resampler rates must be positive, got {in_rate} -> {out_rate}")
    exact = Fraction(out_rate) / Fraction(in_rate)
    bound = max_factor
    frac = exact.limit_denominator(bound)
    while frac.numerator > max_factor or frac.numerator == 0:
        bound //= 2
        if bound == 0:
            raise ParameterError(f"resampler: {in_rate} Hz -> {out_rate} Hz is too far apart")
        frac = exact.limit_denominator(bound)
    return frac.numerator, frac.denominator


def design(up, down):
    """scipy's ``resample_poly`` filter for ``up/down``: ``(h, half)``; the identity when equal."""
    if up == down:
        return np.ones(1), 0
    top = max(up, down)
    half = 10 * top
    h = firwin(2 * half + 1, 1.0 / top, window=("kaiser", 5.0)) * up
    return np.ascontiguousarray(h), half


@njit(cache=True)
def _emit(h, up, down, half, buf, base, n_in, k, out):
    """Every output whose inputs have arrived; returns ``(next k, outputs written)``."""
    taps = h.shape[0]
    m = 0
    while m < out.shape[0]:
        c = k * down + half
        newest = c // up
        if newest >= n_in:
            break
        acc = 0.0
        i = c - newest * up
        n = newest
        while i < taps and n >= 0:
            acc += buf[n - base] * h[i]
            i += up
            n -= 1
        out[m] = acc
        m += 1
        k += 1
    return k, m


class Resampler:
    """``process(block) -> resampled block``, keeping state across calls."""

    def __init__(self, in_rate, out_rate):
        self.in_rate = float(in_rate)
        self.out_rate = float(out_rate)
        self.up, self.down = ratio(self.in_rate, self.out_rate)
        self.h, self.half = design(self.up, self.down)
        self._keep = self.h.shape[0] // self.up + 2
        self.reset()

    @property
    def latency(self):
        """How long output k waits for its newest input, in input samples (the signal itself is not delayed)."""
        return self.half / self.up

    def reset(self):
        self._buf = np.zeros(0)
        self._base = 0
        self._n_in = 0
        self._k = 0

    def _run(self, block):
        block = np.ascontiguousarray(block, dtype=np.float64)
        self._buf = np.concatenate((self._buf, block)) if self._buf.size else block.copy()
        self._n_in += block.shape[0]
        out = np.empty(block.shape[0] * self.up // self.down + self.half // self.down + 2)
        self._k, m = _emit(self.h, self.up, self.down, self.half, self._buf, self._base,
                           self._n_in, self._k, out)
        drop = max(0, self._n_in - self._keep - self._base)
        if drop:
            self._buf = self._buf[drop:]
            self._base += drop
        return out[:m]

    def process(self, block):
        """Resample the next block of the stream (any length, including 0)."""
        return self._run(block)

    def flush(self):
        """End the stream: the outputs still owed for its tail, as ``resample_poly`` pads them.

        The total output then has ``ceil(n_in * up / down)`` samples; the
        resampler starts a new stream afterwards.
        """
        owed = -(-self._n_in * self.up // self.down) - self._k
        out = self._run(np.zeros(self.half // self.up + 2))[:max(owed, 0)]
        self.reset()
        return out
