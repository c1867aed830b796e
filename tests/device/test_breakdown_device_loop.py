"""The breakdown search's trial on a device that runs the loop (device/emulated_loop.py: the emulator's C loop in
lock-step over a pty, the host's shadow) against the model's own loop: the same verdicts away from the edge,
with the host's answers 1 and 20 samples late (the force loop does not cross the link, so lateness moves only
when the bow starts)."""

import pytest

from studyapp.device.emulated_loop import factory
from studyapp.model.breakdown import is_broken

DURATION = 2.0  # s per trial: enough for the verdict far from the edge (the model's 5 s edges: LVT 8.3 N, KALPOS 4.1 N)


@pytest.mark.parametrize("source, fmax, broken", [("LVT", 3.0, False), ("LVT", 30.0, True), ("KALPOS", 1.5, False),
                                                  ("KALPOS", 12.0, True)])
@pytest.mark.parametrize("late", [1, 20])
def test_a_trial_on_the_device_loop_gives_the_models_verdict(source, fmax, broken, late):
    model = is_broken(source, fmax, duration=DURATION, seed=0)
    device = is_broken(source, fmax, duration=DURATION, seed=0, make_loop=factory(late))
    assert model == broken and device == broken
