"""Issue 41 item 5: a device that sends only position got 0 N all run under the default source, LVT, with no word.

The cause: LVT is the velocity transducer's reading (paper Sec. 8.4), the device's velocity channel, and a channel
the device does not send reads 0 (handshake.Scales). So ``live`` (default source LVT) and a session whose protocol
has an LVT condition refuse such a device with one line; a source that reads only position is accepted, and an
accelerometer estimator on a device with no acceleration channel is refused the same way.
"""

import os
import subprocess
import sys
from pathlib import Path

import pytest

from studyapp.cli.device_choice import probe_device
from studyapp.device import messages, source_channels
from studyapp.device.link_device import LinkDevice
from studyapp.errors import ParameterError
from studyapp.experiment.protocol import load_protocol
from tests.device.fake_device import INFO, FakeDevice

ROOT = Path(__file__).resolve().parents[2]
POSITION_ONLY = messages.Info(**{**INFO.__dict__, "channels": (messages.Channel(messages.POSITION),)})


@pytest.fixture
def fake():
    device = FakeDevice(info=POSITION_ONLY)
    yield device
    device.close()


def test_the_cause_lvt_reads_a_velocity_the_device_never_sends(fake):
    device = LinkDevice(fake.path, 5000.0, pings=2)
    x, a, v = device.scales.convert([(0.004,), (0.005,)])
    device.close()
    assert x == [0.004, 0.005] and v == [0.0, 0.0]  # LVT's velocity: 0 whatever the bow does


def test_live_with_the_default_source_refuses_it_with_one_line(fake):
    env = {**os.environ, "PYTHONPATH": str(ROOT)}
    proc = subprocess.run([sys.executable, "-m", "studyapp", "live", "--device", fake.path, "--audio", "null",
                           "--midi", "none", "--seconds", "1"], capture_output=True, text=True, timeout=120, env=env,
                          cwd=ROOT)
    lines = proc.stderr.strip().splitlines()
    assert proc.returncode == 2 and len(lines) == 1 and proc.stdout == "", proc.stderr
    assert lines[0].endswith(f"device at {fake.path}: the source LVT reads the velocity channel, which the device "
                             "does not send (it sends position): it would run on zeros (LVT: 0 N all run); allowed is "
                             "a source that reads only position (an estimator such as LOWPASS) or a device with a "
                             "velocity channel; refused")


def test_a_session_with_an_lvt_condition_refuses_it(fake):
    with pytest.raises(ParameterError, match="the source LVT reads the velocity channel"):
        probe_device(fake.path, 5000.0, load_protocol(ROOT / "protocols/demo.toml"))


def test_sources_that_read_what_the_device_sends_pass():
    source_channels.check(["LOWPASS", "KALLEV", "FOAW"], ["position"], "/dev/x")
    source_channels.check(["LVT", "KALMAN", "COMP1"], ["position", "acceleration", "velocity"], "/dev/x")
    with pytest.raises(ParameterError, match="the source KALMAN reads the acceleration channel, which the device does not send .it sends position, velocity."):
        source_channels.check(["LOWPASS", "KALMAN"], ["position", "velocity"], "/dev/x")
