"""The Lock-step target (issue 40): the emulator in device-loop mode over a real pty, in lock-step, driven by a
minimal host (HELLO, ARM, CONTROL, START, ALIVE after each TELEMETRY packet), equals the model's loop at no
latency (model/loop.py ClosedLoop on the simulated device, the same seed and strokes) every sample: the
sensed position and velocity, the force, and the string's velocity at the bridge, with max difference 0.

One emulator per seed runs the nine adjustment conditions one after the other, 0.5 s each, each segment opened
by a CONTROL (its source, F_max / peak as the gain, the string reset) tagged at its first sample: the host
sends it with the ALIVE that lets the device run that sample, so it is never late. The model runs the same
segments with set_source, set_fmax and reset_string between blocks. F_max goes over 0.5-20 N across the
segments and seeds.
"""

import numpy as np
import pytest

from studyapp.device import loop_messages as lm
from studyapp.device import messages as msg
from studyapp.device.loop_bank import STUDY, names_of
from studyapp.model import bowed_string
from studyapp.model.bowed_string import StringDesign
from studyapp.model.calibration import F0
from studyapp.model.sources import LVT_SENSOR
from tests.device.emulator_process import start_emulator, stop_emulator
from tests.device.loop_host import LoopHost

RATE = 5000
SEGMENT = RATE // 2  # 0.5 s per condition
CONDITIONS = STUDY + (LVT_SENSOR,)  # the adjustment task's nine (protocols/sinclair2014.toml)
FMAX = (0.5, 1.0, 2.0, 5.0, 10.0, 20.0)
PACKET, LEAD = 10, 10


def plan(seed):
    """(condition, F_max) per segment."""
    return [(c, FMAX[(i + 2 * seed) % len(FMAX)]) for i, c in enumerate(CONDITIONS)]


def reference(seed, segments):
    """The model's loop, segment by segment: sensed x and v, force, and the string's bridge wave."""
    from studyapp.model.loop import ClosedLoop, LoopConfig
    loop = ClosedLoop(LoopConfig(rate=RATE, estimators={n: {} for n in STUDY}, source=segments[0][0],
                                 fmax=segments[0][1], gesture="strokes", seed=seed, audio=False), judge=False)
    x, v, force, bridge = [], [], [], []
    for source, fmax in segments:
        loop.set_source(source)
        loop.set_fmax(fmax)
        loop.reset_string()
        r = loop.run(SEGMENT)
        # the bridge wave, from the model's own string on the loop's own bow velocity (bowed_string.step's
        # third output; the loop records the string at the bow, which must come out the same)
        p = loop.string.params()
        s, b_line, n_line = loop.string.new_state()
        v_bow = loop.velocity_scale * r["source_velocity"]
        u, v_string, v_bridge = (np.zeros(SEGMENT) for _ in range(3))
        bowed_string.run(p, s, b_line, n_line, v_bow, True, u, v_string, v_bridge)
        assert np.array_equal(v_string / loop.velocity_scale, r["string_velocity"])
        x.append(r["position"])
        v.append(r["velocity_lvt"])
        force.append(r["force"])
        bridge.append(v_bridge)
    return tuple(np.concatenate(a) for a in (x, v, force, bridge))


def device_run(tmp_path, seed, segments):
    """The emulator's TELEMETRY rows over the pty, in lock-step, and its stats."""
    link = tmp_path / "dev"
    proc = start_emulator(link, "--lockstep", "--loop", "device", "--seed", str(seed))
    host = LoopHost(link)
    rows = []
    try:
        host.send(msg.Hello(lm.LOOP_VERSION))
        info = lm.loop_info(host.wait(msg.Info))
        index = {name: i for i, name in enumerate(names_of(info.kinds))}
        peak = StringDesign(RATE, F0).peak_friction()
        controls = [lm.Control(i + 1, i * SEGMENT, index.get(source, lm.SOURCE_VELOCITY_SENSOR), 1, 1,
                               fmax / peak, 1.0) for i, (source, fmax) in enumerate(segments)]
        host.send(msg.Ping(7))
        assert host.wait(msg.Pong).sample == 0  # a lock-step device stands still until START
        host.send(msg.Arm(0), controls.pop(0), msg.Start(PACKET, LEAD))
        host.wait(msg.State, where=lambda m: m.streaming)
        while len(rows) < SEGMENT * len(segments):
            for m in host.next():
                if isinstance(m, lm.Telemetry):
                    assert m.sample == len(rows)
                    rows += m.rows
                    seen = m.sample + len(m.rows)
                    # the CONTROL goes with the ALIVE that lets the device run its sample: never late
                    while controls and controls[0].sample < seen + LEAD:
                        host.send(controls.pop(0))
                    host.send(lm.Alive(seen))
        host.send(msg.Stop())
        host.wait(msg.State, where=lambda m: not m.streaming)
    finally:
        host.close()
        stats = stop_emulator(proc)
    return np.array(rows[:SEGMENT * len(segments)]), stats


@pytest.mark.slow
@pytest.mark.parametrize("seed", [0, 1, 2])
def test_lockstep_device_loop_equals_the_model(tmp_path, seed):
    segments = plan(seed)
    rows, stats = device_run(tmp_path, seed, segments)
    x, v, force, bridge = reference(seed, segments)
    # a row: x, a, v (f64 channels), loop_force, applied, bridge, control id
    assert np.max(np.abs(rows[:, 0] - x)) == 0.0
    assert np.max(np.abs(rows[:, 2] - v)) == 0.0
    assert np.max(np.abs(rows[:, 3] - force)) == 0.0
    assert np.max(np.abs(rows[:, 4] - force)) == 0.0  # armed, no ramp, far below the clamps: applied as looped
    assert np.max(np.abs(rows[:, 5] - bridge)) == 0.0
    assert np.array_equal(rows[:, 6], np.repeat(np.arange(1, len(segments) + 1), SEGMENT))
    assert stats["late"] == 0 and stats["corrupt"] == 0 and stats["lost"] == 0 and stats["loop_fault"] == 0
    # the loop did something: the strokes moved the handle and every condition pushed back
    assert np.max(np.abs(x)) > 1e-3
    for i, (_, fmax) in enumerate(segments):
        f = np.abs(force[i * SEGMENT:(i + 1) * SEGMENT])
        assert 0.1 * fmax < f.max() <= fmax * (1 + 1e-12)


def test_clocked_device_loop_streams_and_its_keepalive_watchdog_trips(tmp_path):
    """Clocked (5 kHz on its own clock): TELEMETRY without a gap, a CONTROL in effect from its tag (or, if it
    arrived late, from the sample after it arrived, counted late), and once the host's ALIVE stops, the force
    at 0 within K + D - 1 samples of the last one (FAULT WATCHDOG's sample and detail, device time)."""
    keepalive_ms = 50
    k_samples, d_samples = keepalive_ms * RATE // 1000, RATE // 1000
    link = tmp_path / "dev"
    proc = start_emulator(link, "--loop", "device", "--keepalive-ms", str(keepalive_ms))
    host = LoopHost(link)
    rows, control, fault = [], None, None
    try:
        host.send(msg.Hello(lm.LOOP_VERSION))
        host.wait(msg.Info)
        host.send(msg.Arm(0), msg.Start(PACKET, PACKET))
        host.wait(msg.State, where=lambda m: m.streaming)
        while len(rows) < RATE // 2:
            for m in host.poll(1.0):
                if isinstance(m, lm.Telemetry):
                    assert m.sample == (rows[0][0] + len(rows) if rows else m.sample)
                    rows += [(m.sample + i, *r) for i, r in enumerate(m.rows)]
                    if control is None:
                        control = lm.Control(1, m.sample + 25 + RATE // 100, -2, 1, 1, 2.0, 1.0)
                        host.send(control)
                    host.send(lm.Alive(m.sample + len(m.rows)))
        fault = host.wait(msg.Fault, timeout=5.0, where=lambda m: m.code == msg.WATCHDOG)
        host.poll(0.2)
        after = [(t.sample + i, *r) for t in host.inbox if isinstance(t, lm.Telemetry) for i, r in enumerate(t.rows)]
        host.send(msg.Stop())
    finally:
        host.close()
        stats = stop_emulator(proc)
    ids = np.array([r[-1] for r in rows])
    first = rows[int(np.flatnonzero(ids == 1)[0])][0]
    assert ids[0] == 0 and np.all(ids[np.flatnonzero(ids == 1)[0]:] == 1)
    assert (first == control.sample and stats["late"] == 0) or (first > control.sample and stats["late"] == 1)
    assert any(r[5] != 0.0 for r in rows)  # bowing at 2 N / peak: a force
    assert 0 < fault.sample - fault.detail <= k_samples + d_samples - 1
    assert all(r[5] == 0.0 for r in after if r[0] >= fault.sample)
    assert stats["armed"] == 0 and stats["fault"] == msg.WATCHDOG
