"""The device-side safety core on its own, against closed forms: no force unless armed, tagged forces act
at their sample, the ramp k / R, the impulsive and RMS clamps (and model/device.py clamp_force), the
watchdog's ramp to 0 at latency + W + D - 1 samples after the host's last frame, late and corrupt frames."""

import math

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from studyapp.device import messages
from studyapp.device.device_side import LINK_RUN, RING, DeviceSide, SafetyConfig

RATE = 5000
W = 5  # 1 ms
D = 5  # ramp to 0 over 1 ms


def config(**kw):
    base = dict(rate_hz=RATE, impulsive=200.0, sustained=60.0, rms_alpha=1.0 - math.exp(-1.0 / RATE),
                watchdog_ms=1, ramp_ms_min=0)
    return SafetyConfig(**{**base, **kw})


def run(side, n):
    return [side.actuate() for _ in range(n)]


def drive(side, forces):
    """The host answers just in time: each force tagged for the sample about to be actuated."""
    out = []
    for f in forces:
        side.force(side.now, (f,))
        out.append(side.actuate())
    return out


def streaming(latency=2, ramp_ms=0, **kw):
    side = DeviceSide(config(**kw))
    side.start(1, latency)
    side.arm(ramp_ms)
    return side


def test_constants_of_the_config():
    c = config()
    assert (c.watchdog_samples, c.down_samples) == (W, D)
    assert config(rate_hz=48000, watchdog_ms=2).watchdog_samples == 96
    assert config(rate_hz=48000).down_samples == 48


def test_no_force_unless_armed_and_streaming():
    side = DeviceSide(config())
    side.start(1, 0)
    side.force(0, (5.0, 5.0, 5.0))
    assert run(side, 3) == [0.0, 0.0, 0.0]
    side = DeviceSide(config())
    side.arm(0)
    side.force(0, (5.0,))  # not streaming: ignored
    assert run(side, 1) == [0.0]


def test_tagged_forces_act_at_their_sample_and_missing_ones_hold():
    side = streaming(latency=3)
    side.force(3, (1.0, 2.0))
    side.force(6, (4.0,))
    out = run(side, 8)
    assert out == [0.0, 0.0, 0.0, 1.0, 2.0, 2.0, 4.0, 4.0]
    assert side.missing == 2


def test_late_forces_are_dropped_and_counted():
    side = streaming(latency=1)
    side.force(1, (1.0,))
    run(side, 3)
    side.force(1, (9.0, 9.0, 3.0))  # tags 1 and 2 have passed
    assert side.late == 2
    assert run(side, 1) == [3.0]
    assert [r[0] for r in side.reports] == [messages.LATE]


def test_forces_too_far_ahead_are_corrupt():
    side = streaming(latency=1)
    side.force(RING, (1.0,))
    assert side.corrupt == 1


@pytest.mark.parametrize("ramp_ms", [1, 10, 33])
def test_ramp_from_zero_on_arm(ramp_ms):
    side = streaming(latency=0, ramp_ms=ramp_ms)
    r = ramp_ms * RATE // 1000
    n = r + 10
    out = np.array(drive(side, [1.0] * n))
    k = np.arange(n)
    np.testing.assert_array_equal(out, np.minimum(k / r, 1.0))


def test_ramp_min_applies():
    side = streaming(latency=0, ramp_ms=0, ramp_ms_min=2)
    assert side.ramp == 10


def test_impulsive_clamp():
    side = streaming(latency=0)
    side.force(0, (300.0, -250.0, 150.0))
    assert run(side, 3) == [200.0, -200.0, 150.0]
    assert [r[0] for r in side.reports] == [messages.CLAMP]  # once per second at most
    assert side.reports[0][2] == 300000


def test_sustained_rms_closed_form():
    """A constant 100 N: ms_n = 100^2 (1 - (1 - alpha)^n) until it exceeds 60^2, then the clamp is 60 N."""
    side = streaming(latency=0)
    alpha = side.c.rms_alpha
    n_star = math.ceil(math.log(1.0 - 0.36) / math.log(1.0 - alpha))  # first n with ms_n > 3600
    n = n_star + 200
    out = np.array(drive(side, [100.0] * n))
    assert np.all(out[:n_star] == 100.0)  # output n sees ms_n, the mean after n forces
    assert np.all(out[n_star:] == 60.0)  # from above, ms tends to 60^2 and stays above it
    assert messages.SUSTAINED in [r[0] for r in side.reports]


@given(st.lists(st.floats(-400.0, 400.0), min_size=1, max_size=400), st.floats(0.001, 0.05))
@settings(max_examples=30, deadline=None)
def test_clamp_equals_the_models(forces, window):
    from studyapp.model.device import DeviceLimits, clamp_force
    limits = DeviceLimits(sustained=20.0, sustained_window=window)
    p = limits.params(RATE)
    s = np.zeros(1)
    expected = [clamp_force(p, s, f) for f in forces]
    side = streaming(latency=0, sustained=20.0, rms_alpha=p[2], watchdog_ms=1000)
    assert drive(side, forces) == expected


@pytest.mark.parametrize("latency", [1, 2, 5, 20])
def test_watchdog_bound_is_latency_plus_w_plus_d_minus_1(latency):
    """The host answers sensor k with the force tagged k + latency, then stops after sample 50."""
    side = streaming(latency=latency)
    out = []
    last_arrival = None
    for k in range(200):
        if k <= 50:
            side.force(k + latency, (10.0,))
            last_arrival = k
        out.append(side.actuate())
    zero_at = last_arrival + latency + W + D - 1
    expected = np.zeros(200)
    expected[latency:last_arrival + latency + W] = 10.0
    for i in range(D):
        expected[last_arrival + latency + W + i] = 10.0 * (D - 1 - i) / D
    np.testing.assert_allclose(out, expected, rtol=0, atol=1e-12)
    assert out[zero_at] == 0.0 and out[zero_at - 1] > 0.0
    assert (zero_at - last_arrival) / RATE <= latency / RATE + 0.002
    assert side.reports[-1] == (messages.WATCHDOG, zero_at, last_arrival)
    assert not side.armed and side.fault == messages.WATCHDOG
    side.force(side.now + 1, (7.0,))  # latched: no force until ARM
    assert run(side, 3) == [0.0, 0.0, 0.0]
    side.arm(0)
    side.force(side.now, (7.0,))
    assert run(side, 1) == [7.0] and side.fault == 0


def test_watchdog_when_idle_and_keepalive_feeds_it():
    side = DeviceSide(config())
    side.arm(0)
    for _ in range(3):
        run(side, W - 1)
        side.valid_frame(messages.Keepalive())
    out = run(side, W + D)  # the deadline is now + W; 0 at its (D-1)-th sample after
    assert out[-1] == 0.0 and not side.armed and side.reports[-1] == (messages.WATCHDOG, side.now - 1, side.now - W - D)


def test_corrupt_run_disarms_and_disarm_is_immediate():
    side = streaming(latency=0)
    side.force(0, tuple([50.0] * 10))
    assert run(side, 1) == [50.0]
    side.disarm(messages.EMERGENCY_STOP)
    assert run(side, 1) == [0.0]
    side.arm(0)
    for _ in range(LINK_RUN - 1):
        side.corrupt_frame()
    side.valid_frame(messages.Keepalive())
    side.corrupt_frame()
    assert side.armed
    for _ in range(LINK_RUN):
        side.corrupt_frame()
    assert not side.armed and side.fault == messages.LINK_CORRUPT


def test_counter_wraps():
    side = streaming(latency=1)
    side.now = 2**32 - 2
    side.start(1, 1)
    side.arm(0)
    side.force(2**32 - 1, (1.0, 2.0, 3.0))
    assert run(side, 4) == [0.0, 1.0, 2.0, 3.0]
    assert side.now == 2
