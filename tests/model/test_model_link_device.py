"""The simulated device behind a link (issue 29 item 1): the loop before the link bit for bit on the default link, the
impulse's arrival, the block path equal to the per-sample one, seeded runs, and the issue's breakdown target."""

import json

import numpy as np
import pytest

from studyapp.cli import main
from studyapp.model import simulated_device
from studyapp.model.device import HapticDevice
from studyapp.model.link import LinkSpec
from studyapp.model.loop import OUTPUTS, ClosedLoop, LoopConfig
from studyapp.model.simulated_device import SimulatedDevice, discretise

RATE = 5000.0
CASES = {
    "lvt": dict(estimators={"KALLEV": {}, "LOWPASS": {}}, source="LVT", fmax=6.0, gesture="strokes", seed=1),
    "kallev": dict(estimators={"KALLEV": {}, "LOWPASS": {}}, source="KALLEV", fmax=3.0, gesture="strokes", seed=2),
    "true_hold": dict(estimators={"LOWPASS": {}}, source="TRUE", fmax=20.0, gesture="hold", seed=0),
}
BLOCKS = (1000, 37, 1963, 1000)


def run(config, device=None, blocks=BLOCKS):
    loop = ClosedLoop(config, device=device)
    parts = [loop.run(n) for n in blocks]
    return {k: np.concatenate([p[k] for p in parts], axis=-1) for k in list(OUTPUTS) + ["estimates"]}


class PerSample(SimulatedDevice):
    """The simulated device driven as a real driver is: the interface's own exchange."""

    exchange = HapticDevice.exchange


class Unlinked(PerSample):
    """The device as it was before the link existed: the host's command acts at once, with no link code at all."""

    def write_force(self, force):
        target = self._target if self._target is not None else tuple(float(t[0]) for t in self._targets(1))
        f_arm = simulated_device.hand_once(self._hp, self._ds, *target)
        simulated_device.actuate(self._dp, self._ds, self._hp, float(force), f_arm)
        self._target = None
        self._sample += 1


@pytest.mark.parametrize("case", list(CASES))
@pytest.mark.parametrize("link", [None, LinkSpec()])
def test_the_default_link_is_mains_loop_bit_for_bit(case, link):
    """The loop's block path behind no link and behind the default one equals, bit for bit, the loop before the link
    existed: the same device stepped sample by sample through the interface, the command applied with no link code
    (computed on this machine in this run: bits are held equal only to what the same machine computes)."""
    config = LoopConfig(rate=RATE, audio=True, link=link, **CASES[case])
    loop = ClosedLoop(config)
    unlinked = Unlinked(RATE, seed=config.seed, accelerometer=loop.device.accelerometer)
    block, before = run(config), run(config, unlinked)
    assert np.std(block["force"]) > 0.01 and np.std(block["velocity_true"]) > 0.0  # the loop did something
    for key in block:
        np.testing.assert_array_equal(block[key], before[key], err_msg=key)


@pytest.mark.parametrize("link", [LinkSpec(latency=0.0004), LinkSpec(latency=0.0002, packet=0.001),
                                  LinkSpec(latency=0.0002, packet=0.0006, jitter=0.001, loss=0.1)])
def test_the_block_equals_the_per_sample_path_behind_a_link(link):
    config = LoopConfig(rate=RATE, estimators={"LOWPASS": {}}, source="LOWPASS", fmax=3.0, seed=4)
    fast, slow = (run(config, cls(RATE, seed=4, accelerometer=False, link=link), (1500, 7, 700))
                  for cls in (SimulatedDevice, PerSample))
    assert np.std(fast["force"]) > 0.1  # the string was bowed
    for key in fast:
        np.testing.assert_array_equal(slow[key], fast[key], err_msg=key)


@pytest.mark.parametrize("samples", [0, 1, 2, 5])
def test_an_impulse_of_force_moves_the_handle_L_plus_1_samples_later(samples):
    """F[k0] = 1 N acts over [k0 + L, k0 + L + 1]: the position sampled at k0 + L + 1 is the first to differ."""
    k0, n = 30, 60
    link = LinkSpec(latency=samples / RATE)
    positions = []
    for impulse in (0.0, 1.0):
        dev = SimulatedDevice(RATE, seed=3, link=link)
        x = []
        for k in range(n):
            dev.read_sensors()
            x.append(dev.truth()[0])
            dev.write_force(impulse if k == k0 else 0.0)
        positions.append(np.array(x))
    moved = np.flatnonzero(positions[1] != positions[0])
    assert moved[0] == k0 + samples + 1
    # by what 1 N over one step moves the end-effector on the grip: Gamma[0, 0] (checked against scipy's ODE
    # solver in test_model_grip.py), about T^2 / (2 m) less the grip's damping
    hand = dev.hand
    gamma = discretise(dev.mass, hand.mass, hand.grip_stiffness, hand.grip_damping, 1.0 / RATE)[1]
    first = positions[1][moved[0]] - positions[0][moved[0]]
    assert first == pytest.approx(gamma[0, 0], rel=1e-9)


def test_runs_are_seeded():
    link = LinkSpec(latency=0.0004, packet=0.0006, jitter=0.001, loss=0.05)
    config = LoopConfig(rate=RATE, estimators={"LOWPASS": {}}, source="LOWPASS", fmax=3.0, seed=2, link=link)
    a, b = run(config, blocks=(2000,)), run(config, blocks=(500, 1500))
    assert all(np.array_equal(a[k], b[k]) for k in a)
    other = run(LoopConfig(**{**config.__dict__, "seed": 3}), blocks=(2000,))
    assert not np.array_equal(a["force"], other["force"])


def test_breakdown_at_0_2_ms_reproduces_the_issues_table(capsys):
    """Issue 29: 0.2 ms (one sample at 5 kHz) of latency, LVT 5.10 and LOWPASS N (medians), within 15 %.

    LOWPASS was 3.51 with the white LVDT; with issue 42's (its conditioner's 250 Hz low-pass) it is 2.69,
    2.67-2.71 over seeds 0-9 (`studyapp breakdown --source LOWPASS --seeds 10 --latency 1`, 2026-11-29);
    LVT does not read the LVDT (5.02-5.10 over the same seeds)."""
    for source, expected in (("LVT", 5.10), ("LOWPASS", 2.69)):
        assert main(["breakdown", "--source", source, "--seeds", "5", "--latency", "1", "--json"]) == 0
        doc = json.loads(capsys.readouterr().out)
        assert (doc["latency"], doc["packet"], doc["jitter"]) == (0.0002, 0.0, 0.0)
        assert doc["fmax_median"] == pytest.approx(expected, rel=0.15), source
