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
