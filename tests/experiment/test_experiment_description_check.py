"""session.json checked against the log's CRC-protected ``session_created`` (issue 33, item 1).

On main one flipped bit of session.json changed exported values without a word
(SIM02 -> SIM03, a ceiling of 40.0 -> 60.0), a flipped key letter dropped the
session from export although its log held an intact description, and resume
continued with the flipped protocol. Now the log's copy is used and each field
that differs is reported in one line naming the file and the field."""

import os
import random
import shutil

import pandas as pd
import pytest

from studyapp.errors import UserError
from studyapp.experiment.export import export_responses
from studyapp.experiment.protocol import load_protocol
from studyapp.experiment.session import Session
from tests.experiment.demo_protocol import trials_only_demo
from tests.experiment.experiment_fake_loop import run_simulated

FLIPS = 400  # a seeded sample of (byte, bit) over the whole file


@pytest.fixture
def stored(tmp_path):
    """A results folder with SIM02's session (two trials answered) and its export."""
    protocol = load_protocol(trials_only_demo(tmp_path))
    results = tmp_path / "results"
    session = Session.create(protocol, "SIM02", results, seed=3)
    run_simulated(session, trials=2).finish("interrupted")
    session.close()
    baseline = export_responses(results, [])
    assert len(baseline) > 0
    return protocol, results, session.folder, baseline


def _flipped(data, offset, bit):
    return data[:offset] + bytes([data[offset] ^ (1 << bit)]) + data[offset + 1:]


def _named_flips(data):
    """(offset, bit) of the issue's flips: SIM02 -> SIM03, 40.0 -> 60.0 (both copies), a key's letter."""
    sim = data.index(b'"SIM02"') + 5  # '2' (0x32) -> '3' (0x33)
    ceilings = [i for i in range(len(data)) if data.startswith(b"ceiling", i)]
    forty = [data.index(b"40.0", at) for at in ceilings]  # '4' (0x34) -> '6' (0x36)
    key = data.index(b'"study"') + 2  # 't' -> 'u'
    return [(sim, 0), *((at, 1) for at in forty), (key, 0)]


def test_no_flip_of_session_json_changes_or_drops_an_exported_value(stored):
    _, results, folder, baseline = stored
    path = folder / "session.json"
    data = path.read_bytes()
    rng = random.Random(33)
    flips = _named_flips(data) + [(rng.randrange(len(data)), rng.randrange(8)) for _ in range(FLIPS)]
    changed, dropped, silent = [], [], []
    for offset, bit in flips:
        path.write_bytes(_flipped(data, offset, bit))
        problems = []
        frame = export_responses(results, problems)
        if frame.empty:
            dropped.append(offset)
        elif not frame.equals(baseline):
            changed.append(offset)
        elif not problems and _flipped(data, offset, bit) != data and not _same_json(data, offset, bit):
            silent.append(offset)
    path.write_bytes(data)
    assert (changed, dropped, silent) == ([], [], [])


def _same_json(data, offset, bit):
    import json

    try:
        return json.loads(_flipped(data, offset, bit)) == json.loads(data)
    except ValueError:
        return False


def test_a_flipped_participant_is_reported_by_field_and_the_log_copy_exported(stored):
    _, results, folder, baseline = stored
    path = folder / "session.json"
    data = path.read_bytes()
    path.write_bytes(data.replace(b'"SIM02"', b'"SIM03"', 1))
    problems = []
    frame = export_responses(results, problems)
    assert set(frame.participant) == {"SIM02"} and frame.equals(baseline)
    assert [p for p in problems if "'participant'" in p] == [
        f"{path}: field 'participant' differs from the session_created record of events.jsonl ('SIM03' here, "
        "'SIM02' there): the log's copy is used"]


def test_resume_uses_the_log_copy_of_a_flipped_ceiling(stored):
    protocol, results, folder, _ = stored
    path = folder / "session.json"
    data = path.read_bytes()
    flipped = data.replace(b"ceiling = 40.0", b"ceiling = 60.0").replace(b'"ceiling": 40.0', b'"ceiling": 60.0')
    assert flipped != data
    path.write_bytes(flipped)
    session = Session.resume(protocol, "SIM02", results)
    try:
        assert "ceiling = 40.0" in session.protocol.text and session.protocol.settings() == protocol.settings()
        assert any("field 'protocol" in note and "the log's copy is used" in note for note in session.notes)
    finally:
        session.close()


def test_resume_refuses_a_copied_or_linked_participant_folder_and_changes_nothing(stored):
    protocol, results, folder, _ = stored
    study = folder.parent.parent
    shutil.copytree(folder.parent, study / "SIM04")
    os.symlink(folder.parent, study / "SIM05")
    for participant, said in (("SIM04", "holds a session of participant 'SIM02'"), ("SIM05", "a link to")):
        log = next((study / participant).glob("*/events.jsonl"))
        before = log.read_bytes()
        with pytest.raises(UserError) as refused:
            Session.resume(protocol, participant, results)
        assert said in str(refused.value) and "\n" not in str(refused.value)
        assert log.read_bytes() == before
    problems = []
    frame = export_responses(results, problems)
    assert any(p.startswith(str(study / "SIM04")) and "a copy of session" in p for p in problems)  # counted once
    assert isinstance(frame, pd.DataFrame)
