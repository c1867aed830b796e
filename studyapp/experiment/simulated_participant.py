"""A simulated participant: plays both tasks through the same events as a person.

It bows the string with the virtual hand (``set_bowing`` and ``advance`` on the
session runner, which runs the closed loop) and turns knobs and presses pads
(``knob``, ``pad``), so its sessions are logged, resumed and exported exactly
like a person's. Everything random comes from ``numpy.random.default_rng``
seeded by the session seed and the trial's step, so a trial plays the same
way whether or not the session was interrupted before it.

Rating task (Sec. 8.1). For each knob in turn it selects the condition (a
first turn of the knob to mid-range), bows for ``bow_time`` seconds and
measures the condition's noise with ``noisiness.velocity_noise`` over the
second half of the bowing. Its judgement of a condition is the decadic log of
that noise plus Gaussian jitter (``rating_jitter`` decades, the same listener
hearing the same noise differently). Like the paper's participants it sets the
best (least noisy) knob to the top first, then the worst to the bottom, then
places the rest linearly in log-noise between them, each with a little hand
jitter (``hand_jitter`` knob steps), and presses the confirm pad.

Adjustment task (Sec. 8.2). It rests the bow on the string and holds the
handle (gesture ``hold``: the model's oscillation shows when the bow rests or
moves slowly, while regular strokes mask it; see studyapp.model.stability),
then from F_max = 0 raises the knob in steps of 3 to 5 positions (drawn per
trial), listening ``probe_time`` seconds after each, until the loop's
stability monitor flags breakdown (it reacts within ``reaction_time``) or the
loop faults. The oscillation, once started, outlives a small turn back
(hysteresis, as the paper's participants found), so it then works down in a
staircase: lift the bow until the string is calm (at most ``rest_time``),
turn back 2 or 3 positions, bow again and listen, until the string holds. It
confirms there, moved by its personal criterion (a bias of
``criterion_spread`` knob positions drawn once per session: participants
judge "breakdown" differently, Sec. 9.1) and a per-trial jitter of
``hand_jitter`` positions. If the string never breaks down it confirms at the
top of the knob.

Times. Ratings need only a few tenths of a second of bowing. In the
adjustment task each F_max step is probed for ``probe_time`` = 1.2 s, longer
than the stability monitor needs to call a breakdown (about 1 s after the
oscillation starts, studyapp.model.stability): with shorter probes the
participant kept raising F_max past breakdown before hearing it, and confirmed
two to three times above the F_max that model.breakdown.breakdown_fmax finds.
"""

import math

import numpy as np

from studyapp.model.fmax_knob import KNOB_MAX
from studyapp.experiment.noisiness import velocity_noise


class SimulatedParticipant:
    def __init__(self, seed, bow_time=0.25, probe_time=1.2, reaction_time=0.05, rest_time=1.0,
                 retries=12, adjust_gesture="hold", rating_jitter=0.05,
                 hand_jitter=1.5, criterion_spread=2.0):
        self.seed = int(seed)
        self.bow_time = bow_time
        self.probe_time = probe_time
        self.reaction_time = reaction_time
        self.rest_time = rest_time
        self.retries = retries
        self.adjust_gesture = adjust_gesture
        self.rating_jitter = rating_jitter
        self.hand_jitter = hand_jitter
        self.criterion = float(np.random.default_rng([self.seed, 0x5EED]).normal(0.0, criterion_spread))
        self.knob_values = {}

    def play(self, runner):
        """Play every remaining trial of ``runner``'s session."""
        while (trial := runner.start_trial()) is not None:
            rng = np.random.default_rng([self.seed, trial.step])
            self.knob_values = {}
            if trial.task == "rating":
                self.rate(runner, rng)
            else:
                self.adjust(runner, rng)
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

    def _noise(self, runner, block):
        half = len(block["velocity_true"]) // 2
        noise = velocity_noise(block["source_velocity"][half:], block["velocity_true"][half:], runner.loop.rate)
        return noise if math.isfinite(noise) else math.inf

    def rate(self, runner, rng):
        conditions = runner.task.conditions
        judged = []
        runner.set_bowing(True)
        for j in range(len(conditions)):
            self.turn(runner, j, int(rng.integers(40, 88)), rng)
            block = runner.advance(self.bow_time)
            judged.append(math.log10(max(self._noise(runner, block), 1e-12)) + rng.normal(0.0, self.rating_jitter))
        runner.set_bowing(False)
        judged = np.array(judged)
        finite = np.isfinite(judged)
        judged[~finite] = (judged[finite].max() if finite.any() else 0.0) + 1.0
        best, worst = int(np.argmin(judged)), int(np.argmax(judged))
        if best == worst:
            worst = (best + 1) % len(judged)
        span = max(judged[worst] - judged[best], 1e-9)
        self.turn(runner, best, KNOB_MAX, rng)
        self.turn(runner, worst, 0, rng)
        for j in np.argsort(judged):
            if j in (best, worst):
                continue
            place = KNOB_MAX * (judged[worst] - judged[j]) / span + rng.normal(0.0, self.hand_jitter)
            self.turn(runner, int(j), int(np.clip(round(place), 1, KNOB_MAX - 1)), rng)
        runner.pad(runner.task.confirm_pad)

    def _broken(self, runner):
        return bool(runner.loop.monitor.broken) or runner.loop.fault is not None

    def _listen(self, runner, seconds):
        """Bow for up to ``seconds``; True as soon as the string breaks down (a person reacts at once)."""
        chunk = self.reaction_time
        for _ in range(max(1, int(round(seconds / chunk)))):
            runner.advance(chunk)
            if self._broken(runner):
                return True
        return False

    def _rest(self, runner):
        """Lift the bow until the string is calm again (at most ``rest_time`` s), then bow again."""
        runner.set_bowing(False)
        waited = 0.0
        while waited < self.rest_time:
            runner.advance(self.reaction_time)
            waited += self.reaction_time
            if not self._broken(runner):
                break
        runner.set_bowing(True)

    def adjust(self, runner, rng):
        knob = runner.task.knob_index
        step = int(rng.integers(3, 6))
        self.knob_values[knob] = 0
        runner.set_gesture(self.adjust_gesture)
        runner.set_bowing(True)
        runner.advance(self.reaction_time)
        value, broken = 0, False
        while value < KNOB_MAX and not broken:
            value = min(KNOB_MAX, value + step)
            self.turn(runner, knob, value, rng)
            broken = self._listen(runner, self.probe_time)
        if broken and runner.loop.fault is not None:
            value -= step
        elif broken:
            for _ in range(self.retries):
                value = max(1, value - int(rng.integers(2, 4)))
                self._rest(runner)
                self.turn(runner, knob, value, rng)
                if not self._listen(runner, self.probe_time) or value == 1:
                    break
        if broken:
            value = round(value + self.criterion + rng.normal(0.0, self.hand_jitter))
        self.turn(runner, knob, int(np.clip(value, 1, KNOB_MAX)), rng)
        runner.pad(runner.task.confirm_pad)
