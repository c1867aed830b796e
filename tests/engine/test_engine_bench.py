"""``studyapp bench live``: the search over rates (with fake probes), one real probe, and one-line errors.

The search's decisions are checked with a probe whose verdict is a function of
the rate; one short probe runs the real engine to check what a probe reports.
Neither asserts a speed: the figure is a measurement (docs/engine.md).
"""

import pytest

from studyapp.cli import main
from studyapp.engine import benchmark


def _fake(holds, calls, transient=()):
    """A probe that holds real time when ``holds(rate, seconds)``.

    The first run at a rate in ``transient`` fails by the machine's fault (a late start and a stall, no overrun).
    """
    def probe(rate, seconds, progress=print, block_period=benchmark.BLOCK_PERIOD):
        first = not any(c == (rate, seconds) for c in calls)
        calls.append((rate, seconds))
        late_start = rate in transient and first
        passed = holds(rate, seconds) and not late_start
        return {
            "rate": rate, "seconds": seconds, "block": benchmark.block_samples(rate, block_period),
            "achieved_rate": rate, "deadline_misses": 0 if passed else 3, "load_mean": rate / 1e5,
            "load_p99": rate / 8e4, "load_max": rate / 6e4, "faults": [],
            "overruns": 0 if passed or late_start else 2, "stalls": 1 if late_start else 0,
            "wake_late_max": 0.006 if late_start else 0.0,
            "realtime_priority": True, "passed": passed,
        }
    return probe


def test_the_search_climbs_the_ladder_bisects_and_confirms(monkeypatch):
    calls = []
    monkeypatch.setattr(benchmark, "probe", _fake(lambda rate, s: rate <= 30_000, calls))
    result = benchmark.search(confirm_seconds=30.0, progress=lambda text: None)
    assert [r for r, _ in calls[:4]] == [5000.0, 10000.0, 20000.0, 40000.0]
    # bisection between 20 and 40 kHz to within 5%, from below
    assert 30_000 * (1 - benchmark.RESOLUTION) <= result["best_probe_rate"] <= 30_000
    assert result["realtime_rate"] == result["best_probe_rate"]
    assert calls[-2] == (result["realtime_rate"], 30.0)
    # 48 kHz was not on the way, so it was probed for its load figures
    assert calls[-1] == (48000.0, benchmark.PROBE_SECONDS)
    assert result["load_at_48k"]["deadline_misses"] == 3 and result["load_at_48k"]["block"] == 96
    assert len(result["probes"]) == len(calls)


def test_a_miss_of_the_machines_is_run_again_but_an_overrun_is_not(monkeypatch):
    calls = []
    monkeypatch.setattr(benchmark, "probe", _fake(lambda rate, s: rate <= 96_000, calls, transient=(20000.0,)))
    result = benchmark.search(confirm_seconds=5.0, progress=lambda text: None)
    assert calls.count((20000.0, benchmark.PROBE_SECONDS)) == 2
    assert result["best_probe_rate"] == 96_000.0 and result["realtime_rate"] == 96_000.0

    calls = []
    monkeypatch.setattr(benchmark, "probe", _fake(lambda rate, s: rate < 10_000, calls))
    result = benchmark.search(confirm_seconds=5.0, progress=lambda text: None)
    assert calls.count((10000.0, benchmark.PROBE_SECONDS)) == 1  # it overran: no second chance


def test_a_failed_confirmation_steps_down_and_none_is_reported_when_nothing_holds(monkeypatch):
    calls = []
    monkeypatch.setattr(benchmark, "probe", _fake(lambda rate, s: rate <= 20_000 if s > 10 else rate <= 48_000, calls))
    result = benchmark.search(confirm_seconds=30.0, progress=lambda text: None)
    confirms = [r for r, s in calls if s == 30.0]
    assert confirms[0] == result["best_probe_rate"] and confirms[1] == round(confirms[0] * 0.9, -2)
    assert result["realtime_rate"] is None  # three tries, 10% apart, all above 20 kHz

    monkeypatch.setattr(benchmark, "probe", _fake(lambda rate, s: False, []))
    result = benchmark.search(confirm_seconds=30.0, progress=lambda text: None)
    assert result["realtime_rate"] is None and result["best_probe_rate"] is None


def test_one_real_probe_reports_what_it_ran():
    lines = []
    result = benchmark.probe(5000.0, 1.0, progress=lines.append, block_period=0.01)
    assert result["rate"] == 5000.0 and result["block"] == 50
    assert result["seconds"] == pytest.approx(1.0, abs=0.5)
    assert result["faults"] == []
    # Overruns and stalls are kinds of deadline miss, counted at most once each.
    assert result["overruns"] + result["stalls"] <= result["deadline_misses"]
    assert f"overruns {result['overruns']}, stalls {result['stalls']}," in lines[0]
    assert 0.0 < result["load_mean"] <= result["load_p99"] <= result["load_max"]
    assert result["passed"] == (result["deadline_misses"] == 0
                                and abs(result["achieved_rate"] - 5000.0) <= 50.0)
    assert len(lines) == 1 and lines[0].startswith("bench live:     5000 Hz for 1 s:")


@pytest.mark.parametrize("args, words", [
    (["--seconds", "0"], "--seconds 0"),
    (["--seconds", "nan"], "--seconds: 'nan' is not a finite number"),
    (["--block-ms", "500"], "--block-ms 500"),
    (["--block-ms", "x"], "--block-ms"),
])
def test_bad_options_are_one_line_and_exit_code_2(args, words, capsys):
    assert main(["bench", "live", *args]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and err[0].startswith("studyapp: error:") and words in err[0]
