"""The participant's own bowing gesture, as performed: recorded per trial, decimated, and replayed.

Recording (``HandTrace``). With the participant's bowing surface the hand's
target x (m) follows the pointer (``Live`` gesture, model/gestures.py). Each
target, and each time the bow touches or leaves the string, is a sample
``(t, x, bow)``: t the trial's clock (s of loop time the trial has run,
``SessionRunner.clock``), bow 1 on the string, 0 lifted. Decimation: a
sample closer than ``SPACING_S`` to the sample before the last kept one
replaces the last one (unless the bow changed), so the kept samples are at
most 2 / ``SPACING_S`` = 100 per second on average and the newest position
is always kept. 20 ms is enough to replay the gesture: a bowing hand's
motion lies below about 10 Hz (strokes of 0.5 to 3 Hz, reversals of ~0.1 s),
and the virtual hand (model/hand.py, a mass-spring-damper about the target)
and ``Live``'s linear interpolation inside each block smooth the steps the
same way a pointer's own ~60-125 Hz events are smoothed.

A trial's trace is one ``hand_trace`` record in the session log (``trial``,
``spacing_s``, ``t`` in s to the ms, ``x_mm`` in mm to the micrometre,
``bow`` 0/1), logged when the trial ends (its response, an abort, its
restart); a trial the pointer never touched logs none.

Replay. ``HandReplay(trace).motion`` is the trace's bowing motion: the
samples taken with the bow on, their segments joined end to end (the lifted
gaps left out, each segment shifted to start where the last ended in time).
``ReplayingHand(runner, trace)`` wraps a runner for ``SimulatedParticipant``:
it puts the hand on the ``live`` gesture at each trial and, inside every
``advance``, moves the hand's target along that motion at its own times
(looping it). The participant's strategy still decides when the bow touches
the string; the motion is the logged one. ``load_traces(events)`` reads a
session log's traces, by step.
"""

import math

import numpy as np

from studyapp.errors import UserError
from studyapp.experiment import records

SPACING_S = 0.02  # s: see the module docstring


class HandTrace:
    """One trial's gesture as performed (``add``), and its log record (``record``)."""

    def __init__(self, spacing=SPACING_S):
        self.spacing = float(spacing)
        self.samples = []  # (t, x, bow)
        self.x = None  # the latest target (None: the pointer has not moved the hand in this trial)

    def __len__(self):
        return len(self.samples)

    def move(self, t, x, bow):
        self.x = float(x)
        self._add(float(t), self.x, int(bool(bow)))

    def bow(self, t, on):
        """The bow touched (True) or left the string; a sample once the pointer has placed the hand."""
        if self.x is not None:
            self._add(float(t), self.x, int(bool(on)))

    def _add(self, t, x, bow):
        s = self.samples
        if len(s) >= 2 and t - s[-2][0] < self.spacing and s[-1][2] == bow == s[-2][2]:
            s[-1] = (t, x, bow)
        else:
            s.append((t, x, bow))

    def record(self, trial):
        """The ``hand_trace`` log record (None when empty)."""
        if not self.samples:
            return None
        t, x, bow = zip(*self.samples)
        return records.hand_trace(trial, self.spacing, [round(v, 3) for v in t], [round(v * 1e3, 3) for v in x],
                                  list(bow))


def load_traces(events, source="the session log"):
    """{step: hand_trace record} from a session's events; ``UserError`` if it has none."""
    traces = {}
    for event in events:
        if event.get("type") == "hand_trace" and event.get("t"):
            traces.setdefault(event.get("step"), event)  # the first performance of a step (a restart repeats it)
    if not traces:
        raise UserError(f"{source}: no hand_trace record: allowed is the events.jsonl of a session bowed with "
                        "the participant's bowing surface")
    for step, record in traces.items():  # checked here, before a session starts, not when its step comes
        try:
            HandReplay(record)
        except (KeyError, TypeError, ValueError, IndexError, OverflowError) as exc:
            raise UserError(f"{source}: hand_trace of step {step!r}: t, x_mm and bow must be lists of finite "
                            f"numbers of one length ({type(exc).__name__})") from None
        except UserError as exc:
            raise UserError(f"{source}: step {step!r}: {exc}") from None
    return traces


class HandReplay:
    """A logged trace's bowing motion: ``(times, positions)`` from 0, replayed in a loop by ``at``."""

    def __init__(self, record):
        t = np.asarray(record["t"], dtype=float)
        x = np.asarray(record["x_mm"], dtype=float) * 1e-3
        on = np.asarray(record["bow"], dtype=bool)
        if not (t.size == x.size == on.size) or not np.all(np.isfinite(t)) or not np.all(np.isfinite(x)):
            raise UserError("hand_trace: t, x_mm and bow must be lists of finite numbers of one length")
        times, positions, now = [], [], 0.0
        start = None
        for k in range(t.size):
            if on[k]:
                if start is None:  # a new bowing segment: it continues where the last one ended
                    start = t[k] - now
                times.append(t[k] - start)
                positions.append(x[k])
            elif start is not None:
                now, start = times[-1], None
        if not times:  # never bowed: the hand's path anyway
            times, positions = list(t - t[0]), list(x)
        self.times = np.asarray(times)
        self.positions = np.asarray(positions)
        self.duration = float(self.times[-1]) if self.times.size else 0.0

    def at(self, t):
        """The target at ``t`` s (the motion looped; its last position for a motion of one instant)."""
        if self.duration <= 0.0:
            return float(self.positions[-1])
        return float(np.interp(math.fmod(t, self.duration), self.times, self.positions))

    def times_between(self, t0, t1):
        """The motion's own sample times in (t0, t1], looped (each once)."""
        if self.duration <= 0.0:
            return []
        out = []
        lap = math.floor(t0 / self.duration)
        while lap * self.duration < t1:
            base = lap * self.duration
            out += [base + u for u in self.times if t0 < base + u <= t1]
            lap += 1
        return sorted(set(out))


class ReplayingHand:
    """A runner whose hand follows a logged motion; everything else passes through to ``runner``."""

    def __init__(self, runner, traces):
        self._runner = runner
        self._traces = dict(traces)
        self._replay = None
        self._t = 0.0

    def __getattr__(self, name):
        return getattr(self._runner, name)

    def start_trial(self):
        trial = self._runner.start_trial()
        if trial is not None:
            record = self._traces.get(trial.step) or next(iter(self._traces.values()))
            self._replay, self._t = HandReplay(record), 0.0
        return trial

    def set_gesture(self, name):
        """The strategy's gesture is ignored: the hand is the logged one."""

    def _place(self, t):
        """Aim the hand at the motion's position at ``t``: ``Live`` reaches it at the end of the next run."""
        if self._runner.loop is not None:
            if getattr(self._runner, "gesture", None) != "live":
                self._runner.set_gesture("live")
            self._runner.set_hand_target(self._replay.at(t))

    def advance(self, seconds):
        """Run ``seconds`` of the loop, the hand's target moving through the motion's own samples."""
        if self._replay is None or self._runner.loop is None:
            return self._runner.advance(seconds)
        rate = self._runner.loop.rate
        n = max(1, int(round(seconds * rate)))
        start = self._t
        blocks, done = [], 0
        for k in [round((when - start) * rate) for when in self._replay.times_between(start, start + n / rate)] + [n]:
            k = min(k, n)
            if k > done:
                self._place(start + k / rate)
                blocks.append(self._runner.advance((k - done) / rate))
                done = k
        self._t = start + n / rate
        return _joined(blocks)


def _joined(blocks):
    blocks = [b for b in blocks if b is not None]
    if not blocks:
        return None
    if len(blocks) == 1:
        return blocks[0]
    out = {}
    for key, value in blocks[0].items():
        if isinstance(value, np.ndarray):
            out[key] = np.concatenate([b[key] for b in blocks], axis=-1)
        elif isinstance(value, dict):
            out[key] = {k: np.concatenate([b[key][k] for b in blocks], axis=-1) for k in value}
        else:
            out[key] = value
    return out
