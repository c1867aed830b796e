"""A participant's schedule: the trials of a session, in order.

Each ``Trial`` has a ``step`` (its place in the session, from 0), its ``task``,
its ``trial`` number within its condition (from 1), ``conditions`` (the
participant's row of the task's Latin square) and, for a trial of one
condition, ``condition``. Each task type (``studyapp.experiment.tasks``) says
how its conditions make trials: the rating task is one trial over all its
conditions, ``conditions`` then being the knob assignment (knob j plays
``conditions[j]``); an adjustment trial has one ``condition``. The order comes
from the protocol's balanced Latin squares and the participant's enrolment
index (see ``latin_square``); the schedule is stored in session.json, so a
resumed session keeps it whatever the protocol file says.
"""

from dataclasses import asdict, dataclass

from studyapp.experiment.latin_square import balanced_latin_square, task_seed
from studyapp.experiment.tasks import task_type


@dataclass(frozen=True)
class Trial:
    step: int
    task: str
    trial: int
    conditions: tuple
    condition: str | None = None

    def to_dict(self):
        d = asdict(self)
        d["conditions"] = list(self.conditions)
        return d

    @classmethod
    def from_dict(cls, d):
        return cls(step=int(d["step"]), task=d["task"], trial=int(d["trial"]),
                   conditions=tuple(d["conditions"]), condition=d.get("condition"))

    def describe(self):
        return task_type(self.task).describe(self)


def build_schedule(protocol, participant_index, order_row=None):
    """The trials of the ``participant_index``-th participant (from 0) under ``protocol``.

    ``order_row`` (``session_info``) picks the Latin-square rows in place of the enrolment index.

    Returns ``(trials, squares)``: ``squares`` records, per task, the number of
    rows of its Latin square and the rows used, for session.json.
    """
    trials, squares = [], {}
    for task in protocol.tasks:
        spec = protocol.task(task)
        seed = task_seed(protocol.seed, task)
        square = balanced_latin_square(spec.conditions, seed)
        row = participant_index if order_row is None else order_row
        planned, used = task_type(task).schedule(spec, square, row)
        for number, conditions, condition in planned:
            trials.append(Trial(len(trials), task, number, tuple(conditions), condition))
        squares[task] = {"rows": len(square), "rows_used": used, "seed": seed}
    return trials, squares
