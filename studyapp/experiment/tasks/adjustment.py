"""The adjustment task (paper Sec. 8.1-8.2): one knob raises F_max until the string breaks down.

Each condition is played in ``trials`` repetitions; repetition r follows row
r of the task's balanced Latin square from the participant's row on. A trial
starts at F_max = 0. The adjustment knob sets F_max through the one knob law
(``studyapp.model.controls.FmaxKnob``: 0 at the bottom, then logarithmically from
``ceiling`` * 10^-``decades`` to the protocol's ``ceiling``); the participant
turns it up until the string "breaks down" (the margin of stability), turns
back if they overshot, and confirms with the pad. The response is the F_max
at the confirm; the highest F_max reached during the trial is kept too, as a
record of the overshoot. A confirm at F_max = 0 is refused (no force on the
handle, so nothing can break down: it is a slip of the hand; the string
still sounds when bowed, F_max scaling only the force fed back). So is a
confirm above ``heard_fmax``, the largest F_max the attempt has run at with
the bow on and the string sounding (the runner's ``heard``, for at least one
block): nothing is confirmed that was not heard, e.g. a knob turned up over
silence after an emergency stop or an engine restart (issue 31); the response
keeps ``heard_fmax``. Other knobs are ignored.

An interrupted trial starts again from F_max = 0 (a sudden return to a high
F_max could be unsafe on a real device): nothing is restored.

The simulated participant (Sec. 8.2): it bows with the protocol's gesture (as
the participants bowed; ``adjust_gesture`` names another, e.g. ``hold``), and
the loop's stability monitor judges breakdown while bowing, against the ideal
sensor's sound and feel at the same F_max (studyapp.model.stability). From
F_max = 0 it raises the knob in steps of 3
to 5 positions (drawn per trial), listening ``probe_time`` seconds after each,
until the loop's stability monitor flags breakdown (it reacts within
``reaction_time``) or the loop faults. The oscillation, once started,
outlives a small turn back (hysteresis, as the paper's participants found),
so it then works down in a staircase: lift the bow until the string is calm
(at most ``rest_time``), turn back 2 or 3 positions, bow again and listen,
until the string holds. It confirms there, moved by its personal criterion (a
bias of ``criterion_spread`` knob positions drawn once per session:
participants judge "breakdown" differently, Sec. 9.1) and a per-trial jitter
of ``hand_jitter`` positions. If the string never breaks down it confirms at
the top of the knob.

Each F_max step is probed for ``probe_time`` = 1.2 s, longer than the
stability monitor's window (1 s while bowing, studyapp.model.stability): with shorter probes the participant kept
raising F_max past breakdown before hearing it, and confirmed two to three
times above the F_max that model.breakdown.breakdown_fmax finds.
"""

from dataclasses import dataclass

import numpy as np

from studyapp.experiment.audible_fmax import ALLOWED as AUDIBLE, FMAX_AUDIBLE
from studyapp.experiment import records
from studyapp.experiment.latin_square import participant_row
from studyapp.experiment.records import integer, text
from studyapp.experiment.task_type import Measure
from studyapp.experiment.tasks.confirm_pad import ConfirmPadTrial, check_knob_value, read_confirm_pad
from studyapp.experiment.tasks.phases import PhaseFields, read_phases
from studyapp.model.controls import KNOB_MAX, FmaxKnob
from studyapp.model.limits import FMAX_LIMIT, KNOB_DECADES

HEARD_TOLERANCE = 1e-9  # relative: the same knob position gives the same F_max, float for float


@dataclass(frozen=True)
class AdjustmentSpec(PhaseFields):
    conditions: tuple
    trials: int
    ceiling: float
    decades: float
    knob: int
    confirm_pad: int
    instructions: str


class AdjustmentTrial(ConfirmPadTrial):
    task = "adjustment"

    def __init__(self, condition, trial, ceiling, decades, knob=0, confirm_pad=0, min_listen_s=0.0):
        super().__init__(trial, confirm_pad, (condition,), min_listen_s)
        self.condition = condition
        self.ceiling = float(ceiling)
        self.decades = float(decades)
        self.action = FmaxKnob(self.ceiling, self.decades)  # the knob's action, for the worker and for fmax
        self.knob_index = knob
        self.value = 0
        self.peak_value = 0
        self.heard_fmax = 0.0  # the largest F_max heard in this attempt (bow on, the string sounding)

    @property
    def source(self):
        return self.condition

    @property
    def fmax(self):
        return self.action.fmax(self.value)

    def knob(self, index, value):
        check_knob_value(value)
        if self.done or index != self.knob_index:
            return []
        self.value = value
        self.peak_value = max(self.peak_value, value)
        return [records.knob(index, value, fmax=self.fmax)]

    def tick(self, dt, bowing=False):
        if bowing and dt > 0.0 and not self.done:
            self.heard_fmax = max(self.heard_fmax, self.fmax)
        return super().tick(dt, bowing)

    def refusal(self):
        if self.value == 0:
            return "F_max is 0: turn the knob up first"
        if self.fmax > self.heard_fmax * (1.0 + HEARD_TOLERANCE):
            return "this setting has not been heard yet: bow the string, listen, then confirm"
        return None

    def listen_label(self, condition):
        return "the string"

    def answer(self):
        return {
            "condition": self.condition,
            "trial": self.trial,
            "fmax": self.fmax,
            "value": self.value,
            "peak_fmax": self.action.fmax(self.peak_value),
            "heard_fmax": self.heard_fmax,
            "duration": self.elapsed,
        }

    def knob_positions(self):
        return {self.knob_index: self.value}


class Adjustment:
    name = "adjustment"
    measure = Measure(column="fmax", low=0.0, high=FMAX_LIMIT, allowed=f"an F_max from 0 to {FMAX_LIMIT:g} N",
                      higher_is_better=True, label="max F_max")

    def parse(self, table, bounds):
        pad = read_confirm_pad(table, bounds)
        instructions = table.string("instructions")
        return AdjustmentSpec(
            conditions=table.conditions("conditions", bounds.estimators, 1, len(bounds.estimators)),
            trials=table.integer("trials", 1, 100),
            ceiling=table.number("ceiling", FMAX_AUDIBLE, FMAX_LIMIT, AUDIBLE),
            decades=table.number("decades", *KNOB_DECADES, "decades", default=3.0),
            knob=table.integer("knob", 0, bounds.knobs - 1, default=0),
            confirm_pad=pad,
            instructions=instructions,
            **read_phases(table),
        )

    def schedule(self, spec, square, participant_index):
        trials, used = [], []
        for repetition in range(spec.trials):
            row = participant_row(square, participant_index, repetition)
            used.append((participant_index + repetition) % len(square))
            trials += [(repetition + 1, row, condition) for condition in row]
        return trials, used

    def loop_conditions(self, trial):
        return (trial.condition,)

    def start(self, spec, trial):
        return AdjustmentTrial(trial.condition, trial.trial, spec.ceiling, spec.decades, spec.knob, spec.confirm_pad,
                               spec.min_listen_s)

    def typical_duration(self, spec, trial):
        # no figure in the paper: our guess of a slow turn to breakdown, a turn back and the confirm
        # (the simulated participant takes 20-40 s of loop time); or min_listen_s and a confirm
        return max(45.0, spec.min_listen_s + 15.0)

    def describe(self, trial):
        return f"adjustment {trial.condition} trial {trial.trial}"

    def heading(self, trial):
        return f"adjustment, repetition {trial.trial}"

    def knob_captions(self, trial, state, knobs, hidden):
        return ["F_max" if i == state.knob_index else "" for i in range(knobs)]

    def knob_actions(self, trial, state):
        return {f"knob{state.knob_index + 1}": state.action}

    def response_text(self, response):
        return f"Response recorded: F_max = {response['fmax']:.3g} N."

    def summary(self, response):
        return f"F_max = {response['fmax']:.3g} N"

    def response_problem(self, event):
        if not text(event.get("condition")):
            return f"condition = {event.get('condition')!r}: allowed is an estimator name"
        if not integer(event.get("value"), 0):
            return f"value = {event.get('value')!r}: allowed is a knob position, an integer >= 0"
        return None

    def export_rows(self, event):
        return [{"condition": event["condition"], "value": event["value"], "peak_fmax": event.get("peak_fmax")}]

    def simulate(self, participant, runner, rng):
        knob = runner.task.knob_index
        step = int(rng.integers(3, 6))
        participant.knob_values[knob] = 0
        if participant.adjust_gesture is not None:
            runner.set_gesture(participant.adjust_gesture)
        runner.set_bowing(True)
        runner.advance(participant.reaction_time)
        value, broken = 0, False
        while value < KNOB_MAX and not broken:
            value = min(KNOB_MAX, value + step)
            participant.turn(runner, knob, value, rng)
            broken = participant.listen_for_breakdown(runner, participant.probe_time)
        if broken and runner.loop.fault is not None:
            value -= step
        elif broken:
            for _ in range(participant.retries):
                value = max(1, value - int(rng.integers(2, 4)))
                participant.rest(runner)
                participant.turn(runner, knob, value, rng)
                if not participant.listen_for_breakdown(runner, participant.probe_time) or value == 1:
                    break
        if broken:
            value = round(value + participant.criterion + rng.normal(0.0, participant.hand_jitter))
        participant.turn(runner, knob, int(np.clip(value, 1, KNOB_MAX)), rng)
        participant.confirm(runner)


TASK_TYPE = Adjustment()
