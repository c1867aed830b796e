"""Extremes: F_max 0 and 50 N, 1 kHz and 96 kHz, the hand driven into the end stops, faults."""

import numpy as np
import pytest

from studyapp.errors import ParameterError
from studyapp.estimators import create
from studyapp.model.device import DeviceLimits, HapticDevice
from studyapp.model.loop import OUTPUTS, ClosedLoop, LoopConfig

ALL_BUT_LVT = ["BDIFF", "LOWPASS", "LEASTSQ", "FOAW", "LEVANT", "LEVANTLP", "KALPOS", "KALMAN", "KALLEV",
               "KALLEVACC", "KALFOAW", "KALFOAWACC", "COMP1", "COMP2"]


def finite(block):
    for key in OUTPUTS:
        assert np.all(np.isfinite(block[key])), key
    assert np.all(np.isfinite(block["estimates"]))


@pytest.mark.parametrize("rate", [1000.0, 96000.0])
@pytest.mark.parametrize("fmax", [0.0, 50.0])
@pytest.mark.parametrize("source", ["TRUE", "LEVANT"])
def test_extreme_rates_and_gains_stay_finite_and_clamped(rate, fmax, source):
    f0 = 150.0 if rate < 2640.0 else None  # the string plays f0 <= rate / 6 (playable.py)
    loop = ClosedLoop(LoopConfig(rate=rate, fmax=fmax, source=source, estimators={"LEVANT": {}}, f0=f0))
    block = loop.run(int(0.3 * rate))
    finite(block)
    assert np.abs(block["force"]).max() <= min(fmax, 200.0) + 1e-12
    assert loop.fault is None
    if fmax == 0.0:
        assert np.all(block["force"] == 0.0)


def test_every_estimator_at_the_extremes():
    for rate in (1000.0, 96000.0):
        # Table 1's defaults that exist at this rate (COMP2's 2.25 kHz cut-off does not at 1 kHz)
        usable = []
        for name in ALL_BUT_LVT:
            try:
                create(name, rate)
            except ParameterError:
                continue
            usable.append(name)
        assert len(usable) >= 13
        loop = ClosedLoop(LoopConfig(rate=rate, fmax=50.0, source="KALMAN", estimators=usable,
                                     f0=150.0 if rate < 2640.0 else None))
        block = loop.run(int(0.05 * rate))
        finite(block)
        assert np.abs(block["force"]).max() <= 50.0 + 1e-12


def test_hand_driven_into_the_end_stops():
    rate = 5000.0
    t = np.arange(int(0.6 * rate)) / rate
    swing = 0.03 * np.sin(2 * np.pi * 2.0 * t)  # +-30 mm: far past the +-11 mm stops
    loop = ClosedLoop(LoopConfig(rate=rate, fmax=12.1, source="LVT", gesture="playback", trajectory=swing))
    block = loop.run(t.size)
    finite(block)
    x = block["position_true"]
    assert x.max() == pytest.approx(0.011) and x.min() == pytest.approx(-0.011)
    assert np.all(np.abs(x) <= 0.011)
    assert np.abs(block["force"]).max() <= 12.1 + 1e-12
    # at a stop the velocity into it is zero
    v = block["velocity_true"]
    assert np.all(v[1:][x[1:] >= 0.011] <= 0.0) and np.all(v[1:][x[1:] <= -0.011] >= 0.0)


def test_bad_settings_are_one_line_errors():
    loop = ClosedLoop(LoopConfig())
    with pytest.raises(ParameterError, match="source 'KALMAN' is not an active estimator"):
        loop.set_source("KALMAN")
    with pytest.raises(ParameterError, match="unknown source"):
        loop.set_source("FOO")
    with pytest.raises(ParameterError, match="fmax"):
        loop.set_fmax(-1)
    with pytest.raises(ParameterError, match="fmax"):
        loop.set_fmax(float("nan"))
    with pytest.raises(ParameterError, match="unknown gesture"):
        loop.set_gesture("waltz")
    with pytest.raises(ParameterError, match="rate"):
        ClosedLoop(LoopConfig(rate=500.0))
    with pytest.raises(ParameterError, match="hand target"):
        loop.set_hand_target(float("inf"))


def test_live_target_and_settings_at_block_boundaries():
    loop = ClosedLoop(LoopConfig(fmax=1.0, source="LVT", gesture="hold"))
    loop.run(1000)
    loop.set_hand_target(0.005)
    loop.run(5000)
    block = loop.run(2500)
    assert np.mean(block["position_true"]) == pytest.approx(0.005, abs=3e-4)
    loop.set_fmax(3.0)
    loop.set_source("TRUE")
    block = loop.run(2500)
    np.testing.assert_array_equal(block["source_velocity"], block["velocity_true"])
    assert loop.fmax == 3.0


class FakeDevice(HapticDevice):
    """A free mass (no hand), read and written one sample at a time like a real driver."""

    def __init__(self, rate, mass=0.5, bad_after=None):
        self.rate = rate
        self.limits = DeviceLimits()
        self.mass = mass
        self.x, self.v, self.f = 0.0, 0.02, 0.0
        self.samples = 0
        self.bad_after = bad_after
        self.forces = []

    def read_sensors(self):
        self.samples += 1
        if self.bad_after is not None and self.samples > self.bad_after:
            return float("nan"), 0.0, float("nan")
        return self.x, 0.0, self.v

    def write_force(self, force):
        self.forces.append(force)
        self.v += force / self.mass / self.rate
        self.x += self.v / self.rate


def test_external_device_runs_through_the_interface():
    dev = FakeDevice(5000.0)
    loop = ClosedLoop(LoopConfig(fmax=1.0, source="LVT", estimators={"LOWPASS": {}}), device=dev)
    block = loop.run(2000)
    assert dev.samples == 2000 and len(dev.forces) == 2000
    np.testing.assert_array_equal(block["force"], dev.forces)
    assert 0.5 < np.abs(block["force"]).max() <= 1.0  # the friction brakes the mass thrown at 0.02 m/s
    with pytest.raises(ParameterError, match="TRUE"):
        loop.set_source("TRUE")


def test_non_finite_input_latches_a_fault_and_zero_force():
    dev = FakeDevice(5000.0, bad_after=500)
    loop = ClosedLoop(LoopConfig(fmax=1.0, source="LVT"), device=dev)
    block = loop.run(1000)
    assert loop.fault is not None and "t = 0.1000 s" in loop.fault
    assert np.all(block["force"][500:] == 0.0)
    assert np.all(np.isfinite(block["audio"])) and np.all(np.isfinite(block["string_velocity"]))
    dev.bad_after = None  # good data again: the fault stays latched
    block = loop.run(500)
    assert loop.fault is not None and np.all(block["force"] == 0.0)
