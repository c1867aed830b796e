"""What a stroke of bowing did to the handle and the string: ripple, stick fraction, Helmholtz formation time.

Issue 11's item 1 asks for the handle's stick-slip ripple during Helmholtz
motion; docs/model.md ("What the recalibration tried") reports these three
figures for each trial of scripts/recalibration_trials.py.

Cruise: the samples where the gesture's target speed is at its stroke
maximum (within 1 %), shrunk by MARGIN = 20 ms at each end, so the speed
ramps and the transients they excite in the handle do not count as ripple.

- ``ripple_rms``: the RMS (m) over the cruise samples of the handle's true
  position high-passed at RIPPLE_HIGHPASS = 50 Hz (2nd-order Butterworth, run
  forwards and backwards so it adds no delay): what is left is the motion at
  and above the string's pitch, the stick-slip, not the stroke.
- ``stick_fraction``: the share of cruise samples in which the bow sticks.
- ``formation_times``: for each cruise segment, the time (s) from its start
  to the first slip that begins a run of FORMED = 5 slip-to-slip intervals
  each within 8 % of the string's period (Helmholtz motion: one slip per
  period), inf when there is none. A slip is a run of non-sticking samples at
  least a quarter of the Helmholtz slip (beta / f0) long; shorter runs are
  ripple at the junction, not slips (as in tests/model/test_model_helmholtz.py).
"""

import math

import numpy as np
from scipy import signal

RIPPLE_HIGHPASS = 50.0  # Hz
MARGIN = 0.02  # s trimmed from each end of a cruise segment
FORMED = 5  # consecutive one-period slip intervals that count as Helmholtz motion
PERIOD_TOLERANCE = 0.08


def cruise_mask(target_velocity, rate, margin=MARGIN):
    """True where the target speed is within 1 % of its maximum, at least ``margin`` s from a segment's ends."""
    speed = np.abs(np.asarray(target_velocity, dtype=np.float64))
    top = speed.max() if speed.size else 0.0
    if top <= 0.0:
        return np.zeros(speed.size, dtype=bool)
    at_top = speed >= 0.99 * top
    m = int(round(margin * rate))
    if m == 0:
        return at_top
    kernel = np.ones(2 * m + 1)
    return np.convolve(at_top.astype(np.float64), kernel, "same") >= kernel.size - 0.5


def ripple_rms(position, target_velocity, rate, start=0.0):
    """RMS (m) of the position high-passed at 50 Hz over the cruise samples from ``start`` s on."""
    sos = signal.butter(2, RIPPLE_HIGHPASS, btype="high", fs=rate, output="sos")
    ripple = signal.sosfiltfilt(sos, np.asarray(position, dtype=np.float64))
    mask = cruise_mask(target_velocity, rate)
    mask[: int(round(start * rate))] = False
    return float(np.sqrt(np.mean(ripple[mask] ** 2))) if mask.any() else math.nan


def stick_fraction(stick, target_velocity, rate, start=0.0):
    """Share of the cruise samples (from ``start`` s on) in which the bow sticks."""
    mask = cruise_mask(target_velocity, rate)
    mask[: int(round(start * rate))] = False
    return float(np.mean(np.asarray(stick)[mask] > 0.5)) if mask.any() else math.nan


def slip_onsets(stick, min_length):
    """Starts of the runs of non-sticking samples at least ``min_length`` samples long."""
    sticking = np.asarray(stick) > 0.5
    edges = np.flatnonzero(np.diff(sticking.astype(np.int8))) + 1
    starts = np.r_[0, edges]
    lengths = np.diff(np.r_[0, edges, sticking.size])
    keep = (starts > 0) & ~sticking[starts] & (lengths >= min_length)
    return starts[keep]


def formation_times(stick, target_velocity, rate, f0, beta):
    """Per cruise segment, seconds from its start until Helmholtz motion (inf if it never forms)."""
    period = rate / f0
    onsets = slip_onsets(stick, max(1.0, 0.25 * beta * period))
    mask = cruise_mask(target_velocity, rate, margin=0.0).astype(np.int8)
    starts = np.flatnonzero(np.diff(np.r_[0, mask]) == 1)
    ends = np.flatnonzero(np.diff(np.r_[mask, 0]) == -1) + 1
    times = []
    for a, e in zip(starts, ends):
        inside = onsets[(onsets >= a) & (onsets < e)]
        regular = np.abs(np.diff(inside) / period - 1.0) < PERIOD_TOLERANCE
        found = math.inf
        for i in range(regular.size - FORMED + 1):
            if regular[i:i + FORMED].all():
                found = (inside[i] - a) / rate
                break
        times.append(found)
    return times
