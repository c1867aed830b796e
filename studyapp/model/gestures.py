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
- ``Live``: a target set from outside (the GUI's mouse) at block boundaries;
  inside a block the target moves linearly from the old to the new value.
- ``Hold``: the handle held at 0 (the hand at rest), with physiological tremor.

Stroke amplitudes and speeds are in calibration.py with their reasons.
"""

from dataclasses import dataclass

import numpy as np

from studyapp.errors import ParameterError


@dataclass(frozen=True)
class Strokes:
    amplitude: float  # m
    speed: float  # m/s
    ramp: float  # s
    dwell: float  # s

    def _segment(self, u, start, length, direction):
        """Position and velocity ``u`` seconds into one stroke of ``length`` from ``start``."""
        v, tr = self.speed, self.ramp
        tc = max(length - v * tr, 0.0) / v
        pos = np.full_like(u, start + direction * length)
        vel = np.zeros_like(u)
        acc = np.zeros_like(u)
        a = u < tr
        pos[a] = start + direction * 0.5 * v * (u[a] - tr / np.pi * np.sin(np.pi * u[a] / tr))
        vel[a] = direction * 0.5 * v * (1.0 - np.cos(np.pi * u[a] / tr))
        acc[a] = direction * 0.5 * v * np.pi / tr * np.sin(np.pi * u[a] / tr)
        b = (u >= tr) & (u < tr + tc)
        pos[b] = start + direction * (0.5 * v * tr + v * (u[b] - tr))
        vel[b] = direction * v
        c = (u >= tr + tc) & (u < 2.0 * tr + tc)
        w = u[c] - tr - tc
        pos[c] = start + direction * (0.5 * v * tr + v * tc + 0.5 * v * (w + tr / np.pi * np.sin(np.pi * w / tr)))
        vel[c] = direction * 0.5 * v * (1.0 + np.cos(np.pi * w / tr))
        acc[c] = -direction * 0.5 * v * np.pi / tr * np.sin(np.pi * w / tr)
        return pos, vel, acc

    def duration(self, length):
        return 2.0 * self.ramp + max(length - self.speed * self.ramp, 0.0) / self.speed + self.dwell

    def at(self, t):
        """Target position, velocity and acceleration at the times ``t`` (s, an array)."""
        t = np.asarray(t, dtype=np.float64)
        a = self.amplitude
        first = self.duration(a)
        half = self.duration(2.0 * a)
        out = np.empty((3, t.shape[0]))
        lead = t < first
        out[:, lead] = self._segment(t[lead], 0.0, a, 1.0)
        rest = np.flatnonzero(~lead)
        cycle = np.mod(t[rest] - first, 2.0 * half)
        down = cycle < half
        out[:, rest[down]] = self._segment(cycle[down], a, 2.0 * a, -1.0)
        out[:, rest[~down]] = self._segment(cycle[~down] - half, -a, 2.0 * a, 1.0)
        return out[0], out[1], out[2]

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
    """A target set at block boundaries; moves linearly to it across the next block."""

    def __init__(self, position=0.0):
        self.current = float(position)
        self.target = float(position)

    def set(self, x):
        self.target = float(x)

    def block(self, start, n, rate):
        frac = np.arange(1, n + 1) / n
        pos = self.current + (self.target - self.current) * frac
        vel = np.full(n, (self.target - self.current) * rate / n)
        self.current = self.target
        return pos, vel, np.zeros(n)
