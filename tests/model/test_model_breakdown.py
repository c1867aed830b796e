"""Breakdown F_max (studyapp.model.breakdown): the log bisection, the summary over seeds, the checks."""

import math
import statistics

import pytest

from studyapp.errors import ParameterError
from studyapp.model import breakdown


def threshold(edges):
    """A stand-in for ``is_broken``: broken above ``edges[seed]`` N (monotonic, as the search assumes)."""
    calls = []

    def is_broken(source, fmax, seed=0, **kwargs):
        calls.append((seed, fmax))
        return fmax > edges[seed]

    return is_broken, calls


@pytest.mark.parametrize("edge", [0.31, 4.2, 10.4, 96.0])
@pytest.mark.parametrize("tolerance", [0.02, 0.1])
def test_bisection_brackets_the_edge_in_the_closed_form_number_of_trials(monkeypatch, edge, tolerance):
    fake, calls = threshold({0: edge})
    monkeypatch.setattr(breakdown, "is_broken", fake)
    seen = []
    found = breakdown.breakdown_fmax("LOWPASS", tolerance=tolerance, progress=lambda f, b: seen.append((f, b)))
    # the geometric midpoint of a bracket no wider than 1 + tolerance is within sqrt(1 + tolerance) of the edge
    assert 1 / math.sqrt(1 + tolerance) <= found / edge <= math.sqrt(1 + tolerance)
    # two end trials, then halving ln(HIGH / LOW) until it is at most ln(1 + tolerance)
    halvings = math.ceil(math.log2(math.log(breakdown.HIGH / breakdown.LOW) / math.log1p(tolerance)))
    assert len(calls) == 2 + halvings
    assert seen == [(f, f > edge) for _, f in calls]


def test_bisection_reports_its_bounds(monkeypatch):
    fake, calls = threshold({0: 0.01, 1: 500.0})
    monkeypatch.setattr(breakdown, "is_broken", fake)
    assert breakdown.breakdown_fmax("LVT", seed=0) == breakdown.LOW and len(calls) == 1
    assert breakdown.breakdown_fmax("LVT", seed=1) == math.inf and len(calls) == 3


def test_over_seeds_summarises_every_seed(monkeypatch):
    edges = {0: 6.0, 1: 2.0, 2: 500.0, 3: 3.0}
    fake, calls = threshold(edges)
    monkeypatch.setattr(breakdown, "is_broken", fake)
    events = []
    result = breakdown.breakdown_over_seeds("KALPOS", seeds=4, progress=lambda *e: events.append(e))
    assert tuple(result) == breakdown.KEYS
    assert result["seeds"] == 4 and len(result["fmax"]) == 4
    # each within the search's sqrt(1.02) of its seed's edge
    assert result["fmax"][:2] + result["fmax"][3:] == pytest.approx([6.0, 2.0, 3.0], rel=math.sqrt(1.02) - 1)
    assert result["fmax"][2] == math.inf
    fmax = result["fmax"]
    assert result["fmax_median"] == pytest.approx(statistics.median(fmax))  # even count: mean of the middle two
    assert result["fmax_min"] == min(fmax) and result["fmax_max"] == math.inf
    assert {seed for seed, _ in calls} == {0, 1, 2, 3}
    assert (result["first_seed"], result["seeds_used"]) == (0, [0, 1, 2, 3])
    results = [e for e in events if e[3] == "result"]
    assert [(e[0], e[2]) for e in results] == list(enumerate(fmax))
    trials = [e for e in events if e[3] != "result"]
    assert len(trials) == len(calls) and all(e[3] == ("broken" if e[2] > edges[e[0]] else "stable") for e in trials)


def test_over_seeds_on_the_loop_gives_each_seeds_own_search():
    result = breakdown.breakdown_over_seeds("LOWPASS", rate=5000.0, seeds=2, gesture="hold", duration=1.5)
    assert tuple(result) == breakdown.KEYS
    assert (result["source"], result["rate"], result["gesture"], result["seeds"]) == ("LOWPASS", 5000.0, "hold", 2)
    assert all(isinstance(v, float) for v in result["fmax"])
    assert result["fmax"] == [breakdown.breakdown_fmax("LOWPASS", gesture="hold", duration=1.5, seed=s) for s in (0, 1)]
    assert result["fmax_median"] == pytest.approx(statistics.median(result["fmax"]))
    assert (result["fmax_min"], result["fmax_max"]) == (min(result["fmax"]), max(result["fmax"]))


def test_sources_are_every_estimator_and_true():
    from studyapp.estimators import names

    assert breakdown.sources() == names() + ["TRUE"] and "LVT" in breakdown.sources()


@pytest.mark.parametrize("kwargs, words", [
    (dict(source="NOPE"), "source 'NOPE': allowed are BDIFF"),
    (dict(seeds=0), "seeds 0: allowed is a whole number from 1 to 100"),
    (dict(seeds=101), "seeds 101"),
    (dict(seeds=2.0), "seeds 2.0"),
    (dict(gesture="strokes-validation"), "gesture 'strokes-validation': allowed are hold, strokes"),
    (dict(duration=0.1), "duration 0.1: allowed is a number of seconds from 0.5 to 60"),
    (dict(rate=500.0), "rate = 500"),
    (dict(first_seed=-1), "first seed -1: allowed is a whole number from 0 to 999999"),
    (dict(first_seed=1.0), "first seed 1.0"),
    (dict(first_seed=True), "first seed True"),
    (dict(first_seed=999_999, seeds=2), "first seed 999999: allowed is a whole number from 0 to 999998"),
])
def test_bad_settings_are_refused_before_any_trial(monkeypatch, kwargs, words):
    fake, calls = threshold({0: 1.0})
    monkeypatch.setattr(breakdown, "is_broken", fake)
    with pytest.raises(ParameterError, match=words):
        breakdown.breakdown_over_seeds(**{"source": "LVT", "seeds": 1, **kwargs})
    assert calls == []


def test_over_seeds_from_a_first_seed_runs_those_seeds(monkeypatch):
    edges = {5: 6.0, 6: 2.0, 7: 3.0}
    fake, calls = threshold(edges)
    monkeypatch.setattr(breakdown, "is_broken", fake)
    events = []
    result = breakdown.breakdown_over_seeds("KALPOS", seeds=3, first_seed=5, progress=lambda *e: events.append(e))
    assert tuple(result) == breakdown.KEYS
    assert (result["seeds"], result["first_seed"], result["seeds_used"]) == (3, 5, [5, 6, 7])
    assert {seed for seed, _ in calls} == {5, 6, 7}
    assert result["fmax"] == pytest.approx([6.0, 2.0, 3.0], rel=math.sqrt(1.02) - 1)
    assert [(e[0], e[2]) for e in events if e[3] == "result"] == list(zip([5, 6, 7], result["fmax"]))
