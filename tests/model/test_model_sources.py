"""The pseudo-sources (model/sources.py): which velocity each drives the loop with, and the name they share with the LVT estimator."""

import numpy as np
import pytest

from studyapp.estimators import lvt, names
from studyapp.model.loop import ClosedLoop, LoopConfig
from studyapp.model.sources import LVT_SENSOR, PSEUDO_SOURCES, TRUE, is_pseudo, with_pseudo_sources


def test_pseudo_sources_are_listed_once_after_the_estimators():
    assert with_pseudo_sources(["KALMAN"]) == ["KALMAN", LVT_SENSOR, TRUE]
    assert with_pseudo_sources(names()) == names() + [TRUE]  # the LVT estimator's name is not listed twice
    assert is_pseudo(LVT_SENSOR) and is_pseudo(TRUE) and not is_pseudo("KALMAN")
    assert set(PSEUDO_SOURCES) == {"LVT", "TRUE"}  # user-visible names unchanged


@pytest.mark.parametrize("source, reading", [(LVT_SENSOR, "velocity_lvt"), (TRUE, "velocity_true")])
def test_each_pseudo_source_drives_the_loop_with_its_reading(source, reading):
    loop = ClosedLoop(LoopConfig(source=source, fmax=1.0, gesture="strokes", audio=False))
    out = loop.run(2000)
    assert np.std(out[reading]) > 0.0
    assert np.array_equal(out["source_velocity"], out[reading])
    other = "velocity_true" if reading == "velocity_lvt" else "velocity_lvt"
    assert not np.array_equal(out["source_velocity"], out[other])  # the sensor's noise tells them apart


def test_the_lvt_estimator_passes_the_sensor_reading_the_sensor_source_uses():
    # Why one text may name both: with the estimator active, its output equals the sensor source's velocity.
    loop = ClosedLoop(LoopConfig(estimators={lvt.NAME: {}}, source=LVT_SENSOR, fmax=1.0, audio=False))
    out = loop.run(2000)
    assert np.array_equal(out["estimates"][0], out["source_velocity"])
