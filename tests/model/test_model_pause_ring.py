"""Between strokes the stuck bow must not leave the nut segment ringing as a second pitch (issue 42, item 7).

bowed_string.py gives each segment its share of the string's loss; before
(STK's losses lumped at the bridge) the nut segment, pinned by the stuck
bow, rang at f0 / (1 - beta) with a round-trip gain of rho = 0.98 alone.
"""

import numpy as np
import pytest

from studyapp.model import bowed_string, stability
from studyapp.model.bowed_string import P_DN, P_NUT_GAIN, StringDesign
from studyapp.model.calibration import F0
from studyapp.model.pause_ring import amplitude, ring_levels, run_strokes
from studyapp.model.string_pitch import cruise_pitch

RHO_STUCK = 0.98  # bow_table.RHO_MAX: the stuck bow's reflection

# X: a nut segment pinned by the stuck bow, starting at the bowed note's level and decaying by its share of
# the loss and the bow's reflection alone (20 f_ring log10(rho g_n) = 323 dB/s at 5 kHz, bowed_string.py),
# averages 13.6 dB under the note over a pause (Hann-weighted, 95 ms): the closed loop must add nothing to it
PAUSE = 0.095  # s: the dwell less pause_ring.SETTLE


def ring_margin_db(rate, f0=F0):
    design = StringDesign(rate, f0)
    f_ring = rate / design.params()[P_DN]
    decay = -20.0 * f_ring * np.log10(RHO_STUCK * design.params()[P_NUT_GAIN])
    n = int(PAUSE * rate)
    w = np.hanning(n)
    return -20.0 * np.log10(np.sum(w * 10.0 ** (-decay * np.arange(n) / rate / 20.0)) / np.sum(w))


def pinned_decay(design, seconds=0.6):
    """(dB/s, Hz) of the nut segment's ring in the string alone, bowed for 0.3 s and then held still (v_bow = 0)."""
    rate = design.rate
    state, bridge, nut = design.new_state()
    n = int(seconds * rate)
    v_bow = np.where(np.arange(n) < int(0.3 * rate), 0.18, 0.0)
    u, v, b = np.zeros(n), np.zeros(n), np.zeros(n)
    bowed_string.run(design.params(), state, bridge, nut, v_bow, True, u, v, b)
    f_ring = rate / design.params()[P_DN]
    m = int(0.02 * rate)
    start = int(0.31 * rate)
    levels = [20 * np.log10(amplitude(u[i:i + m], rate, 0.9 * f_ring, 1.1 * f_ring)[0])
              for i in range(start, start + 10 * m, m)]
    return -np.polyfit(np.arange(len(levels)) * m / rate, levels, 1)[0], f_ring


@pytest.mark.parametrize("rate", [5000.0, 48000.0])
def test_a_pinned_nut_segment_decays_by_its_share_of_the_loss_and_the_bow(rate):
    """Closed form: a round trip of 1 / f_ring s multiplies the ring by rho g_n |H(f_ring)| (rho: the stuck bow;
    H(z) = 1 - d + d z^-1, the nut line's linear interpolation at its fraction d, a loss of the discretisation)."""
    design = StringDesign(rate, F0)
    measured, f_ring = pinned_decay(design)
    d = design.params()[P_DN] % 1.0
    interpolation = abs(1.0 - d + d * np.exp(-2j * np.pi * f_ring / rate))
    expected = -20.0 * f_ring * np.log10(RHO_STUCK * design.params()[P_NUT_GAIN] * interpolation)
    assert measured == pytest.approx(expected, rel=0.1), (measured, expected)
    # and faster than the whole free string's own decay, 20 f0 log10(loss): a held bow adds a loss
    assert measured > -20.0 * F0 * np.log10(design.loss)


@pytest.mark.parametrize("rate,source,seeds", [(5000.0, "LVT", (40, 41, 42)), (48000.0, "TRUE", (0,))])
def test_no_second_pitch_between_strokes(rate, source, seeds):
    """In every pause of the strokes at 2 N (below every condition's breakdown) the ring at f0 / (1 - beta) stays
    ring_margin_db under the note in the audio, what the participant hears (failed before: LVT -11.7 dB, TRUE at
    48 kHz -8.5 dB). The handle's velocity is reported, not held (docs/model.md): at 720-750 Hz it is above the
    skin's best band."""
    margin = ring_margin_db(rate)
    assert 13.0 < margin < 14.5  # 13.6 dB at 5 kHz (the comment above)
    for seed in seeds:
        block, string = run_strokes(rate, 2.0, seed, source)
        levels, _ = ring_levels(block, rate, string.f0, string.beta)["audio"]
        assert levels.size >= 8
        assert levels.max() < -margin, (source, seed, np.round(levels, 1))


@pytest.mark.parametrize("rate", [5000.0, 48000.0])
def test_the_bowed_pitch_is_still_f0(rate):
    assert abs(cruise_pitch(rate, F0, 2.0) / F0 - 1.0) <= stability.PITCH_TOLERANCE
