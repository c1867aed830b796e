"""`studyapp run` and `studyapp export` end to end: bad input is one line and exit 2;
a headless simulated session killed with SIGKILL mid-task resumes with nothing lost
or duplicated."""

import json
import os
import signal
import subprocess
import sys
import time
from pathlib import Path

import pandas as pd
import pytest

from studyapp.cli import main
from studyapp.experiment.export import COLUMNS
from studyapp.experiment.session_log import read_events

ROOT = Path(__file__).resolve().parents[2]
DEMO = ROOT / "protocols" / "demo.toml"


def one_line_error(capsys, argv):
    code = main(argv)
    err = capsys.readouterr().err.strip()
    assert code == 2
    assert len(err.splitlines()) == 1 and err.startswith("studyapp: error: ") and "Traceback" not in err
    return err


def test_bad_protocol_is_one_line(tmp_path, capsys):
    bad = tmp_path / "bad.toml"
    bad.write_text(DEMO.read_text().replace("fmax = 1.0", "fmax = -1.0"))
    err = one_line_error(capsys, ["run", "--protocol", str(bad), "--participant", "P1", "--headless",
                                  "--simulated-participant", "--results", str(tmp_path)])
    assert "bad.toml: [rating] fmax" in err
    assert not (tmp_path / "demo").exists()


@pytest.mark.parametrize("argv,expected", [
    (["--participant", "no/slash", "--headless", "--simulated-participant"], "participant ID 'no/slash'"),
    (["--participant", "P1", "--headless"], "--headless: allowed only with --simulated-participant"),
    (["--participant", "P1", "--resume", "--headless", "--simulated-participant"], "no session to resume"),
])
def test_bad_run_arguments_are_one_line(tmp_path, capsys, argv, expected):
    err = one_line_error(capsys, ["run", "--protocol", str(DEMO), "--results", str(tmp_path), *argv])
    assert expected in err


def test_without_headless_and_without_a_display_is_one_line(tmp_path, capsys, monkeypatch):
    for name in ("DISPLAY", "WAYLAND_DISPLAY", "QT_QPA_PLATFORM"):
        monkeypatch.delenv(name, raising=False)
    err = one_line_error(capsys, ["run", "--protocol", str(DEMO), "--participant", "P1", "--results", str(tmp_path)])
    assert "no display" in err and "--headless" in err
    assert not (tmp_path / "demo").exists()  # nothing started, nothing written


def test_export_of_an_empty_folder_is_one_line(tmp_path, capsys):
    err = one_line_error(capsys, ["export", str(tmp_path), "-o", str(tmp_path / "r.csv")])
    assert "no responses" in err


def studyapp(*args, **kwargs):
    return subprocess.Popen([sys.executable, "-m", "studyapp", *args], cwd=ROOT, stdout=subprocess.PIPE,
                            stderr=subprocess.PIPE, text=True, **kwargs)


def responses(events):
    return [e for e in events if e["type"] == "response"]


def test_sigkill_mid_task_then_resume_loses_and_repeats_nothing(tmp_path):
    protocol = tmp_path / "crash.toml"
    protocol.write_text(DEMO.read_text().replace('name = "demo"', 'name = "crash"').replace("trials = 1", "trials = 3"))
    results = tmp_path / "results"
    argv = ["run", "--protocol", str(protocol), "--participant", "C01", "--headless", "--simulated-participant",
            "--results", str(results), "--seed", "7"]
    process = studyapp(*argv)
    events_file = None
    deadline = time.monotonic() + 90
    try:
        while time.monotonic() < deadline:
            found = list(results.glob("crash/C01/*/events.jsonl"))
            if found:
                events_file = found[0]
                events = read_events(events_file)
                # Mid-task: two trials answered, a later one begun and not yet answered. Not a page: the
                # simulated participant ends one within milliseconds, before the kill lands.
                answered = {e["step"] for e in responses(events)}
                last = events[-1] if events else {}
                if len(answered) >= 2 and last.get("step") not in (None, *answered) and last.get("task") != "page":
                    break
            assert process.poll() is None, "the session ended before it could be killed"
            time.sleep(0.005)
        process.send_signal(signal.SIGKILL)
    finally:
        process.kill()
        process.communicate()
    assert process.returncode == -signal.SIGKILL
    before = events_file.read_bytes()
    killed = read_events(events_file)
    recorded = responses(killed)
    # what the kill interrupted, as the log on disk says (the step may have ended between reading and killing)
    pending = sorted({e["step"] for e in killed if e["type"] == "trial_start"} - {e["step"] for e in recorded})
    assert len(recorded) >= 2
    assert not any(e["type"] == "session_end" for e in read_events(events_file))

    again = studyapp(*argv[:-2])  # starting again without --resume is refused
    _, err = again.communicate(timeout=60)
    assert again.returncode == 2 and len(err.strip().splitlines()) == 1 and "--resume" in err

    resumed = studyapp(*argv, "--resume")
    out, err = resumed.communicate(timeout=120)
    assert resumed.returncode == 0, err
    assert Path(out.strip()) == events_file.parent

    after = events_file.read_bytes()
    assert after.startswith(before)  # everything on disk before the kill is still there, unchanged
    events = read_events(events_file)
    final = responses(events)
    assert final[: len(recorded)] == recorded
    schedule = json.loads((events_file.parent / "session.json").read_text())["schedule"]
    assert sorted(e["step"] for e in final) == [t["step"] for t in schedule]  # complete, nothing twice
    assert events[-2]["type"] == "session_end"
    assert [e["seq"] for e in events] == list(range(len(events)))
    interrupted = [e for e in events if e["type"] == "trial_start" and e["restart"]]
    assert len(pending) <= 1 and [e["step"] for e in interrupted] == pending

    csv = tmp_path / "responses.csv"
    export = studyapp("export", str(results), "-o", str(csv))
    _, err = export.communicate(timeout=60)
    assert export.returncode == 0, err
    frame = pd.read_csv(csv)
    assert list(frame.columns) == COLUMNS
    assert frame.practice.sum() == 1  # the demo's one adjustment practice trial
    frame = frame[~frame.practice]
    assert len(frame) == 3 + 3 * 3
    assert not frame.duplicated(["participant", "task", "condition", "trial"]).any()
    assert sorted(frame[frame.task == "adjustment"].trial.unique()) == [1, 2, 3]
