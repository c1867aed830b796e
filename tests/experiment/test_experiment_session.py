"""Sessions on disk: the log, create/refuse/resume, the runner and the simulated
participant (against a loop with known noise and breakdown levels), and export."""

import hashlib
import json
import re
from pathlib import Path

import pandas as pd
import pytest

from studyapp.errors import UserError
from studyapp.experiment.export import COLUMNS, export_responses, save_responses
from studyapp.model.fmax_knob import fmax_from_knob
from studyapp.experiment.protocol import load_protocol
from studyapp.experiment.session import Session
from studyapp.experiment.session_log import SessionLog, read_events
from studyapp.experiment.session_runner import SessionRunner
from studyapp.experiment.simulated_participant import SimulatedParticipant
from tests.experiment.demo_protocol import trials_only_demo
from tests.experiment.experiment_fake_loop import NOISE, THRESHOLD, factory, run_simulated

ROOT = Path(__file__).resolve().parents[2]
CONTRACT = ["participant", "session", "task", "condition", "trial", "fmax", "rating", "time", "protocol_hash"]


@pytest.fixture
def protocol(tmp_path):
    return load_protocol(trials_only_demo(tmp_path))


def test_log_stamps_appends_and_repairs_a_torn_tail(tmp_path):
    path = tmp_path / "events.jsonl"
    with SessionLog(path) as log:
        a = log.append({"type": "x", "v": 1})
        b = log.append({"type": "y"})
    assert (a["seq"], b["seq"]) == (0, 1) and b["mono"] >= a["mono"]
    assert re.fullmatch(r"\d{4}-\d\d-\d\dT\d\d:\d\d:\d\d\.\d{3}[+-]\d\d:\d\d", a["wall"])
    with open(path, "ab") as f:
        f.write(b'{"seq": 2, "type": "tor')  # a write cut short
    assert [e["type"] for e in read_events(path)] == ["x", "y"]
    with SessionLog(path) as log:
        assert log.seq == 3  # the repair note takes seq 2
        log.append({"type": "z"})
    events = read_events(path)
    assert [e["type"] for e in events] == ["x", "y", "log_repaired", "z"]
    assert events[2]["dropped_bytes"] == len(b'{"seq": 2, "type": "tor')
    assert path.read_bytes().endswith(b"\n") and len(path.read_bytes().splitlines()) == 4


def test_create_writes_the_session_description(tmp_path, protocol):
    session = Session.create(protocol, "P01", tmp_path, seed=5, apparatus={"device": "simulated"})
    folder = session.folder
    assert folder.parent == tmp_path / "demo" / "P01"
    info = json.loads((folder / "session.json").read_text())
    assert info["protocol"]["sha256"] == hashlib.sha256(Path(protocol.path).read_bytes()).hexdigest()
    assert info["protocol"]["text"] == Path(protocol.path).read_text()
    assert info["seed"] == 5 and info["participant_index"] == 0 and info["participant"] == "P01"
    assert info["app_version"] and info["apparatus"]["rate"] == 5000.0 and info["apparatus"]["device"] == "simulated"
    assert len(info["schedule"]) == 4 and info["schedule"][0]["task"] == "rating"
    assert set(info["latin_squares"]) == {"rating", "adjustment"}
    session.close()
    second = Session.create(protocol, "P02", tmp_path)
    assert second.info["participant_index"] == 1
    second.close()


def test_existing_participant_is_refused_and_resume_is_checked(tmp_path, protocol):
    Session.create(protocol, "P01", tmp_path).close()
    with pytest.raises(UserError, match="'P01' already has a session .*--resume"):
        Session.create(protocol, "P01", tmp_path)
    with pytest.raises(UserError, match="'P09' has no session to resume"):
        Session.resume(protocol, "P09", tmp_path)
    with pytest.raises(UserError, match="--seed 3"):
        Session.resume(protocol, "P01", tmp_path, seed=3)
    changed = tmp_path / "changed.toml"
    changed.write_bytes(Path(protocol.path).read_bytes() + b"\n# edited\n")
    with pytest.raises(UserError, match="differs from the protocol of session"):
        Session.resume(load_protocol(changed), "P01", tmp_path)
    with pytest.raises(UserError, match="participant ID"):
        Session.create(protocol, "../escape", tmp_path)


def test_simulated_participant_rates_by_noise_and_finds_breakdown(tmp_path, protocol):
    session = Session.create(protocol, "S01", tmp_path, seed=1)
    made = []
    runner = run_simulated(session, made)
    assert runner.finish() is True
    events = session.events()
    session.close()
    types = [e["type"] for e in events]
    assert types[:2] == ["session_created", "run_start"] and types[-2:] == ["session_end", "run_stop"]
    responses = [e for e in events if e["type"] == "response"]
    assert [e["step"] for e in responses] == [0, 1, 2, 3]
    rating = {r["condition"]: r["rating"] for r in responses[0]["responses"]}
    assert rating == {"LVT": 0.0, "LOWPASS": pytest.approx(0.5, abs=0.1), "LEVANT": 1.0}
    criterion = round(SimulatedParticipant(session.seed).criterion)  # the participant's own bias, knob positions
    for response in responses[1:]:
        threshold = THRESHOLD[response["condition"]]
        # Confirmed within a few knob steps of the breakdown level, once the participant's criterion is taken off.
        knob = protocol.task("adjustment").ceiling, protocol.task("adjustment").decades
        value = response["value"] - criterion
        assert fmax_from_knob(value - 8, *knob) < threshold < fmax_from_knob(value + 8, *knob)
        assert response["peak_fmax"] > threshold
    # Every knob event of the rating trial drove the loop: selection and F_max.
    rating_loop = made[0]
    assert set(rating_loop.names) == {"LOWPASS", "LEVANT", "LVT"}
    assert ("fmax", 1.0) in rating_loop.calls
    assert {c[1] for c in rating_loop.calls if c[0] == "source"} >= {"LEVANT", "LVT"} - {rating_loop.calls[0][1]}
    adjustment_loops = made[1:]
    assert [loop.names for loop in adjustment_loops] == [[e["condition"]] for e in responses[1:]]
    knobs = [e for e in events if e["type"] == "knob" and e["step"] == 1]
    assert knobs[0]["fmax"] > 0 and all("condition" not in e for e in knobs)
    assert any(e["type"] == "stability" and e["broken"] for e in events)


def test_resume_continues_at_the_first_unfinished_trial(tmp_path, protocol):
    session = Session.create(protocol, "R01", tmp_path, seed=2)
    runner = run_simulated(session, trials=2)
    # A third trial begins, its knob moves, then the program dies without a goodbye.
    runner.start_trial()
    runner.set_bowing(True)
    runner.knob(0, 30)
    before = (session.folder / "events.jsonl").read_bytes()
    session.close()

    resumed = Session.resume(protocol, "R01", tmp_path)
    assert resumed.next_trial().step == 2
    runner = run_simulated(resumed)
    assert runner.finish() is True
    resumed.close()
    after = (session.folder / "events.jsonl").read_bytes()
    assert after.startswith(before)
    events = read_events(session.folder / "events.jsonl")
    assert [e["seq"] for e in events] == list(range(len(events)))
    steps = [e["step"] for e in events if e["type"] == "response"]
    assert steps == [0, 1, 2, 3]
    restarts = [e for e in events if e["type"] == "trial_start" and e["step"] == 2]
    assert [e["restart"] for e in restarts] == [False, True]
    assert [e["resume"] for e in events if e["type"] == "run_start"] == [False, True]
    with pytest.raises(UserError, match="already complete"):
        Session.resume(protocol, "R01", tmp_path)


def test_rating_knobs_come_back_after_an_interruption(tmp_path, protocol):
    session = Session.create(protocol, "K01", tmp_path, seed=3)
    runner = SessionRunner(session, make_loop=factory(NOISE, THRESHOLD))
    runner.begin()
    runner.start_trial()
    runner.knob(0, 127)
    runner.knob(2, 0)
    session.close()
    session = Session.resume(protocol, "K01", tmp_path)
    runner = SessionRunner(session, make_loop=factory(NOISE, THRESHOLD))
    trial = runner.start_trial()
    assert runner.task.values == {trial.conditions[0]: 127, trial.conditions[1]: None, trial.conditions[2]: 0}
    assert runner.task.source == trial.conditions[2]
    runner.knob(1, 64)
    runner.pad(0)
    assert runner.task.done
    session.close()


def test_export_columns_and_content(tmp_path, protocol):
    for participant, seed in (("E01", 1), ("E02", 2)):
        session = Session.create(protocol, participant, tmp_path, seed=seed)
        run_simulated(session).finish()
        session.close()
    frame = export_responses(tmp_path)
    assert list(frame.columns) == COLUMNS and COLUMNS[:9] == CONTRACT
    assert len(frame) == 2 * (3 + 3)
    rating = frame[frame.task == "rating"]
    adjustment = frame[frame.task == "adjustment"]
    assert (rating.trial == 1).all() and (rating.fmax == 1.0).all()
    for _, rows in rating.groupby("participant"):
        assert rows.rating.min() == 0.0 and rows.rating.max() == 1.0
        assert sorted(rows.condition) == ["LEVANT", "LOWPASS", "LVT"]
    assert adjustment.rating.isna().all() and (adjustment.fmax > 0).all() and (adjustment.trial == 1).all()
    assert (frame.protocol_hash == hashlib.sha256(Path(protocol.path).read_bytes()).hexdigest()).all()
    assert pd.to_datetime(frame.time, format="ISO8601").notna().all()
    out = tmp_path / "responses.csv"
    save_responses(export_responses(tmp_path), tmp_path, out)
    back = pd.read_csv(out)
    assert list(back.columns) == COLUMNS and len(back) == len(frame)
    assert back.loc[back.task == "adjustment", "rating"].isna().all()
    assert back.fmax.to_numpy() == pytest.approx(frame.fmax.to_numpy())
    # Any level of the layout exports its own part.
    assert set(export_responses(tmp_path / "demo" / "E01").participant) == {"E01"}


def test_export_of_nothing(tmp_path):
    with pytest.raises(UserError, match="no such results folder"):
        export_responses(tmp_path / "absent")
    assert export_responses(tmp_path).empty
    with pytest.raises(UserError, match="no responses found"):
        save_responses(export_responses(tmp_path), tmp_path, tmp_path / "r.csv")
    assert not (tmp_path / "r.csv").exists()


def test_export_carries_each_trials_engine_health_and_leaves_it_empty_headless(tmp_path, protocol):
    session = Session.create(protocol, "H01", tmp_path, seed=1)
    run_simulated(session).finish()
    counts = {"deadline_misses": 2, "underruns": 1, "faults": 0, "events_dropped": 4}
    for step, scale in ((0, 1), (3, 1), (3, 2)):  # step 3 ran twice (an engine lost): both attempts count
        limited = {} if step == 0 else {"limited": 7 * scale}  # step 0's record as logged before it was counted
        session.log.append({"type": "trial_health", "step": step, "task": "x", "trial": 1,
                            **{k: scale * v for k, v in counts.items()}, **limited})
    session.close()
    headless = Session.create(protocol, "H02", tmp_path, seed=2)
    run_simulated(headless).finish()
    headless.close()
    frame = export_responses(tmp_path)
    columns = ["deadline_misses", "underruns", "faults", "events_dropped", "limited"]
    assert columns == COLUMNS[COLUMNS.index("deadline_misses"):][:5]
    logged = frame[frame.participant == "H01"].set_index(["step", "knob"])[columns]
    assert logged.loc[0].to_numpy().tolist() == [[2, 1, 0, 4, 0]] * 3  # the rating: one row per condition
    assert logged.loc[3].to_numpy().tolist() == [[6, 3, 0, 12, 21]]
    assert logged.drop(index=[0, 3], level="step").isna().all().all()
    assert frame.loc[frame.participant == "H02", columns].isna().all().all()
    save_responses(export_responses(tmp_path), tmp_path, tmp_path / "r.csv")
    back = pd.read_csv(tmp_path / "r.csv")
    assert back.loc[(back.participant == "H01") & (back.step == 3), "events_dropped"].tolist() == [12]
