"""Stability monitor: does the loop still feel and sound like a bowed string?

The paper's participants found the margin of stability by "device oscillation
and clear distortion in the sound" (Sec. 8.3): "the point immediately before
the model no longer feels or sounds like a bowed string".

What breakdown is in this model. While the bow sticks, the string pushes on
the handle through the junction (F = -G rho(v_delta) v_delta, with rho at its
0.98 clip), and the string beyond the bow is a resonator: with the sticking
bow as its fixed end, the nut-side segment rings at about f0 / (1 - beta)
(587 Hz for the default 440 Hz string bowed at beta = 0.25), and below that
the stuck string is stiff. A velocity source that lags the handle's true
velocity turns this coupling from a brake into a drive, and past a gain the
loop oscillates by itself: the force swings between +F_max and -F_max, the
handle buzzes (mm/s) and the string near the bow rings with it (the sound
distorts; the handle's buzz is heard too, contact_mic.py). With TRUE it is
the loop mode; with the tachometer and the estimators the handle bouncing on
the stuck string comes first, at 30-130 Hz (docs/model.md).

Criterion, on absolute quantities (pinned by tests/model/test_model_stability.py).
The monitor watches the handle's velocity v (m/s: the simulation's true
velocity, or a real device's tachometer), high-passed at f0 / 2 (220 Hz for the
default string) so that strokes, their reversals and tremor do not count,
while the loop mode, above f0, does, and so do the harmonics of the lower
bounce (saturated at +-F_max, it is nearly a square wave):

    level = RMS of v over the last WINDOW = 0.25 s                 (``score``, m/s)
    e(t)  = RMS of v over the last ENVELOPE = 12 ms (about one oscillation period)
    cv    = standard deviation / mean of e over the last 0.25 s
    broken  = level > VIBRATION_MIN = 1 mm/s  and  cv < CV_MAX = 0.15

A self-sustained oscillation is large and steady: the force saturates at
+-F_max, so the handle's buzz is of order F_max / (m w) (mm/s at a few newtons
on the 1 kg of handle and hand) with an envelope that hardly moves (cv 0.01-0.1).
What it must not be confused with: estimator noise, whose force is random and
whose envelope fluctuates like a Rayleigh variable (cv 0.2-0.35) even when
large; bowing, whose stick-slip ripple changes with every stroke; and, above
all, anything at a low gain. An earlier criterion on F / F_max read estimator
noise the same at every gain and flagged LEVANT and KALMAN "broken" at
0.001 N on some seeds; in metres per second, a handle pushed by millinewtons
cannot reach VIBRATION_MIN. VIBRATION_MIN sits far above the held handle's
band-passed velocity at low gain (0.001 mm/s with the 440 Hz string, 0.04 mm/s
with the former 147 Hz one: the tremor's leak through the high-pass) and below
the buzz of the breakdowns (LOWPASS 1.9 mm/s at 9.8 N, LVT 3.2 mm/s at 13.3 N;
scripts/model_figures.py prints them). An oscillation that starts is itself
an envelope change: cv falls below CV_MAX some tenths of a second after the
onset, so the verdict lags the onset by about that long (a participant also
needs a moment).

Caveat (what the model shows): regular bowing masks the oscillation, because
every slip restarts the sticking phase in which it grows; it appears when the
bow rests or moves slowly. Breakdown searches (``studyapp.model.breakdown``)
therefore hold the handle, with tremor.
"""

import math

import numpy as np
from numba import njit
from scipy import signal

from studyapp.model import calibration
from studyapp.model.sensors import section_at

WINDOW = 0.25  # s
ENVELOPE = 0.012  # s
HIGHPASS_FRACTION = 0.5  # of f0
VIBRATION_MIN = 1e-3  # m/s
CV_MAX = 0.15

# parameter vector: high-pass section (5), long and short smoothing factors
MP_HP, MP_LONG, MP_SHORT = 0, 5, 6
N_PARAMS = 7
# state: high-pass (2), long mean of r^2, short mean of r^2, long mean of e, long mean of e^2
MS_HP, MS_MS, MS_ENV_MS, MS_ENV_MEAN, MS_ENV_SQ = 0, 2, 3, 4, 5
N_STATE = 6


@njit(cache=True, inline="always")
def observe(mp, ms, v):
    """Advance the monitor by one sample of the handle's velocity ``v`` (m/s; non-finite counts as 0)."""
    if not np.isfinite(v):
        v = 0.0
    y = section_at(mp, MP_HP, ms, MS_HP, v)
    sq = y * y
    a = mp[MP_LONG]
    ms[MS_MS] += a * (sq - ms[MS_MS])
    ms[MS_ENV_MS] += mp[MP_SHORT] * (sq - ms[MS_ENV_MS])
    e = math.sqrt(ms[MS_ENV_MS])
    ms[MS_ENV_MEAN] += a * (e - ms[MS_ENV_MEAN])
    ms[MS_ENV_SQ] += a * (e * e - ms[MS_ENV_SQ])


@njit(cache=True)
def observe_block(mp, ms, velocity, level, cv):
    """``observe`` over a block, writing the running level and cv per sample."""
    for k in range(velocity.shape[0]):
        observe(mp, ms, velocity[k])
        level[k], cv[k] = verdict(ms)


@njit(cache=True, inline="always")
def verdict(ms):
    """(level, cv) from the monitor's state."""
    level = math.sqrt(max(ms[MS_MS], 0.0))
    mean = ms[MS_ENV_MEAN]
    if mean <= 0.0:
        return level, 1.0
    return level, math.sqrt(max(ms[MS_ENV_SQ] - mean * mean, 0.0)) / mean


class StabilityMonitor:
    """``.broken``, ``.score`` (= ``.level``, m/s), ``.cv``; the loop advances ``.state`` sample by sample."""

    def __init__(self, rate, f0=calibration.F0):
        self.rate = float(rate)
        hp = signal.butter(2, min(HIGHPASS_FRACTION * f0, 0.45 * rate), "high", fs=rate, output="sos")[0]
        self.params = np.zeros(N_PARAMS)
        self.params[MP_HP:MP_HP + 5] = np.array([hp[0], hp[1], hp[2], hp[4], hp[5]]) / hp[3]
        self.params[MP_LONG] = 1.0 - np.exp(-1.0 / (WINDOW * rate))
        self.params[MP_SHORT] = 1.0 - np.exp(-1.0 / (ENVELOPE * rate))
        self.state = np.zeros(N_STATE)
        self.reset()

    def reset(self):
        self.state[:] = 0.0
        self.level = 0.0
        self.cv = 1.0
        self.broken = False

    @property
    def score(self):
        return self.level

    def judge(self):
        """Update ``level``, ``cv`` and ``broken`` from the state (the loop calls this after each block)."""
        self.level, self.cv = verdict(self.state)
        self.broken = bool(self.level > VIBRATION_MIN and self.cv < CV_MAX)
        return self.broken

    def measure(self, velocity):
        """Feed a block of handle velocities (m/s, e.g. from a recording); returns per-sample (level, cv)."""
        r = np.ascontiguousarray(velocity, dtype=np.float64)
        level = np.empty_like(r)
        cv = np.empty_like(r)
        observe_block(self.params, self.state, r, level, cv)
        self.judge()
        return level, cv
