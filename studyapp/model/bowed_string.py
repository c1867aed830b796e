"""Smith's digital-waveguide bowed string, STK ``Bowed``-style, with a force output (paper Sec. 3, Fig. 1).

Two delay lines meet at the bow: the bridge side (a fraction ``beta`` of the
loop) and the nut side (``1 - beta``). Each sample

    v_h      = -L(bridge line out) - g_n (nut line out)   incoming waves at the bow
    v_delta  = v_bow - v_h
    u        = rho(v_delta) * v_delta, |u| <= max|rho v| (bow_table.py; 0 when the bow is lifted)
    nut line   <- -L(bridge line out) + u
    bridge line <- -g_n (nut line out) + u

with both ends inverting reflections. The string velocity at the bow is
v_h + u; the wave arriving at the bridge drives the body filter (body.py) for
the audio. The string-on-bow force is F = -G u (bow_table.py derives G from
F_max, eqs. 2, 20).

The losses, shared by the two segments (issue 42, item 7). A string loses
energy all along its length (internal friction, air), so a wave's DC gain
over a path is loss^(path / round trip). STK lumps the whole round trip's
``loss`` into the bridge filter L, which is exact only while the string is
linear: filters commute through the delay lines, and "nut-side losses may be
moved to the bridge side as an additional approximation step" (J. O. Smith,
"Virtual acoustic musical instruments: review and update", J. New Music
Research 33(3), 2004, Sec. "Bowed strings"; Serafin's bowed string keeps a
filter on the nut side: S. Serafin, "The sound of friction", PhD thesis,
Stanford 2004). The bow junction is not linear: while the bow sticks it
reflects -rho = -0.98 of each incoming wave and passes 1 - rho = 0.02, so it
splits the loop in two (McIntyre, Schumacher and Woodhouse, "On the
oscillations of musical instruments", JASA 74(5), 1983, give each
termination of the bowed string its own lossy reflection function). With all
the loss at the bridge the nut segment then rings at f0 / (1 - beta) with a
round-trip gain of rho = 0.98 only: 20 f0 / (1 - beta) log10(0.98) = -127 dB/s
at f0 440 Hz, slower than the whole string's own decay
20 f0 log10(loss) = -196 dB/s, and a bowed string cannot do that: a bow held
on it adds a loss, never removes one. Between strokes the participant heard
it as a second pitch, 12 dB under the note at 2 N and, fed by the haptic
loop, growing above it from 5 N (docs/model.md, "The string between
strokes"). So each segment keeps its share:

    g_n = loss^(1 - beta)                      nut reflection (a gain: no phase, the pitch is unchanged)
    L(z) = loss^beta (1 - p) / (1 - p z^-1)    bridge reflection

The free string's round trip g_n L(z) is STK's loss (1 - p) / (1 - p z^-1)
exactly (bit for bit it is not: the product is rounded in two places), and a
pinned nut segment decays at 20 f0 / (1 - beta) log10(rho g_n)
= -196 - 127 = -323 dB/s: the string's own loss plus the bow's.
``nut_loss=False`` gives STK's lumped form (for the figures that compare).

What is derived from the sample rate, and why:

- Loss filter. STK uses a one-pole low-pass with gain 0.95 and pole
  0.75 - 0.2 * 22050 / rate: designed for 22.05-44.1 kHz, its pole crosses zero
  at 5.88 kHz and turns negative below (a high-pass tilt, not a string loss).
  Here L(z) = loss * (1 - p) / (1 - p z^-1) with p = exp(-2 pi f_loss / rate):
  the same analog prototype (DC gain ``loss``, corner ``f_loss`` Hz) at every
  rate. The default f_loss = 2.1 kHz is STK's own corner at its design rate
  22.05 kHz (p = 0.55), so at that rate the two agree.
- Pitch. The loop delay at f0 must be rate / f0 samples: the two lines' delays
  plus the loss filter's phase delay at f0 (computed exactly, not STK's
  "minus 4 samples"). The lines are read with linear interpolation (STK's
  ``DelayL``), whose phase delay at low frequency equals its fraction, so the
  pitch is right at any rate as long as each line keeps at least one sample
  (rate / f0 >= about 10; below that the lines are clamped and the pitch is sharp).

All velocities here are string units (STK's scale, where the bow sticks for
|v_delta| below about 0.085 at slope 3); the loop converts from m/s.
"""

import math
from dataclasses import dataclass

import numpy as np
from numba import njit

from studyapp.model import bow_table, calibration

# parameter vector layout
P_DB, P_DN, P_LOSS_B0, P_LOSS_A1, P_SLOPE, P_OFFSET, P_PEAK, P_NUT_GAIN = range(8)
N_PARAMS = 8
# state vector layout
S_WRITE, S_LOSS_Y = range(2)
N_STATE = 2

MIN_LINE_DELAY = 1.0


@dataclass(frozen=True)
class StringDesign:
    """The string's parameters at one sample rate; ``params()`` packs them for the compiled loop."""

    rate: float
    f0: float
    beta: float = calibration.BOW_POSITION  # STK's Bowed has 0.127236; calibration.py says why not here
    slope: float = 3.0  # STK BowTable slope (bow pressure)
    offset: float = 0.0
    loss: float = 0.95  # STK stringFilter_ gain: the round trip's DC gain
    f_loss: float = 2100.0  # Hz, STK's loss corner at its design rate 22.05 kHz
    nut_loss: bool = True  # the nut segment keeps its share loss^(1 - beta) (docstring); False: STK's lumped form

    def __post_init__(self):
        if not (0.0 < self.beta < 1.0):
            raise ValueError(f"beta = {self.beta}: allowed is 0 < beta < 1")
        if not (self.f0 > 0.0 and math.isfinite(self.f0)):
            raise ValueError(f"f0 = {self.f0}: allowed is a positive frequency")

    @property
    def pole(self):
        return math.exp(-2.0 * math.pi * self.f_loss / self.rate)

    def loss_phase_delay(self, f):
        """Phase delay (samples) of the loss filter at ``f`` Hz."""
        w = 2.0 * math.pi * f / self.rate
        p = self.pole
        return math.atan2(p * math.sin(w), 1.0 - p * math.cos(w)) / w

    def line_delays(self):
        """(bridge-side delay, nut-side delay) in samples, each at least ``MIN_LINE_DELAY``."""
        total = self.rate / self.f0 - self.loss_phase_delay(self.f0)
        return (max(MIN_LINE_DELAY, self.beta * total), max(MIN_LINE_DELAY, (1.0 - self.beta) * total))

    def buffer_length(self):
        db, dn = self.line_delays()
        return int(math.ceil(max(db, dn))) + 2

    def params(self):
        db, dn = self.line_delays()
        p = self.pole
        out = np.zeros(N_PARAMS)
        out[P_DB], out[P_DN] = db, dn
        nut_share = (1.0 - self.beta) if self.nut_loss else 0.0
        out[P_LOSS_B0] = self.loss ** (1.0 - nut_share) * (1.0 - p)
        out[P_NUT_GAIN] = self.loss ** nut_share
        out[P_LOSS_A1] = p
        out[P_SLOPE], out[P_OFFSET] = self.slope, self.offset
        out[P_PEAK] = self.peak_friction()
        return out

    def peak_friction(self):
        """max |rho(v) v| in string units: F_max = G * this (eq. 20)."""
        return bow_table.peak_friction(self.slope, self.offset)

    def new_state(self):
        """(state vector, bridge-side line, nut-side line), all at rest."""
        n = self.buffer_length()
        return np.zeros(N_STATE), np.zeros(n), np.zeros(n)


@njit(cache=True, inline="always")
def read_line(buf, write, delay):
    """The value written ``delay`` samples ago (linear interpolation), ``1 <= delay <= len(buf) - 2``."""
    n = buf.shape[0]
    i = int(delay)
    frac = delay - i
    ia = write - i
    if ia < 0:
        ia += n
    ib = ia - 1
    if ib < 0:
        ib += n
    a = buf[ia]
    return a + frac * (buf[ib] - a)


@njit(cache=True, inline="always")
def step(p, s, bridge, nut, v_bow, bowing):
    """One sample of the string; returns ``(u, v_string, v_bridge, v_delta)``.

    ``u = rho(v_delta) v_delta`` is the junction's added wave (the friction
    force is -G u); ``v_string`` the string velocity at the bow; ``v_bridge``
    the wave arriving at the bridge (the body filter's input).
    """
    write = int(s[S_WRITE])
    v_bridge = read_line(bridge, write, p[P_DB])
    y = p[P_LOSS_B0] * v_bridge + p[P_LOSS_A1] * s[S_LOSS_Y]
    s[S_LOSS_Y] = y
    bridge_refl = -y
    nut_refl = -p[P_NUT_GAIN] * read_line(nut, write, p[P_DN])
    v_h = bridge_refl + nut_refl
    v_delta = v_bow - v_h
    u = 0.0
    if bowing:
        u = bow_table.friction(v_delta, p[P_SLOPE], p[P_OFFSET], p[P_PEAK])
    nut[write] = bridge_refl + u
    bridge[write] = nut_refl + u
    write += 1
    s[S_WRITE] = 0 if write == bridge.shape[0] else write
    return u, v_h + u, v_bridge, v_delta


@njit(cache=True)
def run(p, s, bridge, nut, v_bow, bowing, u_out, v_out, bridge_out):
    """The string alone, driven by a bow velocity array (for tests and figures)."""
    for k in range(v_bow.shape[0]):
        u, vs, vb, vd = step(p, s, bridge, nut, v_bow[k], bowing)
        u_out[k] = u
        v_out[k] = vs
        bridge_out[k] = vb
