"""Safety: a NaN gives zero force and a latched fault; a runaway ramps the force down; clamps hold."""

import numpy as np
import pytest

from studyapp.engine.safety import Safety, SafetyLimits
from studyapp.errors import ParameterError
from studyapp.model.loop import ClosedLoop, LoopConfig
from tests.engine.nan_device import NanDevice

RATE = 5000.0
BLOCK = 10
LOOP_BLOCK = 50  # blocks of the real loop: fewer calls, the same physics


class FakeLoop:
    """Just what Safety touches on a loop, so blocks can be made to order."""

    def __init__(self, rate=RATE, fmax=1.0):
        self.rate = rate
        self.fmax = fmax
        self.fault = None
        self.force_scale = 1.0
        self.scales = []

    def set_force_scale(self, g):
        self.force_scale = g
        self.scales.append(g)


def _block(force, velocity=0.0, n=BLOCK):
    return {
        "force": np.full(n, force, dtype=float), "velocity_true": np.full(n, velocity, dtype=float),
        "source_velocity": np.zeros(n), "position": np.zeros(n), "velocity_lvt": np.zeros(n),
        "string_velocity": np.zeros(n), "estimates": np.zeros((1, n)),
    }


def test_a_nan_from_the_device_zeroes_the_force_from_that_sample_and_latches():
    device = NanDevice(RATE, nan_at=2000)
    loop = ClosedLoop(LoopConfig(rate=RATE, estimators={"LOWPASS": {}}, source="LOWPASS", fmax=2.0), device=device)
    safety = Safety(loop)
    forces, raised = [], []
    for _ in range(400):
        block = loop.run(BLOCK)
        forces.append(block["force"])
        fault = safety.check(block)
        if fault:
            raised.append(fault)
    force = np.concatenate(forces)
    bad = 1999  # the 2000th reading
    assert np.max(np.abs(force[:bad])) > 0.1
    assert np.all(force[bad:] == 0.0)
    assert np.all(np.array(device.forces[bad:]) == 0.0)  # what the driver was told to output
    assert len(raised) == 1 and "non-finite" in raised[0]
    assert safety.latched and loop.force_scale == 0.0
    # the readings recovered long ago, yet the fault holds; clearing cannot undo the loop's own latch
    safety.clear()
    safety.check(loop.run(BLOCK))
    assert safety.latched and loop.force_scale == 0.0
    assert np.all(loop.run(BLOCK)["force"] == 0.0)


@pytest.mark.parametrize("key", ["force", "estimates", "source_velocity"])
def test_a_nan_anywhere_in_a_block_latches_until_cleared(key):
    loop = FakeLoop()
    safety = Safety(loop, motor_limits=(200.0, 60.0))
    block = _block(0.5)
    block[key] = block[key].copy()
    block[key].flat[3] = np.nan
    assert "non-finite" in safety.check(block)
    assert loop.force_scale == 0.0
    for _ in range(10):
        assert safety.check(_block(0.0)) is None
        assert loop.force_scale == 0.0 and safety.latched
    safety.clear()
    assert loop.force_scale == 1.0 and safety.latched is None


def test_after_a_clear_the_next_blocks_force_is_clamped_at_fmax_not_at_the_latched_scale_zero():
    loop = FakeLoop(fmax=1.0)
    safety = Safety(loop, motor_limits=(200.0, 60.0))
    assert "operator" in safety.check(_block(0.5), force_enable=False, why="Emergency stop (operator): force off")
    safety.clear()
    assert safety.check(_block(0.5)) is None and safety.latched is None  # 0.5 N is within F_max = 1 N


def test_a_force_beyond_its_clamp_latches():
    loop = FakeLoop(fmax=1.0)
    safety = Safety(loop, motor_limits=(200.0, 60.0))
    assert safety.check(_block(1.0 + 1e-12)) is None  # rounding only: the bow table's cap is exact
    assert "exceeded its clamp" in safety.check(_block(1.005))  # the 1 % once allowed is a fault now
    assert loop.force_scale == 0.0


def test_the_watchdog_word_latches_a_fault():
    loop = FakeLoop()
    safety = Safety(loop, motor_limits=(200.0, 60.0))
    assert "watchdog" in safety.check(_block(0.1), force_enable=False)
    assert loop.force_scale == 0.0


def test_a_watchdog_trip_before_a_block_zeroes_that_block_from_its_first_sample():
    loop = ClosedLoop(LoopConfig(rate=RATE, source="TRUE", fmax=2.0))
    safety = Safety(loop)
    block = loop.run(int(0.5 * RATE))  # the scripted strokes: the bow pushes back
    safety.before_block(True)
    assert safety.check(block) is None and np.max(np.abs(block["force"])) > 1.0
    safety.before_block(False)  # the parent cleared the word while the worker was stopped
    assert "watchdog" in safety.latched
    assert np.all(loop.run(LOOP_BLOCK)["force"] == 0.0)


def test_a_block_in_flight_across_a_watchdog_trip_has_its_force_withheld():
    loop = FakeLoop()
    safety = Safety(loop, motor_limits=(200.0, 60.0))
    block = _block(0.9)
    assert "watchdog" in safety.check(block, force_enable=False)
    assert np.all(block["force"] == 0.0)
    assert np.all(block["velocity_true"] == 0.0) and block["position"].shape == (BLOCK,)  # only the force


def test_fmax_is_clamped_to_the_ceiling():
    safety = Safety(FakeLoop(), SafetyLimits(fmax_ceiling=20.0), motor_limits=(200.0, 60.0))
    assert safety.clamp_fmax(5.0) == 5.0
    assert safety.clamp_fmax(50.0) == 20.0
    for bad in (-1.0, float("nan"), float("inf"), "x"):
        with pytest.raises(ParameterError, match="fmax"):
            safety.clamp_fmax(bad)


def test_a_saturated_motor_ramps_the_force_scale_down_linearly():
    limits = SafetyLimits(window=0.1, fraction=0.85, ramp=0.2)
    loop = FakeLoop(fmax=200.0)
    safety = Safety(loop, limits, motor_limits=(200.0, 60.0))
    window_blocks = int(limits.window * RATE / BLOCK)
    detected = None
    for j in range(3 * window_blocks):
        if safety.check(_block(60.0 if j % 10 else 0.0)):  # 90% of blocks at the motor's limit
            detected = j
            break
    assert detected == window_blocks - 1  # as soon as one full window is suspect
    assert "runaway" in safety.latched
    step = BLOCK / (RATE * limits.ramp)
    while loop.force_scale > 0:
        safety.check(_block(60.0 * loop.force_scale))
    expected = np.clip(1.0 - step * np.arange(1, len(loop.scales) + 1), 0, None)
    np.testing.assert_allclose(loop.scales, expected, atol=1e-12)
    assert len(loop.scales) == int(np.ceil(1 / step))  # zero after ``ramp`` seconds


def test_speed_beyond_the_bound_counts_as_runaway_and_short_spikes_do_not():
    loop = FakeLoop()
    safety = Safety(loop, SafetyLimits(window=0.1), motor_limits=(200.0, 60.0))
    for j in range(200):  # 0.4 s with one fast block in five: not a runaway
        assert safety.check(_block(0.1, velocity=1.0 if j % 5 == 0 else 0.05)) is None
    for _ in range(50):
        fault = safety.check(_block(0.1, velocity=0.5))
        if fault:
            break
    assert fault and "velocity beyond 0.3 m/s" in fault


def test_the_real_loop_pinned_at_the_motor_limit_is_caught_and_ramped_to_zero():
    # F_max = 200 N (beyond any sane protocol): the motor sits at its limits (model/device.py)
    limits = SafetyLimits(fmax_ceiling=200.0)
    loop = ClosedLoop(LoopConfig(rate=RATE, estimators={"LOWPASS": {}}, source="LOWPASS", fmax=200.0))
    safety = Safety(loop, limits)
    blocks, detected = [], None
    for j in range(int(3.0 * RATE / LOOP_BLOCK)):
        scale = loop.force_scale
        block = loop.run(LOOP_BLOCK)
        blocks.append((scale, block["force"]))
        if safety.check(block) and detected is None:
            detected = j
        if detected is not None and loop.force_scale == 0.0 and j > detected + 5:
            break
    assert detected is not None, "no runaway found"
    assert "runaway" in safety.latched
    ramp_blocks = int(np.ceil(limits.ramp * RATE / LOOP_BLOCK))
    assert len(blocks) - detected <= ramp_blocks + 7
    # while ramping, every block's force stays within the scale in force during it
    for scale, force in blocks[detected + 1:]:
        assert np.max(np.abs(force)) <= 200.0 * scale * 1.01 + 1e-12
    assert np.all(loop.run(LOOP_BLOCK)["force"] == 0.0)


@pytest.mark.parametrize("source, fmax", [("LVT", 1.0), ("TRUE", 12.1), ("LOWPASS", 60.0)])
def test_ordinary_bowing_up_to_the_ceiling_is_not_a_runaway(source, fmax):
    loop = ClosedLoop(LoopConfig(rate=RATE, estimators={"LOWPASS": {}}, source=source, fmax=fmax))
    safety = Safety(loop)
    for _ in range(int(3.0 * RATE / 100)):
        assert safety.check(loop.run(100)) is None
    assert loop.force_scale == 1.0
