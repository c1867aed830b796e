"""The headphone level check's reference tone: a sine in place of the string's sound.

While on, the sink's output is

    y[j] = (1 - c[j]) s[j] + a[j] sin(phi_0 + omega j),   omega = 2 pi hz / fs,

with s the string's sound (after the fixed stimulus gain), fs the sink's rate, c the
crossfade (0: the string, 1: the tone) and a the tone's peak amplitude,
A = 10^(level_dbfs / 20) (peak, dB re full scale, so -20 dBFS is a peak of
0.1; its RMS is 3.01 dB lower), at most the output limiter's knee (-18 dBFS,
signal_chain.py), so the tone is never bent. c and a move linearly to their targets over ``RAMP`` seconds, so turning
the tone on or off, changing its level, or muting never clicks. The phase is
carried from block to block (phi_0 is the phase reached at the end of the
previous block; 0 when the tone starts from silence): the tone is one sine
whatever the block sizes.

The tone goes through the volume after it, as the string does (issue 31): the
level check is heard at the stimulus level with the volume in force, so the
headphones are set for what the participant will hear at that volume. Its
level is at most the limiter's knee and the volume only attenuates, so the
tone is never bent. The experimenter's mute silences it (mute means silence).
"""

import math

import numpy as np

from studyapp.errors import ParameterError

RAMP = 0.005  # s: on, off and level changes are linear ramps this long
LOWEST_HZ = 20.0
HIGHEST_HZ = 20_000.0
LOWEST_DBFS = -96.0  # a 16-bit file's floor
HIGHEST_DBFS = -18.0  # the limiter's knee (signal_chain: CEILING_DBFS - KNEE_DB): a level check is never bent


def check(hz, level_dbfs, rate):
    """Refuse a tone the sink cannot play as asked (``ParameterError``, one line)."""
    top = min(HIGHEST_HZ, 0.45 * rate)
    if not (math.isfinite(hz) and LOWEST_HZ <= hz <= top):
        raise ParameterError(f"reference tone {hz:g} Hz: allowed is {LOWEST_HZ:g} to {top:g} Hz "
                             f"(at the audio rate {rate:g} Hz)")
    if level_dbfs is not None and not (math.isfinite(level_dbfs) and LOWEST_DBFS <= level_dbfs <= HIGHEST_DBFS):
        raise ParameterError(f"reference tone level {level_dbfs:g} dBFS: allowed is {LOWEST_DBFS:g} to "
                             f"{HIGHEST_DBFS:g} dBFS (peak; the output's limiter bends louder sounds)")


class ReferenceTone:
    def __init__(self, rate, ramp=RAMP):
        self.rate = float(rate)
        self.ramp_samples = max(1, int(round(ramp * self.rate)))
        self.hz = 1000.0
        self.level_dbfs = None  # None: off
        self.muted = False
        self.omega = 2 * math.pi * self.hz / self.rate
        self.phase = 0.0
        self.fade = 0.0  # c: how much of the string the tone replaces
        self.amp = 0.0  # a: the tone's peak amplitude now
        self._amp_step = 0.0

    @property
    def on(self):
        return self.level_dbfs is not None

    @property
    def amp_target(self):
        return 0.0 if self.muted or not self.on else 10.0 ** (self.level_dbfs / 20.0)

    def set(self, hz, level_dbfs):
        """Play ``hz`` at ``level_dbfs`` (peak dBFS); ``level_dbfs`` None gives the string back."""
        check(float(hz), None if level_dbfs is None else float(level_dbfs), self.rate)
        if self.fade == 0.0 and self.amp == 0.0:
            self.phase = 0.0  # from silence: start at a zero crossing
        self.hz = float(hz)
        self.omega = 2 * math.pi * self.hz / self.rate
        self.level_dbfs = None if level_dbfs is None else float(level_dbfs)
        self._retarget()

    def set_muted(self, muted):
        self.muted = bool(muted)
        self._retarget()

    def _retarget(self):
        self._amp_step = max(abs(self.amp_target - self.amp), 1e-12) / self.ramp_samples

    @staticmethod
    def _towards(now, target, step, n):
        ramp = now + np.arange(1, n + 1) * (step if target >= now else -step)
        return np.minimum(ramp, target) if target >= now else np.maximum(ramp, target)

    def mix(self, block):
        """Put the tone into ``block`` (the string's sound at the sink's rate) in place; returns it."""
        fade_target = 1.0 if self.on else 0.0
        amp_target = self.amp_target
        if self.fade == 0.0 and fade_target == 0.0 and self.amp == 0.0:
            return block  # off: the string alone, untouched
        n = block.shape[0]
        if n == 0:
            return block
        fade = self._towards(self.fade, fade_target, 1.0 / self.ramp_samples, n)
        amp = self._towards(self.amp, amp_target, self._amp_step, n)
        tone = amp * np.sin(self.phase + self.omega * np.arange(n))
        block *= 1.0 - fade
        block += tone
        self.fade, self.amp = float(fade[-1]), float(amp[-1])
        self.phase = math.fmod(self.phase + self.omega * n, 2 * math.pi)
        return block
