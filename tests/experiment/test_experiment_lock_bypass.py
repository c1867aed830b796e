"""Locks that cannot be bypassed, and no writes through planted links (issue 33, items 2 and 3).

On main ``notes LINK --add`` (LINK a symbolic link to a running session's
folder) locked the link's parent and wrote while the session wrote; deleting
``.lock`` while a session ran let ``run --resume`` continue the same log; a
``.lock`` or ``events.jsonl`` planted as a symbolic link was written through.
Now every writer also holds a flock on events.jsonl itself, and no file of a
results folder is opened through a link."""

import os
import subprocess
import sys
from pathlib import Path

import pytest

from studyapp.errors import UserError
from studyapp.experiment.log_scan import written_twice
from studyapp.experiment.protocol import load_protocol
from studyapp.experiment.session import Session
from studyapp.experiment.session_log import read_log
from studyapp.experiment.session_notes import add_note
from tests.experiment.demo_protocol import trials_only_demo
from tests.experiment.experiment_fake_loop import run_simulated

ROOT = Path(__file__).resolve().parents[2]


@pytest.fixture
def protocol(tmp_path):
    return load_protocol(trials_only_demo(tmp_path))


def test_a_note_through_a_link_to_a_running_session_is_refused(tmp_path, protocol):
    session = Session.create(protocol, "K01", tmp_path / "results")
    try:
        log = session.folder / "events.jsonl"
        before = log.read_bytes()
        link = tmp_path / "LINK"
        link.symlink_to(session.folder)
        with pytest.raises(UserError) as refused:
            add_note(link, "written while the session runs")
        assert "'K01' is in a session already" in str(refused.value)
        assert log.read_bytes() == before
        run_simulated(session, trials=1)
    finally:
        session.close()
    assert written_twice(read_log(log)) is None


def test_deleting_the_lock_file_does_not_let_a_second_writer_in(tmp_path, protocol):
    results = tmp_path / "results"
    session = Session.create(protocol, "K02", results)
    try:
        runner = run_simulated(session, trials=1)
        (session.folder.parent / ".lock").unlink()
        log = session.folder / "events.jsonl"
        before = log.read_bytes()
        with pytest.raises(UserError) as refused:
            Session.resume(protocol, "K02", results)
        assert "another program is writing this session now" in str(refused.value)
        with pytest.raises(UserError):
            add_note(session.folder, "a note")
        assert log.read_bytes() == before
        run_simulated(session, trials=1)  # the first program goes on, alone
        runner.finish("interrupted")
    finally:
        session.close()
    log_scan = read_log(log)
    assert written_twice(log_scan) is None and not log_scan.damaged


def test_run_resume_after_the_lock_file_is_deleted_is_refused_in_one_line(tmp_path, protocol):
    results = tmp_path / "results"
    session = Session.create(protocol, "K03", results, apparatus={"participant": "simulated"})  # run by the simulated participant
    try:
        (session.folder.parent / ".lock").unlink()
        log = session.folder / "events.jsonl"
        before = log.read_bytes()
        done = subprocess.run([sys.executable, "-m", "studyapp", "run", "--protocol", protocol.path, "--participant",
                               "K03", "--headless", "--simulated-participant", "--results", str(results), "--resume"],
                              cwd=ROOT, capture_output=True, text=True, timeout=300)
        lines = done.stderr.strip().splitlines()
        assert done.returncode == 2 and len(lines) == 1, done.stderr
        assert "another program is writing this session now" in lines[0]
        assert log.read_bytes() == before
    finally:
        session.close()


def test_a_planted_lock_link_is_refused_and_its_target_untouched(tmp_path, protocol):
    results = tmp_path / "results"
    target = tmp_path / "precious.txt"
    target.write_text("keep me\n")
    folder = results / protocol.study / "K04"
    folder.mkdir(parents=True)
    (folder / ".lock").symlink_to(target)
    with pytest.raises(UserError) as refused:
        Session.create(protocol, "K04", results)
    assert "a symbolic link, not a file this app made" in str(refused.value)
    assert target.read_text() == "keep me\n"
    os.link(target, tmp_path / "second-name")
    (folder / ".lock").unlink()
    os.link(target, folder / ".lock")  # a hard link: the same file under two names
    with pytest.raises(UserError) as refused:
        Session.create(protocol, "K04", results)
    assert "a hard link to another file" in str(refused.value)
    assert target.read_text() == "keep me\n"


def test_a_planted_events_link_is_refused_and_its_target_untouched(tmp_path, protocol):
    results = tmp_path / "results"
    session = Session.create(protocol, "K05", results)
    run_simulated(session, trials=1).finish("interrupted")
    session.close()
    log = session.folder / "events.jsonl"
    target = tmp_path / "elsewhere.jsonl"
    target.write_bytes(log.read_bytes() + b'{"torn')
    before = target.read_bytes()
    log.unlink()
    log.symlink_to(target)
    for write in (lambda: Session.resume(protocol, "K05", results), lambda: add_note(session.folder, "a note")):
        with pytest.raises(UserError) as refused:
            write()
        assert "a symbolic link, not a file this app made" in str(refused.value)
        assert target.read_bytes() == before
