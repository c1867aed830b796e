"""A stand-in for studyapp.model.ClosedLoop with known noise and breakdown levels.

Duck-typed like the loop (names, rate, run, set_source, set_fmax, set_bowing,
set_gesture, monitor, fault), so the session runner and the simulated participant can be
tested against known answers: each condition's estimate is the true velocity
plus white noise of a given RMS, and the monitor flags breakdown exactly when
F_max exceeds the condition's threshold while bowing.
"""

import numpy as np

from studyapp.experiment.session_runner import SessionRunner
from studyapp.experiment.simulated_participant import SimulatedParticipant

NOISE = {"LVT": 1e-4, "LOWPASS": 1e-3, "LEVANT": 1e-2}
THRESHOLD = {"LVT": 20.0, "LOWPASS": 5.0, "LEVANT": 10.0}


class Monitor:
    def __init__(self):
        self.broken = False
        self.score = 0.0


class FakeLoop:
    def __init__(self, estimators, source, seed, rate=5000.0, noise=None, threshold=None):
        self.names = list(estimators)
        self.rate = rate
        self.source = source
        self.fmax = 0.0
        self.bowing = False
        self.noise = noise or {}
        self.threshold = threshold or {}
        self.rng = np.random.default_rng(seed)
        self.monitor = Monitor()
        self.fault = None
        self.calls = []
        self.samples = 0

    def set_source(self, name):
        assert name in self.names
        self.source = name
        self.calls.append(("source", name))

    def set_fmax(self, fmax):
        self.fmax = fmax
        self.calls.append(("fmax", fmax))

    def set_bowing(self, on):
        self.bowing = on
        self.calls.append(("bowing", on))

    def set_gesture(self, name):
        self.calls.append(("gesture", name))

    def run(self, n):
        t = (self.samples + np.arange(n)) / self.rate
        self.samples += n
        v = 0.1 * np.sin(2 * np.pi * 1.5 * t) if self.bowing else np.zeros(n)
        estimates = np.array([v + self.noise.get(name, 0.0) * self.rng.standard_normal(n) for name in self.names])
        self.monitor.broken = self.bowing and self.fmax > self.threshold.get(self.source, np.inf)
        self.monitor.score = self.fmax / self.threshold.get(self.source, np.inf)
        return {"t": t, "velocity_true": v, "source_velocity": estimates[self.names.index(self.source)],
                "estimates": estimates, "force": np.zeros(n)}


def factory(noise=None, threshold=None, made=None):
    """A ``make_loop`` for SessionRunner; ``made`` (a list) collects the loops it makes."""

    def make_loop(estimators, source, seed):
        loop = FakeLoop(estimators, source, seed, noise=noise, threshold=threshold)
        if made is not None:
            made.append(loop)
        return loop

    return make_loop


def run_simulated(session, made=None, trials=None):
    """Play ``session`` (all of it, or its next ``trials``) with the simulated participant on fake loops."""
    runner = SessionRunner(session, make_loop=factory(NOISE, THRESHOLD, made))
    runner.begin()
    participant = SimulatedParticipant(session.seed, bow_time=0.1, probe_time=0.02)
    if trials is None:
        participant.play(runner)
    else:
        for _ in range(trials):
            participant.play_trial(runner, runner.start_trial())
    return runner
