"""Checks of single fields of a logged event, shared by the response check and the task types.

Every number has an upper bound as well: a value such as step 10^30 or F_max
10^308 is valid JSON but no session writes it, and letting it through gave an
overflow or a memory error further on (issue 21, item 14).
"""

import math

from studyapp.model.limits import FMAX_LIMIT

STEP_MAX = 10**6  # a session's steps: a few hundred
TRIAL_MAX = 10_000  # trials of one task per condition (the protocol allows 100 plus practice)
FMAX_MAX = FMAX_LIMIT  # N: no loop ran above it


def integer(value, low, high=math.inf):
    """An int (not a bool) from ``low`` to ``high``."""
    return isinstance(value, int) and not isinstance(value, bool) and low <= value <= high


def number(value, high=math.inf):
    """A finite int or float (not a bool) from 0 to ``high``."""
    return (isinstance(value, (int, float)) and not isinstance(value, bool) and math.isfinite(value)
            and 0 <= value <= high)


def text(value):
    """A non-blank string."""
    return isinstance(value, str) and value.strip() != ""
