"""The ``jack_server`` fixture (registered in tests/conftest.py for every folder): a JACK server with its dummy driver: a real, clock-paced PortAudio device and JACK MIDI, no sound card.

The server gets its own name (JACK_DEFAULT_SERVER, inherited by the engine's
worker), so it never meets another JACK server on the machine: the name holds
the pytest-xdist worker and the process id, so each worker of a parallel run
(``make test``), and each of several runs at once, has its own server, and
the virtual MIDI ports the tests open live on that server alone. PortAudio in
this process, if loaded, lets go of it before it stops: a PortAudio still
attached to a vanished server aborts Python at exit.

Period: the issue's ``-p 256`` (5.3 ms) xruns a few times in 10 s on a loaded
two-core VM even for an empty client at real-time priority (measured: 0-4 per
10 s, jackd logging "JackTimedDriver::Process XRun" - the driver thread itself
woke late); ``-p 1024`` (21 ms) absorbs that. STUDYAPP_JACK_PERIOD overrides.
"""

import os
import shutil
import subprocess
import sys
import time

import pytest

RATE = 48000


def _start(jackd, name, realtime, period, log):
    flag = "-R" if realtime else "-r"
    return subprocess.Popen(
        [jackd, "-n", name, flag, "-d", "dummy", "-r", str(RATE), "-p", str(period)],
        stdout=log, stderr=subprocess.STDOUT, env=os.environ.copy(),
    )


def _ready(name, proc, timeout=15.0):
    end = time.monotonic() + timeout
    while time.monotonic() < end:
        if proc.poll() is not None:
            return False
        check = subprocess.run(["jack_wait", "-c", "-s", name], capture_output=True, text=True)
        if check.stdout.strip() == "running":
            return True
        time.sleep(0.1)
    return False


@pytest.fixture(scope="session")
def jack_server(tmp_path_factory):
    """The name of a running dummy JACK server (48 kHz); skips when jackd is not installed."""
    jackd = shutil.which("jackd")
    if jackd is None or shutil.which("jack_wait") is None:
        pytest.skip("jackd not installed (Debian jackd2, listed in scripts/system-deps.txt)")
    name = f"studyapp-test-{os.environ.get('PYTEST_XDIST_WORKER', 'main')}-{os.getpid()}"
    period = int(os.environ.get("STUDYAPP_JACK_PERIOD", "1024"))
    saved = {k: os.environ.get(k) for k in ("JACK_DEFAULT_SERVER", "JACK_NO_START_SERVER")}
    os.environ["JACK_DEFAULT_SERVER"] = name
    os.environ["JACK_NO_START_SERVER"] = "1"
    log_path = tmp_path_factory.mktemp("jack") / "jackd.log"
    log = open(log_path, "w")
    proc = None
    for realtime in (True, False):
        proc = _start(jackd, name, realtime, period, log)
        if _ready(name, proc):
            break
        proc.kill()
        proc.wait()
        proc = None
    if proc is None:
        log.close()
        pytest.fail(f"jackd did not start: {log_path.read_text()[-500:]}")
    try:
        yield name
    finally:
        sd = sys.modules.get("sounddevice")
        if sd is not None:
            sd._terminate()
        proc.terminate()
        try:
            proc.wait(10)
        except subprocess.TimeoutExpired:
            proc.kill()
            proc.wait()
        log.close()
        if sd is not None:
            sd._initialize()
        for key, value in saved.items():
            if value is None:
                os.environ.pop(key, None)
            else:
                os.environ[key] = value
