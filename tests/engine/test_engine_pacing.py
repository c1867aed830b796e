"""The worker's block clock (engine/pacing.py): misses classed as overruns, stalls or late starts; the status window."""

import time

import pytest

from studyapp.engine.pacing import IDLE, Pacing


class TimerSink:
    paced = False
    shortfalls = 0


class AudioSink:
    paced = True
    shortfalls = 0

    def __init__(self, answers):
        self.answers = list(answers)

    def wait(self, timeout):
        return self.answers.pop(0)


PERIOD = 0.002


@pytest.mark.parametrize("finished_late, compute, cpu, miss, overruns, stalls", [
    (False, 0.001, 0.001, False, 0, 0),
    (True, 0.003, 0.0025, True, 1, 0),  # the block itself took longer than its period on the CPU
    (True, 0.003, 0.001, True, 0, 1),  # ... by the wall clock only: taken off the CPU mid-block
    (True, 0.001, 0.001, True, 0, 0),  # it started late
])
def test_a_miss_on_the_timer_is_an_overrun_a_stall_or_a_late_start(finished_late, compute, cpu, miss, overruns, stalls):
    pacing = Pacing(TimerSink(), PERIOD, k=5)
    deadline = pacing.deadline(5)
    assert deadline == pytest.approx(pacing.start + PERIOD)
    finished = deadline + (0.001 if finished_late else -0.0005)
    assert pacing.missed(deadline, finished, compute, cpu) is miss
    assert (pacing.overruns, pacing.stalls) == (overruns, stalls)
    assert pacing.loads == [pytest.approx(compute / PERIOD)]


def test_on_the_audio_clock_a_miss_is_a_period_the_device_played_short():
    sink = AudioSink([True])
    pacing = Pacing(sink, PERIOD, k=0)
    assert pacing.wait(0) is False
    assert not pacing.missed(0.0, 1e9, 0.001, 0.001)  # the timer's deadline does not count on the audio clock
    sink.shortfalls = 1
    assert pacing.missed(1e9, 0.0, 0.001, 0.001)


def test_a_device_that_stops_calling_back_hands_the_pacing_to_the_timer_once():
    pacing = Pacing(AudioSink([False, False, False]), PERIOD, k=10)
    assert [pacing.wait(10) for _ in range(3)] == [False, False, True]
    assert not pacing.audio_clock and pacing.k0 == 10
    before = time.monotonic()
    assert pacing.wait(12) is False  # now on the timer: block 12 starts 2 periods after the hand-over
    assert time.monotonic() - before >= PERIOD


def test_the_status_window_reports_once_a_second():
    pacing = Pacing(TimerSink(), PERIOD, k=0)
    start = pacing.start
    for i in range(3):
        pacing.missed(0.0, 0.0, 0.001 * (i + 1), 0.0)
        assert pacing.window(start + 0.1 * (i + 1), 10) == {}
    pacing.missed(0.0, 0.0, 0.004, 0.0)
    figures = pacing.window(start + 1.0, 10)
    assert figures == {"achieved_rate": pytest.approx(40.0), "load_mean": pytest.approx(1.25),
                       "load_max": pytest.approx(2.0)}
    assert pacing.window(start + 1.1, 10) == {}


def test_the_summary_of_a_run():
    pacing = Pacing(TimerSink(), PERIOD, k=2)
    for compute in (0.001, 0.002, 0.003):
        pacing.missed(0.0, 0.0, compute, 0.0)
    summary = pacing.summary(blocks=12, block=10, end=pacing.start + 2.0)
    assert summary["seconds"] == pytest.approx(2.0) and summary["achieved_rate"] == pytest.approx(50.0)
    assert summary["load_max"] == pytest.approx(1.5) and summary.keys() == IDLE.keys()
