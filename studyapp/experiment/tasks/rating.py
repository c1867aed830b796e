"""The rating task (paper Sec. 8.1-8.2): every condition on its own knob, rated for noisiness.

Knob j plays condition ``conditions[j]`` (the participant's row of the task's
balanced Latin square). Moving knob j selects its condition in the loop, at
the protocol's constant F_max (1 N in the paper), and sets its rating to the
knob's position (0..127). The participant finds the best (least noisy)
condition and turns its knob to the top, the worst to the bottom, and places
the rest between; the confirm pad ends the trial. The confirm is refused (and
the refusal logged) until every condition has been rated and the best and
worst differ. Before the first knob turn nothing plays (F_max 0).

The rating is noisiness, normalised per participant to [0, 1]:

    rating_c = (max_c' k_c' - k_c) / (max_c' k_c' - min_c' k_c')

so 0 is the participant's best (least noisy, highest knob) condition and 1
the worst (noisiest, lowest knob), as in the paper's Fig. 8. It is computed
once, here, when the response is confirmed, and logged beside the raw knob
positions; the export carries the logged value.

On resume, the knob positions logged before the interruption come back (a
rating is a position, not a force: nothing unsafe returns).

The simulated participant (Sec. 8.1): for each knob in turn it selects the
condition (a first turn of the knob to mid-range), bows for ``bow_time``
seconds and measures the condition's noise with ``noisiness.velocity_noise``
over the second half of the bowing. Its judgement of a condition is the
decadic log of that noise plus Gaussian jitter (``rating_jitter`` decades, the
same listener hearing the same noise differently). Like the paper's
participants it sets the best (least noisy) knob to the top first, then the
worst to the bottom, then places the rest linearly in log-noise between them,
each with a little hand jitter (``hand_jitter`` knob steps), and presses the
confirm pad.
"""

import math
from dataclasses import dataclass

import numpy as np

from studyapp.experiment.audible_fmax import ALLOWED as AUDIBLE, FMAX_AUDIBLE
from studyapp.experiment import records
from studyapp.experiment.latin_square import participant_row
from studyapp.experiment.records import integer, number, text
from studyapp.experiment.task_type import Measure
from studyapp.experiment.tasks.confirm_pad import ConfirmPadTrial, check_knob_value, read_confirm_pad
from studyapp.experiment.tasks.phases import PhaseFields, read_phases
from studyapp.model.controls import KNOB_MAX, Select
from studyapp.model.limits import FMAX_LIMIT


@dataclass(frozen=True)
class RatingSpec(PhaseFields):
    conditions: tuple
    fmax: float
    confirm_pad: int
    instructions: str


def normalise_ratings(knob_values):
    """{condition: knob position} -> {condition: noisiness in [0, 1]}: 0 the best (highest) knob."""
    low, high = min(knob_values.values()), max(knob_values.values())
    if high == low:
        raise ValueError("ratings cannot be normalised: the best and worst knob positions are equal")
    return {c: (high - v) / (high - low) for c, v in knob_values.items()}


class RatingTrial(ConfirmPadTrial):
    task = "rating"

    def __init__(self, conditions, fmax, confirm_pad=0, trial=1, min_listen_s=0.0):
        super().__init__(trial, confirm_pad, conditions, min_listen_s)
        self.conditions = tuple(conditions)
        self.rating_fmax = float(fmax)
        self.values = {c: None for c in self.conditions}
        self.selected = None
        self.dwell = {c: 0.0 for c in self.conditions}

    @property
    def source(self):
        return self.selected

    @property
    def fmax(self):
        return self.rating_fmax if self.selected is not None else 0.0

    def knob(self, index, value):
        check_knob_value(value)
        if self.done or not 0 <= index < len(self.conditions):
            return []
        condition = self.conditions[index]
        self.values[condition] = value
        self.selected = condition
        return [records.knob(index, value, condition=condition)]

    def refusal(self):
        unrated = [self.listen_label(c) for c, v in self.values.items() if v is None]
        if unrated:
            return "not rated yet: " + ", ".join(unrated)
        if len(set(self.values.values())) == 1:
            return "the best and worst conditions have the same rating"
        return None

    def answer(self):
        ratings = normalise_ratings(self.values)
        return {
            "trial": self.trial,
            "fmax": self.rating_fmax,
            "duration": self.elapsed,
            "responses": [
                {"condition": c, "knob": j, "value": self.values[c], "rating": ratings[c], "dwell": self.dwell[c]}
                for j, c in enumerate(self.conditions)
            ],
        }

    def listen_label(self, condition):
        return f"knob {self.conditions.index(condition) + 1}"

    def tick(self, dt, bowing=False):
        if self.selected is not None:
            self.dwell[self.selected] += dt
        return super().tick(dt, bowing)

    def restore(self, earlier):
        knobs = [e for e in earlier if e.get("type") == "knob"]
        for e in knobs:
            self.knob(e["index"], e["value"])
        return len(knobs)

    def knob_positions(self):
        return {j: self.values[c] for j, c in enumerate(self.conditions) if self.values[c] is not None}


class Rating:
    name = "rating"
    measure = Measure(column="rating", low=0.0, high=1.0, allowed="a normalised rating in [0, 1]",
                      higher_is_better=False, label="noisiness")

    def parse(self, table, bounds):
        pad = read_confirm_pad(table, bounds)
        instructions = table.string("instructions")
        return RatingSpec(
            conditions=table.conditions("conditions", bounds.estimators, 2, bounds.knobs),
            fmax=table.number("fmax", FMAX_AUDIBLE, FMAX_LIMIT, AUDIBLE),
            confirm_pad=pad,
            instructions=instructions,
            **read_phases(table),
        )

    def schedule(self, spec, square, participant_index):
        return [(1, participant_row(square, participant_index), None)], [participant_index % len(square)]

    def loop_conditions(self, trial):
        return tuple(trial.conditions)

    def start(self, spec, trial):
        return RatingTrial(trial.conditions, spec.fmax, spec.confirm_pad, trial.trial, spec.min_listen_s)

    def typical_duration(self, spec, trial):
        # "All participants finished this task in less than 5 minutes" (paper Sec. 8.1): the upper bound,
        # or longer when min_listen_s makes every condition be heard that long
        return max(300.0, len(trial.conditions) * spec.min_listen_s + 60.0)

    def describe(self, trial):
        return f"rating of {len(trial.conditions)} conditions"

    def heading(self, trial):
        return self.describe(trial)

    def knob_captions(self, trial, state, knobs, hidden):
        return [] if hidden else list(trial.conditions)

    def knob_actions(self, trial, state):
        return {f"knob{j + 1}": Select(c, state.rating_fmax) for j, c in enumerate(state.conditions)}

    def response_text(self, response):
        return "Ratings recorded."

    def summary(self, response):
        return ", ".join(f"{r['condition']} {r['rating']:.2f}" for r in response["responses"])

    def response_problem(self, event):
        responses = event.get("responses")
        allowed = "a list of {condition, knob, value, rating} objects"
        if not isinstance(responses, list) or not responses or not all(isinstance(r, dict) for r in responses):
            return f"responses = {responses!r}: allowed is {allowed}"
        for r in responses:
            if not (text(r.get("condition")) and integer(r.get("knob"), 0) and integer(r.get("value"), 0)
                    and number(r.get("rating"))):
                return f"responses item {r!r}: allowed is {allowed}"
        return None

    def export_rows(self, event):
        return [{"condition": r["condition"], "rating": r["rating"], "value": r["value"], "knob": r["knob"]}
                for r in event["responses"]]

    def simulate(self, participant, runner, rng):
        conditions = runner.task.conditions
        judged = []
        runner.set_bowing(True)
        for j in range(len(conditions)):
            participant.turn(runner, j, int(rng.integers(40, 88)), rng)
            block = runner.advance(max(participant.bow_time, runner.task.min_listen_s))
            noise = participant.noise(runner, block)
            judged.append(math.log10(max(noise, 1e-12)) + rng.normal(0.0, participant.rating_jitter))
        runner.set_bowing(False)
        judged = np.array(judged)
        finite = np.isfinite(judged)
        judged[~finite] = (judged[finite].max() if finite.any() else 0.0) + 1.0
        best, worst = int(np.argmin(judged)), int(np.argmax(judged))
        if best == worst:
            worst = (best + 1) % len(judged)
        span = max(judged[worst] - judged[best], 1e-9)
        participant.turn(runner, best, KNOB_MAX, rng)
        participant.turn(runner, worst, 0, rng)
        for j in np.argsort(judged):
            if j in (best, worst):
                continue
            place = KNOB_MAX * (judged[worst] - judged[j]) / span + rng.normal(0.0, participant.hand_jitter)
            participant.turn(runner, int(j), int(np.clip(round(place), 1, KNOB_MAX - 1)), rng)
        runner.pad(runner.task.confirm_pad)


TASK_TYPE = Rating()
