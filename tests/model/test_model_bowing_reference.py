"""The bowing reference's table is what it was before it was made lighter (issue 30, item 4).

bowing_reference.table now runs TRUE a block at a time and takes its pitch on
a transform of at most 2^18 points (``TABLE_POINTS``), to keep a short
``studyapp simulate`` at 96 kHz under 200 MB. The pitch decides only whether
TRUE is still within stability.PITCH_TOLERANCE of f0; the table must come out
the same as with the 4x padded pitch on the whole run, bit for bit.
"""

import numpy as np
import pytest

from studyapp.model import bowing_reference, stability
from studyapp.model.loop import ClosedLoop, LoopConfig


def _padded_true_run(rate, f0, gesture, fmax, duration=bowing_reference.DURATION, seed=0):
    """TRUE's run as the table took it before: one block, the pitch 4x padded."""
    loop = ClosedLoop(LoopConfig(rate=rate, estimators={}, source="TRUE", fmax=fmax, gesture=gesture, f0=f0,
                                 seed=seed, audio=False), judge=False)
    block = loop.run(int(round(duration * loop.rate)))
    start = int(round(bowing_reference.SETTLE * loop.rate))
    return (stability.band_level(block["velocity_true"], loop.rate, start),
            stability.hiss_level(block["velocity_true"], loop.rate, start),
            bowing_reference.pitch(block["string_velocity"][start:], loop.rate))


@pytest.mark.slow
@pytest.mark.parametrize("rate, f0", [(5000.0, 800.0), (48000.0, 440.0)])
def test_the_table_equals_the_padded_one(rate, f0, monkeypatch):
    log_f, *light = bowing_reference.table.__wrapped__(rate, f0, "strokes")
    monkeypatch.setattr(bowing_reference, "true_run", _padded_true_run)
    _, *padded = bowing_reference.table.__wrapped__(rate, f0, "strokes")
    for a, b in zip(light, padded):  # the buzz band's levels, the upper band's (None where the rate has none)
        assert (a is None and b is None) or np.array_equal(a, b)
    assert np.array_equal(log_f, np.log(np.array(bowing_reference.GRID)))


def test_pitch_finds_a_tone_on_a_capped_transform():
    rate = 96000.0
    t = np.arange(int(2.25 * rate)) / rate
    x = np.sin(2 * np.pi * 146.83 * t) + 0.3 * np.sin(2 * np.pi * 2 * 146.83 * t)
    for points in (None, bowing_reference.TABLE_POINTS, 16):  # 16: no fewer than the samples
        assert bowing_reference.pitch(x, rate, max_points=points) == pytest.approx(146.83, abs=0.05)
