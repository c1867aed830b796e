"""What a task type is: the one interface every task of a study implements.

A study session is a sequence of trials, each of one task type (the paper's
rating and adjustment tasks, Sec. 8.1-8.2, or any other; the pages between
them are steps of the task type ``page``, which no protocol table names:
``protocol_table = False``). Everything the app
knows about a task type goes through ``TaskType``; nothing else in
``studyapp.experiment`` or ``studyapp.analysis`` names a task. A task type is
one module in ``studyapp/experiment/tasks/`` with a module-level ``TASK_TYPE``,
registered by name in ``studyapp.experiment.tasks``:

- **protocol**: ``parse`` reads the task's TOML table (every number with a
  finite range the model accepts) into a frozen spec with at least
  ``conditions`` and ``instructions``;
- **schedule**: ``schedule`` turns the spec and the participant's Latin-square
  row into trials;
- **trial**: ``start`` makes the state machine of one trial (``TrialState``),
  fed by knob, pad and tick events (``tick(dt, bowing)``: the time the loop
  ran and whether the bow was on, which the listening time ``min_listen_s``
  counts); a task with an empty ``loop_conditions`` (``page``) runs without a
  loop, silent, and its state also takes ``acknowledge(by)``;
- **live knobs**: ``knob_actions`` is the mapping the real-time worker applies
  during a trial (a knob acts once, in the worker: studyapp.live);
- **captions**: ``heading``, ``knob_captions``, ``response_text`` are the text
  the console and the participant window show (never a condition name under
  blinding unless the task shows it on purpose);
- **export**: ``response_problem`` checks a logged response's own fields
  (``studyapp.experiment.records`` checks the common ones), ``export_rows`` turns a logged response into rows of the
  responses table (``studyapp.experiment.export``);
- **analysis**: ``measure`` says which column of those rows is the task's
  outcome, its valid range and which way is better (None: not analysed);
- **simulation**: ``simulate`` plays one trial as the simulated participant.
"""

from dataclasses import dataclass
from typing import Protocol, runtime_checkable


@dataclass(frozen=True)
class Bounds:
    """What the protocol's other tables allow a task's fields: the estimators known, the knobs and pads."""

    estimators: tuple
    knobs: int
    pads: int


@dataclass(frozen=True)
class Measure:
    """A task's outcome as the analysis reads it: one number per exported row.

    Values in ``column`` must lie in [``low``, ``high``] and be finite
    (``allowed`` says so in messages); ``higher_is_better`` orders the
    conditions best first; ``label`` names the outcome in the report.
    """

    column: str
    low: float
    high: float
    allowed: str
    higher_is_better: bool
    label: str


@runtime_checkable
class TrialState(Protocol):
    """One trial as a state machine. Each event returns the records to log (dicts with a ``type``);
    ``source`` (the condition in the loop, None for none yet) and ``fmax`` (N) are read after each."""

    task: str
    response: dict | None

    @property
    def done(self) -> bool: ...

    @property
    def source(self) -> str | None: ...

    @property
    def fmax(self) -> float: ...

    def knob(self, index: int, value: int) -> list: ...

    def pad(self, index: int) -> list: ...

    def tick(self, dt: float, bowing: bool = False) -> list:
        """``dt`` seconds of loop time passed, with the bow on the string (``bowing``) or lifted."""

    def restore(self, earlier: list) -> int:
        """Replay what may safely come back from this trial's ``earlier`` events; return how many."""

    def knob_positions(self) -> dict:
        """{knob index: position} the knobs should show at the trial's start."""


@runtime_checkable
class TaskType(Protocol):
    name: str
    measure: Measure | None

    def parse(self, table, bounds: Bounds):
        """The task's spec from its protocol ``table`` (``fields.Fields``); errors via ``table.fail``."""

    def schedule(self, spec, square: list, participant_index: int) -> tuple:
        """``(trials, rows_used)``: trials as ``(trial number, conditions, condition or None)``."""

    def loop_conditions(self, trial) -> tuple:
        """The conditions the trial's loop must hold (empty: no loop, nothing sounds)."""

    def start(self, spec, trial) -> TrialState: ...

    def typical_duration(self, spec, trial) -> float:
        """Seconds a person typically takes for ``trial``: the run sheet's estimate (``run_plan``) until
        the study has recorded trials of its own; ``spec`` is None for a page."""

    def describe(self, trial) -> str:
        """One line for the experimenter's progress (may name the condition)."""

    def heading(self, trial) -> str:
        """The console's task line, blind-safe: e.g. 'adjustment, repetition 2'."""

    def knob_captions(self, trial, state: TrialState, knobs: int, hidden: bool) -> list:
        """A caption per knob (empty string: none); ``hidden`` is the console's blinding switch."""

    def knob_actions(self, trial, state: TrialState) -> dict:
        """{control: action} the engine's worker applies during the trial, as typed actions
        (``studyapp.model.controls``): e.g. ``Select(condition, fmax)`` or
        ``FmaxKnob(ceiling, decades)``; {} for a trial without knobs."""

    def response_text(self, response: dict) -> str:
        """What the console says when ``response`` is logged, blind-safe."""

    def summary(self, response: dict) -> str:
        """One line for the experimenter's progress."""

    def response_problem(self, event: dict) -> str | None:
        """None if a logged response has the task's own fields, else ``field = value: allowed ...``."""

    def export_rows(self, event: dict) -> list:
        """Rows (dicts of ``export.COLUMNS`` beyond the common ones) for a logged response."""

    def simulate(self, participant, runner, rng) -> None:
        """Play the runner's current trial as the simulated ``participant``, with ``rng``."""
