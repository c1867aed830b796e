"""Gestures: where the virtual hand wants the handle to be, sample by sample.

A gesture gives, for a block of samples, the target position x_g (m), its
velocity v_g (m/s) and acceleration a_g (m/s^2); the hand (hand.py) drives the
handle along it.

- ``Strokes``: back-and-forth bow strokes between -A and +A at a cruise speed,
  with raised-cosine speed ramps at each reversal and a dwell at each end; the
  first stroke starts from rest at 0 and goes to +A. A ramp of duration t_r
  covers v t_r / 2, so a stroke of length L cruises for (L - v t_r) / v.
- ``Playback``: a recorded trajectory (m), played at the loop rate; the last
  sample is held.
- ``Live``: a target set from outside (the GUI's mouse) at block boundaries,
  followed by a critically damped second-order glide (corner LIVE_HZ):

      x'' = w^2 (target - x) - 2 w x',   w = 2 pi LIVE_HZ,

  solved exactly over each block for the target held constant,
  e = x - target, e(t) = (e0 + (v0 + w e0) t) exp(-w t). A pointer moves in
  steps, one per mouse event (60-125 a second): followed a block at a time,
  each step was a 2 ms velocity pulse, and the pulses' harmonics filled the
  stability monitor's 50-400 Hz band and the contact microphone's sound at
  F_max 0 ("broken" with no friction, a buzz that was the mouse's: issue 31).
  A bowing hand's motion lies below about 10 Hz (strokes of 0.5 to 3 Hz), so
  the glide keeps the gesture (a lag of 2 / w, 32 ms) and takes the steps out
  (-12 dB per octave above LIVE_HZ: -31 dB at 60 Hz).
- ``Hold``: the handle held at 0 (the hand at rest), with physiological tremor.

Stroke amplitudes and speeds are in calibration.py with their reasons.
"""

import math
from dataclasses import dataclass

import numpy as np
from numba import njit

from studyapp.errors import ParameterError

LIVE_HZ = 10.0  # the live gesture's glide: corner frequency (Hz)


@njit(cache=True)
def _segment(u, start, length, direction, v, tr):
    """Position, velocity, acceleration ``u`` s into one stroke of ``length`` from ``start``."""
    tc = max(length - v * tr, 0.0) / v
    if u < tr:
        w = math.pi * u / tr
        return (start + direction * 0.5 * v * (u - tr / math.pi * math.sin(w)),
                direction * 0.5 * v * (1.0 - math.cos(w)), direction * 0.5 * v * math.pi / tr * math.sin(w))
    if u < tr + tc:
        return start + direction * (0.5 * v * tr + v * (u - tr)), direction * v, 0.0
    if u < 2.0 * tr + tc:
        q = u - tr - tc
        w = math.pi * q / tr
        return (start + direction * (0.5 * v * tr + v * tc + 0.5 * v * (q + tr / math.pi * math.sin(w))),
                direction * 0.5 * v * (1.0 + math.cos(w)), -direction * 0.5 * v * math.pi / tr * math.sin(w))
    return start + direction * length, 0.0, 0.0


@njit(cache=True)
def strokes_at(t, amplitude, speed, ramp, dwell, pos, vel, acc):
    """Fill ``pos``, ``vel``, ``acc`` with the strokes at the times ``t``."""
    first = 2.0 * ramp + max(amplitude - speed * ramp, 0.0) / speed + dwell
    half = 2.0 * ramp + max(2.0 * amplitude - speed * ramp, 0.0) / speed + dwell
    for k in range(t.shape[0]):
        if t[k] < first:
            pos[k], vel[k], acc[k] = _segment(t[k], 0.0, amplitude, 1.0, speed, ramp)
        else:
            c = (t[k] - first) % (2.0 * half)
            if c < half:
                pos[k], vel[k], acc[k] = _segment(c, amplitude, 2.0 * amplitude, -1.0, speed, ramp)
            else:
                pos[k], vel[k], acc[k] = _segment(c - half, -amplitude, 2.0 * amplitude, 1.0, speed, ramp)


@dataclass(frozen=True)
class Strokes:
    amplitude: float  # m
    speed: float  # m/s
    ramp: float  # s
    dwell: float  # s

    def duration(self, length):
        """Seconds for one stroke of ``length`` m, dwell included."""
        return 2.0 * self.ramp + max(length - self.speed * self.ramp, 0.0) / self.speed + self.dwell

    def at(self, t):
        """Target position, velocity and acceleration at the times ``t`` (s, an array)."""
        t = np.ascontiguousarray(t, dtype=np.float64)
        pos, vel, acc = np.empty_like(t), np.empty_like(t), np.empty_like(t)
        strokes_at(t, self.amplitude, self.speed, self.ramp, self.dwell, pos, vel, acc)
        return pos, vel, acc

    def block(self, start, n, rate):
        return self.at((start + np.arange(n)) / rate)


@dataclass(frozen=True)
class Hold:
    """The hand at rest at ``position``, with a sinusoidal physiological tremor."""

    position: float = 0.0
    tremor: float = 0.0  # m, amplitude
    tremor_hz: float = 9.0

    def block(self, start, n, rate):
        w = 2.0 * np.pi * self.tremor_hz
        t = (start + np.arange(n)) / rate
        return (self.position + self.tremor * np.sin(w * t), self.tremor * w * np.cos(w * t),
                -self.tremor * w * w * np.sin(w * t))


class Playback:
    """A trajectory array (m) at the loop rate; the last sample is held after its end."""

    def __init__(self, trajectory, rate):
        traj = np.asarray(trajectory, dtype=np.float64)
        if traj.ndim != 1 or traj.size == 0 or not np.all(np.isfinite(traj)):
            raise ParameterError("trajectory: expected a non-empty 1-D array of finite positions (m)")
        self.trajectory = traj
        self.velocity = np.gradient(traj) * rate if traj.size > 1 else np.zeros(1)
        self.acceleration = np.gradient(self.velocity) * rate if traj.size > 1 else np.zeros(1)

    def block(self, start, n, rate):
        k = start + np.arange(n)
        idx = np.minimum(k, self.trajectory.size - 1)
        after = k >= self.trajectory.size
        vel = np.where(after, 0.0, self.velocity[idx])
        acc = np.where(after, 0.0, self.acceleration[idx])
        return self.trajectory[idx], vel, acc


class Live:
    """A target set at block boundaries, followed by a critically damped glide (see the module docstring)."""

    def __init__(self, position=0.0, hz=None):
        self.current = float(position)
        self.velocity = 0.0
        self.target = float(position)
        self.w = 2.0 * math.pi * (LIVE_HZ if hz is None else float(hz))

    def set(self, x):
        self.target = float(x)

    def block(self, start, n, rate):
        w, e0, v0 = self.w, self.current - self.target, self.velocity
        t = np.arange(1, n + 1) / rate
        decay = np.exp(-w * t)
        c = v0 + w * e0
        pos = self.target + (e0 + c * t) * decay
        vel = (v0 - w * c * t) * decay
        acc = (w * w * c * t - 2.0 * w * v0 - w * w * e0) * decay
        self.current, self.velocity = float(pos[-1]), float(vel[-1])
        return pos, vel, acc
