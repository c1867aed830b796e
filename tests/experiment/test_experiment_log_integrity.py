"""A log that never loses a confirmed response (issue 14, item 2): one damaged line
hides nothing else and is reported by file and line; resume removes nothing but a
torn last line, and keeps a copy of it; a damaged session.json is rebuilt from the
log or refused in one line; export skips an unreadable session with a warning
(refuses with --strict); a write that fails (file too large) tears nothing."""

import json
import os
import resource
import signal
import subprocess
import sys
import zlib
from pathlib import Path

import pytest

from studyapp.cli import main
from studyapp.errors import InputDataError, UserError
from studyapp.experiment.export import export_responses
from studyapp.experiment.protocol import load_protocol
from studyapp.experiment.session import Session
from studyapp.experiment.session_log import LogWriteError, SessionLog, read_log
from studyapp.experiment.session_runner import closed_loop_factory
from tests.experiment.demo_protocol import trials_only_demo
from tests.experiment.experiment_fake_loop import run_simulated

ROOT = Path(__file__).resolve().parents[2]


@pytest.fixture
def protocol(tmp_path):
    return load_protocol(trials_only_demo(tmp_path))


def two_trials(results, protocol, participant="D01", apparatus=None):
    """A session with its rating and first adjustment trial answered (line 21 holds the rating response)."""
    session = Session.create(protocol, participant, results, seed=1, apparatus=apparatus)
    run_simulated(session, trials=2).finish("interrupted")
    session.close()
    return session.folder


def damage(path, line, old, new):
    """Replace ``old`` by ``new`` (same length) on 1-based ``line`` of ``path``."""
    lines = path.read_bytes().split(b"\n")
    assert old in lines[line - 1] and len(old) == len(new)
    lines[line - 1] = lines[line - 1].replace(old, new, 1)
    path.write_bytes(b"\n".join(lines))


def responses(events):
    return [e for e in events if e["type"] == "response"]


def test_every_line_carries_a_crc32_of_its_own_bytes(tmp_path):
    path = tmp_path / "events.jsonl"
    with SessionLog(path) as log:
        log.append({"type": "x", "value": 0.5})
    line = path.read_bytes().rstrip(b"\n")
    head, crc = line.rsplit(b',"crc":"', 1)
    assert zlib.crc32(head + b"}") == int(crc[:8], 16)  # zlib is the reference, independent of the log


def test_a_damaged_line_in_the_middle_hides_nothing_after_it(tmp_path, protocol):
    folder = two_trials(tmp_path, protocol)
    events_file = folder / "events.jsonl"
    before = read_log(events_file).events
    # One byte of the rating response (line 21) damaged, the JSON still valid: only the checksum can tell.
    damage(events_file, 21, b'"trial":1', b'"trial":7')
    log = read_log(events_file)
    assert [n for n, why, _ in log.damaged] == [21] and log.damaged[0][1] == "checksum mismatch"
    assert len(log.events) == len(before) - 1  # every other line kept, those after it too
    assert responses(log.events) == responses(before)[1:]
    # A byte that breaks the JSON on line 20: still only that line is left out.
    damage(events_file, 20, b'{"seq"', b'{"s\x00q"')
    log = read_log(events_file)
    assert [(n, why) for n, why, _ in log.damaged] == [(20, "not valid JSON"), (21, "checksum mismatch")]

    problems = []
    frame = export_responses(tmp_path, problems)
    assert len(frame) == 1 and frame.condition.tolist() == [responses(before)[1]["condition"]]
    assert problems == [f"{events_file} line 20: damaged (not valid JSON), left out; the lines after it are kept",
                        f"{events_file} line 21: damaged (checksum mismatch), left out; the lines after it are kept"]
    with pytest.raises(InputDataError, match="line 20: damaged"):
        export_responses(tmp_path)  # never silent: without a list for the problems, the first one is an error


def test_resume_after_damage_removes_nothing_and_sets_the_lines_aside(tmp_path, protocol):
    folder = two_trials(tmp_path, protocol)
    events_file = folder / "events.jsonl"
    damage(events_file, 20, b'"seq"', b'"s\xffq"')
    damaged = events_file.read_bytes()
    session = Session.resume(protocol, "D01", tmp_path)
    assert session.notes == [f"{events_file} line 20: damaged (not valid JSON), set aside in events.jsonl.damaged; "
                             "the lines after it are kept"]
    assert session.next_trial().step == 2  # both confirmed responses still count
    session.close()
    assert events_file.read_bytes().startswith(damaged)  # nothing removed or rewritten
    assert (folder / "events.jsonl.damaged").read_bytes() == damaged.split(b"\n")[19] + b"\n"
    noted = [e for e in read_log(events_file).events if e["type"] == "log_damaged"]
    assert noted == [{**noted[0], "lines": [20], "copy": "events.jsonl.damaged"}]
    Session.resume(protocol, "D01", tmp_path).close()  # seen again: reported, not logged twice
    assert len([e for e in read_log(events_file).events if e["type"] == "log_damaged"]) == 1


def test_a_torn_last_line_is_copied_aside_and_the_repair_reported(tmp_path, protocol):
    folder = two_trials(tmp_path, protocol)
    events_file = folder / "events.jsonl"
    whole = events_file.read_bytes()
    torn = b'{"seq":93,"type":"kno'
    events_file.write_bytes(whole + torn)
    session = Session.resume(protocol, "D01", tmp_path)
    session.close()
    copies = list(folder.glob("events.jsonl.torn-*"))
    assert len(copies) == 1 and copies[0].read_bytes() == torn
    assert len(session.notes) == 1 and "torn last line (21 bytes" in session.notes[0] and copies[0].name in session.notes[0]
    after = events_file.read_bytes()
    assert after.startswith(whole) and after.endswith(b"\n")
    repaired = read_log(events_file).events[-1]
    assert repaired["type"] == "log_repaired" and repaired["dropped_bytes"] == len(torn)


def test_a_last_line_that_lacks_only_its_newline_is_kept(tmp_path):
    path = tmp_path / "events.jsonl"
    with SessionLog(path) as log:
        log.append({"type": "response", "step": 0})
    path.write_bytes(path.read_bytes()[:-1])
    assert [e["type"] for e in read_log(path).events] == ["response"]
    with SessionLog(path) as log:
        assert log.seq == 1 and "lacked its newline" in log.notes[0]
    assert path.read_bytes().endswith(b"}\n") and not list(tmp_path.glob("*.torn-*"))


def test_a_damaged_session_json_is_rebuilt_from_the_log_on_resume(tmp_path, protocol, capsys):
    folder = two_trials(tmp_path, protocol, apparatus={"participant": "simulated"})  # resumed by the simulated one
    original = json.loads((folder / "session.json").read_text())
    events_file = folder / "events.jsonl"
    events_file.write_bytes(events_file.read_bytes() + b'{"seq":93,"ty')  # and a torn last line
    (folder / "session.json").write_text((folder / "session.json").read_text()[:100])  # truncated
    code = main(["run", "--protocol", protocol.path, "--participant", "D01", "--resume", "--headless",
                 "--simulated-participant", "--results", str(tmp_path)])
    err = capsys.readouterr().err
    assert code == 0, err
    assert "Traceback" not in err
    assert f"warning: {folder / 'session.json'}: damaged" in err and "rebuilt from events.jsonl" in err
    assert "warning: " in err and "torn last line" in err
    assert json.loads((folder / "session.json").read_text()) == original
    assert len(list(folder.glob("session.json.damaged-*"))) == 1
    final = responses(read_log(events_file).events)
    assert sorted(e["step"] for e in final) == [0, 1, 2, 3]


def test_resuming_a_complete_session_still_rebuilds_its_session_json(tmp_path, protocol):
    session = Session.create(protocol, "D03", tmp_path, seed=1)
    run_simulated(session).finish()
    session.close()
    path = session.folder / "session.json"
    original = path.read_bytes()
    path.unlink()
    with pytest.raises(UserError, match=r"already complete \(its session.json rebuilt from events.jsonl\)"):
        Session.resume(protocol, "D03", tmp_path)
    assert path.read_bytes() == original


def test_an_unreadable_session_is_refused_in_one_line_and_skipped_by_export(tmp_path, protocol, capsys):
    good = two_trials(tmp_path, protocol, "D01")
    bad = two_trials(tmp_path, protocol, "D02")
    # An older session, without the session_created event: session.json cannot be rebuilt.
    lines = (bad / "events.jsonl").read_bytes().split(b"\n")
    (bad / "events.jsonl").write_bytes(b"\n".join(lines[1:]))
    (bad / "session.json").write_bytes(b"\x00" * 10)
    code = main(["run", "--protocol", protocol.path, "--participant", "D02", "--resume", "--headless",
                 "--simulated-participant", "--results", str(tmp_path)])
    err = capsys.readouterr().err.strip()
    assert code == 2 and len(err.splitlines()) == 1 and "Traceback" not in err
    assert f"{bad / 'session.json'}: damaged" in err and "holds no session description" in err

    out = tmp_path / "r.csv"
    assert main(["export", str(tmp_path), "-o", str(out), "--strict"]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert err[0].startswith(f"studyapp export: warning: {bad}: skipped, {bad / 'session.json'}: damaged")
    assert err[1].startswith("studyapp: error: ") and "--strict" in err[1] and len(err) == 2
    assert not out.exists()
    assert main(["export", str(tmp_path), "-o", str(out)]) == 0
    err = capsys.readouterr().err
    assert f"warning: {bad}: skipped" in err and "4 responses from 1 sessions" in err
    assert set(__import__("pandas").read_csv(out).session) == {good.name}


def test_a_write_error_stops_the_runner_at_zero_force_and_tears_nothing(tmp_path, protocol):
    session = Session.create(protocol, "W01", tmp_path, seed=1)
    made = []
    runner = run_simulated(session, made, trials=1)
    runner.start_trial()
    runner.knob(runner.task.knob_index, 100)
    assert made[-1].fmax > 0
    before = (session.folder / "events.jsonl").read_bytes()
    os.close(session.log._fd)
    session.log._fd = os.open(session.folder / "session.json", os.O_RDONLY)  # every write now fails
    with pytest.raises(LogWriteError, match="cannot write the session log"):
        runner.knob(runner.task.knob_index, 110)
    assert made[-1].fmax == 0.0
    session.close()
    assert (session.folder / "events.jsonl").read_bytes() == before


def warm_numba_cache(protocol):
    """Load (or compile and cache) the loop's functions here first: under the file-size
    limit, numba could not write its cache files, which are larger than the limit."""
    make_loop = closed_loop_factory(protocol)
    every = [tuple(protocol.task(name).conditions) for name in protocol.tasks]
    for conditions in every + [(c,) for c in set().union(*every)]:
        loop = make_loop({c: protocol.estimator_params(c) for c in conditions}, conditions[0], 0)
        loop.set_bowing(True)
        loop.set_fmax(1.0)
        loop.run(50)


def _limit_file_size(limit):
    def preexec():
        signal.signal(signal.SIGXFSZ, signal.SIG_IGN)  # a write past the limit then fails with EFBIG
        resource.setrlimit(resource.RLIMIT_FSIZE, (limit, limit))
    return preexec


def test_a_full_disk_stops_the_run_in_one_line_and_resume_continues(tmp_path, protocol):
    warm_numba_cache(protocol)
    results = tmp_path / "results"
    argv = [sys.executable, "-m", "studyapp", "run", "--protocol", protocol.path, "--participant", "F01",
            "--headless", "--simulated-participant", "--results", str(results), "--seed", "3"]
    run = subprocess.run(argv, cwd=ROOT, capture_output=True, text=True, timeout=120,
                         preexec_fn=_limit_file_size(16_000))
    err = run.stderr.strip().splitlines()
    assert run.returncode == 2, run.stderr
    assert "Traceback" not in run.stderr
    assert err[-1].startswith("studyapp: error: ") and "cannot write the session log (File too large)" in err[-1]
    events_file = next(results.glob("demo/F01/*/events.jsonl"))
    log = read_log(events_file)
    assert not log.damaged and not log.torn and 14_000 < events_file.stat().st_size <= 16_000
    answered = len(responses(log.events))

    session = Session.resume(protocol, "F01", results)
    assert session.notes == [] and len(session.finished_steps()) == answered < 4
    run_simulated(session).finish()
    session.close()
    final = responses(read_log(events_file).events)
    assert sorted(e["step"] for e in final) == [0, 1, 2, 3]


def test_analyse_reports_an_unreadable_session_and_strict_refuses(tmp_path, protocol, capsys):
    results = tmp_path / "results"
    two_trials(results, protocol, "D01")
    bad = two_trials(results, protocol, "D02")
    (bad / "events.jsonl").write_bytes(b"\n".join((bad / "events.jsonl").read_bytes().split(b"\n")[1:]))
    (bad / "session.json").unlink()
    report = tmp_path / "report"
    assert main(["analyse", str(results), "-o", str(report), "--strict"]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert f"studyapp analyse: warning: {bad}: skipped, {bad / 'session.json'}: missing" in err[0]
    assert err[-1].startswith("studyapp: error: ") and "--strict" in err[-1] and "Traceback" not in "".join(err)
    assert not report.exists()
