"""The bowing measures (bowing_measures.py) on synthetic signals whose answers are known in closed form."""

import math

import numpy as np
import pytest

from studyapp.model import bowing_measures as bm

RATE = 5000.0


def stroke_velocity(cruise=0.3, ramp=0.05, rest=0.1, speed=0.04):
    """rest, linear ramp up, cruise, ramp down, rest (m/s); returns (velocity, cruise start, cruise end) in samples."""
    n = lambda s: int(round(s * RATE))  # noqa: E731
    up = np.linspace(0.0, speed, n(ramp), endpoint=False)
    v = np.r_[np.zeros(n(rest)), up, np.full(n(cruise), speed), up[::-1], np.zeros(n(rest))]
    start = n(rest) + n(ramp)
    return v, start, start + n(cruise)


def top_speed_run(v):
    """(first, last + 1) sample at 99 % of the top speed or more: the ramps' last samples count."""
    top = np.flatnonzero(np.abs(v) >= 0.99 * np.max(np.abs(v)))
    return top[0], top[-1] + 1


def test_cruise_is_the_top_speed_less_the_margins():
    v, a, e = stroke_velocity()
    first, end = top_speed_run(v)
    assert a - 3 <= first <= a and e <= end <= e + 3  # a linear ramp of 250 samples: 2 of them within 1 %
    m = int(bm.MARGIN * RATE)
    expected = np.zeros(v.size, dtype=bool)
    expected[first + m:end - m] = True
    np.testing.assert_array_equal(bm.cruise_mask(v, RATE), expected)


def test_ripple_of_a_sine_on_a_stroke_is_its_rms():
    v, a, e = stroke_velocity(cruise=1.0)
    t = np.arange(v.size) / RATE
    amplitude = 10e-6
    position = np.cumsum(v) / RATE + amplitude * np.sin(2 * np.pi * 147.0 * t)
    # the 50 Hz high-pass passes 147 Hz at |H|^2 (forwards and backwards) of a 2nd-order Butterworth
    gain = 1.0 / (1.0 + (50.0 / 147.0) ** 4)
    assert bm.ripple_rms(position, v, RATE) == pytest.approx(gain * amplitude / math.sqrt(2), rel=0.01)


def test_the_stroke_itself_is_not_ripple():
    v, _, _ = stroke_velocity(cruise=1.0)
    assert bm.ripple_rms(np.cumsum(v) / RATE, v, RATE) < 1e-8


def test_ripple_and_stick_fraction_count_only_after_start():
    v, a, e = stroke_velocity(cruise=1.0)
    first, end = top_speed_run(v)
    stick = np.zeros(v.size)
    stick[: a + int(0.5 * RATE)] = 1.0  # sticks for the first half second of cruise, slips after
    m = int(bm.MARGIN * RATE)
    expected = (a + int(0.5 * RATE) - first - m) / (end - first - 2 * m)
    assert bm.stick_fraction(stick, v, RATE) == pytest.approx(expected)
    assert bm.stick_fraction(stick, v, RATE, start=(a + int(0.5 * RATE)) / RATE) == 0.0


def helmholtz_stick(n, period, slip, irregular_until):
    """Sticking with one slip of ``slip`` samples per ``period`` after ``irregular_until``; before it, slips at
    irregular intervals (1.5 periods apart)."""
    stick = np.ones(n)
    k = 10.0
    while k < n:
        stick[int(k):int(k) + slip] = 0.0
        k += 1.5 * period if k < irregular_until else period
    return stick


def test_formation_is_the_first_slip_of_five_regular_periods():
    f0, beta = 147.0, 0.127
    period = RATE / f0
    v, a, e = stroke_velocity(cruise=0.5)
    regular_from = a + int(0.2 * RATE)
    stick = helmholtz_stick(v.size, period, slip=int(beta * period), irregular_until=regular_from)
    onsets = bm.slip_onsets(stick, 1)
    # the first slip placed at or after regular_from is the first followed by one-period intervals
    expected = (onsets[onsets >= regular_from][0] - top_speed_run(v)[0]) / RATE
    (t,) = bm.formation_times(stick, v, RATE, f0, beta)
    assert t == pytest.approx(expected)
    assert 0.15 < t < 0.21


def test_no_helmholtz_motion_is_inf_and_short_slips_do_not_count():
    f0, beta = 147.0, 0.127
    period = RATE / f0
    v, _, _ = stroke_velocity(cruise=0.5)
    irregular = helmholtz_stick(v.size, period, slip=int(beta * period), irregular_until=v.size)
    assert bm.formation_times(irregular, v, RATE, f0, beta) == [math.inf]
    # one-sample slips are shorter than a quarter of the Helmholtz slip: ripple at the junction
    chatter = helmholtz_stick(v.size, period, slip=1, irregular_until=0)
    assert bm.formation_times(chatter, v, RATE, f0, beta) == [math.inf]


def test_one_time_per_cruise_segment():
    v, _, _ = stroke_velocity(cruise=0.3)
    both = np.r_[v, -v]
    period = RATE / 147.0
    stick = helmholtz_stick(both.size, period, slip=4, irregular_until=0)
    times = bm.formation_times(stick, both, RATE, 147.0, 0.127)
    assert len(times) == 2 and all(0.0 <= t < 2 / 147.0 for t in times)


def test_slip_onsets_against_a_hand_made_run():
    stick = np.array([1, 1, 0, 0, 0, 1, 0, 1, 1, 0, 0], dtype=float)
    np.testing.assert_array_equal(bm.slip_onsets(stick, 2), [2, 9])
    np.testing.assert_array_equal(bm.slip_onsets(stick, 1), [2, 6, 9])
