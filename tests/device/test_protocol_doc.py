"""docs/device-protocol.md: its worked example is the frame the codec makes, and its INFO size formula holds."""

import re
from pathlib import Path

from studyapp.device import emulator, frames, messages

DOC = Path(__file__).resolve().parents[2] / "docs" / "device-protocol.md"


def test_worked_example_parses():
    text = DOC.read_text()
    block = re.search(r"```hex\n(.*?)\n```", text, re.S).group(1)
    wire = bytes.fromhex(block)
    assert wire[-1] == 0
    payload = frames.decode(wire[:-1])
    assert messages.parse(payload) == (7, messages.Force(1000, (1.5,)))
    assert frames.encode(messages.Force(1000, (1.5,)).pack(7)) == wire
    shown = re.search(r"\n    (82 07 [0-9a-f ]+)\n", text).group(1)
    assert bytes.fromhex(shown) == payload
    assert "0x5D24" in text and "24 5d" in text


def test_info_size_formula():
    info = emulator.device_info(emulator.EmulatorConfig(link="-"))
    n, m, c = len(info.name.encode()), len(info.serial.encode()), len(info.channels)
    assert len(info.pack()) == 50 + n + m + 18 * c


def test_version_2_worked_example_parses():
    """The CONTROL example of "Version 2": its wire line decodes to that message, and the codec makes it."""
    from studyapp.device import loop_messages
    text = DOC.read_text()
    blocks = re.findall(r"```hex\n(.*?)\n```", text, re.S)
    wire = bytes.fromhex(next(b for b in blocks if b.startswith("04 89")))
    message = loop_messages.Control(id=1, sample=1000, source=6, bowing=1, reset=1, gain=2.0, force_scale=1.0)
    assert wire[-1] == 0
    payload = frames.decode(wire[:-1])
    assert loop_messages.parse(payload) == (3, message)
    assert frames.encode(message.pack(3)) == wire
    shown = re.search(r"\n    (89 03 [0-9a-f ]+)\n", text).group(1)
    assert bytes.fromhex(shown) == payload
    assert "0x66F8" in text and "f8 66" in text


def test_device_loop_info_fits_its_telemetry():
    """The emulator's device-loop INFO: version 2, max_packet 20 (a TELEMETRY frame of 20 rows within 1024 bytes)."""
    from studyapp.device import loop_messages
    from studyapp.device.loop_bank import device_loop
    config = emulator.EmulatorConfig(link="-", loop="device")
    info = emulator.device_info(config, device_loop(config.rate, accelerometer=True))
    assert info.protocol_version == 2 and info.max_packet == 20 == loop_messages.max_telemetry_packet(info.channels)
    loop = loop_messages.loop_info(info)
    assert loop.loop == 1 and loop.keepalive_ms == 200 and len(loop.kinds) == 13
    assert "max_packet 20" in DOC.read_text()
