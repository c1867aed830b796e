"""Issue 41 item 5: a calibration file made for another serial is refused naming both serials (it was silently
ignored); a channel's table missing gain or offset names the missing key; the bounds INFO's gains are held to hold
for the file's too (a gain of 0, -1e300 with an offset of 1e300)."""

import os
import subprocess
import sys
from pathlib import Path

import pytest

from studyapp.device import calibration_file
from studyapp.device.link_device import LinkDevice
from studyapp.errors import ParameterError
from tests.device.fake_device import FakeDevice

ROOT = Path(__file__).resolve().parents[2]


@pytest.fixture
def fake():
    device = FakeDevice()
    yield device
    device.close()


def _file(tmp_path, text):
    path = tmp_path / "lab.toml"
    path.write_text(text)
    return path


def test_a_file_for_another_serial_is_refused_naming_both(fake, tmp_path):
    path = _file(tmp_path, '["TGR-0001"]\nposition = { gain = 2.0, offset = 0.5 }\n')
    with pytest.raises(ParameterError) as caught:
        LinkDevice(fake.path, 5000.0, calibration=str(path), pings=2)
    assert str(caught.value) == (f"--calibration {path}: no entry for the device's serial 'FAKE-1'; the file has "
                                 "'TGR-0001' (a file made for another device is refused, not ignored)")


def test_live_refuses_it_with_one_line_and_exit_2(fake, tmp_path):
    path = _file(tmp_path, '["TGR-0001"]\nposition = { gain = 2.0, offset = 0.5 }\n')
    env = {**os.environ, "PYTHONPATH": str(ROOT)}
    proc = subprocess.run([sys.executable, "-m", "studyapp", "live", "--device", fake.path, "--calibration", str(path),
                           "--audio", "null", "--midi", "none", "--seconds", "1"], capture_output=True, text=True,
                          timeout=120, env=env, cwd=ROOT)
    lines = proc.stderr.strip().splitlines()
    assert proc.returncode == 2 and len(lines) == 1, proc.stderr
    assert "'FAKE-1'" in lines[0] and "'TGR-0001'" in lines[0]


@pytest.mark.parametrize("table, words", [
    ("{ gain = 2.0 }", "[\"'FAKE-1'\"].position: no offset; allowed is a table { gain = G, offset = O }, both required"),
    ("{ offset = 0.5 }", "[\"'FAKE-1'\"].position: no gain; allowed"),
    ("{ }", "no gain and no offset"),
    ("{ gain = 2.0, offset = 0.5, scale = 3 }", "unknown key 'scale'"),
    ("{ gain = 0.0, offset = 0.5 }", ".position.gain = 0.0: allowed is a number from -1000 to 1000, not 0"),
    ("{ gain = -1e300, offset = 1e300 }", ".position.gain = -1e+300: allowed is a number from -1000 to 1000"),
    ("{ gain = 1.0, offset = 1e300 }", ".position.offset = 1e+300: allowed is a number from -1000 to 1000"),
    ("{ gain = nan, offset = 0.0 }", ".position.gain = nan"),
])
def test_a_bad_channel_table_is_named(tmp_path, table, words):
    path = _file(tmp_path, f'["FAKE-1"]\nposition = {table}\n')
    with pytest.raises(ParameterError) as caught:
        calibration_file.load(path)
    assert str(caught.value).startswith(f"{path}: ")
    assert words.replace("[\"'FAKE-1'\"]", "['FAKE-1']") in str(caught.value), caught.value


def test_the_docs_say_both_keys_are_required_and_the_bounds():
    devices = " ".join((ROOT / "docs/devices.md").read_text().split())
    assert "needs both `gain` and `offset`" in devices and "within +-1000" in devices
    protocol = " ".join((ROOT / "docs/device-protocol.md").read_text().split())
    assert "gain non-zero and within +-1000" in protocol
