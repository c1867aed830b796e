"""Stability monitor: does the loop still feel and sound like a bowed string?

The paper's participants found the margin of stability by "device oscillation
and clear distortion in the sound" (Sec. 8.3): "the point immediately before
the model no longer feels or sounds like a bowed string".

What breakdown is in this model. While the bow sticks, the string pushes on
the handle through the junction (F = -G rho(v_delta) v_delta, with rho at its
0.98 clip), and the string beyond the bow is a resonator: with the sticking
bow as its fixed end, the nut-side segment rings at about f0 / (1 - beta)
(168 Hz for the default 147 Hz string). A velocity source that lags the
handle's true velocity turns this coupling from a brake into a drive, and past
a gain the loop oscillates by itself: the force swings between +F_max and
-F_max at that frequency (the handle buzzes) and the string near the bow rings
with it (the sound distorts). A healthy loop never does this: the friction of
a bowed string keeps one sign, opposing the stroke, with a ripple at the
string's period; a held handle feels almost nothing.

Criterion (pinned by tests/model/test_model_stability.py). With
r = F / F_max = -rho(v_delta) v_delta / max|rho v| (the loop's "friction"
output, in [-1, 1], defined even when F_max = 0), high-passed at 40 Hz:

    level = RMS of r over the last WINDOW = 0.25 s          (``score``)
    e(t)  = RMS of r over the last ENVELOPE = 12 ms (about two oscillation periods)
    cv    = standard deviation / mean of e over the last 0.25 s
    broken  = level > LEVEL_MIN = 0.3  and  cv < CV_MAX = 0.15

A self-sustained oscillation is large and steady: it saturates between about
-F_max and +F_max (level 0.4-0.9) with an envelope that hardly moves
(cv 0.01-0.1). The two things it must not be confused with are healthy
bowing, whose friction keeps one sign (level 0.1-0.2), and estimator noise,
which the string's resonance filters into a narrow-band random force: its
envelope fluctuates like a Rayleigh variable (cv 0.2-0.35 measured) even when
its level is high. Noise so large that it saturates the bow table at any gain
(BDIFF at 5 kHz) is steady too, and is judged broken: that string never
sounds like a bowed string.

Caveat (what the model shows): regular bowing at the strokes' speed masks the
oscillation, because every slip restarts the sticking phase in which it
grows; it appears when the bow rests or moves slowly. Breakdown searches
(``calibration.breakdown_fmax``) therefore hold the handle, with tremor.
"""

import numpy as np
from scipy import signal

WINDOW = 0.25  # s
ENVELOPE = 0.012  # s
HIGHPASS_HZ = 40.0
LEVEL_MIN = 0.3
CV_MAX = 0.15


def _ema(x, alpha, last):
    """Exponential mean y[k] = y[k-1] + alpha (x[k] - y[k-1]) from ``last``; returns (y, new last)."""
    y, _ = signal.lfilter([alpha], [1.0, alpha - 1.0], x, zi=[(1.0 - alpha) * last])
    return y, (float(y[-1]) if y.size else last)


class StabilityMonitor:
    """Updated by ``ClosedLoop.run`` with each block: ``.broken``, ``.score`` (= ``.level``), ``.cv``."""

    def __init__(self, rate):
        self.rate = float(rate)
        self._hp = signal.butter(2, min(HIGHPASS_HZ, 0.45 * rate), "high", fs=rate, output="sos")
        self._a_long = 1.0 - np.exp(-1.0 / (WINDOW * rate))
        self._a_short = 1.0 - np.exp(-1.0 / (ENVELOPE * rate))
        self.reset()

    def reset(self):
        self._hp_z = np.zeros((self._hp.shape[0], 2))
        self._ms = 0.0  # long mean of r^2
        self._env_ms = 0.0  # short mean of r^2
        self._env_mean = 0.0  # long mean of e
        self._env_sq = 0.0  # long mean of e^2
        self.level = 0.0
        self.cv = 1.0
        self.broken = False

    @property
    def score(self):
        return self.level

    def measure(self, friction):
        """Per-sample (level, cv) for one block of the friction ratio F / F_max; advances the state."""
        r = np.nan_to_num(np.asarray(friction, dtype=np.float64), nan=0.0, posinf=0.0, neginf=0.0)
        hf, self._hp_z = signal.sosfilt(self._hp, r, zi=self._hp_z)
        sq = hf * hf
        ms, self._ms = _ema(sq, self._a_long, self._ms)
        env_ms, self._env_ms = _ema(sq, self._a_short, self._env_ms)
        env = np.sqrt(np.maximum(env_ms, 0.0))
        mean, self._env_mean = _ema(env, self._a_long, self._env_mean)
        msq, self._env_sq = _ema(env * env, self._a_long, self._env_sq)
        level = np.sqrt(np.maximum(ms, 0.0))
        spread = np.sqrt(np.maximum(msq - mean * mean, 0.0))
        cv = np.where(mean > 0.0, spread / np.maximum(mean, 1e-300), 1.0)
        return level, cv

    def update(self, block):
        if block["friction"].shape[0] == 0:
            return
        level, cv = self.measure(block["friction"])
        self.level = float(level[-1])
        self.cv = float(cv[-1])
        self.broken = bool(self.level > LEVEL_MIN and self.cv < CV_MAX)
