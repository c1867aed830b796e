"""Task types as plug-ins: the registry, the shared confirm pad, and the listen task
added by one module, run through the protocol, schedule, `studyapp run` and export."""

import importlib
import json
import pkgutil
from pathlib import Path

import pytest

from studyapp.analysis.responses import check_responses, response_values
from studyapp.cli import main
from studyapp.errors import UserError
from studyapp.experiment import tasks
from studyapp.experiment.export import COLUMNS, export_responses
from studyapp.experiment.latin_square import balanced_latin_square, participant_row, task_seed
from studyapp.experiment.protocol import load_protocol, parse_protocol
from studyapp.experiment.schedule import Trial, build_schedule
from studyapp.experiment.session_log import read_events
from studyapp.experiment.task_type import TaskType, TrialState
from studyapp.experiment.tasks import protocol_task_names, task_names, task_type
from studyapp.experiment.tasks.adjustment import AdjustmentTrial
from studyapp.experiment.tasks.confirm_pad import ConfirmPadTrial
from studyapp.experiment.tasks.listen import ListenTrial
from studyapp.experiment.tasks.rating import RatingTrial
from tests.experiment.demo_protocol import trials_only

ROOT = Path(__file__).resolve().parents[2]
DEMO = ROOT / "protocols" / "demo.toml"
RATE = 5000.0
LISTEN = """
[listen]
conditions = ["LVT", "LOWPASS", "LEVANT"]
fmax = 0.8
duration_s = 0.3
instructions = "Bow the string and listen."
"""


def protocol_text(tasks):
    """The demo protocol with a listen table added, running ``tasks``."""
    text = trials_only(DEMO.read_text()).replace('tasks = ["rating", "adjustment"]', f"tasks = {json.dumps(tasks)}") + LISTEN
    if "adjustment" not in tasks:
        text = text[: text.index("[adjustment]")] + text[text.index("[listen]"):]
    return text


def test_every_module_in_the_package_is_registered_and_implements_the_protocol():
    modules = {m.name for m in pkgutil.iter_modules(tasks.__path__)
               if hasattr(importlib.import_module(f"{tasks.__name__}.{m.name}"), "TASK_TYPE")}
    assert modules == set(task_names()) == {"rating", "adjustment", "listen", "page"}
    assert protocol_task_names() == ("rating", "adjustment", "listen")  # a page is no protocol table
    protocol = parse_protocol(protocol_text(["listen", "rating", "adjustment"]), "three.toml")
    for name in protocol_task_names():
        kind = task_type(name)
        assert isinstance(kind, TaskType) and kind.name == name
        trials, _ = kind.schedule(protocol.task(name), [list(protocol.task(name).conditions)], 0)
        number, conditions, condition = trials[0]
        state = kind.start(protocol.task(name), Trial(0, name, number, tuple(conditions), condition))
        assert isinstance(state, TrialState) and state.task == name and not state.done
    with pytest.raises(ValueError, match="task 'nope': allowed is one of rating, adjustment, listen, page"):
        task_type("nope")


def test_a_protocol_names_only_registered_tasks(tmp_path):
    path = tmp_path / "p.toml"
    path.write_text(DEMO.read_text().replace('tasks = ["rating", "adjustment"]', 'tasks = ["rating", "tapping"]'))
    with pytest.raises(UserError, match=r"\[study\] tasks = .*'rating', 'adjustment', 'listen'"):
        load_protocol(path)


def test_rating_and_adjustment_share_the_confirm_pad():
    for trial_class in (RatingTrial, AdjustmentTrial):
        assert issubclass(trial_class, ConfirmPadTrial)
        assert trial_class.pad is ConfirmPadTrial.pad  # one confirm logic, not two


def test_captions_are_blind_safe():
    rating, adjustment, listen = (task_type(n) for n in ("rating", "adjustment", "listen"))
    trial = Trial(0, "rating", 1, ("LVT", "LEVANT"))
    state = RatingTrial(trial.conditions, 1.0)
    assert rating.knob_captions(trial, state, 8, hidden=False) == ["LVT", "LEVANT"]
    assert rating.knob_captions(trial, state, 8, hidden=True) == []
    trial = Trial(3, "adjustment", 2, ("LVT", "LEVANT"), "LEVANT")
    state = AdjustmentTrial("LEVANT", 2, 40.0, 2.0, knob=1)
    assert adjustment.knob_captions(trial, state, 3, hidden=True) == ["", "F_max", ""]
    assert adjustment.heading(trial) == "adjustment, repetition 2" and "LEVANT" not in adjustment.heading(trial)
    assert adjustment.response_text({"fmax": 2.5}) == "Response recorded: F_max = 2.5 N."
    trial = Trial(1, "listen", 1, ("LVT", "LEVANT"), "LEVANT")
    assert listen.heading(trial) == "listen, condition 2 of 2" and listen.knob_captions(trial, None, 8, False) == []


def test_the_listen_trial_ends_when_its_clock_reaches_the_duration():
    trial = ListenTrial("LVT", 1, fmax=0.8, duration_s=0.3)
    assert trial.source == "LVT" and trial.fmax == 0.8  # plays from its start
    assert trial.knob(0, 100) == [] and trial.pad(2) == [{"type": "pad", "index": 2}]
    with pytest.raises(ValueError, match="knob value"):
        trial.knob(0, 128)
    assert trial.tick(0.2) == [] and not trial.done and trial.remaining == pytest.approx(0.1)
    (record,) = trial.tick(0.1)
    assert trial.done and record == {"type": "response", "task": "listen", "condition": "LVT", "trial": 1,
                                     "fmax": 0.8, "listened": True, "duration": pytest.approx(0.3)}
    assert trial.tick(1.0) == [] and trial.response["duration"] == pytest.approx(0.3)


def test_the_listen_task_runs_through_schedule_run_and_export(tmp_path, capsys):
    protocol_file = tmp_path / "listen.toml"
    protocol_file.write_text(protocol_text(["listen", "rating"]))
    protocol = load_protocol(protocol_file)
    results = tmp_path / "results"
    argv = ["run", "--protocol", str(protocol_file), "--participant", "L01", "--simulated-participant",
            "--headless", "--results", str(results), "--seed", "3"]
    assert main(argv) == 0
    folder = Path(capsys.readouterr().out.strip())

    # Schedule: one listen trial per condition, in the participant's Latin-square row, then the rating.
    row = participant_row(balanced_latin_square(protocol.task("listen").conditions, task_seed(1, "listen")), 0)
    schedule = [Trial.from_dict(d) for d in json.loads((folder / "session.json").read_text())["schedule"]]
    assert schedule == build_schedule(protocol, 0)[0]
    assert [(t.task, t.condition, t.trial) for t in schedule[:3]] == [("listen", c, 1) for c in row]
    assert schedule[3].task == "rating" and len(schedule) == 4

    events = read_events(folder / "events.jsonl")
    responses = [e for e in events if e["type"] == "response"]
    assert [e["step"] for e in responses] == [0, 1, 2, 3]
    one_sample = 1 / RATE
    for e, condition in zip(responses[:3], row):
        assert (e["task"], e["condition"], e["fmax"], e["listened"]) == ("listen", condition, 0.8, True)
        assert 0.3 - 1e-9 <= e["duration"] < 0.3 + one_sample  # played for the set time, to a sample
        step = [x for x in events if x.get("step") == e["step"]]
        assert {x["type"] for x in step} == {"trial_start", "bowing", "response"}  # nothing asked of anyone
    assert events[-2]["type"] == "session_end"

    frame = export_responses(results)
    assert list(frame.columns) == COLUMNS
    listen = frame[frame.task == "listen"]
    assert list(listen.condition) == row and (listen.fmax == 0.8).all() and (listen.trial == 1).all()
    assert listen.rating.isna().all() and listen.value.isna().all() and listen.knob.isna().all()
    assert (listen.duration >= 0.3 - 1e-9).all()
    assert len(frame[frame.task == "rating"]) == 3 and frame[frame.task == "rating"].value.notna().all()
    checked = check_responses(frame, "results", include_simulated=True)  # listen rows read, then left out
    assert set(checked.task) == {"listen", "rating"} and set(response_values(checked, "rating").task) == {"rating"}
