"""``studyapp live --device``: a link that is not a device is one line and exit code 2 within 5 s (a silent one
within the HELLO wait and 4 s more), never a hang.

Each case runs the real entry point in a child process (``python -m studyapp``),
so the time includes the interpreter's start; the link is checked before the
engine, numba or the loop are loaded (studyapp/device/link_probe.py).
"""

import os
import socket
import subprocess
import sys
import threading
import time
from pathlib import Path

import pytest

from studyapp.device.handshake import HELLO_WAIT
from tests.device.fake_device import FakeDevice

REPO = Path(__file__).resolve().parents[2]
BOUND = 5.0  # s
SILENT_BOUND = HELLO_WAIT + 4.0  # s: a silent device is waited for HELLO_WAIT (a board may boot that long), then refused


def _live(device, *extra):
    env = {**os.environ, "PYTHONPATH": str(REPO)}
    started = time.monotonic()
    proc = subprocess.run([sys.executable, "-m", "studyapp", "live", "--device", device, "--audio", "null",
                           "--midi", "none", "--seconds", "1", "--json", *extra],
                          capture_output=True, text=True, timeout=60, env=env, cwd=REPO)
    return proc, time.monotonic() - started


def _refused(proc, took, *words, bound=BOUND):
    lines = proc.stderr.strip().splitlines()
    assert proc.returncode == 2, proc.stderr
    assert len(lines) == 1 and proc.stdout == ""
    for word in words:
        assert word in lines[0]
    assert took < bound


@pytest.fixture
def listening():
    """A TCP socket that accepts a connection and then never says a word."""
    server = socket.create_server(("127.0.0.1", 0))
    accepted = []
    thread = threading.Thread(target=lambda: accepted.append(server.accept()), daemon=True)
    thread.start()
    yield f"socket://127.0.0.1:{server.getsockname()[1]}"
    for conn, _ in accepted:
        conn.close()
    server.close()


def test_regular_file(tmp_path):
    path = tmp_path / "device.txt"
    path.write_text("not a device\n")
    _refused(*_live(str(path)), str(path), "a regular file, not a device")
    assert path.read_text() == "not a device\n"


def test_fifo(tmp_path):
    path = tmp_path / "fifo"
    os.mkfifo(path)
    _refused(*_live(str(path)), "a FIFO, not a device")


def test_missing_path(tmp_path):
    _refused(*_live(str(tmp_path / "ttyACM9")), "no such file")


def test_socket_nobody_listens():
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        port = s.getsockname()[1]
    _refused(*_live(f"socket://127.0.0.1:{port}"), "nothing answers there")


def test_socket_that_never_answers(listening):
    _refused(*_live(listening), "no answer to HELLO within 3 s", bound=SILENT_BOUND)


def test_device_that_never_answers_hello():
    fake = FakeDevice(hello=False)
    try:
        _refused(*_live(fake.path), "no answer to HELLO within 3 s", bound=SILENT_BOUND)
    finally:
        fake.close()


def test_device_refused_for_its_rate():
    fake = FakeDevice()
    try:
        _refused(*_live(fake.path, "--rate", "4000"), "rate 5000 Hz, the loop runs at 4000 Hz", "refused")
    finally:
        fake.close()


def test_link_options_without_a_device():
    env = {**os.environ, "PYTHONPATH": str(REPO)}
    proc = subprocess.run([sys.executable, "-m", "studyapp", "live", "--device-latency", "3", "--audio", "null",
                           "--midi", "none", "--seconds", "1"], capture_output=True, text=True, timeout=120, env=env,
                          cwd=REPO)
    assert proc.returncode == 2 and "need --device" in proc.stderr
