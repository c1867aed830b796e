"""The checksum decides (issue 21, items 4-7): a flipped bit never blocks a study, a confirmed
event is never dropped for a damaged newline, resume writes a missing ``session_end``, and a
full disk while creating a session says what is true."""

import errno
import json

import numpy as np
import pandas as pd
import pytest

from studyapp.cli import main
from studyapp.errors import UserError
from studyapp.experiment.export import export_responses
from studyapp.experiment.protocol import load_protocol
from studyapp.experiment.session import Session
from studyapp.experiment.session_log import read_log, scan
from tests.experiment.demo_protocol import trials_only_demo
from tests.experiment.experiment_fake_loop import run_simulated


@pytest.fixture
def protocol(tmp_path):
    return load_protocol(trials_only_demo(tmp_path))


def session_with(results, protocol, participant, trials=None):
    session = Session.create(protocol, participant, results, seed=1)
    runner = run_simulated(session, trials=trials)
    if trials is None:
        runner.finish()
    else:
        runner.finish("interrupted")
    session.close()
    return session.folder


def line_of(path, kind):
    """The 1-based number of the last line holding an event of type ``kind``."""
    return max(n for n, e in zip(read_log(path).lines, read_log(path).events) if e["type"] == kind)


def replace_on_line(path, number, old, new):
    lines = path.read_bytes().split(b"\n")
    assert old in lines[number - 1]
    lines[number - 1] = lines[number - 1].replace(old, new, 1)
    path.write_bytes(b"\n".join(lines))


def test_a_flipped_bit_in_the_type_key_is_a_damaged_line_not_a_refused_study(tmp_path, protocol, capsys):
    intact = session_with(tmp_path, protocol, "C01", trials=2)
    hit = session_with(tmp_path, protocol, "C02", trials=2)
    events_file = hit / "events.jsonl"
    number = line_of(events_file, "knob")
    replace_on_line(events_file, number, b'"type"', b'"typa"')  # valid JSON, no event: the checksum says damaged
    out = tmp_path / "r.csv"
    assert main(["export", str(tmp_path), "-o", str(out)]) == 0
    err = capsys.readouterr().err
    assert f"warning: {events_file} line {number}: damaged (checksum mismatch), left out" in err
    assert set(pd.read_csv(out).participant) == {"C01", "C02"}  # every response of both kept
    assert main(["export", str(tmp_path), "-o", str(tmp_path / "s.csv"), "--strict"]) == 2
    assert intact.exists()


@pytest.mark.parametrize("seed", [0, 1, 2])
def test_no_single_bit_flip_blocks_an_export_or_loses_more_than_its_line(tmp_path, protocol, seed):
    folder = session_with(tmp_path, protocol, "C03", trials=2)
    events_file = folder / "events.jsonl"
    whole = events_file.read_bytes()
    before = export_responses(tmp_path)
    rng = np.random.default_rng(seed)
    newlines = [i for i, byte in enumerate(whole) if byte == 0x0A]
    for position in [*rng.choice(len(whole), 60, replace=False), *rng.choice(newlines, 10, replace=False)]:
        flipped = bytearray(whole)
        flipped[position] ^= 1 << int(rng.integers(8))
        events_file.write_bytes(bytes(flipped))
        problems = []
        frame = export_responses(tmp_path, problems)  # never InputDataError: a flip is damage, not an edit
        log = scan(bytes(flipped))
        assert len(log.damaged) <= 1 and not log.malformed and not log.torn
        assert len(problems) == len(log.damaged)
        assert len(frame) >= len(before) - 3  # at most the one response on the damaged line (three rows)
        if not log.damaged:  # a flip in a newline: every event kept
            assert len(log.events) == len(scan(whole).events)
            pd.testing.assert_frame_equal(frame, before)


def test_a_line_without_its_checksum_in_a_checksummed_log_is_damaged(tmp_path):
    from studyapp.experiment.session_log import SessionLog

    path = tmp_path / "events.jsonl"
    with SessionLog(path) as log:
        log.append({"type": "response", "step": 0})
        log.append({"type": "response", "step": 1})
    replace_on_line(path, 2, b'"crc"', b'"crb"')  # the checksum's own key flipped
    log = read_log(path)
    assert [e["step"] for e in log.events] == [0] and [(n, why) for n, why, _ in log.damaged] == [(2, "no checksum")]
    # lines before the first checksum (a session begun by a version that wrote none) are read as they are
    path.write_bytes(b'{"seq":0,"type":"old"}\n' + path.read_bytes())
    log = read_log(path)
    assert [e["type"] for e in log.events] == ["old", "response"] and [n for n, *_ in log.damaged] == [3]


def test_a_confirmed_last_response_with_a_damaged_newline_is_kept_on_resume(tmp_path, protocol):
    folder = session_with(tmp_path, protocol, "C04", trials=2)
    events_file = folder / "events.jsonl"
    data = events_file.read_bytes()
    cut = data.rindex(b'"type":"response"')
    data = data[: data.index(b"\n", cut) + 1]  # the run ended right after the response was confirmed
    events_file.write_bytes(data[:-1] + b"\x0b")  # ... and its newline was damaged (one bit)
    assert [e["step"] for e in read_log(events_file).events if e["type"] == "response"] == [0, 1]
    session = Session.resume(protocol, "C04", tmp_path)
    assert session.next_trial().step == 2  # not asked again
    assert any("damaged newline of the last confirmed event" in note for note in session.notes), session.notes
    session.close()
    after = events_file.read_bytes()
    assert after.startswith(data) and not read_log(events_file).damaged
    copies = list(folder.glob("events.jsonl.torn-*"))
    assert len(copies) == 1 and copies[0].read_bytes() == b"\x0b"


def test_two_confirmed_events_run_together_by_a_damaged_newline_are_both_kept(tmp_path, protocol):
    folder = session_with(tmp_path, protocol, "C05", trials=2)
    events_file = folder / "events.jsonl"
    whole = read_log(events_file).events
    number = line_of(events_file, "response")
    data = events_file.read_bytes()
    lines = data.split(b"\n")
    at = sum(len(x) + 1 for x in lines[: number - 1]) - 1  # the newline before the response
    events_file.write_bytes(data[:at] + b"J" + data[at + 1:])
    log = read_log(events_file)
    assert log.events == whole and log.mended == [number - 1] and not log.damaged
    problems = []
    assert len(export_responses(tmp_path, problems)) == 4 and problems == []


def complete_but_for_its_end(results, protocol, participant):
    """A complete session killed between its last response and ``session_end``."""
    folder = session_with(results, protocol, participant)
    events_file = folder / "events.jsonl"
    log = read_log(events_file)
    end = log.lines[[e["type"] for e in log.events].index("session_end")]
    events_file.write_bytes(b"".join(events_file.read_bytes().split(b"\n")[i] + b"\n" for i in range(end - 1)))
    return events_file


def test_resume_writes_a_missing_session_end_and_export_counts_the_session_whole(tmp_path, protocol):
    events_file = complete_but_for_its_end(tmp_path, protocol, "C06")
    assert not any(e["type"] == "session_end" for e in read_log(events_file).events)
    problems = []
    frame = export_responses(tmp_path, problems)
    assert problems == [] and sorted(frame.step.unique()) == [0, 1, 2, 3]
    with pytest.raises(UserError, match=r"already complete \(its missing session_end event written\)"):
        Session.resume(protocol, "C06", tmp_path)
    ends = [e for e in read_log(events_file).events if e["type"] == "session_end"]
    assert len(ends) == 1 and ends[0]["recovered"] is True
    with pytest.raises(UserError, match=r"already complete: nothing to resume"):
        Session.resume(protocol, "C06", tmp_path)  # written once
    assert len([e for e in read_log(events_file).events if e["type"] == "session_end"]) == 1
    pd.testing.assert_frame_equal(export_responses(tmp_path), frame)


def test_a_full_disk_while_creating_a_session_says_start_again_not_resume(tmp_path, protocol, monkeypatch, capsys):
    from studyapp.experiment import session_log

    real = session_log.os.write

    def full(fd, data):
        if b'"session_created"' in data:
            raise OSError(errno.ENOSPC, "No space left on device")
        return real(fd, data)

    monkeypatch.setattr(session_log.os, "write", full)
    argv = ["run", "--protocol", protocol.path, "--participant", "C07", "--headless", "--simulated-participant",
            "--results", str(tmp_path / "results")]
    assert main(argv) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and "No space left on device" in err[0] and "Traceback" not in err[0]
    assert "nothing was kept" in err[0] and "start the session again (without --resume)" in err[0]
    assert "then resume it" not in err[0]
    assert not (tmp_path / "results" / "demo" / "C07").exists()  # true: there is nothing to resume
    monkeypatch.undo()
    with pytest.raises(UserError, match="has no session to resume"):
        Session.resume(protocol, "C07", tmp_path / "results")
    Session.create(protocol, "C07", tmp_path / "results").close()  # starting again works
    assert json.loads(next((tmp_path / "results").glob("demo/C07/*/session.json")).read_text())["participant"] == "C07"
