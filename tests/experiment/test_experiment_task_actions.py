"""Tasks name typed actions (model/controls.py), and the F_max a task records is the one the worker applies."""

import pytest

from studyapp.engine import commands as cmd
from studyapp.experiment.tasks import task_type
from studyapp.experiment.tasks.adjustment import AdjustmentTrial
from studyapp.experiment.tasks.rating import RatingTrial
from studyapp.model.controls import FmaxKnob, Select, knob_value
from tests.engine.fake_worker import fake_worker


def test_the_adjustment_and_rating_knobs_are_typed_actions():
    adjustment = AdjustmentTrial("LVT", 1, ceiling=12.0, decades=2.5, knob=2)
    assert task_type("adjustment").knob_actions(None, adjustment) == {"knob3": FmaxKnob(12.0, 2.5)}
    rating = RatingTrial(["LVT", "KALLEV"], fmax=1.5)
    assert task_type("rating").knob_actions(None, rating) == {"knob1": Select("LVT", 1.5), "knob2": Select("KALLEV", 1.5)}


@pytest.mark.parametrize("ceiling, decades", [(12.0, 2.5), (20.0, 3.0), (4.0, 1.0)])
def test_the_worker_applies_the_f_max_the_adjustment_task_records_at_every_step(ceiling, decades):
    worker = fake_worker()
    try:
        task = AdjustmentTrial("LVT", 1, ceiling=ceiling, decades=decades)
        worker.apply(cmd.InstallActions(task_type("adjustment").knob_actions(None, task), trial=1))
        worker.safety.clamp_fmax = lambda fmax: fmax  # no ceiling: the law itself is compared
        for step in range(128):
            worker.apply(cmd.Control("knob1", knob_value(step), sent=1.0))
            task.knob(0, step)
            assert worker.loop.fmax == task.fmax  # the same law, the same number: not merely close
    finally:
        worker.status.close()
