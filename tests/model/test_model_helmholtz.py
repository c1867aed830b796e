"""Helmholtz motion: with TRUE velocity in the loop the bow sticks and slips once per string period."""

import numpy as np
import pytest

from studyapp.model import bow_table, calibration

from .conftest import bow, slip_onsets


@pytest.mark.parametrize("fmax,source", [(1.0, "TRUE"), (2.0, "TRUE"), (4.0, "LVT")])
def test_one_stick_and_one_slip_per_period(fmax, source):
    rate = 5000.0
    # one stroke from -9 mm at the strokes' 0.15 m/s (issue 20: the paper's pace), 15 mm long
    loop, block = bow(rate, fmax=fmax, source=source, duration=0.12, speed=calibration.STROKE_SPEED)
    period = rate / loop.string.f0
    # after the attack (30 ms ramp): Helmholtz motion forms within 10 ms at these gains (docs/model.md)
    steady = slice(int(0.04 * rate), None)
    stick = block["stick"][steady]
    # a slip shorter than a quarter of the Helmholtz slip (beta * period) is a ripple, not a slip
    onsets = slip_onsets(stick, max(1.0, 0.25 * loop.string.beta * period))
    intervals = np.diff(onsets) / period
    assert onsets.size >= 0.06 * rate / period
    # one slip per period, but for a rare double slip (the light end-effector rides on the slips)
    assert np.mean(np.abs(intervals - 1.0) <= 0.06) >= 0.9
    # each period has a stick phase in which bow and string move together:
    # the relative velocity is (1 - rho) v_delta, at most 2% of the breakaway velocity
    scale = loop.velocity_scale
    rel = (block["source_velocity"] - block["string_velocity"])[steady] * scale
    bow_speed = np.median(block["source_velocity"][steady]) * scale
    for a, b in zip(onsets[:-1], onsets[1:]):
        sticking = stick[a:b] > 0.5
        if abs((b - a) / period - 1.0) > 0.06:
            continue
        assert sticking.sum() >= 2  # 3 of 11.4 samples at 0.15 m/s (2.6 breakaway speeds; docs/model.md)
        assert np.max(np.abs(rel[a:b][sticking])) <= 0.02 * bow_table.breakaway(3.0) + 1e-12
        # ... and small next to the slip's relative velocity, about v_bow / beta
        assert np.max(np.abs(rel[a:b][sticking])) < 0.05 * np.max(np.abs(rel[a:b]))
    # the slip is the Helmholtz flyback: the string moves backwards at about v_bow (1 - beta) / beta
    vs = block["string_velocity"][steady] * scale
    beta = loop.string.beta
    # (at 0.15 m/s the light end-effector rides on the slips and the flyback overshoots it by up to 45 %)
    assert np.min(vs) == pytest.approx(-bow_speed * (1 - beta) / beta, rel=0.5)
