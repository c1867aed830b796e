"""An emergency stop, or a watchdog trip, in the simulated participant's first adjustment trial, then Resume
(issue 31 item 4).

Before: the bow was never put back, the participant turned on to the knob's top over silence and its 40 N
was accepted, then it raised ("did not finish") and the session sat in "Running". Now the trial starts
again, the participant plays it again from its start, no response is above the largest F_max heard in its
attempt, and the session ends. A failure of the simulated participant ends the session (aborted, with the
error shown and logged) instead of leaving it "Running". scripts/esc_resume_tries.py makes ten tries (of the
demo by default).

The session is one adjustment trial (``ONE_TRIAL``): the promise is about that trial; with the demo's rating,
practice trial and two more adjustment trials around it each try took 2 min idle (130 s and 121 s, issue 39).
Its knob spans 1.5 decades instead of 2 so LEVANT's breakdown (3.35 N, docs/breakdown.md) comes at knob ~36,
not ~59: the participant probes 1.2 s per step of 3-5 positions up to it, twice (interrupted at knob 12, then
from 0 again).
"""

import pytest

from studyapp.experiment.simulated_participant import SimulatedParticipant
from tests.gui.conftest import ENGINE_START, wait_until
from tests.gui.interrupted_session import play_interrupted

pytest.importorskip("pytestqt")

pytestmark = pytest.mark.gui

ONE_TRIAL = """
[study]
name = "interrupted"
title = "One adjustment trial"
tasks = ["adjustment"]
seed = 1

[apparatus]
rate = 5000.0

[adjustment]
conditions = ["LEVANT"]
trials = 1
ceiling = 40.0
decades = 1.5
instructions = "Bow the string, turn the knob up until it breaks down, then press the pad."
"""


@pytest.mark.parametrize("how", ["esc", "watchdog"])
def test_an_interrupted_first_adjustment_trial_is_played_again_and_the_session_ends(idle_console, qapp, tmp_path,
                                                                                   how):
    protocol = tmp_path / "interrupted.toml"
    protocol.write_text(ONE_TRIAL)
    assert idle_console.choose_protocol(str(protocol)), idle_console.setup.error.text()
    outcome = play_interrupted(idle_console, qapp, tmp_path / "results", "SIMESC", seed=7, how=how)
    assert not outcome.stalled, outcome.stalled
    assert outcome.state == "finished", idle_console.log.toPlainText()[-2000:]
    assert not [e for e in outcome.errors if "simulated participant" in e]
    assert outcome.responses == 1 and not outcome.above_heard
    if how == "esc":
        stops = [e for e in outcome.events if e["type"] == "emergency_stop"]
        assert stops and stops[0]["by"] == "participant"  # Esc on the participant's window is the participant's
    else:
        assert [e for e in outcome.events if e["type"] == "engine_failed"]
    restarted = [e for e in outcome.events if e["type"] == "trial_start" and e["restart"]]
    assert restarted and restarted[0]["task"] == "adjustment"


def test_a_failing_simulated_participant_ends_the_session_visibly(idle_console, qapp, tmp_path, monkeypatch):
    def fail(participant, runner, trial):
        raise ValueError("a participant that cannot go on")

    monkeypatch.setattr(SimulatedParticipant, "play_trial", fail)
    console, c = idle_console, idle_console.controller
    errors = []

    def on_message(text, level, topic):
        if level == "error":
            errors.append(text)

    c.events.message.connect(on_message)
    try:
        console.setup.participant.setText("SIMFAIL")
        console.setup.results.setText(str(tmp_path))
        console.setup.simulated.setChecked(True)
        session = console.start_session(seed=1)
        console.setup.simulated.setChecked(False)
        assert session is not None, console.setup.error.text()
        wait_until(qapp, lambda: c.state == "aborted", ENGINE_START)
    finally:
        c.events.message.disconnect(on_message)
    assert console.simulated is None
    assert any("ValueError: a participant that cannot go on" in e for e in errors)
    assert any("session is aborted" in e for e in errors)
    (log,) = tmp_path.glob("*/*/*/events.jsonl")
    aborts = [line for line in log.read_text().splitlines() if '"type":"abort"' in line]
    assert len(aborts) == 1 and "a participant that cannot go on" in aborts[0]
