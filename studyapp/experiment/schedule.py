"""A participant's schedule: the steps of a session, in order.

Each ``Trial`` has a ``step`` (its place in the session, from 0), its ``task``,
its ``trial`` number within its condition (from 1), ``conditions`` (the
participant's row of the task's Latin square) and, for a trial of one
condition, ``condition``. Each task type (``studyapp.experiment.tasks``) says
how its conditions make trials: the rating task is one trial over all its
conditions, ``conditions`` then being the knob assignment (knob j plays
``conditions[j]``); an adjustment trial has one ``condition``. The order comes
from the protocol's balanced Latin squares and the participant's enrolment
index p (see ``latin_square``); the schedule is stored in session.json, so a
resumed session keeps it whatever the protocol file says.

The session's procedure (paper Sec. 8.2), step by step:

    welcome page(s), calibration page(s)
    for each task:  transition page (from the second task on), instructions page(s),
                    ``practice`` practice trials, "practice is over" (if any),
                    the real trials, a break page after every ``break_every`` of them (not after the last)
    goodbye page(s)

Pages (``studyapp.experiment.pages``) are steps of task ``page`` with the
whole ``page`` stored in the step (a calibration page with its tone's level
made concrete: ``level_check``); ``trial`` numbers them from 1. Practice
trials (``practice`` true, ``trial`` 1..N) are the first N trials the task
type schedules for participants p + 1, p + 2, ... (p the enrolment index,
or the session's ``order_row`` when set): the task's own conditions,
deterministic from the study seed and p, and not the order of the
participant's first real trials.
"""

import itertools
from dataclasses import asdict, dataclass

from studyapp.experiment import pages as page_kinds
from studyapp.experiment.latin_square import balanced_latin_square, task_seed
from studyapp.experiment.level_check import calibrated
from studyapp.experiment.pages import Page
from studyapp.experiment.tasks import task_type


@dataclass(frozen=True)
class Trial:
    step: int
    task: str
    trial: int
    conditions: tuple
    condition: str | None = None
    practice: bool = False
    page: Page | None = None

    @property
    def phase(self):
        """``page``, ``practice`` or ``trial`` (a real trial)."""
        return "page" if self.page is not None else "practice" if self.practice else "trial"

    def to_dict(self):
        d = asdict(self)
        d["conditions"] = list(self.conditions)
        return d

    @classmethod
    def from_dict(cls, d):
        page = d.get("page")  # absent in sessions stored before pages and practice existed
        return cls(step=int(d["step"]), task=d["task"], trial=int(d["trial"]),
                   conditions=tuple(d["conditions"]), condition=d.get("condition"),
                   practice=bool(d.get("practice", False)), page=Page.from_dict(page) if page else None)

    def describe(self):
        text = task_type(self.task).describe(self)
        return f"practice {text}" if self.practice else text


def counted(schedule, trial):
    """``(phase, number, of)``: the trial's place among the steps of its phase (pages: among all
    pages; practice and real trials: among those of its task), e.g. ("trial", 2, 12)."""
    same = [t.step for t in schedule
            if t.phase == trial.phase and (trial.phase == "page" or t.task == trial.task)]
    return trial.phase, same.index(trial.step) + 1, len(same)


def _practice(kind, spec, square, participant_index):
    planned, index = [], participant_index
    while len(planned) < spec.practice:
        index += 1
        planned += kind.schedule(spec, square, index)[0]
    return planned[:spec.practice]


def build_schedule(protocol, participant_index, order_row=None):
    """The steps of the ``participant_index``-th participant (from 0) under ``protocol``.

    ``order_row`` (``session_info``) picks the Latin-square rows in place of the enrolment index.

    Returns ``(trials, squares)``: ``squares`` records, per task, the number of
    rows of its Latin square and the rows used, for session.json.
    """
    steps, squares = [], {}
    pages = protocol.pages
    listed = bool(pages)
    pads = {task: getattr(protocol.task(task), "confirm_pad", 0) for task in protocol.tasks}
    numbered = itertools.count(1)

    def add(task, number, conditions=(), condition=None, practice=False):
        steps.append(Trial(len(steps), task, number, tuple(conditions), condition, practice))

    def show(*shown):
        for page in shown:
            steps.append(Trial(len(steps), "page", next(numbered), (), None, page=page))

    first, last = protocol.tasks[0], protocol.tasks[-1]
    show(*page_kinds.pages_of(pages, "welcome", pads[first]),
         *(calibrated(p, protocol) for p in page_kinds.pages_of(pages, "calibration", pads[first])))
    n = len(protocol.tasks)
    for k, task in enumerate(protocol.tasks, start=1):
        spec, kind, pad = protocol.task(task), task_type(task), pads[task]
        if listed:
            if k > 1:
                show(*page_kinds.transition_page(pages, task, k, n, pad))
            show(*page_kinds.instructions_pages(pages, task, spec.instructions, k, n, pad))
        seed = task_seed(protocol.seed, task)
        square = balanced_latin_square(spec.conditions, seed)
        row = participant_index if order_row is None else order_row
        for number, (_, conditions, condition) in enumerate(_practice(kind, spec, square, row), 1):
            add(task, number, conditions, condition, practice=True)
        if spec.practice:
            show(page_kinds.practice_over_page(task, pad))
        planned, used = kind.schedule(spec, square, row)
        for done, (number, conditions, condition) in enumerate(planned):
            if spec.break_every and done and done % spec.break_every == 0:
                show(page_kinds.break_page(pages, task, done, len(planned), pad))
            add(task, number, conditions, condition)
        squares[task] = {"rows": len(square), "rows_used": used, "seed": seed}
    show(*page_kinds.pages_of(pages, "goodbye", pads[last]))
    return steps, squares
