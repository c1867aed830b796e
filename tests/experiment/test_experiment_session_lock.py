"""One running session per participant (issue 14, item 1): a second start for a
participant whose session is open, in another process or in the same one, is
refused in one line naming the holder and writes nothing; two starts at once
give one session; the lock of a killed process is taken over. (That a resumed
session completes with nothing lost or repeated is test_experiment_cli's SIGKILL test.)"""

import fcntl
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
from studyapp.experiment.session_log import SessionLog, read_log

ROOT = Path(__file__).resolve().parents[2]
DEMO = ROOT / "protocols" / "demo.toml"
HELD = f"held by PID {{pid}} on host {socket.gethostname()} since "


@pytest.fixture
def protocol():
    return load_protocol(DEMO)


def studyapp(*args):
    return subprocess.Popen([sys.executable, "-m", "studyapp", *args], cwd=ROOT, stdout=subprocess.PIPE,
                            stderr=subprocess.PIPE, text=True)


SIMULATED = {"participant": "simulated"}  # sessions the simulated participant of run_argv may resume (issue 31)


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
    Session.create(protocol, "L05", tmp_path, apparatus=SIMULATED).close()  # resumed by the simulated participant
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


# --- issue 21, item 1: a losing start removes nothing it does not hold; a log two programs wrote is refused ---

LATE_START = """import os, sys, time
from studyapp.experiment import session
from studyapp.experiment.protocol import load_protocol
real = session.ParticipantLock
def late(folder, participant):  # the folder is made; another start wins the lock meanwhile
    print("made", flush=True)
    deadline = time.monotonic() + 30
    while not os.path.exists(sys.argv[4]) and time.monotonic() < deadline:
        time.sleep(0.05)
    return real(folder, participant)
session.ParticipantLock = late
try:
    session.Session.create(load_protocol(sys.argv[1]), sys.argv[2], sys.argv[3])
except Exception as exc:
    print("refused:", exc, flush=True)
"""

HOLD = """import sys, time
from studyapp.experiment.protocol import load_protocol
from studyapp.experiment.session import Session
Session.create(load_protocol(sys.argv[1]), sys.argv[2], sys.argv[3])
print("held", flush=True)
time.sleep(60)
"""


def python(code, *args):
    return subprocess.Popen([sys.executable, "-c", code, *map(str, args)], cwd=ROOT, stdout=subprocess.PIPE, text=True)


def test_a_start_that_loses_the_race_leaves_the_winners_lock(tmp_path, protocol):
    go = tmp_path / "go"
    loser = python(LATE_START, DEMO, "L06", tmp_path, go)
    winner = None
    try:
        assert loser.stdout.readline().strip() == "made"  # the loser made the participant folder, and waits
        winner = python(HOLD, DEMO, "L06", tmp_path)
        assert winner.stdout.readline().strip() == "held"
        go.touch()
        lock = tmp_path / "demo" / "L06" / ".lock"
        inode = lock.stat().st_ino
        said = loser.communicate(timeout=60)[0]
        assert f"is in a session already, held by PID {winner.pid}" in said, said
        assert lock.stat().st_ino == inode  # the winner's lock file, not removed by the loser's clean-up
        with pytest.raises(UserError, match=f"held by PID {winner.pid} "):
            Session.resume(protocol, "L06", tmp_path)  # so no third program writes beside the winner
    finally:
        for p in (loser, winner):
            if p is not None:
                p.kill()
                p.communicate()


def test_a_failed_start_leaves_a_study_lock_another_program_holds(tmp_path, protocol, monkeypatch):
    """The start made the study folder; another participant's start enrols (holds the study's lock)
    when this one fails (a full disk) and cleans up."""
    from studyapp.experiment import session as module
    from studyapp.experiment.session_lock import StudyLock

    study = tmp_path / "demo"
    holder = []
    real_make = module.make_folders

    def make_then_another_enrols(path):
        made = real_make(path)
        if not holder:
            holder.append(subprocess.Popen([sys.executable, "-c", "import sys, time\n"
                                            "from studyapp.experiment.session_lock import StudyLock\n"
                                            f"with StudyLock({str(study)!r}):\n"
                                            "    print('held', flush=True)\n"
                                            "    time.sleep(60)\n"], cwd=ROOT, stdout=subprocess.PIPE, text=True))
            assert holder[0].stdout.readline().strip() == "held"
        return made

    def full_disk(folder, info):
        raise OSError(28, "No space left on device")

    monkeypatch.setattr(module, "make_folders", make_then_another_enrols)
    monkeypatch.setattr(module, "_write_description", full_disk)
    monkeypatch.setattr(module, "StudyLock", lambda folder: open(os.devnull))  # this start enrols at once
    try:
        with pytest.raises(UserError, match="No space left on device"):
            Session.create(protocol, "L07", tmp_path)
        assert (study / ".lock").exists() and not (study / "L07").exists()
        fd = os.open(study / ".lock", os.O_RDWR)
        with pytest.raises(BlockingIOError):  # still the holder's
            fcntl.flock(fd, fcntl.LOCK_EX | fcntl.LOCK_NB)
        os.close(fd)
    finally:
        for p in holder:
            p.kill()
            p.communicate()
    with StudyLock(study):
        pass  # free again


def two_writers(results, protocol, participant):
    """A session whose log a second program appended to at once (as when a lock was lost)."""
    from tests.experiment.experiment_fake_loop import run_simulated

    session = Session.create(protocol, participant, results, seed=1)
    run_simulated(session, trials=2).finish("interrupted")
    session.close()  # the log's own lock now refuses a second writer at once: it writes after the first
    second = SessionLog(session.folder / "events.jsonl")
    second.seq -= 5  # it opened the log a few events ago
    answered = [e for e in read_log(session.folder / "events.jsonl").events if e["type"] == "response"]
    second.append({**{k: v for k, v in answered[-1].items() if k not in ("seq", "mono", "wall")}, "fmax": 9.0})
    second.close()
    return session.folder


def test_export_and_analyse_skip_a_log_two_programs_wrote_and_strict_refuses(tmp_path, protocol, capsys):
    from studyapp.cli import main
    from tests.experiment.demo_protocol import trials_only_demo

    results = tmp_path / "results"
    short = load_protocol(trials_only_demo(tmp_path))
    good = Session.create(short, "G01", results, seed=2)
    from tests.experiment.experiment_fake_loop import run_simulated

    run_simulated(good, trials=2).finish("interrupted")
    good.close()
    bad = two_writers(results, short, "G02")
    out = tmp_path / "r.csv"
    assert main(["export", str(results), "-o", str(out)]) == 0
    err = capsys.readouterr().err
    line = next(x for x in err.splitlines() if "warning" in x)
    assert f"{bad}: skipped, {bad / 'events.jsonl'}: 1 steps with more than one response (first: step 1" in line
    assert "seq values repeated" in line and "two programs wrote this log at once" in line
    import pandas as pd

    assert set(pd.read_csv(out).participant) == {"G01"}
    assert main(["export", str(results), "-o", str(tmp_path / "s.csv"), "--strict"]) == 2
    assert not (tmp_path / "s.csv").exists()
    capsys.readouterr()
    assert main(["analyse", str(results), "-o", str(tmp_path / "rep"), "--strict"]) == 2
    err = capsys.readouterr().err
    assert "two programs wrote this log at once" in err and not (tmp_path / "rep").exists()


def test_resume_refuses_a_log_two_programs_wrote_and_leaves_it_as_it_was(tmp_path):
    # on main resume continued such a log, and export, which skips it whole, then lost what the resumed
    # session added too
    from tests.experiment.demo_protocol import trials_only_demo

    results = tmp_path / "results"
    short = load_protocol(trials_only_demo(tmp_path))
    folder = two_writers(results, short, "R01")
    before = (folder / "events.jsonl").read_bytes()
    with pytest.raises(UserError) as refused:
        Session.resume(short, "R01", results)
    line = str(refused.value)
    assert f"{folder / 'events.jsonl'}: 1 steps with more than one response" in line
    assert "two programs wrote this log at once" in line and "allowed is to run the participant again under another participant ID" in line
    assert (folder / "events.jsonl").read_bytes() == before
    Session.create(short, "R01b", results, seed=3).close()
    Session.resume(short, "R01b", results).close()  # the refused resume let go of nothing it should not hold
    with pytest.raises(UserError, match="two programs wrote"):  # and holds no lock: refused again, not locked out
        Session.resume(short, "R01", results)
