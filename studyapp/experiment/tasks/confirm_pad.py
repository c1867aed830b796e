"""What the rating and adjustment trials share: a clock, listening time, and a pad that confirms.

A trial of a confirm-pad task ends when the participant presses the
protocol's ``confirm_pad`` and the task accepts the answer. Every pad press
is logged; a press of another pad, or after the answer, changes nothing. A
press of the confirm pad is refused (with the reason logged) while
``refusal()`` gives one, so a slip of the hand is never taken as an answer.
Accepted, it logs ``{"type": "response", "task": ..., **answer()}``.

The trial's clock (``elapsed``, s) advances with ``tick(dt, bowing)``, i.e.
with the samples the loop really ran. A condition is *heard* while the bow
is on the string and F_max is above 0 (at F_max = 0 the string sounds but the
handle feels no force from it: the condition is not yet in play): ``heard[c]``
adds up those seconds for the condition in the loop. With the task's
``min_listen_s`` = L above 0 a confirm is refused, after the task's own
checks, until every condition c of the trial has heard[c] >= L; the refusal
says, by its knob and never by its name (the participant reads it), how many
more seconds each needs, L - heard[c] rounded up to 0.1 s, and logs them per
condition as ``listen_short``. Knob values are 7-bit MIDI positions
(0..127). No Qt, no I/O.
"""

import math

from studyapp.experiment import records
from studyapp.model.controls import KNOB_MAX

LISTEN_SLACK = 1e-9  # s: what float sums of block times may fall short of a whole second


def check_knob_value(value):
    if isinstance(value, bool) or not isinstance(value, int) or not 0 <= value <= KNOB_MAX:
        raise ValueError(f"knob value = {value!r}: allowed is an integer from 0 to {KNOB_MAX}")
    return value


def read_confirm_pad(table, bounds):
    """The protocol's ``confirm_pad`` field (default the first pad)."""
    return table.integer("confirm_pad", 0, bounds.pads - 1, default=0)


class ConfirmPadTrial:
    task = None  # the task type's name, set by each subclass

    def __init__(self, trial, confirm_pad, conditions, min_listen_s=0.0):
        self.trial = trial
        self.confirm_pad = confirm_pad
        self.min_listen_s = float(min_listen_s)
        self.elapsed = 0.0
        self.heard = {c: 0.0 for c in conditions}
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

    def listen_label(self, condition):
        """How the participant knows ``condition``: its knob, never its name."""
        raise NotImplementedError

    def listen_short(self):
        """{condition: seconds it must still be heard}, for the conditions short of ``min_listen_s``."""
        return {c: self.min_listen_s - s for c, s in self.heard.items() if self.min_listen_s - s > LISTEN_SLACK}

    def _listen_refusal(self):
        short = self.listen_short()
        if not short:
            return None, {}
        parts = [f"{self.listen_label(c)} needs {math.ceil(s * 10 - LISTEN_SLACK) / 10:.1f} s more"
                 for c, s in short.items()]
        return "listen longer with the bow on: " + ", ".join(parts), short

    def pad(self, index):
        record = records.pad(index)
        if self.done or index != self.confirm_pad:
            return [record]
        reason, short = self.refusal(), {}
        if reason is None:
            reason, short = self._listen_refusal()
        if reason is not None:
            return [{**record, "accepted": False, "reason": reason, **({"listen_short": short} if short else {})}]
        self.response = records.response(self.task, **self.answer())
        return [{**record, "accepted": True}, self.response]

    def tick(self, dt, bowing=False):
        self.elapsed += dt
        if bowing and self.source is not None and self.fmax > 0.0 and not self.done:
            self.heard[self.source] += dt
        return []

    def restore(self, earlier):
        return 0
