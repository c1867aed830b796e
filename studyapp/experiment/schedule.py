"""A participant's schedule: the trials of a session, in order.

Each ``Trial`` has a ``step`` (its place in the session, from 0), its ``task``,
and its ``trial`` number within its condition (from 1). The rating task is one
trial over all its conditions; ``conditions`` is then the knob assignment
(knob j plays ``conditions[j]``). An adjustment trial has one ``condition``.
The order comes from the protocol's balanced Latin squares and the
participant's enrolment index (see ``latin_square``); the schedule is stored in
session.json, so a resumed session keeps it whatever the protocol file says.
"""

from dataclasses import asdict, dataclass

from studyapp.experiment.latin_square import balanced_latin_square, participant_row, task_seed


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
        if self.task == "rating":
            return f"rating of {len(self.conditions)} conditions"
        return f"adjustment {self.condition} trial {self.trial}"


def build_schedule(protocol, participant_index):
    """The trials of the ``participant_index``-th participant (from 0) under ``protocol``.

    Returns ``(trials, squares)``: ``squares`` records, per task, the number of
    rows of its Latin square and the rows used, for session.json.
    """
    trials, squares = [], {}
    for task in protocol.tasks:
        spec = protocol.task(task)
        square = balanced_latin_square(spec.conditions, task_seed(protocol.seed, task))
        if task == "rating":
            row = participant_row(square, participant_index)
            trials.append(Trial(len(trials), "rating", 1, tuple(row)))
            used = [participant_index % len(square)]
        else:
            used = []
            for repetition in range(spec.trials):
                row = participant_row(square, participant_index, repetition)
                used.append((participant_index + repetition) % len(square))
                for condition in row:
                    trials.append(Trial(len(trials), "adjustment", repetition + 1, tuple(row), condition))
        squares[task] = {"rows": len(square), "rows_used": used, "seed": task_seed(protocol.seed, task)}
    return trials, squares
