"""The firmware loop, byte level, on both cores: every single-bit flip of a FORCE frame is dropped and counted,
never applied; a gap in the host's seq is counted lost; HELLO, PING and START get their replies."""

import pytest

from studyapp.device import emulator, frames, messages
from studyapp.device.firmware import Firmware
from studyapp.device.streams import host_receiver

INFO = emulator.device_info(emulator.EmulatorConfig(link="-"))


def cores():
    out = [Firmware]
    try:
        from studyapp.device import c_core
        c_core.library()
        out.append(c_core.CCore)
    except Exception:  # noqa: BLE001 - the C core is tested where it builds (test_c_core.py)
        pass
    return out


def armed_streaming(core_class):
    core = core_class(INFO)
    core.rx(frames.encode(messages.Start(1, 2).pack(0)) + frames.encode(messages.Arm(0).pack(1)))
    core.rx(frames.encode(messages.Force(0, (3.0,) * 10).pack(2)))
    core.tx()
    return core


@pytest.mark.parametrize("core_class", cores(), ids=lambda c: c.__name__)
def test_no_single_bit_flip_of_a_force_frame_is_applied(core_class):
    good = frames.encode(messages.Force(3, (77.0, 77.0)).pack(3))
    for bit in range(len(good) * 8):
        core = armed_streaming(core_class)
        bad = bytearray(good)
        bad[bit // 8] ^= 1 << (bit % 8)
        core.rx(bytes(bad) + b"\x00")
        out = []
        for _ in range(6):
            core.sample((0.0, 0.0, 0.0))
            out.append(core.actuate())
        assert out == [3.0] * 6, bit
        assert core.counters()["corrupt"] >= 1, bit


@pytest.mark.parametrize("core_class", cores(), ids=lambda c: c.__name__)
def test_replies_and_lost_count(core_class):
    core = core_class(INFO)
    host = host_receiver()
    core.rx(frames.encode(messages.Hello().pack(0)) + frames.encode(messages.Ping(9).pack(1)))
    core.rx(frames.encode(messages.Start(2, 3).pack(5)))  # seq 2..4 never sent
    for _ in range(4):
        core.sample((0.001, 0.5, -0.01))
        core.actuate()
    got = host.feed(core.tx())
    assert [type(m) for m in got] == [messages.Info, messages.Pong, messages.State, messages.Sensors,
                                      messages.Sensors]
    assert got[0] == INFO and got[1] == messages.Pong(9, 0)
    assert got[3] == messages.Sensors(0, 0, ((0.001, 0.5, -0.01),) * 2) and got[4].sample == 2
    assert core.counters()["lost"] == 3 and host.lost == 0 and host.corrupt == 0
