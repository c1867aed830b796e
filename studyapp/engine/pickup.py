"""Soft takeover ("pickup"): a physical knob acts only once it has passed through the level in force.

A MIDI knob has no motor: when a trial starts (F_max back to 0) or a pause
ends, the knob is still where the hand left it, and its first message would
jump the level to that position (issue 14: LEVANT straight to 3.29 N, above
its breakdown). So a knob whose action sets a level (F_max, volume, a rating)
takes effect only when its movement covers the knob position ``target`` of
the level in force: with ``previous`` its last position seen (any mapping,
held or not; None if never seen) and ``value`` the new one, it acts when

    min(previous, value) <= target <= max(previous, value)    (just value == target without a previous)

A knob that set the level itself keeps acting (its previous position is the
target); one whose level was changed by anything else (a new trial, a pause,
an on-screen knob) must first be turned through the new level. Positions are
knob steps (0..127).
"""

from studyapp.model.fmax_knob import KNOB_MAX, knob_from_fmax

LEVEL_ACTIONS = ("fmax_log", "fmax_linear", "volume", "select")


def passes_through(target, previous, value):
    """True when a knob moving from ``previous`` (None: unknown) to ``value`` reaches ``target``."""
    if previous is None:
        return value == target
    return min(previous, value) <= target <= max(previous, value)


def level_position(action, fmax, volume, rating=None):
    """The knob step (0..127) of the level ``action`` sets, as it is now; None when it has no level yet.

    ``fmax`` (N) and ``volume`` (linear gain) are the worker's; ``rating`` the
    rating knob's position (None: not rated yet, so nothing can jump).
    """
    kind = action[0]
    if kind == "fmax_log":
        return knob_from_fmax(fmax, action[1], action[2])
    if kind == "fmax_linear":
        return _step((fmax - action[1]) / (action[2] - action[1]))
    if kind == "volume":
        return _step(volume)
    if kind == "select":
        return rating
    return None


def _step(fraction):
    return min(max(round(fraction * KNOB_MAX), 0), KNOB_MAX)
