"""Force output: never above F_max nor the motor limits; the peak friction force is F_max."""

import numpy as np
import pytest
from numba import njit

from studyapp.model import device
from studyapp.model.loop import ClosedLoop, LoopConfig

from .conftest import bow


@pytest.mark.parametrize("fmax,source", [(0.3, "TRUE"), (3.0, "TRUE"), (3.0, "LVT"), (12.1, "LVT")])
def test_force_bounded_by_fmax_and_peak_equals_fmax(fmax, source):
    loop = ClosedLoop(LoopConfig(fmax=fmax, source=source, gesture="strokes", audio=False))
    block = loop.run(int(2.0 * loop.rate))
    force = np.abs(block["force"])
    assert force.max() <= fmax * (1 + 1e-12)
    # the friction force reaches its peak every time the bow breaks away
    assert force.max() == pytest.approx(fmax, rel=0.02)


def test_friction_curve_is_the_bow_table_scaled_by_g():
    loop, block = bow(5000.0, fmax=2.0, duration=0.3)
    from studyapp.model.bow_table import table

    vd = block["v_delta"]
    expected = -2.0 / loop.string.peak_friction() * table(vd) * vd
    np.testing.assert_allclose(block["force"], expected, rtol=1e-12, atol=1e-15)


def test_force_scale_and_bowing_switches():
    loop = ClosedLoop(LoopConfig(fmax=5.0, source="TRUE", audio=False))
    loop.run(2000)
    loop.set_force_scale(0.25)
    b = loop.run(5000)
    assert np.abs(b["force"]).max() <= 0.25 * 5.0 + 1e-12
    assert np.abs(b["force"]).max() == pytest.approx(0.25 * 5.0, rel=0.03)
    loop.set_force_scale(7.0)  # clipped to 1
    assert loop.force_scale == 1.0
    loop.set_bowing(False)
    b = loop.run(1000)
    assert np.all(b["force"] == 0.0) and np.all(b["stick"] == 0.0)


@njit(cache=True)
def _hold_command(p, s, command, n, out):
    for k in range(n):
        out[k] = device.clamp_force(p, s, command)


def test_motor_limits_impulsive_and_sustained():
    rate = 5000.0
    limits = device.DeviceLimits()
    p, s = limits.params(rate), np.zeros(device.N_LIMIT_STATE)
    out = np.empty(int(5 * rate))
    _hold_command(p, s, 500.0, out.size, out)
    assert out[0] == 200.0  # impulsive limit
    # the mean square of F climbs as 200^2 (1 - exp(-t / tau)) until its root passes 60 N
    t_switch = -limits.sustained_window * np.log(1.0 - (60.0 / 200.0) ** 2)
    first_60 = np.argmax(out < 200.0) / rate
    assert first_60 == pytest.approx(t_switch, abs=2.0 / rate)
    # from then on the RMS stays at the sustained limit
    tail = out[int(3 * rate):]
    assert np.sqrt(np.mean(tail ** 2)) == pytest.approx(60.0, rel=0.02)
    assert tail.max() <= 200.0
