"""What reaches the headphones: the loop's audio through one chain, live and headless alike.

    x (haptic rate) -> stimulus gain: a fixed G = 10^(STIMULUS_GAIN_DB / 20) (model/stimulus_level.py)
      -> gate: silence while the bow is lifted, fades at every start, stop and cut
      -> resampler (haptic rate -> the sink's rate, resampler.py)
      -> reference tone (reference_tone.py: the level check, in place of the string)
      -> volume and mute (Gain, ramped over one block: the listener's comfort, string and tone alike)
      -> soft limiter: no sample ever above CEILING_DBFS; every sample it bends is counted (``limited``)

Gain staging. The loop's audio (the body's radiated sound and the handle's
buzz, model/body.py, model/contact_mic.py) is scaled by one fixed gain so
that the stimulus stays linear, under the limiter's knee, over every F_max a
protocol's knob reaches below 1.25 x LVT's bowing breakdown; the volume only
attenuates (-40 to 0 dB, model/controls.py VOLUME_DB), so it can never push
the stimulus into the limiter. The limiter is a safety net for what lies
beyond (a loop broken far above its breakdown): ``limited`` counts the output
samples it bends, which the worker reports (``audio_limited``), the session
logs per trial (``trial_health``) and the recorder writes in audio_cues.csv.
The level check's tone is mixed before the volume, so it is heard at the
stimulus level with the volume in force.

Gate. The bow lifted means silence: the string's ringing and the handle's
buzz (contact_mic.py) are not heard while the bow is off the string (the
string at F_max = 0 with the bow *on* still sounds: F_max scales the force on
the handle, not the bowing, as in the paper). Every start (the bow put on),
stop (the bow lifted) and cut (a trial's string reset, a change of velocity
source: a discontinuity in the model's sound) gets a raised-cosine fade of
``FADE_S``,

    r[k] = (1 - cos(pi (k + 1) / (F + 1))) / 2,   k = 0 .. F - 1,   F = round(FADE_S * rate),

so no step ever reaches the output. To fade *out* before a boundary the chain
looks ahead: it holds the newest F samples back (a delay of ``FADE_S``), so
when a block arrives with the bow lifted or a cut, the F samples before the
boundary are still there to be faded to zero, and the new block fades in from
zero: the output is exactly 0 from the lift on. The fades are made at the
haptic rate, before the resampler, which then sees a continuous signal.

Limiter. After the volume a soft clip bounds every sample below the ceiling
C = 10^(CEILING_DBFS / 20):

    y = x                                          for |x| <= K,  K = C 10^(-KNEE_DB / 20)
    y = sign(x) (K + (C - K) tanh((|x| - K) / (C - K)))   above,

continuous with slope 1 at the knee K and |y| <= C always (tanh reaches 1 only
in floating point, for inputs far above the knee). A sample is bent exactly
when its input is above the knee K, so the samples above K in the output are
the samples the limiter touched. The levels the gain gives are in
docs/engine.md ("Levels", from scripts/audio_levels.py).

Position. The chain counts the haptic samples it took (``taken``); the first
sample of the next block appears in the output at frame
``round((taken + F) * out_rate / in_rate)`` (the lookahead delays it by F;
the resampler's output k is the signal at k / out_rate). Audio cues use it.
"""

import math

import numpy as np

from studyapp.engine.reference_tone import ReferenceTone
from studyapp.engine.resampler import Resampler
from studyapp.model.controls import number
from studyapp.model.stimulus_level import KNEE_DBFS, STIMULUS_GAIN

CEILING_DBFS = -12.0  # the documented peak: no output sample exceeds it
KNEE_DB = CEILING_DBFS - KNEE_DBFS  # 6 dB: the limiter bends the signal only above the knee, KNEE_DBFS (-18)
FADE_S = 0.005  # s: every start, stop and cut fades over this (and the gate looks ahead this far)
CEILING = 10.0 ** (CEILING_DBFS / 20.0)
KNEE = 10.0 ** (KNEE_DBFS / 20.0)


def soft_limit(x, ceiling=CEILING, knee_db=KNEE_DB):
    """``x`` with every sample bounded below ``ceiling`` (in place; returns it)."""
    knee = ceiling * 10.0 ** (-knee_db / 20.0)
    over = np.abs(x) > knee
    if over.any():
        a = np.abs(x[over])
        x[over] = np.sign(x[over]) * (knee + (ceiling - knee) * np.tanh((a - knee) / (ceiling - knee)))
    return x


VOLUME_GAIN_MAX = 4.0  # linear; the console's volume law (model/controls.py VOLUME_DB) reaches 1.0


def volume_gain(value):
    """``value`` as a linear volume gain, 0..VOLUME_GAIN_MAX; ``ParameterError`` (errors.py) naming it otherwise."""
    return number("volume", value, 0.0, VOLUME_GAIN_MAX, f"a linear gain from 0 to {VOLUME_GAIN_MAX:g}")


class Gain:
    """Volume and mute, ramped linearly over one block on every change so changes never click.

    Settings made before the first block apply at once (there is nothing to click against).
    """

    def __init__(self, volume=1.0):
        self.volume = float(volume)
        self.muted = False
        self._now = None

    @property
    def target(self):
        return 0.0 if self.muted else self.volume

    def set_volume(self, volume):
        self.volume = volume_gain(volume)

    def apply(self, block):
        target = self.target
        if self._now is None:
            self._now = target
        if target == self._now:
            block *= target
        else:
            block *= np.linspace(self._now, target, block.shape[0] + 1)[1:]
            self._now = target
        return block


class Gate:
    """Silence while the bow is lifted; raised-cosine fades at every start, stop and cut, with lookahead."""

    def __init__(self, rate, fade=FADE_S):
        self.length = max(1, int(round(fade * rate)))
        n = self.length
        self.rise = 0.5 - 0.5 * np.cos(np.pi * np.arange(1, n + 1) / (n + 1))
        self.sounding = False
        self._since = n  # samples since the last fade-in began (n: fully in)
        self._tail = np.zeros(n)  # the newest n samples, held back ...
        self._tail_gain = np.zeros(n)  # ... and their gains so far

    def process(self, x, sounding, cut=False):
        """The next ``len(x)`` samples of the gated stream (delayed by ``length``)."""
        n = self.length
        sounding = bool(sounding)
        x = np.asarray(x, dtype=np.float64)
        if sounding == self.sounding and not cut and (not sounding or self._since >= n):
            return self._steady(x, sounding)
        if self.sounding and (cut or not sounding):
            self._tail_gain *= self.rise[::-1]  # fade out, ending at the boundary
        if sounding and (cut or not self.sounding):
            self._since = 0  # fade in from the boundary
        gain = np.zeros(x.shape[0])
        if sounding:
            k = self._since + np.arange(x.shape[0])
            gain = np.where(k < n, self.rise[np.minimum(k, n - 1)], 1.0)
            self._since = min(self._since + x.shape[0], n)
        self.sounding = sounding
        xs = np.concatenate((self._tail, x))
        gs = np.concatenate((self._tail_gain, gain))
        self._tail, self._tail_gain = xs[-n:].copy(), gs[-n:].copy()
        return xs[:-n] * gs[:-n]

    def _steady(self, x, sounding):
        """No boundary in this block nor in the held-back tail: the new samples' gains are all 1, or all 0."""
        n = self.length
        tail = self._tail * self._tail_gain  # kept with its gains applied from here on
        self._tail_gain = np.ones(n)
        if not sounding and not tail.any():
            self._tail = np.zeros(n)
            return np.zeros(x.shape[0])
        xs = np.concatenate((tail, x if sounding else np.zeros(x.shape[0])))
        self._tail = xs[-n:].copy()
        return xs[:-n]


class SignalChain:
    """``process(audio, sounding, cut)``: one block of the loop's audio -> what the listener hears."""

    def __init__(self, haptic_rate, rate, fade=FADE_S, gain=STIMULUS_GAIN):
        self.haptic_rate = float(haptic_rate)
        self.stimulus_gain = float(gain)
        self.rate = float(rate)
        self.gate = Gate(self.haptic_rate, fade)
        self.resampler = Resampler(self.haptic_rate, self.rate)
        self.gain = Gain()
        self.tone = ReferenceTone(self.rate)
        self.taken = 0  # haptic samples taken so far
        self.emitted = 0  # output frames so far
        self.limited = 0  # output frames the limiter bent (above the knee)

    @property
    def delay(self):
        """The lookahead, in output frames."""
        return self.gate.length * self.rate / self.haptic_rate

    def next_frame(self):
        """The output frame at which the next block's first sample will be heard."""
        return int(round((self.taken + self.gate.length) * self.rate / self.haptic_rate))

    def _finish(self, samples):
        out = self.gain.apply(self.tone.mix(samples))
        self.limited += int(np.count_nonzero(np.abs(out) > KNEE))
        soft_limit(out)
        self.emitted += out.shape[0]
        return out

    def process(self, audio, sounding=True, cut=False):
        self.taken += audio.shape[0]
        gated = self.gate.process(self.stimulus_gain * np.asarray(audio, dtype=np.float64), sounding, cut)
        return self._finish(self.resampler.process(gated))

    def silence(self, n):
        """``n`` haptic samples of nothing (a page: no loop); the tone still plays."""
        return self.process(np.zeros(int(n)), sounding=False)

    def flush(self):
        """The end of the stream: the held-back tail (faded out) and the resampler's last outputs."""
        tail = self.gate.process(np.zeros(self.gate.length), False)
        return self._finish(np.concatenate((self.resampler.process(tail), self.resampler.flush())))


def dbfs(x):
    """20 log10 of a linear level (-inf for 0)."""
    return 20.0 * math.log10(x) if x > 0 else -math.inf
