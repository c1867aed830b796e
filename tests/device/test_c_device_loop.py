"""Protocol version 2's device side in C (firmware/studyapp_device_loop.c) against docs/device-protocol.md,
"Version 2": CONTROL at its tag, a late one at once and counted, the 16-deep queue, a source out of range and
FORCE to a device loop corrupt, the keep-alive watchdog, TELEMETRY's bytes, and the loop's force equal to the
numba model's (model/control.py) on the same sensors and settings."""

import math

import numpy as np
import pytest

from studyapp.device import c_core, c_loop, c_loop_core, emulator, frames, loop_messages as lm, messages as msg
from studyapp.device.errors import ProtocolError
from studyapp.device.loop_bank import device_loop
from studyapp.device.loop_image import image_crc
from studyapp.device.streams import Sender
from studyapp.estimators.dispatch import step_guarded
from studyapp.model import control

RATE = 5000
KEEPALIVE_MS = 10  # K = 50 samples
K = KEEPALIVE_MS * RATE // 1000
D = math.ceil(RATE / 1000)
V_SENSOR = lm.SOURCE_VELOCITY_SENSOR


def make_info(loop, channels=msg.SI_CHANNELS, keepalive_ms=KEEPALIVE_MS, kinds=None, mode=lm.DEVICE_LOOP):
    kinds = tuple(int(k) for k in loop.bank.kinds) if kinds is None else kinds
    tail = lm.LoopInfo(mode, keepalive_ms if mode else 0, image_crc(RATE, loop.control.arrays), kinds).pack()
    largest = min(32, lm.max_telemetry_packet(channels))
    return msg.Info(lm.LOOP_VERSION, 1, 0, RATE, largest, "test", "T-1", 0.011, 200.0, 60.0, 1.0, 1, 0,
                    channels, tail)


class Rig:
    """A C device loop fed by hand: frames in, samples run, frames out (parsed)."""

    def __init__(self, channels=msg.SI_CHANNELS, accelerometer=True, **info):
        self.loop = device_loop(RATE, accelerometer)
        self.info = make_info(self.loop, channels, **info)
        self.core = c_loop_core.CLoopCore(self.info, c_loop.CLoop(self.loop.control.arrays))
        self.sender = Sender()
        self.reader = frames.FrameReader()
        self.channels = channels
        self.out = []
        self.applied = []

    def send(self, *messages):
        self.core.rx(b"".join(self.sender.frame(m) for m in messages))

    def run(self, n, row=(0.0, 0.0, 0.1)):
        for _ in range(n):
            self.core.sample(row)
            self.applied.append(self.core.actuate())
            for payload in self.reader.feed(self.core.tx()):
                self.out.append(lm.parse(payload, self.channels)[1])

    def telemetry(self):
        return [r for m in self.out if isinstance(m, lm.Telemetry) for r in m.rows]

    def counters(self):
        return self.core.counters()

    def start(self, packet=1, latency=1):
        self.send(msg.Arm(0), msg.Start(packet, latency))


def control_at(cid, sample, source=V_SENSOR, gain=1.0, bowing=1, reset=0, force_scale=1.0):
    return lm.Control(cid, sample, source, bowing, reset, gain, force_scale)


def test_control_takes_effect_at_its_tag():
    rig = Rig()
    rig.start()
    rig.send(control_at(1, 5, gain=2.0))
    rig.run(10)
    ids = [r[-1] for r in rig.telemetry()]
    assert ids == [0] * 5 + [1] * 5
    forces = [r[3] for r in rig.telemetry()]
    assert forces[:5] == [0.0] * 5 and all(f != 0.0 for f in forces[5:])  # bowing at 0.1 m/s from sample 5
    assert rig.counters()["late"] == 0 and rig.counters()["queued"] == 0


def test_late_control_applies_at_once_and_is_counted():
    rig = Rig()
    rig.start()
    rig.run(10)
    rig.send(control_at(1, 3))  # sample 3 passed: it acts at sample 10, the next
    rig.run(2)
    assert [r[-1] for r in rig.telemetry()][9:] == [0, 1, 1]
    assert rig.counters()["late"] == 1


def test_controls_due_together_apply_in_the_order_received():
    rig = Rig()
    rig.start()
    rig.send(control_at(2, 4), control_at(1, 3), control_at(3, 4, gain=0.0))
    rig.run(6)
    assert [r[-1] for r in rig.telemetry()] == [0, 0, 0, 1, 3, 3]


def test_queue_holds_sixteen_and_drops_the_next_as_corrupt():
    rig = Rig()
    rig.start()
    rig.send(*(control_at(i + 1, 100 + i) for i in range(17)))
    c = rig.counters()
    assert c["queued"] == 16 and c["corrupt"] == 1 and c["lost"] == 0
    rig.run(120)
    ids = [r[-1] for r in rig.telemetry()]
    assert ids[99] == 0 and ids[100:116] == list(range(1, 17)) and ids[116:] == [16] * 4


@pytest.mark.parametrize("value", [13, -1, 31])
def test_source_out_of_range_is_corrupt(value):
    """13 estimators: 0..12 and -2 (the velocity sensor) are the sources; 31 passes the codec, not the device."""
    rig = Rig()
    assert rig.loop.bank.kinds.shape[0] == 13
    rig.start()
    payload = bytearray(control_at(1, 0).pack(rig.sender.seq))
    payload[8] = value & 0xFF  # source's byte (the payload's offset 8)
    rig.core.rx(frames.encode(bytes(payload)))
    c = rig.counters()
    assert c["corrupt"] == 1 and c["queued"] == 0


@pytest.mark.parametrize("offset, value", [(2, b"\0\0"), (9, b"\2"), (10, b"\2"),
                                           (11, np.float64(np.nan).tobytes()), (11, np.float64(-1.0).tobytes()),
                                           (19, np.float64(1.5).tobytes()), (19, np.float64(np.inf).tobytes())])
def test_a_bad_control_field_is_corrupt(offset, value):
    """id 0, bowing 2, reset 2, gain NaN or below 0, force scale above 1 or infinite: never applied."""
    rig = Rig()
    rig.start()
    payload = bytearray(control_at(1, 0).pack(0))
    payload[offset:offset + len(value)] = value
    with pytest.raises(ProtocolError):  # the codec refuses the same frame
        lm.parse(bytes(payload))
    rig.core.rx(frames.encode(bytes(payload)))
    rig.run(2)
    assert rig.counters()["corrupt"] == 1 and [r[-1] for r in rig.telemetry()] == [0, 0]


def test_force_to_a_device_loop_is_corrupt():
    rig = Rig()
    rig.start()
    rig.send(msg.Force(0, (1.0,)))
    assert rig.counters()["corrupt"] == 1


def test_start_latency_below_one_packet_is_corrupt():
    rig = Rig()
    rig.send(msg.Start(5, 4))
    assert rig.counters()["corrupt"] == 1 and not rig.core.streaming()


@pytest.mark.parametrize("version", [1, 2])
def test_control_and_alive_to_a_host_loop_are_corrupt(version):
    loop = device_loop(RATE, True)
    info = make_info(loop, mode=lm.HOST_LOOP)
    if version == 1:
        info = emulator.device_info(emulator.EmulatorConfig(link="-"))
    core = c_core.CCore(info)
    core.rx(frames.encode(control_at(1, 0).pack(0)) + frames.encode(lm.Alive(0).pack(1)))
    assert core.counters()["corrupt"] == 2


def test_attach_refuses_other_estimators():
    loop = device_loop(RATE, True)
    info = make_info(loop, kinds=tuple(int(k) for k in loop.bank.kinds[::-1]))
    with pytest.raises(c_core.BuildError):
        c_loop_core.CLoopCore(info, c_loop.CLoop(loop.control.arrays))


def run_to_watchdog(alive_every=None):
    rig = Rig()
    rig.start()
    rig.send(control_at(1, 0, gain=3.0))
    last = 0
    for j in range(400):
        if alive_every and j % alive_every == 0:
            rig.send(lm.Alive(j))
            last = j
        rig.run(1)
    return rig, last


def test_keepalive_watchdog_brings_the_force_to_zero():
    rig, last = run_to_watchdog()  # the last feeding frame: the CONTROL at sample 0 (START and ARM too)
    applied = np.array(rig.applied)
    assert np.all(applied[1:K] != 0.0)  # bowing, fed
    zero = int(np.flatnonzero(applied == 0.0)[np.flatnonzero(applied == 0.0) > 0][0])
    assert zero <= last + K + D - 1  # 0 within K + D samples of the last feed
    assert np.all(applied[zero:] == 0.0)
    faults = [m for m in rig.out if isinstance(m, msg.Fault)]
    assert [(f.code, f.detail) for f in faults] == [(msg.WATCHDOG, last)]
    assert rig.counters()["armed"] == 0


def test_alive_feeds_the_watchdog():
    rig, last = run_to_watchdog(alive_every=K // 2)
    assert rig.counters()["armed"] == 1 and not any(isinstance(m, msg.Fault) for m in rig.out)
    assert np.all(np.array(rig.applied[1:]) != 0.0)


def test_alive_stops_feeding_then_force_zero_within_k_plus_d():
    rig = Rig()
    rig.start()
    rig.send(control_at(1, 0, gain=3.0))
    for j in range(300):
        if j <= 120:
            rig.send(lm.Alive(j))
        rig.run(1)
    applied = np.array(rig.applied)
    assert np.all(applied[1:120 + K] != 0.0)
    assert np.all(applied[120 + K + D - 1:] == 0.0)
    assert [(m.code, m.detail) for m in rig.out if isinstance(m, msg.Fault)] == [(msg.WATCHDOG, 120)]


@pytest.mark.parametrize("fmt", ["f64", "counts"])
def test_telemetry_parses_and_the_loop_equals_the_model(fmt):
    """Every TELEMETRY frame parses with loop_messages; its channels are the sensors as sent, its loop force
    and bridge the numba loop's (control.sample) on the same sensors in SI and the same settings."""
    channels = emulator.COUNT_CHANNELS if fmt == "counts" else msg.SI_CHANNELS
    rig = Rig(channels)
    packet = 7
    rig.start(packet, packet)
    rig.send(control_at(1, 0, source=2, gain=4.0, reset=1), control_at(2, 150, source=V_SENSOR, gain=9.0))
    rng = np.random.default_rng(3)
    t = np.arange(350) / RATE
    sensors = np.stack([0.004 * np.sin(2 * np.pi * 3 * t), 2.0 * rng.standard_normal(350),
                        0.004 * 2 * np.pi * 3 * np.cos(2 * np.pi * 3 * t)], axis=1)
    raw = [emulator.raw_row(channels, *s) for s in sensors]
    for k, r in enumerate(raw):
        rig.send(lm.Alive(k))
        rig.run(1, r)
    frames_out = [m for m in rig.out if isinstance(m, lm.Telemetry)]
    assert [m.sample for m in frames_out] == list(range(0, 350, packet))
    assert all(len(m.rows) == packet and m.flags & lm.FLAG_ARMED for m in frames_out)
    rows = rig.telemetry()
    assert [tuple(r[:3]) for r in rows] == [tuple(r) for r in raw]
    # the model: a fresh loop of the same build, stepped by numba
    model = device_loop(RATE, True)
    arrays = model.control.arrays
    ctl = arrays[0]
    out = np.zeros((len(control.OUTPUTS), 1))
    est = np.zeros((model.bank.kinds.shape[0], 1))
    for k, r in enumerate(raw):
        setting = (2, 4.0) if k < 150 else (V_SENSOR, 9.0)
        ctl[control.C_SOURCE], ctl[control.C_GAIN], ctl[control.C_BOWING] = setting[0], setting[1], 1.0
        x, a, v = (c.to_si(value) for c, value in zip(channels, r))
        f = control.sample(arrays, 0, x, a, v, np.nan, np.nan, np.nan, np.nan, v, a, out, est)
        control.observe_others(int(ctl[control.C_SOURCE]), model.bank.kinds, model.bank.states, model.bank.params,
                               out, est)
        assert rows[k][3] == f and rows[k][4] == f, k
        assert rows[k][6] == (1 if k < 150 else 2)
    assert np.array_equal(model.bank.states, rig.loop.bank.states)  # every estimator stepped, the same bits


def test_no_acceleration_channel_gives_zero_acceleration():
    channels = (msg.Channel(msg.POSITION), msg.Channel(msg.VELOCITY))
    rig = Rig(channels)
    rig.start()
    rig.send(control_at(1, 0))
    for k in range(50):
        rig.run(1, (0.001 * k, 0.01))
    model = device_loop(RATE, True)
    for k in range(50):
        for e, kind in enumerate(model.bank.kinds):
            step_guarded(kind, model.bank.states[e], model.bank.params[e], 0.001 * k, 0.0, 0.01)
    assert np.array_equal(model.bank.states, rig.loop.bank.states)
