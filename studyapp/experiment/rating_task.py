"""The rating task (paper Sec. 8.1-8.2) as a state machine fed by events.

Knob j plays condition ``conditions[j]`` (the participant's knob assignment).
Moving knob j selects its condition in the loop and sets its rating to the
knob's position (0..127). The participant finds the best (least noisy)
condition and turns its knob to the top, the worst to the bottom, and places
the rest between; a pad confirms. The confirm is refused (and the refusal
logged) until every condition has been rated and the best and worst differ.

The rating is noisiness, normalised per participant to [0, 1]:

    rating_c = (max_c' k_c' - k_c) / (max_c' k_c' - min_c' k_c')

so 0 is the participant's best (least noisy, highest knob) condition and 1
the worst (noisiest, lowest knob), as in the paper's Fig. 8; the raw knob
positions are kept too.

Events in: ``knob(index, value)``, ``pad(index)``, ``tick(dt)``. Each returns
the list of records to append to the session log (dicts with a ``type``). The
task's ``source`` (the condition to put in the loop, None before the first
knob turn) and ``fmax`` (0 until a condition is selected, so nothing plays an
unchosen condition) are read after each event. No Qt, no I/O.
"""

from studyapp.model.fmax_knob import KNOB_MAX


def check_knob_value(value):
    if isinstance(value, bool) or not isinstance(value, int) or not 0 <= value <= KNOB_MAX:
        raise ValueError(f"knob value = {value!r}: allowed is an integer from 0 to {KNOB_MAX}")
    return value


def normalise_ratings(knob_values):
    """{condition: knob position} -> {condition: noisiness in [0, 1]}: 0 the best (highest) knob."""
    low, high = min(knob_values.values()), max(knob_values.values())
    if high == low:
        raise ValueError("ratings cannot be normalised: the best and worst knob positions are equal")
    return {c: (high - v) / (high - low) for c, v in knob_values.items()}


class RatingTask:
    task = "rating"

    def __init__(self, conditions, fmax, confirm_pad=0, trial=1):
        self.conditions = tuple(conditions)
        self.rating_fmax = float(fmax)
        self.confirm_pad = confirm_pad
        self.trial = trial
        self.values = {c: None for c in self.conditions}
        self.selected = None
        self.elapsed = 0.0
        self.dwell = {c: 0.0 for c in self.conditions}
        self.response = None

    @property
    def done(self):
        return self.response is not None

    @property
    def source(self):
        return self.selected

    @property
    def fmax(self):
        return self.rating_fmax if self.selected is not None else 0.0

    def knob(self, index, value):
        check_knob_value(value)
        if self.done or not 0 <= index < len(self.conditions):
            return []
        condition = self.conditions[index]
        self.values[condition] = value
        self.selected = condition
        return [{"type": "knob", "index": index, "value": value, "condition": condition}]

    def pad(self, index):
        record = {"type": "pad", "index": index}
        if self.done or index != self.confirm_pad:
            return [record]
        unrated = [c for c, v in self.values.items() if v is None]
        if unrated:
            return [{**record, "accepted": False, "reason": "not rated yet: " + ", ".join(unrated)}]
        if len(set(self.values.values())) == 1:
            return [{**record, "accepted": False, "reason": "the best and worst conditions have the same rating"}]
        ratings = normalise_ratings(self.values)
        self.response = {
            "type": "response",
            "task": self.task,
            "trial": self.trial,
            "fmax": self.rating_fmax,
            "duration": self.elapsed,
            "responses": [
                {"condition": c, "knob": j, "value": self.values[c], "rating": ratings[c], "dwell": self.dwell[c]}
                for j, c in enumerate(self.conditions)
            ],
        }
        return [{**record, "accepted": True}, self.response]

    def tick(self, dt):
        self.elapsed += dt
        if self.selected is not None:
            self.dwell[self.selected] += dt
        return []
