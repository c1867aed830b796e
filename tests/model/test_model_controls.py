"""Typed actions (model/controls.py): the one knob law, the value <-> step conversions, the compact spelling."""

import dataclasses

import numpy as np
import pytest

from studyapp.errors import ParameterError
from studyapp.model.controls import (
    KNOB_MAX, Bowing, FmaxKnob, FmaxLinear, HandTarget, Select, Source, Volume, as_action, as_actions, knob_step,
    knob_value,
)


@pytest.mark.parametrize("ceiling, decades", [(40.0, 2.0), (12.0, 3.0), (20.0, np.log10(200.0)), (1.5, 0.5)])
def test_the_knob_law_in_closed_form_and_its_inverse(ceiling, decades):
    knob = FmaxKnob(ceiling, decades)
    assert knob.fmax(0) == 0.0 and knob.fmax(KNOB_MAX) == pytest.approx(ceiling)
    for k in range(1, KNOB_MAX + 1):
        assert knob.fmax(k) == pytest.approx(ceiling * 10 ** (-decades * (127 - k) / 126), rel=1e-12)
        assert knob.step(knob.fmax(k)) == k
    assert knob.step(0.0) == 0


def test_a_value_is_a_step_over_127_and_back_exactly():
    for k in range(KNOB_MAX + 1):
        assert knob_step(knob_value(k)) == k
        assert knob_value(k) == k / 127  # what a MIDI message and an on-screen knob send


def test_actions_are_frozen_and_equal_by_content():
    assert FmaxKnob(40.0, 2.0) == FmaxKnob(40.0, 2.0) and Select("LVT", 1.0) != Select("LVT", None)
    with pytest.raises(dataclasses.FrozenInstanceError):
        FmaxKnob(40.0, 2.0).ceiling = 3.0
    assert hash(Select("LVT")) == hash(Select("LVT", None))


@pytest.mark.parametrize("spelling, action", [
    (("fmax_log", 40.0, 2.0), FmaxKnob(40.0, 2.0)),
    (("fmax_linear", 0.0, 10.0), FmaxLinear(0.0, 10.0)),
    (("volume",), Volume()),
    (("source", "LVT"), Source("LVT")),
    (("select", "KALLEV", 1.0), Select("KALLEV", 1.0)),
    (("select", "KALLEV"), Select("KALLEV", None)),
    (("bowing",), Bowing()),
    (["hand_target", -0.01, 0.01], HandTarget(-0.01, 0.01)),
])
def test_the_compact_spelling_reads_as_the_typed_action(spelling, action):
    assert as_action(spelling) == action and as_action(action) is action
    assert as_actions({"knob1": spelling}) == {"knob1": action}


@pytest.mark.parametrize("spelling, says", [
    (("fmax_cubic", 1.0), "'fmax_cubic': allowed are fmax_log, fmax_linear, volume"),
    ((), "MIDI action ()"),
    ("volume", "MIDI action 'volume'"),
    (("fmax_log", 40.0), "('fmax_log', 40.0): fmax_log takes ceiling, decades"),
    (("volume", 1.0), "volume takes nothing"),
])
def test_a_bad_spelling_is_one_line_naming_it(spelling, says):
    with pytest.raises(ParameterError) as info:
        as_action(spelling)
    assert says in str(info.value) and "\n" not in str(info.value)


def test_the_volume_law_is_the_consoles_decibel_scale_and_inverts():
    from studyapp.model.controls import VOLUME_DB

    assert VOLUME_DB == (-40.0, 0.0)
    assert Volume.gain(0.0) == pytest.approx(0.01) and Volume.gain(1.0) == 1.0
    assert Volume.gain(0.5) == pytest.approx(0.1) and Volume.gain(2.0) == 1.0  # never above full level
    for db in (-40.0, -27.5, -6.0, 0.0):
        assert Volume.db(Volume.value(db)) == pytest.approx(db)
    assert Volume.value(-90.0) == 0.0 and Volume.value(6.0) == 1.0
