"""The F_max knob: one 7-bit knob position mapped logarithmically to F_max.

The paper's participants raised F_max "logarithmically by turning to the
right", starting from no friction (Sec. 8.2). This is the one knob law of the
app, in and out of a session: step 0 gives F_max = 0, and steps 1..127 span
``decades`` decades up to the ``ceiling``:

    F_max(0) = 0,   F_max(k) = ceiling * 10^(-d (127 - k) / 126),  k = 1..127

so every step multiplies F_max by the same 10^(d/126) (3.7 % for d = 2,
5.6 % for d = 3): the relative resolution is the same at every level. The
inverse, rounded to the nearest step, is

    k(F) = 127 + round(126 / d * log10(F / ceiling)),  clipped to 1..127 for F > 0.

The range (``ceiling``, ``decades``) comes from the protocol in a session and
from ``LIVE_RANGE`` outside one.
"""

import math

KNOB_MAX = 127
LIVE_RANGE = (20.0, math.log10(200.0))  # ceiling (N), decades: 0.1 N .. 20 N


def fmax_from_knob(k, ceiling, decades):
    """F_max (N) at knob step ``k`` (0..127)."""
    k = round(k)
    if k <= 0:
        return 0.0
    return ceiling * 10.0 ** (-decades * (KNOB_MAX - min(k, KNOB_MAX)) / (KNOB_MAX - 1))


def knob_from_fmax(fmax, ceiling, decades):
    """The knob step (0..127) whose F_max is nearest ``fmax`` on the logarithmic scale."""
    if fmax <= 0:
        return 0
    step = KNOB_MAX + round((KNOB_MAX - 1) / decades * math.log10(fmax / ceiling))
    return min(max(step, 1), KNOB_MAX)
