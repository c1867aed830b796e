"""Which sample rates the waveguide string can play: rate >= RATE_PER_F0_MIN x f0 (= 6 f0).

The string (bowed_string.py) is a loop of rate / f0 samples: two delay lines
meeting at the bow (the bridge side beta = 0.25 of the loop, the nut side the
rest), read with linear interpolation, and a one-pole loss filter at the
bridge. The line delays are set so that the loop's phase delay at f0 is
rate / f0, taking the interpolators' phase delay as their fraction, which is
exact only at low frequency. At w0 = 2 pi f0 / rate the linear interpolator
with fraction d has phase delay atan(d sin w0 / (1 - d + d cos w0)) / w0, not
d, and gain |1 - d + d e^(-j w0)| down to cos(w0 / 2) at d = 0.5:

- rate / f0 below about 6: the pitch error of the two interpolators reaches
  the 1 % a listener hears as out of tune (the fundamental's phase alone puts
  it at -1.5 % at rate / f0 = 4.5 and +0.7 % at 5.5; bowed, with the
  harmonics' own detuning, -2 % and +1.2 %: measured below);
- at rate / f0 = 4 the bridge line is down to 1 sample (its floor,
  MIN_LINE_DELAY) and only f0 and 2 f0 lie below Nyquist, both damped by the
  interpolators (round-trip gain at f0 about 0.45 at 5 kHz): Helmholtz motion
  does not form and the strongest peak lies elsewhere (1 kHz with 440 Hz, a
  ratio of 2.3, peaks at 106 Hz; 5 kHz with 2000 Hz likewise).

Measured (2026-11-27; TRUE bowed on the strokes at F_max 1, 5 and 10 N, seed 0,
2 s; the string velocity's spectral peak per stroke cruise, median over the
cruises; /tmp scripts summarised in docs/model.md "Rates the string plays"):
within 1 % for every ratio from 5.75 to 9 at 1, 2, 5 and 10 kHz (and 10-480
up to 48 kHz); -1.6 to -2.0 % at 4.5, +1.0 to +1.2 % at 5.5, at 1 and 5 kHz;
4 or below: no f0 at all. 6 keeps a margin above the last failure (5.5).
"""

from studyapp.errors import ParameterError
from studyapp.model.limits import RATE_PER_F0_MIN


def min_rate(f0):
    """The lowest sample rate (Hz) at which the string plays ``f0`` Hz."""
    return RATE_PER_F0_MIN * float(f0)


def check_playable(rate, f0):
    """``ParameterError`` (one line naming rate, f0 and the bound) unless rate >= RATE_PER_F0_MIN x f0."""
    rate, f0 = float(rate), float(f0)
    if rate < min_rate(f0):
        raise ParameterError(
            f"rate {rate:g} Hz with f0 {f0:g} Hz: the string sounds at f0 only at rate >= {RATE_PER_F0_MIN:g} x f0 "
            f"= {min_rate(f0):g} Hz: allowed is a rate of at least {min_rate(f0):g} Hz or an f0 of at most "
            f"{rate / RATE_PER_F0_MIN:g} Hz")
    return rate, f0
