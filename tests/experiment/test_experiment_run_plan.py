"""Issue 22 item 16: the run sheet (``studyapp plan``) shows before Start the plan the session will run.

The plan of a participant without a session must be exactly what ``Session.create`` then
builds (the order row and every step), simulated runs in the folder or not; a participant with
a session gets the stored plan with the steps done ticked.
"""

import contextlib
import io
from pathlib import Path

import pytest

from studyapp.cli import main
from studyapp.errors import UserError
from studyapp.experiment.protocol import load_protocol
from studyapp.experiment.run_plan import make_plan, plan_markdown
from studyapp.experiment.session import Session
from studyapp.experiment.tasks import task_type
from tests.experiment.experiment_fake_loop import run_simulated

ROOT = Path(__file__).resolve().parents[2]
SINCLAIR = ROOT / "protocols" / "sinclair2014.toml"
DEMO = ROOT / "protocols" / "demo.toml"
SIMULATED = {"participant": "simulated"}


def _plan_then_create(protocol, results, participant, apparatus=None, order_row=None):
    simulated = bool(apparatus)
    plan = make_plan(protocol, participant, results, order_row=order_row, simulated=simulated)
    session = Session.create(protocol, participant, results, apparatus=apparatus, order_row=order_row)
    session.close()
    return plan, session.info


@pytest.mark.parametrize("path", [SINCLAIR, DEMO])
def test_the_plan_is_what_the_session_then_runs(tmp_path, path):
    protocol = load_protocol(path)
    for participant, apparatus, row in [("SIM01", SIMULATED, None), ("P01", None, None), ("SIM02", SIMULATED, None),
                                        ("P02", None, None), ("P03", None, 3)]:
        plan, info = _plan_then_create(protocol, tmp_path, participant, apparatus, row)
        assert plan.order_row == info["order_row"] and plan.order_rows == info["order_rows"]
        assert [s.trial.to_dict() for s in plan.steps] == info["schedule"], participant
        assert plan.squares == info["latin_squares"]
        assert plan.session is None and not any(s.done for s in plan.steps)


def test_a_participant_with_a_session_gets_the_stored_plan_with_steps_done(tmp_path):
    protocol = load_protocol(DEMO)
    session = Session.create(protocol, "P01", tmp_path, order_row=2)
    run_simulated(session, trials=3)
    done = session.finished_steps()
    session.close()
    plan = make_plan(protocol, "P01", tmp_path)
    assert plan.session == session.folder and plan.order_source == "stored" and plan.order_row == 2
    assert {s.trial.step for s in plan.steps if s.done} == done and len(done) == 3
    text = plan_markdown(plan)
    assert f"session `{session.folder.name}`: 3 of {len(plan.steps)} steps done" in text
    assert "order row **2** of 6 (stored in the session)" in text
    with pytest.raises(UserError, match="--order-row 1: session .* has order row 2"):
        make_plan(protocol, "P01", tmp_path, order_row=1)


def test_the_sheet_names_every_condition_in_order_and_the_duration(tmp_path):
    protocol = load_protocol(SINCLAIR)
    plan = make_plan(protocol, "P07", tmp_path)
    text = plan_markdown(plan)
    rating = next(s.trial for s in plan.steps if s.trial.task == "rating" and not s.trial.practice)
    assert "- " + ", ".join(f"knob {k + 1}: {c}" for k, c in enumerate(rating.conditions)) in text
    first = [s.trial.condition for s in plan.steps if s.trial.task == "adjustment" and not s.trial.practice][:9]
    assert f"- repetition 1: {', '.join(first)}" in text
    assert "order row **0** of 72 (enrolment: the next real participant's" in text
    assert "Steps: 68 (10 pages, 3 practice trials, 55 trials)" in text
    # typical figures: pages 8 x 30 s + level check 60 s + 2 breaks x 120 s, 2 rating trials x 300 s,
    # 56 adjustment trials x 45 s
    expected = 7 * 30 + 60 + 2 * 120 + 2 * 300 + 56 * 45
    assert plan.seconds == pytest.approx(expected)
    assert f"**1 h {round(expected / 60) - 60:02d} min**" in text
    for step in plan.steps:
        kind = task_type(step.trial.task)
        assert step.seconds == kind.typical_duration(protocol.specs.get(step.trial.task), step.trial)


def test_recorded_real_trials_set_the_estimate_simulated_ones_do_not(tmp_path):
    protocol = load_protocol(DEMO)
    for participant, apparatus, durations in (("P01", None, (10.0, 30.0, 50.0)), ("SIM01", SIMULATED, (999.0,) * 3)):
        session = Session.create(protocol, participant, tmp_path, apparatus=apparatus)
        steps = [t.step for t in session.schedule if t.task == "adjustment" and not t.practice]
        for step, duration in zip(steps, durations):
            session.log.append({"type": "response", "step": step, "task": "adjustment", "condition": "LVT",
                                "trial": 1, "fmax": 2.5, "value": 60, "peak_fmax": 3.0, "duration": duration})
        session.close()
    plan = make_plan(protocol, "P02", tmp_path)
    adjustment = [s for s in plan.steps if s.trial.task == "adjustment"]
    assert all(s.recorded and s.seconds == 30.0 for s in adjustment)  # median of 10, 30, 50; not 999
    rating = [s for s in plan.steps if s.trial.task == "rating"]
    assert all(not s.recorded and s.seconds == 300.0 for s in rating)
    assert "medians of recorded real trials for adjustment" in plan_markdown(plan)


def test_blind_names_no_condition(tmp_path):
    protocol = load_protocol(SINCLAIR)
    text = plan_markdown(make_plan(protocol, "P07", tmp_path), blind=True)
    names = set(protocol.task("adjustment").conditions) | set(protocol.task("rating").conditions)
    assert not [name for name in names if name in text]
    assert "Condition names hidden (blinding)." in text and "adjustment, repetition 6" in text


def _plan_cli(*args):
    out, err = io.StringIO(), io.StringIO()
    with contextlib.redirect_stdout(out), contextlib.redirect_stderr(err):
        code = main(["plan", *map(str, args)])
    return code, out.getvalue(), err.getvalue()


def test_plan_prints_markdown_and_writes_it_with_o(tmp_path):
    code, out, err = _plan_cli("--protocol", SINCLAIR, "--participant", "P07", "--results", tmp_path / "r")
    assert code == 0 and out.startswith("# Run sheet: sinclair2014, participant P07") and "| step" in out
    assert not (tmp_path / "r").exists()  # the results folder is read, never written
    code, _, err = _plan_cli("--protocol", SINCLAIR, "--participant", "P07", "--results", tmp_path / "r",
                             "-o", tmp_path / "sheet.md")
    assert code == 0 and (tmp_path / "sheet.md").read_text() == out
    code, simulated, _ = _plan_cli("--protocol", SINCLAIR, "--participant", "SIM01", "--results", tmp_path / "r",
                                   "--simulated-participant", "--order-row", "5")
    assert code == 0 and "order row **5** of 72 (set with --order-row)" in simulated and "(simulated)" in simulated
