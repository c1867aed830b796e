"""Pages, practice, breaks, listening time and the automatic bow: protocol, schedule, runner, log, export."""

import pytest

from studyapp.cli import main
from studyapp.errors import UserError
from studyapp.experiment.export import export_responses
from studyapp.experiment.latin_square import balanced_latin_square, participant_row, task_seed
from studyapp.experiment.protocol import load_protocol, parse_protocol
from studyapp.experiment.schedule import Trial, build_schedule, counted
from studyapp.experiment.session import Session
from studyapp.experiment.session_runner import SessionRunner
from studyapp.experiment.simulated_participant import SimulatedParticipant
from studyapp.experiment.tasks.adjustment import AdjustmentTrial
from studyapp.experiment.tasks.rating import RatingTrial
from tests.experiment.experiment_fake_loop import factory

HEAD = """
[study]
name = "flow"
tasks = ["rating", "adjustment"]
seed = 5

[apparatus]
rate = 5000.0
"""
RATING = """
[rating]
conditions = ["LVT", "LOWPASS", "LEVANT"]
fmax = 1.0
instructions = "Rate them."
practice = 1
"""
ADJUSTMENT = """
[adjustment]
conditions = ["LVT", "LOWPASS"]
trials = 2
ceiling = 40.0
confirm_pad = 3
instructions = \"\"\"
Turn the knob
up slowly.
\"\"\"
practice = 2
break_every = 2
bow = "auto"
"""
PAGES = """
[[pages]]
kind = "goodbye"
text = "Bye."

[[pages]]
kind = "calibration"
text = "A tone."
tone_hz = 1000
level_dbfs = -20

[[pages]]
kind = "welcome"
title = "Hello"
text = "Welcome, **reader**."

[[pages]]
kind = "instructions"
task = "rating"
text = "Rate the knobs."
"""
FLOW = HEAD + RATING + ADJUSTMENT + PAGES


def steps(text, participant=0):
    return build_schedule(parse_protocol(text, "flow.toml"), participant)[0]


def outline(schedule):
    return [(t.page.kind, t.page.title) if t.page else (t.task, "practice" if t.practice else "trial")
            for t in schedule]


def test_the_schedule_follows_the_procedure_with_practice_and_breaks():
    schedule = steps(FLOW)
    assert outline(schedule) == [
        ("welcome", "Hello"), ("calibration", "Headphone level"),
        ("instructions", "Instructions"),
        ("rating", "practice"), ("transition", "Practice is over"), ("rating", "trial"),
        ("transition", "Part 2 of 2"), ("instructions", "Part 2 of 2: instructions"),
        ("adjustment", "practice"), ("adjustment", "practice"), ("transition", "Practice is over"),
        ("adjustment", "trial"), ("adjustment", "trial"), ("break", "Break"),  # after 2 of 4, not after the last
        ("adjustment", "trial"), ("adjustment", "trial"),
        ("goodbye", "Thank you"),
    ]
    assert [t.step for t in schedule] == list(range(len(schedule)))
    pages = [t for t in schedule if t.page]
    assert [t.trial for t in pages] == list(range(1, len(pages) + 1))
    # the protocol's instructions page for rating; adjustment's is made of its table's instructions,
    # whose hard line breaks Markdown joins (the view renders one paragraph)
    assert pages[2].page.text == "Rate the knobs."
    assert pages[5].page.text == "Turn the knob\nup slowly."
    assert "2 of 4 trials of this part are done" in pages[7].page.text
    # each page is acknowledged with the confirm pad of its task
    assert [p.page.pad for p in pages] == [0, 0, 0, 0, 3, 3, 3, 3, 3]
    assert [p.page.by for p in pages] == ["participant", "experimenter"] + ["participant"] * 7


def test_practice_trials_come_from_the_next_participants_rows_and_count_apart():
    schedule = steps(FLOW, participant=4)
    adjustment = parse_protocol(FLOW, "flow.toml").task("adjustment")
    square = balanced_latin_square(adjustment.conditions, task_seed(5, "adjustment"))
    practice = [t for t in schedule if t.task == "adjustment" and t.practice]
    assert [t.condition for t in practice] == list(participant_row(square, 5)[:2])
    assert [t.trial for t in practice] == [1, 2]
    real = [t for t in schedule if t.task == "adjustment" and not t.practice]
    assert [counted(schedule, t) for t in practice] == [("practice", 1, 2), ("practice", 2, 2)]
    assert [counted(schedule, t) for t in real] == [("trial", n, 4) for n in (1, 2, 3, 4)]
    (rating_practice,) = [t for t in schedule if t.task == "rating" and t.practice]
    rating = parse_protocol(FLOW, "flow.toml").task("rating")
    rating_square = balanced_latin_square(rating.conditions, task_seed(5, "rating"))
    assert rating_practice.conditions == tuple(participant_row(rating_square, 5))
    assert steps(FLOW, participant=4) == schedule  # deterministic


def test_a_protocol_without_pages_or_phases_keeps_its_trials_only():
    plain = HEAD + RATING.replace("practice = 1\n", "") + ADJUSTMENT.replace(
        "practice = 2\nbreak_every = 2\n", "")
    schedule = steps(plain)
    assert [t.task for t in schedule] == ["rating"] + ["adjustment"] * 4
    assert not any(t.practice or t.page for t in schedule)


def test_a_generic_transition_page_leads_into_every_later_task():
    text = FLOW + '\n[[pages]]\nkind = "transition"\ntext = "On to the next part."\n'
    (transition,) = [t.page for t in steps(text) if t.page and t.page.title == "Next part"]
    assert transition.text == "On to the next part." and transition.task == "adjustment"


def test_a_schedule_stored_before_pages_existed_still_loads():
    old = {"step": 3, "task": "adjustment", "trial": 1, "conditions": ["LVT"], "condition": "LVT"}
    trial = Trial.from_dict(old)
    assert trial.practice is False and trial.page is None and trial.phase == "trial"
    for t in steps(FLOW):
        assert Trial.from_dict(t.to_dict()) == t


@pytest.mark.parametrize(("change", "named"), [
    ('[[pages]]\nkind = "intro"\ntext = "x"', "[[pages]] #5 kind = 'intro': allowed is one of welcome"),
    ('[[pages]]\nkind = "welcome"\ntext = ""', "[[pages]] #5 text"),
    ('[[pages]]\nkind = "welcome"', "[[pages]] #5 text is missing"),
    ('[[pages]]\nkind = "instructions"\ntext = "x"', "[[pages]] #5 task is missing"),
    ('[[pages]]\nkind = "instructions"\ntask = "listen"\ntext = "x"', "[[pages]] #5 task = 'listen'"),
    ('[[pages]]\nkind = "transition"\ntask = "rating"\ntext = "x"', "a task after the first"),
    ('[[pages]]\nkind = "welcome"\ntask = "rating"\ntext = "x"', "[[pages]] #5 task is not a known field"),
    ('[[pages]]\nkind = "calibration"\ntext = "x"\nlevel_dbfs = -20', "[[pages]] #5 tone_hz is missing"),
    ('[[pages]]\nkind = "calibration"\ntext = "x"\ntone_hz = 10\nlevel_dbfs = -20',
     "tone_hz = 10.0: allowed is a number from 20 to 20000 Hz"),
    ('[[pages]]\nkind = "calibration"\ntext = "x"\ntone_hz = 1000\nlevel_dbfs = 3',
     "level_dbfs = 3.0: allowed is a number from -60 to -18 dBFS"),
    ('[[pages]]\nkind = "calibration"\ntext = "x"\ntone_hz = nan\nlevel_dbfs = -20', "tone_hz = nan"),
    ('[[pages]]\nkind = "welcome"\ntext = "x"\ntone_hz = 1000', "tone_hz is not a known field"),
    ("pages = 3", "pages = 3: allowed is an array of tables"),
])
def test_a_bad_page_is_refused_in_one_line_naming_it(change, named):
    if change.startswith("[["):  # a fifth page
        text = HEAD + RATING + ADJUSTMENT + PAGES + "\n" + change + "\n"
    else:
        text = change + "\n" + HEAD + RATING + ADJUSTMENT
    with pytest.raises(UserError) as caught:
        parse_protocol(text, "flow.toml")
    message = str(caught.value)
    assert message.startswith("flow.toml: ") and named in message and "\n" not in message


@pytest.mark.parametrize(("table", "field", "value", "allowed"), [
    ("rating", "practice", "21", "an integer from 0 to 20"),
    ("rating", "practice", "-1", "an integer from 0 to 20"),
    ("adjustment", "break_every", "1.5", "an integer from 1 to 1000"),
    ("adjustment", "min_listen_s", "601", "a number from 0 to 600 s"),
    ("adjustment", "min_listen_s", "inf", "a number from 0 to 600 s"),
    ("rating", "bow", '"sometimes"', 'one of "participant", "auto"'),
])
def test_bad_phase_fields_are_refused_in_one_line(table, field, value, allowed):
    section = {"rating": RATING, "adjustment": ADJUSTMENT}[table]
    changed = "\n".join(line for line in section.splitlines() if not line.startswith(f"{field} =")) + (
        f"\n{field} = {value}\n")
    text = (HEAD + RATING + ADJUSTMENT).replace(section, changed)
    with pytest.raises(UserError) as caught:
        parse_protocol(text, "flow.toml")
    assert str(caught.value).startswith(f"flow.toml: [{table}] {field} = ") and allowed in str(caught.value)


def test_the_listen_task_takes_no_min_listen_s():
    text = HEAD.replace('["rating", "adjustment"]', '["listen"]') + (
        '[listen]\nconditions = ["LVT"]\nfmax = 1.0\nduration_s = 1.0\ninstructions = "x"\nmin_listen_s = 2\n')
    with pytest.raises(UserError, match=r"\[listen\] min_listen_s is not a known field"):
        parse_protocol(text, "flow.toml")


def test_pages_is_not_a_task_a_protocol_can_name():
    with pytest.raises(UserError, match="allowed is a list of the tasks"):
        parse_protocol(HEAD.replace('["rating", "adjustment"]', '["page"]'), "flow.toml")


# listening time (min_listen_s) ------------------------------------------------------------------

def test_an_adjustment_confirm_waits_for_the_listening_time_with_the_bow_on():
    trial = AdjustmentTrial("LVT", 1, ceiling=40.0, decades=2.0, min_listen_s=1.0)
    trial.knob(0, 30)
    trial.tick(0.4, bowing=True)
    trial.tick(2.0, bowing=False)  # the bow lifted: not heard
    (refused,) = trial.pad(0)
    assert refused["accepted"] is False
    assert refused["reason"] == "listen longer with the bow on: the string needs 0.6 s more"
    assert refused["listen_short"] == {"LVT": pytest.approx(0.6)}
    trial.knob(0, 0)
    trial.tick(5.0, bowing=True)  # F_max 0: no force on the handle, the condition not yet in play
    trial.knob(0, 30)
    trial.tick(0.6, bowing=True)
    accepted, response = trial.pad(0)
    assert accepted["accepted"] is True and response["type"] == "response"


def test_a_rating_confirm_names_each_knob_short_of_listening_never_its_condition():
    trial = RatingTrial(["LVT", "LOWPASS", "LEVANT"], fmax=1.0, min_listen_s=1.0)
    for index, value, heard in ((0, 100, 1.0), (1, 10, 0.25), (2, 50, 0.93)):
        trial.knob(index, value)
        trial.tick(heard, bowing=True)
    (refused,) = trial.pad(0)
    # 1 - 0.25 = 0.75 -> 0.8 s; 1 - 0.93 = 0.07 -> 0.1 s (rounded up to a tenth)
    assert refused["reason"] == "listen longer with the bow on: knob 2 needs 0.8 s more, knob 3 needs 0.1 s more"
    assert not any(name in refused["reason"] for name in ("LVT", "LOWPASS", "LEVANT"))
    assert refused["listen_short"] == {"LOWPASS": pytest.approx(0.75), "LEVANT": pytest.approx(0.07)}
    trial.knob(1, 10)
    trial.tick(0.75, bowing=True)
    trial.knob(2, 50)
    trial.tick(0.07, bowing=True)
    assert trial.pad(0)[0]["accepted"] is True


def test_an_unrated_knob_is_named_by_its_number():
    trial = RatingTrial(["LVT", "LOWPASS"], fmax=1.0)
    trial.knob(0, 100)
    assert trial.pad(0)[0]["reason"] == "not rated yet: knob 2"


# the runner, the log, resume and export ----------------------------------------------------------

def run_flow(tmp_path, text=FLOW, steps_to_play=None):
    path = tmp_path / "flow.toml"
    path.write_text(text)
    session = Session.create(load_protocol(path), "P01", tmp_path / "results", seed=11)
    runner = SessionRunner(session, make_loop=factory())
    runner.begin()
    return session, runner


def test_pages_are_silent_acknowledged_logged_and_never_shown_again_on_resume(tmp_path):
    session, runner = run_flow(tmp_path)
    welcome = runner.start_trial()
    assert welcome.page.kind == "welcome" and runner.loop is None and runner.task.fmax == 0.0
    runner.set_bowing(True)  # nothing to bow on a page
    assert runner.bowing is False
    runner.pad(1)  # another pad: nothing
    assert not runner.task.done
    runner.pad(0)
    calibration = runner.start_trial()
    assert calibration.page.kind == "calibration"
    assert runner.pad(0)[0] == {"type": "pad", "index": 0, "accepted": False,
                                "reason": "the experimenter confirms this page"}
    assert runner.acknowledge_page("participant")[0]["accepted"] is False and not runner.task.done
    runner.acknowledge_page("experimenter")
    events = session.events()
    responses = [e for e in events if e["type"] == "response"]
    assert [(e["task"], e["kind"], e["by"]) for e in responses] == [
        ("page", "welcome", "participant"), ("page", "calibration", "experimenter")]
    assert responses[1]["tone_hz"] == 1000 and responses[1]["level_dbfs"] == -20
    runner.start_trial()  # the rating instructions page, interrupted
    runner.finish("interrupted")
    session.close()

    again = Session.resume(load_protocol(tmp_path / "flow.toml"), "P01", tmp_path / "results")
    runner = SessionRunner(again, make_loop=factory())
    runner.begin()
    assert runner.start_trial().step == 2  # the instructions again, not the acknowledged pages
    again.close()


def test_practice_is_marked_in_the_log_and_export_and_pages_make_no_rows(tmp_path):
    session, runner = run_flow(tmp_path)
    SimulatedParticipant(session.seed, bow_time=0.1, probe_time=0.02).play(runner)
    assert runner.finish()
    events = session.events()
    practice_steps = {t.step for t in session.schedule if t.practice}
    for event in events:
        if event.get("step") in practice_steps:
            assert event["practice"] is True
        else:
            assert "practice" not in event
    frame = export_responses(tmp_path / "results")
    assert set(frame.task) == {"rating", "adjustment"}  # no page rows
    assert frame.groupby("task").practice.sum().to_dict() == {"adjustment": 2, "rating": 3}  # 3 rows of 1 trial
    assert len(frame) == 3 + 3 + 2 + 4 and frame.practice.dtype == bool
    session.close()


def test_bow_auto_puts_the_bow_on_at_each_trial_start_and_logs_it(tmp_path):
    session, runner = run_flow(tmp_path)
    started = []
    while (trial := runner.start_trial()) is not None:
        last = session.events()[-1]
        started.append((trial.task, trial.phase, runner.bowing))
        if trial.page:
            assert last["type"] == "trial_start"
            runner.acknowledge_page("experimenter")
        elif trial.task == "rating":
            assert last["type"] == "trial_start"
            runner.knob(0, 100), runner.knob(1, 0), runner.knob(2, 50), runner.pad(0)
        else:
            assert (last["type"], last["on"], last["step"]) == ("bowing", True, trial.step)
            assert runner.loop.bowing is True
            runner.knob(0, 20), runner.advance(0.05), runner.pad(3)  # heard (the bow is on), then confirmed
    assert [b for task, phase, b in started if phase != "page"] == [False, False, True, True, True, True, True, True]
    session.close()


def test_the_task_hears_whether_the_bow_is_on(tmp_path):
    text = FLOW.replace('bow = "auto"', "min_listen_s = 0.5")
    session, runner = run_flow(tmp_path, text)
    while (trial := runner.start_trial()).task != "adjustment":
        if trial.page:
            runner.acknowledge_page("experimenter")
        else:
            runner.knob(0, 100), runner.knob(1, 0), runner.knob(2, 50), runner.pad(0)
    runner.knob(0, 20)
    runner.advance(0.3)  # bow lifted
    runner.set_bowing(True)
    runner.advance(0.2)
    assert runner.task.heard == {trial.condition: pytest.approx(0.2)}
    (refused,) = runner.pad(3)
    assert refused["reason"] == "listen longer with the bow on: the string needs 0.3 s more"
    runner.advance(0.3)
    assert runner.pad(3)[0]["accepted"] is True
    session.close()


@pytest.mark.parametrize(("change", "named"), [
    ('[[pages]]\nkind = "calibration"\ntext = "x"\ntone_hz = 1000\nlevel_dbfs = -61', "[[pages]] #5 level_dbfs"),
    ("[adjustment]\nmin_listen_s = -1", "[adjustment] min_listen_s = -1"),
])
def test_studyapp_run_refuses_a_bad_page_or_phase_field_and_enrols_nobody(tmp_path, capsys, change, named):
    text = FLOW + "\n" + change + "\n" if change.startswith("[[") else FLOW.replace("[adjustment]\n", change + "\n")
    bad = tmp_path / "bad.toml"
    bad.write_text(text)
    results = tmp_path / "results"
    code = main(["run", "--protocol", str(bad), "--participant", "P1", "--headless", "--simulated-participant",
                 "--results", str(results)])
    err = capsys.readouterr().err.strip()
    assert code == 2 and len(err.splitlines()) == 1 and err.startswith(f"studyapp: error: {bad}: ") and named in err
    assert not results.exists()
