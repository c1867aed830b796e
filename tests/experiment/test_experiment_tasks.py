"""Task logic: scripted event sequences give the expected logged responses."""

import json

import numpy as np
import pytest

from studyapp.experiment.tasks import task_type
from studyapp.experiment.tasks.adjustment import AdjustmentTrial
from studyapp.experiment.tasks.rating import RatingTrial, normalise_ratings
from studyapp.model.fmax_knob import fmax_from_knob, knob_from_fmax

CONDITIONS = ("LOWPASS", "LEVANT", "KALLEV", "LVT")


def play(task, script):
    """Feed ``script`` (tuples like ("knob", i, v), ("pad", i), ("tick", dt)) and collect the records."""
    records = []
    for kind, *args in script:
        records += getattr(task, kind)(*args)
    return records


def test_rating_knob_selects_and_rates():
    task = RatingTrial(CONDITIONS, fmax=1.0)
    assert task.source is None and task.fmax == 0.0
    records = play(task, [("knob", 2, 50), ("tick", 0.5), ("knob", 0, 10), ("tick", 0.25)])
    assert records == [
        {"type": "knob", "index": 2, "value": 50, "condition": "KALLEV"},
        {"type": "knob", "index": 0, "value": 10, "condition": "LOWPASS"},
    ]
    assert task.source == "LOWPASS" and task.fmax == 1.0
    assert task.dwell["KALLEV"] == 0.5 and task.dwell["LOWPASS"] == 0.25


def test_rating_full_sequence_gives_the_normalised_response():
    task = RatingTrial(CONDITIONS, fmax=1.0, confirm_pad=3)
    script = [
        ("knob", 3, 127), ("tick", 1.0),  # best first: LVT at the top
        ("knob", 1, 0), ("tick", 1.0),    # worst: LEVANT at the bottom
        ("knob", 0, 40), ("knob", 0, 64),  # LOWPASS turned, then placed
        ("knob", 2, 100),
        ("pad", 0),                        # another pad: logged, ignored
        ("pad", 3),
    ]
    records = play(task, script)
    assert [r["type"] for r in records] == ["knob"] * 5 + ["pad", "pad", "response"]
    assert records[5] == {"type": "pad", "index": 0}
    assert records[6] == {"type": "pad", "index": 3, "accepted": True}
    response = records[7]
    assert task.done and response is task.response
    assert response["task"] == "rating" and response["trial"] == 1 and response["fmax"] == 1.0
    assert response["duration"] == 2.0
    got = {r["condition"]: (r["knob"], r["value"], r["rating"]) for r in response["responses"]}
    # Noisiness: 0 = the best (highest knob), 1 = the worst (lowest knob).
    assert got == {"LOWPASS": (0, 64, pytest.approx(63 / 127)), "LEVANT": (1, 0, 1.0),
                   "KALLEV": (2, 100, pytest.approx(27 / 127)), "LVT": (3, 127, 0.0)}
    assert play(task, [("knob", 0, 5), ("pad", 3)]) == [{"type": "pad", "index": 3}]


def test_rating_normalises_within_the_participants_range():
    ratings = normalise_ratings({"A": 20, "B": 100, "C": 60})
    assert ratings == {"A": 1.0, "B": 0.0, "C": 0.5}
    with pytest.raises(ValueError):
        normalise_ratings({"A": 3, "B": 3})


def test_rating_confirm_is_refused_until_complete():
    task = RatingTrial(CONDITIONS, fmax=1.0)
    records = play(task, [("knob", 0, 127), ("knob", 1, 0), ("pad", 0)])
    assert records[-1]["accepted"] is False and records[-1]["reason"] == "not rated yet: knob 3, knob 4"  # blind-safe
    records = play(task, [("knob", 0, 30), ("knob", 1, 30), ("knob", 2, 30), ("knob", 3, 30), ("pad", 0)])
    assert records[-1]["accepted"] is False and "same rating" in records[-1]["reason"]
    assert not task.done


def test_rating_ignores_unassigned_knobs_and_rejects_bad_values():
    task = RatingTrial(CONDITIONS, fmax=1.0)
    assert task.knob(7, 10) == [] and task.source is None
    for bad in (-1, 128, 1.5, True):
        with pytest.raises(ValueError, match="knob value"):
            task.knob(0, bad)


def test_adjustment_sequence_with_overshoot():
    task = AdjustmentTrial("LOWPASS", trial=2, ceiling=40.0, decades=3.0, knob=0, confirm_pad=1)
    assert task.fmax == 0.0 and task.source == "LOWPASS"
    script = [("pad", 1), ("knob", 1, 99), ("knob", 0, 60), ("tick", 0.5, True), ("knob", 0, 100),
              ("tick", 0.5, True), ("knob", 0, 96), ("pad", 0), ("pad", 1)]
    records = play(task, script)
    assert records[0] == {"type": "pad", "index": 1, "accepted": False, "reason": "F_max is 0: turn the knob up first"}
    knobs = [r for r in records if r["type"] == "knob"]
    assert [r["value"] for r in knobs] == [60, 100, 96]
    response = records[-1]
    expected = 40.0 * 10 ** (-3 * (127 - 96) / 126)
    assert response == {
        "type": "response", "task": "adjustment", "condition": "LOWPASS", "trial": 2,
        "fmax": pytest.approx(expected), "value": 96,
        "peak_fmax": pytest.approx(40.0 * 10 ** (-3 * 27 / 126)),
        "heard_fmax": pytest.approx(40.0 * 10 ** (-3 * 27 / 126)), "duration": 1.0,
    }
    assert task.done and task.knob(0, 5) == [] and task.fmax == pytest.approx(expected)


def test_adjustment_refuses_a_setting_never_heard():
    """Issue 31 item 4: after a stop or a restart a knob turned up over silence is not a response."""
    task = AdjustmentTrial("LVT", trial=1, ceiling=40.0, decades=2.0)
    play(task, [("knob", 0, 30), ("tick", 0.5, True), ("knob", 0, 127), ("tick", 0.5, False)])
    (refused,) = task.pad(0)
    assert refused["accepted"] is False and refused["reason"].startswith("this setting has not been heard yet")
    assert "F_max" not in refused["reason"] and not task.done
    task.knob(0, 30)  # back to what was heard: taken
    assert task.pad(0)[-1]["fmax"] == pytest.approx(task.heard_fmax)


def test_fmax_knob_map_is_logarithmic_from_zero_to_the_ceiling():
    assert fmax_from_knob(0, 40.0, 3.0) == 0.0
    assert fmax_from_knob(1, 40.0, 3.0) == pytest.approx(0.04)  # the ceiling 3 decades down
    assert fmax_from_knob(127, 40.0, 3.0) == pytest.approx(40.0)
    values = [fmax_from_knob(k, 12.0, 2.0) for k in range(1, 128)]
    ratios = np.array(values[1:]) / np.array(values[:-1])
    np.testing.assert_allclose(ratios, 10 ** (2 / 126))  # equal ratios: logarithmic
    for k in range(128):
        assert knob_from_fmax(fmax_from_knob(k, 12.0, 2.0), 12.0, 2.0) == k
    assert knob_from_fmax(1e-9, 12.0, 2.0) == 1 and knob_from_fmax(1e9, 12.0, 2.0) == 127


def test_ratings_are_normalised_once_and_exported_as_logged():
    task = RatingTrial(CONDITIONS, fmax=1.0)
    records = play(task, [("knob", 0, 90), ("knob", 1, 10), ("knob", 2, 127), ("knob", 3, 37), ("pad", 0)])
    response = records[-1]
    rows = task_type("rating").export_rows(json.loads(json.dumps(response)))  # as read back from events.jsonl
    # Closed form: noisiness = (max - k) / (max - min) over this participant's knob positions.
    expected = {"LOWPASS": 37 / 117, "LEVANT": 1.0, "KALLEV": 0.0, "LVT": 90 / 117}
    assert {r["condition"]: r["rating"] for r in rows} == pytest.approx(expected)
    assert [r["rating"] for r in rows] == [r["rating"] for r in response["responses"]]
    assert [(r["knob"], r["value"]) for r in rows] == [(0, 90), (1, 10), (2, 127), (3, 37)]
