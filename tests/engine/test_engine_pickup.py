"""Soft takeover: a physical knob acts only once it has passed through the level in force."""

import pytest

from studyapp.engine import commands as cmd
from studyapp.engine import events as ev
from studyapp.engine.pickup import level_position, passes_through
from studyapp.model.fmax_knob import fmax_from_knob
from tests.engine.fake_worker import fake_worker

ADJUST = {"knob1": ("fmax_log", 40.0, 2.0)}


@pytest.mark.parametrize("target, previous, value, acts", [
    (0, None, 0, True),  # never seen: landing on the level picks it up
    (0, None, 1, True),  # ... and so does the first step off it: an LPD8 knob turned up from 0 first sends 1
    (0, None, 2, True),  # (two coalesced steps)
    (0, None, 3, False),
    (127, None, 126, True),  # resting at the top, turned down
    (50, None, 51, True),  # resting at the level, mid-range
    (0, None, 100, False),
    (0, 100, 99, False),  # turned, but not through the level
    (0, 5, 0, True),
    (50, 40, 60, True),  # crossed upwards within one (coalesced) message
    (50, 60, 40, True),  # ... and downwards
    (50, 50, 51, True),  # the knob that set the level keeps acting
    (50, 51, 52, False),
])
def test_the_pickup_rule(target, previous, value, acts):
    assert passes_through(target, previous, value) is acts


def test_the_level_position_of_each_action():
    assert level_position(ADJUST["knob1"], 0.0, None) == 0
    assert level_position(ADJUST["knob1"], fmax_from_knob(77, 40.0, 2.0), None) == 77
    assert level_position(("fmax_linear", 0.0, 10.0), 5.0, None) == 64  # 63.5 steps: the nearer even step
    assert level_position(("volume",), 0.0, 0.1) == 64  # -20 dB: halfway on the console's -40..0 dB law
    assert level_position(("volume",), 0.0, 0.0) == 0  # silent: the knob's bottom
    assert level_position(("volume",), 0.0, 3.0) == 127  # above the knob's range: its top
    assert level_position(("select", "KALLEV", 1.0), 1.0, None, rating=None) is None  # unrated: free
    assert level_position(("select", "KALLEV", 1.0), 1.0, None, rating=90) == 90
    assert level_position(("source", "LVT"), 1.0, None) is None


@pytest.fixture
def worker():
    w = fake_worker()
    yield w
    w.status.close()


def midi(worker, control, step):
    worker.control(control, step / 127, arrived=1.0, block=worker.k)
    return worker.events[-1]


def test_a_knob_left_high_at_a_trial_start_acts_only_once_turned_down_through_zero(worker):
    worker.apply(cmd.InstallActions(ADJUST, trial=1))
    midi(worker, "knob1", 0)
    assert midi(worker, "knob1", 90).commands and worker.loop.fmax == pytest.approx(fmax_from_knob(90, 40.0, 2.0))
    # the next trial: F_max 0, a new mapping; the knob is still at 90
    worker.apply(cmd.SetFmax(0.0))
    worker.apply(cmd.InstallActions(ADJUST, trial=2))
    for step in (91, 60, 3):
        applied = midi(worker, "knob1", step)
        assert isinstance(applied, ev.Applied) and applied.pending_pickup and applied.commands == ()
        assert applied.pickup_target == 0.0 and applied.trial == 2
        assert worker.loop.fmax == 0.0
    applied = midi(worker, "knob1", 0)
    assert not applied.pending_pickup and applied.pickup_target is None and worker.loop.fmax == 0.0
    midi(worker, "knob1", 30)
    assert worker.loop.fmax == pytest.approx(fmax_from_knob(30, 40.0, 2.0))


def test_after_a_pause_an_unmoved_knob_continues_and_a_moved_one_must_come_back(worker):
    fmax30 = fmax_from_knob(30, 40.0, 2.0)
    worker.apply(cmd.InstallActions(ADJUST, trial=1))
    midi(worker, "knob1", 0)
    midi(worker, "knob1", 30)
    # pause and resume, the knob untouched: the level is its position, the next turn acts
    worker.apply(cmd.SetFmax(0.0))
    worker.apply(cmd.InstallActions({}, trial=-1))
    worker.apply(cmd.SetFmax(fmax30))
    worker.apply(cmd.InstallActions(ADJUST, trial=1))
    assert not midi(worker, "knob1", 31).pending_pickup
    # a pause during which the knob went to the top: back through 31 first
    worker.apply(cmd.InstallActions({}, trial=-1))
    midi(worker, "knob1", 127)
    worker.apply(cmd.InstallActions(ADJUST, trial=1))
    assert midi(worker, "knob1", 100).pending_pickup and worker.loop.fmax == pytest.approx(fmax_from_knob(31, 40.0, 2.0))
    assert not midi(worker, "knob1", 20).pending_pickup  # crossed 31 in one message
    assert worker.loop.fmax == pytest.approx(fmax_from_knob(20, 40.0, 2.0))


def test_on_screen_knobs_need_no_pickup_but_move_the_level_a_physical_knob_must_meet(worker):
    worker.apply(cmd.InstallActions(ADJUST, trial=1))
    worker.apply(cmd.Control("knob1", 50 / 127, sent=1.0))
    assert worker.events[-1].origin == "screen" and not worker.events[-1].pending_pickup
    assert midi(worker, "knob1", 10).pending_pickup  # physical knob unseen: it must reach 50
    assert not midi(worker, "knob1", 55).pending_pickup


def test_the_volume_knob_outside_a_session_and_a_rated_knob_are_picked_up_too(worker):
    worker.apply(cmd.InstallActions(cmd.default_actions(["LVT"])))
    assert midi(worker, "knob2", 20).pending_pickup and worker.sink.gain.volume == 1.0  # volume at the top
    assert not midi(worker, "knob2", 127).pending_pickup
    rating = {"knob1": ("select", "KALLEV", 1.0), "knob2": ("select", "LVT", 1.0)}
    worker.apply(cmd.InstallActions(rating, trial=3, positions={"knob2": 80}))  # a resumed rating: knob2 rated 80
    assert not midi(worker, "knob1", 100).pending_pickup  # not rated yet: the position is the rating
    assert worker.loop.source == "KALLEV"
    # knob2 was last at 127: a rating of 80 is not jumped to 100 or 85
    assert midi(worker, "knob2", 100).pending_pickup and worker.loop.source == "KALLEV"
    assert midi(worker, "knob2", 85).pending_pickup
    assert not midi(worker, "knob2", 75).pending_pickup and worker.loop.source == "LVT"
