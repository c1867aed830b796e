"""The simulated participant adjusts F_max while bowing with the protocol's gesture, on the real loop (issue 20)."""

import pytest

from studyapp.experiment.protocol import load_protocol
from studyapp.experiment.session import Session
from studyapp.experiment.session_runner import SessionRunner
from studyapp.experiment.simulated_participant import SimulatedParticipant
from studyapp.model.breakdown import breakdown_fmax
from studyapp.model.fmax_knob import fmax_from_knob
from tests.experiment.demo_protocol import trials_only_demo


@pytest.mark.slow
def test_the_participant_bows_through_the_adjustment_and_confirms_near_the_bowing_breakdown(tmp_path):
    protocol = load_protocol(trials_only_demo(tmp_path))
    assert protocol.gesture == "strokes"
    session = Session.create(protocol, "B01", tmp_path, seed=3)
    runner = SessionRunner(session)
    runner.begin()
    SimulatedParticipant(session.seed).play(runner)
    assert runner.finish() is True
    events = session.events()
    session.close()
    # it never rests the hand to judge: no gesture change, every trial bowed with the protocol's strokes
    assert not [e for e in events if e["type"] == "gesture"]
    task = protocol.task("adjustment")
    params = {name: protocol.estimator_params(name) for name in task.conditions}
    responses = [e for e in events if e["type"] == "response" and "value" in e]
    assert responses
    for response in responses:
        name = response["condition"]
        estimators = {} if name == "LVT" else {name: params[name]}
        edge = breakdown_fmax(name, tolerance=0.05, estimators=estimators)
        confirmed = fmax_from_knob(response["value"], task.ceiling, task.decades)
        # within the participant's criterion (a few knob positions) and the monitor's 1 s window of the edge
        assert 0.6 * edge < confirmed < 1.6 * edge, (name, confirmed, edge)
