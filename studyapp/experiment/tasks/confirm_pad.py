"""What the rating and adjustment trials share: a clock, and a pad that confirms.

A trial of a confirm-pad task ends when the participant presses the
protocol's ``confirm_pad`` and the task accepts the answer. Every pad press
is logged; a press of another pad, or after the answer, changes nothing. A
press of the confirm pad is refused (with the reason logged) while
``refusal()`` gives one, so a slip of the hand is never taken as an answer.
Accepted, it logs ``{"type": "response", "task": ..., **answer()}``.

The trial's clock (``elapsed``, s) advances with ``tick(dt)``, i.e. with the
samples the loop really ran. Knob values are 7-bit MIDI positions (0..127).
No Qt, no I/O.
"""

from studyapp.model.fmax_knob import KNOB_MAX


def check_knob_value(value):
    if isinstance(value, bool) or not isinstance(value, int) or not 0 <= value <= KNOB_MAX:
        raise ValueError(f"knob value = {value!r}: allowed is an integer from 0 to {KNOB_MAX}")
    return value


def read_confirm_pad(table, bounds):
    """The protocol's ``confirm_pad`` field (default the first pad)."""
    return table.integer("confirm_pad", 0, bounds.pads - 1, default=0)


class ConfirmPadTrial:
    task = None  # the task type's name, set by each subclass

    def __init__(self, trial, confirm_pad):
        self.trial = trial
        self.confirm_pad = confirm_pad
        self.elapsed = 0.0
        self.response = None

    @property
    def done(self):
        return self.response is not None

    def refusal(self):
        """Why a confirm now would be refused (None: it is accepted)."""
        raise NotImplementedError

    def answer(self):
        """The response's fields after ``type`` and ``task``."""
        raise NotImplementedError

    def pad(self, index):
        record = {"type": "pad", "index": index}
        if self.done or index != self.confirm_pad:
            return [record]
        reason = self.refusal()
        if reason is not None:
            return [{**record, "accepted": False, "reason": reason}]
        self.response = {"type": "response", "task": self.task, **self.answer()}
        return [{**record, "accepted": True}, self.response]

    def tick(self, dt):
        self.elapsed += dt
        return []

    def restore(self, earlier):
        return 0
