"""The one-rounding nudge of the initial state (model/nudge.py; issue 39, item 2).

A nudge of 0 is the plain model bit for bit (compared within this run); a
nudge of n starts the end-effector n * spacing(travel) off rest, the loop
carries it (the runs differ) and says so in a recording's metadata;
STUDYAPP_NUDGE reaches a command, and a bad value is one line, exit code 2.
"""

import os
import subprocess
import sys

import numpy as np
import pytest

from studyapp.errors import ParameterError
from studyapp.model import nudge
from studyapp.model.device import DeviceLimits
from studyapp.model.simulate import simulate
from studyapp.model.simulated_device import DS_X, SimulatedDevice


def test_the_nudge_is_whole_rounding_steps_of_the_travel():
    travel = DeviceLimits().travel
    assert nudge.initial_position(travel, 0) == 0.0
    assert nudge.initial_position(travel, 1) == np.nextafter(travel, np.inf) - travel
    assert nudge.initial_position(travel, -3) == -3 * np.spacing(travel)
    assert SimulatedDevice(5000.0, nudge=2)._ds[DS_X] == 2 * np.spacing(travel)


@pytest.mark.parametrize("bad", [1.5, True, "1", 10 ** 7])
def test_a_bad_nudge_names_itself(bad):
    with pytest.raises(ParameterError, match="nudge"):
        SimulatedDevice(5000.0, nudge=bad)


def test_the_environment_sets_the_default(monkeypatch):
    monkeypatch.delenv(nudge.VARIABLE, raising=False)
    assert SimulatedDevice(5000.0).nudge == 0
    monkeypatch.setenv(nudge.VARIABLE, " -1 ")
    assert SimulatedDevice(5000.0).nudge == -1
    assert SimulatedDevice(5000.0, nudge=0).nudge == 0
    monkeypatch.setenv(nudge.VARIABLE, "one")
    with pytest.raises(ParameterError, match="STUDYAPP_NUDGE 'one'"):
        SimulatedDevice(5000.0)


def test_nudge_0_is_the_plain_run_and_nudge_1_moves_it(monkeypatch):
    monkeypatch.delenv(nudge.VARIABLE, raising=False)
    plain = simulate(8.0, duration=0.5, seed=0)
    monkeypatch.setenv(nudge.VARIABLE, "0")
    again = simulate(8.0, duration=0.5, seed=0)
    monkeypatch.setenv(nudge.VARIABLE, "1")
    nudged = simulate(8.0, duration=0.5, seed=0)
    for name in ("velocity_true", "force", "audio"):
        np.testing.assert_array_equal(again.columns[name], plain.columns[name])
    assert not np.array_equal(nudged.columns["velocity_true"], plain.columns["velocity_true"])
    assert (plain.meta["nudge"], nudged.meta["nudge"]) == (0, 1)


def test_a_bad_environment_value_is_one_line_and_exit_2(tmp_path):
    done = subprocess.run([sys.executable, "-m", "studyapp", "simulate", "--fmax", "1", "--duration", "0.1",
                           "-o", str(tmp_path / "r.npz")], capture_output=True, text=True,
                          env={**os.environ, nudge.VARIABLE: "2.5"})
    assert done.returncode == 2
    assert done.stderr.strip().splitlines() == [
        "studyapp: error: environment variable STUDYAPP_NUDGE '2.5': allowed is a whole number of rounding steps "
        "from -1000000 to 1000000 (0: the plain model)"]
