"""One device path: the loop drives any HapticDevice through ``exchange``; the simulated device's
compiled block equals its own read_sensors / write_force, sample by sample."""

import numpy as np
import pytest

from studyapp.errors import ParameterError
from studyapp.model.bow_table import table
from studyapp.model.device import DeviceLimits, HapticDevice
from studyapp.model.loop import OUTPUTS, ClosedLoop, LoopConfig
from studyapp.model.simulated_device import SimulatedDevice
from studyapp.model.sources import LVT_SENSOR, TRUE

RATE = 5000.0


class PureMass(HapticDevice):
    """A minimal driver: a free mass (no stops, no hand) under the command plus a constant ``push`` (N),
    moved exactly over each held sample, with ideal sensors (no noise, no lag, no quantisation)."""

    def __init__(self, rate, mass, x0=0.0, v0=0.0, push=0.0):
        self.rate = rate
        self.limits = DeviceLimits()
        self.mass, self.push = mass, push
        self.x, self.v, self.a = x0, v0, 0.0

    def read_sensors(self):
        return self.x, self.a, self.v

    def write_force(self, force):
        t = 1.0 / self.rate
        self.a = (force + self.push) / self.mass
        self.x += self.v * t + 0.5 * self.a * t * t
        self.v += self.a * t


def test_a_pure_mass_without_force_moves_as_the_closed_form():
    """F_max = 0: only the constant push acts, x = x0 + v0 t + F t^2 / (2 m) at every sample."""
    x0, v0, push, mass = 0.002, 0.03, 0.4, 0.5
    dev = PureMass(RATE, mass, x0, v0, push)
    loop = ClosedLoop(LoopConfig(rate=RATE, fmax=0.0, source=LVT_SENSOR, estimators={"LOWPASS": {}}), device=dev)
    block = loop.run(3000)
    t = np.arange(3000) / RATE
    np.testing.assert_allclose(block["position"], x0 + v0 * t + push * t ** 2 / (2 * mass), rtol=0, atol=1e-12)
    np.testing.assert_allclose(block["velocity_lvt"], v0 + push * t / mass, rtol=0, atol=1e-12)
    assert np.all(block["force"] == 0.0)
    # a driver knows no true motion: those columns are NaN, and the source TRUE is refused
    assert np.all(np.isnan(block["velocity_true"])) and np.all(np.isnan(block["hand_force"]))
    with pytest.raises(ParameterError, match="source 'TRUE' needs the simulated device"):
        loop.set_source(TRUE)
    # the observing estimator saw the same stream
    assert np.all(np.isfinite(block["estimates"])) and block["estimates"].shape == (1, 3000)


def test_a_bowed_pure_mass_gets_the_friction_law_and_the_string_its_pitch(fft_peak):
    """A heavy mass at a bowing speed: F = -G rho(v_delta) v_delta every sample, the string at f0."""
    fmax = 2.0
    dev = PureMass(RATE, mass=1000.0, v0=0.04)
    loop = ClosedLoop(LoopConfig(rate=RATE, fmax=fmax, source=LVT_SENSOR), device=dev)
    block = loop.run(int(1.0 * RATE))
    vd = block["v_delta"]
    np.testing.assert_allclose(block["force"], -fmax / loop.string.peak_friction() * table(vd) * vd,
                               rtol=1e-12, atol=1e-15)
    assert np.abs(block["force"]).max() == pytest.approx(fmax, rel=0.02)
    settled = block["string_velocity"][int(0.2 * RATE):]
    assert fft_peak(settled, RATE) == pytest.approx(loop.string.f0, rel=0.01)


class PerSample(SimulatedDevice):
    """The simulated device driven as a real driver is: the interface's own exchange."""

    exchange = HapticDevice.exchange


@pytest.mark.parametrize("source", ["KALMAN", "TRUE"])
def test_simulated_device_block_equals_its_read_and_write(source):
    config = LoopConfig(rate=RATE, estimators={"KALMAN": {}, "LOWPASS": {}}, source=source, fmax=3.0,
                        gesture="strokes", seed=4)
    runs = []
    for cls in (SimulatedDevice, PerSample):
        loop = ClosedLoop(config, device=cls(RATE, seed=4, accelerometer=True))
        parts = [loop.run(n) for n in (1500, 700)]
        runs.append({k: np.concatenate([p[k] for p in parts], axis=-1) for k in list(OUTPUTS) + ["estimates"]})
    fast, slow = runs
    assert np.std(fast["force"]) > 0.1  # the string was bowed
    for key in fast:
        np.testing.assert_allclose(slow[key], fast[key], rtol=0, atol=1e-12, err_msg=key)


def test_the_loop_refuses_an_object_that_is_not_a_device():
    class Duck:
        rate = RATE
        limits = DeviceLimits()

        def read_sensors(self):
            return 0.0, 0.0, 0.0

        def write_force(self, force):
            pass

    with pytest.raises(ParameterError, match="HapticDevice"):
        ClosedLoop(LoopConfig(rate=RATE), device=Duck())


def test_a_fault_the_device_reports_is_latched_and_the_force_held_at_0():
    class Failing(PureMass):
        @property
        def fault(self):
            return "amplifier over temperature" if self.x > 0.001 else None

    dev = Failing(RATE, mass=1000.0, v0=0.04)
    loop = ClosedLoop(LoopConfig(rate=RATE, fmax=2.0, source=LVT_SENSOR), device=dev)
    first = loop.run(500)  # reaches 1 mm at 0.025 s, inside this block
    assert np.any(first["force"] != 0.0)
    assert loop.fault is not None and "amplifier over temperature" in loop.fault
    assert np.all(loop.run(500)["force"] == 0.0)


def test_a_non_finite_accelerometer_sample_latches_the_fault_and_leaves_the_sound_finite():
    """A real device's bad accelerometer sample faults the loop; the contact microphone (which hears the
    accelerometer on a real device) must not keep that NaN in its state and silence the audio for good."""
    class Glitch(PureMass):
        def __init__(self, *args, **kwargs):
            super().__init__(*args, **kwargs)
            self.reads = 0

        def read_sensors(self):
            self.reads += 1
            x, a, v = super().read_sensors()
            return x, (float("nan") if self.reads == 200 else a), v

    loop = ClosedLoop(LoopConfig(rate=RATE, fmax=2.0, source=LVT_SENSOR), device=Glitch(RATE, mass=1.0, v0=0.02))
    out = loop.run(1000)
    assert loop.fault is not None and "a sensor sample" in loop.fault
    assert np.all(out["force"][199:] == 0.0)
    assert np.all(np.isfinite(out["audio"]))
    assert np.any(out["audio"][199:] != 0.0)  # the string rings on after the bow is lifted
