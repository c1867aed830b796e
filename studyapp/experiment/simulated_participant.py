"""A simulated participant: plays every task through the same events as a person.

It bows the string with the virtual hand (``set_bowing`` and ``advance`` on the
session runner, which runs the closed loop) and turns knobs and presses pads
(``knob``, ``pad``), so its sessions are logged, resumed and exported exactly
like a person's. Everything random comes from ``numpy.random.default_rng``
seeded by the session seed and the trial's step, so a trial plays the same
way whether or not the session was interrupted before it.

How it plays a trial is its task type's ``simulate`` (``studyapp.experiment.tasks``:
the rating and adjustment strategies are described there; a page it
acknowledges at once, and a headphone level check as the experimenter would,
after listening to its tone for ``level_check_time``, so a headless session
runs through and its archived audio holds the tone); this class holds
the participant's traits (the times and jitters below, and a personal
criterion of ``criterion_spread`` knob positions drawn once per session) and
the hand's and ear's common moves: turning a knob as a hand does, measuring a
condition's noise, listening for breakdown, listening long enough
(``min_listen_s``), resting the bow.

The criterion's spread is calibrated, not measured on people: the paper reports
only that the within-participant variance of Fig. 7 was "on average 61 percent
lower" (Sec. 9.1), read as 1 - s_w^2 / (s_w^2 + s_b^2) of log F_max
(studyapp.analysis.pilot). In knob positions (each 2/126 decade on
sinclair2014's knob) the pilot's within-participant variance is s_w^2 = 4.5
(the hand jitter's 1.5^2 and the staircase's landing; seeds 1-12, 2026-11-29,
with issue 42's LVDT; 5.3 with the white LVDT before it, which gave 2.9),
and the criterion is all that differs between participants, so s_b^2 =
criterion_spread^2 = 0.61 / 0.39 * 4.5 = 7.1: 2.7 positions (9 % of F_max).
The hand jitter is left as it was: with it each participant's ranking agrees
with the global one at rho 0.95-1, as the paper's did (rho > 0.9).

Time is the loop's: listening for ``seconds`` is looking every
``reaction_time`` at the samples run since the last look until they add up
to ``seconds``. Headless each look is ``reaction_time`` exactly; in a console
on a loaded machine a look can come late and hold more (the engine runs on in
real time), and it counts all it heard, so the participant keeps the
engine's pace instead of spending a GUI round trip per ``reaction_time`` (a
1.2 s probe took 15-35 s at a load of 20 on 2 cores, and the demo session
outran its test's waits: issue 31).
"""

import math

import numpy as np

from studyapp.experiment.noisiness import velocity_noise
from studyapp.experiment.tasks import task_type
from studyapp.model.controls import KNOB_MAX


CRITERION_SPREAD = 2.7  # knob positions, the personal criterion's standard deviation (calibrated, see above)


class TrialRestarted(Exception):
    """The current trial was started again (an emergency stop, an engine restart): play it from its start."""


class SimulatedParticipant:
    def __init__(self, seed, bow_time=0.25, probe_time=1.2, reaction_time=0.05, rest_time=1.0,
                 retries=12, adjust_gesture=None, rating_jitter=0.05,
                 hand_jitter=1.5, criterion_spread=CRITERION_SPREAD, level_check_time=1.0):
        self.seed = int(seed)
        self.bow_time = bow_time
        self.probe_time = probe_time
        self.reaction_time = reaction_time
        self.rest_time = rest_time
        self.retries = retries
        self.adjust_gesture = adjust_gesture  # None: bow with the protocol's gesture, as the participants did
        self.rating_jitter = rating_jitter
        self.hand_jitter = hand_jitter
        self.level_check_time = level_check_time  # s the experimenter listens to the level check's tone
        self.criterion = float(np.random.default_rng([self.seed, 0x5EED]).normal(0.0, criterion_spread))
        self.knob_values = {}

    def play(self, runner):
        """Play every remaining trial of ``runner``'s session."""
        while (trial := runner.start_trial()) is not None:
            try:
                self.play_trial(runner, trial)
            except TrialRestarted:
                continue  # start_trial gives the same step again

    def play_trial(self, runner, trial):
        """Play ``trial``, the runner's current trial, to its response."""
        self.knob_values = {}
        task_type(trial.task).simulate(self, runner, np.random.default_rng([self.seed, trial.step]))
        if not runner.task.done:
            raise RuntimeError(f"the simulated participant did not finish {trial.describe()}")

    def turn(self, runner, index, target, rng):
        """Turn knob ``index`` to ``target`` as a hand does: through a few intermediate positions."""
        start = self.knob_values.get(index)
        target = int(np.clip(target, 0, KNOB_MAX))
        if start is not None and start != target:
            for value in np.linspace(start, target, int(rng.integers(2, 5)) + 1)[1:-1]:
                runner.knob(index, int(round(value)))
        runner.knob(index, target)
        self.knob_values[index] = target

    def noise(self, runner, block):
        """The selected condition's velocity noise over the second half of ``block`` (inf if not finite)."""
        half = len(block["velocity_true"]) // 2
        noise = velocity_noise(block["source_velocity"][half:], block["velocity_true"][half:], runner.loop.rate)
        return noise if math.isfinite(noise) else math.inf

    def broken(self, runner):
        return bool(runner.loop.monitor.broken) or runner.loop.fault is not None

    def listen_for_breakdown(self, runner, seconds):
        """Bow for up to ``seconds``; True as soon as the string breaks down (a person reacts at once)."""
        chunk = self.reaction_time
        needed = max(1, int(round(seconds / chunk))) * max(1, int(round(chunk * runner.loop.rate)))
        heard = 0
        while heard < needed:
            heard += played(runner.advance(chunk))
            if self.broken(runner):
                return True
        return False

    def listen_enough(self, runner):
        """Bow on until the trial's ``min_listen_s`` is met: a person told to listen longer does so."""
        short = runner.task.listen_short()
        if short:
            runner.set_bowing(True)
            runner.advance(max(short.values()) + self.reaction_time)

    def confirm(self, runner):
        """Hear the setting with the bow on, then press the confirm pad; a refusal is read and answered
        by listening longer (``retries`` times at most): a person confirms only what they heard."""
        for _ in range(self.retries):
            runner.set_bowing(True)
            runner.advance(self.reaction_time)
            self.listen_enough(runner)
            runner.pad(runner.task.confirm_pad)
            if runner.task.done:
                return

    def rest(self, runner):
        """Lift the bow until the string is calm again (at most ``rest_time`` s), then bow again."""
        runner.set_bowing(False)
        waited = 0.0
        while waited < self.rest_time:
            waited += played(runner.advance(self.reaction_time)) / runner.loop.rate
            if not self.broken(runner):
                break
        runner.set_bowing(True)


def played(block):
    """How many samples of the loop ``block`` holds: what the participant heard since it last looked."""
    return len(block["force"])
