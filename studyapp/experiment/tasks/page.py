"""A page step: the participant reads a page (``studyapp.experiment.pages``) and goes on.

Not a protocol table (``protocol_table = False``): the schedule makes page
steps from ``[[pages]]``, breaks and practice. The loop is silent while a
page shows (no condition, F_max 0, the bow lifted: ``loop_conditions`` is
empty, so the runner makes no loop).

A page is done when it is acknowledged: by the participant with its ``pad``
(the confirm pad of its task) or the window's Continue button
(``acknowledge("participant")``), or by the experimenter from the console
(``acknowledge("experimenter")``, any page). The headphone level check
(``calibration``) is the experimenter's alone: a participant's press is
logged and refused. The acknowledgement is logged as a ``response`` of task
``page`` (``kind``, ``title``, ``by``, and for a calibration page
``tone_hz``, ``level_dbfs`` and ``volume_db``: the tone's level before the
volume, and the volume in force when the level was confirmed, so the level
heard is their sum), so a resumed session never shows an
acknowledged page again; how long it was read is the time between its
``trial_start`` and this record. It is not a response row: ``export_rows`` is empty
and ``measure`` None (the log keeps when each page was acknowledged).
"""

from studyapp.experiment import records
from studyapp.experiment.pages import KINDS, WHO
from studyapp.experiment.records import text
from studyapp.experiment.tasks.confirm_pad import check_knob_value

REFUSED = "the experimenter confirms this page"


class PageTrial:
    task = "page"

    def __init__(self, page, number):
        self.page = page
        self.trial = number
        self.elapsed = 0.0
        self.response = None

    @property
    def done(self):
        return self.response is not None

    @property
    def source(self):
        return None

    @property
    def fmax(self):
        return 0.0

    def knob(self, index, value):
        check_knob_value(value)
        return []

    def pad(self, index):
        record = records.pad(index)
        if self.done or index != self.page.pad:
            return [record]
        if self.page.by != "participant":
            return [{**record, "accepted": False, "reason": REFUSED}]
        return [{**record, "accepted": True}, self._acknowledged("participant")]

    def acknowledge(self, by, volume_db=0.0):
        """The participant's Continue button or the experimenter's confirm, at the master volume ``volume_db``
        (dB, the console's; 0 without one); returns the records to log."""
        if by not in WHO:
            raise ValueError(f"by = {by!r}: allowed is one of {', '.join(WHO)}")
        if self.done:
            return []
        record = records.acknowledge(by)
        if by == "participant" and self.page.by != "participant":
            return [{**record, "accepted": False, "reason": REFUSED}]
        return [{**record, "accepted": True}, self._acknowledged(by, volume_db)]

    def _acknowledged(self, by, volume_db=0.0):
        p = self.page
        self.response = records.response(self.task, trial=self.trial, fmax=0.0, kind=p.kind, title=p.title, by=by)
        if p.kind == "calibration":
            self.response.update(tone_hz=p.tone_hz, level_dbfs=p.level_dbfs, volume_db=float(volume_db))
        return self.response

    def tick(self, dt, bowing=False):
        self.elapsed += dt
        return []

    def restore(self, earlier):
        return 0

    def knob_positions(self):
        return {}


class PageType:
    name = "page"
    measure = None
    protocol_table = False

    def parse(self, table, bounds):
        raise TypeError("pages are [[pages]] of the protocol, not a task table")

    def schedule(self, spec, square, participant_index):
        raise TypeError("page steps are made by experiment.schedule, not by a Latin square")

    def loop_conditions(self, trial):
        return ()

    def start(self, spec, trial):
        return PageTrial(trial.page, trial.trial)

    def typical_duration(self, spec, trial):
        # our guesses: a break is a rest; the level check waits for the experimenter; a page is read
        return {"break": 120.0, "calibration": 60.0}.get(trial.page.kind, 30.0)

    def describe(self, trial):
        return f"page: {trial.page.kind}, {trial.page.title}"

    def heading(self, trial):
        return self.describe(trial)

    def knob_captions(self, trial, state, knobs, hidden):
        return []

    def knob_actions(self, trial, state):
        return {}

    def response_text(self, response):
        if response.get("kind") == "calibration":
            return f"Level confirmed by the {response['by']}."
        return f"Page acknowledged by the {response['by']}."

    def summary(self, response):
        return f"{response['kind']} page acknowledged by the {response['by']}"

    def response_problem(self, event):
        if event.get("kind") not in KINDS:
            return f"kind = {event.get('kind')!r}: allowed is one of {', '.join(KINDS)}"
        if event.get("by") not in WHO or not text(event.get("title")):
            return f"by = {event.get('by')!r}: allowed is one of {', '.join(WHO)}, with a title"
        return None

    def export_rows(self, event):
        return []

    def simulate(self, participant, runner, rng):
        if runner.task.page.kind == "calibration":
            runner.advance(participant.level_check_time)  # the experimenter listens to the tone first
        runner.acknowledge_page(runner.task.page.by)


TASK_TYPE = PageType()
