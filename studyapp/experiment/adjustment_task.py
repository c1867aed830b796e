"""One trial of the adjustment task (paper Sec. 8.1-8.2) as a state machine.

The trial starts at F_max = 0. The adjustment knob sets F_max through the
logarithmic map of ``fmax_knob`` (0 at the bottom, the protocol's ceiling at
the top); the participant turns it up until the string "breaks down" (the
margin of stability), turns back if they overshot, and confirms with the pad.
The response is the F_max at the confirm; the highest F_max reached during the
trial is kept too, as a record of the overshoot. A confirm at F_max = 0 is
refused (no friction cannot break down: it is a slip of the hand).

Events in: ``knob(index, value)``, ``pad(index)``, ``tick(dt)``; each returns
the records to log. Other knobs than the adjustment knob are ignored. The
condition in the loop (``source``) is fixed for the trial; ``fmax`` is read
after each event. No Qt, no I/O.
"""

from studyapp.model.fmax_knob import fmax_from_knob
from studyapp.experiment.rating_task import check_knob_value


class AdjustmentTask:
    task = "adjustment"

    def __init__(self, condition, trial, ceiling, decades, knob=0, confirm_pad=0):
        self.condition = condition
        self.trial = trial
        self.ceiling = float(ceiling)
        self.decades = float(decades)
        self.knob_index = knob
        self.confirm_pad = confirm_pad
        self.value = 0
        self.peak_value = 0
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
        return fmax_from_knob(self.value, self.ceiling, self.decades)

    def knob(self, index, value):
        check_knob_value(value)
        if self.done or index != self.knob_index:
            return []
        self.value = value
        self.peak_value = max(self.peak_value, value)
        return [{"type": "knob", "index": index, "value": value, "fmax": self.fmax}]

    def pad(self, index):
        record = {"type": "pad", "index": index}
        if self.done or index != self.confirm_pad:
            return [record]
        if self.value == 0:
            return [{**record, "accepted": False, "reason": "F_max is 0: turn the knob up first"}]
        self.response = {
            "type": "response",
            "task": self.task,
            "condition": self.condition,
            "trial": self.trial,
            "fmax": self.fmax,
            "value": self.value,
            "peak_fmax": fmax_from_knob(self.peak_value, self.ceiling, self.decades),
            "duration": self.elapsed,
        }
        return [{**record, "accepted": True}, self.response]

    def tick(self, dt):
        self.elapsed += dt
        return []
