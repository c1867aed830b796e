"""The listen task: each condition plays for a set time, and that it was heard is logged.

A familiarisation or exposure block: one trial per condition, in the order of
the participant's row of the task's balanced Latin square. The trial puts its
condition in the loop at the protocol's constant ``fmax`` (N) from its start
and ends by itself once its clock, which advances with the samples the loop
really ran, reaches ``duration_s``: it then logs a response record with
``listened`` true and the time it played. The participant answers nothing;
knobs are ignored and pads only logged. An interrupted trial plays again
from its start. The task has no outcome to analyse (``measure`` None); its
exported rows carry the condition, F_max and duration.

The simulated participant bows through the whole trial.
"""

from dataclasses import dataclass

from studyapp.experiment.audible_fmax import ALLOWED as AUDIBLE, FMAX_AUDIBLE
from studyapp.experiment import records
from studyapp.experiment.latin_square import participant_row
from studyapp.experiment.records import text
from studyapp.experiment.tasks.confirm_pad import check_knob_value
from studyapp.experiment.tasks.phases import PhaseFields, read_phases
from studyapp.model.limits import FMAX_LIMIT

DURATION_RANGE = (0.1, 600.0)  # s


@dataclass(frozen=True)
class ListenSpec(PhaseFields):
    conditions: tuple
    fmax: float
    duration_s: float
    instructions: str


class ListenTrial:
    task = "listen"

    def __init__(self, condition, trial, fmax, duration_s):
        self.condition = condition
        self.trial = trial
        self.listen_fmax = float(fmax)
        self.duration_s = float(duration_s)
        self.elapsed = 0.0
        self.response = None

    @property
    def done(self):
        return self.response is not None

    @property
    def source(self):
        return self.condition

    @property
    def fmax(self):
        return self.listen_fmax

    @property
    def remaining(self):
        return max(self.duration_s - self.elapsed, 0.0)

    def knob(self, index, value):
        check_knob_value(value)
        return []

    def pad(self, index):
        return [records.pad(index)]

    def tick(self, dt, bowing=False):
        if self.done:
            return []
        self.elapsed += dt
        if self.elapsed < self.duration_s:
            return []
        self.response = records.response(self.task, condition=self.condition, trial=self.trial, fmax=self.listen_fmax,
                                         listened=True, duration=self.elapsed)
        return [self.response]

    def restore(self, earlier):
        return 0

    def knob_positions(self):
        return {}


class Listen:
    name = "listen"
    measure = None

    def parse(self, table, bounds):
        return ListenSpec(
            conditions=table.conditions("conditions", bounds.estimators, 1, len(bounds.estimators)),
            fmax=table.number("fmax", FMAX_AUDIBLE, FMAX_LIMIT, AUDIBLE),
            duration_s=table.number("duration_s", *DURATION_RANGE, "s"),
            instructions=table.string("instructions"),
            **read_phases(table, confirmed=False),
        )

    def schedule(self, spec, square, participant_index):
        row = participant_row(square, participant_index)
        return [(1, row, condition) for condition in row], [participant_index % len(square)]

    def loop_conditions(self, trial):
        return (trial.condition,)

    def start(self, spec, trial):
        return ListenTrial(trial.condition, trial.trial, spec.fmax, spec.duration_s)

    def typical_duration(self, spec, trial):
        return spec.duration_s  # the trial ends by itself

    def describe(self, trial):
        return f"listen to {trial.condition}"

    def heading(self, trial):
        return f"listen, condition {trial.conditions.index(trial.condition) + 1} of {len(trial.conditions)}"

    def knob_captions(self, trial, state, knobs, hidden):
        return []

    def knob_actions(self, trial, state):
        return {}

    def response_text(self, response):
        return "Listened."

    def summary(self, response):
        return f"listened {response['duration']:.3g} s"

    def response_problem(self, event):
        if not text(event.get("condition")):
            return f"condition = {event.get('condition')!r}: allowed is an estimator name"
        return None

    def export_rows(self, event):
        return [{"condition": event["condition"]}]

    def simulate(self, participant, runner, rng):
        runner.set_bowing(True)
        while not runner.task.done:
            runner.advance(runner.task.remaining)


TASK_TYPE = Listen()
