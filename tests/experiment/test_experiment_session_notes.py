"""Issue 22 item 16: notes added after a session are logged with their time as events, and listed."""

import contextlib
import io

import pytest

from studyapp.cli import main
from studyapp.errors import UserError
from studyapp.experiment.protocol import load_protocol
from studyapp.experiment.session import Session
from studyapp.experiment.session_log import read_events
from studyapp.experiment.session_notes import add_note, list_notes
from tests.experiment.demo_protocol import trials_only_demo


@pytest.fixture
def session_folder(tmp_path):
    session = Session.create(load_protocol(trials_only_demo(tmp_path)), "P01", tmp_path / "results")
    session.close()
    return session.folder


def test_a_note_after_the_session_is_an_event_with_its_time(session_folder):
    record = add_note(session_folder, "the participant\tsneezed\nat trial 3")
    last = read_events(session_folder / "events.jsonl")[-1]
    assert last == record and last["type"] == "note" and last["by"] == "experimenter"
    assert last["text"] == "the participant\tsneezed\nat trial 3" and last["wall"] and last["mono"] > 0
    add_note(session_folder.parent, "a second note")  # a participant folder: their latest session
    notes = list_notes(session_folder.parents[2])
    assert notes["text"].tolist() == ["the participant\tsneezed\nat trial 3", "a second note"]
    assert notes["participant"].tolist() == ["P01", "P01"] and notes["step"].isna().all()


def test_a_note_is_refused_while_the_session_is_open_elsewhere_and_when_empty(session_folder, tmp_path):
    protocol = load_protocol(tmp_path / "demo.toml")
    before = (session_folder / "events.jsonl").read_bytes()
    session = Session.resume(protocol, "P01", tmp_path / "results")
    try:
        with pytest.raises(UserError, match="'P01' is in a session already"):
            add_note(session_folder, "too soon")
    finally:
        session.close()
    for text in ("", "   ", "bell\x07", "x" * 2001):
        with pytest.raises(UserError, match="note"):
            add_note(session_folder, text)
    assert (session_folder / "events.jsonl").read_bytes().startswith(before)
    assert not [e for e in read_events(session_folder / "events.jsonl") if e["type"] == "note"]


def _notes_cli(*args):
    out, err = io.StringIO(), io.StringIO()
    with contextlib.redirect_stdout(out), contextlib.redirect_stderr(err):
        code = main(["notes", *map(str, args)])
    return code, out.getvalue(), err.getvalue()


def test_notes_command_adds_and_lists(session_folder, tmp_path):
    code, _, err = _notes_cli(session_folder, "--add", "headphones re-seated")
    assert code == 0 and "note logged in" in err
    code, out, _ = _notes_cli(tmp_path / "results")
    assert code == 0 and out.rstrip().endswith(f"P01 {session_folder.name}: headphones re-seated")
    code, _, _ = _notes_cli(tmp_path / "results", "-o", tmp_path / "notes.csv")
    assert code == 0 and "headphones re-seated" in (tmp_path / "notes.csv").read_text()
    code, _, err = _notes_cli(tmp_path / "results", "--add", "where?")
    assert code == 2 and "not a session folder" in err and len(err.strip().splitlines()) == 1
