"""One running session per participant (issue 14, item 1): a second start for a
participant whose session is open, in another process or in the same one, is
refused in one line naming the holder and writes nothing; two starts at once
give one session; the lock of a killed process is taken over. (That a resumed
session completes with nothing lost or repeated is test_experiment_cli's SIGKILL test.)"""

import os
import signal
import socket
import subprocess
import sys
import time
from pathlib import Path

import pytest

from studyapp.errors import UserError
from studyapp.experiment.protocol import load_protocol
from studyapp.experiment.session import Session
from studyapp.experiment.session_log import read_log

ROOT = Path(__file__).resolve().parents[2]
DEMO = ROOT / "protocols" / "demo.toml"
HELD = f"held by PID {{pid}} on host {socket.gethostname()} since "


@pytest.fixture
def protocol():
    return load_protocol(DEMO)


def studyapp(*args):
    return subprocess.Popen([sys.executable, "-m", "studyapp", *args], cwd=ROOT, stdout=subprocess.PIPE,
                            stderr=subprocess.PIPE, text=True)


def run_argv(results, participant, *extra):
    return ["run", "--protocol", str(DEMO), "--participant", participant, "--headless",
            "--simulated-participant", "--results", str(results), *extra]


def first_to_exit(processes, timeout=120):
    deadline = time.monotonic() + timeout
    while time.monotonic() < deadline:
        for i, p in enumerate(processes):
            if p.poll() is not None:
                return i
        time.sleep(0.01)
    raise AssertionError("neither process ended")


def assert_refused(process):
    _, err = process.communicate(timeout=60)
    lines = err.strip().splitlines()
    assert process.returncode == 2, err
    assert len(lines) == 1 and lines[0].startswith("studyapp: error: ") and "Traceback" not in err
    return lines[0]


def test_a_second_start_in_the_same_process_is_refused_until_close(tmp_path, protocol):
    session = Session.create(protocol, "L01", tmp_path)
    before = (session.folder / "events.jsonl").read_bytes()
    for start in (lambda: Session.resume(protocol, "L01", tmp_path), lambda: Session.create(protocol, "L01", tmp_path)):
        with pytest.raises(UserError) as refused:
            start()
        assert f"participant 'L01' is in a session already, {HELD.format(pid=os.getpid())}" in str(refused.value)
    assert (session.folder / "events.jsonl").read_bytes() == before
    session.close()
    Session.resume(protocol, "L01", tmp_path).close()


def test_a_second_process_is_refused_naming_the_holder_and_writes_nothing(tmp_path, protocol):
    session = Session.create(protocol, "L02", tmp_path)
    files = {p: p.read_bytes() for p in session.folder.parent.rglob("*") if p.is_file()}
    second = studyapp(*run_argv(tmp_path, "L02", "--resume"))
    line = assert_refused(second)
    assert HELD.format(pid=os.getpid()) in line and "'L02'" in line
    assert {p: p.read_bytes() for p in session.folder.parent.rglob("*") if p.is_file()} == files
    session.close()


def test_the_lock_of_a_killed_process_is_taken_over(tmp_path, protocol):
    Session.create(protocol, "L03", tmp_path).close()
    holder = subprocess.Popen(
        [sys.executable, "-c", "import sys, time\n"
         "from studyapp.experiment.protocol import load_protocol\n"
         "from studyapp.experiment.session import Session\n"
         f"Session.resume(load_protocol({str(DEMO)!r}), 'L03', {str(tmp_path)!r})\n"
         "print('held', flush=True)\n"
         "time.sleep(60)\n"], cwd=ROOT, stdout=subprocess.PIPE, text=True)
    try:
        assert holder.stdout.readline().strip() == "held"
        with pytest.raises(UserError, match=f"held by PID {holder.pid} "):
            Session.resume(protocol, "L03", tmp_path)
    finally:
        holder.send_signal(signal.SIGKILL)
        holder.wait()
    Session.resume(protocol, "L03", tmp_path).close()  # the kernel released the dead holder's lock


def test_two_fresh_starts_at_once_make_one_session(tmp_path):
    pair = [studyapp(*run_argv(tmp_path, "L04")) for _ in range(2)]
    try:
        loser = first_to_exit(pair)
        line = assert_refused(pair[loser])
        assert "is in a session already, held by PID" in line or "already has a session" in line
    finally:
        for p in pair:
            p.kill()
            p.communicate()
    assert len(list((tmp_path / "demo" / "L04").iterdir())) == 2  # the lock and one session folder


def test_two_resumes_at_once_run_the_session_once(tmp_path, protocol):
    Session.create(protocol, "L05", tmp_path).close()
    pair = [studyapp(*run_argv(tmp_path, "L05", "--resume")) for _ in range(2)]
    try:
        loser = first_to_exit(pair)
        line = assert_refused(pair[loser])
        winner = pair[1 - loser]
        assert f"held by PID {winner.pid} on host {socket.gethostname()}" in line, line
    finally:
        for p in pair:
            p.kill()
            p.communicate()
    events = read_log(next((tmp_path / "demo" / "L05").glob("*/events.jsonl"))).events
    types = [e["type"] for e in events]
    begun = [e["step"] for e in events if e["type"] == "trial_start"]
    answered = [e["step"] for e in events if e["type"] == "response"]
    assert types.count("run_start") == 1 and types.count("session_end") <= 1  # only the winner ever wrote
    assert begun == sorted(set(begun)) and answered == sorted(set(answered))  # nothing begun or answered twice
    assert [e["seq"] for e in events] == list(range(len(events)))
