"""model/limits.py: the constants several layers read, defined once and importable without the simulation."""

import subprocess
import sys

import numpy as np
import pytest

from studyapp.experiment.protocol import SAFE_CEILING
from studyapp.model import limits
from studyapp.model.device import DeviceLimits
from studyapp.model.loop import make_gesture

# modules that read a limit or the knob law and must not load the compiled simulation
LIGHT = ["studyapp.model.limits", "studyapp.model.fmax_knob", "studyapp.experiment.tasks",
         "studyapp.experiment.protocol", "studyapp.experiment.schedule"]


@pytest.mark.parametrize("module", LIGHT)
def test_importing_a_constant_loads_neither_numba_nor_scipy(module):
    code = f"import sys, {module}; print(sorted(m for m in ('numba', 'scipy') if m in sys.modules))"
    run = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, timeout=120, check=True)
    assert run.stdout.strip() == "[]", f"import {module} loaded {run.stdout.strip()}"


def test_the_device_limits_are_the_limits():
    device = DeviceLimits()
    assert (device.travel, device.impulsive, device.sustained) == (
        limits.TRAVEL, limits.IMPULSIVE_FORCE, limits.SUSTAINED_FORCE)
    assert limits.FMAX_LIMIT == device.impulsive and SAFE_CEILING == device.sustained <= limits.FMAX_LIMIT


def test_each_gesture_set_is_a_set_of_gestures_the_loop_runs():
    for name in limits.GESTURES:
        trajectory = np.zeros(10) if name == "playback" else None
        make_gesture(name, 5000.0, trajectory)
    assert set(limits.SESSION_GESTURES) == set(limits.GESTURES) - {"playback"}
    assert set(limits.CONSOLE_GESTURES) <= set(limits.SESSION_GESTURES)
    assert set(limits.BREAKDOWN_GESTURES) <= set(limits.SESSION_GESTURES)
